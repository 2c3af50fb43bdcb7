"""Solver agreement: the nonlinear kernel against the scipy reference on random record scenes.

Random scenes (seeded) on the shipped records (``data/records``, the horizontal components)
and, when found, the real records of ``../shared/records`` (or ``ROCKSTUDY_RECORDS``): a
block (R 0.3-6 m, log-uniform; alpha 0.08-0.35 rad) under one record scaled to PGA 1-4 x
g tan(alpha) (log-uniform), either sign. Each scene runs

  - the kernel (``simulate_batch``, the free rocking mapped) at ``--rtol``, with the
    ``conditioning`` output (:data:`rockstudy.dynamics.conditioning.CONDITIONING_STEP`: the
    relative change of max |theta| when the amplitude grows by 1e-9);
  - the scipy reference (``simulate_reference``, DOP853, the same free-rocking map) at
    ``--rtol``.

Printed: the scenes, the overturning decisions that differ, and per class of the
conditioning c (:func:`classes`: well conditioned c <= 1e-5, sensitive up to 1e-3,
ill-conditioned above) the share of the scenes and, over those where both stand, the
relative difference of max |theta| (median, max), the count above 10 rtol and the
difference over c. Scenes run in ``--jobs`` processes; ``--seconds`` bounds
the run (the scenes done by then are reported); ``--save`` writes the rows, and
``--summarize`` prints the table of several saved runs (other seeds) together.

    python benchmarks/bench_solver_agreement.py [--scenes 2000] [--rtol 1e-10] [--jobs 2]
    python benchmarks/bench_solver_agreement.py --summarize a.npy b.npy
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SHIPPED = ROOT / "data" / "records"
SHARED = Path(os.environ.get("ROCKSTUDY_RECORDS") or ROOT.parent / "shared" / "records")


def record_paths():
    """The records the scenes draw from: the shipped horizontal components and the shared
    records found."""
    paths = sorted(SHIPPED.glob("*_H.AT2"))
    if SHARED.is_dir():
        paths += sorted(SHARED.glob("*.AT2")) + sorted(SHARED.glob("*.dat"))
    return paths


def load(path):
    import rockstudy as rs

    if path.suffix == ".AT2":
        return rs.motions.Record.from_at2(path)
    return rs.motions.Record.from_csv(path, units="g")


def scenes(n, seed, n_records):
    """n rows of (record index, R [m], alpha [rad], PGA / (g tan alpha), sign)."""
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [
            rng.integers(0, n_records, n),
            np.exp(rng.uniform(math.log(0.3), math.log(6.0), n)),
            rng.uniform(0.08, 0.35, n),
            np.exp(rng.uniform(0.0, math.log(4.0), n)),
            rng.choice([-1.0, 1.0], n),
        ]
    )


def run_scene(path, R, alpha, ratio, sign, rtol):
    """(kernel max |theta|, overturned; reference's; conditioning; reference seconds)."""
    import rockstudy as rs
    from rockstudy.constants import G
    from rockstudy.dynamics.reference import simulate_reference

    rec = load(path)
    scale = sign * ratio * G * math.tan(alpha) / rec.peak
    b = rs.simulate_batch(
        half_diagonal=R,
        slenderness=alpha,
        record=rec,
        scale=scale,
        rtol=rtol,
        outputs=("max_rotation", "overturned", "conditioning"),
    )
    block = rs.Block(half_diagonal=R, slenderness=alpha)
    t0 = time.process_time()
    ref = simulate_reference(
        block.frequency_parameter,
        alpha,
        block.restitution,
        rec.scaled(scale),
        rtol=rtol,
        free_map=True,
    )
    return (
        float(b["max_rotation"][0]),
        bool(b["overturned"][0]),
        ref["max_rotation"],
        ref["overturned"],
        float(b["conditioning"][0]),
        time.process_time() - t0,
    )


#: Classes of the conditioning c (relative change of max |theta| under 1e-9 more amplitude):
#: well conditioned, where rounding amplified by c / 1e-9 stays below 10 rtol at rtol 1e-10;
#: sensitive; ill-conditioned (:mod:`rockstudy.dynamics.conditioning`).
def classes():
    """(name, low, high] of each class of the conditioning c."""
    from rockstudy.dynamics.conditioning import ILL_CONDITIONED as ILL
    from rockstudy.dynamics.conditioning import WELL_CONDITIONED as WELL

    return (
        (f"c <= {WELL:g}", 0.0, WELL),
        (f"{WELL:g} < c <= {ILL:g}", WELL, ILL),
        (f"c > {ILL:g}", ILL, np.inf),
    )


def summary(rows, rtol):
    """Print the counts, medians and shares of the agreement table, per conditioning class."""
    k, k_over, r, r_over, cond, secs = np.asarray(rows, dtype=float).T
    k_over, r_over = k_over > 0, r_over > 0
    n = len(k)
    stand = ~k_over & ~r_over & (r > 0)
    rel = np.abs(k - r) / np.where(r > 0, r, 1.0)
    print(f"scenes {n}; reference CPU median {np.median(secs):.2f} s a scene")
    print(
        f"rest (no uplift) in both: {int(np.sum((k == 0) & (r == 0)))}; "
        f"overturned in both: {int(np.sum(k_over & r_over))}; "
        f"overturning decisions that differ: {int(np.sum(k_over != r_over))}"
    )
    for name, lo, hi in classes():
        inside = (cond > lo) & (cond <= hi) if lo > 0 else cond <= hi
        m = inside & stand
        line = f"{name}: {int(inside.sum())} scenes ({np.mean(inside):.1%})"
        if m.any():
            e = rel[m]
            ratio = e / np.maximum(cond[m], 1e-300)
            line += (
                f"; {int(m.sum())} rock and stand: |kernel - reference| / reference median "
                f"{np.median(e):.1e}, max {e.max():.1e}, above 10 rtol {int(np.sum(e > 10 * rtol))}"
                f"; difference / c median {np.median(ratio):.1e}, max {ratio.max():.1e}"
            )
        decisions = int(np.sum(inside & (k_over != r_over)))
        print(line + f"; overturning decisions that differ {decisions}")
    print(f"conditioning c of the scenes that rock: median {np.median(cond[stand]):.1e}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=2000)
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--seed", type=int, default=34)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seconds", type=float, default=math.inf)
    ap.add_argument("--save", help="write the rows (.npy) here")
    ap.add_argument("--summarize", nargs="+", help="only summarize rows saved by --save runs")
    args = ap.parse_args(argv)
    if args.summarize:
        summary(np.concatenate([np.load(f) for f in args.summarize]), args.rtol)
        return 0
    paths = record_paths()
    print(f"records: {len(paths)} ({', '.join(p.stem for p in paths)})")
    table = scenes(args.scenes, args.seed, len(paths))
    start, rows = time.time(), []
    with ProcessPoolExecutor(args.jobs) as pool:
        futures = [
            pool.submit(run_scene, paths[int(i)], R, a, q, sg, args.rtol)
            for i, R, a, q, sg in table
        ]
        for f in as_completed(futures):
            rows.append(f.result())
            if time.time() - start > args.seconds:
                for g in futures:
                    g.cancel()
                break
    summary(rows, args.rtol)
    if args.save:
        np.save(args.save, np.array(rows, dtype=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
