"""The numba kernel of the block on an isolated base: one row's history, event-driven, and a
parallel batch of rows (private).

A row follows the reference :mod:`rockstudy.dynamics.isolated_reference` phase by phase:
DOP853 steps (:mod:`._isolated_step`) that end at every record sample and at the motion's
end, the regime (side, slide) of :mod:`._isolated_model` changed at the events of
:mod:`._isolated_events`: uplift, impact (momentum exchange, settling below the rest speed),
overturning, the friction pendulum's stop and break-away. After the motion the row ends once
the block rests and the base can neither lift it nor pass its peak
(:func:`._isolated_model.settled`), or at the reference's tail cap (status 1, as the
reference's incomplete history), at the impact cap or at ``max_steps`` steps (status 1).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..motions._kernels import KIND_RECORD, segment_index
from ._isolated_events import (
    EV_IMPACT,
    EV_LIFT,
    EV_NONE,
    EV_OVER,
    EV_PEAK_TH,
    EV_PEAK_X,
    EV_STOP,
    N_TERMINAL,
    active,
    peak_root,
    refine,
    root,
    value,
)
from ._isolated_model import (
    FALL,
    P_ETA,
    P_HM,
    P_OMEGA,
    P_P,
    P_REST,
    base_acceleration,
    demand,
    ground,
    impact,
    lift_side,
    rhs,
    settled,
    slide_after_jump,
    slide_after_stop,
)
from ._isolated_step import dop853_step, error_norm, first_step, step_factor
from ._taylor import NO_REFCOUNT

#: Columns of a row's output: max ``|theta|``, overturned (0/1), max ``|x_b|``, the
#: overturning time (NaN if none), the impact count, the status (0 ok, 1 cut short).
O_THETA, O_OVER, O_X, O_TIME, O_IMPACTS, O_STATUS = range(6)
N_OUT = 6


@njit(cache=True, **NO_REFCOUNT)
def _sign(v):
    return 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)


@njit(cache=True, **NO_REFCOUNT)
def _ag(mot, t, k):
    return ground(mot, t, k)


@njit(cache=True, **NO_REFCOUNT)
def _stop(mot, t, k, t_end):
    """Where the step from t stops: the next record sample, the motion's end, then t_end."""
    dur = mot[1][3]
    if t >= dur:
        return t_end
    if mot[0] == KIND_RECORD:
        return min(mot[2][k + 1], dur)
    return dur


@njit(cache=True, **NO_REFCOUNT)
def _first_terminal(st, mot, k, side, slide, sgn_x, par, a0, a1):
    """(code, s) of the earliest event that ends the phase inside the step; (EV_NONE, 2)."""
    y0, y1 = st[2], st[4]
    best, s_best = EV_NONE, 2.0
    for code in range(N_TERMINAL):
        if not active(code, side, slide, par):
            continue
        v0 = value(code, y0[0], y0[1], y0[2], y0[3], a0, side, slide, sgn_x, par)
        v1 = value(code, y1[0], y1[1], y1[2], y1[3], a1, side, slide, sgn_x, par)
        if v0 <= 0.0 and v1 > 0.0:
            s = root(code, st, mot, k, side, slide, sgn_x, par)
            if s < s_best:
                best, s_best = code, s
    return best, s_best


@njit(cache=True, **NO_REFCOUNT)
def _peak(code, st, s_end, work, par, mot, k, side, slide, sgn_x, a0, a1, acc, yev):
    """Add the peak of event ``code`` (EV_PEAK_TH or EV_PEAK_X) located in the step before
    s_end, if any, to the maxima ``acc`` = (max ``|x_b|``, max ``|theta|``)."""
    if not active(code, side, slide, par):
        return
    y0, y1 = st[2], st[4]
    if value(code, y0[0], y0[1], y0[2], y0[3], a0, side, slide, sgn_x, par) > 0.0:
        return
    if not value(code, y1[0], y1[1], y1[2], y1[3], a1, side, slide, sgn_x, par) > 0.0:
        return
    s = peak_root(code, st)
    if s <= s_end:
        refine(code, s, st, work, par, mot, k, side, slide, yev)
        acc[0] = max(acc[0], abs(yev[0]))
        acc[1] = max(acc[1], abs(yev[2]))


