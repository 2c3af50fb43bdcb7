"""The contact model is of a rectangular block on a base with friction: a study that asks it
of another structure kind (a wall, a frame: their equivalent block has no base that slides)
is refused before it runs, naming the field; a block (and objects that are all blocks) is
taken."""

import numpy as np
import pytest
from _helpers import write_at2

from rockstudy.motions import Record
from rockstudy.study import validate_text

WALL = "half_diagonal = 1.0\nslenderness = 0.1\nrestitution = 0.9"
SAMPLED = """
name = "contact_kinds"
seed = 1
friction = 0.5
[structure]
kind = "{kind}"
{fields}
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = 2.0
period = 0.5
[sampler]
kind = "monte_carlo"
n = 2
[run]
model = "{model}"
"""

OBJECTS = """
name = "contact_objects"
seed = 1
friction = 0.5
[structure]
kind = "objects"
objects = [
  {{ name = "Statue", width = 0.4, height = 1.6 }},
  {{ name = "Wall <1>", kind = "{kind}", half_diagonal = 1.0, slenderness = 0.1{extra} }},
]
[motion]
kind = "record"
files = "quake.AT2"
[design]
kind = "cloud"
[run]
model = "{model}"
"""


def _text(template, kind, model):
    if template is SAMPLED:
        fields = WALL if kind == "rocking_wall" else "half_diagonal = 1.0\nslenderness = 0.2"
        return SAMPLED.format(kind=kind, fields=fields, model=model)
    extra = ", restitution = 0.9" if kind == "rocking_wall" else ""
    return OBJECTS.format(kind=kind, extra=extra, model=model)


@pytest.fixture
def folder(tmp_path):
    t = np.arange(0.0, 2.0, 0.01)
    write_at2(tmp_path / "quake.AT2", Record(3.0 * np.sin(2 * np.pi * t), time=t))
    return tmp_path


@pytest.mark.parametrize("model", ["contact", "auto"])
@pytest.mark.parametrize("template", [SAMPLED, OBJECTS])
def test_the_contact_model_of_a_wall_is_refused_naming_the_field(template, model, folder):
    with pytest.raises(ValueError) as err:
        validate_text(_text(template, "rocking_wall", model), base_dir=folder)
    message = str(err.value)
    assert "run.model" in message and "rocking_wall" in message and "rectangular block" in message


@pytest.mark.parametrize("template", [SAMPLED, OBJECTS])
def test_the_contact_model_of_blocks_is_taken(template, folder):
    study = validate_text(_text(template, "block", "auto"), base_dir=folder)
    assert study.run.model == "auto" and study.structure.kind in ("block", "objects")
