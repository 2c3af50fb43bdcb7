"""One registry of methods (issue 25 section 3): what each method claims to run is what it
runs; ``simulate`` and ``simulate_batch`` refuse an unsupported combination with one message
and share one step limit with one meaning; ``critical_rotation`` and its block alias.

Oracles: the behaviour of the solvers themselves (a capability claimed must run, one not
claimed must be refused), and the step count at which the single-scene path gives up, which
the batch must reproduce on the same scene (both integrate the same phase until the block
overturns inside the pulse).
"""

import inspect
import math
import warnings
from dataclasses import fields

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.contact_model import CONTACT_METHODS
from rockstudy.dynamics.methods import (
    MAX_STEPS,
    METHODS,
    STATUS_STEP_LIMIT,
    StepLimitError,
    method_for,
    unsupported_message,
)
from rockstudy.motions import Record, SinePulse
from rockstudy.structures import RockingWall
from rockstudy.study.designs import records as rd

ALPHA = 0.2
BLOCK = rs.Block(half_diagonal=1.2, slenderness=ALPHA)
UPLIFT = G * math.tan(ALPHA)
PULSE = SinePulse(amplitude=2.0 * UPLIFT, period=0.6)
WALL = RockingWall(1.0, 0.15, 0.9)
_T = np.arange(0.0, 1.0, 0.01)
RECORD = Record(1.5 * UPLIFT * np.sin(2 * np.pi * _T / 0.6), time=_T)
VERTICAL = Record(RECORD.acceleration, time=_T, vertical=0.2 * G * np.cos(9.0 * _T))
BATCH = dict(half_diagonal=1.2, critical_rotation=ALPHA)


def _message(call) -> str:
    with pytest.raises(ValueError) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        call()
    return str(info.value)


def _quiet(call):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call()


def test_unknown_method_same_message_through_both_doors():
    one = _message(lambda: rs.simulate(BLOCK, PULSE, method="housner"))
    two = _message(lambda: rs.simulate_batch(**BATCH, amplitude=3.0, period=0.5, method="housner"))
    assert one == two
    assert one.startswith("method must be one of") and all(m in one for m in METHODS)


@pytest.mark.parametrize("name", sorted(METHODS))
def test_batch_runs_exactly_the_methods_that_claim_it(name):
    call = lambda: rs.simulate_batch(**BATCH, amplitude=3.0, period=0.5, method=name)  # noqa: E731
    if METHODS[name].batch:
        assert _quiet(call)["status"][0] == 0
    else:
        message = _message(call)
        assert message == unsupported_message(name, "batch")
        assert f"method={name!r} does not run in simulate_batch" in message


@pytest.mark.parametrize("name", sorted(METHODS))
def test_structures_as_claimed(name):
    """A claimed structure kind runs; the other is refused with the registry's message."""
    for structure, kind in ((BLOCK, "block"), (WALL, "mechanism")):
        call = lambda s=structure: rs.simulate(s, PULSE, method=name, rtol=1e-6)  # noqa: E731
        if kind in METHODS[name].structures:
            assert _quiet(call).max_rotation > 0.0
        else:
            message = _message(call)
            assert message == unsupported_message(name, kind)
            assert f"method={name!r} does not run a Block" in message


@pytest.mark.parametrize("name", sorted(METHODS))
def test_vertical_shaking_as_claimed_through_both_doors(name):
    structure = WALL if name == "mechanism" else BLOCK
    call = lambda: rs.simulate(structure, VERTICAL, method=name, rtol=1e-6)  # noqa: E731
    batch = lambda: rs.simulate_batch(**BATCH, record=VERTICAL, method=name)  # noqa: E731
    assert METHODS[name].records and _quiet(
        lambda: rs.simulate(structure, RECORD, method=name, rtol=1e-6)
    )
    if METHODS[name].vertical:
        assert _quiet(call).max_rotation > 0.0
    else:
        message = _message(call)
        assert message == unsupported_message(name, "vertical")
        assert "does not take a record's vertical component" in message
    if not METHODS[name].batch:  # the batch refuses the method first, whatever the motion
        assert _message(batch) == unsupported_message(name, "batch")
    elif METHODS[name].vertical:
        assert _quiet(batch)["status"][0] == 0


