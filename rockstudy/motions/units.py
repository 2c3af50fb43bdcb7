"""The units of the package: one table of the unit names it reads, with their factors to SI.

Every door that reads a unit name reads :data:`UNITS`: a study's ``scale_to.units``
(:func:`rockstudy.motions.measures.units_of`), a hazard curve's ``units``
(:class:`rockstudy.risk.HazardCurve`), a record file's ``units``
(:meth:`rockstudy.motions.Record.from_csv`, a study's ``motion.units``) and the CLI's
``--units``. A name is accepted wherever its dimension is, with the same factor.

A unit's dimension is read from its SI unit (:func:`dimension`: ``"m/s^2"`` and
``"m s^-2"`` are both an acceleration), never from a measure's name.
"""

from __future__ import annotations

import re

from ..constants import STANDARD_GRAVITY

__all__ = ["ACCELERATION", "UNITS", "aliases", "acceleration_units", "dimension"]

#: Every unit name the package reads: name -> (factor to SI, SI unit). ``g`` is the unit g,
#: standard gravity 9.80665 m/s^2 (as for records); ``g s`` a velocity, as CAV is often quoted;
#: a gal is 1 cm/s^2.
UNITS = {
    "m/s^2": (1.0, "m/s^2"),
    "m/s2": (1.0, "m/s^2"),
    "g": (STANDARD_GRAVITY, "m/s^2"),
    "cm/s^2": (0.01, "m/s^2"),
    "cm/s2": (0.01, "m/s^2"),
    "gal": (0.01, "m/s^2"),
    "m/s": (1.0, "m/s"),
    "cm/s": (0.01, "m/s"),
    "g s": (STANDARD_GRAVITY, "m/s"),
    "m": (1.0, "m"),
    "cm": (0.01, "m"),
    "s": (1.0, "s"),
}

#: One factor of an SI unit: a base unit and its power (``s^-2``, ``m^0.5``, ``kg``).
_FACTOR = re.compile(r"(m|s|kg|rad)(?:\^(-?[0-9]+(?:\.[0-9]+)?))?\Z")


def dimension(si_unit: str) -> tuple[tuple[str, float], ...]:
    """The powers of the base units of an SI unit, sorted by base unit, e.g. ``(("m", 1.0),
    ("s", -2.0))`` for ``"m/s^2"``, ``"m s^-2"`` or ``"m/s/s"``; ``()`` for ``"1"``.

    Factors are separated by ``" "``, ``"*"`` or ``"/"``; a ``"/"`` divides by the factor that
    follows it. A ValueError names the unit if a factor is not a base unit (m, s, kg, rad) with
    an optional power.
    """
    powers: dict[str, float] = {}
    if si_unit.strip() != "1":
        for sign, factor in re.findall(r"([ */]?)([^ */]+)", si_unit.strip()):
            match = _FACTOR.match(factor)
            if match is None:
                raise ValueError(f"unit {si_unit!r}: {factor!r} is not m, s, kg or rad^power")
            power = float(match.group(2) or 1.0) * (-1.0 if sign == "/" else 1.0)
            powers[match.group(1)] = powers.get(match.group(1), 0.0) + power
    return tuple(sorted((base, p) for base, p in powers.items() if p != 0.0))


#: The dimension of an acceleration, m s^-2.
ACCELERATION = dimension("m/s^2")


def aliases(si_unit: str) -> dict[str, float]:
    """The names of :data:`UNITS` of the dimension of ``si_unit``: name -> factor to SI, with
    ``si_unit`` itself first (factor 1), as written."""
    dim = dimension(si_unit)
    out = {si_unit: 1.0}
    out.update({name: f for name, (f, si) in UNITS.items() if dimension(si) == dim})
    return out


def acceleration_units() -> dict[str, float]:
    """The names of :data:`UNITS` of an acceleration (a record file's samples): name -> factor
    to m/s^2."""
    return aliases("m/s^2")
