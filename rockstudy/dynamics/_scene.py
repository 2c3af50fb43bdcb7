"""The scene and batch drivers (private): one block or mechanism through one motion
(:func:`scene`: uplift, phases, then the free-rocking map or the integrated free rocking),
and many in parallel or serially (:func:`scene_batch` and its variants)."""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from ..constants import FALL_ROTATION
from ..motions._kernels import KIND_RECORD, ground_acceleration, segment_index
from ._demand import FREE_ROCKING_SLENDERNESS, demand_outcome
from ._free_map import free_peak_time, free_rocking_map, free_tail_end
from ._logs import _push, new_tallies, raise_max
from ._phase import PhaseState, Stepping, _phase, _phase_trig, _variant_named, _work_arrays
from ._rows import new_rows, write_row
from ._tables import _free_map_table
from ._uplift import next_uplift
from .constants import (
    FIRST,
    FIRST_STEP,
    MODEL_NONLINEAR,
    MODEL_TABLE,
    NO_STOP,
    NO_TABLE,
    PH_END,
    PH_FAIL,
    PH_IMPACT,
    PH_OVER,
    PH_REST,
    REST_FRACTION,
    STATUS_MAX_STEPS,
    STATUS_OK,
    TOL_SAFETY,
)
from .outputs import KERNEL_ROW

Body = namedtuple("Body", ("p", "alpha", "eta", "model", "fall", "table"))


Body.__doc__ = """What rocks in a :func:`scene`: p [rad/s], alpha [rad] (for MODEL_TABLE phi_cr,
and p the mechanism's p_eq, which then only scales the error tolerances), the restitution
eta [-], the model (MODEL_NONLINEAR, MODEL_LINEAR or MODEL_TABLE), the rotation ``fall``
[rad] at which it is taken to have collapsed (FALL_ROTATION for a block), and the mechanism's
``table`` (:data:`NO_TABLE` for a block)."""


Controls = namedtuple(
    "Controls", ("rtol", "max_steps", "free_map", "tail_end", "demand"), defaults=(False,)
)


Controls.__doc__ = """How a :func:`scene` is computed: the relative tolerance ``rtol``, the
most steps of one phase ``max_steps`` (exceeded: STATUS_MAX_STEPS), whether the free rocking
after the motion is mapped (``free_map``: :func:`free_rocking_map`, no history) rather than
integrated, ``tail_end`` [s], where an integrated free rocking stops
(:func:`free_tail_end`), and whether the friction demand and lift-off of Housner's block are
computed (``demand``, default False: :mod:`._demand`; NaN otherwise, and for the other
models)."""


Start = namedtuple("Start", ("theta", "theta_dot"))


Start.__doc__ = """The state at the start of the motion of a :func:`scene`: theta [rad] and
theta_dot [rad/s]; (0, 0) is rest (the block then waits for uplift)."""


SceneOutcome = namedtuple(
    "SceneOutcome",
    (
        "status",
        "max_rotation",
        "overturned",
        "n_impacts",
        "overturn_time",
        "n_history",
        "n_impact_times",
        "steps",
        "first_impact_time",
        "n_peaks",
        "peak_time",
        "friction_demand",
        "lift_off",
    ),
)


SceneOutcome.__doc__ = """What a :func:`scene` returns: ``status`` (STATUS_OK or
STATUS_MAX_STEPS), ``max_rotation`` max |theta| [rad], ``overturned``, ``n_impacts``,
``overturn_time`` [s] (NaN if it stands), the rows the log needed (``n_history`` history
rows, ``n_impact_times`` impact times, ``n_peaks`` peaks: more than the arrays hold means
they overflowed), ``steps`` (integrator steps: DOP853, or Taylor inside a record) and
``first_impact_time`` [s] (NaN if none), ``peak_time`` [s] when max |theta| was reached (the
overturning time if it overturned; NaN if it never rocked), ``friction_demand`` and
``lift_off`` (:func:`._demand.demand_outcome`: NaN and False where not computed)."""


@njit(cache=True)
def _outcome(code, state, tallies, body):
    """The :class:`SceneOutcome` of a scene whose last phase ended with ``code`` in ``state`` (a
    :class:`PhaseState`), from its tallies (the array of :func:`new_tallies`) and its
    :class:`Body`."""
    ta = tallies[0]
    over = code == PH_OVER
    demand, lift_off = demand_outcome(ta, over, body.eta, body.alpha)
    return SceneOutcome(
        status=STATUS_MAX_STEPS if code == PH_FAIL else STATUS_OK,
        max_rotation=ta.max_rotation,
        overturned=over,
        n_impacts=ta.n_impacts,
        overturn_time=state.t if over else np.nan,
        n_history=ta.n_history,
        n_impact_times=ta.n_impact_times,
        steps=ta.steps,
        first_impact_time=ta.first_impact_time,
        n_peaks=ta.n_peaks,
        peak_time=state.t if over else ta.peak_time,
        friction_demand=demand,
        lift_off=lift_off,
    )


