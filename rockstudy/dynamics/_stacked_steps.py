"""The steps of the two-block kernel (private): DOP853 on the state (theta_1, theta_2,
theta_1', theta_2') of a regime of :mod:`._stacked_model`, its error norm, and the quintic
Hermite interpolant of an interface's angle on a step, on which the kernel locates its events.

The Butcher tableau and error weights are scipy's (``scipy.integrate.DOP853``, Hairer, Norsett
& Wanner, *Solving ODEs I*, II.10), as in :mod:`._dop853`, here with a loop over the stages
(four components). The motion travels as ``mot = (kind, params, times, samples, segment)`` of
:mod:`rockstudy.motions._kernels` (the record segment of the step's start).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.integrate import DOP853 as _DOP853

from ..constants import G
from ..motions._kernels import ground_acceleration
from ._dop853 import hermite5
from ._stacked_model import A1, A2, P1, P2, acceleration
from ._taylor import MAX_ORDER, MODEL_NONLINEAR, NO_REFCOUNT, poly_end, taylor_coefficients
from .constants import ATOL_FRACTION

_A = np.ascontiguousarray(_DOP853.A[:12, :12], dtype=float)
_B = np.ascontiguousarray(_DOP853.B, dtype=float)
_C = np.ascontiguousarray(_DOP853.C[:12], dtype=float)
_E3 = np.ascontiguousarray(_DOP853.E3, dtype=float)
_E5 = np.ascontiguousarray(_DOP853.E5, dtype=float)
_A_EXTRA = np.ascontiguousarray(_DOP853.A_EXTRA, dtype=float)
_C_EXTRA = np.ascontiguousarray(_DOP853.C_EXTRA, dtype=float)
_D = np.ascontiguousarray(_DOP853.D, dtype=float)

#: Rows of the work array of a scene (:func:`work_array`): the 13 stage derivatives and the
#: 3 extra stages of the dense output, a stage's state, the step's end, the derivative
#: there, the state at an instant inside the step (:func:`._stacked_events.true_state`),
#: the dense output's 7 coefficient rows, and (kind, h) of the last accepted step
#: (:data:`DENSE_NONE`...).
K_TMP, K_END, K_FEND, K_SUB, K_FSUB, K_DENSE, K_INFO = 16, 17, 18, 19, 20, 21, 28
#: The first of the 14 rows of the both-rocking Taylor step (:mod:`._stacked_taylor`).
K_BOTH = 29
#: Kinds of the last accepted step in w[K_INFO, 0] (its length in w[K_INFO, 1]): none yet,
#: a DOP853 step, one whose dense
#: output is computed, a Taylor step (its order in w[K_INFO, 2], its series in the rows of
#: :mod:`._stacked_taylor`).
DENSE_NONE, DENSE_STAGES, DENSE_READY, DENSE_TAYLOR = 0.0, 1.0, 2.0, 3.0


@njit(cache=True)
def work_array():
    """The work array of one scene: (K_BOTH + 14, MAX_ORDER + 3) floats (rows
    :data:`K_TMP`...; the DOP853 rows use their first 4 columns)."""
    return np.zeros((K_BOTH + 14, MAX_ORDER + 3))


@njit(cache=True, **NO_REFCOUNT)
def ground(mot, t):
    """u_g''(t) [m/s^2] of the motion ``mot`` (zero outside it)."""
    return ground_acceleration(mot[0], mot[1], mot[2], mot[3], t, mot[4])


@njit(cache=True, **NO_REFCOUNT)
def derivative(g, regime, mot, t, y, out):
    """y' = (theta_1', theta_2', theta_1'', theta_2'') of the regime ``regime`` = (s1, s2,
    flat0, flat1) at (t, y), into ``out``."""
    s1, s2, flat0, flat1 = regime
    a1, a2 = acceleration(g, y, s1, s2, flat0, flat1, ground(mot, t))
    out[0], out[1], out[2], out[3] = y[2], y[3], a1, a2


@njit(cache=True, **NO_REFCOUNT)
def dop853_step(g, regime, mot, t, y, f, h, w, end):
    """One DOP853 step of length h from (t, y) with y' = f there: the stage derivatives into
    w[0:12], the new state into w[end]. The caller puts the derivative at the new
    point into w[12] before :func:`step_error`."""
    for c in range(4):
        w[0, c] = f[c]
    for i in range(1, 12):
        for c in range(4):
            acc = 0.0
            for j in range(i):
                acc += _A[i, j] * w[j, c]
            w[K_TMP, c] = y[c] + h * acc
        derivative(g, regime, mot, t + _C[i] * h, w[K_TMP], w[i])
    for c in range(4):
        acc = 0.0
        for i in range(12):
            acc += _B[i] * w[i, c]
        w[end, c] = y[c] + h * acc


@njit(cache=True, **NO_REFCOUNT)
def dense_state(g, regime, mot, t, y0, sigma, w, out):
    """The state at the fraction sigma of the last accepted DOP853 step (from (t, y0), its
    stages in w[0:13], its end in w[K_END], its length in w[K_INFO, 1]) on the step's
    7th-order dense output (scipy's ``Dop853DenseOutput``: 3 more stages, computed once
    per step), into ``out``."""
    if w[K_INFO, 0] != DENSE_READY:
        _dense_coefficients(g, regime, mot, t, y0, w)
    for c in range(4):
        v = 0.0
        for i in range(7):
            v += w[K_DENSE + 6 - i, c]
            v *= sigma if i % 2 == 0 else 1.0 - sigma
        out[c] = y0[c] + v


@njit(cache=True, **NO_REFCOUNT)
def _dense_coefficients(g, regime, mot, t, y0, w):
    """The extra stages and the 7 coefficient rows of the dense output of the last DOP853
    step (scipy's ``DOP853._dense_output_impl``), into w[13:16] and w[K_DENSE:]."""
    h = w[K_INFO, 1]
    for s in range(13, 16):
        for c in range(4):
            acc = 0.0
            for j in range(s):
                acc += _A_EXTRA[s - 13, j] * w[j, c]
            w[K_TMP, c] = y0[c] + h * acc
        derivative(g, regime, mot, t + _C_EXTRA[s - 13] * h, w[K_TMP], w[s])
    for c in range(4):
        dy = w[K_END, c] - y0[c]
        w[K_DENSE, c], w[K_DENSE + 1, c] = dy, h * w[0, c] - dy
        w[K_DENSE + 2, c] = 2.0 * dy - h * (w[12, c] + w[0, c])
        for i in range(4):
            acc = 0.0
            for j in range(16):
                acc += _D[i, j] * w[j, c]
            w[K_DENSE + 3 + i, c] = h * acc
    w[K_INFO, 0] = DENSE_READY


@njit(cache=True, **NO_REFCOUNT)
def step_error(g, w, h, y0, y1, tol):
    """Hairer's combined 5th/3rd-order error norm of the last step (<= 1 accepts), with the
    scales tol (ATOL_FRACTION alpha_min + |theta|) and tol (ATOL_FRACTION p_max alpha_min +
    |theta'|) of the rocking kernels."""
    a_min, p_max = min(g[A1], g[A2]), max(g[P1], g[P2])
    n5 = n3 = 0.0
    for c in range(4):
        e5 = e3 = 0.0
        for j in range(13):
            e5 += _E5[j] * w[j, c]
            e3 += _E3[j] * w[j, c]
        floor = ATOL_FRACTION * a_min * (1.0 if c < 2 else p_max)
        sc = tol * (floor + max(abs(y0[c]), abs(y1[c])))
        n5 += (e5 / sc) ** 2
        n3 += (e3 / sc) ** 2
    if n5 == 0.0:
        return 0.0
    return abs(h) * n5 / math.sqrt((n5 + 0.01 * n3) * 4.0)


@njit(cache=True, inline="always")
def interface_data(k, y, f):
    """Interface k's angle, rate and acceleration in the state y with derivative f: theta_1
    (k = 0) or phi = theta_2 - theta_1 (k = 1)."""
    if k == 0:
        return y[0], y[2], f[2]
    return y[1] - y[0], y[3] - y[2], f[3] - f[2]


@njit(cache=True, **NO_REFCOUNT)
def interface_at(k, sigma, h, y0, f0, y1, f1):
    """Interface k's (angle, rate, acceleration) at the fraction sigma of a step of length
    h, on the quintic Hermite interpolant of its ends."""
    x0, v0, a0 = interface_data(k, y0, f0)
    x1, v1, a1 = interface_data(k, y1, f1)
    return hermite5(sigma, h, x0, v0, a0, x1, v1, a1)


@njit(cache=True, **NO_REFCOUNT)
def state_at(sigma, h, y0, f0, y1, f1, out):
    """The full state at the fraction sigma of a step on the Hermite interpolant, into out."""
    th1 = hermite5(sigma, h, y0[0], y0[2], f0[2], y1[0], y1[2], f1[2])
    th2 = hermite5(sigma, h, y0[1], y0[3], f0[3], y1[1], y1[3], f1[3])
    out[0], out[1], out[2], out[3] = th1[0], th2[0], th1[1], th2[1]


@njit(cache=True, **NO_REFCOUNT)
def one_body_form(g, regime):
    """(index, P, beta) of a one-body regime, whose angle theta = y[index] (theta_1 of the
    assembly locked on the ground, theta_2 of the upper block alone on the resting lower)
    obeys Housner's equation theta'' = -P [sin(beta - theta) + (u_g''/g) cos(beta - theta)]
    of a rigid body about a fixed pivot: P (its p^2) and beta (its side times its alpha,
    the angle of its centre of mass from the pivot's vertical) read off the regime's own
    acceleration at theta = 0 under u_g'' = 0 and g. Index -1 in the other regimes."""
    s1, s2, flat0, flat1 = regime
    if flat0 == flat1:
        return -1, 0.0, 0.0
    k = 1 if flat0 else 0
    zero = (0.0, 0.0, 0.0, 0.0)
    a0 = acceleration(g, zero, s1, s2, flat0, flat1, 0.0)[k]
    ag = acceleration(g, zero, s1, s2, flat0, flat1, G)[k]
    return k, math.hypot(a0, ag - a0), math.atan2(-a0, a0 - ag)


@njit(cache=True, **NO_REFCOUNT)
def one_body_step(g, form, y, h, a0, a1, dd0, tol, tw, out):
    """One Taylor step of length h of a one-body regime (:func:`one_body_form`) under
    u_g'' linear from a0 to a1 [m/s^2] (:func:`._taylor.taylor_coefficients`, the
    single-block kernel's record step): its end state into ``out``, its scaled series in
    tw[0]; returns (the ratio of its truncation-error bound to the scales tol
    (ATOL_FRACTION alpha_min + ...) of :func:`step_error` (<= 1 accepts), its order).
    ``dd0``: the angle's acceleration at the start as the regime computes it (so that a
    body lifting from rest rises as its lift test said; NaN: the series' own)."""
    k, big_p, beta = form
    th, om = y[k], y[2 + k]
    a_min, p_max = min(g[A1], g[A2]), max(g[P1], g[P2])
    sc_x = tol * (ATOL_FRACTION * a_min + abs(th) + abs(om) * h)
    sc_v = tol * (ATOL_FRACTION * p_max * a_min + abs(om) + abs(th) * big_p * h)
    p = math.sqrt(big_p)
    n, err = taylor_coefficients(
        tw, th, om, 1.0, p, beta, MODEL_NONLINEAR, h, a0, a1, 0.0, 0.0, sc_x, sc_v, dd0
    )
    x, dx, _ = poly_end(tw[0], n)
    for c in range(4):
        out[c] = y[c]
    out[k], out[2 + k] = x, dx / h
    if k == 0:
        out[1], out[3] = x, dx / h
    return err, n
