"""Where the block model stops, per scene of a study: the friction check.

A rocking block is assumed not to slide and not to leave the ground. A study that gives a
friction coefficient ``friction = mu`` (top level, or per object) stores each scene's
``friction_demand`` (max abs(F_h / F_v) at the contact, :mod:`rockstudy.dynamics.contact`) and
``lift_off``; a scene is *outside the model* where the demand exceeds mu (the block would
slide first) or the contact force stopped being compressive (lift-off).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["friction_array", "outside_model", "summary_line"]


def friction_array(ds: xr.Dataset, friction) -> xr.DataArray:
    """The friction coefficient of each scene of ``ds``: a number, or one per structure (on
    ``structure``; NaN where an object gives none)."""
    mu = np.asarray(friction, float)
    given = mu[~np.isnan(mu)]
    if not given.size or not np.all(np.isfinite(given) & (given > 0)):
        raise ValueError(
            f"friction: give friction coefficients > 0 (NaN: none for that structure), got {mu!r}"
        )
    if mu.ndim == 0 or mu.size == 1:
        return xr.DataArray(float(mu.ravel()[0]))
    if "structure" not in ds.dims or ds.sizes["structure"] != mu.size:
        raise ValueError(
            f"friction: give one number or one per structure ({ds.sizes.get('structure', 0)}), "
            f"got {mu.size}"
        )
    return xr.DataArray(mu, dims="structure", coords={"structure": ds["structure"].values})


def outside_model(ds: xr.Dataset, friction) -> xr.DataArray:
    """True where a scene's friction demand exceeds mu or the block lifts off (a scene not
    run, NaN demand, is not flagged)."""
    if "friction_demand" not in ds:
        raise ValueError("ds: holds no friction_demand (give the study a friction coefficient)")
    mu = friction_array(ds, friction)
    demand = ds["friction_demand"]
    lift = ds["lift_off"] == 1 if "lift_off" in ds else xr.zeros_like(demand, bool)
    return (demand > mu) | lift


def summary_line(ds: xr.Dataset, friction) -> str | None:
    """One sentence for the end of a run: how many scenes lie outside the block model, or
    None when none does."""
    flags = outside_model(ds, friction)
    n = int(flags.sum())
    if not n:
        return None
    lifts = int((ds["lift_off"] == 1).sum()) if "lift_off" in ds else 0
    demand = ds["friction_demand"].values
    top = float(np.nanmax(np.where(np.isfinite(demand), demand, np.nan), initial=0.0))
    mu = np.asarray(friction, float)
    given = (
        f"{float(np.nanmin(mu)):.3g}"
        if mu.size == 1 or np.nanmin(mu) == np.nanmax(mu)
        else (f"{float(np.nanmin(mu)):.3g} to {float(np.nanmax(mu)):.3g}")
    )
    return (
        f"{n} of {flags.size} scenes lie outside the rocking-block model: their friction demand "
        f"|F_h / F_v| exceeds the friction coefficient {given} (largest finite demand "
        f"{top:.3g}) or the block lifts off ({lifts} scenes); there the block would slide or "
        "leave the ground before it rocks as computed"
    )
