"""The event-driven numba kernel of the contact model against its scipy reference.

Oracle: the ``solve_ivp`` reference (:mod:`rockstudy.dynamics.slide_rock_reference`) at rtol
1e-12, an independent integrator and event locator (scipy's DOP853 with Brent's method on its
own dense output) of the same equations. The kernel runs at rtol 1e-10 and must agree within
10 rtol: max |theta| to 10 (1e-10 max |theta| + 1e-12 alpha), max |u| to 10 (1e-10 max |u|
+ 1e-12 R alpha), the second terms ten times the reference's own absolute tolerances (its
error floor, which a rotation of a few 1e-4 rad reaches); and its decisions (overturned,
lift-off, whether it slipped, the number of impacts) must be the reference's, except in the
threshold band: a scene whose reference decision flips when the amplitude moves by 1e-6 of
itself.
"""

import functools
import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import _contact_scene as ck
from rockstudy.dynamics import contact_model
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import Record, RickerWavelet, SinePulse

RTOL = 1e-10
REF_RTOL = 1e-12
#: Relative amplitude change that defines the threshold band of a decision.
BAND = 1e-6
DECISIONS = ("overturned", "lift_off", "slipped", "n_impacts")


def decisions(r):
    """The decisions of a result dict (the kernel's or the reference's)."""
    n = r["n_impacts"] if "n_impacts" in r else len(r["impact_times"])
    slipped = not math.isnan(r["first_slip_time"])
    return {
        "overturned": r["overturned"],
        "lift_off": r["lift_off"],
        "slipped": slipped,
        "n_impacts": n,
    }


def reference(scene, scale=1.0):
    """The reference's result of a scene (R, alpha, eta, motion factory, mu_s, mu_k), its
    motion's amplitude times ``scale``."""
    radius, alpha, eta, make, static, kinetic = scene
    return simulate_contact_reference(radius, alpha, eta, make(scale), static, kinetic, REF_RTOL)


def in_band(scene, key, value):
    """Whether the reference's decision ``key`` takes ``value`` within the threshold band."""
    return any(decisions(reference(scene, 1.0 + s * BAND))[key] == value for s in (-1, 1))


def assert_agree(kernel, ref, scene):
    """The kernel's result agrees with the reference's (see the module docstring)."""
    radius, alpha = scene[0], scene[1]
    for key, floor in (("max_rotation", alpha), ("max_slide", radius * alpha)):
        err = abs(kernel[key] - ref[key])
        assert err <= 10 * (RTOL * abs(ref[key]) + REF_RTOL * floor), (key, kernel[key], ref[key])
    mine, theirs = decisions(kernel), decisions(ref)
    for key in DECISIONS:
        if mine[key] != theirs[key]:
            assert in_band(scene, key, mine[key]), (key, mine[key], theirs[key], scene)


def pulse_scene(rng, mix):
    """A random block, friction and pulse: ``mix`` "slide" (mu < tan alpha: rest and slide)
    or "rock" (mu >= tan alpha: rest, rock, slide-rock, impacts, overturning)."""
    if mix == "slide":
        alpha = rng.uniform(math.atan(0.11), 0.5)
        mu = rng.uniform(0.1, math.tan(alpha))
    else:
        alpha = rng.uniform(0.05, 0.5)
        mu = rng.uniform(max(0.1, math.tan(alpha)), 1.0)
    radius = rng.uniform(0.3, 3.0)
    amplitude = rng.uniform(0.8, 4.0) * G * min(math.tan(alpha), mu)
    period = rng.uniform(0.2, 1.5)
    kind = SinePulse if rng.random() < 0.5 else RickerWavelet

    def make(scale):
        return kind(amplitude=scale * amplitude, period=period)

    return radius, alpha, 1.0 - 1.5 * math.sin(alpha) ** 2, make, mu, mu


@pytest.mark.slow
@pytest.mark.parametrize("mix", ["slide", "rock"])
def test_kernel_agrees_with_the_reference_on_random_pulses(mix):
    """200 random pulse scenes per regime mix (mu 0.1-1.0, alpha 0.05-0.5, sine and Ricker
    pulses of 0.8-4 times the level at which the block leaves rest)."""
    rng = np.random.default_rng(36 if mix == "slide" else 63)
    seen = set()
    for _ in range(200):
        scene = pulse_scene(rng, mix)
        radius, alpha, eta, make, static, kinetic = scene
        kernel = ck.contact_scene(radius, alpha, eta, make(1.0), static, kinetic, RTOL)
        assert kernel["status"] == 0
        assert_agree(kernel, reference(scene), scene)
        seen |= {name for name, t in kernel["regime_times"].items() if t > 0.0}
    expected = {"rest", "slide"} if mix == "slide" else {"rest", "rock", "slide_rock"}
    assert expected <= seen


