"""An IDA under the contact model: the overturning capacity and the slide capacities.

Oracle: a dense scan of scale factors of the same record through
``simulate_batch(model="contact")`` (each scale its own scene, no ladder): the ladder's
guarantee (no window of overturning, or of max_slide > d, at least one step wide lies below
the capacity), and the outcome at the capacity itself.
"""

import math

import numpy as np
import pytest
from _helpers import write_at2

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import stochastic_record
from rockstudy.study.designs.records import incremental_dynamic_analysis

STEP, TOL, TOP = 0.05, 0.005, 4.0
#: A slender block that rocks (mu > tan alpha), a stocky one that slides (mu < tan alpha) and
#: one in between.
RADIUS = np.array([0.8, 0.5, 1.0])
ALPHA = np.array([0.2, 0.35, 0.25])
MU = np.array([0.6, 0.25, 0.3])
LIMITS = [0.01, 0.05]


@pytest.fixture(scope="module")
def record():
    return stochastic_record(3.0, duration=3.0, seed=5)


@pytest.fixture(scope="module")
def ida(record):
    return incremental_dynamic_analysis(
        [record],
        {"half_diagonal": RADIUS, "slenderness": ALPHA},
        im="pga",
        step=STEP,
        tolerance=TOL,
        max_pga_ratio=TOP,
        scan=4,
        friction=MU,
        model="contact",
        slide_limits=LIMITS,
    )


def _contact(record, j, scales, outputs):
    """Structure j under the record at each of ``scales``, by the contact model."""
    return rs.simulate_batch(
        half_diagonal=RADIUS[j], slenderness=ALPHA[j], record=record, scale=scales,
        friction=MU[j], model="contact", outputs=outputs,
    )  # fmt: skip


def _dense(record, j, outputs):
    """(scales, outputs) of 400 log-spaced scales from where the block can first slip or
    lift (g min(alpha, mu) / PGA) to the top of the ladder (TOP g tan(alpha) / PGA)."""
    low = G * min(ALPHA[j], MU[j]) / record.peak
    high = TOP * G * math.tan(ALPHA[j]) / record.peak
    scales = np.geomspace(low, high, 400)
    return scales, _contact(record, j, scales, outputs)


def _wide_runs(scales, flags):
    """The upper ends of the runs of consecutive True ``flags`` spanning at least one
    step (a factor 1 + STEP): a rung lies inside each."""
    ends, start = [], None
    for k, flag in enumerate(flags):
        if flag and start is None:
            start = k
        if start is not None and (not flag or k == flags.size - 1):
            last = k if flag else k - 1
            if scales[last] >= scales[start] * (1.0 + STEP):
                ends.append(scales[last])
            start = None
    return ends


def test_overturning_capacity_keeps_the_ladders_guarantee_under_the_contact_model(record, ida):
    """Per structure: the capacity overturns and the bracket's lower end stands (within the
    tolerance), every wide overturning window of a dense scan lies at or above the capacity,
    and a block that the scan never overturns over a step is censored."""
    for j in range(RADIUS.size):
        scales, dense = _dense(record, j, ["overturned"])
        wide = _wide_runs(scales, dense["overturned"].astype(bool))
        cap = float(ida["capacity_scale"][0, j])
        if not wide:
            assert math.isnan(cap) or dense["overturned"].any(), j
            continue
        assert cap <= min(wide) * (1.0 + 1e-12), j
        lower = float(ida["capacity_scale_lower"][0, j])
        at = _contact(record, j, [cap, lower], ["overturned"])["overturned"]
        assert at[0] and not at[1], j
        assert cap <= lower * (1.0 + TOL), j
        assert float(ida["capacity"][0, j]) == pytest.approx(record.peak * cap, rel=1e-12)
    assert np.isfinite(ida["capacity_scale"][0, 0])  # the slender block overturned
    assert int(ida["censored_reason"][0, 1]) == 1  # the stocky one only slides
    models = ida["step_model"].values[0]
    assert np.all(models[np.isfinite(models)] >= 3)  # every point by the contact model


