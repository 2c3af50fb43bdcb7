"""Study files: a TOML declaration of parameter distributions, validated by pydantic v2.

A study names a structure, a motion, a sampler and what to compute. Every parameter is either a
number or a distribution (a table with ``dist = ...``). Unknown keys are errors, so a typo
never passes silently; types are strict (``"1e-8"`` is not a number, ``true`` is not 1), only
finite numbers are accepted, and derived quantities (Housner's restitution) are checked over
the whole support of the distributions. :func:`validate_text` reports every problem as one
sentence naming its field, then checks what the study needs of this machine and its record
files (:mod:`.feasibility`), so that a study that cannot succeed is refused before it runs.

Example (``studies/quickstart.toml``)::

    name = "quickstart"
    seed = 2026
    chunk_size = 2000

    [sampler]
    kind = "monte_carlo"
    n = 20000

    [structure]
    kind = "block"
    half_diagonal = { dist = "uniform", low = 0.5, high = 3.0 }
    slenderness = { dist = "uniform", low = 0.1, high = 0.3 }

    [motion]
    kind = "pulse"
    shape = "sine"
    amplitude_ratio = { dist = "uniform", low = 1.0, high = 5.0 }   # a_g / (g tan alpha)
    period = { dist = "loguniform", low = 0.1, high = 2.0 }          # T_p [s]

    [run]
    method = "nonlinear"
    rtol = 1e-8
    outputs = ["max_rotation", "overturned", "n_impacts"]
"""

from __future__ import annotations

import csv
import difflib
import functools
import hashlib
import io
import json
import math
import re
import reprlib
import tomllib
from dataclasses import asdict
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    PrivateAttr,
    Tag,
    ValidationError,
    create_model,
    field_validator,
    model_validator,
)

from ... import _validate
from ...constants import G
from ...dynamics.methods import MAX_STEPS
from ...dynamics.simulate import MAX_FRICTION
from ...motions import measures
from ...motions.pulses import MAX_CYCLES, PERIOD_RANGE
from ...risk import MAX_YEARS
from ...structures.block import (
    FREQUENCY_PARAMETER_RANGE,
    HALF_DIAGONAL_RANGE,
    MIN_SLENDERNESS,
    uplift_acceleration_block,
)
from .design_kinds import DESIGN_KINDS, design_kind
from .distributions import Distribution
from .feasibility import DEFAULT_MAX_SCALE_FACTOR, notes, problems
from .feasibility import draw_span as _draw_span
from .ida_options import IdaOptionError, IdaOptions
from .samplers import SAMPLERS, kinds_laid_out
from .structures import KINDS, FieldError, FieldErrors, check_all, check_object, object_fields

__all__ = [
    "BlockSpec",
    "CONTACT_OUTPUTS",
    "DesignSpec",
    "EquivalentBlockSpec",
    "HAZARD_MEASURES",
    "HazardSpec",
    "HOUSNER_MAX_SLENDERNESS",
    "HVPair",
    "json_schema",
    "load_study",
    "MAX_CHUNK_SIZE",
    "MAX_DEPTH",
    "MAX_RATIO",
    "MAX_SCALE",
    "MAX_STUDY_BYTES",
    "MIN_RATIO",
    "MIN_RTOL",
    "MIN_SCALE",
    "MotionSpec",
    "OBJECT_COLUMNS",
    "OBJECT_KINDS",
    "ObjectSpec",
    "ObjectsSpec",
    "Output",
    "Param",
    "PulseSpec",
    "RecordSpec",
    "RunSpec",
    "SAMPLER_LAYOUTS",
    "samplers_laid_out",
    "SamplerSpec",
    "scale_units",
    "ScaleIM",
    "ScaleTo",
    "STEPS_PER_CYCLE",
    "StochasticSpec",
    "Structure",
    "Study",
    "StudyError",
    "validate_text",
    "VerticalRule",
    "WallSpec",
]


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

#: Housner's restitution 1 - 1.5 sin^2(alpha), eq. (2.4) of [000], is > 0 only below this
#: slenderness [rad] (sin^2 alpha = 2/3).
HOUSNER_MAX_SLENDERNESS = math.asin(math.sqrt(2.0 / 3.0))
_R_LABEL = "[{:g}, {:g}] m".format(*HALF_DIAGONAL_RANGE)
_ALPHA_LABEL = f"[{MIN_SLENDERNESS:g}, pi/2) rad"


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


def _sampled_geometry(spec):
    """The half-diagonal and slenderness of a sampled kind within the ranges of its registry
    entry (:data:`.structures.KINDS`)."""
    kind = KINDS[spec.kind]
    top, label = kind.slenderness_top, kind.fields["slenderness"].label
    open_label = label.replace(f"[{MIN_SLENDERNESS:g}", "(0")

    def radius():
        _check_positive("half_diagonal", spec.half_diagonal)
        _span("half_diagonal", spec.half_diagonal, *HALF_DIAGONAL_RANGE, _R_LABEL)

    def slenderness():
        _within("slenderness", spec.slenderness, 0.0, top, open_label)
        _span("slenderness", spec.slenderness, MIN_SLENDERNESS, top, label)

    check_all(radius, slenderness)


class BlockSpec(_Model):
    """A rectangular block: half-diagonal R [m], slenderness alpha [rad], restitution eta."""

    kind: Literal["block"]
    half_diagonal: Param
    slenderness: Param
    restitution: _Restitution = "housner"

    @model_validator(mode="after")
    def _ranges(self):
        check_all(lambda: _sampled_geometry(self), self._restitution)
        return self

    def _restitution(self):
        if self.restitution != "housner":
            _within("restitution", self.restitution, 0.0, 1.0 + 1e-15, "(0, 1]")
            return
        # the derived eta = 1 - 1.5 sin^2(alpha), eq. (2.4) of [000], must be in (0, 1]
        top = _largest(self.slenderness)
        if not top < HOUSNER_MAX_SLENDERNESS:
            raise FieldError(
                "slenderness",
                "Housner's restitution eta = 1 - 1.5 sin^2(alpha) (eq. 2.4 of [000]), "
                "derived from it, must lie in (0, 1], which needs slenderness < "
                f"{HOUSNER_MAX_SLENDERNESS:.4f} rad; slenderness reaches {top:g} rad. "
                "Narrow slenderness or give restitution",
            )


class WallSpec(_Model):
    """Out-of-plane rocking wall (slider-crank, two blocks of R and alpha), by its linearized
    equivalent block with kappa_1 = 1/2: p = sqrt(2) p_block, theta_cr = 2 alpha, eq. (23) of
    [003]; eta is given (no Housner value exists for the wall)."""

    kind: Literal["rocking_wall"]
    half_diagonal: Param
    slenderness: Param
    restitution: Param

    @model_validator(mode="after")
    def _ranges(self):
        check_all(
            lambda: _sampled_geometry(self),
            lambda: _within("restitution", self.restitution, 0.0, 1.0 + 1e-15, "(0, 1]"),
        )
        return self


class EquivalentBlockSpec(_Model):
    """Any structure by its rocking parameters: p [rad/s], theta_cr [rad], eta."""

    kind: Literal["equivalent_block"]
    frequency_parameter: Param
    critical_rotation: Param
    restitution: Param

    @model_validator(mode="after")
    def _ranges(self):
        lo, hi = FREQUENCY_PARAMETER_RANGE
        p, theta = self.frequency_parameter, self.critical_rotation

        def frequency():
            _check_positive("frequency_parameter", p)
            _span("frequency_parameter", p, lo, hi, f"[{lo:g}, {hi:g}] rad/s")

        def rotation():
            _within("critical_rotation", theta, 0.0, math.pi / 2, "(0, pi/2) rad")
            _span("critical_rotation", theta, MIN_SLENDERNESS, 2, _ALPHA_LABEL)

        check_all(
            frequency,
            rotation,
            lambda: _within("restitution", self.restitution, 0.0, 1.0 + 1e-15, "(0, 1]"),
        )
        return self


#: Kinds an object of ``[structure] kind = "objects"`` may be (the registry
#: :data:`.structures.KINDS`).
OBJECT_KINDS = tuple(KINDS)


def _a_name(value: str) -> str:
    """A name (of a study or an object), not blank and without a NUL character (which no
    store or report keeps)."""
    if "\0" in value or not value.strip():
        raise ValueError("must be a name: not blank, no NUL character")
    return value


