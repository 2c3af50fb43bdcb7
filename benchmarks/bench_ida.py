"""IDA benchmark (issue 13): bisection against a 40-level ladder, and a 50-record x 200-block
suite end to end. Writes benchmarks/results/ida.json.

    NUMBA_NUM_THREADS=2 python benchmarks/bench_ida.py [--fraction 0.1]

(a) On a suite of synthetic near-fault records (25 s at dt 0.01 s) and blocks of R 0.3-5 m:
    a 40-level ladder of scales, geometric from uplift (PGA = g tan alpha) to PGA =
    30 g tan alpha (steps of 9.1 %), against the IDA by bracket and bisection to the same
    tolerance (9.1 %) and to 1 %: simulations counted, and how often the two first overturning
    levels agree (rocking is not monotonic: a ladder and a bracket can land in different
    overturning windows).
(b) 50 records written as .AT2 files, read by load_suite, their IMs and pulses, an IDA of
    200 blocks at 1 %, the IDA fragility and the IM efficiency table. The IDA runs on
    ``--fraction`` of the records and is extrapolated linearly in the number of records (each
    record is an independent set of batch calls); the extrapolation is printed as such.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from rockstudy import simulate_batch
from rockstudy.constants import G
from rockstudy.motions import load_suite, synthetic_near_fault
from rockstudy.study import records_fragility as rf
from rockstudy.study.records_designs import incremental_dynamic_analysis

OUT = Path(__file__).parent / "results"
MAX_RATIO = 30.0
LADDER = 40


def _suite(n, seed=0):
    rng = np.random.default_rng(seed)
    periods = rng.uniform(0.4, 2.5, n)
    return [
        synthetic_near_fault(t, rng.uniform(2.0, 6.0), seed=seed + i, duration=25.0, dt=0.01)
        for i, t in enumerate(periods)
    ]


def _blocks(n, seed=1):
    rng = np.random.default_rng(seed)
    return {
        "half_diagonal": np.exp(rng.uniform(np.log(0.3), np.log(5.0), n)),
        "slenderness": rng.uniform(0.1, 0.3, n),
    }


def ladder(records, blocks):
    """First overturning scale / uplift scale on a 40-level ladder (NaN if never)."""
    ratios = MAX_RATIO ** (np.arange(1, LADDER + 1) / LADDER)  # first level just above uplift
    R, a = blocks["half_diagonal"], blocks["slenderness"]
    first = np.full((len(records), R.size), np.nan)
    for i, rec in enumerate(records):
        up = G * np.tan(a) / rec.peak
        out = simulate_batch(
            half_diagonal=np.repeat(R, LADDER),
            slenderness=np.repeat(a, LADDER),
            record=rec,
            scale=(up[:, None] * ratios[None, :]).ravel(),
        )["overturned"].reshape(R.size, LADDER)
        hit = out.any(axis=1)
        first[i, hit] = ratios[np.argmax(out[hit], axis=1)]
    # a ladder that stops at the first overturning (no resurrection seen) costs this many
    stopped = np.where(np.isfinite(first), np.log(first) / np.log(MAX_RATIO) * LADDER, LADDER)
    return first, len(records) * R.size * LADDER, int(np.round(stopped).sum())


def part_a(n_rec, n_blk):
    records, blocks = _suite(n_rec), _blocks(n_blk)
    t0 = time.perf_counter()
    first, n_ladder, n_stopped = ladder(records, blocks)
    t_ladder = time.perf_counter() - t0
    step = MAX_RATIO ** (1 / LADDER) - 1
    res = {
        "records": n_rec,
        "blocks": n_blk,
        "ladder_step": step,
        "ladder_sims": n_ladder,
        "stopped_ladder_sims": n_stopped,
        "ladder_s": t_ladder,
    }
    up = G * np.tan(blocks["slenderness"])[None, :] / np.array([r.peak for r in records])[:, None]
    for name, tol, growth, scan in (
        ("same_tolerance", step, 1.25, 0),
        ("same_tolerance_growth_1.5", step, 1.5, 0),
        ("same_tolerance_growth_2", step, 2.0, 0),
        ("one_percent", 0.01, 1.5, 0),
        ("one_percent_with_scan", 0.01, 1.5, 4),
    ):
        t0 = time.perf_counter()
        ds = incremental_dynamic_analysis(
            records, blocks, tolerance=tol, growth=growth, scan=scan, max_pga_ratio=MAX_RATIO
        )
        dt = time.perf_counter() - t0
        cap = ds["capacity_scale"].values / up  # PGA / (g tan alpha) at first overturning
        both = np.isfinite(cap) & np.isfinite(first)
        agree = both & (np.abs(np.log(cap / first)) <= np.log1p(step) * 1.0001)
        res[name] = {
            "tolerance": tol,
            "growth": growth,
            "scan": scan,
            "sims": int(ds.attrs["n_simulations"]),
            "fewer_than_ladder": n_ladder / ds.attrs["n_simulations"],
            "seconds": dt,
            "censored_both": int((~np.isfinite(cap) & ~np.isfinite(first)).sum()),
            "found_both": int(both.sum()),
            "agree_within_ladder_step": int(agree.sum()),
            "ida_above_ladder": int((both & (cap > first * (1 + step) * 1.0001)).sum()),
            "ida_below_ladder": int((both & (cap * (1 + step) * 1.0001 < first)).sum()),
            "censored_mismatch": int((np.isfinite(cap) != np.isfinite(first)).sum()),
            "resurrection_flagged": int(ds["resurrection"].sum()),
        }
    return res


def part_b(n_rec, n_blk, fraction):
    records = _suite(n_rec, seed=100)
    with tempfile.TemporaryDirectory() as tmp:
        for i, r in enumerate(records):
            vals = r.acceleration / G
            lines = [
                "PEER NGA STRONG MOTION DATABASE RECORD",
                r.name,
                "ACCELERATION TIME SERIES IN UNITS OF G",
                f"NPTS= {vals.size}, DT= {r.dt:.4f} SEC,",
            ]
            lines += [" ".join(f"{v:.7E}" for v in vals[k : k + 5]) for k in range(0, vals.size, 5)]
            Path(tmp, f"REC{i:03d}.AT2").write_text("\n".join(lines) + "\n")
        t0 = time.perf_counter()
        suite = load_suite(tmp)
        t_load = time.perf_counter() - t0
    t0 = time.perf_counter()
    for r in suite:
        r.intensity_measures(periods=[0.5, 1.0, 2.0])
        r.pulse()
    t_ims = time.perf_counter() - t0
    k = max(1, int(round(fraction * n_rec)))
    blocks = _blocks(n_blk, seed=3)
    t0, c0 = time.perf_counter(), time.process_time()
    ds = incremental_dynamic_analysis(suite[:k], blocks, periods=[0.5, 1.0, 2.0])
    t_ida, c_ida = time.perf_counter() - t0, time.process_time() - c0
    t0 = time.perf_counter()
    rf.ida_fragility(ds)
    eff = rf.im_efficiency(ds)
    t_fit = time.perf_counter() - t0
    total = t_load + t_ims + t_ida * n_rec / k + t_fit
    return {
        "records": n_rec,
        "blocks": n_blk,
        "records_run": k,
        "load_s": t_load,
        "ims_and_pulses_s": t_ims,
        "ida_s_measured": t_ida,
        "ida_sims_measured": int(ds.attrs["n_simulations"]),
        "ida_cpu_s_measured": c_ida,
        "ida_s_extrapolated": t_ida * n_rec / k,
        "ida_s_extrapolated_idle_2_cores": c_ida / 2 * n_rec / k,
        "fragility_s": t_fit,
        "total_s_extrapolated": total,
        "efficiency_top": eff.reset_index()[["im", "beta"]].head(4).to_dict("records"),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fraction", type=float, default=0.1)
    ap.add_argument("--a-records", type=int, default=6)
    ap.add_argument("--a-blocks", type=int, default=20)
    ap.add_argument("--skip-a", action="store_true", help="only the 50 x 200 suite")
    args = ap.parse_args()
    load = os.getloadavg()
    # compile outside the timings
    incremental_dynamic_analysis(_suite(1), _blocks(2), scan=1)
    a = None if args.skip_a else part_a(args.a_records, args.a_blocks)
    print(json.dumps(a, indent=1))
    b = part_b(50, 200, args.fraction)
    print(json.dumps(b, indent=1, default=str))
    OUT.mkdir(exist_ok=True)
    result = {
        "a": a,
        "b": b,
        "load_average": load,
        "numba_threads": os.environ.get("NUMBA_NUM_THREADS"),
    }
    name = "ida_b.json" if args.skip_a else "ida.json"
    (OUT / name).write_text(json.dumps(result, indent=1, default=str))


if __name__ == "__main__":
    main()
