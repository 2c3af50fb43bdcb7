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
from ..motions._kernels import ground_acceleration
from ._dop853 import hermite5
from ._isolated_model import FALL, P_LIMIT, P_MU, P_OMEGA, P_ZETA, base_acceleration, demand
from ._isolated_step import dop853_step

EV_IMPACT, EV_OVER, EV_LIFT, EV_STOP, EV_BREAK, EV_PEAK_TH, EV_PEAK_X = range(7)
EV_NONE = -1
#: The events that end a phase (the others are peaks).
N_TERMINAL = 5
#: Bisections of the interpolant: to adjacent doubles of s in [0, 1].
BISECTIONS = 60


@njit(cache=True)
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


@njit(cache=True)
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


@njit(cache=True)
def value_at(code, s, st, mot, k, side, slide, sgn_x, par):
    """The event function at the fraction s of the step ``st`` = (t0, h, y0, f0, y1, f1)
    on the interpolant, the ground's acceleration exact."""
    t0, h, y0, f0, y1, f1 = st
    x, xd, _ = hermite5(s, h, y0[0], y0[1], f0[1], y1[0], y1[1], f1[1])
    th, thd, _ = hermite5(s, h, y0[2], y0[3], f0[3], y1[2], y1[3], f1[3])
    a_g = ground_acceleration(mot[0], mot[1], mot[2], mot[3], t0 + s * h, k)
    return value(code, x, xd, th, thd, a_g, side, slide, sgn_x, par)


@njit(cache=True)
def root(code, st, mot, k, side, slide, sgn_x, par):
    """The fraction s in (0, 1] where the event first fires on the interpolant (bisection
    from the step's start, where it has not, to its end, where it has)."""
    lo, hi = 0.0, 1.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if value_at(code, mid, st, mot, k, side, slide, sgn_x, par) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True)
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


@njit(cache=True)
def advance(y, f, dl, out):
    """The state dl [s] after y (dy/dt = f there) by its second-order Taylor polynomial."""
    out[0] = y[0] + (y[1] + 0.5 * f[1] * dl) * dl
    out[1] = y[1] + f[1] * dl
    out[2] = y[2] + (y[3] + 0.5 * f[3] * dl) * dl
    out[3] = y[3] + f[3] * dl


@njit(cache=True)
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
