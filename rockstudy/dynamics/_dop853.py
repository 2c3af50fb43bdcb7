"""One Dormand-Prince 8(5,3) step and the quintic Hermite interpolant (private numba kernels).

The Butcher tableau and error weights are read from scipy (``scipy.integrate.DOP853``), so the
coefficients are those of Hairer, Norsett & Wanner, *Solving ODEs I*, section II.10.
The state is the pair (theta, theta_dot); ``rhs`` returns theta_ddot.
"""

from __future__ import annotations

import math

from numba import njit
from scipy.integrate import DOP853 as _DOP853

# tuples, not arrays: numba freezes them as constants and can cache the kernels
_A = tuple(tuple(float(x) for x in row) for row in _DOP853.A)
_B = tuple(float(x) for x in _DOP853.B)
_C = tuple(float(x) for x in _DOP853.C)
_E3 = tuple(float(x) for x in _DOP853.E3)
_E5 = tuple(float(x) for x in _DOP853.E5)
_NS = len(_B)  # 12 stages; stage 13 is f at the new point (first-same-as-last)


def make_dop853_step(rhs):
    """Build the numba DOP853 step for the right-hand side ``rhs(t, theta, theta_dot, args)``.

    The returned ``step(args, t, y0, y1, f0, h, kx, kv)`` advances (y0, y1) = (theta,
    theta_dot) by h, with f0 = rhs at the start, and returns (theta_new, theta_dot_new).
    kx, kv are work arrays of length 13 that receive the stage derivatives of theta and
    theta_dot; before :func:`dop853_error` the caller stores the derivatives at the new point in
    kx[12], kv[12].
    """

    @njit(cache=True)
    def step(args, t, y0, y1, f0, h, kx, kv):
        kx[0] = y1
        kv[0] = f0
        for i in range(1, _NS):
            sx = 0.0
            sv = 0.0
            for j in range(i):
                a = _A[i][j]
                if a != 0.0:
                    sx += a * kx[j]
                    sv += a * kv[j]
            vi = y1 + h * sv
            kx[i] = vi
            kv[i] = rhs(t + _C[i] * h, y0 + h * sx, vi, args)
        sx = 0.0
        sv = 0.0
        for j in range(_NS):
            sx += _B[j] * kx[j]
            sv += _B[j] * kv[j]
        return y0 + h * sx, y1 + h * sv

    return step


@njit(cache=True)
def dop853_error(kx, kv, h, sc_x, sc_v):
    """Hairer's combined 5th/3rd-order error norm of the last step (<= 1 accepts)."""
    e5x = 0.0
    e5v = 0.0
    e3x = 0.0
    e3v = 0.0
    for j in range(_NS + 1):
        e5x += _E5[j] * kx[j]
        e5v += _E5[j] * kv[j]
        e3x += _E3[j] * kx[j]
        e3v += _E3[j] * kv[j]
    n5 = (e5x / sc_x) ** 2 + (e5v / sc_v) ** 2
    n3 = (e3x / sc_x) ** 2 + (e3v / sc_v) ** 2
    if n5 == 0.0:
        return 0.0
    return abs(h) * n5 / math.sqrt((n5 + 0.01 * n3) * 2.0)


@njit(cache=True, inline="always")
def hermite5(s, h, y0, d0, a0, y1, d1, a1):
    """Quintic Hermite value and derivative at s in [0, 1] of a step of length h.

    y, d, a are the value, first and second time derivatives at the two ends.
    Returns (y(s), dy/dt(s)).
    """
    s2 = s * s
    s3 = s2 * s
    s4 = s3 * s
    s5 = s4 * s
    h00 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5
    h10 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5
    h20 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5
    h01 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5
    h11 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5
    h21 = 0.5 * s3 - s4 + 0.5 * s5
    g00 = -30.0 * s2 + 60.0 * s3 - 30.0 * s4
    g10 = 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4
    g20 = s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4
    g11 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4
    g21 = 1.5 * s2 - 4.0 * s3 + 2.5 * s4
    hh = h * h
    val = h00 * y0 + h10 * h * d0 + h20 * hh * a0 + h01 * y1 + h11 * h * d1 + h21 * hh * a1
    der = (g00 * (y0 - y1)) / h + g10 * d0 + g20 * h * a0 + g11 * d1 + g21 * h * a1
    return val, der
