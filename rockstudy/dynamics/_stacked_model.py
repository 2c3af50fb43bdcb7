"""The equations of two stacked blocks as numba kernels (private): the model of
:mod:`.stacked`, written out in closed form for the event-driven kernel
(:mod:`._stacked_scene`).

The assembly travels as one float array ``g`` (:func:`pack_geometry`, indices :data:`B1`...).
The state is (theta_1, theta_2, theta_1', theta_2'), the absolute rotations; each interface
k (0 ground, 1 upper) is flat or rocks on its corner s_k. Every function here is the
closed form of its namesake in :mod:`.stacked` (mass matrix and forcing of "both rocking",
their restriction to a regime, the lock margins, the post-impact velocities) and gives the
same numbers up to rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import G
from ._taylor import NO_REFCOUNT
from .constants import REST_FRACTION

#: Indices of :func:`pack_geometry`'s array: half-widths, half-heights, offset, masses,
#: centroidal inertias, p and alpha of each block, its rest speed, and each interface's
#: moment scale (the weight it carries times its half-width).
B1, H1, B2, H2, E, M1, M2, I1, I2, P1, P2, A1, A2, REST1, REST2, MOM1, MOM2 = range(17)
GEOMETRY_SIZE = 17


def pack_geometry(stacked) -> np.ndarray:
    """The kernel's array ``g`` of a :class:`~rockstudy.structures.StackedBlocks`."""
    from ..structures.block import frequency_parameter
    from .stacked import geometry

    geo = geometry(stacked)
    lo, up = stacked.lower, stacked.upper
    p = (frequency_parameter(lo.half_diagonal), frequency_parameter(up.half_diagonal))
    alpha = (lo.slenderness, up.slenderness)
    g = np.empty(GEOMETRY_SIZE)
    g[:9] = (geo.b1, geo.h1, geo.b2, geo.h2, geo.e, geo.m1, geo.m2, geo.i1, geo.i2)
    g[P1], g[P2], g[A1], g[A2] = p[0], p[1], alpha[0], alpha[1]
    g[REST1], g[REST2] = REST_FRACTION * p[0] * alpha[0], REST_FRACTION * p[1] * alpha[1]
    g[MOM1], g[MOM2] = (geo.m1 + geo.m2) * G * geo.b1, geo.m2 * G * geo.b2
    return g


@njit(cache=True, inline="always")
def _arms(g, s1, s2):
    """r_1, d, r_2 of :func:`.stacked._arms` as six floats."""
    return (-s1 * g[B1], g[H1], g[E] + s2 * g[B2] - s1 * g[B1], 2.0 * g[H1], -s2 * g[B2], g[H2])


@njit(cache=True, inline="always")
def _trig(q1, q2):
    """(cos q1, sin q1, cos q2, sin q2): computed once per state and shared by the
    equations of both corners (:func:`lock_margins`, :func:`post_impact`). (Shortcuts for a
    resting plinth, q1 = 0, or a locked pair, q2 = q1, measured slower: their branches cost
    more than the sines they save.)"""
    return math.cos(q1), math.sin(q1), math.cos(q2), math.sin(q2)


@njit(cache=True, inline="always")
def _columns(g, trig, s1, s2):
    """The Jacobian's velocity columns dRot(theta) v of r_1 and d (theta_1) and of r_2
    (theta_2) at the angles of ``trig`` (:func:`_trig`), as six floats."""
    r1x, r1y, dx, dy, r2x, r2y = _arms(g, s1, s2)
    c1, n1, c2, n2 = trig
    return (
        -r1x * n1 + r1y * c1,
        -r1x * c1 - r1y * n1,
        -dx * n1 + dy * c1,
        -dx * c1 - dy * n1,
        -r2x * n2 + r2y * c2,
        -r2x * c2 - r2y * n2,
    )


@njit(cache=True, **NO_REFCOUNT)
def both_equations(g, q1, q2, w1, w2, s1, s2, ug):
    """M = (m00, m01, m11) and F = (f0, f1) of "both rocking" on the corners (s1, s2)
    (:func:`.stacked.mass_matrix`, :func:`.stacked.forcing`) under u_g'' = ug [m/s^2]."""
    return _equations(g, _trig(q1, q2), w1, w2, s1, s2, ug)


