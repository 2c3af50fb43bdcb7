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

The models are split by the file's sections: :mod:`.parameters` (the strict model, a parameter
and the checks of its span), :mod:`.structure_spec` and :mod:`.objects_spec` (``[structure]``),
:mod:`.motion_spec` (``[motion]``), :mod:`.sampler_spec`, :mod:`.design_spec`,
:mod:`.hazard_spec`, :mod:`.run_spec`, and :mod:`.study_model` (:class:`Study`, the whole file);
:mod:`.messages` words pydantic's errors. This module reads and validates a study file and
names every model again, so ``rockstudy.study.spec.schema`` gives them all.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from pydantic import ValidationError

from ...dynamics.simulate import MAX_FRICTION
from .design_spec import DesignSpec
from .distributions import Distribution
from .feasibility import notes, problems
from .hazard_spec import HazardSpec, _read_hazard_file
from .ida_options import IdaOptionError
from .messages import _format_errors
from .motion_spec import (
    MAX_SCALE,
    MIN_SCALE,
    RECORD_UNITS,
    BuildingSpec,
    HVPair,
    MotionSpec,
    PulseSpec,
    RecordSpec,
    ScaleIM,
    ScaleTo,
    StochasticSpec,
    UniformShearSpec,
    VerticalRule,
    scale_units,
)
from .objects_spec import OBJECT_COLUMNS, OBJECT_KINDS, ObjectSpec, ObjectsSpec, _read_objects_file
from .parameters import MAX_RATIO, MAX_STUDY_BYTES, MIN_RATIO, Param
from .run_spec import CONTACT_OUTPUTS, MIN_RTOL, STEPS_PER_CYCLE, Output, RunSpec
from .sampler_spec import SAMPLER_LAYOUTS, SamplerSpec, samplers_laid_out
from .structure_spec import (
    HOUSNER_MAX_SLENDERNESS,
    BlockSpec,
    EquivalentBlockSpec,
    Structure,
    WallSpec,
)
from .structures import FieldError
from .study_model import MAX_CHUNK_SIZE, Study, json_schema

__all__ = [
    "CONTACT_OUTPUTS",
    "HOUSNER_MAX_SLENDERNESS",
    "MAX_CHUNK_SIZE",
    "MAX_DEPTH",
    "MAX_FRICTION",
    "MAX_RATIO",
    "MAX_SCALE",
    "MAX_STUDY_BYTES",
    "MIN_RATIO",
    "MIN_RTOL",
    "MIN_SCALE",
    "OBJECT_COLUMNS",
    "OBJECT_KINDS",
    "SAMPLER_LAYOUTS",
    "STEPS_PER_CYCLE",
    "BlockSpec",
    "BuildingSpec",
    "DesignSpec",
    "Distribution",
    "EquivalentBlockSpec",
    "FieldError",
    "HVPair",
    "HazardSpec",
    "IdaOptionError",
    "MotionSpec",
    "ObjectSpec",
    "ObjectsSpec",
    "Output",
    "Param",
    "PulseSpec",
    "RECORD_UNITS",
    "RecordSpec",
    "RunSpec",
    "SamplerSpec",
    "ScaleIM",
    "ScaleTo",
    "StochasticSpec",
    "Structure",
    "Study",
    "StudyError",
    "UniformShearSpec",
    "VerticalRule",
    "WallSpec",
    "json_schema",
    "load_study",
    "samplers_laid_out",
    "scale_units",
    "validate_text",
]


class StudyError(ValueError):
    """A study file that does not validate; ``problems`` lists one line per field."""

    def __init__(self, source, problems):
        self.problems = problems
        super().__init__(f"{source}: {len(problems)} problem(s)\n  " + "\n  ".join(problems))


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


def load_study(path) -> Study:
    """Read and validate a study file; its relative record paths are relative to its folder."""
    from ...motions.records import read_text_file

    path = Path(path)
    try:
        text = read_text_file(path, MAX_STUDY_BYTES)
    except (OSError, ValueError) as exc:
        raise StudyError(str(path), [str(exc)]) from None
    return validate_text(text, str(path), base_dir=path.resolve().parent)
