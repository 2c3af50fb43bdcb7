"""Time to first result (issue 14): ``import rockstudy``, the first ``simulate()`` of a new
process, and the quickstart study, each in fresh subprocesses.

    python benchmarks/bench_first_result.py            # after `make setup` (primed cache)
    python benchmarks/bench_first_result.py --cold     # also with an empty numba cache

Wall times depend on the load of the machine; the CPU time (user + sys of the process and its
children, e.g. the dask workers) is printed next to them. ``--cold`` points NUMBA_CACHE_DIR at an
empty folder, so every kernel is compiled again: what a user who skipped ``rockstudy compile``
waits for, and what ``rockstudy compile`` costs once.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ROCKSTUDY = [sys.executable, "-m", "rockstudy.cli"]

FIRST_SIMULATE = """
import rockstudy
from rockstudy.motions import SinePulse
r = rockstudy.simulate(rockstudy.Block(1.0, 0.2), SinePulse(6.0, 0.5))
assert r.max_rotation > 0
"""


def timed(cmd, env, cwd):
    """(wall [s], CPU of the child and its children [s]) of one command."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, cwd=cwd, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def best(cmd, env, cwd, repeat):
    """The fastest of ``repeat`` runs (wall, CPU)."""
    return min((timed(cmd, env, cwd) for _ in range(repeat)), key=lambda x: x[0])


def row(label, wall_cpu, target=None):
    wall, cpu = wall_cpu
    goal = f"   (target < {target:g} s)" if target else ""
    print(f"{label:48s} {wall:7.2f} s wall {cpu:7.2f} s CPU{goal}", flush=True)


def measure(env, cwd, repeat, out_dir, prefix=""):
    py = [sys.executable]
    row(f"{prefix}import rockstudy", best([*py, "-c", "import rockstudy"], env, cwd, repeat))
    row(
        f"{prefix}import + first simulate() of a new process",
        best([*py, "-c", FIRST_SIMULATE], env, cwd, repeat),
        2.0,
    )
    out = Path(out_dir) / f"{prefix.strip(': ') or 'warm'}.zarr"
    run = [*ROCKSTUDY, "run", str(ROOT / "studies" / "quickstart.toml"), "--out", str(out)]
    row(f"{prefix}rockstudy run studies/quickstart.toml", timed([*run, "--quiet"], env, cwd), 20.0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cold", action="store_true", help="also time an empty numba cache")
    parser.add_argument("--repeat", type=int, default=3, help="runs of the short timings")
    args = parser.parse_args()
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    env = dict(os.environ, PYTHONPATH=path)
    env.pop("NUMBA_CACHE_DIR", None)
    with tempfile.TemporaryDirectory() as tmp:
        print(f"rockstudy at {ROOT}; load average {os.getloadavg()[0]:.1f}, {os.cpu_count()} CPUs")
        row(
            "rockstudy compile (primes the cache; no-op if primed)",
            timed(ROCKSTUDY + ["compile"], env, tmp),
        )
        measure(env, tmp, args.repeat, tmp)
        if args.cold:
            cache = Path(tmp) / "numba-cache"
            cold = dict(env, NUMBA_CACHE_DIR=str(cache))
            first = [sys.executable, "-c", FIRST_SIMULATE]
            row("cold: import + first simulate(), empty cache", timed(first, cold, tmp))
            shutil.rmtree(cache)
            row(
                "cold: rockstudy run quickstart, empty cache",
                timed(
                    [
                        *ROCKSTUDY,
                        "run",
                        str(ROOT / "studies" / "quickstart.toml"),
                        "--quiet",
                        "--out",
                        str(Path(tmp) / "cold.zarr"),
                    ],
                    cold,
                    tmp,
                ),
                20.0,
            )
            shutil.rmtree(cache)
            row("cold: rockstudy compile, empty cache", timed(ROCKSTUDY + ["compile"], cold, tmp))
        print(f"load average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
