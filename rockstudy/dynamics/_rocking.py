"""Event-driven rocking kernels (private): Housner's block, nonlinear or linearized.

State machine per scene: rest, rocking on side s = +1 or -1, overturned. The side is carried
explicitly (never sgn(theta)), so the right-hand side is smooth across theta = 0 and an impact
is a root of theta on the quintic Hermite interpolant of an accepted DOP853 step. After the
excitation ends nothing is integrated unless the block overturns: the free-rocking map
(energy conservation between impacts, eta per impact) gives the peaks and the decision.

A block at rest lifts off where its own acceleration on the side pushed towards turns
positive (:func:`_lift`, the right-hand side itself), found on the motion's monotone pieces
between analytic extrema; the Zeno rule restarts a settling block by the same test, so a
block said to lift always rises and a chatter at the threshold cannot go on without end.

A record's vertical component u_v'' (``vsamples`` of the motion tuple, empty for none) turns
gravity into g + u_v'' in every model (:func:`_accel`), in the lift test and so in the uplift
search and the Zeno rule; the solvers refuse u_v'' <= -g (free fall) before calling a kernel.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from .._roots import ULP_BISECTIONS, newton_bisect
from ..constants import FALL_ROTATION, G
from ..motions._kernels import (
    KIND_RECORD,
    KIND_TRIG,
    ground_acceleration,
    segment_index,
    vertical_acceleration,
)
from ._dop853 import dop853_error, hermite5, make_dop853_step
from ._taylor import (
    FMA,
    NO_REFCOUNT,
    OF_VALUE,
    poly_end,
    poly_root,
    poly_value,
    step_impact,
    step_peak,
    taylor_coefficients,
    taylor_coefficients_trig,
    work_arrays,
)

MODEL_NONLINEAR = 0
MODEL_LINEAR = 1
MODEL_TABLE = 2  # a mechanism, eq. (8) of [003], from tabulated I, G, B (structures/mechanism)

#: Columns of a mechanism table, on a uniform grid of the amplitude phi in [0, fall].
TAB_PHI, TAB_I, TAB_DI, TAB_G, TAB_DG, TAB_B, TAB_DB, TAB_V, TAB_DV = range(9)
NO_TABLE = np.empty((2, 0, 9))  # [direction + (0), direction - (1)], node, column

PH_END = 0
PH_REST = 1
PH_OVER = 2
PH_FAIL = 3
PH_IMPACT = 4
# numpy scalars, not Python ints: numba types a literal argument as Literal[int] and compiles a
# specialization of the callee for each value (a phase, an uplift test compiled twice)
NO_STOP = np.int64(-1)  # a phase's stop_at_impacts: never

STATUS_OK = 0
STATUS_MAX_STEPS = 1
STATUS_HISTORY_FULL = 2

#: Post-impact speed below which the block is taken to be at rest, as a fraction of p*alpha.
REST_FRACTION = 1e-4
#: Local error target as a fraction of rtol, so that global errors (peaks, impact times over
#: tens of cycles) stay below rtol; calibrated against the scipy reference at rtol 1e-12.
TOL_SAFETY = 0.1
#: Local error target of the Taylor record step, as a fraction of TOL_SAFETY * rtol. Rocking
#: through hundreds of impacts amplifies local errors by up to 1e4-1e6, and DOP853 on steps
#: cut at every sample was far more accurate than its rtol. Measured on 1000 record scenes
#: (bench_records' blocks) at rtol 1e-6 against rtol 1e-12: at 1, 12 of 200 Arcadia scenes
#: erred by more than 1e-6 and one overturning decision flipped; at 1e-4, p99 4.5e-7 (the
#: old kernel 1.1e-6), no decision wrong, for two or three more terms per step (~3 % time).
TAYLOR_TOL_FRACTION = 1e-4
#: Shortest step (in units of 1/p) retried when an impact falls outside its step.
MIN_STEP = 1e-9
#: A DOP853 step whose impact the interpolant placed outside it is retried this much shorter.
IMPACT_RETRY_SHRINK = 0.25
#: Step-size control of the DOP853 steps (Hairer, Norsett and Wanner's; also the complex
#: formulation's RK45 steps, with err^(-1/5)): the next step is h STEP_SAFETY err^(-1/8),
#: aimed below the tolerance so that it is rarely rejected ...
STEP_SAFETY = 0.9
#: ... and at least STEP_SHRINK_LIMIT h (in DOP853 also after a NaN error), at most
#: STEP_GROW_LIMIT h (also after a zero error), so that one odd error estimate cannot swing it
#: further.
STEP_SHRINK_LIMIT = 0.2
STEP_GROW_LIMIT = 5.0
#: The first step tried in a scene, in units of 1/p (the controller adapts it from there).
FIRST_STEP = 0.01
#: Cap on the halvings of the bisections on a mechanism's table, which stop at adjacent
#: doubles: 100 halve a bracket of rotations below 1e-30 rad.
TABLE_BISECTIONS = 100
#: Absolute error scales of theta and theta_dot, as fractions of alpha and p*alpha.
ATOL_FRACTION = 1e-3
#: Impact count of :func:`free_rocking_map` when eta = 1 (the block never comes to rest).
#: The solvers do not report it: they count the impacts up to :func:`free_tail_end` instead.
NEVER_AT_REST = 2**31 - 1
#: Length of the free rocking followed after the motion when eta = 1, in units of 1/p.
UNDAMPED_WINDOW = 100.0


@njit(cache=True)
def free_tail_end(p, eta, duration):
    """End of the free rocking that the solvers follow after a motion of ``duration`` [s]:
    until rest (inf), or for a block that never rests (eta >= 1) until duration + 100/p, so
    that impacts are counted within that window, the same way by every path."""
    return duration + UNDAMPED_WINDOW / p if eta >= 1.0 else np.inf


@njit(cache=True, inline="always")
def _hermite3(u, tab, col, dcol):
    """Cubic Hermite value and derivative of table column ``col`` (derivative ``dcol``) at u."""
    n = tab.shape[0]
    dphi = tab[1, TAB_PHI] - tab[0, TAB_PHI]
    i = min(max(int(u / dphi), 0), n - 2)
    x = (u - tab[i, TAB_PHI]) / dphi
    y0, y1 = tab[i, col], tab[i + 1, col]
    d0, d1 = tab[i, dcol] * dphi, tab[i + 1, dcol] * dphi
    x2 = x * x
    x3 = x2 * x
    val = (
        (2 * x3 - 3 * x2 + 1) * y0
        + (x3 - 2 * x2 + x) * d0
        + (-2 * x3 + 3 * x2) * y1
        + (x3 - x2) * d1
    )
    der = ((6 * x2 - 6 * x) * (y0 - y1) + (3 * x2 - 4 * x + 1) * d0 + (3 * x2 - 2 * x) * d1) / dphi
    return val, der


@njit(cache=True, **NO_REFCOUNT)
def _mechanism_accel(u, v, a_g, a_v, tab):
    """u'' of a mechanism from eq. (8) of [003]: I u'' + I'/2 u'^2 - G (g + a_v) = -B a_g.

    The vertical ground acceleration a_v [m/s^2, upwards] enters as gravity does: in the
    frame of the base every mass feels g + a_v downwards, so G g of eq. (8), the generalized
    force of the weights (-dV/dphi, V = g sum m_i y_i), becomes G (g + a_v).
    """
    inertia, d_inertia = _hermite3(u, tab, TAB_I, TAB_DI)
    g_nl = _hermite3(u, tab, TAB_G, TAB_DG)[0]
    b_nl = _hermite3(u, tab, TAB_B, TAB_DB)[0]
    return (g_nl * (G + a_v) - 0.5 * d_inertia * v * v - b_nl * a_g) / inertia


@njit(cache=True, **NO_REFCOUNT)
def _accel(a_g, a_v, th, om, p, alpha, s, model, tab):
    """theta_ddot on side s under the ground accelerations a_g (horizontal) and a_v
    (vertical, upwards) [m/s^2]: eq. (2.2) of [000] with gravity g + a_v,
    -p^2 [(1 + a_v/g) sin(alpha s - theta) + (a_g/g) cos(alpha s - theta)] (nonlinear),
    its linearization p^2 [(1 + a_v/g)(theta - alpha s) - a_g/g] (eq. 3.1 at a_v = 0), or a
    tabulated mechanism, eq. (8) of [003], in the amplitude u = s theta."""
    if model == MODEL_TABLE:
        return s * _mechanism_accel(s * th, s * om, s * a_g, a_v, tab[0] if s > 0.0 else tab[1])
    a = a_g / G
    gv = 1.0 + a_v / G
    if model == MODEL_LINEAR:
        return p * p * (gv * (th - alpha * s) - a)
    x = alpha * s - th
    return -p * p * (gv * math.sin(x) + a * math.cos(x))


@njit(cache=True, **NO_REFCOUNT)
def _rhs(t, th, om, args):
    """theta_ddot at time t on side s (see :func:`_accel`)."""
    p, alpha, s, model, kind, mp, times, samples, vsamples, k, tab = args
    a_g = ground_acceleration(kind, mp, times, samples, t, k)
    a_v = vertical_acceleration(kind, mp, times, vsamples, t, k)
    return _accel(a_g, a_v, th, om, p, alpha, s, model, tab)


@njit(cache=True, **NO_REFCOUNT)
def _lift(a_g, a_v, p, alpha, model, tab):
    """u_ddot of a block at rest on the side that a_g pushes it towards (s = -sign a_g).

    The block lifts off iff this is > 0, i.e. iff |a_g| exceeds (g + a_v) tan(alpha)
    (nonlinear), (g + a_v) alpha (linearized) or (g + a_v) lambda (a mechanism, eq. 10 of
    [003]). It is computed by the right-hand side itself, so that a block said to lift does
    rise: a threshold test in other arithmetic can disagree with it within a few ulps of the
    threshold, where the Zeno rule would then restart a block that falls straight back,
    without end.
    """
    s = -1.0 if a_g > 0.0 else 1.0
    return s * _accel(a_g, a_v, 0.0, 0.0, p, alpha, s, model, tab)


_step = make_dop853_step(_rhs, NO_REFCOUNT)


@njit(cache=True, inline="always")
def _ground_after(kind, mp, times, samples, t, k):
    """u_g'' just after t: zero from the end of the motion on. A step, or a decision to lift,
    taken at t = duration must see the still ground that follows (a cosine pulse jumps there
    from a_g to 0), not the motion's last value."""
    return 0.0 if t >= mp[3] else ground_acceleration(kind, mp, times, samples, t, k)


