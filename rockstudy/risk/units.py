"""The units a hazard curve's levels may be in, by the dimension of its intensity measure."""

from __future__ import annotations

from ..constants import STANDARD_GRAVITY
from ..motions import measures

__all__ = ["UNIT_FACTORS", "units_for"]

#: Units a hazard curve's levels may be given in: name -> (factor to SI, SI unit). An IM's SI
#: unit is that of the registry (:mod:`rockstudy.motions.measures`); its levels may be in any
#: unit here of that dimension ("g" is the unit g, standard gravity 9.80665 m/s^2, as for
#: records and ``scale_to``).
UNIT_FACTORS = {
    "g": (STANDARD_GRAVITY, "m/s^2"),
    "m/s^2": (1.0, "m/s^2"),
    "m/s2": (1.0, "m/s^2"),
    "cm/s^2": (0.01, "m/s^2"),
    "cm/s2": (0.01, "m/s^2"),
    "gal": (0.01, "m/s^2"),
    "m/s": (1.0, "m/s"),
    "cm/s": (0.01, "m/s"),
    "m": (1.0, "m"),
    "cm": (0.01, "m"),
    "s": (1.0, "s"),
}


def units_for(im: str, units: str | None, name: str = "units") -> str:
    """``units`` checked against the dimension of ``im`` (its SI unit when None)."""
    si = measures.measure(im).unit
    if units is not None and not isinstance(units, str):
        raise TypeError(f"{name} must be a unit name (a string) or None, got {units!r}")
    if units is None or units == si:
        return si
    allowed = sorted(u for u, (_, dim) in UNIT_FACTORS.items() if dim == si)
    if units not in UNIT_FACTORS:
        raise ValueError(f"{name} of {im!r} must be one of {allowed}, got {units!r}")
    if UNIT_FACTORS[units][1] != si:
        raise ValueError(
            f"{name}={units!r} is not a unit of {im!r}, which is in {si}: use one of {allowed}"
        )
    return units
