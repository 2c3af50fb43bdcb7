"""The damage states of a design: limits short of (or at) overturning on one demand of a
point (a structure under a scaled record), given as a mapping ``{name: limit}`` (a study's
``[design] damage_states``, the ``damage_states=`` of the record designs of
:mod:`rockstudy.study.designs.records`):

- a number in (0, 1]: a limit on the peak rotation ratio ``max_rotation / critical_rotation``
  (``|theta|/alpha``), reached where the ratio is at least the limit; 1 is overturning;
- ``{slide = d}`` (``{"slide": d}``), d > 0 [m]: a limit on the contact model's peak slide
  ``max_slide``, reached where it exceeds d (with ``[run] model`` "contact" or "auto").

A point that overturned has reached every state. E.g. ``{chipped = 0.2, displaced = 0.5,
fall_off = {slide = 0.1}, overturned = 1.0}``; the states keep the given order.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

__all__ = [
    "MAX_SLIDE",
    "ROTATION_RATIO",
    "SLIDE",
    "DamageState",
    "damage_states",
    "states_attr",
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
