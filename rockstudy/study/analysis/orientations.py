"""A design over orientations summarised per object and record, as RotD100 and RotD50
summarise a pair's spectra: the worst orientation and the median over orientations.

A design with ``[design] orientations`` runs every record along each orientation psi of the
objects' rocking plane (dimension ``orientation``). :func:`orientation_summary` folds that
dimension away, giving a dataset of the design's own layout that every analysis and report
of a design takes (fragility fits, risk): ``"worst"`` keeps, per object and record, the
orientation that overturns the object first (the lowest capacity; for cloud and stripes, a
point overturns if it does at some orientation) and ``"median"`` the median over orientations
(a point overturns if it does at half of them or more). An object whose orientation is not
known stands, on average over orientations, as the median says; the worst orientation is
the bound for an object that may stand at any.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["ORIENTATION_SUMMARIES", "orientation_capacities", "orientation_summary"]

#: The summaries over orientations: name -> what it keeps.
ORIENTATION_SUMMARIES = {
    "worst": "the orientation that overturns first (the lowest capacity; like RotD100)",
    "median": "the median over orientations (like RotD50)",
}
#: The IDA variables an orientation summary sets; the others are kept from orientation 0.
_IDA_SET = ("capacity_scale", "capacity_scale_lower", "censored", "status", "capacity")


def _check(ds, which):
    if "orientation" not in ds.dims:
        raise ValueError("ds: a design over orientations (dimension 'orientation') is needed")
    if which not in ORIENTATION_SUMMARIES:
        raise ValueError(f"which: must be one of {list(ORIENTATION_SUMMARIES)}, got {which!r}")


def _worst(scale, lower, censored):
    """The lowest capacity over the last axis (orientations): exact where the lowest
    uncensored capacity is at most every censored orientation's standing level; censored
    at the lower of the two otherwise (the worst capacity is above it)."""
    exact = np.where(censored, np.inf, scale).min(axis=-1)
    stood = np.where(censored, lower, np.inf).min(axis=-1)
    known = exact <= stood
    return np.where(known, exact, np.nan), np.where(known, np.nan, stood), ~known


def _median(scale, lower, censored):
    """The median capacity over the last axis: a censored orientation's capacity lies above
    its standing level, so the median lies between the median with it there and the median
    with it infinite; exact where the two agree, censored at the lower otherwise."""
    high = np.median(np.where(censored, np.inf, scale), axis=-1)
    low = np.median(np.where(censored, lower, scale), axis=-1)
    known = np.isfinite(high) & (high == low)
    return np.where(known, high, np.nan), np.where(known, np.nan, low), ~known


def orientation_capacities(ds: xr.Dataset) -> xr.Dataset:
    """The IDA capacity scales of every (record, structure) at the worst orientation and
    the median over orientations: ``<which>_scale`` (NaN where censored),
    ``<which>_scale_lower`` (the standing level of a censored one) and ``<which>_censored``
    for ``which`` in :data:`ORIENTATION_SUMMARIES`, and ``status`` (the largest over the
    orientations: 1 if a simulation of one hit the step limit)."""
    _check(ds, "worst")
    dims = [d for d in ds["capacity_scale"].dims if d != "orientation"] + ["orientation"]
    scale, lower = (
        ds[k].transpose(*dims).values for k in ("capacity_scale", "capacity_scale_lower")
    )
    censored = ds["censored"].transpose(*dims).values == 1
    out = {"status": (dims[:-1], ds["status"].transpose(*dims).values.max(axis=-1))}
    for which, summary in (("worst", _worst), ("median", _median)):
        s, low, cens = summary(scale, lower, censored)
        out[f"{which}_scale"] = (dims[:-1], s)
        out[f"{which}_scale_lower"] = (dims[:-1], low)
        out[f"{which}_censored"] = (dims[:-1], cens)
    coords = {k: v for k, v in ds["capacity_scale"].coords.items() if "orientation" not in v.dims}
    return xr.Dataset(out, coords=coords)


def orientation_summary(ds: xr.Dataset, which: str) -> xr.Dataset:
    """``ds`` (a design over orientations) without its ``orientation`` dimension: the worst
    orientation or the median over orientations (``which``, :data:`ORIENTATION_SUMMARIES`)
    of every object and record, in the design's own layout; ``summary`` in the attributes.

    An IDA keeps that capacity (``capacity``, ``capacity_scale``, ``capacity_scale_lower``,
    ``censored``, ``status``; the capacities of damage states and slide limits,
    ``state_capacity`` and ``slide_capacity`` and their scales, likewise per limit, each
    the lower of it and overturning's at every orientation; its other variables, the IDA
    curves, are those of the first orientation); cloud and stripes keep ``overturned`` (at some
    orientation, or at half of them or more; -1 if a point failed at one), ``max_rotation``
    (the largest, or the median) and ``status`` (the largest over the orientations).
    """
    _check(ds, which)
    out = ds.isel(orientation=0, drop=True)
    if "capacity_scale" in ds:
        return _ida_summary(ds, out, which)
    over = ds["overturned"]
    share = over.where(over >= 0).mean("orientation")
    level = 0.0 if which == "worst" else 0.5
    decided = xr.where(share > level, 1, 0) if which == "worst" else xr.where(share >= level, 1, 0)
    out["overturned"] = xr.where((over < 0).any("orientation"), -1, decided).astype(over.dtype)
    rotation = ds["max_rotation"]
    out["max_rotation"] = getattr(rotation, "max" if which == "worst" else "median")("orientation")
    out["status"] = ds["status"].max("orientation")
    out.attrs["summary"] = which
    return out


def _ida_summary(ds, out, which):
    """:func:`orientation_summary` of an IDA: the capacity in the design's measure is the
    ground record's measure (the same at every orientation) times the scale to its power."""
    from ...motions import measures

    caps = orientation_capacities(ds)
    out["capacity_scale"] = caps[f"{which}_scale"]
    out["capacity_scale_lower"] = caps[f"{which}_scale_lower"]
    out["censored"] = caps[f"{which}_censored"]
    out["status"] = caps["status"]
    power = measures.power(ds.attrs["im"])
    measure = (ds["capacity"] / ds["capacity_scale"] ** power).max("orientation")
    out["capacity"] = (measure * out["capacity_scale"] ** power).assign_attrs(ds["capacity"].attrs)
    for name, dim in (("state_capacity", "damage_state"), ("slide_capacity", "slide_limit")):
        if f"{name}_scale" in ds:
            scale = _limit_summary(ds, f"{name}_scale", which)
            out[f"{name}_scale"] = scale.assign_attrs(ds[f"{name}_scale"].attrs)
            per_limit = (ds[name] / ds[f"{name}_scale"] ** power).max(("orientation", dim))
            capacity = np.fmax(measure, per_limit) * scale**power
            out[name] = capacity.assign_attrs(ds[name].attrs)
    out.attrs["summary"] = which
    return out


