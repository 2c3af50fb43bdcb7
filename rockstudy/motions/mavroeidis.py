"""The near-fault velocity pulse of Mavroeidis & Papageorgiou (2003).

.. math::
    v(t) = \\frac{A}{2} \\left[1 + \\cos\\left(\\frac{2 \\pi f_p (t - t_0)}{\\gamma}\\right)\\right]
    \\cos\\left(2 \\pi f_p (t - t_0) + \\nu\\right), \\quad |t - t_0| \\le \\frac{\\gamma}{2 f_p}

and zero elsewhere (Mavroeidis & Papageorgiou 2003, BSSA 93(3)), with f_p = 1 / T_p.
The acceleration is its exact derivative.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["mp_pulse_acceleration", "mp_pulse_velocity"]


def _phases(t, period, gamma, center):
    tau = np.asarray(t, dtype=float) - center
    w = 2.0 * math.pi / period
    inside = np.abs(tau) <= 0.5 * gamma * period
    return tau, w, inside


def mp_pulse_velocity(t, amplitude, period, gamma, phase, center):
    """Velocity [m/s] of the Mavroeidis-Papageorgiou pulse at times ``t`` [s].

    Parameters
    ----------
    t : array_like
        Time [s].
    amplitude : float
        A [m/s].
    period : float
        T_p = 1 / f_p [s].
    gamma : float
        gamma > 1, the number of oscillations under the envelope.
    phase : float
        nu [rad].
    center : float
        t_0 [s], the centre of the envelope.
    """
    tau, w, inside = _phases(t, period, gamma, center)
    env = 0.5 * amplitude * (1.0 + np.cos(w * tau / gamma))
    return np.where(inside, env * np.cos(w * tau + phase), 0.0)


def mp_pulse_acceleration(t, amplitude, period, gamma, phase, center):
    r"""Acceleration [m/s^2] of the M-P pulse: the derivative of :func:`mp_pulse_velocity`.

    .. math::
        a(t) = -\frac{A \omega_p}{2} \left[\frac{1}{\gamma}
        \sin\frac{\omega_p \tau}{\gamma} \cos(\omega_p \tau + \nu)
        + \left(1 + \cos\frac{\omega_p \tau}{\gamma}\right) \sin(\omega_p \tau + \nu)\right]

    with tau = t - t_0 and omega_p = 2 pi f_p.
    """
    tau, w, inside = _phases(t, period, gamma, center)
    x = w * tau
    envelope_term = np.sin(x / gamma) * np.cos(x + phase) / gamma
    carrier_term = (1.0 + np.cos(x / gamma)) * np.sin(x + phase)
    acc = -0.5 * amplitude * w * (envelope_term + carrier_term)
    return np.where(inside, acc, 0.0)
