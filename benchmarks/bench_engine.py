"""Engine benchmark (issue 2): speed and accuracy of the rocking solvers on one scene set.

One run times, on the same random set of sine-pulse scenes:
  - the scipy path: solve_ivp DOP853 with events at rtol 1e-8, integrating the free rocking
    after the pulse ("scipy full"), and with the kernels' closed-form map instead ("scipy+map",
    the like-for-like comparison);
  - the numba nonlinear kernel at rtol 1e-8 (batch entry point, one thread = one core);
  - the exact linear solver (batch entry point, one thread);
  - both of these again for the source tree of ``--old-rev`` (extracted by ``git archive``,
    timed in a subprocess on the same scenes), with the ratios and whether the outputs are
    bit-identical.
The kernels are timed in CPU seconds of their process (``time.process_time``, best of
repeats: the machine is shared, and wall time measures the neighbours). Errors are measured
against solve_ivp DOP853 at rtol 1e-12. Prints a table and writes
benchmarks/results/engine.json.

    python benchmarks/bench_engine.py [--scenes 1000] [--scipy-scenes 1000] [--old-rev 85ac0e1]
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numba
import numpy as np
from bench_records import run_at_rev

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.batch import simulate_batch
from rockstudy.dynamics.reference import simulate_reference

HERE = Path(__file__).resolve().parent
OUT = HERE / "results"


def scene_set(n, seed=20261121):
    rng = np.random.default_rng(seed)
    R = rng.uniform(0.3, 5.0, n)
    alpha = rng.uniform(0.05, 0.4, n)
    ratio = rng.uniform(1.05, 5.0, n)  # a_g / (g tan alpha): rocking and overturning
    amp = ratio * G * np.tan(alpha) * rng.choice([-1.0, 1.0], n)
    period = rng.uniform(0.1, 2.0, n)
    return R, alpha, amp, period


def timed(fn, repeat):
    """(output, best CPU seconds of ``repeat`` calls)."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return out, best


def time_kernels(n, repeat=10):
    """Scenes/s/core of the importable rockstudy's nonlinear kernel (rtol 1e-8) and exact
    linear solver through ``simulate_batch`` on one thread, and their outputs."""
    numba.set_num_threads(1)
    R, alpha, amp, period = scene_set(n)
    kw = dict(half_diagonal=R, slenderness=alpha, pulse="sine", amplitude=amp, period=period)
    few = {k: v[:2] if isinstance(v, np.ndarray) else v for k, v in kw.items()}
    simulate_batch(**few)  # warm up (compile or load the cache)
    simulate_batch(method="linear", **few)
    ker, t_ker = timed(lambda: simulate_batch(rtol=1e-8, **kw), repeat)
    lin, t_lin = timed(lambda: simulate_batch(method="linear", **kw), 3 * repeat)
    return {
        "nonlinear_kernel": n / t_ker,
        "linear_exact": n / t_lin,
        "median_steps": float(np.median(ker["steps"])),
        "nonlinear": {k: np.asarray(v, float).tolist() for k, v in ker.items()},
        "linear": {k: np.asarray(v, float).tolist() for k, v in lin.items()},
    }


