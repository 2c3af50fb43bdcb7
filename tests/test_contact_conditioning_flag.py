"""The contact model flags ill-conditioned scenes: ``simulate_batch(model="contact")`` gives
``status`` 4 to every scene whose answer lies beyond 10 rtol of the scipy reference at rtol
1e-12, and not to a well-conditioned one.

Oracle: the solve_ivp reference at rtol 1e-12 (errors relative to |x| plus 1e-2 alpha,
resp. 1e-2 R alpha, as the accuracy benchmark measures them), and for a well-conditioned
scene the reference with the amplitude moved by 1e-9 either way (its answer does not move
by 10 rtol).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.constants import STATUS_UNCONVERGED
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import Record, SinePulse

RTOL = 1e-8
FLOOR = 1e-2


def decaying_record(rng, seconds=6.0, dt=0.01):
    """White noise through a moving average under a ramp-up and a slow decay (a long tail
    of small rocking: chains of impacts near the rest speed), scaled to a peak of 1."""
    t = np.arange(0.0, seconds, dt)
    envelope = np.minimum(t / 0.5, 1.0) * np.exp(-0.5 * np.maximum(t - 1.5, 0.0))
    x = np.convolve(rng.standard_normal(t.size + 9), np.ones(10) / 10, "valid") * envelope
    return Record(x / np.max(np.abs(x)), time=t)


def reference(radius, alpha, mu, motion):
    """The reference's result of one scene (mu_s = mu_k = mu) at rtol 1e-12."""
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate_contact_reference(radius, alpha, eta, motion, mu, mu, 1e-12)


def error(found, ref, radius, alpha):
    """The larger relative error of max |theta| and max |u|, with the benchmark's floors."""
    e_theta = abs(found[0] - ref["max_rotation"]) / (abs(ref["max_rotation"]) + FLOOR * alpha)
    scale = abs(ref["max_slide"]) + FLOOR * radius * alpha
    return max(e_theta, abs(found[1] - ref["max_slide"]) / scale)


def long_tail_scenes(n=8):
    """(record, radius, alpha, mu, scale) of n rocking blocks (mu 1.05-2.5 tan alpha, peaks
    1.1-3 g tan alpha) under one record with a long tail (:func:`decaying_record`)."""
    rng = np.random.default_rng(1)
    record = decaying_record(rng)
    alpha, radius = rng.uniform(0.1, 0.4, n), rng.uniform(0.5, 3.0, n)
    mu = rng.uniform(1.05, 2.5, n) * np.tan(alpha)
    scale = rng.uniform(1.1, 3.0, n) * G * np.tan(alpha)
    return record, radius, alpha, mu, scale


def test_every_scene_beyond_10_rtol_of_the_reference_is_flagged():
    """Eight rocking blocks under a record with a long tail: the set holds a scene whose
    answer lies beyond 10 rtol of the reference (552 impacts at a rotation below 1e-3
    alpha), and every such scene has status 4; few are flagged."""
    record, radius, alpha, mu, scale = long_tail_scenes()
    n = radius.size
    out = rs.simulate_batch(
        half_diagonal=radius, slenderness=alpha, record=record, scale=scale, friction=mu,
        model="contact", rtol=RTOL, outputs=["max_rotation", "max_slide", "status"],
    )  # fmt: skip
    errors = np.array(
        [
            error(
                (out["max_rotation"][i], out["max_slide"][i]),
                reference(radius[i], alpha[i], mu[i], record.scaled(scale[i])),
                radius[i],
                alpha[i],
            )
            for i in range(n)
        ]
    )
    beyond = errors > 10 * RTOL
    flagged = out["status"] == STATUS_UNCONVERGED
    assert beyond.any(), errors / RTOL
    assert np.all(flagged[beyond]), (errors / RTOL, out["status"])
    assert flagged.sum() <= 2, out["status"]


def test_a_well_conditioned_scene_is_not_flagged():
    """A block rocking under a sine pulse, mu well above its friction demand: the reference
    with the amplitude moved by 1e-9 either way moves max |theta| by less than 10 rtol
    (well conditioned), and the batch returns the answer (status 0) within 10 rtol of it."""
    radius, alpha, mu = 1.0, 0.2, 0.8
    amplitude, period = 1.2 * G * math.tan(alpha), 1.0
    refs = [
        reference(radius, alpha, mu, SinePulse(amplitude=amplitude * f, period=period))
        for f in (1.0 - 1e-9, 1.0, 1.0 + 1e-9)
    ]
    peaks = np.array([r["max_rotation"] for r in refs])
    assert peaks[1] > 0.1 * alpha and not refs[1]["overturned"]
    assert np.ptp(peaks) < 10 * RTOL * peaks[1]
    out = rs.simulate_batch(
        half_diagonal=radius, slenderness=alpha, pulse="sine", amplitude=amplitude,
        period=period, friction=mu, model="contact", rtol=RTOL,
        outputs=["max_rotation", "max_slide", "status"],
    )  # fmt: skip
    assert out["status"][0] == 0
    found = (out["max_rotation"][0], out["max_slide"][0])
    assert error(found, refs[1], radius, alpha) <= 10 * RTOL


def test_simulate_warns_on_the_ill_conditioned_scene():
    """The single-scene path flags the same scene of :func:`long_tail_scenes` (the one
    beyond 10 rtol of the reference) with an AccuracyWarning, by the same twin run."""
    record, radius, alpha, mu, scale = long_tail_scenes()
    block = rs.Block(half_diagonal=radius[3], slenderness=alpha[3])
    with pytest.warns(rs.AccuracyWarning, match="ill-conditioned"):
        rs.simulate(block, record.scaled(scale[3]), friction=mu[3], rtol=RTOL)