@njit(cache=True, inline="always")
def _vertical_after(kind, mp, times, vsamples, t, k):
    """u_v'' just after t, as :func:`_ground_after`: zero from the end of the motion on."""
    return 0.0 if t >= mp[3] else vertical_acceleration(kind, mp, times, vsamples, t, k)


@njit(cache=True)
def _next_break(kind, mp, times, t, k):
    """The first time after t at which the ground acceleration has an extremum or a zero
    (or the motion ends): between two such times it is monotone and of one sign.

    Analytic for the pulses: a sin(omega t + phase) at phases k pi / 2; the Ricker wavelet
    a (1 - 2 x^2) exp(-x^2), x = pi f (t - t0), at x = 0 (peak), +-1/sqrt(2) (zeros) and
    +-sqrt(3/2) (side lobes, where d/dx = 2 x (2 x^2 - 3) exp(-x^2) vanishes). A record is
    linear between its samples.
    """
    dur = mp[3]
    if kind == KIND_RECORD:
        return min(times[segment_index(times, t, k) + 1], dur)
    if kind == KIND_TRIG:
        q = 0.5 * math.pi
        j = math.floor((mp[1] * t + mp[2]) / q) + 1.0
        tb = (j * q - mp[2]) / mp[1]
        if tb <= t:
            tb = ((j + 1.0) * q - mp[2]) / mp[1]
        return min(tb, dur)
    for x in (-math.sqrt(1.5), -math.sqrt(0.5), 0.0, math.sqrt(0.5), math.sqrt(1.5)):
        tb = mp[2] + x / (math.pi * mp[1])
        if tb > t:
            return min(tb, dur)
    return dur


@njit(cache=True, inline="always")
def _record_acceleration(mp, times, samples, t, k):
    """u_g'' [m/s^2] of a record at t on segment k: the sample itself at a sample time (no
    interpolation arithmetic), zero after the end."""
    if t > mp[3]:
        return 0.0
    if t == times[k]:
        return mp[0] * samples[k]
    if t == times[k + 1]:
        return mp[0] * samples[k + 1]
    return ground_acceleration(KIND_RECORD, mp, times, samples, t, k)


#: Relative margin below the uplift level under which record samples are skipped without
#: the exact test (:func:`_lift`); far wider than the few ulps by which the two can differ.
QUIET_MARGIN = 1e-9


@njit(cache=True)
def _skip_quiet(mp, times, samples, alpha, model, lo, k):
    """Start of the first record segment at or after lo (on segment k) whose end sample
    reaches the uplift level |a_g| = g tan(alpha) (nonlinear) or g alpha (linearized), less
    :data:`QUIET_MARGIN`: on the segments before it the ground (linear between samples)
    stays below the level, and no block at rest lifts. One comparison per sample. Not for a
    record with a vertical component, which moves the level ((g + u_v'') tan alpha)."""
    level = G * (alpha if model == MODEL_LINEAR else math.tan(alpha)) * (1.0 - QUIET_MARGIN)
    if mp[0] == 0.0:
        return max(lo, times[times.shape[0] - 2])
    level = level / abs(mp[0])
    j = k + 1
    while j < times.shape[0] - 1 and abs(samples[j]) < level:
        j += 1
    return max(lo, times[j - 1])


@njit(cache=True, **NO_REFCOUNT)
def _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, t, k):
    """:func:`_lift` under the ground accelerations at time t (record segment k)."""
    a_g = ground_acceleration(kind, mp, times, samples, t, k)
    a_v = vertical_acceleration(kind, mp, times, vsamples, t, k)
    return _lift(a_g, a_v, p, alpha, model, tab)


#: Half-width of the first bracket around the closed-form uplift time of a trigonometric
#: pulse, relative to |t| + 1/omega: a few ulps of the phase, so that the bisection to the
#: ulp takes ~8 halvings instead of ~50; widened 64-fold while it does not bracket.
TRIG_BRACKET = 1e-14
TRIG, FIRST = np.int64(KIND_TRIG), np.int64(0)  # the motion kind and segment index, not literals


