"""Does ``model="auto"`` cost pure rocking scenes nearly nothing? Throughput of
:func:`rockstudy.simulate_batch` on scenes whose friction never limits (mu = 10).

Three runs of the same scenes, in one process, after a warm-up (compilation apart):
- ``rocking``: Housner's model, nothing else (today's batch);
- ``rocking + check``: Housner's model with ``friction=10`` (the friction check:
  ``friction_demand`` and ``lift_off``);
- ``auto``: ``model="auto"``, ``friction=10`` (the check, then the contact model on no row).

The scenes: random blocks (R 0.3-3 m, alpha 0.1-0.3) under sine pulses (a_g / (g tan alpha)
1.2-4, T_p 0.2-1 s), and under a synthetic record (scale 0.5-2). Prints and writes
scenes/s (the median of interleaved repeats: the runs take turns, so that each sees the
machine's load as it drifts) and the ratios auto / rocking and auto / (rocking + check), each
the median of the repeats' own ratios; the target is
auto >= 0.8 x rocking on the pure rocking scenes: those that ``auto`` leaves to Housner's model
(the others, which overturn, lift off or need more friction, it runs again with the contact
model), timed again on their own (``pure rocking: auto / rocking``; beside it the same median ratio
of CPU times, all threads, which a shared machine's load disturbs least).

    python benchmarks/contact_auto.py                      # n = 400 pulse rows, 100 record rows
    python benchmarks/contact_auto.py --n 100 --repeats 5  # a quick look
    python benchmarks/contact_auto.py --n 4000 --repeats 21  # a stable median
    python benchmarks/contact_auto.py --motions record     # the record rows only

Writes benchmarks/results/contact_auto.json (``--motions``: replaces those scenes' entries).
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


def throughput(kwargs, runs, repeats):
    """({run: median scenes/s}, {run: outputs}, {run: times [s] per repeat}, {run: CPU
    times [s] per repeat, all threads}) of the ``runs`` (name: extra arguments), each timed
    ``repeats`` times, the runs interleaved (the machine's load, shared, drifts: the runs of
    one repeat see nearly the same load; the CPU times see it least)."""
    n = np.size(kwargs["slenderness"])
    times, cpu, outs = {run: [] for run in runs}, {run: [] for run in runs}, {}
    for _ in range(repeats):
        for run, extra in runs.items():
            t0, c0 = time.perf_counter(), time.process_time()
            outs[run] = simulate_batch(**kwargs, **extra)
            times[run].append(time.perf_counter() - t0)
            cpu[run].append(time.process_time() - c0)
    times = {run: np.array(t) for run, t in times.items()}
    cpu = {run: np.array(t) for run, t in cpu.items()}
    return {run: n / float(np.median(t)) for run, t in times.items()}, outs, times, cpu


def ratio(times, run, base):
    """The median over the repeats of the throughput ratio ``run`` / ``base`` (each repeat's
    runs timed side by side), with its spread (the quartiles)."""
    r = times[base] / times[run]
    return float(np.median(r)), [float(q) for q in np.percentile(r, (25, 75))]


def subset(kwargs, keep):
    """The simulate_batch arguments of the rows ``keep`` (a boolean mask)."""
    return {k: (v[keep] if isinstance(v, np.ndarray) else v) for k, v in kwargs.items()}


def pure_rocking(kwargs, auto, repeats):
    """(scenes, {run: median scenes/s}, (median ratio auto / rocking, its quartiles), the
    same ratio of CPU times) on the rows that ``auto`` (its outputs) answered with Housner's
    model."""
    pure = subset(kwargs, auto["model"] != 3)
    runs = {run: RUNS[run] for run in ("rocking", "auto")}
    rates, _, times, cpu = throughput(pure, runs, repeats)
    n = int(np.size(pure["slenderness"]))
    return n, rates, ratio(times, "auto", "rocking"), ratio(cpu, "auto", "rocking")[0]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=9, help="interleaved repeats per run")
    parser.add_argument(
        "--motions", choices=("all", "sine pulses", "record"), default="all", help="scenes to time"
    )
    args = parser.parse_args(argv)
    results = {}
    for name, kwargs in scenes(args.n).items():
        if args.motions not in ("all", name):
            continue
        warm = {k: (v[:2] if isinstance(v, np.ndarray) else v) for k, v in kwargs.items()}
        for extra in RUNS.values():  # compile outside the timing
            simulate_batch(**warm, **extra)
        rates, outs, times, _ = throughput(kwargs, RUNS, args.repeats)
        contact_rows = int(np.sum(outs["auto"]["model"] == 3))
        n_pure, pure_rates, (pure, pure_q), pure_cpu = pure_rocking(
            kwargs, outs["auto"], args.repeats
        )
        results[name] = {
            "scenes": int(np.size(kwargs["slenderness"])),
            "repeats": args.repeats,
            "scenes_per_s (median)": rates,
            "auto / rocking": ratio(times, "auto", "rocking")[0],
            "auto / (rocking + check)": ratio(times, "auto", "rocking + check")[0],
            "rows run by the contact model under auto": contact_rows,
            "pure rocking scenes": n_pure,
            "pure rocking: scenes_per_s (median)": pure_rates,
            "pure rocking: auto / rocking (median)": pure,
            "pure rocking: auto / rocking (quartiles)": pure_q,
            "pure rocking: auto / rocking (median, CPU time)": pure_cpu,
        }
        print(
            f"{name}: " + ", ".join(f"{k} {v:.0f} scenes/s" for k, v in rates.items()),
            f"| auto / rocking {results[name]['auto / rocking']:.3f}",
            f"| auto / (rocking + check) {results[name]['auto / (rocking + check)']:.3f}",
            f"| contact rows {contact_rows}",
            f"| pure rocking ({n_pure} scenes): auto / rocking median {pure:.3f} "
            f"(quartiles {pure_q[0]:.3f}-{pure_q[1]:.3f}, {args.repeats} repeats; "
            f"CPU time {pure_cpu:.3f})",
        )
    OUT.mkdir(exist_ok=True)
    path = OUT / "contact_auto.json"
    kept = json.loads(path.read_text()) if path.exists() and args.motions != "all" else {}
    path.write_text(json.dumps({**kept, **results}, indent=2) + "\n")


if __name__ == "__main__":
    main()
