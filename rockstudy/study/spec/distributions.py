"""Parameter distributions of study files: each maps uniform numbers in [0, 1) to values.

Every distribution validates its own bounds (``low < high``, ``sigma > 0``, ...), finite numbers
only, and knows its support, so the structure and motion specs can reject, say, a slenderness
that could be negative. A distribution whose values could overflow (a span ``high - low`` or a
ratio ``high / low`` beyond the largest float, a lognormal tail at infinity) is refused: every
value the samplers can draw is finite.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator
from scipy import stats

__all__ = [
    "Choice",
    "Distribution",
    "Grid",
    "LogNormal",
    "LogUniform",
    "Normal",
    "Triangular",
    "TruncNormal",
    "Uniform",
]

#: The extreme probabilities a sampler can draw (Monte Carlo draws in [0, 1), Sobol' is clipped
#: below 1): the values there must be finite.
_U_EXTREMES = np.array([2.0**-53, 0.5, 1.0 - 2.0**-53])


class _Dist(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)

    def _finite_tails(self):
        """Raise unless the values at the extreme probabilities are finite numbers."""
        with np.errstate(all="ignore"):
            values = np.asarray(self.ppf(_U_EXTREMES), dtype=float)
        if not np.all(np.isfinite(values)):
            raise ValueError(
                f"{self.dist} gives values beyond the largest float in its tails; "
                "narrow it so that every sample is a finite number"
            )

    def support(self) -> tuple[float, float]:
        raise NotImplementedError

    def support_positive(self) -> bool:
        return self.support()[0] > 0

    def support_within(self, low, high) -> bool:
        lo, hi = self.support()
        return low < lo and hi < high

    def ppf(self, u):
        """Values at the probabilities ``u`` in [0, 1) (inverse CDF)."""
        raise NotImplementedError


class Uniform(_Dist):
    dist: Literal["uniform"]
    low: float
    high: float

    @model_validator(mode="after")
    def _bounds(self):
        if not self.low < self.high:
            raise ValueError(f"uniform needs low < high, got low={self.low}, high={self.high}")
        _finite_span("uniform", self.low, self.high)
        return self

    def support(self):
        return self.low, self.high

    def ppf(self, u):
        return self.low + (self.high - self.low) * np.asarray(u)


class LogUniform(_Dist):
    dist: Literal["loguniform"]
    low: float = Field(gt=0)
    high: float

    @model_validator(mode="after")
    def _bounds(self):
        if not self.low < self.high:
            raise ValueError(f"loguniform needs 0 < low < high, got {self.low}, {self.high}")
        if not math.isfinite(self.high / self.low):
            raise ValueError(
                f"loguniform needs a finite ratio high / low, got {self.high} / {self.low}"
            )
        return self

    def support(self):
        return self.low, self.high

    def ppf(self, u):
        return self.low * (self.high / self.low) ** np.asarray(u)


class Normal(_Dist):
    dist: Literal["normal"]
    mean: float
    sigma: float = Field(gt=0)

    @model_validator(mode="after")
    def _tails(self):
        self._finite_tails()
        return self

    def support(self):
        return -math.inf, math.inf

    def ppf(self, u):
        return stats.norm.ppf(u, loc=self.mean, scale=self.sigma)


class TruncNormal(_Dist):
    dist: Literal["truncnormal"]
    mean: float
    sigma: float = Field(gt=0)
    low: float
    high: float

    @model_validator(mode="after")
    def _bounds(self):
        if not self.low < self.high:
            raise ValueError(f"truncnormal needs low < high, got {self.low}, {self.high}")
        _finite_span("truncnormal", self.low, self.high)
        self._finite_tails()
        return self

    def support(self):
        return self.low, self.high

    def ppf(self, u):
        a, b = (self.low - self.mean) / self.sigma, (self.high - self.mean) / self.sigma
        return stats.truncnorm.ppf(u, a, b, loc=self.mean, scale=self.sigma)


class LogNormal(_Dist):
    """Lognormal with the given median and standard deviation of the logarithm."""

    dist: Literal["lognormal"]
    median: float = Field(gt=0)
    sigma: float = Field(gt=0)

    @model_validator(mode="after")
    def _tails(self):
        self._finite_tails()
        with np.errstate(all="ignore"):
            smallest = float(self.ppf(_U_EXTREMES[0]))
        if not smallest > 0:
            raise ValueError(
                "lognormal gives values that round to 0 in its lower tail; use a smaller sigma"
            )
        return self

    def support(self):
        return 0.0, math.inf

    def support_positive(self):
        return True

    def ppf(self, u):
        return stats.lognorm.ppf(u, self.sigma, scale=self.median)


class Triangular(_Dist):
    dist: Literal["triangular"]
    low: float
    mode: float
    high: float

    @model_validator(mode="after")
    def _bounds(self):
        if not (self.low <= self.mode <= self.high and self.low < self.high):
            raise ValueError("triangular needs low <= mode <= high and low < high")
        _finite_span("triangular", self.low, self.high)
        return self

    def support(self):
        return self.low, self.high

    def ppf(self, u):
        c = (self.mode - self.low) / (self.high - self.low)
        return stats.triang.ppf(u, c, loc=self.low, scale=self.high - self.low)


class Choice(_Dist):
    """A discrete choice among ``values`` with optional ``weights``."""

    dist: Literal["choice"]
    values: list[float] = Field(min_length=1)
    weights: list[float] | None = None

    @model_validator(mode="after")
    def _weights(self):
        if self.weights is not None:
            if len(self.weights) != len(self.values):
                raise ValueError("choice needs as many weights as values")
            if any(not (w > 0) for w in self.weights):
                raise ValueError("choice weights must be > 0")
            if not math.isfinite(math.fsum(self.weights)):
                raise ValueError("choice weights must have a finite sum")
        return self

    def support(self):
        return min(self.values), max(self.values)

    def support_within(self, low, high):
        return all(low < v < high for v in self.values)

    def ppf(self, u):
        w = np.ones(len(self.values)) if self.weights is None else np.asarray(self.weights)
        edges = np.cumsum(w) / np.sum(w)
        idx = np.minimum(np.searchsorted(edges, np.asarray(u), side="right"), len(w) - 1)
        return np.asarray(self.values)[idx]


class Grid(_Dist):
    """Grid values for the grid sampler: ``values``, or ``n`` points from ``low`` to ``high``."""

    dist: Literal["grid"]
    values: list[float] | None = None
    low: float | None = None
    high: float | None = None
    n: int | None = Field(default=None, ge=2)
    scale: Literal["linear", "log"] = "linear"

    @model_validator(mode="after")
    def _form(self):
        ranged = (self.low, self.high, self.n)
        if self.values is not None:
            if any(x is not None for x in ranged) or not self.values:
                raise ValueError("grid takes either values, or low, high and n")
        elif any(x is None for x in ranged):
            raise ValueError("grid takes either values, or low, high and n")
        elif not self.low < self.high:
            raise ValueError(f"grid needs low < high, got {self.low}, {self.high}")
        elif self.scale == "log" and not self.low > 0:
            raise ValueError("a log grid needs low > 0")
        else:
            _finite_span("grid", self.low, self.high)
        return self

    def size(self) -> int:
        """Number of grid points (without making them)."""
        return len(self.values) if self.values is not None else self.n

    def points(self) -> np.ndarray:
        if self.values is not None:
            return np.asarray(self.values, dtype=float)
        if self.scale == "log":
            return np.geomspace(self.low, self.high, self.n)
        return np.linspace(self.low, self.high, self.n)

    def support(self):
        if self.values is None:  # the end points, without making a grid of any size
            return self.low, self.high
        return min(self.values), max(self.values)


def _finite_span(name, low, high):
    if not math.isfinite(high - low):
        raise ValueError(f"{name} needs a finite span high - low, got {low} to {high}")


Distribution = Annotated[
    Uniform | LogUniform | Normal | TruncNormal | LogNormal | Triangular | Choice | Grid,
    Field(discriminator="dist"),
]
