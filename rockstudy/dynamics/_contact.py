"""The contact forces of a rocking block at many times, in one numba loop (private).

The formulas are plain functions that numpy broadcasts (:mod:`rockstudy.dynamics.contact`
exposes them) and numba compiles for the loop; see that module for their derivation.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..constants import G
from ..motions._kernels import (
    KIND_RECORD,
    ground_acceleration,
    segment_index,
    vertical_acceleration,
)
from ._dop853 import hermite5


def contact_forces(theta, theta_dot, theta_ddot, a_h, a_v, side, radius, slenderness):
    """The ground's force on a rectangular block rocking about its corner, per unit mass.

    .. math::

       F_h / m = \\ddot u_h + R (\\ddot\\theta \\cos\\phi + s \\dot\\theta^2 \\sin\\phi),
       \\quad F_v / m = g + \\ddot u_v + R (s \\ddot\\theta \\sin\\phi
       - \\dot\\theta^2 \\cos\\phi), \\quad \\phi = \\alpha - s \\theta

    (m times the acceleration of the centre of mass, plus its weight; the pivot moves with the
    ground). Broadcasting.

    Parameters
    ----------
    theta, theta_dot, theta_ddot : float or ndarray
        Rotation [rad], its rate [rad/s] and acceleration [rad/s^2].
    a_h, a_v : float or ndarray
        The ground's horizontal and vertical (upwards) accelerations [m/s^2].
    side : float or ndarray
        The pivot: +1 (theta > 0) or -1.
    radius, slenderness : float
        Half-diagonal R [m] and slenderness alpha [rad].

    Returns
    -------
    f_h, f_v : float or ndarray
        Horizontal and vertical (upwards) components [m/s^2].
    """
    phi = slenderness - side * theta
    sin, cos = np.sin(phi), np.cos(phi)
    w2 = theta_dot * theta_dot
    f_h = a_h + radius * (theta_ddot * cos + side * w2 * sin)
    f_v = G + a_v + radius * (side * theta_ddot * sin - w2 * cos)
    return f_h, f_v


def rocking_acceleration(theta, a_h, a_v, side, frequency_parameter, slenderness, linear=False):
    """theta_ddot [rad/s^2] of a block rocking on ``side``: eq. (2.2) of [000] with gravity
    g + a_v, or its linearization (3.1); the kernels' right-hand side. Broadcasting.

    Parameters
    ----------
    theta : float or ndarray
        Rotation [rad].
    a_h, a_v : float or ndarray
        The ground's horizontal and vertical (upwards) accelerations [m/s^2].
    side : float or ndarray
        The pivot: +1 (theta > 0) or -1.
    frequency_parameter, slenderness : float
        p [rad/s] and alpha [rad].
    linear : bool
        The linearized equation (3.1).
    """
    p2, gv, a = frequency_parameter**2, 1.0 + a_v / G, a_h / G
    if linear:
        return p2 * (gv * (theta - slenderness * side) - a)
    x = slenderness * side - theta
    return -p2 * (gv * np.sin(x) + a * np.cos(x))


_forces = njit(cache=True)(contact_forces)
_accel = njit(cache=True)(rocking_acceleration)


@njit(cache=True)
def forces_at(k, t, ends, side, mot, p, alpha, linear, radius):
    """(F_h / m, F_v / m) at the times t[i] inside the rocking intervals k[i].

    ends = (t0, t1, y0, d0, a0, y1, d1, a1): each interval's end times and theta, theta_dot,
    theta_ddot at both ends (the state between them on their quintic Hermite interpolant);
    side: each interval's; mot: the motion's kernel encoding."""
    t0, t1, y0, d0, a0, y1, d1, a1 = ends
    kind, mp, times, samples, vsamples = mot
    f_h, f_v = np.empty(t.size), np.empty(t.size)
    seg = 0
    for i in range(t.size):
        j = k[i]
        h = t1[j] - t0[j]
        y, d, _ = hermite5((t[i] - t0[j]) / h, h, y0[j], d0[j], a0[j], y1[j], d1[j], a1[j])
        if kind == KIND_RECORD:
            seg = segment_index(times, min(max(t[i], 0.0), mp[3]), seg)
        a_h = ground_acceleration(kind, mp, times, samples, t[i], seg)
        a_v = vertical_acceleration(kind, mp, times, vsamples, t[i], seg)
        acc = _accel(y, a_h, a_v, side[j], p, alpha, linear)
        f_h[i], f_v[i] = _forces(y, d, acc, a_h, a_v, side[j], radius, alpha)
    return f_h, f_v
