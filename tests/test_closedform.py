"""Closed forms of paper [000] (sine pulse, linearized block) and [003] eqs. (24)-(25),
against the exact linear solver and independent numerical solutions."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rockstudy as rs
from rockstudy import closedform as cf
from rockstudy.constants import G
from rockstudy.motions import NoMotion, SinePulse

ALPHA = 0.1
R_UNIT = 3 * G / 4  # p = 1 rad/s: t = tau


def linear_modes(a, omega, eta):
    """Mode of [000] Fig. 2 of each (a, omega) from the exact linear solver (an index of
    cf.MODES), and the solver output."""
    a, omega = np.broadcast_arrays(np.asarray(a, float), np.asarray(omega, float))
    out = rs.simulate_batch(
        half_diagonal=R_UNIT,
        slenderness=ALPHA,
        restitution=eta,
        pulse="sine",
        amplitude=a.ravel() * G * ALPHA,
        period=2 * np.pi / omega.ravel(),
        method="linear",
    )
    end = 2 * np.pi / omega.ravel()
    modes = np.where(
        out["max_rotation"] == 0,
        0,
        np.where(
            out["overturned"],
            np.where(out["n_impacts"] == 0, 4, 3),
            np.where(out["first_impact_time"] <= end, 1, 2),
        ),
    )
    return modes.reshape(a.shape), out


def test_impact_during_pulse_eqs_3_21_3_22():
    p = 1.0
    block = rs.Block(R_UNIT, ALPHA, restitution=0.8)
    checked = 0
    for a in (1.2, 1.5, 2.0, 3.0):
        for omega in (0.5, 1.0, 2.0, 3.0):
            pulse = SinePulse(a * G * ALPHA, 2 * math.pi / omega)
            res = rs.simulate(block, pulse, method="linear")
            if not res.n_impacts or res.impact_times[0] > pulse.duration:
                assert np.isnan(cf.first_impact_time_during_pulse(a, omega))
                continue
            t_up = math.asin(1 / a) / omega
            tau = p * (res.impact_times[0] - t_up)
            assert cf.first_impact_time_during_pulse(a, omega) == pytest.approx(tau, abs=1e-9)
            i = np.searchsorted(res.t, res.impact_times[0])
            v = res.theta_dot[i] / (p * ALPHA)
            assert cf.impact_velocity_during_pulse(a, omega, tau) == pytest.approx(v, abs=1e-9)
            checked += 1
    assert checked >= 6


def contact_orders(d, err, smallest=0.005, bands=3):
    """log2 of how much the largest error falls each time the distance d to the point of
    contact halves (bands [smallest 2^k, smallest 2^(k+1)) ): about 3 for third order."""
    edges = smallest * 2.0 ** np.arange(bands + 1)
    worst = []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        band = (d >= lo) & (d < hi)
        assert band.sum() >= 5, (lo, hi)
        worst.append(np.max(err[band]))
    return np.diff(np.log2(worst))


def test_semi_analytical_impact_time_has_third_order_contact_at_tau_1():
    """(3.29) replaces sin(omega tau + psi) by its value at tau = 1 plus kappa e^-tau +
    lambda e^tau, whose first and second derivatives match the sine's there (3.24-3.27). The
    root of (3.21) is then missed by O(|tau_i1 - 1|^3): halving the distance to tau = 1 must
    divide the largest error by about 8 (the order, not a measured error size)."""
    A, W = np.meshgrid(np.geomspace(1.001, 10, 400), np.geomspace(0.3, 12, 400), indexing="ij")
    exact = cf.first_impact_time_during_pulse(A, W)
    approx = cf.first_impact_time_during_pulse_approx(A, W, check=False)
    near = np.abs(exact - 1) < 0.04
    assert np.isfinite(approx[near]).all()
    orders = contact_orders(np.abs(exact - 1), np.abs(approx - exact))
    assert np.all((orders > 2.5) & (orders < 4))


def test_semi_analytical_case_1_1_boundary_inherits_the_contact():
    """(3.30) is (3.20) with (3.29)'s impact time, so it meets the numerical case-1.1
    boundary of (3.20)-(3.21) to third order where that boundary's tau_i1 approaches 1
    (stiff, nearly elastic blocks, omega ~ 4)."""
    omega = np.geomspace(3.0, 5.0, 40)
    d, err = [], []
    for eta in (0.95, 0.97, 0.99, 1.0):
        num = cf.overturning_boundary(omega, eta, "1.1")[:, 0]
        semi = cf.overturning_boundary(omega, eta, "1.1-approx")[:, 0]
        ok = np.isfinite(num) & np.isfinite(semi)
        d.append(np.abs(cf.first_impact_time_during_pulse(num[ok], omega[ok]) - 1))
        err.append(np.abs(semi[ok] / num[ok] - 1))
    orders = contact_orders(np.concatenate(d), np.concatenate(err))
    assert np.all((orders > 2.5) & (orders < 4.5))


@pytest.mark.parametrize("eta", [0.7, 0.85, 0.95])
def test_classifier_agrees_with_linear_solver(eta):
    """100 x 100 grid: >= 99 % agreement outside a 1 % band (in a) around the boundaries."""
    A, W = np.meshgrid(np.geomspace(1.01, 10, 100), np.geomspace(0.5, 12, 100), indexing="ij")
    sim, _ = linear_modes(A, W, eta)
    closed = cf.overturning_mode_code(A, W, eta)
    band = np.zeros(A.shape, bool)
    for f in (0.99, 1.01):
        band |= linear_modes(A * f, W, eta)[0] != sim
        band |= cf.overturning_mode_code(A * f, W, eta) != closed
    agree = sim == closed
    assert agree[~band].mean() >= 0.99
    assert band.mean() < 0.05
    labels = cf.overturning_mode(A, W, eta)
    assert set(np.unique(labels)) <= set(cf.MODES)


@pytest.mark.parametrize("case, mode", [("2", 4), ("1.2", 3), ("1.1", 3)])
@pytest.mark.parametrize("eta", [0.7, 0.95])
def test_each_boundary_separates_two_modes(case, mode, eta):
    """Simulating a (1 -+ 1e-3) either side of a boundary curve gives two different modes, one
    of them the curve's own (4: without impact, 3: after one impact), as the classifier says."""
    omega = np.geomspace(0.6, 10, 25)
    roots = cf.overturning_boundary(omega, eta, case)
    w = np.broadcast_to(omega[:, None], roots.shape)[np.isfinite(roots)]
    r = roots[np.isfinite(roots)]
    assert r.size >= 8
    lo, out_lo = linear_modes(r * (1 - 1e-3), w, eta)
    hi, out_hi = linear_modes(r * (1 + 1e-3), w, eta)
    # overturning after two or more impacts is outside the closed forms: leave those out
    single = ~(
        (out_lo["overturned"] & (out_lo["n_impacts"] >= 2))
        | (out_hi["overturned"] & (out_hi["n_impacts"] >= 2))
    )
    assert single.mean() >= 0.9
    lo, hi, r, w = lo[single], hi[single], r[single], w[single]
    assert np.all(lo != hi)
    assert np.all((lo == mode) | (hi == mode))
    np.testing.assert_array_equal(lo, cf.overturning_mode_code(r * (1 - 1e-3), w, eta))
    np.testing.assert_array_equal(hi, cf.overturning_mode_code(r * (1 + 1e-3), w, eta))