@njit(cache=True)
def _trig_uplift_bracket(mp, times, samples, vsamples, p, alpha, model, lo, hi):
    """A sub-bracket of [lo, hi] (a monotone piece of a sine pulse where the block at rest
    does not lift at lo and lifts at hi) around the closed-form time at which |a_g| reaches
    g tan(alpha) (g alpha linearized), a sin(omega t + phase) = level at the phase
    m pi +- asin(level / |a|) (section 2 of [000]). The exact test (:func:`_lift`) still
    decides: the bracket is returned only where it holds at both ends."""
    level = G * (alpha if model == MODEL_LINEAR else math.tan(alpha))
    w, ph = mp[1], mp[2]
    x = math.asin(min(level / abs(mp[0]), 1.0))
    m = math.floor((w * lo + ph) / math.pi)
    tc = np.inf
    for j in range(4):  # crossings at phases m pi + x, m pi + pi - x, (m + 1) pi + x, ...
        psi = (m + j // 2) * math.pi + (x if j % 2 == 0 else math.pi - x)
        t = (psi - ph) / w
        if lo <= t <= hi:
            tc = t
            break
    if tc == np.inf:
        return lo, hi
    d = TRIG_BRACKET * (abs(tc) + 1.0 / w)
    while d < hi - lo:
        a, b = max(lo, tc - d), min(hi, tc + d)
        lift_a = (
            a > lo
            and _lift_at(TRIG, mp, times, samples, vsamples, p, alpha, model, NO_TABLE, a, FIRST)
            > 0.0
        )
        lift_b = (
            b == hi
            or _lift_at(TRIG, mp, times, samples, vsamples, p, alpha, model, NO_TABLE, b, FIRST)
            > 0.0
        )
        if not lift_a and lift_b:
            return a, b
        d *= 64.0
    return lo, hi


@njit(cache=True, **NO_REFCOUNT)
def next_uplift(kind, mp, times, samples, vsamples, p, alpha, model, tab, t0):
    """First time >= t0 at which a block at rest lifts off (:func:`_lift` > 0), or inf.

    The motion is cut at its extrema and zeros (:func:`_next_break`); on each piece of a pulse
    the lift is monotone, so it is checked at the piece's end and located by bisection to
    the ulp. On a record segment both components are linear in t, so the lift is affine in
    t on each side of the zero of u_g'' (c |u_g''| - d (g + u_v''), c, d > 0: convex on the
    segment), and negative at that zero: where it is not > 0 at both samples it is not > 0
    between them, and where it turns positive it does so once. No short excursion above the
    threshold between scan points can be missed.
    """
    dur = mp[3]
    if t0 > dur:
        return np.inf
    rec = kind == KIND_RECORD
    k = segment_index(times, t0, FIRST) if rec else 0
    lo = t0
    if _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, lo, k) > 0.0:
        return lo
    while lo < dur:
        if kind == KIND_RECORD and model != MODEL_TABLE and vsamples.size == 0:
            lo = _skip_quiet(mp, times, samples, alpha, model, lo, segment_index(times, lo, k))
            if lo >= dur:
                break
        hi = _next_break(kind, mp, times, lo, k)
        if rec:
            k = segment_index(times, lo, k)
        k_hi = segment_index(times, hi, k) if rec else 0
        if _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, hi, k_hi) > 0.0:
            if kind == KIND_TRIG and model != MODEL_TABLE and vsamples.size == 0:
                lo, hi = _trig_uplift_bracket(mp, times, samples, vsamples, p, alpha, model, lo, hi)
            for _ in range(ULP_BISECTIONS):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, mid, k) > 0:
                    hi = mid
                else:
                    lo = mid
            return hi
        lo = hi
    return np.inf


@njit(cache=True, inline="always")
def _hermite_fdf(x, args):
    """The Hermite value (or derivative) minus target at unit step time x, and its x-derivative."""
    target, deriv, h, y0, d0, a0, y1, d1, a1 = args
    v, dv, av = hermite5(x, h, y0, d0, a0, y1, d1, a1)
    return (dv - target, av * h) if deriv else (v - target, dv * h)


# Event times on the interpolant, in units of the step: to 1e-14 of it, near rounding of a
# unit interval (the event is then refined on a true step where it matters).
HERMITE_ROOT_TOL = 1e-14
# Bisection alone reaches 1e-14 of the step in 47 halvings; Newton needs about 5.
HERMITE_ROOT_MAX_ITER = 100


@njit(cache=True)
def _root_hermite(target, sgn, deriv, h, y0, d0, a0, y1, d1, a1, lo, hi):
    """Root in [lo, hi] (unit step time) of the Hermite value (deriv=False) or derivative.

    Finds where sgn * (q(s) - target) changes from >= 0 at lo to < 0 at hi, by Newton steps
    safeguarded by bisection of the bracket (:func:`newton_bisect`), to 1e-14 of the step.
    """
    args = (target, deriv, h, y0, d0, a0, y1, d1, a1)
    return newton_bisect(
        _hermite_fdf, args, lo, hi, 0.5 * (lo + hi), sgn, HERMITE_ROOT_TOL, HERMITE_ROOT_MAX_ITER
    )


#: The running tallies of one scene, one record updated in place by the kernel and the exact
#: linear solvers: max |theta| [rad], the first impact time [s] (NaN before it), impacts,
#: integrator steps (0 in the exact solvers), and the rows the logs needed (history rows,
#: impact times, peaks: more than an array holds means it overflowed), with the requested
#: times of the dense output passed so far (the index of the next one to serve).
TALLIES = np.dtype(
    [
        ("max_rotation", np.float64),
        ("first_impact_time", np.float64),
        ("n_impacts", np.int64),
        ("steps", np.int64),
        ("n_history", np.int64),
        ("n_impact_times", np.int64),
        ("n_peaks", np.int64),
        ("n_dense", np.int64),
    ],
    align=True,
)


@njit(cache=True)
def new_tallies(max_rotation):
    """An array of one :data:`TALLIES` record: no impact yet (first_impact_time NaN), all
    counts 0, max |theta| from ``max_rotation`` [rad] (the start's).

    The kernels pass its element ``tallies[0]`` down (a numba Record, by reference) and
    update it in place. The element does not keep the array alive, and numba frees an array
    after its last use: the function that allocates it reads the results from ``tallies``
    after every other use (a record kept from ``np.zeros(1, TALLIES)[0]`` alone is
    overwritten by the next allocation).
    """
    tallies = np.zeros(1, TALLIES)
    ta = tallies[0]
    ta.max_rotation = max_rotation
    ta.first_impact_time = np.nan
    return tallies


@njit(cache=True, inline="always")
def tally_impact(ta, t):
    """Count an impact at t [s] in the tallies ``ta``, the first one's time kept."""
    if ta.n_impacts == 0:
        ta.first_impact_time = t
    ta.n_impacts += 1


PhaseState = namedtuple("PhaseState", ("t", "theta", "theta_dot", "side", "h"))
PhaseState.__doc__ = """The state of a rocking phase (:func:`_phase`): the time t [s], theta
[rad], theta_dot [rad/s], the side s (+1.0 or -1.0) it rocks on and the next step size h [s]."""

Stepping = namedtuple(
    "Stepping", ("p", "alpha", "eta", "model", "omega_rest", "tol", "max_steps", "fall", "table")
)
Stepping.__doc__ = """What a rocking phase (:func:`_phase`) steps: the body (p [rad/s], alpha
[rad], eta, model, ``fall`` [rad] and ``table`` of a :class:`Body`), the speed ``omega_rest``
[rad/s] below which an impact leaves it at rest, the local error target ``tol`` (TOL_SAFETY
rtol) and the most steps ``max_steps`` of one phase."""


