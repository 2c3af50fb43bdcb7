"""The exact solution of the linearized block under sampled records (issue 14, deliverable 2).

Oracle: the scipy reference path (solve_ivp at rtol 1e-12 on eq. 3.1 of [000], with its own
event location), which integrates what the exact solver solves in closed form.
"""

import warnings

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import _linear_record
from rockstudy.motions import Record, stochastic_record, synthetic_near_fault
from rockstudy.structures import block_parameters

NO_LOG = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
RNG = np.random.default_rng(14)
SCENES = [
    (RNG.uniform(0.5, 3.0), RNG.uniform(0.1, 0.3), RNG.uniform(0.8, 6.0), seed)
    for seed in range(10)
]


def exact(block, record, use_map=False, scale=1.0):
    p, alpha, eta = block_parameters(block)
    times, samples = record.kernel_spec()[2:4]
    r = _linear_record.record_scene(
        p,
        alpha,
        eta,
        scale,
        times,
        samples,
        _linear_record.loud_table(samples),
        use_map,
        np.inf,
        NO_LOG,
        np.empty((0, 7)),
    )
    return r.status, r.max_rotation, r.overturned, r.n_impacts, r.overturn_time, r.first_impact_time


@pytest.mark.parametrize("R, alpha, pga_ratio, seed", SCENES)
def test_exact_linear_record_matches_the_reference(R, alpha, pga_ratio, seed):
    block = rs.Block(R, alpha)
    record = stochastic_record(peak=pga_ratio * G * alpha, duration=5.0, dt=0.01, seed=seed)
    ref = rs.simulate(block, record, method="scipy-linear", rtol=1e-12)
    status, max_rot, over, n_imp, t_ot, t_first = exact(block, record)
    assert status == 0 and over == ref.overturned
    np.testing.assert_allclose(max_rot, ref.max_rotation, rtol=1e-10)
    assert n_imp == ref.impact_times.size
    if n_imp:
        np.testing.assert_allclose(t_first, ref.impact_times[0], rtol=0, atol=1e-9)
    if over:
        np.testing.assert_allclose(t_ot, ref.overturn_time, rtol=0, atol=1e-9)
    # the batch form maps the free rocking after the record instead of following it
    p, a, eta = block_parameters(block)
    times, samples = record.kernel_spec()[2:4]
    row = _linear_record.record_batch(
        np.array([p]), np.array([a]), np.array([eta]), np.ones(1), times, samples
    )[0]
    np.testing.assert_allclose(row["max_rotation"], ref.max_rotation, rtol=1e-10)
    assert bool(row["overturned"]) == ref.overturned and row["steps"] == 0


def test_exact_linear_record_symmetries():
    """Mirroring the record mirrors the motion; no uplift below g alpha (eq. 3.1)."""
    block = rs.Block(1.2, 0.2)
    record = stochastic_record(peak=3.0 * G * 0.2, duration=4.0, dt=0.005, seed=3)
    mirrored = Record(-record.acceleration, dt=record.dt)
    a, b = exact(block, record), exact(block, mirrored)
    assert a[1:4] == pytest.approx(b[1:4], rel=1e-12)
    assert exact(block, record, scale=0.99 / 3.0)[1:4] == (0.0, False, 0)


def test_simulate_batch_linear_records_are_exact():
    """method="linear" of the batch entry point runs the exact solver on records."""
    record = stochastic_record(peak=1.0, duration=4.0, dt=0.01, seed=5)
    R, alpha = np.array([0.8, 1.5, 2.5, 1.0]), np.array([0.12, 0.2, 0.25, 0.15])
    scale = np.array([1.5, 2.5, 4.0, 0.9]) * G * alpha / record.peak
    out = rs.simulate_batch(
        half_diagonal=R, slenderness=alpha, record=record, scale=scale, method="linear"
    )
    assert np.all(out["steps"] == 0) and np.all(out["status"] == 0)
    for i in range(R.size):
        ref = rs.simulate(
            rs.Block(R[i], alpha[i]), record.scaled(scale[i]), method="scipy-linear", rtol=1e-12
        )
        np.testing.assert_allclose(out["max_rotation"][i], ref.max_rotation, rtol=1e-10)
        assert out["overturned"][i] == ref.overturned
    assert out["max_rotation"][3] == 0.0  # 0.9 g alpha: no uplift


