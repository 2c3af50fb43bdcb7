"""Damage states short of overturning: their definition, and their capacities in an IDA.

The states, on the peak rotation ratio ``|theta|/alpha`` or the contact model's peak slide,
are defined (and checked) by :mod:`rockstudy.study.spec.damage_states`; a point that
overturned has reached every state.

**Capacities.** The capacity of a state under a record is found as the overturning capacity
is (:func:`.records.incremental_dynamic_analysis`): the first rung of the structure's ladder
that reaches the state and the rung below bracket it, bisected geometrically on "reaches the
state" until their ratio is at most ``1 + tolerance``; the capacity is the upper end. Since
overturning reaches every state, that rung is at or below the first overturning rung, which
the overturning ladder has simulated already: no rung is added, only the bisection. The
guarantee is the overturning one: every rung below a state's capacity was simulated and did
not reach it, so no window of the state at least one step wide lies below the capacity. NaN
where no rung reached the state (a censored structure standing below it up to its last
rung). The overturning state (limit 1 on the rotation ratio) is the overturning capacity
itself, taken as it is.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..spec.damage_states import (
    ROTATION_RATIO,
    SLIDE,
    DamageState,
    damage_states,
    states_attr,
)

__all__ = [
    "ROTATION_RATIO",
    "SLIDE",
    "DamageState",
    "damage_states",
    "states_attr",
    "LONG_NAMES",
    "bisect",
    "brackets",
    "state_coords",
    "state_scales",
    "state_tables",
]

# ------------------------------------------------------------------------------ capacities


def _reached(state, alpha, out) -> np.ndarray:
    """Whether each point of the outputs ``out`` (max_rotation, overturned[, max_slide])
    reached ``state``; ``alpha`` the critical rotation of each point's structure."""
    over = np.asarray(out["overturned"], float) > 0
    if state.demand == SLIDE:
        return over | (np.asarray(out["max_slide"], float) > state.limit)
    return over | (np.asarray(out["max_rotation"], float) / alpha >= state.limit)


def _rung_outputs(points, j) -> dict:
    """The outputs of the rungs simulated for structure j, in ladder order."""
    rows = [h for h in points.history[j] if h[3] == 0]
    table = np.array(rows, float).reshape(len(rows), -1)
    out = {"max_rotation": table[:, 1], "overturned": table[:, 2]}
    if "max_slide" in points.keys:
        out["max_slide"] = table[:, points.column("max_slide")]
    return out


def brackets(points, ladders, tests):
    """(lower scale, upper scale, (class, structure) index) of the first rung of each
    structure that passes each test of ``tests`` (``test(j, outputs)`` -> bool per point of
    structure(s) ``j``, outputs as :func:`_rung_outputs`; None: no bracket of that class);
    the lower end NaN where the lowest rung passed it."""
    lo, hi, cell = [], [], []
    for j, ladder in enumerate(ladders):
        rungs = _rung_outputs(points, j)
        for c, test in enumerate(tests):
            if test is None:
                continue
            k = np.flatnonzero(test(j, rungs))
            if k.size:
                hi.append(ladder[k[0]])
                lo.append(ladder[k[0] - 1] if k[0] > 0 else np.nan)
                cell.append((c, j))
    return np.array(lo, float), np.array(hi, float), np.array(cell, np.int64).reshape(-1, 2)


def bisect(points, lo, hi, cell, tests, tolerance) -> np.ndarray:
    """The upper ends of the brackets [lo, hi] of the cells (class, structure) of
    :func:`brackets`, bisected geometrically on the class's test until hi <= lo
    (1 + tolerance)."""
    while True:
        active = np.flatnonzero(np.isfinite(lo) & (hi > lo * (1.0 + tolerance)))
        if not active.size:
            return hi
        s = np.sqrt(lo[active] * hi[active])
        structure = cell[active, 1]
        out = points.outcomes(structure, s, 1)
        above = np.zeros(active.size, bool)
        for c in np.unique(cell[active, 0]):
            mine = cell[active, 0] == c
            sub = {k: np.asarray(v)[mine] for k, v in out.items() if np.ndim(v) == 1}
            above[mine] = tests[c](structure[mine], sub)
        hi[active[above]] = s[above]
        lo[active[~above]] = s[~above]


def _state_tests(states, alpha) -> list:
    """The tests of :func:`brackets` of the ``states`` short of overturning: "reaches the
    state" (None for the overturning state)."""

    def reaches(state):
        return lambda j, out: _reached(state, alpha[j], out)

    return [None if state.overturning else reaches(state) for state in states]


def state_scales(points, ladders, states, alpha, capacity_scale, tolerance) -> np.ndarray:
    """The capacity scales of the damage ``states`` under one record, shape (states,
    structures) (see the module).

    ``points`` runs and keeps the points of the record (:class:`.records._Points`), whose
    ladder climb has ended (every rung up to each structure's first overturning simulated);
    ``ladders`` the rungs of each structure; ``alpha`` the critical rotation of each;
    ``capacity_scale`` the overturning capacity scale of each (NaN: censored), the
    capacity of the overturning state."""
    out = np.full((len(states), len(ladders)), np.nan)
    for c, state in enumerate(states):
        if state.overturning:
            out[c] = capacity_scale
    tests = _state_tests(states, alpha)
    lo, hi, cell = brackets(points, ladders, tests)
    if cell.size:
        out[cell[:, 0], cell[:, 1]] = bisect(points, lo, hi, cell, tests, tolerance)
    return out


#: The long names of the IDA's variables of the damage states.
LONG_NAMES = {
    "state_capacity_scale": "lowest scale seen to reach the damage state",
    "state_capacity": "first intensity at which the damage state is reached (NaN: not below "
    "the last rung)",
}


def state_coords(states) -> dict:
    """The coordinates ``damage_state`` (the names), ``damage_demand`` and ``damage_limit``."""
    return {
        "damage_state": ("damage_state", np.array([s.name for s in states], dtype=object)),
        "damage_demand": ("damage_state", np.array([s.demand for s in states], dtype=object)),
        "damage_limit": (
            "damage_state",
            np.array([s.limit for s in states], float),
            {"long_name": "limit of the demand: |theta|/alpha, or max_slide [m]"},
        ),
    }


def state_tables(ds, results, states, measure, power) -> xr.Dataset:
    """``state_capacity_scale`` and ``state_capacity`` (the record's ``measure`` times the
    scale to the measure's ``power``, in the units of ``capacity``) on (damage_state,
    record, structure) from the per-record results of the IDA (``state_capacity_scale`` of
    each), with the coordinates of :func:`state_coords` and ``attrs["damage_states"]``
    (:func:`states_attr`)."""
    scale = np.stack([res["state_capacity_scale"] for res in results], axis=1)
    per_record = np.reshape(measure, (len(results), -1))
    values = {"state_capacity_scale": scale, "state_capacity": per_record * scale**power}
    units = {"state_capacity_scale": "1", "state_capacity": ds["capacity"].attrs["units"]}
    ds = ds.assign_coords(state_coords(states))
    for name, value in values.items():
        attrs = {"units": units[name], "long_name": LONG_NAMES[name]}
        ds[name] = (("damage_state", "record", "structure"), value, attrs)
    ds.attrs["damage_states"] = states_attr(states)
    return ds
