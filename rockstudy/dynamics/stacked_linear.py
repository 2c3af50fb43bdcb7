r"""Two stacked rocking blocks, linearised for small slenderness and solved exactly per regime:
the second, independent door to :class:`~rockstudy.structures.StackedBlocks` beside the
``solve_ivp`` reference (:mod:`.stacked_reference`).

Linearisation (Housner 1963's small-angle form, generalised to two bodies). Each body vector
of :mod:`.stacked` (lower pivot -> lower centre r_1, lower pivot -> upper pivot d, upper
pivot -> upper centre r_2) is written as a length l and an angle beta from the vertical,
v = l (sin beta, cos beta); after the tipping theta its point lies at
l (sin(beta + theta), cos(beta + theta)). The generalised forces of gravity and of the
ground's inertia (the Lagrangian of [P90], section 2) are then

.. math:: Q_1 = g (m_1 l_1 \sin(\beta_1 + \theta_1) + m_2 l_d \sin(\beta_d + \theta_1))
          - \ddot u_g (m_1 l_1 \cos(\beta_1 + \theta_1) + m_2 l_d \cos(\beta_d + \theta_1)),
   \quad Q_2 = m_2 l_2 (g \sin(\beta_2 + \theta_2) - \ddot u_g \cos(\beta_2 + \theta_2)),

and for small alpha (beta, theta and u_g'' / g of order alpha) sin x -> x, cos x -> 1, the
mass matrix is taken at the pivot configuration M(0) (its change with phi is of relative
order alpha^2) and the velocity terms are dropped (relative order alpha^2). For one body
this is Housner's linearised equation theta'' = -p^2 (alpha s - theta + u_g'' / g) (eq. 3.1
of [000]). Each regime (rest, lower, upper, both, with its pivots) is then linear and
time-invariant, M_r q_r'' = K_r q_r + c_r + f_r u_g''(t).

Exact solution. The ground acceleration of a segment is the output of a small linear
"exosystem" w' = E w: (1, sin, cos) for a trigonometric pulse, (1, t - t_k) on a record's
linear segment, (1) after the motion. The regime and the exosystem together are one LTI
system z' = Z z, z = (q_r, q_r', w), solved by the matrix exponential z(t) = e^{Z (t - t_0)}
z_0: nothing is integrated. The grid step's e^{Z h} (h = 1/20 of the fastest time scale of Z)
and z(t_i + tau) inside a step are their Taylor series summed to rounding
(``scipy.linalg.expm`` where that would not converge). Events are roots of linear functions
of z on this exact solution (bracketed on the grid, or at a turning point for an angle that
dips through zero and back inside one step; polished by Brent's method): impacts
(an angle through zero), uplifts (a lock margin through zero, the linearised
:func:`.stacked.lock_margins`), peaks (a rate through zero) and the fall (an angle at pi/2).
The impacts conserve the momenta about the new pivots at the pivot configuration
(:func:`.stacked.post_impact_velocity` at q = 0: the reference's ``_impact`` with
``at_pivots``), the rule of [P90]; for one block this is Housner's restitution
1 - 3/2 sin^2 alpha.

[P90] Psycharis (1990), Earthquake Engng Struct. Dyn. 19:555-575; [000] Dimitrakopoulos &
DeJong (2012), Proc. R. Soc. A 468:2294-2318; Housner (1963), "The behavior of inverted
pendulum structures during earthquakes", Bull. Seism. Soc. Am. 53:403-417.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from .. import _validate
from ..constants import FALL_ROTATION, G
from ..motions._kernels import KIND_RECORD, KIND_TRIG
from . import stacked as st
from .stacked_reference import (
    MAX_PHASES,
    StackedResult,
    _act,
    _Log,
    _pack,
    _Scene,
    _State,
)

__all__ = [
    "GRID_STEPS",
    "SERIES_TERMS",
    "exosystem",
    "linear_forcing",
    "linear_lock_margins",
    "linear_terms",
    "regime_matrix",
    "simulate_stacked_linear",
]


def _lever(v) -> tuple[float, float]:
    """(l, beta): the length [m] of a body vector v = (x, y) and its angle from the vertical
    [rad] (> 0 towards +x), v = l (sin beta, cos beta)."""
    return math.hypot(v[0], v[1]), math.atan2(v[0], v[1])


def linear_terms(geo: st.Geometry, s1: int, s2: int):
    """(K, c, f) of the linearised generalised forces Q = K q + c + f u_g'' of "both
    rocking" on the pivots (s1, s2) (the module's equation for Q_1, Q_2 with sin x -> x,
    cos x -> 1): K [N m / rad], c [N m], f [N m / (m/s^2)], per unit thickness."""
    r1, d, r2 = st._arms(geo, s1, s2)
    (l1, b1), (ld, bd), (l2, b2) = _lever(r1), _lever(d), _lever(r2)
    lever = np.array([geo.m1 * l1 + geo.m2 * ld, geo.m2 * l2])
    c = G * np.array([geo.m1 * l1 * b1 + geo.m2 * ld * bd, geo.m2 * l2 * b2])
    return G * np.diag(lever), c, -lever


def linear_forcing(geo, q, s1, s2, ground) -> np.ndarray:
    """Q = K q + c + f u_g'' (:func:`linear_terms`) at the angles q = (theta_1, theta_2)."""
    k, c, f = linear_terms(geo, s1, s2)
    return k @ np.asarray(q, dtype=float) + c + f * ground


def _pivot_mass(geo, s1, s2) -> np.ndarray:
    """M(0): the Lagrangian mass matrix of "both rocking" at the pivot configuration
    (:func:`.stacked.mass_matrix` at q = 0)."""
    return st.mass_matrix(geo, np.zeros(2), s1, s2)


def linear_lock_margins(geo, q, s1, s2, flat, ground) -> np.ndarray:
    """The closed interfaces' margins s Lambda(s) of :func:`.stacked.lock_margins` for the
    linearised equations (M(0), :func:`linear_forcing`): shape (m, 2), corners s = +1, -1."""
    rows = st.constraint_rows(flat)
    out = np.empty((rows.shape[0], 2))
    for j, s in enumerate((1, -1)):
        p1 = s if flat[st.LOWER] else s1
        p2 = s if flat[st.UPPER] else s2
        m, f = _pivot_mass(geo, p1, p2), linear_forcing(geo, q, p1, p2, ground)
        out[:, j] = s * st._multipliers(m, f, rows)
    return out


def regime_matrix(geo, flat, s1, s2, exo_matrix, exo_ground) -> np.ndarray:
    """Z of the regime (``flat``, pivots s1, s2) driven by an exosystem (w' = E w, u_g'' =
    exo_ground . w, w[0] = 1): z' = Z z for z = (q_r, q_r', w), from M_r q_r'' = K_r q_r +
    c_r + f_r u_g'' with M_r = S^T M(0) S, K_r = S^T K S, c_r = S^T c, f_r = S^T f."""
    sel, (k, c, f) = st.selection(flat), linear_terms(geo, s1, s2)
    n, m = sel.shape[1], exo_matrix.shape[0]
    z = np.zeros((2 * n + m, 2 * n + m))
    z[2 * n :, 2 * n :] = exo_matrix
    if n:
        m_r = sel.T @ _pivot_mass(geo, s1, s2) @ sel
        z[:n, n : 2 * n] = np.eye(n)
        z[n : 2 * n, :n] = np.linalg.solve(m_r, sel.T @ k @ sel)
        drive = np.outer(sel.T @ f, exo_ground)
        drive[:, 0] += sel.T @ c
        z[n : 2 * n, 2 * n :] = np.linalg.solve(m_r, drive)
    return z


def exosystem(motion, t: float):
    """The ground acceleration from t [s] as an exosystem: (t_end, E, w(t), C) with
    u_g''(t') = C . w(t') and w' = E w on [t, t_end] (w[0] = 1); t_end is the end of the
    record segment or of the motion, inf after it (u_g'' = 0)."""
    kind, mp, times, samples, _ = motion.kernel_spec()
    dur = motion.duration
    if t >= dur:
        return math.inf, np.zeros((1, 1)), np.ones(1), np.zeros(1)
    if kind == KIND_TRIG:
        a, om, ph = mp[0], mp[1], mp[2]
        e = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, om], [0.0, -om, 0.0]])
        w = np.array([1.0, math.sin(om * t + ph), math.cos(om * t + ph)])
        return dur, e, w, np.array([0.0, a, 0.0])
    if kind != KIND_RECORD:
        raise ValueError(
            "motion: the linearised stacked model takes a trigonometric pulse or a record "
            f"(piecewise-linear), got {type(motion).__name__}"
        )
    k = min(int(np.searchsorted(times, t, side="right")) - 1, times.size - 2)
    slope = (samples[k + 1] - samples[k]) / (times[k + 1] - times[k])
    u0 = samples[k] + slope * (t - times[k])
    e = np.array([[0.0, 0.0], [1.0, 0.0]])
    return min(times[k + 1], dur), e, np.array([1.0, 0.0]), mp[0] * np.array([u0, slope])


#: Most grid steps of one phase: a regime that lasts longer runs as several phases (the grid
#: is scanned for the first event, so a long one would be built in vain).
GRID_STEPS = 64
#: Most terms of the Taylor series of one grid step (it converges in about 15).
SERIES_TERMS = 60


def _angle_rows(sel, dim):
    """Rows L with (theta_1, phi) = L[:2] z and their rates = L[2:] z, z = (q_r, q_r', w)."""
    n, diff = sel.shape[1], np.array([[1.0, 0.0], [-1.0, 1.0]])
    rows = np.zeros((4, dim))
    rows[:2, :n] = diff @ sel
    rows[2:, n : 2 * n] = diff @ sel
    return rows


def _margin_rows(scene, state, sel, exo_ground, dim):
    """Rows L with the closed interfaces' margins (:func:`linear_lock_margins`, scaled by
    the interface's moment) = L z, in the order (interface, corner +1 / -1): the margins are
    linear in z, so L is their value on the unit vectors."""
    n, out = sel.shape[1], []
    const = linear_lock_margins(scene.geo, np.zeros(2), *state.sides, state.flat, 0.0)
    for col in np.eye(dim):
        q, ground = sel @ col[:n], float(exo_ground @ col[2 * n :])
        lin = linear_lock_margins(scene.geo, q, *state.sides, state.flat, ground)
        out.append((lin - const + col[2 * n] * const).ravel())  # w[0] = 1 carries c
    closed = [k for k in (st.LOWER, st.UPPER) if state.flat[k]]
    scale = np.repeat([scene.moment[k] for k in closed], 2)
    return np.array(out).T.reshape(-1, dim) / (scale[:, None] if scale.size else 1.0), closed


def _step_matrix(zh) -> np.ndarray:
    """e^{Z h} for a grid step: its Taylor series to rounding where |Z h| is small (as
    here; scipy's Pade approximant costs ten times more on these 3 x 3 to 7 x 7 matrices),
    ``scipy.linalg.expm`` otherwise."""
    out, term = np.eye(zh.shape[0]), np.eye(zh.shape[0])
    for k in range(1, SERIES_TERMS):
        term = term @ zh / k
        out += term
        if np.max(np.abs(term)) < 1e-18:
            return out
    return expm(zh)


class _Phase:
    """One regime on one exosystem segment from t0: z(t) = e^{Z (t - t0)} z0, exactly."""

    def __init__(self, scene, state):
        t_seg, e, w0, self.c = exosystem(scene.motion, state.t)
        if state.t >= scene.dur:
            t_seg = state.t + 100.0 / min(scene.p)
        self.sel = st.selection(state.flat)
        n = self.sel.shape[1]
        self.z = regime_matrix(scene.geo, state.flat, *state.sides, e, self.c)
        #: the grid step: 1/20 of the fastest time scale of Z (its largest |eigenvalue|)
        self.h = 0.05 / max(float(np.max(np.abs(np.linalg.eigvals(self.z)))), 1e-3)
        self.t0 = state.t
        self.t1 = min(t_seg, scene.t_end, state.t + GRID_STEPS * self.h)
        pinv = np.linalg.pinv(self.sel)
        self.z0 = np.concatenate([pinv @ state.q, pinv @ state.qd, w0])
        self.n = n

    def angles(self, t):
        """(q, q') = (theta_1, theta_2) and their rates at t."""
        z = self.at(t)
        return self.sel @ z[: self.n], self.sel @ z[self.n : 2 * self.n]

    def at(self, t):
        """z(t), by :meth:`series` from the grid point at or before t."""
        i = min(max(int(np.searchsorted(self.times, t, side="right")) - 1, 0), self.times.size - 2)
        return np.polynomial.polynomial.polyval(t - self.times[i], self.series(i))

    def series(self, i):
        """The Taylor coefficients (K x dim) of z(t_i + tau) = sum_k Z^k z(t_i) tau^k / k!,
        to rounding over a grid step (|Z| h is a few hundredths): the exact solution as a
        polynomial, cheap to evaluate in root finding."""
        if i not in self._series:
            terms = [self.states[:, i]]
            scale = np.max(np.abs(terms[0])) or 1.0
            for k in range(1, SERIES_TERMS):
                terms.append(self.z @ terms[-1] / k)
                if np.max(np.abs(terms[-1])) * self.h**k < 1e-18 * scale:
                    break
            else:
                raise RuntimeError("stacked_linear: the series of e^{Z h} did not converge")
            self._series[i] = np.array(terms)
        return self._series[i]

    def grid(self):
        """Times and states on a grid of steps of at most ``h`` across [t0, t1], by the exact
        step e^{Z h} (:func:`_step_matrix`); kept for :meth:`at`."""
        steps = max(int(math.ceil((self.t1 - self.t0) / self.h)), 1)
        times = np.linspace(self.t0, self.t1, steps + 1)
        step = _step_matrix(self.z * (times[1] - times[0]))
        states = np.empty((self.z0.size, steps + 1))
        states[:, 0] = self.z0
        for i in range(steps):
            states[:, i + 1] = step @ states[:, i]
        self.times, self.states, self._series = times, states, {}
        return times, states


def _events(scene, state, phase):
    """The phase's events as (rows, offsets, kinds): the event function is rows @ z - offset,
    and kind = (name, interface, corner) with name "impact" (s angle down through 0), "fall"
    (s angle up through pi/2), "peak" (a rate through 0, not terminal) or "uplift" (a scaled
    lock margin down through 0)."""
    dim = phase.z0.size
    ang = _angle_rows(phase.sel, dim)
    rows, offsets, kinds = [], [], []
    for k in (st.LOWER, st.UPPER):
        if state.flat[k]:
            continue
        s = state.sides[k]
        rows += [s * ang[k], s * ang[k], ang[2 + k]]
        offsets += [0.0, FALL_ROTATION, 0.0]
        kinds += [("impact", k, s), ("fall", k, s), ("peak", k, s)]
    if any(state.flat):
        marg, closed = _margin_rows(scene, state, phase.sel, phase.c, dim)
        rows += list(marg)
        offsets += [0.0] * marg.shape[0]
        kinds += [("uplift", k, corner) for k in closed for corner in (1, -1)]
    return np.array(rows).reshape(-1, dim), np.array(offsets), kinds


def _crossing(values, name):
    """Index i >= 1 of the first grid interval (i - 1, i) where an event of ``name`` happens,
    or None: impacts and uplifts from > 0 (>= 0) to <= 0 (< 0), the start counted as
    positive; falls upwards through 0; peaks in either direction."""
    v = values.copy()
    if name == "fall":
        hit = (v[:-1] < 0.0) & (v[1:] >= 0.0)
    elif name == "peak":
        hit = (v[:-1] * v[1:] < 0.0) | ((v[1:] == 0.0) & (v[:-1] != 0.0))
    else:
        v[0] = max(v[0], 0.0) if name == "uplift" else 1.0
        hit = (v[:-1] >= 0.0) & (v[1:] < 0.0) if name == "uplift" else (v[:-1] > 0) & (v[1:] <= 0)
    idx = np.flatnonzero(hit)
    return int(idx[0]) + 1 if idx.size else None


def _root(phase, row, offset, a, b, from_zero=False):
    """The time in [a, b] where row @ z(t) = offset (Brent's method on the exact solution);
    a where the bracket holds no sign change (an event at the phase's start). With
    ``from_zero`` (an angle leaving zero at a = t0, in the first grid step), the root of
    (row @ z(t)) / (t - t0)^m, its next zero (a rebound shorter than a grid step), from the
    series of the step with its m leading zero terms dropped (the angle, and its rate too
    after an uplift from rest): no cancellation near t0."""
    if from_zero:
        coefficients = phase.series(0) @ row
        leading = np.flatnonzero(coefficients)
        if not leading.size:  # the angle stays at zero: no rebound to find
            return a
        coefficients = coefficients[leading[0] :]

        def fun(t):
            return float(np.polynomial.polynomial.polyval(t - phase.t0, coefficients))

    else:

        def fun(t):
            return float(row @ phase.at(t)) - offset

    fa, fb = fun(a), fun(b)
    if fa == 0.0 or fa * fb > 0.0:
        return a
    return brentq(fun, a, b, xtol=1e-15, rtol=4.0 * np.finfo(float).eps, maxiter=200)


def _dip(phase, rows, i, times, values):
    """(a, b): the first grid interval where the impact function s angle (row i of an
    "impact" event, its rate the "peak" row i + 2) is not negative at either end but dips
    below zero inside (the rate changes sign there, at a time b where s angle < 0): an impact
    a sign scan of the grid misses; None if there is none."""
    angle, rate = values[i], values[i + 2]
    turning = (rate[:-1] * rate[1:] < 0.0) & (angle[:-1] >= 0.0) & (angle[1:] > 0.0)
    for j in np.flatnonzero(turning) + 1:
        t = _root(phase, rows[i + 2], 0.0, times[j - 1], times[j])
        if rows[i] @ phase.at(t) < 0.0:
            return times[j - 1], t
    return None


def _first_event(phase, rows, offsets, kinds, times, values):
    """(time, kind) of the first terminal event on the grid, polished by :func:`_root`, or
    (t1, None)."""
    best = (phase.t1, None)
    for i, kind in enumerate(kinds):
        if kind[0] == "peak":
            continue
        j = _crossing(values[i], kind[0])
        dip = _dip(phase, rows, i, times, values) if kind[0] == "impact" else None
        if dip is not None and (j is None or dip[0] < times[j - 1]):
            t = _root(phase, rows[i], 0.0, *dip)
        elif j is None or times[j - 1] > best[0]:
            continue
        else:
            from_zero = kind[0] == "impact" and j == 1 and rows[i] @ phase.z0 == 0.0
            t = _root(phase, rows[i], offsets[i], times[j - 1], times[j], from_zero)
        if t < best[0] or best[1] is None:
            best = (t, kind) if t <= best[0] else best
    return best


def _log_peaks(phase, rows, kinds, times, values, t_end, log):
    """Raise the logged peaks to the |angle| at the phase's rate roots before t_end."""
    ang = _angle_rows(phase.sel, phase.z0.size)
    for i, (name, k, _) in enumerate(kinds):
        if name != "peak":
            continue
        for j in np.flatnonzero(values[i][:-1] * values[i][1:] < 0.0) + 1:
            if times[j - 1] < t_end:
                t = _root(phase, rows[i], 0.0, times[j - 1], times[j])
                if t <= t_end:
                    log.peak[k] = max(log.peak[k], abs(float(ang[k] @ phase.at(t))))


def _release(scene, state) -> None:
    """Open the closed interface whose linearised margin is most negative (< -1e-12 of its
    moment) at the state, about that corner: the other interface's change moved its
    forces."""
    m = linear_lock_margins(scene.geo, state.q, *state.sides, state.flat, _ground(scene, state))
    closed = [k for k in (st.LOWER, st.UPPER) if state.flat[k]]
    worst = min(
        (m[i, j] / scene.moment[k], k, corner)
        for i, k in enumerate(closed)
        for j, corner in enumerate((1, -1))
    )
    if worst[0] < -1e-12:
        state.flat[worst[1]], state.sides[worst[1]] = False, worst[2]


def _ground(scene, state) -> float:
    """u_g'' [m/s^2] at the state's time (zero after the motion)."""
    _, _, w, c = exosystem(scene.motion, state.t)
    return float(c @ w)


def _phase(scene, state, log):
    """Run the current regime exactly to its first terminal event or its segment's end and
    act on the event. Returns the overturned body's name or None."""
    if any(state.flat):
        _release(scene, state)
    phase = _Phase(scene, state)
    rows, offsets, kinds = _events(scene, state, phase)
    times, states = phase.grid()
    values = rows @ states - offsets[:, None]
    t_end, event = _first_event(phase, rows, offsets, kinds, times, values)
    _log_peaks(phase, rows, kinds, times, values, t_end, log)
    state.t, (state.q, state.qd) = t_end, phase.angles(t_end)
    log.row(state)
    return _act(scene, state, log, event, at_pivots=True)


def simulate_stacked_linear(stacked, motion, t_max=None) -> StackedResult:
    """Two stacked blocks through a horizontal ground motion, linearised for small alpha
    and solved exactly in each regime (this module's method).

    Parameters
    ----------
    stacked : StackedBlocks
        The assembly (both bodies slender: the model's error is of relative order alpha^2).
    motion : Motion
        A trigonometric pulse or a record (horizontal only).
    t_max : float, optional
        End of the history [s]; by default the free rocking after the motion is followed to
        rest (an impact slower than 1e-4 p alpha of the interface's block closes it).

    Returns
    -------
    StackedResult
        As :func:`.stacked_reference.simulate_stacked`, ``method`` "linear"; the history
        holds the phases' ends and the impacts (not a dense output).
    """
    if t_max is not None:
        t_max = _validate.positive("t_max", t_max)
    # the reference's scene (geometry, p, alpha, rest speeds, moment scales; a vertical
    # component refused), state and log; its rtol is not used here
    scene, state, log, fell = (
        _Scene(stacked, motion, 1e-12, t_max),
        _State((0.0,) * 4),
        _Log(),
        None,
    )
    scene.motion = motion
    log.row(state)
    phases = 0
    for phases in range(MAX_PHASES):  # noqa: B007 (the count is reported)
        if state.t >= scene.t_end or (all(state.flat) and state.t >= scene.dur):
            break
        fell = _phase(scene, state, log)
        if fell is not None:
            break
    else:
        raise RuntimeError(f"StackedBlocks: more than {MAX_PHASES} regime phases in one run")
    packed = _pack(scene, state, log, fell, phases)  # the reference's result, relabelled
    info = {"solver": "exact per regime (stacked_linear)", "phases": phases + 1}
    return dataclasses.replace(packed, method="linear", info=info)
