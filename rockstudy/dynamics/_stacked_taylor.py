"""Taylor-series step of two stacked blocks both rocking (private numba kernels).

With both interfaces rocking on the corners (s1, s2), the equations of :mod:`._stacked_model`
(``both_equations``) read M(phi) q'' = F, phi = theta_2 - theta_1, with

.. math::

    F_0 &= E_1 (u S_1 + g C_1) + E_2 (g S_1 - u C_1) + m_2 \\dot\\theta_2^2 (K S_\\phi + L C_\\phi)

    F_1 &= m_2 r_{2x} (u S_2 + g C_2) + m_2 r_{2y} (g S_2 - u C_2)
           - m_2 \\dot\\theta_1^2 (K S_\\phi + L C_\\phi)

    M_{01} &= m_2 (K C_\\phi - L S_\\phi), \\quad M_{00}, M_{11} \\text{ constant,}

S, C the sine and cosine of theta_1, theta_2 and phi, u = u_g'' (linear on a record's
segment), E = m_1 r_1 + m_2 d, K = d . r_2 and L = d_y r_{2x} - d_x r_{2y} from the arms
r_1, d, r_2 of the pivots. Its Taylor series follows order by order as in :mod:`._taylor`:
the series of S and C by their recurrences, the squares of the rates and their products by
Cauchy sums, and M q'' = F solved at each order with the constant matrix M(phi_0) (the
higher orders of M_01 move to the right-hand side). O(N^2) flops and 6 sines/cosines per
step of order N, against 13 evaluations of the equations (52 sines/cosines) of a DOP853 step.
The coefficients are scaled by the step (c_k = theta_k h^k) and kept: the step's polynomial
is its dense output, on which the kernel's events are refined.
"""

from __future__ import annotations

import math

from numba import njit

from ..constants import G
from ._stacked_model import A1, A2, I1, I2, M1, M2, P1, P2, _arms
from ._stacked_steps import K_BOTH
from ._taylor import _INV, _INV2, MAX_ORDER, MIN_ORDER, NO_REFCOUNT, _converged
from .constants import ATOL_FRACTION

#: Rows of the scene's work array (:func:`._stacked_steps.work_array`) that :func:`both_step`
#: uses: the scaled series of theta_1, theta_2, the sines and cosines of theta_1, theta_2
#: and phi, the squared rates (scaled by h^2), K S_phi + L C_phi, M_01, and h^2 theta_1'',
#: h^2 theta_2''.
Q1, Q2, S1, C1, S2, C2, SP, CP, WW1, WW2, TT, M01, AC1, AC2 = range(K_BOTH, K_BOTH + 14)


@njit(cache=True, inline="always")
def _trig_next(w, k, x_row, x2_row, s_row, c_row):
    """S_k and C_k of the sine and cosine of x = w[x_row] (minus w[x2_row] if x2_row >= 0),
    from the orders below k (the recurrences of :mod:`._taylor`)."""
    sk = ck = 0.0
    for j in range(1, k + 1):
        xj = w[x_row, j] - (w[x2_row, j] if x2_row >= 0 else 0.0)
        sk += j * xj * w[c_row, k - j]
        ck -= j * xj * w[s_row, k - j]
    w[s_row, k], w[c_row, k] = sk * _INV[k], ck * _INV[k]


@njit(cache=True, inline="always")
def _cauchy(w, ra, rb, k, lo):
    """sum_{j=lo..k} w[ra, j] w[rb, k - j]."""
    acc = 0.0
    for j in range(lo, k + 1):
        acc += w[ra, j] * w[rb, k - j]
    return acc


@njit(cache=True, inline="always")
def _squared_rate(w, row, k):
    """Order k of (h theta')^2 from the scaled series of theta in ``row``."""
    acc = 0.0
    for j in range(k + 1):
        acc += (j + 1) * w[row, j + 1] * (k - j + 1) * w[row, k - j + 1]
    return acc


