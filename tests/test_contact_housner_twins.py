"""The conditioning twin of a contact batch row that rocked as Housner's block (no slip, no
lift-off, no fall) runs through the rocking kernel where Housner's twin needs less friction
than mu_s, and the flag is the one the contact kernel's twins give.

Oracle: the flag with every twin run through the contact kernel (the definition of the
conditioning flag), and the rocking kernel's friction demand of Housner's block (the rows
whose twin may leave pure rocking).
"""

from __future__ import annotations

import numpy as np

from rockstudy.constants import G
from rockstudy.dynamics import _contact_flag as cf
from rockstudy.dynamics._contact_scene import MAX_STEPS, contact_batch_serial
from rockstudy.motions import Record

RTOL = 1e-8


def long_tail_rows(n=24, seed=3):
    """(cols, motion_rows) of n blocks (mu from tan alpha to 2.5 tan alpha: some rock
    only, some slip or fly) under a white-noise record with a long, slowly decaying tail
    (chains of small impacts: some rows are ill-conditioned)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 6.0, 0.01)
    envelope = np.minimum(t / 0.5, 1.0) * np.exp(-0.5 * np.maximum(t - 1.5, 0.0))
    x = np.convolve(rng.standard_normal(t.size + 9), np.ones(10) / 10, "valid") * envelope
    record = Record(x / np.max(np.abs(x)), time=t)
    alpha, radius = rng.uniform(0.1, 0.4, n), rng.uniform(0.5, 3.0, n)
    mu = rng.uniform(1.0, 2.5, n) * np.tan(alpha)
    scale = rng.uniform(1.1, 3.0, n) * G * np.tan(alpha)
    kind, _, times, samples, vsamples = record.kernel_spec()
    mp = np.column_stack([scale, np.zeros(n), np.zeros(n), np.full(n, record.duration)])
    eta = 1.0 - 1.5 * np.sin(alpha) ** 2
    p = np.sqrt(0.75 * G / radius)
    cols = tuple(np.ascontiguousarray(c, dtype=float) for c in (p, alpha, eta, mu, mu))
    arrays = (np.ascontiguousarray(a, dtype=float) for a in (mp, times, samples, vsamples))
    return cols, (np.int64(kind), *arrays)


def counting(runner):
    """``runner`` that also lists the rows it ran as twins (factor other than 1)."""
    twinned = []

    def rows(index, tolerance, factor=1.0):
        if factor != 1.0:
            twinned.extend(np.atleast_1d(index).tolist())
        return runner(index, tolerance, factor)

    return rows, twinned


def flags(cols, motion, out, housner):
    """``converged`` of the rows ``out`` by :func:`flag_unconverged`, with Housner twins or
    not, and the rows the contact kernel ran as twins."""
    rows, twinned = counting(cf.row_runner(cols, motion, MAX_STEPS, contact_batch_serial))
    flagged = out.copy()
    cf.flag_unconverged(flagged, cols, rows, RTOL, housner)
    return flagged["converged"], set(int(i) for i in twinned)


def test_housner_twins_flag_the_rows_the_contact_twins_flag():
    """The same ``converged`` as with the contact kernel's twins, on a set that holds pure
    rocking rows, rows that slipped or flew, and ill-conditioned rows; the contact kernel
    twins no pure-rocking row whose Housner twin stands."""
    cols, motion = long_tail_rows()
    out = cf.row_runner(cols, motion, MAX_STEPS, contact_batch_serial)(slice(None), RTOL)
    housner = cf.housner_runner(cols, motion, MAX_STEPS, parallel=False)
    by_contact, all_twins = flags(cols, motion, out, None)
    by_housner, contact_twins = flags(cols, motion, out, housner)
    pure = np.flatnonzero(cf._pure_rocking(out) & (out["status"] == 0))
    assert pure.size >= 5 and (~cf._pure_rocking(out) & (out["max_rotation"] > 0)).any()
    assert (~by_contact).any(), out["max_rotation"]
    np.testing.assert_array_equal(by_housner, by_contact)
    assert set(pure) <= all_twins
    assert not set(pure) & contact_twins


def test_a_housner_twin_near_its_friction_limit_runs_through_the_contact_kernel():
    """A row given mu_s just above its Housner demand (within DEMAND_MARGIN) rocks without
    a slip, but its twin could slip: the contact kernel runs it, and the flag is the one
    of the contact kernel's twins."""
    cols, motion = long_tail_rows()
    out = cf.row_runner(cols, motion, MAX_STEPS, contact_batch_serial)(slice(None), RTOL)
    pure = np.flatnonzero(cf._pure_rocking(out) & (out["status"] == 0))
    housner = cf.housner_runner(cols, motion, MAX_STEPS, parallel=False)
    demand = housner(pure, RTOL)["friction_demand"]
    tight = [np.array(c, copy=True) for c in cols]
    tight[3][pure] = tight[4][pure] = demand * (1.0 + 0.1 * cf.DEMAND_MARGIN)
    tight = tuple(tight)
    out = cf.row_runner(tight, motion, MAX_STEPS, contact_batch_serial)(slice(None), RTOL)
    still = [i for i in pure if cf._pure_rocking(out[i : i + 1])[0]]
    assert still, "no row stayed in pure rocking at its own demand"
    housner = cf.housner_runner(tight, motion, MAX_STEPS, parallel=False)
    by_contact, _ = flags(tight, motion, out, None)
    by_housner, contact_twins = flags(tight, motion, out, housner)
    assert set(still) <= contact_twins
    np.testing.assert_array_equal(by_housner, by_contact)
