"""Alternated A/B timing of the kernels of two source trees, one thread, CPU time.

``python ab_kernels.py TREE_A TREE_B [ROUNDS]`` runs, ROUNDS times (default 6) and alternating
the trees, a child process per tree (PYTHONPATH=tree, NUMBA_NUM_THREADS=1) that times, after a
warm-up, the best of 3 of: simulate_batch on 400 sine pulses (x60) and Ricker wavelets (x20),
100 scaled copies of a stochastic record (x30), and three histories with dense output (x100).
Prints each round and the median ratio B/A per case.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

CHILD = """
import json, time, warnings
import numpy as np
import rockstudy as rs
from rockstudy.motions import stochastic_record
warnings.simplefilter("ignore")
rng = np.random.default_rng(1)
n = 400
R, alpha = rng.uniform(0.3, 8.0, n), rng.uniform(0.05, 0.4, n)
amp, tp = rng.uniform(0.8, 4.0, n) * 9.81 * np.tan(alpha), rng.uniform(0.2, 2.0, n)
rec, scale = stochastic_record(3.0, duration=10.0, seed=3), rng.uniform(0.3, 2.0, n)
block, t_eval = rs.Block(half_diagonal=1.0, slenderness=0.2), np.linspace(0, 9, 200)
def pulses(shape):
    return lambda: rs.simulate_batch(
        half_diagonal=R, slenderness=alpha, pulse=shape, amplitude=amp, period=tp)
cases = {
    "sine": (pulses("sine"), 60),
    "ricker": (pulses("ricker"), 20),
    "record": (lambda: rs.simulate_batch(
        half_diagonal=R[:100], slenderness=alpha[:100], record=rec, scale=scale[:100]), 30),
    "history": (lambda: [rs.simulate(block, rec.scaled(s), t_eval=t_eval)
                         for s in (0.5, 1.0, 1.5)], 100),
}
out = {}
for name, (f, reps) in cases.items():
    f()
    best = np.inf
    for _ in range(3):
        t0 = time.process_time()
        for _ in range(reps):
            f()
        best = min(best, time.process_time() - t0)
    out[name] = best
print(json.dumps(out))
"""


def _time(tree):
    env = dict(os.environ, PYTHONPATH=tree, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    out = subprocess.run(
        [sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(tree_a, tree_b, rounds=6):
    a, b = [], []
    for i in range(rounds):
        a.append(_time(tree_a))
        b.append(_time(tree_b))
        print(i, "A", a[-1], "B", b[-1], flush=True)
    for case in a[0]:
        ratios = [y[case] / x[case] for x, y in zip(a, b, strict=True)]
        print(f"{case}: median B/A {np.median(ratios):.3f} over {rounds} rounds")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], *(int(x) for x in sys.argv[3:4]))
