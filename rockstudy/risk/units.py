"""The units a hazard curve's levels may be in: those of its intensity measure in the package's
one table of units (:mod:`rockstudy.motions.units`), as for a study's ``scale_to``."""

from __future__ import annotations

from ..motions import measures
from ..motions.units import UNITS

__all__ = ["UNIT_FACTORS", "to_si", "units_for"]

#: Every unit name the package reads: name -> (factor to SI, SI unit), the table of
#: :mod:`rockstudy.motions.units` ("g" is the unit g, standard gravity 9.80665 m/s^2, as for
#: records and ``scale_to``). A curve's levels may be in any unit of its IM's dimension, or in
#: its IM's quoted unit (:func:`rockstudy.motions.measures.units_of`).
UNIT_FACTORS = UNITS


def units_for(im: str, units: str | None, name: str = "units") -> str:
    """``units`` checked against the units of ``im`` (:func:`to_si`; its SI unit when None)."""
    allowed = measures.units_of(im)
    if units is not None and not isinstance(units, str):
        raise TypeError(f"{name} must be a unit name (a string) or None, got {units!r}")
    if units is None:
        return next(iter(allowed))
    if units in allowed:
        return units
    if units in UNITS:
        raise ValueError(
            f"{name}={units!r} is not a unit of {im!r}, which is in "
            f"{measures.measure(im).unit}: use one of {list(allowed)}"
        )
    raise ValueError(f"{name} of {im!r} must be one of {list(allowed)}, got {units!r}")


def to_si(im: str, units: str) -> float:
    """The factor from ``units`` (a unit of ``im``, :func:`units_for`) to the SI unit of
    ``im``."""
    return measures.units_of(im)[units_for(im, units)]
