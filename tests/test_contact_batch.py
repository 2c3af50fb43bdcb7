"""simulate_batch(..., friction=, model=) and a study's ``[run] model``: the planar contact
model in a batch and in a study.

Oracles: Housner's no-slip model (the rocking kernel) where friction never limits; the
two-way rigid-plastic (Newmark) sliding block in closed form under a rectangular pulse;
``rockstudy.simulate`` scene by scene (with and without ``friction``) for what ``"auto"``
gives each row, the rows chosen by simulate's own friction demand.
"""

import math

import numpy as np
import pytest
from _helpers import write_at2

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import Record, RickerWavelet, SinePulse
from rockstudy.study import validate_text

ALPHA = 0.2
UPLIFT = G * math.tan(ALPHA)


def step(a, duration):
    """A rectangular pulse of ground acceleration a [m/s^2] over [0, duration] s."""
    return Record([a, a], time=[0.0, duration])


# ---------------------------------------------------------------- friction that never limits


def test_contact_model_with_ample_friction_is_housners_model_row_by_row():
    """mu = 10 under pulses that rock, rock long and overturn: model="contact" gives the
    rocking kernel's max rotation to 1e-10 (rtol 1e-12), its overturning and its impacts;
    the block that stands never slips."""
    ratio = np.array([1.6, 2.2, 3.0, 1.3])
    period = np.array([0.6, 0.5, 0.5, 0.8])
    kw = dict(half_diagonal=1.0, slenderness=ALPHA, amplitude=ratio * UPLIFT, period=period)
    housner = rs.simulate_batch(**kw, rtol=1e-12)
    r = rs.simulate_batch(**kw, rtol=1e-12, friction=10.0, model="contact")
    assert housner["overturned"].any() and not housner["overturned"].all()
    np.testing.assert_array_equal(r["overturned"], housner["overturned"])
    np.testing.assert_allclose(r["max_rotation"], housner["max_rotation"], rtol=1e-10, atol=0)
    stands = ~housner["overturned"]
    np.testing.assert_array_equal(r["n_impacts"][stands], housner["n_impacts"][stands])
    np.testing.assert_allclose(
        r["first_impact_time"], housner["first_impact_time"], rtol=0, atol=1e-9
    )
    assert np.all(r["model"] == 3) and np.all(r["status"] == 0)
    assert np.all(r["max_slide"][stands] == 0.0) and np.all(np.isnan(r["first_slip_time"][stands]))
    assert np.all(r["regime"][stands] == 2)  # rocked, never slid nor flew
    assert np.all(r["steps"] == -1) and np.all(np.isnan(r["peak_time"]))


# ---------------------------------------------------------------- sliding (mu < tan alpha)


def test_stocky_block_under_a_rectangular_pulse_slides_as_newmarks_block():
    """a_g = A on [0, T], mu < tan(alpha) < A / g, one row per (A, mu): the block never
    rotates; it slips back at -(A - mu g) until T, then decelerates at mu g and stops at
    A T / (mu g) with u = -(A - mu g) A T^2 / (2 mu g)."""
    dur = 0.3
    scale = np.array([0.5, 0.8, 0.4])
    mu = np.array([0.1, 0.15, 0.12])
    a = scale * G
    out = rs.simulate_batch(
        half_diagonal=0.8,
        slenderness=0.35,  # tan = 0.365 > mu
        record=step(G, dur),
        scale=scale,
        friction=mu,
        model="contact",
        rtol=1e-12,
    )
    newmark = (a - mu * G) * a * dur**2 / (2 * mu * G)
    np.testing.assert_allclose(out["max_slide"], newmark, rtol=1e-10)
    np.testing.assert_allclose(out["residual_slide"], -newmark, rtol=1e-10)
    np.testing.assert_allclose(out["time_slide"], a * dur / (mu * G), rtol=1e-10)
    assert np.all(out["max_rotation"] == 0.0) and not out["overturned"].any()
    assert np.all(out["n_impacts"] == 0) and np.all(out["first_slip_time"] == 0.0)
    assert np.all(out["regime"] == 1) and np.all(out["time_slide_rock"] == 0.0)
    assert not out["lift_off"].any()


