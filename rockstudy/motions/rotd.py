"""Orientation-independent measures of a pair of horizontal components: RotD50 and RotD100.

The motion along the direction at angle psi from the x component towards y is
a_psi(t) = a_x(t) cos(psi) + a_y(t) sin(psi). A measure of one component (PGA, Sa(T)) taken
along every psi of :data:`ANGLES` gives one peak per angle; RotD100 is the largest of them and
RotD50 their median (Boore 2010), as pyrotd computes them: 180 angles, 0 to 179 degrees in
steps of 1 degree (psi and psi + pi have the same peaks), and the median of the 180 peaks
the mean of the two middle ones (``numpy.percentile``'s linear rule at 50 %).

The peaks are exact for the piecewise-linear record: PGA's along psi is at a sample, and
Sa's is the peak of the oscillator under a_psi by the exact recursion of the spectrum
(:func:`rockstudy.motions.intensity.spectral_displacement`, peaks between samples and in the
free vibration included); only the angles are a grid (at 1 degree, RotD100 is below the
largest peak over every angle by at most 1 - cos(0.5 degree) = 4e-5).
"""

from __future__ import annotations

import math

import numpy as np

from . import _rotd_kernel, intensity

__all__ = ["ANGLES", "rotated_peaks", "rotd", "require_pair"]

#: The orientations psi [rad] of the RotD measures: 0, 1, ..., 179 degrees (pyrotd's).
ANGLES = np.radians(np.arange(180.0))

#: The percentile of each RotD measure.
PERCENTILES = {"rotd50": 50.0, "rotd100": 100.0}


def require_pair(record, measure: str) -> None:
    """A ValueError naming ``measure`` unless ``record`` carries two horizontal components."""
    if getattr(record, "acceleration_y", None) is None:
        raise ValueError(
            f"the measure {measure!r} is of a pair of horizontal components; the record "
            f"{getattr(record, 'name', '')!r} has one (give its acceleration_y, e.g. "
            "Record.from_at2(h1, h2=...) or load_suite(..., h2=...))"
        )


def _peak_accelerations(record) -> np.ndarray:
    """max_t |a_psi(t)| [m/s^2] at each angle of :data:`ANGLES` (the peak of a
    piecewise-linear history is at a sample)."""
    ax, ay = record.acceleration, record.acceleration_y
    return np.array([np.max(np.abs(math.cos(p) * ax + math.sin(p) * ay)) for p in ANGLES])


def _peak_pseudo_accelerations(record, period: float, damping: float) -> np.ndarray:
    """Sa(T, zeta) = omega^2 SD [m/s^2] of a_psi at each angle of :data:`ANGLES`: the two
    components' oscillator states combined per angle (:mod:`._rotd_kernel`), or, where
    their histories would not fit in :data:`MAX_STATES` sub-steps (the rigid limit too),
    the spectrum of each a_psi in turn."""
    ax, ay = record.acceleration, record.acceleration_y
    omega = 2.0 * math.pi / period
    steps = intensity.kernel_steps(record.time)
    substeps, direct = intensity.substeps_of([omega], steps)
    if direct[0] and substeps[0] * steps.size <= MAX_STATES:
        h, fx, fy, state = _rotd_kernel.state_histories(
            omega, damping, steps, np.array(ax), np.array(ay), int(substeps[0])
        )
        sd = _rotd_kernel.rotated_peak_displacements(
            omega, damping, h, fx, fy, state, np.cos(ANGLES), np.sin(ANGLES)
        )
        return omega**2 * sd
    along = (math.cos(p) * ax + math.sin(p) * ay for p in ANGLES)
    return omega**2 * np.array(
        [intensity.spectral_displacement(record.time, a, [period], damping)[0] for a in along]
    )


#: Most sub-steps whose oscillator states the rotated spectrum holds at once (7 arrays of
#: floats: 112 MB).
MAX_STATES = 2_000_000


def rotated_peaks(record, measure: str = "pga", period=None, damping: float = 0.05):
    """The peak of ``measure`` (``"pga"`` or ``"sa"``) along each angle of :data:`ANGLES`
    [m/s^2], cached on the record (a :class:`~rockstudy.motions.Record` with two horizontal
    components, :func:`require_pair`); ``period`` [s] and ``damping`` for ``"sa"``."""
    if measure == "pga":
        return record._cached(("rotated", "pga"), lambda: _peak_accelerations(record))
    period = float(intensity.check_periods(period)[0])
    damping = intensity.check_damping(damping)
    key = ("rotated", "sa", period, damping)
    return record._cached(key, lambda: _peak_pseudo_accelerations(record, period, damping))


def rotd(peaks, which: str) -> float:
    """RotD50 (the median) or RotD100 (the largest) of the peaks along the angles."""
    return float(np.percentile(peaks, PERCENTILES[which], method="linear"))


def pga_rotd(which: str):
    """The measure function of ``pga_rotd50`` or ``pga_rotd100``."""

    def function(record):
        require_pair(record, f"pga_{which}")
        return rotd(rotated_peaks(record, "pga"), which)

    return function


def sa_rotd(which: str):
    """The measure function of ``sa_rotd50`` or ``sa_rotd100`` (period [s], damping)."""

    def function(record, period, damping):
        require_pair(record, f"sa_{which}")
        return rotd(rotated_peaks(record, "sa", period, damping), which)

    return function
