"""The linearised two-block model solved exactly per regime (stacked_linear) against
independent oracles: Housner's linearised block (rockstudy's exact single-block solver,
method="linear") in the one-body limits, and the nonlinear solve_ivp reference, from which it
must differ by O(alpha^2) as the slenderness of both bodies halves."""

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.stacked_linear import simulate_stacked_linear
from rockstudy.dynamics.stacked_reference import simulate_stacked
from rockstudy.motions import Record, RickerWavelet, SinePulse
from rockstudy.structures import Block, StackedBlocks


def _record(scale=1.0):
    """A short decaying record (piecewise-linear, dt 0.01 s) with a high-frequency ripple; at
    ``scale`` 1 it rocks a block of alpha 0.2."""
    t = np.arange(0.0, 1.2, 0.01)
    acc = 2.6 * np.sin(2 * np.pi * t / 0.6) * np.exp(-t) + 0.4 * np.sin(2 * np.pi * t / 0.17)
    acc *= scale
    return Record(np.concatenate([acc, np.zeros(1)]), dt=0.01)


#: the single-block solver warns that its model is linear: the comparison is between linear
#: models
LINEAR_ONLY = pytest.mark.filterwarnings("ignore::rockstudy.LinearizationWarning")


@LINEAR_ONLY
@pytest.mark.parametrize(
    "motion", [SinePulse(amplitude=3.0, period=0.6), SinePulse(2.2, 1.0), _record()]
)
def test_fixed_plinth_leaves_the_upper_block_housners_linear_block(motion):
    """A wide, heavy plinth never lifts: the statue on it, centred or not, is the linearised
    Housner block, peak rotation, overturning and impact times to 1e-9."""
    upper = Block(0.5, 0.2)
    ref = rs.simulate(upper, motion, method="linear")
    for offset in (0.0, -2.0):
        pair = StackedBlocks(Block(6.0, 0.9), upper, density_ratio=0.5, offset=offset)
        r = simulate_stacked_linear(pair, motion)
        assert not np.any(np.isin(r.regime, ["lower", "both"]))
        assert r.max_rotation_lower == 0.0
        assert r.overturned == ref.overturned
        assert r.max_rotation_upper == pytest.approx(ref.max_rotation, rel=1e-9)
        if ref.overturned:
            assert r.overturn_time == pytest.approx(ref.overturn_time, rel=1e-9)
        n = min(6, ref.impact_times.size)
        assert n and r.impact_times.size >= n
        np.testing.assert_allclose(r.impact_times[:n], ref.impact_times[:n], rtol=1e-9)


def _lifting_at_once():
    """A record whose first sample (3.2 m/s^2) already lifts a block of alpha 0.25."""
    t = np.arange(0.0, 1.0, 0.01)
    return Record(np.r_[3.2 * np.cos(2 * np.pi * t / 0.5) * np.exp(-2 * t), 0.0], dt=0.01)


@LINEAR_ONLY
@pytest.mark.parametrize(
    "motion",
    [
        SinePulse(3.0, 0.5),
        SinePulse(4.0, 0.3),
        SinePulse(6.0, 0.5),
        _record(1.6),
        _lifting_at_once(),
    ],
)
def test_vanishing_upper_mass_leaves_the_lower_block_housners_linear_block(motion):
    """density_ratio 1e-13: the plinth rocks as the linearised Housner block alone."""
    lower = Block(1.0, 0.25)
    ref = rs.simulate(lower, motion, method="linear")
    assert ref.max_rotation > 1e-4 and ref.impact_times.size  # the plinth rocks
    r = simulate_stacked_linear(StackedBlocks(lower, Block(0.2, 0.7), 1e-13), motion)
    assert r.overturned == ref.overturned
    assert r.max_rotation_lower == pytest.approx(ref.max_rotation, rel=1e-9)
    if ref.overturned:
        assert r.overturn_time == pytest.approx(ref.overturn_time, rel=1e-9)
    n = min(6, ref.impact_times.size)
    np.testing.assert_allclose(r.impact_times[:n], ref.impact_times[:n], rtol=1e-9)


#: (R_1, alpha_1, R_2, alpha_2, density ratio, a_g / (g alpha_1), pulse period [s] or None
#: for the record of :func:`_shape`) at the scale 1 of alpha, and the regime that shows both
#: bodies moving ("both": both rocking at once; "lower": the statue locked to its rocking
#: plinth); neither body overturns.
SCENES = [
    ((1.0, 0.2, 0.3, 0.25, 0.5, 1.2, 0.3), "both"),
    ((1.0, 0.2, 0.3, 0.25, 0.5, 1.05, 0.5), "both"),
    ((1.2, 0.15, 0.3, 0.3, 2.0, 1.2, 0.5), "lower"),
    ((1.2, 0.15, 0.3, 0.3, 2.0, 1.3, None), "lower"),
]


