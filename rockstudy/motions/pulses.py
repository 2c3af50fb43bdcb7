"""Analytic acceleration pulses (paper [000], section 3 and Fig. 5; DESIGN.md "Pulses").

Time is measured from the start of the motion. A negative amplitude mirrors the pulse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from .. import _validate
from . import _kernels
from .base import Motion

__all__ = [
    "check_period",
    "CosinePulse",
    "HalfSinePulse",
    "MAX_CYCLES",
    "NoMotion",
    "PERIOD_RANGE",
    "pulse_kernel_rows",
    "PULSES",
    "ricker_half_width",
    "RickerWavelet",
    "SinePulse",
]

#: Pulse periods T_p [s] taken: a microsecond to about 11.6 days (far beyond any ground
#: motion at both ends; below ~1e-160 s the kernels' divisions by omega_g underflow).
PERIOD_RANGE = (1e-6, 1e6)
#: Most cycles of a sine or cosine pulse.
MAX_CYCLES = 10**6


def _amplitude(value: float) -> float:
    value = _validate.number("amplitude", value)
    top = _validate.MAX_ACCELERATION
    if not math.isfinite(value) or value == 0.0 or abs(value) > top:
        raise ValueError(
            f"amplitude must be a non-zero number [m/s^2] within +-{top:.0e} (about a "
            f"million g), got {value!r}"
        )
    return value


def check_period(value) -> float:
    """T_p [s] as a float, or a ValueError naming ``period`` and :data:`PERIOD_RANGE`."""
    lo, hi = PERIOD_RANGE
    return _validate.in_range("period", value, lo, hi, f"[{lo:g}, {hi:g}] s")


def _cycles(value) -> int:
    if (
        isinstance(value, (bool, np.bool_))
        or not isinstance(value, (int, float, np.integer, np.floating))
        or not math.isfinite(value)
        or int(value) != value
        or not 1 <= int(value) <= MAX_CYCLES
    ):
        raise ValueError(f"cycles must be a whole number in [1, {MAX_CYCLES}], got {value!r}")
    return int(value)


@dataclass(frozen=True)
class _TrigPulse(Motion):
    """a_g sin(omega_g t + phase) over a whole number of periods (or a half period)."""

    amplitude: float
    period: float
    cycles: int = 1
    _phase: float = field(default=0.0, init=False, repr=False)

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _amplitude(self.amplitude))
        object.__setattr__(self, "period", check_period(self.period))
        object.__setattr__(self, "cycles", _cycles(self.cycles))

    @property
    def angular_frequency(self) -> float:
        """omega_g = 2 pi / T_p [rad/s]."""
        return 2.0 * math.pi / self.period

    @property
    def duration(self) -> float:
        return self.cycles * self.period

    @property
    def peak(self) -> float:
        return abs(self.amplitude)

    def kernel_spec(self):
        kind, rows = pulse_kernel_rows(_NAMES[type(self)], self.amplitude, self.period, self.cycles)
        return kind, rows[0], _EMPTY, _EMPTY, _kernels.NO_VERTICAL


_EMPTY = np.zeros(2)


@dataclass(frozen=True)
class SinePulse(_TrigPulse):
    """One or more cycles of a sine: a_g sin(omega_g t) for 0 <= t <= n T_p (paper [000], eq. 3.2).

    Parameters
    ----------
    amplitude : float
        a_g [m/s^2]; negative mirrors the pulse.
    period : float
        T_p [s], > 0.
    cycles : int
        n, the number of full cycles (default 1, the sine pulse of [000]).
    """


@dataclass(frozen=True)
class CosinePulse(_TrigPulse):
    """a_g cos(omega_g t) for 0 <= t <= n T_p (paper [000], Fig. 5).

    Parameters are those of :class:`SinePulse`.
    """

    _phase: float = field(default=math.pi / 2, init=False, repr=False)


@dataclass(frozen=True)
class HalfSinePulse(_TrigPulse):
    """A single lobe a_g sin(omega_g t) for 0 <= t <= T_p / 2.

    Parameters
    ----------
    amplitude : float
        a_g [m/s^2]; negative mirrors the pulse.
    period : float
        T_p [s], the period of the full sine (the lobe lasts T_p / 2).
    """

    cycles: int = field(default=1, init=False)

    @property
    def duration(self) -> float:
        return 0.5 * self.period


def ricker_half_width(threshold: float = 1e-6) -> float:
    """x = pi f t0 at which the Ricker wavelet has decayed to ``threshold`` of its peak."""
    return brentq(lambda x: (2 * x * x - 1) * math.exp(-x * x) - threshold, 1.0, 10.0, xtol=1e-14)


_RICKER_X0 = ricker_half_width()


@dataclass(frozen=True)
class RickerWavelet(Motion):
    """Ricker wavelet a_g (1 - 2 pi^2 f^2 (t - t0)^2) exp(-pi^2 f^2 (t - t0)^2), f = 1 / T_p.

    t0 is chosen so that the wavelet starts (and ends, at 2 t0) below 1e-6 a_g.

    Parameters
    ----------
    amplitude : float
        a_g [m/s^2], the central peak; negative mirrors the wavelet.
    period : float
        T_p [s], > 0.
    """

    amplitude: float
    period: float

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _amplitude(self.amplitude))
        object.__setattr__(self, "period", check_period(self.period))

    @property
    def center(self) -> float:
        """t0 [s], the time of the central peak."""
        return _RICKER_X0 * self.period / math.pi

    @property
    def duration(self) -> float:
        return 2.0 * self.center

    @property
    def peak(self) -> float:
        return abs(self.amplitude)

    def kernel_spec(self):
        kind, rows = pulse_kernel_rows("ricker", self.amplitude, self.period)
        return kind, rows[0], _EMPTY, _EMPTY, _kernels.NO_VERTICAL


_NAMES = {
    SinePulse: "sine",
    CosinePulse: "cosine",
    HalfSinePulse: "half-sine",
    RickerWavelet: "ricker",
}
PULSES = {name: cls for cls, name in _NAMES.items()}


def pulse_kernel_rows(pulse: str, amplitude, period, cycles=1):
    """Kernel encoding of many pulses of one shape: (kind, params array of shape (n, 4)).

    Parameters
    ----------
    pulse : {"sine", "cosine", "half-sine", "ricker"}
    amplitude, period, cycles : array_like
        a_g [m/s^2], T_p [s] and the number of cycles (sine and cosine), broadcast together.
        They are not validated here; the public constructors and the batch entry point do.
    """
    amp, per, cyc = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(x, dtype=float)) for x in (amplitude, period, cycles))
    )
    rows = np.empty(amp.shape + (4,))
    rows[:, 0] = amp
    if pulse == "ricker":
        rows[:, 1] = 1.0 / per
        rows[:, 2] = _RICKER_X0 * per / math.pi
        rows[:, 3] = 2.0 * rows[:, 2]
        return _kernels.KIND_RICKER, rows
    rows[:, 1] = 2.0 * math.pi / per
    rows[:, 2] = math.pi / 2 if pulse == "cosine" else 0.0
    rows[:, 3] = 0.5 * per if pulse == "half-sine" else cyc * per
    return _kernels.KIND_TRIG, rows


@dataclass(frozen=True)
class NoMotion(Motion):
    """No ground motion: free rocking from the initial state given to ``simulate``."""

    @property
    def duration(self) -> float:
        return 0.0

    @property
    def peak(self) -> float:
        return 0.0

    def kernel_spec(self):
        params = np.array([0.0, 1.0, 0.0, 0.0])
        return _kernels.KIND_TRIG, params, _EMPTY, _EMPTY, _kernels.NO_VERTICAL
