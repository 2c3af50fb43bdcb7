"""The study schema by section: each section module names its models, and ``schema`` all of them.

``rockstudy.study.spec.schema`` reads and validates a study file; the models live in one module
per section of the file. Code written against ``schema`` keeps working: every public name of a
section module is a name of ``schema`` too, and is the same object.
"""

import ast
import importlib
import inspect
from pathlib import Path

import pytest

SPEC = Path(__file__).resolve().parents[1] / "rockstudy" / "study" / "spec"
SECTIONS = (
    "parameters",
    "structure_spec",
    "objects_spec",
    "motion_spec",
    "sampler_spec",
    "design_spec",
    "hazard_spec",
    "run_spec",
    "study_model",
    "messages",
)


def _module(name):
    return importlib.import_module(f"rockstudy.study.spec.{name}")


@pytest.mark.parametrize("name", SECTIONS)
def test_a_section_module_says_what_it_holds(name):
    """A module docstring, and an ``__all__`` of names the module itself defines (not names
    it imports from another section)."""
    tree = ast.parse((SPEC / f"{name}.py").read_text())
    assert ast.get_docstring(tree), f"{name} has no module docstring"
    module = _module(name)
    defined = [getattr(module, n) for n in module.__all__]
    defined = [x for x in defined if inspect.isclass(x) or inspect.isfunction(x)]
    assert [x.__name__ for x in defined if x.__module__ != module.__name__] == []


@pytest.mark.parametrize("name", [s for s in SECTIONS if s != "messages"])
def test_schema_names_every_public_name_of_a_section(name):
    from rockstudy.study.spec import schema

    module = _module(name)
    assert module.__all__, f"{name} exports nothing"
    missing = [n for n in module.__all__ if n not in schema.__all__]
    assert not missing, f"schema.__all__ lacks {missing} of {name}"
    assert all(getattr(schema, n) is getattr(module, n) for n in module.__all__)


def test_a_study_validated_through_schema_is_the_section_models():
    """A study read by ``schema.validate_text`` is made of the section modules' classes."""
    from rockstudy.study.spec import schema

    study = schema.validate_text(
        'name = "t"\nseed = 1\n[sampler]\nkind = "monte_carlo"\nn = 4\n'
        '[structure]\nkind = "block"\nhalf_diagonal = 1.0\nslenderness = 0.2\n'
        '[motion]\nkind = "pulse"\namplitude_ratio = 2.0\nperiod = 0.5\n'
    )
    assert type(study) is _module("study_model").Study
    assert type(study.structure) is _module("structure_spec").BlockSpec
    assert type(study.motion) is _module("motion_spec").PulseSpec
    assert type(study.sampler) is _module("sampler_spec").SamplerSpec
    assert type(study.run) is _module("run_spec").RunSpec