def _assert_matches_reference(r, ref, alpha, p):
    """simulate(method="linear") against solve_ivp at rtol 1e-12 on eq. (3.1): the scalars to
    1e-10, impacts, peaks and dense states to the reference's own event and step accuracy."""
    assert r.overturned == ref.overturned
    np.testing.assert_allclose(r.max_rotation, ref.max_rotation, rtol=1e-10)
    assert r.impact_times.size == ref.impact_times.size
    np.testing.assert_allclose(r.impact_times, ref.impact_times, rtol=0, atol=1e-8)
    if r.overturned:
        np.testing.assert_allclose(r.overturn_time, ref.overturn_time, rtol=0, atol=1e-8)
    assert r.peak_times.size == ref.peak_times.size
    np.testing.assert_allclose(r.peak_times, ref.peak_times, rtol=0, atol=1e-8)
    np.testing.assert_allclose(r.peak_rotations, ref.peak_rotations, rtol=0, atol=1e-10 * alpha)
    np.testing.assert_allclose(r.theta_eval, ref.theta_eval, rtol=0, atol=1e-10 * alpha)
    np.testing.assert_allclose(r.theta_dot_eval, ref.theta_dot_eval, rtol=0, atol=1e-8 * p * alpha)


@pytest.mark.parametrize(
    "R, alpha, pga_ratio, seed", [(1.2, 0.2, 3.0, 3), (0.7, 0.15, 2.0, 6), (2.0, 0.25, 5.0, 7)]
)
def test_simulate_linear_on_a_record_is_the_exact_solver(R, alpha, pga_ratio, seed):
    """simulate(record, method="linear"): history, impacts, peaks and dense output of the
    closed form, nothing integrated, against solve_ivp at rtol 1e-12 on eq. (3.1)."""
    block = rs.Block(R, alpha)
    record = synthetic_near_fault(
        pulse_period=1.0, pga=pga_ratio * G * alpha, seed=seed, duration=4.0, dt=0.01
    )
    kw = dict(dt_out=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rs.LinearizationWarning)
        r = rs.simulate(block, record, method="linear", **kw)
        ref = rs.simulate(block, record, method="scipy-linear", rtol=1e-12, **kw)
    assert r.info["solver"].startswith("exact") and r.info["dop853_steps"] == 0
    assert r.impact_times.size > 0 and np.any(r.theta_eval != 0.0)
    _assert_matches_reference(r, ref, alpha, block.frequency_parameter)
    assert np.all(np.diff(r.t) >= 0.0)
    assert r.t[-1] >= (r.overturn_time if r.overturned else record.duration)
    if r.overturned:
        assert np.all(np.isnan(r.theta_eval[r.t_eval > r.overturn_time]))
    else:
        assert np.max(np.abs(r.peak_rotations)) == pytest.approx(r.max_rotation, rel=1e-12)


def test_simulate_linear_with_a_vertical_component_runs_the_kernel_and_says_so():
    record = synthetic_near_fault(pulse_period=1.0, pga=3.0 * G * 0.2, seed=1, vertical=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rs.LinearizationWarning)
        r = rs.simulate(rs.Block(1.0, 0.2), record, method="linear")
    assert "kernel" in r.info["solver"] and r.info["dop853_steps"] > 0


def _quiet_between_pulses(peak, dt=0.01, quiet=20.0, period=0.3):
    """Two strong one-cycle sine pulses with ``quiet`` s of weak noise (0.2 peak) between."""
    pulse = peak * np.sin(2.0 * np.pi * np.arange(0.0, period, dt) / period)
    rng = np.random.default_rng(0)
    calm = 0.2 * peak * rng.uniform(-1.0, 1.0, int(quiet / dt))
    return Record(np.concatenate([pulse, calm, -pulse, np.zeros(1)]), dt=dt)


def test_rest_phase_jump_over_a_quiet_stretch_is_exact():
    """A block at rest after the first pulse skips the quiet stretch (below g alpha) by the
    table of block maxima; the result is the one without the table (every sample tested)
    and the reference's."""
    block = rs.Block(1.0, 0.2)
    p, alpha, eta = block_parameters(block)
    record = _quiet_between_pulses(3.0 * G * alpha)
    times, samples = record.kernel_spec()[2:4]
    loud = _linear_record.loud_table(samples)
    assert np.sum(loud < G * alpha) > 20  # whole blocks to skip
    every_sample = np.full(loud.size, np.inf)  # no block skipped
    args = (p, alpha, eta, 1.0, times, samples)
    tail = (True, np.inf, NO_LOG, np.empty((0, 7)))
    jump = _linear_record.record_scene(*args, loud, *tail)
    scan = _linear_record.record_scene(*args, every_sample, *tail)
    np.testing.assert_equal(jump._asdict(), scan._asdict())
    ref = rs.simulate(block, record, method="scipy-linear", rtol=1e-12)
    assert not ref.overturned and ref.impact_times.size > 2
    assert ref.impact_times[0] < 2.0 and ref.impact_times[-1] > 20.3  # both pulses rock it
    np.testing.assert_allclose(jump.max_rotation, ref.max_rotation, rtol=1e-10)
    assert jump.n_impacts == ref.impact_times.size
    np.testing.assert_allclose(jump.first_impact_time, ref.impact_times[0], rtol=0, atol=1e-9)