def synthetic_record(rng, vertical):
    """A 3 s record at 0.01 s: white noise through a moving average, scaled to a peak of 1,
    under a ramp-up and decay envelope; with ``vertical`` a vertical component whose lowest
    value is -0.8 (times the record's scale [m/s^2])."""
    t = np.arange(0.0, 3.0, 0.01)
    envelope = np.minimum(t / 0.5, 1.0) * np.exp(-np.maximum(t - 1.5, 0.0))

    def component():
        x = np.convolve(rng.standard_normal(t.size + 9), np.ones(10) / 10, "valid") * envelope
        return x / np.max(np.abs(x))

    a_h, a_v = component(), None
    if vertical:
        a_v = component()
        a_v = 0.8 * a_v / abs(np.min(a_v))
    return t, a_h, a_v


def scaled_record(t, a_h, a_v, amplitude, scale):
    """The record (t, a_h, a_v) times ``amplitude`` * ``scale`` [m/s^2]."""
    vertical = None if a_v is None else scale * amplitude * a_v
    return Record(scale * amplitude * a_h, time=t, vertical=vertical)


@pytest.mark.slow
def test_batch_agrees_with_the_reference_on_synthetic_records():
    """contact_batch on 4 synthetic records (two with a vertical component that drives the
    block into flight) x 12 random blocks, friction and scales, against the reference."""
    rng = np.random.default_rng(2036)
    seen = set()
    for j in range(4):
        t, a_h, a_v = synthetic_record(rng, vertical=j >= 2)
        n = 12
        alpha = rng.uniform(0.05, 0.5, n)
        radius = rng.uniform(0.3, 3.0, n)
        mu = rng.uniform(0.1, 1.0, n)
        if a_v is None:  # the peak of u_h'' [m/s^2]: 0.8-4 times the level of leaving rest
            scale = rng.uniform(0.8, 4.0, n) * G * np.minimum(np.tan(alpha), mu)
        else:  # with the trough of u_v'' at -0.76 to -0.97 g
            scale = rng.uniform(0.95, 1.21, n) * G
        eta = 1.0 - 1.5 * np.sin(alpha) ** 2
        p = np.sqrt(0.75 * G / radius)
        record = Record(a_h, time=t, vertical=a_v)
        kind, _, times, samples, vsamples = record.kernel_spec()
        mp = np.column_stack([scale, np.zeros(n), np.zeros(n), np.full(n, record.duration)])
        rows = ck.contact_batch(p, alpha, eta, mu, mu, (kind, mp, times, samples, vsamples), RTOL)
        for i in range(n):
            make = functools.partial(scaled_record, t, a_h, a_v, scale[i])
            scene = (radius[i], alpha[i], eta[i], make, mu[i], mu[i])
            kernel = {name: rows[name][i] for name in rows.dtype.names}
            assert kernel["status"] == 0
            assert_agree(kernel, reference(scene), scene)
            seen |= {
                name[5:] for name in rows.dtype.names if name[:5] == "time_" and rows[name][i] > 0.0
            }
    assert seen == {"rest", "slide", "rock", "slide_rock", "flight"}