@njit(cache=True, inline="always")
def _lift_off(body, mot, hist, ta, state):
    """The :class:`PhaseState` of a block at rest in ``state`` when it lifts off
    (:func:`._uplift.next_uplift`), on the side the ground pushes it to, logged in ``hist``
    if that is within the motion; t = inf if it never lifts."""
    kind, mp, times, samples, vsamples = mot
    p, alpha, model, tab = body.p, body.alpha, body.model, body.table
    t_up = next_uplift(kind, mp, times, samples, vsamples, p, alpha, model, tab, state.t)
    if t_up >= mp[3]:
        return PhaseState(t_up, state.theta, state.theta_dot, state.side, state.h)
    k = segment_index(times, t_up, FIRST) if kind == KIND_RECORD else 0
    a_g = ground_acceleration(kind, mp, times, samples, t_up, k)
    if hist.shape[0] > 0:
        _push(hist, ta, t_up, 0.0, 0.0)
    return PhaseState(t_up, 0.0, 0.0, -1.0 if a_g > 0.0 else 1.0, state.h)


@njit(cache=True, inline="always")
def _block_map_from(state, p, alpha, eta, model, omega_rest):
    """:func:`._free_map.free_rocking_map` from the state of a phase (a :class:`PhaseState`)."""
    u, v = state.side * state.theta, state.side * state.theta_dot
    return free_rocking_map(u, v, p, alpha, eta, model, omega_rest)


@njit(cache=True, inline="always")
def _raise_to_mapped_peak(ta, state, body, peak):
    """Raise the largest rotation of the tallies ``ta`` to the ``peak`` that the free-rocking
    map found from ``state`` (a :class:`PhaseState`), at its time (:func:`free_peak_time`; NaN
    for a mechanism's table, whose free rocking has no closed-form time)."""
    if peak > ta.max_rotation:
        if body.model == MODEL_TABLE:
            dt = np.nan
        else:
            u, v = state.side * state.theta, state.side * state.theta_dot
            dt = free_peak_time(u, v, body.p, body.alpha, body.eta, body.model)
        raise_max(ta, peak, state.t + dt)


@njit(cache=True, inline="always")
def _table_map_from(state, eta, tab, omega_rest):
    """:func:`._tables._free_map_table` from the state of a phase (a :class:`PhaseState`) of
    a mechanism, on the tables ``tab`` of its two directions."""
    u, v = state.side * state.theta, state.side * state.theta_dot
    side = 0 if state.side > 0.0 else 1
    return _free_map_table(u, v, eta, tab[side], tab[1 - side], omega_rest)


@njit(cache=True, inline="always")
def _scene_start(body, controls, start):
    """The start of a :func:`scene`: its :class:`Stepping` (the rest speed REST_FRACTION p
    alpha [rad/s] and the local error target TOL_SAFETY rtol), the first
    :class:`PhaseState` (on the side the start rocks on; the first step FIRST_STEP / p [s])
    and whether it starts at rest."""
    p, alpha = body.p, body.alpha
    th0, om0 = start.theta, start.theta_dot
    omega_rest = REST_FRACTION * p * alpha
    tol = TOL_SAFETY * controls.rtol
    demand = controls.demand and body.model == MODEL_NONLINEAR
    stepping = Stepping(
        p,
        alpha,
        body.eta,
        body.model,
        omega_rest,
        tol,
        controls.max_steps,
        body.fall,
        body.table,
        demand,
    )
    s0 = math.copysign(1.0, th0 if th0 != 0.0 else om0)  # the side the start rocks on
    state = PhaseState(0.0, th0, om0, s0, FIRST_STEP / p)
    return stepping, state, th0 == 0.0 and om0 == 0.0


