"""The contact batch's ``converged`` flag: a scene whose answer does not converge with rtol is
flagged, a well-conditioned one is not.

Oracles: the solve_ivp reference at rtol 1e-12 (a well-conditioned scene's answer agrees with
it within 10 rtol), and, for a decision on its threshold, the reference under a friction
coefficient moved by far less than rtol either way (its answers differ by far more than 10
rtol: no answer at rtol is trustworthy there).
"""

from __future__ import annotations

import math

import numpy as np

from rockstudy.constants import G
from rockstudy.dynamics import _contact_scene as ck
from rockstudy.dynamics import slide_rock as sr
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import Record

RTOL = 1e-8
REF_RTOL = 1e-12


def batch(radius, alpha, mu, record, scale, max_steps=ck.MAX_STEPS, kinetic=1.0):
    """The contact batch's rows of blocks (radius, alpha, mu_s) under ``record`` times scale,
    mu_k = ``kinetic`` mu_s."""
    columns = map(np.atleast_1d, (radius, alpha, mu, scale))
    radius, alpha, mu, scale = np.broadcast_arrays(*columns)
    n = radius.size
    kind, _, times, samples, vsamples = record.kernel_spec()
    mp = np.column_stack([scale, np.zeros(n), np.zeros(n), np.full(n, record.duration)])
    eta = 1.0 - 1.5 * np.sin(alpha) ** 2
    p = np.sqrt(0.75 * G / radius)
    motion = (kind, mp, times, samples, vsamples)
    return ck.contact_batch(p, alpha, eta, mu, kinetic * mu, motion, RTOL, max_steps=max_steps)


def reference(radius, alpha, mu, record, kinetic=1.0):
    """The reference's result of one scene (mu_k = ``kinetic`` mu_s)."""
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    return simulate_contact_reference(radius, alpha, eta, record, mu, kinetic * mu, REF_RTOL)


def step_record(level, seconds=0.4, dt=0.01):
    """A step of ground acceleration ``level`` [m/s^2] from t = 0, sampled at dt."""
    t = np.arange(0.0, seconds + 0.5 * dt, dt)
    return Record(np.full(t.size, level), time=t)


def test_a_stick_slip_decision_on_its_threshold_is_flagged():
    """Under a step of acceleration a, a block at rest starts in rock where the uplift force
    ratio |F| / N is <= mu_s, in slide-rock above (Shenton 1996); with mu_s equal to that
    ratio the decision is made by rounding. With mu_k = mu_s / 2 the slip starts at once
    at a finite rate: the reference with mu_s moved by 1e-9 of itself either way differs in
    max_slide by far more than 10 rtol, so the scene has no answer at rtol, and the batch
    flags it. The same block with mu_s 5 % higher decides far from the threshold and is not
    flagged."""
    alpha, radius, a = 0.2, 1.0, 0.3
    mu = sr.uplift_force_ratio(a, alpha)
    record = step_record(a * G)
    below, above = (reference(radius, alpha, mu * (1 + s * 1e-9), record, 0.5) for s in (-1, 1))
    assert abs(below["max_slide"] - above["max_slide"]) > 1e3 * RTOL * radius * alpha
    rows = batch(radius, alpha, [mu, 1.05 * mu], record, 1.0, kinetic=0.5)
    assert list(rows["status"]) == [0, 0]
    assert list(rows["converged"]) == [False, True]


def test_a_decision_on_its_threshold_with_one_friction_coefficient_is_not_flagged():
    """With mu_k = mu_s the contact forces are continuous across the threshold (the slip
    starts at a rate proportional to the excess): the reference with mu moved by 1e-9 of
    itself either way gives the same max slide and max rotation within 10 rtol, and the
    batch's answer, not flagged, agrees with both."""
    alpha, radius, a = 0.2, 1.0, 0.3
    mu = sr.uplift_force_ratio(a, alpha)
    record = step_record(a * G)
    rows = batch(radius, alpha, mu, record, 1.0)
    assert rows["status"][0] == 0 and rows["converged"][0]
    for s in (-1, 1):
        ref = reference(radius, alpha, mu * (1 + s * 1e-9), record)
        for key, floor in (("max_rotation", alpha), ("max_slide", radius * alpha)):
            err = abs(rows[key][0] - ref[key])
            assert err <= 10 * RTOL * (abs(ref[key]) + 1e-2 * floor), (s, key, err)


def synthetic_record(rng, seconds=3.0, dt=0.01):
    """A record of white noise through a moving average, under a ramp-up and decay
    envelope, scaled to a peak of 1."""
    t = np.arange(0.0, seconds, dt)
    envelope = np.minimum(t / 0.5, 1.0) * np.exp(-np.maximum(t - 1.5, 0.0))
    x = np.convolve(rng.standard_normal(t.size + 9), np.ones(10) / 10, "valid") * envelope
    return Record(x / np.max(np.abs(x)), time=t)


def test_well_conditioned_scenes_are_not_flagged_and_agree_with_the_reference():
    """Rocking and sliding-rocking blocks under a synthetic record, friction well away
    from the thresholds: every row converged, and its max rotation and max slide lie within
    10 rtol of the reference at rtol 1e-12 (relative to |x| plus 1e-2 alpha, resp.
    1e-2 R alpha: the reference's own error floor)."""
    rng = np.random.default_rng(3601)
    record = synthetic_record(rng)
    radius = np.array([0.6, 1.2, 2.0, 0.9])
    alpha = np.array([0.15, 0.25, 0.3, 0.2])
    mu = np.array([0.6, 0.8, 0.5, 0.35])
    scale = 1.6 * G * np.tan(alpha)
    rows = batch(radius, alpha, mu, record, scale)
    assert np.all(rows["status"] == 0) and np.all(rows["converged"])
    for i in range(radius.size):
        ref = reference(
            radius[i], alpha[i], mu[i], Record(scale[i] * record.acceleration, time=record.time)
        )
        for key, floor in (("max_rotation", alpha[i]), ("max_slide", radius[i] * alpha[i])):
            err = abs(rows[key][i] - ref[key])
            assert err <= 10 * RTOL * (abs(ref[key]) + 1e-2 * floor), (i, key, err)


def test_a_scene_cut_at_its_step_limit_is_not_converged():
    """A row stopped at its step limit (status 1) is never marked converged."""
    record = step_record(0.3 * G)
    rows = batch(1.0, 0.2, 0.8, record, 1.0, max_steps=3)
    assert rows["status"][0] == 1 and not rows["converged"][0]
