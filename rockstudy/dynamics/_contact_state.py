"""The state and the tallies of a scene of the contact model's kernel (private): the layout
of its two float arrays (the run's state st, the tallies ta), the block with its friction
(:class:`Body`), and the small kernels that log a history row, raise the peaks, enter a
regime and tally an impact or a friction decision (:mod:`._contact_scene`)."""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from . import slide_rock as sr

# the tallies of a scene (one float array)
(T_MAX_THETA, T_PEAK_TIME, T_MAX_U, T_N_IMPACTS, T_FIRST_SLIP, T_LIFT, T_STEPS) = range(7)
(T_FIRST_IMPACT, T_OVER_TIME, T_STATUS, T_N_HIST, T_U_END) = range(7, 12)
T_TIMES = 12  # seconds in each regime, 5 slots
# the convergence signals: the least relative margin of a friction decision, and the events
# on the first step of a regime (:func:`_tally_margin`, :func:`_at_event`)
T_MARGIN, T_CLOSE = 17, 18
N_TALLIES = 19
# the run's state (one float array): regime, corner, slip direction, time, step, fresh, and
# whether the half-cycle under way started at a sticking impact after the motion (clean)
S_REG, S_SIDE, S_SLIP, S_T, S_H, S_FRESH, S_CLEAN = range(7)

Body = namedtuple("Body", ("radius", "alpha", "eta", "static", "kinetic"))
Body.__doc__ = """A block with its friction: R [m], alpha [rad], Housner's eta, mu_s, mu_k."""


@njit(cache=True)
def _new_tallies():
    """The tallies of a scene at rest at t = 0."""
    ta = np.zeros(N_TALLIES)
    ta[T_PEAK_TIME] = ta[T_FIRST_SLIP] = ta[T_FIRST_IMPACT] = ta[T_OVER_TIME] = np.nan
    ta[T_MARGIN] = np.inf
    return ta


@njit(cache=True)
def _row(hist, ta, t, theta, theta_dot, u):
    """A history row (t, theta, theta_dot, u) (kept while ``hist`` has room); the peaks of
    |theta| (and its time) and |u| follow it."""
    n = int(ta[T_N_HIST])
    if n < hist.shape[0]:
        hist[n, 0], hist[n, 1], hist[n, 2], hist[n, 3] = t, theta, theta_dot, u
    ta[T_N_HIST] = n + 1
    ta[T_U_END] = u
    _raise_peaks(ta, t, theta, u)


@njit(cache=True)
def _raise_peaks(ta, t, theta, u):
    """Raise max |theta| (with its time) and max |u| to a state's."""
    if abs(theta) > ta[T_MAX_THETA]:
        ta[T_MAX_THETA], ta[T_PEAK_TIME] = abs(theta), t
    ta[T_MAX_U] = max(ta[T_MAX_U], abs(u))


@njit(cache=True)
def _flight_slip(blk, z, side):
    """u [m] of a block in flight: x_c - s b of the corner s = sign(theta) (``side`` at 0)."""
    corner = math.copysign(1.0, z[2]) if z[2] != 0.0 else side
    phi = blk.alpha - corner * z[2]
    return z[0] + corner * blk.radius * (math.sin(phi) - math.sin(blk.alpha))


@njit(cache=True)
def _log_state(hist, ta, st, blk, z):
    """A history row of the state (t, theta, theta_dot, u) in any regime."""
    if int(st[S_REG]) == sr.FLIGHT:
        _row(hist, ta, st[S_T], z[2], z[5], _flight_slip(blk, z, st[S_SIDE]))
    else:
        _row(hist, ta, st[S_T], z[1], z[4], z[0])


@njit(cache=True)
def _enter(st, ta, regime, side, slip):
    """Enter ``regime`` on corner ``side`` slipping towards ``slip`` at st[S_T]."""
    st[S_REG], st[S_SIDE], st[S_SLIP], st[S_FRESH], st[S_CLEAN] = regime, side, slip, 1.0, 0.0
    if (regime == sr.SLIDE or regime == sr.SLIDE_ROCK) and math.isnan(ta[T_FIRST_SLIP]):
        ta[T_FIRST_SLIP] = st[S_T]


@njit(cache=True)
def _tally_margin(ta, static, f_h, f_v):
    """Lower the least margin of the friction decisions to that of ``|F|`` <= mu_s N with
    the force (or impulse) (f_h, f_v), relative to mu_s N: a decision within the state's
    error of its threshold may go either way (:func:`contact_batch` flags it)."""
    cone = static * f_v
    if cone > 0.0:
        ta[T_MARGIN] = min(ta[T_MARGIN], abs(cone - abs(f_h)) / cone)


@njit(cache=True)
def _tally_impact(ta, imps, t):
    """Count an impact (its time into ``imps`` while it has room; the first one's time)."""
    n = int(ta[T_N_IMPACTS])
    if n < imps.shape[0]:
        imps[n] = t
    ta[T_N_IMPACTS] = n + 1.0
    if math.isnan(ta[T_FIRST_IMPACT]):
        ta[T_FIRST_IMPACT] = t
