"""Mechanisms under records (issue 14 section 3): the kernel of a tabulated mechanism,
eq. (8) of [003], inside a record, against the solve_ivp reference on the same tables and the
symmetric frame's exact equivalent block (Table I of [003])."""

import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics._rocking import MODEL_TABLE
from rockstudy.dynamics._structure_tables import structure_parameters, structure_table
from rockstudy.dynamics.reference import simulate_reference
from rockstudy.structures import Arch, RockingWall, SymmetricFrame


def _record(seed, pga, vertical=False):
    return rs.motions.synthetic_near_fault(0.8, pga, seed=seed, vertical=vertical, duration=8.0)


def _reference(structure, motion, rtol=1e-12):
    rp = structure_parameters(structure)
    return simulate_reference(
        rp.frequency_parameter,
        rp.critical_rotation,
        rp.restitution,
        motion,
        MODEL_TABLE,
        rtol,
        table=structure_table(structure),
    )


MECHANISMS = [
    RockingWall(1.0, 0.1, restitution=0.85),
    SymmetricFrame(1.0, 0.15, 0.5),
    Arch(math.pi, 0.75, 5.0, restitution=0.9),
]


@pytest.mark.parametrize("structure", MECHANISMS, ids=lambda s: type(s).__name__)
@pytest.mark.parametrize("rtol", [1e-6, 1e-8])
def test_mechanisms_under_records_against_solve_ivp(structure, rtol):
    """Max rotation within 100 rtol (rocking through tens of impacts), the same overturning
    decision and the same impacts, to 100 rtol of the duration, as solve_ivp at rtol 1e-12."""
    lam = structure_parameters(structure).uplift
    for seed, (factor, vertical) in enumerate(((1.5, False), (2.5, True), (6.0, False))):
        motion = _record(seed, factor * G * lam, vertical)
        res = rs.simulate(structure, motion, rtol=rtol)
        ref = _reference(structure, motion)
        assert res.overturned == ref["overturned"]
        if not ref["overturned"]:
            assert res.max_rotation == pytest.approx(ref["max_rotation"], rel=100 * rtol)
        imp = ref["impact_times"]
        assert len(imp) > 0
        n = min(len(imp), len(res.impact_times))
        assert n >= len(imp) - 1  # the last, in a Zeno sequence, may be one more or less
        np.testing.assert_allclose(res.impact_times[:n], imp[:n], atol=100 * rtol * 8.0)


def test_overturning_under_a_record_against_solve_ivp():
    """A wall thrown over by a strong record: the same decision and fall time (to 1e-6 s)."""
    wall = MECHANISMS[0]
    motion = _record(7, 9.0 * G * structure_parameters(wall).uplift)
    res = rs.simulate(wall, motion, rtol=1e-8)
    ref = _reference(wall, motion)
    assert res.overturned and ref["overturned"]
    assert res.overturn_time == pytest.approx(ref["overturn_time"], abs=1e-6)


def test_symmetric_frame_mechanism_equals_its_exact_block_under_a_record():
    """DESIGN's oracle: the frame through the mechanism code equals its closed-form
    equivalent block (Table I of [003]) run as a block (Taylor record step), under a record."""
    frame = SymmetricFrame(1.3, 0.2, 0.6)
    rp = frame.rocking_parameters()
    motion = _record(3, 2.0 * G * rp.uplift, vertical=True)
    mech = rs.simulate(frame, motion, method="mechanism", rtol=1e-10)
    R, a, gam = 1.3, 0.2, 0.6
    p = math.sqrt(3 * G / (4 * R) * (1 + 2 * gam) / (1 + 3 * gam))
    eta = (1 - 1.5 * math.sin(a) ** 2 + 3 * gam * math.cos(2 * a)) / (1 + 3 * gam)
    block = rs.Block(3 * G / (4 * p**2), a, restitution=eta)  # p = sqrt(3 g / 4 R)
    blk = rs.simulate(block, motion, method="nonlinear", rtol=1e-10)
    assert mech.n_impacts > 5 and not mech.overturned
    assert mech.max_rotation == pytest.approx(blk.max_rotation, rel=1e-7)
    assert mech.impact_times.size == blk.impact_times.size
    np.testing.assert_allclose(mech.impact_times, blk.impact_times, atol=1e-7)