def _peak_at_the_uplift_level(alpha, sign, ulps, before=()):
    """A record whose loudest sample after ``before`` is ``ulps`` ulps above g alpha, between
    two at half of it: a peak of |u_g''| at which a block at rest lifts off at that very
    sample, the ground easing at once. Returns (record, time of the peak [s])."""
    top = G * alpha
    for _ in range(ulps):
        top = np.nextafter(top, np.inf)
    assert top / G > alpha  # above the uplift level of eq. (3.1) in this arithmetic too
    peak = sign * np.array([0.5 * G * alpha, top, 0.5 * G * alpha])
    acc = np.concatenate([before, np.zeros(50), peak, np.zeros(50)])
    return Record(acc, dt=0.01), 0.01 * (len(before) + 51)


def _assert_falls_back_like_the_reference(block, record, t_peak):
    """simulate and simulate_batch (method="linear") against solve_ivp at rtol 1e-12 on a
    record whose last lift-off (at ``t_peak``) falls straight back: the same overturning
    decision and max rotation, the same impacts before the peak, and none after it but at
    it. (The reference's Zeno rule restarts the block at an impact found at its own start,
    at the peak, until its cap on impacts: their number there is not compared.)"""
    alpha = block.slenderness
    with warnings.catch_warnings():  # its impact cap, reached at the peak (after it: silence)
        warnings.simplefilter("ignore", rs.IncompleteReferenceWarning)
        ref = rs.simulate(block, record, method="scipy-linear", rtol=1e-12)
    r = rs.simulate(block, record, method="linear")
    batch = rs.simulate_batch(
        half_diagonal=[block.half_diagonal], slenderness=[alpha], record=record, method="linear"
    )
    assert ref.impact_times[-1] == pytest.approx(t_peak, abs=1e-12)  # the oracle falls back
    for over, max_rot in (
        (r.overturned, r.max_rotation),
        (batch["overturned"][0], batch["max_rotation"][0]),
    ):
        assert bool(over) == ref.overturned
        np.testing.assert_allclose(max_rot, ref.max_rotation, rtol=1e-10, atol=1e-12 * alpha)
    early = t_peak - 1e-8
    np.testing.assert_allclose(
        r.impact_times[r.impact_times < early],
        ref.impact_times[ref.impact_times < early],
        rtol=0,
        atol=1e-8,
    )
    np.testing.assert_allclose(r.impact_times[r.impact_times >= early], t_peak, atol=1e-8)
    np.testing.assert_allclose(batch["first_impact_time"][0], ref.impact_times[0], atol=1e-8)
    for x in (r, ref):  # no rise at the peak: nothing but contact from then on
        assert np.all(np.abs(x.theta[x.t >= early]) <= 1e-12 * alpha)


@pytest.mark.parametrize("sign, ulps", [(1.0, 1), (-1.0, 1), (1.0, 2), (-1.0, 2)])
def test_a_lift_at_a_peak_within_ulps_of_the_uplift_level_falls_straight_back(sign, ulps):
    """Eq. (3.1) of [000] with the first loud sample ulps above g alpha at a peak of |u_g''|:
    the block lifts at that sample, rises for ~1e-18 of p t and falls back (its turning point
    rounds away in the closed form). The exact solver used to start that phase from contact
    without seeing the impact and rock on with s theta < 0 to a false overturning."""
    block = rs.Block(1.0, 0.2)
    record, t_peak = _peak_at_the_uplift_level(0.2, sign, ulps)
    _assert_falls_back_like_the_reference(block, record, t_peak)


