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
auto >= 0.8 x rocking on the pure rocking scenes: those that ``auto`` leaves to Housner's model
(the others, which overturn, lift off or need more friction, it runs again with the contact
model), timed again on their own (``pure rocking: auto / rocking``).

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


def throughput(kwargs, runs, repeat=5):
    """({run: best scenes/s}, {run: outputs}) of the ``runs`` (name: extra arguments), each
    timed ``repeat`` times, the runs interleaved (the machine's load, shared, drifts: each
    run sees the same drift)."""
    n = np.size(kwargs["slenderness"])
    best, outs = dict.fromkeys(runs, np.inf), {}
    for _ in range(repeat):
        for run, extra in runs.items():
            t0 = time.perf_counter()
            outs[run] = simulate_batch(**kwargs, **extra)
            best[run] = min(best[run], time.perf_counter() - t0)
    return {run: n / t for run, t in best.items()}, outs


def subset(kwargs, keep):
    """The simulate_batch arguments of the rows ``keep`` (a boolean mask)."""
    return {k: (v[keep] if isinstance(v, np.ndarray) else v) for k, v in kwargs.items()}


def pure_rocking(kwargs, auto):
    """(scenes, rocking scenes/s, auto scenes/s) on the rows that ``auto`` (its outputs)
    answered with Housner's model."""
    pure = subset(kwargs, auto["model"] != 3)
    rates = throughput(pure, {run: RUNS[run] for run in ("rocking", "auto")})[0]
    return int(np.size(pure["slenderness"])), rates["rocking"], rates["auto"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400)
    args = parser.parse_args(argv)
    results = {}
    for name, kwargs in scenes(args.n).items():
        warm = {k: (v[:2] if isinstance(v, np.ndarray) else v) for k, v in kwargs.items()}
        for extra in RUNS.values():  # compile outside the timing
            simulate_batch(**warm, **extra)
        rates, outs = throughput(kwargs, RUNS)
        contact_rows = int(np.sum(outs["auto"]["model"] == 3))
        n_pure, pure_rocking_rate, pure_auto_rate = pure_rocking(kwargs, outs["auto"])
        results[name] = {
            "scenes": int(np.size(kwargs["slenderness"])),
            "scenes_per_s": rates,
            "auto / rocking": rates["auto"] / rates["rocking"],
            "auto / (rocking + check)": rates["auto"] / rates["rocking + check"],
            "rows run by the contact model under auto": contact_rows,
            "pure rocking scenes": n_pure,
            "pure rocking: scenes_per_s": {"rocking": pure_rocking_rate, "auto": pure_auto_rate},
            "pure rocking: auto / rocking": pure_auto_rate / pure_rocking_rate,
        }
        print(
            f"{name}: " + ", ".join(f"{k} {v:.0f} scenes/s" for k, v in rates.items()),
            f"| auto / rocking {results[name]['auto / rocking']:.3f}",
            f"| auto / (rocking + check) {results[name]['auto / (rocking + check)']:.3f}",
            f"| contact rows {contact_rows}",
            f"| pure rocking ({n_pure} scenes): auto / rocking "
            f"{results[name]['pure rocking: auto / rocking']:.3f}",
        )
    OUT.mkdir(exist_ok=True)
    (OUT / "contact_auto.json").write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
