"""The sliding block under a record, exact on each sample segment (private numba kernel).

A block that cannot rock (mu_k <= mu_s < tan alpha: the base never carries more than
mu_s N, below the uplift force N tan alpha) rests or slides flat, u'' = -u_h'' -
sigma mu_k (g + u_v'') (:func:`.slide_rock.sliding_acceleration`). Between two samples
u_h'' and u_v'' are linear in t, so the slip velocity is a quadratic and the slip a cubic:
the slip starts where ``|u_h''|`` = mu_s (g + u_v'') (a linear equation) and stops where the
quadratic velocity reaches 0; nothing is integrated.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import G


@njit(cache=True)
def _stop(v0, w0, w1, h):
    """The first s in (0, h] at which v0 + w0 s + w1 s^2 / 2 reaches 0 from the side it
    moves on (sign v0, or at v0 = 0 that of w0, then w1), or inf."""
    if v0 == 0.0:
        if w0 == 0.0 or w1 == 0.0 or w0 * w1 > 0.0:
            return math.inf
        s = -2.0 * w0 / w1
        return s if s <= h else math.inf
    if w1 == 0.0:
        s = -v0 / w0 if w0 != 0.0 else math.inf
        return s if 0.0 < s <= h else math.inf
    disc = w0 * w0 - 2.0 * w1 * v0
    if disc < 0.0:
        return math.inf
    q = -0.5 * (w0 + math.copysign(math.sqrt(disc), w0))
    best = math.inf
    for s in (q / (0.5 * w1), v0 / q if q != 0.0 else math.inf):
        if 0.0 < s <= h and s < best:
            best = s
    return best


@njit(cache=True)
def _start(a0, a1, g0, g1, mu, h):
    """The first s in [0, h] at which ``|a|`` > mu g_e begins on a segment where a and g_e
    run linearly from (a0, g0) to (a1, g1), or inf."""
    best = math.inf
    for sign in (1.0, -1.0):
        f0, f1 = sign * a0 - mu * g0, sign * a1 - mu * g1
        if f0 > 0.0:
            return 0.0
        if f1 > 0.0:
            best = min(best, h * f0 / (f0 - f1))
    return best


@njit(cache=True)
def _advance(state, s, w0, w1):
    """Slip state (u, v) after s [s] at the acceleration w0 + w1 s."""
    u, v = state
    return u + s * (v + s * (0.5 * w0 + s * w1 / 6.0)), v + s * (w0 + 0.5 * w1 * s)


@njit(cache=True)
def sliding_scene(times, accel, vert, static, kinetic, out):
    """The slip of a block resting or sliding flat under the record (times [s], u_h''
    and u_v'' [m/s^2] at them; ``vert`` empty without a vertical), then decelerating to rest
    after it. Rows (t, u, u') at every segment end and every start and stop go into ``out``
    (at most 3 per segment plus 2). Returns (rows, max ``|u|``, first slip time or NaN,
    seconds sliding)."""
    n = times.shape[0]
    u, v, sigma, sliding, first, slid, peak, rows = 0.0, 0.0, 1.0, False, math.nan, 0.0, 0.0, 1
    out[0, 0], out[0, 1], out[0, 2] = 0.0, 0.0, 0.0
    for k in range(n - 1):
        t, h = times[k], times[k + 1] - times[k]
        da, dg = (accel[k + 1] - accel[k]) / h, 0.0
        a0, g0 = accel[k], G
        if vert.shape[0]:
            g0, dg = G + vert[k], (vert[k + 1] - vert[k]) / h
        pos = 0.0
        while pos < h:
            a, g_e = a0 + da * pos, g0 + dg * pos
            if not sliding:
                s = _start(a, a0 + da * h, g_e, g0 + dg * h, static, h - pos)
                if s == math.inf:
                    break
                pos += s
                a, g_e = a0 + da * pos, g0 + dg * pos
                sigma, sliding, v = (-1.0 if a > 0.0 else 1.0), True, 0.0
                if math.isnan(first):
                    first = t + pos
                if pos > 0.0:
                    out[rows, 0], out[rows, 1], out[rows, 2], rows = t + pos, u, 0.0, rows + 1
            w0, w1 = -a - sigma * kinetic * g_e, -da - sigma * kinetic * dg
            if v == 0.0 and sigma * w0 < 0.0:  # rounding at the threshold
                w0 = 0.0
            s = _stop(v, w0, w1, h - pos)
            step = min(s, h - pos)
            u, v = _advance((u, v), step, w0, w1)
            slid += step
            pos += step
            peak = max(peak, abs(u))
            if s <= step:  # stopped: at rest, or off the other way at once
                a, g_e = a0 + da * pos, g0 + dg * pos
                v, sliding = 0.0, False
                out[rows, 0], out[rows, 1], out[rows, 2], rows = t + pos, u, 0.0, rows + 1
        if out[rows - 1, 0] != t + h:
            out[rows, 0], out[rows, 1], out[rows, 2], rows = t + h, u, v, rows + 1
    if sliding and v != 0.0:  # after the record: decelerates at mu_k g
        s = abs(v) / (kinetic * G)
        u, slid = u + 0.5 * v * s, slid + s
        peak = max(peak, abs(u))
        out[rows, 0], out[rows, 1], out[rows, 2], rows = times[n - 1] + s, u, 0.0, rows + 1
    return rows, peak, first, slid


def slide_record(times, accel, vert, static, kinetic):
    """:func:`sliding_scene` with its output allocated: (t, u, u' arrays, max ``|u|``, first
    slip time, seconds sliding)."""
    out = np.empty((3 * times.shape[0] + 2, 3))
    rows, peak, first, slid = sliding_scene(times, accel, vert, static, kinetic, out)
    return out[:rows, 0], out[:rows, 1], out[:rows, 2], peak, first, slid
