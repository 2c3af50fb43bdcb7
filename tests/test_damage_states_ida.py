"""Damage states in an IDA: the capacity of each state per record and structure.

Oracle: a dense scan of scale factors of the same record through ``simulate_batch`` (each
scale its own scene, no ladder): the ladder's guarantee (no window of the state at least one
step wide lies below its capacity) and the outcome at the capacity itself; and the IDA of
the same record without damage states (the overturning state is its capacity, bit for bit).
"""

import math

import numpy as np
import pytest
from _helpers import wide_runs

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import stochastic_record
from rockstudy.study.designs.records import cloud, incremental_dynamic_analysis

STEP, TOL, TOP = 0.05, 0.005, 4.0
RADIUS = np.array([0.8, 0.5, 1.0])
ALPHA = np.array([0.2, 0.35, 0.25])
MU = np.array([0.6, 0.25, 0.3])
STATES = {"chipped": 0.2, "displaced": 0.5, "overturned": 1.0}
BLOCKS = {"half_diagonal": RADIUS, "slenderness": ALPHA}
OPTIONS = dict(step=STEP, tolerance=TOL, max_pga_ratio=TOP, scan=4)


@pytest.fixture(scope="module")
def record():
    return stochastic_record(3.0, duration=3.0, seed=5)


@pytest.fixture(scope="module")
def ida(record):
    return incremental_dynamic_analysis([record], BLOCKS, damage_states=STATES, **OPTIONS)


def _scan(record, j, scales, outputs, **model):
    """Structure j under the record at each of ``scales``, one scene each."""
    return rs.simulate_batch(
        half_diagonal=RADIUS[j], slenderness=ALPHA[j], record=record, scale=scales,
        outputs=outputs, **model,
    )  # fmt: skip


def _dense_scales(record, j, slip=math.inf):
    """400 log-spaced scales from where the block can first lift (or slip: mu ``slip``) to
    the top of the ladder (TOP g tan(alpha) / PGA)."""
    low = G * min(ALPHA[j], slip) / record.peak
    return np.geomspace(low, TOP * G * math.tan(ALPHA[j]) / record.peak, 400)


def _ratio_reached(out, j, limit):
    """Whether each scene overturned or rocked to at least ``limit`` alpha."""
    return out["overturned"].astype(bool) | (out["max_rotation"] / ALPHA[j] >= limit)


def _check_first_crossing(s, scales, flags, reached_at_s):
    """The state capacity scale ``s`` against a dense scan's ``flags`` (reached): NaN only
    where no wide window exists, else reached at s and at or below every wide window."""
    wide = wide_runs(scales, flags, STEP)
    if math.isnan(s):
        assert not wide
        return False
    assert reached_at_s(s)
    if wide:
        assert s <= min(wide) * (1.0 + 1e-12)
    return True


def test_state_capacities_are_the_first_crossing_of_a_dense_scan(record, ida):
    """Per state short of overturning and structure: reached at its capacity, at or below
    every window of the state at least a step wide of a dense scan (NaN only without one),
    never below the lowest rung; in the units of ``capacity`` (PGA times the scale)."""
    assert ida["state_capacity"].dims == ("damage_state", "record", "structure")
    assert list(ida["damage_state"].values) == list(STATES)
    assert ida["state_capacity"].attrs["units"] == ida["capacity"].attrs["units"]
    found = 0
    outputs = ["max_rotation", "overturned"]
    for j in range(RADIUS.size):
        scales = _dense_scales(record, j)
        dense = _scan(record, j, scales, outputs)
        for name in ("chipped", "displaced"):
            limit = STATES[name]
            s = float(ida["state_capacity_scale"].sel(damage_state=name)[0, j])

            def reached(x, j=j, limit=limit):
                return bool(_ratio_reached(_scan(record, j, [x], outputs), j, limit)[0])

            found += _check_first_crossing(s, scales, _ratio_reached(dense, j, limit), reached)
            cap = float(ida["state_capacity"].sel(damage_state=name)[0, j])
            assert math.isnan(s) or cap == pytest.approx(record.peak * s, rel=1e-12)
    assert found >= 4


