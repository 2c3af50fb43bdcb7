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


def make_dop853_step(rhs, options=None):
    """Build the numba DOP853 step for the right-hand side ``rhs(t, theta, theta_dot, args)``.

    The returned ``step(args, t, y0, y1, f0, h, kx, kv)`` advances (y0, y1) = (theta,
    theta_dot) by h, with f0 = rhs at the start, and returns (theta_new, theta_dot_new).
    kx, kv are work arrays of length 13 that receive the stage derivatives of theta and
    theta_dot; before :func:`dop853_error` the caller stores the derivatives at the new point in
    kx[12], kv[12]. ``options``: further numba options of the step (a dict).
    """

    @njit(cache=True, **(options or {}))
    def step(args, t, y0, y1, f0, h, kx, kv):
        # unrolled over the non-zero entries of the tableau, indexed by literals
        # fmt: off
        x0 = y1
        v0 = f0
        dx = (_A[1][0] * x0)
        x1 = y1 + h * (_A[1][0] * v0)
        v1 = rhs(t + _C[1] * h, y0 + h * dx, x1, args)
        dx = (_A[2][0] * x0 + _A[2][1] * x1)
        x2 = y1 + h * (_A[2][0] * v0 + _A[2][1] * v1)
        v2 = rhs(t + _C[2] * h, y0 + h * dx, x2, args)
        dx = (_A[3][0] * x0 + _A[3][2] * x2)
        x3 = y1 + h * (_A[3][0] * v0 + _A[3][2] * v2)
        v3 = rhs(t + _C[3] * h, y0 + h * dx, x3, args)
        dx = (_A[4][0] * x0 + _A[4][2] * x2 + _A[4][3] * x3)
        x4 = y1 + h * (_A[4][0] * v0 + _A[4][2] * v2 + _A[4][3] * v3)
        v4 = rhs(t + _C[4] * h, y0 + h * dx, x4, args)
        dx = (_A[5][0] * x0 + _A[5][3] * x3 + _A[5][4] * x4)
        x5 = y1 + h * (_A[5][0] * v0 + _A[5][3] * v3 + _A[5][4] * v4)
        v5 = rhs(t + _C[5] * h, y0 + h * dx, x5, args)
        dx = (_A[6][0] * x0 + _A[6][3] * x3 + _A[6][4] * x4 + _A[6][5] * x5)
        x6 = y1 + h * (_A[6][0] * v0 + _A[6][3] * v3 + _A[6][4] * v4 + _A[6][5] * v5)
        v6 = rhs(t + _C[6] * h, y0 + h * dx, x6, args)
        dx = (_A[7][0] * x0 + _A[7][3] * x3 + _A[7][4] * x4 + _A[7][5] * x5 + _A[7][6] * x6)
        x7 = y1 + h * (_A[7][0] * v0 + _A[7][3] * v3 + _A[7][4] * v4 + _A[7][5] * v5
            + _A[7][6] * v6)
        v7 = rhs(t + _C[7] * h, y0 + h * dx, x7, args)
        dx = (_A[8][0] * x0 + _A[8][3] * x3 + _A[8][4] * x4 + _A[8][5] * x5 + _A[8][6] * x6
            + _A[8][7] * x7)
        x8 = y1 + h * (_A[8][0] * v0 + _A[8][3] * v3 + _A[8][4] * v4 + _A[8][5] * v5
            + _A[8][6] * v6 + _A[8][7] * v7)
        v8 = rhs(t + _C[8] * h, y0 + h * dx, x8, args)
        dx = (_A[9][0] * x0 + _A[9][3] * x3 + _A[9][4] * x4 + _A[9][5] * x5 + _A[9][6] * x6
            + _A[9][7] * x7 + _A[9][8] * x8)
        x9 = y1 + h * (_A[9][0] * v0 + _A[9][3] * v3 + _A[9][4] * v4 + _A[9][5] * v5
            + _A[9][6] * v6 + _A[9][7] * v7 + _A[9][8] * v8)
        v9 = rhs(t + _C[9] * h, y0 + h * dx, x9, args)
        dx = (_A[10][0] * x0 + _A[10][3] * x3 + _A[10][4] * x4 + _A[10][5] * x5 + _A[10][6] * x6
            + _A[10][7] * x7 + _A[10][8] * x8 + _A[10][9] * x9)
        x10 = y1 + h * (_A[10][0] * v0 + _A[10][3] * v3 + _A[10][4] * v4 + _A[10][5] * v5
            + _A[10][6] * v6 + _A[10][7] * v7 + _A[10][8] * v8 + _A[10][9] * v9)
        v10 = rhs(t + _C[10] * h, y0 + h * dx, x10, args)
        dx = (_A[11][0] * x0 + _A[11][3] * x3 + _A[11][4] * x4 + _A[11][5] * x5 + _A[11][6] * x6
            + _A[11][7] * x7 + _A[11][8] * x8 + _A[11][9] * x9 + _A[11][10] * x10)
        x11 = y1 + h * (_A[11][0] * v0 + _A[11][3] * v3 + _A[11][4] * v4 + _A[11][5] * v5
            + _A[11][6] * v6 + _A[11][7] * v7 + _A[11][8] * v8 + _A[11][9] * v9 + _A[11][10] * v10)
        v11 = rhs(t + _C[11] * h, y0 + h * dx, x11, args)
        kx[0], kx[1], kx[2], kx[3], kx[4], kx[5] = x0, x1, x2, x3, x4, x5
        kx[6], kx[7], kx[8], kx[9], kx[10], kx[11] = x6, x7, x8, x9, x10, x11
        kv[0], kv[1], kv[2], kv[3], kv[4], kv[5] = v0, v1, v2, v3, v4, v5
        kv[6], kv[7], kv[8], kv[9], kv[10], kv[11] = v6, v7, v8, v9, v10, v11
        dx = (_B[0] * x0 + _B[5] * x5 + _B[6] * x6 + _B[7] * x7 + _B[8] * x8 + _B[9] * x9
            + _B[10] * x10 + _B[11] * x11)
        dv = (_B[0] * v0 + _B[5] * v5 + _B[6] * v6 + _B[7] * v7 + _B[8] * v8 + _B[9] * v9
            + _B[10] * v10 + _B[11] * v11)
        # fmt: on
        return y0 + h * dx, y1 + h * dv

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
    """Quintic Hermite interpolant of a step of length h at s in [0, 1].

    y, d, a are the value, first and second time derivatives at the two ends.
    Returns (y(s), dy/dt(s), d2y/dt2(s)).
    """
    s2 = s * s
    s3 = s2 * s
    s4 = s3 * s
    s5 = s4 * s
    # basis functions (value), their s-derivatives and second s-derivatives
    h00 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5
    h10 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5
    h20 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5
    h11 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5
    h21 = 0.5 * s3 - s4 + 0.5 * s5
    g00 = -30.0 * s2 + 60.0 * s3 - 30.0 * s4
    g10 = 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4
    g20 = s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4
    g11 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4
    g21 = 1.5 * s2 - 4.0 * s3 + 2.5 * s4
    q00 = -60.0 * s + 180.0 * s2 - 120.0 * s3
    q10 = -36.0 * s + 96.0 * s2 - 60.0 * s3
    q20 = 1.0 - 9.0 * s + 18.0 * s2 - 10.0 * s3
    q11 = -24.0 * s + 84.0 * s2 - 60.0 * s3
    q21 = 3.0 * s - 12.0 * s2 + 10.0 * s3
    dy = y0 - y1
    hh = h * h
    val = y1 + h00 * dy + h10 * h * d0 + h20 * hh * a0 + h11 * h * d1 + h21 * hh * a1
    der = g00 * dy / h + g10 * d0 + g20 * h * a0 + g11 * d1 + g21 * h * a1
    acc = q00 * dy / hh + q10 * d0 / h + q20 * a0 + q11 * d1 / h + q21 * a1
    return val, der, acc
