"""Numba kernels of the rotated oscillator peaks of a pair of components (private).

The oscillator u'' + 2 zeta omega u' + omega^2 u = -a(t) is linear in a, so under
a_psi = a_x cos(psi) + a_y sin(psi) its state is (u, v)_psi = cos(psi) (u, v)_x +
sin(psi) (u, v)_y. The two components' states are advanced once, sub-step by sub-step, by the
spectrum's exact recursion (:func:`rockstudy.motions._spectrum.step_coefficients`); each
angle's peak |u_psi| is then read from the combined states, refined inside a sub-step where
v_psi changes sign, and after the record in the free vibration, by the spectrum's own
functions: the peak of every angle is the spectrum kernel's for a_psi, to rounding.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._spectrum import _advance, _free_vibration_peak, _peak_inside, step_coefficients


@njit(cache=True)
def state_histories(omega, zeta, steps, ax, ay, substeps):
    """(h, f_x, f_y, u_x, v_x, u_y, v_y): the sub-step lengths [s], the forces -a at the
    sub-step ends and the oscillator states there (index 0 the start, at rest), each record
    step split into ``substeps`` equal sub-steps (exact: the record is piecewise linear)."""
    n = steps.shape[0] * substeps
    h = np.empty(n)
    fx = np.empty(n + 1)
    fy = np.empty(n + 1)
    state = np.zeros((4, n + 1))
    fx[0], fy[0] = -ax[0], -ay[0]
    q = step_coefficients(omega, zeta, steps[0] / substeps)
    for s in range(n):
        i = s // substeps
        h[s] = steps[i] / substeps
        if s == 0 or h[s] != h[s - 1]:
            q = step_coefficients(omega, zeta, h[s])
        w = (s - i * substeps + 1.0) / substeps
        fx[s + 1] = -(ax[i] + w * (ax[i + 1] - ax[i])) if w < 1.0 else -ax[i + 1]
        fy[s + 1] = -(ay[i] + w * (ay[i + 1] - ay[i])) if w < 1.0 else -ay[i + 1]
        state[0, s + 1], state[1, s + 1] = _advance(q, state[0, s], state[1, s], fx[s], fx[s + 1])
        state[2, s + 1], state[3, s + 1] = _advance(q, state[2, s], state[3, s], fy[s], fy[s + 1])
    return h, fx, fy, state


@njit(cache=True)
def rotated_peak_displacements(omega, zeta, h, fx, fy, state, cosines, sines):
    """Peak |u_psi| [m] of the oscillator (omega, zeta) at each angle (cos, sin) from the
    states of :func:`state_histories`: refined inside a sub-step whose velocity changes sign
    when the peak could be there (the spectrum kernel's rule), and in the free vibration."""
    out = np.empty(cosines.shape[0])
    n = h.shape[0]
    for j in range(cosines.shape[0]):
        c, s = cosines[j], sines[j]
        u0 = 0.0
        v0 = 0.0
        peak = 0.0
        for k in range(n):
            u1 = c * state[0, k + 1] + s * state[2, k + 1]
            v1 = c * state[1, k + 1] + s * state[3, k + 1]
            peak = max(peak, abs(u1))
            if v0 * v1 < 0.0 and (abs(u0) + abs(v0) * h[k] > peak or omega * h[k] > 1.5):
                f0 = c * fx[k] + s * fy[k]
                f1 = c * fx[k + 1] + s * fy[k + 1]
                peak = max(peak, _peak_inside(omega, zeta, h[k], u0, v0, f0, f1, v1))
            u0, v0 = u1, v1
        out[j] = max(peak, _free_vibration_peak(omega, zeta, u0, v0))
    return out
