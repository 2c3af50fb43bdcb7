"""Numba kernel of the elastic response spectrum (private).

The linear oscillator u'' + 2 zeta omega u' + omega^2 u = -a_g(t), started at rest, is advanced
from sample to sample by the exact recursion for a piecewise-linear excitation of Nigam &
Jennings (1969) (the "piecewise exact" method of Chopra, Dynamics of Structures, sec. 5.2).
The peak |u| is located between samples where the velocity changes sign, and after the last
sample the free vibration is followed to its first extremum, so no peak is under-reported.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


@njit(cache=True)
def step_coefficients(omega, zeta, h, out):
    """The 8 coefficients of one exact step of length h (Nigam & Jennings 1969, eq. 20).

    u1 = A u0 + B v0 + C f0 + D f1 and v1 = A' u0 + B' v0 + C' f0 + D' f1 for a force per
    unit mass f that is linear from f0 to f1 over the step; out = (A, B, C, D, A', B', C', D').
    """
    wd = omega * math.sqrt(1.0 - zeta * zeta)
    r = zeta / math.sqrt(1.0 - zeta * zeta)
    e = math.exp(-zeta * omega * h)
    s = math.sin(wd * h)
    c = math.cos(wd * h)
    k = omega * omega
    out[0] = e * (r * s + c)
    out[1] = e * s / wd
    out[2] = (
        2.0 * zeta / (omega * h)
        + e
        * (((1.0 - 2.0 * zeta * zeta) / (wd * h) - r) * s - (1.0 + 2.0 * zeta / (omega * h)) * c)
    ) / k
    out[3] = (
        1.0
        - 2.0 * zeta / (omega * h)
        + e * ((2.0 * zeta * zeta - 1.0) / (wd * h) * s + 2.0 * zeta / (omega * h) * c)
    ) / k
    out[4] = -e * omega / math.sqrt(1.0 - zeta * zeta) * s
    out[5] = e * (c - r * s)
    out[6] = (-1.0 / h + e * ((omega / math.sqrt(1.0 - zeta * zeta) + r / h) * s + c / h)) / k
    out[7] = (1.0 - e * (r * s + c)) / (k * h)


@njit(cache=True)
def _advance(q, u, v, f0, f1):
    return (
        q[0] * u + q[1] * v + q[2] * f0 + q[3] * f1,
        q[4] * u + q[5] * v + q[6] * f0 + q[7] * f1,
    )


@njit(cache=True)
def _peak_inside(omega, zeta, h, u, v, f0, f1, v1, q):
    """|u| at the velocity zero inside a step (Illinois regula falsi on v over the step)."""
    lo, hi, v_lo, v_hi = 0.0, h, v, v1
    side = 0
    tau = 0.5 * h
    for _ in range(40):
        tau = (lo * v_hi - hi * v_lo) / (v_hi - v_lo)
        if not lo < tau < hi:
            tau = 0.5 * (lo + hi)
        step_coefficients(omega, zeta, tau, q)
        ut, vt = _advance(q, u, v, f0, f0 + (f1 - f0) * tau / h)
        if vt == 0.0 or hi - lo < 1e-12 * h:
            return abs(ut)
        if (vt > 0.0) == (v_lo > 0.0):
            lo, v_lo = tau, vt
            if side == -1:
                v_hi *= 0.5
            side = -1
        else:
            hi, v_hi = tau, vt
            if side == 1:
                v_lo *= 0.5
            side = 1
        if abs(vt) <= 1e-13 * (abs(v) + abs(v1)):
            return abs(ut)
    return abs(ut)


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
def peak_displacement(omega, zeta, steps, acc):
    """Peak |u| [m] of one oscillator (omega [rad/s], zeta) under the record acc [m/s^2]."""
    q = np.empty(8)
    qs = np.empty(8)
    h_prev = -1.0
    u = 0.0
    v = 0.0
    peak = 0.0
    for i in range(steps.shape[0]):
        h = steps[i]
        if h != h_prev:
            step_coefficients(omega, zeta, h, q)
            h_prev = h
        f0 = -acc[i]
        f1 = -acc[i + 1]
        u1, v1 = _advance(q, u, v, f0, f1)
        m = max(abs(u), abs(u1))
        if m > peak:
            peak = m
        if v * v1 < 0.0 and m >= 0.5 * peak:
            peak = max(peak, _peak_inside(omega, zeta, h, u, v, f0, f1, v1, qs))
        u, v = u1, v1
    return max(peak, _free_vibration_peak(omega, zeta, u, v))


@njit(cache=True, parallel=True)
def peak_displacements(omegas, zeta, steps, acc):
    """:func:`peak_displacement` for many oscillators (parallel over omegas)."""
    out = np.empty(omegas.shape[0])
    for j in prange(omegas.shape[0]):
        out[j] = peak_displacement(omegas[j], zeta, steps, acc)
    return out
