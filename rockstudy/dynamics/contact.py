"""Contact forces of a rocking block: the friction it needs and whether it stays on the ground.

Housner's block rocks about a base corner that neither slides nor lifts. Those are
assumptions, and the motion itself says when they fail: the corner carries the force
F = m (a_G + g) that accelerates the centre of mass G, and it holds only while the vertical
part F_v stays compressive and the horizontal part within friction, ``|F_h|`` <= mu F_v.

For a rectangular block of half-diagonal R and slenderness alpha rocking on side s = +-1
(theta > 0 on the positive corner), with phi = alpha - s theta, G sits at
(-s R sin phi, R cos phi) from the pivot, which moves with the ground (u_h'', u_v''); twice
differentiated:

.. math::

   F_h / m = \\ddot u_h + R (\\ddot\\theta \\cos\\phi + s \\dot\\theta^2 \\sin\\phi), \\qquad
   F_v / m = g + \\ddot u_v + R (s \\ddot\\theta \\sin\\phi - \\dot\\theta^2 \\cos\\phi),

with theta_ddot from the equation of motion (eq. 2.2 of [000] with gravity g + u_v'', or its
linearization 3.1). At rest theta_ddot = theta_dot = 0 and F_h / F_v = u_h'' / (g + u_v'');
at uplift, ``|u_h''|`` = (g + u_v'') tan alpha, both expressions give tan alpha.

At an impact the ground's impulse J = m (v_G+ - v_G-) (the ground's velocity is continuous):
with theta_dot+ = eta theta_dot- at theta = 0,
``|J_h / J_v|`` = (1 - eta) / ((1 + eta) tan alpha). Whatever its distribution over the two
corners and the impact's duration, the Coulomb inequalities of its parts add up to
``|J_h|`` <= mu J_v, so this ratio is a friction the impact needs; with Housner's restitution
(2.4 of [000]) the impulse acts at the new corner alone and the ratio is exactly its demand.
"""

from __future__ import annotations

import dataclasses
import functools
from typing import NamedTuple

import numpy as np

from ..constants import G
from ..motions import _kernels as mk
from . import _rocking
from ._contact import contact_forces, forces_at, rocking_acceleration
from ._dop853 import hermite5

__all__ = [
    "ContactCheck",
    "check_contact",
    "contact_forces",
    "half_diagonal",
    "impact_impulse_ratio",
    "rocking_acceleration",
]

#: Interior points per history interval at which the rocking forces are evaluated (besides
#: the record samples and the pulse's extrema inside it), before the largest is refined.
INTERIOR = 4
#: The largest of them is refined by ZOOMS grids of ZOOM points, each 2 / (ZOOM - 1) of the
#: last: the time of the peak to about 1e-5 of a history interval, its value to ~1e-10.
ZOOM, ZOOMS = 33, 3


class ContactCheck(NamedTuple):
    """The contact over a response: the friction coefficient it needs (inf with a lift-off),
    whether the vertical contact force stopped being compressive, and when the need peaked
    [s]."""

    friction_demand: float
    lift_off: bool
    time: float


def half_diagonal(frequency_parameter):
    """R [m] of the rectangular block of p [rad/s]: p^2 = 3 g / (4 R) (eq. 2.2 of [000])."""
    return 0.75 * G / np.asarray(frequency_parameter, dtype=float) ** 2


def impact_impulse_ratio(restitution, slenderness):
    """``|J_h / J_v|`` of the ground's impulse at an impact: (1 - eta) / ((1 + eta) tan alpha)."""
    return (1.0 - restitution) / ((1.0 + restitution) * np.tan(slenderness))


class _Ground:
    """A motion's accelerations from its kernel encoding (read once)."""

    def __init__(self, motion):
        self.kind, self.mp, self.times, self.samples, self.vsamples = motion.kernel_spec()
        self.duration = float(self.mp[3])

    def at(self, t):
        """(a_h, a_v) [m/s^2] at the times ``t`` (a_v zero without a vertical)."""
        t = np.ascontiguousarray(np.atleast_1d(t), dtype=float)
        a_h = mk.ground_acceleration_array(self.kind, self.mp, self.times, self.samples, t)
        if self.vsamples.size == 0:
            return a_h, np.zeros_like(a_h)
        inside = (t >= 0.0) & (t <= self.duration)
        a_v = abs(self.mp[0]) * np.interp(t, self.times, self.vsamples)
        return a_h, np.where(inside, a_v, 0.0)

    def kinks(self, lo, hi):
        """The times inside the spans (lo, hi) (sorted, disjoint) where |a| may peak between
        history points: the record's samples, or the extrema of a pulse's acceleration."""
        if self.kind == mk.KIND_RECORD:
            t = self.times
        elif self.kind == mk.KIND_TRIG and self.mp[1] > 0.0:  # w t + phase = pi/2 + n pi
            w, phase = self.mp[1], self.mp[2]
            n = np.arange(np.floor(phase / np.pi), (w * self.duration + phase) / np.pi + 1)
            t = ((n + 0.5) * np.pi - phase) / w
        elif self.kind == mk.KIND_RICKER:  # extrema at t0 and t0 +- sqrt(3/2) / (pi f)
            d = np.sqrt(1.5) / (np.pi * self.mp[1])
            t = np.array([self.mp[2] - d, self.mp[2], self.mp[2] + d])
        else:
            return np.empty(0, dtype=int), np.empty(0)
        j = np.searchsorted(lo, t, side="right") - 1
        inside = (j >= 0) & (t > lo[np.maximum(j, 0)]) & (t < hi[np.maximum(j, 0)])
        return j[inside], t[inside]


