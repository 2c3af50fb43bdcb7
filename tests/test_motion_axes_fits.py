"""The fits of a record design over floors and orientations: one fit per (floor, orientation);
and ``rockstudy validate``'s count of them.

A small IDA study (three ground pairs, two objects, floors 0 and 2 of a shear building, two
orientations, two damage states, a power-law hazard) gives the dataset with the dimensions
``floor`` and ``orientation``. Oracles: the closed-form lognormal MLE (mean and standard
deviation dividing by n of ln capacity) on the stored capacities of one floor and orientation;
and, floor by floor and orientation by orientation, the fit of ``ds.sel(floor=f,
orientation=psi)``, which is the path without these dimensions that the fits' own tests
check (an independent door for the combination, not for the fit itself).
"""

import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from _helpers import cli, write_ground_pairs

from rockstudy.risk import HazardCurve
from rockstudy.study import load_study, run_study
from rockstudy.study.analysis.orientations import orientation_summary
from rockstudy.study.analysis.record_fragility import ida_fragility, stripe_fragility
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.analysis.states import state_fragility, state_risk
from rockstudy.study.report.sampled import make_report
from rockstudy.study.running.store import open_result

SHEAR = "building = { uniform_shear = { n_storeys = 3, period = 0.3, damping = 0.05 } }"
H2 = 'h2 = { match = "_X\\\\.AT2$", replace = "_Y.AT2" }'
DESIGN = (
    '[design]\nkind = "ida"\nim = "pga"\nstep = 0.1\ntolerance = 0.05\norientations = 2\n'
    "damage_states = { chipped = 0.3, overturned = 1.0 }"
)
HAZARD = '[hazard]\nkind = "power_law"\nim = "pga"\nk0 = 1e-4\nk = 2.5\nunits = "g"\n'
CURVE = HazardCurve.power_law(1e-4, 2.5, im="pga", units="g")
N_BOOT = 20


HEAD = """
name = "floors"
seed = 1
structure = { kind = "objects", file = "objects.csv" }
"""
OBJECTS = "name,half_diagonal,slenderness\nStatue,0.8,0.2\nVase,0.4,0.25\n"


def study_file(folder, where, design=DESIGN, floor="[0, 2]"):
    """A record study of two objects on ``floor`` of a shear building, over ``design``, in
    ``where``: its path."""
    (where / "objects.csv").write_text(OBJECTS)
    path = where / "floors.toml"
    path.write_text(
        f'{HEAD}[motion]\nkind = "record"\nfiles = "{folder}"\n{H2}\n{SHEAR}\nfloor = {floor}\n'
        f'{design}\n[run]\noutputs = ["max_rotation", "overturned"]\n{HAZARD}'
    )
    return path


@pytest.fixture(scope="module")
def pairs(tmp_path_factory):
    """Three ground pairs of near-fault pulses (x, y) as AT2 files."""
    folder = tmp_path_factory.mktemp("pairs")
    return write_ground_pairs(folder, 3, x=(0.6, 0.3, 2.5, 40), y=(0.8, 0.2, 4.0, 50), duration=4.0)


@pytest.fixture(scope="module")
def run(pairs, client, tmp_path_factory):
    """(folder, cube path, cube) of the study over floors [0, 2] and two orientations."""
    where = tmp_path_factory.mktemp("ida")
    path = study_file(pairs, where)
    out = where / "floors.zarr"
    result = run_study(load_study(path), out, client=client, base_dir=where, progress=False)
    assert result.failed_samples == 0
    return where, out, open_result(out).load()


@pytest.fixture(scope="module")
def cube(run):
    return run[2]


def slices(ds):
    """(floor, orientation, ds at them) for every floor and orientation of ``ds``."""
    return [
        (int(f), float(psi), ds.sel(floor=f, orientation=psi, drop=True))
        for f in ds["floor"].values
        for psi in ds["orientation"].values
    ]


def test_the_cube_has_floor_and_orientation_dimensions(cube):
    assert cube["capacity_scale"].dims == ("record", "floor", "orientation", "structure")
    np.testing.assert_array_equal(cube["floor"], [0, 2])
    np.testing.assert_allclose(cube["orientation"], [0.0, math.pi / 2])


