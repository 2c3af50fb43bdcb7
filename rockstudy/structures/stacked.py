"""Two rigid rectangular blocks stacked on rigid ground: a statue on a plinth that can rock
(Psycharis 1990, "Dynamic behaviour of rocking two-block assemblies"; Spanos, Roussis &
Politis 2001).

The geometry and the masses only; the equations of motion are in
:mod:`rockstudy.dynamics.stacked`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import _validate
from .block import Block, restitution_housner

__all__ = ["StackedBlocks"]


def _check_block(name: str, block) -> Block:
    """``block`` if it is a :class:`Block` whose restitution is Housner's (the impacts of the
    assembly derive their own), or a TypeError/ValueError naming ``name``."""
    if not isinstance(block, Block):
        raise TypeError(f"{name} must be a rockstudy Block, got {type(block).__name__}")
    eta = restitution_housner(block.slenderness)
    if not math.isclose(block.restitution, eta, rel_tol=1e-12, abs_tol=0.0):
        raise ValueError(
            f"{name}: StackedBlocks derives its impacts from angular momentum (Psycharis 1990), "
            f"so the block's restitution must be Housner's {eta:.6g}, got "
            f"{block.restitution!r} (a given restitution is not taken yet)"
        )
    return block


@dataclass(frozen=True)
class StackedBlocks:
    """An upper block standing on a lower block that stands on rigid ground, in the plane.

    No sliding at either interface; each interface rocks on the corners of the upper
    body's base. The masses are per unit thickness, from the areas 4 b h of the blocks and
    the densities (the lower one's taken as 1: only ratios enter the motion).

    Parameters
    ----------
    lower, upper : Block
        The plinth and the object on it (half-diagonal R and slenderness alpha each); their
        restitution must be Housner's (the default), since the assembly derives its impacts
        from angular momentum.
    density_ratio : float
        rho_upper / rho_lower [-], finite and > 0.
    offset : float
        Horizontal distance from the lower block's axis to the upper block's axis [m]
        (positive towards +x, the side theta > 0 rotates to); the upper base must lie on the
        lower top: ``|offset| + b_upper <= b_lower``.

    Examples
    --------
    >>> s = StackedBlocks(Block(1.0, 0.3), Block(0.5, 0.2))
    >>> round(s.upper_mass / s.lower_mass, 4)
    0.1724
    """

    lower: Block
    upper: Block
    density_ratio: float = 1.0
    offset: float = 0.0

    def __post_init__(self):
        _check_block("lower", self.lower)
        _check_block("upper", self.upper)
        rho = _validate.positive("density_ratio", self.density_ratio)
        e = _validate.number("offset", self.offset)
        if not math.isfinite(e):
            raise ValueError(f"offset must be finite, got {self.offset!r}")
        b1, b2 = self.lower.width / 2.0, self.upper.width / 2.0
        if abs(e) + b2 > b1 * (1.0 + 1e-12):
            raise ValueError(
                f"offset: the upper block must stand on the lower one's top, |offset| + "
                f"b_upper <= b_lower; got |{e!r}| + {b2:.6g} > {b1:.6g} m"
            )
        object.__setattr__(self, "density_ratio", rho)
        object.__setattr__(self, "offset", e)

    @property
    def lower_mass(self) -> float:
        """m_lower = 4 b h (density 1, unit thickness)."""
        return self.lower.width * self.lower.height

    @property
    def upper_mass(self) -> float:
        """m_upper = density_ratio 4 b h (unit thickness)."""
        return self.density_ratio * self.upper.width * self.upper.height
