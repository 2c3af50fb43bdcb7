"""The ``[run]`` table of a study file: the solver, its tolerance and step budget, the outputs."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from ... import _validate
from ...dynamics import outputs as _outputs
from ...dynamics.methods import MAX_STEPS
from .parameters import _Model
from .structures import FieldError

__all__ = ["CONTACT_OUTPUTS", "MIN_RTOL", "STEPS_PER_CYCLE", "Output", "RunSpec"]


#: The outputs a study may keep: :data:`rockstudy.dynamics.outputs.STUDY_OUTPUTS`.
Output = Literal[_outputs.STUDY_OUTPUTS]
#: The outputs a study's ``friction`` adds (the contact check of
#: :func:`rockstudy.simulate_batch`).
CONTACT_OUTPUTS = _outputs.names("contact")
#: The outputs ``model = "contact"`` or ``"auto"`` adds (the slip and the regimes of the
#: contact model, :func:`rockstudy.simulate_batch`'s ``model``).
SLIDE_OUTPUTS = _outputs.names("contact_model")


#: Smallest relative tolerance taken: that of the solvers (:data:`rockstudy._validate.RTOL_MIN`,
#: where their error target stops drowning in rounding).
MIN_RTOL = _validate.RTOL_MIN
#: Solver steps per cycle of a rocking block under a sine or cosine pulse: at most 322 in
#: 200 random blocks and pulses at rtol 1e-8 (median 14), rounded up.
STEPS_PER_CYCLE = 400


class RunSpec(_Model):
    """The solver and what to keep."""

    method: Literal["nonlinear", "linear", "auto"] = "nonlinear"
    #: The model of every scene (:func:`rockstudy.simulate_batch`'s ``model``): Housner's
    #: no-slip block ("rocking"), the planar contact model ("contact", with the study's
    #: ``friction``), or Housner's with the contact model on the scenes whose friction
    #: demand exceeds mu or that lift off ("auto").
    model: Literal["rocking", "contact", "auto"] = "rocking"
    rtol: float = Field(default=1e-8, gt=0, lt=1)  # for "auto": accuracy of the max rotation
    max_steps: int = Field(default=MAX_STEPS, ge=1, le=_validate.MAX_STEPS_MAX)
    outputs: list[Output] = Field(default=["max_rotation", "overturned"], min_length=1)

    @model_validator(mode="after")
    def _unique(self):
        if len(set(self.outputs)) != len(self.outputs):
            raise FieldError("outputs", "lists a name twice")
        slides = [name for name in self.outputs if name in SLIDE_OUTPUTS]
        if slides and self.model == "rocking":
            raise FieldError(
                "outputs",
                f"{', '.join(slides)} come from the contact model: give model = 'contact' or "
                "'auto' (with the study's friction)",
            )
        if self.model == "contact" and self.method == "linear":
            raise FieldError(
                "method",
                "'linear' does not apply with model = 'contact' (the contact model runs every "
                "scene): give 'nonlinear' or 'auto'",
            )
        if self.rtol < MIN_RTOL:  # scipy's solve_ivp raises smaller ones to this floor
            raise FieldError(
                "rtol",
                f"must be >= {MIN_RTOL:.2g}: below it the solvers' error target drowns in "
                f"rounding, got {self.rtol:g}",
            )
        return self
