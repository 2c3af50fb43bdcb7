"""The contact reference never rocks on a corner that Coulomb's law cannot hold.

Oracle: the contact forces of rocking about a corner (Newton-Euler, :func:`.slide_rock
.contact_forces`) at the state right after each impact of the reference's own history. Where
Housner's impulse stays inside the friction cone but the rocking forces just after it do not
(``|F|`` > mu N), the corner cannot stick: the block must slip from the impact on, so the
slide of the next history row differs from the slide at the impact.
"""

from __future__ import annotations

import math

import numpy as np

from rockstudy.constants import G
from rockstudy.dynamics import slide_rock as sr
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import Record


def synthetic_record(rng, seconds=3.0, dt=0.01):
    """White noise through a moving average under a ramp-up and decay envelope, peak 1."""
    t = np.arange(0.0, seconds, dt)
    envelope = np.minimum(t / 0.5, 1.0) * np.exp(-np.maximum(t - 1.5, 0.0))
    x = np.convolve(rng.standard_normal(t.size + 9), np.ones(10) / 10, "valid") * envelope
    return Record(x / np.max(np.abs(x)), time=t)


def unheld_impacts(result, record, radius, alpha, mu):
    """[(impact time, |F| / N just after it, whether the next row slipped)] of the impacts
    after which rocking on the new corner needs more than 1.01 mu N."""
    t, w, u = (np.asarray(result[key]) for key in ("t", "theta_dot", "slide"))
    found = []
    for t_i in result["impact_times"]:
        j = np.flatnonzero(t == t_i)[-1]  # the row after the impact
        if j + 1 >= t.size or w[j] == 0.0:
            continue
        side = math.copysign(1.0, w[j])
        a_h = float(np.interp(t_i, record.time, record.acceleration))
        theta_ddot = sr.rocking_acceleration(0.0, a_h, 0.0, side, radius, alpha)
        f_h, f_v = sr.contact_forces(0.0, w[j], theta_ddot, 0.0, a_h, 0.0, side, radius, alpha)
        if abs(f_h) > 1.01 * mu * f_v:
            found.append((t_i, abs(f_h) / f_v, bool(u[j + 1] != u[j])))
    return found


def test_a_corner_the_friction_cannot_hold_after_an_impact_slips():
    """A block with mu 4 % above tan(alpha) under a synthetic record: at least one impact
    leaves the new corner with rocking forces outside the cone (Housner's impulse inside
    it), and after every such impact the reference slips at once."""
    alpha, radius = 0.15, 2.0
    mu = 1.04 * math.tan(alpha)
    record = synthetic_record(np.random.default_rng(8)).scaled(1.3 * G * math.tan(alpha))
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    result = simulate_contact_reference(radius, alpha, eta, record, mu, mu, 1e-10)
    found = unheld_impacts(result, record, radius, alpha, mu)
    assert found, "the scene no longer has an impact the friction cannot hold"
    assert all(slipped for _, _, slipped in found), found
