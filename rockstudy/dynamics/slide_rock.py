"""The planar contact model of a free-standing rectangular block: rest, slide, rock,
slide-rock and free flight.

A rigid block of half-width b, half-height h (R = sqrt(b^2 + h^2), alpha = atan(b / h),
I_G = m R^2 / 3) stands on a rigid horizontal base with Coulomb friction: a static
coefficient mu_s and a kinetic mu_k <= mu_s. The base moves with the ground accelerations
u_h'' (horizontal) and u_v'' (upwards); everything is written in the ground's frame, where the
block feels gravity g_e = g + u_v'' and the inertial force -m u_h''. The regimes and their
equations follow from Newton-Euler with the contact forces F (horizontal) and N (vertical)
(Shenton & Jones 1991, "Base excitation of rigid bodies. I. Formulation", J. Eng. Mech.
117(10); Shenton 1996, "Criteria for initiation of slide, rock, and slide-rock rigid-body
modes", J. Eng. Mech. 122(7)):

- rest: F = m u_h'', N = m g_e, anywhere inside the base;
- slide (theta = 0): u'' = -u_h'' - sigma mu_k g_e, sigma = sign(u');
- rock about corner s (theta > 0 on the + corner, s theta >= 0): Housner's eq. (2.2) of [000];
- slide-rock (the corner s slips at u' with sigma = sign(u')): :func:`slide_rock_accelerations`;
- flight (N would be negative): the centre of mass falls freely, theta_dot is constant.

The slip u [m] is the horizontal displacement, relative to the ground, of the base's point
that lies under the centre of mass when the block stands upright: u = x_c - s b, with x_c the
contact corner's position, continuous across a change of corner.

Transitions (Shenton 1996): rest ends where ``|u_h''|`` / g_e exceeds min(mu_s, tan alpha)
(:func:`initiation_regime`); a slip starts where ``|F|`` > mu_s N and stops where the slip
velocity reaches 0 with ``|F|`` <= mu_s N; the block leaves the ground where N < 0; a sliding
block lifts where its friction's moment mu_k > tan alpha puts the resultant outside the base.

Impacts (:func:`corner_impact`, :func:`rocking_impact`): Housner's restitution (the
new corner sticks, theta_dot+ = eta theta_dot- plus the angular momentum of the slip) where
the impulse that needs stays in the friction cone ``|P_h|`` <= mu_s P_v; otherwise the
new corner keeps slipping under a plastic normal impulse and Coulomb's law on the impulses,
``|P_h|`` = mu_k P_v (Brach 1989, "Rigid body collisions", J. Appl. Mech. 56(1), eq. 8 with
normal restitution 0 and the impulse ratio capped at the friction coefficient). That never
creates energy: on the line of impulses that stop the corner's normal velocity, the kinetic
energy change is a convex function which is <= 0 at the frictionless impulse and at the
sticking one, and Brach's impulse lies between them.
"""

from __future__ import annotations

import math

from numba import njit

from ..constants import G

__all__ = [
    "REGIMES",
    "inertia_ratio",
    "sliding_acceleration",
    "rocking_acceleration",
    "contact_forces",
    "slide_rock_denominator",
    "slide_rock_accelerations",
    "uplift_force_ratio",
    "slide_rock_threshold",
    "leaves_rest",
    "initiation_regime",
    "corner_offset",
    "corner_velocity",
    "apply_impulse",
    "corner_impact",
    "rocking_impact",
    "centre_velocity",
    "kinetic_energy",
]

#: The regimes, in the order of ``regime`` codes.
REGIMES = ("rest", "slide", "rock", "slide_rock", "flight")
REST, SLIDE, ROCK, SLIDE_ROCK, FLIGHT = range(5)


@njit(cache=True)
def inertia_ratio():
    """I_G / (m R^2) of a rectangular block: (b^2 + h^2) / 3 / R^2 = 1/3."""
    return 1.0 / 3.0


@njit(cache=True)
def sliding_acceleration(a_h, a_v, slip, friction):
    """u'' [m/s^2] of a block sliding flat, slip direction ``slip`` = sign(u'):

    .. math:: \\ddot u = -\\ddot u_h - \\sigma \\mu_k (g + \\ddot u_v)

    (Newton in the ground's frame, N = m g_e; eq. 4 of Shenton & Jones 1991)."""
    return -a_h - slip * friction * (G + a_v)


