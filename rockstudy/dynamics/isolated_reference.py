"""The ``solve_ivp`` reference of a block on an isolated base (the scipy path).

The regimes and equations are those of :mod:`rockstudy.dynamics.isolated` (Vassiliou & Makris
2012): rest (the isolated mass on its spring and dashpot), rocking on either side of the moving
base, impacts with momentum exchange, overturning. Each regime is integrated by
``solve_ivp`` (DOP853) with events: the uplift (the base's absolute acceleration at rest
passing g tan(alpha)), the impact (theta = 0), the overturning (``|theta|`` = pi/2) and the
peaks of ``|x_b|`` and ``|theta|``. Phases stop at every sample of a record (where u_g'' has a
kink) and at the end of the motion. The friction pendulum's stop and break-away end phases
too. It keeps the whole history; the batches run the numba kernel of the same model
(:mod:`._isolated_scene`), which this reference checks.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from .. import _validate
from .._warnings import IncompleteReferenceWarning
from ..constants import FALL_ROTATION, G
from ..motions import Motion, Record
from ..structures.isolated import IsolatedBlock
from ._isolated_model import (
    base_acceleration,
    demand,
    lift_side,
    row_parameters,
    settled,
    slide_after_jump,
    slide_after_stop,
)
from .constants import REST_FRACTION
from .isolated import IsolatedBody, accelerations, impact_velocities, settling_velocity
from .isolated_result import IsolatedResult
from .reference import _first_lift, _ground

__all__ = ["ISOLATED_METHODS", "MAX_IMPACTS", "absolute_tolerances", "simulate_isolated"]

#: The ``simulate`` methods an IsolatedBlock takes: all run this ``solve_ivp`` reference.
ISOLATED_METHODS = ("nonlinear", "scipy", "auto")
#: Impacts followed before the reference stops (and says so).
MAX_IMPACTS = 20000


@dataclass
class _Scene:
    """What every phase needs: the body, the ground u_g''(t), where phases stop, tolerances."""

    body: IsolatedBody
    acc: object
    duration: float
    breaks: np.ndarray | None
    rtol: float
    atol: np.ndarray  # for (x_b, x_b', theta, theta')
    t_end: float  # t_max, or the tail cap
    t_max_given: bool
    omega_rest: float
    par: np.ndarray  # the kernel's parameter vector (:func:`._isolated_model.row_parameters`)

    def ground(self, t):
        """u_g''(t) [m/s^2], 0 after the motion."""
        return self.acc(t) if t <= self.duration else 0.0

    def stop(self, t):
        """Where a phase from t [s] stops: the next record sample or the motion's end, then
        ``t_end``."""
        if t < self.duration:
            if self.breaks is None:
                return self.duration
            return float(self.breaks[np.searchsorted(self.breaks, t, side="right")])
        return self.t_end


@dataclass
class _Log:
    """The history, the events and the dense-output segments of a run."""

    rows: list = field(default_factory=list)  # (t, x_b, x_b', theta, theta')
    impacts: list = field(default_factory=list)
    uplifts: list = field(default_factory=list)
    segments: list = field(default_factory=list)  # (t0, t1, state(t) -> 4 values)
    max_x: float = 0.0
    max_theta: float = 0.0

    def add(self, t, state):
        self.rows.append((t, *state))
        self.max_x = max(self.max_x, abs(state[0]))
        self.max_theta = max(self.max_theta, abs(state[2]))

    def add_solution(self, sol, t_cut, rest, true_state):
        """The steps of ``sol`` before t_cut [s] (an event's row is added by the caller) and
        the peaks its non-terminal events located, valued by ``true_state(t)``
        (:func:`_true_state`); its dense output as a segment."""
        for t, y in zip(sol.t[1:], sol.y.T[1:], strict=True):
            if t < t_cut:
                self.add(t, (y[0], y[1], 0.0, 0.0) if rest else y)
        for t in sol.t_events[-1 if rest else -2]:
            if t <= t_cut:
                self.max_x = max(self.max_x, abs(true_state(t)[0]))
        if not rest:
            for t in sol.t_events[-1][sol.t_events[-1] <= t_cut]:
                self.max_theta = max(self.max_theta, abs(true_state(t)[2]))
        dense = sol.sol
        if rest:

            def dense(t, f=sol.sol):
                x = f(t)
                return np.array([x[0], x[1], 0.0 * x[0], 0.0 * x[0]])

        self.segments.append((float(sol.t[0]), min(float(sol.t[-1]), t_cut), dense))


def _event(fun, terminal, direction):
    fun.terminal, fun.direction = terminal, direction
    return fun


def _solve(scene, rhs, t0, t1, y0, events, atol):
    sol = solve_ivp(
        rhs,
        (t0, t1),
        y0,
        method="DOP853",
        rtol=scene.rtol,
        atol=atol,
        events=events,
        dense_output=True,
    )
    if sol.status < 0:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol


def _true_state(scene, rhs, sol, t, atol):
    """The state at t [s] integrated from the last step of ``sol`` before t (DOP853 steps
    from there, not the dense output: at rtol 1e-12 the interpolant errs ~10 times more
    than the steps, and the peaks and impacts are read here)."""
    i = max(int(np.searchsorted(sol.t, t, side="left")) - 1, 0)
    t0 = float(sol.t[i])
    if not t > t0:
        return sol.y[:, i]
    run = solve_ivp(
        rhs, (t0, t), sol.y[:, i], "DOP853", rtol=scene.rtol, atol=atol, first_step=t - t0
    )
    return run.y[:, -1]


def _lifted(scene, t, x, xd, slide):
    """The side a block at rest lifts onto at t [s] with the base at (x_b, x_b') (0: stays);
    a stuck base moves with the ground."""
    return lift_side(x, xd, scene.ground(t), slide, scene.par)


def _x_event(scene, side, slide, t0):
    """The event of the base in a phase from t0 [s]: a linear isolator's turning points
    (``|x_b|``'s peaks, non-terminal); a friction pendulum's stop (x_b' back to 0 against
    the sliding; its function taken as 1 at t0, as the impact's) or break-away (the friction
    the stuck base needs past mu g), terminal."""
    mu = scene.body.mu
    if mu == 0.0:
        return _event(lambda t_, y: y[1], False, 0.0)
    if slide != 0.0:
        return _event(lambda t_, y: 1.0 if t_ == t0 else slide * y[1], True, -1.0)

    def excess(t_, y):
        th, thd = (y[2], y[3]) if side != 0.0 else (0.0, 0.0)
        return abs(demand(np.array([y[0], 0.0, th, thd]), scene.ground(t_), side, scene.par)) - (
            mu * G
        )

    return _event(excess, True, 1.0)


def _new_slide(scene, t, y, which_side, slide):
    """The base's regime after its stop (``slide`` != 0: :func:`slide_after_stop`) or its
    break-away (it slides off in the direction of the friction it needs) at (t, y)."""
    state = np.array([y[0], 0.0, *(y[2:4] if len(y) > 2 else (0.0, 0.0))])
    if slide != 0.0:
        return slide_after_stop(state, scene.ground(t), which_side, scene.par)
    return math.copysign(1.0, demand(state, scene.ground(t), which_side, scene.par))


def _rest_phase(scene, log, t, x, xd, slide):
    """The block at rest from t until it lifts, the base stops or breaks away (a friction
    pendulum) or the phase stops: returns (t, x_b, x_b', side, slide), side 0 if it still
    rests at the phase's end."""
    body, limit = scene.body, G * math.tan(scene.body.slenderness)

    def rhs(t_, y):
        xdd = accelerations(y[0], y[1], 0.0, 0.0, scene.ground(t_), 0.0, slide, *body.core)[0]
        return [y[1], xdd]

    def a_b(t_, y):
        return base_acceleration(y[0], y[1], scene.ground(t_), slide, scene.par)

    events = [
        _event(lambda t_, y: a_b(t_, y) + limit, True, -1.0),  # lifts onto the positive pivot
        _event(lambda t_, y: a_b(t_, y) - limit, True, 1.0),  # onto the negative one
        _x_event(scene, 0.0, slide, t),
    ]
    sol = _solve(scene, rhs, t, _rest_window(scene, t), [x, xd], events, scene.atol[:2])

    def true_state(t_):
        return _true_state(scene, rhs, sol, t_, scene.atol[:2])

    hits = [(float(sol.t_events[i][0]), i) for i in (0, 1) if sol.t_events[i].size]
    if events[2].terminal and sol.t_events[2].size:
        hits.append((float(sol.t_events[2][0]), 2))
    if not hits:
        log.add_solution(sol, math.inf, True, true_state)
        return float(sol.t[-1]), float(sol.y[0, -1]), float(sol.y[1, -1]), 0.0, slide
    t_hit, which = min(hits)
    if which == 2:  # the friction pendulum's base stops or breaks away
        y = [float(v) for v in true_state(t_hit)]
        log.add_solution(sol, t_hit, True, true_state)
        y[1] = 0.0 if slide != 0.0 else y[1]
        log.add(t_hit, (y[0], y[1], 0.0, 0.0))
        return t_hit, y[0], y[1], 0.0, _new_slide(scene, t_hit, y, 0.0, slide)
    t_up = _first_lift_time(scene, sol, t_hit, slide)
    log.add_solution(sol, t_up, True, true_state)
    x, xd = sol.sol(t_up)
    log.add(t_up, (x, xd, 0.0, 0.0))
    log.uplifts.append(t_up)
    return t_up, float(x), float(xd), _lifted(scene, t_up, x, xd, slide), slide


def _first_lift_time(scene, sol, t_event, slide):
    """The first double at which the block at rest lifts (on the dense output), at or just
    after the event's root ``t_event``: the bracket from the step before it, then bisection
    to adjacent doubles (:func:`.reference._first_lift`)."""

    def lift(t):
        return 1.0 if _lifted(scene, t, *sol.sol(t), slide) else -1.0

    hi, ulp = t_event, math.ulp(t_event)
    while lift(hi) < 0.0:
        hi += ulp
        ulp *= 2.0
    below = sol.t[sol.t < t_event]
    lo = float(below[-1]) if below.size else float(sol.t[0])
    return hi if lift(lo) > 0.0 else _first_lift(lift, lo, hi)


def _rest_window(scene, t):
    """Where a rest phase from t [s] stops: after the motion without t_max, one isolator period
    on (then :func:`_settled` decides whether to go on)."""
    end = scene.stop(t)
    if t >= scene.duration and not scene.t_max_given:
        end = min(end, t + 2.0 * math.pi / scene.body.omega)
    return end


def _rocking_events(scene, side, slide, t0):
    """The impact (theta back to 0, terminal), the overturning (``|theta|`` = pi/2, terminal),
    and the peaks of ``|x_b|`` and of ``|theta|`` (non-terminal) of a rocking phase on
    ``side`` from t0 [s].
    A phase starts at theta = 0 (after an uplift or an impact) and side theta grows first, so
    the impact's function is taken as 1 at t0: Brent's method, which scipy runs on the step's
    dense output, then finds the return to 0 after a short hop inside the first step rather
    than t0 itself (a root there too)."""
    return [
        _event(lambda t_, y: 1.0 if t_ == t0 else side * y[2], True, -1.0),
        _event(lambda t_, y: side * y[2] - FALL_ROTATION, True, 1.0),
        _x_event(scene, side, slide, t0),
        _event(lambda t_, y: y[3], False, -side),
    ]


def _newton_hit(rhs, t, y, which, side):
    """The impact (which 0: theta = 0) or the overturning (1: theta = s pi/2) at (t, y), the
    true state near the located root, after one Newton correction of its time."""
    target = 0.0 if which == 0 else side * FALL_ROTATION
    f = rhs(t, y)
    dl = -(y[2] - target) / y[3] if y[3] != 0.0 else 0.0
    return t + dl, [float(v + d * dl) for v, d in zip(y, f, strict=True)]


def _rock_phase(scene, log, t, y, side, slide):
    """The block rocking on ``side`` from t [s] with y = (x_b, x_b', theta, theta'), the
    base sliding in the direction ``slide`` (0: stuck), until an impact, the overturning, the
    base's stop or break-away (a friction pendulum) or the phase's end. Returns (t, y, side,
    slide, what happened): "impact" (y after it; side 0 if the block settled),
    "overturned", "slide" or "end"."""
    body = scene.body

    def rhs(t_, s):
        xdd, thdd = accelerations(s[0], s[1], s[2], s[3], scene.ground(t_), side, slide, *body.core)
        return [s[1], xdd, s[3], thdd]

    events = _rocking_events(scene, side, slide, t)
    sol = _solve(scene, rhs, t, scene.stop(t), y, events, scene.atol)

    def true_state(t_):
        return _true_state(scene, rhs, sol, t_, scene.atol)

    ends = (0, 1, 2) if events[2].terminal else (0, 1)
    hits = [(float(sol.t_events[i][0]), i) for i in ends if sol.t_events[i].size]
    if not hits:
        log.add_solution(sol, math.inf, False, true_state)
        return float(sol.t[-1]), [float(v) for v in sol.y[:, -1]], side, slide, "end"
    t_hit, which = min(hits)
    if which == 2:
        y_hit = [float(v) for v in true_state(t_hit)]
        log.add_solution(sol, t_hit, False, true_state)
        y_hit[1] = 0.0 if slide != 0.0 else y_hit[1]
        log.add(t_hit, y_hit)
        return t_hit, y_hit, side, _new_slide(scene, t_hit, y_hit, side, slide), "slide"
    t_hit, y_hit = _newton_hit(rhs, t_hit, true_state(t_hit), which, side)
    log.add_solution(sol, t_hit, False, true_state)
    if which == 1:
        y_hit[2] = side * FALL_ROTATION
        log.add(t_hit, y_hit)
        return t_hit, y_hit, side, slide, "overturned"
    y_hit[2] = 0.0
    log.add(t_hit, y_hit)
    log.impacts.append(t_hit)
    xd, thd = impact_velocities(y_hit[1], y_hit[3], body)
    if abs(thd) < scene.omega_rest:  # the impacts have died out: at rest on the base
        xd, thd, side = settling_velocity(xd, thd, body), 0.0, 0.0
    else:
        side = -side
    after = [y_hit[0], xd, 0.0, thd]
    log.add(t_hit, after)
    slide = slide_after_jump(np.array(after), scene.ground(t_hit), side, scene.par)
    return t_hit, after, side, slide, "impact"


def _run(scene, log, y, side):
    """The phases from t = 0 until the end: returns (overturn time or NaN, complete)."""
    t = 0.0
    log.add(t, y)
    slide = slide_after_stop(np.array(y, dtype=float), scene.ground(0.0), side, scene.par)
    while True:
        if side == 0.0:
            if (
                t >= scene.duration
                and not scene.t_max_given
                and settled(np.array(y, dtype=float), slide, log.max_x, scene.par)
            ):
                return math.nan, True
            if t >= scene.t_end:
                return math.nan, scene.t_max_given
            side = _lifted(scene, t, y[0], y[1], slide)
            if side == 0.0:
                t, x, xd, side, slide = _rest_phase(scene, log, t, y[0], y[1], slide)
                y = [x, xd, 0.0, 0.0]
                continue
            if not log.uplifts or log.uplifts[-1] != t:
                log.uplifts.append(t)
        if t >= scene.t_end:
            return math.nan, scene.t_max_given
        t, y, side, slide, what = _rock_phase(scene, log, t, y, side, slide)
        if what == "overturned":
            return t, True
        if len(log.impacts) >= MAX_IMPACTS:
            warnings.warn(
                f"isolated block: {MAX_IMPACTS} impacts reached at t = {t!r} s; the result "
                "covers [0, that time] only",
                IncompleteReferenceWarning,
                stacklevel=4,
            )
            return math.nan, False


def absolute_tolerances(structure: IsolatedBlock, motion: Motion, rtol: float) -> np.ndarray:
    """The absolute tolerances of (x_b, x_b', theta, theta'): rtol times the base's
    displacement scale (peak + g tan(alpha)) / omega_b^2 and its rate, alpha and p alpha
    (the reference's and the numba kernel's)."""
    body = IsolatedBody.of(structure)
    p = structure.block.frequency_parameter
    scale = (float(getattr(motion, "peak", 0.0)) + G * math.tan(body.slenderness)) / body.omega**2
    alpha = body.slenderness
    return rtol * np.array([scale, scale * body.omega, alpha, p * alpha])


def _scene(structure, motion, rtol, t_max):
    """The scene of a run: the tail after the motion without ``t_max`` is capped at 100 / p +
    100 T_b (an undamped isolator may lift the block for ever)."""
    body = IsolatedBody.of(structure)
    p = structure.block.frequency_parameter
    acc, _ = _ground(motion)
    dur = float(motion.duration)
    atol = absolute_tolerances(structure, motion, rtol)
    cap = dur + 100.0 / p + 100.0 * structure.period
    breaks = np.asarray(motion.time) if isinstance(motion, Record) else None
    t_end = cap if t_max is None else float(t_max)
    return _Scene(
        body,
        acc,
        dur,
        breaks,
        rtol,
        atol,
        t_end,
        t_max is not None,
        REST_FRACTION * p * body.slenderness,
        row_parameters(structure),
    )


def _dense(log, t_eval, overturn_time):
    """The states at ``t_eval`` from the segments' dense output (the one that ends at or after
    each time: at an impact, the state before it); NaN after an overturning. A time beyond
    the history's end is refused."""
    ends = np.array([seg[1] for seg in log.segments] or [log.rows[-1][0]])
    out = np.full((4, t_eval.size), np.nan)
    if t_eval.size and t_eval[-1] > ends[-1] and not t_eval[-1] > overturn_time:
        raise ValueError(
            f"t_eval reaches {t_eval[-1]!r} s, beyond the end of the history {ends[-1]!r} s "
            "(the base and block at rest for good): give t_max to follow it longer"
        )
    for i, t in enumerate(t_eval):
        if t > overturn_time:
            continue
        k = int(np.searchsorted(ends, t, side="left"))
        out[:, i] = log.segments[k][2](t) if log.segments else log.rows[0][1:]
    return {
        "t_eval": t_eval,
        "base_displacement_eval": out[0],
        "base_velocity_eval": out[1],
        "theta_eval": out[2],
        "theta_dot_eval": out[3],
    }


def _initial_side(theta, theta_dot):
    """The side the block starts on: that of theta, else of theta', else 0 (at rest)."""
    if theta != 0.0:
        return math.copysign(1.0, theta)
    return math.copysign(1.0, theta_dot) if theta_dot != 0.0 else 0.0


def _check_options(motion, method, friction, conditioning):
    """Refuse what the isolated block's reference does not run, naming the argument."""
    if not isinstance(motion, Motion):
        raise TypeError(f"motion must be a rockstudy Motion, got {type(motion).__name__}")
    if method not in ISOLATED_METHODS:
        raise ValueError(
            f"method: an IsolatedBlock runs {', '.join(map(repr, ISOLATED_METHODS))} (all the "
            f"solve_ivp reference), got {method!r}"
        )
    if friction is not None:
        raise ValueError("friction: the contact model runs a Block, not an IsolatedBlock")
    if conditioning:
        raise ValueError("conditioning: not available for an IsolatedBlock")
    if motion.kernel_spec()[4].size:
        raise ValueError(
            "motion: an IsolatedBlock takes a horizontal motion only (its model has no "
            "vertical component)"
        )


def simulate_isolated(
    structure: IsolatedBlock,
    motion: Motion,
    method: str = "scipy",
    rtol: float = 1e-8,
    t_max: float | None = None,
    initial_rotation: float = 0.0,
    initial_velocity: float = 0.0,
    t_eval=None,
    dt_out: float | None = None,
    friction=None,
    conditioning: bool = False,
) -> IsolatedResult:
    """Rock a block on an isolated base through a ground motion: the ``solve_ivp`` reference
    (the scipy path, with the whole history; ``simulate_batch`` runs the numba kernel), what
    ``rockstudy.simulate(IsolatedBlock(...), motion)`` runs.

    Parameters
    ----------
    structure : IsolatedBlock
    motion : Motion
        Horizontal ground acceleration (a pulse or a record; a vertical component is refused).
    method : {"nonlinear", "scipy", "auto"}
        All run this reference (``result.method`` is ``"scipy"``); any other is refused.
    rtol : float
        ``solve_ivp``'s relative tolerance, in [1e-12, 1); the absolute tolerances scale with
        alpha, p alpha, and the base's displacement (peak + g tan(alpha)) / omega_b^2.
    t_max : float, optional
        End of the history [s]. By default the response after the motion is followed until
        the block rests and the base can no longer lift it nor pass its peak displacement
        (at most 100 / p + 100 T_b after the motion, said by an
        :class:`~rockstudy.IncompleteReferenceWarning` and ``info["complete"]``).
    initial_rotation, initial_velocity : float
        theta [rad] and theta' [rad/s] at t = 0, the base at rest; both zero (default): the
        block rests on the base.
    t_eval, dt_out : optional
        Output times [s], or a uniform step (see :func:`rockstudy.simulate`).
    friction, conditioning
        Refused (not modelled for an isolated block).

    Returns
    -------
    IsolatedResult
    """
    _check_options(motion, method, friction, conditioning)
    if not isinstance(structure, IsolatedBlock):
        raise TypeError(f"structure must be an IsolatedBlock, got {type(structure).__name__}")
    rtol = _validate.rtol(rtol)
    if t_max is not None:
        t_max = _validate.positive("t_max", t_max)
    th0, om0 = _validate.initial_state(initial_rotation, initial_velocity)
    t_eval = _validate.output_times(t_eval, dt_out, t_max)
    r = _simulate(structure, motion, rtol, t_max, (th0, om0), t_eval)
    if dt_out is not None and t_max is None:  # the grid runs to the end of the response
        grid = _validate.uniform_times(float(dt_out), float(r.t[-1]))
        r = _simulate(structure, motion, rtol, t_max, (th0, om0), grid)
    return r


def _simulate(structure, motion, rtol, t_max, x0, t_eval):
    """One run of :func:`simulate_isolated` on checked arguments."""
    scene, log = _scene(structure, motion, rtol, t_max), _Log()
    t_ot, complete = _run(scene, log, [0.0, 0.0, *x0], _initial_side(*x0))
    rows = np.array(log.rows, dtype=float)
    over = not math.isnan(t_ot)
    dense = {} if t_eval is None else _dense(log, t_eval, t_ot if over else math.inf)
    return IsolatedResult(
        *(rows[:, i].copy() for i in (0, 3, 4, 1, 2)),
        max_rotation=FALL_ROTATION if over else float(log.max_theta),
        overturned=over,
        max_isolator_displacement=float(log.max_x),
        impact_times=np.array(log.impacts, dtype=float),
        uplift_times=np.array(log.uplifts, dtype=float),
        overturn_time=t_ot,
        method="scipy",
        info={
            "model": "block on an isolated base (Vassiliou & Makris 2012), solve_ivp DOP853",
            "rtol": rtol,
            "restitution": structure.restitution,
            "complete": complete,
        },
        isolator_capacity=structure.isolator_capacity,
        **dense,
    )
