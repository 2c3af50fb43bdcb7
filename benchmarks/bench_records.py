"""Record benchmark (issue 14 section 1): the nonlinear kernel on the shared real records.

Per record (the four .AT2 files of shared/records and El Centro), 200 random blocks
(R 0.5-3 m, alpha 0.1-0.3, PGA 0.8-6 x g tan alpha), one call of ``simulate_batch`` on one
thread, timed in CPU seconds of this process (``time.process_time``, best of ``--repeat``:
the machine is shared, and wall time measures the neighbours). Printed per record:
  - scenes/s/core of this checkout (Taylor step inside the record) and of the old kernel
    (DOP853 steps ending on every sample), the source tree of ``--old-rev`` extracted by
    ``git archive`` and timed in a subprocess on the same scenes;
  - the scipy path (``simulate_reference`` with the closed-form free-rocking map, the
    like-for-like algorithm) on ``--scipy-scenes`` of them, and the ratio;
  - accuracy against solve_ivp DOP853 at rtol 1e-12 on ``--ref-scenes`` of them: p99 and max
    of the relative max-rotation error where neither overturns, and overturning
    disagreements, each checked for robustness (the reference's decision at scale x (1 +-
    1e-4)), for this checkout and the old kernel.
Writes benchmarks/results/records.json.

    python benchmarks/bench_records.py [--rtol 1e-6] [--ref-scenes 20] [--old-rev a5019f7]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "results"
RECORDS = Path(os.environ.get("ROCKSTUDY_RECORDS") or ROOT.parent / "shared" / "records")
FILES = (
    "RSN126_GAZLI_GAZ000.AT2",
    "RSN183_IMPVALL.H_H-E08140.AT2",
    "RSN948_NORTHR_CAM009.AT2",
    "RSN982_NORTHR_JEN292.AT2",
    "elcentro_NS.dat",
)
N_BLOCKS = 200


def load(name):
    import rockstudy as rs

    path = RECORDS / name
    if name.endswith(".AT2"):
        return rs.motions.Record.from_at2(path)
    return rs.motions.Record.from_csv(path, units="g")


def blocks(record, seed):
    """R [m], alpha [rad], scale factor on the record: PGA 0.8-6 x g tan(alpha)."""
    from rockstudy.constants import G

    rng = np.random.default_rng(seed)
    R = rng.uniform(0.5, 3.0, N_BLOCKS)
    alpha = rng.uniform(0.1, 0.3, N_BLOCKS)
    pga = rng.uniform(0.8, 6.0, N_BLOCKS) * G * np.tan(alpha)
    return R, alpha, pga / record.peak


def time_kernel(rtol, repeat):
    """{record: (scenes/s/core, outputs)} of the importable rockstudy, one thread."""
    import numba

    from rockstudy.dynamics.batch import simulate_batch

    numba.set_num_threads(1)
    out = {}
    for i, name in enumerate(FILES):
        rec = load(name)
        R, alpha, scale = blocks(rec, 1000 + i)
        kw = dict(half_diagonal=R, slenderness=alpha, record=rec, scale=scale, rtol=rtol)
        simulate_batch(
            **{**kw, "half_diagonal": R[:2], "slenderness": alpha[:2], "scale": scale[:2]}
        )
        best = np.inf
        for _ in range(repeat):
            t0 = time.process_time()
            res = simulate_batch(**kw)
            best = min(best, time.process_time() - t0)
        out[name] = {
            "scenes_per_s": N_BLOCKS / best,
            "median_steps": float(np.median(res["steps"])),
            "max_rotation": res["max_rotation"].tolist(),
            "overturned": res["overturned"].tolist(),
            "status": int(res["status"].max()),
        }
    return out


def run_at_rev(rev, module, call):
    """``module.call`` (a call of a benchmark module, returning JSON data) evaluated in a
    subprocess on the source tree of ``rev``, extracted by ``git archive`` (with its own numba
    cache under the temp folder, kept between runs), on one thread."""
    src = Path(tempfile.gettempdir()) / f"rockstudy-bench-{rev}"
    if not (src / "rockstudy").is_dir():
        src.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(
            ["git", "archive", rev, "rockstudy"], cwd=ROOT, check=True, capture_output=True
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_NUM_THREADS="1")
    code = (
        f"import sys, json; sys.path.insert(0, {str(HERE)!r}); import {module} as b; "
        f"print(json.dumps(b.{call}))"
    )
    run = subprocess.run(
        [sys.executable, "-c", code], env=env, cwd=src, check=True, capture_output=True, text=True
    )
    return json.loads(run.stdout.strip().splitlines()[-1])


def old_kernel(rev, rtol, repeat):
    """:func:`time_kernel` of the source tree at ``rev`` (:func:`run_at_rev`)."""
    return run_at_rev(rev, "bench_records", f"time_kernel({rtol!r}, {repeat})")


def reference(name, rows, rtol, scale_factor=1.0, free_map=True):
    """solve_ivp DOP853 (with the free-rocking map) on ``rows``: (max rotation, overturned,
    CPU seconds)."""
    from rockstudy.constants import G
    from rockstudy.dynamics.reference import simulate_reference
    from rockstudy.structures.block import restitution_housner

    rec = load(name)
    R, alpha, scale = blocks(rec, 1000 + FILES.index(name))
    mx, ov = [], []
    t0 = time.process_time()
    for i in rows:
        p = np.sqrt(3.0 * G / (4.0 * R[i]))
        r = simulate_reference(
            p,
            alpha[i],
            restitution_housner(alpha[i]),
            rec.scaled(scale[i] * scale_factor),
            rtol=rtol,
            free_map=free_map,
        )
        mx.append(r["max_rotation"])
        ov.append(r["overturned"])
    return np.array(mx), np.array(ov, bool), time.process_time() - t0


def accuracy(name, res, rows, ref_max, ref_over):
    """p99 and max relative max-rotation error, and the overturning disagreements (all, and
    on robust scenes) of one kernel's outputs on ``rows``."""
    mx = np.asarray(res["max_rotation"])[rows]
    ov = np.asarray(res["overturned"], bool)[rows]
    both = ~ov & ~ref_over
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(mx[both] / ref_max[both] - 1.0)
    rel = np.where(ref_max[both] == mx[both], 0.0, rel)
    wrong = np.flatnonzero(ov != ref_over)
    robust = 0
    for j in wrong:  # a robust scene keeps the reference's decision at scale x (1 +- 1e-4)
        keeps = [
            reference(name, [rows[j]], 1e-12, f)[1][0] == ref_over[j] for f in (0.9999, 1.0001)
        ]
        robust += all(keeps)
    return {
        "p99_rel_error": float(np.percentile(rel, 99)) if rel.size else 0.0,
        "max_rel_error": float(rel.max()) if rel.size else 0.0,
        "disagreements": int(wrong.size),
        "robust_disagreements": int(robust),
        "compared": int(rows.size),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rtol", type=float, default=1e-6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ref-scenes", type=int, default=20, help="scenes per record vs rtol 1e-12")
    ap.add_argument("--scipy-scenes", type=int, default=5, help="scenes per record timed in scipy")
    ap.add_argument("--old-rev", default="a5019f7", help="git revision of the old kernel")
    args = ap.parse_args()
    t_start = time.perf_counter()
    new = time_kernel(args.rtol, args.repeat)
    old = old_kernel(args.old_rev, args.rtol, args.repeat) if args.old_rev else {}
    rows = np.arange(min(args.ref_scenes, N_BLOCKS))
    results = {}
    head = f"{'record':32s} {'new /s':>8s} {'old /s':>8s} {'x old':>6s}"
    head += f" {'scipy /s':>9s} {'x scipy':>8s}"
    print(f"rtol {args.rtol:g}, {N_BLOCKS} blocks per record, one core (CPU time)")
    print(head + "  p99 err (new/old), disagreements robust/all (new/old)")
    for name in FILES:
        ref_max, ref_over, _ = reference(name, rows, 1e-12)
        sc_rows = np.arange(min(args.scipy_scenes, N_BLOCKS))
        _, _, sc_time = reference(name, sc_rows, args.rtol)
        scipy_rate = sc_rows.size / sc_time
        acc_new = accuracy(name, new[name], rows, ref_max, ref_over)
        acc_old = accuracy(name, old[name], rows, ref_max, ref_over) if old else None
        r_new = new[name]["scenes_per_s"]
        r_old = old[name]["scenes_per_s"] if old else float("nan")
        results[name] = {
            "new_scenes_per_s": r_new,
            "old_scenes_per_s": r_old,
            "speedup_vs_old": r_new / r_old,
            "scipy_scenes_per_s": scipy_rate,
            "speedup_vs_scipy": r_new / scipy_rate,
            "median_steps_new": new[name]["median_steps"],
            "median_steps_old": old[name]["median_steps"] if old else None,
            "status_max": new[name]["status"],
            "accuracy_new": acc_new,
            "accuracy_old": acc_old,
        }
        o = acc_old or {"p99_rel_error": np.nan, "robust_disagreements": -1, "disagreements": -1}
        print(
            f"{name:32s} {r_new:8.0f} {r_old:8.0f} {r_new / r_old:6.1f} {scipy_rate:9.1f} "
            f"{r_new / scipy_rate:8.0f}  {acc_new['p99_rel_error']:.1e}/{o['p99_rel_error']:.1e}, "
            f"{acc_new['robust_disagreements']}/{acc_new['disagreements']} "
            f"({o['robust_disagreements']}/{o['disagreements']})",
            flush=True,
        )
    rates = np.array([r["new_scenes_per_s"] for r in results.values()])
    olds = np.array([r["old_scenes_per_s"] for r in results.values()])
    summary = {
        "min_new_scenes_per_s": float(rates.min()),
        "geomean_speedup_vs_old": float(np.exp(np.mean(np.log(rates / olds)))),
        "p99_rel_error_max": max(r["accuracy_new"]["p99_rel_error"] for r in results.values()),
        "robust_disagreements": sum(
            r["accuracy_new"]["robust_disagreements"] for r in results.values()
        ),
        "wall_s": time.perf_counter() - t_start,
    }
    print(
        f"min {summary['min_new_scenes_per_s']:.0f} scenes/s/core, "
        f"x{summary['geomean_speedup_vs_old']:.1f} "
        f"on the old kernel (geometric mean), p99 error <= {summary['p99_rel_error_max']:.1e}, "
        f"robust disagreements {summary['robust_disagreements']}, {summary['wall_s']:.0f} s"
    )
    write_results("records.json", results, summary, rows.size, args.old_rev, rtol=args.rtol)


def write_results(name, results, summary, ref_scenes, old_rev, **meta):
    """benchmarks/results/<name>: the per-record figures, the summary and how they were timed."""
    meta.update(
        blocks_per_record=N_BLOCKS,
        ref_scenes_per_record=int(ref_scenes),
        old_rev=old_rev,
        timing="CPU seconds of the process (time.process_time), best of repeats, 1 thread",
        machine=platform.processor() or platform.machine(),
        load_average=os.getloadavg(),
    )
    OUT.mkdir(exist_ok=True)
    (OUT / name).write_text(
        json.dumps({"meta": meta, "records": results, "summary": summary}, indent=2)
    )


if __name__ == "__main__":
    main()
