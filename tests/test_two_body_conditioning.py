"""The conditioning of a two-body row (``simulate_batch(structure=..., outputs=[...,
"conditioning"])``): what it promises, checked against oracles that do not use it. Rows it
calls well conditioned agree with the solve_ivp reference to 10 rtol; a row at an overturning
threshold (found by bisection on the decision) is flagged inf; an assembly that never lifts
has nothing to move."""

import numpy as np
from _helpers import random_stacked_scene

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.conditioning import ILL_CONDITIONED, WELL_CONDITIONED
from rockstudy.dynamics.stacked_reference import simulate_stacked
from rockstudy.dynamics.two_body_batch import OVERTURNED_BODY
from rockstudy.structures import Block, IsolatedBlock, StackedBlocks

RTOL = 1e-10
OUTPUTS = ["max_rotation_lower", "max_rotation_upper", "overturned_body", "conditioning"]


def test_rows_called_well_conditioned_agree_with_the_reference():
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(8):
        pair, record = random_stacked_scene(rng, (1.0, 1.5), (1.0, 2.5))
        out = rs.simulate_batch(structure=pair, record=record, rtol=RTOL, outputs=OUTPUTS)
        if out["conditioning"][0] > WELL_CONDITIONED:
            continue
        ref = simulate_stacked(pair, record, rtol=1e-12)
        assert out["overturned_body"][0] == OVERTURNED_BODY[ref.overturned_body]
        for body, x in (("lower", ref.max_rotation_lower), ("upper", ref.max_rotation_upper)):
            alpha = getattr(pair, body).slenderness
            got = out[f"max_rotation_{body}"][0]
            assert abs(got - x) <= 10 * RTOL * (abs(x) + 1e-2 * alpha), (body, got, x)
        checked += 1
    assert checked >= 4, "too few well-conditioned rows to check"


def _threshold(structure, period, low, high, rounds=8):
    """A bracket (stands, falls) of sine-pulse amplitudes [m/s^2] narrowed to a relative
    width below 1e-10, each round a batch of 41 amplitudes across the last bracket."""
    for _ in range(rounds):
        amps = np.linspace(low, high, 41)
        out = rs.simulate_batch(structure=structure, pulse="sine", amplitude=amps, period=period)
        fell = out["overturned"]
        assert not fell[0] and fell[-1], "the bracket must stand at its low end, fall at its high"
        k = int(np.argmax(fell))
        low, high = amps[k - 1], amps[k]
    assert (high - low) / low < 1e-10
    return low, high


def test_a_stacked_row_at_its_overturning_threshold_is_flagged():
    pair = StackedBlocks(Block(1.0, 0.25), Block(0.6, 0.2), density_ratio=1.0)
    low, high = _threshold(pair, 0.5, 0.1 * G, 20.0 * G)
    out = rs.simulate_batch(
        structure=pair, pulse="sine", amplitude=[low, 0.5 * low], period=0.5, outputs=OUTPUTS
    )
    assert np.isinf(out["conditioning"][0])
    assert out["conditioning"][1] < ILL_CONDITIONED


def test_an_isolated_row_at_its_overturning_threshold_is_flagged():
    system = IsolatedBlock(Block(0.8, 0.2), base_mass_ratio=1.0, period=2.0, damping=0.1)
    low, high = _threshold(system, 0.6, 0.2 * G, 30.0 * G)
    out = rs.simulate_batch(
        structure=system, pulse="sine", amplitude=[low, high], period=0.6, outputs="conditioning"
    )
    assert np.isinf(out["conditioning"][0]) and out["conditioning"][1] == 0.0


def test_an_assembly_that_never_lifts_has_nothing_to_move():
    """Below the composite body's uplift level (statue centred: the pair lifts about the
    plinth's corner when a > g b1 / z_c, z_c the height of the pair's centre of mass; the
    statue alone when a > g tan(alpha_2)), every peak is 0 in both runs."""
    lower, upper = Block(1.0, 0.25), Block(0.6, 0.2)
    h1, b1 = lower.half_diagonal * np.cos(0.25), lower.half_diagonal * np.sin(0.25)
    h2, b2 = upper.half_diagonal * np.cos(0.2), upper.half_diagonal * np.sin(0.2)
    m1, m2 = b1 * h1, b2 * h2
    z_c = (m1 * h1 + m2 * (2 * h1 + h2)) / (m1 + m2)
    level = G * min(b1 / z_c, np.tan(0.2))
    out = rs.simulate_batch(
        structure=StackedBlocks(lower, upper, density_ratio=1.0),
        pulse="sine",
        amplitude=0.9 * level,
        period=0.5,
        outputs=OUTPUTS,
    )
    assert out["max_rotation_lower"][0] == 0.0 == out["max_rotation_upper"][0]
    assert out["conditioning"][0] == 0.0
