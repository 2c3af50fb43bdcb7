r"""The physics of two stacked rocking blocks (:class:`~rockstudy.structures.StackedBlocks`).

Psycharis (1990), "Dynamic behaviour of rocking two-block assemblies", Earthquake Engng
Struct. Dyn. 19:555-575 ([P90]); Spanos, Roussis & Politis (2001), "Dynamic analysis of
stacked rigid blocks", Soil Dyn. Earthquake Engng 21:559-578 ([SRP01]).

Coordinates. The absolute rotations q = (theta_1, theta_2) of the lower and the upper block
(each > 0 tipping towards +x, the sign of :func:`rockstudy.simulate`'s theta); the upper
block's rotation relative to the lower one is phi = theta_2 - theta_1. Each interface is
*flat* (closed: theta_1 = 0 on the ground, phi = 0 on the lower top) or *rocks* on the
corner s = +1 or -1 of the base of the body above it (s = sign of its angle). Hence the
regimes of [P90]: rest (both flat), the lower block rocking with the upper one locked to it
(one rigid body about the lower corner), the upper block rocking on the resting lower one,
and both rocking in the four pivot combinations (s_1, s_2).

Every regime is the two-degree-of-freedom system of "both rocking" restricted by a
selection S (q = S q_r): the Lagrangian mass matrix M = A^T W A and forcing
F = A^T (f - W a_c) of [P90] (section 2, written here through the Jacobian A of the bodies'
centre-of-mass velocities and spins, W = diag(m_1, m_1, I_1, m_2, m_2, I_2)), and
M_r = S^T M S, F_r = S^T F. The one-body regimes are Housner's equation of the block or of
the locked assembly (p^2 = m g R_c / I_O).

Transitions (uplift) follow from the contact forces: a flat interface is the constraint
G q'' = 0 with multiplier Lambda (the moment of the distributed contact about the pivot
corner s, on the body above); it stays closed while s Lambda >= 0 at both corners, and
lifts about the corner where s Lambda < 0 (:func:`lock_margins`).

Impacts ([P90], section 3; Housner's assumption at each interface): the impulses act at
the new pivots, so the angular momenta about them are conserved: the whole assembly's
about the new lower pivot and the upper block's about its pivot. In the coordinates of the
post-impact regime this is the conservation of its generalised momenta,
M_r q_r'^+ = (A S)^T W V^-, the mass-weighted projection of the pre-impact velocities V^-
(:func:`post_impact_velocity`): no impact creates energy. Of the post-impact regimes the
first consistent one is taken (released interfaces separating, closed ones pressed by a
compressive impulse), in the order of :func:`impact_candidates`: the impacting interface
moves onto its other corner (Housner) before it stays flat. A simultaneous impact at both
interfaces moves both onto their other corners, both momenta conserved about the two new
pivots at once: Housner's assumption applied at each interface, the rule [P90] states for
one interface extended here to two (not checked against a published simultaneous case; such
impacts need both angles to reach zero at the same instant and are rare). The impacting
interfaces stay flat only where that is inconsistent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..constants import G

__all__ = [
    "Geometry",
    "LOWER",
    "UPPER",
    "constraint_rows",
    "forcing",
    "geometry",
    "impact_candidates",
    "jacobian",
    "lock_margins",
    "mass_matrix",
    "mechanical_energy",
    "post_impact_velocity",
    "regime_acceleration",
    "regime_name",
    "selection",
]

#: Index of the ground interface (under the lower block) and of the upper interface.
LOWER, UPPER = 0, 1


@dataclass(frozen=True)
class Geometry:
    """Half-widths b, half-heights h [m], masses m and centroidal inertias I of the lower
    (1) and upper (2) blocks, and the offset e [m] of the upper axis from the lower one."""

    b1: float
    h1: float
    b2: float
    h2: float
    e: float
    m1: float
    m2: float
    i1: float
    i2: float

    @property
    def weights(self) -> np.ndarray:
        """W = diag(m_1, m_1, I_1, m_2, m_2, I_2): the kinetic-energy metric of the bodies'
        velocities V = (x_1', y_1', theta_1', x_2', y_2', theta_2')."""
        return np.array([self.m1, self.m1, self.i1, self.m2, self.m2, self.i2])


def geometry(stacked) -> Geometry:
    """The :class:`Geometry` of a :class:`~rockstudy.structures.StackedBlocks`; I = m R^2 / 3
    about each centre of mass (a rectangle of half-sides b, h)."""
    lo, up = stacked.lower, stacked.upper
    m1, m2 = stacked.lower_mass, stacked.upper_mass
    return Geometry(
        lo.width / 2.0,
        lo.height / 2.0,
        up.width / 2.0,
        up.height / 2.0,
        stacked.offset,
        m1,
        m2,
        m1 * lo.half_diagonal**2 / 3.0,
        m2 * up.half_diagonal**2 / 3.0,
    )


def _rot(theta, v):
    """Rot(theta) v: a body vector v = (X, Y) after the tipping rotation theta (> 0 towards
    +x)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([v[0] * c + v[1] * s, -v[0] * s + v[1] * c])


