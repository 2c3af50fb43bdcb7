"""Argument checks shared by the public entry points (they raise, kernels never do)."""

from __future__ import annotations

import math

import numpy as np


def positive(name: str, value: float) -> float:
    """Return ``value`` as a float, or raise if it is not finite and > 0."""
    value = float(value)
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def in_open_interval(name: str, value: float, low: float, high: float, label: str) -> float:
    """Return ``value`` as a float, or raise if it is outside ``(low, high)``."""
    value = float(value)
    if not math.isfinite(value) or not low < value < high:
        raise ValueError(f"{name} must lie in {label}, got {value!r}")
    return value


def restitution(value: float) -> float:
    """Return a coefficient of restitution, or raise if it is outside (0, 1]."""
    value = float(value)
    if not math.isfinite(value) or not 0.0 < value <= 1.0:
        raise ValueError(f"restitution must lie in (0, 1], got {value!r}")
    return value


def finite_array(name: str, values) -> np.ndarray:
    """Return a 1-D float array (a contiguous, writable copy: the numba kernels that read it
    are compiled for that layout only), or raise if it is empty or holds NaN/inf."""
    arr = np.array(values, dtype=float)
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D sequence of numbers")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(
            f"{name} must be finite everywhere; {bad.size} value(s) are NaN or infinite, "
            f"first at index {bad[0]}"
        )
    return arr
