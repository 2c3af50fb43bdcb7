"""The rock regime of the contact model by Taylor steps (private).

Rotation about a corner without slip is Housner's equation, the rocking kernels' ODE: where
both ground components are linear in t on a step (inside a record segment, or after the
motion), a step is the rocking kernels' Taylor series (:func:`._taylor.taylor_coefficients`),
an exact dense output of theta within the step's tolerance. Its events are located on that
polynomial: the impact (theta = 0, :func:`._taylor.step_impact`), the fall (s theta =
FALL_ROTATION) and the peak (:func:`._taylor.step_peak`) as in the rocking kernels, and the
events on the contact forces, slip (``|F|`` = mu_s N) and lift-off (N = 0), on the forces of
:func:`.slide_rock.contact_forces` along the polynomial (theta, theta_dot and theta_ddot
from its value and derivatives, the ground interpolated linearly).

The force events are first bounded over the whole step from its series, without a sine, a
cosine or an evaluation of the polynomial (:func:`_forces_away`; the ground term and the
rotational acceleration it drives bounded together, as one polynomial, so that they cancel):
where every g = mu_s N - ``|F|`` and N stays above 0 throughout, no crossing can exist and
none is looked for (the outcome the evaluations below would give, to the bit, on the first
step of a regime too: a bound above 0 there rules out a g at or below 0 at its start). Otherwise
they are screened on three points of the step (its ends and its middle): where every g
there exceeds :data:`FORCE_MARGIN` times its spread over them, no crossing is looked for;
otherwise (and on the first step of a regime, where the regime's start may violate a force
condition at once) g is sampled at the DOP853 steps' points
(:data:`._contact_steps.EVENT_POINTS`, and :data:`._contact_steps.FRESH_POINTS` on a first
step) and its first crossing bisected on the polynomial to the ulp of the step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import FALL_ROTATION, G
from ..motions._kernels import KIND_RECORD
from . import _contact_steps as cs
from . import slide_rock as sr
from ._demand import BOUND_MARGIN, _product, _square
from ._taylor import (
    FMA,
    MODEL_NONLINEAR,
    NO_REFCOUNT,
    OF_VALUE,
    ROW_C,
    ROW_C_SERIES,
    ROW_S,
    poly_end,
    poly_root,
    poly_value,
    step_impact,
    step_peak,
    taylor_coefficients,
)
from .constants import ATOL_FRACTION

#: A force event is not looked for inside a step where each g at its ends and middle exceeds
#: this many times the spread of its three values (g is smooth on a step far shorter than its
#: period: it cannot dip to zero between them).
FORCE_MARGIN = 4.0
#: Outcomes of :func:`rock_step`: rejected (retry shorter), accepted.
REJECTED, ACCEPTED = 0, 1
#: The force events of the rock regime, in the order of :func:`rock_force_events`.
FORCE_EVENTS = (cs.EV_SLIP_POS, cs.EV_SLIP_NEG, cs.EV_LIFT)


@njit(cache=True, inline="always")
def taylor_rock_applies(kind, k):
    """Whether a rock step on record segment k (-1 after the motion) of a motion of ``kind``
    sees a ground linear in t (a record, or none after the motion): a Taylor step."""
    return k < 0 or kind == KIND_RECORD


@njit(cache=True, inline="always", **NO_REFCOUNT)
def rock_force_events(c, n, x, hs, side, static, radius, alpha, gr):
    """g of the slip events (mu_s N - F, mu_s N + F) and of lift-off (N) at unit step time x
    on the step polynomial c of order n; ``gr`` = (a_h, a_v) at the step's ends (a_h0, a_h1,
    a_v0, a_v1) [m/s^2], linear between."""
    th, d, dd = poly_value(c, n, x)
    a_h = gr[0] + x * (gr[1] - gr[0])
    a_v = gr[2] + x * (gr[3] - gr[2])
    f_h, f_v = sr.contact_forces(th, d / hs, dd / (hs * hs), 0.0, a_h, a_v, side, radius, alpha)
    return static * f_v - f_h, static * f_v + f_h, f_v


@njit(cache=True, inline="always")
def _trig_span(a, b, r):
    """The interval of a cos(d) + b sin(d) over ``|d|`` <= r (the sine or cosine of an angle
    within r of one whose sine and cosine are a and b): a +- (``|a|`` r^2 / 2 + ``|b|`` r)."""
    e = 0.5 * abs(a) * r * r + abs(b) * r
    return a - e, a + e


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _series_spans(c, n):
    """Over the step (x in [0, 1]): the radius of theta about c_0; the (lo, hi) of the
    polynomial's first x-derivative (each term of its sign between 0 and its value at
    x = 1); and its second x-derivative's coefficients e_0, e_1, e_2 and the sums of the
    negative and of the positive ones of higher order (e_j = (j + 1) (j + 2) c_{j+2})."""
    r_th = abs(c[1])
    d_lo = d_hi = c[1]
    neg = pos = 0.0
    for k in range(2, n + 1):
        ck = c[k]
        r_th += abs(ck)
        dk = k * ck
        d_lo, d_hi = d_lo + min(dk, 0.0), d_hi + max(dk, 0.0)
        if k >= 5:
            ddk = (k - 1) * dk
            neg, pos = neg + min(ddk, 0.0), pos + max(ddk, 0.0)
    e = (2.0 * c[2], 6.0 * c[3], 12.0 * c[4] if n >= 4 else 0.0)
    return r_th, d_lo, d_hi, e, neg, pos


@njit(cache=True, inline="always")
def _floor(a0, a1, a2, tail):
    """A lower bound over x in [0, 1] of a0 + a1 x + a2 x^2 + (terms of higher order whose
    negative coefficients sum to ``tail``): the quadratic's exact minimum plus ``tail``."""
    low = min(0.0, a1 + a2)
    if a2 > 0.0 and 0.0 < -a1 < 2.0 * a2:
        low = -a1 * a1 / (4.0 * a2)
    return a0 + low + tail


