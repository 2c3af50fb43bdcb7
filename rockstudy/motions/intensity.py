"""Intensity measures of a sampled record, read as the linear interpolation of its samples.

Every function takes the sample times ``t`` [s] and accelerations ``acc`` [m/s^2] of a record
and integrates the piecewise-linear acceleration exactly (except where stated).
:class:`rockstudy.motions.Record` calls them through ``intensity_measures``, which caches.

Baseline correction: the ground starts at rest (v = d = 0 at t = 0), and ground velocity must
return to zero at the end of the record. A constant acceleration offset c = v(t_end) / t_end
is removed before integration (so velocity loses the line c t and displacement c t^2 / 2);
nothing else is filtered. A permanent displacement (fling) is kept.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import simpson

from ..constants import G
from . import _spectrum

#: Band of the mean period [Hz] and the largest frequency step of its spectrum [Hz]
#: (Rathje et al. 2004).
MEAN_PERIOD_BAND = (0.25, 20.0)
MEAN_PERIOD_DF = 0.05
#: Periods of Housner's spectrum intensity [s] (Housner 1952) and the quadrature step [s].
SPECTRUM_INTENSITY_PERIODS = (0.1, 2.5)
SPECTRUM_INTENSITY_STEP = 0.02

#: name -> unit of each scalar measure; ``sa``, ``psv`` and ``sd`` also take a period.
UNITS = {
    "pga": "m/s^2",
    "pgv": "m/s",
    "pgd": "m",
    "arias": "m/s",
    "cav": "m/s",
    "significant_duration": "s",
    "mean_period": "s",
    "spectrum_intensity": "m",
    "sa": "m/s^2",
    "psv": "m/s",
    "sd": "m",
}
SPECTRAL = ("sa", "psv", "sd")
#: name -> power k with which each measure of :data:`UNITS` follows a scale factor s of the
#: record: IM(s a_g) = |s|^k IM(a_g). Amplitudes, spectral values, CAV and spectrum intensity
#: are linear in the record (k = 1); Arias intensity, an integral of a_g^2, goes as s^2;
#: durations and periods do not change (k = 0). The one place every reader takes it from.
SCALING_POWER = {
    "pga": 1,
    "pgv": 1,
    "pgd": 1,
    "arias": 2,
    "cav": 1,
    "significant_duration": 0,
    "mean_period": 0,
    "spectrum_intensity": 1,
    "sa": 1,
    "psv": 1,
    "sd": 1,
}


def _steps(t):
    """Sample steps [s]; exactly equal values where the record is uniform (kernel reuse)."""
    h = np.diff(t)
    mean = (t[-1] - t[0]) / (t.size - 1)
    if np.all(np.abs(h - mean) <= 1e-9 * mean):
        return np.full(h.size, mean)
    return h


def uniform_samples(t, values):
    """(grid, values on it, dt): the record on a uniform grid of its median step [s].

    The samples themselves where the record is uniform; else the linear interpolation.
    """
    dt = float(np.median(np.diff(t)))
    grid = t[0] + dt * np.arange(int(math.floor((t[-1] - t[0]) / dt + 1e-9)) + 1)
    if grid.size == t.size and np.allclose(grid, t, rtol=0.0, atol=1e-9 * dt):
        return grid, values, dt
    return grid, np.interp(grid, t, values), dt


def baseline_offset(t, acc) -> float:
    """c [m/s^2]: the constant acceleration whose removal brings v(t_end) back to zero."""
    v_end = float(np.sum(0.5 * np.diff(t) * (acc[1:] + acc[:-1])))
    return v_end / float(t[-1] - t[0])


def ground_velocity(t, acc):
    """Ground velocity [m/s] at the samples: exact integral of the corrected record.

    .. math:: v_{i+1} = v_i + h_i (a_i + a_{i+1}) / 2, \\quad a \\to a - c
    """
    a = acc - baseline_offset(t, acc)
    return np.concatenate(([0.0], np.cumsum(0.5 * np.diff(t) * (a[1:] + a[:-1]))))


def ground_displacement(t, acc):
    """Ground displacement [m] at the samples: exact double integral of the corrected record.

    .. math:: d_{i+1} = d_i + h_i v_i + h_i^2 (2 a_i + a_{i+1}) / 6
    """
    a = acc - baseline_offset(t, acc)
    h = np.diff(t)
    v = ground_velocity(t, acc)
    inc = h * v[:-1] + h * h * (2.0 * a[:-1] + a[1:]) / 6.0
    return np.concatenate(([0.0], np.cumsum(inc)))


def _husid_increments(t, acc):
    """Exact integral of a^2 over each step [m^2/s^3]: h (a_i^2 + a_i a_{i+1} + a_{i+1}^2) / 3."""
    a0, a1 = acc[:-1], acc[1:]
    return np.diff(t) * (a0 * a0 + a0 * a1 + a1 * a1) / 3.0


def arias_intensity(t, acc) -> float:
    """Arias intensity [m/s] (Arias 1970).

    .. math:: I_A = \\frac{\\pi}{2 g} \\int a^2 \\, dt
    """
    return math.pi / (2.0 * G) * float(np.sum(_husid_increments(t, acc)))


def cumulative_absolute_velocity(t, acc) -> float:
    """CAV [m/s] = integral of |a| dt, exact for the piecewise-linear record.

    On a step where the sign changes, the integral is
    h (a_i^2 + a_{i+1}^2) / (2 (|a_i| + |a_{i+1}|)).
    """
    a0, a1 = np.abs(acc[:-1]), np.abs(acc[1:])
    h = np.diff(t)
    same = acc[:-1] * acc[1:] >= 0.0
    total = a0 + a1
    crossing = np.divide(a0 * a0 + a1 * a1, total, out=np.zeros_like(total), where=total > 0)
    return float(np.sum(np.where(same, 0.5 * h * total, 0.5 * h * crossing)))


def significant_duration(t, acc, low: float = 0.05, high: float = 0.95) -> float:
    """Significant duration [s]: the time between the ``low`` and ``high`` fractions of the
    Arias intensity (Trifunac & Brady 1975).

    The Husid curve is exact at the samples and interpolated linearly between them. NaN for a
    record of zeros.
    """
    husid = np.concatenate(([0.0], np.cumsum(_husid_increments(t, acc))))
    if husid[-1] <= 0.0:
        return math.nan
    husid /= husid[-1]
    return float(np.interp(high, husid, t) - np.interp(low, husid, t))


def mean_period(t, acc) -> float:
    """Mean period T_m [s] (Rathje et al. 1998; 2004).

    .. math::
        T_m = \\sum_i C_i^2 / f_i \\Big/ \\sum_i C_i^2, \\quad 0.25 \\le f_i \\le 20 \\text{ Hz}

    C_i are the Fourier amplitudes of the record, zero-padded so that the frequency step is at
    most 0.05 Hz. A record with a non-uniform step is resampled at its median step first.
    NaN if the band holds no energy.
    """
    _, a, dt = uniform_samples(t, acc)
    nfft = 1 << int(math.ceil(math.log2(max(a.size, 1.0 / (MEAN_PERIOD_DF * dt)))))
    c2 = np.abs(np.fft.rfft(a, nfft)) ** 2
    f = np.fft.rfftfreq(nfft, dt)
    band = (f >= MEAN_PERIOD_BAND[0]) & (f <= MEAN_PERIOD_BAND[1])
    total = float(np.sum(c2[band]))
    if total <= 0.0:
        return math.nan
    return float(np.sum(c2[band] / f[band]) / total)


def check_periods(periods) -> np.ndarray:
    """Periods [s] as a 1-D float array, or ValueError unless every one is finite and > 0."""
    arr = np.atleast_1d(np.asarray(periods, dtype=float))
    if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise ValueError(f"periods must be finite numbers > 0 [s], got {periods!r}")
    return arr


def check_damping(damping) -> float:
    """Damping ratio zeta in [0, 1), or ValueError."""
    value = float(damping)
    if not math.isfinite(value) or not 0.0 <= value < 1.0:
        raise ValueError(f"damping must lie in [0, 1), got {damping!r}")
    return value


def spectral_displacement(t, acc, periods, damping: float = 0.05):
    """SD(T, zeta) [m]: peak relative displacement of linear oscillators (Nigam & Jennings 1969).

    The recursion is exact for the piecewise-linear record; peaks between samples and in the
    free vibration after the record are included (see :mod:`rockstudy.motions._spectrum`).
    """
    periods = check_periods(periods)
    zeta = check_damping(damping)
    if periods.size == 0:
        return np.zeros(0)
    omegas = 2.0 * math.pi / periods
    return _spectrum.peak_displacements(omegas, zeta, _steps(t), np.ascontiguousarray(acc))


def response_spectrum(t, acc, periods, damping: float = 0.05):
    """Elastic response spectrum: ``sd`` [m], ``psv`` = omega SD [m/s], ``sa`` = omega^2 SD [m/s^2].

    Parameters
    ----------
    periods : array_like
        Oscillator periods T [s], > 0.
    damping : float
        Damping ratio zeta in [0, 1).
    """
    periods = check_periods(periods)
    sd = spectral_displacement(t, acc, periods, damping)
    return response_spectrum_dataset(periods, sd, check_damping(damping))


def response_spectrum_dataset(periods, sd, damping: float):
    """The :class:`xarray.Dataset` of :func:`response_spectrum` from SD [m] at ``periods`` [s].

    xarray is imported here, so that importing rockstudy does not pay for it.
    """
    import xarray as xr

    w = 2.0 * math.pi / periods
    coords = {"period": ("period", periods, {"units": "s"})}
    return xr.Dataset(
        {
            "sa": (
                "period",
                w * w * sd,
                {"units": UNITS["sa"], "long_name": "pseudo-acceleration"},
            ),
            "psv": ("period", w * sd, {"units": UNITS["psv"], "long_name": "pseudo-velocity"}),
            "sd": ("period", sd, {"units": UNITS["sd"], "long_name": "spectral displacement"}),
        },
        coords=coords,
        attrs={"damping": damping},
    )


def spectrum_intensity(t, acc, damping: float = 0.05) -> float:
    """Housner's spectrum intensity [m] (Housner 1952).

    .. math:: SI = \\int_{0.1}^{2.5} PSV(T, \\zeta) \\, dT

    Simpson's rule on a 0.02 s grid of periods. Housner used zeta = 0.2; the default here is the
    0.05 of the rest of the measures.
    """
    lo, hi = SPECTRUM_INTENSITY_PERIODS
    periods = np.linspace(lo, hi, int(round((hi - lo) / SPECTRUM_INTENSITY_STEP)) + 1)
    psv = 2.0 * math.pi / periods * spectral_displacement(t, acc, periods, damping)
    return float(simpson(psv, x=periods))
