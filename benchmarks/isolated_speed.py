"""Speed of the isolated block's numba kernel against the single-block kernel on the same
records, the ratio measured in one run.

Records: the eight synthetic near-fault records shipped with rockstudy (horizontal
components, the first ``--seconds`` s). Per record ``--blocks`` random blocks (R 0.3-2 m,
alpha 0.1-0.35, the record scaled to a peak of 0.5-4 times g tan(alpha)); the same rows run
through ``simulate_batch(structure=[IsolatedBlock ...])`` (base mass ratio 0.5-3, T_b 1-3
s, zeta_b 0-0.2) and through ``simulate_batch`` with the blocks' columns (Housner's model),
both in parallel at the same rtol. Printed: scenes/s of each (median wall time of
``--repeat`` runs after one to compile; the machine is shared) and the ratio isolated /
single-block per record and over all.

    python benchmarks/isolated_speed.py [--blocks 40] [--seconds 10] [--rtol 1e-8] [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np


def shipped_records(seconds):
    """The shipped synthetic records' horizontal components, their first ``seconds`` s."""
    import rockstudy as rs
    from rockstudy.motions.shipped import write_shipped_suite

    out = []
    with tempfile.TemporaryDirectory() as folder:
        write_shipped_suite(folder)
        for h in sorted(Path(folder).glob("*_H.AT2")):
            rec = rs.motions.Record.from_at2(h)
            keep = np.asarray(rec.time) <= seconds
            acc = np.asarray(rec.acceleration)[keep]
            out.append(rs.motions.Record(acc, dt=float(rec.time[1] - rec.time[0]), name=h.stem))
    return out


def rows(rng, n, record):
    """(blocks' columns, isolated structures, scales) of n random rows on ``record``."""
    import rockstudy as rs
    from rockstudy.constants import G

    radius, alpha = rng.uniform(0.3, 2.0, n), rng.uniform(0.1, 0.35, n)
    scale = rng.uniform(0.5, 4.0, n) * G * np.tan(alpha) / record.peak
    isos = [
        rs.IsolatedBlock(
            rs.Block(r, a), rng.uniform(0.5, 3.0), period=rng.uniform(1.0, 3.0),
            damping=rng.uniform(0.0, 0.2),
        )
        for r, a in zip(radius, alpha, strict=True)
    ]  # fmt: skip
    return {"half_diagonal": radius, "slenderness": alpha}, isos, scale


def median_time(run, repeat):
    """The median wall seconds of ``repeat`` calls of run() (after one to compile)."""
    run()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main():
    import rockstudy as rs

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=40)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(2012)
    total = {"iso": 0.0, "single": 0.0, "n": 0}
    print(f"{'record':28s} {'isolated/s':>11s} {'single/s':>10s} {'ratio':>7s}")
    for rec in shipped_records(args.seconds):
        cols, isos, scale = rows(rng, args.blocks, rec)

        def isolated(rec=rec, isos=isos, scale=scale):
            rs.simulate_batch(structure=isos, record=rec, scale=scale, rtol=args.rtol)

        def single(rec=rec, cols=cols, scale=scale):
            rs.simulate_batch(**cols, record=rec, scale=scale, rtol=args.rtol)

        t_iso, t_single = median_time(isolated, args.repeat), median_time(single, args.repeat)
        n = len(isos)
        total["iso"] += t_iso
        total["single"] += t_single
        total["n"] += n
        ratio = t_single / t_iso
        print(f"{rec.name:28s} {n / t_iso:11.1f} {n / t_single:10.1f} {ratio:7.3f}")
    n = total["n"]
    overall = total["single"] / total["iso"]
    print(
        f"{'all':28s} {n / total['iso']:11.1f} {n / total['single']:10.1f} {overall:7.3f}"
        f"   (target >= 0.2)"
    )


if __name__ == "__main__":
    main()
