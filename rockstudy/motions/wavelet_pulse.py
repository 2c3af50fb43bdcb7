"""The velocity pulse of a record by the wavelet method of Baker (2007) and Shahi & Baker (2014).

Method (Baker 2007, BSSA 97(5); Shahi & Baker 2014, BSSA 104(5)):

1. The continuous wavelet transform of the ground velocity v with the Daubechies wavelet of
   order 4 (db4, from PyWavelets),

   .. math:: C(s, l) = \\frac{1}{\\sqrt{s}} \\int v(t) \\, \\psi\\left(\\frac{t - l}{s}\\right) dt,

   over scales s whose pseudo-period T = s / F_c (F_c = 0.714, db4's centre frequency) runs
   from :data:`PERIOD_RANGE` [0] to the smaller of :data:`PERIOD_RANGE` [1] and the record's
   duration, over the record padded with ground at rest (zero velocity) before and after it,
   as the authors' continuous transform pads it: a wavelet may reach past the record's ends,
   so a long pulse early in a near-fault record is found. Its centre (the centroid of psi^2)
   must lie inside the record, and the extracted pulse is the part inside the record: a
   pulse centred outside the record, or longer than it, is not a pulse.
2. The wavelet of largest |C| is the first one. :data:`WAVELETS` wavelets at its scale, each
   the largest of the residual within :data:`NEIGHBOURHOOD` scales of the first, are removed
   one after the other (Baker 2007: ten); their sum is the extracted pulse.
3. The pulse indicator (Baker 2007, his logistic model) from the residual r = v - pulse:

   .. math:: PI = 1 / \\left(1 + e^{-23.3 + 14.6 \\, PGV_r / PGV + 20.5 \\, E_r / E}\\right)

   with E the integral of v^2; Baker calls a record pulse-like above 0.85 (and early and strong:
   those two criteria are left to the user).
4. The pulse period T_p is the pseudo-period of the first wavelet, s dt / F_c (Baker 2007;
   the authors' code of Shahi & Baker 2014 computes it so, on a scale zoomed in around the
   best one). The period of the peak of the 5 %-damped pseudo-velocity spectrum of the
   extracted pulse is given as well, ``psv_period``: it is 11-12 % below T_p for an M-P pulse
   of gamma = 2, while T_p is 13 % above the M-P period.

Differences from the papers: one component at a time (Shahi & Baker also rotate the two
horizontal components to the direction of the largest coefficient; a record here is one
component, so its T_p is that of its own orientation); the wavelet transform is a direct
discrete correlation with db4 sampled at each scale.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .intensity import ground_velocity, pseudo_velocity_peak_period, uniform_samples
from .pulse_extraction import PULSE_LIKE_INDICATOR, baker_indicator

__all__ = [
    "DAMPING",
    "extract_wavelet_pulse",
    "LEVEL",
    "NEIGHBOURHOOD",
    "PERIOD_RANGE",
    "SCALE_RATIO",
    "SMALLEST_SCALE",
    "WaveletPulse",
    "WAVELETS",
]

#: Pulse periods scanned [s] (Shahi & Baker 2014: 0.25-15 s).
PERIOD_RANGE = (0.25, 15.0)
#: The scan's ladder of scales [samples]: SMALLEST_SCALE x SCALE_RATIO^k.
SMALLEST_SCALE = 2.0
SCALE_RATIO = 1.05
#: Wavelets summed into the pulse (Baker 2007).
WAVELETS = 10
#: The later wavelets are sought within this many scales of the first one's position.
NEIGHBOURHOOD = 0.4
#: db4 sampled at 2^-LEVEL of its support (PyWavelets ``wavefun``).
LEVEL = 10
#: Damping of the pseudo-velocity spectrum whose peak is T_p.
DAMPING = 0.05


@dataclass(frozen=True, eq=False)
class WaveletPulse:
    """The velocity pulse of a record by the wavelet method (Baker 2007; Shahi & Baker 2014).

    Attributes
    ----------
    period : float
        T_p [s]: the pseudo-period of the first wavelet (NaN if the record has no motion or
        is too short for the shortest pulse).
    indicator : float
        Baker's (2007) pulse indicator in [0, 1].
    amplitude : float
        Peak velocity of the extracted pulse [m/s].
    psv_period : float
        Period [s] of the peak of the extracted pulse's 5 %-damped pseudo-velocity spectrum.
    start, end : float
        Time [s] at which the extracted pulse starts and ends (inside the record).
    pgv_ratio, energy_ratio : float
        PGV and integral of v^2 of the residual over those of the record.
    """

    period: float
    indicator: float
    amplitude: float
    psv_period: float
    start: float
    end: float
    pgv_ratio: float
    energy_ratio: float
    _times: np.ndarray = field(repr=False)
    _velocity: np.ndarray = field(repr=False)

    @property
    def pulse_like(self) -> bool:
        """Baker's (2007) test on the indicator alone: indicator > 0.85."""
        return self.indicator > PULSE_LIKE_INDICATOR

    def velocity(self, t):
        """Velocity of the extracted pulse [m/s] at times ``t`` [s] (zero outside it)."""
        return np.interp(t, self._times, self._velocity, left=0.0, right=0.0)


def _db4():
    """(psi on its support [0, 7], support length 7) of db4, unit L2 norm."""
    import pywt

    _, psi, x = pywt.Wavelet("db4").wavefun(level=LEVEL)
    return x, psi