@njit(cache=True)
def _push(hist, ta, t, th, om):
    """Append a history row if there is room; always count it, so overflow is detectable."""
    n = ta.n_history
    if n < hist.shape[0]:
        hist[n, 0] = t
        hist[n, 1] = th
        hist[n, 2] = om
    ta.n_history = n + 1


@njit(cache=True)
def _record_inside(hist, ta, args, t, h, th, om, f0, kx, kv):
    """Append states at 1/4, 1/2 and 3/4 of [t, t + h] within an accepted step, each by a
    DOP853 step from its start (as accurate as the step itself)."""
    for j in range(1, 4):
        x, v = _step(args, t, th, om, f0, 0.25 * j * h, kx, kv)
        _push(hist, ta, t + 0.25 * j * h, x, v)


@njit(cache=True)
def _log_peak(peaks, ta, t, th):
    """Append the peak (t, theta) to ``peaks`` if there is room; always count it, so that
    overflow is detectable."""
    n = ta.n_peaks
    if n < peaks.shape[0]:
        peaks[n, 0] = t
        peaks[n, 1] = th
    ta.n_peaks = n + 1


@njit(cache=True)
def _newton_peak(t, th, om, acc, t_lo, t_hi):
    r"""The peak near (t, theta, theta_dot, theta_ddot) by one Newton step on theta_dot = 0:
    :math:`t_p = t - \dot\theta / \ddot\theta` (kept in [t_lo, t_hi], its step) and
    :math:`\theta_p = \theta - \dot\theta^2 / (2 \ddot\theta)`. Returns (t_p, theta_p)."""
    if acc == 0.0:
        return t, th
    return min(max(t - om / acc, t_lo), t_hi), th - 0.5 * om * om / acc


@njit(cache=True)
def _dense(dense, ta, args, t, t_end, th, om, f0, kx, kv):
    """Dense output on an accepted step from (t, theta, theta_dot) to t_end: the state at
    each requested time dense[j, 0] in [t, t_end] not yet served, by one DOP853 step from t
    (as accurate as the step), into dense[j, 1:3]. Requested times before t fall in a rest
    and keep the (0, 0) they hold; a time on an impact gets the state just before it."""
    j = ta.n_dense
    while j < dense.shape[0] and dense[j, 0] <= t_end:
        if dense[j, 0] >= t:
            dense[j, 1], dense[j, 2] = _step(args, t, th, om, f0, dense[j, 0] - t, kx, kv)
        j += 1
    ta.n_dense = j


@njit(cache=True, **NO_REFCOUNT)
def _dense_poly(dense, ta, w, n, t, hs, t_end):
    """:func:`_dense` on an accepted Taylor step of length hs from t, by its polynomial w[0]
    of order n (the solution within the step's tolerance), up to t_end."""
    j = ta.n_dense
    while j < dense.shape[0] and dense[j, 0] <= t_end:
        if dense[j, 0] >= t:
            x, d, _ = poly_value(w[0], n, (dense[j, 0] - t) / hs)
            dense[j, 1], dense[j, 2] = x, d / hs
        j += 1
    ta.n_dense = j


@njit(cache=True)
def _true_state(args, t, th, om, f0, dt, kx, kv):
    """State and theta_ddot at t + dt by one DOP853 step from t (dt within an accepted step)."""
    th_s, om_s = _step(args, t, th, om, f0, dt, kx, kv)
    return th_s, om_s, _rhs(t + dt, th_s, om_s, args)


@njit(cache=True, **NO_REFCOUNT)
def _step_events(s, h, th, om, f0, th1, om1, f1):
    """Impact and peak of u = s theta inside an accepted step, in unit step time.

    Returns (s_imp, s_pk): the first root of theta (2.0 if none) and the peak of u before it
    (-1.0 if none), located on the quintic Hermite interpolant.
    """
    u1 = s * th1
    v0 = s * om
    s_imp = 2.0
    if u1 < 0.0:
        s_imp = _root_hermite(0.0, s, False, h, th, om, f0, th1, om1, f1, 0.0, 1.0)
    elif v0 < 0.0 and s * om1 > 0.0:
        s_tr = _root_hermite(0.0, -s, True, h, th, om, f0, th1, om1, f1, 0.0, 1.0)
        if s * hermite5(s_tr, h, th, om, f0, th1, om1, f1)[0] < 0.0:
            s_imp = _root_hermite(0.0, s, False, h, th, om, f0, th1, om1, f1, 0.0, s_tr)
    else:
        # a short hop (up, down through zero, up again) can hide inside one long step
        for j in range(1, 4):
            if s * hermite5(0.25 * j, h, th, om, f0, th1, om1, f1)[0] < 0.0:
                lo = 0.25 * (j - 1)
                s_imp = _root_hermite(0.0, s, False, h, th, om, f0, th1, om1, f1, lo, 0.25 * j)
                break
    s_end = min(s_imp, 1.0)
    s_pk = -1.0
    if v0 >= 0.0 and s * hermite5(s_end, h, th, om, f0, th1, om1, f1)[1] <= 0.0:
        s_pk = _root_hermite(0.0, s, True, h, th, om, f0, th1, om1, f1, 0.0, s_end)
    return s_imp, s_pk


#: Outcomes of one attempted step (:func:`_dop853_attempt`, :func:`_taylor_attempt`).
EV_REJECT = 0  # rejected: retry from the same state with the new step size
EV_NONE = 1  # accepted, no impact and no overturning inside
EV_IMPACT = 2  # accepted up to an impact, at (t_ev, om_ev) with om_ev the speed before it
EV_OVER = 3  # accepted up to overturning, at (t_ev, om_ev)