def test_limit_curve_eq_3_31_separates_impact_during_and_after_pulse():
    omega = np.geomspace(0.6, 10, 25)
    a_lim = cf.overturning_boundary(omega, 0.85, "limit")[:, 0]
    ok = np.isfinite(a_lim)
    assert ok.sum() >= 10
    end = 2 * np.pi / omega[ok]
    _, below = linear_modes(a_lim[ok] * (1 - 1e-3), omega[ok], 0.85)
    _, above = linear_modes(a_lim[ok] * (1 + 1e-3), omega[ok], 0.85)
    assert np.all(below["first_impact_time"] <= end)
    assert np.all(~(above["first_impact_time"] <= end))  # later, or no impact at all


def test_max_rotation_spectrum_and_restitution_law():
    a, omega = 3.0, 6.0
    for eta in (0.8, 0.9, 0.96):
        _, out = linear_modes(a, omega, eta)
        assert cf.max_rotation(a, omega, eta) == pytest.approx(
            out["max_rotation"][0] / ALPHA, rel=1e-9
        )
    # (4.14)-(4.16) against the solver's peak after the first impact (which follows the pulse
    # here): theta_m / alpha = 1 - sqrt(1 - x), x = eta^2 f, f = 1 - D0* (4.16), whose excess
    # over the small-x law x / 2 is x / 4 + O(x^2)
    f = cf.restitution_scaling_function(a, omega)
    for eta in (0.05, 0.1, 0.2):
        res = rs.simulate(
            rs.Block(R_UNIT, ALPHA, restitution=eta),
            SinePulse(a * G * ALPHA, 2 * np.pi / omega),
            method="linear",
        )
        first, second = res.impact_times[:2]
        after = (res.t > first) & (res.t < second)
        peak = np.max(np.abs(res.theta[after])) / ALPHA
        x = eta**2 * f
        assert peak / (0.5 * f * eta**2) - 1 == pytest.approx(x / 4, rel=0.1)
        assert cf.max_rotation_small(a, omega, eta) == pytest.approx(peak, rel=0.3 * x)