@njit(cache=True)
def rocking_acceleration(theta, a_h, a_v, side, radius, slenderness):
    """theta'' [rad/s^2] about the fixed corner ``side``: Housner's eq. (2.2) of [000] with
    gravity g + u_v'' and p^2 = 3 g / (4 R),

    .. math:: \\ddot\\theta = -p^2 [(1 + \\ddot u_v / g) \\sin(s \\alpha - \\theta)
              + (\\ddot u_h / g) \\cos(s \\alpha - \\theta)]."""
    x = slenderness * side - theta
    return -0.75 / radius * ((G + a_v) * math.sin(x) + a_h * math.cos(x))


@njit(cache=True)
def contact_forces(theta, theta_dot, theta_ddot, u_ddot, a_h, a_v, side, radius, slenderness):
    """(F / m, N / m) [m/s^2]: the base's force on a block in contact at corner ``side``,
    m times the centre of mass's absolute acceleration plus its weight (Newton):

    .. math::

       F / m = \\ddot u_h + \\ddot u + R (\\ddot\\theta \\cos\\phi + s \\dot\\theta^2
       \\sin\\phi), \\quad N / m = g + \\ddot u_v + R (s \\ddot\\theta \\sin\\phi
       - \\dot\\theta^2 \\cos\\phi), \\quad \\phi = \\alpha - s \\theta.

    With u'' = 0 these are :func:`rockstudy.dynamics.contact.contact_forces`."""
    phi = slenderness - side * theta
    sin, cos = math.sin(phi), math.cos(phi)
    w2 = theta_dot * theta_dot
    f_h = a_h + u_ddot + radius * (theta_ddot * cos + side * w2 * sin)
    f_v = G + a_v + radius * (side * theta_ddot * sin - w2 * cos)
    return f_h, f_v


@njit(cache=True)
def slide_rock_denominator(theta, side, slip, friction, slenderness):
    """1/3 + k s sin(phi), k = s sin(phi) - mu_k sigma cos(phi): the effective inertia of
    slide-rock (:func:`slide_rock_accelerations`). Where it is <= 0 the equations have no
    solution (Painleve's paradox; possible only for mu_k > 4/3)."""
    phi = slenderness - side * theta
    k = side * math.sin(phi) - friction * slip * math.cos(phi)
    return inertia_ratio() + k * side * math.sin(phi)


@njit(cache=True)
def slide_rock_accelerations(theta, theta_dot, a_h, a_v, side, slip, friction, radius, alpha):
    """(u'', theta'', N / m) of slide-rock: rotation about the corner ``side`` that slips in
    the direction ``slip`` = sign(u'), with F = -sigma mu_k N.

    Newton-Euler (Shenton & Jones 1991, eqs. 10-12): m y_G'' = N - m g_e with
    y_G = R cos(phi), I_G theta'' = -N R (s sin phi - mu_k sigma cos phi), hence

    .. math::

       \\ddot\\theta = -\\frac{k (g_e - R \\cos\\phi \\, \\dot\\theta^2)}
       {R (1/3 + k s \\sin\\phi)}, \\quad k = s \\sin\\phi - \\mu_k \\sigma \\cos\\phi,

    N / m = g_e + R (s theta'' sin phi - theta_dot^2 cos phi) and
    u'' = -sigma mu_k N / m - u_h'' - R (theta'' cos phi + s theta_dot^2 sin phi).
    """
    phi = alpha - side * theta
    sin, cos = math.sin(phi), math.cos(phi)
    k = side * sin - friction * slip * cos
    g_e = G + a_v
    centripetal = radius * cos * theta_dot * theta_dot
    theta_ddot = -k * (g_e - centripetal) / (radius * (inertia_ratio() + k * side * sin))
    normal = g_e + side * radius * sin * theta_ddot - centripetal
    tangential = radius * (theta_ddot * cos + side * theta_dot * theta_dot * sin)
    return -slip * friction * normal - a_h - tangential, theta_ddot, normal


@njit(cache=True)
def uplift_force_ratio(acceleration, slenderness):
    """``|F| / N`` at the instant a block at rest starts to rock under a step of ground
    acceleration a = ``|u_h''|`` / g >= tan(alpha) (horizontal shaking only), from
    :func:`contact_forces` with Housner's theta'' at theta = theta_dot = 0:

    .. math::

       \\frac{|F|}{N} = \\frac{a - \\tfrac34 \\cos\\alpha (a \\cos\\alpha - \\sin\\alpha)}
       {1 + \\tfrac34 \\sin\\alpha (a \\cos\\alpha - \\sin\\alpha)}

    (= tan alpha at a = tan alpha, increasing in a towards (1 + 3 sin^2 alpha) /
    (3 sin alpha cos alpha)). Shenton 1996's rock / slide-rock boundary is where it
    reaches mu_s.
    """
    s, c = math.sin(slenderness), math.cos(slenderness)
    excess = 0.75 * (acceleration * c - s)
    return (acceleration - c * excess) / (1.0 + s * excess)


