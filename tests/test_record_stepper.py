"""The Taylor-series record step (dynamics/_taylor.py) and the kernel that uses it, against
independent oracles: the hyperbolic closed form of the linearized block (3.1) of [000] under
a constant ground acceleration, scipy's DOP853 on one step, and the scipy reference path
(solve_ivp DOP853 at rtol 1e-12) on synthetic and real records."""

import math

import numpy as np
import pytest
from _helpers import REAL_RECORD_FILES as FILES
from _helpers import load_real_record as load
from scipy.integrate import solve_ivp

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import _taylor
from rockstudy.dynamics._rocking import TRIG_STEP_CAP
from rockstudy.dynamics.batch import simulate_batch

P, ALPHA = 2.5, 0.2


def coefficients(th, om, s, model, h, a0, a1, v0=0.0, v1=0.0, tol=1e-13):
    """The step polynomial's coefficients and order at a tolerance of tol (relative)."""
    w = _taylor.work_arrays()
    sc_x, sc_v = tol * ALPHA, tol * P * ALPHA
    n, err = _taylor.taylor_coefficients(
        w, th, om, s, P, ALPHA, model, h, a0, a1, v0, v1, sc_x, sc_v
    )
    assert err <= 1.0
    return w[0, : n + 1].copy(), n


def test_constant_acceleration_series_is_the_cosh_sinh_closed_form():
    # eq. (3.1) of [000] with a constant a_g: theta = c + (th0 - c) cosh(p t) + om0/p sinh(p t),
    # c = alpha s + a_g / g, whose k-th scaled Taylor coefficient is (p h)^k / k! times
    # (th0 - c) (k even) or om0 / p (k odd)
    th0, om0, s, a_g, h = 0.03, -0.2, 1.0, -0.4 * G * ALPHA, 0.02
    c, n = coefficients(th0, om0, s, _taylor.MODEL_LINEAR, h, a_g, a_g)
    centre = ALPHA * s + a_g / G
    k = np.arange(n + 1)
    amp = np.where(k % 2 == 0, th0 - centre, om0 / P)
    expected = amp * (P * h) ** k / np.array([math.factorial(int(j)) for j in k])
    expected[0] += centre
    np.testing.assert_allclose(c, expected, rtol=1e-13, atol=1e-18)
    exact = centre + (th0 - centre) * math.cosh(P * h) + om0 / P * math.sinh(P * h)
    assert _taylor.poly_value(c, n, 1.0)[0] == pytest.approx(exact, rel=1e-14)


def one_step_reference(th, om, s, model, h, a0, a1, v0, v1):
    """theta, theta_dot after h by scipy's DOP853 at rtol 1e-13 on the same equation."""

    def rhs(t, y):
        a = (a0 + (a1 - a0) * t / h) / G
        v = (v0 + (v1 - v0) * t / h) / G
        x = ALPHA * s - y[0]
        if model == _taylor.MODEL_LINEAR:
            return [y[1], -P * P * ((1.0 + v) * x + a)]
        return [y[1], -P * P * ((1.0 + v) * math.sin(x) + a * math.cos(x))]

    sol = solve_ivp(rhs, (0.0, h), [th, om], method="DOP853", rtol=1e-13, atol=1e-16)
    return sol.y[:, -1]


@pytest.mark.parametrize("model", [_taylor.MODEL_NONLINEAR, _taylor.MODEL_LINEAR])
@pytest.mark.parametrize("h", [0.01, 0.05, 0.15])
def test_one_step_matches_a_high_order_reference(model, h):
    # horizontal and vertical ground accelerations linear over the step, both sides
    for s, th, om in ((1.0, 0.05, 0.3), (-1.0, -0.12, 0.4)):
        a0, a1, v0, v1 = 2.0, -3.0, 1.5, -2.5
        c, n = coefficients(th, om, s, model, h, a0, a1, v0, v1)
        x, d, _ = _taylor.poly_value(c, n, 1.0)
        ref = one_step_reference(th, om, s, model, h, a0, a1, v0, v1)
        assert x == pytest.approx(ref[0], abs=1e-13)
        assert d / h == pytest.approx(ref[1], abs=1e-12)


