"""Named objects: the record designs take ``{name: structure}`` and every output keeps the
names; a study file lists the objects. Oracles: single-scene simulations of the same block
run alone (simulate / a dense scan), the objects' own geometry, the Python API on the same
objects for the study file."""

import math

import numpy as np
import pytest
from _helpers import STUDY_OBJECTS, unit_sine_record, write_two_records

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import synthetic_near_fault
from rockstudy.structures.block import frequency_parameter
from rockstudy.study.analysis import record_fragility as rf
from rockstudy.study.designs import records as rd


@pytest.fixture(scope="module")
def records():
    return [
        synthetic_near_fault(0.6, 2.0, seed=1, duration=5.0, dt=0.01),
        synthetic_near_fault(1.0, 2.5, seed=2, duration=6.0, dt=0.01),
    ]


OBJECTS = {
    "Statue A": rs.Block.from_dimensions(width=0.45, height=1.9),
    "Column B": rs.Block(half_diagonal=1.2, slenderness=0.18),
    "Vase": rs.Block(half_diagonal=0.4, slenderness=0.3, restitution=0.85),
}


def test_cloud_keeps_the_names_and_each_object_responds_as_alone(records):
    ds = rd.cloud(records, OBJECTS)
    assert list(ds["structure"].values) == list(OBJECTS)
    for name, block in OBJECTS.items():
        row = ds.sel(structure=name)
        assert float(row["slenderness"]) == pytest.approx(block.slenderness, rel=1e-12)
        assert float(row["half_diagonal"]) == pytest.approx(block.half_diagonal, rel=1e-12)
        assert float(row["restitution"]) == pytest.approx(block.restitution, rel=1e-12)
        for i, r in enumerate(records):
            alone = rs.simulate(block, r)
            assert bool(row["overturned"][i]) == alone.overturned
            if not alone.overturned:
                assert float(row["max_rotation"][i]) == pytest.approx(alone.max_rotation, rel=1e-9)


def test_stripes_keep_the_names_into_the_fragility_table(records):
    levels = [1.0, 2.0, 4.0, 8.0]
    ds = rd.multiple_stripes(records, OBJECTS, levels)
    assert list(ds["structure"].values) == list(OBJECTS)
    block = OBJECTS["Column B"]
    for i, r in enumerate(records):
        for k in (0, 3):
            s = float(ds["scale"].sel(structure="Column B")[i, k])
            assert s * r.peak == pytest.approx(levels[k], rel=1e-12)
            alone = rs.simulate(block, r.scaled(s))
            assert bool(ds["overturned"].sel(structure="Column B")[i, k]) == alone.overturned
    table = rf.stripe_fragility(ds, by="structure", n_boot=0)
    assert list(table.index) == list(OBJECTS)


def test_ida_capacity_of_a_named_object_is_that_of_the_block_alone():
    # one sine cycle at omega/p = 1.5 for the R = 1 block: overturning is monotone in scale,
    # so the first overturning scale of a dense scan of the block alone brackets the capacity
    rec = unit_sine_record(1.5)
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    ds = rd.incremental_dynamic_analysis(rec, objects, scan=0)
    assert list(ds["structure"].values) == ["Stele", "Urn"]
    for name, block in objects.items():
        lo = float(ds["capacity_scale_lower"].sel(structure=name)[0])
        hi = float(ds["capacity_scale"].sel(structure=name)[0])
        assert rs.simulate(block, rec.scaled(hi)).overturned
        assert not rs.simulate(block, rec.scaled(lo)).overturned
        grid = np.geomspace(lo / 1.3, hi * 1.3, 400)
        over = rs.simulate_batch(
            half_diagonal=block.half_diagonal,
            slenderness=block.slenderness,
            record=rec,
            scale=grid,
        )["overturned"]
        first = grid[int(np.argmax(over))]
        assert lo < first * (1 + 1e-9) and hi > grid[int(np.argmax(over)) - 1]
        cap = float(ds["capacity"].sel(structure=name)[0])
        assert cap == pytest.approx(hi * rec.peak, rel=1e-12)
    table = rf.ida_fragility(ds, by="structure", n_boot=0)
    assert list(table.index) == list(objects)


