"""The event-driven kernel of the contact model (private): one scene through every regime of
:mod:`.slide_rock` (rest, slide, rock, slide-rock, flight, with impacts), and a batch of
scenes in parallel.

The scene follows :mod:`.slide_rock_reference` event for event (its transitions are the
same functions of :mod:`.slide_rock`): rest ends where :func:`.slide_rock.leaves_rest` turns
positive, located to the ulp on the motion's monotone pieces; rock (Housner's equation)
under a record or after the motion is stepped by the rocking kernels' Taylor series, its
events located on the step polynomial (:mod:`._contact_taylor`, one call per phase:
:func:`_rock_phase`); the other contact and flight phases are stepped by DOP853
(:mod:`._contact_steps`), and their events (impact, fall, slip, stick, lift-off, landing)
sampled on each step's dense output, located by bisection, then refined on a true step.
Every step stops at each record sample. After the motion the block moves on until it rests
(a stick, or Housner's Zeno rule after an impact) or falls.

A scene's ``status``: 0 (ok), 1 (the step limit: the answer did not converge, e.g. a chatter
that never settles), 3 (no solution: Painleve's paradox, mu_k > 4/3). A batch row whose
status is not 0 must not be used as an answer, nor one whose ``converged`` is False
(:func:`flag_unconverged`: its answer moves by more than 10 rtol at rtol / 100, a
friction decision whose outcome jumps lay within 10 rtol of its threshold, or the row is
ill-conditioned: a twin run with the amplitude moved by 1e-9 moves it by more than 1e4 rtol).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..constants import FALL_ROTATION, G
from ..motions._kernels import KIND_RECORD, segment_index
from . import _contact_steps as cs
from . import _contact_taylor as ct
from . import slide_rock as sr
from ._contact_flag import DECISION_BAND, flag_unconverged, housner_runner, row_runner
from ._contact_rest import _from_flat, _rest
from ._contact_state import (
    S_CLEAN,
    S_FRESH,
    S_H,
    S_REG,
    S_SIDE,
    S_SLIP,
    S_T,
    T_CLOSE,
    T_FIRST_IMPACT,
    T_FIRST_SLIP,
    T_LIFT,
    T_MARGIN,
    T_MAX_THETA,
    T_MAX_U,
    T_N_HIST,
    T_N_IMPACTS,
    T_OVER_TIME,
    T_PEAK_TIME,
    T_STATUS,
    T_STEPS,
    T_TIMES,
    T_U_END,
    Body,
    _enter,
    _flight_slip,
    _log_state,
    _new_tallies,
    _raise_peaks,
    _row,
    _tally_impact,
    _tally_margin,
)
from ._free_map import _rotation_at, _travel_time, free_peak_time, free_rocking_map
from ._sliding import sliding_scene
from ._taylor import poly_value, work_arrays
from ._vertical import refuse_free_fall
from .constants import (
    ATOL_FRACTION,
    MIN_STEP,
    MODEL_NONLINEAR,
    NEVER_AT_REST,
    REST_FRACTION,
    STATUS_MAX_STEPS,
    STEP_GROW_LIMIT,
    STEP_SAFETY,
    STEP_SHRINK_LIMIT,
    TAYLOR_TOL_FRACTION,
    TOL_SAFETY,
)

#: Status of a scene with no solution (Painleve's paradox: slide-rock or an impact with
#: mu_k > 4/3 admits none).
STATUS_NO_SOLUTION = 3
#: Longest step, in units of 1/p: the events are sampled at EVENT_POINTS per step.
STEP_CAP = 0.5
#: Local error target of a step, as a fraction of TOL_SAFETY * rtol. The slip and lift-off
#: events are differences of large contact forces (mu_s N - F), whose zeros move by many
#: times the state's error: at TOL_SAFETY alone, 1 of 300 random pulse scenes erred by
#: 2.8e-9 in max_slide at rtol 1e-10 (a slip 3e-10 s late); at 1e-1 more, none by 1e-9.
CONTACT_TOL_FRACTION = 0.1

#: The fields of a contact batch row: the rocking kernels' row, then the contact outputs.
CONTACT_ROW = np.dtype(
    [
        ("status", "i8"),
        ("max_rotation", "f8"),
        ("overturned", "bool"),
        ("n_impacts", "i8"),
        ("overturn_time", "f8"),
        ("steps", "i8"),
        ("first_impact_time", "f8"),
        ("peak_time", "f8"),
        ("max_slide", "f8"),
        ("residual_slide", "f8"),
        ("first_slip_time", "f8"),
        ("lift_off", "bool"),
        ("converged", "bool"),
        ("decision_margin", "f8"),
        ("close_events", "i8"),
    ]
    + [(f"time_{name}", "f8") for name in sr.REGIMES]
)


@njit(cache=True)
def _start_sliding(blk, st, ta, z, u_dot):
    """Flat on the base with slip velocity u': rest if it is 0, else slide (slide-rock on
    the leading corner where mu_k > tan alpha)."""
    z[1], z[3], z[4] = 0.0, u_dot, 0.0
    if u_dot == 0.0:
        _enter(st, ta, sr.REST, st[S_SIDE], st[S_SLIP])
        return
    s = math.copysign(1.0, u_dot)
    _enter(st, ta, sr.SLIDE if blk.kinetic <= math.tan(blk.alpha) else sr.SLIDE_ROCK, s, s)


@njit(cache=True)
def _impact(blk, st, ta, z, imps):
    """The block on corner st.side lands on the other corner at theta = 0 (the reference's
    ``_impact``): Housner's restitution where its impulse stays in the friction cone, else
    :func:`.slide_rock.corner_impulse`; the Zeno rule below the rest speed. Returns 2 where
    Housner's restitution left it rocking, 1 otherwise, 0 where no impulse exists
    (Painleve's paradox)."""
    R, alpha, side = blk.radius, blk.alpha, st[S_SIDE]
    corner, omega_rest = -side, REST_FRACTION * math.sqrt(0.75 * G / R) * alpha
    u_dot, w = z[3], z[4]
    z[1] = 0.0
    bx, by = sr.centre_velocity(u_dot, 0.0, w, side, R, alpha)
    _tally_impact(ta, imps, st[S_T])
    w_plus = sr.rocking_impact(u_dot, w, side, blk.eta, R, alpha)
    ax, ay = sr.centre_velocity(0.0, 0.0, w_plus, corner, R, alpha)
    p_h, p_v = ax - bx, ay - by
    _tally_margin(ta, blk.static, p_h, p_v)
    if p_v > 0.0 and abs(p_h) <= blk.static * p_v and corner * w_plus > 0.0:
        z[3], z[4] = 0.0, w_plus
        _enter(st, ta, sr.ROCK, corner, st[S_SLIP])
        if abs(w_plus) < omega_rest:  # the Zeno rule
            z[4] = 0.0
            _enter(st, ta, sr.REST, corner, st[S_SLIP])
            return 1
        return 2
    (vx, vy, w_plus), _, stuck = sr.corner_impulse(
        bx, by, w, 0.0, corner, blk.static, blk.kinetic, R, alpha
    )
    if math.isnan(w_plus):
        return 0
    rx, ry = sr.corner_offset(0.0, corner, R, alpha)
    slip_velocity = sr.corner_velocity(vx, vy, w_plus, rx, ry)[0]
    if corner * w_plus > 0.0 and abs(w_plus) >= omega_rest:
        z[4] = w_plus
        z[3] = 0.0 if stuck else slip_velocity
        regime = sr.ROCK if z[3] == 0.0 else sr.SLIDE_ROCK
        _enter(st, ta, regime, corner, math.copysign(1.0, z[3]))
    else:  # lands flat: the rotation stops, the slide goes on
        _start_sliding(blk, st, ta, z, vx)
    return 1


@njit(cache=True)
def _take_off(blk, st, z):
    """From contact at corner st.side to flight: the state of the centre of mass."""
    R, alpha, side = blk.radius, blk.alpha, st[S_SIDE]
    u, theta, u_dot, w = z[0], z[1], z[3], z[4]
    phi = alpha - side * theta
    vx, vy = sr.centre_velocity(u_dot, theta, w, side, R, alpha)
    z[0] = u + side * R * (math.sin(alpha) - math.sin(phi))
    z[1], z[2], z[3], z[4], z[5] = R * math.cos(phi), theta, vx, vy, w
    st[S_REG], st[S_FRESH] = sr.FLIGHT, 1.0


@njit(cache=True)
def _land(blk, st, ta, z, corner, imps):
    """A landing on ``corner``: the corner impact, then rock (it sticks) or slide-rock.
    False where no impulse exists (Painleve's paradox)."""
    R, alpha = blk.radius, blk.alpha
    x_g, theta = z[0], z[2]
    (vx, vy, w), _, stuck = sr.corner_impulse(
        z[3], z[4], z[5], theta, corner, blk.static, blk.kinetic, R, alpha
    )
    if math.isnan(w):
        return False
    rx, ry = sr.corner_offset(theta, corner, R, alpha)
    u_dot = 0.0 if stuck else sr.corner_velocity(vx, vy, w, rx, ry)[0]
    _tally_impact(ta, imps, st[S_T])
    z[0], z[1], z[2] = x_g + rx - corner * R * math.sin(alpha), theta, 0.0
    z[3], z[4], z[5] = u_dot, w, 0.0
    _enter(st, ta, sr.ROCK if u_dot == 0.0 else sr.SLIDE_ROCK, corner, math.copysign(1.0, u_dot))
    return True


@njit(cache=True)
def _stop_corner(blk, mot, st, ta, z, k):
    """Slide-rock whose corner stopped: it sticks (rock) if the rocking forces allow it,
    else it slips the other way."""
    z[3] = 0.0
    a_h, a_v = cs.ground(mot, st[S_T], k)
    R, alpha, side = blk.radius, blk.alpha, st[S_SIDE]
    th_dd = sr.rocking_acceleration(z[1], a_h, a_v, side, R, alpha)
    f_h, f_v = sr.contact_forces(z[1], z[4], th_dd, 0.0, a_h, a_v, side, R, alpha)
    _tally_margin(ta, blk.static, f_h, f_v)
    if abs(f_h) <= blk.static * f_v:
        _enter(st, ta, sr.ROCK, side, st[S_SLIP])
    else:
        _enter(st, ta, sr.SLIDE_ROCK, side, -math.copysign(1.0, f_h))


@njit(cache=True)
def _map_free_rocking(blk, st, ta, z):
    """Housner's free rocking from the impact at st[S_T] to rest, without integration
    (:func:`._free_map.free_rocking_map`): its peak (and time), its impacts, its duration
    (twice the travel time to each peak, :func:`._free_map._travel_time`).

    Exact for the contact model where mu_s >= tan alpha and the half-cycle before this impact
    ran free (after the motion) in rock without a slip or a lift-off, and this impact stuck
    under Housner's restitution: at a given theta the contact forces are affine in the
    energy (theta_dot^2 is, theta_ddot does not depend on it), and every later half-cycle
    passes each theta with less energy, down to none at its peak, where |F| / N =
    (3/4) sin phi cos phi / (1 - (3/4) sin^2 phi) < tan phi <= mu_s and N > 0; so no later
    half-cycle slips or lifts. The impulse ratio of Housner's impact does not depend on the
    speed, so every later impact sticks too."""
    R, alpha, eta = blk.radius, blk.alpha, blk.eta
    p = math.sqrt(0.75 * G / R)
    w = abs(z[4])
    over, peak, n_post = free_rocking_map(
        0.0, w, p, alpha, eta, MODEL_NONLINEAR, REST_FRACTION * p * alpha
    )
    if over or n_post >= NEVER_AT_REST:
        return
    if peak > ta[T_MAX_THETA]:
        dt = free_peak_time(0.0, w, p, alpha, eta, MODEL_NONLINEAR)
        ta[T_MAX_THETA], ta[T_PEAK_TIME] = peak, st[S_T] + dt
    spent, wk = 0.0, w / p
    for _ in range(n_post):
        top = _rotation_at(0.5 * wk * wk, alpha, MODEL_NONLINEAR)
        spent += 2.0 * _travel_time(0.0, wk, top, 0.0, alpha, MODEL_NONLINEAR) / p
        wk *= eta
    ta[T_N_IMPACTS] += n_post
    ta[T_TIMES + sr.ROCK] += spent
    st[S_T] += spent
    z[1], z[4] = 0.0, 0.0
    _enter(st, ta, sr.REST, st[S_SIDE], st[S_SLIP])


@njit(cache=True)
def _transition(ev, blk, mot, st, ta, z, k, imps):
    """The regime after the event ``ev`` at st[S_T] (the state z at it). Returns 2 (fell),
    3 (no solution) or 0 (on). Without a log of impact times (``imps`` empty: a batch), a
    sticking impact after the motion that ends a clean half-cycle (:func:`_map_free_rocking`)
    maps the free rocking to its end."""
    regime, clean = int(st[S_REG]), st[S_CLEAN] > 0.0
    st[S_CLEAN] = 0.0
    if ev == cs.EV_FALL:
        ta[T_OVER_TIME] = st[S_T]
        return 2
    if ev == cs.EV_IMPACT:
        code = _impact(blk, st, ta, z, imps)
        if code == 2 and regime == sr.ROCK and st[S_T] >= mot[1][3]:
            st[S_CLEAN] = 1.0
            if clean and imps.shape[0] == 0 and blk.static >= math.tan(blk.alpha):
                _map_free_rocking(blk, st, ta, z)
        return 3 if code == 0 else 0
    if ev == cs.EV_LAND_POS or ev == cs.EV_LAND_NEG:
        corner = 1.0 if ev == cs.EV_LAND_POS else -1.0
        return 0 if _land(blk, st, ta, z, corner, imps) else 3
    if ev == cs.EV_LIFT:
        ta[T_LIFT] = 1.0
        _take_off(blk, st, z)
    elif ev == cs.EV_SLIP_POS or ev == cs.EV_SLIP_NEG:
        z[3] = 0.0
        _enter(st, ta, sr.SLIDE_ROCK, st[S_SIDE], -1.0 if ev == cs.EV_SLIP_POS else 1.0)
    elif regime == sr.SLIDE:  # the slip stopped
        z[3] = 0.0
        _from_flat(blk, mot, st, ta, z, k)
    else:
        _stop_corner(blk, mot, st, ta, z, k)
    return 0


@njit(cache=True)
def _scales(blk):
    """Absolute error scales of the six states (as fractions of the tolerance): row 0 in
    contact, row 1 in flight."""
    R, a = blk.radius, blk.alpha
    p = math.sqrt(0.75 * G / R)
    sc = np.ones((2, 6))
    sc[0, 0], sc[0, 1], sc[0, 3], sc[0, 4] = R * a, a, p * R * a, p * a
    sc[1, 0], sc[1, 1], sc[1, 2], sc[1, 3], sc[1, 4], sc[1, 5] = (
        R * a,
        R * a,
        a,
        p * R * a,
        p * R * a,
        p * a,
    )
    return sc * ATOL_FRACTION


@njit(cache=True)
def _next_stop(mot, t, k, t_end):
    """Where a step from t must stop: the next record sample or the motion's end (none
    after it), at most t_end."""
    kind, mp, times = mot[0], mot[1], mot[2]
    stop = np.inf
    if t < mp[3]:
        stop = min(times[k + 1], mp[3]) if kind == KIND_RECORD else mp[3]
    return min(stop, t_end)


@njit(cache=True)
def _follow_peaks(rk, mode, st, ta, z, K, z1, hs, s_end, work, found, zp):
    """Raise the tallies to the peaks of s theta inside the step, before s_end."""
    n = cs.peaks(mode, st[S_T], hs, s_end, z, K, z1, work[2], work[5], found)
    for i in range(n):
        t_pk = cs.refine(cs.EV_PEAK, rk, mode, st[S_T], z, K, found[i], hs, zp, work)
        _raise_peaks(ta, t_pk, zp[1], zp[0])


@njit(cache=True)
def _accepted(rk, blk, mot, st, ta, z, K, z1, hs, k, log, work, found, zp):
    """An accepted step: its peaks and first event; the state moves to the step's end or
    to the event, where the regime changes. Returns 0 (on), 2 (fell) or 3 (no solution)."""
    hist = log[0]
    regime = int(st[S_REG])
    mode = (regime, st[S_SIDE], st[S_SLIP], blk, mot, k)
    events = cs.regime_events(regime)
    fresh = st[S_FRESH] > 0.0
    trace = work[5]
    ev, s_ev = cs.first_event(events, mode, st[S_T], hs, z, K, z1, fresh, work[2], trace)
    st[S_FRESH] = 0.0
    if regime == sr.ROCK or regime == sr.SLIDE_ROCK:
        _follow_peaks(rk, mode, st, ta, z, K, z1, hs, s_ev, work, found, zp)
    if ev == cs.EV_NONE:
        ta[T_TIMES + regime] += hs
        st[S_T] += hs
        z[:] = z1
        _log_state(hist, ta, st, blk, z)
        return 0
    t_ev = cs.refine(ev, rk, mode, st[S_T], z, K, s_ev, hs, zp, work)
    z[:] = zp
    return _at_event(ev, t_ev, blk, mot, st, ta, z, k, log, fresh)


@njit(cache=True)
def _at_event(ev, t_ev, blk, mot, st, ta, z, k, log, fresh):
    """The phase in st reached the event ``ev`` at t_ev, with the state z there: its time
    tallied and logged (an event on the first DOP853 step of a regime, ``fresh``, counted: two
    events inside one step, where the sampled events may miss a third one; the Taylor steps
    locate theirs on the step polynomial, as the rocking kernels do), then the regime after
    it (:func:`_transition`). Returns 0 (on), 2 (fell) or 3 (no solution)."""
    hist, regime = log[0], int(st[S_REG])
    if fresh and t_ev > st[S_T]:
        ta[T_CLOSE] += 1.0
    ta[T_TIMES + regime] += t_ev - st[S_T]
    st[S_T] = t_ev
    if ev == cs.EV_FALL:
        side = math.copysign(1.0, z[2]) if regime == sr.FLIGHT else st[S_SIDE]
        u = _flight_slip(blk, z, side) if regime == sr.FLIGHT else z[0]
        _row(hist, ta, t_ev, side * FALL_ROTATION, z[5] if regime == sr.FLIGHT else z[4], u)
        ta[T_U_END] = np.nan
    elif ev != cs.EV_IMPACT:
        _log_state(hist, ta, st, blk, z)
    code = _transition(ev, blk, mot, st, ta, z, k, log[1])
    if code == 0:
        _log_state(hist, ta, st, blk, z)
    return code


@njit(cache=True)
def _rock_phase(blk, mot, st, ta, z, w, log, tol, t_end, k, max_steps):
    """Taylor steps of the rock regime (:func:`_rock_attempt`) while the ground is linear on
    each (a record, or none after the motion), the block rocks (through its impacts), the
    time is below t_end and the steps below ``max_steps``: one call per phase, not per step.
    Returns (0, or 2 fell, 3 no solution, 4 a step below the shortest; the record segment)."""
    rec, code = mot[0] == KIND_RECORD, 0
    while int(st[S_REG]) == sr.ROCK and st[S_T] < t_end and ta[T_STEPS] < max_steps:
        after = st[S_T] >= mot[1][3]
        if rec and not after:
            k = segment_index(mot[2], st[S_T], k)
        if not ct.taylor_rock_applies(mot[0], -1 if after else k):
            break
        code = _rock_attempt(blk, mot, st, ta, z, w, log, tol, t_end, -1 if after else k)
        ta[T_STEPS] += 1.0
        if code >= 2:
            break
    return code, k


@njit(cache=True, inline="always")
def _rock_attempt(blk, mot, st, ta, z, w, log, tol, t_end, k):
    """One attempted Taylor step of the rock regime (:func:`._contact_taylor.rock_step`).
    Returns 0 (on), 1 (rejected), 2 (fell), 3 (no solution), 4 (a step below the shortest)."""
    p = math.sqrt(0.75 * G / blk.radius)
    t = st[S_T]
    t_next = _next_stop(mot, t, k, t_end)
    h = min(st[S_H], STEP_CAP / p)
    last = h >= t_next - t
    hs = t_next - t if last else h
    fresh = st[S_FRESH] > 0.0
    a_h0, a_v0 = cs.ground(mot, t, k)
    a_h1, a_v1 = cs.ground(mot, t + hs, k)
    gr = (a_h0, a_h1, a_v0, a_v1)
    outcome, n, ev, s_ev, s_pk, th1, dth1 = ct.rock_step(
        w[0], w[1], blk, gr, z[1], z[4], st[S_SIDE], hs, tol, fresh
    )
    if outcome == ct.REJECTED:
        if hs * p < MIN_STEP:
            return 4
        st[S_H] = 0.5 * hs
        return 1
    st[S_H] = max(h, 2.0 * hs) if last else 2.0 * hs
    st[S_FRESH] = 0.0
    c = w[0][0]
    if s_pk >= 0.0:
        _raise_peaks(ta, t + s_pk * hs, poly_value(c, n, s_pk)[0], z[0])
    if ev == cs.EV_NONE:
        ta[T_TIMES + sr.ROCK] += hs
        st[S_T] = t_next if last else t + hs
        z[1], z[4] = th1, dth1 / hs
        _log_state(log[0], ta, st, blk, z)
        return 0
    th, dth, _ = poly_value(c, n, s_ev)
    z[1], z[4] = th, dth / hs
    t_ev = t + s_ev * hs
    if ev == cs.EV_IMPACT and t_ev <= t:  # a lift from rest that falls back at once
        t_ev = np.nextafter(t, np.inf)
    return _at_event(ev, t_ev, blk, mot, st, ta, z, k, log, False)


@njit(cache=True)
def _attempt(rk, blk, mot, st, ta, z, K, work, log, tol, t_end, k):
    """One attempted step of the phase in st (rejected: a shorter one next). Returns 0
    (on), 1 (rejected), 2 (fell), 3 (no solution), 4 (a step below the shortest)."""
    regime = int(st[S_REG])
    mode = (regime, st[S_SIDE], st[S_SLIP], blk, mot, k)
    z1, tmp = work[1], work[2]
    p = math.sqrt(0.75 * G / blk.radius)
    t_next = _next_stop(mot, st[S_T], k, t_end)
    h = min(st[S_H], STEP_CAP / p)
    last = h >= t_next - st[S_T]
    hs = t_next - st[S_T] if last else h
    cs.deriv(mode, st[S_T], z, K[0])
    cs.rk_step(rk, mode, st[S_T], z, hs, K, z1, tmp)
    t1 = t_next if last else st[S_T] + hs
    cs.deriv(mode, t1, z1, K[12])
    err = cs.rk_error(rk, K, hs, z, z1, work[6][1 if regime == sr.FLIGHT else 0], tol)
    if not err <= 1.0:  # rejected (NaN: slide-rock without a solution, or a bad step)
        if hs * p < MIN_STEP:
            return 3 if err != err else 4
        shrink = STEP_SHRINK_LIMIT if err != err else STEP_SAFETY * err ** (-0.125)
        st[S_H] = hs * max(STEP_SHRINK_LIMIT, shrink)
        return 1
    grow = STEP_GROW_LIMIT if err == 0.0 else min(STEP_GROW_LIMIT, STEP_SAFETY * err ** (-0.125))
    st[S_H] = max(h, hs * grow) if last else hs * grow
    return _accepted(rk, blk, mot, st, ta, z, K, z1, hs, k, log, work, work[3], work[4])


@njit(cache=True)
def contact_run(blk, mot, rtol, t_max, max_steps, log):
    """One scene of the contact model from rest: ``blk`` a :class:`Body`, ``mot`` =
    (kind, mp, times, samples, vsamples) (:mod:`rockstudy.motions._kernels`), ``rtol``,
    ``t_max`` [s] (inf: until the block rests after the motion or falls), ``max_steps``
    (the most steps; past it the status is 1), ``log`` = (hist, imps): an (n, 4) array for
    the history rows (t, theta, theta_dot, u) and an array for the impact times, of length 0
    for none. Returns (tallies, overturned)."""
    hist = log[0]
    rk = cs.tableau()
    ta, st, z = _new_tallies(), np.zeros(7), np.zeros(6)
    st[S_REG], st[S_SIDE], st[S_SLIP] = sr.REST, 1.0, 1.0
    st[S_H] = 0.01 / math.sqrt(0.75 * G / blk.radius)
    K = np.empty((13, 6))
    n_trace = cs.EVENT_POINTS + len(cs.FRESH_POINTS) + 1
    work = (
        np.empty((13, 6)),
        np.empty(6),
        np.empty(6),
        np.empty(cs.EVENT_POINTS),
        np.empty(6),
        np.empty((n_trace, 2)),
        _scales(blk),
        (work_arrays(), np.empty(3)),
    )
    tol = (CONTACT_TOL_FRACTION * TOL_SAFETY * rtol, TAYLOR_TOL_FRACTION * TOL_SAFETY * rtol)
    rec, k, code = mot[0] == KIND_RECORD, 0, 0
    _row(hist, ta, 0.0, 0.0, 0.0, 0.0)
    while True:
        if int(st[S_REG]) == sr.REST:
            if not _rest(blk, mot, st, ta, z, hist, t_max, k):
                break
            continue
        if st[S_T] >= t_max:
            break
        if ta[T_STEPS] >= max_steps:
            ta[T_STATUS] = STATUS_MAX_STEPS
            break
        if int(st[S_REG]) == sr.ROCK:
            code, k = _rock_phase(blk, mot, st, ta, z, work[7], log, tol[1], t_max, k, max_steps)
            if code >= 2:
                break
            if int(st[S_REG]) != sr.ROCK or st[S_T] >= t_max or ta[T_STEPS] >= max_steps:
                continue
        after = st[S_T] >= mot[1][3]
        if rec and not after:
            k = segment_index(mot[2], st[S_T], k)
        code = _attempt(rk, blk, mot, st, ta, z, K, work, log, tol[0], t_max, -1 if after else k)
        ta[T_STEPS] += 1.0
        if code >= 2:
            break
    if code >= 3:
        ta[T_STATUS] = STATUS_NO_SOLUTION if code == 3 else STATUS_MAX_STEPS
    return ta, code == 2


@njit(cache=True)
def _write(out, i, ta, over):
    """Row i of a contact batch from a scene's tallies."""
    row = out[i]
    row.status = int(ta[T_STATUS])
    row.max_rotation = FALL_ROTATION if over else ta[T_MAX_THETA]
    row.overturned = over
    row.n_impacts = int(ta[T_N_IMPACTS])
    row.overturn_time = ta[T_OVER_TIME] if over else np.nan
    row.steps = int(ta[T_STEPS])
    row.first_impact_time = ta[T_FIRST_IMPACT]
    row.peak_time = ta[T_OVER_TIME] if over else ta[T_PEAK_TIME]
    row.max_slide = ta[T_MAX_U]
    row.residual_slide = np.nan if over else ta[T_U_END]
    row.first_slip_time = ta[T_FIRST_SLIP]
    row.lift_off = ta[T_LIFT] > 0.0
    row.converged = row.status == 0
    row.decision_margin = ta[T_MARGIN]
    row.close_events = int(ta[T_CLOSE])
    row.time_rest = ta[T_TIMES + sr.REST]
    row.time_slide = ta[T_TIMES + sr.SLIDE]
    row.time_rock = ta[T_TIMES + sr.ROCK]
    row.time_slide_rock = ta[T_TIMES + sr.SLIDE_ROCK]
    row.time_flight = ta[T_TIMES + sr.FLIGHT]


@njit(cache=True)
def _sliding_row(out, i, mp, times, samples, vsamples, static, kinetic):
    """Row i of a contact batch for a block that cannot rock (mu_s < tan alpha) under a
    record: the exact sliding kernel (:func:`._sliding.sliding_scene`), nothing integrated."""
    accel, vert = mp[0] * samples, abs(mp[0]) * vsamples
    buf = np.empty((3 * times.shape[0] + 2, 3))
    rows, peak, first, slid = sliding_scene(times, accel, vert, static, kinetic, buf)
    end = max(buf[rows - 1, 0], times[times.shape[0] - 1])
    ta = _new_tallies()
    ta[T_MAX_U], ta[T_FIRST_SLIP], ta[T_U_END] = peak, first, buf[rows - 1, 1]
    ta[T_TIMES + sr.REST], ta[T_TIMES + sr.SLIDE] = end - slid, slid
    _write(out, i, ta, False)


def _make_batch(parallel):
    """:func:`contact_batch_kernel` (parallel over rows) or its one-thread variant."""

    @njit(cache=True, parallel=parallel)
    def batch(p, alpha, eta, static, kinetic, kind, mp, times, samples, vsamples, rtol, max_steps):
        out = np.empty(p.shape[0], CONTACT_ROW)
        for i in prange(p.shape[0]):
            if kind == KIND_RECORD and static[i] < math.tan(alpha[i]):
                _sliding_row(out, i, mp[i], times, samples, vsamples, static[i], kinetic[i])
                continue
            blk = Body(0.75 * G / (p[i] * p[i]), alpha[i], eta[i], static[i], kinetic[i])
            mot = (kind, mp[i], times, samples, vsamples)
            ta, over = contact_run(
                blk, mot, rtol, np.inf, max_steps, (np.empty((0, 4)), np.empty(0))
            )
            _write(out, i, ta, over)
        return out

    return batch


contact_batch_kernel = _make_batch(True)
contact_batch_serial = _make_batch(False)


#: Steps of one scene past which it is flagged (status 1: its answer did not converge).
MAX_STEPS = 2_000_000


def _kernel_motion(motion):
    """A motion's kernel encoding with float arrays; free fall (u_v'' <= -g) refused."""
    kind, mp, times, samples, vsamples = motion.kernel_spec()
    refuse_free_fall(vsamples, mp[0])
    as_float = (np.ascontiguousarray(x, dtype=float) for x in (mp, times, samples, vsamples))
    return (np.int64(kind), *as_float)


def contact_scene(
    radius, alpha, eta, motion, static, kinetic, rtol, t_max=None, max_steps=MAX_STEPS
):
    """One scene of the contact model by the kernel, with its history.

    Returns
    -------
    dict
        status (0 ok, 1 step limit, 3 no solution), t, theta, theta_dot, slide (u [m]),
        max_rotation, overturned, impact count ``n_impacts``, overturn_time, max_slide,
        residual_slide (NaN if overturned), first_slip_time (NaN if it never slips),
        lift_off, regime_times [s], steps, peak_time, first_impact_time.
    """
    mot = _kernel_motion(motion)
    blk = Body(float(radius), float(alpha), float(eta), float(static), float(kinetic))
    end = np.inf if t_max is None else float(t_max)
    hist, imps = np.empty((4096 + 4 * mot[2].size, 4)), np.empty(1024)
    while True:
        ta, over = contact_run(blk, mot, float(rtol), end, int(max_steps), (hist, imps))
        n, n_imp = int(ta[T_N_HIST]), int(ta[T_N_IMPACTS])
        if n <= hist.shape[0] and n_imp <= imps.shape[0]:
            break
        hist, imps = np.empty((max(n, hist.shape[0]), 4)), np.empty(max(n_imp, imps.shape[0]))
    row = np.empty(1, CONTACT_ROW)
    _write(row, 0, ta, over)
    p = math.sqrt(0.75 * G / blk.radius)
    cols = tuple(np.array([x], float) for x in (p, alpha, eta, static, kinetic))
    if t_max is None:  # the batch's flag: the twin runs follow the scene to its end
        motion_rows = (mot[0], mot[1][None, :], *mot[2:])
        runner = row_runner(cols, motion_rows, max_steps, contact_batch_serial)
        housner = housner_runner(cols, motion_rows, max_steps, parallel=False)
        flag_unconverged(row, cols, runner, float(rtol), housner)
    else:
        jumps = row["decision_margin"] < DECISION_BAND * rtol and static > kinetic
        row["converged"] &= ~jumps
    out = {name: row[name][0].item() for name in CONTACT_ROW.names}
    out.update(t=hist[:n, 0], theta=hist[:n, 1], theta_dot=hist[:n, 2], slide=hist[:n, 3])
    out["impact_times"] = imps[:n_imp].copy()
    out["regime_times"] = {name: out.pop(f"time_{name}") for name in sr.REGIMES}
    return out


def contact_batch(
    p, alpha, eta, static, kinetic, motion_rows, rtol, max_steps=MAX_STEPS, parallel=True
):
    """The contact model over rows of scenes, in parallel (``parallel=False``: one thread):
    the exact sliding kernel for a block that cannot rock (mu_s < tan alpha) under a record,
    the event-driven kernel for the others.

    Parameters
    ----------
    p, alpha, eta, static, kinetic : array of float
        Per row: p [rad/s], alpha [rad], Housner's eta, mu_s and mu_k.
    motion_rows : tuple
        (kind, mp, times, samples, vsamples) as :func:`rockstudy.simulate_batch` encodes
        them: one motion kind, mp of shape (rows, 4), the shared record arrays.
    rtol : float
        The relative tolerance.

    Returns
    -------
    numpy structured array of :data:`CONTACT_ROW`, one per row; a row whose ``status`` is
    not 0 did not converge (1) or has no solution (3); a row whose ``converged`` is False
    (:func:`flag_unconverged`) must not be used as an answer at rtol either.
    """
    kind, mp, times, samples, vsamples = motion_rows
    refuse_free_fall(vsamples, mp[:, 0], batch=True)
    cols = (
        np.ascontiguousarray(np.broadcast_to(x, np.shape(p)), dtype=float)
        for x in (p, alpha, eta, static, kinetic)
    )
    cols = tuple(cols)
    arrays = (np.ascontiguousarray(x, dtype=float) for x in (mp, times, samples, vsamples))
    run = contact_batch_kernel if parallel else contact_batch_serial
    motion = (np.int64(kind), *arrays)
    rows = row_runner(cols, motion, max_steps, run)
    out = rows(slice(None), float(rtol))
    housner = housner_runner(cols, motion, max_steps, parallel)
    flag_unconverged(out, cols, rows, float(rtol), housner)
    return out
