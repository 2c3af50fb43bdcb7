"""The stacked-blocks kernel's peak of a plinth that only hops: a statue rocking on a plinth
kicks it into rebounds of 1e-9..1e-7 rad whose peaks lie inside the first step after each
impact; the kernel's max_rotation_lower equals the solve_ivp reference's (rtol 1e-12) to
10 rtol of itself (no floor: the plinth's whole motion is those hops)."""

import numpy as np
from _helpers import random_stacked_scene

from rockstudy.dynamics._stacked_batch import kernel_rows
from rockstudy.dynamics.stacked_reference import simulate_stacked

RTOL = 1e-10


def test_the_peak_of_a_plinth_that_only_hops_is_the_references():
    rng = np.random.default_rng(37)
    for _ in range(92):  # the 92nd scene of this stream: the statue rocks, the plinth hops
        pair, record = random_stacked_scene(rng)
    ref = simulate_stacked(pair, record, rtol=1e-12)
    out = kernel_rows([pair], [record], RTOL, 100_000)
    lower = out["max_rotation_lower"][0]
    assert 0.0 < ref.max_rotation_lower < 1e-6 < ref.max_rotation_upper
    assert abs(lower - ref.max_rotation_lower) <= 10 * RTOL * ref.max_rotation_lower
    assert not out["overturned"][0] and not ref.overturned
