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
