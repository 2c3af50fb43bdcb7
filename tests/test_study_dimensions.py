"""Floors and orientations as dimensions of a record design (study layer).

Oracles: rs.simulate on the component records (x, y) and on floor_motion of them, the pair's
own measures, and numpy's min and median over the stored per-orientation capacities.
"""

import math

import numpy as np
import pytest
import xarray as xr
from _helpers import RECORD_STUDY_HEAD, write_ground_pairs

import rockstudy as rs
from rockstudy.motions import Building, Record, floor_motion
from rockstudy.study import load_study, run_study
from rockstudy.study.analysis.orientations import orientation_capacities, orientation_summary
from rockstudy.study.report.sampled import make_report
from rockstudy.study.running.store import open_result

SHEAR = "building = { uniform_shear = { n_storeys = 3, period = 0.3, damping = 0.05 } }"
H2 = 'h2 = { match = "_X\\\\.AT2$", replace = "_Y.AT2" }'
ANGLES = [0.0, math.pi / 2, math.pi]


@pytest.fixture(scope="module")
def pairs(tmp_path_factory):
    """Two ground pairs of near-fault pulses (x, y; the y one the stronger) as AT2 files."""
    folder = tmp_path_factory.mktemp("pairs")
    return write_ground_pairs(folder, 2, x=(0.6, 0.3, 2.5, 40), y=(0.8, 0.2, 4.0, 50), duration=4.0)


def study_file(folder, where, motion, design, extra=""):
    text = RECORD_STUDY_HEAD.replace("n = 3", "n = 2") + (
        f'[motion]\nkind = "record"\nfiles = "{folder}"\n{motion}\n{design}\n'
        '[run]\noutputs = ["max_rotation", "overturned"]\n' + extra
    )
    path = where / "dims.toml"
    path.write_text(text)
    return load_study(path)


def blocks(cube):
    return [
        rs.Block(half_diagonal=float(r), slenderness=float(a))
        for r, a in zip(cube["half_diagonal"].values, cube["slenderness"].values, strict=True)
    ]


def read(folder, i, part):
    return Record.from_at2(folder / f"p{i}_{part}.AT2")


def pair_of(folder, i):
    x, y = read(folder, i, "X"), read(folder, i, "Y")
    return Record(x.acceleration, time=x.time, acceleration_y=y.acceleration)


def side(result):
    """The sign of theta where |theta| peaks: the side the block rocks (or falls) to most."""
    return np.sign(result.theta[np.argmax(np.abs(result.theta))])


def test_a_cloud_over_floors_and_orientations_runs_each_component_on_each_floor(
    pairs, client, tmp_path
):
    motion = f"{H2}\n{SHEAR}\nfloor = [0, 2]"
    design = f'[design]\nkind = "cloud"\norientations = {ANGLES}'
    study = study_file(pairs, tmp_path, motion, design)
    out = tmp_path / "cube.zarr"
    assert (
        run_study(study, out, client=client, base_dir=tmp_path, progress=False).failed_samples == 0
    )
    cube = open_result(out).load()
    assert cube["max_rotation"].dims == ("record", "floor", "orientation", "structure")
    building = Building.uniform_shear(3, 0.3, 0.05)
    for i in range(2):
        x, y = read(pairs, i, "X"), read(pairs, i, "Y")
        assert float(cube["pga"][i]) == pytest.approx(x.peak, rel=1e-12)  # the ground pair's
        for floor in (0, 2):
            at = {"x": floor_motion(x, building, floor), "y": floor_motion(y, building, floor)}
            for j, block in enumerate(blocks(cube)):
                got = cube["max_rotation"].sel(floor=floor)[i, :, j].values
                want_x = rs.simulate(block, at["x"]).max_rotation
                want_y = rs.simulate(block, at["y"]).max_rotation
                np.testing.assert_allclose(got, [want_x, want_y, want_x], rtol=1e-6)
    # psi + pi mirrors: the same peak, and the block rocks (and overturns) to the other side
    block = blocks(cube)[0]
    pair = pair_of(pairs, 0)
    for psi in (0.3, 1.2):
        a = rs.simulate(block, pair, orientation=psi)
        b = rs.simulate(block, pair, orientation=psi + math.pi)
        assert b.max_rotation == pytest.approx(a.max_rotation, rel=1e-9)
        assert a.overturned == b.overturned and side(b) == -side(a) != 0
    report = make_report(out, tmp_path / "report")
    page = report.read_text()
    assert "floor 2" in page and "Floor spectra" in page
    assert (tmp_path / "report" / "floor_2_worst" / "index.html").exists()


