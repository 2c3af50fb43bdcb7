"""The stacked-blocks kernel's peak of a plinth that only hops: a statue rocking on a plinth
kicks it into rebounds of 1e-9..1e-7 rad whose peaks lie inside the first step after each
impact; the kernel's max_rotation_lower equals the solve_ivp reference's (rtol 1e-12) to
10 rtol of itself (no floor: the plinth's whole motion is those hops)."""

import numpy as np

from rockstudy.constants import G
from rockstudy.dynamics._stacked_batch import kernel_rows
from rockstudy.dynamics.stacked_reference import simulate_stacked
from rockstudy.motions.records import Record
from rockstudy.structures import Block, StackedBlocks

RTOL = 1e-10


def _scene(rng):
    """A random plinth and statue and a generated record (1-2 s of smoothed white noise
    under a sine envelope at 0.02 s, peaking at 1-3 times the uplift acceleration)."""
    a1, r1, a2 = rng.uniform(0.15, 0.35), rng.uniform(0.6, 2.0), rng.uniform(0.12, 0.3)
    r2 = min(rng.uniform(0.3, 1.2), 0.9 * r1 * np.sin(a1) / np.sin(a2))
    pair = StackedBlocks(Block(r1, a1), Block(r2, a2), rng.uniform(0.3, 3.0))
    n = int(rng.uniform(1.0, 2.0) / 0.02)
    t = np.arange(n) * 0.02
    acc = np.convolve(rng.normal(size=n), np.ones(5) / 5, "same") * np.sin(np.pi * t / t[-1])
    acc *= G * np.tan(min(a1, a2)) * rng.uniform(1.0, 3.0) / np.abs(acc).max()
    return pair, Record(np.r_[acc, 0.0], dt=0.02)


def test_the_peak_of_a_plinth_that_only_hops_is_the_references():
    rng = np.random.default_rng(37)
    for _ in range(92):  # the 92nd scene of this stream: the statue rocks, the plinth hops
        pair, record = _scene(rng)
    ref = simulate_stacked(pair, record, rtol=1e-12)
    out = kernel_rows([pair], [record], RTOL, 100_000)
    lower = out["max_rotation_lower"][0]
    assert 0.0 < ref.max_rotation_lower < 1e-6 < ref.max_rotation_upper
    assert abs(lower - ref.max_rotation_lower) <= 10 * RTOL * ref.max_rotation_lower
    assert not out["overturned"][0] and not ref.overturned
