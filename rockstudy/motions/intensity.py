"""Intensity measures of a sampled record.

Every function takes the sample times ``t`` [s] and accelerations ``acc`` [m/s^2] of a record.
The registry of measures (:mod:`rockstudy.motions.measures`: units, scaling powers, labels)
names them; :class:`rockstudy.motions.Record` calls them through ``intensity_measures``, which
caches.

Conventions (those of eqsig and of the usual processing; see docs/records.rst):

- Arias intensity, CAV and the Husid curve of the significant duration are the trapezoidal
  rule over the recorded samples (not the integral of the linearly interpolated record, which
  is 4-5 % lower on real records and 2/3 of the truth for a sine at a quarter of the sampling
  rate).
- Velocity and displacement are the exact integrals of the linearly interpolated record (the
  trapezoidal rule for velocity, as eqsig), after the baseline correction below.
- The response spectrum is that of the linearly interpolated record
  (:mod:`rockstudy.motions._spectrum`).

Baseline correction. The ground starts at rest (v = d = 0 at t = 0). Velocity: a constant
acceleration offset c = v(t_end) / t_end is removed (:func:`baseline_offset`), so the ground
is at rest again at the end; nothing else is filtered. Displacement: the double integral of
that record less the least-squares polynomial c2 t^2 + c3 t^3 (:func:`displacement_baseline`:
the polynomial baseline of strong-motion processing, of the lowest degrees that keep
d(0) = d'(0) = 0). A processed (PEER) record's PGD hardly changes (< 0.5 %); an unprocessed
one keeps what a baseline cannot remove: El Centro 1940 (elcentro_NS.dat) gets PGD 0.33 m,
against 1.81 m with the constant offset alone. A permanent displacement (fling) is not
kept in PGD.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import simpson

from .. import _validate
from ..constants import G
from . import _spectrum

__all__ = [
    "arias_intensity",
    "baseline_offset",
    "check_damping",
    "check_periods",
    "cumulative_absolute_velocity",
    "displacement_baseline",
    "ground_displacement",
    "ground_velocity",
    "mean_period",
    "MEAN_PERIOD_BAND",
    "MEAN_PERIOD_DF",
    "MIN_PERIOD",
    "MIN_PHASE_STEP",
    "pseudo_velocity_peak_period",
    "PSV_PEAK_POINTS",
    "PSV_PEAK_SPAN",
    "response_spectrum",
    "response_spectrum_dataset",
    "rigid_limit_displacement",
    "RIGID_LIMIT_RTOL",
    "significant_duration",
    "spectral_displacement",
    "spectrum_intensity",
    "SPECTRUM_INTENSITY_PERIODS",
    "SPECTRUM_INTENSITY_STEP",
    "SPECTRUM_MAX_WORK",
    "SPECTRUM_PHASE_STEP",
    "uniform_samples",
]

#: Band of the mean period [Hz] and the largest frequency step of its spectrum [Hz]
#: (Rathje et al. 2004).
MEAN_PERIOD_BAND = (0.25, 20.0)
MEAN_PERIOD_DF = 0.05
#: Periods of Housner's spectrum intensity [s] (Housner 1952) and the quadrature step [s].
SPECTRUM_INTENSITY_PERIODS = (0.1, 2.5)
SPECTRUM_INTENSITY_STEP = 0.02


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
    """Ground velocity [m/s] at the samples: the exact (trapezoidal) integral of the record
    less the constant c of :func:`baseline_offset`, so that it ends at rest.

    .. math:: v_{i+1} = v_i + h_i (a_i + a_{i+1}) / 2, \\quad a \\to a - c
    """
    a = acc - baseline_offset(t, acc)
    return np.concatenate(([0.0], np.cumsum(0.5 * np.diff(t) * (a[1:] + a[:-1]))))


def _integrated_displacement(t, acc):
    """Exact double integral [m] of the offset-corrected record at the samples.

    .. math:: d_{i+1} = d_i + h_i v_i + h_i^2 (2 a_i + a_{i+1}) / 6
    """
    a = acc - baseline_offset(t, acc)
    h = np.diff(t)
    v = ground_velocity(t, acc)
    inc = h * v[:-1] + h * h * (2.0 * a[:-1] + a[1:]) / 6.0
    return np.concatenate(([0.0], np.cumsum(inc)))


def displacement_baseline(t, acc) -> tuple:
    """(c2 [m/s^2], c3 [m/s^3]): the least-squares fit c2 t^2 + c3 t^3 of the displacement
    of :func:`_integrated_displacement` (a polynomial baseline that keeps d(0) = d'(0) = 0).

    Time is scaled by the duration in the fit (a well-conditioned 2-column system).
    """
    span = float(t[-1] - t[0])
    x = (t - t[0]) / span
    basis = np.stack((x * x, x * x * x), axis=1)
    coef, *_ = np.linalg.lstsq(basis, _integrated_displacement(t, acc), rcond=None)
    return float(coef[0]) / span**2, float(coef[1]) / span**3


def ground_displacement(t, acc):
    """Ground displacement [m] at the samples: the double integral of the offset-corrected
    record less its polynomial baseline (:func:`displacement_baseline`).

    .. math:: d_c(t) = d(t) - c_2 t^2 - c_3 t^3
    """
    c2, c3 = displacement_baseline(t, acc)
    x = t - t[0]
    return _integrated_displacement(t, acc) - c2 * x * x - c3 * x * x * x


def _peak(acc) -> float:
    """max |acc|, the scale by which the quadratic sums below are taken (no overflow)."""
    return float(np.max(np.abs(acc))) if acc.size else 0.0


def _husid_sums(t, acc):
    """Cumulative trapezoidal integral of (a / peak)^2 at the samples [s], and the peak."""
    peak = _peak(acc)
    if peak == 0.0:
        return np.zeros(acc.size), 0.0
    x2 = (acc / peak) ** 2
    return np.concatenate(([0.0], np.cumsum(0.5 * np.diff(t) * (x2[1:] + x2[:-1])))), peak


def arias_intensity(t, acc) -> float:
    """Arias intensity [m/s] (Arias 1970), by the trapezoidal rule over the samples.

    .. math:: I_A = \\frac{\\pi}{2 g} \\sum_i \\frac{h_i}{2} (a_i^2 + a_{i+1}^2)

    g is the physics' :data:`rockstudy.constants.G` (eqsig uses the same 9.81). Computed on
    a / max|a| so that large records do not overflow; raises ValueError when the intensity
    itself exceeds the floating-point range.
    """
    husid, peak = _husid_sums(t, acc)
    value = math.pi / (2.0 * G) * peak * peak * float(husid[-1])
    if not math.isfinite(value):
        raise ValueError(
            f"acceleration: Arias intensity overflows (peak |a| = {peak:.3g} m/s^2); "
            "no ground motion is that strong"
        )
    return value


def cumulative_absolute_velocity(t, acc) -> float:
    """CAV [m/s] = integral of |a| dt, by the trapezoidal rule over the samples (eqsig's).

    .. math:: CAV = \\sum_i \\frac{h_i}{2} (|a_i| + |a_{i+1}|)
    """
    peak = _peak(acc)
    if peak == 0.0:
        return 0.0
    x = np.abs(acc) / peak
    return peak * float(np.sum(0.5 * np.diff(t) * (x[1:] + x[:-1])))


def significant_duration(t, acc, low: float = 0.05, high: float = 0.95) -> float:
    """Significant duration [s]: the time between the ``low`` and ``high`` fractions of the
    Arias intensity (Trifunac & Brady 1975).

    The Husid curve is the trapezoidal Arias integral at the samples (as eqsig), read by linear
    interpolation between them (eqsig reports the sample times just inside the fractions
    instead, 0 to 2 dt shorter). NaN for a record of zeros.
    """
    husid, _ = _husid_sums(t, acc)
    if husid[-1] <= 0.0:
        return math.nan
    husid = husid / husid[-1]
    return float(np.interp(high, husid, t) - np.interp(low, husid, t))


def mean_period(t, acc) -> float:
    """Mean period T_m [s] (Rathje et al. 1998; 2004).

    .. math::
        T_m = \\sum_i C_i^2 / f_i \\Big/ \\sum_i C_i^2, \\quad 0.25 \\le f_i \\le 20 \\text{ Hz}

    C_i are the Fourier amplitudes of the record, zero-padded so that the frequency step is at
    most 0.05 Hz. A record with a non-uniform step is resampled at its median step first.
    NaN if the band holds no energy (a record of zeros); ValueError naming ``dt`` if the
    record's Nyquist frequency 1 / (2 dt) lies below the band, which it then cannot resolve.
    """
    _, a, dt = uniform_samples(t, acc)
    if 0.5 / dt < MEAN_PERIOD_BAND[0]:
        raise ValueError(
            f"dt: the mean period (Rathje et al. 2004) needs frequencies of "
            f"{MEAN_PERIOD_BAND[0]}-{MEAN_PERIOD_BAND[1]} Hz, but a record sampled every "
            f"dt = {dt:.6g} s holds none above {0.5 / dt:.3g} Hz"
        )
    peak = _peak(a)
    if peak > 0.0:
        a = a / peak  # the ratio below is scale-free; this keeps |C|^2 finite
    nfft = 1 << int(math.ceil(math.log2(max(a.size, 1.0 / (MEAN_PERIOD_DF * dt)))))
    c2 = np.abs(np.fft.rfft(a, nfft)) ** 2
    f = np.fft.rfftfreq(nfft, dt)
    band = (f >= MEAN_PERIOD_BAND[0]) & (f <= MEAN_PERIOD_BAND[1])
    total = float(np.sum(c2[band]))
    if total <= 0.0:
        return math.nan
    return float(np.sum(c2[band] / f[band]) / total)


#: Shortest period accepted [s]: below it omega^2 nears the floating-point range; Sa there is
#: the rigid limit (:func:`rigid_limit_displacement`), reached long before.
MIN_PERIOD = 1e-12
#: Smallest omega dt accepted: longer periods lose digits in the recursion's coefficients
#: (1e-5 keeps SD within about 1e-5 of scipy's lsim).
MIN_PHASE_STEP = 1e-5


def check_periods(periods) -> np.ndarray:
    """Periods [s] as a 1-D float array, or ValueError unless every one is finite and
    >= :data:`MIN_PERIOD`."""
    arr = np.atleast_1d(np.asarray(periods, dtype=float))
    if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr < MIN_PERIOD):
        raise ValueError(
            f"periods must be finite numbers >= {MIN_PERIOD} s (Sa below that is the rigid "
            f"limit, reached at far longer periods), got {periods!r}"
        )
    return arr


def _check_long_periods(periods, steps) -> None:
    """ValueError naming ``periods`` where omega dt < :data:`MIN_PHASE_STEP`."""
    longest = 2.0 * math.pi * float(np.min(steps)) / MIN_PHASE_STEP
    if np.any(periods > longest):
        raise ValueError(
            f"periods: T = {float(np.max(periods)):.6g} s is too long for this record's step "
            f"(dt = {float(np.min(steps)):.6g} s); the spectrum is computed up to "
            f"2 pi dt / {MIN_PHASE_STEP} = {longest:.6g} s"
        )


def check_damping(damping) -> float:
    """Damping ratio zeta in [0, 1), or ValueError naming ``damping``."""
    value = _validate.number("damping", damping)
    if not math.isfinite(value) or not 0.0 <= value < 1.0:
        raise ValueError(f"damping must lie in [0, 1), got {damping!r}")
    return value


def spectral_displacement(t, acc, periods, damping: float = 0.05):
    """SD(T, zeta) [m]: peak relative displacement of linear oscillators (Nigam & Jennings 1969).

    The recursion is exact for the piecewise-linear record; peaks between samples and in the
    free vibration after the record are included (see :mod:`rockstudy.motions._spectrum`).
    Where omega dt > :data:`SPECTRUM_PHASE_STEP` each step is split into sub-steps, so no
    oscillation hides inside a step: below about 10 dt, Sa is that of the piecewise-linear
    record, whose corners the recorded samples are. Periods too short for sub-steps
    (:data:`SPECTRUM_MAX_WORK`) take the rigid limit (:func:`rigid_limit_displacement`), which
    is exact there to :data:`RIGID_LIMIT_RTOL`; a period in between is refused.
    """
    periods = check_periods(periods)
    zeta = check_damping(damping)
    out = np.zeros(periods.size)
    if periods.size == 0:
        return out
    steps = kernel_steps(t)
    acc = np.array(acc, dtype=float)
    omegas = 2.0 * math.pi / periods
    substeps, direct = substeps_of(omegas, steps)
    for k in np.unique(substeps[direct]):
        sel = direct & (substeps == k)
        out[sel] = _spectrum.peak_displacements(
            np.array(omegas[sel], dtype=float), float(zeta), steps, acc, int(k)
        )
    for j in np.flatnonzero(~direct):
        out[j] = rigid_limit_displacement(t, acc, periods[j], zeta)
    return out


def kernel_steps(t) -> np.ndarray:
    """The steps [s] of the sample times ``t`` as the spectrum kernels read them (a writable
    C copy: one kernel signature for every input), checked against :data:`MIN_PHASE_STEP`
    by the caller's periods (:func:`_check_long_periods`)."""
    return np.array(_steps(t), dtype=float)


def substeps_of(omegas, steps) -> tuple[np.ndarray, np.ndarray]:
    """(sub-steps per record step, whether the kernel runs them) of oscillators ``omegas``
    [rad/s] over ``steps`` [s]: omega h <= :data:`SPECTRUM_PHASE_STEP` in every sub-step,
    and at most :data:`SPECTRUM_MAX_WORK` sub-steps in all (else the rigid limit). Refuses
    periods too long for the steps (ValueError naming ``periods``)."""
    _check_long_periods(2.0 * math.pi / np.asarray(omegas), steps)
    phase = np.asarray(omegas) * float(np.max(steps))
    substeps = np.ceil(np.maximum(phase, 1e-300) / SPECTRUM_PHASE_STEP)
    return substeps, substeps * steps.size <= SPECTRUM_MAX_WORK


#: Largest omega h [rad] of a (sub-)step of the spectrum kernel.
SPECTRUM_PHASE_STEP = 0.5
#: Most sub-steps (record steps x sub-steps per step) for one period; beyond: the rigid limit.
SPECTRUM_MAX_WORK = 2e8
#: Largest relative error bound accepted from :func:`rigid_limit_displacement`.
RIGID_LIMIT_RTOL = 1e-6


def rigid_limit_displacement(t, acc, period: float, damping: float) -> float:
    """SD [m] of an oscillator much stiffer than the record's steps (omega dt >> 1).

    The oscillator follows the ground quasi-statically, u = -(a - 2 zeta a' / omega) / omega^2,
    plus the free vibration started by the record's first value (the record is zero before
    t = 0), of amplitude |a_0| / omega^2 decaying as exp(-zeta omega t); its first extremum
    overshoots by exp(-zeta pi / sqrt(1 - zeta^2)). So omega^2 SD tends to

    .. math:: \\max\\Big(|a_0| (1 + e^{-\\zeta \\pi / \\sqrt{1-\\zeta^2}}),
              \\max_{i \\ge 1} |a_i| + |a_0| e^{-\\zeta \\omega t_i}\\Big)

    up to the free vibrations that the record's corners start: a slope change Delta s adds at
    most (1 + 2 zeta) |Delta s| / omega_d to omega^2 |u|, summed over corners without damping
    and as a geometric series of ratio exp(-zeta omega h_min) with it, plus 2 zeta max|s| /
    omega. ValueError naming ``periods`` if that bound exceeds :data:`RIGID_LIMIT_RTOL` of
    the limit.
    """
    omega = 2.0 * math.pi / period
    h = np.diff(t)
    slopes = np.diff(acc) / h
    kinks = np.abs(np.diff(np.concatenate(([0.0], slopes, [0.0]))))
    root = math.sqrt(1.0 - damping * damping)
    if damping > 0.0:
        spread = float(np.max(kinks)) / -math.expm1(-damping * omega * float(np.min(h)))
    else:
        spread = float(np.sum(kinks))
    a0 = abs(float(acc[0]))
    decay = np.exp(-damping * omega * (t[1:] - t[0]))
    limit = max(
        a0 * (1.0 + math.exp(-damping * math.pi / root)),
        float(np.max(np.abs(acc[1:]) + a0 * decay)),
    )
    bound = (
        (1.0 + 2.0 * damping) / root * spread + 2.0 * damping * float(np.max(np.abs(slopes)))
    ) / omega
    if bound > RIGID_LIMIT_RTOL * limit:
        dt = float(np.max(h))
        reach = 2.0 * math.pi * dt * t.size / (SPECTRUM_PHASE_STEP * SPECTRUM_MAX_WORK)
        raise ValueError(
            f"periods: T = {period:.6g} s is too short to sub-step this record (dt = {dt:.6g} "
            f"s) and not short enough for the rigid limit (error bound {bound / limit:.2g}); "
            f"ask for T >= {reach:.3g} s, or a shorter one"
        )
    return limit / (omega * omega)


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
                {"units": "m/s^2", "long_name": "pseudo-acceleration"},
            ),
            "psv": ("period", w * sd, {"units": "m/s", "long_name": "pseudo-velocity"}),
            "sd": ("period", sd, {"units": "m", "long_name": "spectral displacement"}),
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


#: Span around the guess [x guess] and grid of :func:`pseudo_velocity_peak_period`.
PSV_PEAK_SPAN = (0.25, 4.0)
PSV_PEAK_POINTS = 121


def pseudo_velocity_peak_period(t, acc, guess: float, damping: float = 0.05) -> float:
    """The period [s] of the peak of PSV(T) = omega SD(T) within [0.25, 4] x ``guess`` [s]
    (and below the longest period the spectrum computes): the best of a geometric grid of 121
    periods, refined by a bounded scalar search between its neighbours (to 1e-4 relative)."""
    from scipy.optimize import minimize_scalar

    longest = 0.99 * 2.0 * math.pi * float(np.min(np.diff(t))) / MIN_PHASE_STEP
    hi = min(PSV_PEAK_SPAN[1] * guess, longest)
    periods = np.geomspace(min(PSV_PEAK_SPAN[0] * guess, hi), hi, PSV_PEAK_POINTS)
    psv = 2.0 * math.pi / periods * spectral_displacement(t, acc, periods, damping)
    i = int(np.argmax(psv))
    lo, hi = periods[max(i - 1, 0)], periods[min(i + 1, periods.size - 1)]

    def minus_psv(period):
        return -2.0 * math.pi / period * spectral_displacement(t, acc, [period], damping)[0]

    res = minimize_scalar(
        minus_psv, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4 * lo}
    )
    return float(res.x) if -res.fun >= psv[i] else float(periods[i])
