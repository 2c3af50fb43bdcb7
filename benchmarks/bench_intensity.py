"""Intensity-measure benchmark (issue 13): Sa(T) for 100 periods on the 7,554-sample record
(RSN183, El Centro Array #8) and the whole IM set of the five shared records, each from a fresh
Record (no cache). Also the pulse extraction. Prints medians and writes
benchmarks/results/intensity.json. Targets: < 10 ms and < 1 s.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_intensity.py

ROCKSTUDY_RECORDS=DIR points it at another folder of records; without one it runs on five
synthetic near-fault records.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np

from rockstudy.motions import Record, synthetic_near_fault
from rockstudy.motions.intensity import spectral_displacement

OUT = Path(__file__).parent / "results"
RECORDS = Path(
    os.environ.get(
        "ROCKSTUDY_RECORDS", Path(__file__).resolve().parents[1].parent / "shared" / "records"
    )
)
PERIODS = np.geomspace(0.05, 5.0, 100)


def _records():
    if RECORDS.is_dir():
        recs = [Record.from_at2(p) for p in sorted(RECORDS.glob("*.AT2"))]
        return recs + [Record.from_csv(RECORDS / "elcentro_NS.dat")], "shared"
    tp = (1.0, 2.0, 3.0, 4.0, 6.0)
    return [synthetic_near_fault(pulse_period=t, pga=5.0, seed=i) for i, t in enumerate(tp)], (
        "synthetic"
    )


def _timings(f, repeat):
    """(median, min) wall time [s]: the machine is shared, so the min shows the unloaded cost."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), float(np.min(times))


def main():
    recs, source = _records()
    big = max(recs, key=lambda r: r.acceleration.size)
    t, a = big.time, big.acceleration
    spectral_displacement(t, a, PERIODS)  # compile / load the cache
    sa_100 = _timings(lambda: spectral_displacement(t, a, PERIODS), 50)

    def fresh(r):
        return Record(r.acceleration, time=r.time)

    def all_ims():
        for r in recs:
            fresh(r).intensity_measures(periods=PERIODS)

    def all_pulses():
        for r in recs:
            fresh(r).pulse()

    all_ims()
    ims = _timings(all_ims, 7)
    pulses = _timings(all_pulses, 3)
    out = {
        "source": source,
        "threads": int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count())),
        "sa_100_periods_samples": int(a.size),
        "sa_100_periods_ms": {"median": 1e3 * sa_100[0], "min": 1e3 * sa_100[1]},
        "im_set_five_records_s": {"median": ims[0], "min": ims[1]},
        "pulse_five_records_s": {"median": pulses[0], "min": pulses[1]},
    }
    print(json.dumps(out, indent=1))
    OUT.mkdir(exist_ok=True)
    (OUT / "intensity.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
