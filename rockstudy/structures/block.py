"""The rigid rectangular rocking block (Housner 1963), as in paper [000] section 2."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..constants import G

__all__ = [
    "Block",
    "block_parameters",
    "check_half_diagonal",
    "check_slenderness",
    "frequency_parameter",
    "FREQUENCY_PARAMETER_RANGE",
    "HALF_DIAGONAL_RANGE",
    "MIN_SLENDERNESS",
    "restitution_housner",
    "uplift_acceleration",
    "uplift_acceleration_block",
]

#: Half-diagonals R [m] taken: a micrometre to a thousand kilometres, beyond any rocking
#: object at both ends (the kernels divide by powers of p = sqrt(3 g / 4 R)).
HALF_DIAGONAL_RANGE = (1e-6, 1e6)
#: Smallest slenderness alpha [rad] taken: a needle a million times taller than wide. Below
#: ~1e-200 the kernels' divisions by powers of alpha underflow to zero.
MIN_SLENDERNESS = 1e-6
#: Frequency parameters p [rad/s] taken where p is given directly (equivalent blocks): those
#: of HALF_DIAGONAL_RANGE, widened to whole decades.
FREQUENCY_PARAMETER_RANGE = (1e-3, 1e4)


def check_half_diagonal(value) -> float:
    """R [m] as a float, or a ValueError naming ``half_diagonal`` and HALF_DIAGONAL_RANGE."""
    lo, hi = HALF_DIAGONAL_RANGE
    return _validate.in_range("half_diagonal", value, lo, hi, f"[{lo:g}, {hi:g}] m")


def check_slenderness(value) -> float:
    """alpha [rad] as a float, or a ValueError naming ``slenderness``: [MIN_SLENDERNESS,
    pi/2)."""
    return _validate.in_range(
        "slenderness",
        value,
        MIN_SLENDERNESS,
        math.pi / 2,
        f"[{MIN_SLENDERNESS:g}, pi/2) rad",
        high_open=True,
    )


def frequency_parameter(half_diagonal: float) -> float:
    r"""Frequency parameter of a rectangular block, p [rad/s].

    eq. (2.2) of [000]:

    .. math:: p = \sqrt{3 g / (4 R)}

    Parameters
    ----------
    half_diagonal : float
        R, half the diagonal of the block [m].
    """
    return math.sqrt(3.0 * G / (4.0 * half_diagonal))


def uplift_acceleration_block(slenderness):
    r"""Ground acceleration that lifts a rectangular block off its base [m/s^2], on arrays.

    eq. (1) of [003] (section 2 of [000]):

    .. math:: \ddot u_{g,\min} = g \lambda = g \tan\alpha

    Parameters
    ----------
    slenderness : array_like
        alpha [rad] (theta_cr of an equivalent block, which is a block).
    """
    return G * np.tan(np.asarray(slenderness, dtype=float))


def restitution_housner(slenderness: float) -> float:
    r"""Housner's coefficient of restitution of a rectangular block [-].

    Angular-momentum balance about the new pivot, eq. (2.4) of [000]:

    .. math:: \eta = 1 - \tfrac{3}{2} \sin^2 \alpha

    Parameters
    ----------
    slenderness : float
        alpha, the slenderness angle [rad].
    """
    return 1.0 - 1.5 * math.sin(slenderness) ** 2


@dataclass(frozen=True)
class Block:
    """A free-standing rigid rectangular block that can rock on its two base corners.

    Parameters
    ----------
    half_diagonal : float
        R, half the diagonal of the block [m]; must be > 0.
    slenderness : float
        alpha = atan(b / h) [rad]; must lie in (0, pi/2).
    restitution : float or None
        eta, the ratio of angular velocities after and before an impact [-], in (0, 1].
        ``None`` (default) uses Housner's value (2.4) of [000].

    Examples
    --------
    >>> blk = Block(half_diagonal=1.0, slenderness=0.2)
    >>> round(blk.frequency_parameter, 4)
    2.7124
    """

    half_diagonal: float
    slenderness: float
    restitution: float | None = None

    def __post_init__(self):
        R = check_half_diagonal(self.half_diagonal)
        alpha = check_slenderness(self.slenderness)
        if self.restitution is None:
            eta = restitution_housner(alpha)
            if not eta > 0.0:  # sin^2(alpha) >= 2/3: width / height >= sqrt(2)
                raise ValueError(
                    f"slenderness alpha = {alpha:.4g} rad gives Housner's restitution "
                    f"1 - 1.5 sin^2(alpha) = {eta:.3g} (eq. 2.4 of [000]), which must lie in "
                    "(0, 1]: it needs alpha < 0.9553 rad (width / height < sqrt(2)); give "
                    "restitution for a squatter block"
                )
        else:
            eta = _validate.restitution(self.restitution)
        object.__setattr__(self, "half_diagonal", R)
        object.__setattr__(self, "slenderness", alpha)
        object.__setattr__(self, "restitution", eta)

    @classmethod
    def from_dimensions(cls, width: float, height: float, restitution: float | None = None):
        """Build a block from its full width 2b and height 2h [m].

        Parameters
        ----------
        width, height : float
            2b and 2h [m]; both must be > 0.
        restitution : float or None
            As in :class:`Block`.
        """
        b = _validate.positive("width", width) / 2.0
        h = _validate.positive("height", height) / 2.0
        try:
            return cls(math.hypot(b, h), math.atan2(b, h), restitution)
        except ValueError as exc:
            if "restitution" in str(exc).split(" ")[0]:
                raise
            raise ValueError(f"width = {width!r} m and height = {height!r} m: {exc}") from None

    @property
    def frequency_parameter(self) -> float:
        """p = sqrt(3 g / 4 R) [rad/s], eq. (2.2) of [000]."""
        return frequency_parameter(self.half_diagonal)

    @property
    def width(self) -> float:
        """2b = 2 R sin(alpha) [m]."""
        return 2.0 * self.half_diagonal * math.sin(self.slenderness)

    @property
    def height(self) -> float:
        """2h = 2 R cos(alpha) [m]."""
        return 2.0 * self.half_diagonal * math.cos(self.slenderness)

    @property
    def uplift_acceleration(self) -> float:
        """Ground acceleration that starts rocking, g tan(alpha) [m/s^2], section 2 of [000]."""
        return G * math.tan(self.slenderness)


def uplift_acceleration(structure) -> float:
    """Ground acceleration that starts a structure rocking [m/s^2].

    g lambda with lambda = G_nl(0) / B_nl(0), eq. (10) of [003], for a structure with
    ``rocking_parameters()`` (the smaller of the two directions of an asymmetric one: the
    ground pushes both ways); g tan(alpha), eq. (1) of [003], for a block or an
    :class:`~rockstudy.structures.EquivalentBlock` (whose alpha is theta_cr).
    """
    if hasattr(structure, "rocking_parameters"):
        params = structure.rocking_parameters()
        params = params if isinstance(params, tuple) else (params,)
        return G * min(float(q.uplift) for q in params)
    return float(uplift_acceleration_block(block_parameters(structure)[1]))


def block_parameters(structure) -> tuple[float, float, float]:
    """(p [rad/s], alpha [rad], eta [-]) of a block, or of a structure's equivalent block."""
    if hasattr(structure, "equivalent_block"):
        structure = structure.equivalent_block()
    try:
        return (
            float(structure.frequency_parameter),
            float(structure.slenderness),
            float(structure.restitution),
        )
    except AttributeError:
        raise TypeError(
            "structure must be a rockstudy Block or provide equivalent_block(); "
            f"got {type(structure).__name__}"
        ) from None
