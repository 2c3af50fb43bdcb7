"""The options of an incremental dynamic analysis, shared by the study file (``[design]`` of
kind ``ida``), the Python API (:func:`rockstudy.study.incremental_dynamic_analysis`) and the
dataset folded back from a store: their defaults and ranges are written here once."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import ClassVar

import numpy as np

__all__ = ["IdaOptionError", "IdaOptions"]


@dataclass(frozen=True)
class IdaOptions:
    """The options of an incremental dynamic analysis, one place for the API, the study file
    (``[design]`` of kind ``ida``) and the dataset read back from a store.

    Attributes
    ----------
    im : str
        The measure the capacity is reported in (as ``im`` of
        :func:`~rockstudy.study.designs.records.multiple_stripes`).
    period : float or None
        T [s] of ``sa``, ``psv`` and ``sd``.
    step : float
        Ladder step: successive rungs differ by the factor ``1 + step`` in scale (about
        ``step`` in log scale), in [1e-3, 0.5]. Default 0.01.
    tolerance : float
        Relative width of the final bisection bracket of the capacity scale, in
        [1e-6, 0.5]. Default 0.001; at or above ``step`` there is no bisection (the bracket
        is the last surviving and the first overturning rung).
    max_pga_ratio : float
        Top of the ladder, PGA / (g tan alpha), in (1, 1e4]. Default 30.
    scan : int
        Levels simulated above the first overturning rung, spaced geometrically up to the top
        of the ladder, in [0, 1000] (0: none). Default 24.
    """

    im: str = "pga"
    period: float | None = None
    step: float = 0.01
    tolerance: float = 0.001
    max_pga_ratio: float = 30.0
    scan: int = 24

    #: name -> (lowest, highest, lowest allowed itself) of the numeric options
    RANGES: ClassVar[dict] = {
        "step": (1e-3, 0.5, True),
        "tolerance": (1e-6, 0.5, True),
        "max_pga_ratio": (1.0, 1e4, False),
        "scan": (0, 1000, True),
    }

    def __post_init__(self):
        for name, (low, high, closed) in self.RANGES.items():
            value = getattr(self, name)
            whole = name == "scan"
            kind = "a whole number" if whole else "a number"
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float, np.integer, np.floating))
                or (whole and int(value) != value)
                or not math.isfinite(value)
                or not (value >= low if closed else value > low)
                or value > high
            ):
                bracket = "[" if closed else "("
                raise IdaOptionError(
                    name,
                    f"{name} must be {kind} in {bracket}{low:g}, {high:g}], got {value!r}",
                )
        object.__setattr__(self, "scan", int(self.scan))

    @classmethod
    def given(cls, mapping) -> IdaOptions:
        """From a mapping whose missing or None entries take the defaults (a study's
        ``[design]`` table; other keys are ignored)."""
        names = [f.name for f in fields(cls)]
        return cls(**{k: mapping[k] for k in names if mapping.get(k) is not None})

    def attrs(self) -> dict:
        """The options as dataset attributes (``im_period`` NaN when there is none)."""
        out = asdict(self)
        period = out.pop("period")
        out["im_period"] = np.nan if period is None else float(period)
        return out


class IdaOptionError(ValueError):
    """An IDA option outside its range; ``option`` names it."""

    def __init__(self, option, message):
        super().__init__(message)
        self.option = option
