"""Seeded near-fault records: a Mavroeidis-Papageorgiou velocity pulse plus stochastic
high-frequency motion, with an optional vertical component. They need no download.
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate
from ..constants import G
from .mavroeidis import mp_pulse_acceleration
from .records import Record
from .stochastic import stochastic_record

__all__ = ["HIGH_PASS_ORDER", "MAX_GAMMA", "PULSE_PERIOD_RANGE", "synthetic_near_fault"]

#: Order of the Butterworth high-pass that keeps the stochastic part out of the pulse's band.
HIGH_PASS_ORDER = 4
#: Pulse periods T_p [s] taken: near-fault velocity pulses last 0.3 to about 15 s (the
#: longest recorded); 1e-3 to 100 s covers them with margin. T_p = 1e6 s made a record of
#: 1.2e9 points (8 GB, over a minute).
PULSE_PERIOD_RANGE = (1e-3, 100.0)
#: Largest envelope parameter gamma (M-P 2003 fit 1 to about 5; the record holds 1.5 gamma
#: T_p).
MAX_GAMMA = 100.0
#: Float arrays of the record's length held at once (noise, its filtered copy, envelope,
#: times, pulse, vertical and the filter's work arrays).
_ARRAYS = 10


def _high_frequency(peak, duration, dt, corner, seed, ground_frequency):
    """Kanai-Tajimi noise (see :func:`stochastic_record`) high-passed above ``corner`` [Hz]."""
    rec = stochastic_record(
        1.0, duration=duration, dt=dt, ground_frequency=ground_frequency, seed=seed
    )
    from scipy import signal  # imported on use: it costs ~0.6 s (see stochastic.py)

    sos = signal.butter(HIGH_PASS_ORDER, corner, "highpass", fs=1.0 / dt, output="sos")
    acc = signal.sosfiltfilt(sos, rec.acceleration)
    return acc * (peak / np.max(np.abs(acc)))


def synthetic_near_fault(
    pulse_period: float,
    pga: float,
    seed: int = 0,
    vertical: bool = False,
    gamma: float = 2.0,
    phase: float = 0.0,
    noise_ratio: float = 1.0,
    vertical_ratio: float = 2.0 / 3.0,
    duration: float | None = None,
    dt: float = 0.005,
) -> Record:
    """A near-fault record: Mavroeidis-Papageorgiou (2003) pulse + high-passed stochastic motion.

    The pulse (M-P 2003, centred at 0.35 of the duration) carries the velocity; the
    stochastic part (Kanai-Tajimi noise under a Jennings envelope, reused from
    :func:`stochastic_record`, high-passed by a 4th-order Butterworth filter at 2 / T_p so that
    it stays out of the pulse's band) carries the high-frequency acceleration. Its peak is
    ``noise_ratio`` times the pulse's peak acceleration; the sum is then scaled to ``pga``.
    The vertical component (no pulse; Kanai-Tajimi at twice the horizontal ground frequency,
    from an independent seed stream) has a peak of ``vertical_ratio * pga``.

    Parameters
    ----------
    pulse_period : float
        T_p [s] > 0.
    pga : float
        Peak horizontal ground acceleration [m/s^2] > 0.
    seed : int
        The same seed gives the same record.
    vertical : bool
        Also make a vertical component.
    gamma, phase : float
        Pulse envelope gamma (> 1) and phase nu [rad].
    noise_ratio : float
        Peak of the stochastic part over the peak of the pulse's acceleration (>= 0).
    vertical_ratio : float
        Peak vertical over peak horizontal acceleration; ``vertical_ratio * pga`` must be < g.
    duration : float, optional
        Length [s]; default max(20, 6 T_p).
    dt : float
        Time step [s]; must resolve the pulse (dt < T_p / 20).
    """
    period = _validate.in_range(
        "pulse_period",
        pulse_period,
        *PULSE_PERIOD_RANGE,
        "[{:g}, {:g}] s".format(*PULSE_PERIOD_RANGE),
    )
    top = _validate.MAX_ACCELERATION
    pga = _validate.in_range("pga", pga, 0.0, top, f"(0, {top:.0e}] m/s^2")
    if pga == 0.0:
        raise ValueError("pga must be > 0 [m/s^2], got 0.0")
    dt = _validate.in_range("dt", dt, _validate.MIN_STEP, 1.0, f"[{_validate.MIN_STEP:g}, 1] s")
    if not dt < period / 20.0:
        raise ValueError(f"dt must be < pulse_period / 20 = {period / 20.0!r} s, got {dt!r}")
    gamma = _validate.in_range("gamma", gamma, 1.0, MAX_GAMMA, f"(1, {MAX_GAMMA:g}]")
    if gamma == 1.0:
        raise ValueError("gamma must be > 1, got 1.0")
    phase = _validate.in_range("phase", phase, -1e3, 1e3, "[-1000, 1000] rad")
    noise_ratio = _validate.in_range("noise_ratio", noise_ratio, 0.0, 1e3, "[0, 1000]")
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a whole number >= 0, got {seed!r}")
    if not isinstance(vertical, (bool, np.bool_)):
        raise ValueError(f"vertical must be True or False, got {vertical!r}")
    if duration is None:
        duration = max(20.0, 6.0 * period)
    duration = _validate.in_range(
        "duration", duration, 0.0, _validate.MAX_DURATION, f"[0, {_validate.MAX_DURATION:g}] s"
    )
    if not duration >= 1.5 * gamma * period:
        raise ValueError(
            f"duration must hold the pulse: >= 1.5 gamma pulse_period = "
            f"{1.5 * gamma * period!r} s, got {duration!r}"
        )
    points = duration / dt + 1.0
    _validate.check_memory(
        "duration",
        8.0 * _ARRAYS * points,
        f"{duration:g} s at dt = {dt:g} s is a record of {points:.4g} points",
        "shorten duration or coarsen dt",
    )
    if vertical:
        vertical_ratio = _validate.positive("vertical_ratio", vertical_ratio)
        if not vertical_ratio * pga < G:
            raise ValueError(
                f"vertical_ratio * pga = {vertical_ratio * pga!r} m/s^2 must be < g: "
                "the ground would pull away from the structure"
            )
    seq_h, seq_v = np.random.SeedSequence(seed).spawn(2)
    n = int(round(duration / dt)) + 1
    t = dt * np.arange(n)
    acc = mp_pulse_acceleration(t, 1.0, period, gamma, phase, 0.35 * duration)
    if noise_ratio > 0.0:
        acc = acc + _high_frequency(
            noise_ratio * np.max(np.abs(acc)), t[-1], dt, 2.0 / period, seq_h, 5.0 * math.pi
        )
    acc *= pga / np.max(np.abs(acc))
    vert = None
    if vertical:
        vert = stochastic_record(
            vertical_ratio * pga, duration=t[-1], dt=dt, ground_frequency=10.0 * math.pi, seed=seq_v
        ).acceleration
    name = f"near-fault(Tp={period:g}s, pga={pga:g}, seed={seed})"
    return Record(acc, dt=dt, name=name, vertical=vert)