@njit(cache=True, **NO_REFCOUNT)
def _dop853_attempt(args, t, th, om, f0, h, t_next, s, tol, fall, kx, kv):
    """One DOP853 step from (t, th, om) towards t_next, with its events.

    Returns (outcome, new step size, hs, t1, th1, om1, f1, t_ev, om_ev, u_pk, t_pk, extra
    work, order): the step end (t1, th1, om1, f1 = theta_ddot there), the impact or
    overturning (t_ev, om_ev) per the outcome, the peak u_pk of s theta inside (-1 if none)
    at t_pk, the true RK
    steps taken to refine the events, and the order of a Taylor step (0 here).
    """
    p, alpha = args[0], args[1]
    last = h >= t_next - t
    hs = t_next - t if last else h
    th1, om1 = _step(args, t, th, om, f0, hs, kx, kv)
    t1 = t_next if last else t + hs
    f1 = _rhs(t1, th1, om1, args)
    kx[12] = om1
    kv[12] = f1
    sc_x = tol * (ATOL_FRACTION * alpha + max(abs(th), abs(th1)))
    sc_v = tol * (ATOL_FRACTION * p * alpha + max(abs(om), abs(om1)))
    err = dop853_error(kx, kv, hs, sc_x, sc_v)
    if not err <= 1.0:  # rejected (or NaN)
        shrink = max(STEP_SHRINK_LIMIT, STEP_SAFETY * err ** (-0.125))
        h = hs * shrink if err == err else STEP_SHRINK_LIMIT * hs
        return EV_REJECT, h, hs, t, th, om, f0, t, om, -1.0, np.nan, 0, 0
    grow = STEP_GROW_LIMIT if err == 0.0 else STEP_SAFETY * err ** (-0.125)
    fac = min(STEP_GROW_LIMIT, grow)
    h = max(h, hs * fac) if last else hs * fac
    work = 0
    u_pk, t_pk = -1.0, np.nan
    s_imp, s_pk = _step_events(s, hs, th, om, f0, th1, om1, f1)
    if s_pk >= 0.0:  # peak: on a true RK step, then one Newton step (:func:`_newton_peak`)
        work += 1
        x, v, a = _true_state(args, t, th, om, f0, s_pk * hs, kx, kv)
        t_pk, th_pk = _newton_peak(t + s_pk * hs, x, v, a, t, t1)
        u_pk = s * th_pk
    if s_imp > 1.0 and s * th1 >= fall:
        s_ot = _root_hermite(s * fall, -s, False, hs, th, om, f0, th1, om1, f1, 0.0, 1.0)
        om_ot = hermite5(s_ot, hs, th, om, f0, th1, om1, f1)[1]
        return EV_OVER, h, hs, t1, th1, om1, f1, t + s_ot * hs, om_ot, u_pk, t_pk, work, 0
    if s_imp > 1.0:
        return EV_NONE, h, hs, t1, th1, om1, f1, t1, om1, u_pk, t_pk, work, 0
    # impact: located on the interpolant, then one Newton step on a true RK step
    work += 1
    x, v, a = _true_state(args, t, th, om, f0, s_imp * hs, kx, kv)
    dl = -x / v if v != 0.0 else 0.0
    if not 0.0 <= s_imp * hs + dl <= hs:  # the interpolant misplaced it
        if hs * p > MIN_STEP:  # retry with a shorter step
            h = IMPACT_RETRY_SHRINK * hs
            return EV_REJECT, h, hs, t, th, om, f0, t, om, u_pk, t_pk, work, 0
        dl = min(max(s_imp * hs + dl, 0.0), hs) - s_imp * hs
    return EV_IMPACT, h, hs, t1, th1, om1, f1, t + s_imp * hs + dl, v + a * dl, u_pk, t_pk, work, 0


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _taylor_attempt(w, stepping, mot, t, th, om, f0, h, t_next, s, k):
    """One Taylor step (:mod:`._taylor`) on record segment k, from (t, th, om) towards t_next
    (f0: theta_ddot at t, used for a start at rest on contact: :func:`_lift_curvature`).
    Inlined into the phase loop: the call, with its ~50 flattened arguments, cost 6-18 % of a
    record scene (measured); the pulse variant of the loop prunes it, so it costs that
    variant no compile time.

    Both ground components are linear on the step. Returns
    the tuple of :func:`_dop853_attempt`, with the events located on the step polynomial
    (the order of that polynomial last; its coefficients stay in w[0]).
    """
    p, alpha, model, fall = stepping.p, stepping.alpha, stepping.model, stepping.fall
    tol = TAYLOR_TOL_FRACTION * stepping.tol
    kind, mp, times, samples, vsamples = mot
    last = h >= t_next - t
    hs = t_next - t if last else h
    t1 = t_next if last else t + hs
    a0 = _record_acceleration(mp, times, samples, t, k)
    a1 = _record_acceleration(mp, times, samples, t1, k)
    v0 = v1 = 0.0
    if vsamples.shape[0] > 0:
        v0 = vertical_acceleration(kind, mp, times, vsamples, t, k)
        v1 = vertical_acceleration(kind, mp, times, vsamples, t1, k)
    sc_x = tol * (ATOL_FRACTION * alpha + abs(th) + abs(om) * hs)
    sc_v = tol * (ATOL_FRACTION * p * alpha + abs(om) + abs(th) * p * p * hs)
    dd0 = _lift_curvature(th, om, f0)
    n, err = taylor_coefficients(w, th, om, s, p, alpha, model, hs, a0, a1, v0, v1, sc_x, sc_v, dd0)
    if not err <= 1.0:  # rejected (or NaN)
        return EV_REJECT, 0.5 * hs, hs, t, th, om, np.nan, t, om, -1.0, np.nan, 0, 0
    h = max(h, 2.0 * hs) if last else 2.0 * hs
    return _taylor_events(w[0], n, s, t, hs, t1, h, fall)


@njit(cache=True, inline="always")
def _lift_curvature(th, om, f0):
    """theta_ddot at the start of a Taylor step that leaves contact from rest (theta = theta_dot
    = 0): f0, computed by :func:`_accel` with the arithmetic of the lift test (:func:`_lift`),
    so that the step rises as that test said (``_taylor._start_curvature``); NaN otherwise."""
    return f0 if th == 0.0 and om == 0.0 else np.nan


#: Longest Taylor step under a trigonometric pulse or no ground motion, in units of 1/p and
#: of 1/omega: the events of a step are located for one turning point of u = s theta at most
#: (:func:`._taylor.step_impact`), as on a DOP853 step of the same length.
TRIG_STEP_CAP = 0.5
#: Local error target of a Taylor step under a pulse or no ground motion, as a fraction of
#: TOL_SAFETY * rtol (a record's steps: TAYLOR_TOL_FRACTION).
TRIG_TOL_FRACTION = 1e-2
#: Order of the series at which a Taylor step stops growing: a longer step needs a higher
#: order (the O(N^2) recurrences), a shorter one more steps.
TARGET_ORDER = 14


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _taylor_trig_attempt(w, stepping, mot, t, th, om, f0, h, t_next, s):
    """One Taylor step under a trigonometric pulse (``KIND_TRIG``, before its end) or with no
    ground motion (after any motion has ended), from (t, th, om) towards t_next.

    The ground series is exact (:func:`._taylor.taylor_coefficients_trig`); the step is at most
    :data:`TRIG_STEP_CAP` in p t and in omega t, and grows (x2) while the series needs fewer
    than :data:`TARGET_ORDER` terms. Returns the tuple of :func:`_taylor_attempt`.
    """
    p, alpha, model, fall = stepping.p, stepping.alpha, stepping.model, stepping.fall
    tol = TRIG_TOL_FRACTION * stepping.tol
    mp = mot[1]
    forced = t < mp[3]
    h = min(h, TRIG_STEP_CAP / p, TRIG_STEP_CAP / mp[1] if forced else np.inf)
    last = h >= t_next - t
    hs = t_next - t if last else h
    t1 = t_next if last else t + hs
    amp = mp[0] if forced else 0.0
    sc_x = tol * (ATOL_FRACTION * alpha + abs(th) + abs(om) * hs)
    sc_v = tol * (ATOL_FRACTION * p * alpha + abs(om) + abs(th) * p * p * hs)
    phase, wh, dd0 = mp[1] * t + mp[2], mp[1] * hs, _lift_curvature(th, om, f0)
    n, err = taylor_coefficients_trig(
        w, th, om, s, p, alpha, model, hs, amp, phase, wh, sc_x, sc_v, dd0
    )
    if not err <= 1.0:  # rejected (or NaN)
        return EV_REJECT, 0.5 * hs, hs, t, th, om, np.nan, t, om, -1.0, np.nan, 0, 0
    grown = 2.0 * hs if n < TARGET_ORDER else hs
    h = max(h, grown) if last else grown
    return _taylor_events(w[0], n, s, t, hs, t1, h, fall)


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _taylor_events(c, n, s, t, hs, t1, h, fall):
    """The outcome of an accepted Taylor step from t of length hs (ending at t1, the next step
    h): its impact, peak and overturning, located on the step polynomial c of order n. Returns
    the tuple of :func:`_dop853_attempt`."""
    th1, dth1, ddth1 = poly_end(c, n)
    om1 = dth1 / hs
    f1 = ddth1 / (hs * hs)
    s_imp = step_impact(c, n, s, s * th1, s * dth1)
    if s_imp > 1.0:
        s_pk = step_peak(c, n, s, 1.0, s * dth1)
        u_pk = -1.0
        if s_pk >= 0.0:
            u_pk = s * poly_value(c, n, s_pk)[0]
        t_pk = t + s_pk * hs
        if s * th1 >= fall:
            s_ot = poly_root(c, n, s * fall, -s, OF_VALUE, 0.0, 1.0)
            om_ot = poly_value(c, n, s_ot)[1] / hs
            return EV_OVER, h, hs, t1, th1, om1, f1, t + s_ot * hs, om_ot, u_pk, t_pk, 0, n
        return EV_NONE, h, hs, t1, th1, om1, f1, t1, om1, u_pk, t_pk, 0, n
    th_imp, dth_imp, _ = poly_value(c, n, s_imp)
    s_pk = step_peak(c, n, s, s_imp, s * dth_imp)
    u_pk = s * poly_value(c, n, s_pk)[0] if s_pk >= 0.0 else -1.0
    t_pk = t + s_pk * hs
    return EV_IMPACT, h, hs, t1, th1, om1, f1, t + s_imp * hs, dth_imp / hs, u_pk, t_pk, 0, n