def test_the_overturning_state_is_the_capacity_exactly(record, ida):
    """The state of limit 1 equals ``capacity`` of the same IDA without damage states, bit
    for bit, in PGA and in Sa(T) (the measure's power kept), NaN where censored; the
    states change nothing else of the capacity (they add bisection points only)."""
    plain = incremental_dynamic_analysis([record], BLOCKS, **OPTIONS)
    over = ida["state_capacity"].sel(damage_state="overturned", drop=True)
    np.testing.assert_array_equal(over.values, plain["capacity"].values)
    for name in ("capacity", "capacity_scale", "capacity_scale_lower", "censored_reason"):
        np.testing.assert_array_equal(ida[name].values, plain[name].values)
    sa = dict(OPTIONS, im="sa", period=0.4, max_pga_ratio=3.0)  # the large block stands
    stocky = {"half_diagonal": [0.8, 3.0], "slenderness": [0.2, 0.3]}
    with_states = incremental_dynamic_analysis([record], stocky, damage_states=STATES, **sa)
    without = incremental_dynamic_analysis([record], stocky, **sa)
    assert bool(without["censored"][0, 1]) and not bool(without["censored"][0, 0])
    np.testing.assert_array_equal(
        with_states["state_capacity"].sel(damage_state="overturned").values,
        without["capacity"].values,
    )


def test_a_slide_state_is_the_first_crossing_under_the_contact_model(record):
    """A state on the slide ({"slide": d}) under the contact model: reached (slid more
    than d or overturned) at its capacity, at or below every wide window of a dense scan."""
    d = 0.01
    ds = incremental_dynamic_analysis(
        [record], BLOCKS, friction=MU, model="contact",
        damage_states={"fall_off": {"slide": d}, "overturned": 1.0}, **OPTIONS,
    )  # fmt: skip
    assert list(ds["damage_demand"].values) == ["slide", "rotation_ratio"]
    outputs = ["max_slide", "overturned"]
    found = 0
    for j in range(RADIUS.size):
        model = dict(friction=MU[j], model="contact")
        scales = _dense_scales(record, j, MU[j])
        dense = _scan(record, j, scales, outputs, **model)

        def reached(x, j=j, model=model):
            out = _scan(record, j, [x], outputs, **model)
            return bool(out["overturned"][0] or out["max_slide"][0] > d)

        flags = dense["overturned"].astype(bool) | (dense["max_slide"] > d)
        s = float(ds["state_capacity_scale"].sel(damage_state="fall_off")[0, j])
        found += _check_first_crossing(s, scales, flags, reached)
    assert found >= 2
    np.testing.assert_array_equal(
        ds["state_capacity"].sel(damage_state="overturned").values, ds["capacity"].values
    )


@pytest.mark.parametrize(
    ("states", "kw", "words"),
    [
        ({"chipped": 1.5}, {}, "the state 'chipped' has the limit 1.5"),
        ({"chipped": 0.0}, {}, "(0, 1]"),
        ({"chipped": True}, {}, "the state 'chipped' has the limit True"),
        ({"fall": {"slide": -0.1}}, {}, "the state 'fall' has the slide -0.1"),
        ({"fall": {"slid": 0.1}}, {}, "has keys ['slid']"),
        ({"fall": {"slide": 0.1}}, {}, "need the contact model"),
        ({"Chipped": 0.2, "chipped ": 0.3}, {}, "the names 'Chipped' and 'chipped ' clash"),
        ({"a": 0.5, "b": 0.5}, {}, "the states 'a' and 'b' have the same limit 0.5"),
        ({"": 0.5}, {}, "a state's name must be a non-empty text"),
    ],
)
def test_bad_damage_states_are_refused_by_name(record, states, kw, words):
    """Each bad state: a ValueError naming damage_states, the state and what is allowed,
    before any simulation (the IDA and the cloud alike)."""
    for design in (incremental_dynamic_analysis, cloud):
        with pytest.raises(ValueError, match="damage_states") as err:
            design([record], BLOCKS, damage_states=states, **kw)
        assert words in str(err.value)


def test_damage_states_must_be_a_mapping(record):
    with pytest.raises(TypeError, match="damage_states must be a mapping"):
        cloud([record], BLOCKS, damage_states=[0.2, 0.5])