def test_slide_capacity_is_the_first_crossing_of_each_slide_limit(record, ida):
    """For each d: max_slide exceeds d at the slide capacity, every wide window of
    max_slide > d of a dense scan lies at or above it, NaN only where no such window exists,
    and below the lowest rung the block neither slips nor lifts;
    in the units of ``capacity`` (PGA times the scale), on (slide_limit, record, structure)."""
    assert ida["slide_capacity"].dims == ("slide_limit", "record", "structure")
    assert ida["slide_capacity"].attrs["units"] == ida["capacity"].attrs["units"]
    found = 0
    for j in range(RADIUS.size):
        scales, dense = _dense(record, j, ["max_slide", "max_rotation"])
        below = scales < np.nanmin(ida["step_scale"].values[0, j])  # the ladder's lowest rung
        assert not np.any(dense["max_slide"][below]) and not np.any(dense["max_rotation"][below])
        for c, d in enumerate(LIMITS):
            wide = _wide_runs(scales, dense["max_slide"] > d)
            s = float(ida["slide_capacity_scale"][c, 0, j])
            if math.isnan(s):
                assert not wide, (j, d)
                continue
            found += 1
            assert _contact(record, j, [s], ["max_slide"])["max_slide"][0] > d
            if wide:
                assert s <= min(wide) * (1.0 + 1e-12), (j, d)
            assert float(ida["slide_capacity"][c, 0, j]) == pytest.approx(record.peak * s)
    assert found >= 3


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(friction=0.5, slide_limits=[0.01]), "slide_limits need the contact model"),
        (dict(friction=0.5, model="contact", slide_limits=[0.05, 0.01]), "increasing"),
        (dict(friction=0.5, model="contact", slide_limits=[-0.01]), "slide_limits must be"),
        (dict(model="contact"), "needs friction="),
    ],
)
def test_bad_slide_limits_and_models_are_refused_by_name(record, kwargs, words):
    with pytest.raises(ValueError, match=words):
        incremental_dynamic_analysis([record], {"half_diagonal": 1.0, "slenderness": 0.2}, **kwargs)


IDA_STUDY = """
name = "museum_ida_contact"
seed = 1
friction = 0.6
structure = {{ kind = "objects", file = "objects.csv" }}
motion = {{ kind = "record", files = "{folder}" }}
[run]
model = "auto"
[design]
kind = "ida"
slide_limits = [0.01, 0.05]
im = "pga"
step = 0.05
tolerance = 0.01
max_pga_ratio = 3.0
scan = 2
"""
#: A bronze that slides on its base (mu 0.25 < tan 0.35) and a statue on the study's mu.
IDA_OBJECTS = """name,friction,half_diagonal,slenderness
Bronze,0.25,0.5,0.35
Statue,,0.8,0.2
"""


def test_an_ida_study_under_auto_stores_the_capacities_of_the_api(tmp_path):
    """[run] model = "auto" in an IDA study with slide_limits: the stored capacity and slide
    capacities are those of incremental_dynamic_analysis(model="auto") on the same record
    and objects, slide_capacity on (slide_limit, record, structure)."""
    from distributed import Client

    from rockstudy.motions import load_suite
    from rockstudy.study import load_study, run_study
    from rockstudy.study.running.store import open_result

    folder = tmp_path / "records"
    folder.mkdir()
    write_at2(folder / "r0.AT2", stochastic_record(3.0, duration=3.0, seed=11))
    (tmp_path / "objects.csv").write_text(IDA_OBJECTS)
    path = tmp_path / "ida.toml"
    path.write_text(IDA_STUDY.format(folder=folder))
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(load_study(path), cube, client=c, base_dir=tmp_path, progress=False)
    ds = open_result(cube).load()
    api = incremental_dynamic_analysis(
        load_suite(str(folder)),
        {"half_diagonal": [0.5, 0.8], "slenderness": [0.35, 0.2]},
        im="pga", step=0.05, tolerance=0.01, max_pga_ratio=3.0, scan=2,
        friction=[0.25, 0.6], model="auto", slide_limits=[0.01, 0.05],
    )  # fmt: skip
    assert ds["slide_capacity"].dims == ("slide_limit", "record", "structure")
    np.testing.assert_allclose(ds["slide_limit"].values, [0.01, 0.05])
    for name in ("capacity", "slide_capacity"):
        np.testing.assert_allclose(ds[name].values, api[name].values, rtol=1e-12, err_msg=name)
    assert np.isfinite(ds["slide_capacity"].values).any()
    assert "step_max_slide" in ds