def _shape():
    """A decaying record's shape (peak 1, dt 0.01 s, 1.2 s long) with a ripple."""
    t = np.arange(0.0, 1.2, 0.01)
    shape = np.sin(2 * np.pi * t / 0.6) * np.exp(-t) + 0.15 * np.sin(2 * np.pi * t / 0.17)
    return np.concatenate([shape / np.abs(shape).max(), np.zeros(1)])


def _peaks(scene, scale):
    """The linearised and the nonlinear (reference at rtol 1e-12) results of a scene at
    ``scale`` times its slenderness and ground amplitude, to 1 s after the motion."""
    r1, a1, r2, a2, rho, psi, period = scene
    pair = StackedBlocks(Block(r1, a1 * scale), Block(r2, a2 * scale), density_ratio=rho)
    amplitude = psi * G * a1 * scale
    if period is None:
        motion = Record(amplitude * _shape(), dt=0.01)
    else:
        motion = SinePulse(amplitude=amplitude, period=period)
    lin = simulate_stacked_linear(pair, motion, t_max=motion.duration + 1.0)
    ref = simulate_stacked(pair, motion, rtol=1e-12, t_max=motion.duration + 1.0)
    assert not lin.overturned and not ref.overturned
    return lin, ref


@pytest.mark.parametrize(("scene", "regime"), SCENES)
def test_linearised_model_differs_from_the_nonlinear_by_alpha_squared(scene, regime):
    """For alpha -> alpha / 2 (both bodies, the ground amplitude with them) the relative
    difference of the peak rotations falls by 4: observed order in [1.7, 2.3] on two
    halvings, for each body that rocks."""
    errors, rocks = [], None
    for scale in (0.125, 0.0625, 0.03125):
        lin, ref = _peaks(scene, scale)
        rocks = [ref.max_rotation_lower > 0.0, ref.max_rotation_upper > 0.0]
        assert [lin.max_rotation_lower > 0.0, lin.max_rotation_upper > 0.0] == rocks
        errors.append(
            [
                abs(lin.max_rotation_lower / ref.max_rotation_lower - 1.0),
                abs(lin.max_rotation_upper / ref.max_rotation_upper - 1.0) if rocks[1] else 1.0,
            ]
        )
        assert regime in ref.regime and regime in lin.regime
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    for k in range(2):
        if rocks[k]:
            assert np.all((orders[:, k] >= 1.7) & (orders[:, k] <= 2.3)), orders


def test_input_errors_name_the_argument():
    """A motion the exact solution does not cover (a Ricker wavelet, a vertical component)
    and a bad t_max are refused by name."""
    pair = StackedBlocks(Block(1.0, 0.2), Block(0.3, 0.25))
    with pytest.raises(ValueError, match="motion"):
        simulate_stacked_linear(pair, RickerWavelet(amplitude=3.0, period=0.5))
    acc = np.r_[np.zeros(3), 3.0, np.zeros(3)]
    with pytest.raises(ValueError, match="motion"):
        simulate_stacked_linear(pair, Record(acc, dt=0.01, vertical=0.5 * acc))
    for bad in (0.0, -1.0, np.nan):
        with pytest.raises(ValueError, match="t_max"):
            simulate_stacked_linear(pair, SinePulse(3.0, 0.5), t_max=bad)


def test_an_impact_inside_one_grid_step_is_not_missed():
    """A scene that chatters (the statue's relative angle dips through zero and back inside
    one grid step, found by a random search): the impact is found on the exact solution
    (a turning point beyond the pivot), so the run completes (it used to find no consistent
    post-impact regime) and, as the nonlinear reference, nothing lifts beyond its critical
    angle."""
    pair = StackedBlocks(
        Block(1.8192233920530738, 0.08728889687668413),
        Block(0.7918269806353385, 0.07752343632889407),
        density_ratio=1.8799966925444673,
        offset=-0.015469248551230306,
    )
    motion = SinePulse(amplitude=0.6392638510198901, period=0.6504901580196532)
    lin = simulate_stacked_linear(pair, motion, t_max=1.0)
    ref = simulate_stacked(pair, motion, rtol=1e-12, t_max=1.0)
    assert lin.overturned == ref.overturned is False
    assert lin.impact_times.size > 100 and ref.impact_times.size > 100  # it chatters
    assert lin.max_rotation_lower < 1e-3 * pair.lower.slenderness
    assert lin.max_rotation_upper < 1e-3 * pair.upper.slenderness