def test_static_and_kinetic_friction_as_a_pair_of_columns():
    """friction=(mu_s, mu_k): below mu_s g the block rests; above it, it slides at mu_k."""
    dur, mu_s, mu_k = 0.3, 0.15, 0.1
    scale = np.array([0.14, 0.16])
    out = rs.simulate_batch(
        half_diagonal=0.8,
        slenderness=0.35,
        record=step(G, dur),
        scale=scale,
        friction=(mu_s, mu_k),
        model="auto",
        rtol=1e-12,
    )
    a = scale[1] * G
    assert out["max_slide"][0] == 0.0 and out["regime"][0] == 0
    assert out["residual_slide"][1] == pytest.approx(
        -(a - mu_k * G) * a * dur**2 / (2 * mu_k * G), rel=1e-10
    )
    assert out["model"][0] != 3 and out["model"][1] == 3  # slid: the contact model


# ---------------------------------------------------------------- "auto"


def _auto_scenes():
    """Blocks and sine pulses, half with mu below simulate()'s friction demand (0.7 x) and
    half above (1.4 x), and two stocky blocks under pulses below their uplift that slide."""
    rng = np.random.default_rng(36)
    n = 8
    R, alpha = rng.uniform(0.5, 2.0, n), rng.uniform(0.15, 0.3, n)
    amp = rng.uniform(1.2, 2.5, n) * G * np.tan(alpha)
    amp[-2:] = 0.8 * G * np.tan(alpha[-2:])  # never lifts; demand a / g
    period = rng.uniform(0.3, 0.8, n)
    motions = [SinePulse(amplitude=a, period=t) for a, t in zip(amp, period, strict=True)]
    blocks = [rs.Block(half_diagonal=r, slenderness=s) for r, s in zip(R, alpha, strict=True)]
    demand = np.array(
        [rs.simulate(b, m).friction_demand for b, m in zip(blocks, motions, strict=True)]
    )
    mu = np.where(np.arange(n) % 2 == 0, 0.7, 1.4) * demand
    mu[-2:] = 0.7 * demand[-2:]
    return (
        dict(half_diagonal=R, slenderness=alpha, amplitude=amp, period=period),
        mu,
        blocks,
        motions,
    )


def test_auto_gives_the_contact_model_exactly_where_friction_fails():
    """Each row of model="auto" is simulate(friction=mu)'s answer where simulate's friction
    demand exceeds mu (or the block lifts off or overturns), and simulate()'s (Housner's)
    elsewhere."""
    kw, mu, blocks, motions = _auto_scenes()
    rtol = 1e-10
    out = rs.simulate_batch(**kw, friction=mu, model="auto", rtol=rtol)
    contact_rows = 0
    for i, (block, motion) in enumerate(zip(blocks, motions, strict=True)):
        housner = rs.simulate(block, motion, rtol=rtol)
        if housner.friction_demand > mu[i] or housner.lift_off or housner.overturned:
            contact_rows += 1
            r = rs.simulate(block, motion, friction=mu[i], rtol=rtol)
            assert out["model"][i] == 3, i
            assert out["max_rotation"][i] == pytest.approx(r.max_rotation, rel=1e-12, abs=0)
            assert bool(out["overturned"][i]) == r.overturned
            assert out["max_slide"][i] == pytest.approx(r.max_slide, rel=1e-12, abs=0)
            np.testing.assert_allclose(out["residual_slide"][i], r.residual_slide, rtol=1e-12)
            np.testing.assert_allclose(out["first_slip_time"][i], r.first_slip_time, rtol=1e-12)
            for regime in ("slide", "slide_rock", "flight"):
                assert out[f"time_{regime}"][i] == pytest.approx(r.regime_times[regime], abs=1e-12)
            assert bool(out["lift_off"][i]) == r.lift_off
        else:
            assert out["model"][i] == 2, i
            assert out["max_rotation"][i] == pytest.approx(housner.max_rotation, rel=1e-8)
            assert not out["overturned"][i]
            assert out["max_slide"][i] == 0.0 and out["time_slide"][i] == 0.0
        assert out["friction_demand"][i] == pytest.approx(housner.friction_demand, rel=1e-9)
    assert 4 <= contact_rows < len(blocks)
    assert out["max_slide"][-2:].min() > 0.0  # the stocky blocks slid without lifting


