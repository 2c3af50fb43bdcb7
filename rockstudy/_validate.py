"""Argument checks shared by the public entry points (they raise, kernels never do)."""

from __future__ import annotations

import math
import numbers
import os

import numpy as np

GIB = 2.0**30
#: Share of this machine's memory that the whole design of a study (the client) and that one
#: sample (a record's measures, a synthesized record, a simulated history) may take.
DESIGN_SHARE, SAMPLE_SHARE = 0.5, 0.25

#: Largest |ground acceleration| [m/s^2] of a record or pulse: 1e7 m/s^2, about a million g,
#: more than 200,000 times the largest peak ever recorded (about 4.4 g) and beyond any record
#: an IDA scales (max_pga_ratio <= 1e4 times g tan(alpha)). The bound keeps every measure
#: finite: squares and integrals of the samples (Arias intensity, the pulse fit's least
#: squares) overflow near 1e154 m/s^2, and a value of 1e300 made the run fail.
MAX_ACCELERATION = 1e7
#: Smallest sample step of a record [s]: 1 MHz, a thousand times the sampling rate of any
#: accelerograph (the mean period's spectrum alone needs 20 / dt points: 256 GiB at 1e-9 s).
MIN_STEP = 1e-6
#: Longest record [s]: 1e6 s, about 11.6 days; strong motion lasts minutes, a day-long
#: seismometer file 86,400 s.
MAX_DURATION = 1e6


class NotANumberError(TypeError, ValueError):
    """A string, a boolean, None or another object where a number was expected: a wrong type
    (a ``TypeError``, as for every wrong type), and also a ``ValueError`` so that the callers
    that catch bad values keep catching it."""


def machine_memory() -> float:
    """Physical memory of this machine [bytes]."""
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def memory_problem(name: str, nbytes: float, what: str, advice: str, share=SAMPLE_SHARE):
    """A sentence naming ``name`` if ``nbytes`` is more than ``share`` of this machine's
    memory, else None. ``what`` says what takes it (e.g. "a record of 2e10 points")."""
    memory = machine_memory()
    if nbytes <= share * memory:
        return None
    return (
        f"{name}: {what}, about {nbytes / GIB:.3g} GiB in memory, more than {share:.0%} of "
        f"this machine's {memory / GIB:.3g} GiB; {advice}"
    )


def check_memory(name: str, nbytes: float, what: str, advice: str, share=SAMPLE_SHARE):
    """Raise the ValueError of :func:`memory_problem` if there is one."""
    problem = memory_problem(name, nbytes, what, advice, share)
    if problem:
        raise ValueError(problem)


