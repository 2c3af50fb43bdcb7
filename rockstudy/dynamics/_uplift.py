"""Uplift search (private): the first time a block at rest lifts off.

The motion is cut at its extrema and zeros (:func:`_next_break`); on each monotone piece the
lift test (:func:`._rhs._lift`) is located by bisection to the ulp (:func:`next_uplift`),
after skipping a record's quiet samples and, under a sine pulse, from a closed-form bracket.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._roots import ULP_BISECTIONS
from ..constants import G
from ..motions._kernels import (
    KIND_RECORD,
    KIND_TRIG,
    ground_acceleration,
    segment_index,
    vertical_acceleration,
)
from ._rhs import _lift
from ._taylor import NO_REFCOUNT
from .constants import FIRST, MODEL_LINEAR, MODEL_TABLE, NO_TABLE, TRIG


@njit(cache=True)
def _next_break(kind, mp, times, t, k):
    """The first time after t at which the ground acceleration has an extremum or a zero
    (or the motion ends): between two such times it is monotone and of one sign.

    Analytic for the pulses: a sin(omega t + phase) at phases k pi / 2; the Ricker wavelet
    a (1 - 2 x^2) exp(-x^2), x = pi f (t - t0), at x = 0 (peak), +-1/sqrt(2) (zeros) and
    +-sqrt(3/2) (side lobes, where d/dx = 2 x (2 x^2 - 3) exp(-x^2) vanishes). A record is
    linear between its samples.
    """
    dur = mp[3]
    if kind == KIND_RECORD:
        return min(times[segment_index(times, t, k) + 1], dur)
    if kind == KIND_TRIG:
        q = 0.5 * math.pi
        j = math.floor((mp[1] * t + mp[2]) / q) + 1.0
        tb = (j * q - mp[2]) / mp[1]
        if tb <= t:
            tb = ((j + 1.0) * q - mp[2]) / mp[1]
        return min(tb, dur)
    for x in (-math.sqrt(1.5), -math.sqrt(0.5), 0.0, math.sqrt(0.5), math.sqrt(1.5)):
        tb = mp[2] + x / (math.pi * mp[1])
        if tb > t:
            return min(tb, dur)
    return dur


#: Relative margin below the uplift level under which record samples are skipped without
#: the exact test (:func:`_lift`); far wider than the few ulps by which the two can differ.
QUIET_MARGIN = 1e-9


@njit(cache=True)
def _skip_quiet(mp, times, samples, alpha, model, lo, k):
    """Start of the first record segment at or after lo (on segment k) whose end sample
    reaches the uplift level |a_g| = g tan(alpha) (nonlinear) or g alpha (linearized), less
    :data:`QUIET_MARGIN`: on the segments before it the ground (linear between samples)
    stays below the level, and no block at rest lifts. One comparison per sample. Not for a
    record with a vertical component, which moves the level ((g + u_v'') tan alpha)."""
    level = G * (alpha if model == MODEL_LINEAR else math.tan(alpha)) * (1.0 - QUIET_MARGIN)
    if mp[0] == 0.0:
        return max(lo, times[times.shape[0] - 2])
    level = level / abs(mp[0])
    j = k + 1
    while j < times.shape[0] - 1 and abs(samples[j]) < level:
        j += 1
    return max(lo, times[j - 1])


@njit(cache=True, **NO_REFCOUNT)
def _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, t, k):
    """:func:`_lift` under the ground accelerations at time t (record segment k)."""
    a_g = ground_acceleration(kind, mp, times, samples, t, k)
    a_v = vertical_acceleration(kind, mp, times, vsamples, t, k)
    return _lift(a_g, a_v, p, alpha, model, tab)


#: Half-width of the first bracket around the closed-form uplift time of a trigonometric
#: pulse, relative to |t| + 1/omega: a few ulps of the phase, so that the bisection to the
#: ulp takes ~8 halvings instead of ~50; widened 64-fold while it does not bracket.
TRIG_BRACKET = 1e-14


@njit(cache=True)
def _trig_uplift_bracket(mp, times, samples, vsamples, p, alpha, model, lo, hi):
    """A sub-bracket of [lo, hi] (a monotone piece of a sine pulse where the block at rest
    does not lift at lo and lifts at hi) around the closed-form time at which |a_g| reaches
    g tan(alpha) (g alpha linearized), a sin(omega t + phase) = level at the phase
    m pi +- asin(level / |a|) (section 2 of [000]). The exact test (:func:`_lift`) still
    decides: the bracket is returned only where it holds at both ends."""
    level = G * (alpha if model == MODEL_LINEAR else math.tan(alpha))
    w, ph = mp[1], mp[2]
    x = math.asin(min(level / abs(mp[0]), 1.0))
    m = math.floor((w * lo + ph) / math.pi)
    tc = np.inf
    for j in range(4):  # crossings at phases m pi + x, m pi + pi - x, (m + 1) pi + x, ...
        psi = (m + j // 2) * math.pi + (x if j % 2 == 0 else math.pi - x)
        t = (psi - ph) / w
        if lo <= t <= hi:
            tc = t
            break
    if tc == np.inf:
        return lo, hi
    d = TRIG_BRACKET * (abs(tc) + 1.0 / w)
    while d < hi - lo:
        a, b = max(lo, tc - d), min(hi, tc + d)
        lift_a = (
            a > lo
            and _lift_at(TRIG, mp, times, samples, vsamples, p, alpha, model, NO_TABLE, a, FIRST)
            > 0.0
        )
        lift_b = (
            b == hi
            or _lift_at(TRIG, mp, times, samples, vsamples, p, alpha, model, NO_TABLE, b, FIRST)
            > 0.0
        )
        if not lift_a and lift_b:
            return a, b
        d *= 64.0
    return lo, hi


@njit(cache=True, **NO_REFCOUNT)
def next_uplift(kind, mp, times, samples, vsamples, p, alpha, model, tab, t0):
    """First time >= t0 at which a block at rest lifts off (:func:`_lift` > 0), or inf.

    The motion is cut at its extrema and zeros (:func:`_next_break`); on each piece of a pulse
    the lift is monotone, so it is checked at the piece's end and located by bisection to
    the ulp. On a record segment both components are linear in t, so the lift is affine in
    t on each side of the zero of u_g'' (c |u_g''| - d (g + u_v''), c, d > 0: convex on the
    segment), and negative at that zero: where it is not > 0 at both samples it is not > 0
    between them, and where it turns positive it does so once. No short excursion above the
    threshold between scan points can be missed.
    """
    dur = mp[3]
    if t0 > dur:
        return np.inf
    rec = kind == KIND_RECORD
    k = segment_index(times, t0, FIRST) if rec else 0
    lo = t0
    if _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, lo, k) > 0.0:
        return lo
    while lo < dur:
        if kind == KIND_RECORD and model != MODEL_TABLE and vsamples.size == 0:
            lo = _skip_quiet(mp, times, samples, alpha, model, lo, segment_index(times, lo, k))
            if lo >= dur:
                break
        hi = _next_break(kind, mp, times, lo, k)
        if rec:
            k = segment_index(times, lo, k)
        k_hi = segment_index(times, hi, k) if rec else 0
        if _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, hi, k_hi) > 0.0:
            if kind == KIND_TRIG and model != MODEL_TABLE and vsamples.size == 0:
                lo, hi = _trig_uplift_bracket(mp, times, samples, vsamples, p, alpha, model, lo, hi)
            for _ in range(ULP_BISECTIONS):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if _lift_at(kind, mp, times, samples, vsamples, p, alpha, model, tab, mid, k) > 0:
                    hi = mid
                else:
                    lo = mid
            return hi
        lo = hi
    return np.inf
