"""Tallies and logs of a scene (private): max |theta|, impacts, steps, and the history,
peaks and dense output rows, each counted past the end of its array so that an overflow is
detectable."""

from __future__ import annotations

import numpy as np
from numba import njit

from ._rhs import _step
from ._taylor import NO_REFCOUNT, poly_value

#: The running tallies of one scene, one record updated in place by the kernel and the exact
#: linear solvers: max |theta| [rad] and the time it was reached [s] (NaN before any rotation),
#: the first impact time [s] (NaN before it), impacts,
#: integrator steps (0 in the exact solvers), and the rows the logs needed (history rows,
#: impact times, peaks: more than an array holds means it overflowed), with the requested
#: times of the dense output passed so far (the index of the next one to serve).
TALLIES = np.dtype(
    [
        ("max_rotation", np.float64),
        ("peak_time", np.float64),
        ("first_impact_time", np.float64),
        ("n_impacts", np.int64),
        ("steps", np.int64),
        ("n_history", np.int64),
        ("n_impact_times", np.int64),
        ("n_peaks", np.int64),
        ("n_dense", np.int64),
        # the friction demand (:mod:`._demand`): the largest ratio |F_h| / F_v and least F_v
        # [m/s^2] up to alpha and beyond it; the grid's last two samples (time, ratio, side
        # of alpha: 1.0 beyond) and the step before (its start, length, order and record
        # segment); whether the next step starts a rocking phase, samples counted, and
        # whether a part of the response was left uncovered (a DOP853 step, a mapped free
        # rocking)
        ("d_best", np.float64),
        ("d_min_fv", np.float64),
        ("d_over", np.float64),
        ("d_min_fv_over", np.float64),
        ("d_ta", np.float64),
        ("d_fa", np.float64),
        ("d_ca", np.float64),
        ("d_tb", np.float64),
        ("d_fb", np.float64),
        ("d_cb", np.float64),
        ("d_prev_t", np.float64),
        ("d_prev_hs", np.float64),
        ("d_prev_n", np.int64),
        ("d_prev_k", np.int64),
        ("d_fresh", np.int64),
        ("d_samples", np.int64),
        ("d_uncovered", np.int64),
    ],
    align=True,
)


@njit(cache=True)
def new_tallies(max_rotation):
    """An array of one :data:`TALLIES` record: no impact yet (first_impact_time NaN), all
    counts 0, max |theta| from ``max_rotation`` [rad] (the start's, reached at t = 0; NaN for
    its time if it is 0).

    The kernels pass its element ``tallies[0]`` down (a numba Record, by reference) and
    update it in place. The element does not keep the array alive, and numba frees an array
    after its last use: the function that allocates it reads the results from ``tallies``
    after every other use (a record kept from ``np.zeros(1, TALLIES)[0]`` alone is
    overwritten by the next allocation).
    """
    tallies = np.zeros(1, TALLIES)
    ta = tallies[0]
    ta.max_rotation = max_rotation
    ta.peak_time = 0.0 if max_rotation > 0.0 else np.nan
    ta.first_impact_time = np.nan
    ta.d_min_fv = ta.d_min_fv_over = np.inf
    ta.d_fa = ta.d_fb = -np.inf  # an empty grid
    ta.d_fresh = 1
    return tallies


@njit(cache=True, inline="always")
def raise_max(ta, u, t):
    """Raise the largest rotation of the tallies ``ta`` to u [rad], reached at t [s], if u is
    larger (its time kept with it)."""
    if u > ta.max_rotation:
        ta.max_rotation = u
        ta.peak_time = t


@njit(cache=True, inline="always")
def tally_impact(ta, t):
    """Count an impact at t [s] in the tallies ``ta``, the first one's time kept."""
    if ta.n_impacts == 0:
        ta.first_impact_time = t
    ta.n_impacts += 1


@njit(cache=True)
def _push(hist, ta, t, th, om):
    """Append a history row if there is room; always count it, so overflow is detectable."""
    n = ta.n_history
    if n < hist.shape[0]:
        hist[n, 0] = t
        hist[n, 1] = th
        hist[n, 2] = om
    ta.n_history = n + 1