@njit(cache=True, inline="always")
def _ground_term(w, s_row, c_row, k, ex, ey, u0, du, h2):
    """Order k of h^2 [ex (u S + g C) + ey (g S - u C)], u = u0 + du sigma."""
    us, uc = u0 * w[s_row, k], u0 * w[c_row, k]
    if k >= 1:
        us += du * w[s_row, k - 1]
        uc += du * w[c_row, k - 1]
    return h2 * (ex * (us + G * w[c_row, k]) + ey * (G * w[s_row, k] - uc))


@njit(cache=True, fastmath={"contract"}, **NO_REFCOUNT)
def both_step(g, y, h, s1, s2, u0, u1, tol, w, out):
    """One Taylor step of length h of "both rocking" on the corners (s1, s2) from the state y
    under u_g'' linear from u0 to u1 [m/s^2]: its end state into ``out``; returns (error
    ratio, order n) as :func:`._stacked_steps.one_body_step` (<= 1 accepts; scales tol
    (ATOL_FRACTION alpha_min + ...) per angle), the scaled series in w[Q1], w[Q2]."""
    r1x, r1y, dx, dy, r2x, r2y = _arms(g, s1, s2)
    m1, m2 = g[M1], g[M2]
    ex, ey, kk, ll = (
        m1 * r1x + m2 * dx,
        m1 * r1y + m2 * dy,
        dx * r2x + dy * r2y,
        dy * r2x - dx * r2y,
    )
    m00 = m1 * (r1x * r1x + r1y * r1y) + g[I1] + m2 * (dx * dx + dy * dy)
    m11 = m2 * (r2x * r2x + r2y * r2y) + g[I2]
    h2, du = h * h, u1 - u0
    for a in range(2):
        w[Q1 + a, 0], w[Q1 + a, 1] = y[a], h * y[2 + a]
        w[S1 + 2 * a, 0], w[C1 + 2 * a, 0] = math.sin(y[a]), math.cos(y[a])
    w[SP, 0], w[CP, 0] = math.sin(y[1] - y[0]), math.cos(y[1] - y[0])
    a_min, p_max = min(g[A1], g[A2]), max(g[P1], g[P2])
    sc_x = (_scale_x(y, 0, h, a_min, tol), _scale_x(y, 1, h, a_min, tol))
    sc_v = (_scale_v(y, 0, h, a_min, p_max, tol), _scale_v(y, 1, h, a_min, p_max, tol))
    n = MAX_ORDER
    for k in range(MAX_ORDER - 1):
        if k >= 1:
            _trig_next(w, k, Q1, -1, S1, C1)
            _trig_next(w, k, Q2, -1, S2, C2)
            _trig_next(w, k, Q2, Q1, SP, CP)
        w[WW1, k], w[WW2, k] = _squared_rate(w, Q1, k), _squared_rate(w, Q2, k)
        w[TT, k] = kk * w[SP, k] + ll * w[CP, k]
        w[M01, k] = m2 * (kk * w[CP, k] - ll * w[SP, k])
        f0 = _ground_term(w, S1, C1, k, ex, ey, u0, du, h2) + m2 * _cauchy(w, WW2, TT, k, 0)
        f1 = _ground_term(w, S2, C2, k, m2 * r2x, m2 * r2y, u0, du, h2)
        f1 -= m2 * _cauchy(w, WW1, TT, k, 0)
        r0 = f0 - _cauchy(w, M01, AC2, k, 1)
        r1 = f1 - _cauchy(w, M01, AC1, k, 1)
        m01 = w[M01, 0]
        det = m00 * m11 - m01 * m01
        w[AC1, k], w[AC2, k] = (m11 * r0 - m01 * r1) / det, (m00 * r1 - m01 * r0) / det
        m = k + 2
        w[Q1, m], w[Q2, m] = w[AC1, k] * _INV2[m], w[AC2, k] * _INV2[m]
        if m >= MIN_ORDER and _both_converged(w, m, sc_x, sc_v):
            n = m
            break
    both_state(w, n, 1.0, h, out)
    return _both_error(w, n, sc_x, sc_v), n