def test_pure_rocking_under_auto_is_the_rocking_model():
    """mu far above the demand: "auto" runs no contact model and returns "rocking"'s rows
    (with the same friction check), each output identical."""
    kw = dict(half_diagonal=1.0, slenderness=ALPHA, amplitude=[1.5 * UPLIFT, 2.0 * UPLIFT])
    rocking = rs.simulate_batch(**kw, period=0.5, friction=10.0)
    auto = rs.simulate_batch(**kw, period=0.5, friction=10.0, model="auto")
    for name, values in rocking.items():
        np.testing.assert_array_equal(auto[name], values, err_msg=name)
    assert np.all(auto["max_slide"] == 0.0) and np.all(auto["regime"] == 2)


def test_dataset_carries_the_friction_and_the_slide_units():
    ds = rs.simulate_batch(
        half_diagonal=0.8,
        slenderness=0.35,
        record=step(G, 0.3),
        scale=0.5,
        friction=0.1,
        model="contact",
        as_dataset=True,
    )
    assert ds["max_slide"].attrs["units"] == "m" and ds["first_slip_time"].attrs["units"] == "s"
    assert ds["friction_static"].values[0] == 0.1 and ds["friction_kinetic"].values[0] == 0.1


def test_ricker_and_cosine_rows_rebuild_their_pulse():
    """The contact model runs each row's own pulse: a Ricker wavelet and three cosine cycles
    give simulate(friction=)'s answer."""
    for pulse, motion, cycles in (
        ("ricker", RickerWavelet(amplitude=2.0 * UPLIFT, period=0.5), 1),
        ("cosine", rs.motions.CosinePulse(amplitude=0.9 * UPLIFT, period=0.4, cycles=3), 3),
    ):
        out = rs.simulate_batch(
            half_diagonal=1.0,
            slenderness=ALPHA,
            pulse=pulse,
            amplitude=motion.amplitude,
            period=motion.period,
            cycles=cycles,
            friction=0.15,
            model="contact",
        )
        r = rs.simulate(rs.Block(half_diagonal=1.0, slenderness=ALPHA), motion, friction=0.15)
        assert out["max_slide"][0] == pytest.approx(r.max_slide, rel=1e-12), pulse
        assert out["max_rotation"][0] == pytest.approx(r.max_rotation, rel=1e-12, abs=0), pulse


# ---------------------------------------------------------------- refusals


BASE = dict(half_diagonal=1.0, slenderness=ALPHA, amplitude=UPLIFT * 1.5, period=0.5)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(model="slide"), "model must be one of"),
        (dict(model="contact"), "needs friction="),
        (dict(model="auto"), "needs friction="),
        (dict(friction=0.0, model="contact"), "friction[0] = 0.0 is outside"),
        (dict(friction=11.0), "friction[0] = 11.0 is outside"),
        (dict(friction=(0.2, 0.3), model="contact"), "kinetic coefficient 0.3 exceeds"),
        (dict(friction=(0.2, 0.1, 0.1)), "friction: a tuple is (mu_s, mu_k)"),
        (dict(friction="a", model="auto"), "friction must be a number"),
        (dict(friction=0.5, model="contact", method="linear"), "method='linear'"),
        (dict(outputs=["max_slide"]), "come from the contact model"),
        (dict(friction=0.5, model="auto", outputs=["conditioning"]), "conditioning"),
    ],
)
def test_bad_model_and_friction_are_refused_naming_the_argument(kwargs, words):
    with pytest.raises((ValueError, TypeError)) as err:
        rs.simulate_batch(**BASE, **kwargs)
    assert words in str(err.value)


# ---------------------------------------------------------------- a study


