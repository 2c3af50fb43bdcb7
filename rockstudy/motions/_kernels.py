"""Numba kernels that evaluate a ground motion from its kernel encoding (private).

A motion reaches the solvers as ``(kind, params, times, samples, vsamples)``:

- ``KIND_TRIG``: ``a sin(omega t + phase)`` for ``0 <= t <= duration``;
  params = (a, omega, phase, duration).
- ``KIND_RICKER``: ``a (1 - 2 pi^2 f^2 (t-t0)^2) exp(-pi^2 f^2 (t-t0)^2)`` for
  ``0 <= t <= duration``; params = (a, f, t0, duration).
- ``KIND_RECORD``: ``scale`` times the linear interpolation of ``samples`` at ``times``;
  params = (scale, 0, 0, duration).

``vsamples`` is the vertical component [m/s^2, positive upwards] of a record on the same
``times``, multiplied by ``|scale|`` (mirroring the horizontal direction does not turn the
vertical upside down); an empty array for a motion without one (every pulse). It is always
passed, empty or not, so that each kernel has one numba signature.

The acceleration is zero outside ``[0, duration]``. Units: m/s^2 and s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

KIND_TRIG = 0
KIND_RICKER = 1
KIND_RECORD = 2

#: ``vsamples`` of a motion without a vertical component (writable: one numba signature).
NO_VERTICAL = np.empty(0)


@njit(cache=True, inline="always")
def _trig(p, t):
    return p[0] * math.sin(p[1] * t + p[2])


@njit(cache=True, inline="always")
def _ricker(p, t):
    x = (math.pi * p[1] * (t - p[2])) ** 2
    return p[0] * (1.0 - 2.0 * x) * math.exp(-x)


@njit(cache=True)
def _record(times, samples, t, k):
    """Interpolate on segment k, which must satisfy times[k] <= t <= times[k+1]."""
    w = (t - times[k]) / (times[k + 1] - times[k])
    return samples[k] + w * (samples[k + 1] - samples[k])


@njit(cache=True)
def segment_index(times, t, k):
    """Index k of the record segment with times[k] <= t < times[k+1] (the last one at the end).

    The search starts from the hint k, so a forward sweep costs O(1) per call.
    """
    n = times.shape[0]
    if k < 0:
        k = 0
    while k < n - 2 and t >= times[k + 1]:
        k += 1
    while k > 0 and t < times[k]:
        k -= 1
    return k


@njit(cache=True)
def ground_acceleration(kind, params, times, samples, t, k):
    """Ground acceleration [m/s^2] at time t [s]; k is the record segment (ignored otherwise)."""
    if t < 0.0 or t > params[3]:
        return 0.0
    if kind == KIND_TRIG:
        return _trig(params, t)
    if kind == KIND_RICKER:
        return _ricker(params, t)
    return params[0] * _record(times, samples, t, k)


@njit(cache=True, inline="always")
def vertical_acceleration(kind, params, times, vsamples, t, k):
    """Vertical ground acceleration u_v'' [m/s^2] (positive upwards) at time t [s]: 0.0 for a
    motion without a vertical component (``vsamples`` empty) and outside the motion."""
    if vsamples.shape[0] == 0 or t < 0.0 or t > params[3]:
        return 0.0
    return abs(params[0]) * _record(times, vsamples, t, k)


@njit(cache=True)
def ground_acceleration_array(kind, params, times, samples, t):
    """Vectorised :func:`ground_acceleration` over a sorted or unsorted array of times."""
    out = np.empty(t.shape[0])
    k = 0
    for i in range(t.shape[0]):
        if kind == KIND_RECORD:
            k = segment_index(times, min(max(t[i], 0.0), params[3]), k)
        out[i] = ground_acceleration(kind, params, times, samples, t[i], k)
    return out
