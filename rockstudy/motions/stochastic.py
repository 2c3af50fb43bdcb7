"""Seeded stochastic ground motions: Kanai-Tajimi filtered white noise under a time envelope.

``scipy.signal`` is imported where it is used: importing it costs about 0.6 s (it pulls in
``scipy.stats``), which every ``import rockstudy`` paid before.
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate
from .records import Record

__all__ = ["envelope_jennings", "kanai_tajimi_filter", "stochastic_record"]


def envelope_jennings(t, rise: float, plateau_end: float, decay: float):
    r"""Jennings-Housner-Tsai trapezoidal intensity envelope [-].

    .. math::
        e(t) = (t/t_1)^2 \; (t < t_1), \quad 1 \; (t_1 \le t \le t_2), \quad
        e^{-c (t - t_2)} \; (t > t_2)

    Parameters
    ----------
    t : array_like
        Time [s].
    rise, plateau_end : float
        t_1 and t_2 [s].
    decay : float
        c [1/s].
    """
    t = np.asarray(t, dtype=float)
    tail = np.exp(-decay * np.maximum(t - plateau_end, 0.0))
    return np.where(t < rise, (t / rise) ** 2, np.where(t <= plateau_end, 1.0, tail))


def kanai_tajimi_filter(ground_frequency: float, ground_damping: float, dt: float):
    r"""Discrete (bilinear) Kanai-Tajimi filter from white noise to ground acceleration.

    .. math::
        H(s) = \frac{2 \zeta_g \omega_g s + \omega_g^2}{s^2 + 2 \zeta_g \omega_g s + \omega_g^2}

    Returns the ``(b, a)`` coefficients for :func:`scipy.signal.lfilter`.
    """
    from scipy import signal

    wg, zg = ground_frequency, ground_damping
    return signal.bilinear([2 * zg * wg, wg * wg], [1.0, 2 * zg * wg, wg * wg], fs=1.0 / dt)


def stochastic_record(
    peak: float,
    duration: float = 20.0,
    dt: float = 0.01,
    ground_frequency: float = 5.0 * math.pi,
    ground_damping: float = 0.6,
    rise: float | None = None,
    plateau_end: float | None = None,
    decay: float | None = None,
    seed: int | np.random.SeedSequence | None = 0,
) -> Record:
    """Synthesize a record: Kanai-Tajimi filtered white noise under a Jennings envelope.

    The same seed always gives the same record.

    Parameters
    ----------
    peak : float
        Peak ground acceleration the record is scaled to [m/s^2], > 0.
    duration : float
        Total length [s].
    dt : float
        Time step [s].
    ground_frequency : float
        Kanai-Tajimi omega_g [rad/s] (default 5 pi, a firm soil).
    ground_damping : float
        Kanai-Tajimi zeta_g [-] (default 0.6).
    rise, plateau_end, decay : float, optional
        Envelope t_1 [s], t_2 [s] and c [1/s]; by default 0.1, 0.4 of the duration and a
        decay that reaches 5 % at the end.
    seed : int or numpy.random.SeedSequence
        Seed of the white noise.
    """
    top = _validate.MAX_ACCELERATION
    peak = _validate.in_range("peak", peak, 1e-12, top, f"[1e-12, {top:.0e}] m/s^2")
    dt = _validate.in_range("dt", dt, _validate.MIN_STEP, 1.0, f"[{_validate.MIN_STEP:g}, 1] s")
    longest = _validate.MAX_DURATION
    duration = _validate.in_range("duration", duration, 2 * dt, longest, f"[2 dt, {longest:g}] s")
    ground_frequency = _validate.in_range(
        "ground_frequency", ground_frequency, 1e-2, 1e4, "[0.01, 1e4] rad/s"
    )
    ground_damping = _validate.in_range("ground_damping", ground_damping, 1e-3, 10.0, "[1e-3, 10]")
    points = duration / dt + 1.0
    _validate.check_memory(
        "duration",
        8.0 * 6 * points,
        f"{duration:g} s at dt = {dt:g} s is a record of {points:.4g} points",
        "shorten duration or coarsen dt",
    )
    if ground_frequency * dt >= 1.0:
        raise ValueError("dt must resolve the ground frequency: ground_frequency * dt < 1")
    rise = 0.1 * duration if rise is None else _validate.positive("rise", rise)
    plateau_end = 0.4 * duration if plateau_end is None else float(plateau_end)
    if not rise <= plateau_end <= duration:
        raise ValueError("envelope times must satisfy 0 < rise <= plateau_end <= duration")
    if decay is None:
        decay = -math.log(0.05) / max(duration - plateau_end, dt)
    rng = np.random.default_rng(seed)
    n = int(round(duration / dt)) + 1
    noise = rng.standard_normal(n)
    b, a = kanai_tajimi_filter(ground_frequency, ground_damping, dt)
    from scipy import signal

    acc = signal.lfilter(b, a, noise) * envelope_jennings(
        dt * np.arange(n), rise, plateau_end, decay
    )
    acc *= peak / np.max(np.abs(acc))
    return Record(acc, dt=dt, name=f"kanai-tajimi(seed={seed})")