@njit(cache=True, **NO_REFCOUNT)
def _lift_at(t, y, f, mot, k, slide, par, tmp):
    """The first double from t [s] (a few ulps on at most) at which the block at rest lifts,
    the state carried there by its Taylor polynomial into y (the reference's first lifted
    double): (that time, the side)."""
    for i in range(64):
        dl = 0.0 if i == 0 else (np.nextafter(t, np.inf) - t) * 2.0 ** (i - 1)
        tmp[0] = y[0] + (y[1] + 0.5 * f[1] * dl) * dl
        tmp[1] = y[1] + f[1] * dl
        side = lift_side(tmp[0], tmp[1], _ag(mot, t + dl, k), slide, par)
        if side != 0.0:
            y[0], y[1] = tmp[0], tmp[1]
            return t + dl, side
    return t, -_sign(base_acceleration(y[0], y[1], _ag(mot, t, k), slide, par))


@njit(cache=True, **NO_REFCOUNT)
def _impact(y, side, par, acc):
    """The impact at y (theta = 0): the velocities after it, the block settled on the base
    below the rest speed. Returns the new side."""
    y[2] = 0.0
    xd, thd = impact(y[1], y[3], par[P_ETA], par[P_HM])
    acc[2] += 1.0
    if abs(thd) < par[P_REST]:  # the impacts have died out: at rest on the base
        y[1], y[3] = xd + par[P_HM] * thd, 0.0
        return 0.0
    y[1], y[3] = xd, thd
    return -side


@njit(cache=True, **NO_REFCOUNT)
def _on_event(code, t, y, f, side, slide, mot, k, par, acc, tmp):
    """The regime after event ``code`` at (t, y): (t, side, slide, overturned)."""
    if code == EV_OVER:
        return t, side, slide, True
    if code == EV_IMPACT:
        side = _impact(y, side, par, acc)
        return t, side, slide_after_jump(y, _ag(mot, t, k), side, par), False
    if code == EV_LIFT:
        t, new = _lift_at(t, y, f, mot, k, slide, par, tmp)
        return t, new, slide, False
    if code == EV_STOP:
        y[1] = 0.0
        return t, side, slide_after_stop(y, _ag(mot, t, k), side, par), False
    f_need = demand(y, _ag(mot, t, k), side, par)  # EV_BREAK
    return t, side, _sign(f_need), False


@njit(cache=True, **NO_REFCOUNT)
def _copy(dst, src):
    """dst[:] = src for 4 values (a slice assignment needs numba's reference counting)."""
    for j in range(4):
        dst[j] = src[j]


@njit(cache=True, **NO_REFCOUNT)
def _maxima(acc, y):
    acc[0] = max(acc[0], abs(y[0]))
    acc[1] = max(acc[1], abs(y[2]))


@njit(cache=True, **NO_REFCOUNT)
def _start(par, mot, y):
    """The row's start: the block at rest on the base at rest, y = 0 (a friction pendulum's
    base stuck unless the ground's first acceleration breaks it away): its slide."""
    y[0] = y[1] = y[2] = y[3] = 0.0
    return slide_after_stop(y, _ag(mot, 0.0, 0), 0.0, par)


