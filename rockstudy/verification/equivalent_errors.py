"""How good is the equivalent block? The error maps of paper [003] (Figs. 3, 6-8, 10-13).

For a structure and its equivalent block (eqs. 14-20):

- free-rocking period ratio T_blockeq / T_mech at amplitude phi / phi_cr: T_mech is four times
  the quarter period from energy conservation, the integral of sqrt(I / (2 g (V(phi0) - V)))
  (exact, from the mechanism's terms); T_blockeq is eq. (24);
- overturning-time ratio t_blockeq / t_mech under a constant ground acceleration r g lambda
  (r > 1): t_mech is the integral of sqrt(I / (2 W)) to phi_cr, W = work of gravity and of the
  ground acceleration (eq. 8 is an exact differential: d(I phi_dot^2 / 2) = (G g - B a) dphi);
  t_blockeq is eq. (25), with kappa_1 (lambda_lin) or kappa_2 (lambda);
- the uplift error lambda_lin / lambda.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from scipy.integrate import quad

from ..closedform.free import free_rocking_period, overturning_time_constant_acceleration
from ..constants import G

__all__ = ["Direction", "error_map"]


def _quarter_period(mech, phi0):
    t0 = mech.terms(np.array([phi0]))
    v0 = float(t0["V"][0])

    def smooth(phi):  # times sqrt(phi0 - phi): the singularity goes into the weight
        t = mech.terms(np.array([phi]))
        d = phi0 - phi
        slope = (v0 - t["V"][0]) / d if d > 1e-13 else -t["G"][0]
        return math.sqrt(t["I"][0] / (2 * G * slope))

    return quad(smooth, 0.0, phi0, weight="alg", wvar=(0.0, -0.5), epsrel=1e-10)[0]


def _time_to_critical(mech, phi_cr, ratio, uplift):
    """Time from rest to phi_cr under a constant acceleration ratio * g * lambda (uplifting)."""
    t0 = mech.terms(np.array([0.0]))
    v0, x0 = float(t0["V"][0]), float(t0["X"][0])
    a = ratio * uplift * G

    def work(phi):
        t = mech.terms(np.array([phi]))
        return -G * (t["V"][0] - v0) - a * (t["X"][0] - x0), t["I"][0]

    def smooth(phi):  # times phi^-1/2: W ~ W'(0) phi near the start
        w, inertia = work(phi)
        if phi < 1e-13:
            t = mech.terms(np.array([0.0]))
            slope = t["G"][0] * G + t["B"][0] * a
        else:
            slope = w / phi
        return math.sqrt(inertia / (2 * slope))

    return quad(smooth, 0.0, phi_cr, weight="alg", wvar=(-0.5, 0.0), epsrel=1e-9, limit=200)[0]


def error_map(
    structures,
    labels: dict,
    amplitude=(0.1, 0.3, 0.5, 0.7, 0.9),
    acceleration=(1.1, 1.5, 2.0, 3.0, 5.0),
) -> xr.Dataset:
    """Error maps of the equivalent block for a family of structures.

    Parameters
    ----------
    structures : sequence
        Structures with ``mechanism()`` and ``rocking_parameters()``, one per ``structure``
        coordinate.
    labels : dict
        Name -> sequence of the parameters that distinguish the structures (coordinates).
    amplitude : sequence of float
        phi / phi_cr for the period ratio.
    acceleration : sequence of float
        Ground acceleration over g lambda (> 1) for the overturning-time ratios.

    Returns
    -------
    xarray.Dataset
        ``period_ratio`` (structure, amplitude), ``overturn_time_ratio_kappa1`` and
        ``..._kappa2`` (structure, acceleration), ``uplift_ratio`` (structure).
    """
    amp = np.asarray(amplitude, float)
    acc = np.asarray(acceleration, float)
    per = np.empty((len(structures), amp.size))
    k1 = np.empty((len(structures), acc.size))
    k2 = np.empty_like(k1)
    up = np.empty(len(structures))
    for i, s in enumerate(structures):
        mech, rp = s.mechanism(), s.rocking_parameters()
        p = rp.frequency_parameter
        for j, r in enumerate(amp):
            per[i, j] = free_rocking_period(p, r) / (
                4 * _quarter_period(mech, r * rp.critical_rotation)
            )
        for j, r in enumerate(acc):
            t_mech = _time_to_critical(mech, rp.critical_rotation, r, rp.uplift)
            k1[i, j] = (
                overturning_time_constant_acceleration(p, r, rp.uplift / rp.uplift_linearized)
                / t_mech
            )
            k2[i, j] = overturning_time_constant_acceleration(p, r) / t_mech
        up[i] = rp.uplift_linearized / rp.uplift
    coords = {"structure": np.arange(len(structures)), "amplitude": amp, "acceleration": acc}
    ds = xr.Dataset(
        {
            "period_ratio": (
                ("structure", "amplitude"),
                per,
                {"long_name": "T_blockeq / T_mech, free rocking", "units": "1"},
            ),
            "overturn_time_ratio_kappa1": (
                ("structure", "acceleration"),
                k1,
                {"long_name": "t_blockeq / t_mech, kappa_1", "units": "1"},
            ),
            "overturn_time_ratio_kappa2": (
                ("structure", "acceleration"),
                k2,
                {"long_name": "t_blockeq / t_mech, kappa_2", "units": "1"},
            ),
            "uplift_ratio": (
                ("structure",),
                up,
                {"long_name": "lambda_lin / lambda", "units": "1"},
            ),
        },
        coords=coords,
    )
    for name, values in labels.items():
        ds.coords[name] = ("structure", np.asarray(values))
    ds["amplitude"].attrs.update(long_name="phi / phi_cr", units="1")
    ds["acceleration"].attrs.update(long_name="u_g'' / (g lambda)", units="1")
    return ds


class Direction:
    """One rocking direction of an asymmetric structure, seen as a symmetric one (for
    :func:`error_map`): direction 1 rocks towards +x, -1 towards -x."""

    def __init__(self, structure, direction: int):
        self.structure, self.direction = structure, direction

    def mechanism(self):
        return self.structure.mechanism(self.direction)

    def rocking_parameters(self):
        pos, neg = self.structure.rocking_parameters()
        return pos if self.direction == 1 else neg
