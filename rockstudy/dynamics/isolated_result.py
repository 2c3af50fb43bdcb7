"""The result of one simulation of a block on an isolated base."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["IsolatedResult"]


@dataclass(frozen=True)
class IsolatedResult:
    """Response of a block on an isolated base (:class:`rockstudy.structures.IsolatedBlock`)
    to one ground motion, from :func:`rockstudy.dynamics.isolated_reference.simulate_isolated`.

    Attributes
    ----------
    t : ndarray
        Times of the history [s]; at an impact the time appears twice (before and after).
    theta, theta_dot : ndarray
        The block's rotation relative to the base [rad] and its rate [rad/s]; theta > 0 rocks
        on the positive pivot. Zero while the block rests on the base.
    base_displacement, base_velocity : ndarray
        x_b [m] and x_b' [m/s], the base's displacement and velocity relative to the ground
        (the isolator's deformation).
    max_rotation : float
        Max ``|theta|`` [rad]; pi/2 if the block overturned.
    overturned : bool
        Whether the block fell over (``|theta|`` reached pi/2); the history ends there.
    max_isolator_displacement : float
        Max ``|x_b|`` [m] over the history (up to the overturning, if any), located on the
        integrator's dense output at the zeros of x_b'.
    impact_times, uplift_times : ndarray
        Times [s] of the impacts on the base and of the uplifts from rest.
    overturn_time : float
        When ``|theta|`` reached pi/2 [s]; NaN if the block survived.
    method : str
        ``"scipy"``: the ``solve_ivp`` reference (the numba kernel runs the batches only).
    info : dict
        What ran: the model, rtol, the restitution on the base, whether the history is
        complete (``complete``: False where the impact cap or the tail cap stopped it).
    isolator_capacity : float or None
        The structure's stated isolator capacity [m], for :attr:`exceeds_capacity`.
    t_eval, theta_eval, theta_dot_eval, base_displacement_eval, base_velocity_eval : ndarray
        Dense output when asked for (``t_eval`` or ``dt_out``): the state at those times from
        ``solve_ivp``'s dense output; at an impact the state just before it; NaN after an
        overturning. None otherwise.
    """

    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    base_displacement: np.ndarray
    base_velocity: np.ndarray
    max_rotation: float
    overturned: bool
    max_isolator_displacement: float
    impact_times: np.ndarray
    uplift_times: np.ndarray
    overturn_time: float
    method: str = "scipy"
    info: dict = field(default_factory=dict)
    isolator_capacity: float | None = None
    t_eval: np.ndarray | None = None
    theta_eval: np.ndarray | None = None
    theta_dot_eval: np.ndarray | None = None
    base_displacement_eval: np.ndarray | None = None
    base_velocity_eval: np.ndarray | None = None

    @property
    def exceeds_capacity(self) -> bool | None:
        """Whether ``max_isolator_displacement`` exceeds the stated ``isolator_capacity``;
        None where no capacity was stated."""
        if self.isolator_capacity is None:
            return None
        return bool(self.max_isolator_displacement > self.isolator_capacity)

    def to_xarray(self):
        """The history as an :class:`xarray.Dataset` on ``time`` [s]: ``theta`` [rad],
        ``theta_dot`` [rad/s], ``base_displacement`` [m], ``base_velocity`` [m/s], and the
        impact and uplift times on their own dimensions; the scalars are attributes."""
        import xarray as xr

        def var(dim, values, units, name):
            return (dim, values, {"units": units, "long_name": name})

        ds = xr.Dataset(
            {
                "theta": var("time", self.theta, "rad", "rotation of the block on the base"),
                "theta_dot": var("time", self.theta_dot, "rad s-1", "rate of the rotation"),
                "base_displacement": var(
                    "time", self.base_displacement, "m", "base displacement from the ground"
                ),
                "base_velocity": var("time", self.base_velocity, "m s-1", "base velocity"),
                "impact_time": var("impact", self.impact_times, "s", "time of an impact"),
                "uplift_time": var("uplift", self.uplift_times, "s", "time of an uplift"),
            },
            coords={"time": ("time", self.t, {"units": "s", "long_name": "time"})},
        )
        ds.attrs.update(
            max_rotation=self.max_rotation,
            overturned=int(self.overturned),
            max_isolator_displacement=self.max_isolator_displacement,
            overturn_time=self.overturn_time,
            method=self.method,
            **{
                k: int(v) if isinstance(v, bool) else v
                for k, v in self.info.items()
                if isinstance(v, int | float | str)
            },
        )
        if self.isolator_capacity is not None:
            ds.attrs["isolator_capacity"] = self.isolator_capacity
        return ds
