"""Seeded near-fault synthetic records, and the record-based dimensionless groups."""

import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import Record, SinePulse, mp_pulse_acceleration, synthetic_near_fault
from rockstudy.similarity import groups, record_groups, uplift_acceleration
from rockstudy.structures.equivalent import SymmetricFrame


@pytest.mark.parametrize("period", [0.5, 1.0, 2.0, 4.0, 8.0])
def test_pulse_period_and_pga_as_asked(period):
    rec = synthetic_near_fault(pulse_period=period, pga=4.0, seed=7)
    assert rec.peak == pytest.approx(4.0, rel=1e-12)
    assert rec.pulse(method="mavroeidis").period == pytest.approx(period, rel=0.05)
    assert rec.pulse(method="mavroeidis").pulse_like
    assert rec.vertical is None


def test_seeded_and_reproducible():
    a = synthetic_near_fault(pulse_period=1.5, pga=3.0, seed=1, vertical=True)
    b = synthetic_near_fault(pulse_period=1.5, pga=3.0, seed=1, vertical=True)
    c = synthetic_near_fault(pulse_period=1.5, pga=3.0, seed=2, vertical=True)
    np.testing.assert_array_equal(a.acceleration, b.acceleration)
    np.testing.assert_array_equal(a.vertical, b.vertical)
    assert not np.allclose(a.acceleration, c.acceleration)
    assert not np.allclose(a.vertical, c.vertical)


def test_vertical_component():
    rec = synthetic_near_fault(pulse_period=2.0, pga=6.0, seed=3, vertical=True, vertical_ratio=0.5)
    assert rec.vertical.shape == rec.acceleration.shape
    assert np.max(np.abs(rec.vertical)) == pytest.approx(3.0, rel=1e-12)
    # the horizontal motion does not depend on whether a vertical one is made
    flat = synthetic_near_fault(pulse_period=2.0, pga=6.0, seed=3)
    np.testing.assert_array_equal(rec.acceleration, flat.acceleration)


def test_without_noise_it_is_the_pulse():
    rec = synthetic_near_fault(pulse_period=1.2, pga=2.0, seed=0, noise_ratio=0.0, phase=0.7)
    pulse = rec.pulse(method="mavroeidis")
    assert pulse.period == pytest.approx(1.2, rel=1e-4)
    assert pulse.phase == pytest.approx(0.7, abs=1e-4)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"pulse_period": 0.0, "pga": 1.0}, "pulse_period"),
        ({"pulse_period": 1.0, "pga": -1.0}, "pga"),
        ({"pulse_period": 1.0, "pga": 1.0, "gamma": 0.9}, "gamma"),
        ({"pulse_period": 1.0, "pga": 1.0, "noise_ratio": -1.0}, "noise_ratio"),
        ({"pulse_period": 1.0, "pga": 1.0, "dt": 0.1}, "dt"),
        ({"pulse_period": 10.0, "pga": 1.0, "duration": 12.0}, "duration"),
        ({"pulse_period": 1.0, "pga": 15.0, "vertical": True}, "vertical_ratio"),
    ],
)
def test_bad_input(kwargs, field):
    with pytest.raises(ValueError, match=field):
        synthetic_near_fault(seed=0, **kwargs)


# --- record_groups --------------------------------------------------------------------------


def test_record_groups_of_a_sampled_sine_pulse_match_the_pulse_groups():
    """A record that samples paper 000's sine pulse (at its peak) has PGA / (g tan alpha) equal
    to 1 / uplift_ratio of the pulse groups; its PGV = 2 a_g / omega_g (closed form)."""
    blk = rs.Block(1.2, 0.15)
    pulse = SinePulse(4.0, 0.8)
    dt = 0.8 / 4000
    t = dt * np.arange(4001)
    rec = Record(pulse.ground_acceleration(t), dt=dt)
    g = record_groups(blk, rec)
    assert g["pga_ratio"] == pytest.approx(1 / groups(blk, pulse)["uplift_ratio"], rel=1e-12)
    w = 2 * math.pi / 0.8
    p = blk.frequency_parameter
    assert g["pgv_ratio"] == pytest.approx(2 * 4.0 / w * p / (G * math.tan(0.15)), rel=1e-6)


def test_record_groups_of_a_pure_mp_pulse():
    """The groups take the record's (wavelet) pulse: omega_p = 2 pi / T_p and its peak
    velocity (plumbing); for an M-P pulse of gamma = 2, T_p is 5-20 % above the M-P period
    and the extracted pulse's peak velocity within 15 % of A (Baker's db4 pulse)."""
    blk = rs.Block(0.8, 0.2)
    rec = synthetic_near_fault(pulse_period=1.5, pga=3.0, seed=0, noise_ratio=0.0)
    g = record_groups(blk, rec)
    p, a_up = blk.frequency_parameter, G * math.tan(0.2)
    pulse = rec.pulse()
    assert g["pulse_frequency_ratio"] == pytest.approx(2 * math.pi / (pulse.period * p), rel=1e-12)
    assert 1.05 * 1.5 < pulse.period < 1.2 * 1.5
    t = rec.time
    unit = mp_pulse_acceleration(t, 1.0, 1.5, 2.0, 0.0, 0.35 * max(20.0, 6 * 1.5))
    amplitude = 3.0 / np.max(np.abs(unit))
    assert pulse.amplitude == pytest.approx(amplitude, rel=0.15)
    assert g["pulse_amplitude_ratio"] == pytest.approx(
        2 * math.pi / pulse.period * pulse.amplitude / a_up, rel=1e-12
    )


def test_record_groups_are_similarity_invariant():
    """Paper 000's similarity: a block s times larger (p / sqrt(s)) under the record slowed by
    sqrt(s) (same accelerations) has the same groups."""
    s = 4.0
    rec = synthetic_near_fault(pulse_period=1.0, pga=3.0, seed=5)
    slow = Record(rec.acceleration, dt=rec.dt * math.sqrt(s))
    a = record_groups(rs.Block(0.5, 0.2), rec)
    b = record_groups(rs.Block(0.5 * s, 0.2), slow)
    for key in a:
        assert b[key] == pytest.approx(a[key], rel=1e-6), key


def test_record_groups_of_a_structure_use_its_uplift():
    """A symmetric frame of two columns (R, alpha) under a rigid beam lifts off at g tan(alpha),
    like its columns, whatever the beam's mass (paper [003])."""
    frame = SymmetricFrame(half_diagonal=1.5, slenderness=0.2, mass_ratio=0.5)
    rec = synthetic_near_fault(pulse_period=1.0, pga=3.0, seed=5)
    assert uplift_acceleration(frame) == pytest.approx(G * math.tan(0.2), rel=1e-9)
    g = record_groups(frame, rec)
    assert g["pga_ratio"] == pytest.approx(3.0 / (G * math.tan(0.2)), rel=1e-9)


def test_record_groups_need_a_record():
    with pytest.raises(TypeError, match="Record"):
        record_groups(rs.Block(1.0, 0.2), SinePulse(1.0, 1.0))