class _ObjectBase(_Model):
    """One named object of a kind of :data:`.structures.KINDS` (by default a block: ``width``
    and ``height`` [m], or ``half_diagonal`` [m] and ``slenderness`` [rad]; restitution by
    default Housner's), with the fields of its kind as its physics class takes them."""

    name: str = Field(min_length=1)
    kind: Literal[OBJECT_KINDS] = "block"
    #: The friction coefficient mu of this object's contact (overrides the study's friction).
    friction: float | None = Field(default=None, gt=0, le=MAX_FRICTION)
    _params: tuple = PrivateAttr(default=None)
    _printable = field_validator("name")(lambda value: _a_name(value))

    @model_validator(mode="after")
    def _shape(self):
        given = {f: getattr(self, f) for f in object_fields() if getattr(self, f) is not None}
        structure, rocking = check_object(f"object {self.name!r}", self.kind, given)
        R = float(getattr(structure, "half_diagonal", np.nan))
        self._params = (*rocking, R)
        return self

    def geometry(self) -> tuple[float, float]:
        """(half-diagonal R [m], NaN for a structure without one; theta_cr [rad], the
        equivalent block's slenderness), as the design functions store them."""
        return self._params[4], self._params[1]

    def uplift(self) -> float:
        """The ground acceleration that starts the object rocking [m/s^2]: g tan(alpha) of a
        block, g lambda of another structure (eq. 10 of [003];
        :func:`rockstudy.structures.uplift_acceleration`)."""
        return self._params[3]

    def rocking(self) -> tuple[float, float, float]:
        """(p [rad/s], theta_cr [rad], eta) of the equivalent block of the object's physics
        class (:func:`rockstudy.structures.block_parameters`)."""
        return self._params[:3]


ObjectSpec = create_model(
    "ObjectSpec",
    __base__=_ObjectBase,
    __doc__=_ObjectBase.__doc__,
    **{f: (float | None, None) for f in object_fields()},
)


class ObjectsSpec(_Model):
    """Named objects studied one by one in a record ``[design]``: ``objects`` lists them (the
    ``structure`` coordinate of the result carries their names), or ``file`` names a CSV file
    of the same columns (read relative to the study file's folder into ``objects`` when the
    study is validated)."""

    kind: Literal["objects"]
    objects: list[ObjectSpec] = Field(min_length=1)
    file: str | None = None

    @model_validator(mode="after")
    def _unique(self):
        seen = {}
        for i, o in enumerate(self.objects):
            if o.name in seen:
                raise ValueError(
                    f"object {i} is named {o.name!r} like object {seen[o.name]}; names must differ"
                )
            seen[o.name] = i
        return self

    def rocking(self) -> np.ndarray:
        """(n, 3) array of (p [rad/s], theta_cr [rad], eta) of the objects, in order."""
        return np.array([o.rocking() for o in self.objects], float)

    def uplift(self) -> np.ndarray:
        """(n,) array of the objects' uplift accelerations [m/s^2] (:meth:`ObjectSpec.uplift`)."""
        return np.array([o.uplift() for o in self.objects], float)


#: Largest dimensionless intensity (amplitude_ratio, amplitude_a, pga_ratio, pgv_ratio) and
#: frequency ratio omega_g / p taken; the amplitudes and periods they give are then checked
#: against the solver's ranges (:meth:`Study._engine_ranges`).
MAX_RATIO = 1e4
#: Smallest ratio taken (a millionth: the motions they give must not vanish into subnormals).
MIN_RATIO = 1e-6
_RATIO_LABEL = f"[{MIN_RATIO:g}, {MAX_RATIO:g}]"
#: Largest |scale| of a record (its scaled peak is then checked against MAX_ACCELERATION),
#: and the smallest.
MAX_SCALE, MIN_SCALE = 1e6, 1e-6
#: The largest chunk_size written (a count, as max_steps); a chunk holds min(chunk_size, n)
#: rows, at most :data:`.feasibility.MAX_CHUNK_ROWS` (checked with the design).
MAX_CHUNK_SIZE = 10**12


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


def _nonzero(name, value):
    """A fixed factor must be != 0; a distribution must not reach 0."""
    if isinstance(value, (int, float)):
        if value == 0:
            raise FieldError(name, "must not be 0 (a record scaled by 0 is no motion)")
        return
    if value.dist == "choice" or (value.dist == "grid" and value.values is not None):
        bad = 0.0 in value.values
    else:
        lo, hi = value.support()
        bad = lo <= 0.0 <= hi
    if bad:
        raise FieldError(
            name, "the distribution must not give 0 (a record scaled by 0 is no motion)"
        )


class PulseSpec(_Model):
    """An analytic pulse. Give the amplitude in m/s^2 (``amplitude``), as a multiple of the
    uplift acceleration a_up (``amplitude_ratio``: g tan(alpha) of a block, the groups of eqs.
    5.3 and 6.1 of [000]; g lambda of a wall, eq. 10 of [003]) or of g alpha (``amplitude_a``,
    a of eq. 3.6: the groups of 4.10 and 4.11), and the period in seconds (``period``) or as
    omega_g / p (``frequency_ratio``)."""

    kind: Literal["pulse"]
    shape: Literal["sine", "cosine", "half-sine", "ricker"] = "sine"
    cycles: int = Field(default=1, ge=1, le=MAX_CYCLES)
    amplitude: Param | None = None
    amplitude_ratio: Param | None = None
    amplitude_a: Param | None = None
    period: Param | None = None
    frequency_ratio: Param | None = None
    direction: Literal[1, -1] = 1

    @field_validator("direction", mode="before")
    @classmethod
    def _not_a_boolean(cls, value):
        if isinstance(value, bool):
            raise ValueError(f"must be 1 or -1, not the boolean {str(value).lower()}")
        return value

    @model_validator(mode="after")
    def _one_of_each(self):
        given = [x is not None for x in (self.amplitude, self.amplitude_ratio, self.amplitude_a)]
        if sum(given) != 1:
            raise ValueError(
                "give exactly one of amplitude [m/s^2], amplitude_ratio "
                "(a_g / (g tan alpha)) or amplitude_a (a_g / (g alpha))"
            )
        if (self.period is None) == (self.frequency_ratio is None):
            raise ValueError("give exactly one of period [s] or frequency_ratio")
        for name in ("amplitude", "amplitude_ratio", "amplitude_a", "period", "frequency_ratio"):
            _check_positive(name, getattr(self, name))
        for name, low, top in (
            ("amplitude", 0.0, _validate.MAX_ACCELERATION),
            ("amplitude_ratio", MIN_RATIO, MAX_RATIO),
            ("amplitude_a", MIN_RATIO, MAX_RATIO),
            ("frequency_ratio", MIN_RATIO, MAX_RATIO),
        ):
            if getattr(self, name) is not None:
                _span(name, getattr(self, name), low, top, f"[{low:g}, {top:g}]")
        if self.period is not None:
            _span("period", self.period, *PERIOD_RANGE, "[{:g}, {:g}] s".format(*PERIOD_RANGE))
        if self.cycles != 1 and self.shape not in ("sine", "cosine"):
            raise FieldError("cycles", f"applies to sine and cosine pulses, not {self.shape}")
        return self


def _scale_im(name: str) -> str:
    """A name of :func:`rockstudy.motions.measures.scale_targets`, or a ValueError listing them."""
    if name not in measures.scale_targets():
        raise ValueError(f"must be one of {list(measures.scale_targets())}, got {name!r}")
    return name


#: Intensity measures a record can be scaled to: the registry's measures of power > 0 (see
#: :func:`rockstudy.motions.register_measure`) and the dimensionless targets ``pga_ratio`` =
#: PGA / a_up and ``pgv_ratio`` = PGV p / a_up (a_up the structure's uplift acceleration: g tan
#: alpha of a block, g lambda of another structure, eq. 10 of [003]); ``sa``, ``psv`` and ``sd``
#: (any measure that needs one) need a ``period``.
ScaleIM = Annotated[str, AfterValidator(_scale_im)]
#: The damping ratio of ``sa``, ``psv``, ``sd`` and the spectrum intensity in record studies.
_Damping = Annotated[float, Field(ge=0.0, lt=1.0)]
#: Periods of spectral measures [s]: 1 ms to 100 s, the span of response spectra.
_Period = Annotated[float, Field(ge=1e-3, le=100.0)]


