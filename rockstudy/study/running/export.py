"""The netCDF export of a finished cube (:func:`export_netcdf`: scipy backend, netCDF3,
streamed), and the check, before a run, that the export replaces nothing but an earlier
export of the same study (:func:`check_export_target`)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import xarray as xr

from ._files import StoreError

__all__ = ["check_export_target", "export_netcdf"]

_INT32 = np.iinfo(np.int32)


def _netcdf_study(path) -> str | None:
    """The ``study_sha256`` attribute of a netCDF file, or None if it is not one of ours."""
    try:
        with xr.open_dataset(path, engine="scipy") as ds:
            return ds.attrs.get("study_sha256")
    except Exception:  # noqa: BLE001 - whatever it is, it is not an export we wrote
        return None


def check_export_target(out_path, study_sha: str, overwrite: bool = False) -> None:
    """Refuse, before anything runs, an export that would replace what this study did not write.

    A folder is never replaced; a file is replaced only if it is an export of the same study
    (an earlier or interrupted run of it) or ``overwrite`` is set.
    """
    out_path = Path(out_path)
    if out_path.is_dir():
        raise StoreError(
            f"{out_path} is a folder: the netCDF export cannot be written there; move it away "
            "or choose another --out"
        )
    if overwrite or not out_path.exists() or _netcdf_study(out_path) == study_sha:
        return
    raise StoreError(
        f"{out_path} exists and was not written by a run of this study: it was left as is; "
        "pass --overwrite to replace it, or choose another --out"
    )


def _nc3_attr(value):
    """netCDF3 attributes are 32-bit: larger integers (a seed >= 2**31) are kept as text."""
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        if not _INT32.min <= value <= _INT32.max:
            return str(value)
    return value


def export_netcdf(path, out_path) -> Path:
    """Write the finished cube as netCDF (scipy backend) beside the zarr store, streamed.

    The file is written under a temporary name inside the store and renamed at the end, so
    ``out_path`` is either the previous file or the complete export, never a partial one.
    """
    import dask

    out_path = Path(out_path)
    ds = xr.open_zarr(Path(path), consolidated=True)  # lazy: written chunk by chunk
    if "record_design" in ds.attrs:  # a record design is exported in its own layout
        from ..designs.record_rows import design_dataset

        ds = design_dataset(ds)
        empty = [d for d, size in ds.sizes.items() if size == 0]  # netCDF3 has none
        ds = ds.drop_dims(empty)
    ds.attrs["grid_dims"] = json.dumps(ds.attrs.get("grid_dims", []))
    ds.attrs = {k: _nc3_attr(v) for k, v in ds.attrs.items()}
    for name in list(ds.variables):
        var = ds[name]
        if var.dtype == np.int64:  # netCDF3 has no 64-bit integers: int32 if it fits
            lo, hi = (int(x) for x in dask.compute(var.min(), var.max(), scheduler="threads"))
            fits = var.size == 0 or (_INT32.min <= lo and hi <= _INT32.max)
            ds[name] = var.astype(np.int32 if fits else np.float64)
        elif var.dtype.kind in "OT":  # variable-length text: its width is needed, so load
            attrs = {k: v for k, v in var.attrs.items() if k != "_FillValue"}
            ds[name] = (var.dims, var.values.astype(object), attrs)
    tmp = Path(path) / ".export.nc.partial"
    with dask.config.set(scheduler="threads"):
        ds.to_netcdf(tmp, engine="scipy")
    os.replace(tmp, out_path)
    return out_path
