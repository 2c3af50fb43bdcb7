"""The free-rocking map of a block (private): the outcome of rocking after the motion.

Energy is conserved between impacts and each impact multiplies the speed by eta (eqs. 2.3,
4.12 of [000]): the peaks, the impacts until rest and the overturning decision follow without
integration (:func:`free_rocking_map`); :func:`free_tail_end` bounds the free rocking that
the solvers follow when it is integrated.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import FALL_ROTATION
from .constants import MODEL_LINEAR, NEVER_AT_REST, UNDAMPED_WINDOW


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
