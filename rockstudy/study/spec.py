"""Study files: a TOML declaration of parameter distributions, validated by pydantic v2.

A study names a structure, a motion, a sampler and what to compute. Every parameter is either a
number or a distribution (a table with ``dist = ...``). Unknown keys are errors, so a typo
never passes silently; :func:`validate_text` reports every problem with the field it is in.

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

import hashlib
import json
import math
import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .distributions import Distribution

Param = float | Distribution


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def _check_positive(name, value):
    """A fixed parameter must be > 0; a distribution must have positive support."""
    if isinstance(value, (int, float)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be > 0, got {value}")
    elif value is not None and not value.support_positive():
        raise ValueError(f"{name}: the distribution must only give values > 0")


class BlockSpec(_Model):
    """A rectangular block: half-diagonal R [m], slenderness alpha [rad], restitution eta."""

    kind: Literal["block"]
    half_diagonal: Param
    slenderness: Param
    restitution: Param | Literal["housner"] = "housner"

    @model_validator(mode="after")
    def _ranges(self):
        _check_positive("half_diagonal", self.half_diagonal)
        _within("slenderness", self.slenderness, 0.0, math.pi / 2, "(0, pi/2) rad")
        if self.restitution != "housner":
            _within("restitution", self.restitution, 0.0, 1.0 + 1e-15, "(0, 1]")
        return self


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
        _check_positive("half_diagonal", self.half_diagonal)
        _within("slenderness", self.slenderness, 0.0, math.pi / 4, "(0, pi/4) rad")
        _within("restitution", self.restitution, 0.0, 1.0 + 1e-15, "(0, 1]")
        return self


class EquivalentBlockSpec(_Model):
    """Any structure by its rocking parameters: p [rad/s], theta_cr [rad], eta."""

    kind: Literal["equivalent_block"]
    frequency_parameter: Param
    critical_rotation: Param
    restitution: Param

    @model_validator(mode="after")
    def _ranges(self):
        _check_positive("frequency_parameter", self.frequency_parameter)
        _within("critical_rotation", self.critical_rotation, 0.0, math.pi / 2, "(0, pi/2) rad")
        _within("restitution", self.restitution, 0.0, 1.0 + 1e-15, "(0, 1]")
        return self


def _within(name, value, low, high, label):
    if isinstance(value, (int, float)):
        if not (low < value < high):
            raise ValueError(f"{name} must lie in {label}, got {value}")
    elif not value.support_within(low, high):
        raise ValueError(f"{name}: the distribution must only give values in {label}")


class PulseSpec(_Model):
    """An analytic pulse. Give the amplitude in m/s^2 (``amplitude``), as a multiple of the
    uplift acceleration g tan(alpha) (``amplitude_ratio``, the groups of eqs. 5.3 and 6.1 of
    [000]) or of g alpha (``amplitude_a``, a of eq. 3.6: the groups of 4.10 and 4.11), and the
    period in seconds (``period``) or as omega_g / p (``frequency_ratio``)."""

    kind: Literal["pulse"]
    shape: Literal["sine", "cosine", "half-sine", "ricker"] = "sine"
    cycles: int = Field(default=1, ge=1)
    amplitude: Param | None = None
    amplitude_ratio: Param | None = None
    amplitude_a: Param | None = None
    period: Param | None = None
    frequency_ratio: Param | None = None
    direction: Literal[1, -1] = 1

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
        if self.cycles != 1 and self.shape not in ("sine", "cosine"):
            raise ValueError(f"cycles applies to sine and cosine pulses, not {self.shape}")
        return self


class RecordSpec(_Model):
    """Recorded motions, each sample picking one of ``files`` (uniformly) and scaling it,
    either by ``scale`` or to a peak ground acceleration ``pga_ratio`` x g tan(alpha)."""

    kind: Literal["record"]
    files: list[str] = Field(min_length=1)
    units: Literal["g", "m/s2", "cm/s2"] = "g"
    scale: Param | None = None
    pga_ratio: Param | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.scale is None) == (self.pga_ratio is None):
            raise ValueError("give exactly one of scale or pga_ratio")
        if self.pga_ratio is not None:
            _check_positive("pga_ratio", self.pga_ratio)
        return self


class StochasticSpec(_Model):
    """Kanai-Tajimi filtered white noise; every sample draws its own seeded record."""

    kind: Literal["stochastic"]
    pga_ratio: Param
    duration: float = Field(default=20.0, gt=0)
    dt: float = Field(default=0.01, gt=0)
    ground_frequency: float = Field(default=5 * math.pi, gt=0)
    ground_damping: float = Field(default=0.6, gt=0)

    @model_validator(mode="after")
    def _ranges(self):
        _check_positive("pga_ratio", self.pga_ratio)
        return self


class SamplerSpec(_Model):
    """Monte Carlo, Latin hypercube, Sobol' (Saltelli layout, n = 2^k) or a full grid."""

    kind: Literal["monte_carlo", "lhs", "sobol", "grid"]
    n: int | None = Field(default=None, ge=1)
    second_order: bool = False
    replicates: int = Field(default=1, ge=1)

    @model_validator(mode="after")
    def _n(self):
        if self.kind == "grid":
            if self.n is not None:
                raise ValueError("a grid takes its size from the grid parameters; remove n")
        elif self.n is None:
            raise ValueError(f"sampler {self.kind!r} needs n")
        elif self.kind == "sobol" and self.n & (self.n - 1):
            raise ValueError(f"sobol needs n = 2^k, got {self.n}")
        if self.second_order and self.kind != "sobol":
            raise ValueError("second_order applies to the sobol sampler only")
        if self.replicates > 1 and self.kind not in ("monte_carlo", "lhs"):
            raise ValueError("replicates applies to the monte_carlo and lhs samplers")
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
]


