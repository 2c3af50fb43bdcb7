"""The events of a step of the block on an isolated base (private numba kernels).

An event is a function of the state that fires when it passes from <= 0 to > 0 between the
ends of an accepted step (as ``solve_ivp`` detects its events): the impact (theta back to
0), the overturning (``|theta|`` = pi/2), the uplift (the base's absolute acceleration past
g tan(alpha)), the friction pendulum's stop (x_b' = 0 against the sliding) and break-away
(the friction the stuck base needs past mu g), and the peaks of ``|theta|`` and ``|x_b|``
(which end nothing). Each is located by bisection on the step's quintic Hermite interpolant
(:func:`._dop853.hermite5`), then one Newton correction on a true DOP853 step to it
(:func:`refine`), as the rocking kernels locate theirs.
"""

from __future__ import annotations

import math

from numba import njit

from ..constants import G
from ._dop853 import hermite5
from ._isolated_model import FALL, P_LIMIT, P_MU, P_OMEGA, P_ZETA, base_acceleration, demand, ground
from ._isolated_step import dop853_step
from ._taylor import NO_REFCOUNT

EV_IMPACT, EV_OVER, EV_LIFT, EV_STOP, EV_BREAK, EV_PEAK_TH, EV_PEAK_X = range(7)
EV_NONE = -1
#: The events that end a phase (the others are peaks).
N_TERMINAL = 5
#: Most narrowings of an event's bracket on the interpolant.
BISECTIONS = 60
#: Width of the bracket in s at which the narrowing stops: one Newton step on the true state
#: then leaves an error of order (1e-13 h)^2 in the event's time.
ROOT_WIDTH = 1e-13


@njit(cache=True, **NO_REFCOUNT)
def active(code, side, slide, par):
    """Whether event ``code`` is watched in the regime (side, slide)."""
    fp = par[P_MU] > 0.0
    if code in (EV_IMPACT, EV_OVER, EV_PEAK_TH):
        return side != 0.0
    if code == EV_LIFT:
        return side == 0.0
    if code == EV_STOP:
        return fp and slide != 0.0
    if code == EV_BREAK:
        return fp and slide == 0.0
    return not fp  # EV_PEAK_X: a linear isolator's turning points


@njit(cache=True, **NO_REFCOUNT)
def value(code, x, xd, th, thd, a_g, side, slide, sgn_x, par):
    """The event function, > 0 once the event has happened."""
    if code == EV_IMPACT:
        return -side * th
    if code == EV_OVER:
        return side * th - FALL
    if code == EV_LIFT:
        return abs(base_acceleration(x, xd, a_g, slide, par)) - par[P_LIMIT]
    if code == EV_STOP:
        return -slide * xd
    if code == EV_BREAK:
        y = (x, xd, th, thd)
        return abs(demand(y, a_g, side, par)) - par[P_MU] * G
    if code == EV_PEAK_TH:
        return -side * thd
    return -sgn_x * xd


@njit(cache=True, **NO_REFCOUNT)
def value_at(code, s, st, mot, k, side, slide, sgn_x, par):
    """The event function at the fraction s of the step ``st`` = (t0, h, y0, f0, y1, f1)
    on the interpolant, the ground's acceleration exact."""
    t0, h, y0, f0, y1, f1 = st
    x, xd, _ = hermite5(s, h, y0[0], y0[1], f0[1], y1[0], y1[1], f1[1])
    th, thd, _ = hermite5(s, h, y0[2], y0[3], f0[3], y1[2], y1[3], f1[3])
    a_g = 0.0  # only the uplift and the break-away read the ground
    if code == EV_LIFT or code == EV_BREAK:
        a_g = ground(mot, t0 + s * h, k)
    return value(code, x, xd, th, thd, a_g, side, slide, sgn_x, par)


