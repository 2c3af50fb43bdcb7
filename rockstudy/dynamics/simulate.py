"""``simulate``: one structure, one ground motion, one method."""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Literal

import numpy as np

from .. import _validate
from .._warnings import EquivalentBlockWarning, LinearizationWarning
from ..constants import FALL_ROTATION, G
from ..motions import Motion
from ..motions import _kernels as mk
from ..motions.pulses import PULSES
from ..structures.block import block_parameters
from ..structures.equivalent import ConicalShell, PointMassStrut, SymmetricFrame
from ..structures.isolated import IsolatedBlock
from ..structures.stacked import StackedBlocks
from . import _auto, _linear, _linear_record, _rocking, contact, contact_model
from ._vertical import refuse_free_fall, uplift_ratio
from .conditioning import peak_change, perturbed
from .isolated_reference import simulate_isolated
from .methods import MAX_STEPS, StepLimitError, method_for
from .reference import simulate_reference
from .result import RockingResult, describe
from .stacked_reference import simulate_stacked_blocks

__all__ = [
    "check_friction",
    "EXACT_EQUIVALENTS",
    "LINEAR_WARN",
    "MAX_FRICTION",
    "Method",
    "simulate",
]

#: Largest friction coefficient mu taken (simulate's ``friction`` and a study's; no contact
#: needs more).
MAX_FRICTION = 10.0

#: simulate(method="linear") warns above this linearization error bound.
LINEAR_WARN = 0.1

_SHAPES = {cls: name for name, cls in PULSES.items()}  # pulse class -> shape name

#: Structures whose kappa_1 equivalent block is exact (Table I of [003]: kappa_1 = 1, so the
#: block's theta is the structure's phi, and I_nl is constant): ``auto`` runs the block.
EXACT_EQUIVALENTS = (PointMassStrut, ConicalShell, SymmetricFrame)

Method = Literal["nonlinear", "linear", "scipy", "scipy-linear", "mechanism", "complex", "auto"]


def _kernel(
    p,
    alpha,
    eta,
    motion,
    model,
    rtol,
    t_max,
    max_steps,
    method,
    x0,
    fall=FALL_ROTATION,
    tab=_rocking.NO_TABLE,
    t_eval=None,
):
    kind, mp, times, samples, vsamples = motion.kernel_spec()
    scene, tab = _scene_variant(kind, model, vsamples, tab)
    t_tail = _tail_end(p, eta, motion, t_max)
    _check_end(t_eval, t_tail)
    cap = 4096
    while True:
        hist = np.empty((cap, 3))
        imps = np.empty(cap)
        peaks = np.empty((cap, 2))
        dense = np.zeros((0 if t_eval is None else t_eval.size, 3))  # (0, 0): at rest
        if t_eval is not None:
            dense[:, 0] = t_eval
        r = scene(
            _rocking.Body(p, alpha, eta, model, fall, tab),
            (kind, mp, times, samples, vsamples),
            _rocking.Controls(rtol, max_steps, False, t_tail),
            _rocking.Start(x0[0], x0[1]),
            (hist, imps, peaks, dense),
        )
        if max(r.n_history, r.n_impact_times, r.n_peaks) <= cap:
            break
        cap *= 4
    if r.status == _rocking.STATUS_MAX_STEPS:
        raise StepLimitError(method, max_steps)
    nh, over, t_ot = r.n_history, bool(r.overturned), float(r.overturn_time)
    return RockingResult(
        hist[:nh, 0].copy(),
        hist[:nh, 1].copy(),
        hist[:nh, 2].copy(),
        float(r.max_rotation),
        over,
        imps[: r.n_impact_times].copy(),
        t_ot,
        method,
        {"steps": int(r.steps), "dop853_steps": int(r.steps)},
        peaks[: r.n_peaks, 0].copy(),
        peaks[: r.n_peaks, 1].copy(),
        **_dense_fields(t_eval, dense[:, 1], dense[:, 2], over, t_ot),
    )


def _scene_variant(kind, model, vsamples, tab):
    """The scene kernel for a motion and model, and its table argument: a block model under a
    trigonometric pulse without a vertical component runs :func:`._rocking.scene_trig` (the
    same steps, compiled in half the time); anything else the general :func:`._rocking.scene`.
    The tables (:data:`._rocking.NO_TABLE`, a structure's) are read-only, the type a study's
    batch kernel compiles the scenes for, so that the kernels cached by a study serve
    ``simulate`` too."""
    if kind == mk.KIND_TRIG and model != _rocking.MODEL_TABLE and not vsamples.size:
        return _rocking.scene_trig, _rocking.NO_TABLE
    return _rocking.scene, tab