@njit(cache=True, inline="always")
def _force_floor(k0, k1, wgt, e, neg, pos, rest):
    """A lower bound over the step of k0 + k1 x + wgt theta''(x) (theta'' the polynomial's
    second x-derivative, of coefficients ``e``, ``neg`` and ``pos`` as :func:`_series_spans`
    gives them) plus ``rest`` (the lower bound of the remaining terms)."""
    tail = wgt * neg if wgt >= 0.0 else wgt * pos
    return _floor(k0 + wgt * e[0], k1 + wgt * e[1], wgt * e[2], tail) + rest


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _forces_away(w, n, hs, blk, gr):
    """Whether every force event's g (:func:`rock_force_events`) stays above 0 throughout
    the step, by a bound over it (no evaluation, no sine or cosine).

    With q = R / hs^2, theta' and theta'' the polynomial's x-derivatives, S = sin x and
    C = cos x (x = alpha s - theta; s sin(phi) = S, cos(phi) = C in
    :func:`.slide_rock.contact_forces`), S = S_0 + dS and C = C_0 + dC about their values at
    the step's start (w[ROW_S, 0], w[ROW_C_SERIES, 0]):

    .. math::

       \\mu N \\mp F = [\\mu (g + a_v) \\mp a_h + q (\\mu S_0 \\mp C_0) \\theta'']
       + q \\theta'' (\\mu dS \\mp dC) - q \\theta'^2 (\\mu C \\pm S),

    and N likewise. The bracket, a polynomial in x (the ground linear), is bounded as one
    (:func:`_force_floor`): the ground acceleration and the rotational acceleration it
    drives cancel in it; the rest by intervals (``|dS|``, ``|dC|`` from theta's radius
    about c_0, :func:`_trig_span`; theta'^2 from its range). Each g's lower bound must exceed
    :data:`._demand.BOUND_MARGIN` times the forces' size (the rounding of the evaluations it
    stands for)."""
    c = w[ROW_C]
    r_th, d_lo, d_hi, e, neg, pos = _series_spans(c, n)
    s0, c0 = w[ROW_S, 0], w[ROW_C_SERIES, 0]
    sl, sh = _trig_span(s0, c0, r_th)
    cl, ch = _trig_span(c0, s0, r_th)
    q = blk.radius / (hs * hs)
    wl, wh = _square(d_lo, d_hi)
    wl, wh = q * wl, q * wh  # R theta_dot^2
    rdd = q * (abs(e[0]) + abs(e[1]) + abs(e[2]) + pos - neg)  # >= R |theta_ddot|
    ds, dc = sh - s0, ch - c0  # >= |dS|, |dC|
    a_h0, a_h1, a_v0, a_v1 = gr
    mu = blk.static
    v0, dv, dh = G + a_v0, a_v1 - a_v0, a_h1 - a_h0
    g1 = _force_floor(
        mu * v0 - a_h0,
        mu * dv - dh,
        q * (mu * s0 - c0),
        e,
        neg,
        pos,
        -rdd * (mu * ds + dc) - _product(wl, wh, mu * cl + sl, mu * ch + sh)[1],
    )
    g2 = _force_floor(
        mu * v0 + a_h0,
        mu * dv + dh,
        q * (mu * s0 + c0),
        e,
        neg,
        pos,
        -rdd * (mu * ds + dc) - _product(wl, wh, mu * cl - sh, mu * ch - sl)[1],
    )
    g3 = _force_floor(v0, dv, q * s0, e, neg, pos, -rdd * ds - _product(wl, wh, cl, ch)[1])
    ground = G + max(abs(a_v0), abs(a_v1)) + max(abs(a_h0), abs(a_h1))
    size = BOUND_MARGIN * (1.0 + mu) * (ground + rdd + wh)
    return g3 > size and g1 > size and g2 > size