def _check_period(im, period, field):
    """``period`` [s] is required by the measures that need one and refused by the others."""
    needs = measures.target(im).needs_period
    if needs and period is None:
        raise FieldError(field, f"im = {im!r} needs a period [s]")
    if not needs and period is not None:
        raise FieldError(field, f"applies to measures with a period (sa, psv, sd), not {im!r}")


def scale_units(im: str) -> dict:
    """Units a target of ``im`` may be written in: name -> factor to SI, the SI unit first
    (:data:`rockstudy.motions.measures.UNIT_ALIASES` of its SI unit, and its quoted unit;
    ``g`` is the standard gravity 9.80665 m/s^2, as for records); ``1`` for a ratio."""
    if im in measures.RATIOS:
        return {"1": 1.0}
    m = measures.measure(im)
    out = {m.unit: 1.0, **measures.UNIT_ALIASES.get(m.unit, {})}
    out.setdefault(m.quoted_unit, 1.0 / m.factor)
    return out


class ScaleTo(_Model):
    """Scale each record so that its measure ``im`` equals ``value``, in ``units`` (one of
    :func:`scale_units` of ``im``; by default the SI units of ``im``: ``pga``, ``sa``
    [m/s^2], ``pgv`` [m/s], ...; dimensionless for ``pga_ratio`` and ``pgv_ratio``). ``value``
    is a number or a distribution (Monte Carlo rows), or a grid (the levels of a stripes
    design); it is converted to SI before the run (:meth:`si_factor`)."""

    im: ScaleIM
    period: _Period | None = None
    damping: _Damping = 0.05
    value: Param | None = None
    units: str | None = None

    @model_validator(mode="after")
    def _ranges(self):
        _check_period(self.im, self.period, "period")
        allowed = scale_units(self.im)
        if self.units is not None and self.units not in allowed:
            raise FieldError(
                "units", f"for im = {self.im!r} must be one of {list(allowed)}, got {self.units!r}"
            )
        _check_positive("value", self.value)
        if self.value is not None and self.im in measures.RATIOS:
            _span("value", self.value, MIN_RATIO, MAX_RATIO, _RATIO_LABEL)
        return self

    @property
    def unit_label(self) -> str:
        """The units ``value`` is written in (the SI unit of ``im`` when none is given)."""
        return self.units or next(iter(scale_units(self.im)))

    def si_factor(self) -> float:
        """The factor that turns ``value`` (in :attr:`unit_label`) into SI."""
        return scale_units(self.im)[self.unit_label]

    def levels(self) -> np.ndarray:
        """The levels of a stripes design (the grid of ``value``) in SI."""
        return np.asarray(self.value.points(), float) * self.si_factor()


class HVPair(_Model):
    """One record as a horizontal and a vertical file on the same samples."""

    horizontal: str = Field(min_length=1)
    vertical: str = Field(min_length=1)


class VerticalRule(_Model):
    """H/V pairing of a folder or glob: the vertical file of each horizontal file is in the same
    folder, named by ``re.sub(match, replace, name)`` (files that are some record's vertical
    component are not read as horizontal records)."""

    match: str = Field(min_length=1)
    replace: str

    @field_validator("match")
    @classmethod
    def _regex(cls, value):
        try:
            re.compile(value)
        except re.error as exc:
            raise ValueError(f"must be a regular expression ({exc})") from None
        return value


class RecordSpec(_Model):
    """Recorded motions: a suite of record files, each scaled, or left unscaled in a design.

    ``files`` is a folder (its ``.AT2``, ``.dat``, ``.txt`` and ``.csv`` files), a glob, or a
    list of files and ``{ horizontal = ..., vertical = ... }`` pairs. ``vertical`` gives the
    vertical components: a list as long as ``files`` (of plain files), or ``{ match, replace }``
    naming each vertical file after its horizontal one. Monte Carlo rows pick one record per
    sample (uniformly) and scale it, either by ``scale`` (a factor != 0; negative mirrors), to
    ``pga_ratio`` x a_up (the structure's uplift acceleration: g tan(alpha) of a block, g lambda
    of another structure, eq. 10 of [003]), or to ``scale_to``; a ``[design]`` runs every record.

    ``units`` is the unit of the acceleration column of text records (``g``, ``m/s2`` or
    ``m/s^2``, ``cm/s2`` or ``cm/s^2``); ``.AT2`` files are in g (PEER's format), and a
    suite of ``.AT2`` files alone with other units is refused.

    A path is absolute as written, or relative to the study file's folder (never to the
    working folder; see :func:`.feasibility.record_path`). Only regular text files up to 64 MiB
    are read. No record is skipped: every file named, matched or found must read.
    """

    kind: Literal["record"]
    files: Annotated[str, Field(min_length=1)] | Annotated[list[str | HVPair], Field(min_length=1)]
    vertical: list[str] | VerticalRule | None = None
    units: Literal["g", "m/s2", "m/s^2", "cm/s2", "cm/s^2"] = "g"
    scale: Param | None = None
    pga_ratio: Param | None = None
    scale_to: ScaleTo | None = None

    @field_validator("files")
    @classmethod
    def _paths(cls, files):
        names = [files] if isinstance(files, str) else files
        for i, item in enumerate(names):
            for name in (item.horizontal, item.vertical) if isinstance(item, HVPair) else (item,):
                if not name.strip() or "\0" in name:
                    where = "files" if isinstance(files, str) else f"files[{i}]"
                    raise ValueError(f"{where} must be a path (not empty, no NUL character)")
        return files

    @model_validator(mode="after")
    def _one(self):
        given = [x is not None for x in (self.scale, self.pga_ratio, self.scale_to)]
        if sum(given) > 1:
            raise ValueError("give at most one of scale, pga_ratio or scale_to")
        if self.pga_ratio is not None:
            _check_positive("pga_ratio", self.pga_ratio)
            _span("pga_ratio", self.pga_ratio, MIN_RATIO, MAX_RATIO, _RATIO_LABEL)
        elif self.scale is not None:
            _nonzero("scale", self.scale)
            _span("scale", self.scale, -MAX_SCALE, MAX_SCALE, f"[-{MAX_SCALE:g}, {MAX_SCALE:g}]")
            lo, hi = _draw_span(self.scale)
            if min(abs(lo), abs(hi)) < MIN_SCALE:
                raise FieldError(
                    "scale", f"must be at least {MIN_SCALE:g} in magnitude; it reaches {lo:g}"
                )
        if isinstance(self.vertical, list):
            if isinstance(self.files, str):
                raise FieldError(
                    "vertical",
                    "a list pairs with a list of files; for a folder or glob give "
                    "vertical = { match = '<regex>', replace = '<replacement>' }",
                )
            if len(self.vertical) != len(self.files):
                raise FieldError(
                    "vertical",
                    f"lists {len(self.vertical)} files but files lists {len(self.files)}; "
                    "give one vertical file per record",
                )
            if any(isinstance(f, HVPair) for f in self.files):
                raise FieldError("vertical", "give pairs either in files or in vertical, not both")
        return self

    def target(self) -> ScaleTo | None:
        """The scaling target, with ``pga_ratio`` read as ``scale_to = { im = "pga_ratio" }``."""
        if self.pga_ratio is not None:
            return ScaleTo(im="pga_ratio", value=self.pga_ratio)
        return self.scale_to


class DesignSpec(_Model):
    """A record design over records x structures (``sampler.n`` structures drawn by the
    sampler) [x levels]: ``cloud`` (records unscaled), ``stripes`` (every record scaled to
    each level of ``motion.scale_to.value``, a grid), or ``ida`` (the first overturning
    intensity of each structure under each record in ``im``, by a ladder of ``step`` refined
    by bisection to ``tolerance``; ``max_pga_ratio`` and ``scan`` as in
    :class:`rockstudy.study.spec.ida_options.IdaOptions`, which holds their defaults and
    ranges). ``periods`` [s] are those of the spectral accelerations ``sa`` stored for every
    record, ``damping`` their damping ratio."""

    kind: Literal[tuple(DESIGN_KINDS)]
    periods: list[_Period] = Field(default=[], max_length=1000)
    damping: _Damping = 0.05
    im: ScaleIM | None = None
    period: _Period | None = None
    step: float | None = None
    tolerance: float | None = None
    max_pga_ratio: float | None = None
    scan: int | None = None
    growth: float | None = None  # replaced by step: refused with a message saying so
    #: Scale factors above this are noted by validate (records scaled far from what they
    #: recorded; cloud and stripes designs).
    max_scale_factor: float = Field(default=DEFAULT_MAX_SCALE_FACTOR, gt=1, le=1e6)

    @model_validator(mode="after")
    def _ida_keys(self):
        ida = ("im", "period", "step", "tolerance", "max_pga_ratio", "scan")
        if self.growth is not None:
            raise FieldError(
                "growth",
                "is no longer an option: the IDA climbs a ladder of rungs; give step (the "
                "relative step between rungs, default 0.01) instead",
            )
        if not design_kind(self.kind).capacities:
            for name in ida:
                if getattr(self, name) is not None:
                    raise FieldError(name, f"applies to kind = 'ida' only, not {self.kind!r}")
            return self
        _check_period(self.im or "pga", self.period, "period")
        try:
            options = self.ida()
        except IdaOptionError as exc:
            raise FieldError(exc.option, str(exc).partition(" ")[2]) from None
        for name in ida:  # the stored study shows every option the run used
            object.__setattr__(self, name, getattr(options, name))
        return self

    def ida(self) -> IdaOptions:
        """The IDA's options (defaults filled in)."""
        return IdaOptions.given(self.model_dump())

    def ida_options(self) -> dict:
        """Keyword arguments of the IDA (defaults filled in)."""
        return asdict(self.ida())


