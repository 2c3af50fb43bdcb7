"""The bound that spares a rock step of the contact kernel its search for slip and lift-off.

Oracle for the bound: the contact forces evaluated densely along the step's own polynomial
(:func:`rockstudy.dynamics._contact_taylor.rock_force_events` at 2,001 points): a step the
bound clears must have every g (mu_s N - F, mu_s N + F, N) above 0 at every point, and a
step on which some g reaches 0 must never be cleared. Oracle for the kernel: the scipy
reference (:mod:`rockstudy.dynamics.slide_rock_reference`, rtol 1e-12), whose slip onset
is found by Brent's method on its own dense output.
"""

import math

import numpy as np
import pytest

from rockstudy.constants import G
from rockstudy.dynamics import _contact_scene as ck
from rockstudy.dynamics import _contact_taylor as ct
from rockstudy.dynamics._contact_state import Body
from rockstudy.dynamics._taylor import work_arrays
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import Record

DENSE = np.linspace(0.0, 1.0, 2001)


def random_step(rng):
    """A random rock step: a block, its friction, (theta, theta_dot) on corner s, a ground
    linear over the step and the step's length (up to 0.6 / p)."""
    alpha = rng.uniform(0.05, 0.5)
    radius = rng.uniform(0.3, 3.0)
    mu = rng.uniform(math.tan(alpha), 1.0)
    blk = Body(radius, alpha, 1.0 - 1.5 * math.sin(alpha) ** 2, mu, mu)
    p = math.sqrt(0.75 * G / radius)
    side = rng.choice((-1.0, 1.0))
    theta = side * rng.uniform(0.0, alpha)
    theta_dot = rng.normal(0.0, 0.5 * p * alpha)
    a_h = rng.uniform(-3.0, 3.0, 2) * G * math.tan(alpha)
    a_v = rng.uniform(-0.3, 0.3, 2) * G if rng.random() < 0.5 else np.zeros(2)
    gr = (a_h[0], a_h[1], a_v[0], a_v[1])
    return blk, gr, theta, theta_dot, side, rng.uniform(0.01, 0.6) / p


def test_a_step_cleared_by_the_bound_has_no_force_event_anywhere_in_it():
    """On 3,000 random rock steps: every step the bound clears keeps each g above 0 at
    2,001 points, every step with a g <= 0 somewhere is left to the search, and the bound
    clears at least half the steps whose g stay well away from 0 (it is worth its cost)."""
    rng = np.random.default_rng(3601)
    w, prev = work_arrays(), np.empty(3)
    cleared = crossing = far = far_cleared = 0
    for _ in range(3000):
        blk, gr, theta, theta_dot, side, hs = random_step(rng)
        outcome, n = ct.rock_step(w, prev, blk, gr, theta, theta_dot, side, hs, 1e-8, False)[:2]
        if outcome != ct.ACCEPTED:
            continue
        g = np.array(
            [
                ct.rock_force_events(w[0], n, x, hs, side, blk.static, blk.radius, blk.alpha, gr)
                for x in DENSE
            ]
        )
        away = ct._forces_away(w, n, hs, blk, gr)
        if away:
            cleared += 1
            assert np.all(g > 0.0), (blk, gr, theta, theta_dot, side, hs)
        if np.any(g <= 0.0):
            crossing += 1
            assert not away
        if np.all(g.min(axis=0) > 0.5 * np.abs(g).max(axis=0)):
            far += 1
            far_cleared += away
    assert crossing > 50 and cleared > 500
    assert far_cleared >= 0.5 * far


def sine_record(dt, periods, period):
    """``periods`` cycles of a unit sine of ``period`` [s] sampled at dt, then 1 s of rest."""
    t = np.arange(0.0, periods * period + 1.0, dt)
    return t, np.sin(2.0 * math.pi * t / period) * (t < periods * period)


@pytest.mark.parametrize("dt", [0.02, 0.0137])
def test_a_slip_onset_inside_a_rock_step_is_caught_at_the_references_time(dt):
    """A block that rocks (mu above tan alpha) and, a few steps later, slips on its corner
    under a coarsely sampled sine: the kernel's Taylor steps span the sample intervals, so
    the onset lies inside a step, off its ends and middle; the kernel finds it at the
    reference's time."""
    alpha, mu, radius = 0.15, 0.2, 1.0
    t, a = sine_record(dt, 2, 0.6)
    scale = 2.5 * G * math.tan(alpha)
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    ref = simulate_contact_reference(radius, alpha, eta, Record(scale * a, time=t), mu, mu, 1e-12)
    rec = Record(a, time=t)
    kind, _, times, samples, vsamples = rec.kernel_spec()
    mp = np.array([[scale, 0.0, 0.0, rec.duration]])
    one = np.array([1.0])
    rows = ck.contact_batch(
        one * math.sqrt(0.75 * G / radius),
        one * alpha,
        one * eta,
        one * mu,
        one * mu,
        (kind, mp, times, samples, vsamples),
        1e-10,
        parallel=False,
    )
    onset = ref["first_slip_time"]
    # it left rest (its only rest) and rocked over more than two sample intervals first
    assert math.isfinite(onset) and onset - ref["regime_times"]["rest"] > 2.0 * dt
    phase = (onset % dt) / dt  # where in its sample interval (a step's longest span)
    assert 0.05 < phase < 0.45 or 0.55 < phase < 0.95
    assert rows["status"][0] == 0
    assert rows["first_slip_time"][0] == pytest.approx(onset, abs=1e-9)