@njit(cache=True, inline="always")
def _scale_x(y, a, h, a_min, tol):
    """The error scale of angle a over a step: tol (ATOL_FRACTION alpha_min + |theta| +
    |theta'| h), as :func:`._stacked_steps.one_body_step`'s."""
    return tol * (ATOL_FRACTION * a_min + abs(y[a]) + abs(y[2 + a]) * h)


@njit(cache=True, inline="always")
def _scale_v(y, a, h, a_min, p_max, tol):
    """h times the error scale of angle a's rate: tol (ATOL_FRACTION p_max alpha_min +
    |theta'| + |theta| p_max^2 h) h."""
    return tol * (ATOL_FRACTION * p_max * a_min + abs(y[2 + a]) + abs(y[a]) * p_max**2 * h) * h


@njit(cache=True, inline="always")
def _both_converged(w, m, sc_x, sc_v):
    """:func:`._taylor._converged` of both angles' series at order m."""
    for a in range(2):
        if not _converged(w[Q1 + a, m - 1], w[Q1 + a, m], m, sc_x[a], sc_v[a]):
            return False
    return True


@njit(cache=True, inline="always")
def _both_error(w, n, sc_x, sc_v):
    """The larger of the angles' truncation-error bounds over their scales (the last two
    terms, :func:`._taylor._error_ratio`)."""
    err = 0.0
    for a in range(2):
        b, e = abs(w[Q1 + a, n - 1]), abs(w[Q1 + a, n])
        err = max(err, (b + e) / sc_x[a], ((n - 1) * b + n * e) / sc_v[a])
    return err


@njit(cache=True, **NO_REFCOUNT)
def both_state(w, n, sigma, h, out):
    """The state at the fraction sigma of the last :func:`both_step` (order n, length h) on
    its polynomials, into out."""
    for a in range(2):
        v = d = 0.0
        for k in range(n, 0, -1):
            v = v * sigma + w[Q1 + a, k]
            d = d * sigma + k * w[Q1 + a, k]
        out[a], out[2 + a] = v * sigma + w[Q1 + a, 0], d / h


@njit(cache=True, **NO_REFCOUNT)
def one_body_series(w, c, n, k, y, h):
    """Keep the scaled series c (order n) of a one-body regime's step of length h from y
    (:func:`._stacked_steps.one_body_step`, its angle theta = y[k]) as both angles' series
    for :func:`both_state`: theta_2 = theta_1 of the locked assembly (k = 0), theta_1 at rest
    under the upper block alone (k = 1)."""
    for j in range(n + 1):
        w[Q1 + k, j] = c[j]
        w[Q2 - k, j] = c[j] if k == 0 else 0.0
    if k == 1:
        w[Q1, 0], w[Q1, 1] = y[0], h * y[2]


@njit(cache=True, **NO_REFCOUNT)
def series_clear(w, n, k, s):
    """Whether interface k (rocking on side s) stays off zero with a rate of one sign
    throughout the last Taylor step (its scaled series of order n in w[Q1], w[Q2]; the
    interface's angle theta_1 for k = 0, phi = theta_2 - theta_1 for k = 1): no impact,
    trough or peak inside it. |sum_j c_j sigma^j| <= sum_j |c_j| on [0, 1] bounds the
    angle's excursion and the rate's change, so s c_0 > sum_{j>=1} |c_j| and |c_1| >
    sum_{j>=2} j |c_j| prove it for the series."""
    c0 = w[Q1, 0] if k == 0 else w[Q2, 0] - w[Q1, 0]
    c1 = w[Q1, 1] if k == 0 else w[Q2, 1] - w[Q1, 1]
    if not s * c0 > 0.0:
        return False
    spread, slope = abs(c1), 0.0
    for j in range(2, n + 1):
        c = abs(w[Q1, j] if k == 0 else w[Q2, j] - w[Q1, j])
        spread += c
        slope += j * c
    return s * c0 > spread and abs(c1) > slope
