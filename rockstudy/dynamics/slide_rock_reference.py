"""The contact model of :mod:`.slide_rock` integrated by ``scipy.integrate.solve_ivp``.

Event-driven: each regime is integrated (DOP853 by default, rtol down to 1e-12) until an
event of that regime, located by scipy (Brent's method on the dense output): the impact,
the fall (|theta| = pi/2), a slip (``|F|`` = mu_s N), a stick (slip velocity 0), a lift-off
(N = 0) or a landing (a corner at the base). Rest is not integrated: its end is found by
Brent's method on ``|u_h''|`` - min(mu_s, tan alpha) g_e. Phases stop at every record sample
(where u_h'' has a kink). The work of the ground and of friction are integrated along
(two more states), the impact losses summed, for the energy balance in ``info``.

The free rocking after the motion follows Housner's Zeno rule of the rocking kernels (a
stuck impact leaving less than 1e-4 p alpha rests the block).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .._warnings import IncompleteReferenceWarning
from ..constants import FALL_ROTATION, G
from . import slide_rock as sr
from .constants import REST_FRACTION
from .reference import _grids, _ground, _uplift_time

__all__ = [
    "HOP_POINTS",
    "simulate_contact_reference",
]


class _Scene:
    """The block, the friction, the ground and the run's controls."""

    def __init__(self, radius, alpha, eta, motion, static, kinetic, rtol, t_max):
        self.radius, self.alpha, self.eta = radius, alpha, eta
        self.half_width = radius * math.sin(alpha)
        self.p = math.sqrt(0.75 * G / radius)
        self.static, self.kinetic = static, kinetic
        (self.acc, self.vert), self.dur = _ground(motion), motion.duration
        self.grid, self.breaks = _grids(motion)
        self.rtol = rtol
        self.t_end = math.inf if t_max is None else float(t_max)
        self.omega_rest = REST_FRACTION * self.p * alpha
        #: the slip speed the solver resolves [m/s]: rtol of the largest speed the ground can
        #: give (its peak acceleration over the motion's duration)
        peak = max(abs(float(self.acc(t))) for t in self.grid[:: max(1, self.grid.size // 4097)])
        self.slip_rest = rtol * peak * self.dur

    def ground(self, t):
        """(u_h'', u_v'') [m/s^2] at t (0 after the motion)."""
        return (self.acc(t), self.vert(t)) if t <= self.dur else (0.0, 0.0)

    def stop(self, t):
        """Where a phase from t stops: the next record sample or the motion's end; after the
        motion 100 / p on, at most t_max."""
        if t < self.dur:
            if self.breaks is None:
                return min(self.dur, self.t_end)
            return min(self.breaks[np.searchsorted(self.breaks, t, side="right")], self.t_end)
        return min(self.t_end, t + 100.0 / self.p)


class _Log:
    """The history (t, theta, theta_dot, u), impacts, regime times and energy terms."""

    def __init__(self):
        self.t, self.theta, self.theta_dot, self.u = [0.0], [0.0], [0.0], [0.0]
        self.impacts, self.losses = [], 0.0
        self.times = dict.fromkeys(sr.REGIMES, 0.0)
        self.max_theta, self.max_u, self.first_slip, self.lift_off = 0.0, 0.0, math.nan, False
        self.sequence, self.impact_losses = [], []

    def row(self, t, theta, theta_dot, u):
        """A history row; the peaks of |theta| and |u| follow it."""
        self.t.append(t), self.theta.append(theta), self.theta_dot.append(theta_dot)
        self.u.append(u)
        self.max_theta = max(self.max_theta, abs(theta))
        self.max_u = max(self.max_u, abs(u))

    def lost(self, energy):
        """An impact's loss of kinetic energy [J/kg]."""
        self.losses += energy
        self.impact_losses.append(energy)

    def spent(self, regime, t0, t1):
        """[t0, t1] spent in ``regime`` (and the first slip, if it slips)."""
        self.times[sr.REGIMES[regime]] += float(t1 - t0)
        if not self.sequence or self.sequence[-1][1] != sr.REGIMES[regime]:
            self.sequence.append((float(t0), sr.REGIMES[regime]))
        if regime in (sr.SLIDE, sr.SLIDE_ROCK) and math.isnan(self.first_slip):
            self.first_slip = t0


def _contact_rhs(scene, regime, side, slip):
    """d/dt of (u, theta, u', theta', work of the ground, friction work) per unit mass."""
    R, alpha, mu = scene.radius, scene.alpha, scene.kinetic

    def rhs(t, y):
        a_h, a_v = scene.ground(t)
        u_dot, theta, theta_dot = y[2], y[1], y[3]
        if regime == sr.SLIDE:
            u_dd, th_dd, normal = sr.sliding_acceleration(a_h, a_v, slip, mu), 0.0, G + a_v
        elif regime == sr.ROCK:
            u_dd, normal = 0.0, 0.0
            th_dd = sr.rocking_acceleration(theta, a_h, a_v, side, R, alpha)
        else:
            if sr.slide_rock_denominator(theta, side, slip, mu, alpha) <= 0.0:
                raise ValueError(
                    f"friction: mu_k = {mu!r} gives slide-rock no solution here (Painleve's "
                    "paradox, possible only for mu_k > 4/3)"
                )
            u_dd, th_dd, normal = sr.slide_rock_accelerations(
                theta, theta_dot, a_h, a_v, side, slip, mu, R, alpha
            )
        vx, vy = sr.centre_velocity(u_dot, theta, theta_dot, side, R, alpha)
        return [u_dot, theta_dot, u_dd, th_dd, -a_h * vx - a_v * vy, mu * normal * abs(u_dot)]

    return rhs


def _forces(scene, regime, side, slip, t, y):
    """(F / m, N / m) in a contact regime at (t, y)."""
    a_h, a_v = scene.ground(t)
    R, alpha = scene.radius, scene.alpha
    theta, theta_dot = y[1], y[3]
    if regime == sr.SLIDE_ROCK:
        u_dd, th_dd, normal = sr.slide_rock_accelerations(
            theta, theta_dot, a_h, a_v, side, slip, scene.kinetic, R, alpha
        )
        return -slip * scene.kinetic * normal, normal
    th_dd = sr.rocking_acceleration(theta, a_h, a_v, side, R, alpha)
    return sr.contact_forces(theta, theta_dot, th_dd, 0.0, a_h, a_v, side, R, alpha)


def _contact_events(scene, regime, side, slip, t0):
    """The events of a contact regime (terminal unless said): impact (s theta down through 0,
    taken positive at t0), fall (s theta = pi/2), stick (sigma u' down through 0), slip
    (mu_s N -+ F down through 0), lift-off (N down through 0), peaks (s theta', not
    terminal) and troughs (s theta' up through 0, where :func:`_dip` looks for a hop
    through theta = 0 inside one step)."""

    def impact(t, y):
        return side * y[1] if t > t0 else 1.0

    def fall(t, y):
        return side * y[1] - FALL_ROTATION

    def stick(t, y):
        return slip * y[2] if t > t0 else 1.0

    def slip_pos(t, y):
        f_h, f_v = _forces(scene, regime, side, slip, t, y)
        return scene.static * f_v - f_h if t > t0 else 1.0

    def slip_neg(t, y):
        f_h, f_v = _forces(scene, regime, side, slip, t, y)
        return scene.static * f_v + f_h if t > t0 else 1.0

    def lift(t, y):
        return _forces(scene, regime, side, slip, t, y)[1] if t > t0 else 1.0

    def peak(t, y):
        return side * y[3]

    def trough(t, y):
        return side * y[3] if t > t0 else 1.0

    events = {"impact": impact, "fall": fall, "stick": stick, "slip+": slip_pos}
    events.update({"slip-": slip_neg, "lift": lift, "peak": peak, "trough": trough})
    for name, event in events.items():
        event.terminal = name != "peak"
        event.direction = 1 if name in ("fall", "trough") else -1
    wanted = {
        sr.SLIDE: ("stick",),
        sr.ROCK: ("impact", "fall", "slip+", "slip-", "lift", "peak", "trough"),
        sr.SLIDE_ROCK: ("impact", "fall", "stick", "lift", "peak", "trough"),
    }[regime]
    return wanted, [events[name] for name in wanted]


#: Points of each step at which :func:`_dip` looks for s theta < 0 (as the rocking reference).
HOP_POINTS = 8


def _dip(sol, side, t0, t_end):
    """The first time in (t0, t_end] at which s theta < 0 on the dense output, at
    :data:`HOP_POINTS` a step, located by Brent's method; None if there is none. A hop down
    through theta = 0 and up again inside one step changes the sign of s theta at no step's
    end, where scipy's impact event looks."""
    a, b = sol.t[:-1], sol.t[1:]
    pts = (a[:, None] + (b - a)[:, None] * (np.arange(1, HOP_POINTS + 1) / HOP_POINTS)).ravel()
    pts = pts[pts <= t_end]
    below = np.flatnonzero(side * sol.sol(pts)[1] < 0.0) if pts.size else pts
    if not below.size:
        return None
    k = int(below[0])
    lo = float(pts[k - 1]) if k > 0 else t0
    return brentq(lambda t: side * sol.sol(t)[1], lo, float(pts[k]), xtol=1e-15)


def _first_event(sol, names):
    """(name, time, state) of the first terminal event of a solve, or None."""
    best = None
    for name, times, states in zip(names, sol.t_events, sol.y_events, strict=True):
        if name != "peak" and times.size and (best is None or times[0] < best[1]):
            best = (name, float(times[0]), states[0])
    return best


class _State:
    """Where the run is: regime, corner ``side``, slip direction ``slip``, time [s] and
    the contact state y = (u, theta, u', theta', work of the ground, friction work) or, in
    flight, (x_G, y_G, theta, x_G', y_G', theta', the same two works)."""

    def __init__(self):
        self.regime, self.side, self.slip, self.t = sr.REST, 1.0, 1.0, 0.0
        self.y = np.zeros(6)
        self.overturn_time = math.nan


def _rtol(scene, n):
    """The relative tolerance given to ``solve_ivp`` for n states: scipy's error norm is the
    root mean square over the states, so that the n states of the contact model would be
    controlled sqrt(n / 2) more loosely than the two of the rocking reference (theta,
    theta_dot) at the same rtol; divided by that, they are controlled alike."""
    return scene.rtol / math.sqrt(n / 2)


def _atol(scene, n):
    """Absolute tolerances of the contact (n = 6) or flight (n = 8) states."""
    R, a, p, r = scene.radius, scene.alpha, scene.p, _rtol(scene, n)
    energy = r * G * R * a
    if n == 6:
        return [r * R * a, r * a, r * p * R * a, r * p * a, energy, energy]
    return [r * R * a, r * R * a, r * a, r * p * R * a, r * p * R * a, r * p * a, energy, energy]


def _solve(scene, rhs, t0, t1, y0, events):
    """One phase by ``solve_ivp`` from t0 to t1 [s] with the phase's events; a failed solve
    raises RuntimeError."""
    sol = solve_ivp(
        rhs,
        (t0, t1),
        y0,
        method=scene.integrator,
        rtol=_rtol(scene, len(y0)),
        atol=_atol(scene, len(y0)),
        events=events,
        dense_output=True,
    )
    if sol.status < 0:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol


def _log_solve(log, sol, until, to_row):
    """The rows of a solve before ``until`` [s] and its peaks (located events) into ``log``;
    ``to_row(y)`` gives (theta, theta_dot, u) of a state."""
    for k in range(1, sol.t.size):
        if sol.t[k] < until:
            log.row(float(sol.t[k]), *to_row(sol.y[:, k]))
    for times, states in zip(sol.t_events, sol.y_events, strict=True):
        for t, y in zip(times, states, strict=True):
            if t < until:
                theta, _, u = to_row(y)
                log.max_theta, log.max_u = max(log.max_theta, abs(theta)), max(log.max_u, abs(u))


def _start_sliding(scene, st, u_dot):
    """Flat on the base with slip velocity u' [m/s]: rest if it is 0, else slide (slide-rock
    on the leading corner where mu_k > tan alpha: the friction's resultant leaves the base)."""
    st.y[1], st.y[2], st.y[3] = 0.0, u_dot, 0.0
    if u_dot == 0.0:
        st.regime = sr.REST
        return
    st.slip = st.side = math.copysign(1.0, u_dot)
    st.regime = sr.SLIDE if scene.kinetic <= math.tan(scene.alpha) else sr.SLIDE_ROCK


def _from_flat(scene, st, t):
    """The regime a flat block at rest (or whose slip just stopped) enters at t."""
    a_h, a_v = scene.ground(t)
    regime, side = sr.initiation_regime(
        a_h, a_v, scene.static, scene.kinetic, scene.radius, scene.alpha
    )
    st.y[1:4] = 0.0
    st.regime, st.side, st.slip = regime, side, side
    if regime == sr.SLIDE and scene.kinetic > math.tan(scene.alpha):
        st.regime = sr.SLIDE_ROCK


def _leave_rest(scene, log, st):
    """From rest at st.t: the next time the block leaves rest and its regime there; False
    where it rests to the end of the motion (the history then ends at the later of st.t and
    the motion's end)."""

    def leaves(t):  # > 0 exactly where initiation_regime is not rest
        a_h, a_v = scene.ground(t)
        return sr.leaves_rest(a_h, a_v, scene.static, scene.radius, scene.alpha)

    t_up = _uplift_time(leaves, st.t, scene.dur, scene.grid)
    if t_up >= min(scene.dur, scene.t_end):
        end = max(st.t, min(scene.dur, scene.t_end))
        log.spent(sr.REST, st.t, end)
        if end > st.t:
            log.row(end, 0.0, 0.0, float(st.y[0]))
        return False
    log.spent(sr.REST, st.t, t_up)
    if t_up > st.t:
        log.row(t_up, 0.0, 0.0, float(st.y[0]))
    st.t = t_up
    _from_flat(scene, st, t_up)
    return True


def _slide_to_rest(scene, log, st):
    """A slide on still ground (after the motion) ends in closed form: the slip velocity v
    falls at mu_k g, so the block stops after ``|v| / (mu_k g)`` having slid ``v |v| /
    (2 mu_k g)``, friction taking its kinetic energy v^2 / 2 [J/kg] (Coulomb's law with N =
    m g). A slip speed below the solver's resolution (:attr:`_Scene.slip_rest`) is taken as
    0: it would carry a slide of ``v^2 / (2 mu_k g)`` made of the integration's error alone.
    True where it stops before the end of the run (st is then at rest), else False."""
    v = float(st.y[2])
    if abs(v) <= scene.slip_rest:
        v = 0.0
    elif scene.kinetic == 0.0:  # a frictionless base: it slides on to the end of the run
        return False
    t_stop = abs(v) / (scene.kinetic * G) if v != 0.0 else 0.0
    if st.t + t_stop > scene.t_end:
        return False
    log.spent(sr.SLIDE, st.t, st.t + t_stop)
    st.t += t_stop
    st.y[0] += 0.5 * v * t_stop
    st.y[5] += 0.5 * v * v
    st.y[1:4] = 0.0
    st.regime = sr.REST
    log.row(st.t, 0.0, 0.0, float(st.y[0]))
    return True


def _contact_phase(scene, log, st):
    """One contact phase (slide, rock or slide-rock) from st to its first event or the next
    stop; returns "end" (the run's end reached), "fall" or "on"."""
    if st.regime == sr.SLIDE and st.t >= scene.dur and _slide_to_rest(scene, log, st):
        return "on"
    stop = scene.stop(st.t)
    if st.t >= stop:
        return "end"
    if st.regime == sr.ROCK:
        _slip_if_unheld(scene, st)
    regime, side, slip = st.regime, st.side, st.slip
    names, events = _contact_events(scene, regime, side, slip, st.t)
    sol = _solve(scene, _contact_rhs(scene, regime, side, slip), st.t, stop, st.y, events)
    hit = _first_event(sol, names)
    t1 = stop if hit is None else hit[1]
    if regime != sr.SLIDE and (hit is None or hit[0] != "impact"):
        t_dip = _dip(sol, side, st.t, t1)
        if t_dip is not None:
            hit, t1 = ("impact", t_dip, sol.sol(t_dip)), t_dip
    _log_solve(log, sol, t1, lambda y: (float(y[1]), float(y[3]), float(y[0])))
    log.spent(regime, st.t, t1)
    if hit is None:
        st.t, st.y = t1, sol.y[:, -1].copy()
        log.row(st.t, float(st.y[1]), float(st.y[3]), float(st.y[0]))
        return "end" if st.t >= scene.t_end else "on"
    name, st.t, st.y = hit[0], hit[1], hit[2].copy()
    if name == "fall":
        log.row(st.t, side * FALL_ROTATION, float(st.y[3]), float(st.y[0]))
        st.overturn_time = st.t
        return "fall"
    if name == "impact":
        st.y[1] = 0.0
        _impact(scene, log, st)
        return "on"
    log.row(st.t, float(st.y[1]), float(st.y[3]), float(st.y[0]))
    if name == "trough":  # above theta = 0: on from it
        return "on"
    if name == "lift":
        log.lift_off = True
        _take_off(scene, st)
    elif name in ("slip+", "slip-"):  # the corner slips against the force it lacks
        st.regime, st.slip, st.y[2] = sr.SLIDE_ROCK, (-1.0 if name == "slip+" else 1.0), 0.0
    elif regime == sr.SLIDE:  # the slip stopped
        _from_flat(scene, st, st.t)
    else:  # slide-rock whose corner stopped: it sticks if the rocking forces allow it
        st.y[2] = 0.0
        f_h, f_v = _forces(scene, sr.ROCK, side, slip, st.t, st.y)
        if abs(f_h) <= scene.static * f_v:
            st.regime = sr.ROCK
        else:
            st.slip = -math.copysign(1.0, f_h)
    return "on"


def _slip_if_unheld(scene, st):
    """Slide-rock, slipping against F, where a block entering rock on corner st.side presses
    on the base (N > 0) with rocking forces outside the friction cone (``|F|`` > mu_s N):
    after an impact whose impulse stayed inside the cone, the forces just after it need
    not (the rock phase's slip events see only crossings after its start). N <= 0 is left
    to the lift-off event."""
    f_h, f_v = _forces(scene, sr.ROCK, st.side, st.slip, st.t, st.y)
    if f_v > 0.0 and abs(f_h) > scene.static * f_v:
        st.regime, st.slip = sr.SLIDE_ROCK, -math.copysign(1.0, f_h)


def _impact(scene, log, st):
    """The block on corner st.side lands on the other corner at theta = 0: Housner's
    restitution where its impulse stays in the friction cone (the new corner sticks),
    else :func:`.slide_rock.corner_impact` (the corner slips, or the block lands flat when
    it would turn back into the base); the Zeno rule of the kernels below omega_rest."""
    R, alpha, side = scene.radius, scene.alpha, st.side
    corner = -side
    u_dot, w = float(st.y[2]), float(st.y[3])
    before = sr.centre_velocity(u_dot, 0.0, w, side, R, alpha)
    energy = sr.kinetic_energy(*before, w, R)
    log.impacts.append(st.t)
    log.row(st.t, 0.0, w, float(st.y[0]))
    w_plus = sr.rocking_impact(u_dot, w, side, scene.eta, R, alpha)
    after = sr.centre_velocity(0.0, 0.0, w_plus, corner, R, alpha)
    p_h, p_v = after[0] - before[0], after[1] - before[1]
    if p_v > 0.0 and abs(p_h) <= scene.static * p_v and corner * w_plus > 0.0:
        st.regime, st.side, st.y[2], st.y[3] = sr.ROCK, corner, 0.0, w_plus
        if abs(w_plus) < scene.omega_rest:  # the Zeno rule
            st.regime, st.y[3] = sr.REST, 0.0
    else:
        (vx, vy, w_plus), _, stuck = sr.corner_impact(
            *before, w, 0.0, corner, scene.static, scene.kinetic, R, alpha
        )
        slip_velocity = sr.corner_velocity(vx, vy, w_plus, *sr.corner_offset(0.0, corner, R, alpha))
        if corner * w_plus > 0.0 and abs(w_plus) >= scene.omega_rest:
            st.side, st.y[3] = corner, w_plus
            st.y[2] = 0.0 if stuck else slip_velocity[0]
            st.regime = sr.ROCK if st.y[2] == 0.0 else sr.SLIDE_ROCK
            st.slip = math.copysign(1.0, st.y[2])
        else:  # lands flat: the rotation and the fall stop, the slide goes on
            _start_sliding(scene, st, vx)
    after = sr.centre_velocity(float(st.y[2]), 0.0, float(st.y[3]), st.side, R, alpha)
    log.lost(energy - sr.kinetic_energy(*after, float(st.y[3]), R))
    log.row(st.t, 0.0, float(st.y[3]), float(st.y[0]))


def _take_off(scene, st):
    """From contact at corner st.side to flight: the state of the centre of mass."""
    R, alpha, side = scene.radius, scene.alpha, st.side
    u, theta, u_dot, w, work, friction = (float(x) for x in st.y)
    phi = alpha - side * theta
    x_g = u + side * scene.half_width - side * R * math.sin(phi)
    vx, vy = sr.centre_velocity(u_dot, theta, w, side, R, alpha)
    st.y = np.array([x_g, R * math.cos(phi), theta, vx, vy, w, work, friction])
    st.regime = sr.FLIGHT


def _flight_slip(scene, y, side):
    """u [m] of a block in flight: x_c - s b of the corner s = sign(theta) (``side`` at 0)."""
    corner = math.copysign(1.0, y[2]) if y[2] != 0.0 else side
    phi = scene.alpha - corner * y[2]
    return y[0] + corner * scene.radius * math.sin(phi) - corner * scene.half_width


def _flight_rhs(scene):
    """d/dt of the flight state: the centre of mass falls freely in the ground's frame
    (x_G'' = -u_h'', y_G'' = -(g + u_v'')), theta_dot is constant; the ground's work."""

    def rhs(t, y):
        a_h, a_v = scene.ground(t)
        return [y[3], y[4], y[5], -a_h, -(G + a_v), 0.0, -a_h * y[3] - a_v * y[4], 0.0]

    return rhs


def _flight_events(scene, t0):
    """Landing on the + and - corners (the corner's height down through 0, taken positive at
    t0) and the fall (|theta| up through pi/2)."""

    def landing(corner):
        def event(t, y):
            if t <= t0:
                return 1.0
            return y[1] - scene.radius * math.cos(scene.alpha - corner * y[2])

        event.terminal, event.direction = True, -1
        return event

    def fall(t, y):
        return abs(y[2]) - FALL_ROTATION

    fall.terminal, fall.direction = True, 1
    return ("land+", "land-", "fall"), [landing(1.0), landing(-1.0), fall]


def _flight_phase(scene, log, st):
    """Free flight from st to a landing (a corner impact, :func:`.slide_rock.corner_impact`),
    the fall or the next stop."""
    stop = scene.stop(st.t)
    if st.t >= stop:
        return "end"
    names, events = _flight_events(scene, st.t)
    sol = _solve(scene, _flight_rhs(scene), st.t, stop, st.y, events)
    hit = _first_event(sol, names)
    t1 = stop if hit is None else hit[1]
    side = st.side
    _log_solve(log, sol, t1, lambda y: (float(y[2]), float(y[5]), _flight_slip(scene, y, side)))
    log.spent(sr.FLIGHT, st.t, t1)
    st.t, st.y = (t1, sol.y[:, -1].copy()) if hit is None else (hit[1], hit[2].copy())
    y = st.y
    log.row(st.t, float(y[2]), float(y[5]), _flight_slip(scene, y, side))
    if hit is None:
        return "end" if st.t >= scene.t_end else "on"
    if hit[0] == "fall":
        st.overturn_time = st.t
        return "fall"
    _land(scene, log, st, 1.0 if hit[0] == "land+" else -1.0)
    return "on"


def _land(scene, log, st, corner):
    """A landing on ``corner``: the corner impact, then rock (it sticks) or slide-rock."""
    R, alpha = scene.radius, scene.alpha
    x_g, _, theta, vx, vy, w, work, friction = (float(v) for v in st.y)
    energy = sr.kinetic_energy(vx, vy, w, R)
    (vx, vy, w), _, stuck = sr.corner_impact(
        vx, vy, w, theta, corner, scene.static, scene.kinetic, R, alpha
    )
    rx, ry = sr.corner_offset(theta, corner, R, alpha)
    u_dot = 0.0 if stuck else sr.corner_velocity(vx, vy, w, rx, ry)[0]
    u = x_g + rx - corner * scene.half_width
    log.impacts.append(st.t)
    log.lost(energy - sr.kinetic_energy(vx, vy, w, R))
    st.y = np.array([u, theta, u_dot, w, work, friction])
    st.side, st.slip = corner, math.copysign(1.0, u_dot)
    st.regime = sr.ROCK if u_dot == 0.0 else sr.SLIDE_ROCK
    log.row(st.t, theta, w, u)


def _energy(scene, st):
    """The energy balance per unit mass [J/kg] at the end of the run (the state st)."""
    R, alpha = scene.radius, scene.alpha
    if st.regime == sr.FLIGHT:
        _, y_g, _, vx, vy, w, work, friction = (float(v) for v in st.y)
    else:
        _, theta, u_dot, w, work, friction = (float(v) for v in st.y)
        vx, vy = sr.centre_velocity(u_dot, theta, w, st.side, R, alpha)
        y_g = R * math.cos(alpha - st.side * theta)
    return {
        "ground_work": work,
        "kinetic": sr.kinetic_energy(vx, vy, w, R),
        "potential_change": G * (y_g - R * math.cos(alpha)),
        "friction_work": friction,
    }


def simulate_contact_reference(
    radius,
    slenderness,
    restitution,
    motion,
    static,
    kinetic=None,
    rtol=1e-12,
    integrator="DOP853",
    t_max=None,
    max_phases=200_000,
    initial_state=(0.0, 0.0),
):
    """One scene of the contact model (:mod:`.slide_rock`) by ``solve_ivp`` with events.

    Parameters
    ----------
    radius, slenderness, restitution : float
        Half-diagonal R [m], slenderness alpha [rad] and Housner's restitution eta [-] of
        the rectangular block.
    motion : Motion
        The ground motion (a record's vertical component acts as g + u_v'').
    static, kinetic : float
        mu_s and mu_k (default mu_s), 0 <= mu_k <= mu_s.
    rtol : float
        Relative tolerance of ``solve_ivp``; absolute ones scale with alpha, R and p.
    integrator : str
        A ``solve_ivp`` method ("DOP853", "Radau", ...).
    t_max : float, optional
        End of the history [s]; by default until the block rests after the motion (or
        100 / p past the motion's end per free phase).
    initial_state : (float, float)
        theta [rad] and theta_dot [rad/s] at t = 0, rocking on the corner sign(theta) (or
        sign(theta_dot) at theta = 0) without slip; (0, 0) starts at rest.
    max_phases : int
        Cap on the phases (events) followed; past it the run stops with an
        :class:`~rockstudy.IncompleteReferenceWarning`.

    Returns
    -------
    dict
        t, theta, theta_dot, slide (the slip u [m]), max_rotation, overturned,
        impact_times, overturn_time, max_slide, residual_slide (NaN if overturned),
        first_slip_time (NaN if it never slips), lift_off, regime_times [s],
        regime_sequence (the (start time, regime) of each change of regime) and energy
        (ground_work, kinetic (its change), potential_change, friction_work, impact_losses
        [J/kg] and each_impact_loss, per impact, in time order).
    """
    kinetic = static if kinetic is None else kinetic
    scene = _Scene(radius, slenderness, restitution, motion, static, kinetic, rtol, t_max)
    scene.integrator = integrator
    log, st = _Log(), _State()
    theta, theta_dot = (float(x) for x in initial_state)
    if theta != 0.0 or theta_dot != 0.0:
        st.regime, st.side = sr.ROCK, math.copysign(1.0, theta if theta != 0.0 else theta_dot)
        st.y[1], st.y[3] = theta, theta_dot
        log.theta[0], log.theta_dot[0], log.max_theta = theta, theta_dot, abs(theta)
    initial = _energy(scene, st)
    outcome = "on"
    for _ in range(max_phases):
        if st.regime == sr.REST:
            if st.t >= min(scene.dur, scene.t_end) or not _leave_rest(scene, log, st):
                outcome = "end"
                break
            continue
        phase = _flight_phase if st.regime == sr.FLIGHT else _contact_phase
        outcome = phase(scene, log, st)
        if outcome != "on":
            break
    else:
        warnings.warn(
            f"contact reference: max_phases={max_phases} reached at t = {st.t!r} s; the "
            "result covers [0, that time] only",
            IncompleteReferenceWarning,
            stacklevel=2,
        )
    return _pack(scene, log, st, outcome == "fall", initial)


def _pack(scene, log, st, overturned, initial):
    """The result dict of a run (see :func:`simulate_contact_reference`)."""
    u = np.asarray(log.u)
    energy = {**_energy(scene, st), "impact_losses": log.losses}
    energy["kinetic"] -= initial["kinetic"]
    energy["potential_change"] -= initial["potential_change"]
    energy["each_impact_loss"] = np.asarray(log.impact_losses)
    return {
        "t": np.asarray(log.t),
        "theta": np.asarray(log.theta),
        "theta_dot": np.asarray(log.theta_dot),
        "slide": u,
        "max_rotation": FALL_ROTATION if overturned else log.max_theta,
        "overturned": overturned,
        "impact_times": np.asarray(log.impacts),
        "overturn_time": st.overturn_time,
        "max_slide": log.max_u,
        "residual_slide": math.nan if overturned else float(u[-1]),
        "first_slip_time": log.first_slip,
        "lift_off": log.lift_off,
        "regime_times": dict(log.times),
        "regime_sequence": list(log.sequence),
        "energy": energy,
    }
