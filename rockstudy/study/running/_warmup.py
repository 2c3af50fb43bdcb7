"""Compile the numba kernels once per install: ``rockstudy compile`` (``make setup`` runs it).

Every kernel is decorated ``cache=True``, so numba keeps its machine code next to the source
(``__pycache__/*.nbi``, ``*.nbc``) and a new process, or a dask worker, loads it in
milliseconds instead of compiling it again (about 10 s for ``simulate`` alone, 200 s of CPU for
everything). The index of each source file is keyed by that file's modification time and
size: editing a module recompiles only its kernels. :func:`compile_kernels` drives every
kernel through the public entry points with small inputs, so the signatures it leaves in the
cache are the ones ``simulate``, ``simulate_batch``, the closed forms and studies use (a
kernel compiled for other argument types would be compiled again on first use).

numba checks only the file of each kernel: a kernel that calls (or inlines) a kernel of another
file, or reads a constant of ``constants.py``, keeps its stale machine code when only that other
file changes. So the warm-up also fingerprints every source file that holds kernels or their
constants, and clears the package's numba cache when the fingerprint has changed since the last
warm-up (:func:`purge_stale_cache`).

The warm-up compiles its groups of kernels (:data:`GROUPS`) in a pool of processes, one per
core, the kernels of ``make demo`` first. numba saves a function's cache index without a lock
(two processes compiling different signatures of one shared helper could lose an entry or map
one signature to the other's machine code): the pool's processes lock each save
(:func:`rockstudy._numba_cache.serialize_cache_writes`).

``python -m rockstudy.study.running._warmup`` does the same as ``rockstudy compile``.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import time
import warnings
from pathlib import Path

import numpy as np

from ...constants import G

PACKAGE = Path(__file__).resolve().parents[2]
STAMP = "numba-sources.sha256"
_USES_NUMBA = re.compile(r"^(from numba import|import numba$)", re.MULTILINE)


def _kernel_sources(root):
    """The source files whose code or constants numba compiles into the kernels."""
    return sorted(
        path
        for path in Path(root).rglob("*.py")
        if path.name == "constants.py" or _USES_NUMBA.search(path.read_text())
    )


def purge_stale_cache(root=PACKAGE) -> int:
    """Delete numba's cache files under ``root`` if its kernel sources changed since the last
    call (a fingerprint in ``root/__pycache__``); returns how many were deleted.

    Does nothing when NUMBA_CACHE_DIR moves the cache elsewhere.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return 0
    digest = hashlib.sha256()
    for path in _kernel_sources(root):
        digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes())
    stamp = Path(root) / "__pycache__" / STAMP
    if stamp.exists() and stamp.read_text() == digest.hexdigest():
        return 0
    stale = [f for ext in ("nbi", "nbc") for f in Path(root).rglob(f"__pycache__/*.{ext}")]
    for path in stale:
        path.unlink(missing_ok=True)
    stamp.parent.mkdir(exist_ok=True)
    stamp.write_text(digest.hexdigest())
    return len(stale)


class _CompileCounter:
    """Counts numba dispatcher compilations (cache misses); calls ``on_first`` at the first."""

    def __init__(self, on_first=None):
        self.count, self.on_first = 0, on_first

    @contextlib.contextmanager
    def listening(self):
        from numba.core import event

        class _Listener(event.Listener):
            def on_start(_, ev):
                if self.count == 0 and self.on_first is not None:
                    self.on_first()
                self.count += 1

            def on_end(_, ev):
                pass

        with event.install_listener("numba:compile", _Listener()):
            yield self


def _with_vertical(record):
    """``record`` with a small vertical component on its samples (a third of it, upwards)."""
    from ...motions import Record

    return Record(record.acceleration, dt=record.dt, vertical=record.acceleration / 3.0)


