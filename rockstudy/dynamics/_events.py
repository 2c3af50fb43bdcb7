"""Events and impacts (private): impacts, peaks and overturning inside an accepted step.

On a DOP853 step, roots of theta and theta_dot on the quintic Hermite interpolant
(:func:`_step_events`); on a Taylor step, on the step polynomial (:func:`_taylor_events`).
An impact multiplies the speed by eta (:func:`_impact`, eq. 2.3 of [000]); a slow one leaves
the block at rest unless the ground lifts it again (the Zeno rule, :func:`_zeno`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._roots import newton_bisect
from ._dop853 import hermite5
from ._logs import _push, tally_impact
from ._rhs import _lift, _rhs, _step
from ._taylor import (
    FMA,
    NO_REFCOUNT,
    OF_VALUE,
    poly_end,
    poly_root,
    poly_value,
    step_impact,
    step_peak,
)


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


@njit(cache=True)
def _newton_peak(t, th, om, acc, t_lo, t_hi):
    r"""The peak near (t, theta, theta_dot, theta_ddot) by one Newton step on theta_dot = 0:
    :math:`t_p = t - \dot\theta / \ddot\theta` (kept in [t_lo, t_hi], its step) and
    :math:`\theta_p = \theta - \dot\theta^2 / (2 \ddot\theta)`. Returns (t_p, theta_p)."""
    if acc == 0.0:
        return t, th
    return min(max(t - om / acc, t_lo), t_hi), th - 0.5 * om * om / acc


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
