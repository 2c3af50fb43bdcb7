"""Does ``model="auto"`` cost pure rocking scenes nearly nothing? Throughput of
:func:`rockstudy.simulate_batch` on scenes whose friction never limits (mu = 10).

Three runs of the same scenes, in one process, after a warm-up (compilation apart):
- ``rocking``: Housner's model, nothing else (today's batch);
- ``rocking + check``: Housner's model with ``friction=10`` (the friction check:
  ``friction_demand`` and ``lift_off``);
- ``auto``: ``model="auto"``, ``friction=10`` (the check, then the contact model on no row).

The scenes: random blocks (R 0.3-3 m, alpha 0.1-0.3) under sine pulses (a_g / (g tan alpha)
1.2-4, T_p 0.2-1 s), and under a synthetic record (scale 0.5-2). Prints and writes
scenes/s and the ratios auto / rocking and auto / (rocking + check); the target is
auto >= 0.8 x rocking.

    python benchmarks/contact_auto.py            # n = 400 pulse rows, 100 record rows
    python benchmarks/contact_auto.py --n 100    # a quick look

Writes benchmarks/results/contact_auto.json.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from rockstudy import simulate_batch
from rockstudy.constants import G
from rockstudy.motions import stochastic_record

OUT = Path(__file__).parent / "results"
RUNS = {
    "rocking": {},
    "rocking + check": dict(friction=10.0),
    "auto": dict(friction=10.0, model="auto"),
}


def scenes(n, seed=36):
    """simulate_batch arguments of n pulse rows and n // 4 record rows."""
    rng = np.random.default_rng(seed)
    alpha = rng.uniform(0.1, 0.3, n)
    pulses = dict(
        half_diagonal=rng.uniform(0.3, 3.0, n),
        slenderness=alpha,
        amplitude=rng.uniform(1.2, 4.0, n) * G * np.tan(alpha),
        period=rng.uniform(0.2, 1.0, n),
    )
    m = max(n // 4, 1)
    records = dict(
        half_diagonal=rng.uniform(0.3, 3.0, m),
        slenderness=rng.uniform(0.1, 0.3, m),
        record=stochastic_record(3.0, duration=8.0, seed=seed),
        scale=rng.uniform(0.5, 2.0, m),
    )
    return {"sine pulses": pulses, "record": records}


def throughput(kwargs, extra, repeat=3):
    """Best scenes/s of ``repeat`` runs."""
    n = np.size(kwargs["slenderness"])
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = simulate_batch(**kwargs, **extra)
        best = min(best, time.perf_counter() - t0)
    return n / best, out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400)
    args = parser.parse_args(argv)
    results = {}
    for name, kwargs in scenes(args.n).items():
        warm = {k: (v[:2] if isinstance(v, np.ndarray) else v) for k, v in kwargs.items()}
        for extra in RUNS.values():  # compile outside the timing
            simulate_batch(**warm, **extra)
        rates, outs = {}, {}
        for run, extra in RUNS.items():
            rates[run], outs[run] = throughput(kwargs, extra)
        contact_rows = int(np.sum(outs["auto"]["model"] == 3))
        results[name] = {
            "scenes": int(np.size(kwargs["slenderness"])),
            "scenes_per_s": rates,
            "auto / rocking": rates["auto"] / rates["rocking"],
            "auto / (rocking + check)": rates["auto"] / rates["rocking + check"],
            "rows run by the contact model under auto": contact_rows,
        }
        print(
            f"{name}: " + ", ".join(f"{k} {v:.0f} scenes/s" for k, v in rates.items()),
            f"| auto / rocking {results[name]['auto / rocking']:.3f}",
            f"| auto / (rocking + check) {results[name]['auto / (rocking + check)']:.3f}",
            f"| contact rows {contact_rows}",
        )
    OUT.mkdir(exist_ok=True)
    (OUT / "contact_auto.json").write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