def _check_end(t_eval, end):
    """Refuse requested times beyond the end of the history ``end`` [s] (before the run)."""
    if t_eval is not None and t_eval.size and t_eval[-1] > end:
        raise ValueError(
            f"t_eval reaches {t_eval[-1]!r} s, beyond the simulated end {end!r} s (a block "
            "that never comes to rest, restitution 1, is followed for 100 / p after the "
            "motion: give t_max to follow it longer)"
        )


def _dense_fields(t_eval, theta, theta_dot, over, t_ot) -> dict:
    """The dense-output fields of a RockingResult: none without ``t_eval``; NaN after an
    overturning at ``t_ot`` [s] (the model ends there)."""
    if t_eval is None:
        return {}
    theta, theta_dot = np.array(theta, dtype=float), np.array(theta_dot, dtype=float)
    if over:
        theta[t_eval > t_ot] = np.nan
        theta_dot[t_eval > t_ot] = np.nan
    return {"t_eval": t_eval, "theta_eval": theta, "theta_dot_eval": theta_dot}


def _linear_exact(p, alpha, eta, motion, model, rtol, t_max, max_steps, method, x0, t_eval=None):
    """Exact piecewise solution for trigonometric pulses (eq. 3.4 of [000]) and for records
    without a vertical component (:func:`_linear_record_exact`); the kernel for other motions
    (also for a record with a vertical component, which the constant-coefficient closed forms
    cannot take: said in ``info["solver"]``). Peaks and the dense output are the closed
    form's."""
    kind, mp, _, _, vsamples = motion.kernel_spec()
    if kind == mk.KIND_RECORD and not vsamples.size:
        return _linear_record_exact(p, alpha, eta, motion, t_max, method, x0, t_eval)
    if kind != mk.KIND_TRIG:
        args = (p, alpha, eta, motion, model, rtol, t_max, max_steps, method, x0)
        r = _kernel(*args, t_eval=t_eval)
        if vsamples.size:
            r.info["solver"] = (
                "Taylor-step kernel of the linearized eq. (3.1) of [000] with gravity g + u_v'' "
                "(the exact record solver has constant coefficients: no vertical component)"
            )
        return r
    t_tail = _tail_end(p, eta, motion, t_max)
    _check_end(t_eval, t_tail)
    cap = 1024
    while True:
        rec = np.zeros((cap, _linear.PHASE_LOG_WIDTH))
        r = _linear.trig_scene(p, alpha, eta, mp, False, t_tail, rec, x0[0], x0[1])
        if rec[0, 0] < cap - 1:
            break
        cap *= 4
    t, th, om, impacts = _linear.phase_history(rec, p, alpha, mp[1], mp[2], x0)
    dense = {}
    if t_eval is not None:
        th_e, om_e = _linear.phase_states(rec, p, alpha, mp[1], mp[2], t_eval, x0)
        dense = _dense_fields(t_eval, th_e, om_e, r.overturned, r.overturn_time)
    return RockingResult(
        t,
        th,
        om,
        float(r.max_rotation),
        bool(r.overturned),
        impacts,
        float(r.overturn_time),
        method,
        {"solver": "exact piecewise (eq. 3.4 of [000])"},
        *_linear.phase_peaks(rec, p),
        **dense,
    )


