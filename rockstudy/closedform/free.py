"""Closed forms of the linearized (equivalent) block without a pulse: paper [003], eqs. (24)-(25).

These hold for any structure reduced to its rocking parameters: p (the frequency parameter),
theta_cr (the critical rotation, alpha for a block) and the uplift ratio lambda / lambda_lin.
"""

from __future__ import annotations

import numpy as np


def free_rocking_period(frequency_parameter, amplitude_ratio):
    r"""Free-rocking period of the linearized block from rest at theta_0, eq. (24) of [003].

    .. math:: T = \frac{4}{p} \cosh^{-1}\left(\frac{1}{1 - \theta_0/\theta_{cr}}\right)

    Parameters
    ----------
    frequency_parameter : array_like
        p [rad/s] > 0.
    amplitude_ratio : array_like
        theta_0 / theta_cr in [0, 1) (theta_cr = alpha for a block).

    Returns
    -------
    ndarray
        T [s]; NaN outside the allowed ranges.
    """
    p = np.asarray(frequency_parameter, dtype=float)
    r = np.asarray(amplitude_ratio, dtype=float)
    ok = (p > 0) & (r >= 0) & (r < 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ok, 4.0 / p * np.arccosh(1.0 / (1.0 - np.where(ok, r, 0.0))), np.nan)


def overturning_time_constant_acceleration(
    frequency_parameter, acceleration_ratio, uplift_ratio=1.0
):
    r"""Time for a linearized block at rest to reach theta_cr under a constant acceleration.

    eq. (25) of [003]:

    .. math::
        t = \frac{1}{p} \cosh^{-1}\left(
            \frac{1}{\frac{\ddot u_g}{g\lambda} \frac{\lambda}{\lambda_{lin}} - 1} + 1\right)

    Parameters
    ----------
    frequency_parameter : array_like
        p [rad/s] > 0.
    acceleration_ratio : array_like
        u_g'' / (g lambda), the acceleration over the (exact) uplift acceleration.
    uplift_ratio : array_like
        lambda / lambda_lin (1 for the linearized block itself, where lambda = alpha).

    Returns
    -------
    ndarray
        t [s]; inf if the block does not lift off (u_g'' <= g lambda_lin), NaN for p <= 0.
    """
    p = np.asarray(frequency_parameter, dtype=float)
    q = np.asarray(acceleration_ratio, dtype=float) * np.asarray(uplift_ratio, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.arccosh(1.0 / (q - 1.0) + 1.0) / p
    return np.where(p > 0, np.where(q > 1.0, t, np.inf), np.nan)