def test_orientations_need_a_second_component(pairs, tmp_path):
    from rockstudy.study import StudyError

    with pytest.raises(StudyError, match="design.orientations: needs records of two"):
        study_file(pairs, tmp_path, "", '[design]\nkind = "cloud"\norientations = 4')


def test_floor_lists_and_orientations_are_checked_by_name(pairs, tmp_path):
    from rockstudy.study import StudyError

    for motion, design, message in (
        (f"{SHEAR}\nfloor = [1, 1]", "", "motion.floor: a list of floors must name distinct"),
        (f"{SHEAR}\nfloor = [1, 4]", "", "motion.floor: must be in 0..3"),
        (H2, "orientations = 0", "design.orientations: must be a number of angles in 1..360"),
        (H2, "orientations = [0.0, 0.0]", "design.orientations: a list must hold"),
    ):
        with pytest.raises(StudyError, match=message):
            study_file(pairs, tmp_path, motion, f'[design]\nkind = "cloud"\n{design}')


def test_orientation_summaries_against_numpy():
    rng = np.random.default_rng(1)
    scale = rng.lognormal(size=(3, 8, 2))  # (record, orientation, structure)
    ds = xr.Dataset(
        {
            "capacity_scale": (("record", "orientation", "structure"), scale),
            "capacity_scale_lower": (("record", "orientation", "structure"), scale / 1.01),
            "censored": (("record", "orientation", "structure"), np.zeros(scale.shape, bool)),
            "status": (("record", "orientation", "structure"), np.zeros(scale.shape, int)),
            "capacity": (("record", "orientation", "structure"), 2.0 * scale),
        },
        coords={"orientation": np.pi * np.arange(8) / 8},
        attrs={"im": "pga"},
    )
    caps = orientation_capacities(ds)
    np.testing.assert_array_equal(caps["worst_scale"], scale.min(axis=1))
    np.testing.assert_allclose(caps["median_scale"], np.median(scale, axis=1), rtol=1e-15)
    np.testing.assert_allclose(
        orientation_summary(ds, "median")["capacity"], 2.0 * np.median(scale, axis=1)
    )
    # censored orientations: capacity known only to lie above the standing level
    censored = np.zeros(scale.shape, bool)
    censored[0, :, 0] = True  # every orientation stands: worst censored at the lowest level
    censored[1, :5, 0] = True  # most stand, above the standing levels: the median is censored
    lower = ds["capacity_scale_lower"].values
    cut = ds.assign(censored=(ds["censored"].dims, censored))
    caps = orientation_capacities(cut)
    assert bool(caps["worst_censored"][0, 0]) and np.isnan(caps["worst_scale"][0, 0])
    assert float(caps["worst_scale_lower"][0, 0]) == lower[0, :, 0].min()
    assert bool(caps["median_censored"][1, 0])
    assert float(caps["worst_scale"][1, 0]) == pytest.approx(scale[1, 5:, 0].min()) or bool(
        caps["worst_censored"][1, 0]
    )
    assert not bool(caps["median_censored"][2, 0])


def test_an_ida_over_orientations_on_a_floor_with_a_hazard_reports_worst_and_median(
    pairs, client, tmp_path
):
    motion = f"{H2}\n{SHEAR}\nfloor = 2"
    design = '[design]\nkind = "ida"\nim = "pga"\nstep = 0.05\ntolerance = 0.02\norientations = 2'
    hazard = '[hazard]\nkind = "power_law"\nim = "pga"\nk0 = 1e-4\nk = 2.5\nunits = "g"\n'
    study = study_file(pairs, tmp_path, motion, design, hazard)
    out = tmp_path / "ida.zarr"
    assert (
        run_study(study, out, client=client, base_dir=tmp_path, progress=False).failed_samples == 0
    )
    cube = open_result(out).load()
    cap = cube["capacity_scale"].transpose("record", "orientation", "structure").values
    cens = cube["censored"].transpose("record", "orientation", "structure").values
    caps = orientation_capacities(cube)
    ok = ~cens.any(axis=1)
    np.testing.assert_array_equal(caps["worst_scale"].values[ok], cap.min(axis=1)[ok])
    np.testing.assert_allclose(caps["median_scale"].values[ok], np.median(cap, axis=1)[ok])
    pair = pair_of(pairs, 0)
    # the capacity is in the ground pair's PGA (its x component's) at every orientation
    got = cube["capacity"].isel(record=0).values
    np.testing.assert_allclose(got, pair.peak * cube["capacity_scale"].isel(record=0).values)
    report = make_report(out, tmp_path / "ida_report")
    page = report.read_text()
    assert "worst orientation" in page
    assert (tmp_path / "ida_report" / "design_median" / "index.html").exists()
