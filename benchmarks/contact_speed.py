"""Speed of the contact model's kernel against the rocking kernel on the same record scenes.

Records: the five real ones of shared/records (``ROCKSTUDY_RECORDS`` to move it) and the eight
synthetic near-fault records shipped with rockstudy (with their vertical components), whole.
Per record ``--blocks`` random blocks (R 0.3-3 m, alpha 0.05-0.5, the record scaled to a
peak of 0.8-4 times g min(tan alpha, mu)), in two sets of the same blocks and scales:
``contact`` (mu from max(0.1, tan alpha) to 1: the event-driven kernel) and ``sliding`` (mu
from 0.1 below tan alpha: the exact sliding kernel). Each set runs through
:func:`rockstudy.dynamics._contact_scene.contact_batch` and, without friction, through the
rocking kernel (:func:`rockstudy.dynamics._rocking.scene_batch_serial`, Housner's model with
the free-rocking map), both on one thread at the same rtol, timed in CPU seconds of this
process (best of ``--repeat``: the machine is shared). Printed per set: scenes/s of each
and the ratio contact / rocking, per record and over all (total scenes / total seconds), and
the median of the records' ratios.

    python benchmarks/contact_speed.py [--blocks 100] [--rtol 1e-8] [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from contact_accuracy import record_counts, records


def blocks(rng, n, a_h, a_v, sliding):
    """(R, alpha, mu, scale) of n random blocks on one record, ``sliding`` (mu < tan alpha)
    or not; alpha at least atan(0.11) for the sliding set (mu >= 0.1 below tan alpha)."""
    from rockstudy.constants import G

    rows = []
    while len(rows) < n:
        alpha = rng.uniform(math.atan(0.11) if sliding else 0.05, 0.5)
        tan = math.tan(alpha)
        mu = rng.uniform(0.1, tan) if sliding else rng.uniform(max(0.1, tan), 1.0)
        scale = rng.uniform(0.8, 4.0) * G * min(tan, mu) / np.max(np.abs(a_h))
        if a_v is not None and scale * np.min(a_v) <= -0.95 * G:
            continue
        rows.append((rng.uniform(0.3, 3.0), alpha, mu, scale))
    return np.array(rows).T


def best_time(run, repeat):
    """The least CPU seconds of ``repeat`` calls of run() (after one to compile)."""
    run()
    best = math.inf
    for _ in range(repeat):
        t0 = time.process_time()
        run()
        best = min(best, time.process_time() - t0)
    return best


def time_set(rec, radius, alpha, mu, scale, rtol, repeat):
    """CPU seconds of the contact batch and of the rocking batch on the same rows."""
    from rockstudy.constants import G
    from rockstudy.dynamics import _rocking
    from rockstudy.dynamics._contact_scene import contact_batch
    from rockstudy.dynamics.methods import MAX_STEPS

    kind, _, times, samples, vsamples = rec.kernel_spec()
    n = radius.size
    mp = np.column_stack([scale, np.zeros(n), np.zeros(n), np.full(n, rec.duration)])
    eta = 1.0 - 1.5 * np.sin(alpha) ** 2
    p = np.sqrt(0.75 * G / radius)
    motion = (kind, mp, times, samples, vsamples)

    def contact():
        contact_batch(p, alpha, eta, mu, mu, motion, rtol, parallel=False)

    def rocking():
        _rocking.scene_batch_serial(
            p,
            alpha,
            eta,
            _rocking.MODEL_NONLINEAR,
            kind,
            mp,
            times,
            samples,
            vsamples,
            rtol,
            MAX_STEPS,
        )

    return best_time(contact, repeat), best_time(rocking, repeat)


def main():
    import numba

    from rockstudy.motions import Record

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=100)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seed", type=int, default=36)
    args = parser.parse_args()
    numba.set_num_threads(1)
    rng = np.random.default_rng(args.seed)
    totals = {"contact": np.zeros(2), "sliding": np.zeros(2)}
    ratios = {kind: [] for kind in totals}
    recs = records(math.inf)
    for name, t, a_h, a_v in recs:
        rec = Record(a_h, time=t, vertical=a_v)
        line = [f"{name:32s}"]
        for kind in totals:
            radius, alpha, mu, scale = blocks(rng, args.blocks, a_h, a_v, kind == "sliding")
            seconds = np.array(time_set(rec, radius, alpha, mu, scale, args.rtol, args.repeat))
            totals[kind] += seconds
            c, r = args.blocks / seconds
            ratios[kind].append(c / r)
            line.append(f"{kind}: {c:8.0f} vs {r:8.0f} scenes/s ({c / r:5.2f})")
        print("  ".join(line), flush=True)
    n = args.blocks * len(recs)
    for kind, seconds in totals.items():
        c, r = n / seconds
        print(
            f"all {record_counts(r[0] for r in recs)}, {kind}: contact {c:.0f} scenes/s, "
            f"rocking {r:.0f} scenes/s, "
            f"ratio {c / r:.2f}, median of the records' ratios {np.median(ratios[kind]):.2f} "
            f"(rtol {args.rtol:g}, one thread)"
        )


if __name__ == "__main__":
    main()
