"""IDA benchmark (issue 23 section 1): the ladder against the former bracket-and-bisection,
in one run, for accuracy (against a dense scan) and for cost (50 records x 200 blocks).
Writes benchmarks/results/ida.json.

    NUMBA_NUM_THREADS=2 python benchmarks/bench_ida.py [--fraction 0.1] [--skip-a]

(a) Accuracy. For synthetic near-fault records x random blocks, and for the shared real
    records (../shared/records) x five museum objects: a dense scan of ``--dense`` log-spaced
    levels from half the rest scale (PGA = g alpha / 2) to PGA = 30 g tan alpha gives the
    first overturning d. A pair *agrees* when the capacity lies within the tolerance of the
    dense scan's first bracket; the first window is *narrow* when a fine scan (200 levels) of
    [d, d (1 + step)] finds a survival (the ladder can step over it). Reported for the ladder
    (default step 1 %, tolerance 0.1 %) and the former bisection (growth 1.5, tolerance 1 %),
    with the ratio capacity / d where they miss.
(b) Cost. 50 records written as .AT2 files, read by load_suite, their IMs and pulses, an IDA of
    200 blocks, the IDA fragility and the IM efficiency table, for both algorithms. The IDAs
    run on ``--fraction`` of the records; each record is an independent set of batch calls,
    so the total is the median time per record times 50 (printed as such). On a shared
    machine the wall time depends on the load: the CPU time / 2 is given as the time on two
    idle cores.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from rockstudy import Block, simulate_batch
from rockstudy.constants import G
from rockstudy.motions import Record, load_suite, synthetic_near_fault
from rockstudy.study.analysis import record_fragility as rf
from rockstudy.study.designs.records import incremental_dynamic_analysis

OUT = Path(__file__).parent / "results"
RECORDS = Path(os.environ.get("ROCKSTUDY_RECORDS") or Path(__file__).parents[2] / "shared/records")
MAX_RATIO = 30.0
#: Museum objects (width, height) [m]: two statues, two columns, a vase.
OBJECTS = ((0.45, 1.9), (0.35, 1.5), (0.5, 4.0), (0.7, 5.5), (0.3, 0.8))


def _suite(n, seed=0, duration=25.0):
    rng = np.random.default_rng(seed)
    periods = rng.uniform(0.4, 2.5, n)
    return [
        synthetic_near_fault(t, rng.uniform(2.0, 6.0), seed=seed + i, duration=duration, dt=0.01)
        for i, t in enumerate(periods)
    ]


def _blocks(n, seed=1):
    rng = np.random.default_rng(seed)
    return {
        "half_diagonal": np.exp(rng.uniform(np.log(0.3), np.log(5.0), n)),
        "slenderness": rng.uniform(0.1, 0.3, n),
    }


def _objects():
    blocks = [Block.from_dimensions(width=w, height=h) for w, h in OBJECTS]
    return {
        "half_diagonal": np.array([b.half_diagonal for b in blocks]),
        "slenderness": np.array([b.slenderness for b in blocks]),
    }


# ------------------------------------------------------------ the former algorithm


def bisection_ida(record, blocks, tolerance=0.01, growth=1.5, scan=4):
    """The IDA as it was before the ladder: bracket from g alpha / PGA (assumed to survive) by
    ``growth``, bisect to ``tolerance``, scan ``scan`` levels above. Returns the capacity
    scales (NaN: censored) and the simulations."""
    R, a = blocks["half_diagonal"], blocks["slenderness"]
    lo, top = G * a / record.peak, MAX_RATIO * G * np.tan(a) / record.peak
    hi, sims = np.full(R.size, np.nan), 0

    def run(idx, s):
        nonlocal sims
        sims += idx.size
        return simulate_batch(
            half_diagonal=R[idx], slenderness=a[idx], record=record, scale=s, outputs=["overturned"]
        )["overturned"]

    active, censored = np.arange(R.size), np.zeros(R.size, bool)
    while active.size:
        s = np.minimum(lo[active] * growth, top[active])
        over = run(active, s)
        hi[active[over]], lo[active[~over]] = s[over], s[~over]
        censored[active[~over & (s >= top[active])]] = True
        active = active[~over & (s < top[active])]
    while (active := np.flatnonzero(~censored & (hi > lo * (1 + tolerance)))).size:
        s = np.sqrt(lo[active] * hi[active])
        over = run(active, s)
        hi[active[over]], lo[active[~over]] = s[over], s[~over]
    found = np.flatnonzero(~censored)
    if scan and found.size:
        k = np.arange(1, scan + 1) / scan
        run(
            np.repeat(found, scan),
            (hi[found, None] * (top[found, None] / hi[found, None]) ** k).ravel(),
        )
    return np.where(censored, np.nan, hi), sims


def ladder_ida(record, blocks, **kw):
    ds = incremental_dynamic_analysis(record, blocks, **kw)
    return ds["capacity_scale"].values[0], int(ds.attrs["n_simulations"])


# ------------------------------------------------------------ (a) accuracy


def _dense(record, blocks, n_levels):
    R, a = blocks["half_diagonal"], blocks["slenderness"]
    scales = np.geomspace(
        0.5 * G * a / record.peak, MAX_RATIO * G * np.tan(a) / record.peak, n_levels
    ).T
    over = simulate_batch(
        half_diagonal=np.repeat(R, n_levels),
        slenderness=np.repeat(a, n_levels),
        record=record,
        scale=scales.ravel(),
        outputs=["overturned"],
    )["overturned"].reshape(scales.shape)
    return scales, over


def _narrow(record, R, a, d, step):
    fine = np.geomspace(d, d * (1 + step), 200)
    return not simulate_batch(
        half_diagonal=R, slenderness=a, record=record, scale=fine, outputs=["overturned"]
    )["overturned"].all()


def accuracy(records, blocks, n_levels, step=0.01):
    """Counts for the ladder and the bisection against the dense scan."""
    out = {
        name: {
            "pairs": 0,
            "agree": 0,
            "below_dense": 0,
            "missed": 0,
            "missed_wide": 0,
            "censored_both": 0,
            "censored_mismatch": 0,
            "sims": 0,
            "miss_ratios": [],
        }
        for name in ("ladder", "bisection")
    }
    narrow = 0
    for rec in records:
        scales, over = _dense(rec, blocks, n_levels)
        caps = {
            "ladder": ladder_ida(rec, blocks, step=step, scan=0),
            "bisection": bisection_ida(rec, blocks, scan=0),
        }
        tol = {"ladder": 0.001, "bisection": 0.01}
        for j in range(scales.shape[0]):
            has = over[j].any()
            if has:
                k = int(np.argmax(over[j]))
                d, d_prev = scales[j, k], scales[j, k - 1]
                is_narrow = _narrow(
                    rec, blocks["half_diagonal"][j], blocks["slenderness"][j], d, step
                )
                narrow += is_narrow
            for name, (cap, sims) in caps.items():
                o = out[name]
                o["pairs"] += 1
                o["sims"] += sims / scales.shape[0]  # per pair: the record's over its blocks
                c = cap[j]
                if not has or not np.isfinite(c):
                    o["censored_both" if has == np.isfinite(c) else "censored_mismatch"] += 1
                elif d_prev / (1 + tol[name]) <= c <= d * (1 + tol[name]):
                    o["agree"] += 1
                elif c < d_prev:
                    o["below_dense"] += 1
                else:
                    o["missed"] += 1
                    o["missed_wide"] += int(not is_narrow)
                    o["miss_ratios"].append(float(c / d))
    for o in out.values():
        r = np.array(o.pop("miss_ratios"))
        o["miss_ratio_median"] = float(np.median(r)) if r.size else None
        o["miss_ratio_max"] = float(r.max()) if r.size else None
        o["sims_per_pair"] = o.pop("sims") / o["pairs"]
    out["narrow_first_windows"] = int(narrow)
    return out


# ------------------------------------------------------------ (b) cost


def _write_suite(records, folder):
    for i, r in enumerate(records):
        vals = r.acceleration / G
        lines = [
            "PEER NGA STRONG MOTION DATABASE RECORD",
            r.name,
            "ACCELERATION TIME SERIES IN UNITS OF G",
            f"NPTS= {vals.size}, DT= {r.dt:.4f} SEC,",
        ]
        lines += [" ".join(f"{v:.7E}" for v in vals[k : k + 5]) for k in range(0, vals.size, 5)]
        Path(folder, f"REC{i:03d}.AT2").write_text("\n".join(lines) + "\n")


def cost(n_rec, n_blk, fraction):
    records = _suite(n_rec, seed=100)
    with tempfile.TemporaryDirectory() as tmp:
        _write_suite(records, tmp)
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
    res = {"records": n_rec, "blocks": n_blk, "records_run": k, "load_s": t_load, "ims_s": t_ims}
    for name, fn in (
        ("bisection", lambda r: bisection_ida(r, blocks)),
        ("ladder", lambda r: ladder_ida(r, blocks)),
    ):
        wall, cpu, sims = [], [], 0
        for r in suite[:k]:
            t0, c0 = time.perf_counter(), time.process_time()
            sims += fn(r)[1]
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        res[name] = {
            "median_wall_s_per_record": float(np.median(wall)),
            "median_cpu_s_per_record": float(np.median(cpu)),
            "ida_wall_s_50_records": float(np.median(wall)) * n_rec,
            "ida_s_50_records_two_idle_cores": float(np.median(cpu)) / 2 * n_rec,
            "sims_per_pair": sims / (k * n_blk),
        }
    t0 = time.perf_counter()
    ds = incremental_dynamic_analysis(suite[:k], blocks, periods=[0.5, 1.0, 2.0])
    rf.ida_fragility(ds)
    rf.im_efficiency(ds)
    res["fragility_and_efficiency_s"] = (
        time.perf_counter() - t0 - res["ladder"]["median_wall_s_per_record"] * k
    )
    for name in ("bisection", "ladder"):
        res[name]["end_to_end_s_two_idle_cores"] = (
            t_load + t_ims + res[name]["ida_s_50_records_two_idle_cores"]
        )
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fraction", type=float, default=0.1)
    ap.add_argument("--a-records", type=int, default=6)
    ap.add_argument("--a-blocks", type=int, default=8)
    ap.add_argument("--dense", type=int, default=1500)
    ap.add_argument("--skip-a", action="store_true", help="only the 50 x 200 cost")
    args = ap.parse_args()
    load = os.getloadavg()
    incremental_dynamic_analysis(_suite(1, duration=10.0), _blocks(2), scan=1)  # compile
    a = None
    if not args.skip_a:
        a = {
            "synthetic": accuracy(
                _suite(args.a_records, seed=7, duration=10.0),
                _blocks(args.a_blocks, seed=8),
                args.dense,
            )
        }
        if RECORDS.is_dir():
            real = load_suite(sorted(RECORDS.glob("*.AT2")))
            real.append(Record.from_csv(RECORDS / "elcentro_NS.dat"))
            a["real"] = accuracy(real, _objects(), args.dense)
        print(json.dumps(a, indent=1))
    b = cost(50, 200, args.fraction)
    print(json.dumps(b, indent=1))
    OUT.mkdir(exist_ok=True)
    result = {
        "a": a,
        "b": b,
        "load_average": load,
        "numba_threads": os.environ.get("NUMBA_NUM_THREADS"),
    }
    (OUT / ("ida_b.json" if args.skip_a else "ida.json")).write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
