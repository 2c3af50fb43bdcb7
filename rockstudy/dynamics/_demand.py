"""The friction demand and lift-off of Housner's block, computed while a kernel rocks it
(private): the batch's friction check without a history.

The ground's force on the block per unit mass (:mod:`rockstudy.dynamics.contact`), with
x = alpha s - theta, S = sin x, C = cos x, gamma = g + u_v'' and R theta_ddot = -(3/4)
(gamma S + u_h'' C) from eq. (2.2) of [000] (R p^2 = 3 g / 4):

.. math::

   F_h / m = \\ddot u_h + R \\ddot\\theta C + R \\dot\\theta^2 S, \\qquad
   F_v / m = \\gamma + R \\ddot\\theta S - R \\dot\\theta^2 C.

On every accepted Taylor step the ratio ``|F_h|`` / F_v is evaluated on the step polynomial
at :data:`INTERIOR` points and the step's end (its start too where a rocking phase starts: at
uplift, after an impact; read off the series' first coefficients), theta, theta_dot, S and C
summed from the step's series (no sine or cosine per sample); where the largest of a step's
samples, or the vertex of the parabola through it and its neighbours, reaches the largest
ratio so far, it is refined by parabolic interpolation (:func:`_parabolic`) between its
neighbours. The demand is the largest ratio, with the impulse ratio of the impacts,
(1 - eta) / ((1 + eta) tan alpha), if the block struck the ground; the block lifts off where
F_v <= 0 at a sample (demand inf).

What needs no evaluation: a block at rest has ``|u_h''|`` / gamma <= tan alpha (else it
lifts), and the ratio is exactly tan alpha at uplift (a sample), so the rests never set the
demand of a block that lifts; free rocking after the motion, which the batch maps
(:func:`._free_map.free_rocking_map`) rather than integrates, needs less than tan alpha and
never lifts off for alpha <= :data:`FREE_ROCKING_SLENDERNESS` (its forces depend on the
rotation and the energy only: :func:`free_rocking_ratio`). As
:func:`rockstudy.dynamics.contact.check_contact`, of an overturned block only the response up
to the last time ``|theta|`` = alpha counts: samples beyond alpha are held apart and kept
only when the block comes back below it.

The state lives in the scene's tallies (:data:`._logs.TALLIES`, fields ``d_*``) and the
polynomial of the step before in a row of the Taylor work array (:data:`._taylor.ROW_PREV`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import G
from ..motions._kernels import (
    KIND_RECORD,
    KIND_TRIG,
    ground_acceleration,
    vertical_acceleration,
)
from ._rhs import _record_acceleration
from ._taylor import (
    FMA,
    NO_REFCOUNT,
    OF_VALUE,
    ROW_C,
    ROW_C_SERIES,
    ROW_F,
    ROW_PREV,
    ROW_S,
    poly_root,
    poly_value,
)

#: Points inside each Taylor step at which the forces are evaluated (besides its end), but
#: inside a record (its steps end on its samples).
INTERIOR = 2
#: Iterations at most of the refinement of a local maximum between its neighbouring
#: samples (:func:`_parabolic`), until the parabola's vertex moves less than REFINE_TOL
#: (relative to the bracket; the ratio then exact to ~REFINE_TOL^2) or the bracket is that
#: short.
REFINE_ITERATIONS = 30
REFINE_TOL = 1e-6
#: Where the refinement of a largest sample at the start (the end) of a rocking phase tests
#: the slope: this fraction of the way to the next (the previous) sample.
START_OFFSET = 1e-3
#: Largest slenderness [rad] for which free rocking (no ground motion, below the overturning
#: energy) needs less friction than tan alpha and keeps F_v > 0 (checked on a dense grid of
#: energies and rotations: the ratio peaks at 0.75 tan alpha for small alpha and reaches
#: tan alpha near alpha = 0.96); beyond it a mapped free rocking leaves the demand uncomputed.
FREE_ROCKING_SLENDERNESS = 0.9
#: Relative margins of the bound of a step's ratio over its samples' rounding
#: (:func:`_below_best`) and of a pulse's ground over its value from the step's series.
BOUND_MARGIN = 1e-9
GROUND_MARGIN = 1e-9
_GOLD = 0.5 * (math.sqrt(5.0) - 1.0)


@njit(cache=True, fastmath=FMA, inline="always")
def _ratio(sx, cx, om, a_h, a_v, p):
    """(``|F_h|`` / F_v, F_v / m) of a block rocking at theta_dot = om [rad/s] under the ground
    (a_h, a_v) [m/s^2], from S = sin x, C = cos x (x = alpha s - theta, on side s); the ratio
    inf where F_v <= 0."""
    gam = G + a_v
    r_acc = -0.75 * (gam * sx + a_h * cx)  # R theta_ddot
    r_om2 = 0.75 * G * (om / p) ** 2  # R theta_dot^2
    f_h = a_h + r_acc * cx + r_om2 * sx
    f_v = gam + r_acc * sx - r_om2 * cx
    return (abs(f_h) / f_v if f_v > 0.0 else np.inf), f_v


def free_rocking_ratio(c, energy):
    """``|F_h|`` / F_v and F_v / (m g) of a block rocking freely (no ground motion), as
    functions of c = cos(alpha - ``|theta|``) and K = (theta_dot / p)^2 + 2 c (constant
    between impacts): F_h / (m R p^2) = sin phi (K - 3 c), F_v / (m R p^2) = 3 c^2 - K c + 1/3.
    Broadcasting (numpy)."""
    f_h = np.sqrt(1.0 - c * c) * np.abs(energy - 3.0 * c)
    f_v = 3.0 * c * c - energy * c + 1.0 / 3.0
    return f_h / f_v, 0.75 * f_v


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _sample(w, ta, tau, step):
    """(ratio, F_v / m, u = s theta) at time tau [s] on the polynomial of the step that holds
    it: the current one (``step`` = (t0, hs, n, k, s, p, alpha, mot), its series in w:
    :func:`_series_at`) or, before t0, the step before (w[ROW_PREV], its t0, hs, n, k in
    ``ta``; S and C from theta)."""
    t0, hs, n, k, s, p, alpha, mot = step
    if tau < t0:
        t0, hs, n, k = ta.d_prev_t, ta.d_prev_hs, ta.d_prev_n, ta.d_prev_k
        th, d, _ = poly_value(w[ROW_PREV], n, (tau - t0) / hs)
        x = alpha * s - th
        sx, cx = math.sin(x), math.cos(x)
    else:
        th, d, sx, cx = _series_at(w, n, (tau - t0) / hs)
    a_h, a_v = _grounds(mot, t0, tau, k)
    ratio, f_v = _ratio(sx, cx, d / hs, a_h, a_v, p)
    return ratio, f_v, s * th


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _grounds(mot, t0, tau, k):
    """(u_h'', u_v'') [m/s^2] at tau [s] (record segment k) on a step that starts at t0 [s]:
    0 on a step after the motion; u_h'' as :func:`rockstudy.motions._kernels.ground_acceleration`
    gives it, without its call where the arithmetic is short (a trigonometric pulse, and a
    record on one of its samples, where the record's steps end: no interpolation)."""
    kind, mp, times, samples, vsamples = mot
    a_h = a_v = 0.0
    if t0 < mp[3]:  # the step lies within the motion
        if kind == KIND_TRIG:
            a_h = mp[0] * math.sin(mp[1] * tau + mp[2]) if 0.0 <= tau <= mp[3] else 0.0
        elif kind == KIND_RECORD:
            a_h = _record_acceleration(mp, times, samples, tau, k)
        else:
            a_h = ground_acceleration(kind, mp, times, samples, tau, k)
        a_v = vertical_acceleration(kind, mp, times, vsamples, tau, k)
    return a_h, a_v


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _series_at(w, n, x):
    """(theta, dtheta/dx, S, C) at unit step time x on the current step: theta's polynomial
    of order n (w[ROW_C]) and the series of S = sin(alpha s - theta) and C = cos(alpha s -
    theta) to order n - 2 (w[ROW_S], w[ROW_C_SERIES]; within the step's tolerance, as in
    :func:`_sample_end`), summed by one Horner loop: no sine or cosine per sample."""
    d = w[ROW_C, n]
    v = d * x + w[ROW_C, n - 1]
    sx = w[ROW_S, n - 2]
    cx = w[ROW_C_SERIES, n - 2]
    for j in range(n - 2, 0, -1):
        d = d * x + v
        v = v * x + w[ROW_C, j]
        sx = sx * x + w[ROW_S, j - 1]
        cx = cx * x + w[ROW_C_SERIES, j - 1]
    return v * x + w[ROW_C, 0], d * x + v, sx, cx


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _sample_end(w, tau, end, step):
    """:func:`_sample` at the end of the current step (unit step time 1), where its state
    ``end`` = (theta, theta_dot) is known: S = sin x and C = cos x as the sums of their
    series (to order n - 2, within the step's tolerance: their next terms are of the size of
    the last two of theta's, which the step's error test bounds), the ground at tau [s]."""
    t0, hs, n, k, s, p, alpha, mot = step
    s0 = s1 = c0 = c1 = 0.0
    for j in range(0, n - 2, 2):  # two sums each: shorter dependency chains
        s0 += w[ROW_S, j]
        c0 += w[ROW_C_SERIES, j]
        s1 += w[ROW_S, j + 1]
        c1 += w[ROW_C_SERIES, j + 1]
    if (n - 1) % 2 == 1:
        s0 += w[ROW_S, n - 2]
        c0 += w[ROW_C_SERIES, n - 2]
    a_h, a_v = _grounds(mot, t0, tau, k)
    ratio, f_v = _ratio(s0 + s1, c0 + c1, end[1], a_h, a_v, p)
    return ratio, f_v, s * end[0]


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _sample_start(w, step):
    """:func:`_sample` at the start of the current step (unit step time 0), where its series
    start: theta, its derivative, S and C are their first coefficients (what
    :func:`_series_at` sums at x = 0, without the sums), the ground at the step's start."""
    t0, hs, n, k, s, p, alpha, mot = step
    a_h, a_v = _grounds(mot, t0, t0, k)
    ratio, f_v = _ratio(w[ROW_S, 0], w[ROW_C_SERIES, 0], w[ROW_C, 1] / hs, a_h, a_v, p)
    return ratio, f_v, s * w[ROW_C, 0]


@njit(cache=True, inline="always")
def _take(ta, ratio, f_v, over):
    """Count a sample: beyond alpha (``over``) held apart; below it, the held ones kept (the
    block came back) and the sample with them."""
    ta.d_samples += 1
    if over:
        ta.d_over = max(ta.d_over, ratio)
        ta.d_min_fv_over = min(ta.d_min_fv_over, f_v)
        return
    _keep_over(ta)
    ta.d_best = max(ta.d_best, ratio)
    ta.d_min_fv = min(ta.d_min_fv, f_v)


@njit(cache=True, inline="always")
def _keep_over(ta):
    """Keep the samples held beyond alpha (the block did not fall from there); nothing to do
    where none is held (the common case: no stores on a record's every step)."""
    if ta.d_min_fv_over == np.inf and ta.d_over == 0.0:
        return
    ta.d_best = max(ta.d_best, ta.d_over)
    ta.d_min_fv = min(ta.d_min_fv, ta.d_min_fv_over)
    ta.d_over = 0.0
    ta.d_min_fv_over = np.inf


@njit(cache=True, inline="always")
def _parabola(x0, f0, x1, f1, x2, f2):
    """(a, b) of the parabola f1 + b dx + a dx^2 (dx = x - x1) through three points
    (x0 < x1 < x2)."""
    h0, h2 = x1 - x0, x2 - x1
    a = ((f0 - f1) / h0 + (f2 - f1) / h2) / (h0 + h2)
    return a, (f2 - f1) / h2 - a * h2


@njit(cache=True, inline="always")
def _vertex_at(x0, f0, x1, f1, x2, f2):
    """Where the parabola through three points (x0 < x1 < x2) has its maximum (NaN if it has
    none)."""
    a, b = _parabola(x0, f0, x1, f1, x2, f2)
    return x1 - 0.5 * b / a if a < 0.0 else np.nan


@njit(cache=True, inline="always")
def _vertex(x0, f0, x1, f1, x2, f2):
    """The largest value of the parabola through three points (x0 < x1 < x2) where it has a
    maximum; else f1."""
    a, b = _parabola(x0, f0, x1, f1, x2, f2)
    return f1 - b * b / (4.0 * a) if a < 0.0 else f1


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _parabolic(w, ta, x, f, step):
    """Count the largest ratio near the best of three times x[1] (x[0] < x[1] < x[2], f[1]
    the largest of f), found by successive parabolic interpolation kept inside the bracket, a
    golden-section step where the parabola's vertex would not shrink it."""
    x0, x1, x2 = x
    f0, f1, f2 = f
    tol = REFINE_TOL * (x2 - x0)
    for _ in range(REFINE_ITERATIONS):
        h0, h2 = x1 - x0, x2 - x1
        xv = x1 - (1.0 - _GOLD) * h0 if h0 > h2 else x1 + (1.0 - _GOLD) * h2
        xp = _vertex_at(x0, f0, x1, f1, x2, f2)
        if abs(xp - x1) <= tol or h0 + h2 <= tol:
            break  # converged: the parabola's vertex is the best point
        if x0 < xp < x2:
            xv = xp
        r, f_v, u = _sample(w, ta, xv, step)
        _take(ta, r, f_v, u > step[6])
        if r > f1:
            if xv < x1:
                x2, f2, x1, f1 = x1, f1, xv, r
            else:
                x0, f0, x1, f1 = x1, f1, xv, r
        elif xv < x1:
            x0, f0 = xv, r
        else:
            x2, f2 = xv, r


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _refine_window(w, ta, tc, fc, step):
    """Refine the middle sample of the grid's last three (a, b in ``ta``, c = (tc, fc)) where
    it is a local maximum (:func:`_refine_peak`). Only this test is inlined (it runs on every
    sample); the refinement, rarer, is a call: inlined at each of :func:`demand_step`'s four
    :func:`_push` it cost the phase loop most of its compile time."""
    fb = ta.d_fb
    if fb >= fc and fb >= ta.d_fa and math.isfinite(fb):
        _refine_peak(w, ta, tc, fc, step)


@njit(cache=True, **NO_REFCOUNT)
def _refine_peak(w, ta, tc, fc, step):
    """Refine the grid's local maximum b (a, b in ``ta``, c = (tc, fc)) where all three lie
    on one side of alpha and it may exceed the largest ratio of that side so far; a at the
    start of a rocking phase (none: f -inf) refines from b, the phase's first sample, by the
    slope START_OFFSET of the way to c. Compiled without ``fastmath``, as the phase loop it
    was inlined into (the same roundings)."""
    t_a, fa, tb, fb = ta.d_ta, ta.d_fa, ta.d_tb, ta.d_fb
    over = ta.d_cb
    if math.isfinite(fa):
        if ta.d_ca != over or _vertex(t_a, fa, tb, fb, tc, fc) < (ta.d_over if over else ta.d_best):
            return
        _parabolic(w, ta, (t_a, tb, tc), (fa, fb, fc), step)
        return
    near = tb + START_OFFSET * (tc - tb)
    r, f_v, u = _sample(w, ta, near, step)
    _take(ta, r, f_v, u > step[6])
    if r > fb and r >= fc:
        _parabolic(w, ta, (tb, near, tc), (fb, r, fc), step)


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _close(w, ta, step):
    """Close the grid of a rocking phase whose last sample is b (an impact, the overturning,
    the end of the motion): where the ratio falls into b (a point START_OFFSET of the way
    back to a lies above it), refine between a and b."""
    t_a, fa, tb, fb = ta.d_ta, ta.d_fa, ta.d_tb, ta.d_fb
    ta.d_fa = ta.d_fb = -np.inf
    if not (math.isfinite(fa) and math.isfinite(fb)) or ta.d_ca != ta.d_cb:
        return
    near = tb - START_OFFSET * (tb - t_a)
    r, f_v, u = _sample(w, ta, near, step)
    _take(ta, r, f_v, u > step[6])
    if r > fb and r >= fa:
        _parabolic(w, ta, (t_a, near, tb), (fa, r, fb), step)


@njit(cache=True, **NO_REFCOUNT)
def _push_crossing(w, ta, tau, step, over):
    """Count and add to the grid the sample at ``|theta|`` = alpha between the grid's last
    sample b and the sample at tau [s] on the other side of alpha (``over``: 1.0 where that
    one lies beyond alpha). A call, not inlined: rare, and inlined at each :func:`_push` it
    cost the phase loop's compile; without ``fastmath``, as the loop it was inlined into."""
    t0, hs, n, s, alpha = step[0], step[1], step[2], step[4], step[6]
    lo = max((ta.d_tb - t0) / hs, 0.0)
    up = over == 1.0
    x = poly_root(w[ROW_C], n, s * alpha, -s if up else s, OF_VALUE, lo, (tau - t0) / hs)
    rc, fvc, _ = _sample(w, ta, t0 + x * hs, step)
    _take(ta, rc, fvc, False)
    _shift(ta, t0 + x * hs, rc, 0.0)


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _push(w, ta, tau, step, sample):
    """Count and add to the grid the sample (ratio, F_v / m, u = s theta) taken at tau [s]
    (in time order), with the sample at ``|theta|`` = alpha before it where the two lie on
    either side of alpha (:func:`_push_crossing`: the end of the response that counts if the
    block falls from there); refine the grid's local maximum (:func:`_refine_window`).
    Inlined, as :func:`_refine_window`'s test: their calls, with the step's flattened
    arguments, cost a pulse's demand about a third of its time (measured on single-thread
    CPU time)."""
    r, f_v, u = sample
    alpha = step[6]
    over = 1.0 if u > alpha else 0.0
    if math.isfinite(ta.d_fb) and over != ta.d_cb:
        _push_crossing(w, ta, tau, step, over)
    _take(ta, r, f_v, over == 1.0)
    _refine_window(w, ta, tau, r, step)
    _shift(ta, tau, r, over)


@njit(cache=True, inline="always")
def _shift(ta, t, f, over):
    """The grid's last two samples become (b, (t, f, over))."""
    ta.d_ta, ta.d_fa, ta.d_ca = ta.d_tb, ta.d_fb, ta.d_cb
    ta.d_tb, ta.d_fb, ta.d_cb = t, f, over


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def demand_step(ta, w, n, t, hs, t_end, s, p, alpha, mot, k, end):
    """Count an accepted Taylor step of length hs [s] from t [s] up to t_end on side s, whose
    polynomial of order n is in w[ROW_C] (record segment k): its samples on the grid and
    their refinement (module docstring); keep it as the step before (w[ROW_PREV]). ``end``:
    (theta, theta_dot) at t_end where it is the step's end, NaN where it is an event. Inlined
    into the phase loop (a call with its flattened arguments costs a record step ~10 %).

    A step with interior samples is first bounded (:func:`_below_best`) and left out where
    none of its samples can count; a record's step, sampled at its end only, is sampled
    without the bound, which costs more than that one sample (the demand's share of a
    record scene's CPU fell from 43 % to 31 % of the bare kernel's)."""
    step = (t, hs, n, k, s, p, alpha, mot)
    fresh = 0
    kind, mp = mot[0], mot[1]
    inside = 0 if kind == KIND_RECORD and t < mp[3] else INTERIOR
    if inside and end[0] == end[0] and _below_best(ta, w, n, t, hs, t_end, s, p, alpha, mot, k):
        _close(w, ta, step)  # the grid ends at the step's start
        _keep_over(ta)  # the block is below alpha
        fresh = 1  # the next step sampled starts a new grid
    else:
        if ta.d_fresh != 0:  # a rocking phase starts: a new grid
            _close(w, ta, step)
            _push(w, ta, t, step, _sample_start(w, step))
        for j in range(1, inside + 1):
            tau = t + (t_end - t) * j / (inside + 1)
            _push(w, ta, tau, step, _sample(w, ta, tau, step))
        if end[0] == end[0]:
            _push(w, ta, t_end, step, _sample_end(w, t_end, end, step))
        else:  # an impact or the overturning ends the phase
            _push(w, ta, t_end, step, _sample(w, ta, t_end, step))
            _close(w, ta, step)
    for j in range(n + 1):
        w[ROW_PREV, j] = w[ROW_C, j]
    ta.d_prev_t, ta.d_prev_hs, ta.d_prev_n, ta.d_prev_k = t, hs, n, k
    ta.d_fresh = fresh


@njit(cache=True, inline="always")
def _product(al, ah, bl, bh):
    """The interval of the products of [al, ah] and [bl, bh]."""
    p1, p2, p3, p4 = al * bl, al * bh, ah * bl, ah * bh
    return min(min(p1, p2), min(p3, p4)), max(max(p1, p2), max(p3, p4))


@njit(cache=True, inline="always")
def _square(lo, hi):
    """The interval of the squares of [lo, hi]."""
    low = 0.0 if lo <= 0.0 <= hi else min(lo * lo, hi * hi)
    return low, max(lo * lo, hi * hi)


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _ground_range(w, t, t_end, hs, p, mot, k):
    """(lo, hi) of u_h'' and of u_v'' [m/s^2] as the samples see them over the step from t
    to t_end [s] (:func:`_ground`; 0 beyond the motion): a record's segment k is linear, so
    are its vertical samples; a trigonometric pulse a sin(omega t + phase) lies within
    GROUND_MARGIN of its start value and slope (a0 + a1 x from the step's ground series
    w[ROW_F], as scaled by :func:`._taylor.taylor_coefficients_trig`) plus |a| (omega h)^2 / 2,
    and within +-|a|. NaN for the other motions."""
    kind, mp, times, samples, vsamples = mot
    if t >= mp[3]:
        return 0.0, 0.0, 0.0, 0.0
    vl = vh = 0.0
    if kind == KIND_RECORD:
        a0, a1 = mp[0] * samples[k], mp[0] * samples[k + 1]
        lo, hi = min(a0, a1), max(a0, a1)
        if vsamples.shape[0] != 0:
            v0, v1 = abs(mp[0]) * vsamples[k], abs(mp[0]) * vsamples[k + 1]
            vl, vh = min(v0, v1), max(v0, v1)
    elif kind == KIND_TRIG and vsamples.shape[0] == 0:
        amp = abs(mp[0])
        scale = G / -((p * hs) ** 2)  # the series' factor q / g undone
        a0, a1 = w[ROW_F, 0] * scale, w[ROW_F, 1] * scale
        r = 0.5 * amp * (mp[1] * hs) ** 2 + GROUND_MARGIN * amp
        lo = max(a0 + min(a1, 0.0) - r, -amp)
        hi = min(a0 + max(a1, 0.0) + r, amp)
    else:
        return np.nan, np.nan, np.nan, np.nan
    if t_end > mp[3]:  # the samples after the motion's end see no ground
        lo, hi, vl, vh = min(lo, 0.0), max(hi, 0.0), min(vl, 0.0), max(vh, 0.0)
    return lo, hi, vl, vh


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _series_ranges(w, n, hs, p):
    """Over the current step (unit step time x in [0, 1]): theta's start value and radius,
    and the intervals of S, C and R theta_dot^2 = (3/4) g (theta_dot / p)^2 (theta_dot =
    (dtheta/dx) / hs), as their series bound them: ``|sum c_k x^k - c_0|`` <= sum ``|c_k|``
    (k >= 1)."""
    r_th, r_d = abs(w[ROW_C, 1]), 0.0
    for j in range(2, n + 1):
        a = abs(w[ROW_C, j])
        r_th += a
        r_d += j * a
    r_s = r_c = 0.0
    for j in range(1, n - 1):
        r_s += abs(w[ROW_S, j])
        r_c += abs(w[ROW_C_SERIES, j])
    d0 = w[ROW_C, 1]
    dl, dh = _square(d0 - r_d, d0 + r_d)
    q = 0.75 * G / (p * hs) ** 2
    s0, c0 = w[ROW_S, 0], w[ROW_C_SERIES, 0]
    return (w[ROW_C, 0], r_th), (s0 - r_s, s0 + r_s), (c0 - r_c, c0 + r_c), (q * dl, q * dh)


@njit(cache=True, inline="always")
def _ratio_bound(ground, sn, cs, q):
    """An upper bound of ``|F_h|`` / F_v (inf where F_v may reach 0) from intervals of the
    ground (u_h'', u_v''), S, C and R theta_dot^2 (:func:`_ratio`'s forces, regrouped so
    that each of u_h'' and S enters ``|F_h|`` once):
    F_h / m = u_h'' (1 - 3 C^2 / 4) + S (R theta_dot^2 - 3 gamma C / 4),
    F_v / m = gamma (1 - 3 S^2 / 4) - C (3 u_h'' S / 4 + R theta_dot^2)."""
    al, ah, vl, vh = ground
    (sl, sh), (cl, ch), (ql, qh) = sn, cs, q
    gl, gh = G + vl, G + vh
    c2l, c2h = _square(cl, ch)
    h1l, h1h = _product(al, ah, 1.0 - 0.75 * c2h, 1.0 - 0.75 * c2l)
    gcl, gch = _product(gl, gh, cl, ch)
    h2l, h2h = _product(sl, sh, ql - 0.75 * gch, qh - 0.75 * gcl)
    s2l, s2h = _square(sl, sh)
    v1l = _product(gl, gh, 1.0 - 0.75 * s2h, 1.0 - 0.75 * s2l)[0]
    asl, ash = _product(al, ah, sl, sh)
    f_v = v1l - _product(cl, ch, 0.75 * asl + ql, 0.75 * ash + qh)[1]
    return max(-(h1l + h2l), h1h + h2h) / f_v if f_v > 0.0 else np.inf


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _below_best(ta, w, n, t, hs, t_end, s, p, alpha, mot, k):
    """Whether no sample of the current step can count: theta stays below alpha on side s,
    F_v above 0 and the ratio below the largest so far, by the bounds of the ratio over the
    step (:func:`_ratio_bound`, with a relative BOUND_MARGIN for the rounding of the
    samples)."""
    if not ta.d_best > 0.0:
        return False
    ground = _ground_range(w, t, t_end, hs, p, mot, k)
    if ground[0] != ground[0]:
        return False
    (th0, r_th), sn, cs, q = _series_ranges(w, n, hs, p)
    if s * th0 + r_th >= alpha:
        return False
    return _ratio_bound(ground, sn, cs, q) * (1.0 + BOUND_MARGIN) < ta.d_best


@njit(cache=True)
def demand_outcome(ta, over, eta, alpha):
    """(friction_demand, lift_off) of a scene from its tallies: NaN (and False) where the
    kernel did not compute it (it never rocked, or a step or the free rocking it could not
    cover); of an overturned block (``over``) the samples beyond alpha left out."""
    if ta.d_uncovered != 0 or ta.d_samples == 0:
        return np.nan, False
    if not over:
        _keep_over(ta)
    if ta.d_min_fv <= 0.0:
        return np.inf, True
    best = ta.d_best
    if ta.n_impacts > 0:
        best = max(best, (1.0 - eta) / ((1.0 + eta) * math.tan(alpha)))
    return best, False
