"""The slide capacities of an IDA under the contact model: for each slide d of
``slide_limits``, the first scale of each record at which a structure's ``max_slide``
exceeds d.

The ladder of the overturning capacity (:func:`.records.incremental_dynamic_analysis`)
climbs on past the first overturning, rung by rung, until ``max_slide`` exceeds the largest
d (or the ladder ends); for each d the first rung whose ``max_slide`` exceeds it and the
rung below bracket the capacity, bisected geometrically on ``max_slide > d`` until their
ratio is at most ``1 + tolerance`` (the bisection of :mod:`.ida_states`): the capacity is
the upper end. ``max_slide`` need not grow with the scale (a block that slides at one
scale can rock without slip at a higher one): the capacity is that of the first crossing
seen on the rungs, bisected inside that rung's bracket; a crossing narrower than a rung
below it can be missed, as an overturning window can. NaN where no rung up to the largest exceeds d.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from . import ida_states

__all__ = ["slide_limits", "slide_scales", "slide_tables"]

#: The key of the contact model's slide in a point's outputs.
_SLIDE = "max_slide"


def slide_limits(values, model) -> np.ndarray:
    """``slide_limits`` [m] as an array: finite, > 0 and increasing, under the contact model
    only (``model`` not None); a ValueError naming ``slide_limits`` otherwise."""
    limits = np.atleast_1d(np.asarray(values, dtype=float))
    if not limits.size:
        return limits
    if limits.ndim != 1 or not np.all(np.isfinite(limits) & (limits > 0.0)):
        raise ValueError(f"slide_limits must be finite slides > 0 [m], got {values!r}")
    if np.any(np.diff(limits) <= 0.0):
        raise ValueError(f"slide_limits must be distinct and increasing [m], got {values!r}")
    if model is None:
        raise ValueError(
            "slide_limits need the contact model's max_slide: give model='contact' or 'auto' "
            "(with friction)"
        )
    return limits


def slide_scales(points, ladders, done, limits, tolerance, climb) -> np.ndarray:
    """The slide capacity scales of one record, shape (limits, structures) (see the module).

    ``points`` runs and keeps the points (``.outcomes(idx, scales, kind)``, ``.history``
    of rows (scale, max_rotation, overturned, kind, ...), ``.column(name)``: an output's
    column in a row);
    ``ladders`` the rungs of each structure, of which the first ``done`` were simulated
    (raised in place by the rungs this climb adds); ``climb`` the ladder climb of
    :func:`.records._climb`."""
    limits = np.asarray(limits, dtype=float)
    out = np.full((limits.size, len(ladders)), np.nan)
    if not limits.size:
        return out
    top = limits[-1]
    start = np.array(done)
    for j in range(len(ladders)):
        if np.any(_rung_slides(points, j) > top):
            start[j] = ladders[j].size  # crossed already: not climbed again
    _, reached = climb(points, ladders, start, lambda o: np.asarray(o[_SLIDE]) > top)
    climbed = start < np.array([r.size for r in ladders])
    done[climbed] = reached[climbed]
    tests = [_slid_more(d) for d in limits]
    lo, hi, cell = ida_states.brackets(points, ladders, tests)
    out[cell[:, 0], cell[:, 1]] = ida_states.bisect(points, lo, hi, cell, tests, tolerance)
    return out


def _rung_slides(points, j) -> np.ndarray:
    """max_slide at each rung simulated for structure j, in ladder order."""
    column = points.column(_SLIDE)
    return np.array([h[column] for h in points.history[j] if h[3] == 0], float)


def _slid_more(d):
    """The test of :func:`.ida_states.brackets` "slid more than ``d``"."""
    return lambda j, out: np.asarray(out[_SLIDE], float) > d


def slide_tables(ds, results, limits, measure, power) -> xr.Dataset:
    """``slide_capacity_scale`` and ``slide_capacity`` (the record's ``measure`` times the
    scale to the measure's ``power``, in the units of ``capacity``) on (slide_limit, record,
    structure) from the per-record results of the IDA, with the ``slide_limit`` coordinate
    [m]."""
    scales = np.stack([res["slide_capacity_scale"] for res in results], axis=1)
    measure = np.broadcast_to(np.reshape(measure, (len(results), -1)), scales.shape[1:])
    dims = ("slide_limit", "record", "structure")
    ds = ds.assign_coords(slide_limit=("slide_limit", limits, {"units": "m"}))
    ds["slide_capacity_scale"] = (
        dims,
        scales,
        {"units": "1", "long_name": "lowest scale seen to slide more than slide_limit"},
    )
    ds["slide_capacity"] = (
        dims,
        measure * scales**power,
        {
            "units": ds["capacity"].attrs["units"],
            "long_name": "first intensity at which max_slide exceeds slide_limit (NaN: not "
            "below the largest rung)",
        },
    )
    return ds
