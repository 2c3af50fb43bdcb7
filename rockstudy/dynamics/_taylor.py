"""Taylor-series step for rocking under a sampled record (private numba kernels).

Between two samples of a record the ground acceleration is linear in t, and so is a vertical
component sampled on the same grid. On one side s of Housner's block, eq. (2.2) of [000]
with a vertical acceleration v(t) reads

.. math:: \\ddot\\theta = -p^2 [(1 + v/g) \\sin x + (a/g) \\cos x], \\quad x = \\alpha s - \\theta

(linearized, eq. (3.1): sin x -> x, cos x -> 1). Its Taylor series about the start of a step
follows from the recurrences of the series of S = sin x and C = cos x (Moore, *Interval
Analysis*, 1966; Jorba & Zou, *Exp. Math.* 14, 2005):

.. math:: k S_k = \\sum_{j=1}^{k} j x_j C_{k-j}, \\qquad k C_k = -\\sum_{j=1}^{k} j x_j S_{k-j},

one sine and one cosine per step and O(N^2) flops for order N. Under a trigonometric pulse
a_g sin(omega t + phase) (and with no ground motion at all, after any motion has ended) the
ground term is a whole series, F_k = F_{k-2} (-(omega h)^2 / (k (k-1))), and enters the
product F C as a Cauchy sum, again O(N^2) (:func:`taylor_coefficients_trig`).

The coefficients are kept scaled by the step, c_k = theta_k h^k, so the step is the
polynomial sum_k c_k sigma^k on sigma in [0, 1]: an exact dense output (within the
tolerance of the step), on which impacts, peaks and overturning are located by a
safeguarded Newton-bisection.

The order is chosen step by step: terms are added until the last two are below the error
scale of theta (and, times their order, of h theta_dot). Those two terms bound the
truncation error conservatively: the series decreases roughly like (p h)^k / k!, so the
remainder is far below its last retained term. A step whose series has not converged at
:data:`MAX_ORDER` is rejected and retried shorter.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._roots import newton_bisect
from ..constants import G

#: Highest order tried before a step is rejected (p h <~ 1 converges well below it).
MAX_ORDER = 24
#: Lowest order accepted: below it the last two terms could both vanish by symmetry
#: (theta_dot = 0 and a symmetric forcing) and hide the true error.
MIN_ORDER = 4
#: Iteration cap and tolerance (unit step time) of the root finder on the step polynomial.
ROOT_ITERATIONS = 100
ROOT_TOL = 1e-14

MODEL_NONLINEAR = 0
MODEL_LINEAR = 1

#: numba options of the per-step kernels that allocate nothing and keep no array beyond the
#: call: no reference counting (numba's private ``_nrt`` flag). Otherwise numba counts a
#: reference (an atomic increment, and a decrement at each exit) for every array argument,
#: array unpacked from a tuple and row view of a function with several exits, where its
#: pruning pass fails: about 20 calls per record step, measured at 12 % of its time.
NO_REFCOUNT = {"_nrt": False}
#: numba's fastmath flag for fused multiply-adds (one rounding instead of two): shorter
#: dependency chains in the recurrences and Horner sums; nothing else of fastmath (NaN and
#: infinity keep their meaning). LLVM fuses only where the CPU has FMA instructions, so record
#: results may differ in their last bits between machines with and without them (well inside
#: the step tolerance; a study that must be bit-reproducible runs on one kind of machine).
FMA = {"contract"}


@njit(cache=True)
def work_arrays():
    """Coefficient work space of :func:`taylor_coefficients`: rows c, j x_j, S, C and the
    ground series F; and the polynomial of the step before (:mod:`._demand`)."""
    return np.empty((6, MAX_ORDER + 1))


#: 1/k and 1/(k (k-1)), read by the recurrences (constants: no division in the loops).
_INV = np.array([0.0] + [1.0 / k for k in range(1, MAX_ORDER + 1)])
_INV2 = np.array([0.0, 0.0] + [1.0 / (k * (k - 1)) for k in range(2, MAX_ORDER + 1)])


#: Rows of the work array: the scaled coefficients c_k, j x_j, the series S and C, and the
#: series F of the ground term of a trigonometric pulse (:func:`taylor_coefficients_trig`).
ROW_C, ROW_JX, ROW_S, ROW_C_SERIES, ROW_F = 0, 1, 2, 3, 4
#: Row of the polynomial of the step before, kept by the friction demand (:mod:`._demand`).
ROW_PREV = 5


@njit(cache=True, inline="always")
def _sin_cos_next(w, k):
    """S_k and C_k of the series of sin x and cos x, from j x_j and S, C up to k-1 (the
    recurrences of the module docstring).

    The terms are summed oldest first: j = 2 .. k-1, whose factors are known orders before,
    then j = k (j x_j of the newest coefficient but one) and j = 1 (S, C of the last order),
    so that a new order waits for two additions, not for the whole sum.
    """
    sk = 0.0
    ck = 0.0
    for j in range(2, k):
        jxj = w[ROW_JX, j]
        sk += jxj * w[ROW_C_SERIES, k - j]
        ck -= jxj * w[ROW_S, k - j]
    if k > 1:
        jxk = w[ROW_JX, k]
        sk += jxk * w[ROW_C_SERIES, 0]
        ck -= jxk * w[ROW_S, 0]
    jx1 = w[ROW_JX, 1]
    sk += jx1 * w[ROW_C_SERIES, k - 1]
    ck -= jx1 * w[ROW_S, k - 1]
    return sk * _INV[k], ck * _INV[k]


@njit(cache=True, inline="always")
def _series_start(w, th, om, s, alpha, model, h):
    """The orders 0 and 1 of a step's series: theta, h theta_dot (and j x_j), and S_0, C_0 of
    x = alpha s - theta (linearized: S = x, C = 1)."""
    x0 = alpha * s - th
    w[ROW_C, 0] = th
    w[ROW_C, 1] = om * h
    w[ROW_JX, 1] = -om * h
    if model == MODEL_LINEAR:
        w[ROW_S, 0], w[ROW_C_SERIES, 0] = x0, 1.0
    else:
        w[ROW_S, 0], w[ROW_C_SERIES, 0] = math.sin(x0), math.cos(x0)


@njit(cache=True, inline="always")
def _series_sin_cos(w, k, model):
    """S_k and C_k (:func:`_sin_cos_next`; linearized: x_k = -c_k and 0), stored and returned."""
    if model == MODEL_LINEAR:
        sk, ck = -w[ROW_C, k], 0.0
    else:
        sk, ck = _sin_cos_next(w, k)
    w[ROW_S, k] = sk
    w[ROW_C_SERIES, k] = ck
    return sk, ck


@njit(cache=True, inline="always")
def _store(w, m, cm):
    """Store the scaled coefficient c_m and m x_m = -m c_m (x = alpha s - theta)."""
    w[ROW_C, m] = cm
    w[ROW_JX, m] = -m * cm


@njit(cache=True, fastmath=FMA)
def taylor_coefficients(w, th, om, s, p, alpha, model, h, a0, a1, v0, v1, sc_x, sc_v, dd0=np.nan):
    """Scaled Taylor coefficients c_k = theta_k h^k of one step of length h [s] into w[0].

    th, om: theta [rad] and theta_dot [rad/s] at the start; s: the side (+1 or -1);
    a0, a1 (v0, v1): horizontal (vertical) ground acceleration [m/s^2] at the start and the
    end of the step, linear between. sc_x, sc_v: error scales of theta [rad] and theta_dot
    [rad/s]. dd0: theta_ddot at the start [rad/s^2] as the caller's lift test computed it, for a
    block that leaves contact from rest (NaN otherwise: :func:`_start_curvature`). Returns
    (order n, error ratio): the step is sum_{k<=n} c_k sigma^k, accepted if the ratio of its
    truncation-error bound to the scales is <= 1.

    The rows of ``w`` are indexed in place (no row views: each would cost a reference count
    in every step).
    """
    q = -((p * h) ** 2)
    ah0 = q * a0 / G
    ah1 = q * (a1 - a0) / G
    vh0 = q * (1.0 + v0 / G)
    vh1 = q * (v1 - v0) / G
    _series_start(w, th, om, s, alpha, model, h)
    tol_v = sc_v * h
    c2 = _start_curvature(0.5 * (vh0 * w[ROW_S, 0] + ah0 * w[ROW_C_SERIES, 0]), dd0, h)
    _store(w, 2, c2)
    b = c2
    n = MAX_ORDER
    for m in range(3, MAX_ORDER + 1):
        k = m - 2
        sk, ck = _series_sin_cos(w, k, model)
        # the terms of the last order first (ready earlier), the new S_k and C_k last
        rhs = (vh1 * w[ROW_S, k - 1] + ah1 * w[ROW_C_SERIES, k - 1]) + (vh0 * sk + ah0 * ck)
        cm = rhs * _INV2[m]
        _store(w, m, cm)
        if m >= MIN_ORDER and _converged(b, cm, m, sc_x, tol_v):
            n = m
            break
        b = cm
    return n, _error_ratio(w, n, sc_x, tol_v)


@njit(cache=True, inline="always")
def _start_curvature(c2, dd0, h):
    """c_2 = theta_ddot h^2 / 2 of a step: from ``dd0`` where it is given (not NaN), else the
    series' own ``c2``. A block lifted from rest by a ground acceleration within a few ulps of
    its uplift level must rise as the lift test (other arithmetic) said it does: with c_2 of
    the wrong sign by rounding it would fall back at once, an impact at the step's start, and
    the Zeno rule would restart it there without end."""
    return 0.5 * dd0 * h * h if dd0 == dd0 else c2


@njit(cache=True, inline="always")
def _converged(b, cm, m, sc_x, tol_v):
    """Whether the series may stop at order m: its last two terms b = c_{m-1} and cm = c_m
    are below the error scale of theta, and, times their order, of h theta_dot."""
    e = abs(cm)
    return abs(b) + e <= sc_x and (m - 1) * abs(b) + m * e <= tol_v


@njit(cache=True, inline="always")
def _error_ratio(w, n, sc_x, tol_v):
    """The truncation-error bound of a series stopped at order n (its last two terms, as in
    :func:`_converged`) over the error scales: the step is accepted if it is <= 1."""
    b = abs(w[ROW_C, n - 1])
    e = abs(w[ROW_C, n])
    return max((b + e) / sc_x, ((n - 1) * b + n * e) / tol_v)


@njit(cache=True, fastmath=FMA)
def taylor_coefficients_trig(
    w, th, om, s, p, alpha, model, h, amp, phase, wh, sc_x, sc_v, dd0=np.nan
):
    """:func:`taylor_coefficients` under the ground acceleration amp sin(phase + wh sigma)
    [m/s^2] on the step (sigma = (t - t_start) / h in [0, 1]; amp = 0: no ground motion).

    The ground series is F_k = (amp/g) wh^k / k! sin(phase + k pi/2), by the two-term
    recurrence F_k = -F_{k-2} wh^2 / (k (k-1)); eq. (2.2) of [000] takes it through the
    Cauchy product sum_j F_j C_{k-j} (the linearized eq. (3.1): F_k itself). Returns (order
    n, error ratio), as :func:`taylor_coefficients`.
    """
    q = -((p * h) ** 2)
    _series_start(w, th, om, s, alpha, model, h)
    linear = model == MODEL_LINEAR
    f = q * amp / G  # the ground series carries the factor q of the right-hand side
    w[ROW_F, 0] = f * math.sin(phase) if amp != 0.0 else 0.0
    w[ROW_F, 1] = f * wh * math.cos(phase) if amp != 0.0 else 0.0
    wh2 = wh * wh
    tol_v = sc_v * h
    c2 = _start_curvature(0.5 * (q * w[ROW_S, 0] + w[ROW_F, 0] * w[ROW_C_SERIES, 0]), dd0, h)
    _store(w, 2, c2)
    b = c2
    n = MAX_ORDER
    for m in range(3, MAX_ORDER + 1):
        k = m - 2
        sk, ck = _series_sin_cos(w, k, model)
        if k >= 2:
            w[ROW_F, k] = -w[ROW_F, k - 2] * wh2 * _INV2[k]
        rhs = q * sk
        if linear:
            rhs += w[ROW_F, k]
        elif amp != 0.0:
            for j in range(k + 1):
                rhs += w[ROW_F, j] * w[ROW_C_SERIES, k - j]
        cm = rhs * _INV2[m]
        _store(w, m, cm)
        if m >= MIN_ORDER and _converged(b, cm, m, sc_x, tol_v):
            n = m
            break
        b = cm
    return n, _error_ratio(w, n, sc_x, tol_v)


@njit(cache=True, inline="always")
def poly_value(c, n, x):
    """Value, first and second derivative (in unit step time) of sum_{k<=n} c_k x^k."""
    v = c[n]
    d = 0.0
    dd = 0.0
    for k in range(n - 1, -1, -1):
        dd = dd * x + 2.0 * d
        d = d * x + v
        v = v * x + c[k]
    return v, d, dd


@njit(cache=True, inline="always")
def poly_end(c, n):
    """:func:`poly_value` at x = 1 (the end of the step): sum c_k, sum k c_k and
    sum k (k-1) c_k, as three independent sums (shorter dependency chains than Horner's)."""
    v = c[0]
    d = c[1]
    dd = 0.0
    for k in range(2, n + 1):
        ck = c[k]
        v += ck
        d += k * ck
        dd += k * (k - 1) * ck
    return v + c[1], d, dd


@njit(cache=True, inline="always")
def _poly_fdf(x, args):
    """The polynomial's value (or derivative) minus target at x, and its x-derivative."""
    c, n, target, deriv = args
    v, d, dd = poly_value(c, n, x)
    return (d - target, dd) if deriv else (v - target, d)


# deriv flags as numpy booleans: a Python literal would compile a specialization per value
OF_VALUE, OF_SLOPE = np.bool_(False), np.bool_(True)


@njit(cache=True)
def poly_root(c, n, target, sgn, deriv, lo, hi):
    """Root in [lo, hi] of the polynomial's value (deriv=False) or derivative, minus target.

    Finds where sgn * (q(x) - target) changes from >= 0 at lo to < 0 at hi, by Newton steps
    safeguarded by bisection of the bracket (:func:`rockstudy._roots.newton_bisect`), to
    :data:`ROOT_TOL` of the step.
    """
    return poly_root_near(c, n, target, sgn, deriv, lo, hi, 0.5 * (lo + hi))


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def poly_root_near(c, n, target, sgn, deriv, lo, hi, x0):
    """:func:`poly_root` from the first iterate x0 in [lo, hi] (a guess near the root saves
    Newton steps; the bracket keeps any guess safe)."""
    args = (c, n, target, deriv)
    return newton_bisect(_poly_fdf, args, lo, hi, x0, sgn, ROOT_TOL, ROOT_ITERATIONS)


@njit(cache=True, inline="always")
def _secant(f_lo, f_hi, lo, hi):
    """Where the chord through (lo, f_lo) and (hi, f_hi) crosses zero (f_lo, f_hi of opposite
    signs or f_lo = 0): the first Newton iterate of a root that the step's near-linear
    polynomial holds within a small fraction of the step."""
    return lo + (hi - lo) * f_lo / (f_lo - f_hi)


@njit(cache=True, inline="always")
def _rises_throughout(c, n, s):
    """Whether u = s theta (u(0) >= 0, u'(0) >= 0) surely stays >= 0 on the step: u'' is at
    least m = 2 s c_2 - sum_{k>=3} k (k-1) |c_k| there, so u >= u(0) + u'(0) x + m x^2 / 2,
    a parabola whose minimum on [0, 1] is at an end when m < 0."""
    m = 2.0 * s * c[2]
    for k in range(3, n + 1):
        m -= k * (k - 1) * abs(c[k])
    return m >= 0.0 or s * (c[0] + c[1]) + 0.5 * m >= 0.0


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def step_impact(c, n, s, u1, du1):
    """First root of theta in the step, in unit step time (2.0 if none), for a block on side
    s; u1 = s theta and du1 = s dtheta/dx at the end of the step.

    Beyond a sign change at the end, a dip through zero between two rises is looked for at
    the minimum of s theta, and, unless a bound on the curvature rules it out, a short hop
    (up, down through zero, up again) at the quarter points.
    """
    if u1 < 0.0:
        return poly_root_near(c, n, 0.0, s, OF_VALUE, 0.0, 1.0, _secant(s * c[0], u1, 0.0, 1.0))
    if s * c[1] < 0.0:
        if du1 > 0.0:
            x0 = _secant(s * c[1], du1, 0.0, 1.0)
            x_min = poly_root_near(c, n, 0.0, -s, OF_SLOPE, 0.0, 1.0, x0)
            if s * poly_value(c, n, x_min)[0] < 0.0:
                return poly_root(c, n, 0.0, s, OF_VALUE, 0.0, x_min)
        return 2.0
    if _rises_throughout(c, n, s):
        return 2.0
    for j in range(1, 4):
        if s * poly_value(c, n, 0.25 * j)[0] < 0.0:
            return poly_root(c, n, 0.0, s, OF_VALUE, 0.25 * (j - 1), 0.25 * j)
    return 2.0


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def step_peak(c, n, s, x_end, du_end):
    """Unit step time of the peak of u = s theta in [0, x_end] (-1.0 if none): where
    u' turns from >= 0 to <= 0; du_end = u'(x_end)."""
    if s * c[1] >= 0.0 and du_end <= 0.0:
        x0 = _secant(s * c[1], du_end, 0.0, x_end) if s * c[1] > du_end else 0.5 * x_end
        return poly_root_near(c, n, 0.0, s, OF_SLOPE, 0.0, x_end, x0)
    return -1.0
