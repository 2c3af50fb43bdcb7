"""Numba kernel of the elastic response spectrum (private).

The linear oscillator u'' + 2 zeta omega u' + omega^2 u = -a_g(t), started at rest, is advanced
from sample to sample by the exact recursion for a piecewise-linear excitation of Nigam &
Jennings (1969) (the "piecewise exact" method of Chopra, Dynamics of Structures, sec. 5.2).
The peak |u| is located between samples where the velocity changes sign, and after the last
sample the free vibration is followed to its first extremum, so no peak is under-reported.
Where omega h is large a step is split into sub-steps (the record is piecewise linear, so this
is exact), so that no oscillation hides inside a step (see ``substeps``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .._roots import newton_bisect


@njit(cache=True)
def step_coefficients(omega, zeta, h):
    """The 8 coefficients of one exact step of length h (Nigam & Jennings 1969;
    the coefficients as tabulated by Chopra, Dynamics of Structures, sec. 5.2).

    u1 = A u0 + B v0 + C f0 + D f1 and v1 = A' u0 + B' v0 + C' f0 + D' f1 for a force per
    unit mass f that is linear from f0 to f1 over the step; returns (A, B, C, D, A', B', C', D').
    """
    wd = omega * math.sqrt(1.0 - zeta * zeta)
    r = zeta / math.sqrt(1.0 - zeta * zeta)
    e = math.exp(-zeta * omega * h)
    s = math.sin(wd * h)
    c = math.cos(wd * h)
    k = omega * omega
    q0 = e * (r * s + c)
    q1 = e * s / wd
    q2 = (
        2.0 * zeta / (omega * h)
        + e
        * (((1.0 - 2.0 * zeta * zeta) / (wd * h) - r) * s - (1.0 + 2.0 * zeta / (omega * h)) * c)
    ) / k
    q3 = (
        1.0
        - 2.0 * zeta / (omega * h)
        + e * ((2.0 * zeta * zeta - 1.0) / (wd * h) * s + 2.0 * zeta / (omega * h) * c)
    ) / k
    q4 = -e * omega / math.sqrt(1.0 - zeta * zeta) * s
    q5 = e * (c - r * s)
    q6 = (-1.0 / h + e * ((omega / math.sqrt(1.0 - zeta * zeta) + r / h) * s + c / h)) / k
    q7 = (1.0 - e * (r * s + c)) / (k * h)
    return q0, q1, q2, q3, q4, q5, q6, q7


@njit(cache=True)
def _advance(q, u, v, f0, f1):
    return (
        q[0] * u + q[1] * v + q[2] * f0 + q[3] * f1,
        q[4] * u + q[5] * v + q[6] * f0 + q[7] * f1,
    )


@njit(cache=True, inline="always")
def _state_inside(tau, args):
    """(u, v) at tau inside a step from (u, v) with the force linear from f0 to f1 over h."""
    omega, zeta, h, u, v, f0, f1 = args
    return _advance(step_coefficients(omega, zeta, tau), u, v, f0, f0 + (f1 - f0) * tau / h)


@njit(cache=True, inline="always")
def _velocity_fdf(tau, args):
    """v(tau) and v'(tau) = f - 2 zeta omega v - omega^2 u inside a step (:func:`_state_inside`)."""
    omega, zeta, h, u, v, f0, f1 = args
    ut, vt = _state_inside(tau, args)
    return vt, f0 + (f1 - f0) * tau / h - 2.0 * zeta * omega * vt - omega * omega * ut


# The peak's time to 1e-12 of the step: |u| is flat there, so its error is far below that.
PEAK_TIME_TOL = 1e-12
# Newton from the zero of the linear v converges in 2-4 steps; bisection alone needs 40.
PEAK_MAX_ITER = 30


@njit(cache=True)
def _peak_inside(omega, zeta, h, u, v, f0, f1, v1):
    """|u| at the velocity zero inside a step: safeguarded Newton on the exact v(tau).

    Starts from the zero of the linear interpolation of v; v' = f - 2 zeta omega v - omega^2 u.
    """
    args = (omega, zeta, h, u, v, f0, f1)
    sign_lo = 1.0 if v > 0.0 else -1.0
    tau = newton_bisect(
        _velocity_fdf, args, 0.0, h, h * v / (v - v1), sign_lo, PEAK_TIME_TOL * h, PEAK_MAX_ITER
    )
    return abs(_state_inside(tau, args)[0])


