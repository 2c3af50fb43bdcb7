"""One attempted step of a rocking phase (private), with its events: DOP853
(:func:`_dop853_attempt`, a Ricker wavelet or a mechanism), or Taylor series inside a record
(:func:`_taylor_attempt`) and under a trigonometric pulse or no ground motion
(:func:`_taylor_trig_attempt`). Each returns the outcome tuple of :func:`_dop853_attempt`."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..motions._kernels import vertical_acceleration
from ._dop853 import dop853_error, hermite5
from ._events import (
    EV_IMPACT,
    EV_NONE,
    EV_OVER,
    EV_REJECT,
    _newton_peak,
    _root_hermite,
    _step_events,
    _taylor_events,
    _true_state,
)
from ._rhs import _record_acceleration, _rhs, _step
from ._taylor import FMA, NO_REFCOUNT, taylor_coefficients, taylor_coefficients_trig
from .constants import (
    ATOL_FRACTION,
    IMPACT_RETRY_SHRINK,
    MIN_STEP,
    STEP_GROW_LIMIT,
    STEP_SAFETY,
    STEP_SHRINK_LIMIT,
    TAYLOR_TOL_FRACTION,
)


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
