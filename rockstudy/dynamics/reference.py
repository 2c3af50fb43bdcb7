"""The slow reference path: Housner's rocking block integrated by ``scipy.integrate.solve_ivp``.

Independent of the numba kernels in everything but the model itself: scipy's integrators,
scipy's event location (dense output and Brent's method), uplift times found by Brent's
method on a scan, and free rocking after the excitation integrated, never mapped.
It costs milliseconds per scene and is meant for verification at rtol down to 1e-12.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .._warnings import IncompleteReferenceWarning
from ..constants import FALL_ROTATION, G
from ..motions import Motion, Record
from ._events import _zeno
from ._rocking import (
    MODEL_LINEAR,
    MODEL_TABLE,
    NO_TABLE,
    REST_FRACTION,
    _accel,
    _free_map_table,
    _lift,
    free_rocking_map,
)
from ._vertical import refuse_free_fall

__all__ = ["HOP_POINTS", "simulate_reference"]


def _scalar_vertical(motion: Motion):
    """A plain-Python u_v''(t) [m/s^2, upwards] for the reference path, or None."""
    _, mp, times, _, vsamples = motion.kernel_spec()
    if not vsamples.size:
        return None
    a, dur = abs(mp[0]), mp[3]
    return lambda t: float(np.interp(t, times, vsamples)) * a if 0.0 <= t <= dur else 0.0


def _scalar_acceleration(motion: Motion):
    """A plain-Python u_g''(t) [m/s^2] for the reference path (zero outside the motion)."""
    kind, mp, times, samples, _ = motion.kernel_spec()
    a, w, ph, dur = mp
    if isinstance(motion, Record):
        return lambda t: float(np.interp(t, times, samples)) * a if 0.0 <= t <= dur else 0.0
    if kind == 0:
        return lambda t: a * math.sin(w * t + ph) if 0.0 <= t <= dur else 0.0

    def ricker(t):
        x = (math.pi * w * (t - ph)) ** 2
        return a * (1.0 - 2.0 * x) * math.exp(-x) if 0.0 <= t <= dur else 0.0

    return ricker


def _first_lift(lift, lo, hi):
    """The first double in (lo, hi] at which ``lift`` > 0, where it is not > 0 at lo and is
    at hi: Brent's root narrows the bracket, then bisection to adjacent doubles finds where
    the test switches, the time :func:`._uplift.next_uplift` bisects to."""
    t = brentq(lift, lo, hi, xtol=1e-15)
    if lift(t) > 0.0:
        hi = t
    else:
        lo = t
    while True:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            return hi
        if lift(mid) > 0.0:
            hi = mid
        else:
            lo = mid


def _uplift_time(lift, t0, dur, grid):
    """First t >= t0 at which a block at rest lifts (``lift`` > 0, the kernels' rule
    :func:`._rhs._lift`), by a scan on ``grid`` and :func:`_first_lift`; inf if never."""
    if lift(t0) > 0.0:
        return t0
    pts = np.concatenate([[t0], grid[grid > t0], [dur]])
    for lo, hi in zip(pts[:-1], pts[1:], strict=True):
        if lift(hi) > 0.0:
            return hi if hi <= lo else _first_lift(lift, lo, hi)
    return math.inf


def _equations(p, alpha, model, tab, acc, vert, dur):
    """The lift test lift(t) of a block at rest under the ground just after t (> 0 where it
    lifts: :func:`._rhs._lift`, the rule of every solver, with the still ground from the end
    of the motion on, as :func:`._rhs._ground_after`) and the right-hand side rhs(t, y, s) of
    the model on side s, under the ground acceleration functions acc and vert [m/s^2]."""
    linear = model == MODEL_LINEAR
    table = NO_TABLE if tab is None else tab

    def lift(t):
        if t >= dur:
            return _lift(0.0, 0.0, p, alpha, model, table)
        return _lift(acc(t), vert(t), p, alpha, model, table)

    def rhs(t, y, s):
        if tab is not None:
            return [y[1], _accel(acc(t), vert(t), y[0], y[1], p, alpha, s, MODEL_TABLE, tab)]
        a = acc(t) / G
        gv = 1.0 + vert(t) / G
        if linear:
            return [y[1], p * p * (gv * (y[0] - alpha * s) - a)]
        x = alpha * s - y[0]
        return [y[1], -p * p * (gv * math.sin(x) + a * math.cos(x))]

    return lift, rhs


def _events(s, fall_at, t0, at_trough):
    """The ``solve_ivp`` events of a phase on side s from t0 [s]: the impact (terminal), the
    fall at rotation ``fall_at`` (terminal), the peaks of s theta and its troughs (terminal;
    each also receives s, the ``args`` of the solve).

    scipy looks for an event only where its function changes sign between two step ends, and
    locates it by Brent's method on the step's interpolant. Two consequences are ruled out
    here. A phase that starts at theta = 0 (after an impact or a lift-off) would have its
    impact found at the start itself if the block falls back within the first step: the
    impact function is taken positive at t0 (s theta >= 0 there, and > 0 just after).
    A dip of s theta through zero and back inside one step changes no sign at the step ends
    and would be missed: every trough (s theta_dot from < 0 to > 0) ends the phase, where
    :func:`_dip_impact` checks it (one sign change of theta_dot, which scipy does see). A
    phase that starts at a trough (``at_trough``) takes its trough function positive at t0,
    so that the trough it starts at is not found again."""

    def impact(t_, y, s=s):
        return s * y[0] if t_ > t0 else 1.0

    def fall(t_, y, s=s):
        return s * y[0] - fall_at

    def peak(t_, y, s=s):
        return s * y[1]

    def trough(t_, y, s=s):
        return 1.0 if at_trough and t_ <= t0 else s * y[1]

    impact.terminal, impact.direction = True, -1
    fall.terminal, fall.direction = True, 1
    peak.direction = -1
    trough.terminal, trough.direction = True, 1
    return impact, fall, peak, trough


def _free_map(u, v, s, p, alpha, eta, model, tab):
    """The kernels' free-rocking map from u = s theta, v = s theta_dot on side s: of a block
    (:func:`._free_map.free_rocking_map`) or, with tables, of a mechanism
    (:func:`._tables._free_map_table`). Returns (overturns, peak, impacts until rest)."""
    omega_rest = REST_FRACTION * p * alpha
    if tab is not None:
        side = 0 if s > 0.0 else 1
        return _free_map_table(u, v, eta, tab[side], tab[1 - side], omega_rest)
    return free_rocking_map(u, v, p, alpha, eta, model, omega_rest)


def _ground(motion):
    """The ground accelerations u_h''(t) and u_v''(t) [m/s^2] of a motion as scalar functions
    (u_v'' = 0 without a vertical component); free fall (u_v'' <= -g) is refused."""
    _, mp, _, _, vsamples = motion.kernel_spec()
    refuse_free_fall(vsamples, mp[0])
    return _scalar_acceleration(motion), _scalar_vertical(motion) or (lambda t: 0.0)


def _log_peaks(sol, s, max_u, peaks, before):
    """Append the peaks of a phase's ``solve_ivp`` solution on side s before ``before`` [s]
    (its impact, if any) to ``peaks``; returns max_u [rad] raised to the largest of them."""
    inside = sol.t_events[2] < before
    if np.any(inside):
        u = sol.y_events[2][inside, 0]
        max_u = max(max_u, float(np.max(s * u)))
        peaks.extend(zip(sol.t_events[2][inside], u, strict=True))
    return max_u


def _grids(motion):
    """The times scanned for uplift and those the phases stop at: a record's samples (where
    u_g'' has a kink) for both, or 4097 points over a pulse and no stops."""
    if isinstance(motion, Record):
        grid = np.asarray(motion.time)
        return grid, grid
    return np.linspace(0.0, motion.duration, 4097), None


def _stop_time(t, dur, breaks, t_end, p):
    """Where a phase from t [s] stops: the next record sample (``breaks``) or the motion's end
    ``dur``; after the motion, 100 / p on, at most ``t_end``."""
    if t < dur:
        return dur if breaks is None else breaks[np.searchsorted(breaks, t, side="right")]
    return min(t_end, t + 100.0 / p)


def _solve(rhs, span, y0, s, integrator, rtol, atol, fall_at, at_trough=False):
    """One phase on side s by ``solve_ivp`` over ``span``, with dense output and the events of
    :func:`_events`; a failed solve raises RuntimeError."""
    sol = solve_ivp(
        rhs,
        span,
        y0,
        method=integrator,
        args=(s,),
        rtol=rtol,
        atol=atol,
        events=_events(s, fall_at, span[0], at_trough),
        dense_output=True,
    )
    if sol.status < 0:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol


def _side_after_impact(om_post, s, t, acc, vert, dur, body):
    """The side after an impact at t [s] on side s that left the speed om_post, by the
    kernels' rule (:func:`._events._zeno`: the other side, or below the rest speed at rest
    unless the ground just after t lifts the block, which then restarts on the side it is
    pushed to). ``body`` = (p, alpha, model, table, rest speed). Returns (at rest, side,
    speed)."""
    p, alpha, model, tab, omega_rest = body
    a_g, a_v = (0.0, 0.0) if t >= dur else (acc(t), vert(t))
    at_rest, side, om = _zeno(om_post, s, omega_rest, a_g, a_v, p, alpha, model, tab)
    return bool(at_rest), float(side), float(om)


#: Points of each ``solve_ivp`` step at which the reference looks for s theta < 0 on the dense
#: output: a short hop (down through zero and up again, with a peak before it) inside one step
#: changes the sign of neither theta nor theta_dot between the step's ends, where scipy's
#: events look.
HOP_POINTS = 8


def _impact_of(sol, s, t0):
    """The first impact of a phase from t0 [s] on side s whose solution is ``sol`` (with dense
    output), as (time [s], theta_dot just before it [rad/s]), or None: the first point of
    :data:`HOP_POINTS` a step (and the steps' ends) where s theta < 0, located by Brent's
    method on the interpolant, else scipy's impact event. That covers a dip through zero
    inside one step, found at its trough (:func:`_events`) or at those points."""
    impact = _events(s, 0.0, t0, False)[0]
    t_stop = float(sol.t_events[0][0]) if sol.t_events[0].size else math.inf
    frac = np.arange(1, HOP_POINTS + 1) / HOP_POINTS
    a, b = sol.t[:-1], sol.t[1:]
    pts = (a[:, None] + (b - a)[:, None] * frac).ravel()
    pts = pts[pts < t_stop]
    if pts.size:
        below = np.flatnonzero(s * sol.sol(pts)[0] < 0.0)
        if below.size:
            k = int(below[0])
            lo = float(pts[k - 1]) if k > 0 else t0
            t_imp = brentq(lambda t_: impact(t_, sol.sol(t_)), lo, float(pts[k]), xtol=1e-15)
            return t_imp, float(sol.sol(t_imp)[1])
    if sol.t_events[0].size:
        return t_stop, float(sol.y_events[0][0, 1])
    return None


def _warn_incomplete(max_impacts, t):
    """Warn that the reference stopped at ``max_impacts`` impacts, at t [s]."""
    warnings.warn(
        f"scipy reference: max_impacts={max_impacts} impacts reached at t = {t!r} "
        "s (a chatter it cannot end); the result covers [0, that time] only",
        IncompleteReferenceWarning,
        stacklevel=3,
    )


def simulate_reference(
    p,
    alpha,
    eta,
    motion: Motion,
    model=0,
    rtol=1e-12,
    integrator="DOP853",
    t_max=None,
    initial_state=(0.0, 0.0),
    free_map=False,
    max_impacts=20000,
    t_eval=None,
    table=None,
):
    """Integrate one scene with ``solve_ivp`` and events.

    Parameters
    ----------
    p, alpha, eta : float
        Frequency parameter [rad/s], slenderness [rad] and restitution [-].
    motion : Motion
    model : int
        0 for Housner's nonlinear equation (2.2) of [000], 1 for the linearized (3.1), 2 for
        a tabulated mechanism, eq. (8) of [003] (``table``); a record's vertical component
        u_v'' turns g into g + u_v'' in each (refused where u_v'' <= -g, free fall).
    rtol : float
        Relative tolerance; the absolute tolerances are rtol * alpha and rtol * p * alpha.
    integrator : str
        A ``solve_ivp`` method: "DOP853", "RK45", "LSODA", ...
    t_max : float, optional
        End of the free-rocking tail [s]; by default until rest or overturning.
    initial_state : (float, float)
        theta [rad] and theta_dot [rad/s] at t = 0; (0, 0) starts at rest.
    free_map : bool
        After the motion ends, use the closed-form free-rocking map of the kernels instead of
        integrating (integrating on only if the block overturns). This is the scipy path with
        the same algorithm as the kernels, for a like-for-like timing.
    max_impacts : int
        Cap on the impacts followed; past it the run stops and says so
        (:class:`rockstudy.IncompleteReferenceWarning`): the result covers only its start.
    t_eval : ndarray, optional
        Sorted times [s] at which to return the state, from ``solve_ivp``'s dense output
        (not with ``free_map``): (0, 0) at rest, the state just before an impact at its time,
        NaN after an overturning.
    table : (ndarray, float), optional
        For model 2: the mechanism's tables and collapse amplitude, as returned by
        ``_structure_tables.structure_table``; p and alpha are then its p_eq and phi_cr (they
        set the tolerances) and the overturning is at the collapse amplitude, reported as the
        max rotation.

    Returns
    -------
    dict with keys t, theta, theta_dot, max_rotation, overturned, impact_times, overturn_time,
    peak_times and peak_rotations (the maxima of |theta|, by scipy's event location), and
    with ``t_eval`` also t_eval, theta_eval and theta_dot_eval.
    """
    if free_map and t_eval is not None:
        raise ValueError("t_eval needs the free rocking integrated: free_map=False")
    dense = _Dense(t_eval)
    (acc, vert), dur = _ground(motion), motion.duration
    tab, fall_at = table if model == MODEL_TABLE else (None, FALL_ROTATION)
    omega_rest = REST_FRACTION * p * alpha
    t_end, atol = (math.inf if t_max is None else float(t_max)), [rtol * alpha, rtol * p * alpha]
    grid, breaks = _grids(motion)

    lift, rhs = _equations(p, alpha, model, tab, acc, vert, dur)
    body = (p, alpha, model, NO_TABLE if tab is None else tab, omega_rest)
    th, om = (float(x) for x in initial_state)
    ts, ths, oms, impacts, peaks = [0.0], [th], [om], [], []
    max_u, t = abs(th), 0.0
    at_rest = th == 0.0 and om == 0.0
    mapped = at_trough = False
    s = math.copysign(1.0, th if th != 0.0 else om)
    while True:
        if at_rest:
            lifted = _lift_from_rest(lift, acc, t, dur, grid, (ts, ths, oms, impacts))
            if lifted is None:
                break
            (t, s, at_rest), th, om = lifted, 0.0, 0.0
            if at_rest:
                continue
        if t >= dur and free_map and not mapped:
            mapped = True
            over, peak, n_post = _free_map(s * th, s * om, s, p, alpha, eta, model, tab)
            if not over:
                impacts.extend([math.nan] * n_post)
                return _pack(ts, ths, oms, max(max_u, peak), False, impacts, math.nan, peaks)
        stop = _stop_time(t, dur, breaks, t_end, p)
        if t >= stop:
            break
        sol = _solve(rhs, (t, stop), [th, om], s, integrator, rtol, atol, fall_at, at_trough)
        at_trough = False
        hit = _impact_of(sol, s, t)
        t_cut = math.inf if hit is None else hit[0]
        rows = slice(1, -1 if sol.status == 1 else None)  # an event's row is added below
        rows = np.flatnonzero(sol.t[rows] < t_cut) + 1
        ts.extend(sol.t[rows]), ths.extend(sol.y[0, rows]), oms.extend(sol.y[1, rows])
        max_u = _log_peaks(sol, s, max_u, peaks, t_cut)
        dense.fill(sol.sol, t, min(float(sol.t[-1]), t_cut))
        if sol.t_events[1].size:
            t_ot = float(sol.t_events[1][0])
            ts.append(t_ot), ths.append(s * fall_at), oms.append(sol.y_events[1][0, 1])
            return _pack(ts, ths, oms, fall_at, True, impacts, t_ot, peaks, dense)
        if hit is not None:
            t, om_pre = hit
            om_post = eta * om_pre
            impacts.append(t)
            ts.extend([t, t]), ths.extend([0.0, 0.0]), oms.extend([om_pre, om_post])
            th = 0.0
            at_rest, s, om = _side_after_impact(om_post, s, t, acc, vert, dur, body)
            if not at_rest and len(impacts) >= max_impacts:
                _warn_incomplete(max_impacts, t)
                break
            continue
        t, th, om = float(sol.t[-1]), float(sol.y[0, -1]), float(sol.y[1, -1])
        if sol.t_events[3].size:  # a trough above zero: on from it
            at_trough = True
            ts.append(t), ths.append(th), oms.append(om)
        max_u = max(max_u, s * th)
        if t >= t_end:
            break
    return _pack(ts, ths, oms, max_u, False, impacts, math.nan, peaks, dense)


def _lift_from_rest(lift, acc, t, dur, grid, history):
    """From rest at ``t``: (time, side, still at rest) after the next uplift, its states added
    to ``history`` (ts, ths, oms, impacts); None where the block rests to the end of the
    motion. A lift shorter than an ulp of its time falls straight back, its impact one ulp on
    and a rest there (the kernels' rule, ``._events._impact``)."""
    ts, ths, oms, impacts = history
    t_up = _uplift_time(lift, t, dur, grid)
    if t_up >= dur:
        return None
    ts.append(t_up), ths.append(0.0), oms.append(0.0)
    if lift(np.nextafter(t_up, math.inf)) > 0.0:
        return t_up, (-1.0 if acc(t_up) > 0 else 1.0), False
    t_back = float(np.nextafter(t_up, math.inf))
    impacts.append(t_back), ts.extend([t_back] * 2), ths.extend([0.0] * 2), oms.extend([0.0] * 2)
    return t_back, 1.0, True


class _Dense:
    """Dense output of the reference: the requested times, the states found so far ((0, 0)
    for those in a rest) and the next time to serve."""

    def __init__(self, t_eval):
        self.wanted = t_eval is not None
        self.t = np.asarray(t_eval if self.wanted else [], dtype=float)
        self.y = np.zeros((2, self.t.size))
        self.next = 0

    def fill(self, sol, t0, t1):
        """The requested times in [t0, t1] not yet served, from the interpolant ``sol``."""
        stop = int(np.searchsorted(self.t, t1, side="right"))
        if stop <= self.next:
            return
        inside = np.arange(self.next, stop)
        inside = inside[self.t[inside] >= t0]
        if inside.size:
            self.y[:, inside] = sol(self.t[inside])
        self.next = stop

    def fields(self, t_ot):
        """The dense-output keys of the result; NaN after an overturning at ``t_ot``."""
        if not self.wanted:
            return {}
        y = self.y.copy()
        y[:, self.t > t_ot] = np.nan
        return {"t_eval": self.t, "theta_eval": y[0], "theta_dot_eval": y[1]}


def _pack(ts, ths, oms, max_u, over, impacts, t_ot, peaks, dense=None):
    peaks = np.array(peaks, dtype=float).reshape(-1, 2)
    return {
        "peak_times": peaks[:, 0],
        "peak_rotations": peaks[:, 1],
        **(dense.fields(t_ot) if dense is not None else {}),
        "t": np.asarray(ts),
        "theta": np.asarray(ths),
        "theta_dot": np.asarray(oms),
        "max_rotation": float(max_u),
        "overturned": bool(over),
        "impact_times": np.asarray(impacts),
        "overturn_time": t_ot,
    }