def _linear_record_exact(p, alpha, eta, motion, t_max, method, x0, t_eval=None):
    """The linearized block under a record, in closed form on each record segment
    (``_linear_record.record_scene``): the history holds the uplifts, the impacts (before and
    after), the rests and every segment end, then the free rocking after the record in closed
    form (``_linear.trig_scene``); peaks at the closed-form turning points; the dense output
    from the closed form of the segment (or free-rocking phase) that holds each time."""
    _, mp, times, samples, _ = motion.kernel_spec()
    t_tail = _tail_end(p, eta, motion, t_max)
    _check_end(t_eval, t_tail)
    dur = float(times[-1])
    t_in = np.empty(0) if t_eval is None else t_eval[t_eval <= dur]
    loud = _linear_record.loud_table(samples)
    cap = 4096
    while True:
        log = (np.empty((cap, 3)), np.empty(cap), np.empty((cap, 2)), np.zeros((t_in.size, 3)))
        log[3][:, 0] = t_in
        tail = np.zeros((cap, _linear.PHASE_LOG_WIDTH))
        args = (p, alpha, eta, mp[0], times, samples, loud, False, t_tail, log, tail)
        r = _linear_record.record_scene(*args, *x0)
        counts = r.log_rows
        if max(counts) <= cap and tail[0, 0] < cap - 1:
            break
        cap *= 4
    nh, ni, npk = counts
    t_free, th_free, om_free, imp_free = _linear.phase_history(tail, p, alpha, 1.0, 0.0)
    peak_t, peak_th = _linear.phase_peaks(tail, p)
    hist = log[0][:nh]
    peaks = log[2][:npk]
    if x0[0] != 0.0 and x0[1] == 0.0:  # released at rest: t = 0 is a peak, as for pulses
        peaks = np.vstack([[0.0, x0[0]], peaks])
    dense = {}
    if t_eval is not None:
        after = t_eval[t_eval > dur] - dur
        th_after, om_after = _linear.phase_states(tail, p, alpha, 1.0, 0.0, after)
        theta = np.concatenate([log[3][:, 1], th_after])
        theta_dot = np.concatenate([log[3][:, 2], om_after])
        dense = _dense_fields(t_eval, theta, theta_dot, r.overturned, r.overturn_time)
    return RockingResult(
        np.concatenate([hist[:, 0], t_free[1:] + dur]),
        np.concatenate([hist[:, 1], th_free[1:]]),
        np.concatenate([hist[:, 2], om_free[1:]]),
        float(r.max_rotation),
        bool(r.overturned),
        np.concatenate([log[1][:ni], imp_free + dur]),
        float(r.overturn_time),
        method,
        {
            "solver": "exact piecewise: eq. (3.1) of [000] in closed form on each record segment",
            "steps": 0,
            "dop853_steps": 0,
        },
        np.concatenate([peaks[:, 0], peak_t + dur]),
        np.concatenate([peaks[:, 1], peak_th]),
        **dense,
    )


def _tail_end(p, eta, motion, t_max):
    """End of the free-rocking history: t_max, or open-ended unless the block never rests."""
    if t_max is not None:
        return t_max
    return _rocking.free_tail_end(p, eta, motion.duration)


def _complex(p, alpha, eta, motion, model, rtol, t_max, max_steps, method, x0, l=1e-4, t_eval=None):
    from .complex import simulate_complex

    r = simulate_complex(p, alpha, eta, motion, l=l, rtol=rtol, t_end=t_max, x0=x0, t_eval=t_eval)
    return RockingResult.from_dict(r, method, {"l": l, "rk45_steps": r["steps"]})


def _linearization_bound(p, alpha, eta, motion, x0):
    """(psi, error bound of the linear model, whether the table covers the scene) for one
    scene; the bound is inf where none is tabulated."""
    _, mp, _, samples, vsamples = motion.kernel_spec()
    if vsamples.size:  # max |u_h''| / ((g + u_v'') tan alpha): > 1 where the block can lift
        psi = float(uplift_ratio(mp[0], alpha, samples, vsamples)[0])
    else:
        psi = motion.peak / (G * math.tan(alpha))
    shape = _SHAPES.get(type(motion))
    tabulated = shape in _auto.bound_table()["shape_index"]
    if x0 != (0.0, 0.0) or not tabulated or getattr(motion, "cycles", 1) != 1:
        return psi, math.inf, False
    omega = 2.0 * math.pi / (motion.period * p)
    bound = float(_auto.linearization_bound(shape, eta, alpha, psi, omega))
    return psi, bound, _auto.table_covers(eta, alpha, psi, omega)


def _warn_linearization(p, alpha, eta, motion, x0):
    psi, bound, covered = _linearization_bound(p, alpha, eta, motion, x0)
    if psi < 1.0 and x0 == (0.0, 0.0):
        return
    if covered and bound > LINEAR_WARN:
        what = (
            f"up to {bound:.2g}"
            if math.isfinite(bound)
            else "unbounded: one of the two models overturns near this scene"
        )
    elif not covered and alpha > _auto.largest_slenderness():
        what = "unknown here, and of order alpha^2 / 2 at best"
    else:
        return
    warnings.warn(
        f"linearized model (3.1) at alpha = {alpha:.3g} rad, a_g / (g tan alpha) = "
        f"{psi:.3g}: its relative max-rotation error is {what} (it grows as alpha^2, near "
        "psi = 1 and near the overturning boundaries); use method='nonlinear' or 'auto'",
        LinearizationWarning,
        stacklevel=4,
    )