STUDY = """
name = "contact_auto"
seed = 3
chunk_size = 4
{friction}
[sampler]
kind = "monte_carlo"
n = 6
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 1.5 }}
slenderness = {{ dist = "uniform", low = 0.15, high = 0.3 }}
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = {{ dist = "uniform", low = 0.8, high = 2.0 }}
period = {{ dist = "uniform", low = 0.3, high = 0.8 }}
[run]
model = "{model}"
rtol = 1e-8
outputs = ["max_rotation", "overturned"]
"""


def test_a_study_with_model_auto_stores_the_slide_outputs(tmp_path, capsys):
    """[run] model = "auto" with friction: every scene's row equals simulate_batch's under
    the same model, the slide outputs stored with their units; the end of the run warns of
    no scene outside the model (the contact model ran them)."""
    import xarray as xr
    from distributed import Client

    from rockstudy.cli import _contact_warning
    from rockstudy.study import run_study

    study = validate_text(STUDY.format(friction="friction = 0.2", model="auto"))
    assert {"max_slide", "regime", "friction_demand"} <= set(study.run.outputs)
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(study, cube, client=c, progress=False, netcdf=False)
    ds = xr.open_zarr(cube)
    assert ds["max_slide"].attrs["units"] == "m"
    assert ds["time_slide"].attrs["units"] == "s"
    assert np.all(ds["status"].values == 1)
    expected = rs.simulate_batch(
        frequency_parameter=ds["frequency_parameter"].values,
        critical_rotation=ds["critical_rotation"].values,
        restitution=ds["restitution"].values,
        amplitude=ds["amplitude"].values,
        period=ds["period"].values,
        friction=0.2,
        model="auto",
    )
    for name in ("max_rotation", "max_slide", "residual_slide", "regime"):
        np.testing.assert_array_equal(ds[name].values, expected[name], err_msg=name)
    assert (expected["model"] == 3).any()  # some scene needed the contact model
    _contact_warning(study, cube)
    assert "outside" not in capsys.readouterr().err


@pytest.mark.parametrize(
    "friction, model, field, words",
    [
        ("", "contact", "run.model", "needs the friction coefficient"),
        ("", "auto", "run.model", "needs the friction coefficient"),
        ("friction = 0.2", "slip", "run.model", "rocking"),
    ],
)
def test_a_study_refuses_the_contact_model_without_friction(friction, model, field, words):
    with pytest.raises(ValueError) as err:
        validate_text(STUDY.format(friction=friction, model=model))
    assert field in str(err.value) and words in str(err.value)


def test_a_study_refuses_slide_outputs_under_the_rocking_model():
    text = STUDY.format(friction="friction = 0.2", model="rocking").replace(
        '"overturned"]', '"overturned", "max_slide"]'
    )
    with pytest.raises(ValueError) as err:
        validate_text(text)
    assert "run.outputs" in str(err.value) and "contact model" in str(err.value)


# ---------------------------------------------------------------- a record design


OBJECTS_STUDY = """
name = "museum_contact"
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
slide_limits = [0.01, 0.05]
[run]
model = "auto"
"""
#: A stocky bronze on a smooth base (mu 0.2 < tan 0.35: it slides) and a slender statue on
#: the study's mu 0.8 (it rocks).
OBJECTS_CSV = """name,half_diagonal,slenderness,friction
Bronze,0.5,0.35,0.2
Statue,1.0,0.15,
"""