def test_ida_fragility_per_floor_and_orientation_is_the_closed_form_mle(cube):
    table = ida_fragility(cube, by="structure", n_boot=N_BOOT)
    assert table.index.names == ["floor", "orientation", "structure"]
    checked = 0
    for f, psi, part in slices(cube):
        alone = ida_fragility(part, by="structure", n_boot=N_BOOT)
        pd.testing.assert_frame_equal(table.loc[(f, psi)], alone)
        for s in part["structure"].values:
            one = part.sel(structure=s)
            if one["censored"].any():
                continue
            ln_c = np.log(one["capacity"].values / 9.80665)  # stored in m/s^2, fitted in g
            row = table.loc[(f, psi, s)]
            np.testing.assert_allclose(row["theta"], np.exp(ln_c.mean()), rtol=1e-12)
            np.testing.assert_allclose(row["beta"], ln_c.std(ddof=0), rtol=1e-12)
            checked += 1
    assert checked >= 2  # the closed form was checked on uncensored groups


def test_state_fragility_and_risk_per_floor_and_orientation(cube):
    for nested in (False, True):
        table = state_fragility(cube, n_boot=0, nested=nested)
        assert table.index.names[:3] == ["floor", "orientation", "damage_state"]
        rates = state_risk(cube, CURVE, n_boot=N_BOOT, nested=nested)
        dims = {"floor", "orientation", "damage_state", "structure"}
        assert set(rates["annual_rate"].dims) == dims
        for f, psi, part in slices(cube):
            pd.testing.assert_frame_equal(
                table.loc[(f, psi)], state_fragility(part, n_boot=0, nested=nested)
            )
            xr.testing.assert_identical(
                rates.sel(floor=f, orientation=psi, drop=True),
                state_risk(part, CURVE, n_boot=N_BOOT, nested=nested),
            )


def test_object_risk_per_floor_and_orientation_keeps_the_design_order(cube):
    rates = object_risk(cube, CURVE, n_boot=N_BOOT)
    np.testing.assert_array_equal(rates["structure"], cube["structure"])
    for f, psi, part in slices(cube):
        alone = object_risk(part, CURVE, n_boot=N_BOOT)  # ranked by its rate
        xr.testing.assert_allclose(
            rates.sel(floor=f, orientation=psi, drop=True),
            alone.sel(structure=cube["structure"].values),
            rtol=0,
            atol=0,
        )


def test_a_design_over_floors_alone_is_fitted_per_floor(cube):
    floors = cube.isel(orientation=0, drop=True)
    rates = object_risk(floors, CURVE, n_boot=N_BOOT)
    states = state_risk(floors, CURVE, n_boot=N_BOOT, nested=True)
    assert rates["annual_rate"].dims == ("floor", "structure")
    for f in floors["floor"].values:
        alone = floors.sel(floor=f, drop=True)
        xr.testing.assert_identical(
            rates.sel(floor=f, drop=True),
            object_risk(alone, CURVE, n_boot=N_BOOT).sel(structure=floors["structure"].values),
        )
        xr.testing.assert_identical(
            states.sel(floor=f, drop=True), state_risk(alone, CURVE, n_boot=N_BOOT, nested=True)
        )


def test_the_accessor_fits_every_floor_and_orientation_or_a_summary(cube):
    table = cube.rocking.fragility(by="structure", n_boot=N_BOOT)
    pd.testing.assert_frame_equal(table, ida_fragility(cube, by="structure", n_boot=N_BOOT))
    for which in ("worst", "median"):
        got = cube.rocking.fragility(by="structure", n_boot=N_BOOT, orientation=which)
        assert got.index.names == ["floor", "structure"]
        for f in cube["floor"].values:
            view = orientation_summary(cube.sel(floor=f, drop=True), which)
            pd.testing.assert_frame_equal(
                got.loc[int(f)], ida_fragility(view, by="structure", n_boot=N_BOOT)
            )
        risk = cube.rocking.risk(CURVE, n_boot=N_BOOT, orientation=which)
        assert "orientation" not in risk.dims and "floor" in risk.dims
    with pytest.raises(ValueError, match="orientation: must be one of"):
        cube.rocking.fragility(orientation="best")


def test_an_orientation_summary_of_a_design_without_orientations_is_refused(cube):
    flat = cube.isel(orientation=0, drop=True)
    with pytest.raises(ValueError, match="no 'orientation' dimension"):
        flat.rocking.fragility(orientation="worst")


