"""The event-driven kernel of two stacked blocks (private): one scene from rest through one
ground motion (:func:`stacked_scene`) and many in parallel (:func:`stacked_batch`).

The same model and the same history as :func:`.stacked_reference.simulate_stacked`: rest
until an interface lifts (:func:`._stacked_impact.uplift_from_rest`), then phases of one
regime stepped by DOP853 (:mod:`._stacked_steps`) to their first event
(:mod:`._stacked_events`): an impact (:func:`._stacked_impact.resolve_impact`), an uplift, or
a fall, which ends the run; a closed interface whose lock margin is negative at a phase's
start opens first. The steps stop at every record sample (u_g'' has a kink there) and at the
end of the motion; the history ends at rest after the motion or at a fall.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from ..constants import FALL_ROTATION
from ..motions._kernels import KIND_RECORD, segment_index
from ._stacked_events import (
    EVENT_FALL,
    EVENT_IMPACT,
    EVENT_NONE,
    EVENT_UPLIFT,
    SAMPLES,
    event_state,
    first_event,
    step_peaks,
)
from ._stacked_impact import REST_BISECTIONS, resolve_impact, scan_cell_end, uplift_from_rest
from ._stacked_model import P1, P2, lock_margins
from ._stacked_steps import (
    DENSE_STAGES,
    DENSE_TAYLOR,
    K_END,
    K_FEND,
    K_INFO,
    derivative,
    dop853_step,
    ground,
    interface_data,
    one_body_form,
    one_body_step,
    step_error,
    work_array,
)
from ._stacked_taylor import both_step, one_body_series
from ._taylor import NO_REFCOUNT, work_arrays
from .constants import (
    FIRST_STEP,
    STATUS_MAX_STEPS,
    STATUS_OK,
    STEP_GROW_LIMIT,
    STEP_SAFETY,
    STEP_SHRINK_LIMIT,
    TAYLOR_TOL_FRACTION,
    TOL_SAFETY,
)
from .stacked_reference import MAX_PHASES

#: Local error target as a fraction of rtol (the rocking kernels' TOL_SAFETY is 0.1): near an
#: overturning the two bodies' unstable motion amplifies local errors more than one block's
#: (a scene of the accuracy test erred by 25 rtol at 0.1, and the reference by 120 rtol at
#: rtol 1e-11).
TOL_FRACTION = 0.01

#: Local error target of a one-body regime's Taylor step, as a fraction of rtol: the
#: single-block kernel's record step (TAYLOR_TOL_FRACTION of TOL_SAFETY rtol). Its bound on
#: the truncation error is no norm of a 5th/3rd-order pair: at TOL_FRACTION a scene whose
#: statue fell after a long free phase erred by 10 rtol in its plinth's angle.
TAYLOR_TOL = TAYLOR_TOL_FRACTION * TOL_SAFETY

#: Longest step, in units of 1/p_max: the events of a step are sought on its interpolant.
STEP_CAP = 0.5

#: The first step of a phase that starts with a rebound, in units of the rebound's hop time
#: on the start's parabola (:func:`_hop_step`): the hop ends inside it.
HOP_STEP = 1.5

#: A phase's ends besides its events (:data:`._stacked_events.EVENT_NONE`...).
PHASE_END, PHASE_MAX_STEPS = 10, 11

#: ``overturned_body`` codes of a scene (as :data:`.two_body_batch.OVERTURNED_BODY`).
BODY_NONE, BODY_LOWER, BODY_UPPER, BODY_BOTH = 0, 1, 2, 3


_FIELDS = "status max_rotation_lower max_rotation_upper overturned overturned_body"
StackedOutcome = namedtuple("StackedOutcome", _FIELDS + " overturn_time n_impacts")


StackedOutcome.__doc__ = """The outcome of a :func:`stacked_scene`: status (STATUS_OK or
STATUS_MAX_STEPS), max |theta_1| and max |phi| [rad], whether a body fell, its code
(BODY_NONE...), when [s] (NaN if none) and the number of impacts."""


@njit(cache=True, **NO_REFCOUNT)
def _next_stop(mot, t, t_end):
    """(the time the step from t must stop at, the record segment of t): the next record
    sample or the motion's end; ``t_end`` after the motion."""
    dur, seg = mot[1][3], mot[4]
    if t >= dur:
        return t_end, seg
    if mot[0] != KIND_RECORD:
        return min(dur, t_end), seg
    seg = segment_index(mot[2], t, seg)
    stop = mot[2][seg + 1] if seg + 1 < mot[2].shape[0] else dur
    return min(stop, dur, t_end), seg