class RunSpec(_Model):
    """The solver and what to keep."""

    method: Literal["nonlinear", "linear", "auto"] = "nonlinear"
    rtol: float = Field(default=1e-8, gt=0, lt=1)  # for "auto": accuracy of the max rotation
    max_steps: int = Field(default=1_000_000, ge=1)
    outputs: list[Output] = Field(default=["max_rotation", "overturned"], min_length=1)

    @model_validator(mode="after")
    def _unique(self):
        if len(set(self.outputs)) != len(self.outputs):
            raise ValueError("outputs lists a name twice")
        return self


Structure = Annotated[BlockSpec | WallSpec | EquivalentBlockSpec, Field(discriminator="kind")]
MotionSpec = Annotated[PulseSpec | RecordSpec | StochasticSpec, Field(discriminator="kind")]


class Study(_Model):
    """A whole study file."""

    name: str = Field(min_length=1)
    description: str = ""
    seed: int = Field(ge=0)
    chunk_size: int = Field(default=4096, ge=1)
    sampler: SamplerSpec
    structure: Structure
    motion: MotionSpec
    run: RunSpec = RunSpec()

    @model_validator(mode="after")
    def _grid(self):
        grid_params = [n for n, d in self.parameters().items() if d.dist == "grid"]
        if self.sampler.kind == "grid":
            if not grid_params:
                raise ValueError("a grid sampler needs at least one parameter with dist = 'grid'")
            others = [n for n, d in self.parameters().items() if d.dist != "grid"]
            if others:
                raise ValueError(f"a grid sampler takes only grid parameters; {others} are not")
        elif grid_params:
            raise ValueError(f"{grid_params} use dist = 'grid', which needs sampler.kind = 'grid'")
        if self.sampler.kind == "sobol" and len(self.parameters()) < 2:
            raise ValueError("sobol needs at least two distributed parameters")
        if self.sampler.replicates > 1:
            mo, st = self.motion, self.structure
            if mo.kind != "pulse" or mo.amplitude is not None or mo.period is not None:
                raise ValueError(
                    "replicates need a pulse given by its groups: amplitude_ratio "
                    "or amplitude_a, and frequency_ratio"
                )
            if st.kind != "block" or st.restitution == "housner":
                raise ValueError(
                    "replicates need a block with a given restitution (Housner's "
                    "depends on alpha, which would change the groups)"
                )
        return self

    def group_parameters(self) -> list[str]:
        """Distributed parameters that are dimensionless groups (held fixed across the
        replicates of a group point): the pulse's ratios and the restitution."""
        names = ("amplitude_ratio", "amplitude_a", "frequency_ratio", "restitution")
        return [n for n in self.parameters() if n in names]

    def parameters(self) -> dict[str, Distribution]:
        """The distributed parameters, in design order (structure, then motion)."""
        out = {}
        for part in (self.structure, self.motion):
            for name in type(part).model_fields:
                value = getattr(part, name)
                if isinstance(value, BaseModel) and hasattr(value, "dist"):
                    out[name] = value
        return out

    def normalized(self) -> str:
        """Canonical JSON of the study (defaults filled in), as stored in result cubes."""
        return json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))

    def sha256(self) -> str:
        """sha256 of :meth:`normalized`."""
        return hashlib.sha256(self.normalized().encode()).hexdigest()


def _format_errors(err: ValidationError) -> list[str]:
    lines = []
    for e in err.errors():
        loc = ".".join(str(x) for x in e["loc"] if not str(x).startswith("function-after"))
        lines.append(f"{loc or '(top level)'}: {e['msg']}")
    return lines


class StudyError(ValueError):
    """A study file that does not validate; ``problems`` lists one line per field."""

    def __init__(self, source, problems):
        self.problems = problems
        super().__init__(f"{source}: {len(problems)} problem(s)\n  " + "\n  ".join(problems))


def validate_text(text: str, source: str = "<study>") -> Study:
    """Parse and validate a study from TOML text; raise :class:`StudyError` listing problems."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(source, [f"not valid TOML: {exc}"]) from None
    try:
        return Study.model_validate(data)
    except ValidationError as exc:
        raise StudyError(source, _format_errors(exc)) from None


def load_study(path) -> Study:
    """Read and validate a study file."""
    path = Path(path)
    return validate_text(path.read_text(), str(path))


def json_schema() -> dict:
    """The JSON schema of study files."""
    return Study.model_json_schema()
