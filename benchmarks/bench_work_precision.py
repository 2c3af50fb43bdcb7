"""Work-precision benchmark (issue 6): error against CPU time for every rocking method.

One run evaluates a fixed set of scenes (slender and non-slender blocks; sine, cosine, half-sine
and Ricker pulses; the El Centro NS record scaled to several intensities) over a common window
(the motion plus 3 s), with every method:

  - the numba nonlinear kernel (``simulate``) at rtol 1e-4 ... 1e-10;
  - scipy's RK45, DOP853 and LSODA with events (the reference path) at rtol 1e-4 ... 1e-10;
  - a fixed-step semi-implicit Euler with an impact on the sign change of theta, the scheme users
    often write, at dt = 1e-2 ... 1e-5 s;
  - the linearized model (exact piecewise solver for pulses, the kernel on eq. 3.1 otherwise);
  - the complex formulation of [001] at l = 1e-2 ... 1e-5 (on a subset when l is small: its
    steps are below l / 10);
  - the closed form (4.13) of [000] with the mode classifier (3.10)-(3.31), on the sine pulses;
  - the equivalent block (kappa_1) against the full mechanism, eq. (8) of [003], for a wall, a
    frame and an arch (their own scenes; reference: the mechanism at rtol 1e-12);
  - ``method="auto"`` at tolerances 1e-1 ... 1e-6, through simulate() and the batch entry
    point, with the share of scenes within the tolerance and its cost against the cheapest
    method that was adequate for each scene.

The reference is solve_ivp DOP853 at rtol 1e-12 (over the window of the motion plus 3 s; for
the batch entry point, which maps the free rocking after the motion to its end, with that
map too: a block that overturns after the window is no disagreement). Error measures:
max-rotation relative error (scenes where neither overturns), first-impact-time error, and the
overturning disagreement rate. Prints a table and writes
benchmarks/results/work_precision.{json,png}.

    python benchmarks/bench_work_precision.py [--scenes 200] [--complex-subset 20]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
import warnings
from pathlib import Path

import matplotlib
import numba
import numpy as np
from numba import njit

import rockstudy as rs
from rockstudy.constants import FALL_ROTATION, G
from rockstudy.dynamics import simulate_batch
from rockstudy.dynamics.reference import simulate_reference
from rockstudy.structures.block import block_parameters
from rockstudy.verification.accuracy import relative_max_rotation_error

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

OUT = Path(__file__).parent / "results"
RECORD = Path(__file__).resolve().parents[2] / "shared" / "records" / "elcentro_NS.dat"
TOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
SCIPY_TOLS = (1e-4, 1e-6, 1e-8, 1e-10)
STEPS = (1e-2, 1e-3, 1e-4, 1e-5)
LS = (1e-2, 1e-3, 1e-4, 1e-5)
AUTO_TOLS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-6)
CANDIDATE_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)


def scene_set(n, seed=6):
    """(block, motion, t_end, batch spec) for n scenes; every fifth one runs the record."""
    rng = np.random.default_rng(seed)
    rec = rs.motions.Record.from_csv(RECORD, units="g")
    rec = rs.motions.Record(rec.acceleration[:601], dt=0.02, name="El Centro NS, first 12 s")
    makers = [
        (rs.motions.SinePulse, "sine"),
        (rs.motions.CosinePulse, "cosine"),
        (rs.motions.HalfSinePulse, "half-sine"),
        (rs.motions.RickerWavelet, "ricker"),
    ]
    scenes = []
    for i in range(n):
        alpha = rng.uniform(0.05, 0.25) if i % 2 == 0 else rng.uniform(0.3, 0.6)
        block = rs.Block(half_diagonal=rng.uniform(0.3, 3.0), slenderness=alpha)
        ratio = rng.uniform(1.05, 4.0)  # peak over the uplift level g tan(alpha)
        sign = rng.choice([-1.0, 1.0])
        if i % 5 == 4:
            factor = sign * ratio * G * math.tan(alpha) / rec.peak
            motion, spec = rec.scaled(factor), {"record": rec, "scale": factor}
        else:
            cls, name = makers[(i - i // 5) % 4]
            amp, period = sign * ratio * G * math.tan(alpha), rng.uniform(0.2, 1.5)
            motion, spec = cls(amp, period), {"pulse": name, "amplitude": amp, "period": period}
        scenes.append((block, motion, motion.duration + 3.0, spec))
    return scenes


def batch_kernel(scenes, rtol, method="nonlinear", subset=None):
    """The batch entry point on every scene (or ``subset``), one call per pulse shape and one
    for the record. Returns the per-scene outputs and the CPU time per scene."""
    groups = {}
    for i, (_, _, _, spec) in enumerate(scenes):
        if subset is None or i in subset:
            groups.setdefault(spec.get("pulse", "record"), []).append(i)
    out = [None] * len(scenes)
    cpu = 0.0
    for key, idx in groups.items():
        blocks = [scenes[i][0] for i in idx]
        specs = [scenes[i][3] for i in idx]
        kw = {
            "half_diagonal": np.array([b.half_diagonal for b in blocks]),
            "slenderness": np.array([b.slenderness for b in blocks]),
            "rtol": rtol,
            "method": method,
        }
        if key == "record":
            kw |= {"record": specs[0]["record"], "scale": np.array([s["scale"] for s in specs])}
        else:
            kw |= {
                "pulse": key,
                "amplitude": np.array([s["amplitude"] for s in specs]),
                "period": np.array([s["period"] for s in specs]),
            }
        simulate_batch(**{k: v[:1] if isinstance(v, np.ndarray) else v for k, v in kw.items()})
        t0 = time.process_time()
        r = simulate_batch(**kw)
        cpu += time.process_time() - t0
        for j, i in enumerate(idx):
            out[i] = (r["max_rotation"][j], r["overturned"][j], r["first_impact_time"][j])
    n = sum(len(idx) for idx in groups.values())
    return out, cpu / max(n, 1)


@njit(cache=True)
def _euler_scene(p, alpha, eta, acc, dt):
    """Semi-implicit Euler on eq. (2.2) of [000], uplift when |a_g| > g tan(alpha), an impact
    when theta changes sign (theta_dot *= eta), rest below 1e-4 p alpha after an impact.
    Returns (max |theta|, overturned, first impact time)."""
    th = 0.0
    om = 0.0
    s = 0.0
    rest = True
    thr = G * math.tan(alpha)
    max_u = 0.0
    first = math.nan
    for k in range(acc.size):
        a = acc[k] / G
        if rest:
            if abs(acc[k]) <= thr:
                continue
            rest = False
            s = -1.0 if a > 0.0 else 1.0
        x = alpha * s - th
        om += dt * (-p * p * (math.sin(x) + a * math.cos(x)))
        th_new = th + dt * om
        if th_new * s < 0.0:  # crossed theta = 0: impact
            om *= eta
            s = -s
            if math.isnan(first):
                first = (k + 1) * dt
            if abs(om) < 1e-4 * p * alpha:
                th, om, rest = 0.0, 0.0, True
                continue
        th = th_new
        max_u = max(max_u, abs(th))
        if max_u >= FALL_ROTATION:
            return FALL_ROTATION, True, first
    return max_u, False, first


def euler(block, motion, t_end, dt):
    p, alpha, eta = block_parameters(block)
    acc = np.asarray(motion.ground_acceleration(np.arange(0.0, t_end, dt)), dtype=float)
    return _euler_scene(p, alpha, eta, acc, dt)


def run_simulate(block, motion, t_end, **kw):
    r = rs.simulate(block, motion, t_max=t_end, **kw)
    first = r.impact_times[0] if r.n_impacts else math.nan
    return r.max_rotation, r.overturned, first


def run_scipy(block, motion, t_end, integrator, rtol, free_map=False):
    """solve_ivp over the window [0, t_end], or (``free_map``) with the free rocking after the
    motion mapped to its end, as the batch entry point does."""
    p, alpha, eta = block_parameters(block)
    t_max = None if free_map else t_end
    r = simulate_reference(
        p, alpha, eta, motion, rtol=rtol, integrator=integrator, t_max=t_max, free_map=free_map
    )
    imp = r["impact_times"]
    return r["max_rotation"], r["overturned"], imp[0] if imp.size else math.nan


def measure(name, family, fn, scenes, ref, idx=None):
    """Time ``fn`` over the scenes (or the subset ``idx``) and compare with the reference."""
    idx = np.arange(len(scenes)) if idx is None else np.asarray(idx)
    out, errors = [], []
    if isinstance(fn, tuple):  # precomputed (outputs, cpu per scene)
        out, cpu = fn
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rs.AccuracyWarning)
            fn(*scenes[idx[0]][:3])  # compile / warm up
            t0 = time.process_time()
            for i in idx:
                try:
                    out.append(fn(*scenes[i][:3]))
                except (ValueError, RuntimeError) as exc:  # e.g. scipy's event search fails
                    out.append((math.nan, False, math.nan))
                    errors.append(f"scene {i}: {type(exc).__name__}: {exc}")
        cpu = (time.process_time() - t0) / idx.size
    ok = np.array([math.isfinite(o[0]) for o in out])
    idx, out = idx[ok], [o for o, k in zip(out, ok, strict=True) if k]
    mx = np.array([o[0] for o in out])
    ov = np.array([bool(o[1]) for o in out])
    t1 = np.array([o[2] for o in out])
    r_mx, r_ov, r_t1 = ref[0][idx], ref[1][idx], ref[2][idx]
    both_rock = ~ov & ~r_ov & (r_mx > 0)
    rot = np.abs(mx[both_rock] - r_mx[both_rock]) / r_mx[both_rock]
    both_imp = np.isfinite(t1) & np.isfinite(r_t1)
    imp = np.abs(t1[both_imp] - r_t1[both_imp])
    missed = int(np.sum(np.isfinite(r_t1) != np.isfinite(t1)))

    def stats(e):
        if e.size == 0:
            return {"median": None, "p99": None, "max": None}
        return {k: float(f(e)) for k, f in (("median", np.median), ("max", np.max))} | {
            "p99": float(np.percentile(e, 99))
        }

    row = {
        "method": name,
        "family": family,
        "scenes": int(idx.size),
        "cpu_s_per_scene": cpu,
        "max_rotation_rel_error": stats(rot),
        "first_impact_error_s": stats(imp),
        "first_impact_missed_or_spurious": missed,
        "overturn_disagreement_rate": float(np.mean(ov != r_ov)),
        "failed_runs": len(errors),
        "failures": errors[:5],
    }
    r, i = row["max_rotation_rel_error"], row["first_impact_error_s"]
    print(
        f"{name:24s} {idx.size:5d} {cpu * 1e3:10.3f} {r['p99'] or math.nan:12.2e} "
        f"{i['p99'] or math.nan:12.2e} {missed:6d} "
        f"{row['overturn_disagreement_rate']:8.3f} {len(errors):5d}",
        flush=True,
    )
    return row


def closed_form(scenes):
    """(4.13) with the mode classifier on the sine-pulse scenes: (outputs, cpu per scene, idx).
    The closed forms are those of the linearized block: a = a_g / (g alpha)."""
    idx = [i for i, sc in enumerate(scenes) if sc[3].get("pulse") == "sine"]
    pars = np.array([block_parameters(scenes[i][0]) for i in idx])
    p, alpha, eta = pars.T
    amp = np.array([abs(scenes[i][3]["amplitude"]) for i in idx])
    a = amp / (G * alpha)
    w = 2 * np.pi / (np.array([scenes[i][3]["period"] for i in idx]) * p)
    rs.closedform.max_rotation(a[:1], w[:1], eta[:1], check=False)
    t0 = time.process_time()
    reps = 200
    for _ in range(reps):
        mode = rs.closedform.overturning_mode_code(a, w, eta)
        th = rs.closedform.max_rotation(a, w, eta, check=False) * alpha
    cpu = (time.process_time() - t0) / reps / len(idx)
    over = (mode == rs.closedform.sine.OVER_IMPACT) | (mode == rs.closedform.sine.OVER_NO_IMPACT)
    over |= (a > 1) & ~np.isfinite(th)
    th = np.where(a > 1, th, 0.0)
    out = [
        (FALL_ROTATION if o else float(t), bool(o), math.nan) for o, t in zip(over, th, strict=True)
    ]
    return (out, cpu), idx


def structure_rows(seed=3, n=40):
    """The equivalent block (kappa_1) and the full mechanism at several tolerances, against
    the mechanism at rtol 1e-12, for a wall, a frame and an arch."""
    rows = []
    structures = (
        ("wall", rs.structures.RockingWall(1.0, 0.1, restitution=0.85)),
        ("frame", rs.structures.SymmetricFrame(1.0, 0.15, 0.5)),
        ("arch", rs.structures.Arch(math.pi, 0.75, 5.0, restitution=0.9)),
    )
    for name, st in structures:
        rng = np.random.default_rng(seed)
        rp = st.rocking_parameters()
        eq = st.equivalent_block()
        scenes = []
        for i in range(n):
            cls = (rs.motions.SinePulse, rs.motions.CosinePulse, rs.motions.HalfSinePulse)[i % 3]
            amp = rng.choice([-1, 1]) * rng.uniform(1.05, 4.0) * G * rp.uplift
            m = cls(amp, rng.uniform(0.2, 2.0))
            scenes.append((st, m, m.duration + 3.0, {}))

        def mech(s, m, t, r=1e-12):
            res = rs.simulate(s, m, t_max=t, rtol=r)
            return res.max_rotation, res.overturned, math.nan

        def block(s, m, t, e=eq):
            res = rs.simulate(e, m, t_max=t, rtol=1e-8)
            return e.scale * res.max_rotation, res.overturned, math.nan

        ref_rows = [mech(*sc[:3]) for sc in scenes]
        ref = (
            np.array([r[0] for r in ref_rows]),
            np.array([r[1] for r in ref_rows]),
            np.full(n, math.nan),
        )
        for rtol in (1e-4, 1e-6, 1e-8):
            rows.append(
                measure(
                    f"{name} mechanism {rtol:.0e}",
                    f"{name}: full mechanism (8) [003]",
                    lambda s, m, t, r=rtol: mech(s, m, t, r),
                    scenes,
                    ref,
                )
            )
        rows.append(
            measure(
                f"{name} equivalent block",
                f"{name}: equivalent block (kappa_1)",
                block,
                scenes,
                ref,
            )
        )
    return rows


def _time_each(fn, scenes, repeat=3):
    """Outputs and the least of ``repeat`` wall times [s] of fn on each scene."""
    outs, cost = [], []
    for b, m, t, _ in scenes:
        best = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            out = fn(b, m, t)
            best = min(best, time.perf_counter() - t0)
        outs.append(out)
        cost.append(best)
    return outs, np.array(cost)


def _rel_errors(outs, ref):
    """Per-scene relative max-rotation error (inf on an overturning disagreement)."""
    got = {
        "max_rotation": np.array([o[0] for o in outs]),
        "overturned": np.array([bool(o[1]) for o in outs]),
    }
    return relative_max_rotation_error(got, {"max_rotation": ref[0], "overturned": ref[1]})


def auto_analysis(scenes, ref, ref_mapped):
    """method="auto" per tolerance: share of scenes within it, and its cost against the
    cheapest adequate candidate (linear, or the kernel at rtol 1e-3 ... 1e-10) of each scene,
    through simulate() (per scene, against ``ref``) and through the batch entry point (the whole
    set, against ``ref_mapped``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rs.AccuracyWarning)
        cands = {"linear": lambda b, m, t: run_simulate(b, m, t, method="linear")}
        for r in CANDIDATE_RTOLS:
            cands[f"kernel {r:.0e}"] = lambda b, m, t, r=r: run_simulate(b, m, t, rtol=r)
        for fn in cands.values():
            fn(*scenes[0][:3])
        timed = {k: _time_each(fn, scenes) for k, fn in cands.items()}
        errs = {k: _rel_errors(o, ref) for k, (o, _) in timed.items()}
        rows = []
        for tol in AUTO_TOLS:
            fn = lambda b, m, t, r=tol: run_simulate(b, m, t, method="auto", rtol=r)  # noqa: E731
            fn(*scenes[0][:3])
            outs, cost = _time_each(fn, scenes)
            err = _rel_errors(outs, ref)
            cheapest = np.full(len(scenes), np.inf)
            choice = np.full(len(scenes), "", dtype=object)
            for k in cands:
                ok = (errs[k] <= tol) & (timed[k][1] < cheapest)
                cheapest[ok], choice[ok] = timed[k][1][ok], k
            has = np.isfinite(cheapest)
            ratio = cost[has] / cheapest[has]
            b_out, b_cpu = batch_kernel(scenes, tol, method="auto")
            b_err = _rel_errors(b_out, ref_mapped)
            oracle_cpu = 0.0  # the per-scene cheapest adequate candidates, run in batches
            for k in set(choice[has]):
                sub = set(np.flatnonzero(choice == k))
                method, r = ("linear", 1e-8) if k == "linear" else ("nonlinear", float(k[7:]))
                oracle_cpu += batch_kernel(scenes, r, method=method, subset=sub)[1] * len(sub)
            rows.append(
                {
                    "tolerance": tol,
                    "within_tolerance_simulate": float(np.mean(err <= tol)),
                    "within_tolerance_batch": float(np.mean(b_err <= tol)),
                    "scenes_with_an_adequate_candidate": int(has.sum()),
                    "cost_ratio_simulate_total": float(cost[has].sum() / cheapest[has].sum()),
                    "cost_ratio_simulate_median": float(np.median(ratio)),
                    "cost_ratio_simulate_p90": float(np.percentile(ratio, 90)),
                    "share_within_2x_simulate": float(np.mean(ratio <= 2.0)),
                    "cpu_s_per_scene_simulate": float(cost.mean()),
                    "cpu_s_per_scene_batch": b_cpu,
                    "cost_ratio_batch_total": b_cpu * len(scenes) / oracle_cpu,
                    "cheapest_choices": {k: int(np.sum(choice == k)) for k in cands},
                    "max_rotation_rel_error_p99_simulate": float(np.percentile(err, 99)),
                }
            )
            r = rows[-1]
            print(
                f"auto tol={tol:.0e}: within tol {r['within_tolerance_simulate']:.3f} (simulate) "
                f"{r['within_tolerance_batch']:.3f} (batch); cost / cheapest adequate: total "
                f"{r['cost_ratio_simulate_total']:.2f}, "
                f"median {r['cost_ratio_simulate_median']:.2f}, "
                f"p90 {r['cost_ratio_simulate_p90']:.2f} (simulate), batch total "
                f"{r['cost_ratio_batch_total']:.2f}",
                flush=True,
            )
    return rows