class StochasticSpec(_Model):
    """Kanai-Tajimi filtered white noise; every sample draws its own seeded record."""

    kind: Literal["stochastic"]
    pga_ratio: Param
    duration: float = Field(default=20.0, gt=0, le=_validate.MAX_DURATION)
    dt: float = Field(default=0.01, ge=_validate.MIN_STEP, le=1.0)
    ground_frequency: float = Field(default=5 * math.pi, gt=0, le=1e4)
    ground_damping: float = Field(default=0.6, gt=0, le=10.0)

    @model_validator(mode="after")
    def _ranges(self):
        _check_positive("pga_ratio", self.pga_ratio)
        _span("pga_ratio", self.pga_ratio, MIN_RATIO, MAX_RATIO, _RATIO_LABEL)
        if not self.ground_frequency * self.dt < 1.0:
            raise FieldError(
                "dt",
                f"must resolve the ground frequency: ground_frequency * dt < 1, got "
                f"{self.ground_frequency:g} rad/s * {self.dt:g} s",
            )
        if not self.duration >= 2.0 * self.dt:
            raise FieldError("duration", f"must hold at least two steps dt = {self.dt:g} s")
        return self

    def points(self) -> int:
        """Samples of each synthesized record."""
        return int(round(self.duration / self.dt)) + 1


#: Sampler kind -> its layout (:data:`.samplers.LAYOUTS`), read from the one registry
#: :data:`.samplers.SAMPLERS`.
SAMPLER_LAYOUTS = {kind: s.layout for kind, s in SAMPLERS.items()}


def samplers_laid_out(*layouts) -> list[str]:
    """The sampler kinds of the given layouts, in the order of :data:`.samplers.SAMPLERS`."""
    return kinds_laid_out(*layouts)


class SamplerSpec(_Model):
    """Monte Carlo, Latin hypercube, Sobol' (Saltelli layout, n = 2^k) or a full grid."""

    kind: Literal[tuple(SAMPLERS)]
    n: int | None = Field(default=None, ge=1, le=2**53)
    second_order: bool = False
    replicates: int = Field(default=1, ge=1, le=10**6)

    @model_validator(mode="after")
    def _n(self):
        sampler = SAMPLERS[self.kind]
        if not sampler.takes_n:
            if self.n is not None:
                raise FieldError("n", "a grid takes its size from the grid parameters; remove n")
        elif self.n is None:
            raise FieldError("n", f"sampler {self.kind!r} needs n")
        elif sampler.n_rule is not None and sampler.n_rule(self.n):
            raise FieldError("n", sampler.n_rule(self.n))
        if self.second_order and self.kind != "sobol":
            raise FieldError("second_order", "applies to the sobol sampler only")
        if self.replicates > 1 and SAMPLER_LAYOUTS[self.kind] != "random":
            random = " and ".join(samplers_laid_out("random"))
            raise FieldError("replicates", f"applies to the {random} samplers")
        return self


Output = Literal[
    "max_rotation",
    "max_rotation_ratio",
    "overturned",
    "n_impacts",
    "overturn_time",
    "first_impact_time",
    "steps",
    "model",
    "friction_demand",
    "lift_off",
]
#: The outputs a study's ``friction`` adds (the contact check of
#: :func:`rockstudy.simulate_batch`).
CONTACT_OUTPUTS = ("friction_demand", "lift_off")


#: Smallest relative tolerance taken: that of the solvers (:data:`rockstudy._validate.RTOL_MIN`,
#: where their error target stops drowning in rounding).
MIN_RTOL = _validate.RTOL_MIN
#: Solver steps per cycle of a rocking block under a sine or cosine pulse: at most 322 in
#: 200 random blocks and pulses at rtol 1e-8 (median 14), rounded up.
STEPS_PER_CYCLE = 400


class RunSpec(_Model):
    """The solver and what to keep."""

    method: Literal["nonlinear", "linear", "auto"] = "nonlinear"
    rtol: float = Field(default=1e-8, gt=0, lt=1)  # for "auto": accuracy of the max rotation
    max_steps: int = Field(default=MAX_STEPS, ge=1, le=_validate.MAX_STEPS_MAX)
    outputs: list[Output] = Field(default=["max_rotation", "overturned"], min_length=1)

    @model_validator(mode="after")
    def _unique(self):
        if len(set(self.outputs)) != len(self.outputs):
            raise FieldError("outputs", "lists a name twice")
        if self.rtol < MIN_RTOL:  # scipy's solve_ivp raises smaller ones to this floor
            raise FieldError(
                "rtol",
                f"must be >= {MIN_RTOL:.2g}: below it the solvers' error target drowns in "
                f"rounding, got {self.rtol:g}",
            )
        return self


Structure = Annotated[
    BlockSpec | WallSpec | EquivalentBlockSpec | ObjectsSpec, Field(discriminator="kind")
]
MotionSpec = Annotated[PulseSpec | RecordSpec | StochasticSpec, Field(discriminator="kind")]


#: Measures a ``[hazard]`` curve may be of: those a record design stores for every record.
HAZARD_MEASURES = ("pga", "pgv", "pgd", "arias", "cav", "spectrum_intensity", "sa", "psv", "sd")


class HazardSpec(_Model):
    """The site's hazard curve, for the annual probability of overturning of each structure
    of a record ``[design]`` (:func:`rockstudy.study.analysis.risk.object_risk`).

    ``kind = "power_law"``: lambda(x) = ``k0`` x^-``k`` (x in ``units``); ``kind = "file"``:
    ``file``, a path relative to the study file, of two columns (level, annual rate of
    exceedance) or an OpenQuake hazard-curve CSV (:meth:`rockstudy.risk.HazardCurve.from_csv`).
    The file is read when the study is validated: its levels and rates are then part of the
    study (``levels``, ``rates``: not to be given by hand), so a stored result keeps the curve
    it was reported with. ``im`` is the measure (one of :data:`HAZARD_MEASURES`; ``sa``,
    ``psv`` and ``sd`` at a ``period`` [s] the design stores), ``units`` the units of its
    levels (:data:`rockstudy.risk.UNIT_FACTORS`; default the IM's SI unit, or OpenQuake's
    for its files) and ``years`` the exposure time of the probability reported (default 50).
    """

    kind: Literal["power_law", "file"]
    im: Literal[HAZARD_MEASURES]
    units: str | None = None
    period: _Period | None = None
    years: float = Field(default=50.0, gt=0, le=MAX_YEARS)
    k0: float | None = Field(default=None, gt=0)
    k: float | None = Field(default=None, gt=0)
    file: str | None = None
    levels: list[float] | None = None
    rates: list[float] | None = None

    @model_validator(mode="after")
    def _curve(self):
        own = ("k0", "k") if self.kind == "power_law" else ("file", "levels", "rates")
        other = ("file", "levels", "rates") if self.kind == "power_law" else ("k0", "k")
        for name in other:
            if getattr(self, name) is not None:
                raise FieldError(name, f"does not apply to kind = {self.kind!r}")
        for name in own:
            if getattr(self, name) is None:
                raise FieldError(
                    name,
                    f"is required for kind = {self.kind!r}"
                    + (
                        " (read from file when the study file is validated)"
                        if name in ("levels", "rates")
                        else ""
                    ),
                )
        try:
            self.curve()
        except ValueError as exc:
            text = str(exc)
            field = next(
                (
                    f
                    for f in ("units", "period", "levels", "rates", "k0", "k")
                    if text.startswith(f)
                ),
                "file" if self.kind == "file" else "im",
            )
            raise FieldError(field, text.removeprefix(f"{field}: ")) from None
        return self

    def curve(self):
        """The :class:`rockstudy.risk.HazardCurve`."""
        from ...risk import HazardCurve

        if self.kind == "power_law":
            return HazardCurve.power_law(self.k0, self.k, self.im, self.units, self.period)
        return HazardCurve(self.im, self.levels, self.rates, self.units, self.period, self.file)


