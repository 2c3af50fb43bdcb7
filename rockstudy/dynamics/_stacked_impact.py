"""The impacts and the rest of the two-block kernel (private): the post-impact regime and
velocities (the rule of :func:`.stacked_reference._impact`: the first consistent candidate of
:func:`.stacked.impact_candidates`), and the first uplift from rest
(:func:`.stacked_reference._leave_rest`).

The interfaces' state travels as the int array ``iv`` = (flat0, flat1, s1, s2).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..motions._kernels import KIND_RECORD, segment_index
from ._stacked_model import A1, A2, REST1, REST2, body_velocities, lock_margins, post_impact
from ._stacked_steps import ground

#: Halvings of the bisection of an uplift time from rest (to adjacent doubles).
REST_BISECTIONS = 200
#: Scan points over a pulse for the uplift from rest (the reference's grid).
PULSE_GRID = 4096


@njit(cache=True)
def impacting(g, y, iv, k):
    """Which interfaces close at an impact of interface k: k, and the other one too if it
    rocks with its angle within 1e-12 alpha of zero, moving through it (simultaneous)."""
    other = 1 - k
    angle = y[0] if other == 0 else y[1] - y[0]
    rate = y[2] if other == 0 else y[3] - y[2]
    alpha = g[A1] if other == 0 else g[A2]
    both = iv[other] == 0 and abs(angle) <= 1e-12 * alpha and iv[2 + other] * rate < 0.0
    return (True, both) if k == 0 else (both, True)


@njit(cache=True, inline="always")
def _option(flat, hit, slow, side, i):
    """Option i of an interface at an impact (:func:`.stacked.impact_candidates`): (flat,
    side, exists)."""
    if hit:
        first = (i == 0) != slow  # the other corner first, flat first when slow
        if i > 1:
            return False, side, False
        return (False, -side, True) if first else (True, side, True)
    if flat:
        if i > 2:
            return True, 1, False
        return (True, 1, True) if i == 0 else (False, 3 - 2 * i, True)
    return False, side, i == 0


@njit(cache=True, inline="always")
def _consistent(closing, flat, sides, w1, w2, margins, resting):
    """:func:`.stacked_reference._consistent` of a candidate (flat, sides) with post-impact
    rates (w1, w2 - w1) and impulse margins."""
    rates = (w1, w2 - w1)
    for k in range(2):
        if not flat[k] and closing[k] and sides[k] * rates[k] < 0.0:
            return False
    if (flat[0] or flat[1]) and not resting:
        big = 0.0
        for j in range(4):
            if flat[j // 2]:
                big = max(big, abs(margins[j]))
        for j in range(4):
            if flat[j // 2] and margins[j] < -1e-12 * big:
                return False
    return True


@njit(cache=True)
def resolve_impact(g, y, iv, k, v, margins):
    """The impact of interface k (and of the other if simultaneous): the first consistent
    post-impact regime, its velocities conserving the generalised momenta about the new
    pivots. Updates y (the impacting angles set to zero) and iv; False if no candidate is
    consistent (the state is then left as it was)."""
    hits = impacting(g, y, iv, k)
    rates = (y[2], y[3] - y[2])
    slow = (abs(rates[0]) < g[REST1], abs(rates[1]) < g[REST2])
    th1 = 0.0 if hits[0] else y[0]
    phi = 0.0 if hits[1] else y[1] - y[0]
    q1, q2 = th1, th1 + phi
    body_velocities(g, q1, q2, y[2], y[3], iv[2], iv[3], v)
    closing = (hits[0] or iv[0] != 0, hits[1] or iv[1] != 0)
    resting = (slow[0] and hits[0]) or (slow[1] and hits[1])
    for rank in range(3):
        for i in range(rank + 1):
            f0, c0, ok0 = _option(iv[0] != 0, hits[0], slow[0], iv[2], i)
            f1, c1, ok1 = _option(iv[1] != 0, hits[1], slow[1], iv[3], rank - i)
            if not (ok0 and ok1):
                continue
            w1, w2 = post_impact(g, q1, q2, v, c0, c1, f0, f1, margins)
            if _consistent(closing, (f0, f1), (c0, c1), w1, w2, margins, resting):
                y[0], y[1], y[2], y[3] = q1, q2, w1, w2
                iv[0], iv[1], iv[2], iv[3] = f0, f1, c0, c1
                return True
    return False


@njit(cache=True)
def _rest_lift(m0, m1, mot, t, hint):
    """The reference's lift test at rest: -min of the normalised margins m0 + u_g'' m1 (> 0
    where an interface lifts); -1 from the end of the motion on. ``hint``: a record segment
    at or near that of t (the search for it starts there)."""
    if t >= mot[1][3]:
        return -1.0
    seg = hint
    if mot[0] == KIND_RECORD:
        seg = segment_index(mot[2], t, hint)
    ug = ground((mot[0], mot[1], mot[2], mot[3], seg), t)
    worst = np.inf
    for j in range(4):
        worst = min(worst, m0[j] + ug * m1[j])
    return -worst


@njit(cache=True)
def _first_lift(m0, m1, mot, lo, hi, hint):
    """The first double in (lo, hi] where the lift test is > 0 (not at lo, at hi), by
    bisection to adjacent doubles (``hint``: the record segment of lo)."""
    for _ in range(REST_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _rest_lift(m0, m1, mot, mid, hint) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True)
def _grid_point(mot, i):
    """Point i of the scan grid: a record's sample, or i dur / 4096 over a pulse (count
    :func:`_grid_size`)."""
    if mot[0] == KIND_RECORD:
        return mot[2][i]
    if i == PULSE_GRID:
        return mot[1][3]
    return i * (mot[1][3] / PULSE_GRID)


@njit(cache=True)
def _grid_start(mot, t0):
    """The last scan point at or before t0 (0 before the motion): the scan of a rest that
    begins late in a record (after an impact that came to rest) reads on from there."""
    if t0 <= 0.0:
        return 0
    if mot[0] == KIND_RECORD:
        return segment_index(mot[2], min(t0, mot[1][3]), mot[4])
    return min(int(t0 / (mot[1][3] / PULSE_GRID)), PULSE_GRID)


@njit(cache=True)
def scan_cell_end(mot, t):
    """The end of the scan cell of t (< the motion's duration): the next scan point after
    t, at most the duration."""
    dur = mot[1][3]
    i = _grid_start(mot, t) + 1
    hi = _grid_point(mot, min(i, _grid_size(mot) - 1)) if i < _grid_size(mot) else dur
    return min(hi, dur) if hi > t else dur


@njit(cache=True)
def _grid_size(mot):
    return mot[2].shape[0] if mot[0] == KIND_RECORD else PULSE_GRID + 1


@njit(cache=True)
def uplift_from_rest(g, mot, t0, tmp):
    """(time, interface, corner) of the first uplift from rest at or after t0: a scan of
    the lift test on the record's samples (4097 points over a pulse), then
    :func:`_first_lift`; the time inf if nothing lifts before the motion ends."""
    zero = tmp[:4]
    zero[:] = 0.0
    lock_margins(g, zero, 1, 1, True, True, 0.0, tmp[4:8])
    lock_margins(g, zero, 1, 1, True, True, 1.0, tmp[8:12])
    m0, m1 = tmp[4:8], tmp[8:12]
    for j in range(4):
        m1[j] -= m0[j]
    t_up, seg = _scan_lift(m0, m1, mot, t0)
    if t_up == math.inf:
        return t_up, -1, 0
    lift = _rest_lift(m0, m1, mot, t_up, seg)
    seg = segment_index(mot[2], t_up, seg) if mot[0] == KIND_RECORD else 0
    ug = ground((mot[0], mot[1], mot[2], mot[3], seg), t_up)
    for j in range(4):  # the first margin at the minimum, in the reference's order
        if -(m0[j] + ug * m1[j]) == lift:
            return t_up, j // 2, 1 - 2 * (j % 2)
    return t_up, 0, 1


@njit(cache=True)
def _scan_lift(m0, m1, mot, t0):
    """(the first instant at or after t0 where the lift test of :func:`_rest_lift` is > 0,
    a record segment at or before it): the scan points from t0 on, then
    :func:`_first_lift` in the cell where it turns positive; (inf, -) if it never does
    before the motion ends. Each scan point's segment is its own index (O(1) a point)."""
    i0 = _grid_start(mot, t0)
    hint = i0 if mot[0] == KIND_RECORD else mot[4]
    if _rest_lift(m0, m1, mot, t0, hint) > 0.0:
        return t0, hint
    lo, n = t0, _grid_size(mot)
    for i in range(i0, n + 1):
        hi = _grid_point(mot, i) if i < n else mot[1][3]
        if hi <= lo and i < n:
            continue
        seg = min(i, n - 2) if mot[0] == KIND_RECORD else hint
        if _rest_lift(m0, m1, mot, hi, seg) > 0.0:
            if hi <= lo:
                return hi, seg
            cell = max(i - 1, i0) if mot[0] == KIND_RECORD else hint
            return _first_lift(m0, m1, mot, lo, hi, cell), cell
        lo = hi
    return math.inf, hint