def _limit_summary(ds, name, which) -> xr.DataArray:
    """The capacity scales ``name`` of limits short of overturning (``state_capacity_scale``
    on damage_state, ``slide_capacity_scale`` on slide_limit) at the worst orientation or the
    median over orientations (``which``), NaN where that summary is censored (the fits then
    censor it at the summary's ``capacity_scale_lower``).

    At each orientation the limit counts as reached at the lower of its capacity and the
    overturning capacity (an overturned block has slid, and reached every state): a limit
    neither reached nor overturned is censored there at the highest rung, which stood, that
    orientation's ``capacity_scale_lower``. Such a limit's summary is censored only where
    overturning's is, and overturning's censoring level is at or below the limit's: the
    capacity lies above it. The overturning state's summary is the summary's
    ``capacity_scale``."""
    overturned = ds["capacity_scale"].where(ds["censored"] == 0)
    scale = np.fmin(ds[name], overturned)
    dims = [d for d in scale.dims if d != "orientation"] + ["orientation"]
    values = scale.transpose(*dims).values
    lower = ds["capacity_scale_lower"].broadcast_like(scale).transpose(*dims).values
    summary = {"worst": _worst, "median": _median}[which]
    exact = summary(values, lower, np.isnan(values))[0]
    coords = {k: v for k, v in scale.coords.items() if "orientation" not in v.dims}
    return xr.DataArray(exact, dims=dims[:-1], coords=coords, name=name)