def test_free_rocking_period_eq_24_of_003():
    block = rs.Block(R_UNIT, ALPHA, restitution=1.0)
    for ratio in (0.2, 0.6, 0.95):
        res = rs.simulate(
            block, NoMotion(), method="linear", initial_rotation=ratio * ALPHA, t_max=60.0
        )
        period = cf.free_rocking_period(1.0, ratio)
        np.testing.assert_allclose(np.diff(res.impact_times[:5]), period / 2, atol=1e-9)
    assert np.isnan(cf.free_rocking_period(1.0, 1.2))


def test_overturning_time_eq_25_of_003():
    """Against solve_ivp on the linearized block under a constant acceleration."""
    p = 2.0
    for ratio in (1.05, 1.5, 3.0):
        q = ratio * ALPHA

        def reach(t, y):
            return y[0] - ALPHA

        reach.terminal = True
        sol = solve_ivp(
            lambda t, y, q=q: [y[1], p * p * (y[0] - ALPHA + q)],
            (0, 100),
            [0, 0],
            events=reach,
            rtol=1e-12,
            atol=1e-14,
        )
        t_num = sol.t_events[0][0]
        assert cf.overturning_time_constant_acceleration(p, ratio) == pytest.approx(t_num, rel=1e-9)
    assert cf.overturning_time_constant_acceleration(p, 0.9) == np.inf


def test_pulse_end_and_d0_product_form():
    a, omega = 2.5, 3.0
    psi = math.asin(1 / a)
    assert cf.pulse_end_time(a, omega) == pytest.approx((2 * math.pi - psi) / omega)
    assert np.isnan(cf.d0_star(0.9, omega))
    # the expanded form of (3.9) with the square restored (DESIGN.md errata) equals the product
    te = (2 * math.pi - psi) / omega
    r = math.sqrt(a * a - 1)
    expanded = (omega / (omega**2 + 1)) ** 2 * (
        omega**2 - 2 * a * a + 1 + (r + omega) * a * math.exp(-te) + (r - omega) * a * math.exp(te)
    )
    assert cf.d0_star(a, omega) == pytest.approx(expanded, rel=1e-12)
