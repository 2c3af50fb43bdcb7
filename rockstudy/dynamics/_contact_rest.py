"""Rest in the contact model's kernel (private): when a block at rest leaves it (located to
the ulp on the motion's monotone pieces), and the regime it enters then
(:mod:`._contact_scene`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..motions._kernels import KIND_RECORD, segment_index
from . import _contact_steps as cs
from . import slide_rock as sr
from ._contact_state import S_T, T_TIMES, _enter, _row, _tally_margin
from ._uplift import _next_break, _skip_quiet
from .constants import MODEL_NONLINEAR


@njit(cache=True)
def _from_flat(blk, mot, st, ta, z, k):
    """The regime a flat block at rest (or whose slip just stopped) enters at st[S_T]."""
    a_h, a_v = cs.ground(mot, st[S_T], k)
    regime, side = sr.initiation_regime(a_h, a_v, blk.static, blk.kinetic, blk.radius, blk.alpha)
    if regime != sr.REST and blk.static >= math.tan(blk.alpha):  # rock or not: the forces
        acc = sr.rocking_acceleration(0.0, a_h, a_v, side, blk.radius, blk.alpha)
        f = sr.contact_forces(0.0, 0.0, acc, 0.0, a_h, a_v, side, blk.radius, blk.alpha)
        _tally_margin(ta, blk.static, f[0], f[1])
    z[1], z[3], z[4] = 0.0, 0.0, 0.0
    if regime == sr.SLIDE and blk.kinetic > math.tan(blk.alpha):
        regime = sr.SLIDE_ROCK
    _enter(st, ta, regime, side, side)


@njit(cache=True)
def _leaves(blk, mot, t, k):
    """:func:`.slide_rock.leaves_rest` under the ground at t (> 0 where the block leaves rest)."""
    a_h, a_v = cs.ground(mot, t, k)
    return sr.leaves_rest(a_h, a_v, blk.static, blk.radius, blk.alpha)


@njit(cache=True)
def _leave_rest_time(blk, mot, t0, k):
    """The first time >= t0 at which a block at rest leaves it, or inf: the motion cut at
    its extrema and zeros (:func:`._uplift._next_break`), where the test is monotone, and
    located by bisection to the ulp; a record's quiet samples skipped below the level
    g min(mu_s, tan alpha) (:func:`._uplift._skip_quiet`)."""
    kind, mp, times, samples, vsamples = mot
    dur, rec = mp[3], kind == KIND_RECORD
    if t0 > dur:
        return np.inf
    k = segment_index(times, t0, k) if rec else 0
    if _leaves(blk, mot, t0, k) > 0.0:
        return t0
    angle = math.atan(min(blk.static, math.tan(blk.alpha)))  # of the level g tan(angle)
    lo = t0
    while lo < dur:
        if rec and vsamples.size == 0:
            lo = _skip_quiet(
                mp, times, samples, angle, MODEL_NONLINEAR, lo, segment_index(times, lo, k)
            )
            if lo >= dur:
                break
        if rec:
            k = segment_index(times, lo, k)
        hi = _next_break(kind, mp, times, lo, k)
        k_hi = segment_index(times, hi, k) if rec else 0
        if _leaves(blk, mot, hi, k_hi) > 0.0:
            while True:
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    return hi
                if _leaves(blk, mot, mid, k) > 0.0:
                    hi = mid
                else:
                    lo = mid
        lo = hi
    return np.inf


@njit(cache=True)
def _rest(blk, mot, st, ta, z, hist, t_end, k):
    """From rest at st[S_T] (record segment k, a hint): on to the time the block leaves it
    (True), or to the end of the motion (False)."""
    end = min(mot[1][3], t_end)
    t0 = st[S_T]
    t_up = _leave_rest_time(blk, mot, t0, k) if t0 < end else np.inf
    if t_up >= end:
        stop = max(t0, end)
        ta[T_TIMES + sr.REST] += stop - t0
        if stop > t0:
            st[S_T] = stop
            _row(hist, ta, stop, 0.0, 0.0, z[0])
        return False
    ta[T_TIMES + sr.REST] += t_up - t0
    st[S_T] = t_up
    if t_up > t0:
        _row(hist, ta, t_up, 0.0, 0.0, z[0])
    k = segment_index(mot[2], t_up, k) if mot[0] == KIND_RECORD else 0
    _from_flat(blk, mot, st, ta, z, k)
    return True