def _make_scene(general):
    """:func:`scene` on :func:`_phase` (``general``), or :func:`scene_trig` on
    :func:`_phase_trig` (block models under a trigonometric pulse, no vertical component)."""

    @njit(cache=True)
    @_variant_named(general)
    def scene(body, mot, controls, start, log):
        """Rock one block (or tabulated mechanism) through one motion, from rest or a given state.

        body: a :class:`Body`; mot = (kind, mp, times, samples, vsamples) (see
        :mod:`rockstudy.motions._kernels`); controls: a :class:`Controls`; start: a
        :class:`Start`, (0, 0) for rest; log = (hist, imps, peaks, dense): arrays to fill with
        history rows (t, theta, theta_dot), impact times and peaks (t, theta, the maxima of
        |theta|), and the requested times dense[:, 0] (sorted), whose states the integration
        writes into dense[:, 1:3] (the rows it does not reach, in a rest or after a fall, keep
        their values: fill them with 0, the state at rest); each of length 0 for none.
        Returns a :class:`SceneOutcome`.
        """
        stepping, state, at_rest = _scene_start(body, controls, start)
        th0, om0 = start.theta, start.theta_dot
        hist = log[0]
        rec = hist.shape[0] > 0
        dur = mot[1][3]
        tallies = new_tallies(abs(th0))
        ta = tallies[0]  # updated in place; the outcome reads tallies, last (new_tallies)
        wk = _work_arrays()
        if rec:
            _push(hist, ta, 0.0, th0, om0)
        code = PH_END
        phases = 0
        while state.t < dur:
            phases += 1
            if phases > controls.max_steps:  # a guard: every phase must move the state on
                code = PH_FAIL
                break
            if at_rest:
                lifted = _lift_off(body, mot, hist, ta, state)
                if lifted.t >= dur:
                    break
                state, at_rest = lifted, False
            if general:
                code, state = _phase(stepping, mot, log, state, ta, wk, dur, NO_STOP)
            else:
                code, state = _phase_trig(stepping, mot, log, state, ta, wk, dur, NO_STOP)
            if code != PH_END and code != PH_REST:
                break
            at_rest = code == PH_REST
        if controls.free_map and code == PH_END and not at_rest and ta.n_impacts == 0:
            # integrate on to time the first impact
            if general:
                code, state = _phase(
                    stepping, mot, log, state, ta, wk, controls.tail_end, np.int64(1)
                )
            else:
                code, state = _phase_trig(
                    stepping, mot, log, state, ta, wk, controls.tail_end, np.int64(1)
                )
            at_rest = code == PH_REST
        if at_rest:
            if rec:
                _push(hist, ta, dur, 0.0, 0.0)
        elif code == PH_END or code == PH_IMPACT:
            eta, omega_rest = body.eta, stepping.omega_rest
            if general and body.model == MODEL_TABLE:
                over, peak, n_post = _table_map_from(state, eta, body.table, omega_rest)
            else:
                over, peak, n_post = _block_map_from(
                    state, body.p, body.alpha, eta, body.model, omega_rest
                )
            if controls.free_map and not over and eta < 1.0:
                if body.alpha > FREE_ROCKING_SLENDERNESS:  # its demand is not bounded
                    ta.d_uncovered = 1
                _raise_to_mapped_peak(ta, state, body, peak)
                ta.n_impacts += n_post
            else:  # integrate the free rocking: for the history, to time the overturning, or to
                # count the impacts of a block that never rests (eta = 1) up to the tail's end
                if general:
                    code, state = _phase(
                        stepping, mot, log, state, ta, wk, controls.tail_end, NO_STOP
                    )
                else:
                    code, state = _phase_trig(
                        stepping, mot, log, state, ta, wk, controls.tail_end, NO_STOP
                    )
        return _outcome(code, state, tallies, body)

    return scene


scene = _make_scene(True)
scene_trig = _make_scene(False)


#: The fields of a batch kernel's row (:data:`.outputs.KERNEL_ROW`).
BATCH_COLUMNS = KERNEL_ROW.names


def _make_scene_batch(general, parallel=True):
    """:func:`scene_batch` (every motion and model) or :func:`scene_batch_trig` (the block
    models under trigonometric pulses without a vertical component, :func:`scene_trig`); with
    ``parallel=False`` their one-thread variants (``*_serial``), which a study's workers run
    (one thread each): the parallel loop's lowering costs a fifth of a cold sine study's
    compile (about 6 s of 30 s CPU)."""

    @njit(cache=True, parallel=parallel)
    @_variant_named(general, serial=not parallel)
    def scene_batch(
        p, alpha, eta, model, kind, mp, times, samples, vsamples, rtol, max_steps, demand=False
    ):
        """:func:`scene` over rows of (p, alpha, eta, mp[i]) with the free-rocking map, in parallel
        (``vsamples``: the vertical component, empty for none; scaled by |mp[i, 0]|), with the
        friction demand and lift-off of Housner's block if ``demand`` (:mod:`._demand`).

        Returns an array of :data:`.outputs.KERNEL_ROW` rows.
        """
        out = new_rows(p.shape[0])
        no_log = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
        for i in prange(p.shape[0]):
            body = Body(p[i], alpha[i], eta[i], model, FALL_ROTATION, NO_TABLE)
            mot = (kind, mp[i], times, samples, vsamples)
            tail = free_tail_end(p[i], eta[i], mp[i, 3])
            ctl = Controls(rtol, max_steps, True, tail, demand)
            if general:
                r = scene(body, mot, ctl, Start(0.0, 0.0), no_log)
            else:
                r = scene_trig(body, mot, ctl, Start(0.0, 0.0), no_log)
            write_row(out, i, r)
        return out

    return scene_batch


scene_batch = _make_scene_batch(True)
scene_batch_trig = _make_scene_batch(False)
scene_batch_serial = _make_scene_batch(True, parallel=False)
scene_batch_trig_serial = _make_scene_batch(False, parallel=False)