def test_simulate_runs_the_kernel_and_keeps_the_reference():
    """simulate(friction=) runs the kernel by default and the reference with
    method="scipy"; they agree within 10 rtol, history and outputs alike."""
    block = rs.Block(half_diagonal=1.0, slenderness=0.2)
    pulse = RickerWavelet(amplitude=2.0 * G * math.tan(0.2), period=0.6)
    kernel = rs.simulate(block, pulse, friction=0.21, rtol=RTOL)
    scipy = rs.simulate(block, pulse, friction=0.21, rtol=1e-12, method="scipy")
    assert kernel.info["solver"] == contact_model.KERNEL
    assert scipy.info["solver"] == contact_model.SOLVER
    assert scipy.regime_times["slide_rock"] > 0.0
    assert kernel.max_rotation == pytest.approx(scipy.max_rotation, rel=10 * RTOL)
    assert kernel.max_slide == pytest.approx(scipy.max_slide, rel=10 * RTOL)
    assert kernel.residual_slide == pytest.approx(scipy.residual_slide, rel=10 * RTOL)
    assert kernel.first_slip_time == pytest.approx(scipy.first_slip_time, abs=1e-9)
    np.testing.assert_allclose(kernel.impact_times, scipy.impact_times, rtol=0, atol=1e-9)
    for name, seconds in scipy.regime_times.items():
        assert kernel.regime_times[name] == pytest.approx(seconds, abs=1e-8)
    slide = kernel.to_xarray()["slide"]
    assert float(np.max(np.abs(slide))) == pytest.approx(kernel.max_slide, rel=1e-3)


def test_a_scene_that_does_not_converge_is_flagged():
    """A scene cut at its step limit has status 1 in a batch (never a plain answer), and
    simulate() raises StepLimitError for it; a scene at rest needs no step (status 0)."""
    pulse = SinePulse(amplitude=3.0, period=0.5)
    kind, mp, times, samples, vsamples = pulse.kernel_spec()
    alpha = np.array([0.2, 0.2])
    p = np.sqrt(0.75 * G / np.array([1.0, 1.0]))
    mp_rows = np.array([mp, mp * [0.1, 1.0, 1.0, 1.0]])  # the second stays at rest
    rows = ck.contact_batch(
        p, alpha, 0.94, 0.5, 0.5, (kind, mp_rows, times, samples, vsamples), RTOL, max_steps=5
    )
    assert list(rows["status"]) == [1, 0]
    assert rows["steps"][0] == 5 and rows["steps"][1] == 0
    with pytest.raises(rs.StepLimitError):
        contact_model._contact_kernel(
            1.0, 0.2, 0.94, pulse, (0.5, 0.5), "nonlinear", RTOL, None, max_steps=5
        )


def test_parallel_and_serial_batches_are_the_same_scenes():
    """The parallel batch gives each row the one-thread batch's answer, bit for bit, and
    the single-scene entry's."""
    rng = np.random.default_rng(7)
    scenes = [pulse_scene(rng, "rock") for _ in range(6)]
    radius, alpha, eta = (np.array([s[k] for s in scenes]) for k in range(3))
    mu = np.array([s[4] for s in scenes])
    motion = SinePulse(amplitude=2.5, period=0.5)
    kind, mp, times, samples, vsamples = motion.kernel_spec()
    rows = (kind, np.tile(mp, (6, 1)), times, samples, vsamples)
    p = np.sqrt(0.75 * G / radius)
    a = ck.contact_batch(p, alpha, eta, mu, mu, rows, RTOL)
    b = ck.contact_batch(p, alpha, eta, mu, mu, rows, RTOL, parallel=False)
    for name in a.dtype.names:
        np.testing.assert_array_equal(a[name], b[name])
    for i in range(6):
        one = ck.contact_scene(radius[i], alpha[i], eta[i], motion, mu[i], mu[i], RTOL)
        assert one["max_rotation"] == a["max_rotation"][i]
        assert one["max_slide"] == a["max_slide"][i]


def test_reference_leaves_rest_at_the_closed_form_time():
    """Under a sine pulse a sin(omega t), a block with mu < tan alpha leaves rest where
    a sin(omega t) = mu g: t = asin(mu g / a) / omega, to the ulps of the test (the
    reference once returned the next point of its scan grid, 1.1e-5 s late, when Brent's
    root lay more than 64 ulps from the switch)."""
    amplitude, period, mu = 5.263148098680732, 0.2277254057239914, 0.18985891398782673
    radius, alpha = 2.7838321219055624, 0.21468864602164256
    pulse = SinePulse(amplitude=amplitude, period=period)
    closed = math.asin(mu * G / amplitude) / (2.0 * math.pi / period)
    r = simulate_contact_reference(radius, alpha, 0.93, pulse, mu, mu, 1e-12)
    k = ck.contact_scene(radius, alpha, 0.93, pulse, mu, mu, RTOL)
    assert r["first_slip_time"] == pytest.approx(closed, rel=1e-14)
    assert k["first_slip_time"] == pytest.approx(closed, rel=1e-14)
