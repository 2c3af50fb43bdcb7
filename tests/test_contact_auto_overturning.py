"""``model="auto"`` on blocks that overturn: the fall of an overturning block unloads its
base, so it slips or flies before it lies flat, which Housner's model cannot say.

Oracle: the ``solve_ivp`` reference of the contact model at rtol 1e-12
(:func:`rockstudy.dynamics.slide_rock_reference.simulate_contact_reference`), an integrator
independent of the batch's kernels.
"""

import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import SinePulse

ALPHA = 0.2
R = 0.8


def test_an_overturning_block_under_auto_gets_the_contact_models_slide_and_slip_time():
    """A slender block (tan alpha = 0.20 < mu = 0.5) whose friction demand stays below mu
    until it passes alpha, then overturns: "auto" answers it with the contact model, whose
    slip before the fall and first slip time equal the reference's."""
    amplitude = np.array([4.0, 5.0])
    period = 0.6
    mu = 0.5
    out = rs.simulate_batch(
        half_diagonal=R,
        slenderness=ALPHA,
        amplitude=amplitude,
        period=period,
        friction=mu,
        model="auto",
        rtol=1e-10,
    )
    block = rs.Block(half_diagonal=R, slenderness=ALPHA)
    for i, a in enumerate(amplitude):
        housner = rs.simulate(block, SinePulse(amplitude=a, period=period))
        assert housner.overturned and housner.friction_demand < mu  # the case in question
        motion = SinePulse(amplitude=a, period=period)
        ref = simulate_contact_reference(R, ALPHA, block.restitution, motion, mu)
        assert ref["overturned"] and math.isfinite(ref["first_slip_time"])
        assert out["model"][i] == 3
        assert bool(out["overturned"][i])
        assert out["first_slip_time"][i] == pytest.approx(ref["first_slip_time"], abs=1e-7)
        assert out["max_slide"][i] == pytest.approx(ref["max_slide"], rel=1e-6, abs=1e-9 * R)
        assert out["max_slide"][i] > 0.0
    assert G * math.tan(ALPHA) < amplitude.min()  # the pulses lift the block
