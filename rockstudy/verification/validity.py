"""Where the sine-pulse closed forms of [000] hold: a map over (a, omega, eta), and alpha.

:func:`validity_map` evaluates the closed forms, the exact linear solver and the nonlinear
kernel on one grid and stores everything as an ``xarray.Dataset``. Measured on the default grid
(60 x 60 values of a in [1.01, 10] and omega in [0.3, 12], eta in {0.7, 0.85, 0.95}, nonlinear
blocks with alpha in {0.05, 0.25}; ``tests/test_validity.py`` asserts these on a coarser grid):

- the mode classifier (3.10, 3.18, 3.20-3.21, 3.31) agrees with the linear solver on 99.8 % of
  the points that uplift; every disagreement is an overturning after two or more impacts, which
  the closed forms do not cover (they call it safe);
- first impact times (3.13) and (3.21) agree with the linear solver to 4e-13 wherever they apply;
- the spectrum (4.13) is exact for the peak after a first impact that follows the pulse (above
  the 3.31 curve): there it equals the maximum rotation to 1e-6 on 53 % of the safe points, and
  on all the others the maximum comes before that impact (the solver's maximum is larger).
  Below the (3.31) curve (4.13) is an approximation: median error 16 %, unbounded near the
  overturning boundaries;
- the semi-analytical impact time (3.29) is within 7 % of (3.21) only for 0.8 < tau_i1 < 1.2
  (errors of order 1 elsewhere); its boundary (3.30) stays within 6.4 % of (3.20)-(3.21) for
  0.4 < omega < 4.2; beyond omega ~ 5 there is no case 1.1 overturning at all;
- the nonlinear block follows the linear modes on 99.8 % of the grid for alpha = 0.05 and on
  95.8 % for alpha = 0.25 (the linearization error of non-slender blocks).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..closedform import sine
from ..constants import G
from ..dynamics.batch import simulate_batch

__all__ = ["linear_outcomes", "validity_map"]

_P = 1.0  # the map is in (a, omega): any p will do; p = 1 makes t = tau
_LIN_ALPHA = 0.05  # the linear model is scale-free in (a, omega, eta): any alpha will do
_R = 3.0 * G / (4.0 * _P * _P)


def _modes(out, period):
    """Mode index of cf.MODES from a batch output (first impact vs the end of the pulse)."""
    return np.where(
        out["max_rotation"] == 0,
        sine.NO_UPLIFT,
        np.where(
            out["overturned"],
            np.where(out["n_impacts"] == 0, sine.OVER_NO_IMPACT, sine.OVER_IMPACT),
            np.where(out["first_impact_time"] <= period, sine.SAFE_DURING, sine.SAFE_AFTER),
        ),
    ).astype(np.int8)


def linear_outcomes(a, omega, eta):
    """The exact linear solver on the sine pulses of (a, omega, eta) (any p: here p = 1), and
    the mode of each (an index of cf.MODES). Returns (modes, batch outputs)."""
    a, omega, eta = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (a, omega, eta)))
    period = 2.0 * np.pi / (omega * _P)
    out = simulate_batch(
        half_diagonal=_R,
        slenderness=_LIN_ALPHA,
        restitution=eta.ravel(),
        pulse="sine",
        amplitude=(a * G * _LIN_ALPHA).ravel(),
        period=period.ravel(),
        method="linear",
    )
    out = {k: v.reshape(a.shape) for k, v in out.items()}
    return _modes(out, period), out


def validity_map(
    a=None, omega=None, eta=(0.7, 0.85, 0.95), alpha=(0.05, 0.25), rtol=1e-10
) -> xr.Dataset:
    """Closed forms against the linear and nonlinear solvers on an (a, omega, eta) grid.

    Parameters
    ----------
    a : array_like, optional
        a = a_g / (g alpha) values (> 1); default 60 values in [1.01, 10], geometric.
    omega : array_like, optional
        omega_g / p values; default 60 values in [0.3, 12], geometric.
    eta : sequence of float
        Coefficients of restitution.
    alpha : sequence of float
        Slenderness of the blocks run through the nonlinear kernel [rad] (a_g = a g alpha).
    rtol : float
        Tolerance of the nonlinear kernel.

    Returns
    -------
    xarray.Dataset
        Modes (indices of :data:`rockstudy.closedform.MODES`), first impact times tau from
        uplift, max rotations theta / alpha and their errors, on dims (eta, omega, a) and
        (alpha, eta, omega, a); summary shares in the attributes.
    """
    a = np.geomspace(1.01, 10.0, 60) if a is None else np.asarray(a, dtype=float)
    omega = np.geomspace(0.3, 12.0, 60) if omega is None else np.asarray(omega, dtype=float)
    eta = np.asarray(eta, dtype=float)
    alpha = np.asarray(alpha, dtype=float)
    E, W, A = np.meshgrid(eta, omega, a, indexing="ij")
    shape = E.shape
    period = 2.0 * np.pi / (W * _P)
    t_up = np.arcsin(1.0 / A) / (W * _P)
    dims = ("eta", "omega", "a")

    mode_lin, lin = linear_outcomes(A, W, E)
    tau_lin = _P * (lin["first_impact_time"] - t_up)

    mode_cf = sine.overturning_mode_code(A, W, E)
    tau_i1 = sine.first_impact_time_during_pulse(A, W)
    tau_i1_hat = sine.first_impact_time_during_pulse_approx(A, W, check=False)
    tau_i2 = sine.first_impact_time_after_pulse(A, W)
    during = sine.limit_residual(A, W) >= 0.0
    tau_cf = np.where(during, tau_i1, tau_i2)
    th_cf = sine.max_rotation(A, W, E, check=False)
    th_lin = np.where(lin["overturned"], np.nan, lin["max_rotation"] / _LIN_ALPHA)

    ds = xr.Dataset(
        {
            "mode_closed_form": (dims, mode_cf),
            "mode_linear": (dims, mode_lin),
            "impacts_linear": (dims, lin["n_impacts"]),
            "first_impact_closed_form": (dims, tau_cf),
            "first_impact_linear": (dims, tau_lin),
            "first_impact_error": (dims, np.abs(tau_cf - tau_lin)),
            "first_impact_semi_analytical": (dims, tau_i1_hat),
            "first_impact_semi_analytical_error": (dims, np.abs(tau_i1_hat / tau_i1 - 1)),
            "impact_during_pulse": (dims, during),
            "max_rotation_closed_form": (dims, th_cf),
            "max_rotation_linear": (dims, th_lin),
            "max_rotation_error": (dims, np.abs(th_cf / th_lin - 1)),
        },
        coords={"eta": eta, "omega": omega, "a": a, "alpha": alpha},
    )
    nl_modes, nl_max = [], []
    for al in alpha:
        amp = A * G * al
        out = simulate_batch(
            half_diagonal=_R,
            slenderness=al,
            restitution=E.ravel(),
            pulse="sine",
            amplitude=amp.ravel(),
            period=period.ravel(),
            rtol=rtol,
        )
        out = {k: v.reshape(shape) for k, v in out.items()}
        nl_modes.append(_modes(out, period))
        nl_max.append(np.where(out["overturned"], np.nan, out["max_rotation"] / al))
    ds["mode_nonlinear"] = (("alpha",) + dims, np.array(nl_modes))
    ds["max_rotation_nonlinear"] = (("alpha",) + dims, np.array(nl_max))
    _describe(ds)
    _summarise(ds)
    return ds


_ATTRS = {
    "mode_closed_form": ("index into rockstudy.closedform.MODES, eqs. (3.10)-(3.31) of [000]", "1"),
    "mode_linear": ("mode from the exact linear solver, eq. (3.1)", "1"),
    "impacts_linear": ("impacts of the linear solver until rest or overturning", "1"),
    "first_impact_closed_form": ("tau_i1 (3.21) or tau_i2 (3.13) from uplift", "1"),
    "first_impact_linear": ("p t of the first impact from uplift, linear solver", "1"),
    "first_impact_error": ("|closed form - linear| of the first impact time", "1"),
    "first_impact_semi_analytical": ("tau_i1 hat (3.29)", "1"),
    "first_impact_semi_analytical_error": ("relative error of (3.29) against (3.21)", "1"),
    "impact_during_pulse": ("below the (3.31) curve: first impact before the pulse ends", "1"),
    "max_rotation_closed_form": ("theta_max / alpha by (4.13)", "1"),
    "max_rotation_linear": ("theta_max / alpha, linear solver (NaN if overturned)", "1"),
    "max_rotation_error": ("relative error of (4.13) against the linear solver", "1"),
    "mode_nonlinear": ("mode from the nonlinear kernel, eq. (2.2), a_g = a g alpha", "1"),
    "max_rotation_nonlinear": ("theta_max / alpha, nonlinear kernel (NaN if overturned)", "1"),
}


def _describe(ds):
    for name, (long_name, units) in _ATTRS.items():
        ds[name].attrs.update(long_name=long_name, units=units)
    ds["a"].attrs.update(long_name="a_g / (g alpha)", units="1")
    ds["omega"].attrs.update(long_name="omega_g / p", units="1")
    ds["eta"].attrs.update(long_name="coefficient of restitution", units="1")
    ds["alpha"].attrs.update(long_name="slenderness of the nonlinear blocks", units="rad")


def _summarise(ds):
    """Shares that the module docstring quotes, as attributes."""
    uplift = ds.mode_linear != sine.NO_UPLIFT
    agree = (ds.mode_closed_form == ds.mode_linear).where(uplift)
    multi = (ds.mode_linear == sine.OVER_IMPACT) & (ds.impacts_linear >= 2)
    ds.attrs["classifier_agreement"] = float(agree.mean())
    ds.attrs["disagreements_after_two_or_more_impacts"] = float(
        (multi & (ds.mode_closed_form != ds.mode_linear)).sum()
        / max(int(((ds.mode_closed_form != ds.mode_linear) & uplift).sum()), 1)
    )
    after = ~ds.impact_during_pulse & np.isfinite(ds.max_rotation_error)
    ds.attrs["max_rotation_within_1e-6_after_pulse"] = float(
        (ds.max_rotation_error < 1e-6).where(after).mean()
    )
    ds.attrs["max_rotation_within_1e-6_during_pulse"] = float(
        (ds.max_rotation_error < 1e-6)
        .where(ds.impact_during_pulse & np.isfinite(ds.max_rotation_error))
        .mean()
    )
    ds.attrs["first_impact_max_error"] = float(ds.first_impact_error.max())
    for i, al in enumerate(ds.alpha.values):
        same = (ds.mode_nonlinear.isel(alpha=i) == ds.mode_linear).where(uplift)
        ds.attrs[f"nonlinear_alpha_{al:g}_mode_agreement"] = float(same.mean())