@njit(cache=True, **NO_REFCOUNT)
def _quiet_forces(c, n, hs, side, blk, gr, g0):
    """Whether no force event can lie inside the step: at its ends and middle (g0 at its
    start) every g is positive and exceeds :data:`FORCE_MARGIN` times its spread there."""
    mu, radius, alpha = blk.static, blk.radius, blk.alpha
    g1 = rock_force_events(c, n, 0.5, hs, side, mu, radius, alpha, gr)
    g2 = rock_force_events(c, n, 1.0, hs, side, mu, radius, alpha, gr)
    for e in range(3):
        lo = min(g0[e], g1[e], g2[e])
        if not lo > FORCE_MARGIN * (max(g0[e], g1[e], g2[e]) - lo):
            return False
    return True


@njit(cache=True, **NO_REFCOUNT)
def _bisect_force(e, c, n, hs, side, blk, gr, lo, hi):
    """The crossing of force event e (> 0 at lo, <= 0 at hi) on the polynomial, by bisection
    to adjacent doubles of unit step time."""
    while True:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            return hi
        g = rock_force_events(c, n, mid, hs, side, blk.static, blk.radius, blk.alpha, gr)[e]
        if g > 0.0:
            lo = mid
        else:
            hi = mid


@njit(cache=True, **NO_REFCOUNT)
def first_force_event(c, n, hs, side, blk, gr, fresh, s_end, prev):
    """(event, unit step time) of the first slip or lift-off before s_end, or (EV_NONE, 2.0).

    On the first step of the regime (``fresh``) a g below 0 at the start is the event, at
    once (a slip right after an impact), and a g of 0 there is taken positive (the regime's
    entry decided it so). Then the step is screened (:func:`_quiet_forces`), and where that
    does not rule a crossing out, g is sampled at :data:`._contact_steps.EVENT_POINTS` and
    the first crossing bisected (``prev``: work space of 3)."""
    g0 = rock_force_events(c, n, 0.0, hs, side, blk.static, blk.radius, blk.alpha, gr)
    for e in range(3):
        prev[e] = g0[e]
        if fresh and g0[e] < 0.0:
            return FORCE_EVENTS[e], 0.0
        if fresh and g0[e] == 0.0:
            prev[e] = 1.0
    if _quiet_forces(c, n, hs, side, blk, gr, g0):
        return cs.EV_NONE, 2.0
    lo = 0.0
    for j in range(cs.EVENT_POINTS):
        x = min(cs.sample_point(j, False), s_end)
        g = rock_force_events(c, n, x, hs, side, blk.static, blk.radius, blk.alpha, gr)
        best, best_x = cs.EV_NONE, 2.0
        for e in range(3):
            if prev[e] > 0.0 and not g[e] > 0.0:
                root = _bisect_force(e, c, n, hs, side, blk, gr, lo, x)
                if root < best_x:
                    best, best_x = FORCE_EVENTS[e], root
            prev[e] = g[e]
        if best != cs.EV_NONE:
            return best, best_x
        lo = x
        if x >= s_end:
            break
    return cs.EV_NONE, 2.0


