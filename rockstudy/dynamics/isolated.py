r"""The physics of a rigid block standing free on a seismically isolated base.

The model of Vassiliou & Makris (2012), "Analysis of the rocking response of rigid blocks
standing free on a seismically isolated base", Earthquake Engng Struct. Dyn. 41:177-196: a
block (mass m, half-diagonal R, slenderness alpha, I_0 = (4/3) m R^2 about a corner) on a base
of mass m_b = gamma m, which a linear isolator (stiffness k, dashpot c) ties to the ground;
x_b is the base's displacement relative to the ground, theta the block's rotation (theta > 0
on the positive pivot, as Housner's block of [000]). The equations below are derived here from
the Lagrangian of that model (the paper's text is not in the project's papers, so its
equation numbers are not quoted). Everything is per unit block mass, with M = 1 + gamma,
k = M omega_b^2 and c = 2 zeta_b M omega_b (:class:`rockstudy.structures.IsolatedBlock`).

Two regimes:

- **rest**: the block moves with the base, one degree of freedom,
  M x_b'' + c x_b' + k x_b = -M u_g''  (:func:`rest_acceleration`);
- **rocking** on side s: with phi = s alpha - theta, the Lagrangian
  T = M (u_g' + x_b')^2 / 2 + m R cos(phi) (u_g' + x_b') theta' + I_0 theta'^2 / 2,
  V = m g R cos(phi) + k x_b^2 / 2, gives the coupled mass matrix of
  :func:`rocking_accelerations`.

The block lifts when the base's absolute acceleration at rest passes g tan(alpha)
(:func:`uplift_side`), impacts exchange momentum between block and base
(:func:`impact_velocities`), and it overturns at ``|theta|`` = pi/2. The ``solve_ivp`` path that
integrates them is :mod:`rockstudy.dynamics.isolated_reference`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..constants import G
from ..structures.isolated import IsolatedBlock, isolated_restitution

__all__ = [
    "IsolatedBody",
    "base_acceleration_at_rest",
    "impact_velocities",
    "rest_acceleration",
    "rocking_accelerations",
    "settling_velocity",
    "uplift_side",
]


class IsolatedBody(NamedTuple):
    """The parameters of the equations, per unit block mass."""

    radius: float  #: R [m]
    slenderness: float  #: alpha [rad]
    mass: float  #: M = 1 + gamma, the isolated mass over the block's [-]
    omega: float  #: omega_b = 2 pi / T_b [rad/s]
    zeta: float  #: zeta_b [-]

    @classmethod
    def of(cls, structure: IsolatedBlock) -> IsolatedBody:
        """The body of an :class:`~rockstudy.structures.IsolatedBlock`."""
        blk = structure.block
        return cls(
            blk.half_diagonal,
            blk.slenderness,
            1.0 + structure.base_mass_ratio,
            structure.isolator_frequency,
            structure.damping,
        )


def base_acceleration_at_rest(x_b, x_b_dot, omega, zeta):
    r"""The base's absolute acceleration u_g'' + x_b'' [m/s^2] with the block at rest on it.

    From the rest regime's equation (:func:`rest_acceleration`): the isolator's force over
    the whole isolated mass,

    .. math:: \ddot u_g + \ddot x_b = -(2 \zeta_b \omega_b \dot x_b + \omega_b^2 x_b)

    (the ground's acceleration does not enter: it reaches the base through the isolator).
    """
    return -(2.0 * zeta * omega * x_b_dot + omega * omega * x_b)


def rest_acceleration(x_b, x_b_dot, a_g, omega, zeta):
    r"""x_b'' [m/s^2] of the base with the block at rest on it: the linear SDOF

    .. math:: \ddot x_b + 2 \zeta_b \omega_b \dot x_b + \omega_b^2 x_b = -\ddot u_g

    (M x_b'' + c x_b' + k x_b = -M u_g'' divided by M = m + m_b, Vassiliou & Makris 2012).
    """
    return base_acceleration_at_rest(x_b, x_b_dot, omega, zeta) - a_g


def uplift_side(a_base, slenderness):
    r"""The side s a block at rest lifts onto under the base's absolute acceleration
    ``a_base`` [m/s^2]: +1 where a_base < -g tan(alpha), -1 where a_base > g tan(alpha), else 0.

    Housner's condition (eq. 1 of [003]) on the base instead of the ground: the block's
    equation of :func:`rocking_accelerations` at theta = theta' = 0 gives
    (I_0 - m R^2 cos^2(alpha) / M) theta'' = -m R (g sin(s alpha) + cos(alpha) a_base)
    with a_base the rest regime's (:func:`base_acceleration_at_rest`), so theta'' has the sign
    of s exactly when s a_base < -g tan(alpha). (A positive base acceleration throws the block
    back onto its negative pivot.)
    """
    limit = G * math.tan(slenderness)
    if a_base < -limit:
        return 1.0
    if a_base > limit:
        return -1.0
    return 0.0


def rocking_accelerations(x_b, x_b_dot, theta, theta_dot, a_g, side, body: IsolatedBody):
    r"""(x_b'', theta'') [m/s^2, rad/s^2] of the block rocking on side s on the moving base.

    Lagrange's equations of T and V (module docstring), per unit block mass, with
    phi = s alpha - theta:

    .. math::
        \begin{bmatrix} M & R\cos\phi \\ R\cos\phi & \tfrac43 R^2 \end{bmatrix}
        \begin{bmatrix} \ddot x_b \\ \ddot\theta \end{bmatrix} =
        \begin{bmatrix} -M \ddot u_g - c \dot x_b - k x_b - R \sin\phi\, \dot\theta^2 \\
                        -R \cos\phi\, \ddot u_g - g R \sin\phi \end{bmatrix}

    The second row is Housner's eq. (2.2) of [000] with the base's absolute acceleration
    u_g'' + x_b'' for the ground's; the first is the base's, loaded by the block's inertia.
    The determinant R^2 (4 M / 3 - cos^2 phi) is > 0 for every M >= 1.
    """
    R, alpha, M, omega, zeta = body
    phi = side * alpha - theta
    c, sn = R * math.cos(phi), R * math.sin(phi)
    i0 = 4.0 / 3.0 * R * R
    f_base = -M * (a_g + 2.0 * zeta * omega * x_b_dot + omega * omega * x_b) - sn * theta_dot**2
    f_block = -c * a_g - G * sn
    det = M * i0 - c * c
    return (i0 * f_base - c * f_block) / det, (M * f_block - c * f_base) / det


def impact_velocities(x_b_dot, theta_dot, body: IsolatedBody):
    r"""(x_b', theta') [m/s, rad/s] just after an impact (theta = 0) from those just before.

    The impulse acts at the new pivot and between block and base only (the old pivot lifts,
    Housner's assumption; the isolator's and gravity's forces are finite), so two momenta are
    conserved, as in Vassiliou & Makris (2012), per unit block mass (h = R cos alpha,
    b = R sin alpha, derived in docs/isolated.rst):

    - the block's angular momentum about the new pivot:
      I_0 theta'+ + h (u_g' + x_b'+) = (I_0 - 2 b^2) theta'- + h (u_g' + x_b'-);
    - the horizontal momentum of block and base:
      M x_b'+ + h theta'+ = M x_b'- + h theta'-.

    Hence theta'+ = eta theta'- with eta = :func:`~rockstudy.structures.isolated_restitution`
    (Housner's 1 - 1.5 sin^2 alpha, eq. 2.4 of [000], as M -> infinity), and
    x_b'+ = x_b'- - (h / M) (theta'+ - theta'-). The ground's velocity u_g' is continuous,
    so the relative x_b' jumps as the absolute one does.
    """
    R, alpha, M = body.radius, body.slenderness, body.mass
    after = isolated_restitution(alpha, M - 1.0) * theta_dot
    return x_b_dot - R * math.cos(alpha) / M * (after - theta_dot), after


def settling_velocity(x_b_dot, theta_dot, body: IsolatedBody):
    """x_b' [m/s] of the base once a block whose impacts have died out (theta' below the rest
    speed) is taken to rest on it: theta' -> 0 conserving the horizontal momentum of block
    and base, M x_b' + h theta' (:func:`impact_velocities`), per unit block mass."""
    return x_b_dot + body.radius * math.cos(body.slenderness) / body.mass * theta_dot
