"""Sine-pulse closed forms of the linearized block: eqs. (3.3)-(3.15) and (4.13) of [000]."""

from __future__ import annotations

import numpy as np


def _check_a(a):
    a = np.asarray(a, dtype=float)
    if np.any(~(a >= 1.0)):
        raise ValueError("a = a_g / (g alpha) must be >= 1 (the block must uplift)")
    return a


def pulse_end_time(a, omega):
    r"""Time from uplift to the end of a one-cycle sine pulse, p T_ex [-].

    eq. (3.2)-(3.3) of [000]:

    .. math:: p T_{ex} = (2\pi - \psi) / \omega, \quad \psi = \arcsin(1/a)
    """
    a = _check_a(a)
    return (2.0 * np.pi - np.arcsin(1.0 / a)) / np.asarray(omega, dtype=float)


def sine_constants(a, omega):
    r"""A0*, B0* and C0* of eq. (3.9) of [000] (twice the constants of eq. 3.7, over alpha).

    .. math::
        A_0^* = \frac{\omega^2 + \omega\sqrt{a^2-1}}{\omega^2+1}, \quad
        B_0^* = \frac{\omega^2 - \omega\sqrt{a^2-1}}{\omega^2+1}, \quad
        C_0^* = \frac{2a}{\omega^2+1}
    """
    a = _check_a(a)
    w = np.asarray(omega, dtype=float)
    root = np.sqrt(a * a - 1.0)
    den = w * w + 1.0
    return (w * w + w * root) / den, (w * w - w * root) / den, 2.0 * a / den


def d0_star(a, omega):
    r"""D0* of eq. (3.9) of [000], in its product form (the expanded form has lost a square).

    .. math::
        D_0^* = \left(A_0^* - \tfrac{\omega}{2} C_0^* e^{pT_{ex}}\right)
                \left(B_0^* + \tfrac{\omega}{2} C_0^* e^{-pT_{ex}}\right)
    """
    A, B, C = sine_constants(a, omega)
    w = np.asarray(omega, dtype=float)
    e = np.exp(pulse_end_time(a, omega))
    return (A - 0.5 * w * C * e) * (B + 0.5 * w * C / e)


def first_impact_time_after_pulse(a, omega):
    r"""tau_i2 = p t_i2, the first impact (from uplift) when it follows the end of the pulse.

    eq. (3.13) of [000]:

    .. math::
        \tau_{i2} = \ln\frac{1 + \sqrt{1 - D_0^*}}{B_0^* + \frac{\omega}{2} C_0^* e^{-pT_{ex}}}
    """
    A, B, C = sine_constants(a, omega)
    w = np.asarray(omega, dtype=float)
    den = B + 0.5 * w * C * np.exp(-pulse_end_time(a, omega))
    return np.log((1.0 + np.sqrt(1.0 - d0_star(a, omega))) / den)


def impact_velocity_after_pulse(a, omega):
    r"""|theta_dot| / (p alpha) just before that first impact, eq. (3.15) of [000].

    .. math:: \dot\theta_{i2} / (p\alpha) = \sqrt{1 - D_0^*}
    """
    return np.sqrt(1.0 - d0_star(a, omega))


def max_rotation(a, omega, eta):
    r"""Peak rotation after the first impact, theta_max / alpha, eq. (4.13) of [000].

    Exact when the first impact follows the end of the pulse; NaN where the block overturns
    (eta^2 (1 - D0*) >= 1).

    .. math:: \theta_m / \alpha = 1 - \sqrt{1 - \eta^2 (1 - D_0^*)}
    """
    x = 1.0 - np.asarray(eta, dtype=float) ** 2 * (1.0 - d0_star(a, omega))
    with np.errstate(invalid="ignore"):
        return np.where(x > 0.0, 1.0 - np.sqrt(np.where(x > 0.0, x, 0.0)), np.nan)