def _auto_kernel(run, rtol, critical):
    """(result, kernel rtol) of ``run(kernel_rtol)`` at the rtol ``auto`` needs: 0.05 ``rtol``
    (5e-6 at most), and tighter again for responses below SMALL_ROTATION ``critical``
    (chattering makes the kernel's error absolute there; see :mod:`._auto`)."""
    k_rtol = _auto.kernel_rtol(rtol)
    r = run(k_rtol)
    ratio = r.max_rotation / critical
    if 0.0 < ratio < _auto.SMALL_ROTATION:
        k_rtol = float(_auto.kernel_rtol_small(rtol, ratio))
        r = run(k_rtol)
    return r, k_rtol


def _auto_method(p, alpha, eta, motion, model, rtol, t_max, max_steps, method, x0, t_eval=None):
    """The cheapest method whose error bound meets ``rtol`` (see :mod:`._auto`). With a full
    history the exact linear solver is not cheaper than the kernel (it evaluates its phases on
    a dense grid in Python: 0.70 ms against 0.15-0.6 ms per work-precision scene), so here the
    choice is rest or the kernel; :func:`simulate_batch` also uses the linear model."""
    psi, bound, _ = _linearization_bound(p, alpha, eta, motion, x0)
    rest = x0 == (0.0, 0.0) and psi < 1.0
    args = (p, alpha, eta, motion, _rocking.MODEL_NONLINEAR)
    r, k_rtol = _auto_kernel(
        lambda k: _kernel(*args, k, t_max, max_steps, method, x0, t_eval=t_eval), rtol, alpha
    )
    chosen = _auto.MODEL_REST if rest else _auto.MODEL_NONLINEAR
    r.info.update(model=_auto.MODEL_NAMES[chosen], linearization_bound=bound, rtol=k_rtol)
    return r


def _scipy(p, alpha, eta, motion, model, rtol, t_max, max_steps, method, x0, t_eval=None):
    _check_end(t_eval, _tail_end(p, eta, motion, t_max))
    r = simulate_reference(
        p, alpha, eta, motion, model, rtol, t_max=t_max, initial_state=x0, t_eval=t_eval
    )
    return RockingResult.from_dict(r, method)


#: method -> (runner, kernel model) of a block; what each method can run is in
#: :data:`rockstudy.dynamics.methods.METHODS`
_RUNNERS = {
    "nonlinear": (_kernel, _rocking.MODEL_NONLINEAR),
    "linear": (_linear_exact, _rocking.MODEL_LINEAR),
    "scipy": (_scipy, _rocking.MODEL_NONLINEAR),
    "scipy-linear": (_scipy, _rocking.MODEL_LINEAR),
    "mechanism": (None, _rocking.MODEL_TABLE),
    "complex": (_complex, None),
    "auto": (_auto_method, None),
}


def check_friction(value) -> float:
    """The friction coefficient mu in (0, :data:`MAX_FRICTION`] as a float, or a ValueError
    naming ``friction``."""
    value = _validate.number("friction", value)
    if not (math.isfinite(value) and 0.0 < value <= MAX_FRICTION):
        raise ValueError(f"friction must lie in (0, {MAX_FRICTION:g}], got {value!r}")
    return value


