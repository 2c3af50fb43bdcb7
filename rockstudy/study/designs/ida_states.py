"""Damage states short of overturning: their definition, and their capacities in an IDA.

A damage state is a limit on one demand of a point (a structure under a scaled record):

- the peak rotation ratio ``max_rotation / critical_rotation`` (``|theta|/alpha``): a number
  in (0, 1], reached where the ratio is at least the limit; 1 is overturning itself;
- the contact model's peak slide ``max_slide`` [m]: ``{"slide": d}`` with d > 0, reached where
  ``max_slide`` > d (with ``model="contact"`` or ``"auto"`` only).

A point that overturned has reached every state. The states are given as a mapping
``{name: limit}``, e.g. ``{"chipped": 0.2, "displaced": 0.5, "fall_off": {"slide": 0.1},
"overturned": 1.0}`` (a study's ``[design] damage_states``), and kept in that order.

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

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import xarray as xr

__all__ = [
    "ROTATION_RATIO",
    "SLIDE",
    "DamageState",
    "damage_states",
    "states_attr",
    "state_scales",
    "state_tables",
]

#: The demand of a state on the peak rotation ratio max_rotation / critical_rotation.
ROTATION_RATIO = "rotation_ratio"
#: The demand of a state on the contact model's peak slide max_slide [m].
SLIDE = "slide"
#: Largest slide limit of a state [m] (as ``design.slide_limits``).
MAX_SLIDE = 100.0
_HELP = (
    "give a rotation ratio |theta|/alpha in (0, 1] (1 = overturning) or {slide = d} with a "
    f"slide d in (0, {MAX_SLIDE:g}] m"
)


@dataclass(frozen=True)
class DamageState:
    """A damage state: its ``name``, its ``demand`` (:data:`ROTATION_RATIO` or :data:`SLIDE`)
    and the ``limit`` of that demand (a ratio in (0, 1], or a slide [m])."""

    name: str
    demand: str
    limit: float

    @property
    def overturning(self) -> bool:
        """Whether the state is overturning itself (a rotation ratio of 1)."""
        return self.demand == ROTATION_RATIO and self.limit == 1.0

    def spec(self):
        """The state's value in the mapping form (a number, or ``{"slide": d}``)."""
        return self.limit if self.demand == ROTATION_RATIO else {SLIDE: self.limit}


def _number(value) -> float | None:
    """``value`` as a finite float, or None if it is not a (non-boolean) real number."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.number):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def _state(name, value) -> DamageState:
    """One state from its name and value; a ValueError naming ``damage_states`` and the
    state otherwise."""
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"damage_states: a state's name must be a non-empty text, got {name!r}")
    where = f"damage_states: the state {name!r}"
    if isinstance(value, Mapping):
        if set(value) != {SLIDE}:
            raise ValueError(f"{where} has keys {sorted(map(str, value))}: {_HELP}")
        d = _number(value[SLIDE])
        if d is None or not 0.0 < d <= MAX_SLIDE:
            raise ValueError(f"{where} has the slide {value[SLIDE]!r}: {_HELP}")
        return DamageState(name, SLIDE, d)
    ratio = _number(value)
    if ratio is None or not 0.0 < ratio <= 1.0:
        raise ValueError(f"{where} has the limit {value!r}: {_HELP}")
    return DamageState(name, ROTATION_RATIO, ratio)


def damage_states(values, model=None) -> tuple[DamageState, ...]:
    """The damage states of a mapping ``{name: limit}`` (see the module; None or empty:
    none), in the given order. ``model``: whether the contact model runs (a state on the
    slide needs it). A ValueError naming ``damage_states`` and the state otherwise: names
    are non-empty and unique (also once stripped and lower-cased), limits as the module
    says, no two states alike."""
    if values is None:
        return ()
    if isinstance(values, str):
        values = json.loads(values)
    if not isinstance(values, Mapping):
        raise TypeError(
            f"damage_states must be a mapping {{name: limit}}, got {type(values).__name__}"
        )
    states = tuple(_state(name, value) for name, value in values.items())
    _check_distinct(states)
    slides = [s.name for s in states if s.demand == SLIDE]
    if slides and not model:
        raise ValueError(
            f"damage_states: the states {slides} on the slide need the contact model's "
            "max_slide: run with model 'contact' or 'auto' (with friction)"
        )
    return states


def _check_distinct(states) -> None:
    """A ValueError naming ``damage_states`` where two states share a name (up to case and
    spaces) or a demand and limit."""
    seen, limits = {}, {}
    for s in states:
        key = s.name.strip().lower()
        if key in seen:
            raise ValueError(f"damage_states: the names {seen[key]!r} and {s.name!r} clash")
        seen[key] = s.name
        if (s.demand, s.limit) in limits:
            raise ValueError(
                f"damage_states: the states {limits[s.demand, s.limit]!r} and {s.name!r} have "
                f"the same limit {s.spec()!r}"
            )
        limits[s.demand, s.limit] = s.name


def states_attr(states) -> str:
    """The states as a JSON text ``{name: limit}`` (a design's ``attrs["damage_states"]``)."""
    return json.dumps({s.name: s.spec() for s in states})


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


def _brackets(points, ladders, states, alpha):
    """(lower scale, upper scale, (state, structure) index) of the first rung of each
    structure that reaches each state short of overturning; the lower end NaN where the
    lowest rung reached it."""
    lo, hi, cell = [], [], []
    for j, ladder in enumerate(ladders):
        rungs = _rung_outputs(points, j)
        for c, state in enumerate(states):
            if state.overturning:
                continue
            k = np.flatnonzero(_reached(state, alpha[j], rungs))
            if k.size:
                hi.append(ladder[k[0]])
                lo.append(ladder[k[0] - 1] if k[0] > 0 else np.nan)
                cell.append((c, j))
    return np.array(lo, float), np.array(hi, float), np.array(cell, np.int64).reshape(-1, 2)


def _bisect(points, lo, hi, cell, states, alpha, tolerance) -> np.ndarray:
    """The upper ends of the brackets [lo, hi] of the cells (state, structure), bisected
    geometrically on "reaches the state" until hi <= lo (1 + tolerance)."""
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
            above[mine] = _reached(states[c], alpha[structure[mine]], sub)
        hi[active[above]] = s[above]
        lo[active[~above]] = s[~above]


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
    lo, hi, cell = _brackets(points, ladders, states, alpha)
    if cell.size:
        out[cell[:, 0], cell[:, 1]] = _bisect(points, lo, hi, cell, states, alpha, tolerance)
    return out


#: The long names of the IDA's variables of the damage states.
_LONG_NAMES = {
    "state_capacity_scale": "lowest scale seen to reach the damage state",
    "state_capacity": "first intensity at which the damage state is reached (NaN: not below "
    "the last rung)",
}


def _state_coords(states) -> dict:
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
    each), with the coordinates of :func:`_state_coords` and ``attrs["damage_states"]``
    (:func:`states_attr`)."""
    scale = np.stack([res["state_capacity_scale"] for res in results], axis=1)
    per_record = np.reshape(measure, (len(results), -1))
    values = {"state_capacity_scale": scale, "state_capacity": per_record * scale**power}
    units = {"state_capacity_scale": "1", "state_capacity": ds["capacity"].attrs["units"]}
    ds = ds.assign_coords(_state_coords(states))
    for name, value in values.items():
        attrs = {"units": units[name], "long_name": _LONG_NAMES[name]}
        ds[name] = (("damage_state", "record", "structure"), value, attrs)
    ds.attrs["damage_states"] = states_attr(states)
    return ds
