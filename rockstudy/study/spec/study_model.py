"""The whole study file: :class:`Study` assembles the sections and checks them together.

The sections are the models of :mod:`.structure_spec`, :mod:`.objects_spec`,
:mod:`.motion_spec`, :mod:`.sampler_spec`, :mod:`.design_spec`, :mod:`.hazard_spec` and
:mod:`.run_spec`; :class:`Study` adds the top-level keys and the checks that need more than
one section (a design needs records, a grid sampler grid parameters, the ratios' amplitudes
and periods must lie in the solvers' ranges, ...), and answers what the run needs of it
(its parameters, its rows, its canonical JSON). :func:`json_schema` is its JSON schema.
"""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np
from pydantic import BaseModel, Field, PrivateAttr, field_validator, model_validator

from ... import _validate
from ...constants import G
from ...motions import measures
from ...motions.pulses import PERIOD_RANGE
from ...structures.block import uplift_acceleration_block
from .design_kinds import design_kind
from .design_spec import DesignSpec
from .distributions import Distribution
from .feasibility import draw_span as _draw_span
from .friction_spec import Friction, as_pair, friction_pair, friction_value
from .hazard_spec import HazardSpec
from .motion_spec import MotionSpec
from .parameters import _a_name, _largest, _Model, _smallest
from .run_spec import CONTACT_OUTPUTS, SLIDE_OUTPUTS, STEPS_PER_CYCLE, RunSpec
from .sampler_spec import SAMPLER_LAYOUTS, SamplerSpec, samplers_laid_out
from .structure_spec import Structure
from .structures import KINDS, FieldError
from .two_body_spec import check_two_body

__all__ = ["MAX_CHUNK_SIZE", "Study", "json_schema"]


