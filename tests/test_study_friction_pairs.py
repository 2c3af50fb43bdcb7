"""A static and a kinetic friction coefficient in studies and designs: ``friction = [mu_s,
mu_k]`` (top level or per object), an objects CSV file's ``friction_kinetic`` column, checked
with messages naming the field; the pair reaches the contact model of every point, the
design's ``friction_static``/``friction_kinetic``, the study's cube and its report.

Oracles: simulate_batch run here with ``friction=(mu_s, mu_k)`` on the same scenes, and
the values written in the study file."""

from __future__ import annotations

import json

import numpy as np
import pytest
from _helpers import write_at2

import rockstudy as rs
from rockstudy.motions.suites import read_pair
from rockstudy.study.designs import records as rd
from rockstudy.study.spec.schema import validate_text

STUDY = """
name = "pairs"
seed = 1
{top}
[structure]
kind = "objects"
file = "objects.csv"
[motion]
kind = "record"
files = "{folder}/*.AT2"
[design]
kind = "cloud"
[run]
model = "contact"
"""
#: A stocky amphora that slides (mu_s 0.25 < tan 0.45) with a lower kinetic coefficient, and a
#: bronze that takes the study's pair.
OBJECTS = """name,half_diagonal,slenderness,friction,friction_kinetic
Amphora,0.3,0.45,0.25,0.15
Bronze,0.5,0.3,,
"""

HIGH_KINETIC = OBJECTS.replace("0.25,0.15", "0.25,0.3")
KINETIC_ALONE = OBJECTS.replace("0.25,0.15", ",0.15")


def _study(tmp_path, top="friction = [0.6, 0.4]", objects=OBJECTS):
    folder = tmp_path / "records"
    folder.mkdir(exist_ok=True)
    rec = rs.motions.synthetic_near_fault(pulse_period=0.4, pga=4.0, seed=7, duration=2.0)
    write_at2(folder / "r0.AT2", rec)
    (tmp_path / "objects.csv").write_text(objects)
    text = STUDY.format(top=top, folder=folder)
    return validate_text(text, base_dir=tmp_path), folder


def test_a_pair_per_object_or_for_the_study_is_read_in_object_order(tmp_path):
    study, _ = _study(tmp_path)
    static, kinetic = study.friction_pairs()
    np.testing.assert_array_equal(static, [0.25, 0.6])
    np.testing.assert_array_equal(kinetic, [0.15, 0.4])
    np.testing.assert_array_equal(study.friction_coefficients(), [0.25, 0.6])


@pytest.mark.parametrize(
    ("top", "objects", "words"),
    [
        ("friction = [0.4, 0.5]", OBJECTS, ["friction", "mu_s >= mu_k"]),
        ("friction = [0.5, 0.4, 0.3]", OBJECTS, ["friction", "pair", "3 values"]),
        ("friction = [0.5, 12.0]", OBJECTS, ["friction", "mu_k", "(0, 10]"]),
        ("friction = 0.5", HIGH_KINETIC, ["Amphora", "friction_kinetic", "mu_s >= mu_k"]),
        ("friction = 0.5", KINETIC_ALONE, ["Amphora", "friction_kinetic", "needs"]),
    ],
)  # fmt: skip
def test_bad_pairs_are_refused_naming_the_field(tmp_path, top, objects, words):
    with pytest.raises(ValueError) as err:
        _study(tmp_path, top, objects)
    for word in words:
        assert word in str(err.value)


def test_a_design_runs_each_structures_pair_and_stores_it(tmp_path):
    """cloud(friction=(mu_s, mu_k)) under the contact model gives simulate_batch's answer
    with the same pair, point by point, and stores the pair on structure."""
    rec = rs.motions.synthetic_near_fault(pulse_period=0.4, pga=4.0, seed=7, duration=2.0)
    R, alpha = np.array([0.3, 0.5]), np.array([0.45, 0.3])
    mu_s, mu_k = np.array([0.25, 0.6]), np.array([0.15, 0.4])
    ds = rd.cloud(
        [rec], {"half_diagonal": R, "slenderness": alpha}, friction=(mu_s, mu_k), model="contact"
    )
    want = rs.simulate_batch(
        half_diagonal=R, slenderness=alpha, record=rec, friction=(mu_s, mu_k), model="contact"
    )
    equal = rs.simulate_batch(
        half_diagonal=R, slenderness=alpha, record=rec, friction=mu_s, model="contact"
    )
    assert want["max_slide"][0] != equal["max_slide"][0]  # the kinetic coefficient matters
    for name in ("max_slide", "max_rotation", "regime"):
        np.testing.assert_array_equal(ds[name].values[0], want[name])
    np.testing.assert_array_equal(ds["friction_static"].values, mu_s)
    np.testing.assert_array_equal(ds["friction_kinetic"].values, mu_k)
    with pytest.raises(ValueError, match="friction: structure 0: the kinetic"):
        rd.cloud(
            [rec],
            {"half_diagonal": R, "slenderness": alpha},
            friction=(mu_k, mu_s),
            model="contact",
        )


def test_a_study_runs_stores_and_reports_its_pairs(tmp_path):
    from distributed import Client

    from rockstudy.study import run_study
    from rockstudy.study.report import make_report
    from rockstudy.study.running.store import open_result

    study, _ = _study(tmp_path)
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(study, cube, client=c, base_dir=tmp_path, progress=False)
    ds = open_result(cube).load()
    rec = read_pair(json.loads(ds.attrs["record_files"])[0])
    np.testing.assert_array_equal(ds["friction_static"].values.ravel(), [0.25, 0.6])
    np.testing.assert_array_equal(ds["friction_kinetic"].values.ravel(), [0.15, 0.4])
    want = rs.simulate_batch(
        half_diagonal=[0.3, 0.5],
        slenderness=[0.45, 0.3],
        record=rec,
        friction=([0.25, 0.6], [0.15, 0.4]),
        model="contact",
        outputs=("max_slide",),
    )
    np.testing.assert_allclose(ds["max_slide"].values.ravel(), want["max_slide"], rtol=0, atol=0)
    page = make_report(cube, tmp_path / "report").read_text()
    assert "mu_k (kinetic)" in page and "0.15" in page
