"""The result cube: a zarr store written chunk by chunk, with a ``status`` written last.

The template (design, outputs filled with their fill values, ``status`` = 0 pending) is written
first. Each finished chunk is written into its own region (zarr chunks are aligned with the
study's chunks, so no two writers ever share a zarr chunk), outputs first and ``status`` last:
a chunk whose status is not pending is complete. A killed run resumes from the pending chunks.
"""

from __future__ import annotations

import importlib.metadata
import json
import platform
from pathlib import Path

import numpy as np
import xarray as xr

from .evaluate import ERROR_DTYPE, OUTPUTS, STATUS_PENDING
from .spec import Study

_FORMAT = {"zarr_format": 2, "consolidated": True}
_PACKAGES = (
    "rockstudy",
    "numpy",
    "scipy",
    "numba",
    "xarray",
    "zarr",
    "dask",
    "distributed",
    "SALib",
    "pydantic",
)


def package_versions() -> dict:
    out = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def chunk_bounds(n: int, size: int) -> list[tuple[int, int]]:
    """[start, stop) of each chunk of ``size`` rows."""
    return [(i, min(i + size, n)) for i in range(0, n, size)]


def create_store(path, design: xr.Dataset, study: Study, overwrite: bool = False) -> None:
    """Write the template cube: design, outputs at their fill values, status pending.

    The attribute ``template_complete`` is set last: a store without it was interrupted before
    any result was written, and is rebuilt (``overwrite``) rather than resumed.
    """
    import dask
    import dask.array as da

    n = design.sizes["sample"]
    size = min(study.chunk_size, n)
    ds = design.copy()

    def lazy(fill, dtype):  # written chunk by chunk: the template never sits in memory
        return ("sample", da.full(n, fill, dtype=dtype, chunks=size))

    for name in study.run.outputs:
        long_name, units, dtype, fill = OUTPUTS[name]
        ds[name] = lazy(fill, dtype)
        ds[name].attrs.update(long_name=long_name, units=units)
    ds["status"] = lazy(STATUS_PENDING, np.int8)
    ds["status"].attrs.update(long_name="0 pending, 1 ok, 2 failed", units="1")
    ds["error"] = lazy(b"", ERROR_DTYPE)
    ds["error"].attrs.update(long_name="error message of a failed sample", units="1")
    ds.attrs.update(
        study=study.normalized(),
        study_sha256=study.sha256(),
        study_name=study.name,
        seed=study.seed,
        chunk_size=study.chunk_size,
        versions=json.dumps(package_versions()),
        Conventions="CF-1.8",
    )
    chunks = {
        name: {"chunks": (size,)} for name, var in ds.data_vars.items() if var.dims == ("sample",)
    }
    with dask.config.set(scheduler="threads"):  # here, never on a cluster's workers
        ds.to_zarr(Path(path), mode="w" if overwrite else "w-", encoding=chunks, **_FORMAT)
    import zarr

    zarr.open_group(str(path), mode="r+", zarr_format=2).attrs["template_complete"] = 1
    zarr.consolidate_metadata(str(path), zarr_format=2)


def template_complete(path) -> bool:
    """Whether a store's template was fully written."""
    try:
        return bool(xr.open_zarr(Path(path), consolidated=True).attrs.get("template_complete"))
    except Exception:
        return False


def study_sha256(path) -> str | None:
    """The sha256 of the study a store holds."""
    return xr.open_zarr(Path(path), consolidated=True).attrs.get("study_sha256")


class ChunkWriter:
    """Writes finished chunks straight into the zarr arrays of a cube, ``status`` last.

    The arrays were created by :func:`create_store` with the study's chunks, so each chunk
    write touches its own zarr chunks only.
    """

    def __init__(self, path):
        import zarr

        self.group = zarr.open_group(str(path), mode="r+", zarr_format=2)

    def write(self, start: int, stop: int, result: dict) -> None:
        for name, values in result.items():
            if name != "status":
                self.group[name][start:stop] = values
        self.group["status"][start:stop] = result["status"]


def write_chunk(path, start: int, stop: int, result: dict) -> None:
    """Write one finished chunk: every output, then ``status`` (last)."""
    ChunkWriter(path).write(start, stop, result)


def read_status(path) -> np.ndarray:
    """The per-sample status array of a store (0 pending, 1 ok, 2 failed)."""
    return xr.open_zarr(Path(path), consolidated=True)["status"].values


def pending_chunks(path, size: int) -> list[tuple[int, int]]:
    """Chunks with at least one pending sample."""
    status = read_status(path)
    return [
        (a, b) for a, b in chunk_bounds(status.size, size) if np.any(status[a:b] == STATUS_PENDING)
    ]


def open_result(path) -> xr.Dataset:
    """Open a result cube (zarr or netCDF); grid studies come back on their grid dimensions."""
    path = Path(path)
    if path.suffix == ".nc":
        ds = xr.open_dataset(path)
    else:
        ds = xr.open_zarr(path, consolidated=True)
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


def export_netcdf(path, out_path) -> Path:
    """Write the finished cube as netCDF (scipy backend) beside the zarr store, streamed."""
    import dask

    ds = xr.open_zarr(Path(path), consolidated=True)  # lazy: written chunk by chunk
    ds.attrs["grid_dims"] = json.dumps(ds.attrs.get("grid_dims", []))
    for name in list(ds.variables):
        if ds[name].dtype == np.int64:  # netCDF3 has no 64-bit integers
            ds[name] = ds[name].astype(np.int32)
    with dask.config.set(scheduler="threads"):
        ds.to_netcdf(Path(out_path), engine="scipy")
    return Path(out_path)
