"""``[design] damage_states`` of a study file: the states a design reads, and the refusals
(one problem at the CLI naming ``design.damage_states``, the state and what is allowed)."""

import pytest
from _helpers import cli, write_at2

import rockstudy as rs

STUDY = """
name = "museum_states"
seed = 1
friction = 0.8
[structure]
kind = "objects"
file = "objects.csv"
[motion]
kind = "record"
files = "{folder}"
[design]
kind = "cloud"
damage_states = {states}
[run]
model = "{model}"
"""
OBJECTS_CSV = "name,half_diagonal,slenderness\nStatue,1.0,0.15\n"
GOOD = "{chipped = 0.2, fall_off = {slide = 0.1}, overturned = 1.0}"


def _study(tmp_path, states=GOOD, model="auto"):
    folder = tmp_path / "records"
    folder.mkdir(exist_ok=True)
    rec = rs.motions.synthetic_near_fault(pulse_period=0.5, pga=2.5, seed=1, duration=2.0)
    write_at2(folder / "r0.AT2", rec)
    (tmp_path / "objects.csv").write_text(OBJECTS_CSV)
    path = tmp_path / "museum.toml"
    path.write_text(STUDY.format(folder=folder, states=states, model=model))
    return path


def test_a_study_reads_its_damage_states_in_order(tmp_path):
    from rockstudy.study import load_study

    states = load_study(_study(tmp_path)).design.states()
    assert [(s.name, s.demand, s.limit) for s in states] == [
        ("chipped", "rotation_ratio", 0.2),
        ("fall_off", "slide", 0.1),
        ("overturned", "rotation_ratio", 1.0),
    ]


@pytest.mark.parametrize(
    ("states", "model", "words"),
    [
        ("{chipped = 1.5}", "auto", "the state 'chipped' has the limit 1.5: give a rotation"),
        ("{chipped = -0.2}", "auto", "in (0, 1]"),
        ('{chipped = "half"}', "auto", "the state 'chipped' has the limit 'half'"),
        ("{fall = {slide = 0.0}}", "auto", "the state 'fall' has the slide 0.0"),
        ("{fall = {slip = 0.1}}", "auto", "has keys ['slip']"),
        ("{Chipped = 0.2, chipped = 0.3}", "auto", "'Chipped' and 'chipped' clash"),
        ("{a = 0.5, b = 0.5}", "auto", "the same limit"),
        (GOOD, "rocking", "on the slide need the contact model"),
    ],
)
def test_bad_damage_states_are_refused_in_one_line_naming_the_field(tmp_path, states, model, words):
    code, _, err = cli("validate", _study(tmp_path, states, model))
    assert code == 2 and "Traceback" not in err
    problems = [line.strip() for line in err.splitlines()[1:] if line.strip()]
    assert len(problems) == 1, err
    assert problems[0].startswith("design.damage_states: ") and words in problems[0], err
