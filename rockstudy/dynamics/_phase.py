"""The phase loop (private): rocking on from a state until rest, overturning or a stop time.

:func:`_phase` steps any motion and model; :func:`_phase_trig` only the block models under a
trigonometric pulse without a vertical component (Taylor steps throughout), a variant that
compiles in about half the time. Both come from one factory (:func:`_make_phase`) and are
named apart (:func:`_variant_named`) for numba's cache.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ..motions._kernels import KIND_RECORD, KIND_TRIG, segment_index
from ._demand import demand_step
from ._events import EV_NONE, EV_OVER, EV_REJECT, _impact, _zeno
from ._logs import _log_dop853_step, _log_peak, _log_poly_step, _push, raise_max
from ._rhs import _accel, _ground_after, _vertical_after
from ._steps import _dop853_attempt, _taylor_attempt, _taylor_trig_attempt
from ._taylor import NO_REFCOUNT, work_arrays
from .constants import FIRST, MODEL_TABLE, PH_END, PH_FAIL, PH_IMPACT, PH_OVER, PH_REST

PhaseState = namedtuple("PhaseState", ("t", "theta", "theta_dot", "side", "h"))


PhaseState.__doc__ = """The state of a rocking phase (:func:`_phase`): the time t [s], theta
[rad], theta_dot [rad/s], the side s (+1.0 or -1.0) it rocks on and the next step size h [s]."""


Stepping = namedtuple(
    "Stepping",
    ("p", "alpha", "eta", "model", "omega_rest", "tol", "max_steps", "fall", "table", "demand"),
)


Stepping.__doc__ = """What a rocking phase (:func:`_phase`) steps: the body (p [rad/s], alpha
[rad], eta, model, ``fall`` [rad] and ``table`` of a :class:`Body`), the speed ``omega_rest``
[rad/s] below which an impact leaves it at rest, the local error target ``tol`` (TOL_SAFETY
rtol), the most steps ``max_steps`` of one phase, and whether the friction demand is computed
on its steps (``demand``: :mod:`._demand`)."""


@njit(cache=True)
def _work_arrays():
    """Work arrays of one scene, allocated once and passed down to every phase: the DOP853
    stage derivatives of theta and theta_dot (13 each), and the Taylor series
    of :mod:`._taylor` (:func:`._taylor.work_arrays`)."""
    return np.empty(13), np.empty(13), work_arrays()


def _variant_named(general, serial=False):
    """Decorator (under ``@njit``) that names a factory's trig-only variant apart:
    ``<name>_trig``, and a serial one ``<name>_serial``. numba names a compiled function, and
    so its cache entry, by its qualified name and a counter of the process that compiled it;
    two variants of one name that were each the first function compiled in their process (a
    CLI run, a test's child process) got one name, and a process that loaded both from the
    cache ran the second with the first's environment (scene_batch after scene_batch_trig:
    RuntimeError "'descr' is NULL")."""

    def name(fn):
        suffix = ("" if general else "_trig") + ("_serial" if serial else "")
        fn.__name__ += suffix
        fn.__qualname__ += suffix
        return fn

    return name


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _accel_after(stepping, mot, t, k, th, om, s):
    """theta_ddot just after t (record segment k) in the state (th, om) on side s, under the
    ground just after t (:func:`._rhs._ground_after`, :func:`._rhs._vertical_after`)."""
    kind, mp, times, samples, vsamples = mot
    return _accel(
        _ground_after(kind, mp, times, samples, t, k),
        _vertical_after(kind, mp, times, vsamples, t, k),
        th,
        om,
        stepping.p,
        stepping.alpha,
        s,
        stepping.model,
        stepping.table,
    )


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _after_impact(stepping, mot, log, ta, t, th, om, s, k, t_ev, om_ev):
    """The state after an impact at t_ev [s] of a phase at (t, th, om) on side s (record
    segment k), with speed om_ev just before it: the impact (:func:`._events._impact`) and
    the side or rest after it (:func:`._events._zeno`). Returns (at rest, t, theta, theta_dot,
    side, segment, theta_ddot after it; NaN at rest)."""
    kind, mp, times, samples, vsamples = mot
    hist, imps = log[0], log[1]
    t, om = _impact(t, th, om, t_ev, om_ev, stepping.eta, ta, imps, hist)
    ta.d_fresh = 1  # the forces jump at an impact: the next step's start is a sample
    if kind == KIND_RECORD:
        k = segment_index(times, min(t, mp[3]), k)
    a_g = _ground_after(kind, mp, times, samples, t, k)
    a_v = _vertical_after(kind, mp, times, vsamples, t, k)
    p, alpha, model, tab = stepping.p, stepping.alpha, stepping.model, stepping.table
    resting, s, om = _zeno(om, s, stepping.omega_rest, a_g, a_v, p, alpha, model, tab)
    f0 = np.nan if resting else _accel(a_g, a_v, 0.0, om, p, alpha, s, model, tab)
    return resting, t, 0.0, om, s, k, f0


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _peak_inside(peaks, ta, u_pk, t_pk, s):
    """Log the peak of u = s theta that a step found inside it (``u_pk`` >= 0 at ``t_pk``
    [s]; -1 for none) and raise the largest rotation to it."""
    if u_pk >= 0.0:
        raise_max(ta, u_pk, t_pk)
        _log_peak(peaks, ta, t_pk, s * u_pk)


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _reached(hist, ta, t, th, om, u):
    """A step's end (t [s], theta [rad], theta_dot [rad/s]) with u = s theta: the largest
    rotation raised to u, and the history row appended when a history is kept."""
    raise_max(ta, u, t)
    if hist.shape[0] > 0:
        _push(hist, ta, t, th, om)


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _fell(hist, ta, t, th, om, fall):
    """The fall at t [s], theta = +-``fall`` [rad]: the largest rotation is ``fall``, the
    history row appended when a history is kept; returns (t, theta, theta_dot)."""
    ta.max_rotation = fall
    ta.peak_time = t
    if hist.shape[0] > 0:
        _push(hist, ta, t, th, om)
    return t, th, om


def _make_phase(general):
    """The phase kernel (:func:`_phase`): for every motion and model (``general``), or only for
    the block models under a trigonometric pulse without a vertical component, which step by
    Taylor series throughout (:func:`_phase_trig`). The branches of the other steps are
    constants of the closure, pruned before numba types them: that variant compiles in about
    half the time (a study of sine pulses from an empty cache)."""
    trig_only = not general

    @njit(cache=True, **NO_REFCOUNT)
    @_variant_named(general)
    def phase(stepping, mot, log, state, ta, wk, t_stop, stop_at_impacts):
        """Integrate rocking from ``state`` (a :class:`PhaseState`) until rest, overturning or
        t_stop.

        stepping: a :class:`Stepping`; mot = (kind, mp, times, samples, vsamples), log = (hist,
        imps, peaks, dense) (see :func:`scene`).
        wk = (kx, kv, w): the scene's work arrays (:func:`_work_arrays`).
        The tallies ``ta`` (a :data:`TALLIES` record) are updated in place. Returns (code,
        the :class:`PhaseState` at the end): PH_END, PH_REST, PH_OVER or PH_FAIL; or PH_IMPACT
        once the impact count reaches ``stop_at_impacts`` (the state is then just after that
        impact; :data:`NO_STOP` for never). The block models step by Taylor series inside a record
        (:func:`_taylor_attempt`), under a trigonometric pulse and in the free rocking after any
        motion (:func:`_taylor_trig_attempt`); a Ricker wavelet and a mechanism's table by DOP853.
        """
        p, alpha, model, tab = stepping.p, stepping.alpha, stepping.model, stepping.table
        kind, mp, times, samples, vsamples = mot
        hist, peaks, fall = log[0], log[2], stepping.fall
        t, th, om, s, h = state
        dur = mp[3]
        kx, kv, w = wk
        k = segment_index(times, t, FIRST) if kind == KIND_RECORD else 0
        f0 = _accel_after(stepping, mot, t, k, th, om, s)
        ta.d_fresh = 1
        steps = 0
        code = PH_END
        while t < t_stop:
            steps += 1
            ta.steps += 1
            if steps > stepping.max_steps:
                code = PH_FAIL
                break
            t_next = t_stop
            in_record = kind == KIND_RECORD and t < dur
            if in_record:  # end steps on record samples (kinks in u_g'')
                k = segment_index(times, t, k)
                t_next = min(t_next, times[k + 1])
            # Taylor series for the block models (a tabulated mechanism steps by DOP853): on record
            # samples, under a trigonometric pulse, and with no ground motion after any motion
            taylor = model != MODEL_TABLE and (in_record or t >= dur or kind == KIND_TRIG)
            if general and in_record and taylor:
                out = _taylor_attempt(w, stepping, mot, t, th, om, f0, h, t_next, s, k)
            elif trig_only or taylor:
                out = _taylor_trig_attempt(w, stepping, mot, t, th, om, f0, h, t_next, s)
            else:
                args = (p, alpha, s, model, kind, mp, times, samples, vsamples, k, tab)
                out = _dop853_attempt(args, t, th, om, f0, h, t_next, s, stepping.tol, fall, kx, kv)
            ev, h, hs, t1, th1, om1, f1, t_ev, om_ev, u_pk, t_pk, work, order = out
            ta.steps += work
            if ev == EV_REJECT:
                continue
            _peak_inside(peaks, ta, u_pk, t_pk, s)
            t_end = t1 if ev == EV_NONE else t_ev  # the step's end, or its event
            if trig_only or taylor:
                _log_poly_step(log, ta, w, order, t, hs, t_end)
                if stepping.demand:
                    end = (th1, om1) if ev == EV_NONE else (np.nan, np.nan)
                    demand_step(ta, w, order, t, hs, t_end, s, p, alpha, mot, k, end)
            else:
                args = (p, alpha, s, model, kind, mp, times, samples, vsamples, k, tab)
                _log_dop853_step(log, ta, args, t, t_end, th, om, f0, kx, kv)
                ta.d_uncovered = 1
            if ev == EV_OVER:
                t, th, om = _fell(hist, ta, t_ev, s * fall, om_ev, fall)
                code = PH_OVER
                break
            if ev == EV_NONE:
                _reached(hist, ta, t1, th1, om1, s * th1)
                t, th, om, f0 = t1, th1, om1, f1
                continue
            # impact at t_ev, with speed om_ev just before it
            resting, t, th, om, s, k, f0 = _after_impact(
                stepping, mot, log, ta, t, th, om, s, k, t_ev, om_ev
            )
            if resting:
                code = PH_REST
                break
            if ta.n_impacts == stop_at_impacts:
                code = PH_IMPACT
                break
        return code, PhaseState(t, th, om, s, h)

    return phase


_phase = _make_phase(True)
_phase_trig = _make_phase(False)
