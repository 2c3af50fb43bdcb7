"""The annual rate's cut of the fragility at the uplift PGA holds only where the objects feel
the record whose PGA the design stores: not on a floor motion measured by its ground record,
not along an orientation of a pair, not for a block on an isolator (whose base can amplify
the ground). There the whole lognormal is integrated: Cornell's closed form."""

import numpy as np
import pytest

import rockstudy as rs
from rockstudy import risk
from rockstudy.constants import G
from rockstudy.motions import Building, floor_motion, synthetic_near_fault
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.designs import records as rd
from rockstudy.study.designs.record_rows import _felt_motion

K0, K = 1e-4, 2.5
BLOCK = rs.Block(half_diagonal=0.6, slenderness=0.2)


@pytest.fixture(scope="module")
def grounds():
    return [
        synthetic_near_fault(pulse_period=tp, pga=3.0, seed=s, duration=4.0)
        for s, tp in ((1, 0.6), (2, 0.9), (3, 1.2))
    ]


def _lognormal_mle(caps):
    logs = np.log(caps)
    return float(np.exp(logs.mean())), float(logs.std())


HAZARD = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
STANDARD_G = 9.80665  # the unit g of the hazard [m/s^2]


def _rate(ds):
    return object_risk(ds, HAZARD, n_boot=0, min_overturning=1).isel(structure=0)


def test_ground_records_keep_the_cut(grounds):
    ds = rd.incremental_dynamic_analysis(grounds, [BLOCK], im="pga", step=0.05, scan=0)
    out = _rate(ds)
    uplift = G * np.tan(BLOCK.slenderness) / STANDARD_G  # g tan(alpha), in units of g
    assert float(out["cut_level"]) == pytest.approx(uplift, rel=1e-12)


def test_floor_motions_integrate_the_whole_lognormal(grounds):
    building = Building.uniform_shear(4, 0.5, 0.05)
    floors = [floor_motion(g, building, 3) for g in grounds]
    ds = rd.incremental_dynamic_analysis(floors, [BLOCK], im="pga", step=0.05, scan=0)
    assert not ds["measured_motion"].values.any()
    out = _rate(ds)
    assert np.isnan(float(out["cut_level"]))
    caps = ds["capacity"].isel(structure=0).values / STANDARD_G  # ground PGA [g]
    assert np.all(np.isfinite(caps))
    theta, beta = _lognormal_mle(caps)
    closed = K0 * theta**-K * np.exp(K**2 * beta**2 / 2)
    assert float(out["annual_rate"]) == pytest.approx(closed, rel=1e-6)


def test_an_isolated_block_is_not_cut(grounds):
    iso = rs.IsolatedBlock(BLOCK, base_mass_ratio=1.0, period=1.5, damping=0.1)
    structures = {
        "frequency_parameter": np.array([BLOCK.frequency_parameter] * 2),
        "critical_rotation": np.array([BLOCK.slenderness] * 2),
        "two_body": np.array([None, iso], dtype=object),
    }
    ds = rd.incremental_dynamic_analysis(grounds[:2], structures, im="pga", step=0.2, scan=0)
    assert list(ds["uplift_bounds"].values) == [True, False]


@pytest.mark.parametrize(
    "motion, design, objects, measured, bounds",
    [
        ({"kind": "record"}, {}, None, True, [True, True]),
        ({"kind": "record", "floor": 0}, {}, None, True, [True, True]),
        ({"kind": "record", "floor": 2}, {}, None, False, [True, True]),
        ({"kind": "record", "floor": [0, 3]}, {}, None, False, [True, True]),
        ({"kind": "record"}, {"orientations": 8}, None, False, [True, True]),
        ({"kind": "record"}, {}, [{"kind": "isolated"}, {}], True, [False, True]),
    ],
)
def test_a_study_cube_says_what_its_objects_feel(motion, design, objects, measured, bounds):
    study = {"motion": motion, "design": design, "structure": {"objects": objects}}
    out = _felt_motion(study, 3, 2)
    assert list(out["measured_motion"][1]) == [measured] * 3
    assert list(out["uplift_bounds"][1]) == bounds