@njit(cache=True)
def slide_rock_threshold(friction, slenderness):
    """a* = ``|u_h''|`` / g above which a block at rest with mu >= tan(alpha) starts in
    slide-rock instead of rock (a step of acceleration, horizontal only): the root of
    :func:`uplift_force_ratio` = mu (Shenton 1996),

    .. math::

       a^* = \\frac{\\mu (1 + 3 \\cos^2\\alpha) - 3 \\sin\\alpha \\cos\\alpha}
       {1 + 3 \\sin^2\\alpha - 3 \\mu \\sin\\alpha \\cos\\alpha},

    inf where the denominator is <= 0 (mu >= (1 + 3 sin^2 alpha) / (3 sin alpha cos alpha):
    never slide-rock); tan(alpha) at mu = tan(alpha). NaN for mu < tan(alpha), where the
    block slides and never rocks from rest.
    """
    s, c = math.sin(slenderness), math.cos(slenderness)
    if friction < s / c:
        return math.nan
    den = 1.0 + 3.0 * s * s - 3.0 * friction * s * c
    return math.inf if den <= 0.0 else (friction * (1.0 + 3.0 * c * c) - 3.0 * s * c) / den


@njit(cache=True)
def leaves_rest(a_h, a_v, static, radius, slenderness):
    """> 0 exactly where a block at rest under the ground (a_h, a_v) [m/s^2] leaves rest:
    ``|a_h|`` - mu_s (g + a_v) where mu_s < tan(alpha) (it slides first), else s theta'' of
    Housner's equation at theta = 0 on the side s = -sign(a_h) it is pushed to (the rocking
    kernels' lift test, :func:`._rhs._lift`: a block said to lift does rise, to the last
    bit)."""
    if static < math.tan(slenderness):
        return abs(a_h) - static * (G + a_v)
    side = -1.0 if a_h > 0.0 else 1.0
    return side * rocking_acceleration(0.0, a_h, a_v, side, radius, slenderness)


@njit(cache=True)
def initiation_regime(a_h, a_v, static, kinetic, radius, slenderness):
    """The regime a block at rest (or stopping, slip velocity 0, theta = 0) enters under the
    ground (a_h, a_v) [m/s^2] (Shenton 1996): rest while ``|a_h|`` / g_e <= min(mu_s,
    tan alpha) (:func:`leaves_rest`, to the last bit); otherwise rock if the rocking forces
    at uplift stay inside the cone (``|F|`` <= mu_s N), else slide if mu_k <= tan(alpha)
    (the friction's resultant stays inside the base), else slide-rock. Returns (regime, side
    or slip direction -sign(a_h))."""
    tan = math.tan(slenderness)
    side = -1.0 if a_h > 0.0 else 1.0
    if not leaves_rest(a_h, a_v, static, radius, slenderness) > 0.0:
        return REST, side
    if static < tan and abs(a_h) <= tan * (G + a_v):
        return SLIDE, side
    acc = rocking_acceleration(0.0, a_h, a_v, side, radius, slenderness)
    f_h, f_v = contact_forces(0.0, 0.0, acc, 0.0, a_h, a_v, side, radius, slenderness)
    if abs(f_h) <= static * f_v:
        return ROCK, side
    return (SLIDE if kinetic <= tan else SLIDE_ROCK), side


@njit(cache=True)
def corner_offset(theta, corner, radius, slenderness):
    """(r_x, r_y) [m]: the corner ``corner`` (+1 or -1) from the centre of mass."""
    phi = slenderness - corner * theta
    return corner * radius * math.sin(phi), -radius * math.cos(phi)


@njit(cache=True)
def corner_velocity(vx, vy, theta_dot, rx, ry):
    """The velocity [m/s] of the point at (r_x, r_y) from the centre of mass moving at
    (vx, vy) with theta_dot (theta clockwise)."""
    return vx + theta_dot * ry, vy - theta_dot * rx


