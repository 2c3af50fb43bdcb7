"""Exact solution of the linearized rocking block under sampled records (private).

On a record segment the ground term of eq. (3.1) of [000] is linear in tau = p t,
F = f0 + f1 sigma (F = u_g'' / g, sigma = tau - tau_k), so theta'' = theta - g0 - f1 sigma with
g0 = alpha s + f0 has the closed form, from theta0 and v0 = theta'(0),

    theta(sigma) = theta0 + v0 sinh + (theta0 - g0)(cosh - 1) - f1 (sinh - sigma),

written so that no large terms cancel where theta is small (near impacts). Nothing is
integrated: each segment is a 2 x 2 exponential recursion of (theta, theta').

Events on a segment. theta = g0 + f1 sigma + A e^-sigma + B e^sigma, so theta'' = A e^-sigma
+ B e^sigma has at most one zero: where theta'' has one strict sign at both ends of the segment,
theta' is monotone, and theta' has a zero inside only if it changes sign. On such a segment
(almost every one) theta is monotone, and the only test is whether s theta ends below 0 (an
impact) or above FALL_ROTATION (the fall). Elsewhere theta' = 0 where x = e^sigma solves
B x^2 + f1 x - A = 0: at most two turning points (the peaks), between which theta is monotone,
so an impact or the fall is the single root of a bracketed monotone function.

Costs. The functions of sigma are Taylor polynomials below 0.25 (a record segment is p dt ~
0.005-0.1), computed once per scene for the record's step (a uniform record: once; else
whenever the length changes) and once per impact for the rest of the segment. A block at
rest skips the samples below the uplift level g alpha by a table of block maxima of |u_g''|
shared by every row of a batch (:func:`loud_table`), and the exact lift-off time is found on
the first segment that can lift, by the kernel's own test (``_rocking._lift``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .._roots import ULP_BISECTIONS, newton_bisect
from ..constants import FALL_ROTATION, G
from ..motions._kernels import KIND_RECORD, ground_acceleration, segment_index
from ._linear import (
    PHASE_LOG_WIDTH,
    ROOT_MAX_ITER,
    ROOT_TOL,
    ExactOutcome,
    _exact_outcome,
    trig_scene,
)
from ._logs import raise_max
from ._rocking import (
    MODEL_LINEAR,
    NO_TABLE,
    PH_END,
    PH_OVER,
    PH_REST,
    QUIET_MARGIN,
    REST_FRACTION,
    STATUS_OK,
    _lift,
    new_tallies,
    tally_impact,
)
from ._rows import new_rows, write_row
from ._taylor import FMA, NO_REFCOUNT

#: Below this |sigma| the segment functions are Taylor polynomials: the first term left out
#: is about 1e-18 of the sum at most (sinh - sigma to sigma^13, cosh - 1 to sigma^12).
SERIES_LIMIT = 0.25
#: Samples per entry of the table of |u_g''| maxima that a block at rest skips by.
LOUD_BLOCK = 64
#: Relative change of the segment length below which the cached segment functions are reused
#: (the sample times of a uniform record differ from k dt by rounding).
SAME_LENGTH = 1e-9


@njit(cache=True, fastmath=FMA, inline="always")
def _seg_series(sig):
    """sinh(sigma) - sigma and cosh(sigma) - 1 by their Taylor series (|sigma| < SERIES_LIMIT):
    the tails in pairs (shorter dependency chains than Horner's), the leading terms added last
    (the factorials' inverses folded at compile time)."""
    x2 = sig * sig
    x4 = x2 * x2
    tail_s = (1.0 / 5040.0 + x2 * (1.0 / 362880.0)) + x4 * (
        1.0 / 39916800.0 + x2 * (1.0 / 6227020800.0)
    )
    tail_c = (1.0 / 720.0 + x2 * (1.0 / 40320.0)) + x4 * (
        1.0 / 3628800.0 + x2 * (1.0 / 479001600.0)
    )
    smx = sig * x2 * (1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * tail_s))
    cm1 = x2 * (0.5 + x2 * (1.0 / 24.0 + x2 * tail_c))
    return smx, cm1


@njit(cache=True, fastmath=FMA, inline="always")
def _seg_functions(sig):
    """sinh(sigma), cosh(sigma) - 1 and sinh(sigma) - sigma, each without cancellation: the
    series below SERIES_LIMIT (:func:`_seg_series`); above it cosh - 1 = 2 sinh^2(sigma / 2),
    and sinh - sigma from the series at sigma / 3^m by the triple-angle identity
    sinh 3y - 3y = 3 (sinh y - y) + 4 sinh^3 y (terms of one sign: sinh(sigma) - sigma loses
    a hundred ulps to cancellation at sigma = 0.25)."""
    if abs(sig) < SERIES_LIMIT:
        smx, cm1 = _seg_series(sig)
        return sig + smx, cm1, smx
    y = sig
    m = 0
    while abs(y) >= SERIES_LIMIT:
        y /= 3.0
        m += 1
    smx = _seg_series(y)[0]
    sh = y + smx
    for _ in range(m):
        cube = 4.0 * sh * sh * sh
        smx = 3.0 * smx + cube
        sh = 3.0 * sh + cube
    half = math.sinh(0.5 * sig)
    return math.sinh(sig), 2.0 * half * half, smx


@njit(cache=True, fastmath=FMA, inline="always")
def _seg_advance(th0, v0, g0, f1, sh, cm1, smx):
    """theta and theta' after sigma on a record segment, given :func:`_seg_functions` of sigma."""
    return th0 + v0 * sh + (th0 - g0) * cm1 - f1 * smx, v0 + (th0 - g0) * sh + (v0 - f1) * cm1


@njit(cache=True, fastmath=FMA, inline="always")
def _seg_state(th0, v0, g0, f1, sig):
    """theta [rad] and theta' = d theta / d tau at sigma on a record segment (closed form of
    the module docstring, eq. 3.1 of [000] under a linear ground)."""
    sh, cm1, smx = _seg_functions(sig)
    return _seg_advance(th0, v0, g0, f1, sh, cm1, smx)


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _seg_turning_points(th0, v0, g0, f1, length, e_length):
    """The sigma in (0, length) where theta' = 0 (B x^2 + f1 x - A = 0, x = e^sigma), in order;
    inf where there is none. ``e_length`` is e^length (no logarithm unless a root is inside)."""
    A = 0.5 * ((th0 - g0) - (v0 - f1))
    B = 0.5 * ((th0 - g0) + (v0 - f1))
    r1 = r2 = np.inf
    if B == 0.0:
        if f1 != 0.0:
            r1 = A / f1
    else:
        disc = f1 * f1 + 4.0 * A * B
        if disc < 0.0:
            return np.inf, np.inf
        qq = -0.5 * (f1 + math.copysign(math.sqrt(disc), f1))
        r1 = qq / B
        r2 = -A / qq if qq != 0.0 else np.inf
    s1 = math.log(r1) if 1.0 < r1 < e_length else np.inf
    s2 = math.log(r2) if 1.0 < r2 < e_length else np.inf
    s1 = s1 if s1 < length else np.inf
    s2 = s2 if s2 < length else np.inf
    return min(s1, s2), max(s1, s2)


@njit(cache=True, fastmath=FMA, inline="always")
def _seg_fdf(x, args):
    """f = s theta - target at sigma = x on a record segment (:func:`_seg_state`), and the
    slope that makes a Newton step of :func:`newton_bisect` a Halley step, f' - f f'' / 2 f'
    (cubic convergence; theta'' = theta - g0 - f1 sigma comes free with the state)."""
    target, th0, v0, g0, f1, s = args
    th, v = _seg_state(th0, v0, g0, f1, x)
    f = s * th - target
    df = s * v
    return f, (df - 0.5 * f * s * (th - g0 - f1 * x) / df if df != 0.0 else 0.0)


@njit(cache=True, fastmath=FMA, inline="always")
def _root_guess(target, lo, hi, u_lo, u_hi, du_lo, du_hi):
    """Where u = target on [lo, hi], u monotone from u_lo to u_hi with slopes du_lo, du_hi at
    the ends (0 at a turning point). Both slopes of the rise's sign: the cubic Hermite
    interpolant of the inverse function sigma(u) (error ~ length^4, against length^2 for the
    secant). A turning point at one end: the parabola with its vertex there (an inverse with an
    infinite slope, where the secant lands far from the root). Otherwise the secant."""
    rise = u_hi - u_lo
    if rise == 0.0:
        return 0.5 * (lo + hi)
    t = (target - u_lo) / rise
    if du_lo * rise > 0.0 and du_hi * rise > 0.0:
        t2 = t * t
        return (
            lo
            + (t2 * (3.0 - 2.0 * t)) * (hi - lo)
            + (t * (1.0 - t) * (1.0 - t)) * rise / du_lo
            - (t2 * (1.0 - t)) * rise / du_hi
        )
    if du_lo == 0.0 and 0.0 <= t <= 1.0:
        return lo + (hi - lo) * math.sqrt(t)
    if du_hi == 0.0 and 0.0 <= t <= 1.0:
        return hi - (hi - lo) * math.sqrt(1.0 - t)
    return lo + (hi - lo) * t


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _seg_root(target, th0, v0, g0, f1, s, lo, hi, u_lo, u_hi, du_lo, du_hi):
    """sigma in [lo, hi] where s theta - target changes sign, theta monotone on [lo, hi] with
    s theta = u_lo, u_hi and slopes du_lo, du_hi (0 at a turning point) at the ends (Halley steps
    from :func:`_root_guess`, safeguarded by bisection, to rounding)."""
    sign_lo = 1.0 if u_lo - target >= 0.0 else -1.0
    x0 = _root_guess(target, lo, hi, u_lo, u_hi, du_lo, du_hi)
    x0 = min(max(x0, lo), hi)
    args = (target, th0, v0, g0, f1, s)
    return newton_bisect(_seg_fdf, args, lo, hi, x0, sign_lo, ROOT_TOL, ROOT_MAX_ITER)


@njit(cache=True, fastmath=FMA, inline="always")
def _push(hist, ta, t, theta, theta_dot):
    """Append the row (t, theta, theta_dot) to the history, if it has room; count it."""
    n = ta.n_history
    if n < hist.shape[0]:
        hist[n, 0], hist[n, 1], hist[n, 2] = t, theta, theta_dot
    ta.n_history = n + 1


@njit(cache=True, fastmath=FMA, inline="always")
def _push_impact(times, ta, t):
    """Append an impact time to its log, if it has room; count it."""
    n = ta.n_impact_times
    if n < times.shape[0]:
        times[n] = t
    ta.n_impact_times = n + 1


@njit(cache=True, fastmath=FMA, inline="always")
def _push_peak(peaks, ta, t, theta):
    """Append a peak (t, theta) to its log, if it has room; count it."""
    n = ta.n_peaks
    if n < peaks.shape[0]:
        peaks[n, 0], peaks[n, 1] = t, theta
    ta.n_peaks = n + 1


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _dense_piece(dense, ta, p, tau_a, tau_b, th, v, g0, f1):
    """Write the states at the requested times in (tau_a, tau_b] (tau units, sorted, from
    ``ta.n_dense`` on) from the closed form of the segment piece starting at tau_a in (th, v);
    requested times before tau_a fall in a rest and keep (0, 0)."""
    i = ta.n_dense
    while i < dense.shape[0] and p * dense[i, 0] <= tau_b:
        if p * dense[i, 0] >= tau_a:
            th_i, v_i = _seg_state(th, v, g0, f1, p * dense[i, 0] - tau_a)
            dense[i, 1] = th_i
            dense[i, 2] = p * v_i
        i += 1
    ta.n_dense = i


@njit(cache=True, fastmath=FMA, inline="always")
def _monotone(v, v_end, d0, d1, length):
    """Whether theta is monotone on a segment: theta' keeps one strict sign. theta'' = A e^-sigma
    + B e^sigma is monotone or of one sign, so it has its extremes d0, d1 at the ends: where
    they have one strict sign theta' is monotone too, and otherwise |theta''| <= M = max(|d0|,
    |d1|) keeps theta' >= (|v| + |v_end| - M length) / 2 > 0 in magnitude."""
    if v * v_end <= 0.0:
        return False
    return d0 * d1 > 0.0 or abs(v) + abs(v_end) > max(abs(d0), abs(d1)) * length


@njit(cache=True, fastmath=FMA, inline="always")
def _below(u0, du0, ddu0, ddu1, length, level):
    """Whether u = s theta stays at or below ``level`` on a segment where it starts at u0 with
    u' = du0 and u'' = ddu0 ... ddu1 at the ends (u'' has its maximum at an end, as theta''):
    u <= u0 + max(u', 0) length + max(u'', 0) length^2 / 2."""
    top = u0 + max(du0, 0.0) * length + 0.5 * max(ddu0, ddu1, 0.0) * length * length
    return top <= level


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _slow_segment(th, v, g0, f1, s, length, th_end, v_end, sh, cm1, tau, p, ta, log):
    """A segment on which theta may turn: split at its turning points (the peaks, logged),
    on each monotone piece look for an impact (s theta reaching 0) or the fall (FALL_ROTATION);
    a piece from contact that never rises is an impact at its start (a lift that falls back).
    Returns (sigma of the event or -1, whether it is the fall)."""
    c1, c2 = _seg_turning_points(th, v, g0, f1, length, 1.0 + sh + cm1)
    lo = 0.0
    u_lo = s * th
    for hi in (c1, c2, length):
        if hi == np.inf or hi < lo:
            continue
        th_hi = th_end if hi == length else _seg_state(th, v, g0, f1, hi)[0]
        u_hi = s * th_hi
        du_lo = s * v if lo == 0.0 else 0.0  # a turning point otherwise
        du_hi = s * v_end if hi == length else 0.0
        if u_lo > 0.0 and u_hi <= 0.0:
            return _seg_root(0.0, th, v, g0, f1, s, lo, hi, u_lo, u_hi, du_lo, du_hi), False
        if u_lo <= 0.0 and u_hi < 0.0 and s * f1 >= 0.0:
            # never above contact since a lift from rest, and the ground easing (s f1 >= 0):
            # a lift at a peak of |u_g''| within ulps of g alpha, whose rise (~1e-18 of
            # sigma, its turning point rounded away) falls straight back. An impact here at
            # ~zero speed (the Zeno rule rests the block), as solve_ivp and the kernel find;
            # not run on with s theta < 0 (a false overturning). Where the ground pushes
            # harder (s f1 < 0), a start a few ulps below contact (the lift test and the
            # closed form differing in the last bit) rises at once: it goes on.
            return lo, False
        if u_hi >= FALL_ROTATION:
            return (
                _seg_root(FALL_ROTATION, th, v, g0, f1, s, lo, hi, u_lo, u_hi, du_lo, du_hi),
                True,
            )
        if hi < length and u_hi > 0.0 and u_hi - s * (g0 + f1 * hi) < 0.0:  # u'' < 0: a peak
            _push_peak(log[2], ta, (tau + hi) / p, th_hi)
        raise_max(ta, u_hi, (tau + hi) / p)
        lo, u_lo = hi, u_hi
    return -1.0, False


@njit(cache=True, fastmath=FMA, inline="always")
def _segment_event(th, v, g0, f1, s, length, th_end, v_end, sh, cm1, tau, p, ta, log):
    """The first impact or fall on a segment: (sigma or -1, whether it is the fall), with the
    max rotation (``ta.max_rotation``) and the peaks updated. Most segments are decided without a
    root: theta monotone (:func:`_monotone`), or, when no peak is logged, a single turning
    point that cannot raise the max rotation so far (:func:`_below`)."""
    u0, u_end = s * th, s * th_end
    d0 = th - g0  # theta'' at both ends
    d1 = th_end - g0 - f1 * length
    if _monotone(v, v_end, d0, d1, length):
        du0, du1 = s * v, s * v_end
        if 0.0 < u_end < FALL_ROTATION:
            raise_max(ta, u_end, (tau + length) / p)
            return -1.0, False
        if u_end >= FALL_ROTATION:
            return (
                _seg_root(FALL_ROTATION, th, v, g0, f1, s, 0.0, length, u0, u_end, du0, du1),
                True,
            )
        if u0 > 0.0:
            return _seg_root(0.0, th, v, g0, f1, s, 0.0, length, u0, u_end, du0, du1), False
    elif (
        log[2].shape[0] == 0
        and s * v > 0.0 > s * v_end
        and u_end > 0.0
        and _below(u0, s * v, s * d0, s * d1, length, ta.max_rotation)
    ):
        return -1.0, False  # one turning point, a maximum: no impact, and not a new max
    return _slow_segment(th, v, g0, f1, s, length, th_end, v_end, sh, cm1, tau, p, ta, log)


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _record_phase(alpha, eta, p, c, times, samples, k, tau, th, v, s, ta, log):
    """Rock exactly from (tau, theta, theta', side) on record segment k until rest, overturning
    or the end of the record (eq. 3.1 of [000] with u_g''/g = c samples; impacts with
    restitution eta; rest when the speed after an impact is below REST_FRACTION alpha, the
    caller deciding by the kernel's lift test whether the block rises again). ``log`` =
    (history, impacts, peaks, dense) (arrays of length 0 for none), counted in ``ta``. Returns
    (code, k, tau, theta, theta', side)."""
    n = times.shape[0]
    rest_v = REST_FRACTION * alpha
    logging = log[0].shape[0] > 0
    dense = log[3].shape[0] > 0
    known = -1.0  # the segment length whose functions are in (sh_l, cm1_l, smx_l, inv_l)
    sh_l = cm1_l = smx_l = inv_l = 0.0
    t_lo = p * times[k]
    while k < n - 1:
        t_hi = p * times[k + 1]
        seg = t_hi - t_lo
        if abs(seg - known) > SAME_LENGTH * seg:
            known = seg
            sh_l, cm1_l, smx_l = _seg_functions(seg)
            inv_l = 1.0 / seg
        F0 = c * samples[k]
        f1 = (c * samples[k + 1] - F0) * inv_l
        length = t_hi - tau
        if tau == t_lo:
            g0 = alpha * s + F0
            sh, cm1, smx = sh_l, cm1_l, smx_l
        else:  # the rest of a segment, after an impact or a lift-off inside it
            g0 = alpha * s + F0 + f1 * (tau - t_lo)
            sh, cm1, smx = _seg_functions(length)
        th_end, v_end = _seg_advance(th, v, g0, f1, sh, cm1, smx)
        hit, fall = _segment_event(
            th, v, g0, f1, s, length, th_end, v_end, sh, cm1, tau, p, ta, log
        )
        if dense:
            _dense_piece(log[3], ta, p, tau, t_hi if hit < 0.0 else tau + hit, th, v, g0, f1)
        if hit < 0.0:  # on to the next segment
            th, v, tau, t_lo = th_end, v_end, t_hi, t_hi
            k += 1
            if logging:
                _push(log[0], ta, times[k], th, p * v)
            continue
        th_hit, v_hit = _seg_state(th, v, g0, f1, hit)
        tau += hit
        if fall:
            ta.max_rotation = FALL_ROTATION
            if logging:
                _push(log[0], ta, tau / p, s * FALL_ROTATION, p * v_hit)
            return PH_OVER, k, tau, s * FALL_ROTATION, 0.0, s
        v_post = eta * v_hit
        tally_impact(ta, tau / p)
        th = 0.0
        if logging:
            _push(log[0], ta, tau / p, 0.0, p * v_hit)
            _push_impact(log[1], ta, tau / p)
        if abs(v_post) < rest_v:
            if logging:
                _push(log[0], ta, tau / p, 0.0, 0.0)
            return PH_REST, k, tau, 0.0, 0.0, s
        s = -s
        v = v_post
        if logging:
            _push(log[0], ta, tau / p, 0.0, p * v)
    return PH_END, n - 1, tau, th, v, s


@njit(cache=True)
def loud_table(samples):
    """max |samples| over blocks of LOUD_BLOCK samples: a block at rest skips a whole block
    whose maximum is below the uplift level (one table per record, shared by every row)."""
    out = np.zeros((samples.shape[0] + LOUD_BLOCK - 1) // LOUD_BLOCK)
    for i in range(samples.shape[0]):
        out[i // LOUD_BLOCK] = max(out[i // LOUD_BLOCK], abs(samples[i]))
    return out


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _first_loud(samples, loud, level, j):
    """The first sample index >= j (below the last) with |sample| >= level, or the last."""
    n = samples.shape[0]
    while j < n - 1:
        if j % LOUD_BLOCK == 0 and loud[j // LOUD_BLOCK] < level:
            j += LOUD_BLOCK
        elif abs(samples[j]) >= level:
            return j
        else:
            j += 1
    return n - 1


@njit(cache=True, fastmath=FMA, inline="always")
def _lifts(p, alpha, mp, times, samples, t, k):
    """Whether the ground at t [s] (segment k) lifts a block at rest (``_rocking._lift``)."""
    a_g = ground_acceleration(KIND_RECORD, mp, times, samples, t, k)
    return _lift(a_g, 0.0, p, alpha, MODEL_LINEAR, NO_TABLE) > 0.0


#: Steps of one ulp from the crossing of the uplift level before the switch is bisected for.
ULP_STEPS = 16


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _bisect_lift(p, alpha, mp, times, samples, lo, hi, k, lifts_hi):
    """The time in (lo, hi] on segment k where the lift test turns to ``lifts_hi``, to the ulp.

    The ground is linear on the segment, so the switch is where |u_g''| crosses g alpha; the
    test itself (``_rocking._lift``, other arithmetic) is then checked one ulp either side of
    that time, and bisected for on [lo, hi] only if it is more than ULP_STEPS ulps away.
    """
    a_lo = ground_acceleration(KIND_RECORD, mp, times, samples, lo, k)
    a_hi = ground_acceleration(KIND_RECORD, mp, times, samples, hi, k)
    level = math.copysign(G * alpha, a_hi if lifts_hi else a_lo)
    t = lo + (hi - lo) * (level - a_lo) / (a_hi - a_lo) if a_hi != a_lo else hi
    t = min(max(t, np.nextafter(lo, hi)), hi)
    for _ in range(ULP_STEPS):
        if _lifts(p, alpha, mp, times, samples, t, k) != lifts_hi:
            if t >= hi:
                break
            t = np.nextafter(t, hi)
        else:
            before = np.nextafter(t, lo)
            if before <= lo or _lifts(p, alpha, mp, times, samples, before, k) != lifts_hi:
                return t
            t = before
    for _ in range(ULP_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _lifts(p, alpha, mp, times, samples, mid, k) == lifts_hi:
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _record_uplift(p, alpha, mp, times, samples, loud, t, k):
    """First time >= t [s] (on segment k) at which the record lifts a block at rest, and its
    segment; (inf, k) if none. The samples below the uplift level (less QUIET_MARGIN) are
    skipped by the block table ``loud``; on a segment the ground is linear, so the lift test is
    monotone on each side of its zero and needs checking at the segment's end only
    (``_rocking.next_uplift``)."""
    n = times.shape[0]
    if _lifts(p, alpha, mp, times, samples, t, k):
        return t, k
    level = G * alpha * (1.0 - QUIET_MARGIN) / abs(mp[0]) if mp[0] != 0.0 else np.inf
    lo = t
    while k < n - 1:
        j = _first_loud(samples, loud, level, k + 1)
        if j - 1 > k:
            k = j - 1
            lo = times[k]
        hi = times[k + 1]
        if _lifts(p, alpha, mp, times, samples, hi, min(k + 1, n - 2)):
            return _bisect_lift(p, alpha, mp, times, samples, lo, hi, k, True), k
        lo = hi
        k += 1
    return np.inf, k


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _record_lift_end(p, alpha, mp, times, samples, t, k):
    """First time >= t [s] (segment k) at which the ground stops lifting a block at rest, or
    the end of the record (``_linear._lift_ends``: a block lifted from rest cannot come back
    before it; when the closed form brings it back earlier, it is left at rest until here)."""
    n = times.shape[0]
    lo = t
    while k < n - 1:
        hi = times[k + 1]
        if hi >= mp[3] or not _lifts(p, alpha, mp, times, samples, hi, k):
            return _bisect_lift(p, alpha, mp, times, samples, lo, hi, k, False)
        lo = hi
        k += 1
    return mp[3]


@njit(cache=True)
def record_scene(
    p, alpha, eta, scale, times, samples, loud, use_map, t_tail, log, tail_log, th0=0.0, om0=0.0
):
    """Linearized block under a sampled record (linear between samples), exactly.

    Nothing is integrated: every record segment is the closed form of :func:`_seg_state`. The
    block lifts off where |scale samples| first exceeds g alpha (eq. 3.1 of [000]), by the
    kernel's test (``_rocking._lift``), also after a Zeno rest. ``loud`` is
    :func:`loud_table` of the samples. After the record the free rocking is mapped
    (``use_map``) or followed in closed form until rest, overturning or ``t_tail`` [s]
    (``_linear.trig_scene``, logged in ``tail_log``, its times from the record's end).
    ``log`` = (history (t, theta, theta_dot), impact times, peaks (t, theta), dense (t,
    theta, theta_dot)) inside the record, each of length 0 for none.

    Returns an ``_linear.ExactOutcome`` (its ``log_rows`` those of ``log``).

    Horizontal only: the closed form needs constant coefficients, which a vertical
    component (p^2 (1 + u_v''/g) in time) breaks; the callers run the kernel with
    MODEL_LINEAR for a record that has one.
    """
    dur = times[-1]
    mp = np.array([scale, 0.0, 0.0, dur])
    tallies = new_tallies(abs(th0))
    ta = tallies[0]  # updated in place; every return reads tallies, last (new_tallies)
    logging = log[0].shape[0] > 0
    if logging:
        _push(log[0], ta, 0.0, th0, om0)
    rocking = th0 != 0.0 or om0 != 0.0
    tau, th, v = 0.0, th0, om0 / p
    s = math.copysign(1.0, th0 if th0 != 0.0 else om0)
    k = 0
    code = PH_END
    t_rest = 0.0  # [s] from which a block at rest waits for the ground to lift it
    while True:
        lifted = not rocking  # this phase starts from rest
        if not rocking:
            t_up, k = _record_uplift(p, alpha, mp, times, samples, loud, t_rest, k)
            k_up = k
            if t_up >= dur:
                if logging:
                    _push(log[0], ta, dur, 0.0, 0.0)
                return _exact_outcome(tallies, False, np.nan)
            a_g = ground_acceleration(KIND_RECORD, mp, times, samples, t_up, k)
            s = -1.0 if a_g > 0.0 else 1.0
            tau, th, v = p * t_up, 0.0, 0.0
            if logging:
                _push(log[0], ta, t_up, 0.0, 0.0)
        rocking = False
        code, k, tau, th, v, s = _record_phase(
            alpha, eta, p, scale / G, times, samples, k, tau, th, v, s, ta, log
        )
        if code != PH_REST:
            break
        t_rest = tau / p
        if lifted:  # kept in seconds: p (t_up + 1 ulp) / p may round back to t_up (no progress)
            t_rest = max(t_rest, _record_lift_end(p, alpha, mp, times, samples, t_up, k_up))
        k = segment_index(times, t_rest, k)
    inside = _exact_outcome(tallies, code == PH_OVER, tau / p if code == PH_OVER else np.nan)
    if code == PH_OVER:
        return inside
    # the free rocking after the record: trig_scene under a motion of zero length, from here
    t_free = max(t_tail - dur, 0.0)
    tail = trig_scene(
        p, alpha, eta, np.array([0.0, 1.0, 0.0, 0.0]), use_map, t_free, tail_log, th, v * p
    )
    return _then_tail(inside, tail, dur)


@njit(cache=True)
def _then_tail(inside, tail, dur):
    """The :class:`ExactOutcome` of a record (``inside``) followed by the free rocking after it
    (``tail``, its times from the record's end ``dur`` [s])."""
    n_imp = inside.n_impacts
    later = tail.max_rotation > inside.max_rotation
    return ExactOutcome(
        status=STATUS_OK,
        max_rotation=tail.max_rotation if later else inside.max_rotation,
        overturned=tail.overturned,
        n_impacts=n_imp + tail.n_impacts,
        overturn_time=tail.overturn_time + dur,
        steps=0,
        first_impact_time=inside.first_impact_time if n_imp > 0 else tail.first_impact_time + dur,
        peak_time=tail.peak_time + dur if later else inside.peak_time,
        friction_demand=inside.friction_demand,
        lift_off=inside.lift_off,
        log_rows=inside.log_rows,
    )


@njit(cache=True, parallel=True)
def record_batch(p, alpha, eta, scale, times, samples):
    """:func:`record_scene` over rows (one record, scaled row by row), in parallel; an array
    of :data:`.outputs.KERNEL_ROW`."""
    out = new_rows(p.shape[0])
    loud = loud_table(samples)
    no_log = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
    no_tail = np.empty((0, PHASE_LOG_WIDTH))
    for i in prange(p.shape[0]):
        r = record_scene(
            p[i], alpha[i], eta[i], scale[i], times, samples, loud, True, np.inf, no_log, no_tail
        )
        write_row(out, i, r)
    return out