def _simulate_calls():
    """One small call of every method of :func:`rockstudy.simulate` on a record and a pulse
    (also one with a vertical component, on the same kernel signatures). The record first:
    its general scene compiles here while the demo's group compiles the sine pulses' scene
    in the other process, which this group then loads from the cache."""
    from ...dynamics import simulate
    from ...motions import RickerWavelet, SinePulse, stochastic_record
    from ...structures import Block, PointMassStrut

    alpha = 0.2
    block = Block(1.0, alpha)
    pulse = SinePulse(3.0 * G * math.tan(alpha), 0.5)
    record = stochastic_record(peak=3.0 * G * math.tan(alpha), duration=2.0, dt=0.01, seed=0)
    for motion in (record, RickerWavelet(3.0 * G * math.tan(alpha), 0.5), pulse):
        motion.ground_acceleration(np.linspace(0.0, 1.0, 3))
        for method in ("nonlinear", "linear", "auto"):
            simulate(block, motion, method=method)
        simulate(block, motion, method="complex", initial_rotation=0.5 * alpha, t_max=0.05)
    for method in ("nonlinear", "linear", "auto"):
        simulate(block, _with_vertical(record), method=method)
    simulate(PointMassStrut(1.0, alpha), pulse)  # the mechanism (tabulated) kernel
    simulate(PointMassStrut(1.0, alpha), _with_vertical(record))


@contextlib.contextmanager
def _threads(n=None):
    """numba's kernels on ``n`` threads (all if None) while the block runs."""
    import numba

    threads = numba.get_num_threads()
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS if n is None else n)
    try:
        yield
    finally:
        numba.set_num_threads(threads)


def _batch_calls(methods=("nonlinear", "linear", "auto")):
    """:func:`rockstudy.simulate_batch` on pulses and on a record, for each of ``methods``,
    in parallel and on one thread (a study's workers run the serial kernels)."""
    import numba

    for n in sorted({numba.get_num_threads(), 1}):
        with _threads(n):
            _batch_calls_of(methods)


def _batch_calls_of(methods):
    """:func:`_batch_calls` on the current number of threads."""
    from ...dynamics import simulate_batch
    from ...motions import stochastic_record

    alpha = np.array([0.15, 0.2])
    peak = 3.0 * G * np.tan(alpha)
    record = stochastic_record(peak=1.0, duration=2.0, dt=0.01, seed=0)
    for method in methods:
        common = dict(half_diagonal=1.0, slenderness=alpha, method=method)
        for shape in ("sine", "ricker"):
            simulate_batch(pulse=shape, amplitude=peak, period=0.5, **common)
        simulate_batch(record=record, scale=peak, **common)
        simulate_batch(record=_with_vertical(record), scale=peak, **common)


def _record_measure_calls():
    """Intensity measures, spectrum and pulse of a record (studies store them per record),
    a floor motion (a study on a floor replaces each record by one), and the RotD measures
    of a pair of components."""
    from ...motions import Building, Record, floor_motion, synthetic_near_fault

    record = synthetic_near_fault(pulse_period=1.0, pga=3.0, seed=0, duration=4.0)
    floor_motion(record, Building.uniform_shear(2, 0.5, 0.05), 1)
    pair = Record(record.acceleration, acceleration_y=record.acceleration[::-1], dt=record.dt)
    pair.intensity_measure("sa_rotd50", period=0.5)
    pair.intensity_measure("pga_rotd100")
    record.intensity_measures(periods=[0.5, 1.0])
    record.response_spectrum([0.5, 1.0])
    record.pulse()


def _closedform_calls():
    """Every ufunc of :mod:`rockstudy.closedform.sine`, and the boundary-curve kernel."""
    from ...closedform import overturning_boundary, sine

    names = sine.build_all()
    sine.overturning_mode(np.array([2.0]), np.array([1.0]), np.array([0.9]))
    overturning_boundary(np.array([1.0]), 0.9, "1.2", n_grid=8)
    return names


def _demo_calls():
    """What ``make demo`` runs: the quickstart study's batch kernel (sine pulses, one thread, as
    a dask worker runs it) and the demo's :func:`rockstudy.simulate` of a block under a sine
    pulse by each method it shows, with dense output."""
    from ...dynamics import simulate, simulate_batch
    from ...motions import SinePulse
    from ...structures import Block

    alpha = np.array([0.15, 0.2])
    with _threads(1):
        simulate_batch(
            half_diagonal=1.0, slenderness=alpha, pulse="sine", amplitude=9.0, period=0.5
        )
    block = Block.from_dimensions(width=0.5, height=2.0)
    pulse = SinePulse(1.5 * G * math.tan(block.slenderness), 0.6)
    for method in ("nonlinear", "linear", "scipy"):
        simulate(block, pulse, method=method, t_eval=np.linspace(0.0, 0.5, 3))


