"""Physics oracles for the solvers: closed forms of [000], free-rocking period, energy,
restitution, mirror symmetry."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

import rockstudy as rs
from rockstudy import closedform as cf
from rockstudy.constants import G
from rockstudy.motions import NoMotion, SinePulse

FREE_METHODS = ["nonlinear", "linear", "scipy", "scipy-linear"]


@pytest.mark.parametrize("eta", [0.7, 0.85, 0.95])
def test_linear_solver_against_eq_4_13_after_pulse(eta):
    """Where the first impact follows the end of the pulse, eqs. (3.13), (3.15) and (4.13) of
    [000] are exact for the linearized block."""
    alpha = 0.05
    block = rs.Block(1.3, alpha, restitution=eta)
    p = block.frequency_parameter
    checked = 0
    for a in (1.1, 1.3, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0):
        for omega in (2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0):
            wg = omega * p
            pulse = SinePulse(a * G * alpha, 2 * math.pi / wg)
            res = rs.simulate(block, pulse, method="linear")
            if res.n_impacts == 0 or res.impact_times[0] <= pulse.duration:
                continue  # impact during the pulse: (4.13) is then only approximate
            t_up = math.asin(1.0 / a) / wg
            tau_i2 = p * (res.impact_times[0] - t_up)
            assert tau_i2 == pytest.approx(cf.first_impact_time_after_pulse(a, omega), abs=1e-10)
            i = np.searchsorted(res.t, res.impact_times[0])
            v_pre = abs(res.theta_dot[i]) / (p * alpha)
            assert v_pre == pytest.approx(cf.impact_velocity_after_pulse(a, omega), rel=1e-9)
            closed = cf.max_rotation(a, omega, eta)
            if np.isnan(closed):
                assert res.overturned
            else:
                after = res.max_rotation / alpha  # the peak after the impact dominates here
                peak_during = np.abs(res.theta[res.t <= res.impact_times[0]]).max() / alpha
                if closed > peak_during:
                    assert after == pytest.approx(closed, rel=1e-8)
                    checked += 1
    assert checked >= 5


@pytest.mark.parametrize("method", ["linear", "scipy-linear"])
def test_housner_free_rocking_period_linearized(method):
    """T = (4/p) arccosh(1 / (1 - theta0/alpha)) for the linearized block (Housner 1963)."""
    block = rs.Block(2.0, 0.15, restitution=1.0)
    p = block.frequency_parameter
    for ratio in (0.1, 0.5, 0.9):
        res = rs.simulate(
            block,
            NoMotion(),
            method=method,
            initial_rotation=ratio * 0.15,
            rtol=1e-11,
            t_max=30.0 / p,
        )
        period = 4.0 / p * math.acosh(1.0 / (1.0 - ratio))
        assert res.impact_times[0] == pytest.approx(period / 4, abs=1e-10)
        np.testing.assert_allclose(np.diff(res.impact_times[:6]), period / 2, atol=1e-9)


@pytest.mark.parametrize("method", ["nonlinear", "scipy"])
def test_free_rocking_period_nonlinear_by_quadrature(method):
    """Quarter period of eq. (2.2): integral of d theta / theta_dot from energy conservation."""
    alpha, R = 0.3, 1.0
    block = rs.Block(R, alpha, restitution=1.0)
    p = block.frequency_parameter
    for th0 in (0.05, 0.2, 0.29):
        # cos(alpha - u) - cos(alpha - th0) = 2 sin((2 alpha - u - th0) / 2) sin((th0 - u) / 2);
        # the 1/sqrt(th0 - u) singularity goes into quad's algebraic weight
        def smooth(u, th0=th0):
            d = th0 - u
            sinc = math.sin(d / 2) / (d / 2) if d > 0 else 1.0
            return 1.0 / math.sqrt(2 * p * p * math.sin((2 * alpha - u - th0) / 2) * sinc)

        quarter, _ = quad(smooth, 0.0, th0, weight="alg", wvar=(0.0, -0.5), epsabs=0, epsrel=1e-13)
        res = rs.simulate(
            block, NoMotion(), method=method, initial_rotation=th0, rtol=1e-11, t_max=40.0 / p
        )
        assert res.impact_times[0] == pytest.approx(quarter, rel=1e-9)
        np.testing.assert_allclose(np.diff(res.impact_times[:6]), 2 * quarter, rtol=1e-8)


def _jumps(res):
    """Indices i where t[i] == t[i+1]: the pre/post rows of an impact."""
    return np.flatnonzero(np.diff(res.t) == 0.0)


@pytest.mark.parametrize("method", ["nonlinear", "scipy"])
def test_energy_conserved_between_impacts_and_eta_once_per_impact(method):
    alpha, eta = 0.25, 0.8
    block = rs.Block(1.5, alpha, restitution=eta)
    p = block.frequency_parameter
    res = rs.simulate(block, NoMotion(), method=method, initial_rotation=0.2, rtol=1e-10)
    th, om = res.theta, res.theta_dot
    jumps = _jumps(res)
    assert jumps.size == res.n_impacts > 10
    np.testing.assert_allclose(om[jumps + 1] / om[jumps], eta, rtol=1e-13)
    energy = 0.5 * om**2 + p * p * np.cos(alpha - np.abs(th))
    bounds = np.concatenate([[0], jumps + 1, [th.size]])
    for k in range(min(8, bounds.size - 1)):
        seg = energy[bounds[k] : bounds[k + 1]]
        np.testing.assert_allclose(seg, seg[0], rtol=1e-9)
    # each impact multiplies the kinetic energy at theta = 0 by eta^2, exactly once
    e_at_zero = energy[jumps[:8] + 1] - p * p * math.cos(alpha)
    np.testing.assert_allclose(e_at_zero[1:] / e_at_zero[:-1], eta**2, rtol=1e-8)


@pytest.mark.parametrize("method", ["nonlinear", "linear", "scipy"])
def test_mirror_symmetry(method):
    block = rs.Block(1.0, 0.2)
    for pulse in (
        SinePulse(2.0 * G * math.tan(0.2), 0.7),
        rs.motions.RickerWavelet(1.8 * G * math.tan(0.2), 0.5),
    ):
        mirrored = type(pulse)(-pulse.amplitude, pulse.period)
        a = rs.simulate(block, pulse, method=method)
        b = rs.simulate(block, mirrored, method=method)
        np.testing.assert_array_equal(a.t, b.t)
        np.testing.assert_array_equal(a.theta, -b.theta)
        np.testing.assert_array_equal(a.impact_times, b.impact_times)
        assert a.max_rotation == b.max_rotation


@pytest.mark.parametrize("method", ["nonlinear", "linear"])
def test_below_uplift_nothing_moves(method):
    alpha = 0.2
    thr = G * (math.tan(alpha) if method == "nonlinear" else alpha)
    res = rs.simulate(rs.Block(1.0, alpha), SinePulse(0.999 * thr, 0.5), method=method)
    assert res.max_rotation == 0.0 and res.n_impacts == 0 and not res.overturned


def test_simulate_rejects_bad_arguments():
    block = rs.Block(1.0, 0.2)
    pulse = SinePulse(3.0, 0.5)
    with pytest.raises(ValueError, match="method"):
        rs.simulate(block, pulse, method="nonlinaer")
    with pytest.raises(ValueError, match="rtol"):
        rs.simulate(block, pulse, rtol=0.0)
    with pytest.raises(ValueError, match="initial_rotation"):
        rs.simulate(block, pulse, initial_rotation=2.0)
    with pytest.raises(ValueError, match="initial_velocity"):
        rs.simulate(block, pulse, initial_velocity=float("nan"))
    with pytest.raises(TypeError, match="motion"):
        rs.simulate(block, [1.0, 2.0])
