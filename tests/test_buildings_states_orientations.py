"""Floors, orientations and damage states together in one study: objects on floors of a
five-storey shear building, at several orientations, with three damage states, in an IDA
and in stripes, with a hazard curve (validate, run, report, risk).

Oracles: the IDA of the Python API on the oriented floor record built by hand (the ground
pair turned to psi, a_x cos psi + a_y sin psi, then carried up the building), numpy's min
and median over the stored per-orientation capacities, overturning's own capacity and
annual rate for the overturning state, and the points of stripes read against the limits.
"""

import math

import numpy as np
import pandas as pd
import pytest
from _helpers import write_ground_pairs

from rockstudy.motions import Building, Record, floor_motion
from rockstudy.motions.building import with_ground
from rockstudy.study import load_study, run_study
from rockstudy.study.analysis.orientations import orientation_summary
from rockstudy.study.analysis.states import state_risk
from rockstudy.study.designs.records import incremental_dynamic_analysis
from rockstudy.study.report.sampled import make_report
from rockstudy.study.running.store import open_result

N_ORIENTATIONS = 4
STATES = {"chipped": 0.2, "displaced": 0.5, "overturned": 1.0}
IDA = {"im": "pga", "step": 0.05, "tolerance": 0.02, "max_pga_ratio": 3.0, "scan": 2}
BUILDING = Building.uniform_shear(5, 0.5, 0.05)
STUDY = """
name = "statues_upstairs"
seed = 1
structure = {{ kind = "objects", file = "objects.csv" }}
[motion]
kind = "record"
files = "{folder}"
h2 = {{ match = "_X\\\\.AT2$", replace = "_Y.AT2" }}
building = {{ uniform_shear = {{ n_storeys = 5, period = 0.5, damping = 0.05 }} }}
floor = {floor}
[design]
orientations = {n}
damage_states = {{ chipped = 0.2, displaced = 0.5, overturned = 1.0 }}
{design}
[hazard]
kind = "power_law"
im = "pga"
k0 = 1e-4
k = 2.5
units = "g"
"""
OBJECTS = "name,half_diagonal,slenderness\nStatue,0.8,0.2\n"
IDA_DESIGN = 'kind = "ida"\n' + "\n".join(f"{k} = {v!r}".replace("'", '"') for k, v in IDA.items())
STRIPES_DESIGN = """kind = "stripes"
[motion.scale_to]
im = "pga"
value = { dist = "grid", values = [1.0, 2.5] }"""


@pytest.fixture(scope="module")
def pairs(tmp_path_factory):
    """Two ground pairs of different near-fault pulses (x, y), as AT2 files."""
    folder = tmp_path_factory.mktemp("pairs")
    return write_ground_pairs(folder, 2, x=(0.5, 0.3, 2.5, 60), y=(0.7, 0.2, 3.5, 70), duration=3.0)


def _study(folder, where, floor, design):
    """The study file of the statue on ``floor`` (a number or a list) with ``design``,
    checked as ``rockstudy validate`` checks it."""
    (where / "objects.csv").write_text(OBJECTS)
    path = where / "upstairs.toml"
    path.write_text(STUDY.format(folder=folder, floor=floor, n=N_ORIENTATIONS, design=design))
    return load_study(path)


def _run(study, where, client, name):
    out = where / f"{name}.zarr"
    result = run_study(study, out, client=client, base_dir=where, progress=False)
    assert result.failed_samples == 0
    return out, open_result(out).load()


def _pair(folder, i) -> Record:
    """The ground pair i read back from its files."""
    x, y = (Record.from_at2(folder / f"p{i}_{c}.AT2") for c in ("X", "Y"))
    return Record(x.acceleration, time=x.time, acceleration_y=y.acceleration, name=x.name)


