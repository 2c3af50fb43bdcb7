"""Contact rows per second of :func:`rockstudy.simulate_batch` (``model="contact"``) against
the same rows run one by one through :func:`rockstudy.dynamics.contact_model.contact_outputs`
(the single-scene path: what the batch did before it called the parallel kernels).

Random blocks (R 0.3-3 m, alpha 0.1-0.4, mu 0.2-0.8: stocky ones that slide and slender ones
that rock) under sine pulses (a_g / (g min(tan alpha, mu)) 1.2-4, T_p 0.2-1 s) and under a
synthetic record (8 s, scale 0.5-2). Both paths alternate in one process after a warm-up;
printed: the best of three runs of each, in rows per wall second and per CPU second of the
process (the CPU seconds are fairer on a shared machine).

    python benchmarks/contact_batch_rows.py [--n 200]
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from rockstudy import simulate_batch
from rockstudy.constants import G
from rockstudy.dynamics import contact_model
from rockstudy.motions import SinePulse, stochastic_record


def scenes(n, seed=36):
    """{name: (simulate_batch arguments, the Motion of row i, p, alpha, eta, mu)}."""
    rng = np.random.default_rng(seed)
    alpha, mu, radius = rng.uniform(0.1, 0.4, n), rng.uniform(0.2, 0.8, n), rng.uniform(0.3, 3, n)
    p, eta = np.sqrt(0.75 * G / radius), 1.0 - 1.5 * np.sin(alpha) ** 2
    amp = rng.uniform(1.2, 4.0, n) * G * np.minimum(np.tan(alpha), mu)
    period = rng.uniform(0.2, 1.0, n)
    record, scale = stochastic_record(3.0, duration=8.0, seed=seed), rng.uniform(0.5, 2.0, n)
    block = dict(half_diagonal=radius, slenderness=alpha, friction=mu, model="contact")
    return {
        "sine pulses": (
            dict(block, amplitude=amp, period=period),
            lambda i: SinePulse(amplitude=amp[i], period=period[i]),
        ),
        "record": (dict(block, record=record, scale=scale), lambda i: record.scaled(scale[i])),
    }, (p, alpha, eta, mu)


def best(run, repeat=3):
    """(least wall seconds, least CPU seconds) of ``repeat`` calls of run()."""
    wall = cpu = np.inf
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        run()
        wall, cpu = min(wall, time.perf_counter() - w), min(cpu, time.process_time() - c)
    return wall, cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=200)
    args = parser.parse_args()
    sets, (p, alpha, eta, mu) = scenes(args.n)
    for name, (kwargs, motion) in sets.items():

        def one_by_one(motion=motion):
            for i in range(args.n):
                contact_model.contact_outputs(
                    p[i], alpha[i], eta[i], motion(i), (mu[i], mu[i]), 1e-8
                )

        def batch(kwargs=kwargs):
            simulate_batch(**kwargs)

        batch(), one_by_one()  # compile and warm up
        rows = [args.n / t for t in (*best(one_by_one), *best(batch))]
        print(
            f"{name}: {args.n} rows, {numba.get_num_threads()} threads: one by one "
            f"{rows[0]:.0f} rows/s ({rows[1]:.0f} per CPU s), batch {rows[2]:.0f} rows/s "
            f"({rows[3]:.0f} per CPU s), ratio {rows[2] / rows[0]:.1f}"
        )


if __name__ == "__main__":
    main()