@njit(cache=True)
def apply_impulse(vx, vy, theta_dot, p_h, p_v, rx, ry, radius):
    """The velocities after the impulse (p_h, p_v) per unit mass [m/s] at (r_x, r_y):
    momentum, and the angular momentum about G, I_G dtheta_dot = -(r x P)."""
    inertia = inertia_ratio() * radius * radius
    return vx + p_h, vy + p_v, theta_dot - (rx * p_v - ry * p_h) / inertia


@njit(cache=True)
def corner_impulse(vx, vy, theta_dot, theta, corner, static, kinetic, radius, slenderness):
    """A corner strikes the base: the velocities after it, the impulse per unit mass and
    whether the corner sticks.

    Plastic in the normal direction (the corner's normal velocity becomes 0). Sticking (the
    corner's velocity becomes 0) where the impulse it needs lies in the cone
    ``|P_h|`` <= mu_s P_v; otherwise Coulomb's law on the impulses, P_h = -sign mu_k P_v in
    the direction of the sticking impulse (Brach 1989, eq. 8; see the module docstring for
    why this never creates energy). Where no such impulse exists (Painleve's paradox,
    possible only for mu_k > 4/3) every returned number is NaN.

    Returns
    -------
    (vx, vy, theta_dot), (p_h, p_v), stuck
    """
    rx, ry = corner_offset(theta, corner, radius, slenderness)
    cx, cy = corner_velocity(vx, vy, theta_dot, rx, ry)
    inv = 1.0 / (inertia_ratio() * radius * radius)
    w00, w01, w11 = 1.0 + ry * ry * inv, -rx * ry * inv, 1.0 + rx * rx * inv
    det = w00 * w11 - w01 * w01
    p_h = -(w11 * cx - w01 * cy) / det
    p_v = -(-w01 * cx + w00 * cy) / det
    if abs(p_h) <= static * p_v:
        return apply_impulse(vx, vy, theta_dot, p_h, p_v, rx, ry, radius), (p_h, p_v), True
    ratio = math.copysign(kinetic, p_h)
    den = w01 * ratio + w11
    if den <= 0.0:
        return (math.nan, math.nan, math.nan), (math.nan, math.nan), False
    p_v = -cy / den
    p_h = ratio * p_v
    return apply_impulse(vx, vy, theta_dot, p_h, p_v, rx, ry, radius), (p_h, p_v), False


def corner_impact(vx, vy, theta_dot, theta, corner, static, kinetic, radius, slenderness):
    """:func:`corner_impulse`, with a ValueError where no impulse exists (Painleve's
    paradox, possible only for mu_k > 4/3)."""
    after, impulse, stuck = corner_impulse(
        vx, vy, theta_dot, theta, corner, static, kinetic, radius, slenderness
    )
    if math.isnan(after[2]):
        raise ValueError(
            f"friction: mu_k = {kinetic!r} admits no impact impulse at this corner "
            "(Painleve's paradox, possible only for mu_k > 4/3)"
        )
    return after, impulse, stuck


@njit(cache=True)
def rocking_impact(u_dot, theta_dot, side, restitution, radius, slenderness):
    """theta_dot+ [rad/s] when the block on corner ``side`` lands on the other corner at
    theta = 0 and that corner sticks: Housner's restitution on the rotation (eq. 2.4 of
    [000], theta_dot+ = eta theta_dot-) plus the angular momentum of the slip u' about
    the new corner, m h u' / I_O with I_O = 4 m R^2 / 3:

    .. math:: \\dot\\theta^+ = \\eta \\dot\\theta^- + \\frac{3 \\cos\\alpha}{4 R} \\dot u^-.

    With Housner's eta = 1 - 3/2 sin^2 alpha this is the conservation of the angular
    momentum about the new corner (:func:`corner_impact` with the corner sticking)."""
    return restitution * theta_dot + 0.75 * math.cos(slenderness) / radius * u_dot


@njit(cache=True)
def centre_velocity(u_dot, theta, theta_dot, side, radius, slenderness):
    """(vx, vy) [m/s] of the centre of mass of a block in contact at corner ``side``:
    d/dt (x_c - s R sin phi, R cos phi) with x_c' = u'."""
    phi = slenderness - side * theta
    return u_dot + radius * math.cos(phi) * theta_dot, side * radius * math.sin(phi) * theta_dot


@njit(cache=True)
def kinetic_energy(vx, vy, theta_dot, radius):
    """Kinetic energy per unit mass [J/kg] relative to the ground: translation plus
    I_G theta_dot^2 / 2."""
    return 0.5 * (vx * vx + vy * vy) + 0.5 * inertia_ratio() * radius * radius * theta_dot**2