def _drot(theta, v):
    """d Rot(theta) v / d theta."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([-v[0] * s + v[1] * c, -v[0] * c - v[1] * s])


def _arms(geo: Geometry, s1: int, s2: int):
    """Body vectors [m]: r_1 (lower pivot -> lower centre), d (lower pivot -> upper pivot),
    r_2 (upper pivot -> upper centre), for the pivot corners s1, s2 ([P90] Fig. 1)."""
    r1 = (-s1 * geo.b1, geo.h1)
    d = (geo.e + s2 * geo.b2 - s1 * geo.b1, 2.0 * geo.h1)
    r2 = (-s2 * geo.b2, geo.h2)
    return r1, d, r2


def jacobian(geo: Geometry, q, s1: int, s2: int) -> np.ndarray:
    """A(q) (6 x 2): the bodies' velocities V = A q' of "both rocking" on the corners
    (s1, s2), q = (theta_1, theta_2)."""
    r1, d, r2 = _arms(geo, s1, s2)
    a = np.zeros((6, 2))
    a[0:2, 0], a[2, 0] = _drot(q[0], r1), 1.0
    a[3:5, 0] = _drot(q[0], d)
    a[3:5, 1], a[5, 1] = _drot(q[1], r2), 1.0
    return a


def _centripetal(geo: Geometry, q, qd, s1: int, s2: int) -> np.ndarray:
    """a_c: the bodies' accelerations at q'' = 0, (dA/dt) q' [m/s^2, rad/s^2]."""
    r1, d, r2 = _arms(geo, s1, s2)
    a = np.zeros(6)
    a[0:2] = -_rot(q[0], r1) * qd[0] ** 2
    a[3:5] = -_rot(q[0], d) * qd[0] ** 2 - _rot(q[1], r2) * qd[1] ** 2
    return a


def _applied(geo: Geometry, ground: float) -> np.ndarray:
    """f: gravity and the inertia force of the ground acceleration u_g'' [m/s^2] on each body
    (in the ground's frame)."""
    return np.array([-geo.m1 * ground, -geo.m1 * G, 0.0, -geo.m2 * ground, -geo.m2 * G, 0.0])


def mass_matrix(geo: Geometry, q, s1: int, s2: int) -> np.ndarray:
    r"""The Lagrangian mass matrix of "both rocking" (2 x 2), [P90] eq. (5):

    .. math:: M = A^T W A =
       \begin{pmatrix} I_{O1} + m_2 |d|^2 & m_2\, d \cdot \mathrm{Rot}(\phi) r_2 \\
       \cdot & \tfrac43 m_2 R_2^2 \end{pmatrix}

    coupled through phi = theta_2 - theta_1.
    """
    a = jacobian(geo, q, s1, s2)
    return a.T @ (geo.weights[:, None] * a)


def forcing(geo: Geometry, q, qd, s1: int, s2: int, ground: float) -> np.ndarray:
    """The generalised forces of "both rocking", F = A^T (f - W a_c) ([P90] eq. 5): gravity,
    the ground's inertia force and the velocity terms (m_2 dM_12/dphi theta_j'^2)."""
    a = jacobian(geo, q, s1, s2)
    return a.T @ (_applied(geo, ground) - geo.weights * _centripetal(geo, q, qd, s1, s2))


def selection(flat: tuple[bool, bool]) -> np.ndarray:
    """S (2 x n): q = S q_r for the regime whose interfaces are ``flat`` = (ground, upper):
    both rocking (I), the upper locked (q_r = theta_1), the lower resting (q_r = theta_2),
    rest (2 x 0)."""
    cols = {
        (False, False): [[1.0, 0.0], [0.0, 1.0]],
        (False, True): [[1.0], [1.0]],
        (True, False): [[0.0], [1.0]],
        (True, True): np.zeros((2, 0)),
    }
    return np.array(cols[tuple(flat)], dtype=float).reshape(2, -1)


def constraint_rows(flat: tuple[bool, bool]) -> np.ndarray:
    """G (m x 2): the closed interfaces' constraints G q = 0 (theta_1 = 0 on the ground,
    phi = theta_2 - theta_1 = 0 on the lower top), in the order (ground, upper)."""
    rows = [r for r, closed in zip(([1.0, 0.0], [-1.0, 1.0]), flat, strict=True) if closed]
    return np.array(rows, dtype=float).reshape(-1, 2)


def regime_acceleration(geo, q, qd, s1, s2, flat, ground) -> np.ndarray:
    """q_r'' = M_r^-1 F_r of the regime (``flat``, pivots s1, s2); q, qd full (2,)."""
    sel = selection(flat)
    if sel.shape[1] == 0:
        return np.zeros(0)
    m, f = mass_matrix(geo, q, s1, s2), forcing(geo, q, qd, s1, s2, ground)
    return np.linalg.solve(sel.T @ m @ sel, sel.T @ f)


def _multipliers(m, rhs, rows):
    """Lambda of M x = rhs + G^T Lambda with G x = 0: -(G M^-1 G^T)^-1 G M^-1 rhs."""
    mi_g = np.linalg.solve(m, rows.T)
    return -np.linalg.solve(rows @ mi_g, mi_g.T @ rhs)


def lock_margins(geo, q, qd, s1, s2, flat, ground) -> np.ndarray:
    """The closed interfaces' margins s Lambda(s) [N m per unit thickness], at s = +1 and
    -1 (shape (m, 2), rows in the order of :func:`constraint_rows`): the moment about the
    corner s of the distributed contact on the body above, which must push (>= 0) for the
    interface to stay closed; < 0 at a corner, the interface lifts about it. The pivots of
    the rocking interfaces are s1, s2; of a flat one, each corner in turn."""
    rows = constraint_rows(flat)
    out = np.empty((rows.shape[0], 2))
    for j, s in enumerate((1, -1)):
        p1 = s if flat[LOWER] else s1
        p2 = s if flat[UPPER] else s2
        lam = _multipliers(mass_matrix(geo, q, p1, p2), forcing(geo, q, qd, p1, p2, ground), rows)
        out[:, j] = s * lam
    return out


def post_impact_velocity(geo, q, v_before, s1, s2, flat):
    """The post-impact q_r' of the regime (``flat``, pivots s1, s2) and its closed
    interfaces' impulse margins (as :func:`lock_margins`, for the impulses).

    Angular momentum about the new pivots ([P90] section 3): the generalised momenta of the
    post-impact regime are conserved, M_r q_r'^+ = (A S)^T W V^-, with V^- the bodies'
    velocities just before (:func:`jacobian`); the impulse margins come from the same
    balance in "both rocking" with the closed interfaces' impulses as multipliers.
    """
    sel, rows, w = selection(flat), constraint_rows(flat), geo.weights
    margins = np.empty((rows.shape[0], 2))
    qd_r = np.zeros(sel.shape[1])
    for j, s in enumerate((1, -1)):
        p1 = s if flat[LOWER] else s1
        p2 = s if flat[UPPER] else s2
        a = jacobian(geo, q, p1, p2)
        m, mom = a.T @ (w[:, None] * a), a.T @ (w * v_before)
        if j == 0 and sel.shape[1]:
            qd_r = np.linalg.solve(sel.T @ m @ sel, sel.T @ mom)
        if rows.shape[0]:
            margins[:, j] = s * _multipliers(m, mom, rows)
    return qd_r, margins


def impact_candidates(flat, sides, impacting, slow):
    """The post-impact regimes to try, in order, as (flat, s1, s2).

    ``flat``: the interfaces' state before the impact; ``sides``: their pivots (the side of
    a rocking one); ``impacting``: which interfaces close now (angle 0, moving through it);
    ``slow``: of those, the ones whose speed is below the rest threshold (tried flat first:
    the rest rule of the single-block kernels). An impacting interface moves onto its other
    corner (-s, [P90]) or stays flat; an interface flat before stays flat or lifts about
    either corner; a rocking one keeps its pivot.
    """
    options = []
    for k in (LOWER, UPPER):
        if impacting[k]:
            opts = [(False, -sides[k]), (True, sides[k])]
            options.append(opts[::-1] if slow[k] else opts)
        elif flat[k]:
            options.append([(True, 1), (False, 1), (False, -1)])
        else:
            options.append([(False, sides[k])])
    return [
        ((lo[0], up[0]), lo[1], up[1])
        for rank in range(3)
        for lo in options[LOWER]
        for up in options[UPPER]
        if options[LOWER].index(lo) + options[UPPER].index(up) == rank
    ]


def body_velocities(geo, q, qd, s1, s2) -> np.ndarray:
    """V = A q' [m/s, rad/s] of the bodies, q' the full (theta_1', theta_2')."""
    return jacobian(geo, q, s1, s2) @ np.asarray(qd, dtype=float)


def mechanical_energy(geo, q, qd, s1, s2) -> float:
    """Kinetic plus gravitational energy [J per unit thickness], zero at rest upright: the
    kinetic energy 1/2 V^T W V and m g (y_c - y_c,rest) of both bodies."""
    v = body_velocities(geo, q, qd, s1, s2)
    r1, d, r2 = _arms(geo, s1, s2)
    y1 = _rot(q[0], r1)[1] - r1[1]
    y2 = _rot(q[0], d)[1] + _rot(q[1], r2)[1] - d[1] - r2[1]
    return 0.5 * float(v @ (geo.weights * v)) + G * (geo.m1 * y1 + geo.m2 * y2)


def regime_name(flat) -> str:
    """ "rest", "lower" (the lower rocking, the upper locked to it), "upper" (the upper
    rocking on the resting lower) or "both"."""
    return {
        (True, True): "rest",
        (False, True): "lower",
        (True, False): "upper",
        (False, False): "both",
    }[tuple(flat)]
