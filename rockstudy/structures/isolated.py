"""A rigid block standing free on a seismically isolated base (Vassiliou & Makris 2012).

The base, of mass m_b = ``base_mass_ratio`` m (m the block's mass), slides on a linear isolator
(spring k and dashpot c) tied to the ground; the block rocks on the moving base. The isolator is
given, as an engineer states it, by the period and damping ratio of the whole isolated mass:

    T_b = 2 pi sqrt((m + m_b) / k),   c = 2 zeta_b (m + m_b) (2 pi / T_b).

A friction-pendulum isolator (``isolator="friction_pendulum"``, its ``radius`` R_fp and
``friction`` mu) instead carries the base on a spherical surface: the restoring force
M g x_b / R_fp (the period T_b = 2 pi sqrt(R_fp / g) while it slides) and Coulomb's friction
mu M g, the base sticking to the ground when its velocity vanishes under a smaller force.

The equations of motion are in :mod:`rockstudy.dynamics.isolated`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import _validate
from ..constants import G
from .block import Block, restitution_housner

__all__ = [
    "ISOLATORS",
    "IsolatedBlock",
    "MAX_BASE_MASS_RATIO",
    "PERIOD_RANGE",
    "isolated_restitution",
]

#: Largest base mass ratio m_b / m taken: 1e12 (a base a trillion times heavier than the block
#: is rigid ground; beyond that the momentum of the block drowns in the base's rounding).
MAX_BASE_MASS_RATIO = 1e12
#: Isolator periods T_b [s] taken: a millisecond (a stiff mount) to 100 s.
PERIOD_RANGE = (1e-3, 100.0)
#: The isolators an :class:`IsolatedBlock` takes.
ISOLATORS = ("linear", "friction_pendulum")


def isolated_restitution(slenderness: float, base_mass_ratio: float) -> float:
    r"""The ratio of the block's angular velocities after and before an impact on the isolated
    base, theta_dot+ / theta_dot- [-].

    Derived in :func:`rockstudy.dynamics.isolated.impact_velocities` from the conservation of
    the block's angular momentum about the new pivot and of the horizontal momentum of block
    and base (the isolator's forces are finite, so they give no impulse), as in Vassiliou &
    Makris (2012); with gamma = m_b / m and I_0 = (4/3) m R^2:

    .. math:: \frac{\dot\theta^+}{\dot\theta^-} =
              \frac{\tfrac43 - 2\sin^2\alpha - \cos^2\alpha / (1 + \gamma)}
                   {\tfrac43 - \cos^2\alpha / (1 + \gamma)}

    which is Housner's 1 - (3/2) sin^2 alpha (eq. 2.4 of [000]) as gamma -> infinity.

    Parameters
    ----------
    slenderness : float
        alpha [rad].
    base_mass_ratio : float
        gamma = m_b / m [-].
    """
    c2 = math.cos(slenderness) ** 2 / (1.0 + base_mass_ratio)
    return (4.0 / 3.0 - 2.0 * math.sin(slenderness) ** 2 - c2) / (4.0 / 3.0 - c2)


def _isolator(iso) -> tuple:
    """(period, damping, radius, friction) of an :class:`IsolatedBlock`'s isolator, checked:
    a ValueError names the argument that does not fit its ``isolator``."""
    if iso.isolator not in ISOLATORS:
        raise ValueError(f"isolator must be one of {list(ISOLATORS)}, got {iso.isolator!r}")
    lo, hi = PERIOD_RANGE
    if iso.isolator == "linear":
        for name in ("radius", "friction"):
            if getattr(iso, name) is not None:
                raise ValueError(f"{name}: only a friction_pendulum isolator takes it")
        for name in ("period", "damping"):
            if getattr(iso, name) is None:
                raise ValueError(f"{name}: a linear isolator needs it")
        period = _validate.in_range("period", iso.period, lo, hi, f"[{lo:g}, {hi:g}] s")
        return period, _validate.in_range("damping", iso.damping, 0.0, 1.0, "[0, 1]"), None, None
    for name in ("period", "damping"):
        if getattr(iso, name) is not None:
            raise ValueError(
                f"{name}: a friction_pendulum isolator takes none (its period is "
                "2 pi sqrt(radius / g), its damping is its friction)"
            )
    for name in ("radius", "friction"):
        if getattr(iso, name) is None:
            raise ValueError(f"{name}: a friction_pendulum isolator needs it")
    lo_r, hi_r = (G * (t / (2.0 * math.pi)) ** 2 for t in PERIOD_RANGE)
    radius = _validate.in_range("radius", iso.radius, lo_r, hi_r, f"[{lo_r:.3g}, {hi_r:.4g}] m")
    mu = _validate.in_range("friction", iso.friction, 0.0, 1.0, "[0, 1]")
    return 2.0 * math.pi * math.sqrt(radius / G), 0.0, radius, mu


def _check_block(block) -> Block:
    """``block`` if it is a :class:`Block` with Housner's restitution, else a TypeError or a
    ValueError naming ``block``."""
    if not isinstance(block, Block):
        raise TypeError(f"block must be a rockstudy Block, got {type(block).__name__}")
    housner = restitution_housner(block.slenderness)
    if not math.isclose(block.restitution, housner, rel_tol=1e-12):
        raise ValueError(
            f"block.restitution: the isolated block's impacts follow from momentum (their "
            f"restitution depends on base_mass_ratio), so the block must have Housner's "
            f"restitution {housner:.6g}, not {block.restitution!r}: build it without restitution"
        )
    return block


@dataclass(frozen=True)
class IsolatedBlock:
    """A :class:`Block` standing free on a base of mass ``base_mass_ratio`` times the block's,
    carried by a linear isolator (spring and dashpot) or a friction pendulum on the ground.

    Parameters
    ----------
    block : Block
        The rocking block, with Housner's restitution (the default): the restitution on the
        isolated base follows from momentum (:func:`isolated_restitution`).
    base_mass_ratio : float
        gamma = m_b / m, the base's mass over the block's [-], in (0, :data:`MAX_BASE_MASS_RATIO`].
    period : float
        T_b = 2 pi sqrt((m + m_b) / k) [s], the linear isolator's period with the whole
        isolated mass on it (block at rest), in :data:`PERIOD_RANGE`. A friction pendulum
        takes none: its period is 2 pi sqrt(R_fp / g).
    damping : float
        zeta_b, the linear isolator's damping ratio for the whole isolated mass [-], in
        [0, 1]. A friction pendulum takes none (0: it dissipates by friction).
    isolator_capacity : float, optional
        The isolator's displacement capacity [m], > 0: stored for reporting
        (:attr:`rockstudy.dynamics.isolated.IsolatedResult.exceeds_capacity`), never used
        by the dynamics.
    isolator : {"linear", "friction_pendulum"}
        The isolator's law (:data:`ISOLATORS`).
    radius : float
        R_fp [m], the friction pendulum's radius of curvature, whose period
        2 pi sqrt(R_fp / g) lies in :data:`PERIOD_RANGE`; a friction pendulum only.
    friction : float
        mu, the friction pendulum's coefficient of friction [-], in [0, 1]; a friction
        pendulum only.

    Examples
    --------
    >>> from rockstudy.structures import Block, IsolatedBlock
    >>> iso = IsolatedBlock(Block(1.0, 0.2), base_mass_ratio=1.0, period=2.0, damping=0.1)
    >>> round(iso.restitution, 4)
    0.9075
    >>> fp = IsolatedBlock(Block(1.0, 0.2), base_mass_ratio=1.0,
    ...                    isolator="friction_pendulum", radius=1.0, friction=0.05)
    >>> round(fp.period, 4)
    2.0061
    """

    block: Block
    base_mass_ratio: float
    period: float | None = None
    damping: float | None = None
    isolator_capacity: float | None = None
    isolator: str = "linear"
    radius: float | None = None
    friction: float | None = None

    def __post_init__(self):
        _check_block(self.block)
        ratio = _validate.in_range(
            "base_mass_ratio",
            self.base_mass_ratio,
            0.0,
            MAX_BASE_MASS_RATIO,
            f"(0, {MAX_BASE_MASS_RATIO:g}]",
            low_open=True,
        )
        capacity = self.isolator_capacity
        if capacity is not None:
            capacity = _validate.positive("isolator_capacity", capacity)
        object.__setattr__(self, "base_mass_ratio", ratio)
        object.__setattr__(self, "isolator_capacity", capacity)
        for name, value in zip(
            ("period", "damping", "radius", "friction"), _isolator(self), strict=True
        ):
            object.__setattr__(self, name, value)
        eta = isolated_restitution(self.block.slenderness, ratio)
        if not eta > 0.0:
            raise ValueError(
                f"base_mass_ratio {ratio!r} with slenderness {self.block.slenderness:.4g} rad "
                f"gives the impact ratio {eta:.3g} (isolated_restitution), which must be > 0: "
                "a squat block on a light base stops dead at an impact; give a heavier base"
            )

    @property
    def friction_coefficient(self) -> float:
        """mu of the friction pendulum; 0.0 for a linear isolator [-]."""
        return 0.0 if self.friction is None else self.friction

    @property
    def isolator_frequency(self) -> float:
        """omega_b = 2 pi / T_b [rad/s]."""
        return 2.0 * math.pi / self.period

    @property
    def restitution(self) -> float:
        """theta_dot+ / theta_dot- at an impact on the base [-] (:func:`isolated_restitution`)."""
        return isolated_restitution(self.block.slenderness, self.base_mass_ratio)

    @property
    def uplift_acceleration(self) -> float:
        """g tan(alpha) [m/s^2]: the base's absolute acceleration that lifts the block."""
        return G * math.tan(self.block.slenderness)