def test_named_objects_bad_input(records):
    with pytest.raises(ValueError, match="non-empty str"):
        rd.cloud(records, {"": rs.Block(1.0, 0.2)})
    with pytest.raises(TypeError, match=r"structures\['B'\]"):
        rd.cloud(records, {"A": rs.Block(1.0, 0.2), "B": 3.0})
    with pytest.raises(ValueError, match="at least one"):
        rd.cloud(records, {})
    # the uplift level of each object is its own
    ds = rd.cloud(records[:1], OBJECTS)
    for name, block in OBJECTS.items():
        expect = G * math.tan(block.slenderness)
        assert float(ds["uplift_acceleration"].sel(structure=name)) == pytest.approx(expect)


# ------------------------------------------------------------------------------ study files

from rockstudy.motions import load_suite  # noqa: E402
from rockstudy.study import StudyError, load_study, run_study  # noqa: E402
from rockstudy.study.running.store import open_result  # noqa: E402


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    """A folder of two small synthetic records."""
    return write_two_records(tmp_path_factory.mktemp("records"))


LISTED = """objects = [
  { name = "Statue A", width = 0.45, height = 1.9 },
  { name = "Column B", half_diagonal = 1.2, slenderness = 0.18 },
  { name = "Vase", half_diagonal = 0.4, slenderness = 0.3, restitution = 0.85 },
]"""
CSV = """name,width,height,half_diagonal,slenderness,restitution
Statue A,0.45,1.9,,,
Column B,,,1.2,0.18,
Vase,,,0.4,0.3,0.85
"""


@pytest.mark.parametrize("where", ["listed", "csv"])
def test_objects_study_cube_equals_the_python_api_with_the_same_dict(
    suite, client, tmp_path, where
):
    if where == "csv":
        (tmp_path / "objects.csv").write_text(CSV)
        objects = 'file = "objects.csv"'
    else:
        objects = LISTED
    path = tmp_path / "museum.toml"
    path.write_text(STUDY_OBJECTS.format(objects=objects, folder=suite))
    study = load_study(path)
    out = tmp_path / "cube.zarr"
    report = run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    assert report.failed_samples == 0
    cube = open_result(out).load()
    assert list(cube["structure"].values) == list(OBJECTS)
    api = rd.multiple_stripes(load_suite(suite), OBJECTS, [2.0, 5.0])
    for name in ("scale", "max_rotation", "overturned", "half_diagonal", "slenderness"):
        np.testing.assert_allclose(
            np.asarray(cube[name].transpose(*api[name].dims).values, float),
            np.asarray(api[name].values, float),
            rtol=1e-12,
            equal_nan=True,
            err_msg=name,
        )
    table = rf.stripe_fragility(cube, by="structure", n_boot=0)
    assert list(table.index) == list(OBJECTS)


def test_objects_ida_study_equals_the_python_api(suite, client, tmp_path):
    text = STUDY_OBJECTS.format(objects=LISTED, folder=suite).replace(
        'scale_to = { im = "pga", value = { dist = "grid", values = [2.0, 5.0] } }\n', ""
    )
    text = text.replace('kind = "stripes"', 'kind = "ida"\ntolerance = 0.02\nscan = 2')
    path = tmp_path / "ida.toml"
    path.write_text(text)
    out = tmp_path / "ida.zarr"
    run_study(load_study(path), out, client=client, base_dir=tmp_path, progress=False)
    cube = open_result(out).load()
    assert list(cube["structure"].values) == list(OBJECTS)
    api = rd.incremental_dynamic_analysis(load_suite(suite), OBJECTS, tolerance=0.02, scan=2)
    for name in ("capacity", "capacity_scale", "censored"):
        np.testing.assert_allclose(
            np.asarray(cube[name].values, float),
            np.asarray(api[name].values, float),
            rtol=1e-12,
            equal_nan=True,
            err_msg=name,
        )
    table = rf.ida_fragility(cube, by="structure", n_boot=0)
    assert list(table.index) == list(OBJECTS)


