"""One DOP853 step of the block on an isolated base (private numba kernels).

The state y = (x_b, x_b', theta, theta') of :mod:`._isolated_model`; the tableau and the error
weights are scipy's (``scipy.integrate.DOP853``, Hairer, Norsett & Wanner, *Solving ODEs I*,
II.10), the error norm and the step-size rule scipy's too, so that the kernel takes the steps
the ``solve_ivp`` reference takes at the same rtol and atol.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.integrate import DOP853 as _DOP853

from ._isolated_model import rhs
from ._taylor import NO_REFCOUNT

_NS = 12  # stages; stage 13 is f at the new point (first-same-as-last)
# global arrays: numba freezes them into the kernels as constants (indexing a tuple of tuples
# at run time cost ~3x the whole step, measured)
_A = np.ascontiguousarray(_DOP853.A[:_NS, :_NS], dtype=float)
_B = np.ascontiguousarray(_DOP853.B, dtype=float)
_C = np.ascontiguousarray(_DOP853.C[:_NS], dtype=float)
_E3 = np.ascontiguousarray(_DOP853.E3, dtype=float)
_E5 = np.ascontiguousarray(_DOP853.E5, dtype=float)
#: scipy's step-size rule: safety factor, the limits of one change, the exponent 1/8.
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0


@njit(cache=True, **NO_REFCOUNT)
def dop853_step(t, y, h, K, ynew, tmp, par, mot, k, side, slide):
    """Advance y by h from t (K[0] = dy/dt at t): the new state into ``ynew``, the stages into
    K[0:12] and dy/dt at the new point into K[12]."""
    for i in range(1, _NS):
        for j in range(4):
            acc = 0.0
            for m in range(i):
                acc += _A[i, m] * K[m, j]
            tmp[j] = y[j] + h * acc
        rhs(t + _C[i] * h, tmp, par, mot, k, side, slide, K[i])
    for j in range(4):
        acc = 0.0
        for m in range(_NS):
            acc += _B[m] * K[m, j]
        ynew[j] = y[j] + h * acc
    rhs(t + h, ynew, par, mot, k, side, slide, K[_NS])


@njit(cache=True, **NO_REFCOUNT)
def error_norm(K, h, y, ynew, rtol, atol, n):
    """scipy's DOP853 error norm of the last step over the first n components (2 with the
    block at rest, as the reference integrates (x_b, x_b') only; 4 while it rocks)."""
    n5 = 0.0
    n3 = 0.0
    for j in range(n):
        e5 = 0.0
        e3 = 0.0
        for m in range(_NS + 1):
            e5 += _E5[m] * K[m, j]
            e3 += _E3[m] * K[m, j]
        sc = atol[j] + rtol * max(abs(y[j]), abs(ynew[j]))
        n5 += (e5 / sc) ** 2
        n3 += (e3 / sc) ** 2
    if n5 == 0.0 and n3 == 0.0:
        return 0.0
    return abs(h) * n5 / math.sqrt((n5 + 0.01 * n3) * n)


@njit(cache=True, **NO_REFCOUNT)
def step_factor(err, rejected):
    """scipy's factor on the step size after an error norm ``err`` (accepted if <= 1)."""
    if err < 1.0:  # accepted
        fac = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**-0.125)
        return min(1.0, fac) if rejected else fac
    return max(MIN_FACTOR, SAFETY * err**-0.125)


@njit(cache=True, **NO_REFCOUNT)
def first_step(t, y, f0, par, mot, k, side, slide, rtol, atol, n, t_bound, tmp, f1):
    """scipy's initial step (``select_initial_step``, order 7) from t with dy/dt = f0."""
    d0 = 0.0
    d1 = 0.0
    for j in range(n):
        sc = atol[j] + abs(y[j]) * rtol
        d0 += (y[j] / sc) ** 2
        d1 += (f0[j] / sc) ** 2
    d0, d1 = math.sqrt(d0 / n), math.sqrt(d1 / n)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, t_bound - t)
    for j in range(4):
        tmp[j] = y[j] + h0 * f0[j]
    rhs(t + h0, tmp, par, mot, k, side, slide, f1)
    d2 = 0.0
    for j in range(n):
        sc = atol[j] + abs(y[j]) * rtol
        d2 += ((f1[j] - f0[j]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, t_bound - t)