def test_a_cloud_of_objects_under_auto_stores_each_objects_slide(tmp_path):
    """[run] model = "auto" in a cloud design with a friction column: each (record, object)
    point is simulate(friction=the object's mu)'s answer where simulate's friction demand
    exceeds it, Housner's (no slip) elsewhere; max_slide stored in metres."""
    from distributed import Client

    from rockstudy.motions import load_suite, synthetic_near_fault
    from rockstudy.study import load_study, run_study
    from rockstudy.study.running.store import open_result

    folder = tmp_path / "records"
    folder.mkdir()
    for i, tp in enumerate((0.4, 0.9)):
        rec = synthetic_near_fault(pulse_period=tp, pga=2.5, seed=40 + i, duration=3.0)
        write_at2(folder / f"r{i}.AT2", rec)
    (tmp_path / "objects.csv").write_text(OBJECTS_CSV)
    path = tmp_path / "museum.toml"
    path.write_text(OBJECTS_STUDY.format(folder=folder))
    study = load_study(path)
    assert study.design.slide_limits == [0.01, 0.05]
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(study, cube, client=c, base_dir=tmp_path, progress=False, netcdf=False)
    ds = open_result(cube).load()
    assert ds["max_slide"].attrs["units"] == "m"
    records = load_suite(str(folder))
    blocks = {"Bronze": (0.5, 0.35, 0.2), "Statue": (1.0, 0.15, 0.8)}
    slid = 0
    for r, rec in enumerate(records):
        for s, (name, (R, alpha, mu)) in enumerate(blocks.items()):
            point = ds.isel(record=r, structure=s)
            block = rs.Block(half_diagonal=R, slenderness=alpha)
            housner = rs.simulate(block, rec)
            if housner.friction_demand > mu or housner.lift_off:
                expected = rs.simulate(block, rec, friction=mu)
                assert int(point["model"]) == 3, (r, name)
                assert float(point["max_slide"]) == pytest.approx(expected.max_slide, rel=1e-12)
                assert int(point["regime"]) >= 1
                slid += expected.max_slide > 0
            else:
                assert int(point["model"]) != 3, (r, name)
                assert float(point["max_slide"]) == 0.0
                assert float(point["max_rotation"]) == pytest.approx(housner.max_rotation, rel=1e-6)
    assert slid >= 2  # the bronze slid under both records


@pytest.mark.parametrize(
    "old, new, field, words",
    [
        ("[0.01, 0.05]", "[0.05, 0.01]", "design.slide_limits", "increasing"),
        ("[0.01, 0.05]", "[0.0, 0.05]", "design.slide_limits", "must be > 0"),
        ('"auto"', '"rocking"', "design.slide_limits", "contact model"),
        ("friction = 0.8", "", "run.model", "needs the friction coefficient"),
    ],
)
def test_a_design_refuses_bad_slide_limits_and_the_contact_model_without_friction(
    tmp_path, old, new, field, words
):
    """slide_limits: > 0 m, increasing, with the contact model; the contact model: with
    every object's friction (the statue has none without the study's)."""
    folder = tmp_path / "records"
    folder.mkdir()
    rec = rs.motions.synthetic_near_fault(pulse_period=0.5, pga=2.5, seed=1, duration=2.0)
    write_at2(folder / "r0.AT2", rec)
    (tmp_path / "objects.csv").write_text(OBJECTS_CSV)
    text = OBJECTS_STUDY.format(folder=folder).replace(old, new)
    path = tmp_path / "museum.toml"
    path.write_text(text)
    from rockstudy.study import load_study

    with pytest.raises(ValueError) as err:
        load_study(path)
    assert field in str(err.value) and words in str(err.value), str(err.value)


def test_stripes_of_a_stocky_block_slide_as_newmarks_block_at_each_level():
    """multiple_stripes(..., friction=, model="contact") under a rectangular pulse scaled to
    each PGA level: the stocky block never rotates, and slides the Newmark closed form of
    that level (mu 0.1 for the first block, 0.15 for the second)."""
    dur, levels, mu = 0.3, np.array([0.3, 0.6]) * G, np.array([0.1, 0.15])
    ds = rs.study.multiple_stripes(
        [step(G, dur)],
        {"half_diagonal": [0.8, 0.6], "slenderness": [0.35, 0.4]},
        levels,
        im="pga",
        friction=mu,
        model="contact",
    )
    a = levels[None, :]
    newmark = (a - mu[:, None] * G) * a * dur**2 / (2 * mu[:, None] * G)
    np.testing.assert_allclose(ds["max_slide"].isel(record=0).values, newmark, rtol=1e-9)
    assert np.all(ds["max_rotation"].values == 0.0) and np.all(ds["model"].values == 3)
    assert ds["max_slide"].dims == ("record", "structure", "level")
    with pytest.raises(ValueError, match="needs friction="):
        rs.study.cloud([step(G, dur)], {"half_diagonal": 0.8, "slenderness": 0.35}, model="auto")
