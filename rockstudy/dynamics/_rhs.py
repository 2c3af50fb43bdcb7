"""The right-hand side of the rocking kernels (private): :func:`_accel`, the only one.

Housner's block (eq. 2.2 of [000]), its linearization (eq. 3.1) or a tabulated mechanism
(eq. 8 of [003]), with gravity g + u_v''; the lift test of a block at rest (:func:`_lift`)
and the DOP853 step (:data:`_step`) are built on it, and the ground just after a time.
"""

from __future__ import annotations

import math

from numba import njit

from ..constants import G
from ..motions._kernels import KIND_RECORD, ground_acceleration, vertical_acceleration
from ._dop853 import make_dop853_step
from ._tables import _mechanism_accel
from ._taylor import NO_REFCOUNT
from .constants import MODEL_LINEAR, MODEL_TABLE


@njit(cache=True, **NO_REFCOUNT)
def _accel(a_g, a_v, th, om, p, alpha, s, model, tab):
    """theta_ddot on side s under the ground accelerations a_g (horizontal) and a_v
    (vertical, upwards) [m/s^2]: eq. (2.2) of [000] with gravity g + a_v,
    -p^2 [(1 + a_v/g) sin(alpha s - theta) + (a_g/g) cos(alpha s - theta)] (nonlinear),
    its linearization p^2 [(1 + a_v/g)(theta - alpha s) - a_g/g] (eq. 3.1 at a_v = 0), or a
    tabulated mechanism, eq. (8) of [003], in the amplitude u = s theta."""
    if model == MODEL_TABLE:
        return s * _mechanism_accel(s * th, s * om, s * a_g, a_v, tab[0] if s > 0.0 else tab[1])
    a = a_g / G
    gv = 1.0 + a_v / G
    if model == MODEL_LINEAR:
        return p * p * (gv * (th - alpha * s) - a)
    x = alpha * s - th
    return -p * p * (gv * math.sin(x) + a * math.cos(x))


@njit(cache=True, **NO_REFCOUNT)
def _rhs(t, th, om, args):
    """theta_ddot at time t on side s (see :func:`_accel`)."""
    p, alpha, s, model, kind, mp, times, samples, vsamples, k, tab = args
    a_g = ground_acceleration(kind, mp, times, samples, t, k)
    a_v = vertical_acceleration(kind, mp, times, vsamples, t, k)
    return _accel(a_g, a_v, th, om, p, alpha, s, model, tab)


@njit(cache=True, **NO_REFCOUNT)
def _lift(a_g, a_v, p, alpha, model, tab):
    """u_ddot of a block at rest on the side that a_g pushes it towards (s = -sign a_g).

    The block lifts off iff this is > 0, i.e. iff |a_g| exceeds (g + a_v) tan(alpha)
    (nonlinear), (g + a_v) alpha (linearized) or (g + a_v) lambda (a mechanism, eq. 10 of
    [003]). It is computed by the right-hand side itself, so that a block said to lift does
    rise: a threshold test in other arithmetic can disagree with it within a few ulps of the
    threshold, where the Zeno rule would then restart a block that falls straight back,
    without end.
    """
    s = -1.0 if a_g > 0.0 else 1.0
    return s * _accel(a_g, a_v, 0.0, 0.0, p, alpha, s, model, tab)


_step = make_dop853_step(_rhs, NO_REFCOUNT)


@njit(cache=True, inline="always")
def _ground_after(kind, mp, times, samples, t, k):
    """u_g'' just after t: zero from the end of the motion on. A step, or a decision to lift,
    taken at t = duration must see the still ground that follows (a cosine pulse jumps there
    from a_g to 0), not the motion's last value."""
    return 0.0 if t >= mp[3] else ground_acceleration(kind, mp, times, samples, t, k)


@njit(cache=True, inline="always")
def _vertical_after(kind, mp, times, vsamples, t, k):
    """u_v'' just after t, as :func:`_ground_after`: zero from the end of the motion on."""
    return 0.0 if t >= mp[3] else vertical_acceleration(kind, mp, times, vsamples, t, k)


@njit(cache=True, inline="always")
def _record_acceleration(mp, times, samples, t, k):
    """u_g'' [m/s^2] of a record at t on segment k: the sample itself at a sample time (no
    interpolation arithmetic), zero after the end."""
    if t > mp[3]:
        return 0.0
    if t == times[k]:
        return mp[0] * samples[k]
    if t == times[k + 1]:
        return mp[0] * samples[k + 1]
    return ground_acceleration(KIND_RECORD, mp, times, samples, t, k)