def same_outputs(a, b):
    """Whether two output dicts are bit-identical (NaN equal to NaN), and the largest
    relative difference of max_rotation."""
    same = all(np.array_equal(np.asarray(a[k]), np.asarray(b[k]), equal_nan=True) for k in a)
    x, y = np.asarray(a["max_rotation"]), np.asarray(b["max_rotation"])
    return same, float(np.max(np.abs(x - y) / np.maximum(np.abs(y), 1e-300)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=1000)
    ap.add_argument(
        "--scipy-scenes", type=int, default=1000, help="scenes timed through scipy (the slow part)"
    )
    ap.add_argument("--old-rev", default="85ac0e1", help="the kernel to compare with")
    ap.add_argument("--repeat", type=int, default=10, help="timing repeats (best is kept)")
    args = ap.parse_args()
    n = args.scenes
    R, alpha, amp, period = scene_set(n)
    p = np.sqrt(3 * G / (4 * R))
    eta = 1 - 1.5 * np.sin(alpha) ** 2
    print(f"timing {n} scenes: this checkout, then {args.old_rev} ...", flush=True)
    new = time_kernels(n, args.repeat)
    old = run_at_rev(args.old_rev, "bench_engine", f"time_kernels({n}, {args.repeat})")
    ker = {k: np.asarray(v) for k, v in new["nonlinear"].items()}
    ker["overturned"] = ker["overturned"].astype(bool)

    # reference, rtol 1e-12, full integration
    print(f"reference: {n} scenes through solve_ivp DOP853 at rtol 1e-12 ...", flush=True)
    ref = [
        simulate_reference(
            p[i], alpha[i], eta[i], rs.motions.SinePulse(amp[i], period[i]), rtol=1e-12
        )
        for i in range(n)
    ]
    ref_max = np.array([r["max_rotation"] for r in ref])
    ref_over = np.array([r["overturned"] for r in ref])

    # scipy timings at rtol 1e-8
    m = min(args.scipy_scenes, n)
    sc_times = {"full": [], "map": []}
    sc_max = np.empty(m)
    for i in range(m):
        pulse = rs.motions.SinePulse(amp[i], period[i])
        for key, fm in (("full", False), ("map", True)):
            t0 = time.perf_counter()
            r = simulate_reference(p[i], alpha[i], eta[i], pulse, rtol=1e-8, free_map=fm)
            sc_times[key].append(time.perf_counter() - t0)
            if fm:
                sc_max[i] = r["max_rotation"]

    # kernel impact times (single-scene path, rtol 1e-8) against the reference
    imp_err = np.full(n, np.nan)
    for i in range(n):
        pulse = rs.motions.SinePulse(amp[i], period[i])
        res = rs.simulate(rs.Block(R[i], alpha[i]), pulse, rtol=1e-8)
        k = min(10, ref[i]["impact_times"].size, res.n_impacts)
        if k:
            imp_err[i] = np.max(np.abs(res.impact_times[:k] - ref[i]["impact_times"][:k]))
    # conditioning of the scenes that miss 1e-8 s: how far do their impact times move for a
    # 1e-9 relative change of a_g? error / sensitivity = the equivalent input perturbation
    ill = []
    for i in np.flatnonzero(imp_err > 1e-8):
        pulse = rs.motions.SinePulse(amp[i] * (1 + 1e-9), period[i])
        pert = simulate_reference(p[i], alpha[i], eta[i], pulse, rtol=1e-12)["impact_times"]
        k = min(10, pert.size, ref[i]["impact_times"].size)
        sens = np.max(np.abs(pert[:k] - ref[i]["impact_times"][:k])) / 1e-9
        ill.append(
            {
                "scene": int(i),
                "error_s": float(imp_err[i]),
                "sensitivity_s_per_relative_amplitude": float(sens),
                "equivalent_relative_amplitude_error": float(imp_err[i] / sens),
                "max_rotation_over_alpha": float(ref_max[i] / alpha[i]),
            }
        )
    imp_err = imp_err[np.isfinite(imp_err)]

    survived = ~ref_over & (ref_max > 0)
    rel = np.abs(ker["max_rotation"][survived] / ref_max[survived] - 1)
    disagree = np.flatnonzero(ker["overturned"] != ref_over)
    near_boundary = 0
    for i in disagree:  # is the scene within 1e-4 (relative amplitude) of the boundary?
        outs = {
            simulate_reference(
                p[i], alpha[i], eta[i], rs.motions.SinePulse(amp[i] * f, period[i]), rtol=1e-12
            )["overturned"]
            for f in (1 - 1e-4, 1 + 1e-4)
        }
        near_boundary += len(outs) == 2

    rate = {
        "scipy_full": m / float(np.sum(sc_times["full"])),
        "scipy_map": m / float(np.sum(sc_times["map"])),
        "nonlinear_kernel": new["nonlinear_kernel"],
        "linear_exact": new["linear_exact"],
        f"nonlinear_kernel_{args.old_rev}": old["nonlinear_kernel"],
        f"linear_exact_{args.old_rev}": old["linear_exact"],
    }
    versus_old = {
        path: {
            "ratio": new[path] / old[path],
            "bit_identical": same_outputs(new[key], old[key])[0],
            "max_rotation_max_rel_difference": same_outputs(new[key], old[key])[1],
        }
        for path, key in (("nonlinear_kernel", "nonlinear"), ("linear_exact", "linear"))
    }
    result = {
        "scenes": n,
        "scipy_scenes": m,
        "machine": platform.processor() or platform.machine(),
        "scenes_per_second_per_core": rate,
        "old_rev": args.old_rev,
        "versus_old_rev": versus_old,
        "median_steps": new["median_steps"],
        "ratio_kernel_vs_scipy_full": rate["nonlinear_kernel"] / rate["scipy_full"],
        "ratio_kernel_vs_scipy_map": rate["nonlinear_kernel"] / rate["scipy_map"],
        "ratio_linear_vs_scipy_map": rate["linear_exact"] / rate["scipy_map"],
        "kernel_max_rotation_rel_error": {
            "max": float(rel.max()),
            "p99": float(np.quantile(rel, 0.99)),
            "median": float(np.median(rel)),
        },
        "scipy_1e-8_max_rotation_rel_error_max": float(
            np.max(np.abs(sc_max[survived[:m]] / ref_max[:m][survived[:m]] - 1))
        ),
        "kernel_first10_impact_time_abs_error": {
            "max": float(imp_err.max()),
            "p99": float(np.quantile(imp_err, 0.99)),
            "median": float(np.median(imp_err)),
            "scenes_above_1e-8_s": len(ill),
            "scenes_checked": int(imp_err.size),
        },
        "ill_conditioned_scenes": ill,
        "overturn_disagreements": int(disagree.size),
        "overturn_disagreements_within_1e-4_of_boundary": int(near_boundary),
        "overturned_share": float(ref_over.mean()),
        "status_nonzero": int(np.count_nonzero(ker["status"])),
    }
    OUT.mkdir(exist_ok=True)
    (OUT / "engine.json").write_text(json.dumps(result, indent=2))
    print(f"{'path':22s} {'scenes/s/core':>14s} {'vs scipy full':>14s} {'vs scipy+map':>13s}")
    for key, v in rate.items():
        print(f"{key:22s} {v:14.1f} {v / rate['scipy_full']:14.1f} {v / rate['scipy_map']:13.1f}")
    for path, v in versus_old.items():
        print(
            f"{path}: {v['ratio']:.2f} x {args.old_rev}; outputs "
            + (
                "bit-identical"
                if v["bit_identical"]
                else f"differ (max_rotation by {v['max_rotation_max_rel_difference']:.1e} rel.)"
            )
        )
    e = result["kernel_max_rotation_rel_error"]
    print(
        f"kernel max-rotation rel. error vs rtol 1e-12: max {e['max']:.2e}, "
        f"p99 {e['p99']:.2e}, median {e['median']:.2e}"
    )
    print(
        f"kernel first-10 impact times: median {np.median(imp_err):.1e} s, p99 "
        f"{np.quantile(imp_err, 0.99):.1e} s, max {imp_err.max():.1e} s; "
        f"{len(ill)} of {imp_err.size} scenes above 1e-8 s:"
    )
    for c in ill:
        print(
            f"  scene {c['scene']}: error {c['error_s']:.1e} s, sensitivity "
            f"{c['sensitivity_s_per_relative_amplitude']:.1e} s per unit relative a_g -> "
            f"equivalent a_g error {c['equivalent_relative_amplitude_error']:.1e} "
            f"(theta_max/alpha = {c['max_rotation_over_alpha']:.2f})"
        )
    print(
        f"overturning: {disagree.size} disagreements, {near_boundary} of them within 1e-4 "
        f"of the boundary; {ref_over.mean():.0%} of scenes overturn"
    )
    print(f"wrote {OUT / 'engine.json'}")


if __name__ == "__main__":
    main()
