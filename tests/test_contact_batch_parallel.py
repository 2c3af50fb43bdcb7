"""simulate_batch's contact rows in one parallel call of the contact kernels.

Oracles: ``rockstudy.simulate(friction=)`` scene by scene (its exact sliding kernel, its
event-driven kernel, and its ``solve_ivp`` reference with ``method="scipy"``).
"""

import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import contact_model
from rockstudy.motions import SinePulse, stochastic_record

RTOL = 1e-10


def _record_scenes():
    """Stocky (mu < tan alpha: the sliding kernel) and slender blocks under one record."""
    record = stochastic_record(3.0, duration=4.0, seed=7)
    alpha = np.array([0.15, 0.35, 0.2, 0.4, 0.25, 0.3])
    mu = np.array([0.5, 0.2, 0.6, 0.3, 0.8, 0.35])
    radius = np.array([0.6, 1.2, 0.9, 0.5, 1.5, 0.8])
    scale = 1.6 * G * np.minimum(np.tan(alpha), mu) / record.peak
    return record, dict(half_diagonal=radius, slenderness=alpha, scale=scale), mu


def test_record_rows_are_simulates_answer_scene_by_scene():
    """Each contact row of a record batch (sliding and rocking blocks in one call) is the
    answer of simulate(friction=) on its scene, to 10 rtol."""
    record, kw, mu = _record_scenes()
    out = rs.simulate_batch(**kw, record=record, friction=mu, model="contact", rtol=RTOL)
    assert np.all(out["status"] == 0) and np.all(out["model"] == 3)
    slid = 0
    for i in range(mu.size):
        block = rs.Block(half_diagonal=kw["half_diagonal"][i], slenderness=kw["slenderness"][i])
        r = rs.simulate(block, record.scaled(kw["scale"][i]), friction=mu[i], rtol=RTOL)
        assert bool(out["overturned"][i]) == r.overturned, i
        assert out["max_rotation"][i] == pytest.approx(r.max_rotation, rel=10 * RTOL, abs=1e-15)
        assert out["max_slide"][i] == pytest.approx(r.max_slide, rel=10 * RTOL, abs=1e-15)
        assert bool(out["lift_off"][i]) == r.lift_off
        slid += r.max_slide > 0.0
    assert slid >= 3  # the stocky blocks slid


def test_rows_the_kernel_cannot_finish_are_answered_by_the_reference(monkeypatch):
    """A row whose kernel run reaches its step limit is run again by the solve_ivp reference
    and marked ``model`` 4, with simulate(method="scipy")'s answer; a sliding row (the exact
    kernel, nothing stepped) keeps model 3."""
    monkeypatch.setattr(contact_model, "MAX_STEPS", 3)
    alpha, mu = 0.2, 0.5
    amp = np.array([1.5, 2.5]) * G * math.tan(alpha)
    out = rs.simulate_batch(
        half_diagonal=1.0, slenderness=alpha, amplitude=amp, period=0.5, friction=mu,
        model="contact", rtol=1e-8,
    )  # fmt: skip
    assert np.all(out["model"] == 4) and np.all(out["status"] == 0)
    block = rs.Block(half_diagonal=1.0, slenderness=alpha)
    for i, a in enumerate(amp):
        r = rs.simulate(
            block, SinePulse(amplitude=a, period=0.5), friction=mu, method="scipy", rtol=1e-8
        )
        assert bool(out["overturned"][i]) == r.overturned
        assert out["max_rotation"][i] == pytest.approx(r.max_rotation, rel=1e-12)
        assert out["max_slide"][i] == pytest.approx(r.max_slide, rel=1e-12, abs=1e-15)
    record, kw, mu = _record_scenes()
    stocky = mu < np.tan(kw["slenderness"])
    out = rs.simulate_batch(**kw, record=record, friction=mu, model="contact")
    assert np.all(out["model"][stocky] == 3) and np.all(out["model"][~stocky] == 4)
