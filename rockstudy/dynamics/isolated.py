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

from numba import njit

from ..constants import G
from ..structures.isolated import IsolatedBlock, isolated_restitution

__all__ = [
    "IsolatedBody",
    "accelerations",
    "base_acceleration_at_rest",
    "friction_demand",
    "housner_acceleration",
    "impact_jump",
    "impact_velocities",
    "isolator_acceleration",
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
    mu: float = 0.0  #: the friction pendulum's mu (0: a linear isolator) [-]

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
            structure.friction_coefficient,
        )

    @property
    def core(self):
        """(R, alpha, M, omega, zeta, mu): the scalar arguments of :func:`accelerations`."""
        return tuple(self)


@njit(cache=True)
def isolator_acceleration(x_b, x_b_dot, slide, omega, zeta, mu):
    r"""The isolator's force on the base per unit isolated mass [m/s^2], the base sliding in
    the direction ``slide`` (+1 or -1; its sign is immaterial when mu = 0):

    .. math:: 2 \zeta_b \omega_b \dot x_b + \omega_b^2 x_b + \mu g\, \mathrm{slide}

    A linear isolator (mu = 0): spring and dashpot. A friction pendulum of radius R_fp:
    omega_b^2 = g / R_fp (the pendulum's restoring force M g x_b / R_fp) and Coulomb's
    friction mu M g against the sliding, the normal force taken as the isolated weight M g.
    """
    return 2.0 * zeta * omega * x_b_dot + omega * omega * x_b + mu * G * slide


@njit(cache=True)
def housner_acceleration(theta, a_base, side, radius, slenderness):
    r"""theta'' [rad/s^2] of the block rocking on side s on a base of absolute acceleration
    ``a_base``, the base's motion prescribed (Housner's eq. 2.2 of [000]):
    theta'' = -(3 / 4R) (cos(phi) a_base + g sin(phi)), phi = s alpha - theta."""
    phi = side * slenderness - theta
    return -0.75 / radius * (math.cos(phi) * a_base + G * math.sin(phi))


@njit(cache=True)
def accelerations(x_b, x_b_dot, theta, theta_dot, a_g, side, slide, R, alpha, M, omega, zeta, mu):
    r"""(x_b'', theta'') in every regime: the block at rest (side 0) or rocking on side s, the
    base sliding in the direction ``slide`` or stuck (slide 0 with mu > 0: the friction
    pendulum's stick, x_b'' = 0, the block rocking as Housner's on the ground).

    The base sliding: :func:`rest_acceleration` at rest, the coupled Lagrange equations of
    :func:`rocking_accelerations` while the block rocks. The scalar arguments (R, alpha, M,
    omega, zeta, mu: :attr:`IsolatedBody.core`) let the numba kernel compile this function
    as it is (it is compiled by numba: :mod:`._isolated_model` calls it).
    """
    if slide == 0.0 and mu > 0.0:
        if side == 0.0:
            return 0.0, 0.0
        return 0.0, housner_acceleration(theta, a_g, side, R, alpha)
    f_iso = isolator_acceleration(x_b, x_b_dot, slide, omega, zeta, mu)
    if side == 0.0:
        return -a_g - f_iso, 0.0
    phi = side * alpha - theta
    c, sn = R * math.cos(phi), R * math.sin(phi)
    i0 = 4.0 / 3.0 * R * R
    f_base = -M * (a_g + f_iso) - sn * theta_dot**2
    f_block = -c * a_g - G * sn
    det = M * i0 - c * c
    return (i0 * f_base - c * f_block) / det, (M * f_block - c * f_base) / det


@njit(cache=True)
def friction_demand(x_b, theta, theta_dot, a_g, side, R, alpha, M, omega):
    r"""The friction force a stuck base needs, per unit isolated mass [m/s^2]: the first
    row of :func:`rocking_accelerations` with x_b'' = 0 and theta'' Housner's on the ground
    (:func:`housner_acceleration`),

    .. math:: F/M = -(\ddot u_g + \omega_b^2 x_b)
                    - (R\cos\phi\, \ddot\theta + R\sin\phi\, \dot\theta^2) / M

    (the block's inertia term vanishes at rest). The base stays stuck while ``|F|/M`` <= mu g
    and slides off in the direction of F otherwise.
    """
    demand = -(a_g + omega * omega * x_b)
    if side != 0.0:
        phi = side * alpha - theta
        thdd = housner_acceleration(theta, a_g, side, R, alpha)
        demand -= R * (math.cos(phi) * thdd + math.sin(phi) * theta_dot**2) / M
    return demand


def base_acceleration_at_rest(x_b, x_b_dot, omega, zeta, mu=0.0, slide=1.0):
    r"""The base's absolute acceleration u_g'' + x_b'' [m/s^2] with the block at rest on it and
    the base sliding (in the direction ``slide`` when mu > 0).

    From the rest regime's equation (:func:`rest_acceleration`): the isolator's force over
    the whole isolated mass (:func:`isolator_acceleration`),

    .. math:: \ddot u_g + \ddot x_b = -(2 \zeta_b \omega_b \dot x_b + \omega_b^2 x_b
              + \mu g\, \mathrm{slide})

    (the ground's acceleration does not enter: it reaches the base through the isolator; a
    stuck base moves with the ground, its absolute acceleration is u_g'').
    """
    return -isolator_acceleration(x_b, x_b_dot, slide, omega, zeta, mu)


def rest_acceleration(x_b, x_b_dot, a_g, omega, zeta, mu=0.0, slide=1.0):
    r"""x_b'' [m/s^2] of the sliding base with the block at rest on it: the linear SDOF

    .. math:: \ddot x_b + 2 \zeta_b \omega_b \dot x_b + \omega_b^2 x_b = -\ddot u_g

    (M x_b'' + c x_b' + k x_b = -M u_g'' divided by M = m + m_b, Vassiliou & Makris 2012),
    with mu g slide more on the left for a friction pendulum.
    """
    return base_acceleration_at_rest(x_b, x_b_dot, omega, zeta, mu, slide) - a_g


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


def rocking_accelerations(x_b, x_b_dot, theta, theta_dot, a_g, side, body: IsolatedBody, slide=1.0):
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
    The determinant R^2 (4 M / 3 - cos^2 phi) is > 0 for every M >= 1. A friction
    pendulum adds mu g slide to the isolator's force (:func:`isolator_acceleration`); its
    stuck base (slide 0) leaves Housner's block on the ground (:func:`accelerations`).
    """
    return accelerations(x_b, x_b_dot, theta, theta_dot, a_g, side, slide, *body.core)


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
    eta = isolated_restitution(body.slenderness, body.mass - 1.0)
    return impact_jump(
        x_b_dot, theta_dot, eta, body.radius * math.cos(body.slenderness) / body.mass
    )


@njit(cache=True)
def impact_jump(x_b_dot, theta_dot, eta, h_over_m):
    """(x_b', theta') after an impact (:func:`impact_velocities`) from the restitution eta and
    h / M = R cos(alpha) / M, the scalar form the numba kernel compiles."""
    after = eta * theta_dot
    return x_b_dot - h_over_m * (after - theta_dot), after


def settling_velocity(x_b_dot, theta_dot, body: IsolatedBody):
    """x_b' [m/s] of the base once a block whose impacts have died out (theta' below the rest
    speed) is taken to rest on it: theta' -> 0 conserving the horizontal momentum of block
    and base, M x_b' + h theta' (:func:`impact_velocities`), per unit block mass."""
    return x_b_dot + body.radius * math.cos(body.slenderness) / body.mass * theta_dot
