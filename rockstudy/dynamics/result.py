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
        counters.
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