@njit(cache=True, inline="always")
def _equations(g, trig, w1, w2, s1, s2, ug):
    """:func:`both_equations` at the angles of ``trig`` (:func:`_trig`)."""
    r1x, r1y, dx, dy, r2x, r2y = _arms(g, s1, s2)
    c1, n1, c2, n2 = trig
    m1, m2 = g[M1], g[M2]
    a1x, a1y, adx, ady, a2x, a2y = _columns(g, trig, s1, s2)
    m00 = m1 * (r1x * r1x + r1y * r1y) + g[I1] + m2 * (dx * dx + dy * dy)
    m01 = m2 * (adx * a2x + ady * a2y)
    m11 = m2 * (r2x * r2x + r2y * r2y) + g[I2]
    # f - W a_c: gravity, the ground's inertia force, minus the centripetal accelerations
    ww1, ww2 = w1 * w1, w2 * w2
    u1x = -m1 * ug + m1 * (r1x * c1 + r1y * n1) * ww1
    u1y = -m1 * G + m1 * (-r1x * n1 + r1y * c1) * ww1
    u2x = -m2 * ug + m2 * ((dx * c1 + dy * n1) * ww1 + (r2x * c2 + r2y * n2) * ww2)
    u2y = -m2 * G + m2 * ((-dx * n1 + dy * c1) * ww1 + (-r2x * n2 + r2y * c2) * ww2)
    f0 = a1x * u1x + a1y * u1y + adx * u2x + ady * u2y
    f1 = a2x * u2x + a2y * u2y
    return m00, m01, m11, f0, f1


@njit(cache=True, **NO_REFCOUNT)
def acceleration(g, y, s1, s2, flat0, flat1, ug):
    """(theta_1'', theta_2'') of the regime (flat0, flat1) (:func:`.stacked.
    regime_acceleration`, mapped back through S): "lower" keeps theta_2'' = theta_1'',
    "upper" theta_1'' = 0, rest both zero."""
    if flat0 and flat1:
        return 0.0, 0.0
    m00, m01, m11, f0, f1 = both_equations(g, y[0], y[1], y[2], y[3], s1, s2, ug)
    return reduced_solve(m00, m01, m11, f0, f1, flat0, flat1)


@njit(cache=True, inline="always")
def _row_multiplier(m00, m01, m11, r0, r1, k):
    """Lambda of one closed interface k (row G = (1, 0) or (-1, 1)) for M x = r + G^T
    Lambda, G x = 0: -(G adj(M) r) / (G adj(M) G^T) (the determinant cancels)."""
    g0, g1 = (1.0, 0.0) if k == 0 else (-1.0, 1.0)
    y0, y1 = m11 * g0 - m01 * g1, -m01 * g0 + m00 * g1
    return -(y0 * r0 + y1 * r1) / (g0 * y0 + g1 * y1)


@njit(cache=True, **NO_REFCOUNT)
def multipliers(m00, m01, m11, r0, r1, flat0, flat1):
    """(Lambda_ground, Lambda_upper) of the closed interfaces (NaN for an open one):
    :func:`.stacked._multipliers`; with both closed, -G^-T r = -(r0 + r1, r1)."""
    if flat0 and flat1:
        return -(r0 + r1), -r1
    if flat0:
        return _row_multiplier(m00, m01, m11, r0, r1, 0), np.nan
    if flat1:
        return np.nan, _row_multiplier(m00, m01, m11, r0, r1, 1)
    return np.nan, np.nan


@njit(cache=True, inline="always")
def _pivots(j, s1, s2, flat0, flat1):
    """The corner s = +1 (j = 0) or -1 (j = 1) of the closed interfaces, and the pivots
    (p1, p2) with it: s at a closed interface, its own side at a rocking one."""
    s = 1 - 2 * j
    return s, (s if flat0 else s1), (s if flat1 else s2)


