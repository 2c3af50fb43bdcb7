"""The friction demand's first sample of a rocking phase (rockstudy.dynamics._demand), read
off the first coefficients of the phase's first Taylor step. Oracle: the ground's force on
the block from the rigid-body equations, F_h = m (u_g'' + x_G''), F_v = m (g + u_v'' + y_G''),
with the centre of mass G at (-s R sin phi, R cos phi) from the pivot (phi = alpha - s theta),
its accelerations by the chain rule and theta_ddot from Housner's equation, all written here.
"""

import math

import numpy as np
import pytest

from rockstudy.constants import G
from rockstudy.dynamics import _demand, _rocking
from rockstudy.dynamics._taylor import taylor_coefficients, work_arrays
from rockstudy.motions._kernels import KIND_RECORD

P, ALPHA = 2.0, 0.2
#: The step [s], from t = 0, and the record's one segment.
HS = 0.01


def motion(a0, a1):
    """The kernel encoding of a record whose one segment runs from a0 to a1 [m/s^2] over
    the step."""
    mp = np.array([1.0, 0.0, 0.0, HS])
    return (KIND_RECORD, mp, np.array([0.0, HS]), np.array([a0, a1]), np.empty(0))


def forces(t, th, om, s, a0, a1):
    """(F_h / m, F_v / m) of the block at (theta, theta_dot) on side s at t [s] under the
    ground a0 + (a1 - a0) t / HS, from the centre of mass's accelerations."""
    a_h = a0 + (a1 - a0) * t / HS
    radius = 0.75 * G / P**2
    x = ALPHA * s - th
    th_dd = -(P**2) * (math.sin(x) + a_h / G * math.cos(x))
    phi, dphi, ddphi = ALPHA - s * th, -s * om, -s * th_dd
    x_dd = -s * radius * (math.cos(phi) * ddphi - math.sin(phi) * dphi**2)
    y_dd = radius * (-math.sin(phi) * ddphi - math.cos(phi) * dphi**2)
    return a_h + x_dd, G + y_dd


def step_from(th, om, s, a0, a1):
    """The work array and order of one Taylor step from (theta, theta_dot) on side s at t = 0,
    of length HS, under the ground a0 + (a1 - a0) t / HS."""
    w = work_arrays()
    tol = 1e-10
    n, err = taylor_coefficients(
        w, th, om, s, P, ALPHA, _rocking.MODEL_NONLINEAR, HS, a0, a1, 0.0, 0.0, tol, tol
    )
    assert err <= 1.0
    return w, n


STARTS = [  # (theta, theta_dot, side, a0, a1): after an impact (theta = 0) and inside a phase
    (0.0, -0.8, 1.0, 0.5, -1.0),
    (0.0, 0.3, -1.0, -2.0, 1.5),
    (0.0, 1.7, -1.0, 0.0, 3.0),
    (0.05, 0.4, 1.0, -1.0, -2.5),
    (-0.12, 0.9, -1.0, 1.2, 0.2),
]


@pytest.mark.parametrize("th, om, s, a0, a1", STARTS)
def test_a_phases_first_sample_is_the_force_ratio_at_its_start_state(th, om, s, a0, a1):
    w, n = step_from(th, om, s, a0, a1)
    step = (0.0, HS, n, 0, s, P, ALPHA, motion(a0, a1))
    ratio, f_v, u = _demand._sample_start(w, step)
    f_h, f_v_true = forces(0.0, th, om, s, a0, a1)
    assert f_v == pytest.approx(f_v_true, rel=1e-12)
    assert ratio == pytest.approx(abs(f_h) / f_v_true, rel=1e-12)
    assert u == s * th
