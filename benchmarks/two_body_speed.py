"""Speed of the two-stacked-blocks kernel against the single-block kernel on the same records,
and the time of an IDA-like load of stacked objects.

Records: the five real ones of shared/records (``ROCKSTUDY_RECORDS`` to move it) and the eight
synthetic near-fault records shipped with rockstudy (horizontal components only), whole (a
``--seconds`` window from 2 s before the peak: :func:`contact_accuracy.records`).

1. Ratio. Per record ``--objects`` random assemblies (plinth R 0.6-2 m, alpha 0.15-0.35;
   statue alpha 0.12-0.3 on the plinth's top; density ratio 0.3-3), the record scaled to a
   peak of 0.8-3 times g tan(alpha_min) of each assembly. The stacked rows run through
   ``simulate_batch(structure=...)`` (the numba kernel, rows in parallel), the single-block
   rows through ``simulate_batch(half_diagonal=, slenderness=)`` with the plinth's columns and
   the same scales (and, for comparison, with the statue's columns), all at ``--rtol``,
   timed in wall seconds (median of ``--repeat`` after a warm call; the machine is shared),
   or with ``--one-thread`` on one numba thread in process seconds (the steadiest measure
   on a loaded machine). Printed: scenes/s of each over all records and the ratios, all in
   this one run.
2. IDA. ``--ida-records`` records x 6 stacked objects x ``--rungs`` scale rungs (the peak
   from 0.5 to 5 g tan(alpha_min) of each object), one ``simulate_batch(structure=...)`` call
   per record; printed: the total wall seconds (and the overturning fraction).

    python benchmarks/two_body_speed.py [--objects 40] [--rtol 1e-8] [--repeat 3] [--rungs 15]
        [--one-thread]
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np
from bench_closedform import median_time
from contact_accuracy import record_counts, records

from rockstudy.constants import G
from rockstudy.dynamics.batch import simulate_batch
from rockstudy.motions.records import Record
from rockstudy.structures import Block, StackedBlocks


def assemblies(rng, n):
    """n random (StackedBlocks, g tan(alpha_min)) of the ranges above."""
    out = []
    for _ in range(n):
        a1, r1, a2 = rng.uniform(0.15, 0.35), rng.uniform(0.6, 2.0), rng.uniform(0.12, 0.3)
        b1 = r1 * np.sin(a1)
        r2 = min(rng.uniform(0.3, 1.2), 0.9 * b1 / np.sin(a2))
        pair = StackedBlocks(Block(r1, a1), Block(r2, a2), rng.uniform(0.3, 3.0))
        out.append((pair, G * np.tan(min(a1, a2))))
    return out


def ratio(recs, n, rtol, repeat, rng, clock=time.perf_counter):
    """(stacked scenes/s, single-block scenes/s with the plinth's columns, with the
    statue's) over the records, timed on ``clock``."""
    t_stacked = t_single = t_statue = 0.0
    scenes = 0
    for _name, t, a_h, _ in recs:
        rec = Record(a_h, time=t)
        objs = assemblies(rng, n)
        pairs = [p for p, _ in objs]
        peak = np.abs(a_h).max()
        scale = np.array([g * rng.uniform(0.8, 3.0) / peak for _, g in objs])
        r1 = np.array([p.lower.half_diagonal for p in pairs])
        a1 = np.array([p.lower.slenderness for p in pairs])
        t_stacked += median_time(
            lambda rec=rec, pairs=pairs, scale=scale: simulate_batch(
                structure=pairs, record=rec, scale=scale, rtol=rtol
            ),
            repeat,
            clock,
        )
        t_single += median_time(
            lambda rec=rec, r1=r1, a1=a1, scale=scale: simulate_batch(
                half_diagonal=r1, slenderness=a1, record=rec, scale=scale, rtol=rtol
            ),
            repeat,
            clock,
        )
        r2 = np.array([p.upper.half_diagonal for p in pairs])
        a2 = np.array([p.upper.slenderness for p in pairs])
        t_statue += median_time(
            lambda rec=rec, r2=r2, a2=a2, scale=scale: simulate_batch(
                half_diagonal=r2, slenderness=a2, record=rec, scale=scale, rtol=rtol
            ),
            repeat,
            clock,
        )
        scenes += n
    return scenes / t_stacked, scenes / t_single, scenes / t_statue


def ida(recs, rungs, rtol, rng):
    """(wall seconds, overturned fraction) of records x 6 objects x rungs."""
    objs = assemblies(rng, 6)
    t0, fell, rows = time.perf_counter(), 0, 0
    for _name, t, a_h, _ in recs:
        rec, peak = Record(a_h, time=t), np.abs(a_h).max()
        pairs = [p for p, _ in objs for _ in range(rungs)]
        scale = np.concatenate([np.linspace(0.5, 5.0, rungs) * g / peak for _, g in objs])
        out = simulate_batch(structure=pairs, record=rec, scale=scale, rtol=rtol)
        fell += int(out["overturned"].sum())
        rows += len(pairs)
    return time.perf_counter() - t0, fell / rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--objects", type=int, default=40)
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rungs", type=int, default=15)
    ap.add_argument("--ida-records", type=int, default=8)
    ap.add_argument("--seconds", type=float, default=1e9)
    ap.add_argument("--one-thread", action="store_true")
    args = ap.parse_args(argv)
    recs = records(args.seconds)
    rng = np.random.default_rng(2026)
    clock = time.perf_counter
    if args.one_thread:
        numba.set_num_threads(1)
        clock = time.process_time
    stacked, single, statue = ratio(recs, args.objects, args.rtol, args.repeat, rng, clock)
    where = "one thread, process time" if args.one_thread else "wall time"
    counts = record_counts(r[0] for r in recs)
    print(f"{counts} x {args.objects} objects at rtol {args.rtol:g} ({where})")
    print(f"stacked kernel: {stacked:9.1f} scenes/s")
    print(f"single block  : {single:9.1f} scenes/s")
    print(f"ratio stacked / single: {stacked / single:.1%}")
    print(f"(single block with the statue's columns: {statue:9.1f} scenes/s, ratio ", end="")
    print(f"{stacked / statue:.1%})")
    if args.ida_records < 1:
        return
    seconds, fell = ida(recs[: args.ida_records], args.rungs, args.rtol, rng)
    print(
        f"IDA {min(len(recs), args.ida_records)} records x 6 stacked objects x {args.rungs} "
        f"rungs: {seconds:.1f} s wall ({fell:.0%} of the rows overturned)"
    )


if __name__ == "__main__":
    main()