@njit(cache=True, inline="always")
def _segment_of(kind, times, dur, t, seg):
    """The record segment of t (from the hint seg; of the motion's end after it): a phase
    starts at an uplift from rest or an event anywhere in the record."""
    if kind != KIND_RECORD:
        return seg
    return segment_index(times, min(t, dur), seg)


@njit(cache=True, **NO_REFCOUNT)
def _accepted(g, hs, y0, y1, w, tol, h, last):
    """(accepted, next step) of a DOP853 step of length hs (Hairer's step control)."""
    err = step_error(g, w, hs, y0, y1, tol)
    if not err <= 1.0:  # rejected (or NaN)
        shrink = max(STEP_SHRINK_LIMIT, STEP_SAFETY * err ** (-0.125)) if err == err else 0.2
        return False, hs * shrink
    grow = STEP_GROW_LIMIT if err == 0.0 else min(STEP_GROW_LIMIT, STEP_SAFETY * err ** (-0.125))
    return True, (max(h, hs * grow) if last else hs * grow)


@njit(cache=True, **NO_REFCOUNT)
def _one_body_step(g, form, mot, t, hs, t1, y, f0, tol, tw, y1):
    """:func:`._stacked_steps.one_body_step` from t to t1 (= t + hs) on a record's segment (u_g''
    linear there; its acceleration f0 at t) or after the motion (no ground motion: the
    derivative carried from the motion's last instant does not hold)."""
    tol *= TAYLOR_TOL / TOL_FRACTION
    if t >= mot[1][3]:
        return one_body_step(g, form, y, hs, 0.0, 0.0, np.nan, tol, tw, y1)
    dd0 = f0[2 + form[0]]
    return one_body_step(g, form, y, hs, ground(mot, t), ground(mot, t1), dd0, tol, tw, y1)


@njit(cache=True, **NO_REFCOUNT)
def _taylor_step(g, form, regime, mot, t, hs, t1, y, f0, tol, tw, w):
    """A Taylor step from t to t1 (= t + hs) on a record's segment or after the motion, its
    end into w[K_END]: (error ratio, order) of a both-rocking step
    (:func:`._stacked_taylor.both_step`) or of a one-body one (:func:`_one_body_step`), its
    series kept in w (:func:`._stacked_taylor.one_body_series`)."""
    if form[0] >= 0:
        err, n = _one_body_step(g, form, mot, t, hs, t1, y, f0, tol, tw, w[K_END])
        one_body_series(w, tw[0], n, form[0], y, hs)
        return err, n
    u0, u1 = (ground(mot, t), ground(mot, t1)) if t < mot[1][3] else (0.0, 0.0)
    tol *= TAYLOR_TOL / TOL_FRACTION
    return both_step(g, y, hs, regime[0], regime[1], u0, u1, tol, w, w[K_END])


@njit(cache=True, inline="always")
def _taylor_accepted(err, hs, h, last):
    """(accepted, next step) of a Taylor step of length hs (the single-block kernel's
    control: halved on rejection, doubled otherwise)."""
    if not err <= 1.0:  # rejected (or NaN)
        return False, 0.5 * hs
    return True, (max(h, 2.0 * hs) if last else 2.0 * hs)


@njit(cache=True, **NO_REFCOUNT)
def _hop_step(regime, y, f0):
    """The first step of a phase in which a rocking interface leaves zero (an impact's
    rebound): HOP_STEP times its hop's duration on the start's parabola (u' > 0 > u''), so
    that the hop of a chatter ends inside one short step of low order; inf if none."""
    s1, s2, flat0, flat1 = regime
    hop = math.inf
    for k in range(2):
        if (flat0, flat1)[k]:
            continue
        s = (s1, s2)[k]
        x, v, a = interface_data(k, y, f0)
        if x == 0.0 and s * v > 0.0 and s * a < 0.0:
            hop = min(hop, HOP_STEP * 2.0 * v / -a)
    return hop


@njit(cache=True, **NO_REFCOUNT)
def _raise_peaks(y, peaks):
    peaks[0] = max(peaks[0], abs(y[0]))
    peaks[1] = max(peaks[1], abs(y[1] - y[0]))


