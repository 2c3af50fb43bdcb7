"""Whether a contact batch row's answer converged with rtol (private): the rows' signals
(``decision_margin``, ``close_events``) and a second run at rtol / 100 where they call for it,
and the conditioning of every row that rocked (a twin run with the amplitude moved by
CONDITIONING_STEP) (:func:`flag_unconverged`).

A row that rocked without a slip, a lift-off or a fall answers Housner's problem, and so does
its twin where Housner's block under the twin's motion needs less friction than mu_s (by
DEMAND_MARGIN) and never lifts off: that motion is then a solution of the contact model
(every contact force inside the cone, every impulse of Housner's impacts too: the demand
holds their ratio), which is the contact model's answer. Such a twin runs through the
rocking kernel (:func:`housner_runner`, about a third of the contact kernel's cost), which
computes that demand on the way; the other twins, and the rows whose Housner twin fails the
test, run through the contact kernel."""

from __future__ import annotations

import numpy as np

from ..constants import G
from . import _rocking

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
#: Relative margin by which the friction demand of a Housner twin (sampled on its steps and
#: refined at its peaks, :mod:`._demand`) must lie below mu_s for the twin to stand for the
#: contact model's: far above the error of the sampled demand.
DEMAND_MARGIN = 1e-3
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


def _pure_rocking(out):
    """Which rows of ``out`` rocked without a slip, a lift-off, a flight or a fall (their
    answer is Housner's)."""
    return (
        (out["max_rotation"] > 0.0)
        & ~out["overturned"]
        & ~out["lift_off"]
        & np.isnan(out["first_slip_time"])
        & (out["time_slide"] == 0.0)
        & (out["time_slide_rock"] == 0.0)
        & (out["time_flight"] == 0.0)
    )


def _housner_twins(housner, index, static, rtol):
    """The twins of the pure-rocking rows ``index`` by the rocking kernel ``housner`` (rows
    of :func:`housner_runner`): (the rows whose twin stands for the contact model's, those
    twins as contact rows with no slide). A twin stands where it stays up, never lifts off
    and its friction demand times 1 + DEMAND_MARGIN lies below mu_s (``static``); a demand
    the kernel did not compute (NaN) does not."""
    twin = housner(index, rtol, 1.0 + CONDITIONING_STEP)
    with np.errstate(invalid="ignore"):
        below = twin["friction_demand"] * (1.0 + DEMAND_MARGIN) < static[index]
    stands = (twin["status"] == 0) & ~twin["overturned"] & (twin["lift_off"] == 0) & below
    rows = {
        "status": twin["status"][stands],
        "overturned": twin["overturned"][stands],
        "max_rotation": twin["max_rotation"][stands],
        "max_slide": np.zeros(int(stands.sum())),
    }
    return stands, rows


def _ill_conditioned(out, cols, rows, rtol, ok, housner=None):
    """Which rows of ``out`` (their ``ok`` ones that rocked: rest and pure slide, exact or
    Lipschitz in the amplitude, are left out) change under the twin run
    ``rows(index, rtol, 1 + CONDITIONING_STEP)`` by more than CONVERGED_RTOL rtol
    CONDITIONING_STEP / RESOLVED: their condition number times RESOLVED exceeds
    CONVERGED_RTOL rtol (see RESOLVED; rtol no finer than FINEST_RTOL). With ``housner``
    (:func:`housner_runner`), the twins of the pure-rocking rows run through the rocking
    kernel where they stand for the contact model's (:func:`_housner_twins`)."""
    p, alpha, static = cols[0], cols[1], cols[3]
    rocked = ok & (out["max_rotation"] > 0.0)
    ill = np.zeros(out.size, bool)
    bound = CONVERGED_RTOL * max(rtol, FINEST_RTOL) * CONDITIONING_STEP / RESOLVED
    pure = np.flatnonzero(rocked & _pure_rocking(out)) if housner else np.empty(0, int)
    if pure.size:
        stands, twin = _housner_twins(housner, pure, static, rtol)
        done = pure[stands]
        ill[done] = _moved(out[done], twin, p[done], alpha[done], bound)
        rocked[done] = False
    rest = np.flatnonzero(rocked)
    if rest.size:
        twin = rows(rest, rtol, 1.0 + CONDITIONING_STEP)
        ill[rest] = _moved(out[rest], twin, p[rest], alpha[rest], bound)
    return ill


def flag_unconverged(out, cols, rows, rtol, housner=None):
    """Set ``converged`` of the batch rows ``out`` (``cols`` = p, alpha, eta, mu_s, mu_k per
    row): False where the status is not 0, where a friction decision whose outcome jumps
    (mu_s > mu_k) lay within DECISION_BAND rtol of its threshold, where the cheap signals
    (a decision within SUSPECT_BAND rtol, an event on the first DOP853 step of a regime)
    call for a second run, ``rows(index, rtol * RERUN_FACTOR)``, whose answer moved by more
    than CONVERGED_RTOL rtol (:func:`_moved`), and where the row is ill-conditioned
    (:func:`_ill_conditioned`: ``rows(index, rtol, factor)`` runs the rows with their
    amplitudes times ``factor``; ``housner``, of :func:`housner_runner`, the same rows of
    Housner's block for the pure-rocking rows' twins)."""
    p, alpha, static, kinetic = cols[0], cols[1], cols[3], cols[4]
    ok = out["status"] == 0
    margin = out["decision_margin"]
    suspect = np.flatnonzero(ok & ((margin < SUSPECT_BAND * rtol) | (out["close_events"] > 0)))
    if suspect.size:
        fine = rows(suspect, rtol * RERUN_FACTOR)
        bound = CONVERGED_RTOL * rtol
        ok[suspect] &= ~_moved(out[suspect], fine, p[suspect], alpha[suspect], bound)
    ok &= ~_ill_conditioned(out, cols, rows, rtol, ok, housner)
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


def housner_runner(cols, motion_rows, max_steps, parallel):
    """housner(index, tolerance, factor=1.0): the rocking kernel's rows ``index`` (Housner's
    block, nonlinear, with its friction demand and lift-off) of the columns ``cols`` (p,
    alpha, eta, ...) and ``motion_rows`` (kind, mp, times, samples, vsamples) at
    ``tolerance``, their amplitudes times ``factor``; in parallel or on one thread."""
    run = _rocking.scene_batch if parallel else _rocking.scene_batch_serial

    def housner(index, tolerance, factor=1.0):
        p, alpha, eta = (c[index] for c in cols[:3])
        kind, mp, times, samples, vsamples = motion_rows
        amplitudes = mp[index] * np.array([factor, 1.0, 1.0, 1.0])
        model = _rocking.MODEL_NONLINEAR
        motion = (kind, amplitudes, times, samples, vsamples)
        return run(p, alpha, eta, model, *motion, tolerance, int(max_steps), True)

    return housner
