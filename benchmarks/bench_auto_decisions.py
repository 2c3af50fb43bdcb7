"""Does ``method="auto"`` keep its promise (issue 11)? Overturning decisions and outputs on
dense (psi, omega) grids.

Grids: psi = |a_g| / (g tan alpha) in [1.01, 6] and omega = omega_g / p in [0.3, 12]
(geometric, N x N), alpha 0.05, 0.18 and 0.28 with Housner's restitution (2.4), one-cycle
sine, cosine and half-sine pulses. The reference is the nonlinear kernel at rtol 1e-10
(tested against scipy's solve_ivp at 1e-12 in tests/test_dynamics_reference.py). A decision
counts as wrong on a robust scene: one whose reference decision holds for a_g x (1 +- 1e-4).

For each rtol (1e-2, 1e-4, 1e-6) it runs auto twice:
- asking only for ``max_rotation`` and ``overturned`` (the linear model allowed where the
  table bounds it): wrong decisions (robust / all), share of the linear model, share of
  surviving scenes with max rotation within rtol;
- with the default outputs (all of them; no linear rows): the same, and the shares of
  ``overturn_time`` and ``first_impact_time`` within rtol (relative) of the reference.

    python benchmarks/bench_auto_decisions.py            # 400 x 400, about 8 min of one core
    python benchmarks/bench_auto_decisions.py --n 100    # a quick look

Writes benchmarks/results/auto_decisions.json.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

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


def main(n):
    results = []
    t0 = time.perf_counter()
    for shape in SHAPES:
        for alpha in ALPHAS:
            kw = grid_kwargs(shape, alpha, n)
            ref = simulate_batch(**kw, rtol=1e-10)
            for rtol in RTOLS:
                lean = simulate_batch(**kw, method="auto", rtol=rtol, outputs=COVERED)
                full = simulate_batch(**kw, method="auto", rtol=rtol)
                row = {"shape": shape, "alpha": alpha, "rtol": rtol}
                row["covered_only"] = decisions(kw, ref, lean, rtol)
                row["all_outputs"] = decisions(kw, ref, full, rtol)
                for name in ("overturn_time", "first_impact_time"):
                    row["all_outputs"][f"{name}_within_rtol"] = share_within(
                        full[name], ref[name], rtol
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
    path.write_text(json.dumps({"n": n, "results": results, "total": total}, indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400, help="grid points per axis")
    main(parser.parse_args().n)
