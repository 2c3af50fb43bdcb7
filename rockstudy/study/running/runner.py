"""Run a study on dask: chunks of samples as tasks, results streamed into the zarr cube.

The client makes the design, writes the template, submits the pending chunks with a bounded
number in flight, and writes each result into its region as it completes (``as_completed``).
Losing a worker loses nothing: the scheduler reruns its task elsewhere. Killing the run loses
nothing finished: ``resume=True`` computes only the chunks whose status is still pending.
"""

from __future__ import annotations

import errno
import json
import logging
import math
import multiprocessing
import re
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...motions.records import read_text_file
from ..designs.sampling import make_design
from ..spec.schema import Study
from . import store
from ._warmup import prime_study
from .evaluate import STATUS_FAILED, evaluate_chunk

__all__ = [
    "error_summary",
    "FailedSamplesError",
    "MAX_SCHEDULER_FILE_BYTES",
    "MAX_SCRIPT_BYTES",
    "out_of_memory",
    "ResourceError",
    "run_study",
    "RunReport",
    "SchedulerError",
]


@dataclass
class RunReport:
    """What a run did."""

    path: Path
    samples: int
    chunks_total: int
    chunks_computed: list = field(default_factory=list)
    failed_samples: int = 0
    seconds: float = 0.0
    #: Of ``seconds``, those spent compiling the study's numba kernels (0 when cached).
    compile_seconds: float = 0.0
    netcdf: Path | None = None
    damaged_chunks: list = field(default_factory=list)
    errors: dict = field(default_factory=dict)


class _Progress:
    """A one-line progress bar with an ETA on stderr."""

    def __init__(self, total, enabled):
        self.total, self.done, self.enabled, self.t0 = total, 0, enabled, time.perf_counter()

    def step(self, k=1):
        self.done += k
        if not self.enabled:
            return
        el = time.perf_counter() - self.t0
        eta = el / self.done * (self.total - self.done) if self.done else float("nan")
        bar = "#" * int(30 * self.done / max(self.total, 1))
        sys.stderr.write(
            f"\r[{bar:<30s}] {self.done}/{self.total} chunks, {el:6.1f} s, ETA {eta:6.1f} s"
        )
        if self.done == self.total:
            sys.stderr.write("\n")
        sys.stderr.flush()


def _imported(plain_numbers=False) -> None:
    """A worker that runs it has imported this module and the engine's (no kernel); with
    ``plain_numbers`` (a worker of our own local cluster) numpy scalars in its messages read
    as numbers (``-13.45``, not ``np.float64(-13.45)``)."""
    if plain_numbers:
        np.set_printoptions(legacy="1.25")


def _close(client, cluster):
    client.close()
    if cluster is not None:
        cluster.close()


class _Priming(threading.Thread):
    """:func:`_prime` in a thread (a daemon: Ctrl-C need not wait for the compiler); its
    exception, if any, in ``error``."""

    def __init__(self, *args):
        super().__init__(daemon=True, name="rockstudy-prime")
        self.args, self.error, self.seconds = args, None, 0.0

    def run(self):
        try:
            self.seconds = _prime(*self.args)
        except BaseException as exc:  # noqa: BLE001 - raised again in the calling thread
            self.error = exc


def _start_prime(study_json, columns, base_dir, progress) -> _Priming:
    """Start compiling the study's kernels in a thread of this process (see :func:`_prime`),
    so that the local cluster can start meanwhile on the other core."""
    thread = _Priming(study_json, columns, base_dir, progress)
    thread.start()
    return thread


def _prime(study_json, columns, base_dir, progress):
    """Compile the study's kernels in this process, once, before the workers start: they then
    load them from numba's cache instead of each compiling them (see :mod:`._warmup`);
    returns the seconds it compiled (0 when all were cached)."""

    def say(text):
        if progress:
            sys.stderr.write(text)
            sys.stderr.flush()

    r = prime_study(
        study_json,
        columns,
        base_dir,
        lambda: say(
            "compiling the numba kernels this study needs (once: they are cached; "
            "`rockstudy compile` does them all) ..."
        ),
    )
    if r["compiled"]:
        say(f" done in {r['seconds']:.1f} s\n")
    return r["seconds"] if r["compiled"] else 0.0


