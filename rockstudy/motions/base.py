"""The interface every ground motion offers to the solvers."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _validate
from . import _kernels

__all__ = ["axis_sign", "check_orientation", "Motion", "ON_AXIS"]

#: |sin(psi)| below which an orientation psi is on a one-component motion's axis (0 or pi):
#: math.sin(math.pi) is 1.2e-16, and a multiple of pi a few turns away a few times that.
ON_AXIS = 1e-12


def check_orientation(psi) -> float:
    """``psi`` [rad] as a float, or a ValueError naming ``orientation``."""
    psi = _validate.number("orientation", psi)
    if not math.isfinite(psi):
        raise ValueError(f"orientation must be a finite angle [rad], got {psi!r}")
    return psi


def axis_sign(psi: float, what: str) -> float:
    """+1 where ``psi`` is 0 and -1 where it is pi (up to whole turns): the directions of a
    motion of one horizontal component (``what`` names it); a ValueError for any other angle."""
    if abs(math.sin(psi)) > ON_AXIS:
        raise ValueError(
            f"orientation = {psi!r} rad: {what} has one horizontal component, which has the "
            "directions 0 and pi only; give a record with acceleration_y (two components) to "
            "orient it at other angles"
        )
    return math.copysign(1.0, math.cos(psi))


class Motion:
    """Base class of ground motions: horizontal acceleration of the base in time.

    Subclasses define :attr:`duration`, :attr:`peak` and :meth:`kernel_spec`.
    """

    @property
    def duration(self) -> float:
        """Time after which the acceleration is zero [s]."""
        raise NotImplementedError

    @property
    def peak(self) -> float:
        """Peak absolute acceleration [m/s^2]."""
        raise NotImplementedError

    def kernel_spec(self):
        """``(kind, params, times, samples, vsamples)``: the encoding the numba kernels read
        (see :mod:`rockstudy.motions._kernels`; ``vsamples`` empty without a vertical)."""
        raise NotImplementedError

    def oriented(self, psi: float) -> Motion:
        """The motion along the direction at angle ``psi`` [rad] from its x axis: itself at
        psi = 0 and mirrored at psi = pi (a pulse of amplitude -a_g), up to whole turns; a
        motion of one horizontal component has no other direction (ValueError).
        :meth:`Record.oriented <rockstudy.motions.Record.oriented>` takes any angle for a
        record with two components."""
        psi = check_orientation(psi)
        if axis_sign(psi, f"the {type(self).__name__}") > 0 or self.peak == 0.0:
            return self
        if dataclasses.is_dataclass(self) and hasattr(self, "amplitude"):
            return dataclasses.replace(self, amplitude=-self.amplitude)
        raise TypeError(f"orientation: cannot mirror a {type(self).__name__}")

    def __call__(self, t):
        """Same as :meth:`ground_acceleration`."""
        return self.ground_acceleration(t)

    def ground_acceleration(self, t):
        """Ground acceleration [m/s^2] at times ``t`` [s] (zero outside the motion).

        Parameters
        ----------
        t : float or array_like
            Times measured from the start of the motion [s].
        """
        kind, params, times, samples, _ = self.kernel_spec()
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        out = _kernels.ground_acceleration_array(kind, params, times, samples, tt.ravel())
        return out.reshape(tt.shape) if np.ndim(t) else float(out[0])