def simulate(
    structure,
    motion: Motion,
    method: Method = "nonlinear",
    rtol: float = 1e-8,
    t_max: float | None = None,
    initial_rotation: float = 0.0,
    initial_velocity: float = 0.0,
    max_steps: int = MAX_STEPS,
    l: float = 1e-4,
    t_eval=None,
    dt_out: float | None = None,
    friction: float | None = None,
    conditioning: bool = False,
    orientation: float | None = None,
) -> RockingResult:
    """Rock a structure through a ground motion.

    Parameters
    ----------
    structure : Block or structure with ``mechanism()`` and ``equivalent_block()``
        The rocking block (p, alpha, eta), or a structure of [003] (wall, arch, frame, ...).
        An :class:`~rockstudy.IsolatedBlock` runs its ``solve_ivp`` reference instead
        (:func:`~rockstudy.dynamics.isolated_reference.simulate_isolated`, which says what it
        takes) and returns an :class:`~rockstudy.dynamics.isolated_result.IsolatedResult`.
    motion : Motion
        Ground acceleration, e.g. :class:`rockstudy.motions.SinePulse` or a ``Record``. A
        record's vertical component u_v'' (upwards) acts as gravity g + u_v'' (Housner's
        equation with vertical shaking; eq. 8 of [003] with G (g + u_v'') for a mechanism) in
        every method but ``"complex"``, which refuses it; u_v'' <= -g anywhere (free fall)
        is refused with a ValueError before any integration.
    method : {"nonlinear", "linear", "scipy", "scipy-linear", "mechanism", "complex", "auto"}
        One of :data:`rockstudy.dynamics.methods.METHODS`, which says what each can run; a
        combination it cannot (a vertical component under ``"complex"``, a Block under
        ``"mechanism"``, ``friction`` where no demand is computed) is refused with a
        ValueError, the message :func:`rockstudy.simulate_batch` gives too.
        ``"nonlinear"``: Housner's eq. (2.2) of [000] by an event-driven kernel: Taylor-series
        steps under trigonometric pulses, inside records and in free rocking, DOP853 steps
        under a Ricker wavelet and for mechanisms (``info["steps"]`` counts both;
        ``info["dop853_steps"]`` is its former name, kept).
        ``"linear"``: the linearized eq. (3.1) of [000]; exact piecewise solution for
        trigonometric pulses and for records (closed form on each sample segment, nothing
        integrated: ``info["steps"]`` = 0), the same kernel otherwise (a record with a
        vertical component, a Ricker wavelet; ``info["solver"]`` says which ran).
        ``"scipy"`` / ``"scipy-linear"``: the slow ``solve_ivp`` reference of either model.
        ``"complex"``: the single-ODE formulation of [001] with angular momentum ``l``
        (Housner's model as l -> 0; steps below l / 10 make it slow).
        ``"auto"``: the cheapest method whose error bound meets ``rtol``: no integration
        where the ground never reaches g tan(alpha), otherwise the nonlinear kernel at
        0.05 ``rtol``, 5e-6 at most (tighter again for responses below 0.1 alpha, where
        chattering makes its error absolute). With a history to build the exact linear
        solver is not cheaper, so only :func:`rockstudy.simulate_batch` chooses it, and only
        under one-cycle pulses, where a tabulated bound covers its error; under records no
        such bound is known, and ``"auto"`` runs rest or the nonlinear kernel.
        ``result.info`` holds the model, the kernel's rtol and the scene's linearization
        bound.
        On a structure with a ``mechanism()``: ``"nonlinear"``, ``"mechanism"`` and
        ``"auto"`` integrate the mechanism, eq. (8) of [003], in its rotation phi (``"auto"``
        runs the equivalent block instead where it is exact: the Table I structures,
        :data:`EXACT_EQUIVALENTS`, with phi = theta). The other methods run its kappa_1
        equivalent block, in the block's theta = phi / kappa_1, and say so in
        ``result.info`` (``structure_model``, ``coordinate``) and in an
        :class:`~rockstudy.EquivalentBlockWarning` (none for the exact Table I blocks).
    rtol : float
        Relative tolerance, in [1e-12, 1) (below 1e-12 the kernels' error target drowns in
        rounding); absolute tolerances scale with alpha and p*alpha.
        For ``"auto"``: the relative accuracy of ``max_rotation``, with the overturning
        decision of Housner's model (or of the mechanism); ``impact_times``,
        ``overturn_time`` and the history are the kernel's at that rtol, which ``rtol``
        does not bound.
    t_max : float, optional
        End of the history [s]. By default the free rocking after the motion is followed until
        the block comes to rest or overturns.
    initial_rotation, initial_velocity : float
        theta [rad] and theta_dot [rad/s] at t = 0; |theta| < pi/2. Both zero (default): the
        block starts at rest. Use with :class:`rockstudy.motions.NoMotion` for free rocking.
    max_steps : int
        Safety cap on the integrator steps in one rocking phase, a whole number in [1, 1e12];
        default :data:`rockstudy.dynamics.methods.MAX_STEPS`, as
        :func:`rockstudy.simulate_batch`. Reached: a
        :class:`~rockstudy.dynamics.methods.StepLimitError` (a ``RuntimeError``), where the
        batch marks the same scene with ``status`` 1. For the kernel methods (``"nonlinear"``,
        ``"linear"`` where it runs the kernel, ``"mechanism"``, ``"auto"``); ``"scipy"`` has
        no cap, and ``"complex"`` its own (50,000,000 steps over the whole motion).
    l : float
        The complex formulation's l (method ``"complex"`` only), in (0, 0.1).
    t_eval : array_like, optional
        Times [s] at which to return the state (dense output, ``result.t_eval``,
        ``theta_eval``, ``theta_dot_eval``): finite, >= 0, sorted, and within the simulated
        end (``t_max`` when given; a block with restitution 1 is followed for 100 / p after
        the motion). Each state is as accurate as the steps: one DOP853 step from the start
        of the accepted step that contains the time (kernel methods), the closed form
        (``"linear"`` on a pulse or a record), scipy's dense output (``"scipy"``) or the
        cubic Hermite interpolant of the steps (``"complex"``). At rest (0, 0); at an
        impact, the state just before it; after an overturning NaN.
    dt_out : float, optional
        Instead of ``t_eval``: the uniform grid 0, dt_out, 2 dt_out, ... [s] up to ``t_max``
        or, without it, up to the end of the history (rest or overturning; the scene then
        runs twice, once to find that end).
    friction : float or (float, float), optional
        Runs the planar contact model instead of Housner's no-slip one
        (:mod:`rockstudy.dynamics.slide_rock`: rest, slide, rock, slide-rock and flight on a
        base with Coulomb friction): the coefficient mu, or (mu_s, mu_k) with
        mu_s >= mu_k, each in (0, 10] (:data:`MAX_FRICTION`, as in a study). Only for a
        :class:`~rockstudy.Block`, with ``method`` "nonlinear", "scipy" or "auto" (all run
        the model's ``solve_ivp`` reference at ``rtol``: milliseconds to seconds per
        scene), from rest, without ``t_eval``/``dt_out`` or ``conditioning``. The result
        adds ``slide``, ``max_slide``, ``residual_slide``, ``first_slip_time`` and
        ``regime_times``; its ``lift_off`` is the contact model's (the block flew), its
        ``friction_demand`` that of Housner's model on the scene (computed on first use).
        None (default): Housner's model, whose ``friction_demand`` and ``lift_off`` say
        where its no-slip, no-lift assumption fails.
    conditioning : bool
        Also run the scene with the amplitude (a pulse's, a record's samples) times 1 + 1e-9,
        by the same method, and give the relative change of ``max_rotation`` as
        ``result.conditioning`` (:mod:`rockstudy.dynamics.conditioning`): above 1e-3 the
        scene is ill-conditioned. Off by default: it doubles the cost.
    orientation : float, optional
        The angle psi [rad] of the structure's rocking plane, from the record's x component
        (``acceleration``) towards its y component (``acceleration_y``): the structure rocks
        under a_psi = a_x cos(psi) + a_y sin(psi) (:meth:`rockstudy.motions.Record.oriented`;
        psi + pi mirrors the motion, so the response). A motion of one horizontal component
        (a pulse, a record without ``acceleration_y``) takes psi = 0 and pi only (pi
        mirrors it); other angles are refused. None (default): the motion as given (a
        two-component record's x component); ``result.info["orientation"]`` says which.

    Returns
    -------
    RockingResult
        With the peaks (``peak_times``, ``peak_rotations``: every local maximum of |theta|)
        located by each method on its own solution: on the DOP853 step's interpolant and one
        Newton step on a true step (the kernels), on the closed form (``"linear"`` on a
        pulse or a record), by scipy's event location (``"scipy"``) or on the cubic Hermite
        interpolant of the steps (``"complex"``). For a :class:`~rockstudy.Block` (all
        methods but ``"complex"``), ``friction_demand`` and ``lift_off``
        (:func:`rockstudy.dynamics.contact.check_contact`).
    """
    if not isinstance(motion, Motion):
        raise TypeError(f"motion must be a rockstudy Motion, got {type(motion).__name__}")
    if orientation is not None:
        motion = motion.oriented(orientation)
    if isinstance(structure, IsolatedBlock):  # the solve_ivp reference, its own result
        args = (rtol, t_max, initial_rotation, initial_velocity, t_eval, dt_out, friction)
        return simulate_isolated(structure, motion, method, *args, conditioning)
    if isinstance(structure, StackedBlocks):  # its solve_ivp reference (no kernel yet)
        options = dict(initial_rotation=initial_rotation, initial_velocity=initial_velocity)
        options.update(t_eval=t_eval, dt_out=dt_out, friction=friction, conditioning=conditioning)
        return simulate_stacked_blocks(structure, motion, method, rtol, t_max, **options)
    kind, mp, _, _, vsamples = motion.kernel_spec()
    refuse_free_fall(vsamples, mp[0])
    method_for(
        method,
        structure="mechanism" if hasattr(structure, "mechanism") else "block",
        record=kind == mk.KIND_RECORD,
        vertical=bool(vsamples.size),
        friction_demand=friction is not None,
    )
    rtol = _validate.rtol(rtol)
    max_steps = _validate.max_steps(max_steps)
    if t_max is not None:
        t_max = _validate.positive("t_max", t_max)
    th0, om0 = _validate.initial_state(initial_rotation, initial_velocity)
    if method in ("nonlinear", "mechanism"):
        _auto.warn_loose_tolerance(rtol)
    x0 = (th0, om0)
    t_eval = _validate.output_times(t_eval, dt_out, t_max)
    block = not hasattr(structure, "mechanism") and method_for(method).friction_demand
    if friction is not None:
        friction = contact_model.friction_pair(friction, MAX_FRICTION)
        if not block:
            name = type(structure).__name__
            raise ValueError(
                "friction: the contact model runs a Block, not "
                f"{'an' if name[0] in 'AEIOU' else 'a'} {name}"
            )
        contact_model.refuse_options(method, x0, t_eval, conditioning)
        return _simulate_contact(structure, motion, friction, method, rtol, t_max)
    run_args = (motion, method, rtol, t_max, int(max_steps), x0, l)
    if hasattr(structure, "mechanism"):
        run, run_args = _simulate_structure, (structure, *run_args)
    else:
        run, run_args = _simulate_block, (*block_parameters(structure), *run_args)
    if dt_out is not None and t_max is None:  # the grid runs to the end of the response
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t_eval = _validate.uniform_times(float(dt_out), float(run(*run_args).t[-1]))
    r = run(*run_args, t_eval=t_eval)
    if conditioning:
        other = run(*_with_motion(run_args, run is _simulate_structure, perturbed(motion)))
        change = peak_change(r.max_rotation, r.overturned, other.max_rotation, other.overturned)
        object.__setattr__(r, "conditioning", float(change))
    object.__setattr__(r, "_motion", motion)  # a fresh result: for plot(), at no cost
    object.__setattr__(r, "_structure", structure)
    r.info.update(
        motion=describe(motion),
        rtol_requested=rtol,
        initial_rotation=th0,
        initial_velocity=om0,
        orientation=0.0 if orientation is None else float(orientation),
    )
    return contact.with_contact(r, motion, method) if block else r


