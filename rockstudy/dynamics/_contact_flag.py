"""Whether a contact batch row's answer converged with rtol (private): the rows' signals
(``decision_margin``, ``close_events``) and a second run at rtol / 100 where they call for it
(:func:`flag_unconverged`)."""

from __future__ import annotations

import numpy as np

from ..constants import G

#: Relative margin of a friction decision, in units of rtol, below which a scene's answer is
#: flagged outright where mu_s > mu_k: the decision lies within rtol of its threshold, and its
#: outcome jumps there (a slip starts under mu_k N < mu_s N). Where mu_s = mu_k the contact
#: forces, and so the answer, are continuous across the threshold (a slip starts at a rate
#: proportional to the excess): a rerun decides (SUSPECT_BAND).
DECISION_BAND = 10.0
#: Relative margin, in units of rtol, below which a scene is run again at rtol *
#: RERUN_FACTOR to see whether its answer holds (as is any scene with an event on the first
#: step of a regime: two events inside one step).
SUSPECT_BAND = 1e4
RERUN_FACTOR = 1e-2
#: Change of max_rotation or max_slide between the two runs, in units of rtol, beyond which
#: a scene's answer did not converge: relative to |x| plus FLOOR alpha (resp. FLOOR R alpha),
#: the measure of the accuracy benchmark.
CONVERGED_RTOL = 10.0
FLOOR = 1e-2


def _moved(a, b, p, alpha, rtol):
    """Whether rows b answer differently from rows a (blocks p, alpha) by more than
    CONVERGED_RTOL rtol: a status, an overturning decision, max_rotation or max_slide."""
    radius = 0.75 * G / (p * p)
    d_theta = np.abs(a["max_rotation"] - b["max_rotation"])
    d_u = np.abs(a["max_slide"] - b["max_slide"])
    bound = CONVERGED_RTOL * rtol
    return (
        (a["status"] != b["status"])
        | (a["overturned"] != b["overturned"])
        | ~(d_theta <= bound * (np.abs(b["max_rotation"]) + FLOOR * alpha))
        | ~(d_u <= bound * (np.abs(b["max_slide"]) + FLOOR * radius * alpha))
    )


def flag_unconverged(out, cols, rows, rtol):
    """Set ``converged`` of the batch rows ``out`` (``cols`` = p, alpha, eta, mu_s, mu_k per
    row): False where the status is not 0, where a friction decision whose outcome jumps
    (mu_s > mu_k) lay within DECISION_BAND rtol of its threshold, and where the cheap signals
    (a decision within SUSPECT_BAND rtol, an event on the first DOP853 step of a regime)
    call for a second run, ``rows(index, rtol * RERUN_FACTOR)``, whose answer moved by more
    than CONVERGED_RTOL rtol (:func:`_moved`)."""
    p, alpha, static, kinetic = cols[0], cols[1], cols[3], cols[4]
    ok = out["status"] == 0
    margin = out["decision_margin"]
    suspect = np.flatnonzero(ok & ((margin < SUSPECT_BAND * rtol) | (out["close_events"] > 0)))
    if suspect.size:
        fine = rows(suspect, rtol * RERUN_FACTOR)
        ok[suspect] &= ~_moved(out[suspect], fine, p[suspect], alpha[suspect], rtol)
    out["converged"] = ok & ~((margin < DECISION_BAND * rtol) & (static > kinetic))
