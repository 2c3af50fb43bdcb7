"""The friction demand and lift-off of Housner's block, computed while a kernel rocks it
(private): the batch's friction check without a history.

The ground's force on the block per unit mass (:mod:`rockstudy.dynamics.contact`), with
x = alpha s - theta, S = sin x, C = cos x, gamma = g + u_v'' and R theta_ddot = -(3/4)
(gamma S + u_h'' C) from eq. (2.2) of [000] (R p^2 = 3 g / 4):

.. math::

   F_h / m = \\ddot u_h + R \\ddot\\theta C + R \\dot\\theta^2 S, \\qquad
   F_v / m = \\gamma + R \\ddot\\theta S - R \\dot\\theta^2 C.

On every accepted Taylor step the ratio ``|F_h|`` / F_v is evaluated on the step polynomial
at :data:`INTERIOR` points and the step's end (its start too where a rocking phase starts: at
uplift, after an impact); where the largest of a step's samples, or the vertex of the parabola
through it and its neighbours, reaches the largest ratio so far, it is refined by a golden
section search (:data:`GOLDEN_ITERATIONS`) between its neighbours. The demand is the largest
ratio, with the impulse ratio of the impacts, (1 - eta) / ((1 + eta) tan alpha), if the block
struck the ground; the block lifts off where F_v <= 0 at a sample (demand inf).

What needs no evaluation: a block at rest has ``|u_h''|`` / gamma <= tan alpha (else it
lifts), and the ratio is exactly tan alpha at uplift (a sample), so the rests never set the
demand of a block that lifts; free rocking after the motion, which the batch maps
(:func:`._free_map.free_rocking_map`) rather than integrates, needs less than tan alpha and
never lifts off for alpha <= :data:`FREE_ROCKING_SLENDERNESS` (its forces depend on the
rotation and the energy only: :func:`free_rocking_ratio`). As
:func:`rockstudy.dynamics.contact.check_contact`, of an overturned block only the response up
to the last time ``|theta|`` = alpha counts: samples beyond alpha are held apart and kept
only when the block comes back below it.

The state lives in the scene's tallies (:data:`._logs.TALLIES`, fields ``d_*``) and the
samples of a step in rows of the Taylor work array (:data:`._taylor.ROW_SIG` ...).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import G
from ..motions._kernels import ground_acceleration, vertical_acceleration
from ._taylor import (
    FMA,
    NO_REFCOUNT,
    OF_VALUE,
    ROW_C,
    ROW_CLS,
    ROW_SIG,
    ROW_VAL,
    poly_root,
    poly_value,
)

#: Points inside each Taylor step at which the forces are evaluated (besides its end).
INTERIOR = 2
#: Iterations at most of the refinement of a step's largest ratio between its neighbouring
#: samples (:func:`_parabolic`), until the bracket is REFINE_TOL of the step.
REFINE_ITERATIONS = 30
REFINE_TOL = 1e-6
#: Where the refinement of a largest sample at an end of a step tests the slope: this
#: fraction of the way from the end to the midpoint towards the next sample.
END_OFFSET = 1e-3
#: Largest slenderness [rad] for which free rocking (no ground motion, below the overturning
#: energy) needs less friction than tan alpha and keeps F_v > 0 (checked on a dense grid of
#: energies and rotations: the ratio peaks at 0.75 tan alpha for small alpha and reaches
#: tan alpha near alpha = 0.96); beyond it a mapped free rocking leaves the demand uncomputed.
FREE_ROCKING_SLENDERNESS = 0.9
_GOLD = 0.5 * (math.sqrt(5.0) - 1.0)


@njit(cache=True, inline="always")
def force_ratio(th, om, s, a_h, a_v, p, alpha):
    """(``|F_h|`` / F_v, F_v / m) of a block rocking on side s at theta = th [rad], theta_dot
    = om [rad/s] under the ground (a_h, a_v) [m/s^2]; the ratio inf where F_v <= 0."""
    x = alpha * s - th
    sx, cx = math.sin(x), math.cos(x)
    gam = G + a_v
    r_acc = -0.75 * (gam * sx + a_h * cx)  # R theta_ddot
    r_om2 = 0.75 * G * (om / p) ** 2  # R theta_dot^2
    f_h = a_h + r_acc * cx + r_om2 * sx
    f_v = gam + r_acc * sx - r_om2 * cx
    return (abs(f_h) / f_v if f_v > 0.0 else np.inf), f_v


def free_rocking_ratio(c, energy):
    """``|F_h|`` / F_v and F_v / (m g) of a block rocking freely (no ground motion), as
    functions of c = cos(alpha - ``|theta|``) and K = (theta_dot / p)^2 + 2 c (constant
    between impacts): F_h / (m R p^2) = sin phi (K - 3 c), F_v / (m R p^2) = 3 c^2 - K c + 1/3.
    Broadcasting (numpy)."""
    f_h = np.sqrt(1.0 - c * c) * np.abs(energy - 3.0 * c)
    f_v = 3.0 * c * c - energy * c + 1.0 / 3.0
    return f_h / f_v, 0.75 * f_v


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _sample(c, n, sig, hs, s, p, alpha, mot, ground):
    """(ratio, F_v / m, u = s theta) at unit step time sig of the step polynomial c of order n
    (length hs [s]); ground = (t0 [s], record segment, whether the motion still acts)."""
    t0, k, forced = ground
    th, d, _ = poly_value(c, n, sig)
    a_h = a_v = 0.0
    if forced:
        kind, mp, times, samples, vsamples = mot
        t = t0 + sig * hs
        a_h = ground_acceleration(kind, mp, times, samples, t, k)
        a_v = vertical_acceleration(kind, mp, times, vsamples, t, k)
    ratio, f_v = force_ratio(th, d / hs, s, a_h, a_v, p, alpha)
    return ratio, f_v, s * th


@njit(cache=True, fastmath=FMA, inline="always", **NO_REFCOUNT)
def _sample_taken(ta, c, n, sig, hs, s, p, alpha, mot, ground):
    """:func:`_sample`, counted (:func:`_take`); returns its ratio."""
    r, f_v, u = _sample(c, n, sig, hs, s, p, alpha, mot, ground)
    _take(ta, r, f_v, u > alpha)
    return r


@njit(cache=True, inline="always")
def _take(ta, ratio, f_v, over):
    """Count a sample: beyond alpha (``over``) held apart; below it, the held ones kept (the
    block came back) and the sample with them."""
    ta.d_samples += 1
    if over:
        ta.d_over = max(ta.d_over, ratio)
        ta.d_min_fv_over = min(ta.d_min_fv_over, f_v)
        return
    _keep_over(ta)
    ta.d_best = max(ta.d_best, ratio)
    ta.d_min_fv = min(ta.d_min_fv, f_v)


@njit(cache=True, inline="always")
def _keep_over(ta):
    """Keep the samples held beyond alpha (the block did not fall from there)."""
    ta.d_best = max(ta.d_best, ta.d_over)
    ta.d_min_fv = min(ta.d_min_fv, ta.d_min_fv_over)
    ta.d_over = 0.0
    ta.d_min_fv_over = np.inf


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _parabolic(c, n, x, f, hs, s, p, alpha, mot, ground):
    """The largest ratio near the best of three samples x[1] (x[0] < x[1] < x[2], f[1] the
    largest of f), by successive parabolic interpolation kept inside the bracket, a
    golden-section step where the parabola's vertex would not shrink it: (ratio, F_v, u) at
    the best point evaluated (f[1] with F_v NaN if none beat it)."""
    x0, x1, x2 = x
    f0, f1, f2 = f
    best = (f1, np.nan, np.nan)
    for _ in range(REFINE_ITERATIONS):
        h0, h2 = x1 - x0, x2 - x1
        xv = x1 - (1.0 - _GOLD) * h0 if h0 > h2 else x1 + (1.0 - _GOLD) * h2
        xp = _vertex_at(x0, f0, x1, f1, x2, f2)
        if abs(xp - x1) <= REFINE_TOL:
            break  # converged: the parabola's vertex is the best point
        if x0 < xp < x2:
            xv = xp
        if h0 + h2 <= REFINE_TOL:
            break
        r, f_v, u = _sample(c, n, xv, hs, s, p, alpha, mot, ground)
        if r > f1:
            best = (r, f_v, u)
            if xv < x1:
                x2, f2, x1, f1 = x1, f1, xv, r
            else:
                x0, f0, x1, f1 = x1, f1, xv, r
        elif xv < x1:
            x0, f0 = xv, r
        else:
            x2, f2 = xv, r
    return best


@njit(cache=True, inline="always")
def _parabola(x0, f0, x1, f1, x2, f2):
    """(a, b) of the parabola f1 + b dx + a dx^2 (dx = x - x1) through three points
    (x0 < x1 < x2)."""
    h0, h2 = x1 - x0, x2 - x1
    a = ((f0 - f1) / h0 + (f2 - f1) / h2) / (h0 + h2)
    return a, (f2 - f1) / h2 - a * h2


@njit(cache=True, inline="always")
def _vertex_at(x0, f0, x1, f1, x2, f2):
    """Where the parabola through three points (x0 < x1 < x2) has its maximum (NaN if it has
    none)."""
    a, b = _parabola(x0, f0, x1, f1, x2, f2)
    return x1 - 0.5 * b / a if a < 0.0 else np.nan


@njit(cache=True, inline="always")
def _vertex(x0, f0, x1, f1, x2, f2):
    """The largest value of the parabola through three points (x0 < x1 < x2) where it has a
    maximum; else f1."""
    a, b = _parabola(x0, f0, x1, f1, x2, f2)
    return f1 - b * b / (4.0 * a) if a < 0.0 else f1


@njit(cache=True, **NO_REFCOUNT)
def _insert_crossings(w, c, n, m, s, alpha, hs, p, mot, ground, ta):
    """Insert, between samples on either side of alpha, the sample at ``|theta|`` = alpha
    itself (the end of the response that counts if the block falls from there). Returns the
    new number of samples."""
    sig, val, cls = w[ROW_SIG], w[ROW_VAL], w[ROW_CLS]
    j = 0
    while j < m - 1:
        if cls[j] != cls[j + 1]:
            up = cls[j] == 0.0
            x = poly_root(c, n, s * alpha, -s if up else s, OF_VALUE, sig[j], sig[j + 1])
            r, f_v, _ = _sample(c, n, x, hs, s, p, alpha, mot, ground)
            for i in range(m, j + 1, -1):
                sig[i], val[i], cls[i] = sig[i - 1], val[i - 1], cls[i - 1]
            sig[j + 1], val[j + 1], cls[j + 1] = x, r, 0.0
            _take(ta, r, f_v, False)
            m += 1
            j += 1
        j += 1
    return m


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def _end_bracket(ta, w, c, n, m, j, hs, s, p, alpha, mot, ground):
    """Three points (in time order) around the largest ratio of a step whose largest sample
    j is an end of it (0 or m - 1), from the midpoint towards the next sample i and a point
    END_OFFSET of the way back from the end: (near, mid, i) where the ratio still rises at
    mid, else (end, near, mid). Where the ratio rises into the end (near below it), the
    middle ratio is below the end's: the end is the largest."""
    sig, val = w[ROW_SIG], w[ROW_VAL]
    i = 1 if j == 0 else m - 2
    end = sig[j]
    mid = 0.5 * (sig[i] + end)
    near = end + END_OFFSET * (mid - end)
    f_mid = _sample_taken(ta, c, n, mid, hs, s, p, alpha, mot, ground)
    f_near = _sample_taken(ta, c, n, near, hs, s, p, alpha, mot, ground)
    if f_mid >= f_near:
        x, f = (near, mid, sig[i]), (f_near, f_mid, val[i])
    else:
        x, f = (end, near, mid), (val[j], f_near, f_mid)
    if j == 0:
        return x, f
    return (x[2], x[1], x[0]), (f[2], f[1], f[0])