def _batch_calls_parallel():
    """:func:`_batch_calls_of` on every thread (the parallel batch kernels)."""
    with _threads():
        _batch_calls_of(("nonlinear", "linear", "auto"))


def _batch_calls_serial():
    """:func:`_batch_calls_of` on one thread (the kernels a study's workers run)."""
    with _threads(1):
        _batch_calls_of(("nonlinear", "linear", "auto"))


def _two_body_calls():
    """:func:`rockstudy.simulate_batch` of a statue on a plinth and of a block on an isolator
    (linear and friction pendulum) under a pulse and a record, in parallel and on one thread
    (their kernels: :mod:`rockstudy.dynamics.two_body_batch`)."""
    import numba

    from ...dynamics import simulate_batch
    from ...motions import stochastic_record
    from ...structures import Block, IsolatedBlock, StackedBlocks

    statue = Block(0.5, 0.2)
    systems = (
        StackedBlocks(Block(1.0, 0.4), statue),
        IsolatedBlock(statue, base_mass_ratio=1.0, period=2.0, damping=0.1),
        IsolatedBlock(statue, 1.0, isolator="friction_pendulum", radius=2.0, friction=0.05),
    )
    record = stochastic_record(peak=3.0, duration=2.0, dt=0.01, seed=0)
    for n in sorted({numba.get_num_threads(), 1}):
        with _threads(n):
            for system in systems:
                simulate_batch(structure=system, amplitude=[2.0, 6.0], period=0.5)
                simulate_batch(structure=system, record=record, scale=[1.0, 2.0])


#: The warm-up's groups of calls (``rockstudy compile --group NAME``); :data:`START_ORDER`
#: gives the order they start in.
GROUPS = {
    "demo": _demo_calls,
    "simulate": _simulate_calls,
    "batch-parallel": _batch_calls_parallel,
    "batch-serial": _batch_calls_serial,
    "records": _record_measure_calls,
    "closedforms": _closedform_calls,  # a sampled study's report draws the closed forms
    "two-body": _two_body_calls,
}

#: The order the groups start in, each in the first free process of the pool. The two scene
#: kernels (sine pulses; every other motion) take most of the compile (about 90 s of CPU
#: each, in their phase loop): ``demo`` compiles the first, ``simulate`` the second, side
#: by side; the groups that need neither (records, closed forms, two-body) follow, and the
#: batch groups, which call both scenes, start last and load them from the cache. The batch
#: groups started while a scene was still compiling in the other process compiled it a second
#: time (numba shares nothing but the cache between processes).
START_ORDER = (
    "demo",
    "simulate",
    "records",
    "closedforms",
    "two-body",
    "batch-parallel",
    "batch-serial",
)


def _all_calls():
    """Every call of the warm-up, in one process."""
    for calls in GROUPS.values():
        calls()


def _count_compiled(calls, on_first_compile=None) -> int:
    """Run ``calls()`` (warnings silenced); return how many dispatchers it compiled."""
    with _CompileCounter(on_first_compile).listening() as counter, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        calls()
    return counter.count


_FIRST_COMPILE = None  # in a pool process: the event set at its first compilation


def _pool_init(first_compile):
    """Initializer of a warm-up pool process: locked cache saves, and the shared event."""
    from ..._numba_cache import serialize_cache_writes

    global _FIRST_COMPILE
    _FIRST_COMPILE = first_compile
    serialize_cache_writes()


def _run_group(name):
    """Run the group ``name`` of :data:`GROUPS` in a pool process: (compiled, CPU seconds)."""
    c0 = time.process_time()
    compiled = _count_compiled(GROUPS[name], _FIRST_COMPILE.set)
    return compiled, time.process_time() - c0


