"""The fits of a record design over floors and orientations: one fit per floor and orientation.

A study with a list of floors (``[motion] floor = [..]``) or with ``[design] orientations``
gives a design dataset with the dimensions ``floor`` and ``orientation``
(:func:`~rockstudy.study.designs.record_rows.design_dataset`): every record runs on each
floor, along each orientation psi of the objects' rocking plane. The fits of a record design
(fragility, risk, damage states, slide limits, the efficiency of measures) are fits of
capacities or points of one motion per record; :func:`per_motion` makes each of them fit
every (floor, orientation) apart, as it fits every structure apart, and carries the two
dimensions in its result: an outer index level of a table, a dimension of a Dataset.

Over orientations this is the fit of an object of known orientation psi. For an object whose
orientation is not known, fold the dimension first with
:func:`~rockstudy.study.analysis.orientations.orientation_summary` (the worst orientation, or
the median over orientations), then fit: ``ds.rocking.fragility(orientation="median")``.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pandas as pd
import xarray as xr

__all__ = ["MOTION_DIMS", "motion_dims", "motion_slices", "per_motion"]

#: The motion dimensions of a design dataset, in the order of the results' outer levels.
MOTION_DIMS = ("floor", "orientation")


def motion_dims(ds: xr.Dataset) -> list[str]:
    """The motion dimensions (:data:`MOTION_DIMS`) that ``ds`` has, in that order."""
    return [d for d in MOTION_DIMS if d in ds.dims]


def _label(value):
    """A coordinate value as a plain Python number (a floor an int, an angle a float)."""
    return value.item() if isinstance(value, np.generic) else value


def motion_slices(ds: xr.Dataset) -> list[tuple[tuple, xr.Dataset]]:
    """((floor, orientation) values, ``ds`` at them without the dimensions) for every
    combination of the motion dimensions of ``ds`` (each tuple only of the dimensions it
    has), in the order of the coordinates."""
    dims = motion_dims(ds)
    positions = itertools.product(*(range(ds.sizes[d]) for d in dims))
    return [
        (
            tuple(_label(ds[d].values[k]) for d, k in zip(dims, at, strict=True)),
            ds.isel(dict(zip(dims, at, strict=True)), drop=True),
        )
        for at in positions
    ]


def _frame(parts, dims, keys):
    """The tables ``parts`` under outer index levels ``dims`` (the values ``keys``)."""
    flat = [k[0] for k in keys] if len(dims) == 1 else keys
    return pd.concat(parts, keys=flat, names=dims)


def _nested(items: list, shape) -> list:
    """``items`` (row-major) as nested lists of ``shape``."""
    if len(shape) == 1:
        return list(items)
    step = len(items) // shape[0]
    return [_nested(items[k * step : (k + 1) * step], shape[1:]) for k in range(shape[0])]


def _dataset(parts, dims, keys, order):
    """The Datasets ``parts`` with the dimensions ``dims`` (coordinates from ``keys``,
    row-major); each part's structures in the design's ``order`` (a part ranked by a rate
    is reordered)."""
    stacked = []
    for part, key in zip(parts, keys, strict=True):
        if "structure" in part.dims:
            part = part.sel(structure=order)
        stacked.append(part.expand_dims({d: [v] for d, v in zip(dims, key, strict=True)}))
    shape = [len(dict.fromkeys(k[i] for k in keys)) for i in range(len(dims))]
    return xr.combine_nested(_nested(stacked, shape), concat_dim=dims, combine_attrs="override")


def _combine(parts, dims, keys, order):
    """The results of every motion slice as one result of the fit's own type."""
    first = parts[0]
    if isinstance(first, pd.DataFrame):
        return _frame(parts, dims, keys)
    if isinstance(first, xr.Dataset):
        return _dataset(parts, dims, keys, order)
    if isinstance(first, tuple):
        return tuple(_combine([p[i] for p in parts], dims, keys, order) for i in range(len(first)))
    raise TypeError(f"per_motion: cannot combine results of type {type(first).__name__}")


def per_motion(fit):
    """``fit(ds, ...)`` made to take a design dataset with the dimensions ``floor`` and
    ``orientation``: ``fit`` of every (floor, orientation) apart (:func:`motion_slices`), the
    results combined with those dimensions (outer index levels of a table, in the order
    ``floor``, ``orientation``; dimensions of a Dataset, its structures in the design's order;
    each element of a tuple likewise). A dataset without them is ``fit``'s own."""

    @functools.wraps(fit)
    def on_every_motion(ds, *args, **kw):
        dims = motion_dims(ds)
        if not dims:
            return fit(ds, *args, **kw)
        slices = motion_slices(ds)
        parts = [fit(part, *args, **kw) for _, part in slices]
        order = ds["structure"].values if "structure" in ds.dims else None
        return _combine(parts, dims, [key for key, _ in slices], order)

    return on_every_motion