@njit(cache=True, **NO_REFCOUNT)
def _refine(w, c, n, m, over, hs, s, p, alpha, mot, ground, ta):
    """Refine the largest sample of one side of alpha (``over``) of a step, between its
    neighbours, where it may exceed the largest ratio of that side so far."""
    sig, val, cls = w[ROW_SIG], w[ROW_VAL], w[ROW_CLS]
    j = -1
    for i in range(m):
        if cls[i] == over and (j < 0 or val[i] > val[j]):
            j = i
    best = ta.d_over if over else ta.d_best
    if j < 0 or not math.isfinite(val[j]):
        return
    estimate = val[j]
    if 0 < j < m - 1:
        estimate = _vertex(sig[j - 1], val[j - 1], sig[j], val[j], sig[j + 1], val[j + 1])
    if estimate < best:
        return
    if 0 < j < m - 1:
        x, f = (sig[j - 1], sig[j], sig[j + 1]), (val[j - 1], val[j], val[j + 1])
    else:
        x, f = _end_bracket(ta, w, c, n, m, j, hs, s, p, alpha, mot, ground)
        if not f[1] >= max(f[0], f[2]):
            return  # the ratio rises into the step's end: the end is the largest
    r, f_v, u = _parabolic(c, n, x, f, hs, s, p, alpha, mot, ground)
    if f_v == f_v and (u > alpha) == over:
        _take(ta, r, f_v, over)