#: The largest chunk_size written (a count, as max_steps); a chunk holds min(chunk_size, n)
#: rows, at most :data:`.feasibility.MAX_CHUNK_ROWS` (checked with the design).
MAX_CHUNK_SIZE = 10**12


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
    #: The friction coefficient mu of the contact, or a pair [mu_s, mu_k] (per object in an
    #: objects list; :mod:`.friction_spec`): each scene then stores ``friction_demand`` and
    #: ``lift_off``, and the scenes whose demand exceeds mu_s (the block would slide) or that
    #: lift off are flagged, reported and warned about.
    friction: Friction | None = None
    #: The study file's text as read (None for a study not read from text).
    _text: str | None = PrivateAttr(default=None)
    #: What will happen that the user should know before the run (not a problem): e.g. the
    #: points of a design that free fall censors (:func:`.feasibility.notes`).
    _notes: list = PrivateAttr(default_factory=list)

    _printable = field_validator("name")(lambda value: _a_name(value))
    _pair = field_validator("friction", mode="before")(lambda value: as_pair(value))
    _friction = field_validator("friction")(lambda value: friction_value(value))

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
        (``friction_demand`` and ``lift_off`` join ``run.outputs``), and with
        ``run.model = "contact"`` or ``"auto"`` the contact model's slip and regimes
        (:data:`.run_spec.SLIDE_OUTPUTS`)."""
        if not (isinstance(data, dict) and data.get("friction") is not None):
            return data
        run = data.get("run", {})
        if data.get("design") is not None or not isinstance(run, dict):
            return data
        outputs = run.get("outputs", RunSpec.model_fields["outputs"].default)
        if not isinstance(outputs, list):
            return data  # the schema names the problem
        added = CONTACT_OUTPUTS + (SLIDE_OUTPUTS if run.get("model") in ("contact", "auto") else ())
        missing = [n for n in added if n not in outputs]
        return {**data, "run": {**run, "outputs": list(outputs) + missing}}

    @model_validator(mode="after")
    def _two_body(self):
        """What two-body objects cannot ask (:func:`.two_body_spec.check_two_body`)."""
        check_two_body(self)
        return self

    @model_validator(mode="after")
    def _contact_model(self):
        """``run.model = "contact"`` or ``"auto"`` needs the friction of every scene (the
        study's ``friction``, or each object's), in a Monte Carlo study or any record
        design; ``design.slide_limits`` needs it."""
        model = self.run.model
        if model == "rocking":
            if self.design is not None and self.design.slide_limits:
                raise FieldError(
                    "design.slide_limits",
                    "needs the contact model's max_slide: give [run] model = 'contact' or "
                    "'auto' (with friction)",
                )
            if self.design is not None:
                self.design.slide_states_need_contact()
            return self
        self._contact_structures()
        mu = self.friction_coefficients()
        if mu is None or np.isnan(mu).any():
            raise FieldError(
                "run.model",
                f"{model!r} runs the contact model, which needs the friction coefficient mu of "
                "every scene: give friction (top level, or per object), or model = 'rocking'",
            )
        return self

    def _contact_structures(self):
        """The contact model is of a rectangular block on its base: a FieldError naming the
        structure (or the object) of another kind, whose equivalent block has no base that
        slides."""
        st = self.structure
        if st.kind == "objects":
            others = [(f"object {o.name!r}", o.kind) for o in st.objects if o.kind != "block"]
        else:
            others = [("structure.kind", st.kind)] if st.kind != "block" else []
        if others:
            who, kind = others[0]
            raise FieldError(
                "run.model",
                f"{self.run.model!r} runs the contact model of a rectangular block on a base "
                f"with friction; {who} is a {kind} (its equivalent block has no such base): "
                "give model = 'rocking', or leave it out of the study",
            )

    def friction_coefficients(self) -> np.ndarray | None:
        """The (static) friction coefficient mu_s of each object (NaN where none is given),
        the study's ``friction`` for sampled structures; None when no friction is given
        anywhere. The friction check and ``"auto"``'s choice compare the demand with it."""
        pairs = self.friction_pairs()
        return None if pairs is None else pairs[0]

    def friction_pairs(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(mu_s, mu_k) of each object (NaNs where none is given; :meth:`friction_coefficients`
        for which), each array as long as that method's; None when no friction is given."""
        st = self.structure
        if st.kind == "objects":
            pairs = [o.friction_pair(self.friction) for o in st.objects]
        else:
            pairs = [friction_pair(self.friction)]
        static, kinetic = (np.array(c, float) for c in zip(*pairs, strict=True))
        return None if np.isnan(static).all() else (static, kinetic)

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
    def _pair_measures(self):
        """A measure of a pair of horizontal components (RotD50, ...) needs records of two."""
        for field, im in self._measure_fields():
            if measures.measure(im).needs_pair and getattr(self.motion, "h2", None) is None:
                raise FieldError(
                    field,
                    f"{im!r} is a measure of two horizontal components, but the records have "
                    "one: give motion.h2 = { match = '<regex>', replace = '<replacement>' } "
                    "naming each record's second one",
                )
        return self

    def _measure_fields(self) -> list[tuple[str, str]]:
        """(field, measure) of the study's intensity measures: ``design.im`` of an IDA,
        ``motion.scale_to.im`` (a ratio's base measure) and ``hazard.im``."""
        out = []
        if self.design is not None and design_kind(self.design.kind).capacities:
            out.append(("design.im", self.design.ida().im))
        target = getattr(self.motion, "scale_to", None)
        if target is not None:
            out.append(("motion.scale_to.im", target.im))
        if self.hazard is not None:
            out.append(("hazard.im", self.hazard.im))
        return [(f, measures.target(im, f).name) for f, im in out]

    @model_validator(mode="after")
    def _floor_list(self):
        """A list of floors is a dimension of a record design only."""
        if isinstance(getattr(self.motion, "floor", None), list) and self.design is None:
            raise FieldError(
                "motion.floor", "a list of floors needs a [design]; Monte Carlo rows take one"
            )
        if self.design is not None and self.design.orientations is not None:
            if getattr(self.motion, "h2", None) is None:
                raise FieldError(
                    "design.orientations",
                    "needs records of two horizontal components: give motion.h2 = { match = "
                    "'<regex>', replace = '<replacement>' } naming each record's second one",
                )
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
        if measures.measure(hz.im).needs_period:
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


def json_schema() -> dict:
    """The JSON schema of study files."""
    return Study.model_json_schema()
