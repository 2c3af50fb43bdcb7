"""Closed forms of the linearized (equivalent) block without a pulse: paper [003], eqs. (24)-(25).

These hold for any structure reduced to its rocking parameters: p (the frequency parameter),
theta_cr (the critical rotation, alpha for a block) and the uplift ratio lambda / lambda_lin.
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from ..structures.block import FREQUENCY_PARAMETER_RANGE

__all__ = ["free_rocking_period", "overturning_time_constant_acceleration"]

_P_LOW, _P_HIGH = FREQUENCY_PARAMETER_RANGE
_P_LABEL = f"finite, in [{_P_LOW:g}, {_P_HIGH:g}] rad/s"


def _frequency_parameter(value) -> np.ndarray:
    return _validate.real_array("frequency_parameter", value, _P_LOW, _P_HIGH, _P_LABEL)


def free_rocking_period(frequency_parameter, amplitude_ratio):
    r"""Free-rocking period of the linearized block from rest at theta_0, eq. (24) of [003].

    .. math:: T = \frac{4}{p} \cosh^{-1}\left(\frac{1}{1 - \theta_0/\theta_{cr}}\right)

    Parameters
    ----------
    frequency_parameter : array_like
        p [rad/s], in [1e-3, 1e4] (the range of a block's p).
    amplitude_ratio : array_like
        theta_0 / theta_cr >= 0 (theta_cr = alpha for a block).

    Returns
    -------
    ndarray
        T [s]; NaN where theta_0 / theta_cr >= 1: the block starts at or past its critical
        rotation and overturns without rocking back.

    Raises
    ------
    ValueError
        Naming the argument that is not a number, not finite, or outside its range.
    """
    p = _frequency_parameter(frequency_parameter)
    r = _validate.real_array("amplitude_ratio", amplitude_ratio, 0.0, label="finite and >= 0")
    ok = np.broadcast_to(r < 1, np.broadcast_shapes(p.shape, r.shape))
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
        p [rad/s], in [1e-3, 1e4] (the range of a block's p).
    acceleration_ratio : array_like
        u_g'' / (g lambda) >= 0, the acceleration over the (exact) uplift acceleration.
    uplift_ratio : array_like
        lambda / lambda_lin > 0 (1 for the linearized block itself, where lambda = alpha).

    Returns
    -------
    ndarray
        t [s]; inf if the block does not lift off (u_g'' <= g lambda_lin).

    Raises
    ------
    ValueError
        Naming the argument that is not a number, not finite, or outside its range.
    """
    p = _frequency_parameter(frequency_parameter)
    q = _validate.real_array(
        "acceleration_ratio", acceleration_ratio, 0.0, label="finite and >= 0"
    ) * _validate.real_array("uplift_ratio", uplift_ratio, 1e-300, label="finite and > 0")
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = np.arccosh(1.0 / (q - 1.0) + 1.0) / p
    return np.where(q > 1.0, t, np.inf)
