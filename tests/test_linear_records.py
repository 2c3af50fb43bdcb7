"""The exact solution of the linearized block under sampled records (issue 14, deliverable 2).

Oracle: the scipy reference path (solve_ivp at rtol 1e-12 on eq. 3.1 of [000], with its own
event location), which integrates what the exact solver solves in closed form.
"""

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import _linear_record
from rockstudy.motions import Record, stochastic_record
from rockstudy.structures import block_parameters

NO_LOG = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
RNG = np.random.default_rng(14)
SCENES = [
    (RNG.uniform(0.5, 3.0), RNG.uniform(0.1, 0.3), RNG.uniform(0.8, 6.0), seed)
    for seed in range(10)
]


def exact(block, record, use_map=False, scale=1.0):
    p, alpha, eta = block_parameters(block)
    times, samples = record.kernel_spec()[2:4]
    return _linear_record.record_scene(p, alpha, eta, scale, times, samples, _linear_record.loud_table(samples), use_map, np.inf, NO_LOG, np.empty((0, 7)))[:6]


@pytest.mark.parametrize("R, alpha, pga_ratio, seed", SCENES)
def test_exact_linear_record_matches_the_reference(R, alpha, pga_ratio, seed):
    block = rs.Block(R, alpha)
    record = stochastic_record(peak=pga_ratio * G * alpha, duration=5.0, dt=0.01, seed=seed)
    ref = rs.simulate(block, record, method="scipy-linear", rtol=1e-12)
    status, max_rot, over, n_imp, t_ot, t_first = exact(block, record)
    assert status == 0 and over == ref.overturned
    np.testing.assert_allclose(max_rot, ref.max_rotation, rtol=1e-10)
    assert n_imp == ref.impact_times.size
    if n_imp:
        np.testing.assert_allclose(t_first, ref.impact_times[0], rtol=0, atol=1e-9)
    if over:
        np.testing.assert_allclose(t_ot, ref.overturn_time, rtol=0, atol=1e-9)
    # the batch form maps the free rocking after the record instead of following it
    p, a, eta = block_parameters(block)
    times, samples = record.kernel_spec()[2:4]
    row = _linear_record.record_batch(
        np.array([p]), np.array([a]), np.array([eta]), np.ones(1), times, samples
    )[0]
    np.testing.assert_allclose(row[1], ref.max_rotation, rtol=1e-10)
    assert bool(row[2]) == ref.overturned and row[5] == 0.0


def test_exact_linear_record_symmetries():
    """Mirroring the record mirrors the motion; no uplift below g alpha (eq. 3.1)."""
    block = rs.Block(1.2, 0.2)
    record = stochastic_record(peak=3.0 * G * 0.2, duration=4.0, dt=0.005, seed=3)
    mirrored = Record(-record.acceleration, dt=record.dt)
    a, b = exact(block, record), exact(block, mirrored)
    assert a[1:4] == pytest.approx(b[1:4], rel=1e-12)
    assert exact(block, record, scale=0.99 / 3.0)[1:4] == (0.0, False, 0)


def test_simulate_batch_linear_records_are_exact():
    """method="linear" of the batch entry point runs the exact solver on records."""
    record = stochastic_record(peak=1.0, duration=4.0, dt=0.01, seed=5)
    R, alpha = np.array([0.8, 1.5, 2.5, 1.0]), np.array([0.12, 0.2, 0.25, 0.15])
    scale = np.array([1.5, 2.5, 4.0, 0.9]) * G * alpha / record.peak
    out = rs.simulate_batch(
        half_diagonal=R, slenderness=alpha, record=record, scale=scale, method="linear"
    )
    assert np.all(out["steps"] == 0) and np.all(out["status"] == 0)
    for i in range(R.size):
        ref = rs.simulate(
            rs.Block(R[i], alpha[i]), record.scaled(scale[i]), method="scipy-linear", rtol=1e-12
        )
        np.testing.assert_allclose(out["max_rotation"][i], ref.max_rotation, rtol=1e-10)
        assert out["overturned"][i] == ref.overturned
    assert out["max_rotation"][3] == 0.0  # 0.9 g alpha: no uplift