def plot(rows, path):
    fig, axes = plt.subplots(1, 3, figsize=(17, 6.4))
    keys = [
        ("max_rotation_rel_error", "max-rotation relative error (p99)"),
        ("first_impact_error_s", "first-impact-time error [s] (p99)"),
    ]
    families = sorted({r["family"] for r in rows}, key=[r["family"] for r in rows].index)
    colors = plt.get_cmap("tab20").colors
    style = {
        fam: (colors[k % 20], "osD^v<>ph*"[k % 10], "-" if "equivalent" not in fam else "none")
        for k, fam in enumerate(families)
    }
    for ax, (key, title) in zip(axes[:2], keys, strict=True):
        for fam in families:
            sel = [r for r in rows if r["family"] == fam and r[key]["p99"] is not None]
            if sel:
                c, m, ls = style[fam]
                x = [r["cpu_s_per_scene"] for r in sel]
                y = [max(r[key]["p99"], 1e-16) for r in sel]
                ax.loglog(x, y, marker=m, ls=ls, color=c, label=fam)
        ax.set_xlabel("CPU time per scene [s]")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    for fam in families:
        sel = [r for r in rows if r["family"] == fam]
        c, m, ls = style[fam]
        x = [r["cpu_s_per_scene"] for r in sel]
        y = [100 * r["overturn_disagreement_rate"] for r in sel]
        axes[2].semilogx(x, y, marker=m, ls=ls, color=c, label=fam)
    axes[2].set_xlabel("CPU time per scene [s]")
    axes[2].set_title("overturning disagreement [%]")
    axes[2].grid(True, which="both", alpha=0.3)
    handles, labels = axes[2].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=8)
    fig.suptitle(
        "rockstudy work-precision: error vs CPU time (reference: DOP853 rtol 1e-12; "
        "structures: their mechanism at rtol 1e-12; equivalent blocks: one point each)"
    )
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    fig.savefig(path, dpi=120)