class Study(_Model):
    """A whole study file."""

    name: str = Field(min_length=1)
    description: str = ""
    seed: int = Field(ge=0)
    chunk_size: int = Field(default=4096, ge=1, le=MAX_CHUNK_SIZE)
    sampler: SamplerSpec
    structure: Structure
    motion: MotionSpec
    design: DesignSpec | None = None
    hazard: HazardSpec | None = None
    run: RunSpec = RunSpec()
    #: The friction coefficient mu of the contact (per object in an objects list): each scene
    #: then stores ``friction_demand`` and ``lift_off``, and the scenes whose demand exceeds
    #: mu (the block would slide) or that lift off are flagged, reported and warned about.
    friction: float | None = Field(default=None, gt=0, le=MAX_FRICTION)
    #: The study file's text as read (None for a study not read from text).
    _text: str | None = PrivateAttr(default=None)
    #: What will happen that the user should know before the run (not a problem): e.g. the
    #: points of a design that free fall censors (:func:`.feasibility.notes`).
    _notes: list = PrivateAttr(default_factory=list)

    _printable = field_validator("name")(lambda value: _a_name(value))

    @property
    def source_text(self) -> str | None:
        """The TOML text the study was validated from, as read (stored with its run)."""
        return self._text

    @property
    def notes(self) -> list[str]:
        """What the run will do that the user should know (one line each, naming the field):
        the levels a vertical component censors at free fall, records scaled beyond
        ``design.max_scale_factor`` and targets at which nothing can rock
        (:func:`.feasibility.notes`)."""
        return list(self._notes)

    @model_validator(mode="before")
    @classmethod
    def _objects_sampler(cls, data):
        """Named objects are the structures themselves: ``[sampler]`` may be left out (it is
        then ``kind = "grid"``: one row per object, record and level)."""
        if isinstance(data, dict) and "sampler" not in data:
            st = data.get("structure")
            if isinstance(st, dict) and st.get("kind") == "objects":
                return {**data, "sampler": {"kind": "grid"}}
        return data

    @model_validator(mode="before")
    @classmethod
    def _contact_outputs(cls, data):
        """A Monte Carlo study that gives ``friction`` stores the contact check of every scene
        (``friction_demand`` and ``lift_off`` join ``run.outputs``)."""
        if not (isinstance(data, dict) and data.get("friction") is not None):
            return data
        run = data.get("run", {})
        if data.get("design") is not None or not isinstance(run, dict):
            return data
        outputs = run.get("outputs", RunSpec.model_fields["outputs"].default)
        if not isinstance(outputs, list):
            return data  # the schema names the problem
        missing = [n for n in CONTACT_OUTPUTS if n not in outputs]
        return {**data, "run": {**run, "outputs": list(outputs) + missing}}

    def friction_coefficients(self) -> np.ndarray | None:
        """The friction coefficient of each object (NaN where none is given), the study's
        ``friction`` for sampled structures; None when no friction is given anywhere."""
        st = self.structure
        if st.kind == "objects":
            mu = [self.friction if o.friction is None else o.friction for o in st.objects]
            mu = np.array([np.nan if m is None else m for m in mu], float)
            return None if np.isnan(mu).all() else mu
        return None if self.friction is None else np.array([self.friction])

    @model_validator(mode="after")
    def _objects(self):
        if self.structure.kind != "objects":
            return self
        if self.design is None:
            raise FieldError(
                "structure.kind",
                "named objects are studied in a record [design] (cloud, stripes or ida); add one",
            )
        if self.sampler.kind != "grid":
            raise FieldError(
                "sampler.kind",
                "named objects are the structures of the design, not drawn: leave [sampler] out "
                f"or give kind = 'grid', not {self.sampler.kind!r}",
            )
        return self

    @model_validator(mode="after")
    def _design(self):
        mo, de = self.motion, self.design
        if de is None:
            if mo.kind == "record":
                if mo.scale is None and mo.target() is None:
                    raise FieldError(
                        "motion.scale",
                        "give one of scale, pga_ratio or scale_to (or a [design] table)",
                    )
                if mo.scale_to is not None and mo.scale_to.value is None:
                    raise FieldError("motion.scale_to.value", "is required (the target value)")
            return self
        if mo.kind != "record":
            raise FieldError("design", f"needs [motion] kind = 'record', not {mo.kind!r}")
        if SAMPLER_LAYOUTS[self.sampler.kind] not in ("random", "grid"):
            *some, last = samplers_laid_out("random", "grid")
            raise FieldError(
                "sampler.kind",
                f"a [design] draws its structures with {', '.join(some)} or {last}, not "
                f"{self.sampler.kind!r}",
            )
        if mo.scale is not None or mo.pga_ratio is not None:
            which = "scale" if mo.scale is not None else "pga_ratio"
            raise FieldError(
                f"motion.{which}",
                f"does not apply to a [design] (kind = {de.kind!r}); "
                + (
                    "give motion.scale_to with a grid of levels"
                    if design_kind(de.kind).levels
                    else "remove it"
                ),
            )
        if design_kind(de.kind).levels:
            if mo.scale_to is not None and mo.scale_to.damping != de.damping:
                raise FieldError(
                    "motion.scale_to.damping",
                    f"a stripes design scales with design.damping = {de.damping:g}; give the "
                    "same value or leave it out",
                )
            value = None if mo.scale_to is None else mo.scale_to.value
            if value is None or getattr(value, "dist", None) != "grid":
                raise FieldError(
                    "motion.scale_to.value",
                    "a stripes design needs the levels as a grid: "
                    "scale_to = { im = ..., value = { dist = 'grid', values = [...] } }",
                )
        elif mo.scale_to is not None:
            raise FieldError(
                "motion.scale_to",
                f"does not apply to a {de.kind!r} design"
                + (
                    "; give the IDA's measure as design.im"
                    if design_kind(de.kind).capacities
                    else ""
                ),
            )
        if self.sampler.replicates > 1:
            raise FieldError("sampler.replicates", "does not apply to a [design]")
        return self

    @model_validator(mode="after")
    def _hazard(self):
        hz, de = self.hazard, self.design
        if hz is None:
            return self
        if de is None:
            raise FieldError(
                "hazard",
                "applies to a record [design] (cloud, stripes or ida) only: the fragility "
                "it integrates is fitted per structure over records, which a Monte Carlo "
                "or Sobol study does not have",
            )
        if hz.im in ("sa", "psv", "sd"):
            stored = set(de.periods) | {de.period}
            if self.motion.kind == "record" and self.motion.scale_to is not None:
                stored.add(self.motion.scale_to.period)
            stored.discard(None)
            if hz.period not in stored:
                raise FieldError(
                    "hazard.period",
                    f"a {hz.im!r} hazard curve needs its period among the periods the design "
                    f"stores ({sorted(stored) or 'none'}: design.periods, design.period); "
                    f"got {hz.period!r}",
                )
        return self

    @model_validator(mode="after")
    def _grid(self):
        grid_params = [n for n, d in self.parameters().items() if d.dist == "grid"]
        if self.structure.kind == "objects":
            pass  # the objects are the grid (checked in _objects)
        elif self.sampler.kind == "grid":
            if not grid_params:
                raise FieldError(
                    "sampler.kind", "a grid sampler needs at least one parameter with dist = 'grid'"
                )
            others = [n for n, d in self.parameters().items() if d.dist != "grid"]
            if others:
                raise FieldError(
                    "sampler.kind", f"a grid sampler takes only grid parameters; {others} are not"
                )
        elif grid_params:
            raise FieldError(
                "sampler.kind", f"{grid_params} use dist = 'grid', which needs kind = 'grid'"
            )
        if self.sampler.kind == "sobol" and len(self.parameters()) < 2:
            raise FieldError("sampler.kind", "sobol needs at least two distributed parameters")
        if self.sampler.replicates > 1:
            mo, st = self.motion, self.structure
            if mo.kind != "pulse" or mo.amplitude is not None or mo.period is not None:
                raise FieldError(
                    "sampler.replicates",
                    "replicates need a pulse given by its groups: amplitude_ratio "
                    "or amplitude_a, and frequency_ratio",
                )
            if st.kind != "block":  # the self-similarity report reads a block's (R, alpha)
                raise FieldError(
                    "sampler.replicates",
                    f'replicates need structure.kind = "block" (got "{st.kind}"): the '
                    "self-similarity section compares blocks (R, alpha) at one group point",
                )
            if st.restitution == "housner":
                raise FieldError(
                    "sampler.replicates",
                    "replicates need a block with a given restitution (Housner's "
                    "depends on alpha, which would change the groups)",
                )
        return self

    @model_validator(mode="after")
    def _cycles(self):
        mo = self.motion
        if (
            mo.kind == "pulse"
            and mo.cycles > 1
            and mo.cycles * STEPS_PER_CYCLE > self.run.max_steps
        ):
            raise FieldError(
                "motion.cycles",
                f"{mo.cycles} cycles could take up to {mo.cycles * STEPS_PER_CYCLE:.3g} solver "
                f"steps (up to {STEPS_PER_CYCLE} per cycle while the block rocks), more than "
                f"run.max_steps = {self.run.max_steps}; use at most "
                f"{self.run.max_steps // STEPS_PER_CYCLE} cycles or raise run.max_steps",
            )
        return self

    @model_validator(mode="after")
    def _engine_ranges(self):
        """The amplitudes and periods that the ratios give must lie in the solver's ranges
        (over the whole support of the structure's distributions)."""
        mo, top = self.motion, _validate.MAX_ACCELERATION
        up_max = self.uplift_span()[1]
        for name, uplift in (
            ("amplitude_ratio", up_max),
            ("amplitude_a", G * self.largest_critical_rotation()),
            ("pga_ratio", up_max),
        ):
            value = getattr(mo, name, None)
            if value is not None and _largest(value) * uplift > top:
                raise FieldError(
                    f"motion.{name}",
                    f"reaches {_largest(value):g} x {uplift:.4g} m/s^2 = "
                    f"{_largest(value) * uplift:.4g} m/s^2 with the largest uplift level, "
                    f"beyond the {top:.0e} m/s^2 the solvers take",
                )
        ratio = getattr(mo, "frequency_ratio", None)
        if ratio is not None:
            p_lo, p_hi = self.frequency_parameter_span()
            longest = 2.0 * math.pi / (_smallest(ratio) * p_lo)
            shortest = 2.0 * math.pi / (_largest(ratio) * p_hi)
            lo, hi = PERIOD_RANGE
            if not (lo <= shortest and longest <= hi):
                raise FieldError(
                    "motion.frequency_ratio",
                    f"gives pulse periods 2 pi / (omega_g / p x p) from {shortest:.4g} to "
                    f"{longest:.4g} s over the structures' p of {p_lo:.4g} to {p_hi:.4g} rad/s; "
                    f"the solvers take [{lo:g}, {hi:g}] s",
                )
        return self

    def frequency_parameter_span(self) -> tuple[float, float]:
        """The smallest and largest p [rad/s] the structures can have."""
        st = self.structure
        if st.kind == "objects":
            p = st.rocking()[:, 0]
            return float(p.min()), float(p.max())
        if st.kind == "equivalent_block":
            return _smallest(st.frequency_parameter), _largest(st.frequency_parameter)
        R = [_smallest(st.half_diagonal), _largest(st.half_diagonal)]
        alpha = [_smallest(st.slenderness), _largest(st.slenderness)]
        p = KINDS[st.kind].sampled(*np.meshgrid(R, alpha))[0]  # p is monotone in R and alpha
        return float(p.min()), float(p.max())

    def largest_critical_rotation(self) -> float:
        """The largest critical rotation theta_cr [rad] the structures can have."""
        st = self.structure
        if st.kind == "objects":
            return float(st.rocking()[:, 1].max())
        if st.kind == "equivalent_block":
            return _largest(st.critical_rotation)
        return float(KINDS[st.kind].sampled(1.0, _largest(st.slenderness))[1])

    def uplift_span(self) -> tuple[float, float]:
        """The smallest and largest uplift acceleration a_up [m/s^2] the structures can have:
        the ground acceleration that starts each rocking (g tan(alpha) of a block or an
        equivalent block, g lambda of another structure, eq. 10 of [003]; at most
        g tan(pi/2 - 1e-9) where theta_cr reaches pi/2)."""
        st = self.structure
        if st.kind == "objects":
            up = st.uplift()
            return float(up.min()), float(up.max())
        if st.kind == "equivalent_block":
            ends = np.array(_draw_span(st.critical_rotation))
        else:
            ends = np.array(_draw_span(st.slenderness))
        ends = np.minimum(ends, math.pi / 2 - 1e-9)
        if st.kind == "equivalent_block":
            up = uplift_acceleration_block(ends)
        else:  # a_up is monotone in the slenderness (not in R) of every sampled kind
            up = KINDS[st.kind].sampled(np.ones(2), ends)[2]
        return float(up[0]), float(up[1])

    def largest_uplift_over_rest(self) -> float:
        """The largest a_up / (g theta_cr) of the structures: the uplift acceleration over
        the linearized model's rest level g theta_cr (the IDA ladder's span)."""
        st = self.structure
        if st.kind == "objects":
            return float(np.max(st.uplift() / (G * st.rocking()[:, 1])))
        top = min(self.largest_critical_rotation(), math.pi / 2 - 1e-9)
        return self.uplift_span()[1] / (G * top)  # increasing in the slenderness for each kind

    def levels(self) -> int:
        """Intensity levels of each record and structure of a design (1 but for stripes)."""
        if self.design is not None and design_kind(self.design.kind).levels:
            return self.motion.scale_to.value.size()
        return 1

    def rows_per_chunk(self) -> int:
        """Rows of each stored chunk: ``chunk_size``, or for a ``[design]`` one record's rows
        (its structures times levels: one record per task)."""
        return self.chunk_size if self.design is None else self.samples()

    def samples(self) -> int:
        """Number of rows of the design (without making it); for a ``[design]``, the number of
        structures times :meth:`levels` (each record adds as many)."""
        s, params = self.sampler, self.parameters()
        if self.structure.kind == "objects":
            return len(self.structure.objects) * self.levels()
        if self.design is not None and s.kind != "grid":
            return s.n * self.levels()
        if self.design is not None:
            return math.prod(d.size() for d in params.values()) * self.levels()
        if s.kind == "grid":
            return math.prod(d.size() for d in params.values())
        if s.kind == "sobol":  # Saltelli layout: N (D + 2), or N (2 D + 2) with second order
            return s.n * ((2 if s.second_order else 1) * len(params) + 2)
        return s.n * s.replicates

    def group_parameters(self) -> list[str]:
        """Distributed parameters that are dimensionless groups (held fixed across the
        replicates of a group point): the pulse's ratios and the restitution."""
        names = ("amplitude_ratio", "amplitude_a", "frequency_ratio", "restitution")
        return [n for n in self.parameters() if n in names]

    def parameters(self) -> dict[str, Distribution]:
        """The distributed parameters, in design order (structure, then motion); a distributed
        ``motion.scale_to.value`` is the parameter ``target`` (the levels of a stripes design are
        no parameter: they are its ``level`` dimension)."""
        out = {}
        for part in (self.structure, self.motion):
            for name in type(part).model_fields:
                value = getattr(part, name)
                if isinstance(value, BaseModel) and hasattr(value, "dist"):
                    out[name] = value
        target = getattr(self.motion, "scale_to", None)
        if self.design is None and target is not None and hasattr(target.value, "dist"):
            out["target"] = target.value
        return out

    def normalized(self) -> str:
        """Canonical JSON of the study (defaults filled in), as stored in result cubes."""
        return json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))

    def sha256(self) -> str:
        """sha256 of :meth:`normalized`."""
        return hashlib.sha256(self.normalized().encode()).hexdigest()


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