@pytest.mark.parametrize("name", sorted(METHODS))
def test_friction_demand_as_claimed_through_both_doors(name):
    structure = WALL if name == "mechanism" else BLOCK
    call = lambda: rs.simulate(structure, PULSE, method=name, rtol=1e-6, friction=5.0)  # noqa: E731
    if METHODS[name].friction_demand and name not in CONTACT_METHODS:
        # friction= runs the contact model, which this method does not solve: refused by name
        message = _message(call)
        assert "friction" in message and all(m in message for m in CONTACT_METHODS)
    if METHODS[name].friction_demand:
        if name in CONTACT_METHODS:
            r = _quiet(call)
            assert r.friction_demand > 0.0 and r.lift_off is False
        # below uplift the block moves with the ground: the demand is max |a_g| / g
        low = SinePulse(amplitude=0.5 * UPLIFT, period=0.6)
        r = _quiet(lambda: rs.simulate(BLOCK, low, method=name, rtol=1e-6))
        assert r.friction_demand == pytest.approx(0.5 * math.tan(ALPHA), rel=1e-12)
    else:
        message = _message(call)
        assert message == unsupported_message(name, "friction_demand")
        assert "does not compute the friction demand" in message
    outputs = ("max_rotation", "friction_demand")
    batch = lambda: rs.simulate_batch(  # noqa: E731
        **BATCH, amplitude=2.0 * UPLIFT, period=0.6, method=name, outputs=outputs
    )
    if METHODS[name].batch and METHODS[name].friction_demand:
        assert _quiet(batch)["friction_demand"][0] > 0.0
    elif not METHODS[name].batch:
        assert _message(batch) == unsupported_message(name, "batch")


def test_registry_refuses_each_missing_need():
    """method_for refuses exactly the needs a method lacks, each with its one message."""
    needs = {
        "batch": {"batch": True},
        "block": {"structure": "block"},
        "mechanism": {"structure": "mechanism"},
        "records": {"record": True},
        "vertical": {"record": True, "vertical": True},
        "friction_demand": {"friction_demand": True},
    }
    for name, info in METHODS.items():
        for need, kwargs in needs.items():
            kwargs = {"structure": info.structures[0], **kwargs}
            has = (
                need in info.structures
                if need in needs and "structure" in needs[need]
                else (getattr(info, need))
            )
            if has:
                assert method_for(name, **kwargs) is info
            else:
                with pytest.raises(ValueError) as err:
                    method_for(name, **kwargs)
                assert str(err.value) == unsupported_message(name, need)


def _overturning_steps() -> int:
    """The smallest max_steps at which simulate completes a scene that overturns inside its
    pulse (one rocking phase from uplift to overturning), by bisection."""
    pulse = SinePulse(amplitude=4.0 * UPLIFT, period=0.8)
    assert rs.simulate(BLOCK, pulse).overturned
    lo, hi = 1, 100_000  # lo fails, hi completes
    with pytest.raises(StepLimitError):
        rs.simulate(BLOCK, pulse, max_steps=lo)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        try:
            rs.simulate(BLOCK, pulse, max_steps=mid)
            hi = mid
        except StepLimitError:
            lo = mid
    return hi


def test_simulate_and_batch_stop_at_the_same_step_limit():
    needed = _overturning_steps()
    assert needed > 10
    for max_steps, status in ((needed - 1, STATUS_STEP_LIMIT), (needed, 0)):
        out = rs.simulate_batch(
            **BATCH, amplitude=4.0 * UPLIFT, period=0.8, max_steps=max_steps, outputs="status"
        )
        assert out["status"][0] == status, max_steps
    with pytest.raises(StepLimitError, match=f"more than max_steps={needed - 1} steps") as err:
        rs.simulate(BLOCK, SinePulse(amplitude=4.0 * UPLIFT, period=0.8), max_steps=needed - 1)
    assert isinstance(err.value, RuntimeError) and err.value.max_steps == needed - 1


def test_one_default_step_limit():
    for fn in (rs.simulate, rs.simulate_batch, rd.cloud, rd.multiple_stripes):
        assert inspect.signature(fn).parameters["max_steps"].default == MAX_STEPS, fn
    from rockstudy.study.spec.schema import RunSpec

    assert RunSpec.model_fields["max_steps"].default == MAX_STEPS


