"""The interface every ground motion offers to the solvers."""

from __future__ import annotations

import numpy as np

from . import _kernels

__all__ = ["Motion"]


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