def trig_coefficients(th, om, s, model, h, amp, omega, phase, tol=1e-13):
    """The step polynomial under amp sin(omega t + phase) [m/s^2] from t = 0, and its order."""
    w = _taylor.work_arrays()
    sc_x, sc_v = tol * ALPHA, tol * P * ALPHA
    n, err = _taylor.taylor_coefficients_trig(
        w, th, om, s, P, ALPHA, model, h, amp, phase, omega * h, sc_x, sc_v
    )
    assert err <= 1.0
    return w[0, : n + 1].copy(), n


@pytest.mark.parametrize("omega", [1.0, 6.0, 25.0])
def test_sine_pulse_series_is_the_linear_closed_form(omega):
    # eq. (3.1) of [000] under a_g sin(omega t + phi): theta = alpha s + K sin(omega t + phi)
    # + C cosh(p t) + D sinh(p t), K = p^2 a_g / (g (p^2 + omega^2)), C and D from the start
    amp, phase, s, th0, om0 = 3.0, 0.7, -1.0, -0.04, 0.25
    K = P * P * amp / (G * (P * P + omega * omega))
    C = th0 - ALPHA * s - K * math.sin(phase)
    D = (om0 - K * omega * math.cos(phase)) / P
    for h in (0.02, TRIG_STEP_CAP / max(P, omega)):  # up to the kernel's longest step
        c, n = trig_coefficients(th0, om0, s, _taylor.MODEL_LINEAR, h, amp, omega, phase)
        x, d, _ = _taylor.poly_value(c, n, 1.0)
        t = h
        exact = ALPHA * s + K * math.sin(omega * t + phase) + C * math.cosh(P * t)
        exact += D * math.sinh(P * t)
        rate = K * omega * math.cos(omega * t + phase) + P * (C * math.sinh(P * t))
        rate += P * D * math.cosh(P * t)
        assert x == pytest.approx(exact, abs=1e-14)
        assert d / h == pytest.approx(rate, abs=1e-13)


def trig_step_reference(th, om, s, h, amp, omega, phase):
    """theta, theta_dot after h of Housner's (2.2) under amp sin(omega t + phase), by scipy's
    DOP853 at rtol 1e-13."""

    def rhs(t, y):
        a = amp * math.sin(omega * t + phase) / G
        x = ALPHA * s - y[0]
        return [y[1], -P * P * (math.sin(x) + a * math.cos(x))]

    sol = solve_ivp(rhs, (0.0, h), [th, om], method="DOP853", rtol=1e-13, atol=1e-16)
    return sol.y[:, -1]


@pytest.mark.parametrize("amp", [0.0, 4.0, -9.0])
@pytest.mark.parametrize("omega", [2.0, 20.0])
def test_nonlinear_trig_step_matches_a_high_order_reference(amp, omega):
    # the longest step the kernel takes (TRIG_STEP_CAP in p t and omega t), both sides
    h = TRIG_STEP_CAP / max(P, omega)
    for s, th, om in ((1.0, 0.05, 0.3), (-1.0, -0.12, 0.4), (1.0, 0.0, 0.0)):
        c, n = trig_coefficients(th, om, s, _taylor.MODEL_NONLINEAR, h, amp, omega, 1.1)
        x, d, _ = _taylor.poly_value(c, n, 1.0)
        ref = trig_step_reference(th, om, s, h, amp, omega, 1.1)
        assert x == pytest.approx(ref[0], abs=1e-13)
        assert d / h == pytest.approx(ref[1], abs=1e-12)


def test_a_step_whose_series_does_not_converge_is_rejected():
    w = _taylor.work_arrays()
    # p h = 25: the series of sin(x) has no chance at order MAX_ORDER
    n, err = _taylor.taylor_coefficients(
        w, 0.1, 1.0, 1.0, P, ALPHA, 0, 10.0, 1.0, 1.0, 0.0, 0.0, 1e-9, 1e-9
    )
    assert n == _taylor.MAX_ORDER
    assert err > 1.0


def test_poly_root_finds_a_known_root():
    c = np.array([-0.5, 0.0, 2.0])  # 2 x^2 - 1/2: root at 0.5
    assert _taylor.poly_root(c, 2, 0.0, -1.0, False, 0.0, 1.0) == pytest.approx(0.5, abs=1e-14)
    # its derivative 4 x crosses 1 at x = 0.25
    assert _taylor.poly_root(c, 2, 1.0, -1.0, True, 0.0, 1.0) == pytest.approx(0.25, abs=1e-14)


def synthetic(seed, pga):
    return rs.motions.synthetic_near_fault(1.0, pga, seed=seed, duration=12.0, dt=0.01)