def _path(data, loc) -> list:
    """The keys of ``loc`` that exist in the input (dropping pydantic's union tags and
    validator names), as a list of keys and list indices."""
    out, node = [], data
    for key in loc:
        if isinstance(node, dict) and key in node:
            node = node[key]
        elif isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node):
            node = node[key]
        else:
            continue
        out.append(key)
    return out


def _dotted(keys) -> str:
    text = ""
    for key in keys:
        text += f"[{key}]" if isinstance(key, int) else (f".{key}" if text else str(key))
    return text or "(top level)"


_BOUNDS = {
    "greater_than": ">",
    "greater_than_equal": ">=",
    "less_than": "<",
    "less_than_equal": "<=",
}


#: What a value of the wrong type must be, by pydantic error type.
_MUST_BE = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_parsing": "an integer",
    "int_from_float": "an integer",
    "finite_number": "a finite number",
    "string_type": "a string",
    "bool_type": "true or false",
    "list_type": "a list",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "dict_type": "a table",
}


@functools.cache
def _schema() -> dict:
    """The JSON schema of study files, made once (it is fixed when the module is imported)."""
    return json_schema()


def _settings_at(loc) -> list[str]:
    """The settings of the table at the pydantic location ``loc`` (a union's tags included),
    read from the JSON schema of study files; [] where the path cannot be followed."""
    schema = _schema()

    def resolve(node):
        while "$ref" in node:
            node = schema["$defs"][node["$ref"].rsplit("/", 1)[-1]]
        return node

    node = resolve(schema)
    for key in loc:
        if key in node.get("properties", {}):
            node = resolve(node["properties"][key])
        elif key in node.get("discriminator", {}).get("mapping", {}):
            node = resolve({"$ref": node["discriminator"]["mapping"][key]})
        elif isinstance(key, int) and "items" in node:
            node = resolve(node["items"])
        else:
            return []
    tables = [resolve(n) for n in node.get("oneOf", node.get("anyOf", [node]))]
    return sorted({name for t in tables for name in t.get("properties", {})})