@njit(cache=True)
def _record_poly(hist, ta, c, n, t, hs, t_end):
    """Append states at 1/4, 1/2 and 3/4 of [t, t_end] within an accepted Taylor step of
    length hs, from its polynomial c of order n (the solution within the step's tolerance)."""
    for j in range(1, 4):
        tj = t + 0.25 * j * (t_end - t)
        x, d, _ = poly_value(c, n, (tj - t) / hs)
        _push(hist, ta, tj, x, d / hs)


@njit(cache=True)
def _work_arrays():
    """Work arrays of one scene, allocated once and passed down to every phase: the DOP853
    stage derivatives of theta and theta_dot (13 each), and the Taylor series
    of :mod:`._taylor` (:func:`._taylor.work_arrays`)."""
    return np.empty(13), np.empty(13), work_arrays()


def _variant_named(general, serial=False):
    """Decorator (under ``@njit``) that names a factory's trig-only variant apart:
    ``<name>_trig``, and a serial one ``<name>_serial``. numba names a compiled function, and
    so its cache entry, by its qualified name and a counter of the process that compiled it;
    two variants of one name that were each the first function compiled in their process (a
    CLI run, a test's child process) got one name, and a process that loaded both from the
    cache ran the second with the first's environment (scene_batch after scene_batch_trig:
    RuntimeError "'descr' is NULL")."""

    def name(fn):
        suffix = ("" if general else "_trig") + ("_serial" if serial else "")
        fn.__name__ += suffix
        fn.__qualname__ += suffix
        return fn

    return name


@njit(cache=True, inline="always")
def _impact(t, th, om, t_ev, om_ev, eta, ta, imps, hist):
    """The impact at t_ev [s] of a phase at (t, th, om), with speed om_ev just before it:
    the speed after it, eta om_ev (eq. 2.3 of [000]), tallied and logged (``imps``, ``hist``:
    arrays of length 0 for none). Returns (time, speed after).

    A lift from rest that falls back within the resolution of t (the ground above the uplift
    level for less than an ulp of t) has its impact one ulp on, where the ground has eased, so
    that the Zeno rule rests the block instead of restarting it at the same t without end.
    """
    if t_ev <= t and th == 0.0 and om == 0.0:
        t_ev = np.nextafter(t, np.inf)
    om_post = eta * om_ev
    tally_impact(ta, t_ev)
    if hist.shape[0] > 0:
        n = ta.n_impact_times
        if n < imps.shape[0]:
            imps[n] = t_ev
        ta.n_impact_times = n + 1
        _push(hist, ta, t_ev, 0.0, om_ev)
        _push(hist, ta, t_ev, 0.0, om_post)
    return t_ev, om_post


@njit(cache=True, inline="always")
def _zeno(om, s, omega_rest, a_g, a_v, p, alpha, model, tab):
    """The side after an impact that left the speed om [rad/s] with the ground (a_g, a_v):
    the other side, or, below ``omega_rest``, the Zeno rule: at rest unless the ground lifts
    the block (:func:`_lift`), which then restarts from rest on the side it is pushed to.
    Returns (at rest, side, speed)."""
    if not abs(om) < omega_rest:  # (a NaN speed too: carried on, not rested)
        return False, -s, om
    if not _lift(a_g, a_v, p, alpha, model, tab) > 0.0:
        return True, s, 0.0
    return False, (-1.0 if a_g > 0.0 else 1.0), 0.0


def _make_phase(general):
    """The phase kernel (:func:`_phase`): for every motion and model (``general``), or only for
    the block models under a trigonometric pulse without a vertical component, which step by
    Taylor series throughout (:func:`_phase_trig`). The branches of the other steps are
    constants of the closure, pruned before numba types them: that variant compiles in about
    half the time (a study of sine pulses from an empty cache)."""
    trig_only = not general

    @njit(cache=True, **NO_REFCOUNT)
    @_variant_named(general)
    def phase(stepping, mot, log, state, ta, wk, t_stop, stop_at_impacts):
        """Integrate rocking from ``state`` (a :class:`PhaseState`) until rest, overturning or
        t_stop.

        stepping: a :class:`Stepping`; mot = (kind, mp, times, samples, vsamples), log = (hist,
        imps, peaks, dense) (see :func:`scene`).
        wk = (kx, kv, w): the scene's work arrays (:func:`_work_arrays`).
        The tallies ``ta`` (a :data:`TALLIES` record) are updated in place. Returns (code,
        the :class:`PhaseState` at the end): PH_END, PH_REST, PH_OVER or PH_FAIL; or PH_IMPACT
        once the impact count reaches ``stop_at_impacts`` (the state is then just after that
        impact; :data:`NO_STOP` for never). The block models step by Taylor series inside a record
        (:func:`_taylor_attempt`), under a trigonometric pulse and in the free rocking after any
        motion (:func:`_taylor_trig_attempt`); a Ricker wavelet and a mechanism's table by DOP853.
        """
        p, alpha, eta, model = stepping.p, stepping.alpha, stepping.eta, stepping.model
        tab, fall = stepping.table, stepping.fall
        kind, mp, times, samples, vsamples = mot
        hist, imps, peaks, dense = log
        rec = hist.shape[0] > 0
        t, th, om, s, h = state
        dur = mp[3]
        kx, kv, w = wk
        k = segment_index(times, t, FIRST) if kind == KIND_RECORD else 0
        f0 = _accel(
            _ground_after(kind, mp, times, samples, t, k),
            _vertical_after(kind, mp, times, vsamples, t, k),
            th,
            om,
            p,
            alpha,
            s,
            model,
            tab,
        )
        steps = 0
        code = PH_END
        while t < t_stop:
            steps += 1
            ta.steps += 1
            if steps > stepping.max_steps:
                code = PH_FAIL
                break
            t_next = t_stop
            in_record = kind == KIND_RECORD and t < dur
            if in_record:  # end steps on record samples (kinks in u_g'')
                k = segment_index(times, t, k)
                t_next = min(t_next, times[k + 1])
            # Taylor series for the block models (a tabulated mechanism steps by DOP853): on record
            # samples, under a trigonometric pulse, and with no ground motion after any motion
            taylor = model != MODEL_TABLE and (in_record or t >= dur or kind == KIND_TRIG)
            if general and in_record and taylor:
                out = _taylor_attempt(w, stepping, mot, t, th, om, f0, h, t_next, s, k)
            elif trig_only or taylor:
                out = _taylor_trig_attempt(w, stepping, mot, t, th, om, f0, h, t_next, s)
            else:
                args = (p, alpha, s, model, kind, mp, times, samples, vsamples, k, tab)
                out = _dop853_attempt(args, t, th, om, f0, h, t_next, s, stepping.tol, fall, kx, kv)
            ev, h, hs, t1, th1, om1, f1, t_ev, om_ev, u_pk, t_pk, work, order = out
            ta.steps += work
            if ev == EV_REJECT:
                continue
            if u_pk >= 0.0:  # the peak site: a peak of u = s theta inside the step
                ta.max_rotation = max(ta.max_rotation, u_pk)
                _log_peak(peaks, ta, t_pk, s * u_pk)
            t_end = t1 if ev == EV_NONE else t_ev  # the step's end, or its event
            if trig_only or taylor:
                if dense.shape[0] > 0:
                    _dense_poly(dense, ta, w, order, t, hs, t_end)
                if rec:
                    _record_poly(hist, ta, w[0], order, t, hs, t_end)
            else:
                args = (p, alpha, s, model, kind, mp, times, samples, vsamples, k, tab)
                _dense(dense, ta, args, t, t_end, th, om, f0, kx, kv)
                if rec:
                    _record_inside(hist, ta, args, t, t_end - t, th, om, f0, kx, kv)
            if ev == EV_OVER:
                t, th, om = t_ev, s * fall, om_ev
                ta.max_rotation = fall
                if rec:
                    _push(hist, ta, t, th, om)
                code = PH_OVER
                break
            if ev == EV_NONE:
                ta.max_rotation = max(ta.max_rotation, s * th1)
                if rec:
                    _push(hist, ta, t1, th1, om1)
                t, th, om, f0 = t1, th1, om1, f1
                continue

            # impact at t_ev, with speed om_ev just before it
            t, om = _impact(t, th, om, t_ev, om_ev, eta, ta, imps, hist)
            th = 0.0
            if kind == KIND_RECORD:
                k = segment_index(times, min(t, dur), k)
            a_g = _ground_after(kind, mp, times, samples, t, k)
            a_v = _vertical_after(kind, mp, times, vsamples, t, k)
            resting, s, om = _zeno(om, s, stepping.omega_rest, a_g, a_v, p, alpha, model, tab)
            if resting:
                code = PH_REST
                break
            if ta.n_impacts == stop_at_impacts:
                code = PH_IMPACT
                break
            f0 = _accel(a_g, a_v, th, om, p, alpha, s, model, tab)
        return code, PhaseState(t, th, om, s, h)

    return phase


