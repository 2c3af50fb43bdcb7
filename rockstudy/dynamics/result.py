"""The result of one simulation."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class RockingResult:
    """Response of one rocking structure to one ground motion.

    Attributes
    ----------
    t : ndarray
        Times of the history [s], from the start of the motion. At an impact the time appears
        twice: before and after the jump of ``theta_dot``.
    theta, theta_dot : ndarray
        Rotation [rad] and angular velocity [rad/s]; theta > 0 rocks on the positive pivot.
        For a structure, the coordinate named in ``info["coordinate"]``: the mechanism's phi
        (methods "nonlinear", "mechanism", "auto"), or the theta of its equivalent block
        (other methods; phi = kappa_1 theta, eq. 14 of [003]).
    max_rotation : float
        Max |theta| over the response [rad]; pi/2 when the block or structure overturns
        (also for a mechanism that collapses earlier, at ``info["fall_rotation"]``, where its
        history ends).
    overturned : bool
        Whether the block fell over (|theta| reached pi/2, or the mechanism's collapse
        amplitude).
    impact_times : ndarray
        Times of the impacts [s].
    overturn_time : float
        Time at which |theta| reached pi/2 [s], NaN if the block survived.
    method : str
        The method that produced the result.
    info : dict
        What ran: for ``"auto"``, ``model`` (the model each call chose) and ``rtol`` (the
        kernel's); for a structure, ``structure_model`` (the mechanism, or which equivalent
        block) and ``coordinate`` (what ``theta`` and ``max_rotation`` measure); solver
        counters. Every :func:`rockstudy.simulate` result also holds the rocking parameters of
        what ran (``frequency_parameter`` p [rad/s], ``critical_rotation`` [rad]: alpha for a
        block, theta_cr for a structure, ``restitution``), ``motion`` (a description),
        ``rtol_requested`` and the initial conditions.
    """

    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    max_rotation: float
    overturned: bool
    impact_times: np.ndarray
    overturn_time: float
    method: str
    info: dict = field(default_factory=dict)

    @property
    def n_impacts(self) -> int:
        """Number of impacts (until rest, overturning or the end of the history)."""
        return int(self.impact_times.size)

    @classmethod
    def from_dict(cls, r: dict, method: str, info: dict | None = None) -> RockingResult:
        """From the dict of a solver (keys: the field names)."""
        return cls(
            r["t"],
            r["theta"],
            r["theta_dot"],
            r["max_rotation"],
            r["overturned"],
            r["impact_times"],
            r["overturn_time"],
            method,
            info or {},
        )

    def __repr__(self) -> str:
        first = f"{self.impact_times[0]:.4g} s" if self.n_impacts else "none"
        crit = self.info.get("critical_rotation")
        share = (
            f" ({self.max_rotation / crit:.4g} x critical rotation {crit:.4g} rad)" if crit else ""
        )
        over = f"yes, at {self.overturn_time:.4g} s" if self.overturned else "no"
        return (
            f"<RockingResult method={self.method!r}: max rotation {self.max_rotation:.4g} rad"
            f"{share}, overturned {over}, {self.n_impacts} impacts, first impact {first}, "
            f"{self.t.size} history points>"
        )

    def _attributes(self) -> dict:
        """The scalars and inputs as netCDF-ready attributes (numbers and strings)."""
        attrs = {}
        for key, value in self.summary().items():
            if value is None:
                continue
            if isinstance(value, (bool, np.bool_)):
                value = int(value)
            if isinstance(value, (int, float, str, np.integer, np.floating)):
                attrs[key] = value
            else:
                attrs[key] = str(value)
        return attrs

    def to_xarray(self):
        """The history as an :class:`xarray.Dataset` on ``time`` [s] (CF units and long
        names): ``theta`` [rad], ``theta_dot`` [rad/s], and ``impact_time`` [s] on its own
        ``impact`` dimension; the scalars and inputs (rocking parameters, motion, method,
        rtol) are attributes."""
        import xarray as xr

        coordinate = self.info.get("coordinate", "rotation of the block")
        ds = xr.Dataset(
            {
                "theta": ("time", self.theta, {"units": "rad", "long_name": coordinate}),
                "theta_dot": (
                    "time",
                    self.theta_dot,
                    {"units": "rad s-1", "long_name": f"rate of the {coordinate}"},
                ),
                "impact_time": (
                    "impact",
                    self.impact_times,
                    {"units": "s", "long_name": "time of an impact"},
                ),
            },
            coords={"time": ("time", self.t, {"units": "s", "long_name": "time"})},
            attrs=self._attributes(),
        )
        return ds

    def to_dataframe(self):
        """The history as a :class:`pandas.DataFrame`: columns ``t`` [s], ``theta`` [rad] and
        ``theta_dot`` [rad/s] (an impact's time appears twice: before and after it)."""
        import pandas as pd

        return pd.DataFrame({"t": self.t, "theta": self.theta, "theta_dot": self.theta_dot})

    def plot(self, ax=None):
        """Draw theta / theta_cr against t, the impacts as dotted verticals and the
        overturning as a cross; return the matplotlib axes. Without ``info
        ["critical_rotation"]`` theta is drawn in rad."""
        if ax is None:
            import matplotlib.pyplot as plt

            ax = plt.figure().add_subplot()
        crit = self.info.get("critical_rotation")
        scale = crit if crit else 1.0
        ax.plot(self.t, self.theta / scale, lw=1, label="rotation")
        for k, ti in enumerate(self.impact_times):
            ax.axvline(ti, color="0.6", ls=":", lw=0.8, label="impacts" if k == 0 else None)
        if self.overturned and np.isfinite(self.overturn_time):
            ax.plot(
                [self.overturn_time],
                [np.sign(self.theta[-1]) * self.max_rotation / scale],
                "rx",
                ms=9,
                label="overturned",
            )
        ax.set(
            xlabel="time t [s]",
            ylabel="theta / theta_cr [-]" if crit else "theta [rad]",
        )
        ax.legend(fontsize=8)
        return ax

    def summary(self) -> dict:
        """The scalar outcomes as a JSON-ready dict."""
        return {
            "method": self.method,
            "max_rotation": float(self.max_rotation),
            "overturned": bool(self.overturned),
            "n_impacts": self.n_impacts,
            "first_impact_time": float(self.impact_times[0]) if self.n_impacts else None,
            "overturn_time": None if np.isnan(self.overturn_time) else float(self.overturn_time),
            **self.info,
        }
