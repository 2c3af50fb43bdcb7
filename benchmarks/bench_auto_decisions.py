"""Does ``method="auto"`` keep its promise (issue 11)? Overturning decisions and outputs on
dense (psi, omega) grids.

Grids: psi = |a_g| / (g tan alpha) in [1.01, 6] and omega = omega_g / p in [0.3, 12]
(geometric, N x N), alpha 0.05, 0.18 and 0.28 with Housner's restitution (2.4), one-cycle
sine, cosine and half-sine pulses. The reference is the nonlinear kernel at rtol 1e-10
(tested against scipy's solve_ivp at 1e-12 in tests/test_dynamics_reference.py). A decision
counts as wrong on a robust scene: one whose reference decision holds for a_g x (1 +- 1e-4).

For each rtol (1e-2, 1e-4, 1e-6) it runs auto twice:
- on the N x N grid, asking only for ``max_rotation`` and ``overturned`` (the linear model
  allowed where the table bounds it): wrong decisions (robust / all), share of the linear
  model, share of surviving scenes with max rotation within rtol;
- on an M x M grid, with the default outputs (all of them; no linear rows): the same, and
  the shares of ``overturn_time`` and ``first_impact_time`` within rtol (relative) of the
  reference.

    python benchmarks/bench_auto_decisions.py                  # N 400, M 100: ~6 min, one core
    python benchmarks/bench_auto_decisions.py --n 100 --m 50   # a quick look

With ``--work-precision`` it measures auto on the scenes of bench_work_precision.py instead
(its 200 scenes: sine, cosine, half-sine, Ricker and a record; the reference is solve_ivp's
DOP853 at rtol 1e-12): the share of scenes within each tolerance (max rotation and
overturning decision), through simulate() and the batch entry point (all outputs, and the
covered ones only), and the share of first impact times within the tolerance.

Writes benchmarks/results/auto_decisions.json (or auto_work_precision.json).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from rockstudy import AccuracyWarning
from rockstudy.constants import G
from rockstudy.dynamics import _auto, simulate_batch
from rockstudy.verification.accuracy import (
    GRID_FREQUENCY,
    relative_max_rotation_error,
    robust_decision,
)

OUT = Path(__file__).parent / "results"
SHAPES = ("sine", "cosine", "half-sine")
ALPHAS = (0.05, 0.18, 0.28)
RTOLS = (1e-2, 1e-4, 1e-6)
COVERED = ("max_rotation", "overturned", "model")


def grid_kwargs(shape, alpha, n):
    """simulate_batch arguments of the N x N (psi, omega) grid."""
    P, W = np.meshgrid(np.geomspace(1.01, 6.0, n), np.geomspace(0.3, 12.0, n), indexing="ij")
    return dict(
        frequency_parameter=GRID_FREQUENCY,
        slenderness=alpha,
        pulse=shape,
        amplitude=(P * G * np.tan(alpha)).ravel(),
        period=(2.0 * np.pi / (W * GRID_FREQUENCY)).ravel(),
    )


def share_within(got, ref, tol):
    """Share of the rows with a finite reference where |got / ref - 1| <= tol."""
    ok = np.isfinite(ref) & (ref > 0)
    if not ok.any():
        return None
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.abs(got[ok] / ref[ok] - 1.0)
    return float(np.mean(rel <= tol))


def decisions(kw, ref, out, rtol):
    """Wrong decisions (robust and all), by model, and the max-rotation share within rtol."""
    wrong = np.flatnonzero(out["overturned"] != ref["overturned"])
    robust = robust_decision(kw, wrong, ref["overturned"][wrong])
    err = relative_max_rotation_error(out, ref)
    alive = ~ref["overturned"]
    return {
        "wrong_robust": int(robust.sum()),
        "wrong_all": int(wrong.size),
        "wrong_robust_linear": int(np.sum(out["model"][wrong[robust]] == _auto.MODEL_LINEAR)),
        "linear_share": float(np.mean(out["model"] == _auto.MODEL_LINEAR)),
        "max_rotation_within_rtol": float(np.mean(err[alive] <= rtol)),
    }


def main(n, m):
    results = []
    t0 = time.perf_counter()
    for shape in SHAPES:
        for alpha in ALPHAS:
            kw, kw_m = grid_kwargs(shape, alpha, n), grid_kwargs(shape, alpha, m)
            ref = simulate_batch(**kw, rtol=1e-10)
            ref_m = simulate_batch(**kw_m, rtol=1e-10)
            for rtol in RTOLS:
                lean = simulate_batch(**kw, method="auto", rtol=rtol, outputs=COVERED)
                full = simulate_batch(**kw_m, method="auto", rtol=rtol)
                row = {"shape": shape, "alpha": alpha, "rtol": rtol}
                row["covered_only"] = decisions(kw, ref, lean, rtol)
                row["all_outputs"] = decisions(kw_m, ref_m, full, rtol)
                for name in ("overturn_time", "first_impact_time"):
                    row["all_outputs"][f"{name}_within_rtol"] = share_within(
                        full[name], ref_m[name], rtol
                    )
                results.append(row)
                a, b = row["covered_only"], row["all_outputs"]
                print(
                    f"{shape:9s} alpha {alpha:.2f} rtol {rtol:.0e}: wrong robust "
                    f"{a['wrong_robust']} (all {a['wrong_all']}, linear "
                    f"{a['linear_share']:.1%}) | all outputs: wrong robust {b['wrong_robust']}"
                    f", t_ot {b['overturn_time_within_rtol']:.3f}, t_imp1 "
                    f"{b['first_impact_time_within_rtol']:.3f} within rtol "
                    f"[{time.perf_counter() - t0:.0f} s]",
                    flush=True,
                )
    total = {
        key: sum(r[key]["wrong_robust"] for r in results) for key in ("covered_only", "all_outputs")
    }
    print(f"robust wrong decisions over all grids: {total}")
    OUT.mkdir(exist_ok=True)
    path = OUT / "auto_decisions.json"
    path.write_text(json.dumps({"n": n, "m": m, "results": results, "total": total}, indent=1))
    print(f"wrote {path}")


def work_precision(n_scenes, record):
    """auto on the work-precision scenes: shares within tolerance (see the module doc)."""
    sys.path.insert(0, str(Path(__file__).parent))
    import bench_work_precision as wp

    wp.RECORD = Path(record) if record else wp.RECORD
    scenes = wp.scene_set(n_scenes)
    t0 = time.perf_counter()
    ref = [wp.run_scipy(b, m, t, "DOP853", 1e-12) for b, m, t, _ in scenes]
    ref_rot = {
        "max_rotation": np.array([r[0] for r in ref]),
        "overturned": np.array([r[1] for r in ref]),
    }
    ref_t1 = np.array([r[2] for r in ref])
    print(f"reference: {len(scenes)} scenes in {time.perf_counter() - t0:.0f} s", flush=True)

    def shares(outs, tol):
        got = {
            "max_rotation": np.array([o[0] for o in outs]),
            "overturned": np.array([o[1] for o in outs]),
        }
        err = relative_max_rotation_error(got, ref_rot)
        t1 = np.array([o[2] for o in outs])
        has = np.isfinite(ref_t1)
        return float(np.mean(err <= tol)), share_within(t1[has], ref_t1[has], tol)

    rows = []
    for tol in (1e-1, 1e-2, 1e-3, 1e-4, 1e-6):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", AccuracyWarning)
            sim = [wp.run_simulate(b, m, t, method="auto", rtol=tol) for b, m, t, _ in scenes]
        batch, _ = wp.batch_kernel(scenes, tol, method="auto")
        row = {"tolerance": tol}
        row["simulate"], row["simulate_first_impact"] = shares(sim, tol)
        row["batch"], row["batch_first_impact"] = shares(batch, tol)
        rows.append(row)
        print(
            f"auto tol {tol:.0e}: max rotation + decision within tol: simulate "
            f"{row['simulate']:.3f}, batch {row['batch']:.3f}; first impact within tol: "
            f"simulate {row['simulate_first_impact']:.3f}, batch {row['batch_first_impact']:.3f}",
            flush=True,
        )
    OUT.mkdir(exist_ok=True)
    path = OUT / "auto_work_precision.json"
    path.write_text(json.dumps({"scenes": len(scenes), "rows": rows}, indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400, help="grid points per axis (decisions)")
    parser.add_argument("--m", type=int, default=100, help="grid points per axis (all outputs)")
    parser.add_argument(
        "--work-precision", action="store_true", help="the scenes of bench_work_precision.py"
    )
    parser.add_argument("--scenes", type=int, default=200, help="work-precision scenes")
    parser.add_argument("--record", help="elcentro_NS.dat (default: bench_work_precision's)")
    args = parser.parse_args()
    if args.work_precision:
        work_precision(args.scenes, args.record)
    else:
        main(args.n, args.m)