_phase = _make_phase(True)
_phase_trig = _make_phase(False)


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


@njit(cache=True)
def _potential_level(level, lo, hi, tab):
    """u in [lo, hi] where V(u) = level, V increasing there (bisection on the table)."""
    for _ in range(TABLE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _hermite3(mid, tab, TAB_V, TAB_DV)[0] < level:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def _critical(tab):
    """phi_cr of a table: where G changes sign (bisection on the Hermite interpolant)."""
    g = tab[:, TAB_G]
    i = 0
    while i < g.shape[0] - 1 and g[i + 1] < 0.0:
        i += 1
    lo, hi = tab[i, TAB_PHI], tab[min(i + 1, g.shape[0] - 1), TAB_PHI]
    for _ in range(TABLE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _hermite3(mid, tab, TAB_G, TAB_DG)[0] < 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def _free_map_table(u, v, eta, tab, other, omega_rest):
    """:func:`free_rocking_map` for a tabulated mechanism: E = I(u) v^2 / 2 + g V(u) on this
    side's table, the other side's after an impact; the speed at the pivot is multiplied by
    eta at each impact. Returns (overturns, peak, impacts)."""
    fall = tab[-1, TAB_PHI]
    phi_cr = _critical(tab)
    barrier = _hermite3(phi_cr, tab, TAB_V, TAB_DV)[0]
    e = 0.5 * _hermite3(u, tab, TAB_I, TAB_DI)[0] * v * v / G + _hermite3(u, tab, TAB_V, TAB_DV)[0]
    peak = u
    if e >= barrier:
        if (u < phi_cr and v > 0.0) or (u >= phi_cr and v >= 0.0):
            return True, fall, 0
    elif u > phi_cr:
        return True, fall, 0
    elif v > 0.0:
        peak = _potential_level(e, u, phi_cr, tab)
    w = math.sqrt(max(2.0 * G * (e - tab[0, TAB_V]) / tab[0, TAB_I], 0.0))  # impact speed
    w1 = eta * w
    e1 = 0.5 * other[0, TAB_I] * w1 * w1 / G + other[0, TAB_V]
    phi_cr1 = _critical(other)
    if e1 >= _hermite3(phi_cr1, other, TAB_V, TAB_DV)[0]:
        return True, fall, 1
    peak = max(peak, _potential_level(e1, 0.0, phi_cr1, other))
    return False, peak, _impacts_until_rest(w1, omega_rest, eta)


Body = namedtuple("Body", ("p", "alpha", "eta", "model", "fall", "table"))
Body.__doc__ = """What rocks in a :func:`scene`: p [rad/s], alpha [rad] (for MODEL_TABLE phi_cr,
and p the mechanism's p_eq, which then only scales the error tolerances), the restitution
eta [-], the model (MODEL_NONLINEAR, MODEL_LINEAR or MODEL_TABLE), the rotation ``fall``
[rad] at which it is taken to have collapsed (FALL_ROTATION for a block), and the mechanism's
``table`` (:data:`NO_TABLE` for a block)."""

Controls = namedtuple("Controls", ("rtol", "max_steps", "free_map", "tail_end"))
Controls.__doc__ = """How a :func:`scene` is computed: the relative tolerance ``rtol``, the
most steps of one phase ``max_steps`` (exceeded: STATUS_MAX_STEPS), whether the free rocking
after the motion is mapped (``free_map``: :func:`free_rocking_map`, no history) rather than
integrated, and ``tail_end`` [s], where an integrated free rocking stops
(:func:`free_tail_end`)."""

Start = namedtuple("Start", ("theta", "theta_dot"))
Start.__doc__ = """The state at the start of the motion of a :func:`scene`: theta [rad] and
theta_dot [rad/s]; (0, 0) is rest (the block then waits for uplift)."""

SceneOutcome = namedtuple(
    "SceneOutcome",
    (
        "status",
        "max_rotation",
        "overturned",
        "n_impacts",
        "overturn_time",
        "n_history",
        "n_impact_times",
        "steps",
        "first_impact_time",
        "n_peaks",
    ),
)
SceneOutcome.__doc__ = """What a :func:`scene` returns: ``status`` (STATUS_OK or
STATUS_MAX_STEPS), ``max_rotation`` max |theta| [rad], ``overturned``, ``n_impacts``,
``overturn_time`` [s] (NaN if it stands), the rows the log needed (``n_history`` history
rows, ``n_impact_times`` impact times, ``n_peaks`` peaks: more than the arrays hold means
they overflowed), ``steps`` (integrator steps: DOP853, or Taylor inside a record) and
``first_impact_time`` [s] (NaN if none)."""


@njit(cache=True)
def _outcome(code, state, tallies):
    """The :class:`SceneOutcome` of a scene whose last phase ended with ``code`` in ``state`` (a
    :class:`PhaseState`), from its tallies (the array of :func:`new_tallies`)."""
    ta = tallies[0]
    over = code == PH_OVER
    return SceneOutcome(
        status=STATUS_MAX_STEPS if code == PH_FAIL else STATUS_OK,
        max_rotation=ta.max_rotation,
        overturned=over,
        n_impacts=ta.n_impacts,
        overturn_time=state.t if over else np.nan,
        n_history=ta.n_history,
        n_impact_times=ta.n_impact_times,
        steps=ta.steps,
        first_impact_time=ta.first_impact_time,
        n_peaks=ta.n_peaks,
    )


def _make_scene(general):
    """:func:`scene` on :func:`_phase` (``general``), or :func:`scene_trig` on
    :func:`_phase_trig` (block models under a trigonometric pulse, no vertical component)."""

    @njit(cache=True)
    @_variant_named(general)
    def scene(body, mot, controls, start, log):
        """Rock one block (or tabulated mechanism) through one motion, from rest or a given state.

        body: a :class:`Body`; mot = (kind, mp, times, samples, vsamples) (see
        :mod:`rockstudy.motions._kernels`); controls: a :class:`Controls`; start: a
        :class:`Start`, (0, 0) for rest; log = (hist, imps, peaks, dense): arrays to fill with
        history rows (t, theta, theta_dot), impact times and peaks (t, theta, the maxima of
        |theta|), and the requested times dense[:, 0] (sorted), whose states the integration
        writes into dense[:, 1:3] (the rows it does not reach, in a rest or after a fall, keep
        their values: fill them with 0, the state at rest); each of length 0 for none.
        Returns a :class:`SceneOutcome`.
        """
        p, alpha, eta, model, tab = body.p, body.alpha, body.eta, body.model, body.table
        th0, om0 = start.theta, start.theta_dot
        kind, mp, times, samples, vsamples = mot
        omega_rest = REST_FRACTION * p * alpha
        tol = TOL_SAFETY * controls.rtol
        stepping = Stepping(
            p, alpha, eta, model, omega_rest, tol, controls.max_steps, body.fall, tab
        )
        hist = log[0]
        rec = hist.shape[0] > 0
        dur = mp[3]
        at_rest = th0 == 0.0 and om0 == 0.0
        s0 = math.copysign(1.0, th0 if th0 != 0.0 else om0)  # the side the start rocks on
        state = PhaseState(0.0, th0, om0, s0, FIRST_STEP / p)
        tallies = new_tallies(abs(th0))
        ta = tallies[0]  # updated in place; the outcome reads tallies, last (new_tallies)
        wk = _work_arrays()
        if rec:
            _push(hist, ta, 0.0, th0, om0)
        code = PH_END
        phases = 0
        while state.t < dur:
            phases += 1
            if phases > controls.max_steps:  # a guard: every phase must move the state on
                code = PH_FAIL
                break
            if at_rest:
                t_up = next_uplift(
                    kind, mp, times, samples, vsamples, p, alpha, model, tab, state.t
                )
                if t_up >= dur:
                    break
                k = segment_index(times, t_up, FIRST) if kind == KIND_RECORD else 0
                a_g = ground_acceleration(kind, mp, times, samples, t_up, k)
                state = PhaseState(t_up, 0.0, 0.0, -1.0 if a_g > 0.0 else 1.0, state.h)
                at_rest = False
                if rec:
                    _push(hist, ta, t_up, 0.0, 0.0)
            if general:
                code, state = _phase(stepping, mot, log, state, ta, wk, dur, NO_STOP)
            else:
                code, state = _phase_trig(stepping, mot, log, state, ta, wk, dur, NO_STOP)
            if code != PH_END and code != PH_REST:
                break
            at_rest = code == PH_REST
        if controls.free_map and code == PH_END and not at_rest and ta.n_impacts == 0:
            # integrate on to time the first impact
            if general:
                code, state = _phase(
                    stepping, mot, log, state, ta, wk, controls.tail_end, np.int64(1)
                )
            else:
                code, state = _phase_trig(
                    stepping, mot, log, state, ta, wk, controls.tail_end, np.int64(1)
                )
            at_rest = code == PH_REST
        if at_rest:
            if rec:
                _push(hist, ta, dur, 0.0, 0.0)
        elif code == PH_END or code == PH_IMPACT:
            u, v = state.side * state.theta, state.side * state.theta_dot
            if general and model == MODEL_TABLE:
                side = 0 if state.side > 0.0 else 1
                over, peak, n_post = _free_map_table(
                    u, v, eta, tab[side], tab[1 - side], omega_rest
                )
            else:
                over, peak, n_post = free_rocking_map(u, v, p, alpha, eta, model, omega_rest)
            if controls.free_map and not over and eta < 1.0:
                ta.max_rotation = max(ta.max_rotation, peak)
                ta.n_impacts += n_post
            else:  # integrate the free rocking: for the history, to time the overturning, or to
                # count the impacts of a block that never rests (eta = 1) up to the tail's end
                if general:
                    code, state = _phase(
                        stepping, mot, log, state, ta, wk, controls.tail_end, NO_STOP
                    )
                else:
                    code, state = _phase_trig(
                        stepping, mot, log, state, ta, wk, controls.tail_end, NO_STOP
                    )
        return _outcome(code, state, tallies)

    return scene


scene = _make_scene(True)
scene_trig = _make_scene(False)


#: Columns of the batch output array.
BATCH_COLUMNS = (
    "status",
    "max_rotation",
    "overturned",
    "n_impacts",
    "overturn_time",
    "steps",
    "first_impact_time",
)


def _make_scene_batch(general, parallel=True):
    """:func:`scene_batch` (every motion and model) or :func:`scene_batch_trig` (the block
    models under trigonometric pulses without a vertical component, :func:`scene_trig`); with
    ``parallel=False`` their one-thread variants (``*_serial``), which a study's workers run
    (one thread each): the parallel loop's lowering costs a fifth of a cold sine study's
    compile (about 6 s of 30 s CPU)."""

    @njit(cache=True, parallel=parallel)
    @_variant_named(general, serial=not parallel)
    def scene_batch(p, alpha, eta, model, kind, mp, times, samples, vsamples, rtol, max_steps):
        """:func:`scene` over rows of (p, alpha, eta, mp[i]) with the free-rocking map, in parallel
        (``vsamples``: the vertical component, empty for none; scaled by |mp[i, 0]|).

        Returns an (n, 7) float array with the columns of :data:`BATCH_COLUMNS`.
        """
        out = np.empty((p.shape[0], 7))
        no_log = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
        for i in prange(p.shape[0]):
            body = Body(p[i], alpha[i], eta[i], model, FALL_ROTATION, NO_TABLE)
            mot = (kind, mp[i], times, samples, vsamples)
            ctl = Controls(rtol, max_steps, True, free_tail_end(p[i], eta[i], mp[i, 3]))
            if general:
                r = scene(body, mot, ctl, Start(0.0, 0.0), no_log)
            else:
                r = scene_trig(body, mot, ctl, Start(0.0, 0.0), no_log)
            out[i, 0], out[i, 1], out[i, 2] = r.status, r.max_rotation, r.overturned
            out[i, 3], out[i, 4] = r.n_impacts, r.overturn_time
            out[i, 5], out[i, 6] = r.steps, r.first_impact_time
        return out

    return scene_batch


scene_batch = _make_scene_batch(True)
scene_batch_trig = _make_scene_batch(False)
scene_batch_serial = _make_scene_batch(True, parallel=False)
scene_batch_trig_serial = _make_scene_batch(False, parallel=False)
