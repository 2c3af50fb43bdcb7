"""Blocks rocking under the real records of shared/records, kernel against scipy reference."""

import numpy as np
import pytest
from _helpers import REAL_RECORD_FILES as FILES
from _helpers import load_real_record as load

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.batch import simulate_batch


@pytest.mark.parametrize("name", FILES)
def test_block_rocks_under_record_like_the_reference(records_dir, name):
    rec = load(records_dir, name)
    # scale each record so that the block rocks: PGA = 2 g tan(alpha)
    block = rs.Block.from_dimensions(width=0.6, height=2.4)
    rec = rec.scaled(2.0 * G * np.tan(block.slenderness) / rec.peak)
    ker = rs.simulate(block, rec, rtol=1e-10)
    ref = rs.simulate(block, rec, method="scipy", rtol=1e-12)
    assert ker.n_impacts > 0
    assert ker.overturned == ref.overturned
    if not ref.overturned:
        assert ker.max_rotation == pytest.approx(ref.max_rotation, rel=1e-6)
    k = min(10, ref.n_impacts)
    np.testing.assert_allclose(ker.impact_times[:k], ref.impact_times[:k], atol=1e-8)
    # the batch path (scaled copies of one record, free rocking mapped) agrees
    b = simulate_batch(
        half_diagonal=block.half_diagonal,
        slenderness=block.slenderness,
        record=rec,
        scale=[1.0, -1.0],
        rtol=1e-10,
    )
    assert list(b["overturned"]) == [ker.overturned] * 2
    np.testing.assert_allclose(b["max_rotation"], ker.max_rotation, rtol=1e-8)


def test_record_mirror_symmetry(records_dir):
    rec = load(records_dir, "elcentro_NS.dat")
    block = rs.Block(1.5, 0.15)
    a = rs.simulate(block, rec)
    b = rs.simulate(block, rec.scaled(-1.0))
    np.testing.assert_array_equal(a.theta, -b.theta)
    np.testing.assert_array_equal(a.impact_times, b.impact_times)


def test_stochastic_record_rocks_a_block():
    rec = rs.motions.stochastic_record(peak=0.5 * G, duration=15.0, seed=3)
    block = rs.Block(1.0, 0.15)
    ker = rs.simulate(block, rec, rtol=1e-10)
    ref = rs.simulate(block, rec, method="scipy", rtol=1e-12)
    assert ker.overturned == ref.overturned
    k = min(10, ref.n_impacts)
    assert k > 0
    np.testing.assert_allclose(ker.impact_times[:k], ref.impact_times[:k], atol=1e-8)
