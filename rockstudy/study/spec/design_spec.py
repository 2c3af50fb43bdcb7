"""The ``[design]`` table of a study file: a record design (cloud, stripes or IDA).

Its IDA options are checked, and filled in, by :class:`.ida_options.IdaOptions`; a design's
fit with the motion and the sampler is checked by the whole study
(:class:`.study_model.Study`).
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from .damage_states import damage_states
from .design_kinds import DESIGN_KINDS, design_kind
from .feasibility import DEFAULT_MAX_SCALE_FACTOR
from .ida_options import IdaOptionError, IdaOptions
from .motion_spec import ScaleIM, _check_period
from .parameters import _Damping, _Model, _Period
from .structures import FieldError

__all__ = ["DesignSpec"]

#: Most orientations of a design (``design.orientations``).
MAX_ORIENTATIONS = 360
#: Largest slide limit taken [m] (``design.slide_limits``).
MAX_SLIDE_LIMIT = 100.0
#: A slide limit d [m] of ``design.slide_limits``.
_SlideLimit = Annotated[float, Field(gt=0.0, le=MAX_SLIDE_LIMIT)]


class DesignSpec(_Model):
    """A record design over records x structures (``sampler.n`` structures drawn by the
    sampler) [x levels]: ``cloud`` (records unscaled), ``stripes`` (every record scaled to
    each level of ``motion.scale_to.value``, a grid), or ``ida`` (the first overturning
    intensity of each structure under each record in ``im``, by a ladder of ``step`` refined
    by bisection to ``tolerance``; ``max_pga_ratio`` and ``scan`` as in
    :class:`rockstudy.study.spec.ida_options.IdaOptions`, which holds their defaults and
    ranges). ``periods`` [s] are those of the spectral accelerations ``sa`` stored for every
    record, ``damping`` their damping ratio. ``slide_limits`` [m] are the slides d of the
    fragility of sliding, P(max_slide > d) (the contact model's ``max_slide``: with
    ``run.model`` "contact" or "auto"), distinct and increasing. ``orientations`` (n, for the
    n angles k pi / n in [0, pi), or a list of angles [rad]) runs every record along each
    orientation psi of the objects' rocking plane, a_x cos(psi) + a_y sin(psi)
    (:meth:`rockstudy.motions.Record.oriented`): a dimension ``orientation`` of the design,
    whose records need two horizontal components (``motion.h2``). ``damage_states``
    ``{name = limit}`` are the damage states short of overturning
    (:mod:`rockstudy.study.spec.damage_states`): a limit on the peak rotation ratio
    abs(theta)/alpha in (0, 1] (1 = overturning), or ``{slide = d}`` on the peak slide [m]
    (with the contact model)."""

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
    slide_limits: list[_SlideLimit] = Field(default=[], max_length=100)
    #: The orientations psi [rad] of the objects' rocking plane (:meth:`angles`): a dimension
    #: ``orientation`` of the design; each record then needs two horizontal components.
    orientations: int | list[float] | None = None
    damage_states: dict[str, Any] = Field(default={}, max_length=100)

    @model_validator(mode="after")
    def _orientations(self):
        o = self.orientations
        if o is None:
            return self
        if isinstance(o, int) and not 1 <= o <= MAX_ORIENTATIONS:
            raise FieldError(
                "orientations", f"must be a number of angles in 1..{MAX_ORIENTATIONS}, got {o}"
            )
        if isinstance(o, list):
            if not 1 <= len(o) <= MAX_ORIENTATIONS or len(set(o)) < len(o):
                raise FieldError(
                    "orientations",
                    f"a list must hold 1..{MAX_ORIENTATIONS} distinct angles [rad], got {o}",
                )
            if not all(math.isfinite(a) for a in o):
                raise FieldError("orientations", f"the angles [rad] must be finite, got {o}")
        return self

    def angles(self):
        """The orientations psi [rad] of the design: n equally spaced in [0, pi)
        (``orientations = n``: k pi / n) or the list given; None without ``orientations``."""
        o = self.orientations
        if o is None:
            return None
        return np.pi * np.arange(o) / o if isinstance(o, int) else np.array(o, float)

    @model_validator(mode="after")
    def _damage_states(self):
        try:  # the contact model a slide state needs is checked by the study
            self.states()
        except ValueError as exc:
            raise FieldError("damage_states", str(exc).partition(": ")[2]) from None
        return self

    @model_validator(mode="after")
    def _increasing_slide_limits(self):
        d = self.slide_limits
        if any(b <= a for a, b in zip(d[:-1], d[1:], strict=True)):
            raise FieldError("slide_limits", f"must be distinct and increasing [m], got {d}")
        return self

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

    def states(self, contact: bool = True) -> tuple:
        """The damage states (:func:`.damage_states.damage_states`); ``contact``: whether
        the contact model runs (a slide state needs it)."""
        return damage_states(self.damage_states, model=contact)

    def slide_states_need_contact(self) -> None:
        """A FieldError naming ``design.damage_states`` if a state is on the slide (the
        contact model's max_slide, which Housner's model does not give)."""
        try:
            self.states(contact=False)
        except ValueError as exc:
            raise FieldError("design.damage_states", str(exc).partition(": ")[2]) from None

    def ida(self) -> IdaOptions:
        """The IDA's options (defaults filled in)."""
        return IdaOptions.given(self.model_dump())

    def ida_options(self) -> dict:
        """Keyword arguments of the IDA (defaults filled in)."""
        return asdict(self.ida())
