"""Designs on floor motions report the ground record's intensity measures."""

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.motions import Building, floor_motion, synthetic_near_fault
from rockstudy.motions.building import ground_record
from rockstudy.study.designs import records as rd

BUILDING = Building.uniform_shear(3, 0.4, 0.05)
BLOCK = rs.Block(half_diagonal=0.8, slenderness=0.25)


@pytest.fixture(scope="module")
def ground():
    return synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=3, duration=4.0)


def _first_overturning_scale(ground, floor, scales):
    """The first of ``scales`` whose ground record, scaled and then carried up to ``floor``,
    overturns the block (rs.simulate on the recomputed floor motion at each scale)."""
    for s in scales:
        motion = floor_motion(ground.scaled(s), BUILDING, floor)
        if rs.simulate(BLOCK, motion).overturned:
            return s
    raise AssertionError("no scale of the scan overturned the block")


def test_ida_capacity_on_a_floor_is_in_the_ground_measure(ground):
    floor = 2
    motion = floor_motion(ground, BUILDING, floor)
    ida = rd.incremental_dynamic_analysis(
        [motion], [BLOCK], im="pga", step=0.01, tolerance=0.001, scan=0
    )
    assert float(ida["pga"][0]) == pytest.approx(ground.peak, rel=1e-12)
    # below this ground scale the floor's peak stays under g tan(alpha): nothing lifts
    start = 9.80665 * np.tan(BLOCK.slenderness) / motion.peak
    scales = start * 1.001 ** np.arange(3000)
    oracle = _first_overturning_scale(ground, floor, scales) * ground.peak
    assert float(ida["capacity"][0, 0]) == pytest.approx(oracle, rel=2.5e-3)
    assert motion.peak != pytest.approx(ground.peak, rel=0.05)  # the floor amplifies


def test_a_scaled_floor_motion_scales_its_ground_record(ground):
    motion = floor_motion(ground, BUILDING, 3).scaled(-2.0)
    assert ground_record(motion).peak == pytest.approx(2.0 * ground.peak, rel=1e-15)
    np.testing.assert_array_equal(ground_record(motion).acceleration, -2.0 * ground.acceleration)
    assert ground_record(ground) is ground