@njit(cache=True, **NO_REFCOUNT)
def run_row(par, atol, mot, rtol, max_steps, max_impacts, out, K, K2, vec, acc):
    """One row's history (module docstring) into ``out`` (the columns O_*); K, K2 (13, 4),
    vec (6, 4) and acc (3,) are its scratch arrays (allocated by the caller: this kernel
    counts no references)."""
    y, y1, tmp, yev, yt, tmp2 = vec[0], vec[1], vec[2], vec[3], vec[4], vec[5]
    acc[0] = acc[1] = acc[2] = 0.0  # max |x_b|, max |theta|, impacts
    dur = mot[1][3]
    t_end = dur + 100.0 / par[P_P] + 200.0 * math.pi / par[P_OMEGA]
    slide = _start(par, mot, y)
    t, k, side, h, status, t_ot = 0.0, 0, 0.0, np.nan, 1, np.nan
    rejected, fresh, steps = False, True, 0
    while steps < max_steps:
        if mot[0] == KIND_RECORD:
            k = segment_index(mot[2], min(t, dur), k)
        if side == 0.0:
            if t >= dur and settled(y, slide, acc[0], par):
                status = 0
                break
            side = lift_side(y[0], y[1], _ag(mot, t, k), slide, par)
            if side != 0.0:  # a new phase: the reference's fresh first step
                fresh, h = True, np.nan
        if t >= t_end:
            break
        t_stop, n = _stop(mot, t, k, t_end), 4 if side != 0.0 else 2
        if fresh:
            rhs(t, y, par, mot, k, side, slide, K[0])
            if not h == h:
                h = first_step(t, y, K[0], par, mot, k, side, slide, rtol, atol, n, t_stop, tmp, y1)
            fresh = False
        steps += 1
        last = h >= t_stop - t
        hs = t_stop - t if last else h
        dop853_step(t, y, hs, K, y1, tmp, par, mot, k, side, slide)
        err = error_norm(K, hs, y, y1, rtol, atol, n)
        h = hs * step_factor(err, rejected or not err < 1.0)
        rejected = not err < 1.0
        if rejected:
            continue
        t1 = t_stop if last else t + hs
        st = (t, hs, y, K[0], y1, K[12])
        a0, a1 = _ag(mot, t, k), _ag(mot, t1, k)
        sgn_x = _sign(y[1]) if y[1] != 0.0 else _sign(K[0, 1])
        code, s = _first_terminal(st, mot, k, side, slide, sgn_x, par, a0, a1)
        _copy(K2[0], K[0])
        work = (K2, yt, tmp2)
        for code_pk in (EV_PEAK_TH, EV_PEAK_X):
            _peak(code_pk, st, min(s, 1.0), work, par, mot, k, side, slide, sgn_x, a0, a1, acc, yev)
        if code == EV_NONE:
            t = t1
            _copy(y, y1)
            _copy(K[0], K[12])
            _maxima(acc, y)
            fresh = t >= t_stop  # f0 anew at a sample or the motion's end
            continue
        t = refine(code, s, st, work, par, mot, k, side, slide, y)
        if code == EV_OVER:
            y[2] = side * FALL
        _maxima(acc, y)
        t, side, slide, over = _on_event(code, t, y, K2[12], side, slide, mot, k, par, acc, tmp)
        if over:
            t_ot, status = t, 0
            break
        if acc[2] >= max_impacts:
            break
        fresh, h = True, np.nan
    out[O_THETA] = FALL if t_ot == t_ot else acc[1]
    out[O_OVER] = 1.0 if t_ot == t_ot else 0.0
    out[O_X], out[O_TIME], out[O_IMPACTS], out[O_STATUS] = acc[0], t_ot, acc[2], status


@njit(cache=True, parallel=True)
def isolated_batch(pars, atols, kinds, mps, times, samples, offsets, rtol, max_steps, max_imp):
    """The rows of a batch in parallel: row i is the structure pars[i] (with its absolute
    tolerances atols[i]) under the motion (kinds[i], mps[i], its samples
    times/samples[offsets[i]:offsets[i + 1]]). Returns the (n, N_OUT) outputs."""
    n = pars.shape[0]
    out = np.empty((n, N_OUT))
    for i in prange(n):
        a, b = offsets[i], offsets[i + 1]
        mot = (kinds[i], mps[i], times[a:b], samples[a:b])
        K, K2, vec, acc = np.empty((13, 4)), np.empty((13, 4)), np.empty((6, 4)), np.empty(3)
        run_row(pars[i], atols[i], mot, rtol, max_steps, max_imp, out[i], K, K2, vec, acc)
    return out


def run_rows(structures, motions, rtol, max_steps, max_impacts) -> np.ndarray:
    """The (n, N_OUT) outputs of the (structure, motion) rows by :func:`isolated_batch`: the
    rows' parameters (:func:`._isolated_model.row_parameters`), tolerances
    (:func:`.isolated_reference.absolute_tolerances`) and motions (their kernel encodings;
    a record's samples are stacked per row, as each row's record is scaled)."""
    from ._isolated_model import row_parameters
    from .isolated_reference import absolute_tolerances

    pars = np.array([row_parameters(s) for s in structures])
    atols = np.array(
        [absolute_tolerances(s, m, rtol) for s, m in zip(structures, motions, strict=True)]
    )
    specs = [m.kernel_spec() for m in motions]
    for m, spec in zip(motions, specs, strict=True):
        if spec[4].size:
            raise ValueError(
                f"motion: {type(m).__name__} has a vertical component, which the model lacks"
            )
    kinds = np.array([spec[0] for spec in specs], dtype=np.int64)
    mps = np.array([spec[1] for spec in specs], dtype=float)
    sizes = np.array([spec[2].size for spec in specs])
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    times = np.concatenate([np.asarray(spec[2], dtype=float) for spec in specs])
    samples = np.concatenate([np.asarray(spec[3], dtype=float) for spec in specs])
    return isolated_batch(
        pars, atols, kinds, mps, times, samples, offsets, float(rtol), max_steps, max_impacts
    )
