"""The result cube: a zarr store written chunk by chunk, with a ``status`` written last.

The template (design, outputs filled with their fill values, ``status`` = 0 pending, every
chunk file written) is written first. Each finished chunk is written into its own region (zarr
chunks are aligned with the study's chunks, so no two writers ever share a zarr chunk) in three
stages (:class:`ChunkWriter`): its outputs; the sha256 of every file of the chunk, ``status``
included (encoded beforehand in a staging array), into ``.rockstudy-chunks/<k>``; and its
``status`` file, moved in by one rename. A chunk whose status reads done and whose files match
those sums is finished; one whose status reads pending is pending; anything else is damaged. A
killed run resumes from the pending chunks.

The store never destroys what it did not write. A run claims a folder only if it is new (or
empty: nothing in it but, at most, a lock file), and writes a marker file ``.rockstudy`` into
it first (the study's sha256, the sha256 of every input file, the package version, and whether
the template is complete). Only that marker identifies a store: a lock file never does, and a
store whose marker is lost is resumed only if its cube's own attributes pass the marker's
checks. A marker is believed only where it agrees with the cube: the same study and input
files as the cube's attributes, and no finished chunk if it says the template is unfinished.
A run holds an exclusive lock (``.rockstudy.lock``, ``fcntl.flock``, naming its PID and
host once the run is accepted) for its whole life: a second run on the same store is refused
at once, and the lock of a killed run vanishes with its process, so ``--resume`` after SIGKILL
just works. The template records the sha256 of ``.zmetadata`` and of the design's files; every
other metadata file must read as its copy in ``.zmetadata``. On resume a chunk marked done
whose files are missing or differ is computed again and metadata files are restored from
``.zmetadata``; a reader (:func:`open_result`, :func:`verify_cube`) refuses a cube whose files
differ.

This module writes the template (:func:`create_store`), finds the chunks a resume computes
(:func:`chunks_to_compute`) and opens a cube (:func:`open_result`); it is also where the
store's names are imported from. Each other concern is a module of its own: ``_files`` (what
they all share), ``_lock`` (the lock), ``_checksums`` (the chunk writer and the sums),
``_marker`` (the marker and claiming a folder), ``_verify`` (checking a cube) and ``export``
(the netCDF export).
"""

from __future__ import annotations

import contextlib
import json
import shutil
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from ...constants import STANDARD_GRAVITY, G
from ..spec.schema import Study
from ._checksums import (
    CHECKSUMS,
    DONE,
    TEMPLATE_SUMS,
    ChunkWriter,
    _chunk_finished,
    _ChunkDamage,
    _consolidated,
    _results_with_values,
    _status_chunks,
    chunk_bounds,
    read_template_sums,
    write_template_sums,
)
from ._files import StoreError, _write_json, file_sha256
from ._lock import LOCK, StoreLock
from ._marker import (
    _OWN,
    MARKER,
    STORE_FORMAT,
    claim,
    discard_if_unused,
    input_hashes,
    package_versions,
    read_marker,
    template_complete,
    write_marker,
)
from ._verify import DamagedCube, _metadata_differences, verify_cube, written_by_run
from .evaluate import OUTPUTS, STATUS_PENDING
from .export import check_export_target, export_netcdf

__all__ = [
    "CHECKSUMS",
    "DONE",
    "LOCK",
    "MARKER",
    "STORE_FORMAT",
    "TEMPLATE_SUMS",
    "ChunkWriter",
    "DamagedCube",
    "StoreError",
    "StoreLock",
    "check_export_target",
    "chunk_bounds",
    "chunks_to_compute",
    "claim",
    "clear_template",
    "create_store",
    "discard_if_unused",
    "export_netcdf",
    "file_sha256",
    "input_hashes",
    "open_result",
    "output_table",
    "package_versions",
    "read_marker",
    "read_status",
    "read_template_sums",
    "stop_zarr_io",
    "template_complete",
    "verify_cube",
    "write_marker",
    "write_template_sums",
    "written_by_run",
]


def clear_template(path, names) -> None:
    """Remove a partly written template from a folder this run owns (its marker says so).

    ``names`` are the entries a template writes; anything else in the folder was not written by
    rockstudy, so the folder is refused whole (StoreError) and nothing is removed.
    """
    path = Path(path)
    if read_marker(path) is None:
        raise StoreError(f"{path} has no rockstudy marker: refusing to clear it")
    allowed = set(names) | _OWN | {".zattrs", ".zgroup", ".zmetadata", CHECKSUMS, MARKER + ".tmp"}
    foreign = sorted(entry.name for entry in path.iterdir() if entry.name not in allowed)
    if foreign:
        shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
        raise StoreError(
            f"{path} holds {shown}, which rockstudy did not write: nothing was removed; move "
            "them away, or run into a new --out"
        )
    for entry in path.iterdir():
        if entry.name in _OWN:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


