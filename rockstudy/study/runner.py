"""Run a study on dask: chunks of samples as tasks, results streamed into the zarr cube.

The client makes the design, writes the template, submits the pending chunks with a bounded
number in flight, and writes each result into its region as it completes (``as_completed``).
Losing a worker loses nothing: the scheduler reruns its task elsewhere. Killing the run loses
nothing finished: ``resume=True`` computes only the chunks whose status is still pending.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import store
from ._warmup import prime_study
from .evaluate import STATUS_FAILED, evaluate_chunk
from .sampling import make_design
from .spec import Study


@dataclass
class RunReport:
    """What a run did."""

    path: Path
    samples: int
    chunks_total: int
    chunks_computed: list = field(default_factory=list)
    failed_samples: int = 0
    seconds: float = 0.0
    netcdf: Path | None = None


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


def _prime(study_json, columns, base_dir, progress):
    """Compile the study's kernels in this process, once, before the workers start: they then
    load them from numba's cache instead of each compiling them (see :mod:`._warmup`)."""

    def say(text):
        if progress:
            sys.stderr.write(text)
            sys.stderr.flush()

    r = prime_study(
        study_json,
        columns,
        base_dir,
        lambda: say("compiling the numba kernels (once per install; `rockstudy compile`) ..."),
    )
    if r["compiled"]:
        say(f" done in {r['seconds']:.1f} s\n")


def _client(workers=None, scheduler=None, scheduler_file=None):
    from distributed import Client, LocalCluster

    if scheduler is not None:
        return Client(scheduler), None
    if scheduler_file is not None:
        return Client(scheduler_file=str(scheduler_file)), None
    cluster = LocalCluster(
        n_workers=workers or 2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    return Client(cluster), cluster


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
) -> RunReport:
    """Run ``study`` into the zarr store ``out`` (opened later with ``xarray.open_zarr``).

    Parameters
    ----------
    workers : int, optional
        Size of the local cluster (default 2 processes of one thread).
    scheduler, scheduler_file : optional
        Join an existing cluster by address or scheduler file instead.
    resume : bool
        Continue a killed run: compute only the chunks still pending in ``out``.
    base_dir : path, optional
        Where relative record paths may also be found (the study file's folder).
    netcdf : bool
        Also write ``out`` with the suffix ``.nc`` at the end.
    client : distributed.Client, optional
        Use this client (for tests and notebooks).
    """
    t0 = time.perf_counter()
    out = Path(out)
    design = make_design(study)
    n = design.sizes["sample"]
    bounds = store.chunk_bounds(n, study.chunk_size)
    template = None
    if out.exists() and not resume:
        raise FileExistsError(f"{out} exists: pass resume=True (--resume) or a new path")
    if out.exists() and store.template_complete(out):
        if store.study_sha256(out) != study.sha256():
            raise ValueError(f"{out} holds a different study (sha256 mismatch); cannot resume")
        todo = store.pending_chunks(out, study.chunk_size)
    else:  # new, or killed while its template was written: nothing finished yet

        def template():
            store.create_store(out, design, study, overwrite=True)

        todo = bounds
    report = RunReport(out, n, len(bounds))
    cols_names = [name for name, v in design.data_vars.items() if v.dims == ("sample",)]
    columns = {name: design[name].values for name in cols_names}
    columns["sample"] = design["sample"].values
    study_json = study.normalized()
    own = client is None
    cluster = None
    if todo:
        _prime(study_json, columns, base_dir, progress)
    if own and todo:
        client, cluster = _client(workers, scheduler, scheduler_file)
    bar = _Progress(len(todo), progress)
    try:
        if todo:
            _execute(client, todo, columns, study_json, base_dir, out, report, bar, template)
        elif template is not None:
            template()
    finally:
        if own and client is not None:
            client.close()
            if cluster is not None:
                cluster.close()
    status = store.read_status(out)
    report.failed_samples = int(np.count_nonzero(status == STATUS_FAILED))
    if netcdf:
        report.netcdf = store.export_netcdf(out, out.with_suffix(".nc"))
    report.seconds = time.perf_counter() - t0
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
