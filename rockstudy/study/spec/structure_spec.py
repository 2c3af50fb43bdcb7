"""The ``[structure]`` table of a study file: a block, a rocking wall or an equivalent block.

Each sampled kind's fields are numbers or distributions checked over their whole support
against the ranges of its entry in :data:`.structures.KINDS` (Housner's restitution, when it is
derived, against the slenderness where it stays in (0, 1]). :data:`Structure` is the union of
the kinds, with the named objects of :mod:`.objects_spec`, told apart by ``kind``.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, model_validator

from ...structures.block import FREQUENCY_PARAMETER_RANGE, HALF_DIAGONAL_RANGE, MIN_SLENDERNESS
from .objects_spec import ObjectsSpec
from .parameters import Param, _check_positive, _largest, _Model, _Restitution, _span, _within
from .structures import KINDS, FieldError, check_all

__all__ = ["HOUSNER_MAX_SLENDERNESS", "BlockSpec", "EquivalentBlockSpec", "Structure", "WallSpec"]


#: Housner's restitution 1 - 1.5 sin^2(alpha), eq. (2.4) of [000], is > 0 only below this
#: slenderness [rad] (sin^2 alpha = 2/3).
HOUSNER_MAX_SLENDERNESS = math.asin(math.sqrt(2.0 / 3.0))
_R_LABEL = "[{:g}, {:g}] m".format(*HALF_DIAGONAL_RANGE)
_ALPHA_LABEL = f"[{MIN_SLENDERNESS:g}, pi/2) rad"


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


Structure = Annotated[
    BlockSpec | WallSpec | EquivalentBlockSpec | ObjectsSpec, Field(discriminator="kind")
]