def _rocking_intervals(t, th, om):
    """Mask of the history intervals [t_i, t_i+1] in which the block rocks (not those of zero
    length at an impact, nor a rest: theta = 0 at both ends and at rest, theta_dot = 0, at
    the second), and each one's side."""
    rest = (th[:-1] == 0.0) & (th[1:] == 0.0) & (om[1:] == 0.0)
    rocking = (t[1:] > t[:-1]) & ~rest
    # the side: of theta where it is not 0; else leaving the left end (theta_dot there) or
    # arriving at an impact at the right end (against theta_dot there)
    side = np.where(
        th[:-1] != 0.0,
        np.sign(th[:-1]),
        np.where(
            th[1:] != 0.0,
            np.sign(th[1:]),
            np.where(om[:-1] != 0.0, np.sign(om[:-1]), -np.sign(om[1:])),
        ),
    )
    return rocking, side


def _rest_spans(t, rocking, end):
    """The complement in [0, end] of the rocking intervals: the spans at rest [s]."""
    starts, stops = t[:-1][rocking], t[1:][rocking]
    lo = np.concatenate([[0.0], stops])
    hi = np.concatenate([starts, [end]])
    keep = hi > lo
    return lo[keep], hi[keep]


def _rest_ratio(ground, lo, hi):
    """(max |a_h| / (g + a_v), its time) over the rest spans: exact, a_h and a_v being linear
    between a record's samples (the ratio of two linear functions is monotone) and |a_h|
    peaking at the pulse's known extrema."""
    if lo.size == 0:
        return 0.0, np.nan
    t = np.concatenate([lo, hi, ground.kinks(lo, hi)[1]])
    a_h, a_v = ground.at(t)
    ratio = np.abs(a_h) / (G + a_v)
    i = int(np.argmax(ratio))
    return float(ratio[i]), float(t[i])


class _Rocking:
    """The rocking part of a history: its intervals with the state and theta_ddot at both
    ends, evaluated anywhere inside on the quintic Hermite interpolant."""

    def __init__(self, t, th, om, ground, p, alpha, linear, rocking, side):
        self.ground, self.p, self.alpha, self.linear = ground, p, alpha, linear
        self.radius = float(half_diagonal(p))
        i = np.flatnonzero(rocking)
        self.t0, self.t1, self.s = t[i], t[i + 1], side[i]
        self.y0, self.y1, self.d0, self.d1 = th[i], th[i + 1], om[i], om[i + 1]
        self.a0 = self._accel(self.t0, self.y0, self.s)
        self.a1 = self._accel(self.t1, self.y1, self.s)

    def _accel(self, t, theta, side):
        a_h, a_v = self.ground.at(t)
        return rocking_acceleration(theta, a_h, a_v, side, self.p, self.alpha, self.linear)

    def forces(self, k, t):
        """(F_h / m, F_v / m) at times t inside intervals k."""
        g = self.ground
        mot = (g.kind, g.mp, g.times, g.samples, g.vsamples)
        ends = (self.t0, self.t1, self.y0, self.d0, self.a0, self.y1, self.d1, self.a1)
        return forces_at(k, t, ends, self.s, mot, self.p, self.alpha, self.linear, self.radius)

    def candidates(self):
        """(interval, time) of the points where the forces are evaluated: both ends, INTERIOR
        points between, and the ground's kinks and extrema inside."""
        n = self.t0.size
        u = np.linspace(0.0, 1.0, INTERIOR + 2)
        k = np.repeat(np.arange(n), u.size)
        t = (self.t0[:, None] + u[None, :] * (self.t1 - self.t0)[:, None]).ravel()
        j, extra = self.ground.kinks(self.t0, self.t1)
        return np.concatenate([k, j]), np.concatenate([t, extra])

    def peak_ratio(self):
        """(max ``|F_h / F_v|``, its time, min F_v / m) over the rocking, the largest ratio found
        on the candidates refined on finer grids around it."""
        if self.t0.size == 0:
            return 0.0, np.nan, np.inf
        k, t = self.candidates()
        f_h, f_v = self.forces(k, t)
        if np.min(f_v) <= 0.0:
            i = int(np.argmin(f_v))
            return np.inf, float(t[i]), float(f_v[i])
        ratio = np.abs(f_h) / f_v
        i = int(np.argmax(ratio))
        best, t_best = float(ratio[i]), float(t[i])
        h = (self.t1[k[i]] - self.t0[k[i]]) / (INTERIOR + 1)
        for _ in range(ZOOMS):  # zoom on the largest: ZOOM points over +- h around it
            grid = np.linspace(t_best - h, t_best + h, ZOOM)
            kk = np.searchsorted(self.t0, grid, side="right") - 1
            ok = (kk >= 0) & (grid <= self.t1[np.maximum(kk, 0)])  # in a rocking interval
            fh, fv = self.forces(kk[ok], grid[ok])
            r = np.abs(fh) / fv
            j = int(np.argmax(r))
            if r[j] > best:
                best, t_best = float(r[j]), float(grid[ok][j])
            h = 2.0 * h / (ZOOM - 1)
        return best, t_best, float(np.min(f_v))


