"""The events of the two-block kernel on an accepted step (private): impacts and falls of
the rocking interfaces, uplifts of the closed ones (a lock margin through zero), and the
peaks of |angle|; located on the step's quintic Hermite interpolant
(:func:`._stacked_steps.interface_at`) by safeguarded Newton steps, then refined on the
state inside the step (:func:`true_state`: the step's polynomials or dense output).

An interface's angle u = s angle (s its pivot side) is sampled at :data:`SAMPLES` points of
the step: an impact is its first sample at or below zero, or a minimum below zero between
two samples (a dip the ends of the step would miss); a peak a maximum of u. The lock
margins are checked at the step's end, as the reference's events are (a sign change
between the ends of a step).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._roots import newton_bisect
from ..constants import FALL_ROTATION
from ._stacked_model import A1, lock_margins
from ._stacked_steps import (
    DENSE_TAYLOR,
    K_FSUB,
    K_INFO,
    K_SUB,
    dense_state,
    derivative,
    ground,
    interface_at,
    interface_data,
    state_at,
)
from ._stacked_taylor import both_state, series_clear
from ._taylor import NO_REFCOUNT, ROOT_ITERATIONS, ROOT_TOL

#: Samples of the interpolant per step at which the impacts and peaks are sought.
SAMPLES = 4
#: Halvings of the bracket of an uplift (a lock margin through zero) on the interpolant.
BISECTIONS = 60
#: Secant steps on true sub-steps that refine an uplift located on the interpolant.
SECANTS = 3

EVENT_NONE, EVENT_IMPACT, EVENT_FALL, EVENT_UPLIFT = 0, 1, 2, 3


@njit(cache=True, inline="always")
def _angle_fdf(x, args):
    """s angle_k - level at the fraction x of the step and its x-derivative (the
    interpolant's)."""
    k, s, level, h, y0, f0, y1, f1 = args
    u, v, _ = interface_at(k, x, h, y0, f0, y1, f1)
    return s * u - level, s * v * h


@njit(cache=True, inline="always")
def _rate_fdf(x, args):
    """s angle_k' at the fraction x of the step and its x-derivative (the interpolant's)."""
    k, s, h, y0, f0, y1, f1 = args
    _, v, a = interface_at(k, x, h, y0, f0, y1, f1)
    return s * v, s * a * h


@njit(cache=True, **NO_REFCOUNT)
def _angle_root(k, s, level, lo, hi, h, y0, f0, y1, f1, guess):
    """The fraction in [lo, hi] where s angle_k - level changes sign (> 0 at lo, <= 0 at hi
    for level 0; < 0 at lo, >= 0 at hi otherwise), by safeguarded Newton steps on the
    interpolant (:func:`rockstudy._roots.newton_bisect`, to ROOT_TOL of the step) from
    ``guess`` (in [lo, hi])."""
    args = (k, s, level, h, y0, f0, y1, f1)
    sign_lo = 1.0 if level == 0.0 else -1.0
    return newton_bisect(_angle_fdf, args, lo, hi, guess, sign_lo, ROOT_TOL, ROOT_ITERATIONS)


@njit(cache=True, **NO_REFCOUNT)
def _rate_root(k, s, lo, hi, h, y0, f0, y1, f1, falling):
    """The fraction in [lo, hi] where s angle_k' changes sign (from + to - if ``falling``,
    a peak; from - to + otherwise, a trough), as :func:`_angle_root`."""
    args = (k, s, h, y0, f0, y1, f1)
    sign_lo = 1.0 if falling else -1.0
    return newton_bisect(
        _rate_fdf, args, lo, hi, 0.5 * (lo + hi), sign_lo, ROOT_TOL, ROOT_ITERATIONS
    )


@njit(cache=True, **NO_REFCOUNT)
def impact_fraction(k, s, h, y0, f0, y1, f1, rates):
    """The first fraction of the step at which interface k (rocking on side s) reaches zero:
    a short hop back to zero before the first sample (:func:`_early_return`), a sample at
    or below zero, or a trough below zero between samples; 2.0 if none. The rates s angle'
    at the samples it read go to ``rates`` (NaN from the first it did not read), for
    :func:`step_peaks`."""
    rates[:] = np.nan
    hop = _early_return(k, s, h, y0, f0, y1, f1)
    if hop <= 1.0:
        return hop
    x, v, _ = interface_data(k, y0, f0)
    lo, u_lo, u_prev, rates[0] = 0.0, 1.0, s * x, s * v
    for j in range(1, SAMPLES + 1):
        hi = j / SAMPLES
        if j < SAMPLES:
            x, v, _ = interface_at(k, hi, h, y0, f0, y1, f1)
        else:  # the interpolant's end is the step's
            x, v, _ = interface_data(k, y1, f1)
        u, rates[j] = s * x, s * v
        if u <= 0.0:
            guess = lo + (hi - lo) * u_prev / (u_prev - u) if u_prev > 0.0 else 0.5 * (lo + hi)
            return _angle_root(k, s, 0.0, lo, hi, h, y0, f0, y1, f1, guess)
        if rates[j - 1] < 0.0 <= rates[j]:  # a trough between the samples
            mid = _rate_root(k, s, lo, hi, h, y0, f0, y1, f1, False)
            if s * interface_at(k, mid, h, y0, f0, y1, f1)[0] <= 0.0 < u_lo:
                return _angle_root(k, s, 0.0, lo, mid, h, y0, f0, y1, f1, 0.5 * (lo + mid))
        lo, u_lo, u_prev = hi, u, u
    return 2.0


@njit(cache=True, **NO_REFCOUNT)
def _early_return(k, s, h, y0, f0, y1, f1):
    """The fraction at which interface k is back at zero after a hop shorter than the first
    sample: the return time of u = s angle on its quadratic from the step's start (u0 + v0 t
    + a0 t^2 / 2, a0 < 0), checked on the interpolant at 1.5 times it; 2.0 if there is no
    such hop. (A body released with a tiny speed by the other interface's impact falls back
    within a fraction of a step, up and down between two samples.)"""
    x0, v0, a0 = interface_data(k, y0, f0)
    u0, v0, a0 = s * x0, s * v0, s * a0
    if not a0 < 0.0 or u0 < 0.0 or (u0 == 0.0 and not v0 > 0.0):  # no hop from a standstill
        return 2.0
    tau = (v0 + (v0 * v0 - 2.0 * a0 * u0) ** 0.5) / -a0
    hi = 1.5 * tau / h
    if not hi < 1.0 / SAMPLES or s * interface_at(k, hi, h, y0, f0, y1, f1)[0] > 0.0:
        return 2.0
    return _angle_root(k, s, 0.0, 0.0, hi, h, y0, f0, y1, f1, tau / h)


@njit(cache=True, **NO_REFCOUNT)
def fall_fraction(k, s, h, y0, f0, y1, f1):
    """The fraction at which s angle_k reaches :data:`FALL_ROTATION` (2.0 if it does not by
    the step's end)."""
    if s * interface_data(k, y1, f1)[0] < FALL_ROTATION:
        return 2.0
    return _angle_root(k, s, FALL_ROTATION, 0.0, 1.0, h, y0, f0, y1, f1, 0.5)


@njit(cache=True, **NO_REFCOUNT)
def uplift_fraction(g, regime, mot, t, h, y0, f0, y1, f1, j, margins, tmp, w):
    """The fraction of the step at which lock margin j (:func:`._stacked_model.lock_margins`
    order) turns negative, by bisection on the interpolated state, then secant steps on true
    sub-steps (:func:`_true_margin`); 2.0 if it is not negative at the step's end
    (``margins`` holds the end's margins)."""
    if not margins[j] < 0.0:
        return 2.0
    s1, s2, flat0, flat1 = regime
    lo, hi = 0.0, 1.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        state_at(mid, h, y0, f0, y1, f1, tmp[:4])
        lock_margins(g, tmp[:4], s1, s2, flat0, flat1, ground(mot, t + mid * h), tmp[4:])
        if tmp[4 + j] < 0.0:
            hi = mid
        else:
            lo = mid
    a, b = lo, hi
    m_a = _true_margin(g, regime, mot, t, y0, f0, a * h, j, tmp, w)
    m_b = _true_margin(g, regime, mot, t, y0, f0, b * h, j, tmp, w)
    for _ in range(SECANTS):
        if m_b == m_a or m_b == 0.0:
            break
        a, m_a, b = b, m_b, b - m_b * (b - a) / (m_b - m_a)
        m_b = _true_margin(g, regime, mot, t, y0, f0, b * h, j, tmp, w)
    return min(max(b, 0.0), 1.0) if abs(m_b) < abs(margins[j]) else hi


@njit(cache=True, **NO_REFCOUNT)
def _true_margin(g, regime, mot, t, y0, f0, dt, j, tmp, w):
    """Lock margin j at t + dt on a true sub-step (:func:`true_state`)."""
    s1, s2, flat0, flat1 = regime
    true_state(g, regime, mot, t, y0, f0, dt, w)
    y = w[K_SUB]
    lock_margins(g, y, s1, s2, flat0, flat1, ground(mot, t + dt), tmp[4:])
    return tmp[4 + j]


@njit(cache=True, **NO_REFCOUNT)
def true_state(g, regime, mot, t, y0, f0, dt, w):
    """The state and its derivative at t + dt inside the last accepted step (from (t, y0)),
    into w[K_SUB] and w[K_FSUB]: on the step's polynomials after a Taylor step
    (:func:`._stacked_taylor.both_state`), else on its dense output after a DOP853 step
    (:func:`._stacked_steps.dense_state`) (a step of length 0 copies the start)."""
    if dt == 0.0:
        for c in range(4):
            w[K_SUB, c], w[K_FSUB, c] = y0[c], f0[c]
        return
    if w[K_INFO, 0] == DENSE_TAYLOR:
        both_state(w, int(w[K_INFO, 2]), dt / w[K_INFO, 1], w[K_INFO, 1], w[K_SUB])
    else:
        dense_state(g, regime, mot, t, y0, dt / w[K_INFO, 1], w, w[K_SUB])
    derivative(g, regime, mot, t + dt, w[K_SUB], w[K_FSUB])


@njit(cache=True, **NO_REFCOUNT)
def step_peaks(g, regime, mot, t, h, y0, f0, y1, f1, upto, peaks, w, rates):
    """Raise ``peaks`` (|theta_1|, |phi|) to the maxima of |angle| of the rocking interfaces
    inside the step before the fraction ``upto``: a maximum of s angle between the samples
    of :func:`impact_fraction` (their rates in ``rates[k]``) located on the interpolant,
    valued on a true sub-step and one Newton step on the rate (skipped where the
    interpolant's value cannot raise the peak)."""
    s1, s2, flat0, flat1 = regime
    for k in range(2):
        if (flat0, flat1)[k]:
            continue
        s = (s1, s2)[k]
        for j in range(1, SAMPLES + 1):
            lo = (j - 1) / SAMPLES
            if lo >= upto or not rates[k, j] == rates[k, j]:
                break
            if rates[k, j - 1] > 0.0 >= rates[k, j]:
                mid = _rate_root(k, s, lo, j / SAMPLES, h, y0, f0, y1, f1, True)
                x = abs(interface_at(k, mid, h, y0, f0, y1, f1)[0])
                if mid <= upto and x > peaks[k] - 1e-6 * g[A1 + k]:
                    _, ys, fs = _refined(g, regime, mot, t, y0, f0, mid * h, k, w)
                    peaks[k] = max(peaks[k], abs(ys))


@njit(cache=True, **NO_REFCOUNT)
def _refined(g, regime, mot, t, y0, f0, dt, k, w):
    """Interface k's extremum near t + dt: x - v^2 / (2 a) of the true sub-step's angle x,
    rate v and acceleration a (one Newton step on the rate); returns (dt, value, a)."""
    true_state(g, regime, mot, t, y0, f0, dt, w)
    y, f = w[K_SUB], w[K_FSUB]
    if k == 0:
        x, v, a = y[0], y[2], f[2]
    else:
        x, v, a = y[1] - y[0], y[3] - y[2], f[3] - f[2]
    if a == 0.0:
        return dt, x, a
    return dt, x - 0.5 * v * v / a, a


@njit(cache=True, **NO_REFCOUNT)
def first_event(g, regime, mot, t, h, y0, f0, y1, f1, margins, tmp, w, rates):
    """The first event inside an accepted step: (fraction, kind, interface, corner), the
    fraction 2.0 and kind EVENT_NONE if none. ``margins`` holds the lock margins at the
    step's end; ``rates`` (2, SAMPLES + 1) receives the rocking interfaces' sampled rates
    (:func:`impact_fraction`)."""
    s1, s2, flat0, flat1 = regime
    best, kind, iface, corner = 2.0, EVENT_NONE, -1, 0
    for k in range(2):
        s = (s1, s2)[k]
        if (flat0, flat1)[k]:
            for j in range(2):
                sig = uplift_fraction(
                    g, regime, mot, t, h, y0, f0, y1, f1, 2 * k + j, margins, tmp, w
                )
                if sig < best:
                    best, kind, iface, corner = sig, EVENT_UPLIFT, k, 1 - 2 * j
            continue
        if w[K_INFO, 0] == DENSE_TAYLOR and series_clear(w, int(w[K_INFO, 2]), k, s):
            rates[k, :] = np.nan  # no impact, and no peak for step_peaks
            sig = 2.0
        else:
            sig = impact_fraction(k, s, h, y0, f0, y1, f1, rates[k])
        if sig < best:
            best, kind, iface, corner = sig, EVENT_IMPACT, k, s
        sig = fall_fraction(k, s, h, y0, f0, y1, f1)
        if sig < best:
            best, kind, iface, corner = sig, EVENT_FALL, k, s
    return best, kind, iface, corner


@njit(cache=True, **NO_REFCOUNT)
def event_state(g, regime, mot, t, h, y0, f0, sigma, kind, k, side, w, out):
    """The state at an event at the fraction sigma of the step, into ``out``; returns its
    time. A true sub-step to it, then for an impact or a fall of interface k (rocking on
    ``side``) one Newton step onto the angle's zero or side pi/2 (all components moved by
    the same dt, to second order)."""
    true_state(g, regime, mot, t, y0, f0, sigma * h, w)
    y, f = w[K_SUB], w[K_FSUB]
    dl = 0.0
    if kind == EVENT_IMPACT or kind == EVENT_FALL:
        target = 0.0 if kind == EVENT_IMPACT else side * FALL_ROTATION
        x, v = (y[0], y[2]) if k == 0 else (y[1] - y[0], y[3] - y[2])
        if v != 0.0:
            dl = min(max((target - x) / v, -sigma * h), (1.0 - sigma) * h)
    for c in range(2):
        out[c] = y[c] + dl * (y[2 + c] + 0.5 * dl * f[2 + c])
        out[2 + c] = y[2 + c] + dl * f[2 + c]
    return t + sigma * h + dl
