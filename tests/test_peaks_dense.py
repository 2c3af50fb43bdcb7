"""Exact peaks and dense output of ``simulate`` (issue 15, section 1).

Oracles: the free-rocking closed forms of [000] (energy between impacts, eta per impact,
eq. 2.3 and 4.12; the cosh/sinh solution of the linearized eq. 3.1 for the times), and
``solve_ivp`` DOP853 at rtol 1e-12 with scipy's own event location and dense output (the
``"scipy"`` method, rockstudy/dynamics/reference.py, which shares nothing with the kernels but
the model), under a sine pulse and a record.
"""

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import rockstudy as rs  # noqa: E402
from rockstudy.motions import NoMotion, SinePulse, stochastic_record  # noqa: E402
from rockstudy.structures import PointMassStrut  # noqa: E402

ALPHA = 0.2
BLOCK = rs.Block(1.0, ALPHA)
P = math.sqrt(3 * 9.81 / 4)  # a rectangular block of R = 1 m: p^2 = 3 g / (4 R)
ETA = 1 - 1.5 * math.sin(ALPHA) ** 2  # Housner's restitution, eq. (2.3) of [000]
THETA0 = 0.7 * ALPHA


def energy_map_peaks(theta0, alpha, eta, n):
    """|theta| of the first n peaks of free rocking released at rest from theta0: between
    impacts cos(alpha - theta_max) - cos(alpha) (the energy above the impact level, / p^2) is
    conserved, and each impact multiplies it by eta^2 (the speed by eta)."""
    rise = math.cos(alpha - theta0) - math.cos(alpha)
    out = []
    for k in range(n):
        out.append(alpha - math.acos(math.cos(alpha) + rise * eta ** (2 * k)))
    return np.array(out)


def linear_free_peaks(theta0, alpha, eta, p, n):
    """Peak times [s] and |theta| of free rocking of the linearized block (eq. 3.1 of [000]),
    released at rest from theta0: u = alpha - (alpha - u0) cosh(p t) to the impact, speed
    p sqrt(alpha^2 - (alpha - u0)^2) there, then u = alpha (1 - cosh) + (v/p) sinh to the
    next peak, at tanh(p t) = v / (p alpha), of alpha - sqrt(alpha^2 - (v/p)^2)."""
    t, u = 0.0, theta0
    times, peaks = [t], [u]
    for _ in range(n - 1):
        t += math.acosh(alpha / (alpha - u)) / p
        v = eta * p * math.sqrt(alpha**2 - (alpha - u) ** 2)
        t += math.atanh(v / (p * alpha)) / p
        u = alpha - math.sqrt(alpha**2 - (v / p) ** 2)
        times.append(t)
        peaks.append(u)
    return np.array(times), np.array(peaks)


def assert_alternating(r):
    """A peak between each pair of impacts, and the side changes at every impact."""
    sides = np.sign(r.peak_rotations)
    bounds = np.concatenate([[-np.inf], r.impact_times, [np.inf]])
    slot = np.searchsorted(bounds, r.peak_times) - 1  # the inter-impact interval of each peak
    for k in range(1, slot.size):
        if slot[k] == slot[k - 1]:  # two peaks between the same impacts: same side
            assert sides[k] == sides[k - 1]
        else:  # the side flips at each impact in between (one pivot, then the other)
            assert sides[k] == sides[k - 1] * (-1) ** (slot[k] - slot[k - 1])


# ---------------------------------------------------------------- free rocking: closed forms


