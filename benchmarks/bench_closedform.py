"""Closed-form benchmark (issue 3): throughput of the spectrum and the classifier, and the time
for one overturning boundary over 1000 values of omega. Prints medians of repeats and writes
benchmarks/results/closedform.json.

    python benchmarks/bench_closedform.py
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numba
import numpy as np

from rockstudy import closedform as cf

OUT = Path(__file__).parent / "results"


def median_time(fn, repeat=7, clock=time.perf_counter):
    """The median of ``repeat`` timings of fn() on ``clock`` [s], after a warm call."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return float(np.median(times))


def main():
    n = 2_000_000
    rng = np.random.default_rng(1)
    a = rng.uniform(1.0, 10.0, n)
    w = rng.uniform(0.3, 12.0, n)
    result = {"points": n, "threads": numba.config.NUMBA_NUM_THREADS}
    for name, fn in (
        ("spectrum_4_13", lambda: cf.max_rotation(a, w, 0.85, check=False)),
        ("classifier_codes", lambda: cf.overturning_mode_code(a, w, 0.85)),
        ("classifier_labels", lambda: cf.overturning_mode(a, w, 0.85)),
    ):
        result[f"{name}_points_per_second"] = n / median_time(fn)
    omega = np.geomspace(0.3, 12.0, 1000)
    for case in ("2", "1.2", "1.1", "1.1-approx", "limit"):
        result[f"boundary_{case}_1000_omega_seconds"] = median_time(
            lambda case=case: cf.overturning_boundary(omega, 0.85, case), repeat=3
        )
    OUT.mkdir(exist_ok=True)
    (OUT / "closedform.json").write_text(json.dumps(result, indent=2))
    for key, value in result.items():
        print(f"{key:45s} {value:.4g}" if isinstance(value, float) else f"{key:45s} {value}")


if __name__ == "__main__":
    main()