def create_store(path, design: xr.Dataset, study: Study, inputs: dict | None = None) -> None:
    """Write the template cube: design, outputs filled with their fill values, status pending.

    ``path`` is a folder this run claimed (:func:`claim`); anything a killed template left in
    it is cleared first. The marker's ``template_complete`` is set last.
    """
    import dask
    import dask.array as da
    import zarr

    table = output_table(study)
    clear_template(path, [*design.variables, *table, "status", "error"])
    n = design.sizes["sample"]
    size = min(study.rows_per_chunk(), n)
    ds = design.copy()

    def lazy(fill, dtype, extra=None):  # written chunk by chunk: never whole in memory
        if extra is None:
            return ("sample", da.full(n, fill, dtype=dtype, chunks=size))
        width = ds.attrs["ida_steps"] if extra == "step" else ds.sizes[extra]
        return (("sample", extra), da.full((n, width), fill, dtype=dtype, chunks=(size, width)))

    for name, (long_name, units, dtype, fill, extra) in table.items():
        ds[name] = lazy(fill, dtype, extra)
        ds[name].attrs.update(long_name=long_name, units=units)
    ds["status"] = lazy(STATUS_PENDING, np.int8)
    ds["status"].attrs.update(long_name="0 pending, 1 ok, 2 failed", units="1")
    ds.attrs.update(
        study=study.normalized(),
        study_sha256=study.sha256(),
        inputs_sha256=json.dumps(inputs or {}),
        study_name=study.name,
        study_text=study.source_text or "",
        seed=study.seed,
        chunk_size=study.chunk_size,
        versions=json.dumps(package_versions()),
        store_format=STORE_FORMAT,
        Conventions="CF-1.8",
        gravity=G,  # [m/s^2] the physics' g: p = sqrt(3 g / 4 R), uplift g tan(alpha)
        record_g_unit=STANDARD_GRAVITY,  # [m/s^2] the unit g of records read in g
    )
    chunks = {
        name: {"chunks": (size,) + var.shape[1:]}
        for name, var in ds.data_vars.items()
        if var.dims[:1] == ("sample",)
    }
    with dask.config.set(scheduler="threads"), _quiet_about_our_files():
        ds.to_zarr(  # every chunk file is written (status included): a lost one is known
            Path(path),
            mode="a",
            encoding=chunks,
            zarr_format=2,
            consolidated=False,
            write_empty_chunks=True,
        )
        group = zarr.open_group(str(path), mode="r+", zarr_format=2)
        error = group.create_array("error", shape=(n,), chunks=(size,), dtype=str, fill_value="")
        error.attrs.update(  # variable-length: messages are stored whole
            _ARRAY_DIMENSIONS=["sample"], long_name="error message of a failed sample", units="1"
        )
        group.attrs["template_complete"] = 1
        zarr.consolidate_metadata(str(path), zarr_format=2)
    write_template_sums(path, design.variables)
    write_marker(path, template_complete=True)


def output_table(study: Study) -> dict:
    """The per-sample outputs of a study: name -> (long_name, units, dtype, fill, extra
    dimension or None)."""
    if study.design is not None:
        from ..designs.record_rows import outputs

        return outputs(study)
    out = {name: (*OUTPUTS[name], None) for name in study.run.outputs}
    if study.motion.kind == "record":
        from ..designs.record_rows import sample_outputs

        out.update(sample_outputs(study))
    return out


