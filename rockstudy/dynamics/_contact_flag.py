"""Whether a contact batch row's answer converged with rtol (private): the rows' signals
(``decision_margin``, ``close_events``) and a second run at rtol / 100 where they call for it,
and the conditioning of every row that rocked (a twin run with the amplitude moved by
CONDITIONING_STEP) (:func:`flag_unconverged`)."""

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
#: Relative change of the amplitude of the twin run that measures a row's conditioning.
CONDITIONING_STEP = 1e-9
#: The relative precision to which a solver resolves a scene's inputs and states (the
#: scipy reference's rtol, 1e-12; the kernel's event times and rounding are resolved no
#: better): a row whose condition number kappa (relative change of max |theta| or max |u|
#: per relative change of the amplitude, from the twin run) times RESOLVED exceeds
#: CONVERGED_RTOL rtol has no answer to 10 rtol, from the kernel or the reference (a long
#: chain of impacts near the rest speed, an uplift or an overturning grazed).
RESOLVED = 1e-12
#: The finest rtol whose 10 rtol the scipy reference (rtol RESOLVED) can check: below it,
#: the twin run's bound is that of FINEST_RTOL (a chain of impacts resolved to 1e-12 is
#: as good as any solver gives it).
FINEST_RTOL = 1e-10


def _moved(a, b, p, alpha, bound):
    """Whether rows b answer differently from rows a (blocks p, alpha) by more than
    ``bound`` (relative): a status, an overturning decision, max_rotation or max_slide."""
    radius = 0.75 * G / (p * p)
    d_theta = np.abs(a["max_rotation"] - b["max_rotation"])
    d_u = np.abs(a["max_slide"] - b["max_slide"])
    return (
        (a["status"] != b["status"])
        | (a["overturned"] != b["overturned"])
        | ~(d_theta <= bound * (np.abs(b["max_rotation"]) + FLOOR * alpha))
        | ~(d_u <= bound * (np.abs(b["max_slide"]) + FLOOR * radius * alpha))
    )


def _ill_conditioned(out, cols, rows, rtol, ok):
    """Which rows of ``out`` (their ``ok`` ones that rocked: rest and pure slide, exact or
    Lipschitz in the amplitude, are left out) change under the twin run
    ``rows(index, rtol, 1 + CONDITIONING_STEP)`` by more than CONVERGED_RTOL rtol
    CONDITIONING_STEP / RESOLVED: their condition number times RESOLVED exceeds
    CONVERGED_RTOL rtol (see RESOLVED; rtol no finer than FINEST_RTOL)."""
    p, alpha = cols[0], cols[1]
    rocked = np.flatnonzero(ok & (out["max_rotation"] > 0.0))
    ill = np.zeros(out.size, bool)
    if rocked.size:
        twin = rows(rocked, rtol, 1.0 + CONDITIONING_STEP)
        bound = CONVERGED_RTOL * max(rtol, FINEST_RTOL) * CONDITIONING_STEP / RESOLVED
        ill[rocked] = _moved(out[rocked], twin, p[rocked], alpha[rocked], bound)
    return ill


def flag_unconverged(out, cols, rows, rtol):
    """Set ``converged`` of the batch rows ``out`` (``cols`` = p, alpha, eta, mu_s, mu_k per
    row): False where the status is not 0, where a friction decision whose outcome jumps
    (mu_s > mu_k) lay within DECISION_BAND rtol of its threshold, where the cheap signals
    (a decision within SUSPECT_BAND rtol, an event on the first DOP853 step of a regime)
    call for a second run, ``rows(index, rtol * RERUN_FACTOR)``, whose answer moved by more
    than CONVERGED_RTOL rtol (:func:`_moved`), and where the row is ill-conditioned
    (:func:`_ill_conditioned`: ``rows(index, rtol, factor)`` runs the rows with their
    amplitudes times ``factor``)."""
    p, alpha, static, kinetic = cols[0], cols[1], cols[3], cols[4]
    ok = out["status"] == 0
    margin = out["decision_margin"]
    suspect = np.flatnonzero(ok & ((margin < SUSPECT_BAND * rtol) | (out["close_events"] > 0)))
    if suspect.size:
        fine = rows(suspect, rtol * RERUN_FACTOR)
        bound = CONVERGED_RTOL * rtol
        ok[suspect] &= ~_moved(out[suspect], fine, p[suspect], alpha[suspect], bound)
    ok &= ~_ill_conditioned(out, cols, rows, rtol, ok)
    out["converged"] = ok & ~((margin < DECISION_BAND * rtol) & (static > kinetic))


def row_runner(cols, motion_rows, max_steps, run):
    """rows(index, tolerance, factor=1.0): the batch kernel ``run``'s rows ``index`` of the
    columns ``cols`` (p, alpha, eta, mu_s, mu_k) and ``motion_rows`` (kind, mp, times,
    samples, vsamples) at ``tolerance``, their amplitudes times ``factor``."""
    kind, mp, times, samples, vsamples = motion_rows

    def rows(index, tolerance, factor=1.0):
        """The kernel's rows ``index`` at ``tolerance``, their amplitudes times ``factor``."""
        picked = (c[index] for c in cols)
        amplitudes = mp[index] * np.array([factor, 1.0, 1.0, 1.0])
        motion = (kind, amplitudes, times, samples, vsamples)
        return run(*picked, *motion, tolerance, int(max_steps))

    return rows
