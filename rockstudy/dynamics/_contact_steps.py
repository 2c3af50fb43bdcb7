"""One step of the contact model's kernel (private): the right-hand side of each regime, a
DOP853 step of the six states, its quintic Hermite dense output, and the events of a regime
located on that dense output.

The state is z = (q0, q1, q2, q0', q1', q2'): in contact (slide, rock, slide-rock)
q = (u, theta, 0) (the slip u [m] of :mod:`.slide_rock` and the rotation theta [rad]), in
flight q = (x_G, y_G, theta) (the centre of mass in the ground's frame). Every equation is
:mod:`.slide_rock`'s (numba-compiled there, called here). A ``mode`` is the tuple
(regime, side, slip, block, motion, k): the regime's code, the corner s, the slip direction
sigma, block = (R, alpha, eta, mu_s, mu_k), motion = (kind, mp, times, samples, vsamples)
and the record segment k of the step (-1 after the motion).

Under a record both ground components are linear in t on a step (the steps stop at every
sample), so sliding and flight have cubic solutions, which DOP853 (order 8) integrates
exactly: their error estimate vanishes and one step spans a sample interval.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import FALL_ROTATION, G
from ..motions._kernels import ground_acceleration, vertical_acceleration
from . import slide_rock as sr
from ._dop853 import _A, _B, _C, _E3, _E5, hermite5

#: Event codes. All are zeros of a function g crossing downwards (> 0 before, <= 0 after).
EV_NONE, EV_IMPACT, EV_FALL, EV_STICK, EV_SLIP_POS, EV_SLIP_NEG, EV_LIFT = range(7)
EV_LAND_POS, EV_LAND_NEG, EV_PEAK = 7, 8, 9
#: Points per step at which the events are sampled on the dense output (the reference's
#: HOP_POINTS: a hop through theta = 0 inside one step is an impact).
EVENT_POINTS = 8
#: Unit step time to which an event is located on the dense output before its refinement.
EVENT_S_TOL = 1e-15
#: Largest Newton correction of an event time, as a fraction of its step: the dense output
#: misplaces a crossing by far less; a larger one means that g has no zero there (an event
#: that the regime's start violates at once).
NEWTON_REACH = 1e-3
#: Most secant steps refining an event.
NEWTON_ITERATIONS = 4


@njit(cache=True)
def tableau():
    """The DOP853 tableau as arrays (A, B, C, E3, E5) (scipy's, through :mod:`._dop853`)."""
    return np.array(_A), np.array(_B), np.array(_C), np.array(_E3), np.array(_E5)


@njit(cache=True, inline="always")
def ground(mot, t, k):
    """(u_h'', u_v'') [m/s^2] at t on record segment k (0 after the motion); k < 0 for a
    step from the motion's end on, which sees the still ground even at its start (a pulse
    or a record may end on a non-zero acceleration)."""
    kind, mp, times, samples, vsamples = mot
    if k < 0:
        return 0.0, 0.0
    a_h = ground_acceleration(kind, mp, times, samples, t, k)
    return a_h, vertical_acceleration(kind, mp, times, vsamples, t, k)


@njit(cache=True)
def deriv(mode, t, z, out):
    """dz/dt of the regime of ``mode`` into ``out``; NaN where slide-rock has no solution
    (Painleve's paradox, mu_k > 4/3)."""
    regime, side, slip, blk, mot, k = mode
    radius, alpha, _, _, kinetic = blk
    a_h, a_v = ground(mot, t, k)
    out[0], out[1], out[2], out[5] = z[3], z[4], z[5], 0.0
    if regime == sr.FLIGHT:
        out[3], out[4] = -a_h, -(G + a_v)
    elif regime == sr.SLIDE:
        out[3], out[4] = sr.sliding_acceleration(a_h, a_v, slip, kinetic), 0.0
    elif regime == sr.ROCK:
        out[3], out[4] = 0.0, sr.rocking_acceleration(z[1], a_h, a_v, side, radius, alpha)
    elif sr.slide_rock_denominator(z[1], side, slip, kinetic, alpha) <= 0.0:
        out[3], out[4] = math.nan, math.nan
    else:
        u_dd, th_dd, _ = sr.slide_rock_accelerations(
            z[1], z[4], a_h, a_v, side, slip, kinetic, radius, alpha
        )
        out[3], out[4] = u_dd, th_dd


@njit(cache=True)
def rk_step(rk, mode, t, z, h, K, z1, tmp):
    """One DOP853 step of length h from (t, z), K[0] = dz/dt there: the stages into K[:12],
    the new state into z1 (K[12], dz/dt at the end, is the caller's)."""
    A, B, C = rk[0], rk[1], rk[2]
    for i in range(1, 12):
        for m in range(6):
            acc = 0.0
            for j in range(i):
                acc += A[i, j] * K[j, m]
            tmp[m] = z[m] + h * acc
        deriv(mode, t + C[i] * h, tmp, K[i])
    for m in range(6):
        acc = 0.0
        for j in range(12):
            acc += B[j] * K[j, m]
        z1[m] = z[m] + h * acc


@njit(cache=True)
def rk_error(rk, K, h, z, z1, scale, tol):
    """Hairer's combined 5th/3rd-order error norm of the step (<= 1 accepts): absolute
    scales tol * ``scale``, relative tol."""
    E3, E5 = rk[3], rk[4]
    n5, n3 = 0.0, 0.0
    for m in range(6):
        e5, e3 = 0.0, 0.0
        for j in range(13):
            e5 += E5[j] * K[j, m]
            e3 += E3[j] * K[j, m]
        sc = tol * (scale[m] + max(abs(z[m]), abs(z1[m])))
        n5 += (e5 / sc) ** 2
        n3 += (e3 / sc) ** 2
    if n5 == 0.0:
        return 0.0
    return abs(h) * n5 / math.sqrt(n5 + 0.01 * n3)


@njit(cache=True)
def dense(s, h, z, K, z1, out):
    """The state at unit step time s in [0, 1] on the quintic Hermite interpolant of a step
    (value, velocity and acceleration of each q at both ends) into ``out``."""
    for j in range(3):
        q, v, _ = hermite5(s, h, z[j], z[3 + j], K[0, 3 + j], z1[j], z1[3 + j], K[12, 3 + j])
        out[j], out[3 + j] = q, v


@njit(cache=True)
def forces(mode, t, z):
    """(F / m, N / m) of a contact regime at (t, z) (:func:`.slide_rock.contact_forces`, or
    F = -sigma mu_k N in slide-rock)."""
    regime, side, slip, blk, mot, k = mode
    radius, alpha, _, _, kinetic = blk
    a_h, a_v = ground(mot, t, k)
    if regime == sr.SLIDE_ROCK:
        normal = sr.slide_rock_accelerations(
            z[1], z[4], a_h, a_v, side, slip, kinetic, radius, alpha
        )[2]
        return -slip * kinetic * normal, normal
    th_dd = sr.rocking_acceleration(z[1], a_h, a_v, side, radius, alpha)
    return sr.contact_forces(z[1], z[4], th_dd, 0.0, a_h, a_v, side, radius, alpha)


@njit(cache=True)
def _g(ev, mode, z, f_h, f_v):
    """g of event ``ev`` at the state z with the contact forces (f_h, f_v) there."""
    regime, side, slip, blk = mode[0], mode[1], mode[2], mode[3]
    if ev == EV_IMPACT:
        return side * z[1]
    if ev == EV_FALL:
        return FALL_ROTATION - (abs(z[2]) if regime == sr.FLIGHT else side * z[1])
    if ev == EV_STICK:
        return slip * z[3]
    if ev == EV_PEAK:
        return side * z[4]
    if ev == EV_LAND_POS or ev == EV_LAND_NEG:
        corner = 1.0 if ev == EV_LAND_POS else -1.0
        return z[1] - blk[0] * math.cos(blk[1] - corner * z[2])
    if ev == EV_LIFT:
        return f_v
    return blk[3] * f_v - f_h if ev == EV_SLIP_POS else blk[3] * f_v + f_h


@njit(cache=True)
def event_value(ev, mode, t, z):
    """g of event ``ev`` at (t, z): it crosses 0 downwards at the event."""
    if EV_SLIP_POS <= ev <= EV_LIFT:
        f_h, f_v = forces(mode, t, z)
        return _g(ev, mode, z, f_h, f_v)
    return _g(ev, mode, z, math.nan, math.nan)


@njit(cache=True)
def regime_events(regime):
    """The terminal events of a regime (the peaks are followed apart)."""
    if regime == sr.SLIDE:
        return (EV_STICK, EV_NONE, EV_NONE, EV_NONE, EV_NONE)
    if regime == sr.ROCK:
        return (EV_IMPACT, EV_FALL, EV_SLIP_POS, EV_SLIP_NEG, EV_LIFT)
    if regime == sr.SLIDE_ROCK:
        return (EV_IMPACT, EV_FALL, EV_STICK, EV_LIFT, EV_NONE)
    return (EV_LAND_POS, EV_LAND_NEG, EV_FALL, EV_NONE, EV_NONE)


@njit(cache=True)
def _value_at(ev, mode, t, h, s, z, K, z1, tmp):
    """g of event ``ev`` at unit step time s on the dense output."""
    dense(s, h, z, K, z1, tmp)
    return event_value(ev, mode, t + s * h, tmp)


@njit(cache=True)
def _bisect(ev, mode, t, h, lo, hi, z, K, z1, tmp):
    """The zero of g (> 0 at lo, <= 0 at hi) on the dense output, to EVENT_S_TOL."""
    while hi - lo > EVENT_S_TOL:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _value_at(ev, mode, t, h, mid, z, K, z1, tmp) > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


#: Extra sample points (unit step time) of the first step of a regime, for the events on
#: the contact forces (slip, lift-off): one that the regime's start violates at once (a slip
#: right after an impact) is caught even where it holds only for a moment, as the
#: reference's short first step catches it. The events on the state (impact, stick,
#: landing), which start at 0, are sampled from EARLIEST on, where the state has moved
#: beyond the rounding of the dense output.
FRESH_POINTS = (1e-9, 1e-7, 1e-5, 1e-3, 1e-2)
EARLIEST = 1.0 / EVENT_POINTS


@njit(cache=True)
def sample_point(j, fresh):
    """The j-th sample point of a step (FRESH_POINTS first on a regime's first step)."""
    if fresh:
        if j < len(FRESH_POINTS):
            return FRESH_POINTS[j]
        j -= len(FRESH_POINTS)
    return (j + 1) / EVENT_POINTS


@njit(cache=True)
def first_event(events, mode, t, h, z, K, z1, fresh, tmp, trace):
    """(event, unit step time) of the first terminal event inside the step, or
    (EV_NONE, 1.0): each g sampled at EVENT_POINTS points (g taken positive at the start
    of a regime, ``fresh``, as the reference's events are at a phase's start; there the
    force events also at FRESH_POINTS), then the first interval where one crosses located
    by bisection. The sampled (s, s theta') go into ``trace`` (for :func:`peaks`) until a
    row with s = inf."""
    prev, los = np.empty(5), np.zeros(5)
    with_forces = False
    for e in range(5):
        ev = events[e]
        with_forces = with_forces or EV_SLIP_POS <= ev <= EV_LIFT
        prev[e] = 1.0 if fresh or ev == EV_NONE else event_value(ev, mode, t, z)
    n = EVENT_POINTS + (len(FRESH_POINTS) if fresh else 0)
    for j in range(n):
        s = sample_point(j, fresh)
        dense(s, h, z, K, z1, tmp)
        f_h = f_v = math.nan
        if with_forces:
            f_h, f_v = forces(mode, t + s * h, tmp)
        trace[j, 0], trace[j, 1], trace[j + 1, 0] = s, mode[1] * tmp[4], math.inf
        best, best_s = EV_NONE, 2.0
        for e in range(5):
            ev = events[e]
            if ev == EV_NONE or (s < EARLIEST and not EV_SLIP_POS <= ev <= EV_LIFT):
                continue
            g = _g(ev, mode, tmp, f_h, f_v)
            if prev[e] > 0.0 and not g > 0.0:
                root = _bisect(ev, mode, t, h, los[e], s, z, K, z1, tmp) if g == g else s
                if root < best_s:
                    best, best_s = ev, root
            prev[e], los[e] = g, s
        if best != EV_NONE:
            return best, best_s
    return EV_NONE, 1.0


@njit(cache=True)
def peaks(mode, t, h, s_end, z, K, z1, tmp, trace, found):
    """The unit step times in (0, s_end] of the peaks of s theta (s theta' down through 0),
    from the samples of :func:`first_event` (``trace``), into ``found``; returns how many."""
    n = 0
    prev, lo = mode[1] * z[4], 0.0
    for j in range(trace.shape[0]):
        s = trace[j, 0]
        if s > s_end:  # the interval of the event: its end
            s = s_end
        g = trace[j, 1] if s == trace[j, 0] else _value_at(EV_PEAK, mode, t, h, s, z, K, z1, tmp)
        if prev > 0.0 and not g > 0.0 and n < found.shape[0]:
            found[n] = _bisect(EV_PEAK, mode, t, h, lo, s, z, K, z1, tmp)
            n += 1
        prev, lo = g, s
        if s >= s_end:
            break
    return n


@njit(cache=True)
def _true_state(rk, mode, t, z, K, dt, out, work):
    """The state at t + dt by one DOP853 step from (t, z) into ``out``; its g there."""
    K2, tmp = work[0], work[2]
    K2[0, :] = K[0]
    if dt > 0.0:
        rk_step(rk, mode, t, z, dt, K2, out, tmp)
    else:
        out[:] = z


@njit(cache=True)
def refine(ev, rk, mode, t, z, K, s, h, out, work):
    """The state at the event ``ev`` located at unit step time s of a step: secant steps on
    g at true DOP853 steps from t (the first rate from the dense output; none beyond
    :data:`NEWTON_REACH`, where g has no zero nearby), the last one applied to the state by
    its second-order expansion. Returns the event time; the state goes into ``out``.
    ``work`` = (K2, z1 of the step, tmp, ...)."""
    z1, tmp = work[1], work[2]
    dt = s * h
    lo, hi = max(s - 1e-7, 0.0), min(s + 1e-7, 1.0)
    g_lo = _value_at(ev, mode, t, h, lo, z, K, z1, tmp)
    rate = (_value_at(ev, mode, t, h, hi, z, K, z1, tmp) - g_lo) / ((hi - lo) * h)
    dl, g_old = 0.0, np.nan
    for _ in range(NEWTON_ITERATIONS):
        _true_state(rk, mode, t, z, K, dt, out, work)
        g = event_value(ev, mode, t + dt, out)
        if g_old == g_old and dl != 0.0 and g != g_old:
            rate = (g - g_old) / dl
        dl = -g / rate if rate != 0.0 and g == g else 0.0
        if not abs(dl) <= NEWTON_REACH * h:  # no crossing nearby: g <= 0 from the start
            dl = 0.0
        dl = min(max(dl, -dt), h - dt)
        if abs(dl) <= EVENT_S_TOL * h:
            break
        dt, g_old = dt + dl, g
    deriv(mode, t + dt, out, tmp)
    for j in range(3):
        a = tmp[3 + j]
        out[j] += dl * (out[3 + j] + 0.5 * a * dl)
        out[3 + j] += a * dl
    return t + dt + dl