def _simulate_contact(block, motion, friction, method, rtol, t_max):
    """The contact model of ``block`` (:mod:`.contact_model`); its ``friction_demand`` from
    Housner's model run on first use by the same ``simulate``."""
    p, alpha, eta = block_parameters(block)

    def rocking():
        return simulate(block, motion, rtol=rtol, t_max=t_max)

    r = contact_model.simulate_contact(
        p, alpha, eta, motion, friction, method, rtol, t_max, rocking
    )
    object.__setattr__(r, "_motion", motion)
    object.__setattr__(r, "_structure", block)
    r.info.update(motion=describe(motion), rtol_requested=rtol)
    return r


def _with_motion(run_args, structure_first, motion):
    """The arguments of a run (:func:`_simulate_structure`'s if ``structure_first``, else
    :func:`_simulate_block`'s) with another motion."""
    i = 1 if structure_first else 3
    return (*run_args[:i], motion, *run_args[i + 1 :])


def _simulate_block(p, alpha, eta, motion, method, rtol, t_max, max_steps, x0, l, t_eval=None):
    """A block (p, alpha, eta) through ``method``."""
    runner, model = _RUNNERS[method]
    if method in ("linear", "scipy-linear"):
        _warn_linearization(p, alpha, eta, motion, x0)
    args = (p, alpha, eta, motion, model, rtol, t_max, max_steps, method, x0)
    if method == "complex":
        r = _complex(*args, l, t_eval=t_eval)
    else:
        r = runner(*args, t_eval=t_eval)
    _record_parameters(r, p, alpha, eta)
    return r


