"""The contact model's pure sliding (mu < tan alpha) against a peer library: pySLAMMER's rigid
(Newmark) sliding-block analysis (pySLAMMER is based on the USGS tool SLAMMER).

Where the definitions agree. pySLAMMER's rigid analysis is one-way: the block slips only in
the direction of positive ground acceleration, at u_rel'' = a_g - k_y g, and never back. A
block of ours on a level base with mu < tan(alpha) is the two-way rigid-plastic block with
yield acceleration mu g (u'' = -a_g - sigma mu g). The two agree on one-sided records
(a_g >= 0 throughout: our block never slips back, which needs a_g < -mu g), with
k_y = mu g / g_pySLAMMER (pySLAMMER's g is 9.80665 m/s^2; the record is given to it in its
g). Direction: pySLAMMER's displacement is positive for positive ground acceleration, the
block lagging behind the ground: it is -u in ours.

The tolerance. Ours is exact on each record segment (piecewise-linear acceleration);
pySLAMMER integrates the same piecewise-linear record by the trapezoidal rule on the samples,
with the slip's start and stop snapped to the samples. Its error is second order in dt, and
bounded by (:func:`trapezoid_error_bound`):

- a start between two samples, at a fraction f of a step of slope j = ``|a_g'|``: the
  trapezoid gives the velocity j f dt^2 / 2 for the exact j (f dt)^2 / 2, an error
  <= j dt^2 / 8 carried to the end of the record (duration T): <= j dt^2 T / 8;
- a stop: the last partial step's slip, <= ``|u''|`` dt^2 / 2 with ``|u''|`` <=
  max ``|a_g - k_y g|``;
- inside a slip, the velocity is exact (the trapezoid integrates the linear acceleration
  exactly) and the slip's trapezoid errs by dt^3 ``|a_g'|`` / 12 a step: dt^2 TV(a_g) / 12
  over the record (TV: total variation).

The test holds pySLAMMER to that bound at dt = 5 ms and at dt / 8 (the same piecewise-linear
record on a finer grid), where it is 64 times smaller: a constant relative discrepancy of
the two models (a wrong g, a wrong yield acceleration) would not shrink with it.
"""

import numpy as np
import pyslammer  # the test extra: never skipped
import pytest
from pyslammer.constants import G_EARTH

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import Record
from rockstudy.motions.synthetic import synthetic_near_fault

DT = 0.005
MU = 0.2
BLOCK = rs.Block(half_diagonal=1.0, slenderness=0.4)  # tan(alpha) = 0.42 > mu: it cannot rock


def near_fault_pulse(period, seed):
    """The velocity pulse of the shipped records' generator (no stochastic part), its
    negative half removed: a smooth one-sided record of 0.5 g peak, 1 s of rest appended."""
    rec = synthetic_near_fault(
        pulse_period=period, pga=0.5 * G, seed=seed, noise_ratio=0.0, duration=6.0, dt=DT
    )
    return np.concatenate([np.maximum(rec.acceleration, 0.0), np.zeros(200)])


def half_sine_train(seed):
    """Four half-sine pulses of ground acceleration (0.25-0.6 g, 0.2-0.8 s, overlapping
    where they fall so) at random times in 5 s, then 2 s of rest."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 7.0, DT)
    a = np.zeros_like(t)
    for _ in range(4):
        start, length, peak = rng.uniform(0, 5), rng.uniform(0.2, 0.8), rng.uniform(0.25, 0.6)
        inside = (t >= start) & (t <= start + length)
        a[inside] += peak * G * np.sin(np.pi * (t[inside] - start) / length)
    return a


RECORDS = {
    "pulse Tp 0.8 s": lambda: near_fault_pulse(0.8, 1),
    "pulse Tp 1.3 s": lambda: near_fault_pulse(1.3, 2),
    "half sines 3": lambda: half_sine_train(3),
    "half sines 4": lambda: half_sine_train(4),
}


def refine(a, dt, k):
    """The same piecewise-linear record sampled k times more finely."""
    fine = np.arange((a.size - 1) * k + 1) * (dt / k)
    return np.interp(fine, np.arange(a.size) * dt, a)


def trapezoid_error_bound(a, dt, yield_acceleration):
    """An upper bound [m] on the error of pySLAMMER's rigid analysis (the module docstring):
    dt^2 (sum over starts of j T / 8 + starts x max ``|a - a_y|`` / 2 + TV(a) / 12)."""
    slope = np.abs(np.diff(a)) / dt
    starts = np.flatnonzero((a[:-1] <= yield_acceleration) & (a[1:] > yield_acceleration))
    duration = a.size * dt
    return dt**2 * (
        slope[starts].sum() * duration / 8
        + starts.size * np.max(np.abs(a - yield_acceleration)) / 2
        + np.abs(np.diff(a)).sum() / 12
    )


def pyslammer_slip(a, dt):
    """pySLAMMER's rigid sliding displacement [m] at the samples of ``a`` [m/s^2]."""
    motion = pyslammer.GroundMotion(a / G_EARTH, dt, "one-sided")
    return pyslammer.RigidAnalysis(MU * G / G_EARTH, motion).sliding_disp


@pytest.mark.parametrize("name", RECORDS)
def test_one_way_sliding_agrees_with_pyslammer(name):
    a = RECORDS[name]()
    assert a.min() >= 0.0 and a.max() > MU * G  # one-sided, and it slides
    ours = rs.simulate(BLOCK, Record(a, dt=DT), friction=MU)
    assert ours.info["solver"].startswith("exact sliding kernel")
    assert np.all(ours.theta == 0.0) and np.all(ours.slide <= 0.0)  # one way: u <= 0
    assert ours.max_slide == pytest.approx(-ours.residual_slide, rel=1e-14)
    for k in (1, 8):
        fine = refine(a, DT, k)
        theirs = pyslammer_slip(fine, DT / k)
        assert theirs[-1] == pytest.approx(theirs.max(), rel=1e-14)  # it has come to rest
        bound = trapezoid_error_bound(fine, DT / k, MU * G)
        assert abs(theirs[-1] - ours.max_slide) <= bound, (k, theirs[-1], ours.max_slide)
        # the slip history at the record's samples (rows of ours), to the same bound
        ours_at = -np.interp(np.arange(a.size) * DT, ours.t, ours.slide)
        assert np.max(np.abs(theirs[::k] - ours_at)) <= bound