@njit(cache=True, fastmath=FMA, **NO_REFCOUNT)
def demand_step(ta, w, n, t, hs, t_end, s, p, alpha, mot, k):
    """Count an accepted Taylor step of length hs [s] from t [s] up to t_end (its end or its
    event) on side s, whose polynomial of order n is in w[ROW_C] (record segment k): its
    samples and their refinement (module docstring)."""
    c = w[ROW_C]
    sig, val, cls = w[ROW_SIG], w[ROW_VAL], w[ROW_CLS]
    ground = (t, k, t < mot[1][3])
    se = (t_end - t) / hs
    m = INTERIOR + 2
    for j in range(m):
        sig[j] = se * j / (m - 1)
        if j == 0 and ta.d_fresh == 0:  # the end of the step before
            val[0], cls[0] = ta.d_last, ta.d_last_over
            continue
        r, f_v, u = _sample(c, n, sig[j], hs, s, p, alpha, mot, ground)
        over = u > alpha
        val[j], cls[j] = r, 1.0 if over else 0.0
        _take(ta, r, f_v, over)
    ta.d_fresh = 0
    ta.d_last, ta.d_last_over = val[m - 1], cls[m - 1]
    mixed = False
    for j in range(1, m):
        mixed = mixed or cls[j] != cls[0]
    if mixed:
        m = _insert_crossings(w, c, n, m, s, alpha, hs, p, mot, ground, ta)
    _refine(w, c, n, m, 0.0, hs, s, p, alpha, mot, ground, ta)
    if mixed or cls[0] == 1.0:
        _refine(w, c, n, m, 1.0, hs, s, p, alpha, mot, ground, ta)


@njit(cache=True)
def demand_outcome(ta, over, eta, alpha):
    """(friction_demand, lift_off) of a scene from its tallies: NaN (and False) where the
    kernel did not compute it (it never rocked, or a step or the free rocking it could not
    cover); of an overturned block (``over``) the samples beyond alpha left out."""
    if ta.d_uncovered != 0 or ta.d_samples == 0:
        return np.nan, False
    if not over:
        _keep_over(ta)
    if ta.d_min_fv <= 0.0:
        return np.inf, True
    best = ta.d_best
    if ta.n_impacts > 0:
        best = max(best, (1.0 - eta) / ((1.0 + eta) * math.tan(alpha)))
    return best, False
