"""The two-block kernel under a ground acceleration within a few ulps of an uplift level: a
body at rest exactly at its threshold is lifted by the lift test while its own equation
holds it down (or the reverse), within rounding. The kernel must leave such a state in
finitely many phases (no endless lift - fall back - rest at one instant) with the physical
answer: the body barely moves (its rotation below 1e-12 rad), every row's status OK.

The uplift levels are computed here from the geometry (statics of the rigid assembly), not
by the kernel: the statue lifts about its corner at g tan(alpha_2); the assembly (statue
locked on the plinth) about a plinth corner at g times the horizontal distance of the
composite centre of mass from that corner over its height."""

import time

import numpy as np

from rockstudy.constants import G
from rockstudy.dynamics._stacked_batch import kernel_rows
from rockstudy.motions.records import Record
from rockstudy.structures import Block, StackedBlocks

#: Phase steps allowed to a row; a run that loops at one instant ends by its phase cap
#: (status 1) with as many impacts as phases, far beyond IMPACTS.
MAX_STEPS = 10_000
IMPACTS = 20


def _levels(r1, a1, r2, a2, density_ratio, offset):
    """The uplift levels [m/s^2] of the statue (either side) and of the locked assembly
    about each plinth corner: +level lifts about the corner of negative x."""
    b1, h1, b2, h2 = r1 * np.sin(a1), r1 * np.cos(a1), r2 * np.sin(a2), r2 * np.cos(a2)
    m1, m2 = 4.0 * b1 * h1, density_ratio * 4.0 * b2 * h2
    x_c = m2 * offset / (m1 + m2)
    y_c = (m1 * h1 + m2 * (2.0 * h1 + h2)) / (m1 + m2)
    statue = G * b2 / h2
    return [statue, -statue, G * (b1 + x_c) / y_c, -G * (b1 - x_c) / y_c]


def _shapes(level):
    """Records (dt 0.01 s) that reach ``level`` and hold it: a plateau, and a plateau then
    its opposite."""
    return [
        np.r_[0.0, np.full(20, level), 0.0],
        np.r_[0.0, 0.5 * level, level, level, 0.3 * level, -level, -level, 0.0],
    ]


def test_ground_at_an_uplift_level_ends_in_finite_steps_at_rest():
    rng = np.random.default_rng(11)
    pairs, motions = [], []
    for _ in range(8):
        a1, r1, a2 = rng.uniform(0.15, 0.35), rng.uniform(0.6, 2.0), rng.uniform(0.12, 0.3)
        r2 = min(rng.uniform(0.3, 1.2), 0.9 * r1 * np.sin(a1) / np.sin(a2))
        rho = rng.uniform(0.3, 3.0)
        b1, b2 = r1 * np.sin(a1), r2 * np.sin(a2)
        e = rng.uniform(-0.5, 0.5) * (b1 - b2) if rng.random() < 0.5 else 0.0
        pair = StackedBlocks(Block(r1, a1), Block(r2, a2), rho, offset=e)
        levels = _levels(r1, a1, r2, a2, rho, e)
        lowest = min(levels, key=abs)  # the first threshold the ground reaches
        for k in range(-3, 4):
            for acc in _shapes(lowest * (1.0 + k * 2.0**-52)):
                pairs.append(pair)
                motions.append(Record(acc, dt=0.01))
    t0 = time.perf_counter()
    out = kernel_rows(pairs, motions, 1e-8, MAX_STEPS, t_max=0.5)
    seconds = time.perf_counter() - t0
    assert np.all(out["status"] == 0), np.nonzero(out["status"])[0]
    assert out["n_impacts"].max() <= IMPACTS
    assert out["max_rotation_lower"].max() < 1e-12
    assert out["max_rotation_upper"].max() < 1e-12
    assert not out["overturned"].any()
    assert seconds < 120.0
