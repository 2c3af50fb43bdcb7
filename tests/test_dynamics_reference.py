"""The numba kernels against the scipy reference path (solve_ivp, DOP853, rtol 1e-12)."""

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.batch import simulate_batch

PULSES = [
    rs.motions.SinePulse,
    rs.motions.CosinePulse,
    rs.motions.HalfSinePulse,
    rs.motions.RickerWavelet,
]


def random_scenes(n, seed):
    """Blocks and pulses spanning rest (a_g below uplift), rocking and overturning."""
    rng = np.random.default_rng(seed)
    scenes = []
    for i in range(n):
        alpha = rng.uniform(0.05, 0.4)
        block = rs.Block(rng.uniform(0.3, 5.0), alpha)
        ratio = rng.choice([rng.uniform(0.5, 0.99), rng.uniform(1.05, 6.0)], p=[0.15, 0.85])
        cls = PULSES[i % len(PULSES)]
        amp = ratio * G * np.tan(alpha) * rng.choice([-1.0, 1.0])
        scenes.append((block, cls(amp, rng.uniform(0.1, 2.0))))
    return scenes


SCENES = random_scenes(60, seed=2024)


@pytest.fixture(scope="module")
def outcomes():
    out = []
    for block, pulse in SCENES:
        ref = rs.simulate(block, pulse, method="scipy", rtol=1e-12)
        ker = rs.simulate(block, pulse, method="nonlinear", rtol=1e-10)
        out.append((block, pulse, ref, ker))
    return out


def test_cases_cover_rest_rocking_and_overturning(outcomes):
    kinds = {
        ("rest" if r.max_rotation == 0 else "over" if r.overturned else "rock")
        for _, _, r, _ in outcomes
    }
    assert kinds == {"rest", "rock", "over"}


def test_overturning_decisions_agree(outcomes):
    for block, pulse, ref, ker in outcomes:
        assert ker.overturned == ref.overturned, (block, pulse)


def test_max_rotation_within_1e6(outcomes):
    for _, _, ref, ker in outcomes:
        if ref.overturned:
            assert ker.overturn_time == pytest.approx(ref.overturn_time, abs=1e-8)
        else:
            assert ker.max_rotation == pytest.approx(ref.max_rotation, rel=1e-6, abs=1e-12)


def test_first_ten_impact_times_within_1e8_s(outcomes):
    for block, pulse, ref, ker in outcomes:
        k = min(10, ref.n_impacts)
        assert ker.n_impacts >= k
        np.testing.assert_allclose(
            ker.impact_times[:k],
            ref.impact_times[:k],
            rtol=0,
            atol=1e-8,
            err_msg=str((block, pulse)),
        )


def test_batch_map_matches_integrated_free_rocking(outcomes):
    """The batch path maps the free rocking after the pulse; simulate integrates it."""
    for block, pulse, _, ker in outcomes:
        kind = {
            rs.motions.SinePulse: "sine",
            rs.motions.CosinePulse: "cosine",
            rs.motions.HalfSinePulse: "half-sine",
            rs.motions.RickerWavelet: "ricker",
        }
        b = simulate_batch(
            half_diagonal=block.half_diagonal,
            slenderness=block.slenderness,
            pulse=kind[type(pulse)],
            amplitude=pulse.amplitude,
            period=pulse.period,
            rtol=1e-10,
        )
        assert bool(b["overturned"][0]) == ker.overturned
        assert b["max_rotation"][0] == pytest.approx(ker.max_rotation, rel=1e-8, abs=1e-12)
        if not ker.overturned:
            assert int(b["n_impacts"][0]) == ker.n_impacts
        else:
            assert b["overturn_time"][0] == pytest.approx(ker.overturn_time, abs=1e-9)


@pytest.mark.parametrize("seed", [5, 6])
def test_linear_exact_solver_matches_scipy_linear(seed):
    rng = np.random.default_rng(seed)
    for i in range(12):
        alpha = rng.uniform(0.02, 0.3)
        block = rs.Block(rng.uniform(0.3, 5.0), alpha)
        cls = PULSES[i % 3]
        pulse = cls(rng.uniform(1.05, 5.0) * G * alpha, rng.uniform(0.1, 2.0))
        ref = rs.simulate(block, pulse, method="scipy-linear", rtol=1e-12)
        lin = rs.simulate(block, pulse, method="linear")
        assert lin.overturned == ref.overturned
        if not ref.overturned:
            assert lin.max_rotation == pytest.approx(ref.max_rotation, rel=1e-7)
        k = min(10, ref.n_impacts)
        np.testing.assert_allclose(lin.impact_times[:k], ref.impact_times[:k], atol=1e-8)


def test_linear_exact_matches_linear_kernel_in_batch():
    """Two independent solutions of eq. (3.1): closed form pieces and DOP853 integration."""
    from rockstudy.dynamics import _linear, _rocking
    from rockstudy.motions.pulses import pulse_kernel_rows

    rng = np.random.default_rng(11)
    n = 3000
    R = rng.uniform(0.3, 5, n)
    alpha = rng.uniform(0.02, 0.35, n)
    amp = rng.uniform(0.5, 6, n) * G * alpha
    period = rng.uniform(0.1, 2.0, n)
    p = np.sqrt(3 * G / (4 * R))
    eta = 1 - 1.5 * np.sin(alpha) ** 2
    for shape in ("sine", "cosine", "half-sine"):
        kind, mp = pulse_kernel_rows(shape, amp, period)
        exact = _linear.trig_batch(p, alpha, eta, mp)
        rk = _rocking.scene_batch(
            p,
            alpha,
            eta,
            _rocking.MODEL_LINEAR,
            kind,
            mp,
            np.zeros(2),
            np.zeros(2),
            np.empty(0),
            1e-11,
            10**6,
        )
        over = exact["overturned"] == 1.0
        np.testing.assert_array_equal(over, rk["overturned"] == 1.0)
        m_ex, m_rk = exact["max_rotation"], rk["max_rotation"]
        err = np.abs(m_rk - m_ex)[~over]
        assert np.all(err <= 1e-6 * m_ex[~over] + 1e-9 * alpha[~over]), err.max()
        t_ex, t_rk = exact["overturn_time"], rk["overturn_time"]
        np.testing.assert_allclose(t_rk[over], t_ex[over], rtol=0, atol=1e-8)
        f_ex, f_rk = exact["first_impact_time"], rk["first_impact_time"]
        np.testing.assert_array_equal(np.isnan(f_ex), np.isnan(f_rk))
        np.testing.assert_allclose(f_rk, f_ex, rtol=0, atol=1e-8)


def test_the_reference_says_when_its_impact_cap_cuts_the_run_short():
    """A reference run that stops at ``max_impacts`` warns instead of returning a short history
    as if it were the whole response (a rocking block under a pulse: 10 impacts or more)."""
    from rockstudy.dynamics.reference import simulate_reference

    block = rs.Block(1.0, 0.2)
    pulse = rs.motions.SinePulse(2.0 * G * np.tan(0.2), 0.5)
    p, eta = block.frequency_parameter, block.restitution
    full = simulate_reference(p, 0.2, eta, pulse, rtol=1e-10)
    assert full["impact_times"].size > 10 and not full["overturned"]
    with pytest.warns(rs.IncompleteReferenceWarning, match="max_impacts=3"):
        short = simulate_reference(p, 0.2, eta, pulse, rtol=1e-10, max_impacts=3)
    assert short["impact_times"].size == 3
    np.testing.assert_allclose(short["impact_times"], full["impact_times"][:3], rtol=1e-9)