@contextlib.contextmanager
def _quiet_about_our_files():
    """zarr warns about files it does not know while listing a folder: our marker and lock."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Object at .rockstudy", UserWarning)
        yield


def stop_zarr_io(timeout: float = 60.0) -> None:
    """Stop zarr's IO event loop and wait for its thread, before the process exits.

    zarr runs its IO on an event loop in a thread, and stops it at exit (``atexit``) by joining
    that thread for 0.2 s only, then closing the loop: on a busy machine the thread has not
    stopped yet and exit prints ``RuntimeError: Cannot close a running event loop``.
    This waits up to ``timeout`` seconds instead; zarr's own clean-up then has nothing left to
    do. Does nothing if zarr never started its loop.
    """
    import sys

    sync = sys.modules.get("zarr.core.sync")
    if sync is None:
        return
    with sync._get_lock():  # noqa: SLF001 - the lock zarr's own clean-up takes
        loop, thread = sync.loop[0], sync.iothread[0]
        if loop is None:
            return
        loop.call_soon_threadsafe(loop.stop)
        if thread is not None:
            thread.join(timeout)
        if loop.is_running():  # still stuck after the timeout: left to zarr's clean-up
            return
        loop.close()
        sync.loop[0] = sync.iothread[0] = None


def read_status(path) -> np.ndarray:
    """The per-sample status array of a store (0 pending, 1 ok, 2 failed)."""
    return xr.open_zarr(Path(path), consolidated=True)["status"].values


def _restore_metadata(path, meta) -> list[str]:
    """Rewrite the metadata files that are missing or differ, from the consolidated copy
    (checked by its sha256); StoreError for one the copy does not list."""
    restored = []
    for key in _metadata_differences(path, meta):
        if key not in meta:
            raise StoreError(
                f"{path} holds a metadata file {key} that its .zmetadata does not list: "
                "nothing was changed; move it away, or run into a new --out"
            )
        target = Path(path) / key
        target.parent.mkdir(parents=True, exist_ok=True)
        _write_json(target, meta[key])
        restored.append(key)
    return restored


def chunks_to_compute(path, design: xr.Dataset, size: int) -> tuple[list, list]:
    """The chunks a resume must compute: ``(pending, damaged)``.

    A chunk marked done is trusted only if every file of it, ``status`` included, still has
    the sha256 recorded when it was written (see :func:`_chunk_finished`); otherwise its files
    are removed, it is marked pending again and listed in ``damaged``. The design variables are
    compared with ``design`` (made again from the study) and rewritten where they differ.
    Metadata files that are missing or differ from the consolidated ``.zmetadata`` are
    restored from it.
    """
    import zarr

    path = Path(path)
    meta = _consolidated(path)
    missing = [n for n in design.data_vars if f"{n}/.zarray" not in meta]
    if missing:  # a store written before the design had them (e.g. uplift_acceleration)
        raise StoreError(
            f"{path}: the store lacks the design variable(s) {missing} that this rockstudy "
            "writes (it was made by an earlier version); run the study into a new store"
        )
    _restore_metadata(path, meta)
    group = zarr.open_group(str(path), mode="r+", zarr_format=2)
    with zarr.config.set({"array.write_empty_chunks": True}):
        for name in design.variables:
            want = design[name].values
            try:
                same = np.array_equal(group[name][:], want, equal_nan=want.dtype.kind == "f")
            except Exception:  # noqa: BLE001 - any unreadable design chunk is written again
                same = False
            if not same:
                group[name][:] = want
        write_template_sums(path, design.variables)  # the design as it now reads
        results = _results_with_values(meta, read_template_sums(path)["results"])
        pending, damaged = [], []
        bounds = chunk_bounds(design.sizes["sample"], size)
        for k, (rows, status) in enumerate(
            zip(bounds, _status_chunks(group["status"], bounds), strict=True)
        ):
            try:
                finished = _chunk_finished(path, results, k, status)
            except _ChunkDamage:
                damaged.append(rows)
                _reset_chunk(path, group, results, k, rows)
                continue
            if not finished:
                pending.append(rows)
    return pending, damaged


def _reset_chunk(path, group, results, k, rows) -> None:
    """Remove the files of chunk ``k`` (never merged into: a damaged file may not decode) and
    its checksums, and mark it pending."""
    (path / CHECKSUMS / str(k)).unlink(missing_ok=True)
    for name, ndim in results.items():
        (path / name / (str(k) + ".0" * (ndim - 1))).unlink(missing_ok=True)
    group["status"][rows[0] : rows[1]] = np.full(rows[1] - rows[0], STATUS_PENDING, np.int8)


def open_result(path, verify: bool = True) -> xr.Dataset:
    """Open a result cube (zarr or netCDF); grid studies come back on their grid dimensions.

    A zarr cube is first checked against the sha256 recorded when it was written
    (:func:`verify_cube`): a damaged one raises :class:`DamagedCube` naming the variable and
    chunk. ``verify=False`` skips the check (to look at a damaged cube). A netCDF export, and a
    dataset saved with ``to_zarr``, carry no checksums and are read as they are.
    """
    path = Path(path)
    if path.suffix == ".nc":
        ds = xr.open_dataset(path)
    else:
        if verify and written_by_run(path):  # a dataset saved with to_zarr has no sums
            verify_cube(path)
        ds = xr.open_zarr(path, consolidated=True)
    if "record_design" in ds.attrs and "sample" in ds.dims:
        from ..designs.record_rows import design_dataset

        return design_dataset(ds)
    grid = ds.attrs.get("grid_dims")
    if isinstance(grid, str):
        grid = json.loads(grid)
    if grid:
        ds = _unstack_grid(ds, list(grid))
    return ds


def _unstack_grid(ds, dims):
    shape = [ds.sizes[f"{d}_grid"] for d in dims]
    out = {}
    for name, var in ds.data_vars.items():
        if var.dims == ("sample",) and name not in dims:
            out[name] = (tuple(dims), var.values.reshape(shape), var.attrs)
    coords = {d: ds[f"{d}_grid"].values for d in dims}
    return xr.Dataset(out, coords=coords, attrs=ds.attrs)
