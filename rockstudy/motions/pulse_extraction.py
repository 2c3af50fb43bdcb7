"""The dominant velocity pulse of a record: a least-squares fit of the Mavroeidis-Papageorgiou
(2003) pulse to the ground velocity, with the pulse indicator of Baker (2007).

This is ``Record.pulse(method="mavroeidis")``; the default is the wavelet method of Baker
(2007) and Shahi & Baker (2014), :mod:`rockstudy.motions.wavelet_pulse`, whose T_p is the
field's. The M-P period of a pulse is about 10-15 % off that T_p (e.g. the shipped records).

Method
------
1. Scan: for every (T_p, gamma) of a grid, the pulse is linear in (A cos nu, A sin nu), so its
   best amplitude and phase at every centre t_0 follow from two cross-correlations of the
   velocity with the windowed cosine and sine (a matched filter, like Baker's wavelet scan).
   The scan keeps the (T_p, gamma, t_0) that explains the most velocity energy.
2. Refine: :func:`scipy.optimize.least_squares` on all five parameters from the best scan
   points.
3. Indicator (Baker 2007, his logistic predictor): with the residual velocity r = v - v_pulse,

   .. math:: PI = 1 / \\left(1 + e^{-23.3 + 14.6 \\, PGV_r / PGV + 20.5 \\, E_r / E}\\right)

   where E is the cumulative squared velocity. Baker calls a record pulse-like above 0.85 (and
   with an early, strong pulse). His coefficients were fitted to wavelet-extracted pulses; here
   they are applied to the fitted M-P pulse, whose five free parameters capture more of the
   velocity than one wavelet: a record whose velocity is one long, clean oscillation (e.g.
   unprocessed noise dominated by its lowest frequencies) scores high.

What the fit is for: the M-P parameters (T_p, A, gamma, nu, t_0) are the ones that the
synthetic records (:func:`rockstudy.motions.synthetic_near_fault`) are made with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import fft, optimize

from .intensity import ground_velocity, uniform_samples
from .mavroeidis import mp_pulse_velocity

__all__ = [
    "baker_indicator",
    "extract_pulse",
    "GAMMA_BOUNDS",
    "OUTSIDE",
    "PULSE_LIKE_INDICATOR",
    "SCAN_GAMMAS",
    "SCAN_PERIODS",
    "SCAN_SAMPLES",
    "VelocityPulse",
]

#: Grid of the scan: number of periods and the values of gamma.
SCAN_PERIODS = 40
SCAN_GAMMAS = (1.2, 1.6, 2.0, 2.5, 3.0)
#: Samples per period of the scan's block-averaged velocity.
SCAN_SAMPLES = 24
GAMMA_BOUNDS = (1.0, 5.0)
#: Baker (2007): the pulse indicator above which a record is pulse-like.
PULSE_LIKE_INDICATOR = 0.85
#: A fitted pulse that reaches more than this many periods outside the record is not a pulse
#: (indicator 0): white noise was fitted a 1325 s pulse starting at -196 s.
OUTSIDE = 0.5


@dataclass(frozen=True)
class VelocityPulse:
    """The dominant velocity pulse of a record (Mavroeidis-Papageorgiou 2003 parameters).

    Attributes
    ----------
    period : float
        T_p [s].
    amplitude : float
        A [m/s] (> 0; the sign is in ``phase``).
    indicator : float
        Baker's (2007) pulse indicator in [0, 1].
    start : float
        t_0 - gamma T_p / 2 [s], when the pulse begins. A fit whose pulse reaches more than
        half a period outside the record gets indicator 0: it is not a pulse of the record.
    gamma : float
        Oscillations under the envelope.
    phase : float
        nu [rad] in [0, 2 pi).
    center : float
        t_0 [s].
    pgv_ratio, energy_ratio : float
        PGV and cumulative squared velocity of the residual over those of the record.
    """

    period: float
    amplitude: float
    indicator: float
    start: float
    gamma: float
    phase: float
    center: float
    pgv_ratio: float
    energy_ratio: float

    @property
    def pulse_like(self) -> bool:
        """Baker's (2007) test on the indicator alone: indicator > 0.85."""
        return self.indicator > PULSE_LIKE_INDICATOR

    def velocity(self, t):
        """Velocity of the pulse [m/s] at times ``t`` [s] (measured like the record's)."""
        return mp_pulse_velocity(
            t, self.amplitude, self.period, self.gamma, self.phase, self.center
        )


def baker_indicator(pgv_ratio: float, energy_ratio: float) -> float:
    """Baker's (2007) pulse indicator: 1 / (1 + exp(-23.3 + 14.6 PGV_r + 20.5 E_r))."""
    z = -23.3 + 14.6 * pgv_ratio + 20.5 * energy_ratio
    return 1.0 / (1.0 + math.exp(min(z, 700.0)))


