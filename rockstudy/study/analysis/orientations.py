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
    ``censored``, ``status``; with damage states, ``state_capacity`` and
    ``state_capacity_scale`` of each state likewise; its other variables, the IDA curves, are
    those of the first orientation); cloud and stripes keep ``overturned`` (at some
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
    if "state_capacity_scale" in ds:
        scale = _state_summary(ds, which)
        out["state_capacity_scale"] = scale.assign_attrs(ds["state_capacity_scale"].attrs)
        per_state = ds["state_capacity"] / ds["state_capacity_scale"] ** power
        state = np.fmax(measure, per_state.max(("orientation", "damage_state"))) * scale**power
        out["state_capacity"] = state.assign_attrs(ds["state_capacity"].attrs)
    out.attrs["summary"] = which
    return out


def _state_summary(ds, which) -> xr.DataArray:
    """The damage states' capacity scales (``state_capacity_scale``, on damage_state) at the
    worst orientation or the median over orientations (``which``), NaN where that summary
    is censored (:func:`state_design` of :mod:`.states` then censors it at the summary's
    ``capacity_scale_lower``).

    A state not reached at an orientation is censored there at the highest rung, which
    stood: that orientation's ``capacity_scale_lower``. A state is reached at or below
    overturning, so a state's summary is censored only where overturning's is, and
    overturning's censoring level is at or below the state's: the capacity lies above it.
    The overturning state's summary is the summary's ``capacity_scale``."""
    scale = ds["state_capacity_scale"]
    dims = [d for d in scale.dims if d != "orientation"] + ["orientation"]
    values = scale.transpose(*dims).values
    lower = ds["capacity_scale_lower"].broadcast_like(scale).transpose(*dims).values
    summary = {"worst": _worst, "median": _median}[which]
    exact = summary(values, lower, np.isnan(values))[0]
    coords = {k: v for k, v in scale.coords.items() if "orientation" not in v.dims}
    return xr.DataArray(exact, dims=dims[:-1], coords=coords, name=scale.name)