def stripes_over_floors():
    """Stripes (3 records, 2 floors, 2 structures, 4 levels) of outcomes drawn from a known
    lognormal per floor, as a record design's dataset."""
    rng = np.random.default_rng(7)
    levels = np.array([0.5, 1.0, 2.0, 4.0])
    pga = np.array([1.0, 2.0, 3.0]) * 9.80665 / 4  # m/s^2; stripes in g at scale x pga
    scale = 4 * levels[None, :] / np.array([1.0, 2.0, 3.0])[:, None]
    x = pga[:, None] * scale / 9.80665  # g, (record, level)
    theta = np.array([1.5, 0.8])  # per floor
    z = np.log(x[:, None, None, :] / theta[None, :, None, None]) / 0.5  # beta 0.5
    p = 0.5 * (1 + np.vectorize(math.erf)(z / math.sqrt(2)))
    over = (rng.random((3, 2, 2, 4)) < p).astype(np.int8)
    dims = ("record", "floor", "structure", "level")
    return xr.Dataset(
        {
            "overturned": (dims, over),
            "status": (dims, np.zeros(over.shape, np.int8)),
            "scale": (("record", "level"), scale),
            "pga": (("record",), pga),
        },
        coords={"floor": [1, 3], "structure": [0, 1], "level": levels},
        attrs={"design": "stripes", "im": "pga"},
    )


def test_stripe_fragility_per_floor():
    ds = stripes_over_floors()
    table = stripe_fragility(ds, by="structure", n_boot=0)
    assert table.index.names == ["floor", "structure"]
    for f in (1, 3):
        pd.testing.assert_frame_equal(
            table.loc[f], stripe_fragility(ds.sel(floor=f, drop=True), by="structure", n_boot=0)
        )


@pytest.mark.parametrize(
    ("floor", "orientations", "size"),
    [
        ("[0, 2]", "orientations = 4", ": 3 records x 2 floors [0, 2] x 4 orientations x 2 "),
        ("2", "orientations = [0.0, 1.0, 2.0]", " on floor 2: 3 records x 3 orientations x 2 "),
        ("[1, 2, 3]", "", ": 3 records x 3 floors [1, 2, 3] x 2 "),
    ],
)  # fmt: skip
def test_validate_counts_floors_and_orientations(pairs, tmp_path, floor, orientations, size):
    design = f'[design]\nkind = "ida"\nim = "pga"\n{orientations}'
    path = study_file(pairs, tmp_path, design, floor)
    code, out, err = cli("validate", str(path))
    assert code == 0, err
    assert f" ida design{size}structures, 0 distributed parameters" in out


def test_the_report_gives_the_nested_and_the_apart_rate_of_each_state(run):
    """The states' table labels its two estimators; fitted apart, the overturning state's
    rate is the overturning table's and object_risk's (overturning fitted alone); the
    nested rate is state_risk's nested fit."""
    where, out, ds = run
    make_report(out, where / "report")
    for floor in (0, 2):
        for which in ("worst", "median"):
            folder = where / "report" / f"floor_{floor}_{which}"
            rates = pd.read_csv(folder / "annual_states.csv", index_col=[0, 1], dtype=str)
            overturning = pd.read_csv(folder / "annual_overturning.csv", index_col=0, dtype=str)
            view = orientation_summary(ds.sel(floor=floor, drop=True), which)
            alone = object_risk(view, CURVE, n_boot=0)["annual_rate"]
            nested = state_risk(view, CURVE, nested=True)["annual_rate"]
            for s in ds["structure"].values:
                name = "lambda(state), fitted apart [1/yr]"
                apart = float(rates.loc[("overturned", str(s)), name])
                np.testing.assert_allclose(apart, float(alone.sel(structure=s)), rtol=1e-12)
                table = float(overturning.loc[str(s), "lambda_OT [1/yr]"])
                np.testing.assert_allclose(apart, table, rtol=1e-12)
                for state in ("chipped", "overturned"):
                    np.testing.assert_allclose(
                        float(rates.loc[(state, str(s)), "lambda(state), nested fit [1/yr]"]),
                        float(nested.sel(structure=s, damage_state=state)),
                        rtol=1e-12,
                    )
