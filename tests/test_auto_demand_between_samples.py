"""``model="auto"`` sends a record scene to the contact model when its friction demand exceeds
mu between two of the record's samples, where no sample of the record shows it.

Oracle: Housner's block integrated by solve_ivp with the ground's forces maximised on a fine
grid and refined (:class:`test_kernel_friction_demand.Oracle`); the same forces at the
record's sample times give the largest ratio a check on the samples alone would see.
"""

import math

import numpy as np
import pytest
from test_kernel_friction_demand import Ground, Oracle

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.batch import MODEL_CONTACT
from rockstudy.motions import Record

P, ALPHA, ETA = 3.0, 0.2, 0.95  # impulse ratio of the impacts 0.13 < tan alpha: rocking sets it
AMPLITUDE = 1.3  # / (g tan alpha)
#: mu this far (relative) on either side of the oracle's demand.
MARGIN = 1e-5


def sampled_demand(oracle, times):
    """The largest ``|F_h|`` / F_v of the oracle's response at the record's sample times."""
    best = 0.0
    for t0, t1, sol, s in oracle.pieces:
        t = times[(times >= t0) & (times <= t1)]
        if t.size:
            f_h, f_v = oracle.forces(t, *sol(t), s)
            best = max(best, float(np.max(np.abs(f_h) / f_v)))
    return best


def plateau_record():
    """0.25 s at +1.3 g tan alpha, 0.25 s at -1.3 g tan alpha, then 2.5 s at rest, sampled
    every 0.05 s: the ground is constant between the samples of each plateau, where the
    rocking alone sets the forces' ratio (its largest value falls between two samples)."""
    acc = np.zeros(60)
    acc[1:6], acc[6:11] = AMPLITUDE * G * math.tan(ALPHA), -AMPLITUDE * G * math.tan(ALPHA)
    return Record(acc, dt=0.05)


@pytest.fixture(scope="module")
def scene():
    record = plateau_record()
    oracle = Oracle(P, ALPHA, ETA, Ground.record(record)).run()
    demand, min_fv = oracle.demand()
    assert not oracle.overturned and min_fv > 0
    assert demand > math.tan(ALPHA) and demand > (1 - ETA) / ((1 + ETA) * math.tan(ALPHA))
    return record, demand, sampled_demand(oracle, record.time)


def auto_model(record, mu):
    """The ``model`` code ``"auto"`` gives the scene at friction mu."""
    out = rs.simulate_batch(
        frequency_parameter=P,
        slenderness=ALPHA,
        restitution=ETA,
        record=record,
        scale=1.0,
        friction=mu,
        model="auto",
        rtol=1e-9,
        outputs=["model", "friction_demand"],
    )
    return int(out["model"][0])


def test_the_demand_peaks_between_two_samples(scene):
    _, demand, sampled = scene
    assert sampled < demand * (1 - 10 * MARGIN)


def test_a_demand_just_above_mu_between_samples_runs_the_contact_model(scene):
    record, demand, _ = scene
    assert auto_model(record, demand * (1 - MARGIN)) == MODEL_CONTACT


def test_a_demand_just_below_mu_keeps_housners_model(scene):
    record, demand, _ = scene
    assert auto_model(record, demand * (1 + MARGIN)) != MODEL_CONTACT