def _cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def _compile_in_pool(processes, on_first_compile, names) -> dict:
    """The groups of :data:`GROUPS` in a pool of ``processes`` spawned processes, in order;
    ``on_first_compile`` called here once a process has started compiling."""
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    ctx = multiprocessing.get_context("spawn")  # no fork of a process with numba's threads
    first = ctx.Event()
    told = on_first_compile is None
    with ProcessPoolExecutor(processes, ctx, initializer=_pool_init, initargs=(first,)) as pool:
        futures = {pool.submit(_run_group, name): name for name in names}
        pending = set(futures)
        while pending:
            _, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
            if not told and first.is_set():
                told = True
                on_first_compile()
        return {futures[f]: f.result() for f in futures}


def compile_kernels(on_first_compile=None, processes=None, groups=None) -> dict:
    """Compile every numba kernel signature the package uses, or load it from numba's cache.

    Parameters
    ----------
    on_first_compile : callable, optional
        Called with no argument when the first kernel has to be compiled (not found in the
        cache), e.g. to tell the user why the wait.
    processes : int, optional
        Processes that compile the groups of :data:`GROUPS` in parallel (the kernels of ``make
        demo`` first); default one per core, at most one per group; 1 compiles in this process.
    groups : sequence of str, optional
        Only these groups of :data:`GROUPS` (default all), e.g. ``["closedforms"]`` while a
        study runs, before its report.

    Returns
    -------
    dict
        ``compiled``: dispatchers compiled now (0 when the cache was already primed);
        ``seconds``: wall time [s]; ``groups``: for each group, (compiled, CPU seconds of its
        process).
    """
    names = list(GROUPS) if groups is None else list(groups)
    unknown = [g for g in names if g not in GROUPS]
    if unknown or not names:
        raise ValueError(f"groups = {groups!r}: give names among {list(GROUPS)}")
    names.sort(key=START_ORDER.index)
    t0 = time.perf_counter()
    purge_stale_cache()
    n = min(len(names), _cores()) if processes is None else int(processes)
    if n < 1:
        raise ValueError(f"processes = {processes!r}: give a positive number of processes")
    if n == 1:
        groups = {}
        for name in names:
            c0 = time.process_time()
            groups[name] = (
                _count_compiled(GROUPS[name], on_first_compile),
                time.process_time() - c0,
            )
            if groups[name][0]:
                on_first_compile = None  # told once
    else:
        groups = _compile_in_pool(n, on_first_compile, names)
    compiled = sum(count for count, _ in groups.values())
    return {"compiled": compiled, "seconds": time.perf_counter() - t0, "groups": groups}


def prime_study(study_json: str, columns: dict, base_dir=None, on_first_compile=None) -> dict:
    """Put the kernels of a study in numba's cache before the dask workers start, so that they
    load them instead of each compiling them: the study's first rows run in this process (its
    kernels, with its argument types), and for ``method="auto"``, whose rows choose their model
    by their values, the batch kernels of both models.

    Returns the dict of :func:`compile_kernels` for this step.
    """
    import numba

    from .evaluate import evaluate_chunk

    t0 = time.perf_counter()
    purge_stale_cache()
    threads = numba.get_num_threads()
    head = {k: v[:2] for k, v in columns.items()}
    try:
        with _CompileCounter(on_first_compile).listening() as counter:
            evaluate_chunk(study_json, head, base_dir)
            if json.loads(study_json)["run"]["method"] == "auto":
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    _batch_calls(("linear", "nonlinear", "auto"))
    finally:
        numba.set_num_threads(threads)  # evaluate_chunk pins one thread for the workers
    return {"compiled": counter.count, "seconds": time.perf_counter() - t0}


def main(groups=None) -> int:
    """``rockstudy compile [--group NAME ...]``: prime numba's cache and say what it did."""
    import sys

    count = len(GROUPS) if groups is None else len(groups)

    def note():
        print(
            f"compiling the numba kernels (once per install) in {min(count, _cores())} "
            "processes ...",
            flush=True,
        )

    r = compile_kernels(note, groups=groups)
    what = f"compiled {r['compiled']} kernels" if r["compiled"] else "all kernels were cached"
    print(f"rockstudy kernels ready: {what} in {r['seconds']:.1f} s", file=sys.stdout)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