_GUARD = (
    'put the call to run_study under `if __name__ == "__main__":` (dask starts its worker '
    "processes by importing the script again)"
)


class SchedulerError(RuntimeError):
    """The dask scheduler cannot be reached, or no worker joined it in time."""


class ResourceError(RuntimeError):
    """The run stopped for want of memory, or because worker processes died (were killed):
    not a fault of the study. A store whose template was not finished is removed; one with
    finished chunks is kept and can be resumed."""


#: What to try when a run runs out of memory.
_LESS_MEMORY = "give it more memory (a higher ulimit -v), fewer --workers or a smaller chunk_size"


def out_of_memory(exc: BaseException) -> bool:
    """Whether ``exc``, or an exception it was raised from or during, is this process running
    out of memory: a MemoryError, a thread that could not start, an allocation refused."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, MemoryError):
            return True
        if isinstance(exc, RuntimeError) and "can't start new thread" in str(exc):
            return True
        if isinstance(exc, OSError) and exc.errno == errno.ENOMEM:
            return True
        exc = exc.__cause__ or exc.__context__
    return False


def _resource_error(exc: BaseException) -> ResourceError | None:
    """``exc`` as a :class:`ResourceError` if it is a want of memory or a worker that died
    (dask's KilledWorker: a chunk whose workers died on it four times), else None."""
    from distributed import KilledWorker

    if out_of_memory(exc):
        return ResourceError(f"the run ran out of memory; {_LESS_MEMORY}")
    if isinstance(exc, KilledWorker):
        return ResourceError(
            "a chunk's dask worker processes died four times (killed, most often for want of "
            f"memory); {_LESS_MEMORY}"
        )
    return None


class FailedSamplesError(RuntimeError):
    """More samples failed than the run allows; the cube is complete and kept.

    ``report`` is the :class:`RunReport`, ``report.errors`` the distinct messages and counts.
    """

    def __init__(self, message, report):
        super().__init__(message)
        self.report = report


def _check_workers(workers) -> None:
    if workers is not None and (
        isinstance(workers, bool) or int(workers) != workers or workers < 1
    ):
        raise ValueError(f"workers: {workers!r} is not allowed; give a whole number >= 1")


#: Largest scheduler file read [bytes] (dask writes a few hundred).
MAX_SCHEDULER_FILE_BYTES = 2**16


def _scheduler_address(scheduler_file, timeout) -> str:
    """The address in a dask scheduler file, waiting up to ``timeout`` seconds for the file to
    appear (a scheduler that is starting writes it); SchedulerError if it does not, or if it is
    not a scheduler file."""
    path = Path(scheduler_file)
    deadline = time.monotonic() + timeout
    while not path.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    if not path.exists():
        raise SchedulerError(
            f"the scheduler file {path} does not exist (waited {timeout:g} s): start the "
            "scheduler with --scheduler-file, or check the path"
        )
    what = "a dask scheduler file (a JSON object whose 'address' is like tcp://HOST:PORT)"
    try:  # a regular file of bounded size: a pipe would hang, a device fill the memory
        text = read_text_file(path, MAX_SCHEDULER_FILE_BYTES)
    except (OSError, ValueError) as exc:
        raise SchedulerError(f"{exc}, so not {what}") from None
    try:
        address = json.loads(text)["address"]
        if not isinstance(address, str) or "://" not in address:
            raise TypeError
    except (ValueError, KeyError, TypeError):
        raise SchedulerError(f"{path} is not {what}") from None
    return address


def _remote_client(scheduler, scheduler_file, security, timeout):
    """A client of a running cluster that has at least one worker, or SchedulerError."""
    from distributed import Client

    where = scheduler or f"the scheduler file {scheduler_file}"
    if scheduler is None:
        scheduler = _scheduler_address(scheduler_file, timeout)
    kw = {"timeout": timeout} if security is None else {"timeout": timeout, "security": security}
    try:
        client = Client(scheduler, **kw)
    except (OSError, TimeoutError) as exc:
        raise SchedulerError(
            f"cannot reach the dask scheduler at {where} within {timeout:g} s ({exc})"
        ) from None
    except (TypeError, ValueError) as exc:  # distributed's word for missing TLS credentials
        tls = "tls" in str(exc).lower() or "ssl" in str(exc).lower()
        raise SchedulerError(
            f"cannot connect to the dask scheduler at {where}: "
            + (
                "a tls:// scheduler needs certificates: give --tls-ca-file, --tls-cert and "
                "--tls-key (or set distributed.comm.tls in dask's configuration)"
                if tls
                else f"{type(exc).__name__}: {' '.join(str(exc).split())}"
            )
        ) from None
    try:
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:
        client.close()
        raise SchedulerError(
            f"no worker joined the dask scheduler at {where} within {timeout:g} s: start "
            "workers on it (dask worker ADDRESS) or check the address"
        ) from None
    return client


#: dask's statistical profiler samples every thread's frames (``sys._current_frames``) from
#: a thread of its own, which can crash CPython 3.11 when a sampled thread's frame goes away
#: under it (a segmentation fault in ``distributed/profile.py``, seen in the tests' in-process
#: cluster); it feeds only the dashboard's profile page, which rockstudy's clusters do not
#: serve, and sees nothing inside the numba kernels: it is off.
NO_PROFILER = {"distributed.worker.profile.enabled": False}


def _local_cluster(workers):
    """A local cluster on loopback, without a dashboard, whose workers ignore Ctrl-C (the
    client handles it: one message, then the cluster is closed)."""
    import signal
    import threading

    import dask
    from distributed import LocalCluster

    main_thread = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main_thread else None
    try:
        # no HTTP routes anywhere: the scheduler's and the workers' servers (which dask always
        # starts) answer 404 to everything, /metrics and /health included
        routes = {"distributed.scheduler.http.routes": [], "distributed.worker.http.routes": []}
        with dask.config.set({**routes, **NO_PROFILER}):
            return LocalCluster(
                n_workers=workers or 2,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",  # an HTTP server always starts: no routes
                scheduler_kwargs={"dashboard": False},
                # a stopped run prints one line, not its workers': a worker whose heartbeat
                # meets the scheduler already closed (a run ending on an error) logs that at
                # ERROR with a traceback; the run reports what failed itself
                silence_logs=logging.CRITICAL,
            )
    except Exception as exc:  # noqa: BLE001 - reported in one sentence, with its cause
        cause = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
        if _unguarded_script():
            raise RuntimeError(
                f"the local dask cluster did not start ({cause}); if you called run_study "
                f"from a script, {_GUARD}"
            ) from None
        raise ResourceError(
            f"the local dask cluster did not start ({cause}): a worker process died while it "
            f"started (killed, or out of memory); {_LESS_MEMORY}"
        ) from None
    finally:
        if main_thread:
            signal.signal(signal.SIGINT, old)


def _unguarded_script() -> bool:
    """Whether the program is a Python script without an ``if __name__ == "__main__":``
    guard, which dask's worker processes import again (run_study then refuses to run in
    them): the one cause of a local cluster that does not start that its author can fix."""
    path = getattr(sys.modules.get("__main__"), "__file__", None)
    if path is None:  # interactive, a notebook: nothing is imported again
        return False
    try:
        text = read_text_file(path, MAX_SCRIPT_BYTES)
    except (OSError, ValueError):
        return False
    return not re.search(r"__name__\s*==\s*['\"]__main__['\"]", text)


#: Largest script read to see whether it guards its run_study call [bytes].
MAX_SCRIPT_BYTES = 2**20


def _client(workers=None, scheduler=None, scheduler_file=None, security=None, timeout=60.0):
    from distributed import Client

    if scheduler is not None or scheduler_file is not None:
        return _remote_client(scheduler, scheduler_file, security, timeout), None
    cluster = _local_cluster(workers)
    return Client(cluster), cluster


def error_summary(path) -> dict:
    """Distinct error messages of the failed samples of a store, with their counts."""
    from collections import Counter

    import xarray as xr

    ds = xr.open_zarr(Path(path), consolidated=True)
    failed = ds["status"].values == STATUS_FAILED
    messages = ds["error"].values[failed]
    text = (m.decode("utf-8", "replace") if isinstance(m, bytes) else str(m) for m in messages)
    return dict(Counter(text).most_common())


def run_study(
    study: Study,
    out,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    scheduler_file=None,
    resume: bool = False,
    base_dir=None,
    progress: bool = True,
    netcdf: bool = True,
    client=None,
    overwrite: bool = False,
    max_failed: float = 0.0,
    security=None,
    timeout: float = 60.0,
) -> RunReport:
    """Run ``study`` into the zarr store ``out`` (opened later with ``xarray.open_zarr``).

    Parameters
    ----------
    workers : int, optional
        Size of the local cluster (default 2 processes of one thread).
    scheduler, scheduler_file : optional
        Join an existing cluster by address (``tcp://`` or ``tls://``) or scheduler file.
    resume : bool
        Continue a killed run: compute only the chunks still pending in ``out``, and those
        marked done that do not read back whole. ``out`` must hold a store of the same study,
        input files and rockstudy version.
    base_dir : path, optional
        Where relative record paths may also be found (the study file's folder).
    netcdf : bool
        Also write ``out`` with the suffix ``.nc`` at the end.
    client : distributed.Client, optional
        Use this client (for tests and notebooks).
    overwrite : bool
        Let the netCDF export replace a file that is not an export of this study.
    max_failed : float
        Largest share of failed samples [0, 1] accepted; above it :class:`FailedSamplesError`
        is raised after the cube is complete (default 0: any failed sample).
    security : distributed.Security, optional
        TLS credentials for a ``tls://`` scheduler (default: dask's configuration).
    timeout : float
        Seconds to wait for a remote scheduler to answer and for its first worker [s].

    Raises
    ------
    ResourceError
        The run ran out of memory, or its worker processes died (while the local cluster
        started, or four times on one chunk). A store whose template was not finished is
        removed; one with finished chunks is kept for ``resume=True``.
    SchedulerError
        The remote scheduler was not reached, or no worker joined it in time.
    FailedSamplesError
        More samples failed than ``max_failed`` allows (the cube is complete and kept).
    """
    if getattr(multiprocessing.current_process(), "_inheriting", False):
        # a process being spawned (a worker of the local cluster) imports the user's script,
        # as multiprocessing's own check (spawn._check_not_importing_main) sees it: leave
        raise SystemExit(f"rockstudy: run_study ran again as a dask worker started: {_GUARD}")
    t0 = time.perf_counter()
    out = Path(out)
    _check_workers(workers)
    if isinstance(timeout, bool) or not (isinstance(timeout, (int, float)) and timeout > 0):
        raise ValueError(f"timeout: {timeout!r} is not allowed; give seconds > 0")
    if not math.isfinite(timeout):
        raise ValueError(f"timeout: {timeout!r} is not allowed; give a finite number of seconds")
    if not 0.0 <= max_failed <= 1.0:
        raise ValueError(f"max_failed: {max_failed!r} is not a share in [0, 1]")
    nc = out.with_suffix(".nc") if netcdf else None
    if nc == out:
        raise ValueError(f"out: {out} ends in .nc, the name of its netCDF export; use .zarr")
    design = make_design(study, base_dir)
    n = design.sizes["sample"]
    bounds = store.chunk_bounds(n, study.rows_per_chunk())
    inputs = store.input_hashes(study, base_dir)
    if nc is not None and not resume:  # refused before the folder is even created
        store.check_export_target(nc, study.sha256(), overwrite)
    lock, complete = store.claim(out, study, inputs, resume)
    try:
        if nc is not None and resume:  # after the store was found to hold this study
            store.check_export_target(nc, study.sha256(), overwrite)
        report = _run_locked(
            study,
            out,
            design,
            bounds,
            inputs,
            complete,
            base_dir,
            progress,
            client,
            (workers, scheduler, scheduler_file, security, timeout),
        )
        if nc is not None:
            report.netcdf = store.export_netcdf(out, nc)
    except BaseException as exc:
        if not complete:  # failed before its template was written: leave no trace
            _discard_unfinished(out, lock.made_folder, design, study)
        resource = _resource_error(exc)
        if resource is not None:
            raise resource from exc
        raise
    finally:
        lock.release()
    report.seconds = time.perf_counter() - t0
    if report.failed_samples > max_failed * n:
        raise FailedSamplesError(_failure_message(report, max_failed), report)
    return report


def _discard_unfinished(out, made_folder, design, study) -> None:
    """Remove what a run that stopped before its template was complete wrote in ``out``
    (nothing finished: its marker says so), and the folder if the run made it. A folder that
    holds files rockstudy did not write, or that cannot be cleared, is left for ``--resume``
    (which writes the template again)."""
    marker = store.read_marker(out)
    if marker is None or marker.get("template_complete"):
        return
    names = [*design.variables, *store.output_table(study), "status", "error"]
    try:
        store.clear_template(out, names)
        store.discard_if_unused(out, made_folder)
    except (store.StoreError, OSError, MemoryError):
        pass  # left as it is: --resume writes the template again


def _failure_message(report, max_failed) -> str:
    lines = [
        f"{report.failed_samples} of {report.samples} samples failed (allowed: "
        f"{max_failed:.0%}); the cube is kept in {report.path}. Errors:"
    ]
    for message, count in list(report.errors.items())[:10]:
        lines.append(f"  {count:8d} x {message}")
    if len(report.errors) > 10:
        lines.append(f"  ... and {len(report.errors) - 10} other messages")
    return "\n".join(lines)


def _run_locked(study, out, design, bounds, inputs, complete, base_dir, progress, client, where):
    """The run proper, while the store's lock is held."""
    if complete:
        pending, damaged = store.chunks_to_compute(out, design, study.rows_per_chunk())
        todo, template = sorted(pending + damaged), None
        if damaged:
            sys.stderr.write(
                f"note: {len(damaged)} chunk(s) of {out} marked done did not read back whole "
                "(missing or damaged files): computing them again\n"
            )
    else:  # new, or killed while its template was written: nothing finished yet

        def template():
            store.create_store(out, design, study, inputs)

        todo, damaged = bounds, []
    report = RunReport(out, design.sizes["sample"], len(bounds), damaged_chunks=damaged)
    cols_names = [name for name, v in design.data_vars.items() if v.dims == ("sample",)]
    columns = {name: design[name].values for name in cols_names}
    columns["sample"] = design["sample"].values
    study_json = study.normalized()
    own = client is None
    cluster = None
    if todo:
        remote = where[1] is not None or where[2] is not None
        if own and remote:  # reached (or refused in one line) before anything is compiled
            client = _client(*where)[0]
        priming = _start_prime(study_json, columns, base_dir, progress)
        if own and not remote:  # the local workers start while the client compiles
            client, cluster = _client(*where)
        try:
            if own:
                client.run(_imported, cluster is not None)
            priming.join()  # only then do the workers get a chunk: they load the kernels
            if priming.error is not None:
                raise priming.error
            report.compile_seconds = priming.seconds
        except BaseException:  # also Ctrl-C while the client compiles
            if own:
                _close(client, cluster)
            raise
    bar = _Progress(len(todo), progress)
    try:
        if todo:
            _execute(client, todo, columns, study_json, base_dir, out, report, bar, template)
        elif template is not None:
            template()
    finally:
        if own and client is not None:
            _close(client, cluster)
    status = store.read_status(out)
    report.failed_samples = int(np.count_nonzero(status == STATUS_FAILED))
    report.errors = error_summary(out) if report.failed_samples else {}
    return report


def _execute(client, todo, columns, study_json, base_dir, out, report, bar, template):
    """Submit the chunks, write the template while the first ones run, then write results."""
    from distributed import as_completed

    n_workers = max(1, len(client.nthreads()))
    in_flight = max(4, 3 * n_workers)
    pending = list(todo)
    futures = {}

    def submit(a, b):
        cols = {k: v[a:b] for k, v in columns.items()}
        fut = client.submit(
            evaluate_chunk,
            study_json,
            cols,
            base_dir,
            pure=False,
            retries=3,
            key=f"rockstudy-chunk-{a}-{b}-{time.time_ns()}",
        )
        futures[fut] = (a, b)
        return fut

    first = [submit(*pending.pop(0)) for _ in range(min(in_flight, len(pending)))]
    if template is not None:
        template()
    writer = store.ChunkWriter(out)
    seq = as_completed(first)
    for fut in seq:
        a, b = futures.pop(fut)
        result = fut.result()
        writer.write(a, b, result)
        report.chunks_computed.append((a, b))
        bar.step()
        if pending:
            seq.add(submit(*pending.pop(0)))