def test_step_limit_in_the_friction_rows_of_a_batch():
    """A row whose history run (for its friction demand) reaches the limit: status 1 and a
    NaN demand, not an exception out of the batch."""
    out = rs.simulate_batch(
        **BATCH, amplitude=4.0 * UPLIFT, period=0.8, max_steps=3, outputs="friction_demand"
    )
    assert out["status"][0] == STATUS_STEP_LIMIT and np.isnan(out["friction_demand"][0])


def test_critical_rotation_and_its_alias():
    pulse = dict(half_diagonal=1.2, amplitude=[2.0, 3.0], period=0.6)
    one = rs.simulate_batch(critical_rotation=ALPHA, **pulse)
    two = rs.simulate_batch(slenderness=ALPHA, **pulse)
    for k in one:
        np.testing.assert_array_equal(one[k], two[k])
    # the alias is a block's slenderness: the single-scene path on the Block agrees
    r = rs.simulate(BLOCK, SinePulse(amplitude=3.0, period=0.6))
    assert one["max_rotation"][1] == pytest.approx(r.max_rotation, rel=1e-6)
    ds = rs.simulate_batch(critical_rotation=ALPHA, **pulse, as_dataset=True)
    assert ds["critical_rotation"].attrs["units"] == "rad" and "slenderness" not in ds.coords
    assert "slenderness" in rs.simulate_batch(slenderness=ALPHA, **pulse, as_dataset=True).coords
    with pytest.raises(ValueError, match="exactly once"):
        rs.simulate_batch(critical_rotation=ALPHA, slenderness=ALPHA, **pulse)
    with pytest.raises(ValueError, match="exactly once"):
        rs.simulate_batch(**pulse)
    with pytest.raises(ValueError, match=r"slenderness\[0\]"):
        rs.simulate_batch(slenderness=2.0, **pulse)
    with pytest.raises(ValueError, match=r"critical_rotation\[0\]"):
        rs.simulate_batch(critical_rotation=-0.1, **pulse)


def test_design_structures_take_critical_rotation():
    common = dict(half_diagonal=[1.0, 2.0], restitution=0.9)
    one = rd.cloud([RECORD], dict(critical_rotation=[0.15, 0.2], **common))
    two = rd.cloud([RECORD], dict(slenderness=[0.15, 0.2], **common))
    np.testing.assert_array_equal(one["max_rotation"], two["max_rotation"])
    np.testing.assert_array_equal(one["critical_rotation"], [0.15, 0.2])
    np.testing.assert_array_equal(one["slenderness"], one["critical_rotation"])
    with pytest.raises(ValueError, match="exactly once"):
        rd.cloud([RECORD], dict(critical_rotation=0.2, slenderness=0.2, half_diagonal=1.0))


def test_wrong_types_are_type_errors():
    with pytest.raises(TypeError, match="structure must be a rockstudy Block"):
        rs.simulate("block", PULSE)
    with pytest.raises(TypeError, match=r"records\[0\] must be a rockstudy Record"):
        rd.cloud([PULSE], dict(critical_rotation=0.2, half_diagonal=1.0))
    with pytest.raises(TypeError, match="amplitude must be a number"):
        rs.simulate_batch(**BATCH, amplitude="3.0", period=0.5)
    with pytest.raises(TypeError, match="t_max must be a number"):
        rs.simulate(BLOCK, PULSE, t_max="2")
    # a bad value of the right type stays a ValueError, and is not a TypeError
    with pytest.raises(ValueError) as err:
        rs.simulate_batch(**BATCH, amplitude=0.0, period=0.5)
    assert not isinstance(err.value, TypeError)


def test_ida_options_defined_once():
    """The API's defaults, the study's defaults and the dataset's attributes all come from
    IdaOptions."""
    defaults = {f.name: f.default for f in fields(rd.IdaOptions)}
    params = inspect.signature(rd.incremental_dynamic_analysis).parameters
    assert {k: params[k].default for k in defaults} == defaults
    from rockstudy.study.spec.schema import DesignSpec

    spec = DesignSpec(kind="ida")
    assert spec.ida_options() == defaults
    assert set(rd.IdaOptions().attrs()) == (set(defaults) - {"period"}) | {"im_period"}