def _block_means(grid, v, q):
    """v averaged over blocks of q samples (an anti-aliased decimation) and the block centres."""
    m = v.size // q
    return grid[: m * q : q] + 0.5 * (q - 1) * (grid[1] - grid[0]), v[: m * q].reshape(m, q).mean(1)


def _scan(grid, v, dt):
    """Best (energy, period, gamma, center, amplitude, phase) of the matched-filter scan.

    Each period is scanned on the velocity block-averaged to about period / SCAN_SAMPLES.
    """
    span = grid[-1] - grid[0]
    periods = np.geomspace(max(8.0 * dt, 0.05), max(span / 1.5, 16.0 * dt), SCAN_PERIODS)
    best = (-1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for period in periods:
        q = max(1, int(period / (SCAN_SAMPLES * dt)))
        tq, vq = _block_means(grid, v, q) if q > 1 else (grid, v)
        step = q * dt
        half_max = int(math.ceil(0.5 * max(SCAN_GAMMAS) * period / step))
        nfft = fft.next_fast_len(vq.size + 2 * half_max)
        spectrum = fft.fft(vq, nfft)
        for gamma in SCAN_GAMMAS:
            half = int(math.ceil(0.5 * gamma * period / step))
            tau = step * np.arange(-half, half + 1)
            x = 2.0 * math.pi * tau / period
            env = 0.5 * (1.0 + np.cos(x / gamma)) * (np.abs(tau) <= 0.5 * gamma * period)
            kc, ks = env * np.cos(x), env * np.sin(x)
            # kc is even and ks odd: correlating with them is convolving with kc and -ks
            conv = fft.ifft(spectrum * fft.fft(kc + 1j * ks, nfft))[half : half + vq.size]
            cc, cs = conv.real, -conv.imag
            g11, g12, g22 = kc @ kc, kc @ ks, ks @ ks
            det = g11 * g22 - g12 * g12
            a_cos = (g22 * cc - g12 * cs) / det
            a_sin = (g11 * cs - g12 * cc) / det
            energy = (a_cos * cc + a_sin * cs) * q
            i = int(np.argmax(energy))
            if energy[i] > best[0]:
                phase = math.atan2(-a_sin[i], a_cos[i])
                best = (energy[i], period, gamma, tq[i], math.hypot(a_cos[i], a_sin[i]), phase)
    return best


def _refine(t, v, start):
    """Least-squares fit of the five pulse parameters from ``start`` = (A, T_p, gamma, nu, t_0)."""
    span = t[-1] - t[0]
    dt_min = float(np.min(np.diff(t)))
    # the pulse lies in the record: its centre inside it, its period no longer than it
    lower = [0.0, 4.0 * dt_min, GAMMA_BOUNDS[0], start[3] - 2 * math.pi, t[0]]
    upper = [np.inf, span, GAMMA_BOUNDS[1], start[3] + 2 * math.pi, t[-1]]
    x0 = np.clip(start, np.array(lower) + 1e-12, np.array(upper) - 1e-12)

    def residual(x):
        return mp_pulse_velocity(t, *x) - v

    return optimize.least_squares(residual, x0, bounds=(lower, upper), x_scale="jac").x


def extract_pulse(t, acc) -> VelocityPulse:
    """The dominant velocity pulse of the record (t [s], acc [m/s^2]); see the module notes.

    Returns a pulse of amplitude 0 and indicator 0 for a record without motion.
    """
    v = ground_velocity(t, acc)
    energy = float(v @ v)
    if energy == 0.0:
        return VelocityPulse(math.nan, 0.0, 0.0, math.nan, math.nan, 0.0, math.nan, 1.0, 1.0)
    grid, vg, dt = uniform_samples(t, v)
    _, period, gamma, center, amplitude, phase = _scan(grid, vg, dt)
    amplitude, period, gamma, phase, center = _refine(
        t, v, np.array([amplitude, period, gamma, phase, center])
    )
    residual = v - mp_pulse_velocity(t, amplitude, period, gamma, phase, center)
    pgv_ratio = float(np.max(np.abs(residual)) / np.max(np.abs(v)))
    energy_ratio = float(_csv(t, residual) / _csv(t, v))
    half = 0.5 * gamma * period
    outside = center - half < t[0] - OUTSIDE * period or center + half > t[-1] + OUTSIDE * period
    return VelocityPulse(
        period=float(period),
        amplitude=float(amplitude),
        indicator=0.0 if outside else baker_indicator(pgv_ratio, energy_ratio),
        start=float(center - 0.5 * gamma * period),
        gamma=float(gamma),
        phase=float(phase % (2.0 * math.pi)),
        center=float(center),
        pgv_ratio=pgv_ratio,
        energy_ratio=energy_ratio,
    )


def _csv(t, v) -> float:
    """Cumulative squared velocity at the end of the record [m^2/s] (trapezoidal)."""
    return float(np.sum(0.5 * np.diff(t) * (v[1:] ** 2 + v[:-1] ** 2)))
