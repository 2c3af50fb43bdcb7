"""Two stacked rocking blocks integrated by ``scipy.integrate.solve_ivp``: the reference path of
:class:`~rockstudy.structures.StackedBlocks`, with its full history (:func:`rockstudy.simulate`
runs it; the batches run the event-driven numba kernel of the same model, :mod:`._stacked_scene`).

Event-driven over the regimes of :mod:`.stacked`: each regime is integrated (DOP853, rtol
down to 1e-12) in its own coordinates until one of its events, located by scipy (Brent's
method on the dense output): an impact at a rocking interface (its angle through zero), an
uplift of a closed interface (a lock margin of :func:`.stacked.lock_margins` through zero),
a fall (an angle at pi/2). Rest is not integrated: its end is found by Brent's method on the
lock margins, which at rest are linear in the ground acceleration. Phases stop at every
record sample (where u_g'' has a kink) and at the end of the motion; the free rocking after
it is followed to rest (an impact at less than 1e-4 p alpha of the interface's own block
closes it, as the single-block kernels' rest rule) or to ``t_max``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from .. import _validate
from .._warnings import AccuracyWarning
from ..constants import FALL_ROTATION, G
from ..structures.block import frequency_parameter
from . import stacked as st
from .constants import REST_FRACTION
from .reference import _grids, _ground, _stop_time, _uplift_time

__all__ = [
    "MAX_PHASES",
    "STACKED_METHODS",
    "StackedResult",
    "simulate_stacked",
    "simulate_stacked_blocks",
]

#: Most regime phases of one run before it is refused (a RuntimeError): no scene of a
#: ground motion comes near it.
MAX_PHASES = 200_000


@dataclass(frozen=True)
class StackedResult:
    """Response of two stacked blocks to one ground motion.

    Attributes
    ----------
    t : ndarray
        Times of the history [s] (an impact's time twice: before and after the jump).
    theta_lower, theta_upper : ndarray
        The lower block's rotation on the ground and the upper block's rotation relative to
        the lower one [rad] (> 0 tipping towards +x).
    theta_lower_dot, theta_upper_dot : ndarray
        Their rates [rad/s].
    regime : ndarray of str
        The regime at each time: "rest", "lower" (the lower rocking, the upper locked to it),
        "upper" (the upper rocking on the resting lower) or "both".
    max_rotation_lower, max_rotation_upper : float
        Max ``|theta_lower|`` and ``|theta_upper|`` [rad] (the peaks located by events); pi/2
        for the rotation that reached it at an overturning.
    overturned : bool
        Whether either body fell (a rotation reached pi/2; the run ends there).
    overturned_body : {"lower", "upper", "both", None}
        Which rotation reached pi/2: "upper" (the upper fell off the lower), "lower" (the
        lower fell while the upper rocked on it), "both" (the assembly fell as one body, the
        upper locked to the lower, or both rotations at once); None if nothing fell.
    overturn_time : float
        When, NaN if nothing fell [s].
    impact_times : ndarray
        Times of the impacts [s] (either interface).
    impact_interfaces : ndarray of str
        "lower" (on the ground), "upper" (on the lower top) or "both" (simultaneous).
    method : str
        "scipy": this module.
    info : dict
        ``solver``, ``rtol``, ``phases``, ``energy_lost`` [J per unit thickness, the impacts'
        losses], ``missed_impacts`` (extrema found beyond a pivot: impacts the steps
        stepped over, warned about with an :class:`~rockstudy.AccuracyWarning`) and what
        ran.
    """

    t: np.ndarray
    theta_lower: np.ndarray
    theta_upper: np.ndarray
    theta_lower_dot: np.ndarray
    theta_upper_dot: np.ndarray
    regime: np.ndarray
    max_rotation_lower: float
    max_rotation_upper: float
    overturned: bool
    overturned_body: str | None
    overturn_time: float
    impact_times: np.ndarray
    impact_interfaces: np.ndarray
    method: str = "scipy"
    info: dict = field(default_factory=dict)

    def to_xarray(self):
        """The history as an ``xarray.Dataset`` on ``time`` (repeated at impacts), the peaks
        and decisions as attributes (``overturned_body`` "none" if nothing fell)."""
        import xarray as xr

        data = {
            name: ("time", getattr(self, name))
            for name in ("theta_lower", "theta_upper", "theta_lower_dot", "theta_upper_dot")
        }
        data["regime"] = ("time", self.regime.astype(str))
        attrs = {
            "max_rotation_lower": self.max_rotation_lower,
            "max_rotation_upper": self.max_rotation_upper,
            "overturned": int(self.overturned),
            "overturned_body": self.overturned_body or "none",
            "method": self.method,
        }
        return xr.Dataset(data, coords={"time": ("time", self.t)}, attrs=attrs)


class _Scene:
    """The assembly, the ground and the run's controls."""

    def __init__(self, stacked, motion, rtol, t_max):
        self.geo = st.geometry(stacked)
        self.acc, vert = _ground(motion)
        _, _, _, _, vsamples = motion.kernel_spec()
        if vsamples.size:
            raise ValueError(
                "motion: StackedBlocks takes a horizontal ground motion only (a vertical "
                "component is not modelled for two blocks yet)"
            )
        self.dur = motion.duration
        self.grid, self.breaks = _grids(motion)
        self.rtol = rtol
        self.t_end = math.inf if t_max is None else float(t_max)
        lo, up = stacked.lower, stacked.upper
        self.p = (frequency_parameter(lo.half_diagonal), frequency_parameter(up.half_diagonal))
        self.alpha = (lo.slenderness, up.slenderness)
        self.rest_speed = tuple(
            REST_FRACTION * p * a for p, a in zip(self.p, self.alpha, strict=True)
        )
        g = self.geo
        #: a moment scale per interface [N m]: its weight times its half-width
        self.moment = ((g.m1 + g.m2) * G * g.b1, g.m2 * G * g.b2)

    def ground(self, t):
        """u_g''(t) [m/s^2], zero after the motion."""
        return self.acc(t) if t <= self.dur else 0.0

    def stop(self, t):
        """Where a phase from t stops (:func:`.reference._stop_time`)."""
        return min(_stop_time(t, self.dur, self.breaks, self.t_end, min(self.p)), self.t_end)


class _State:
    """The full state: time, q = (theta_1, theta_2), q', which interfaces are closed and the
    pivots (s1, s2) of the rocking ones."""

    def __init__(self, initial):
        th1, phi, om1, om_phi = initial
        self.t = 0.0
        self.q = np.array([th1, th1 + phi])
        self.qd = np.array([om1, om1 + om_phi])
        self.flat = [th1 == 0.0 and om1 == 0.0, phi == 0.0 and om_phi == 0.0]
        self.sides = [_side(th1, om1), _side(phi, om_phi)]

    def angles(self):
        """(theta_1, phi) and their rates."""
        return (self.q[0], self.q[1] - self.q[0]), (self.qd[0], self.qd[1] - self.qd[0])


def _side(angle, rate):
    """The pivot corner of an interface at ``angle`` moving at ``rate``: their sign, +1 at
    rest."""
    return int(math.copysign(1.0, angle if angle != 0.0 else rate or 1.0))


class _Log:
    """History rows, peaks, impacts and the impacts' energy losses."""

    def __init__(self):
        self.rows, self.regimes = [], []
        self.peak = [0.0, 0.0]
        self.impacts, self.interfaces, self.lost = [], [], 0.0
        self.missed = 0

    def row(self, state):
        (a1, a2), (w1, w2) = state.angles()
        self.rows.append((state.t, a1, a2, w1, w2))
        self.regimes.append(st.regime_name(state.flat))
        self.peak = [max(self.peak[0], abs(a1)), max(self.peak[1], abs(a2))]


def _angle(k, y, n, sel):
    """Interface k's angle (theta_1 or phi) and rate from a phase's state y = (q_r, q_r')."""
    q, qd = sel @ y[:n], sel @ y[n:]
    if k == st.LOWER:
        return q[0], qd[0]
    return q[1] - q[0], qd[1] - qd[0]


def _phase_events(scene, state, sel):
    """The events of a regime phase and their names: per rocking interface the impact
    (terminal), the fall (terminal) and the peak of |angle| (not terminal); per closed
    interface its lock margin at each corner (terminal, uplift). The impact function is
    taken positive at the start t0, where a phase from an impact or an uplift has its angle
    at zero (as :func:`.reference._events`), lest scipy find the start again."""
    n, geo, (s1, s2), t0 = sel.shape[1], scene.geo, state.sides, state.t
    events, names = [], []

    def add(fun, terminal, direction, name):
        fun.terminal, fun.direction = terminal, direction
        events.append(fun)
        names.append(name)

    for k in (st.LOWER, st.UPPER):
        s = state.sides[k]
        if state.flat[k]:
            for j, corner in enumerate((1, -1)):

                def margin(t, y, k=k, j=j):
                    q, qd = sel @ y[:n], sel @ y[n:]
                    m = st.lock_margins(geo, q, qd, s1, s2, state.flat, scene.ground(t))
                    return m[0, j] / scene.moment[k]

                add(margin, True, -1, ("uplift", k, corner))
            continue
        add(
            lambda t, y, k=k, s=s: s * _angle(k, y, n, sel)[0] if t > t0 else 1.0,
            True,
            -1,
            ("impact", k, s),
        )
        add(
            lambda t, y, k=k, s=s: s * _angle(k, y, n, sel)[0] - FALL_ROTATION,
            True,
            1,
            ("fall", k, s),
        )
        add(lambda t, y, k=k: _angle(k, y, n, sel)[1], False, 0, ("peak", k, s))
    return events, names


def _release_violated(scene, state):
    """Open a closed interface whose lock margin is already negative at the start of a
    phase (the other one's uplift changed its forces): about the corner of the most negative
    margin. Returns whether one opened."""
    m = st.lock_margins(
        scene.geo, state.q, state.qd, *state.sides, state.flat, scene.ground(state.t)
    )
    closed = [k for k in (st.LOWER, st.UPPER) if state.flat[k]]
    worst = min(
        (
            (m[i, j] / scene.moment[k], k, corner)
            for i, k in enumerate(closed)
            for j, corner in enumerate((1, -1))
        ),
    )
    if worst[0] >= -1e-12:
        return False
    state.flat[worst[1]], state.sides[worst[1]] = False, worst[2]
    return True


def _solve_phase(scene, state, sel, events):
    """One phase by ``solve_ivp`` from the state to the next stop, with ``events``."""
    n, geo, (s1, s2), flat = sel.shape[1], scene.geo, state.sides, tuple(state.flat)

    def rhs(t, y):
        q, qd = sel @ y[:n], sel @ y[n:]
        acc = st.regime_acceleration(geo, q, qd, s1, s2, flat, scene.ground(t))
        return np.concatenate([y[n:], acc])

    a_min, p_max = min(scene.alpha), max(scene.p)
    y0 = np.concatenate([np.linalg.pinv(sel) @ state.q, np.linalg.pinv(sel) @ state.qd])
    sol = solve_ivp(
        rhs,
        (state.t, scene.stop(state.t)),
        y0,
        method="DOP853",
        rtol=scene.rtol,
        atol=[scene.rtol * a_min] * n + [scene.rtol * p_max * a_min] * n,
        events=events,
        dense_output=False,
    )
    if sol.status < 0:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol


def _phase(scene, state, log):
    """Integrate the current regime to its first terminal event or its stop, update the
    state and act on the event. Returns the overturned body's name or None."""
    if any(state.flat) and _release_violated(scene, state):
        return None
    sel = st.selection(state.flat)
    n = sel.shape[1]
    events, names = _phase_events(scene, state, sel)
    sol = _solve_phase(scene, state, sel, events)
    first, t_end, y_end = None, sol.t[-1], sol.y[:, -1]
    for i, name in enumerate(names):
        if events[i].terminal and sol.t_events[i].size and sol.t_events[i][0] <= t_end:
            first, t_end, y_end = name, sol.t_events[i][0], sol.y_events[i][0]
    _log_peaks(scene, log, sol, names, t_end, sel)
    for t, y in zip(sol.t[1:-1], sol.y[:, 1:-1].T, strict=True):
        if t < t_end:
            state.t, state.q, state.qd = t, sel @ y[:n], sel @ y[n:]
            log.row(state)
    state.t, state.q, state.qd = t_end, sel @ y_end[:n], sel @ y_end[n:]
    log.row(state)
    return _act(scene, state, log, first)


def _log_peaks(scene, log, sol, names, t_end, sel):
    """Raise the logged peaks to the phase's extrema of |angle| before ``t_end``. An extremum
    on the wrong side of its pivot (s angle < -1e-12 alpha) is an impact the steps missed
    (the angle dipped through zero and back inside one step): counted in
    ``log.missed``, which the result reports and warns about."""
    n = sel.shape[1]
    for i, (kind, k, side) in enumerate(names):
        if kind != "peak":
            continue
        for t, y in zip(sol.t_events[i], sol.y_events[i], strict=True):
            angle = _angle(k, y, n, sel)[0]
            if t <= t_end:
                log.peak[k] = max(log.peak[k], abs(angle))
                log.missed += side * angle < -1e-12 * scene.alpha[k]


def _act(scene, state, log, event, at_pivots=False):
    """The event's consequence: an impact (:func:`_impact`, ``at_pivots`` passed on), an
    uplift, or a fall (the body's name)."""
    if event is None:
        return None
    kind, k, corner = event
    if kind == "uplift":
        state.flat[k], state.sides[k] = False, corner
    elif kind == "impact":
        _impact(scene, state, log, k, at_pivots)
    else:
        if k == st.UPPER:
            return "upper"
        return "both" if state.flat[st.UPPER] else "lower"
    return None


def _impacting(scene, state, k):
    """Which interfaces close at an impact of interface k: k, and the other one too when it
    rocks and its angle is within 1e-12 alpha of zero, moving through it (simultaneous)."""
    (angles, rates), other = state.angles(), 1 - k
    hits = [False, False]
    hits[k] = True
    hits[other] = (
        not state.flat[other]
        and abs(angles[other]) <= 1e-12 * scene.alpha[other]
        and state.sides[other] * rates[other] < 0.0
    )
    return hits


def _consistent(flat, sides, closing, rates, margins, resting) -> bool:
    """Whether a post-impact regime holds: each interface it opens from angle zero (the
    impacting ones, and a closed one it releases) moves onto its corner, and each closed
    interface's impulse presses at both corners (margins >= 0, to 1e-12 of the largest).
    Where an impacting interface is closed by the rest rule (``resting``) no impulse is
    checked: Housner's impact never stops a block (angular momentum about the landing corner
    survives), so that rest is the rule's (at 1e-4 p alpha, a negligible impulse), not the
    impulses'."""
    for k in (st.LOWER, st.UPPER):
        if not flat[k] and closing[k] and sides[k] * rates[k] < 0.0:
            return False
    if margins.size and not any(resting):
        return bool(np.all(margins >= -1e-12 * np.max(np.abs(margins))))
    return True


def _impact(scene, state, log, k, at_pivots=False):
    """An impact of interface k (and of the other if simultaneous): the first consistent
    post-impact regime of :func:`.stacked.impact_candidates`, its velocities conserving the
    generalised momenta about the new pivots (:func:`.stacked.post_impact_velocity`), taken
    at the state's angles, or ``at_pivots`` at the pivot configuration q = 0 (the linearised
    rule of :mod:`.stacked_linear`)."""
    geo, hits = scene.geo, _impacting(scene, state, k)
    (a1, a2), rates = state.angles()
    th1, phi = (0.0 if hits[st.LOWER] else a1), (0.0 if hits[st.UPPER] else a2)
    state.q = np.array([th1, th1 + phi])
    q = np.zeros(2) if at_pivots else state.q
    v_before = st.body_velocities(geo, q, state.qd, *state.sides)
    e_before = st.mechanical_energy(geo, q, state.qd, *state.sides)
    slow = [abs(rates[i]) < scene.rest_speed[i] for i in (0, 1)]
    closing = [hits[i] or state.flat[i] for i in (0, 1)]
    for flat, s1, s2 in st.impact_candidates(state.flat, state.sides, hits, slow):
        qd_r, margins = st.post_impact_velocity(geo, q, v_before, s1, s2, flat)
        qd = st.selection(flat) @ qd_r
        resting = [slow[i] and hits[i] for i in (0, 1)]
        if _consistent(flat, (s1, s2), closing, (qd[0], qd[1] - qd[0]), margins, resting):
            break
    else:
        raise RuntimeError(
            f"no consistent post-impact regime at t = {state.t!r} s (impact at the "
            f"{'ground' if k == st.LOWER else 'upper interface'})"
        )
    state.flat, state.sides, state.qd = list(flat), [s1, s2], qd
    log.lost += e_before - st.mechanical_energy(geo, q, qd, s1, s2)
    log.impacts.append(state.t)
    log.interfaces.append("both" if all(hits) else ("lower", "upper")[k])
    log.row(state)


def _leave_rest(scene, state, log) -> bool:
    """From rest: the first time an interface lifts (Brent's method on the lock margins,
    linear in u_g'' at rest), which then rocks about the corner that lifted. False if
    nothing lifts before the end of the motion (the state then rests there)."""
    zero = np.zeros(2)
    m0 = st.lock_margins(scene.geo, zero, zero, 1, 1, (True, True), 0.0)
    m1 = st.lock_margins(scene.geo, zero, zero, 1, 1, (True, True), 1.0) - m0
    scale = np.array(scene.moment)[:, None]

    def normalised(t):
        return (m0 + scene.ground(t) * m1) / scale

    def lift(t):  # > 0 where an interface lifts (ground just after t: 0 after the motion)
        return -float(normalised(t).min()) if t < scene.dur else -1.0

    t_up = _uplift_time(lift, state.t, scene.dur, scene.grid)
    if not t_up <= scene.t_end:
        state.t = min(scene.dur, scene.t_end)
        log.row(state)
        return False
    state.t = t_up
    log.row(state)
    k, j = np.unravel_index(int(np.argmin(normalised(t_up))), (2, 2))
    state.flat[k], state.sides[k] = False, (1, -1)[j]
    return True


def simulate_stacked(stacked, motion, rtol=1e-10, t_max=None, initial=(0.0, 0.0, 0.0, 0.0)):
    """Two stacked blocks through a horizontal ground motion, by ``solve_ivp``.

    Parameters
    ----------
    stacked : StackedBlocks
        The assembly.
    motion : Motion
        The ground acceleration (horizontal only: a vertical component is refused).
    rtol : float
        ``solve_ivp``'s relative tolerance, in [1e-12, 1); absolute tolerances rtol alpha_min
        and rtol p_max alpha_min.
    t_max : float, optional
        End of the history [s]; by default the free rocking after the motion is followed to
        rest.
    initial : (theta_1, phi, theta_1', phi')
        The lower block's rotation, the upper one's relative rotation [rad] and their rates
        [rad/s] at t = 0; default at rest.

    Returns
    -------
    StackedResult
    """
    rtol = _validate.rtol(rtol)
    if t_max is not None:
        t_max = _validate.positive("t_max", t_max)
    initial = _check_initial(initial)
    scene = _Scene(stacked, motion, rtol, t_max)
    state, log, fell = _State(initial), _Log(), None
    log.row(state)
    phases = 0
    for phases in range(MAX_PHASES):  # noqa: B007 (the count is reported)
        if state.t >= scene.t_end:
            break
        if all(state.flat):
            if state.t >= scene.dur or not _leave_rest(scene, state, log):
                break
            continue
        fell = _phase(scene, state, log)
        if fell is not None:
            break
    else:
        raise RuntimeError(f"StackedBlocks: more than {MAX_PHASES} regime phases in one run")
    return _pack(scene, state, log, fell, phases)


def _check_initial(initial):
    """(theta_1, phi, theta_1', phi') as floats, finite, the angles in (-pi/2, pi/2), or a
    ValueError naming ``initial``."""
    values = tuple(_validate.number("initial", v) for v in initial)
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"initial must be 4 finite numbers (theta_1, phi, rates), got {initial!r}")
    if max(abs(values[0]), abs(values[1])) >= FALL_ROTATION:
        raise ValueError(f"initial: the angles must lie in (-pi/2, pi/2) rad, got {initial!r}")
    return values