@pytest.mark.parametrize("method,reference", [("nonlinear", "scipy"), ("linear", "scipy-linear")])
@pytest.mark.parametrize("seed,ratio", [(1, 1.6), (2, 3.0), (3, 6.0)])
def test_synthetic_record_like_the_reference(method, reference, seed, ratio):
    block = rs.Block(1.2, 0.2)
    rec = synthetic(seed, ratio * G * math.tan(block.slenderness))
    ker = rs.simulate(block, rec, method=method, rtol=1e-10)
    ref = rs.simulate(block, rec, method=reference, rtol=1e-12)
    assert ker.overturned == ref.overturned
    if not ref.overturned:
        assert ker.max_rotation == pytest.approx(ref.max_rotation, rel=1e-7)
        assert ker.n_impacts == ref.n_impacts
    else:
        assert ker.overturn_time == pytest.approx(ref.overturn_time, abs=1e-7)
    k = min(10, ref.n_impacts)
    np.testing.assert_allclose(ker.impact_times[:k], ref.impact_times[:k], atol=1e-7)


def test_history_of_a_record_is_on_the_reference_trajectory():
    block = rs.Block(1.2, 0.2)
    rec = synthetic(6, 2.0 * G * math.tan(block.slenderness))
    ker = rs.simulate(block, rec, rtol=1e-10)
    ref = rs.simulate(block, rec, method="scipy", rtol=1e-12)
    assert not ref.overturned and ref.n_impacts >= 10
    # both histories hold the record's sample times while rocking (steps end on samples):
    # compare theta there, away from the impact instants
    common = np.intersect1d(ker.t, ref.t)
    common = common[(common < rec.duration) & ~np.isin(common, ref.impact_times)]
    assert common.size > 500
    k_th = np.interp(common, ker.t, ker.theta)
    r_th = np.interp(common, ref.t, ref.theta)
    np.testing.assert_allclose(k_th, r_th, rtol=0, atol=1e-9 * block.slenderness)


def test_step_cap_counts_taylor_steps():
    block = rs.Block(1.2, 0.2)
    rec = synthetic(5, 3.0 * G * math.tan(block.slenderness))
    out = simulate_batch(
        half_diagonal=1.2, slenderness=0.2, record=rec, scale=[1.0, 1.0], max_steps=50
    )
    assert list(out["status"]) == [1, 1]
    full = simulate_batch(half_diagonal=1.2, slenderness=0.2, record=rec, scale=1.0)
    assert full["status"][0] == 0
    # one Taylor step per sample segment while rocking, at most: a few more at impacts
    rocking_samples = rec.duration / 0.01
    assert 50 < full["steps"][0] < 2 * rocking_samples


@pytest.mark.parametrize("name", FILES)
def test_real_record_at_rtol_1e6_like_the_reference(records_dir, name):
    rec = load(records_dir, name)
    rng = np.random.default_rng(7)
    for R, alpha, ratio in zip(
        rng.uniform(0.5, 3.0, 2), rng.uniform(0.1, 0.3, 2), rng.uniform(0.8, 6.0, 2), strict=True
    ):
        block = rs.Block(R, alpha)
        scaled = rec.scaled(ratio * G * math.tan(alpha) / rec.peak)
        out = simulate_batch(half_diagonal=R, slenderness=alpha, record=scaled, rtol=1e-6)
        ref = rs.simulate(block, scaled, method="scipy", rtol=1e-12)
        assert bool(out["overturned"][0]) == ref.overturned
        if not ref.overturned:
            assert out["max_rotation"][0] == pytest.approx(ref.max_rotation, rel=1e-6)
        if ref.n_impacts:
            assert out["first_impact_time"][0] == pytest.approx(ref.impact_times[0], abs=1e-6)


def test_uplift_skips_quiet_samples_without_missing_a_crossing():
    # a record whose only loud sample is exactly at the uplift level times (1 + 1e-12): the
    # prefilter must leave it to the exact test, which lifts the block there
    alpha = 0.2
    times = np.arange(0.0, 5.0001, 0.01)
    acc = np.full(times.size, 0.1 * G * math.tan(alpha))
    i = 300
    acc[i] = G * math.tan(alpha) * (1.0 + 1e-12)
    rec = rs.motions.Record(acc, dt=0.01)
    res = rs.simulate(rs.Block(1.0, alpha), rec, rtol=1e-8)
    assert res.t[1] == pytest.approx(times[i], abs=1e-9)