@njit(cache=True)
def _record_inside(hist, ta, args, t, h, th, om, f0, kx, kv):
    """Append states at 1/4, 1/2 and 3/4 of [t, t + h] within an accepted step, each by a
    DOP853 step from its start (as accurate as the step itself)."""
    for j in range(1, 4):
        x, v = _step(args, t, th, om, f0, 0.25 * j * h, kx, kv)
        _push(hist, ta, t + 0.25 * j * h, x, v)


@njit(cache=True)
def _log_peak(peaks, ta, t, th):
    """Append the peak (t, theta) to ``peaks`` if there is room; always count it, so that
    overflow is detectable."""
    n = ta.n_peaks
    if n < peaks.shape[0]:
        peaks[n, 0] = t
        peaks[n, 1] = th
    ta.n_peaks = n + 1


@njit(cache=True)
def _dense(dense, ta, args, t, t_end, th, om, f0, kx, kv):
    """Dense output on an accepted step from (t, theta, theta_dot) to t_end: the state at
    each requested time dense[j, 0] in [t, t_end] not yet served, by one DOP853 step from t
    (as accurate as the step), into dense[j, 1:3]. Requested times before t fall in a rest
    and keep the (0, 0) they hold; a time on an impact gets the state just before it."""
    j = ta.n_dense
    while j < dense.shape[0] and dense[j, 0] <= t_end:
        if dense[j, 0] >= t:
            dense[j, 1], dense[j, 2] = _step(args, t, th, om, f0, dense[j, 0] - t, kx, kv)
        j += 1
    ta.n_dense = j


@njit(cache=True, **NO_REFCOUNT)
def _dense_poly(dense, ta, w, n, t, hs, t_end):
    """:func:`_dense` on an accepted Taylor step of length hs from t, by its polynomial w[0]
    of order n (the solution within the step's tolerance), up to t_end."""
    j = ta.n_dense
    while j < dense.shape[0] and dense[j, 0] <= t_end:
        if dense[j, 0] >= t:
            x, d, _ = poly_value(w[0], n, (dense[j, 0] - t) / hs)
            dense[j, 1], dense[j, 2] = x, d / hs
        j += 1
    ta.n_dense = j


@njit(cache=True)
def _record_poly(hist, ta, c, n, t, hs, t_end):
    """Append states at 1/4, 1/2 and 3/4 of [t, t_end] within an accepted Taylor step of
    length hs, from its polynomial c of order n (the solution within the step's tolerance)."""
    for j in range(1, 4):
        tj = t + 0.25 * j * (t_end - t)
        x, d, _ = poly_value(c, n, (tj - t) / hs)
        _push(hist, ta, tj, x, d / hs)


@njit(cache=True, inline="always", **NO_REFCOUNT)
def _log_poly_step(log, ta, w, n, t, hs, t_end):
    """Log an accepted Taylor step of length hs from t, up to t_end (its end or its event),
    from its polynomial w[0] of order n: the dense output (:func:`_dense_poly`) and the
    history (:func:`_record_poly`), where ``log`` = (hist, imps, peaks, dense) asks for them."""
    hist, dense = log[0], log[3]
    if dense.shape[0] > 0:
        _dense_poly(dense, ta, w, n, t, hs, t_end)
    if hist.shape[0] > 0:
        _record_poly(hist, ta, w[0], n, t, hs, t_end)


@njit(cache=True, inline="always")
def _log_dop853_step(log, ta, args, t, t_end, th, om, f0, kx, kv):
    """Log an accepted DOP853 step from (t, th, om) up to t_end (its end or its event): the
    dense output (:func:`_dense`) and the history (:func:`_record_inside`)."""
    hist, dense = log[0], log[3]
    _dense(dense, ta, args, t, t_end, th, om, f0, kx, kv)
    if hist.shape[0] > 0:
        _record_inside(hist, ta, args, t, t_end - t, th, om, f0, kx, kv)
