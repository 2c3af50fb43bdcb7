"""The ``[motion]`` table of a study file: an analytic pulse, a suite of records, or noise.

A pulse is given by its amplitude and period or by their dimensionless groups; a record suite
by its files (H/V pairs as lists or by a renaming rule) and how each record is scaled
(``scale``, ``pga_ratio`` or a target :class:`ScaleTo` of an intensity measure, in the units
of :func:`scale_units`), and optionally the floor of a linear building it is felt on
(:class:`BuildingSpec`, ``floor``); a stochastic motion by its Kanai-Tajimi filter.
:data:`MotionSpec` is their union, told apart by ``kind``.
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Literal

import numpy as np
from pydantic import AfterValidator, Field, field_validator, model_validator

from ... import _validate
from ...motions import measures
from ...motions.building import MAX_STOREYS, Building, floor_motion
from ...motions.pulses import MAX_CYCLES, PERIOD_RANGE
from ...motions.units import acceleration_units
from .feasibility import draw_span as _draw_span
from .parameters import (
    _RATIO_LABEL,
    MAX_RATIO,
    MIN_RATIO,
    Param,
    _check_positive,
    _Damping,
    _Model,
    _Period,
    _span,
)
from .structures import FieldError

__all__ = [
    "BuildingSpec",
    "MAX_SCALE",
    "MIN_SCALE",
    "HVPair",
    "MotionSpec",
    "PulseSpec",
    "RECORD_UNITS",
    "RecordSpec",
    "ScaleIM",
    "ScaleTo",
    "StochasticSpec",
    "UniformShearSpec",
    "VerticalRule",
    "scale_units",
]


#: Largest |scale| of a record (its scaled peak is then checked against MAX_ACCELERATION),
#: and the smallest.
MAX_SCALE, MIN_SCALE = 1e6, 1e-6


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


def _check_period(im, period, field):
    """``period`` [s] is required by the measures that need one and refused by the others."""
    needs = measures.target(im).needs_period
    if needs and period is None:
        raise FieldError(field, f"im = {im!r} needs a period [s]")
    if not needs and period is not None:
        raise FieldError(field, f"applies to measures with a period (sa, psv, sd), not {im!r}")


def scale_units(im: str) -> dict:
    """Units a target of ``im`` may be written in: name -> factor to SI, the SI unit first
    (:func:`rockstudy.motions.measures.units_of`: the units of its dimension, as for hazard
    curves, and its quoted unit; ``g`` is the standard gravity 9.80665 m/s^2, as for
    records); ``1`` for a ratio."""
    return measures.units_of(im)


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


class UniformShearSpec(_Model):
    """A shear building of equal storeys (:meth:`rockstudy.motions.Building.uniform_shear`):
    ``n_storeys``, the first ``period`` [s] and the ``damping`` ratio of every mode."""

    n_storeys: int = Field(ge=1, le=MAX_STOREYS)
    period: float = Field(gt=0.0, le=100.0)
    damping: _Damping


#: The fields of a modal building (:class:`rockstudy.motions.Building`), in its order.
_MODAL_FIELDS = ("periods", "mode_shapes", "participation", "damping")


class BuildingSpec(_Model):
    """The linear building whose floor the records are felt on: either ``uniform_shear =
    { n_storeys, period, damping }`` or its modes, ``periods`` [s], ``mode_shapes`` (one list
    per mode: its value at floors 1..n), ``participation`` (one factor per mode) and
    ``damping`` (one ratio, or one per mode); see :class:`rockstudy.motions.Building`."""

    uniform_shear: UniformShearSpec | None = None
    periods: list[float] | None = None
    mode_shapes: list[list[float]] | None = None
    participation: list[float] | None = None
    damping: float | list[float] | None = None

    @model_validator(mode="after")
    def _one_form(self):
        given = [f for f in _MODAL_FIELDS if getattr(self, f) is not None]
        if self.uniform_shear is not None and given:
            raise FieldError(given[0], "give either uniform_shear = { ... } or the modes, not both")
        missing = [f for f in _MODAL_FIELDS if getattr(self, f) is None]
        if self.uniform_shear is None and missing:
            raise FieldError(
                missing[0],
                "is required: give uniform_shear = { n_storeys, period, damping } or the "
                f"modes {', '.join(_MODAL_FIELDS)}",
            )
        try:
            self.building()
        except ValueError as exc:
            field, _, rest = str(exc).partition(" ")
            raise FieldError(field, rest) if field in _MODAL_FIELDS else exc from None
        return self

    def building(self) -> Building:
        """The :class:`rockstudy.motions.Building` this table describes."""
        if self.uniform_shear is not None:
            u = self.uniform_shear
            return Building.uniform_shear(u.n_storeys, u.period, u.damping)
        return Building(self.periods, self.mode_shapes, self.participation, self.damping)


#: Units of a text record's acceleration column: those of an acceleration in the package's one
#: table of units (:func:`rockstudy.motions.units.acceleration_units`).
RECORD_UNITS = tuple(acceleration_units())


class RecordSpec(_Model):
    """Recorded motions: a suite of record files, each scaled, or left unscaled in a design.

    ``files`` is a folder (its ``.AT2``, ``.dat``, ``.txt`` and ``.csv`` files), a glob, or a
    list of files and ``{ horizontal = ..., vertical = ... }`` pairs. ``vertical`` gives the
    vertical components: a list as long as ``files`` (of plain files), or ``{ match, replace }``
    naming each vertical file after its horizontal one. Monte Carlo rows pick one record per
    sample (uniformly) and scale it, either by ``scale`` (a factor != 0; negative mirrors), to
    ``pga_ratio`` x a_up (the structure's uplift acceleration: g tan(alpha) of a block, g lambda
    of another structure, eq. 10 of [003]), or to ``scale_to``; a ``[design]`` runs every record.

    ``units`` is the unit of the acceleration column of text records (one of
    :data:`RECORD_UNITS`: ``g``, ``m/s2`` or ``m/s^2``, ``cm/s2``, ``cm/s^2`` or ``gal``);
    ``.AT2`` files are in g (PEER's format), and a
    suite of ``.AT2`` files alone with other units is refused.

    ``building`` (a :class:`BuildingSpec`) and ``floor`` (0 = the ground, to the building's
    top floor n) put the objects on a floor: every record is replaced by the absolute
    acceleration of that floor (:func:`rockstudy.motions.floor_motion`) before it is run. A
    design measures, scales and reports each record by its ground record's measures (those of
    the site's hazard curve: the building is linear, so the ground record scaled by s gives the
    floor motion scaled by s); Monte Carlo rows too (``pga_ratio`` and ``scale_to`` bring the
    ground record's measure to the target, and store its measures). A list of distinct
    floors (``floor = [1, 3, 5]``, a design only) is a dimension ``floor`` of the design:
    every design runs on every floor.

    ``h2 = { match, replace }`` names each record's second horizontal component (in the same
    folder, ``re.sub(match, replace, name)``; as ``load_suite(h2=)``): a design over
    ``orientations`` needs it.

    A path is absolute as written, or relative to the study file's folder (never to the
    working folder; see :func:`.feasibility.record_path`). Only regular text files up to 64 MiB
    are read. No record is skipped: every file named, matched or found must read.
    """

    kind: Literal["record"]
    files: Annotated[str, Field(min_length=1)] | Annotated[list[str | HVPair], Field(min_length=1)]
    vertical: list[str] | VerticalRule | None = None
    units: Literal[RECORD_UNITS] = "g"
    scale: Param | None = None
    pga_ratio: Param | None = None
    scale_to: ScaleTo | None = None
    building: BuildingSpec | None = None
    floor: int | list[int] | None = None
    h2: VerticalRule | None = None

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
        self._check_floor()
        return self

    def _check_floor(self) -> None:
        """``building`` and ``floor`` come together; ``floor`` is one floor in 0..n, or a
        list of distinct ones."""
        if (self.building is None) != (self.floor is None):
            given, other = ("building", "floor") if self.floor is None else ("floor", "building")
            raise FieldError(other, f"is required with {given} (the floor of the building)")
        if self.building is None:
            return
        floors = self.floors()
        if not floors or len(set(floors)) < len(floors):
            raise FieldError("floor", f"a list of floors must name distinct floors, got {floors}")
        top = self.building.building().n_floors
        for k in floors:
            if not 0 <= k <= top:
                raise FieldError("floor", f"must be in 0..{top} (0 = the ground), got {k}")

    def floors(self) -> list[int]:
        """The floors of the study (``[0]``, the ground, without a building)."""
        if self.floor is None:
            return [0]
        return list(self.floor) if isinstance(self.floor, list) else [self.floor]

    def floor_motion(self, record, floor=None):
        """``record`` as felt on ``floor`` (default: the study's one floor) of ``building``
        (the record itself without one; its ground record in ``metadata["ground"]``)."""
        if self.building is None:
            return record
        if floor is None:
            if isinstance(self.floor, list):
                raise ValueError(
                    "motion.floor: a list of floors is a dimension of a [design]; Monte Carlo "
                    "rows take one floor"
                )
            floor = self.floor
        return floor_motion(record, self.building.building(), floor)

    def target(self) -> ScaleTo | None:
        """The scaling target, with ``pga_ratio`` read as ``scale_to = { im = "pga_ratio" }``."""
        if self.pga_ratio is not None:
            return ScaleTo(im="pga_ratio", value=self.pga_ratio)
        return self.scale_to


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


MotionSpec = Annotated[PulseSpec | RecordSpec | StochasticSpec, Field(discriminator="kind")]