@njit(cache=True)
def _free_vibration_peak(omega, zeta, u, v):
    """Largest |u| of the damped free vibration from (u, v): at t = 0 or its first extremum."""
    wd = omega * math.sqrt(1.0 - zeta * zeta)
    c = (zeta * omega * v + omega * omega * u) / wd
    phi = math.atan2(v, c)
    if phi <= 0.0:
        phi += math.pi
    t = phi / wd
    e = math.exp(-zeta * omega * t)
    ut = e * (u * math.cos(wd * t) + (v + zeta * omega * u) / wd * math.sin(wd * t))
    return max(abs(u), abs(ut))


@njit(cache=True)
def _coefficient_table(omegas, zeta, h, q):
    """q[k, j]: coefficient k of :func:`step_coefficients` for oscillator j."""
    for j in range(omegas.shape[0]):
        c = step_coefficients(omegas[j], zeta, h)
        for k in range(8):
            q[k, j] = c[k]


@njit(cache=True)
def _block_peaks(omegas, zeta, steps, acc, substeps):
    """Peak |u| [m] of a block of oscillators under the record acc [m/s^2].

    Each record step is advanced in ``substeps`` equal sub-steps, the force interpolated
    linearly (exact: the record is piecewise linear), so that omega h stays small enough for
    no oscillation to hide inside a step. The sub-steps run in the outer loop and the
    oscillators in the inner one, which the compiler vectorizes (keep the inner loop free of
    divisions and branches). A step whose velocity changes sign is refined
    (:func:`_peak_inside`) when |u| + |v| h could exceed the peak: twice the parabolic
    estimate of the excess, v tau / 2 with tau <= h the zero of the linear v; and always when
    omega h > 1.5, where that estimate is poor.
    """
    m = omegas.shape[0]
    q = np.empty((8, m))
    h = steps[0] / substeps
    _coefficient_table(omegas, zeta, h, q)
    u = np.zeros(m)
    v = np.zeros(m)
    u0 = np.zeros(m)
    v0 = np.zeros(m)
    peak = np.zeros(m)
    flag = np.zeros(m, dtype=np.bool_)
    q0, q1, q2, q3, q4, q5, q6, q7 = q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7]
    f1 = -acc[0]
    for s in range(steps.shape[0] * substeps):
        i = s // substeps
        if steps[i] / substeps != h:
            h = steps[i] / substeps
            _coefficient_table(omegas, zeta, h, q)
        f0 = f1
        w = (s - i * substeps + 1.0) / substeps
        f1 = -(acc[i] + w * (acc[i + 1] - acc[i])) if w < 1.0 else -acc[i + 1]
        refine = False
        for j in range(m):
            uj = u[j]
            vj = v[j]
            u1 = q0[j] * uj + q1[j] * vj + q2[j] * f0 + q3[j] * f1
            v1 = q4[j] * uj + q5[j] * vj + q6[j] * f0 + q7[j] * f1
            p = max(peak[j], abs(u1))
            f = (vj * v1 < 0.0) & ((abs(uj) + abs(vj) * h > p) | (omegas[j] * h > 1.5))
            flag[j] = f
            refine |= f
            peak[j] = p
            u0[j] = uj
            v0[j] = vj
            u[j] = u1
            v[j] = v1
        if refine:
            for j in range(m):
                if flag[j]:
                    inside = _peak_inside(omegas[j], zeta, h, u0[j], v0[j], f0, f1, v[j])
                    peak[j] = max(peak[j], inside)
    for j in range(m):
        peak[j] = max(peak[j], _free_vibration_peak(omegas[j], zeta, u[j], v[j]))
    return peak


#: Oscillators per block of :func:`peak_displacements` (the unit of parallel work).
BLOCK = 32


@njit(cache=True, parallel=True)
def peak_displacements(omegas, zeta, steps, acc, substeps):
    """Peak |u| [m] of linear oscillators (omegas [rad/s], zeta) under acc [m/s^2] sampled at
    the given steps [s], each advanced in ``substeps`` sub-steps, started at rest; blocks of
    oscillators run in parallel."""
    n = omegas.shape[0]
    out = np.empty(n)
    for b in prange((n + BLOCK - 1) // BLOCK):
        lo = b * BLOCK
        hi = min(n, lo + BLOCK)
        out[lo:hi] = _block_peaks(omegas[lo:hi], zeta, steps, acc, substeps)
    return out