def _problems(tmp_path, suite, objects, extra=""):
    path = tmp_path / "bad.toml"
    path.write_text(STUDY_OBJECTS.format(objects=objects, folder=suite) + extra)
    with pytest.raises(StudyError) as err:
        load_study(path)
    return "\n".join(err.value.problems)


def test_objects_study_errors_name_the_object_and_the_field(suite, tmp_path):
    text = _problems(
        tmp_path,
        suite,
        'objects = [{ name = "A", width = 0.4, height = 2.0 }, '
        '{ name = "Urn", width = -0.4, height = 2.0 }]',
    )
    assert "structure.objects[1]" in text and "'Urn'" in text and "width" in text
    text = _problems(tmp_path, suite, 'objects = [{ name = "A", width = "wide", height = 2.0 }]')
    assert "structure.objects[0] ('A').width" in text
    text = _problems(tmp_path, suite, 'objects = [{ name = "A", width = 0.4 }]')
    assert "'A'" in text and "width and height" in text
    text = _problems(
        tmp_path, suite, 'objects = [{ name = "A", kind = "pyramid", width = 0.4, height = 2.0 }]'
    )
    assert "'A'" in text and "'arch'" in text and "'pyramid'" in text
    text = _problems(
        tmp_path,
        suite,
        'objects = [{ name = "A", width = 0.4, height = 2.0 }, '
        '{ name = "A", width = 0.5, height = 2.0 }]',
    )
    assert "named 'A' like object 0" in text
    text = _problems(tmp_path, suite, LISTED, extra='[sampler]\nkind = "lhs"\nn = 4\n')
    assert "sampler.kind" in text
    text = _problems(tmp_path, suite, 'file = "missing.csv"')
    assert "structure.file" in text and "missing.csv" in text
    path = tmp_path / "typo.toml"  # a misspelt kind: the missing sampler says why it is needed
    path.write_text(
        STUDY_OBJECTS.format(objects=LISTED, folder=suite).replace('"objects"', '"objetcs"')
    )
    with pytest.raises(StudyError) as err:
        load_study(path)
    assert "structure.kind" in str(err.value) and "'objetcs'" in str(err.value)
    assert 'sampler: is required (unless [structure] kind = "objects")' in err.value.problems
    (tmp_path / "o.csv").write_text("name,colour\nA,red\n")
    text = _problems(tmp_path, suite, 'file = "o.csv"')
    assert "o.csv" in text and "line 1: column 2 of the header is not an object column" in text


def test_objects_geometry_is_that_of_the_block():
    from rockstudy.study.spec.schema import ObjectSpec

    o = ObjectSpec(name="S", width=0.45, height=1.9)
    b = rs.Block.from_dimensions(width=0.45, height=1.9)
    p, theta, eta = o.rocking()
    assert (p, theta, eta) == pytest.approx(
        (b.frequency_parameter, b.slenderness, b.restitution), rel=1e-12
    )
    wall = ObjectSpec(
        name="W", kind="rocking_wall", half_diagonal=1.0, slenderness=0.1, restitution=0.9
    )
    # eq. (23) of [003]: the wall's equivalent block has p sqrt(2) and theta_cr 2 alpha
    assert wall.rocking() == pytest.approx((math.sqrt(2) * frequency_parameter(1.0), 0.2, 0.9))


def test_validate_notes_an_object_given_in_centimetres(suite, tmp_path):
    """45 x 190 typed for a statue 45 cm wide and 190 cm high: a block of R = sqrt(22.5^2 +
    95^2) m; validate says the sizes are read in metres (a note: a spire may be large)."""
    from rockstudy.study.spec.feasibility import notes

    path = tmp_path / "cm.toml"
    objects = (
        'objects = [{ name = "A", width = 45, height = 190 }, '
        '{ name = "B", width = 0.45, height = 1.9 }]'
    )
    path.write_text(STUDY_OBJECTS.format(objects=objects, folder=suite))
    found = [n for n in notes(load_study(path)) if "sizes are in metres" in n]
    assert len(found) == 1 and found[0].startswith("structure.objects[0] ('A')"), found
    assert f"R = {math.hypot(22.5, 95.0):.4g} m" in found[0]