def number(name: str, value) -> float:
    """``value`` as a float, or a :class:`NotANumberError` naming ``name`` if it is not a real
    number: a string (``"0.1"``), a boolean (``True``) or anything else is not taken for
    one."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise NotANumberError(f"{name} must be a number, got {_what(value)}")
    return float(value)


def _what(value) -> str:
    """A short description of a wrong value for a message."""
    if isinstance(value, (bool, np.bool_)):
        return f"the boolean {bool(value)}"
    text = repr(value)
    return f"{type(value).__name__} {text[:40] + '...' if len(text) > 40 else text}"


def positive(name: str, value: float) -> float:
    """Return ``value`` as a float, or raise if it is not finite and > 0."""
    value = number(name, value)
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def in_open_interval(name: str, value: float, low: float, high: float, label: str) -> float:
    """Return ``value`` as a float, or raise if it is outside ``(low, high)``."""
    value = number(name, value)
    if not math.isfinite(value) or not low < value < high:
        raise ValueError(f"{name} must lie in {label}, got {value!r}")
    return value


def restitution(value: float) -> float:
    """Return a coefficient of restitution, or raise if it is outside (0, 1]."""
    value = number("restitution", value)
    if not math.isfinite(value) or not 0.0 < value <= 1.0:
        raise ValueError(f"restitution must lie in (0, 1], got {value!r}")
    return value


def finite_array(name: str, values) -> np.ndarray:
    """Return a 1-D float array (a contiguous, writable copy: the numba kernels that read it
    are compiled for that layout only), or raise if it is empty or holds NaN/inf."""
    raw = values if isinstance(values, np.ndarray) else _as_array(name, values)
    if raw.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be a 1-D sequence of numbers, got {_what(values)}")
    arr = np.array(raw, dtype=float)
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D sequence of numbers")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(
            f"{name} must be finite everywhere; {bad.size} value(s) are NaN or infinite, "
            f"first at index {bad[0]}"
        )
    return arr


def numbers_array(name: str, values) -> np.ndarray:
    """``values`` (a number or a nested sequence or array of numbers) as a float array of any
    shape, or a :class:`NotANumberError` naming ``name``: a string (``"0.1"``), a boolean
    (``True``, also one inside a list of floats, which numpy would take for 1.0), None or any
    other object is not a number. NaN and infinities pass (the caller says its range)."""
    raw = _as_array(name, values)
    boolean = raw.dtype.kind == "b" or (
        isinstance(values, list | tuple)
        and any(isinstance(v, bool | np.bool_) for v in np.asarray(values, dtype=object).flat)
    )
    if boolean or raw.dtype.kind not in "iuf":
        raise NotANumberError(
            f"{name} must be a number or an array of numbers, got {_what(values)}"
        )
    return raw.astype(float)


def real_array(name: str, values, low=-math.inf, high=math.inf, label="") -> np.ndarray:
    """``values`` as a float array of any shape, or a ValueError naming ``name``: not numbers
    (:func:`numbers_array`), NaN, infinite, or outside [low, high] (``label`` says the
    allowed range in the message)."""
    if _as_array(name, values).size == 0:
        raise ValueError(f"{name} must be a number or an array of numbers, got {_what(values)}")
    arr = numbers_array(name, values)
    bad = ~np.isfinite(arr) | (arr < low) | (arr > high)
    if bad.any():
        first = float(arr.flat[int(np.flatnonzero(bad)[0])])
        allowed = label or "finite numbers"
        raise ValueError(f"{name} must be {allowed}, got {first!r}")
    return arr


def count(name: str, value, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int, or a ValueError naming ``name`` unless it is a whole number (an
    integer type: not a float, a string or a boolean) in [low, high] (high None: no bound)."""
    label = f">= {low}" if high is None else f"in [{low}, {high}]"
    whole = isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)
    if not whole or value < low or (high is not None and value > high):
        raise ValueError(f"{name} must be a whole number {label}, got {_what(value)}")
    return int(value)


def flag(name: str, value) -> bool:
    """``value`` as a bool, or a TypeError naming ``name`` unless it is True or False (a
    string such as ``"yes"`` or a number is not taken for one)."""
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be True or False, got {_what(value)}")
    return bool(value)


def _as_array(name, values) -> np.ndarray:
    try:
        return np.asarray(values)
    except (TypeError, ValueError):  # ragged nesting
        raise ValueError(f"{name} must be a 1-D sequence of numbers, got {_what(values)}") from None


#: The tightest rtol offered. The kernels' local error target is 0.1 rtol, which as rtol -> 0
#: drowns in the rounding of a DOP853 step (steps shrink without end: rtol = 1e-300 ran for
#: minutes). Measured on 1,600 random pulse scenes (alpha 0.005-0.45, R 1 mm-20 m, half of
#: them 1e-15 to 0.1 above uplift): at 1e-12 and at 1e-13 every scene finished, the only ones
#: above 200,000 steps being two with 112,486 impacts of real free rocking. 1e-12 is also
#: the tolerance at which the kernels are calibrated against the scipy reference.
RTOL_MIN = 1e-12
#: The largest step cap: step counts are tallied in float64 and int64 inside the kernels.
MAX_STEPS_MAX = 10**12