@njit(cache=True, **NO_REFCOUNT)
def run_phase(g, mot, iv, y, st, tol, max_steps, peaks, w, margins, tmp, rates, tw):
    """One regime from the state (st = (t, h, t_end, record segment), y, iv) to its first
    event or ``t_end``: returns (kind, interface, corner), the state moved to the event (or
    the end). ``rates``: the work array of :func:`._stacked_events.first_event`; ``tw``
    the Taylor work array of a one-body regime's steps (:func:`._taylor.work_arrays`):
    those step by Taylor series on a record's segments and after the motion, the others
    (and pulses) by DOP853."""
    regime = (iv[2], iv[3], iv[0] != 0, iv[1] != 0)
    t, h, t_end = st[0], st[1], st[2]
    cap = STEP_CAP / max(g[P1], g[P2])
    seg = mot[4]
    mot = (mot[0], mot[1], mot[2], mot[3], seg)
    f0 = tmp[12:16]
    derivative(g, regime, mot, t, y, f0)
    form, dur = one_body_form(g, regime), mot[1][3]
    hop = _hop_step(regime, y, f0)
    for _ in range(max_steps):
        stop, seg = _next_stop(mot, t, t_end)
        if t >= stop:
            st[0], st[1], st[3] = t, h, seg
            return PHASE_END, -1, 0
        mot = (mot[0], mot[1], mot[2], mot[3], seg)
        short = hop < min(h, cap)  # a hop's step: h kept for the steps after it
        last = min(h, cap, hop) >= stop - t
        hs = stop - t if last else min(h, cap, hop)
        t1, hop = (stop if last else t + hs), math.inf
        y1, f1 = w[K_END], w[K_FEND]
        if mot[0] == KIND_RECORD or t >= dur:
            err, n = _taylor_step(g, form, regime, mot, t, hs, t1, y, f0, tol, tw, w)
            derivative(g, regime, mot, t1, y1, f1)
            ok, h = _taylor_accepted(err, hs, h, last or short)
            w[K_INFO, 0], w[K_INFO, 1], w[K_INFO, 2] = DENSE_TAYLOR, hs, n
        else:
            dop853_step(g, regime, mot, t, y, f0, hs, w, K_END)
            derivative(g, regime, mot, t1, y1, f1)
            for c in range(4):
                w[12, c] = f1[c]
            ok, h = _accepted(g, hs, y, y1, w, tol, h, last or short)
            w[K_INFO, 0], w[K_INFO, 1] = DENSE_STAGES, hs
        if not ok:
            continue
        lock_margins(g, y1, iv[2], iv[3], regime[2], regime[3], ground(mot, t1), margins)
        sig, kind, k, corner = first_event(
            g, regime, mot, t, hs, y, f0, y1, f1, margins, tmp, w, rates
        )
        step_peaks(g, regime, mot, t, hs, y, f0, y1, f1, min(sig, 1.0), peaks, w, rates)
        if kind == EVENT_NONE:
            t = t1
            for c in range(4):
                y[c], f0[c] = y1[c], f1[c]
            _raise_peaks(y, peaks)
            continue
        t = event_state(g, regime, mot, t, hs, y, f0, sig, kind, k, corner, w, tmp[16:20])
        for c in range(4):
            y[c] = tmp[16 + c]
        _raise_peaks(y, peaks)
        st[0], st[1], st[3] = t, h, seg
        return kind, k, corner
    st[0], st[1], st[3] = t, h, seg
    return PHASE_MAX_STEPS, -1, 0