def reference(scenes, free_map=False):
    """(max rotation, overturned, first impact time) of solve_ivp DOP853 at rtol 1e-12 on every
    scene (:func:`run_scipy`)."""
    rows = [run_scipy(b, m, t, "DOP853", 1e-12, free_map) for b, m, t, _ in scenes]
    return (
        np.array([r[0] for r in rows]),
        np.array([bool(r[1]) for r in rows]),
        np.array([r[2] for r in rows]),
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=200)
    ap.add_argument(
        "--complex-subset", type=int, default=20, help="scenes for the complex form at l <= 1e-4"
    )
    ap.add_argument("--no-complex", action="store_true", help="skip the complex formulation")
    ap.add_argument("--plot-only", action="store_true", help="redraw the PNG from the JSON")
    args = ap.parse_args()
    if args.plot_only:
        plot(
            json.loads((OUT / "work_precision.json").read_text())["rows"],
            OUT / "work_precision.png",
        )
        return
    numba.set_num_threads(1)
    scenes = scene_set(args.scenes)
    print(f"reference: {len(scenes)} scenes, DOP853 rtol 1e-12 ...", flush=True)
    ref = reference(scenes)
    # the batch entry point maps the free rocking to its end (no window): so does its
    # reference for the max rotation and the overturning (the map gives no impact times)
    ref_mapped = reference(scenes, free_map=True)[:2] + ref[2:]
    print(f"{np.mean(ref[1]):.0%} of the scenes overturn; {np.mean(ref[0] == 0):.0%} stay at rest")
    print(
        f"{'method':24s} {'n':>5s} {'ms/scene':>10s} {'rot p99':>12s} {'t1 p99 [s]':>12s} "
        f"{'miss':>6s} {'overt.':>8s} {'fail':>5s}"
    )
    rows = []
    for rtol in TOLS:
        rows.append(
            measure(
                f"kernel rtol={rtol:.0e}",
                "nonlinear kernel, simulate()",
                lambda b, m, t, r=rtol: run_simulate(b, m, t, rtol=r),
                scenes,
                ref,
            )
        )
    for rtol in TOLS:
        rows.append(
            measure(
                f"batch rtol={rtol:.0e}",
                "nonlinear kernel, batch",
                batch_kernel(scenes, rtol),
                scenes,
                ref_mapped,
            )
        )
    for integrator in ("RK45", "DOP853", "LSODA"):
        for rtol in SCIPY_TOLS:
            rows.append(
                measure(
                    f"scipy {integrator} {rtol:.0e}",
                    f"scipy {integrator}",
                    lambda b, m, t, i=integrator, r=rtol: run_scipy(b, m, t, i, r),
                    scenes,
                    ref,
                )
            )
    for dt in STEPS:
        rows.append(
            measure(
                f"Euler dt={dt:.0e}",
                "semi-implicit Euler",
                lambda b, m, t, h=dt: euler(b, m, t, h),
                scenes,
                ref,
            )
        )
    rows.append(
        measure(
            "linear",
            "linearized (3.1)",
            lambda b, m, t: run_simulate(b, m, t, method="linear"),
            scenes,
            ref,
        )
    )
    rng = np.random.default_rng(1)
    subset = np.sort(rng.choice(len(scenes), min(args.complex_subset, len(scenes)), False))
    for ell in () if args.no_complex else LS:
        rows.append(
            measure(
                f"complex l={ell:.0e}",
                "complex [001]",
                lambda b, m, t, e=ell: run_simulate(b, m, t, method="complex", l=e),
                scenes,
                ref,
                idx=None if ell > 1e-4 else subset[: args.complex_subset if ell > 1e-5 else 3],
            )
        )
    cf_out, cf_idx = closed_form(scenes)
    rows.append(
        measure("closed form (4.13)", "closed form (4.13), sine", cf_out, scenes, ref, cf_idx)
    )
    rows.extend(structure_rows())
    for tol in AUTO_TOLS:
        rows.append(
            measure(
                f"auto batch tol={tol:.0e}",
                "auto, batch",
                batch_kernel(scenes, tol, method="auto"),
                scenes,
                ref_mapped,
            )
        )
    auto = auto_analysis(scenes, ref, ref_mapped)
    OUT.mkdir(exist_ok=True)
    doc = {
        "machine": platform.processor() or platform.machine(),
        "scenes": len(scenes),
        "window": "motion duration + 3 s",
        "reference": "solve_ivp DOP853 rtol 1e-12 with events",
        "rows": rows,
        "auto": auto,
    }
    (OUT / "work_precision.json").write_text(json.dumps(doc, indent=2))
    plot(rows, OUT / "work_precision.png")
    print(f"wrote {OUT / 'work_precision.json'} and work_precision.png")


if __name__ == "__main__":
    main()
