"""What every section of a study file is made of: the strict model, the parameter, its checks.

Each section's model derives from ``_Model``: unknown keys are errors, types are strict
(``"1e-8"`` is not a number, ``true`` is not 1) and only finite numbers are accepted. A
parameter (:data:`Param`) is a number or a :class:`.distributions.Distribution` (a table with
``dist = ...``); ``_check_positive``, ``_span`` and ``_within`` check a fixed value or the
whole support of a distribution, raising :class:`.structures.FieldError` naming the field.
Also here: the limits several sections share (:data:`MIN_RATIO`, :data:`MAX_RATIO`,
:data:`MAX_STUDY_BYTES`), the spectral ``_Period`` and ``_Damping``, the check of a name, and
how a value written in TOML is quoted in a message (``_describe``).
"""

from __future__ import annotations

import math
import reprlib
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag

from .distributions import Distribution
from .feasibility import draw_span as _draw_span
from .structures import FieldError

__all__ = ["MAX_RATIO", "MAX_STUDY_BYTES", "MIN_RATIO", "Param"]


def _param_tag(value):
    """Which member of a parameter union a TOML value is meant for (a table is a
    distribution, anything else is meant as a number), so that an error names one."""
    if isinstance(value, dict | BaseModel):
        return "distribution"
    if isinstance(value, str) and value == "housner":
        return "housner"
    return "number"


_NUMBER = Annotated[float, Tag("number")]
_DISTRIBUTION = Annotated[Distribution, Tag("distribution")]
Param = Annotated[_NUMBER | _DISTRIBUTION, Discriminator(_param_tag)]
_Restitution = Annotated[
    _NUMBER | _DISTRIBUTION | Annotated[Literal["housner"], Tag("housner")],
    Discriminator(_param_tag),
]


class _Model(BaseModel):
    # strict: "1e-8" is not a number and true is not 1; inf and NaN are not accepted
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


def _check_positive(name, value):
    """A fixed parameter must be > 0; a distribution must have positive support."""
    if isinstance(value, (int, float)):
        if not (math.isfinite(value) and value > 0):
            raise FieldError(name, f"must be > 0, got {value}")
    elif value is not None and not value.support_positive():
        raise FieldError(name, "the distribution must only give values > 0")


def _a_name(value: str) -> str:
    """A name (of a study or an object), not blank and without a NUL character (which no
    store or report keeps)."""
    if "\0" in value or not value.strip():
        raise ValueError("must be a name: not blank, no NUL character")
    return value


#: Largest dimensionless intensity (amplitude_ratio, amplitude_a, pga_ratio, pgv_ratio) and
#: frequency ratio omega_g / p taken; the amplitudes and periods they give are then checked
#: against the solver's ranges (:meth:`Study._engine_ranges`).
MAX_RATIO = 1e4
#: Smallest ratio taken (a millionth: the motions they give must not vanish into subnormals).
MIN_RATIO = 1e-6
_RATIO_LABEL = f"[{MIN_RATIO:g}, {MAX_RATIO:g}]"


def _span(name, value, low, high, label):
    """A fixed value or a distribution's support must lie in the closed [low, high]."""
    lo, hi = _draw_span(value)
    if not (low <= lo and hi <= high):
        got = f"got {value}" if lo == hi else f"it spans {lo:g} to {hi:g}"
        raise FieldError(name, f"must lie in {label}; {got}")


def _smallest(value) -> float:
    """The smallest value a fixed parameter or a distribution can give."""
    return _draw_span(value)[0]


def _largest(value) -> float:
    """The largest value a fixed parameter or a distribution can give."""
    return _draw_span(value)[1]


def _within(name, value, low, high, label):
    if isinstance(value, (int, float)):
        if not (low < value < high):
            raise FieldError(name, f"must lie in {label}, got {value}")
    elif not value.support_within(low, high):
        lo, hi = value.support()
        raise FieldError(
            name, f"the distribution must only give values in {label}; it spans {lo:g} to {hi:g}"
        )


#: The damping ratio of ``sa``, ``psv``, ``sd`` and the spectrum intensity in record studies.
_Damping = Annotated[float, Field(ge=0.0, lt=1.0)]
#: Periods of spectral measures [s]: 1 ms to 100 s, the span of response spectra.
_Period = Annotated[float, Field(ge=1e-3, le=100.0)]


_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = 40
_SHORT.maxlevel = 2


def _describe(value) -> str:
    """A value as the user wrote it in TOML, shortened."""
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, str):
        return f"the string {_SHORT.repr(value)}"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "a list"
    return _SHORT.repr(value)


#: Largest study file read [bytes] (a study is a page of TOML).
MAX_STUDY_BYTES = 2**20