@njit(cache=True)
def _release_violated(g, mot, iv, y, t, margins):
    """Open a closed interface whose lock margin is already below -1e-12 at a phase's start,
    about the corner of the most negative margin; returns whether one opened."""
    lock_margins(g, y, iv[2], iv[3], iv[0] != 0, iv[1] != 0, ground(mot, t), margins)
    worst, j_worst = -1e-12, -1
    for j in range(4):
        if iv[j // 2] != 0 and margins[j] < worst:
            worst, j_worst = margins[j], j
    if j_worst < 0:
        return False
    iv[j_worst // 2], iv[2 + j_worst // 2] = 0, 1 - 2 * (j_worst % 2)
    return True


@njit(cache=True)
def _rises(g, mot, iv, y, k, t, f):
    """Whether interface k, just opened (iv) at t from rest, rises under its regime's own
    acceleration, computed as its phase's first step computes it (the motion's segment of
    t, :func:`._stacked_steps.derivative`)."""
    mot = (mot[0], mot[1], mot[2], mot[3], _segment_of(mot[0], mot[2], mot[1][3], t, mot[4]))
    derivative(g, (iv[2], iv[3], iv[0] != 0, iv[1] != 0), mot, t, y, f)
    return iv[2 + k] * (f[2] if k == 0 else f[3] - f[2]) > 0.0


@njit(cache=True)
def _rise_start(g, mot, iv, y, k, t_up, f):
    """(start, lifted) of the phase of interface k opened from rest at t_up: t_up if it rises
    there (:func:`_rises`); else, within rounding of its uplift level where the lift test and
    the regime's equation disagree, the first double of the scan cell of t_up where it
    rises (by bisection), or the cell's end with ``lifted`` False (it stays at rest: a body
    the test lifts but its equation holds down would fall back at once, be put to rest and
    be lifted again at the same instant without end)."""
    if _rises(g, mot, iv, y, k, t_up, f):
        return t_up, True
    lo, hi = t_up, scan_cell_end(mot, t_up)
    if not _rises(g, mot, iv, y, k, hi, f):
        return hi, False
    for _ in range(REST_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _rises(g, mot, iv, y, k, mid, f):
            hi = mid
        else:
            lo = mid
    return hi, True


@njit(cache=True)
def _fallen(k, iv):
    """The body code of a fall of interface k."""
    if k == 1:
        return BODY_UPPER
    return BODY_BOTH if iv[1] != 0 else BODY_LOWER


@njit(cache=True)
def stacked_scene(g, kind, mp, times, samples, rtol, max_steps, t_end):
    """Two stacked blocks from rest through one motion: (status, max |theta_1|, max |phi|,
    overturned, body code, overturn time, impacts): a :data:`StackedOutcome`."""
    w, tmp, margins, tw = work_array(), np.empty(24), np.empty(4), work_arrays()
    rates = np.empty((2, SAMPLES + 1))
    y, iv, peaks = np.zeros(4), np.array([1, 1, 1, 1]), np.zeros(2)
    st = np.array([0.0, FIRST_STEP / max(g[P1], g[P2]), t_end, 0.0])
    mot = (kind, mp, times, samples, 0)
    dur, n_imp, status, body, t_over = mp[3], 0, STATUS_OK, BODY_NONE, math.nan
    for _ in range(MAX_PHASES):
        t = st[0]
        mot = (kind, mp, times, samples, _segment_of(kind, times, mp[3], t, int(st[3])))
        if t >= t_end:
            break
        if iv[0] != 0 and iv[1] != 0:
            if t >= dur:
                break
            t_up, k, corner = uplift_from_rest(g, mot, t, tmp)
            if not t_up <= t_end:
                break
            side, iv[k], iv[2 + k] = iv[2 + k], 0, corner
            st[0], lifted = _rise_start(g, mot, iv, y, k, t_up, tmp[12:16])
            if not lifted:
                iv[k], iv[2 + k] = 1, side
            continue
        if (iv[0] != 0 or iv[1] != 0) and _release_violated(g, mot, iv, y, t, margins):
            continue
        ev, k, corner = run_phase(
            g, mot, iv, y, st, TOL_FRACTION * rtol, max_steps, peaks, w, margins, tmp, rates, tw
        )
        if ev == PHASE_MAX_STEPS:
            status = STATUS_MAX_STEPS
            break
        if ev == EVENT_UPLIFT:
            iv[k], iv[2 + k] = 0, corner
        elif ev == EVENT_IMPACT:
            n_imp += 1
            if not resolve_impact(g, y, iv, k, tmp[:6], margins):
                status = STATUS_MAX_STEPS
                break
            _raise_peaks(y, peaks)
        elif ev == EVENT_FALL:
            body, t_over = _fallen(k, iv), st[0]
            peaks[1 if body == BODY_UPPER else 0] = FALL_ROTATION
            break
    else:
        status = STATUS_MAX_STEPS
    return StackedOutcome(status, peaks[0], peaks[1], body != BODY_NONE, body, t_over, n_imp)


@njit(cache=True, parallel=True)
def stacked_batch(
    geoms, kinds, params, times, samples, offsets, rtol, max_steps, t_end, out, codes
):
    """Many scenes in parallel: row i is geoms[i] under the motion (kinds[i], params[i],
    times/samples[offsets[i]:offsets[i + 1]]), to rest after the motion, a fall or t_end [s].
    out[i] = (max |theta_1|, max |phi|, overturn
    time); codes[i] = (status, overturned, body code, impacts)."""
    for i in prange(geoms.shape[0]):
        a, b = offsets[i], offsets[i + 1]
        r = stacked_scene(
            geoms[i], kinds[i], params[i], times[a:b], samples[a:b], rtol, max_steps, t_end
        )
        out[i, 0], out[i, 1] = r.max_rotation_lower, r.max_rotation_upper
        out[i, 2], codes[i, 0], codes[i, 1] = r.overturn_time, r.status, r.overturned
        codes[i, 2], codes[i, 3] = r.overturned_body, r.n_impacts
