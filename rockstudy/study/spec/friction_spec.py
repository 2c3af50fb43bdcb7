"""The friction of a study's contact: ``friction`` (top level or per object) is one
coefficient mu (mu_s = mu_k) or a pair [mu_s, mu_k] of a static and a kinetic coefficient,
each in (0, :data:`~rockstudy.dynamics.simulate.MAX_FRICTION`], mu_s >= mu_k; an objects CSV
file gives the pair as the columns ``friction`` (mu_s) and ``friction_kinetic`` (mu_k), a cell
holding one number.
"""

from __future__ import annotations

import math

from ...dynamics.simulate import MAX_FRICTION

__all__ = ["Friction", "as_pair", "coefficient", "friction_pair", "friction_value"]

#: The type of a ``friction`` field: mu, or (mu_s, mu_k) (read from a list [mu_s, mu_k] by
#: :func:`as_pair`, a field's before-validator).
Friction = float | tuple[float, float]


def as_pair(value):
    """A list (a TOML array) as a tuple, for the strict ``tuple`` of :data:`Friction`; a
    list of another length than 2 a ValueError saying what is allowed."""
    if isinstance(value, list):
        if len(value) != 2:
            raise ValueError(
                f"give one coefficient mu or a pair [mu_s, mu_k], got {len(value)} values"
            )
        return tuple(value)
    return value


def coefficient(value, what: str) -> float:
    """``value`` as a coefficient in (0, MAX_FRICTION], or a ValueError naming ``what``."""
    if not (math.isfinite(value) and 0.0 < value <= MAX_FRICTION):
        raise ValueError(f"{what} must lie in (0, {MAX_FRICTION:g}], got {value!r}")
    return float(value)


def friction_value(value):
    """A ``friction`` field's value checked: None, mu as a float, or (mu_s, mu_k) with
    mu_s >= mu_k; a ValueError saying what is allowed otherwise."""
    if value is None:
        return None
    if isinstance(value, (list, tuple)):
        if len(value) != 2:
            raise ValueError(
                f"friction: give one coefficient mu or a pair [mu_s, mu_k], got {len(value)} values"
            )
        static = coefficient(value[0], "the static coefficient mu_s")
        kinetic = coefficient(value[1], "the kinetic coefficient mu_k")
        if kinetic > static:
            raise ValueError(
                f"a pair [mu_s, mu_k] needs mu_s >= mu_k, got [{static!r}, {kinetic!r}]"
            )
        return (static, kinetic)
    return coefficient(value, "the coefficient mu")


def friction_pair(value) -> tuple[float, float]:
    """(mu_s, mu_k) of a checked ``friction`` value (NaNs for None)."""
    if value is None:
        return (math.nan, math.nan)
    return value if isinstance(value, tuple) else (value, value)