def _pack(scene, state, log, fell, phases) -> StackedResult:
    """The result of a run."""
    rows = np.array(log.rows)
    peaks = list(log.peak)
    if log.missed:
        warnings.warn(
            f"StackedBlocks: {log.missed} impact(s) missed by the steps (an angle dipped "
            f"through zero inside one step) at rtol {scene.rtol:g}: the result is not "
            "reliable; run at a tighter rtol",
            AccuracyWarning,
            stacklevel=3,
        )
    if fell in ("lower", "both"):
        peaks[st.LOWER] = FALL_ROTATION
    if fell == "upper":
        peaks[st.UPPER] = FALL_ROTATION
    return StackedResult(
        rows[:, 0],
        rows[:, 1],
        rows[:, 2],
        rows[:, 3],
        rows[:, 4],
        np.array(log.regimes),
        float(peaks[0]),
        float(peaks[1]),
        fell is not None,
        fell,
        float(state.t) if fell else math.nan,
        np.array(log.impacts),
        np.array(log.interfaces, dtype=str),
        "scipy",
        {
            "solver": "solve_ivp DOP853 (stacked_reference)",
            "rtol": scene.rtol,
            "phases": phases + 1,
            "energy_lost": float(log.lost),
            "missed_impacts": int(log.missed),
        },
    )


#: ``simulate``'s methods that run two stacked blocks: all run this reference for now.
STACKED_METHODS = ("nonlinear", "scipy", "auto")


def simulate_stacked_blocks(stacked, motion, method, rtol, t_max, **options) -> StackedResult:
    """:func:`rockstudy.simulate` of a :class:`~rockstudy.structures.StackedBlocks`: this
    module's ``solve_ivp`` reference for every method of :data:`STACKED_METHODS` (the
    event-driven numba kernel is not written yet), said in ``info["solver"]``; the options
    it does not take yet (initial conditions, ``t_eval``/``dt_out``, ``friction``,
    ``conditioning``) refused by name when given."""
    if method not in STACKED_METHODS:
        raise ValueError(
            f"method: StackedBlocks runs {', '.join(map(repr, STACKED_METHODS))} (all by the "
            f"solve_ivp reference), got {method!r}"
        )
    for name, value in options.items():
        unset = value is None or value is False
        if not unset and not (isinstance(value, (int, float)) and value == 0.0):
            raise ValueError(f"{name}: not taken for StackedBlocks yet, got {value!r}")
    r = simulate_stacked(stacked, motion, rtol=rtol, t_max=t_max)
    r.info.update(method_requested=method)
    return r
