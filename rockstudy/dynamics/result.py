"""The result of one simulation."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["describe", "RockingResult"]

#: The optional arrays of a result (peaks and dense output), in field order.
_OPTIONAL_ARRAYS = ("peak_times", "peak_rotations", "t_eval", "theta_eval", "theta_dot_eval")


def _check_plot_arguments(ax, structure, motion) -> None:
    """TypeError naming ``ax`` if it is neither None nor a matplotlib Axes, or ``structure``
    or ``motion`` if it is neither None nor a string."""
    from matplotlib.axes import Axes

    if ax is not None and not isinstance(ax, Axes):
        raise TypeError(f"ax must be a matplotlib Axes (or None), got {type(ax).__name__}")
    for name, value in (("structure", structure), ("motion", motion)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{name} must be a name (a str) or None, got {type(value).__name__}")


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
    peak_times, peak_rotations : ndarray or None
        The peaks of the response: every local maximum of |theta| (theta_dot = 0 with the
        block swinging back towards its pivot), during the motion and in the free rocking
        after it, as its time [s] and its signed rotation theta [rad] (positive on the
        positive pivot), in time order, each located by the method itself (see
        :func:`rockstudy.simulate`), not read off the history. A rotation at t = 0 counts
        as a peak when the block is released there at rest (theta_dot = 0). Not listed:
        the minima of |theta| (impacts, or rarely a dip under forcing without one) and
        the fall of a block that overturns. ``None`` when the producer did not locate
        peaks.
    t_eval, theta_eval, theta_dot_eval : ndarray or None
        Dense output, when asked for (``simulate(..., t_eval=...)`` or ``dt_out=``): the
        requested times [s] and the state there [rad, rad/s], as accurate as the method's
        own steps. At rest the state is (0, 0); at an impact, the state just before it;
        after an overturning, NaN (the model ends there).
    friction_demand : float or None
        max ``|F_h / F_v|`` of the ground's force on the block at its contact over the response,
        at rest, while rocking and at the impacts (the impulses' ratio): the friction
        coefficient the block needs to rock without sliding, as the model assumes; inf when
        ``lift_off``. Of an overturned block, up to its last time at |theta| = alpha
        (:func:`rockstudy.dynamics.contact.check_contact`). ``None`` where it is not computed:
        a structure other than a :class:`~rockstudy.Block`, or the method ``"complex"``.
    lift_off : bool or None
        Whether the vertical contact force F_v stopped being compressive somewhere (possible
        under strong vertical shaking): the block would leave the ground, which the model
        does not describe, so the result is outside the model. ``None`` where not computed.
        Both are computed from the history on first use (measured: 20-40 ms for a 20 s
        record with 8,600 history points, whose nonlinear run took 5 ms; 1 ms for a pulse).
    conditioning : float or None
        With ``simulate(..., conditioning=True)``: the relative change of ``max_rotation``
        when the amplitude grows by 1e-9, the same method run again
        (:func:`rockstudy.dynamics.conditioning.peak_change`; inf where the overturning
        decision changes). Above 1e-3
        (:data:`~rockstudy.dynamics.conditioning.ILL_CONDITIONED`) the scene is
        ill-conditioned: its peak is not determined to better than that, by any solver.
        ``None`` when not asked for.
    slide : ndarray or None
        With ``simulate(..., friction=mu)`` (the contact model): the slip u [m] on ``t``,
        the horizontal displacement relative to the ground of the base's point under the
        centre of mass of the upright block (:mod:`rockstudy.dynamics.slide_rock`). None
        for Housner's no-slip model, as the four below.
    max_slide, residual_slide : float or None
        Peak ``|u|`` [m] over the response, and u at its end (NaN if the block overturned).
    first_slip_time : float or None
        When the block first slipped (slide or slide-rock) [s]; NaN if it never did.
    regime_times : dict or None
        Seconds spent in each regime: ``rest``, ``slide``, ``rock``, ``slide_rock``,
        ``flight`` (up to the end of the history). With the contact model, ``lift_off``
        says whether the block flew, and ``friction_demand`` is that of Housner's no-slip
        model on the same scene.
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
    peak_times: np.ndarray | None = None
    peak_rotations: np.ndarray | None = None
    t_eval: np.ndarray | None = None
    theta_eval: np.ndarray | None = None
    theta_dot_eval: np.ndarray | None = None
    conditioning: float | None = None
    slide: np.ndarray | None = None
    max_slide: float | None = None
    residual_slide: float | None = None
    first_slip_time: float | None = None
    regime_times: dict | None = None
    _contact: Callable[[], Any] | None = field(default=None, repr=False, compare=False)
    #: the motion and the structure that produced the result (for ``plot``), or None
    _motion: Any = field(default=None, repr=False, compare=False)
    _structure: Any = field(default=None, repr=False, compare=False)

    @property
    def friction_demand(self) -> float | None:
        """max ``|F_h / F_v|`` at the contact over the response (see the class docstring); computed
        on first use, None where not available."""
        check = self._contact_check()
        return None if check is None else float(check.friction_demand)

    @property
    def lift_off(self) -> bool | None:
        """Whether the vertical contact force stopped being compressive (see the class
        docstring); computed on first use, None where not available."""
        check = self._contact_check()
        return None if check is None else bool(check.lift_off)

    def _contact_check(self):
        """The :class:`~rockstudy.dynamics.contact.ContactCheck` of the response, computed
        once from the history (``_contact``: the call that computes it), or None."""
        if self._contact is None:
            return None
        if "_contact_cache" not in self.__dict__:
            object.__setattr__(self, "_contact_cache", self._contact())
        return self.__dict__["_contact_cache"]

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
            *(r.get(k) for k in _OPTIONAL_ARRAYS),
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
                **self._peaks_and_dense(coordinate),
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
        if self.slide is not None:
            ds["slide"] = (
                "time",
                self.slide,
                {"units": "m", "long_name": "slip relative to the ground"},
            )
        return ds

    def _peaks_and_dense(self, coordinate) -> dict:
        """The peaks (on a ``peak`` dimension) and the dense output (on ``time_eval``) as
        Dataset variables, those the result has."""
        out = {}
        if self.peak_times is not None:
            out["peak_time"] = (
                "peak",
                self.peak_times,
                {"units": "s", "long_name": "time of a peak"},
            )
            out["peak_rotation"] = (
                "peak",
                self.peak_rotations,
                {"units": "rad", "long_name": f"{coordinate} at a peak (signed)"},
            )
        if self.t_eval is not None:
            te = {"units": "s", "long_name": "requested time (dense output)"}
            out["theta_eval"] = (
                "time_eval",
                self.theta_eval,
                {"units": "rad", "long_name": f"{coordinate} at the requested times"},
            )
            out["theta_dot_eval"] = (
                "time_eval",
                self.theta_dot_eval,
                {
                    "units": "rad s-1",
                    "long_name": f"rate of the {coordinate} at the requested times",
                },
            )
            out["time_eval"] = ("time_eval", self.t_eval, te)
        return out

    def to_dataframe(self, part=None):
        """A :class:`pandas.DataFrame` of one part of the result.

        Parameters
        ----------
        part : {"history", "dense", "peaks"}, optional
            ``"history"``: columns ``t`` [s], ``theta`` [rad] and ``theta_dot`` [rad/s] (an
            impact's time appears twice: before and after it). ``"dense"``: the same columns
            at the requested times of ``simulate(..., t_eval=)``. ``"peaks"``: columns ``t``
            [s] and ``theta`` [rad] of the peaks. Default: ``"dense"`` when the result has a
            dense output, else ``"history"``.
        """
        import pandas as pd

        if part is None:
            part = "history" if self.t_eval is None else "dense"
        if part == "history":
            return pd.DataFrame({"t": self.t, "theta": self.theta, "theta_dot": self.theta_dot})
        if part == "dense" and self.t_eval is not None:
            return pd.DataFrame(
                {"t": self.t_eval, "theta": self.theta_eval, "theta_dot": self.theta_dot_eval}
            )
        if part == "peaks" and self.peak_times is not None:
            return pd.DataFrame({"t": self.peak_times, "theta": self.peak_rotations})
        if part in ("dense", "peaks"):
            raise ValueError(
                f"part={part!r}: this result has no "
                + ("dense output (simulate(..., t_eval=...))" if part == "dense" else "peaks")
            )
        raise ValueError(f"part must be 'history', 'dense' or 'peaks', got {part!r}")

    def plot(self, ax=None, *, ground=False, structure=None, motion=None):
        """Draw theta / theta_cr against t, with the impacts and the overturning marked.

        The curve passes through the exact peaks and the dense output, smooth between the
        history's points (their cubic Hermite interpolant in theta and theta_dot). Each
        impact is a short tick on the time axis (theta = 0, where it happens), so that a
        long record with a hundred impacts stays readable; an overturning is a cross where
        |theta| last passes theta_cr. Dashed lines mark |theta| = theta_cr where the axis
        reaches them: the axis spans the rocking (1.2 times its peak), and for a fall the
        rocking before it up to +-1.15 theta_cr (the fall runs off the axis). Without
        ``info["critical_rotation"]`` theta is drawn in rad, the cross at the overturning
        time.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Where to draw (not with ``ground``); default a new figure with constrained
            layout, so that no label is clipped.
        ground : bool or Motion
            Add a panel below with the ground acceleration a_g(t) [m/s^2] on the same time
            axis: True for the motion the result was computed with (a result of
            :func:`rockstudy.simulate`), or the :class:`~rockstudy.motions.Motion` to draw.
        structure, motion : str, optional
            Names for the title, e.g. ``"Statue A"`` and ``"Northridge 1994"``; default the
            descriptions in ``info["structure"]`` and ``info["motion"]``.

        Raises
        ------
        TypeError
            Naming ``ax`` if it is no matplotlib Axes, ``structure`` or ``motion`` if it is no
            string (checked before anything is drawn).

        Returns
        -------
        matplotlib Axes
            The rotation's axes (with ``ground``, ``ax.figure.axes[1]`` is the ground's).
        """
        import matplotlib.pyplot as plt

        _check_plot_arguments(ax, structure, motion)
        drawn = self._ground_motion(ground)
        if ax is None:
            fig = plt.figure(layout="constrained", figsize=(7.0, 4.8 if drawn else 3.6))
            axes = fig.subplots(2 if drawn else 1, 1, sharex=True, squeeze=False)[:, 0]
            ax = axes[0]
        elif drawn is not None:
            raise ValueError("ground: the ground panel needs a new figure; leave ax out")
        crit = self.info.get("critical_rotation")
        scale = crit if crit else 1.0
        t, theta = self._curve()
        ax.plot(t, theta / scale, lw=1, label="rotation")
        ax.axhline(0.0, color="0.8", lw=0.6, zorder=0)
        if self.n_impacts:
            ax.plot(
                self.impact_times,
                np.zeros(self.n_impacts),
                "|",
                color="C1",
                ms=11,
                mew=1.2,
                zorder=3,  # over the curve, which lies on theta = 0 at each impact
                label=f"impacts ({self.n_impacts})",
            )
        if crit:
            self._rocking_axis(ax, t, theta / crit)
        elif self.overturned and np.isfinite(self.overturn_time):
            ax.plot(
                [self.overturn_time],
                [np.sign(self.theta[-1]) * self.max_rotation],
                "rx",
                ms=9,
                label="overturned",
            )
        ax.set(
            ylabel="theta / theta_cr [-]" if crit else "theta [rad]",
            title=self._title(structure, motion),
        )
        ax.legend(fontsize=8, loc="best")
        if drawn is None:
            ax.set_xlabel("time t [s]")
            return ax
        g_ax = axes[1]
        g_t = np.linspace(0.0, max(float(t[-1]), drawn.duration), 4000)
        g_ax.plot(g_t, drawn.ground_acceleration(g_t), lw=0.8, color="0.3")
        g_ax.set(xlabel="time t [s]", ylabel="a_g [m/s^2]")
        return ax

    def _rocking_axis(self, ax, t, ratio):
        """The axis of theta / theta_cr (``ratio`` on the times ``t``): dashed lines at +-1,
        and limits that show the rocking before a fall (the fall itself, beyond theta_cr,
        runs off the axis from the cross where it last passed theta_cr)."""
        size = np.abs(ratio)
        inside = np.flatnonzero(size < 1.0)
        if self.overturned and inside.size and inside[-1] + 1 < size.size:
            k = inside[-1]  # the last point inside: the fall passes theta_cr after it
            t_cr = np.interp(1.0, size[k : k + 2], t[k : k + 2])
            sign = np.sign(ratio[k + 1])
            ax.plot([t_cr], [sign], "rx", ms=9, label="overturned (passes theta_cr)")
            top = 1.15
        else:
            top = 1.2 * float(np.max(np.abs(ratio))) or 1.0
        if top >= 1.0:
            ax.axhline(1.0, ls="--", lw=0.8, color="C3", label="|theta| = theta_cr")
            ax.axhline(-1.0, ls="--", lw=0.8, color="C3")
        ax.set_ylim(-top, top)

    def _ground_motion(self, ground):
        """The motion to draw under the response: None, the result's own, or ``ground``."""
        if ground is False or ground is None:
            return None
        if ground is True:
            if self._motion is None:
                raise ValueError(
                    "ground=True: this result does not hold its motion (it was not made by "
                    "rockstudy.simulate); pass the Motion itself, ground=motion"
                )
            return self._motion
        if not hasattr(ground, "ground_acceleration"):
            raise TypeError(f"ground must be True, False or a Motion, got {type(ground).__name__}")
        return ground

    def _title(self, structure=None, motion=None) -> str:
        """The structure and the motion: their names if given, else their descriptions."""
        structure = structure or (describe(self._structure) if self._structure else "structure")
        motion = motion or getattr(self._motion, "name", "") or self.info.get("motion", "motion")
        title = f"{structure} under {motion}"
        return title if len(title) <= 70 else f"{structure}\nunder {motion}"

    def _curve(self, per_interval=8):
        """(t, theta) to draw: the history with the exact peaks and the dense output merged
        in, in time order, and ``per_interval`` points between each two of them on the cubic
        Hermite interpolant of (theta, theta_dot). The drawn curve passes through the true
        peaks, with no corners (the history alone is sampled at a quarter of each step, up to
        0.03 s apart in free rocking, and cuts the peaks)."""
        parts = [(self.t, self.theta, self.theta_dot)]
        if self.peak_times is not None:  # theta_dot = 0 there
            parts.insert(0, (self.peak_times, self.peak_rotations, 0.0 * self.peak_times))
        if self.t_eval is not None:
            ok = np.isfinite(self.theta_eval)
            parts.insert(0, (self.t_eval[ok], self.theta_eval[ok], self.theta_dot_eval[ok]))
        # a stable sort with the history last: at an impact its two rows (before and after the
        # jump of theta_dot) stay together, after any other point at that time
        t, y, d = (np.concatenate(c) for c in zip(*parts, strict=True))
        order = np.argsort(t, kind="stable")
        t, y, d = t[order], y[order], d[order]
        h = np.diff(t)[:, None]
        s = np.linspace(0.0, 1.0, per_interval + 2)[1:-1][None, :]
        # theta = 0 at both ends and no peak between (the peaks are merged in): the block
        # rests there, flat, whatever speed the row of the impact that stopped it holds
        moving = ~((y[:-1] == 0.0) & (y[1:] == 0.0)) if self.peak_times is not None else True
        between = (
            (2 * s**3 - 3 * s**2 + 1) * y[:-1, None]
            + (s**3 - 2 * s**2 + s) * h * (moving * d[:-1])[:, None]
            + (3 * s**2 - 2 * s**3) * y[1:, None]
            + (s**3 - s**2) * h * (moving * d[1:])[:, None]
        )
        t_all = np.concatenate([t[:-1, None], t[:-1, None] + s * h], axis=1)
        y_all = np.concatenate([y[:-1, None], between], axis=1)
        keep = np.concatenate([np.ones((h.size, 1), bool), np.repeat(h > 0, s.size, 1)], axis=1)
        return (
            np.append(t_all[keep], t[-1:]),
            np.append(y_all[keep], y[-1:]),
        )

    def _contact_summary(self) -> dict:
        """friction_demand (None when unbounded: a lift-off) and lift_off, where computed."""
        if self._contact is None:
            return {}
        demand = float(self.friction_demand)
        return {
            "friction_demand": demand if np.isfinite(demand) else None,
            "lift_off": bool(self.lift_off),
        }

    def _slide_summary(self) -> dict:
        """The contact model's sliding outputs, where computed."""
        if self.regime_times is None:
            return {}

        def number(x):
            return float(x) if np.isfinite(x) else None

        return {
            "max_slide": self.max_slide,
            "residual_slide": number(self.residual_slide),
            "first_slip_time": number(self.first_slip_time),
            "regime_times": dict(self.regime_times),
        }

    def summary(self) -> dict:
        """The scalar outcomes as a JSON-ready dict."""
        return {
            "method": self.method,
            "max_rotation": float(self.max_rotation),
            "overturned": bool(self.overturned),
            "n_impacts": self.n_impacts,
            "first_impact_time": float(self.impact_times[0]) if self.n_impacts else None,
            "overturn_time": None if np.isnan(self.overturn_time) else float(self.overturn_time),
            **self._contact_summary(),
            **self._slide_summary(),
            **self.info,
        }


def describe(thing) -> str:
    """A one-line description of a motion or a structure: its class and scalar parameters
    (floats to 12 significant digits: a width of 0.45, not 0.44999999999999996)."""
    if dataclasses.is_dataclass(thing):
        scalars = {
            f.name: getattr(thing, f.name)
            for f in dataclasses.fields(thing)
            if not f.name.startswith("_") and isinstance(getattr(thing, f.name), (int, float, str))
        }
        text = ", ".join(
            f"{k}={float(f'{v:.12g}')!r}" if isinstance(v, float) else f"{k}={v!r}"
            for k, v in scalars.items()
        )
        return f"{type(thing).__name__}({text})"
    return type(thing).__name__