@njit(cache=True, **NO_REFCOUNT)
def root(code, st, mot, k, side, slide, sgn_x, par):
    """The fraction s in (0, 1] where the event first fires on the interpolant: the bracket
    from the step's start (where it has not fired) to its end (where it has) narrowed by
    the Illinois variant of regula falsi (a bisection where the secant leaves the bracket)
    to :data:`ROOT_WIDTH`; its upper end (:func:`refine` then corrects the time by Newton on
    a true step, the uplift by ulps in :func:`._isolated_scene._lift_at`)."""
    lo, hi = 0.0, 1.0
    f_lo = min(value_at(code, 0.0, st, mot, k, side, slide, sgn_x, par), 0.0)
    f_hi = value_at(code, 1.0, st, mot, k, side, slide, sgn_x, par)
    last = 0  # the end moved last: 1 the upper, -1 the lower
    for _ in range(BISECTIONS):
        if hi - lo <= ROOT_WIDTH:
            break
        mid = hi - f_hi * (hi - lo) / (f_hi - f_lo)
        if not lo < mid < hi:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
        f = value_at(code, mid, st, mot, k, side, slide, sgn_x, par)
        if f > 0.0:
            hi, f_hi = mid, f
            f_lo = 0.5 * f_lo if last == 1 else f_lo
            last = 1
        else:
            lo, f_lo = mid, f
            f_hi = 0.5 * f_hi if last == -1 else f_hi
            last = -1
    return hi


@njit(cache=True, **NO_REFCOUNT)
def peak_root(code, st):
    """The fraction s of the step at which the peak ``code`` (EV_PEAK_TH: theta' = 0;
    EV_PEAK_X: x_b' = 0) lies: the secant of the rate between the step's ends, then three
    Newton steps on the interpolant (a peak's value is second order in its time, and
    :func:`refine` corrects it on a true step)."""
    t0, h, y0, f0, y1, f1 = st
    j = 2 if code == EV_PEAK_TH else 0
    d0, d1 = y0[j + 1], y1[j + 1]
    s = d0 / (d0 - d1) if d0 != d1 else 0.5
    for _ in range(3):
        _, d, a = hermite5(s, h, y0[j], y0[j + 1], f0[j + 1], y1[j], y1[j + 1], f1[j + 1])
        if a == 0.0:
            break
        s = min(max(s - d / (a * h), 0.0), 1.0)
    return s


@njit(cache=True, **NO_REFCOUNT)
def newton_delta(code, y, f, side, slide, par):
    """One Newton correction [s] of the event's time from the true state y, dy/dt f there
    (0 for the events of the ground's time alone or without a closed derivative)."""
    if code == EV_IMPACT:
        return -y[2] / y[3] if y[3] != 0.0 else 0.0
    if code == EV_OVER:
        return -(y[2] - side * FALL) / y[3] if y[3] != 0.0 else 0.0
    if code == EV_PEAK_TH:
        return -y[3] / f[3] if f[3] != 0.0 else 0.0
    if code in (EV_STOP, EV_PEAK_X):
        return -y[1] / f[1] if f[1] != 0.0 else 0.0
    if code == EV_LIFT and not (slide == 0.0 and par[P_MU] > 0.0):
        w, zeta = par[P_OMEGA], par[P_ZETA]
        a_b = -(2.0 * zeta * w * y[1] + w * w * y[0] + par[P_MU] * G * slide)
        rate = -(2.0 * zeta * w * f[1] + w * w * y[1])
        gap = a_b - math.copysign(par[P_LIMIT], a_b)
        return -gap / rate if rate != 0.0 else 0.0
    return 0.0


@njit(cache=True, **NO_REFCOUNT)
def advance(y, f, dl, out):
    """The state dl [s] after y (dy/dt = f there) by its second-order Taylor polynomial."""
    out[0] = y[0] + (y[1] + 0.5 * f[1] * dl) * dl
    out[1] = y[1] + f[1] * dl
    out[2] = y[2] + (y[3] + 0.5 * f[3] * dl) * dl
    out[3] = y[3] + f[3] * dl


@njit(cache=True, **NO_REFCOUNT)
def refine(code, s, st, work, par, mot, k, side, slide, out):
    """The time and state (into ``out``) of the event located at s of the step: a true
    DOP853 step from the step's start to it, then one Newton correction, kept inside the
    step. ``work`` = (K2, y, tmp) are scratch arrays; K2[0] must hold the step's f0."""
    t0, h, y0, f0, y1, f1 = st
    K2, yt, tmp = work
    tau = s * h
    if tau <= 0.0:
        for j in range(4):
            out[j] = y0[j]
        return t0
    dop853_step(t0, y0, tau, K2, yt, tmp, par, mot, k, side, slide)
    dl = newton_delta(code, yt, K2[12], side, slide, par)
    dl = min(max(dl, -tau), h - tau)
    advance(yt, K2[12], dl, out)
    return t0 + tau + dl