def test_free_rocking_peaks_are_the_energy_map():
    r = rs.simulate(BLOCK, NoMotion(), rtol=1e-10, initial_rotation=THETA0)
    n = r.peak_rotations.size
    assert n > 50  # the whole free rocking, down to the Zeno rest
    exact = energy_map_peaks(THETA0, ALPHA, ETA, n)
    np.testing.assert_allclose(np.abs(r.peak_rotations), exact, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(np.sign(r.peak_rotations), (-1.0) ** np.arange(n))
    # one peak between each pair of impacts (the release at t = 0 is the first)
    assert r.peak_times[0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(r.impact_times[: n - 1] < r.peak_times[1:])
    assert np.all(r.peak_times[1:] < r.impact_times[1:n])
    assert np.max(np.abs(r.peak_rotations)) == pytest.approx(r.max_rotation, rel=1e-12)


def test_history_has_points_inside_every_half_cycle():
    # late in free rocking a whole half-cycle fits in one DOP853 step: the history must still
    # sample its inside (it held only the two impacts, theta = 0, and drew a flat line there)
    r = rs.simulate(BLOCK, NoMotion(), initial_rotation=THETA0)
    inside = np.searchsorted(r.t, r.impact_times[1:], "left") - np.searchsorted(
        r.t, r.impact_times[:-1], "right"
    )
    assert r.n_impacts > 50 and np.all(inside >= 3)


@pytest.mark.filterwarnings("ignore::rockstudy.LinearizationWarning")
@pytest.mark.parametrize("motion", ["pulse solver", "kernel"])
def test_linearized_free_rocking_peaks_and_times_are_the_closed_form(motion):
    # NoMotion is a trigonometric motion: the exact piecewise solver; a record of zeros
    # sends method="linear" to the DOP853 kernel
    ground = NoMotion() if motion == "pulse solver" else rs.motions.Record(np.zeros(3), dt=0.01)
    r = rs.simulate(BLOCK, ground, method="linear", rtol=1e-10, initial_rotation=THETA0)
    n = min(r.peak_rotations.size, 40)
    times, peaks = linear_free_peaks(THETA0, ALPHA, ETA, P, n)
    np.testing.assert_allclose(np.abs(r.peak_rotations[:n]), peaks, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(r.peak_times[:n], times, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(np.sign(r.peak_rotations[:n]), (-1.0) ** np.arange(n))


@pytest.mark.filterwarnings("ignore::rockstudy.LinearizationWarning")
def test_dense_output_of_free_linearized_rocking_is_the_cosh_solution():
    t_eval = np.linspace(0.0, 0.3, 31)  # before the first impact
    r = rs.simulate(BLOCK, NoMotion(), method="linear", initial_rotation=THETA0, t_eval=t_eval)
    exact = ALPHA - (ALPHA - THETA0) * np.cosh(P * t_eval)
    np.testing.assert_allclose(r.theta_eval, exact, rtol=1e-12, atol=1e-15)
    rate = -(ALPHA - THETA0) * P * np.sinh(P * t_eval)
    np.testing.assert_allclose(r.theta_dot_eval, rate, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(r.t_eval, t_eval)


def test_mechanism_path_gives_the_energy_map_peaks():
    # a point mass on a strut: kappa_1 = 1, its mechanism rocks as the block of its p, alpha
    # and eta = cos 2 alpha; the mechanism kernel integrates tabulated I, G, B (eq. 8 of [003])
    strut = PointMassStrut(1.0, ALPHA)
    r = rs.simulate(strut, NoMotion(), rtol=1e-10, initial_rotation=THETA0)
    eta = math.cos(2 * ALPHA)
    assert r.info["restitution"] == pytest.approx(eta)
    n = min(r.peak_rotations.size, 30)
    assert n >= 10
    exact = energy_map_peaks(THETA0, ALPHA, eta, n)
    np.testing.assert_allclose(np.abs(r.peak_rotations[:n]), exact, rtol=1e-6)
    assert_alternating(r)


def test_complex_peaks_approach_the_energy_map():
    # [001]'s formulation is Housner's only as l -> 0; at l = 1e-4 its error is about
    # 0.006 alpha (rockstudy/dynamics/complex.py)
    r = rs.simulate(BLOCK, NoMotion(), method="complex", initial_rotation=THETA0, t_max=3.0)
    n = r.peak_rotations.size
    assert n >= 3  # the release and two after impacts
    exact = energy_map_peaks(THETA0, ALPHA, ETA, n)
    np.testing.assert_allclose(np.abs(r.peak_rotations), exact, atol=0.01 * ALPHA)
    np.testing.assert_array_equal(np.sign(r.peak_rotations), (-1.0) ** np.arange(n))


# ---------------------------------------------------- under a pulse and a record: solve_ivp

PULSE = SinePulse(3.0, 0.5)
RECORD = stochastic_record(peak=3.0 * 9.81 * math.tan(ALPHA), duration=2.0, dt=0.01, seed=3)


@pytest.fixture(scope="module", params=["pulse", "record"])
def forced(request):
    motion = PULSE if request.param == "pulse" else RECORD
    t_eval = np.linspace(0.0, 4.0, 57)
    ref = rs.simulate(BLOCK, motion, method="scipy", rtol=1e-12, t_eval=t_eval)
    return motion, t_eval, ref


@pytest.mark.parametrize("method", ["nonlinear", "auto"])
def test_peaks_and_dense_output_match_solve_ivp(forced, method):
    motion, t_eval, ref = forced
    r = rs.simulate(BLOCK, motion, method=method, rtol=1e-10, t_eval=t_eval)
    assert r.peak_times.size == ref.peak_times.size >= 10
    # measured: 4e-10 s, 6e-12 alpha, 3e-11 alpha
    np.testing.assert_allclose(r.peak_times, ref.peak_times, rtol=0, atol=2e-9)
    np.testing.assert_allclose(r.peak_rotations, ref.peak_rotations, rtol=0, atol=1e-10 * ALPHA)
    np.testing.assert_allclose(r.theta_eval, ref.theta_eval, rtol=0, atol=2e-10 * ALPHA)
    np.testing.assert_allclose(r.theta_dot_eval, ref.theta_dot_eval, rtol=0, atol=1e-8 * P * ALPHA)
    assert not r.overturned and np.any(r.theta_eval != 0.0)
    assert np.max(np.abs(r.peak_rotations)) == pytest.approx(r.max_rotation, rel=1e-12)
    assert np.max(np.abs(ref.peak_rotations)) == pytest.approx(ref.max_rotation, rel=1e-12)
    assert_alternating(r)


def test_exact_linear_solver_matches_solve_ivp_of_the_linear_model():
    t_eval = np.linspace(0.0, 4.0, 57)
    with pytest.warns(rs.LinearizationWarning):
        r = rs.simulate(BLOCK, PULSE, method="linear", t_eval=t_eval)
    with pytest.warns(rs.LinearizationWarning):
        ref = rs.simulate(BLOCK, PULSE, method="scipy-linear", rtol=1e-12, t_eval=t_eval)
    assert r.info["solver"].startswith("exact") and r.peak_times.size == ref.peak_times.size
    # measured: 7e-10 s, 5e-12 alpha, 4e-11 alpha (mostly scipy's error at rtol 1e-12)
    np.testing.assert_allclose(r.peak_times, ref.peak_times, rtol=0, atol=2e-9)
    np.testing.assert_allclose(r.peak_rotations, ref.peak_rotations, rtol=0, atol=1e-10 * ALPHA)
    np.testing.assert_allclose(r.theta_eval, ref.theta_eval, rtol=0, atol=2e-10 * ALPHA)
    np.testing.assert_allclose(r.theta_dot_eval, ref.theta_dot_eval, rtol=0, atol=1e-8 * P * ALPHA)
    assert np.max(np.abs(r.peak_rotations)) == pytest.approx(r.max_rotation, rel=1e-12)


def test_dense_output_is_rest_before_uplift_and_nan_after_a_fall():
    strong = SinePulse(30.0, 1.5)
    t_eval = np.linspace(0.0, 1.5, 31)
    r = rs.simulate(BLOCK, strong, rtol=1e-10, t_eval=t_eval)
    ref = rs.simulate(BLOCK, strong, method="scipy", rtol=1e-12, t_eval=t_eval)
    assert r.overturned and ref.overturned
    after = t_eval > r.overturn_time
    assert after.any() and np.all(np.isnan(r.theta_eval[after]))
    assert np.all(np.isnan(r.theta_dot_eval[after]))
    before = ~after
    np.testing.assert_allclose(r.theta_eval[before], ref.theta_eval[before], atol=1e-9 * ALPHA)
    assert np.all(np.abs(r.theta_eval[before]) < math.pi / 2)
    # at t = 0 the ground is still below uplift: the block is at rest
    assert r.theta_eval[0] == 0.0 and r.theta_dot_eval[0] == 0.0


def test_dt_out_is_the_uniform_grid():
    r = rs.simulate(BLOCK, PULSE, rtol=1e-10, dt_out=0.05)
    k = np.arange(r.t_eval.size)
    np.testing.assert_allclose(r.t_eval, 0.05 * k, rtol=1e-15, atol=0)
    assert r.t_eval[-1] <= r.t[-1] < r.t_eval[-1] + 0.05  # up to the end of the response
    ref = rs.simulate(BLOCK, PULSE, method="scipy", rtol=1e-12, t_eval=r.t_eval)
    np.testing.assert_allclose(r.theta_eval, ref.theta_eval, rtol=0, atol=1e-9 * ALPHA)
    with_end = rs.simulate(BLOCK, PULSE, dt_out=0.1, t_max=1.0)
    np.testing.assert_allclose(with_end.t_eval, 0.1 * np.arange(11), rtol=1e-15)


# ------------------------------------------------------------------------ validation, surface


@pytest.mark.parametrize(
    "bad, words",
    [
        ([0.0, np.nan, 1.0], "finite"),
        ([0.0, 2.0, 1.0], "sorted"),
        ([-0.1, 1.0], ">= 0"),
        ([0.0, 3.0], "beyond"),
        ([[0.0, 1.0]], "1-D"),
        ([], "non-empty"),
    ],
)
def test_bad_t_eval_is_refused_by_name(bad, words):
    with pytest.raises(ValueError, match="t_eval") as info:
        rs.simulate(BLOCK, PULSE, t_eval=bad, t_max=2.0)
    assert words in str(info.value)


def test_t_eval_beyond_the_end_of_an_open_history_is_refused():
    block = rs.Block(1.0, ALPHA, restitution=1.0)  # never rests: followed for 100 / p
    with pytest.raises(ValueError, match="t_eval .* beyond the simulated end"):
        rs.simulate(block, PULSE, t_eval=[0.0, 1e4])
    with pytest.raises(ValueError, match="t_eval .* beyond the simulated end"):
        rs.simulate(BLOCK, NoMotion(), method="complex", initial_rotation=0.1, t_eval=[50.0])
    with pytest.raises(ValueError, match="t_eval or dt_out"):
        rs.simulate(BLOCK, PULSE, t_eval=[0.0], dt_out=0.1)
    with pytest.raises(ValueError, match="dt_out"):
        rs.simulate(BLOCK, PULSE, dt_out=0.0)


def test_exports_carry_peaks_and_dense_output():
    t_eval = np.linspace(0.0, 2.0, 9)
    r = rs.simulate(BLOCK, PULSE, t_eval=t_eval)
    ds = r.to_xarray()
    np.testing.assert_array_equal(ds["peak_time"].values, r.peak_times)
    np.testing.assert_array_equal(ds["peak_rotation"].values, r.peak_rotations)
    np.testing.assert_array_equal(ds["theta_eval"].values, r.theta_eval)
    np.testing.assert_array_equal(ds["time_eval"].values, t_eval)
    assert ds["peak_rotation"].attrs["units"] == "rad" and ds["time_eval"].attrs["units"] == "s"
    dense = r.to_dataframe()  # the dense output when there is one
    np.testing.assert_array_equal(dense["theta"].to_numpy(), r.theta_eval)
    np.testing.assert_array_equal(r.to_dataframe("peaks")["t"].to_numpy(), r.peak_times)
    np.testing.assert_array_equal(r.to_dataframe("history")["t"].to_numpy(), r.t)
    with pytest.raises(ValueError, match="part"):
        r.to_dataframe("nonsense")
    with pytest.raises(ValueError, match="no dense output"):
        rs.simulate(BLOCK, PULSE).to_dataframe("dense")


def test_plot_passes_through_the_exact_peaks():
    import matplotlib.pyplot as plt

    r = rs.simulate(BLOCK, NoMotion(), initial_rotation=THETA0, t_max=2.0)
    ax = r.plot()
    x, y = ax.get_lines()[0].get_data()
    for tp, up in zip(r.peak_times, r.peak_rotations, strict=True):
        i = np.flatnonzero(x == tp)
        assert i.size and y[i[0]] * ALPHA == pytest.approx(up, rel=1e-15)
        # and the drawn curve has no point above the peak around it
        near = np.abs(x - tp) < 0.05
        assert np.max(np.abs(y[near])) * ALPHA <= abs(up) * (1 + 1e-12)
    plt.close(ax.figure)


def test_cli_writes_peaks_and_the_dt_out_grid(tmp_path):
    import json

    import xarray as xr
    from _helpers import cli

    args = ["simulate", "--half-diagonal", "1", "--slenderness", str(ALPHA)]
    args += ["--amplitude", "3.0", "--period", "0.5", "--dt-out", "0.01", "--json"]
    code, stdout, err = cli(*args, "--out", tmp_path / "h.nc")
    assert code == 0, err
    r = rs.simulate(BLOCK, PULSE, dt_out=0.01)
    peaks = json.loads(stdout)["result"]["peaks"]
    assert peaks["count"] == r.peak_times.size
    assert abs(peaks["largest_rotation"]) == pytest.approx(r.max_rotation, rel=1e-12)
    with xr.open_dataset(tmp_path / "h.nc") as ds:
        np.testing.assert_array_equal(ds["peak_rotation"].values, r.peak_rotations)
        np.testing.assert_allclose(ds["time_eval"].values, 0.01 * np.arange(r.t_eval.size))
        np.testing.assert_array_equal(ds["theta_eval"].values, r.theta_eval)
