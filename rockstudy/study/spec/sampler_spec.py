"""The ``[sampler]`` table of a study file, its kinds read from :data:`.samplers.SAMPLERS`."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from .parameters import _Model
from .samplers import SAMPLERS, kinds_laid_out
from .structures import FieldError

__all__ = ["SAMPLER_LAYOUTS", "SamplerSpec", "samplers_laid_out"]


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