def _oriented_floor(pair, psi, floor) -> Record:
    """The floor motion of the ground turned to psi, built by hand: the ground component
    a_x cos psi + a_y sin psi carried up the building, measured on the ground pair."""
    turned = pair.acceleration * math.cos(psi) + pair.acceleration_y * math.sin(psi)
    ground = Record(turned, time=pair.time, name=pair.name)
    return with_ground(floor_motion(ground, BUILDING, floor), pair)


@pytest.fixture(scope="module")
def ida(pairs, client, tmp_path_factory):
    where = tmp_path_factory.mktemp("ida")
    study = _study(pairs, where, "[3, 5]", IDA_DESIGN)
    out, ds = _run(study, where, client, "ida")
    return where, out, ds


def test_state_capacities_on_every_floor_and_orientation_are_those_of_the_oriented_floor(
    ida, pairs
):
    _, _, ds = ida
    dims = ("damage_state", "record", "floor", "orientation", "structure")
    assert ds["state_capacity"].dims == dims
    assert list(ds["damage_state"].values) == list(STATES)
    np.testing.assert_allclose(ds["orientation"], np.pi * np.arange(N_ORIENTATIONS) / 4)
    statue = {"half_diagonal": [0.8], "slenderness": [0.2]}
    for i in range(2):
        pair = _pair(pairs, i)
        for floor in (3, 5):
            for k, psi in enumerate(ds["orientation"].values):
                record = _oriented_floor(pair, float(psi), floor)
                api = incremental_dynamic_analysis([record], statue, damage_states=STATES, **IDA)
                got = ds.isel(record=i, orientation=k).sel(floor=floor)
                for name in ("state_capacity", "state_capacity_scale", "capacity"):
                    np.testing.assert_allclose(
                        got[name].values, api[name].isel(record=0).values, rtol=1e-9,
                        err_msg=f"{name}, record {i}, floor {floor}, psi {psi}",
                    )  # fmt: skip
    # the overturning state is the capacity itself, bit for bit, everywhere
    over = ds["state_capacity"].sel(damage_state="overturned", drop=True)
    np.testing.assert_array_equal(over.transpose(*ds["capacity"].dims), ds["capacity"])
    # a state is reached at or below overturning, and chipped at or below displaced
    caps = ds["state_capacity"].values
    assert np.isfinite(caps[0]).all()
    assert (caps[0] <= caps[1]).all() and (
        caps[1][np.isfinite(caps[2])] <= caps[2][np.isfinite(caps[2])]
    ).all()


def test_worst_and_median_orientation_of_every_state_against_numpy(ida):
    _, _, ds = ida
    on_floor = ds.sel(floor=3, drop=True)
    scale = on_floor["state_capacity_scale"].transpose(
        "damage_state", "record", "structure", "orientation"
    )
    measure = on_floor["pga"].values[:, None]  # the ground pair's PGA: the design's im
    for which, reduce in (("worst", np.min), ("median", np.median)):
        view = orientation_summary(on_floor, which)
        got = view["state_capacity_scale"].transpose("damage_state", "record", "structure")
        known = np.isfinite(scale.values).all(axis=-1)
        assert known[:2].all()  # chipped and displaced reached at every orientation
        np.testing.assert_array_equal(got.values[known], reduce(scale.values, axis=-1)[known])
        np.testing.assert_allclose(
            view["state_capacity"].transpose(*got.dims).values[known],
            (measure * reduce(scale.values, axis=-1))[known],
            rtol=1e-12,
        )
        # the overturning state's summary is overturning's own
        np.testing.assert_array_equal(
            got.sel(damage_state="overturned").values,
            view["capacity_scale"].transpose("record", "structure").values,
        )