def rtol(value: float) -> float:
    """Return a relative tolerance, or raise if it is outside [RTOL_MIN, 1)."""
    return in_range("rtol", value, RTOL_MIN, 1.0, f"[{RTOL_MIN:g}, 1)", high_open=True)


def in_range(name, value, low, high, label, high_open=False, low_open=False) -> float:
    """Return ``value`` as a float, or raise if it is outside [low, high] (an end marked open
    excluded: ``high_open``, ``low_open``)."""
    value = number(name, value)
    above = value >= high if high_open else value > high
    below = value <= low if low_open else value < low
    if not math.isfinite(value) or below or above:
        raise ValueError(f"{name} must lie in {label}, got {value!r}")
    return value


def max_steps(value) -> int:
    """Return a step cap as an int, or raise if it is not a whole number in [1, 1e12]."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"max_steps must be a whole number in [1, 1e12], got {value!r}")
    if not (math.isfinite(value) and value == int(value) and 1 <= value <= MAX_STEPS_MAX):
        raise ValueError(f"max_steps must be a whole number in [1, 1e12], got {value!r}")
    return int(value)


def output_times(t_eval, dt_out, t_max) -> np.ndarray | None:
    """Return the requested output times of a simulation as a sorted float array (None for
    none), or raise: ``t_eval`` must be finite, >= 0, non-decreasing and at most ``t_max``
    [s] when that is given; ``dt_out`` [s] > 0 asks for the uniform grid 0, dt_out, ...
    up to ``t_max`` (or, without it, to the end of the response, which the caller finds)."""
    if t_eval is not None and dt_out is not None:
        raise ValueError("give t_eval or dt_out, not both")
    if dt_out is not None:
        dt_out = positive("dt_out", dt_out)
        return None if t_max is None else uniform_times(dt_out, t_max)
    if t_eval is None:
        return None
    arr = finite_array("t_eval", t_eval)
    if arr[0] < 0.0:
        raise ValueError(f"t_eval must be >= 0 (the motion starts at t = 0), got {arr[0]!r}")
    down = np.flatnonzero(np.diff(arr) < 0.0)
    if down.size:
        raise ValueError(
            f"t_eval must be sorted (non-decreasing); it decreases at index {down[0] + 1}"
        )
    if t_max is not None and arr[-1] > t_max:
        raise ValueError(
            f"t_eval reaches {arr[-1]!r} s, beyond the simulated end t_max = {t_max!r} s"
        )
    return arr


#: Float arrays of the output grid's length a simulation holds (times, theta, theta_dot and
#: the kernel's dense-output work arrays).
OUTPUT_ARRAYS = 6


def uniform_times(dt_out: float, end: float) -> np.ndarray:
    """The times k dt_out [s] in [0, end]; a ValueError naming ``dt_out`` if that grid would
    not fit in memory (see :func:`check_memory`)."""
    points = end / dt_out + 1.0
    check_memory(
        "dt_out",
        8.0 * OUTPUT_ARRAYS * points,
        f"dt_out = {dt_out:g} s asks for {points:.3g} output times up to {end:g} s",
        "give a larger dt_out, or t_eval",
    )
    return np.minimum(dt_out * np.arange(int(math.floor(end / dt_out)) + 1), end)


def initial_state(initial_rotation, initial_velocity) -> tuple[float, float]:
    """The initial (theta [rad], theta_dot [rad/s]) of a simulation as floats, or a ValueError
    naming ``initial_rotation`` (it must lie in (-pi/2, pi/2)) or ``initial_velocity`` (finite).
    """
    half_pi = math.pi / 2
    th0 = in_open_interval(
        "initial_rotation", initial_rotation, -half_pi, half_pi, "(-pi/2, pi/2) rad"
    )
    om0 = number("initial_velocity", initial_velocity)
    if not math.isfinite(om0):
        raise ValueError(f"initial_velocity must be finite, got {initial_velocity!r}")
    return th0, om0