def _kernel(scale: float, x, psi):
    """db4 stretched to ``scale`` samples per unit of its support, sampled, unit norm."""
    k = np.arange(int(math.floor(x[-1] * scale)) + 1)
    values = np.interp(k / scale, x, psi)
    norm = math.sqrt(float(values @ values))
    return values / norm if norm > 0.0 else values


def _correlate(v, kernel):
    """C[l] = sum_k v[l + k] kernel[k] for every l with the kernel inside ``v``."""
    from scipy import signal  # imported on use: it costs ~0.6 s (see stochastic.py)

    return signal.fftconvolve(v, kernel[::-1], mode="valid")


def _scales(n: int, dt: float, centre: float):
    """Scales [samples] of the scan: a fixed geometric ladder in samples (so a record slowed
    down is scanned alike: T_p scales with it), those whose pseudo-period s dt / F_c lies in
    PERIOD_RANGE and is no longer than the record."""
    ladder = SMALLEST_SCALE * SCALE_RATIO ** np.arange(int(math.log(n) / math.log(SCALE_RATIO)))
    period = ladder * dt / centre
    keep = (period >= PERIOD_RANGE[0]) & (period <= min(PERIOD_RANGE[1], (n - 1) * dt))
    return ladder[keep]


def _centroid(x, psi) -> float:
    """The centroid of psi^2 on db4's support [units of the support]."""
    weight = psi * psi
    return float((x * weight).sum() / weight.sum())


def _largest(v, scales, x, psi, record):
    """(|C|, scale, position) of the largest |C| over ``scales``, among the positions whose
    wavelet has its centroid inside ``record`` = (first, last) sample of the record in ``v``."""
    best, centre = (-1.0, 0.0, 0), _centroid(x, psi)
    for s in scales:
        c = np.abs(_correlate(v, _kernel(s, x, psi)))
        lo = max(0, int(math.ceil(record[0] - centre * s)))
        hi = min(c.size, int(math.floor(record[1] - centre * s)) + 1)
        if hi <= lo:
            continue
        i = lo + int(np.argmax(c[lo:hi]))
        if c[i] > best[0]:
            best = (float(c[i]), float(s), i)
    return best


def _first_wavelet(v, scales, x, psi, record):
    """(scale, position) of the largest |C|: over the ladder, then on a 20 times finer ladder
    between the best rung's neighbours (the zoom of Shahi & Baker's scan)."""
    _, scale, _ = _largest(v, scales, x, psi, record)
    fine = scale * SCALE_RATIO ** np.linspace(-1.0, 1.0, 41)
    fine = fine[(fine >= scales[0]) & (fine <= scales[-1])]
    _, scale, position = _largest(v, fine, x, psi, record)
    return scale, position


def _extract(v, scale, position, x, psi):
    """The sum of WAVELETS wavelets at ``scale`` near ``position`` (each removed in turn)."""
    kernel = _kernel(scale, x, psi)
    residual = v.copy()
    pulse = np.zeros_like(v)
    reach = int(math.ceil(NEIGHBOURHOOD * scale))
    for _ in range(WAVELETS):
        c = _correlate(residual, kernel)
        lo, hi = max(0, position - reach), min(c.size, position + reach + 1)
        i = lo + int(np.argmax(np.abs(c[lo:hi])))
        piece = c[i] * kernel
        pulse[i : i + kernel.size] += piece
        residual[i : i + kernel.size] -= piece
    return pulse, residual


def extract_wavelet_pulse(t, acc) -> WaveletPulse:
    """The velocity pulse of the record (t [s], acc [m/s^2]); see the module notes.

    A record without motion, or too short to hold the shortest pulse, gets indicator 0,
    amplitude 0 and period NaN.
    """
    import pywt

    grid, v, dt = uniform_samples(t, ground_velocity(t, acc))
    x, psi = _db4()
    centre = pywt.central_frequency("db4")
    scales = _scales(v.size, dt, centre)
    pgv = float(np.max(np.abs(v)))
    if pgv == 0.0 or scales.size == 0:
        empty = np.zeros(0)
        return WaveletPulse(
            math.nan, 0.0, 0.0, math.nan, math.nan, math.nan, 1.0, 1.0, empty, empty
        )
    pad = int(math.ceil(float(x[-1]) * scales[-1] * SCALE_RATIO)) + 1  # the longest wavelet
    padded = np.concatenate([np.zeros(pad), v, np.zeros(pad)])  # ground at rest around it
    scale, position = _first_wavelet(padded, scales, x, psi, (pad, pad + v.size - 1))
    pulse = _extract(padded, scale, position, x, psi)[0][pad : pad + v.size]
    residual = v - pulse
    pgv_ratio = float(np.max(np.abs(residual))) / pgv
    energy_ratio = float(residual @ residual) / float(v @ v)
    inside = np.flatnonzero(pulse)
    pulse_acc = np.gradient(pulse, dt)
    period = scale * dt / centre
    return WaveletPulse(
        period=float(period),
        indicator=baker_indicator(pgv_ratio, energy_ratio),
        amplitude=float(np.max(np.abs(pulse))),
        psv_period=pseudo_velocity_peak_period(grid, pulse_acc, period, DAMPING),
        start=float(grid[inside[0]]),
        end=min(float(grid[inside[-1]]), float(t[-1])),  # the grid's last time, not beyond
        pgv_ratio=pgv_ratio,
        energy_ratio=energy_ratio,
        _times=grid,
        _velocity=pulse,
    )
