"""The free-rocking map of a block (private): the outcome of rocking after the motion.

Energy is conserved between impacts and each impact multiplies the speed by eta (eqs. 2.3,
4.12 of [000]): the peaks, the impacts until rest and the overturning decision follow without
integration (:func:`free_rocking_map`), and the time of the largest peak in closed form
(:func:`free_peak_time`); :func:`free_tail_end` bounds the free rocking that the solvers
follow when it is integrated.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import FALL_ROTATION
from .constants import MODEL_LINEAR, NEVER_AT_REST, UNDAMPED_WINDOW

#: Carlson's duplication stops when the arguments agree to this relative spread: the error of
#: the fifth-order series left is then about 1e-16 (Press et al., Numerical Recipes 6.11).
RF_SPREAD = 0.0025
#: Duplications at most: each divides the spread by 4, from any spread down to RF_SPREAD.
RF_MAX_ITER = 60


@njit(cache=True)
def free_tail_end(p, eta, duration):
    """End of the free rocking that the solvers follow after a motion of ``duration`` [s]:
    until rest (inf), or for a block that never rests (eta >= 1) until duration + 100/p, so
    that impacts are counted within that window, the same way by every path."""
    return duration + UNDAMPED_WINDOW / p if eta >= 1.0 else np.inf


@njit(cache=True, inline="always")
def _rise(u, alpha, model):
    r"""Potential energy at rotation u above that at theta = 0, / p^2 [-]:
    :math:`\cos(\alpha - u) - \cos\alpha = 2 \sin(\alpha - u/2) \sin(u/2)` (nonlinear) or
    :math:`\alpha u - u^2/2` (linearized), in forms free of cancellation for small u, alpha."""
    if model == MODEL_LINEAR:
        return u * (alpha - 0.5 * u)
    return 2.0 * math.sin(alpha - 0.5 * u) * math.sin(0.5 * u)


@njit(cache=True, inline="always")
def _rise_to_top(alpha, model):
    """:func:`_rise` at the top u = alpha: 1 - cos(alpha) = 2 sin^2(alpha/2), or alpha^2/2."""
    if model == MODEL_LINEAR:
        return 0.5 * alpha * alpha
    return 2.0 * math.sin(0.5 * alpha) ** 2


@njit(cache=True)
def _rotation_at(k, alpha, model):
    r"""The rotation u in [0, alpha] with :func:`_rise` (u) = k, for 0 <= k <= the top.

    With :math:`s = \sin(\alpha/2)` and :math:`b = \sin((\alpha - u)/2) = \sqrt{s^2 - k/2}`,
    :math:`u/2 = \arcsin s - \arcsin b = \arcsin\frac{k/2}{s\sqrt{1-b^2} + b\cos(\alpha/2)}`
    (nonlinear); :math:`u = 2k / (\alpha + \sqrt{\alpha^2 - 2k})` (linearized). Both keep
    the relative precision of k, where :math:`\alpha - \arccos(\cos\alpha + k)` loses it.
    """
    if model == MODEL_LINEAR:
        return 2.0 * k / (alpha + math.sqrt(max(alpha * alpha - 2.0 * k, 0.0)))
    sa = math.sin(0.5 * alpha)
    b = math.sqrt(max(sa * sa - 0.5 * k, 0.0))
    x = 0.5 * k / (sa * math.sqrt(1.0 - b * b) + b * math.cos(0.5 * alpha))
    return 2.0 * math.asin(min(x, 1.0))


@njit(cache=True)
def _impacts_until_rest(w1, rest, eta):
    """Impacts of a free-rocking sequence whose first impact left speed w1 (> 0): impact k
    leaves w1 eta^(k-1) (eq. 2.3 of [000]); the first one below ``rest`` ends it."""
    if w1 < rest:
        return 1
    if eta >= 1.0:
        return NEVER_AT_REST
    return 2 + int(math.floor(math.log(rest / w1) / math.log(eta)))


@njit(cache=True)
def free_rocking_map(u, v, p, alpha, eta, model, omega_rest):
    r"""Outcome of free rocking from rotation u = s theta and speed v = s theta_dot [rad, rad/s].

    Energy is conserved between impacts and each impact multiplies theta_dot by eta
    (eq. 2.3 of [000]); the peak after an impact follows from
    :math:`\cos(\alpha - \theta_{max}) = \cos\alpha + \dot\theta^2 / 2p^2` (eq. 4.12 of [000]
    for the linearized block). Returns (overturns, peak u, impacts until rest).
    """
    k = 0.5 * (v / p) ** 2 + _rise(u, alpha, model)  # energy above the impact level, / p^2
    top = _rise_to_top(alpha, model)
    peak = u
    if k >= top:
        if (u < alpha and v > 0.0) or (u >= alpha and v >= 0.0):
            return True, FALL_ROTATION, 0
    elif u > alpha:
        return True, FALL_ROTATION, 0
    elif v > 0.0:
        peak = _rotation_at(k, alpha, model)
    # speed at the first impact, / p; that impact always happens (counted, as integration
    # does, even when it leaves the block at rest)
    w = math.sqrt(max(2.0 * k, 0.0))
    rest = omega_rest / p
    w1 = eta * w
    k1 = 0.5 * w1 * w1
    if k1 >= top:
        return True, FALL_ROTATION, 1
    peak = max(peak, _rotation_at(k1, alpha, model))
    return False, peak, _impacts_until_rest(w1, rest, eta)


@njit(cache=True)
def _carlson_rf(x, y, z):
    r"""Carlson's symmetric elliptic integral of the first kind
    :math:`R_F(x, y, z) = \frac12 \int_0^\infty dt / \sqrt{(t+x)(t+y)(t+z)}` (x, y, z >= 0,
    at most one 0), by duplication and its fifth-order series (Carlson 1995)."""
    for _ in range(RF_MAX_ITER):
        mu = (x + y + z) / 3.0
        if max(abs(x - mu), abs(y - mu), abs(z - mu)) <= RF_SPREAD * mu:
            break
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
    mu = (x + y + z) / 3.0
    dx, dy = 1.0 - x / mu, 1.0 - y / mu
    dz = -(dx + dy)
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(mu)


@njit(cache=True)
def _travel_time(u0, w0, u1, w1, alpha, model):
    r"""p times the time [-] that free rocking takes between rotations u0 and u1 [rad] of one
    half cycle (no impact, no turning point strictly between them), where its speeds theta_dot
    / p are w0 and w1 (their signs ignored), in closed form.

    Linearized (eq. 3.5 of [000]): a = alpha - u obeys a'' = a, so a + |a'| grows as
    :math:`e^\tau` towards the pivot and shrinks so away from it:
    :math:`\tau = |\ln((a_0 + |w_0|) / (a_1 + |w_1|))|`. Nonlinear: with
    :math:`z = \sin^2((\alpha - u)/2)` the energy gives :math:`(w/2)^2 = z - b^2`
    (:math:`b^2 = \sin^2(\alpha/2) - k/2`, negative above the top), and
    :math:`\tau = \frac12 \int dz / \sqrt{z (z - b^2)(1 - z)}`, Carlson's
    :math:`R_F(U_{12}^2, U_{13}^2, U_{14}^2)` of the three factors at both ends (DLMF
    19.29.4 with a fourth factor 1), every term positive.
    """
    w0, w1 = abs(w0), abs(w1)
    if model == MODEL_LINEAR:
        return abs(math.log((alpha - u0 + w0) / (alpha - u1 + w1)))
    x1, x3 = math.sin(0.5 * (alpha - u0)), math.cos(0.5 * (alpha - u0))  # sqrt z, sqrt(1 - z)
    y1, y3 = math.sin(0.5 * (alpha - u1)), math.cos(0.5 * (alpha - u1))
    x2, y2 = 0.5 * w0, 0.5 * w1  # sqrt(z - b^2)
    dz = abs(math.sin(0.5 * (u1 - u0)) * math.sin(alpha - 0.5 * (u0 + u1)))  # |z0 - z1|
    u12 = (x1 * x2 * y3 + y1 * y2 * x3) / dz
    u13 = (x1 * x3 * y2 + y1 * y3 * x2) / dz
    u14 = (x1 * y2 * y3 + y1 * x2 * x3) / dz
    return _carlson_rf(u12 * u12, u13 * u13, u14 * u14)


@njit(cache=True)
def free_peak_time(u, v, p, alpha, eta, model):
    """Time [s] from rotation u = s theta and speed v = s theta_dot [rad, rad/s] to the largest
    peak of the free rocking that follows (of a block that does not overturn: the peak
    :func:`free_rocking_map` gives): the peak of this half cycle if the block rises (v > 0),
    else the one after the next impact (speed times eta, eq. 2.3 of [000]); each stretch by
    :func:`_travel_time`."""
    w = v / p
    k = 0.5 * w * w + _rise(u, alpha, model)
    if v > 0.0:
        return _travel_time(u, w, _rotation_at(k, alpha, model), 0.0, alpha, model) / p
    w_imp = math.sqrt(2.0 * k)
    to_impact = _travel_time(u, w, 0.0, w_imp, alpha, model) if u > 0.0 else 0.0
    w1 = eta * w_imp
    peak = _rotation_at(0.5 * w1 * w1, alpha, model)
    return (to_impact + _travel_time(0.0, w1, peak, 0.0, alpha, model)) / p