@njit(cache=True)
def _scales(th, om, hs, p, alpha, tol):
    """The error scales of theta and theta_dot of a Taylor step (the rocking kernels')."""
    sc_x = tol * (ATOL_FRACTION * alpha + abs(th) + abs(om) * hs)
    sc_v = tol * (ATOL_FRACTION * p * alpha + abs(om) + abs(th) * p * p * hs)
    return sc_x, sc_v


@njit(cache=True, **NO_REFCOUNT)
def rock_step(w, prev, blk, gr, th, om, side, hs, tol, fresh):
    """One Taylor step of the rock regime from (th, om) on corner ``side``, of length hs,
    under the ground ``gr`` = (a_h, a_v) at its ends (a_h0, a_h1, a_v0, a_v1) [m/s^2],
    linear between, at the local tolerance ``tol`` (``prev``: work space of 3).

    Returns (outcome, order n, event, unit step time of the event (1.0 if none), unit step
    time of the peak of s theta before it (-1.0 if none), theta and d theta / d sigma at
    the step's end); the polynomial stays in w[0].
    The event is the first of the impact, the fall, a slip and lift-off (EV_NONE if none).
    """
    p = math.sqrt(0.75 * G / blk.radius)
    a_h0, a_h1, a_v0, a_v1 = gr
    sc_x, sc_v = _scales(th, om, hs, p, blk.alpha, tol)
    dd0 = np.nan
    if th == 0.0 and om == 0.0:  # from rest: rise as the initiation test said (_taylor)
        dd0 = sr.rocking_acceleration(0.0, a_h0, a_v0, side, blk.radius, blk.alpha)
    n, err = taylor_coefficients(
        w, th, om, side, p, blk.alpha, MODEL_NONLINEAR, hs, a_h0, a_h1, a_v0, a_v1, sc_x, sc_v, dd0
    )
    if not err <= 1.0:
        return REJECTED, n, cs.EV_NONE, 1.0, -1.0, th, om
    c = w[0]
    th1, dth1, _ = poly_end(c, n)
    ev, s_ev = cs.EV_NONE, 1.0
    s_imp = step_impact(c, n, side, side * th1, side * dth1)
    if s_imp <= 1.0:
        ev, s_ev = cs.EV_IMPACT, s_imp
    elif side * th1 >= FALL_ROTATION:
        ev, s_ev = cs.EV_FALL, poly_root(c, n, side * FALL_ROTATION, -side, OF_VALUE, 0.0, 1.0)
    if not _forces_away(w, n, hs, blk, gr):
        ev_f, s_f = first_force_event(c, n, hs, side, blk, gr, fresh, s_ev, prev)
    else:
        ev_f, s_f = cs.EV_NONE, 2.0
    if s_f <= s_ev:
        ev, s_ev = ev_f, s_f
    du_end = side * (poly_value(c, n, s_ev)[1] if s_ev < 1.0 else dth1)
    s_pk = step_peak(c, n, side, s_ev, du_end)
    return ACCEPTED, n, ev, s_ev, s_pk, th1, dth1
