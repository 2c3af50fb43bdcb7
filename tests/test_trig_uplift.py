"""Uplift under sine pulses (issue 14, pulses): the closed-form bracket of next_uplift.

Oracles: Housner's uplift condition |a_g| = g tan(alpha) (g alpha linearized), section 2 of
[000], solved in closed form, and the definition of the uplift time as the first float at
which the kernel's own lift test (_lift) turns positive.
"""

import math

import numpy as np
import pytest

from rockstudy.constants import G
from rockstudy.dynamics import _rocking
from rockstudy.motions._kernels import KIND_TRIG, NO_VERTICAL

Z = np.zeros(2)


def _lifts(mp, p, alpha, model, t):
    a = mp[0] * math.sin(mp[1] * t + mp[2])
    return _rocking._lift(a, 0.0, p, alpha, model, _rocking.NO_TABLE) > 0.0


@pytest.mark.parametrize("model", [_rocking.MODEL_NONLINEAR, _rocking.MODEL_LINEAR])
def test_sine_uplift_is_the_first_float_that_lifts_at_the_analytic_crossing(model):
    rng = np.random.default_rng(7)
    for _ in range(300):
        alpha = rng.uniform(0.02, 0.6)
        level = G * (alpha if model == _rocking.MODEL_LINEAR else math.tan(alpha))
        ratio = rng.choice([1.0 + 1e-9, 1.0 + 1e-6, rng.uniform(1.0001, 8.0)])
        sign = rng.choice([-1.0, 1.0])
        w = 2 * math.pi / rng.uniform(0.05, 3.0)
        ph = rng.choice([0.0, 0.5 * math.pi])
        mp = np.array([sign * ratio * level, w, ph, 3 * 2 * math.pi / w])
        p = rng.uniform(1.0, 6.0)
        t0 = rng.choice([0.0, rng.uniform(0.0, 2 * math.pi / w)])
        t_up = _rocking.next_uplift(
            KIND_TRIG, mp, Z, Z, NO_VERTICAL, p, alpha, model, _rocking.NO_TABLE, t0
        )
        assert t_up >= t0
        # the first float that lifts: it lifts, its predecessor (after t0) does not
        assert _lifts(mp, p, alpha, model, t_up)
        if t_up > t0:
            assert not _lifts(mp, p, alpha, model, np.nextafter(t_up, -np.inf))
        # the analytic crossing: |sin| rises through 1/ratio at the phases k pi + asin(1/ratio)
        if not _lifts(mp, p, alpha, model, t0):
            x = math.asin(1.0 / ratio)
            t_an = min(t for k in range(-1, 8) if (t := (k * math.pi + x - ph) / w) >= t0)
            # ill-conditioned as ratio -> 1 (the square root of the rounding)
            tol = 1e-12 / w if ratio > 1.0001 else 1e-6 / w
            assert t_up == pytest.approx(t_an, abs=tol)
