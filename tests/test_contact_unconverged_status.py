"""simulate_batch under the contact model marks a row whose answer does not converge with
rtol (``status`` 4), so that no design or study takes it as an answer.

Oracle: the solve_ivp reference at rtol 1e-12 with the static coefficient moved by 1e-9 of
itself either way: on Shenton's slide-rock threshold its max slide jumps by far more than
10 rtol (no answer at rtol can be trusted there); 5 % above it the reference agrees with the
batch."""

import math
import warnings

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import slide_rock as sr
from rockstudy.dynamics.constants import STATUS_UNCONVERGED
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import Record

ALPHA, RADIUS, LEVEL, RTOL = 0.2, 1.0, 0.3, 1e-8


def test_a_row_on_a_stick_slip_threshold_gets_the_unconverged_status():
    t = np.arange(0.0, 0.405, 0.01)
    record = Record(np.full(t.size, LEVEL * G), time=t)
    mu = sr.uplift_force_ratio(LEVEL, ALPHA)
    eta = 1.0 - 1.5 * math.sin(ALPHA) ** 2

    def slide(mu_s):
        return simulate_contact_reference(RADIUS, ALPHA, eta, record, mu_s, 0.5 * mu_s, 1e-12)

    jump = abs(slide(mu * (1 - 1e-9))["max_slide"] - slide(mu * (1 + 1e-9))["max_slide"])
    assert jump > 1e3 * RTOL * RADIUS * ALPHA  # the scene has no answer at rtol
    static = np.array([mu, 1.05 * mu])
    out = rs.simulate_batch(
        half_diagonal=RADIUS,
        slenderness=ALPHA,
        restitution=eta,
        record=record,
        friction=(static, 0.5 * static),
        model="contact",
        rtol=RTOL,
    )
    assert list(out["status"]) == [STATUS_UNCONVERGED, 0]
    far = slide(1.05 * mu)
    assert out["max_slide"][1] == pytest.approx(far["max_slide"], rel=10 * RTOL, abs=1e-12)


def test_simulate_warns_on_a_stick_slip_decision_on_its_threshold():
    """The single-scene path says the same of the same scene: an AccuracyWarning naming
    rtol; 5 % above the threshold it is silent."""
    t = np.arange(0.0, 0.405, 0.01)
    record = Record(np.full(t.size, LEVEL * G), time=t)
    mu = sr.uplift_force_ratio(LEVEL, ALPHA)
    block = rs.Block(half_diagonal=RADIUS, slenderness=ALPHA)
    with pytest.warns(rs.AccuracyWarning, match="did not converge with rtol"):
        rs.simulate(block, record, friction=(mu, 0.5 * mu), rtol=RTOL)
    with warnings.catch_warnings():
        warnings.simplefilter("error", rs.AccuracyWarning)
        rs.simulate(block, record, friction=(1.05 * mu, 0.525 * mu), rtol=RTOL)