def _sentence(e: dict, keys: list) -> str:
    """One plain sentence for one pydantic error (``keys`` may be extended)."""
    kind, ctx, value = e["type"], e.get("ctx", {}), e.get("input")
    got = _describe(value)
    if kind == "missing":
        keys.append(e["loc"][-1])
        if tuple(e["loc"]) == ("sampler",):  # (a misspelt "objects" lands here too)
            return 'is required (unless [structure] kind = "objects")'
        return "is required"
    if kind == "extra_forbidden":
        close = difflib.get_close_matches(str(e["loc"][-1]), _settings_at(e["loc"][:-1]), 3)
        if close:
            return f"is not a setting here; did you mean {' or '.join(map(repr, close))}?"
        return "is not a setting here (a typo?); `rockstudy schema` lists the settings"
    if kind in _MUST_BE:
        return f"must be {_MUST_BE[kind]}, got {got}"
    if kind == "literal_error":
        return f"must be {ctx['expected']}, got {got}"
    if kind in _BOUNDS:
        bound = next(v for k, v in ctx.items() if k in ("gt", "ge", "lt", "le"))
        return f"must be {_BOUNDS[kind]} {bound}, got {got}"
    if kind == "too_short":
        return f"must hold at least {ctx['min_length']} item(s)"
    if kind == "string_too_short":
        return f"must hold at least {ctx['min_length']} character(s)"
    if kind == "union_tag_invalid":
        keys.append(ctx["discriminator"].strip("'"))
        return f"must be one of {ctx['expected_tags']}, got {_describe(ctx['tag'])}"
    if kind == "union_tag_not_found":
        keys.append(ctx["discriminator"].strip("'"))
        return "is required (it names the kind of table)"
    if kind == "value_error":
        error = ctx.get("error")
        if isinstance(error, FieldError):
            keys.extend(error.field.split("."))
        return str(error)
    return e["msg"]


def _object_name(data, keys) -> str:
    """`` ("Statue A")`` after a path into ``structure.objects[i]`` naming the object."""
    if len(keys) > 2 and keys[:2] == ["structure", "objects"] and isinstance(keys[2], int):
        item = data["structure"]["objects"][keys[2]]
        if isinstance(item, dict) and isinstance(item.get("name"), str):
            return f" ({item['name']!r})"
    return ""


def _expanded(errors):
    """pydantic's errors, with each :class:`FieldErrors` split into one error per field."""
    for e in errors:
        error = e.get("ctx", {}).get("error")
        if e["type"] == "value_error" and isinstance(error, FieldErrors):
            for one in error.errors:
                yield {**e, "ctx": {**e["ctx"], "error": one}}
        else:
            yield e


def _format_errors(err: ValidationError, data) -> list[str]:
    lines = []
    for e in _expanded(err.errors()):
        loc = e["loc"][:-1] if e["type"] == "missing" else e["loc"]
        keys = _path(data, loc)
        message = _sentence(e, keys)
        where = _dotted(keys)
        name = _object_name(data, keys)
        if name:  # after the index: structure.objects[1] ('Urn').width
            head = _dotted(keys[:3])
            where = head + name + where[len(head) :]
        line = f"{where}: {message}"
        if line not in lines:
            lines.append(line)
    return lines


class StudyError(ValueError):
    """A study file that does not validate; ``problems`` lists one line per field."""

    def __init__(self, source, problems):
        self.problems = problems
        super().__init__(f"{source}: {len(problems)} problem(s)\n  " + "\n  ".join(problems))


#: Largest study file read [bytes] (a study is a page of TOML).
MAX_STUDY_BYTES = 2**20
#: Deeper tables or lists than this are no study file (its deepest is motion.files[i]).
MAX_DEPTH = 16


def _depth(data) -> int:
    """Nesting depth of parsed TOML (iterative: no recursion limit)."""
    deepest, stack = 0, [(data, 1)]
    while stack:
        node, depth = stack.pop()
        if isinstance(node, dict | list):
            deepest = max(deepest, depth)
            if depth > MAX_DEPTH:
                break
            items = node.values() if isinstance(node, dict) else node
            stack.extend((x, depth + 1) for x in items)
    return deepest