@pytest.mark.parametrize("sign, ulps", [(1.0, 2), (-1.0, 1)])
def test_a_lift_at_a_peak_of_the_uplift_level_after_rocking_and_a_rest(sign, ulps):
    """The same peak mid-record: a strong pulse rocks the block (eq. 3.1 of [000]) to a Zeno
    rest, and seconds later the block at rest meets the peak; the peak pushes it the other
    way for sign -1."""
    alpha = 0.2
    pulse = 3.0 * G * alpha * np.sin(2.0 * np.pi * np.arange(0.0, 0.3, 0.01) / 0.3)
    before = np.concatenate([pulse, np.zeros(1200)])
    record, t_peak = _peak_at_the_uplift_level(alpha, sign, ulps, before)
    _assert_falls_back_like_the_reference(rs.Block(1.0, alpha), record, t_peak)


def test_exact_linear_solver_on_the_shipped_and_real_records(records_dir):
    """Two of the shared real records, a few blocks each: the batch solver (free rocking
    mapped) against solve_ivp with the same map, to the reference's own accuracy. Chattering
    through many impacts amplifies the reference's error: on one of these scenes its max
    rotation moves by 1.6e-9 between rtol 1e-13 and 3e-14 (and by 1e-11 only between 1e-12
    and 3e-13, while still 2e-9 away from its limit: two loose tolerances can agree on a wrong
    value). The exact solver must lie within three times the last step of the reference's
    convergence at its tightest tolerances (and within 1e-10 where the reference has
    converged)."""
    from rockstudy.dynamics._rocking import MODEL_LINEAR
    from rockstudy.dynamics.reference import simulate_reference

    records = [
        Record.from_at2(records_dir / "RSN126_GAZLI_GAZ000.AT2"),
        Record.from_csv(records_dir / "elcentro_NS.dat", units="g"),
    ]
    rng = np.random.default_rng(7)
    for record in records:
        times, samples = record.kernel_spec()[2:4]
        R = rng.uniform(0.5, 3.0, 3)
        alpha = rng.uniform(0.1, 0.3, 3)
        scale = rng.uniform(0.8, 6.0, 3) * G * alpha / record.peak
        p = np.sqrt(0.75 * G / R)
        eta = 1.0 - 1.5 * np.sin(alpha) ** 2
        out = _linear_record.record_batch(p, alpha, eta, scale, times, samples)
        for i in range(R.size):
            ref, finer = (
                simulate_reference(
                    p[i],
                    alpha[i],
                    eta[i],
                    record.scaled(scale[i]),
                    MODEL_LINEAR,
                    rtol,
                    free_map=True,
                )
                for rtol in (1e-13, 3e-14)
            )
            assert bool(out["overturned"][i]) == ref["overturned"] == finer["overturned"]
            spread = abs(ref["max_rotation"] - finer["max_rotation"])
            tol = 1e-10 * finer["max_rotation"] + 3.0 * spread
            np.testing.assert_allclose(
                out["max_rotation"][i], finer["max_rotation"], rtol=0, atol=tol
            )
            assert (
                out["overturned"][i]
                or ref["max_rotation"] == 0.0
                or spread < 1e-7 * ref["max_rotation"]
            )
            if finer["impact_times"].size:
                np.testing.assert_allclose(
                    out["first_impact_time"][i], finer["impact_times"][0], rtol=0, atol=1e-8
                )


def _exact_segment_functions(sig):
    """sinh(sigma) - sigma and cosh(sigma) - 1 of the double sigma, by their Taylor series in
    exact rational arithmetic (terms to sigma^61: below 1e-40 of the sum for |sigma| <= 3)."""
    from fractions import Fraction

    x = Fraction(sig)
    smx = cm1 = Fraction(0)
    term = x  # x^k / k!
    for k in range(2, 62):
        term = term * x / k
        if k % 2:
            smx += term
        else:
            cm1 += term
    return float(smx), float(cm1)


@pytest.mark.parametrize(
    "sig", [1e-9, 3e-4, 0.01, 0.037, -0.1, 0.2, 0.2499, 0.25, 0.26, -0.4, 0.6, 0.75, 1.3, 2.9]
)
def test_segment_functions_to_a_few_ulps(sig):
    """The functions of sigma that every record segment is advanced by (the closed form of
    eq. 3.1 of [000]): within a few ulps of the exact series, on both sides of the switch from
    the series to the library's sinh (where sinh - sigma would cancel)."""
    sh, cm1, smx = _linear_record._seg_functions.py_func(sig)
    smx_exact, cm1_exact = _exact_segment_functions(sig)
    assert smx == pytest.approx(smx_exact, rel=8 * np.finfo(float).eps)
    assert cm1 == pytest.approx(cm1_exact, rel=8 * np.finfo(float).eps)
    assert sh == pytest.approx(sig + smx_exact, rel=4 * np.finfo(float).eps)