def _record_parameters(r, p, alpha, eta):
    """The rocking parameters of what ran, in ``r.info``: p [rad/s], the critical rotation
    [rad] of ``theta`` (alpha for a block) and the restitution."""
    r.info.update(
        frequency_parameter=float(p), critical_rotation=float(alpha), restitution=float(eta)
    )


def _simulate_structure(structure, motion, method, rtol, t_max, max_steps, x0, l, t_eval=None):
    """A structure with a ``mechanism()``: the mechanism, eq. (8) of [003], for "nonlinear",
    "mechanism" and "auto" (the exact equivalent block for the Table I structures under
    "auto"); the kappa_1 equivalent block for the other methods, said in ``result.info`` and
    in an :class:`EquivalentBlockWarning` unless the block is exact."""
    exact = isinstance(structure, EXACT_EQUIVALENTS)
    if method in ("nonlinear", "mechanism"):
        return _mechanism(structure, motion, rtol, t_max, max_steps, x0, method, t_eval)
    if method == "auto" and not exact:
        params = _structure_parameters(structure)
        r, k_rtol = _auto_kernel(
            lambda k: _mechanism(structure, motion, k, t_max, max_steps, x0, method, t_eval),
            rtol,
            params.critical_rotation,
        )
        r.info.update(model="mechanism", rtol=k_rtol)
        return r
    eq = structure.equivalent_block()
    p, alpha, eta = block_parameters(eq)
    name = type(structure).__name__
    if exact:
        model = f"exact equivalent block of the {name} (Table I of [003])"
        coordinate = "phi (= theta of the exact equivalent block: kappa_1 = 1)"
    else:
        model = f"equivalent block of the {name}, kappa_1 = {eq.scale:.6g} (eq. 14-17 of [003])"
        coordinate = f"theta of the equivalent block (phi = kappa_1 theta = {eq.scale:.6g} theta)"
        warnings.warn(
            f"method={method!r} runs the {model}, not the mechanism: "
            f"max_rotation, theta and initial_rotation are the {coordinate}, and the block "
            "only approximates the mechanism; use method='nonlinear' or 'auto' for the "
            "mechanism, eq. (8) of [003]",
            EquivalentBlockWarning,
            stacklevel=3,
        )
    r = _simulate_block(p, alpha, eta, motion, method, rtol, t_max, max_steps, x0, l, t_eval)
    r.info.update(structure_model=model, coordinate=coordinate)
    return r


