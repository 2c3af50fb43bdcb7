"""Time to first result (issue 14): ``import rockstudy``, the first ``simulate()`` of a new
process, and the quickstart study, each in fresh subprocesses.

    python benchmarks/bench_first_result.py            # this checkout, after `make setup`
    python benchmarks/bench_first_result.py --cold     # a fresh clone of HEAD, from nothing

Wall times depend on the load of the machine (printed at the start and at the end); the CPU
time (user + sys of the process and its children: the dask workers, the second compile
process) is printed next to them. Rows timed more than once give the median of ``--repeat``.

``--cold`` clones HEAD (committed code only) into a temporary folder and runs it with
NUMBA_CACHE_DIR unset, so numba's cache starts empty in the clone's ``__pycache__``: the
quickstart study with the compile it needs included (a new user who skipped the set-up),
then, with the cache emptied again, ``rockstudy compile`` (the set-up's step), then the first
``simulate()`` of a new process and the quickstart study after it.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

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


def median(command, env, cwd, repeat):
    """The medians of wall and CPU over ``repeat`` runs of ``command(i)``, run i's command."""
    runs = [timed(command(i), env, cwd) for i in range(repeat)]
    return statistics.median(w for w, _ in runs), statistics.median(c for _, c in runs)


def row(label, wall_cpu, target=None):
    wall, cpu = wall_cpu
    goal = f"   (target < {target:g} s)" if target else ""
    print(f"{label:58s} {wall:7.2f} s wall {cpu:7.2f} s CPU{goal}", flush=True)


def load():
    return "load average " + " ".join(f"{x:.1f}" for x in os.getloadavg())


def quickstart(root, out):
    """The command of the quickstart study of the checkout ``root`` into ``out``."""
    toml = Path(root) / "studies" / "quickstart.toml"
    return [sys.executable, "-m", "rockstudy.cli", "run", str(toml), "--quiet", "--out", str(out)]


def compile_cmd():
    return [sys.executable, "-m", "rockstudy.cli", "compile"]


def after_setup(env, cwd, root, repeat, tmp):
    """The rows of a primed cache: the first simulate() of a new process, the quickstart."""
    py = [sys.executable]
    row("import rockstudy", median(lambda i: [*py, "-c", "import rockstudy"], env, cwd, repeat))
    row(
        "first simulate() of a new process, after set-up",
        median(lambda i: [*py, "-c", FIRST_SIMULATE], env, cwd, repeat),
        2.0,
    )
    row(
        "quickstart study alone, after set-up",
        median(lambda i: quickstart(root, Path(tmp) / f"warm{i}.zarr"), env, cwd, repeat),
    )


def clear_numba_cache(root):
    """Delete numba's cache files (and the warm-up's stamp) under ``root``."""
    for path in Path(root).rglob("__pycache__"):
        shutil.rmtree(path)


def cold(env, repeat, tmp):
    """The rows of a fresh clone of HEAD, from an empty cache."""
    clone = Path(tmp) / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    head = subprocess.run(
        ["git", "-C", str(clone), "log", "-1", "--format=%h %s"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    print(f"fresh clone of {head[:70]}")
    env = dict(env, PYTHONPATH=str(clone))
    clear_numba_cache(clone)
    row(
        "quickstart study from a fresh clone, compile included",
        timed(quickstart(clone, Path(tmp) / "cold.zarr"), env, tmp),
        20.0,
    )
    clear_numba_cache(clone)
    row("rockstudy compile, cold (the set-up's step)", timed(compile_cmd(), env, tmp))
    after_setup(env, tmp, clone, repeat, tmp)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cold", action="store_true", help="a fresh clone, from nothing")
    parser.add_argument("--repeat", type=int, default=3, help="runs of the timings after set-up")
    args = parser.parse_args()
    env = dict(os.environ)
    env.pop("NUMBA_CACHE_DIR", None)
    print(f"rockstudy at {ROOT}; {os.cpu_count()} CPUs; {load()}")
    with tempfile.TemporaryDirectory() as tmp:
        if args.cold:
            cold(env, args.repeat, tmp)
        else:
            path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
            env["PYTHONPATH"] = path
            row("rockstudy compile (no-op if the cache is primed)", timed(compile_cmd(), env, tmp))
            after_setup(env, tmp, ROOT, args.repeat, tmp)
    print(f"at the end: {load()}")


if __name__ == "__main__":
    main()