def _upright_part(t, th, om, ground, p, alpha, linear):
    """The history of an overturned block up to the last time |theta| = alpha, located by
    bisection on the quintic Hermite interpolant of the interval that crosses it."""
    upright = np.flatnonzero(np.abs(th) <= alpha)
    n = int(upright[-1]) + 1 if upright.size else 1
    if n == t.size or t[n] == t[n - 1]:
        return t[:n], th[:n], om[:n]
    s = np.sign(th[n])
    a_h, a_v = ground.at(t[n - 1 : n + 1])
    acc = rocking_acceleration(th[n - 1 : n + 1], a_h, a_v, s, p, alpha, linear)
    h = t[n] - t[n - 1]
    ends = (th[n - 1], om[n - 1], acc[0], th[n], om[n], acc[1])
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if s * hermite5(mid, h, *ends)[0] <= alpha:
            lo = mid
        else:
            hi = mid
    y, d, _ = hermite5(lo, h, *ends)
    return (
        np.append(t[:n], t[n - 1] + lo * h),
        np.append(th[:n], y),
        np.append(om[:n], d),
    )


def check_contact(t, theta, theta_dot, motion, p, alpha, eta, linear=False, overturned=False):
    """The friction demand and lift-off of a rocking block over its response history.

    max ``|F_h / F_v|`` over the response (see the module docstring for the forces): at rest
    (``|u_h''|`` / (g + u_v''), exactly: at the record's samples or the pulse's extrema), while
    rocking (the forces on the quintic Hermite interpolant of the history's states and the
    equation of motion's theta_ddot, at 4 points inside each history interval and at the ground's
    kinks, the largest refined on finer grids around it; F_v is checked at the same points,
    unrefined), and at the impacts (the impulse ratio
    (1 - eta) / ((1 + eta) tan alpha)). Of an overturned block, up to the last time
    |theta| = alpha (on the interpolant): its fall after it is the overturning, in which F_v
    tends to 0 (at cos phi = 1/3 for a block falling from rest).

    Parameters
    ----------
    t, theta, theta_dot : ndarray
        The history of a :class:`~rockstudy.RockingResult` (an impact's time twice).
    motion : Motion
        The ground motion it ran under.
    p, alpha, eta : float
        Frequency parameter [rad/s], slenderness [rad], restitution of the rectangular block.
    linear : bool
        The history is the linearized model's: theta_ddot from eq. (3.1) of [000].
    overturned : bool
        Whether the block overturned.

    Returns
    -------
    ContactCheck
        ``friction_demand`` (inf where the vertical force did not stay compressive),
        ``lift_off``, and ``time`` [s] of the demand.
    """
    t, th, om = (np.asarray(x, dtype=float) for x in (t, theta, theta_dot))
    ground = _Ground(motion)
    if overturned:
        t, th, om = _upright_part(t, th, om, ground, p, alpha, linear)
    rocking, side = _rocking_intervals(t, th, om)
    still = th[-1] == 0.0 and abs(om[-1]) < _rocking.REST_FRACTION * p * alpha
    end = max(motion.duration, t[-1]) if still and not overturned else t[-1]
    rest, t_rest = _rest_ratio(ground, *_rest_spans(t, rocking, end))
    rocks = _Rocking(t, th, om, ground, p, alpha, linear, rocking, side)
    rock, t_rock, min_fv = rocks.peak_ratio()
    if min_fv <= 0.0:
        return ContactCheck(np.inf, True, t_rock)
    best, when = (rest, t_rest) if rest >= rock else (rock, t_rock)
    impacts = np.flatnonzero(
        (th[:-1] == 0.0) & (th[1:] == 0.0) & (t[1:] == t[:-1]) & (om[:-1] != 0.0)
    )
    if impacts.size:
        ratio = float(impact_impulse_ratio(eta, alpha))
        if ratio > best:
            best, when = ratio, float(t[impacts[0]])
    return ContactCheck(best, False, when)


def with_contact(result, motion, method):
    """``result`` whose ``friction_demand`` and ``lift_off`` come from :func:`check_contact`
    on its history and the rocking parameters in its ``info`` (computed on first use)."""
    info = result.info
    check = functools.partial(
        check_contact,
        result.t,
        result.theta,
        result.theta_dot,
        motion,
        info["frequency_parameter"],
        info["critical_rotation"],
        info["restitution"],
        method in ("linear", "scipy-linear"),
        result.overturned,
    )
    return dataclasses.replace(result, _contact=check)