@njit(cache=True, **NO_REFCOUNT)
def lock_margins(g, y, s1, s2, flat0, flat1, ug, out):
    """The closed interfaces' lock margins s Lambda(s) / moment scale, written to out =
    (ground +1, ground -1, upper +1, upper -1); +inf for an open interface
    (:func:`.stacked.lock_margins`, normalised as the reference's events)."""
    if not (flat0 or flat1):  # both rocking: no margin to compute
        for j in range(4):
            out[j] = np.inf
        return
    trig = _trig(y[0], y[1])
    for j in range(2):
        s, p1, p2 = _pivots(j, s1, s2, flat0, flat1)
        m00, m01, m11, f0, f1 = _equations(g, trig, y[2], y[3], p1, p2, ug)
        lam0, lam1 = multipliers(m00, m01, m11, f0, f1, flat0, flat1)
        out[j] = s * lam0 / g[MOM1] if flat0 else np.inf
        out[2 + j] = s * lam1 / g[MOM2] if flat1 else np.inf


@njit(cache=True, inline="always")
def _momenta(g, trig, p1, p2, v):
    """M at pivots (p1, p2) and the generalised momenta A^T W V of the bodies' velocities v
    (6,) about them, at the angles of ``trig`` (:func:`_trig`)."""
    m00, m01, m11, _, _ = _equations(g, trig, 0.0, 0.0, p1, p2, 0.0)
    a1x, a1y, adx, ady, a2x, a2y = _columns(g, trig, p1, p2)
    mom0 = g[M1] * (a1x * v[0] + a1y * v[1]) + g[I1] * v[2] + g[M2] * (adx * v[3] + ady * v[4])
    mom1 = g[M2] * (a2x * v[3] + a2y * v[4]) + g[I2] * v[5]
    return m00, m01, m11, mom0, mom1


@njit(cache=True)
def body_velocities(g, q1, q2, w1, w2, s1, s2, v):
    """V = A q' (6,) of the bodies (:func:`.stacked.body_velocities`), into v."""
    a1x, a1y, adx, ady, a2x, a2y = _columns(g, _trig(q1, q2), s1, s2)
    v[0], v[1], v[2] = a1x * w1, a1y * w1, w1
    v[3], v[4], v[5] = adx * w1 + a2x * w2, ady * w1 + a2y * w2, w2


@njit(cache=True)
def post_impact(g, q1, q2, v, s1, s2, flat0, flat1, margins):
    """The post-impact (theta_1', theta_2') of the regime (flat0, flat1; pivots s1, s2),
    conserving its generalised momenta about the new pivots, and the closed interfaces'
    impulse margins into ``margins`` (as :func:`lock_margins`, not normalised; NaN for an
    open interface): :func:`.stacked.post_impact_velocity`."""
    w1 = w2 = 0.0
    trig = _trig(q1, q2)
    for j in range(2):
        s, p1, p2 = _pivots(j, s1, s2, flat0, flat1)
        m00, m01, m11, mom0, mom1 = _momenta(g, trig, p1, p2, v)
        if j == 0:
            w1, w2 = reduced_solve(m00, m01, m11, mom0, mom1, flat0, flat1)
        lam0, lam1 = multipliers(m00, m01, m11, mom0, mom1, flat0, flat1)
        margins[j], margins[2 + j] = s * lam0, s * lam1
    return w1, w2


@njit(cache=True, inline="always")
def reduced_solve(m00, m01, m11, r0, r1, flat0, flat1):
    """x = S (S^T M S)^-1 S^T r of the regime (flat0, flat1), M = (m00, m01, m11): the
    accelerations of the forces r, or the velocities of the momenta r, mapped back to
    (theta_1, theta_2) ("lower": equal; "upper": theta_1 fixed; rest: zero)."""
    if flat0 and flat1:
        return 0.0, 0.0
    if flat1:
        x = (r0 + r1) / (m00 + 2.0 * m01 + m11)
        return x, x
    if flat0:
        return 0.0, r1 / m11
    det = m00 * m11 - m01 * m01
    return (m11 * r0 - m01 * r1) / det, (m00 * r1 - m01 * r0) / det