def _structure_parameters(structure):
    """One direction's rocking parameters (the positive one of an asymmetric structure)."""
    from ._structure_tables import structure_parameters

    params = structure_parameters(structure)
    return params[0] if isinstance(params, tuple) else params


def _mechanism(structure, motion, rtol, t_max, max_steps, x0, method="mechanism", t_eval=None):
    """The full mechanism, eq. (8) of [003], through the tabulated kernel. An overturned
    structure reports max_rotation = pi/2, as a block does (its history ends at
    ``info["fall_rotation"]``, where the mechanism collapses or its kinematics end)."""
    from ._structure_tables import structure_table

    params = _structure_parameters(structure)
    if not params.restitution > 0:
        raise ValueError(f"{type(structure).__name__} needs a restitution (in (0, 1]) to rock")
    tab, fall = structure_table(structure)
    result = _kernel(
        params.frequency_parameter,
        params.critical_rotation,
        params.restitution,
        motion,
        _rocking.MODEL_TABLE,
        rtol,
        t_max,
        max_steps,
        method,
        x0,
        fall,
        tab,
        t_eval,
    )
    if result.overturned:
        result = dataclasses.replace(result, max_rotation=FALL_ROTATION)
    _record_parameters(
        result, params.frequency_parameter, params.critical_rotation, params.restitution
    )
    result.info.update(
        fall_rotation=fall,
        structure_model=f"mechanism of the {type(structure).__name__} (eq. 8 of [003])",
        coordinate="phi (the mechanism's rotation)",
    )
    return result