_STRINGS_AND_COMMENTS = re.compile(
    r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:\\.|[^"\\\n])*"|\'[^\'\n]*\'|#[^\n]*'
)
_DOTTED = re.compile(r"[\w-]+(?:[ \t]*\.[ \t]*[\w-]+)+")


def _dotted_depth(text: str) -> int:
    """Most segments of a dotted key (``a.b.c``) in TOML text, found without parsing it:
    tomllib takes minutes on a key of 10^5 segments."""
    bare = _STRINGS_AND_COMMENTS.sub(lambda m: "" if m.group().startswith("#") else "q", text)
    return max((m.group().count(".") + 1 for m in _DOTTED.finditer(bare)), default=0)


def validate_text(text: str, source: str = "<study>", base_dir=None) -> Study:
    """Parse and validate a study from TOML text; raise :class:`StudyError` listing problems.

    Beyond the schema, a study that cannot produce a finite sample is refused before it runs:
    its record files must be readable records (see :func:`.feasibility.record_path` for where
    they are looked up; ``base_dir`` is the study file's folder, by default the working folder), and
    its design and per-sample memory must fit this machine.
    """
    if _dotted_depth(text) > MAX_DEPTH:
        raise StudyError(
            source, [f"not a study file: its keys nest deeper than {MAX_DEPTH} levels"]
        )
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(source, [f"not valid TOML: {exc}"]) from None
    except RecursionError:
        raise StudyError(
            source, ["not a study file: its tables or lists nest too deeply"]
        ) from None
    if _depth(data) > MAX_DEPTH:
        raise StudyError(
            source, [f"not a study file: its tables or lists nest deeper than {MAX_DEPTH} levels"]
        )
    file_problem = _read_objects_file(data, base_dir)
    hazard_problem = _read_hazard_file(data, base_dir)
    try:
        study = Study.model_validate(data)
    except ValidationError as exc:  # with the problems of the parts that are valid alone
        found = _format_errors(exc, data)
        if file_problem:
            found = [file_problem] + [x for x in found if not x.startswith("structure.objects")]
        if hazard_problem:
            found = [hazard_problem] + [x for x in found if not x.startswith("hazard.")]
            if found == [hazard_problem]:  # the rest is valid: its own checks (motion.units)
                found += _problems_without_hazard(data, base_dir)
        raise StudyError(source, found + _motion_problems(data, base_dir)) from None
    if file_problem or hazard_problem:  # with the rest's problems (a bad motion.units too)
        found = [p for p in (file_problem, hazard_problem) if p]
        rest = [x for x in _problems_beside(study, base_dir) if not x.startswith("hazard")]
        raise StudyError(source, found + [x for x in rest if x not in found])

    if study.design is not None and "chunk_size" in data:
        raise StudyError(
            source, ["chunk_size: does not apply to a [design], whose chunks are its records"]
        )
    found = problems(study, base_dir)
    if found:
        raise StudyError(source, found)
    study._text = text
    study._notes = notes(study, base_dir)
    return study


def _problems_without_hazard(data, base_dir) -> list[str]:
    """The problems of a study whose hazard file could not be read, without its ``[hazard]``
    (so that a bad ``motion.units`` is reported beside a bad ``hazard.units``)."""
    rest = {k: v for k, v in data.items() if k != "hazard"}
    try:
        study = Study.model_validate(rest)
    except ValidationError:
        return []
    return [x for x in _problems_beside(study, base_dir) if not x.startswith("hazard")]


def _problems_beside(study, base_dir) -> list[str]:
    """:func:`problems` of a study whose objects or hazard file could not be read (what they
    leave may be checked or may fail on their absence: then nothing more is said)."""
    try:
        return problems(study, base_dir)
    except Exception:  # noqa: BLE001 - the file's own problem is already reported
        return []


def _motion_problems(data, base_dir) -> list[str]:
    """The record files' problems of a study that does not validate, when its ``files`` and
    ``vertical`` do alone (a misspelt folder is reported beside a bad ``units``)."""
    motion = data.get("motion")
    if not (isinstance(motion, dict) and motion.get("kind") == "record"):
        return []
    files = {k: motion[k] for k in ("kind", "files", "vertical") if k in motion}
    try:  # the paths alone: another field of [motion] may be what is wrong
        spec = RecordSpec.model_validate(files)
    except ValidationError:
        return []  # reported by the whole study's validation
    from .feasibility import read_problems, record_pairs

    try:
        pairs = record_pairs(spec, base_dir)
    except ValueError as exc:
        return [str(exc)]
    try:  # and the records themselves, in the study's units if those are valid
        spec = RecordSpec.model_validate({**files, "units": motion.get("units", "g")})
    except ValidationError:
        return []
    return read_problems(spec, pairs)


#: Columns of an objects CSV file (``[structure] kind = "objects"``, ``file = ...``).
OBJECT_COLUMNS = tuple(ObjectSpec.model_fields)


def _read_objects_file(data, base_dir) -> str | None:
    """Read ``structure.file`` (a CSV of :data:`OBJECT_COLUMNS`, a header line then one object a
    line; empty cells are left out) into ``structure.objects`` of ``data``, in place; the
    problem as one line naming the file and the line, never its contents, or None."""
    st = data.get("structure")
    if not (isinstance(st, dict) and st.get("kind") == "objects" and "file" in st):
        return None
    name = st["file"]
    if "objects" in st:
        return "structure.file: give objects or file, not both"
    if not isinstance(name, str) or not name.strip():
        return f"structure.file: must be the path of a CSV file, got {_describe(name)}"
    from ...motions.records import read_text_file
    from .feasibility import record_path

    path = record_path(name, base_dir)
    try:
        text = read_text_file(path, MAX_STUDY_BYTES)
        st["objects"] = _object_rows(text)
    except (OSError, ValueError) as exc:
        return f"structure.file: cannot read {str(path)!r} ({exc})"
    return None


def _object_rows(text: str) -> list[dict]:
    """The objects of the text of an objects CSV file, one dict a row without its empty cells;
    ValueError naming the line and what was expected (never a cell: the file may be anything).

    A row may be shorter than the header; cells beyond the header, or under a column without a
    name, must be empty. Blank lines are skipped.
    """
    expected = f"a header line of columns among {list(OBJECT_COLUMNS)}, then one object a line"
    reader = csv.reader(io.StringIO(text.removeprefix("\ufeff")))  # a spreadsheet's BOM
    rows = []
    try:
        for cells in reader:
            if any("\n" in c or "\r" in c for c in cells):
                raise ValueError(
                    f"line {reader.line_num}: a quoted cell spans lines; expected {expected}"
                )
            rows.append((reader.line_num, [c.strip() for c in cells]))
    except csv.Error:  # a carriage return inside a line, a cell over csv's size limit
        raise ValueError(
            f"line {reader.line_num}: is not a line of comma-separated cells (a carriage "
            f"return alone, or a cell too long); expected {expected}"
        ) from None
    rows = [(line, cells) for line, cells in rows if any(cells)]
    if not rows:
        raise ValueError(f"it holds no line; expected {expected}")
    header = _object_header(*rows[0], expected)
    if len(rows) == 1:
        raise ValueError(f"it holds no object after its header; expected {expected}")
    return [_object_row(line, cells, header) for line, cells in rows[1:]]


def _object_header(line: int, cells: list[str], expected: str) -> list[str]:
    """The column names of the header of an objects CSV file ('' for a column without a name,
    which must stay empty); ValueError naming the first column that is no object column."""
    for i, cell in enumerate(cells):
        if cell and cell not in OBJECT_COLUMNS:
            raise ValueError(
                f"line {line}: column {i + 1} of the header is not an object column; "
                f"expected {expected}"
            )
        if cell and cell in cells[:i]:
            raise ValueError(f"line {line}: column {i + 1} of the header repeats a column")
    if "name" not in cells:
        raise ValueError(f"line {line}: the header has no name column; expected {expected}")
    return cells


def _object_row(line: int, cells: list[str], header: list[str]) -> dict:
    """One object of an objects CSV file: its non-empty cells by column, names and kinds as
    text and the rest as numbers where they read as one; ValueError for a non-empty cell
    beyond the header or under a column without a name."""
    stray = [i for i, cell in enumerate(cells) if cell and (i >= len(header) or not header[i])]
    if stray:
        raise ValueError(
            f"line {line}: cell {stray[0] + 1} is not under a named column (the row has "
            f"{len(cells)} cells, the header names {sum(map(bool, header))} columns)"
        )
    return {
        header[i]: cell if header[i] in ("name", "kind") else _cell(cell)
        for i, cell in enumerate(cells)
        if cell
    }


def _read_hazard_file(data, base_dir) -> str | None:
    """Read ``hazard.file`` (:meth:`rockstudy.risk.HazardCurve.from_csv`, relative to the
    study file's folder) into ``hazard.levels`` and ``hazard.rates`` of ``data``, in place
    (and ``units``, ``period`` where the file gives them); the problem as one line, or None."""
    hz = data.get("hazard")
    if not (isinstance(hz, dict) and hz.get("kind") == "file" and "file" in hz):
        return None
    given = [k for k in ("levels", "rates") if k in hz]
    if given:
        return f"hazard.{given[0]}: is read from hazard.file; give the file only"
    name = hz["file"]
    if not isinstance(name, str) or not name.strip():
        return f"hazard.file: must be the path of a hazard-curve file, got {_describe(name)}"
    from ...risk import HazardCurve
    from .feasibility import record_path

    args = {k: hz.get(k) for k in ("im", "units", "period")}
    plain = all(v is None or isinstance(v, str | float | int) for v in args.values())
    if args["im"] not in HAZARD_MEASURES or not plain:
        return None  # the schema names the bad field; the file is read once it is right
    path = record_path(name, base_dir)
    try:
        curve = HazardCurve.from_csv(path, **args)
    except (TypeError, ValueError, KeyError) as exc:
        text = str(exc)
        # a bad units, period or im is that field's problem, not the file's
        field = next((f for f in ("units", "period", "im") if text.startswith(f)), "file")
        return f"hazard.{field}: {text.removeprefix(f'{field}: ').removeprefix('path: ')}"
    hz["levels"], hz["rates"] = curve.levels.tolist(), curve.rates.tolist()
    hz["units"] = curve.units
    if curve.period is not None:
        hz["period"] = curve.period
    return None


def _cell(text: str):
    """A CSV cell: a number if it reads as one, else the text (the schema then names it)."""
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        return text


def load_study(path) -> Study:
    """Read and validate a study file; its relative record paths are relative to its folder."""
    from ...motions.records import read_text_file

    path = Path(path)
    try:
        text = read_text_file(path, MAX_STUDY_BYTES)
    except (OSError, ValueError) as exc:
        raise StudyError(str(path), [str(exc)]) from None
    return validate_text(text, str(path), base_dir=path.resolve().parent)


def json_schema() -> dict:
    """The JSON schema of study files."""
    return Study.model_json_schema()