def test_the_report_and_the_risk_of_every_state_on_every_floor(ida):
    where, out, ds = ida
    from rockstudy.risk import HazardCurve

    hazard = HazardCurve.power_law(1e-4, 2.5, im="pga", units="g")
    page = make_report(out, where / "report").read_text()
    assert "floor 3" in page and "floor 5" in page and "Floor spectra" in page
    for floor in (3, 5):
        for which in ("worst", "median"):
            folder = where / "report" / f"floor_{floor}_{which}"
            assert "Damage states" in (folder / "index.html").read_text()
            rates = pd.read_csv(folder / "annual_states.csv", index_col=[0, 1])
            overturning = pd.read_csv(folder / "annual_overturning.csv", index_col=0)
            view = orientation_summary(ds.sel(floor=floor, drop=True), which)
            nested = state_risk(view, hazard, n_boot=50, nested=True)
            lam = nested["annual_rate"].sel(structure="Statue")
            # the report's rates are the summary's nested fit (analysis.nested_fit)
            np.testing.assert_allclose(
                rates["lambda(state), nested fit [1/yr]"].values, lam.values, rtol=1e-12
            )
            apart = state_risk(view, hazard, n_boot=50)["annual_rate"].sel(structure="Statue")
            # fitted apart, the overturning state is overturning's own rate
            np.testing.assert_allclose(
                float(apart.sel(damage_state="overturned")),
                float(overturning.filter(like="lambda").iloc[0, 0]),
                rtol=1e-12,
            )


def test_stripes_on_a_floor_over_orientations_read_every_state_from_their_points(
    pairs, client, tmp_path
):
    study = _study(pairs, tmp_path, "3", STRIPES_DESIGN)
    out, ds = _run(study, tmp_path, client, "stripes")
    assert ds["max_rotation"].dims == ("record", "orientation", "structure", "level")
    view = orientation_summary(ds, "worst")
    alpha = float(ds["critical_rotation"][0])
    from rockstudy.study.analysis.states import design_states, reached

    for state in design_states(view):
        got = reached(view, state).values
        rot = ds["max_rotation"].values
        want = (rot >= state.limit * alpha) | (ds["overturned"].values == 1)
        np.testing.assert_array_equal(got, want.any(axis=1), err_msg=state.name)
    page = make_report(out, tmp_path / "report").read_text()
    assert "Floor 3" in page and "8 orientations" not in page
    assert "Damage states" in (tmp_path / "report" / "design_worst" / "index.html").read_text()


def test_slide_capacities_are_summarised_over_orientations_against_numpy():
    """An IDA of the contact model over orientations: each slide limit's capacity scale at
    the worst orientation and the median, as numpy's min and median of the lower of it and
    overturning's at every orientation (a block that overturned has slid)."""
    import xarray as xr

    rng = np.random.default_rng(3)
    shape = (3, 8, 2)  # (record, orientation, structure)
    cap = rng.lognormal(size=shape)
    slide = cap[None] * rng.uniform(0.3, 1.4, size=(2, *shape))  # above cap: overturned first
    slide[1, 0, 3, 1] = np.nan  # not slid that far below overturning
    dims = ("record", "orientation", "structure")
    ds = xr.Dataset(
        {
            "capacity_scale": (dims, cap),
            "capacity_scale_lower": (dims, cap / 1.01),
            "censored": (dims, np.zeros(shape, bool)),
            "status": (dims, np.zeros(shape, int)),
            "capacity": (dims, 2.0 * cap),
            "slide_capacity_scale": (("slide_limit", *dims), slide),
            "slide_capacity": (("slide_limit", *dims), 2.0 * slide),
        },
        coords={"orientation": np.pi * np.arange(8) / 8, "slide_limit": [0.02, 0.1]},
        attrs={"im": "pga"},
    )
    effective = np.fmin(slide, cap[None])
    for which, reduce in (("worst", np.min), ("median", np.median)):
        view = orientation_summary(ds, which)
        got = view["slide_capacity_scale"].transpose("slide_limit", "record", "structure")
        np.testing.assert_allclose(got.values, reduce(effective, axis=2), rtol=1e-15)
        np.testing.assert_allclose(
            view["slide_capacity"].transpose(*got.dims).values,
            2.0 * reduce(effective, axis=2),
            rtol=1e-15,
        )
