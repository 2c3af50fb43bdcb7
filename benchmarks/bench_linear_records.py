"""Linear record benchmark (issue 14 section 2): the exact solver of eq. (3.1) of [000] under
the shared real records.

The scenes of ``bench_records.py`` (per record, the four .AT2 files of shared/records and El
Centro: 200 random blocks, R 0.5-3 m, alpha 0.1-0.3, PGA 0.8-6 x g tan alpha), through
``simulate_batch(method="linear")`` on one thread, timed in CPU seconds of this process
(``time.process_time``, best of ``--repeat``: the machine is shared). Printed per record:
  - scenes/s/core of this checkout and of ``--old-rev`` (its source tree extracted by
    ``git archive`` and timed in a subprocess on the same scenes);
  - accuracy against solve_ivp DOP853 at rtol 1e-12 on eq. (3.1) with the same free-rocking
    map (``simulate_reference``) on ``--ref-scenes`` of them: max relative max-rotation error
    where neither overturns, max first-impact time error, overturning disagreements;
  - on the same scenes, the max relative difference from the nonlinear kernel's Taylor steps
    on the linearized equation at rtol 1e-12 (an independent integration: a zero vertical
    component routes the linear model to that kernel, the exact solver needing constant
    coefficients), a second oracle where solve_ivp's own error (~1e-10 over a long record
    with many impacts) is the larger.
Writes benchmarks/results/linear_records.json.

    python benchmarks/bench_linear_records.py [--ref-scenes 10] [--old-rev 85ac0e1]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import bench_records as br  # noqa: E402  (the scenes and the record loader)

OUT = HERE / "results"


def time_linear(repeat):
    """{record: {scenes_per_s, outputs}} of the importable rockstudy, one thread."""
    import numba

    from rockstudy.dynamics.batch import simulate_batch

    numba.set_num_threads(1)
    out = {}
    for i, name in enumerate(br.FILES):
        rec = br.load(name)
        R, alpha, scale = br.blocks(rec, 1000 + i)
        kw = dict(half_diagonal=R, slenderness=alpha, record=rec, scale=scale, method="linear")
        simulate_batch(
            **{**kw, "half_diagonal": R[:2], "slenderness": alpha[:2], "scale": scale[:2]}
        )
        best = np.inf
        for _ in range(repeat):
            t0 = time.process_time()
            res = simulate_batch(**kw)
            best = min(best, time.process_time() - t0)
        out[name] = {
            "scenes_per_s": br.N_BLOCKS / best,
            "max_rotation": res["max_rotation"].tolist(),
            "overturned": res["overturned"].tolist(),
            "first_impact_time": res["first_impact_time"].tolist(),
            "steps_max": int(res["steps"].max()),
        }
    return out


def old_linear(rev, repeat):
    """:func:`time_linear` of the source tree at ``rev`` (``bench_records.run_at_rev``)."""
    return br.run_at_rev(rev, "bench_linear_records", f"time_linear({repeat})")


def reference(name, rows):
    """solve_ivp DOP853 at rtol 1e-12 on eq. (3.1) with the free-rocking map, on ``rows``:
    (max rotation, overturned, first impact time)."""
    from rockstudy.constants import G
    from rockstudy.dynamics._rocking import MODEL_LINEAR
    from rockstudy.dynamics.reference import simulate_reference
    from rockstudy.structures.block import restitution_housner

    rec = br.load(name)
    R, alpha, scale = br.blocks(rec, 1000 + br.FILES.index(name))
    mx, ov, first = [], [], []
    for i in rows:
        p = np.sqrt(3.0 * G / (4.0 * R[i]))
        eta = restitution_housner(alpha[i])
        r = simulate_reference(
            p, alpha[i], eta, rec.scaled(scale[i]), MODEL_LINEAR, 1e-12, free_map=True
        )
        mx.append(r["max_rotation"])
        ov.append(r["overturned"])
        first.append(r["impact_times"][0] if r["impact_times"].size else np.nan)
    return np.array(mx), np.array(ov, bool), np.array(first)


def taylor_check(name, rows):
    """Max rotations of the Taylor-step kernel on eq. (3.1) at rtol 1e-12 on ``rows``."""
    import warnings

    import rockstudy as rs
    from rockstudy.motions import Record

    rec = br.load(name)
    R, alpha, scale = br.blocks(rec, 1000 + br.FILES.index(name))
    out = []
    for i in rows:
        motion = rec.scaled(scale[i])
        motion = Record(
            motion.acceleration, dt=motion.dt, vertical=np.zeros(motion.acceleration.size)
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the linearization's validity warning
            out.append(rs.simulate(rs.Block(R[i], alpha[i]), motion, method="linear", rtol=1e-12))
    return np.array([r.max_rotation for r in out]), np.array([r.overturned for r in out])


def accuracy(res, rows, ref):
    """Max relative max-rotation error (neither overturns), max first-impact error [s] and
    overturning disagreements of one solver's outputs on ``rows``."""
    ref_max, ref_over, ref_first = ref
    mx = np.asarray(res["max_rotation"])[rows]
    ov = np.asarray(res["overturned"], bool)[rows]
    first = np.asarray(res["first_impact_time"], float)[rows]
    both = ~ov & ~ref_over & (ref_max > 0.0)
    rel = np.abs(mx[both] / ref_max[both] - 1.0)
    has = ~np.isnan(ref_first)
    return {
        "max_rel_error": float(rel.max()) if rel.size else 0.0,
        "median_rel_error": float(np.median(rel)) if rel.size else 0.0,
        "first_impact_max_error_s": float(np.nanmax(np.abs(first[has] - ref_first[has])))
        if has.any()
        else 0.0,
        "disagreements": int(np.sum(ov != ref_over)),
        "compared": int(rows.size),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--ref-scenes", type=int, default=10, help="scenes per record vs rtol 1e-12")
    ap.add_argument("--old-rev", default="85ac0e1", help="git revision to compare with ('' none)")
    args = ap.parse_args()
    t_start = time.perf_counter()
    new = time_linear(args.repeat)
    old = old_linear(args.old_rev, args.repeat) if args.old_rev else {}
    rows = np.arange(min(args.ref_scenes, br.N_BLOCKS))
    print(f"exact linear solver, {br.N_BLOCKS} blocks per record, one core (CPU time)")
    print(
        f"{'record':32s} {'new /s':>8s} {'old /s':>8s} {'x old':>6s}  max rel err (new/old), "
        "first impact err [s], overturning disagreements, max rel diff from the Taylor kernel"
    )
    results = {}
    for name in br.FILES:
        ref = reference(name, rows)
        acc_new = accuracy(new[name], rows, ref)
        tay_max, tay_over = taylor_check(name, rows)
        mine = np.asarray(new[name]["max_rotation"])[rows]
        both = ~tay_over & ~np.asarray(new[name]["overturned"], bool)[rows] & (tay_max > 0.0)
        diff = np.abs(mine[both] / tay_max[both] - 1.0)
        acc_new["max_rel_diff_taylor"] = float(diff.max()) if diff.size else 0.0
        acc_new["taylor_disagreements"] = int(
            np.sum(tay_over != np.asarray(new[name]["overturned"], bool)[rows])
        )
        acc_old = accuracy(old[name], rows, ref) if old else None
        r_new = new[name]["scenes_per_s"]
        r_old = old[name]["scenes_per_s"] if old else float("nan")
        results[name] = {
            "new_scenes_per_s": r_new,
            "old_scenes_per_s": r_old,
            "speedup_vs_old": r_new / r_old,
            "steps_max": new[name]["steps_max"],
            "accuracy_new": acc_new,
            "accuracy_old": acc_old,
        }
        o = acc_old or {"max_rel_error": np.nan, "disagreements": -1}
        print(
            f"{name:32s} {r_new:8.0f} {r_old:8.0f} {r_new / r_old:6.1f}  "
            f"{acc_new['max_rel_error']:.1e}/{o['max_rel_error']:.1e}, "
            f"{acc_new['first_impact_max_error_s']:.1e}, "
            f"{acc_new['disagreements']} ({o['disagreements']}), "
            f"{acc_new['max_rel_diff_taylor']:.1e}",
            flush=True,
        )
    rates = np.array([r["new_scenes_per_s"] for r in results.values()])
    olds = np.array([r["old_scenes_per_s"] for r in results.values()])
    summary = {
        "min_new_scenes_per_s": float(rates.min()),
        "all_scenes_per_s": float(len(rates) / np.sum(1.0 / rates)),
        "geomean_speedup_vs_old": float(np.exp(np.mean(np.log(rates / olds)))),
        "max_rel_error": max(r["accuracy_new"]["max_rel_error"] for r in results.values()),
        "max_rel_diff_taylor": max(
            r["accuracy_new"]["max_rel_diff_taylor"] for r in results.values()
        ),
        "disagreements": sum(r["accuracy_new"]["disagreements"] for r in results.values()),
        "wall_s": time.perf_counter() - t_start,
    }
    print(
        f"min {summary['min_new_scenes_per_s']:.0f} scenes/s/core, "
        f"{summary['all_scenes_per_s']:.0f} over all five records, "
        f"x{summary['geomean_speedup_vs_old']:.1f} on {args.old_rev} (geometric mean), "
        f"max rel error {summary['max_rel_error']:.1e} "
        f"(from the Taylor-step kernel {summary['max_rel_diff_taylor']:.1e}), "
        f"disagreements {summary['disagreements']}, {summary['wall_s']:.0f} s"
    )
    br.write_results("linear_records.json", results, summary, rows.size, args.old_rev)


if __name__ == "__main__":
    main()
