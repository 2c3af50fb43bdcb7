"""The batch entry point: many (block, motion) rows in one parallel numba call.

Studies call :func:`simulate_batch`; it returns only the response metrics, and follows the
free rocking after the motion with the closed-form map rather than by integration.
"""

from __future__ import annotations

from typing import Literal

import numba
import numpy as np

from .. import _validate
from ..constants import G
from ..motions import Record
from ..motions import _kernels as mk
from ..motions.pulses import MAX_CYCLES, PERIOD_RANGE, PULSES, pulse_kernel_rows
from ..structures.block import FREQUENCY_PARAMETER_RANGE, HALF_DIAGONAL_RANGE, MIN_SLENDERNESS
from . import _auto, _linear, _linear_record, _rocking, conditioning, contact_model, outputs
from ._batch_io import (
    CONDITIONING_OUTPUTS,
    CONTACT_OUTPUTS,
    OUTPUTS,
    SLIDE_OUTPUTS,
    batch_dataset,
    requested_outputs,
)
from ._oriented import with_orientation
from ._vertical import refuse_free_fall, uplift_ratio
from .methods import MAX_STEPS, STATUS_STEP_LIMIT, method_for
from .simulate import MAX_FRICTION
from .two_body_batch import two_body_batch

__all__ = ["CONDITIONING_OUTPUTS", "CONTACT_OUTPUTS", "OUTPUTS", "PulseName", "simulate_batch"]

PulseName = Literal["sine", "cosine", "half-sine", "ricker"]
#: The models :func:`simulate_batch` runs a scene under (its ``model``): Housner's no-slip
#: block, the planar contact model, or Housner's with the contact model where it fails.
CONTACT_CHOICES = ("rocking", "contact", "auto")
#: The ``model`` output of a row the contact model answered (0-2: :mod:`._auto`): by its
#: kernels, or by its ``solve_ivp`` reference where the kernel reached its step limit.
MODEL_CONTACT, MODEL_CONTACT_REFERENCE = 3, 4
#: batch method -> kernel model (None: chosen row by row); what each method can run is in
#: :data:`rockstudy.dynamics.methods.METHODS`
_MODELS = {"nonlinear": _rocking.MODEL_NONLINEAR, "linear": _rocking.MODEL_LINEAR, "auto": None}
_CODES = {
    _rocking.MODEL_NONLINEAR: _auto.MODEL_NONLINEAR,
    _rocking.MODEL_LINEAR: _auto.MODEL_LINEAR,
}

# (trig-only, one thread) -> batch kernel: on one thread (a study's workers) the serial
# variants, which compile without the parallel loop's cost
_BATCH_KERNELS = {
    (False, False): _rocking.scene_batch,
    (True, False): _rocking.scene_batch_trig,
    (False, True): _rocking.scene_batch_serial,
    (True, True): _rocking.scene_batch_trig_serial,
}


def _column(name, values, n, low=None, high=None, low_open=True, high_open=True):
    arr = np.broadcast_to(np.asarray(_numbers(name, values), dtype=float), (n,))
    bad = ~np.isfinite(arr)
    if low is not None:
        bad |= arr <= low if low_open else arr < low
    if high is not None:
        bad |= arr >= high if high_open else arr > high
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        lo = "-inf" if low is None else ("(" if low_open else "[") + f"{low:g}"
        hi = "inf" if high is None else f"{high:g}" + (")" if high_open else "]")
        raise ValueError(f"{name}[{i}] = {float(arr[i])!r} is outside the allowed range {lo}, {hi}")
    return np.ascontiguousarray(arr)


def _common_length(**columns) -> int:
    """The length n that the scalar and 1-D arguments broadcast to; a ValueError naming the
    argument for anything of more dimensions or of another length."""
    lengths = {}
    for name, x in columns.items():
        if x is None:
            continue
        shape = np.shape(x)
        if len(shape) > 1:
            raise ValueError(f"{name} must be a scalar or a 1-D array, got shape {shape}")
        if shape == (0,):
            raise ValueError(f"{name} is empty: give a scalar or a non-empty 1-D array")
        if shape and shape[0] != 1:
            lengths[name] = shape[0]
    if len(set(lengths.values())) > 1:
        raise ValueError(
            "the 1-D arguments must have one common length (or length 1), got "
            + ", ".join(f"{k}: {v}" for k, v in lengths.items())
        )
    return max(max(lengths.values(), default=1), 1)


def _numbers(name, values):
    """``values`` as an array of numbers, or a :class:`rockstudy._validate.NotANumberError`
    (a TypeError and a ValueError) naming ``name`` (strings, booleans and objects are not
    numbers)."""
    arr = np.asarray(values)
    if arr.dtype.kind not in "iuf":
        raise _validate.NotANumberError(
            f"{name} must be a number or an array of numbers, got {values!r:.60}"
        )
    return arr


def _pulse_params(pulse, amplitude, period, cycles, n):
    if pulse not in PULSES:
        raise ValueError(f"pulse must be one of {sorted(PULSES)}, got {pulse!r}")
    if amplitude is None or period is None:
        raise ValueError("a pulse needs amplitude [m/s^2] and period [s] (or give record=)")
    top = _validate.MAX_ACCELERATION
    amp = _column("amplitude", amplitude, n, -top, top, False, False)
    if np.any(amp == 0.0):
        raise ValueError(f"amplitude[{int(np.flatnonzero(amp == 0)[0])}] must be non-zero")
    per = _column("period", period, n, *PERIOD_RANGE, False, False)
    cyc = _column("cycles", cycles, n, 1, MAX_CYCLES, False, False)
    if np.any(cyc != np.round(cyc)):
        raise ValueError("cycles must be whole numbers >= 1")
    return pulse_kernel_rows(pulse, amp, per, cyc)


def _record_params(record, scale, amplitude, period, cycles, n):
    """The kernel rows of ``record`` scaled row by row by ``scale``; the pulse's arguments
    are refused beside it, and so is a scaled peak beyond MAX_ACCELERATION."""
    if not isinstance(record, Record):
        raise TypeError(f"record must be a rockstudy Record, got {type(record).__name__}")
    given = [k for k, v in (("amplitude", amplitude), ("period", period)) if v is not None]
    if given or not np.all(np.asarray(cycles) == 1):
        raise ValueError(
            f"record= takes no {', '.join(given) or 'cycles'}: those describe a pulse; scale "
            "the record with scale="
        )
    vpeak = 0.0 if record.vertical is None else float(np.max(np.abs(record.vertical)))
    top = _validate.MAX_ACCELERATION / max(record.peak, vpeak, 1e-300)
    kind, p1, times, samples, vsamples = record.kernel_spec()
    mp = np.tile(p1, (n, 1))
    mp[:, 0] = _column("scale", scale, n, -top, top, False, False)
    return kind, mp, times, samples, vsamples


def _critical_rotation(critical_rotation, slenderness):
    """(name, values) of the critical rotation given to :func:`simulate_batch` under its
    name or its block alias ``slenderness``; a ValueError for both or neither."""
    if (critical_rotation is None) == (slenderness is None):
        raise ValueError(
            "give critical_rotation [rad] (or its alias for a block, slenderness), exactly once"
        )
    if critical_rotation is None:
        return "slenderness", slenderness
    return "critical_rotation", critical_rotation


def _blocks(half_diagonal, frequency_parameter, critical_rotation, restitution, n):
    """The block columns of :func:`simulate_batch`, checked, of length n: (R or None, p,
    alpha, eta), p from R by eq. (2.2) of [000] and eta by default Housner's eq. (2.4).
    ``critical_rotation`` is (the name it was given under, the values)."""
    name, values = critical_rotation
    alpha = _column(name, values, n, MIN_SLENDERNESS, np.pi / 2, False)
    R = None
    if half_diagonal is not None:
        R = _column("half_diagonal", half_diagonal, n, *HALF_DIAGONAL_RANGE, False, False)
        p = np.sqrt(3.0 * G / (4.0 * R))  # eq. (2.2) of [000], as block.frequency_parameter
    else:
        p_range = FREQUENCY_PARAMETER_RANGE
        p = _column("frequency_parameter", frequency_parameter, n, *p_range, False, False)
    if restitution is None:
        eta = 1.0 - 1.5 * np.sin(alpha) ** 2  # eq. (2.4), as block.restitution_housner
    else:
        eta = _column("restitution", restitution, n, 0.0, 1.0, high_open=False)
    return R, p, alpha, eta


def _motions(pulse, record, scale, amplitude, period, cycles, n):
    """The motion rows of :func:`simulate_batch`: (kind, mp, times, samples, vsamples) of the
    scaled record (free fall refused) or of the pulses."""
    if record is not None:
        kind, mp, times, samples, vsamples = _record_params(
            record, scale, amplitude, period, cycles, n
        )
        refuse_free_fall(vsamples, mp[:, 0], batch=True)
        return kind, mp, times, samples, vsamples
    kind, mp = _pulse_params(pulse, amplitude, period, cycles, n)
    return kind, mp, np.zeros(2), np.zeros(2), mk.NO_VERTICAL


def _motion_inputs(record, mp, amplitude, period, cycles, n):
    """The motion inputs of a batch's dataset: the record's scale, or the pulses' amplitude,
    period and cycles, each of length n."""
    if record is not None:
        return {"scale": mp[:, 0]}
    values = (("amplitude", amplitude), ("period", period), ("cycles", cycles))
    return {name: np.broadcast_to(np.asarray(value), (n,)) for name, value in values}


@with_orientation(_common_length, _column)  # the orientation column: rows grouped by angle
def simulate_batch(
    *,
    half_diagonal=None,
    frequency_parameter=None,
    critical_rotation=None,
    slenderness=None,
    restitution=None,
    pulse: PulseName = "sine",
    amplitude=None,
    period=None,
    cycles=1,
    record: Record | None = None,
    scale=1.0,
    method: Literal["nonlinear", "linear", "auto"] = "nonlinear",
    rtol: float = 1e-8,
    max_steps: int = MAX_STEPS,
    outputs=None,
    as_dataset: bool = False,
    friction=None,
    model: Literal["rocking", "contact", "auto"] = "rocking",
    structure=None,
):
    """Rock many blocks through many pulses (or scaled copies of one record) in one call.

    Every argument broadcasts to a common length n. The rows run in parallel (numba
    ``prange``); each row costs microseconds to a millisecond.

    Parameters
    ----------
    half_diagonal : array_like, optional
        R [m] > 0; or give ``frequency_parameter`` p [rad/s] directly (equivalent blocks).
    critical_rotation : array_like
        theta_cr [rad] in (0, pi/2): a block's slenderness alpha, or the critical rotation of
        an equivalent block (with ``frequency_parameter``).
    slenderness : array_like
        The block's name of ``critical_rotation`` (an alias, kept for blocks): give one of
        the two, not both.
    restitution : array_like, optional
        eta in (0, 1]; default Housner's (2.4) of [000].
    pulse : {"sine", "cosine", "half-sine", "ricker"}
        Pulse shape, with ``amplitude`` a_g [m/s^2] (non-zero) and ``period`` T_p [s] > 0.
    cycles : int or array_like
        Number of cycles of sine and cosine pulses.
    record : Record, optional
        Use this record instead of a pulse, multiplied row by row by ``scale`` (its vertical
        component, if any, by ``|scale|``; it acts as gravity g + u_v'', and a row where
        that reaches 0, free fall, is refused with a ValueError before any integration).
    method : {"nonlinear", "linear", "auto"}
        The methods of :data:`rockstudy.dynamics.methods.METHODS` that run in a batch (the
        others are refused with the message :func:`rockstudy.simulate` gives for what they
        cannot run). Housner's eq. (2.2) or the linearized eq. (3.1) of [000]. The linear
        model under trigonometric pulses and under records uses the exact piecewise solution
        (under a record with a vertical component, whose time-varying gravity it cannot
        take, the DOP853 kernel of the linear model: ``steps`` > 0 says so). ``"auto"``
        chooses row by row the cheapest model whose error bound meets ``rtol``: rest where the
        ground never reaches g tan(alpha) (exact), the exact linear solver where its tabulated
        linearization error (one-cycle trigonometric pulses) is below ``rtol`` and only
        ``max_rotation`` and ``overturned`` are asked for (see ``outputs``), and the
        nonlinear kernel at 0.05 ``rtol`` (5e-6 at most, for the overturning decisions)
        otherwise. Under a record ``"auto"`` never runs the linear model: no bound on its
        error is known there (the table is measured on one-cycle pulses; under a record the
        error depends on the whole history, and the two models part for good once one of
        them crosses an overturning boundary or a rest that the other does not).
    rtol : float
        Relative tolerance of the integrator, in [1e-12, 1). For ``"auto"``: the relative
        accuracy of ``max_rotation``, with the overturning decision of Housner's model;
        ``rtol`` covers no other output (``overturn_time`` and ``first_impact_time`` are the
        kernel's at that rtol, ``n_impacts`` the kernel's count until its rest rule).
    outputs : sequence of str, optional
        The outputs to return (names of :data:`OUTPUTS`; ``status`` always comes along).
        Default: all of them. With ``"auto"``, asking only for ``max_rotation`` and
        ``overturned`` (and ``steps``, ``model``) lets the rows whose bound allows it run the
        cheaper linear model; asking for any other output runs the kernel on every row that
        lifts, so that no returned value lies outside what ``auto`` promises. Also, never by
        default: ``friction_demand`` and ``lift_off`` (as
        :attr:`rockstudy.RockingResult.friction_demand`), computed by the kernel on its
        Taylor steps (a linearized or Ricker row that lifts is run again with a history, 1-40
        ms: :mod:`._batch_contact`); a row that never lifts: ``max |u_h''| / (g + u_v'')``.
        Also never by default: ``conditioning``, the relative change
        of ``max_rotation`` when the amplitude (a pulse's, a record's ``scale``) grows by
        1e-9 (:func:`rockstudy.dynamics.conditioning.peak_change`: inf where the overturning
        decision changes, NaN where a run reached the step limit), for which every row is run
        again (twice the cost); above 1e-3 the scene is ill-conditioned, and no solver's
        ``max_rotation`` is determined better than that (docs/methods.rst).
    max_steps : int
        Cap on the integrator steps in one rocking phase of a row, a whole number in
        [1, 1e12]; default :data:`rockstudy.dynamics.methods.MAX_STEPS`, as
        :func:`rockstudy.simulate`. A row that reaches it has ``status`` 1 (the other rows
        run on), where :func:`rockstudy.simulate` raises a
        :class:`~rockstudy.dynamics.methods.StepLimitError` on the same scene.

    as_dataset : bool
        Return an :class:`xarray.Dataset` on a ``scene`` dimension instead: the inputs
        (``frequency_parameter`` p [rad/s], ``critical_rotation`` or ``slenderness`` under
        the name it was given, ``restitution``, and ``amplitude``, ``period``, ``cycles`` of
        the pulse or the record's ``scale``; with ``half_diagonal`` if given; with
        ``friction``, ``friction_static`` and ``friction_kinetic``) as coordinates with units,
        the outputs as variables.
    friction : float, array_like or tuple, optional
        The friction coefficient of the base, in (0, 10] (:data:`.simulate.MAX_FRICTION`):
        mu (a scalar or one per row: mu_s = mu_k), or a tuple (mu_s, mu_k) (each a scalar or
        one per row) with mu_s >= mu_k, as :func:`rockstudy.simulate`'s ``friction``.
    model : {"rocking", "contact", "auto"}
        The model of every scene. ``"rocking"`` (default): Housner's no-slip model, as
        without ``friction``; with ``friction``, ``friction_demand`` and ``lift_off`` (the
        friction check) are returned by default too. ``"contact"`` (needs ``friction``): the
        planar contact model (:func:`rockstudy.dynamics.contact_model.contact_outputs`: the
        exact sliding kernel where the block cannot rock, mu_s < tan(alpha) under a record,
        else the ``solve_ivp`` reference at ``rtol``; milliseconds to seconds a row, one row
        at a time) on every row; ``method`` "linear" is refused. ``"auto"`` (needs
        ``friction``): Housner's model with the friction check on every row, then the
        contact model on the rows whose friction demand exceeded mu_s, that lifted off or
        that overturned (the fall unloads the base: it ends in slip or flight); the other
        rows keep Housner's answer, which the contact model would give too (no slip, no
        flight). The output ``model`` says which answered each row (3: the contact
        model). With ``"contact"`` or ``"auto"`` the outputs also hold (by default)
        ``max_slide`` [m], ``residual_slide`` [m], ``first_slip_time`` [s], ``time_slide``,
        ``time_slide_rock``, ``time_flight`` [s] and ``regime`` (the most involved regime
        entered: 0 rest, 1 slide, 2 rock, 3 slide-rock, 4 flight), as
        :func:`rockstudy.simulate` with ``friction`` names them; ``lift_off`` is the contact
        model's (the block flew) on its rows. Rows the contact model answered have
        ``steps`` -1 and ``peak_time`` NaN (it counts no steps and times no peak), and
        ``status`` 1 where its reference stopped at its cap of phases. Rows Housner's model
        answered have no slip (0; NaN, with ``first_slip_time``, where the block overturned:
        the fall's slip lies outside that model) and ``regime`` 0 or 2. ``conditioning`` is
        refused with these models. Under ``"auto"``, ``outputs`` may also name
        ``overturned_rocking`` and ``status_rocking``: Housner's decision and its kernel's
        status on every row, the rocking-only answer that "auto" computes first.
    orientation : float or array_like, optional
        The angle psi [rad] of each row's rocking plane, as :func:`rockstudy.simulate`'s (rows
        grouped by angle, a batch each; a dataset gains the ``orientation`` coordinate).
    structure : StackedBlocks or IsolatedBlock, or a sequence of one of them, optional
        A two-body system (one, or one per row) instead of the block columns (refused beside
        it): its outputs are those :func:`rockstudy.simulate` names for it
        (:mod:`.two_body_batch`), and on request ``conditioning``
        (:data:`.two_body_batch.CONDITIONING`: the rows run twice).

    Returns
    -------
    dict of ndarrays (or xarray.Dataset with ``as_dataset``)
        ``max_rotation`` [rad] (pi/2 if overturned), ``overturned`` (bool), ``n_impacts``
        (until rest; with restitution 1 the block never rests, and the impacts are counted up
        to duration + 100/p, the end of :func:`rockstudy.simulate`'s default history),
        ``overturn_time`` [s] (NaN if it survived), ``first_impact_time`` [s] (NaN if none),
        ``peak_time`` [s] (when |theta| reached ``max_rotation``, after the motion too; the
        overturning time if overturned, NaN if it never lifted),
        ``status`` (0 ok, 1 step limit reached), ``steps`` (integrator steps taken: DOP853,
        or Taylor steps inside a record; 0 for the exact solver), ``model`` (0 rest without
        integration, 1 linear, 2 nonlinear, 3 the contact model's kernels, 4 its ``solve_ivp``
        reference where its kernel reached the step limit: what each row ran); only those of
        ``outputs`` (and ``status``) if given.
    """
    if structure is not None:  # a two-body system: its own rows, from these arguments
        return two_body_batch(dict(locals()))
    _check_model(model, friction, method)
    wanted = requested_outputs(outputs, model, friction is not None)
    method_for(
        method,
        batch=True,
        record=record is not None,
        vertical=getattr(record, "vertical", None) is not None,
        friction_demand=bool(set(CONTACT_OUTPUTS) & set(wanted)) or model != "rocking",
    )
    kernel_model = _MODELS[method]
    theta_cr = _critical_rotation(critical_rotation, slenderness)
    rtol, max_steps = _controls(method, rtol, max_steps, half_diagonal, frequency_parameter)
    n = _common_length(
        half_diagonal=half_diagonal,
        frequency_parameter=frequency_parameter,
        **{theta_cr[0]: theta_cr[1]},
        restitution=restitution,
        amplitude=amplitude,
        period=period,
        scale=scale,
        cycles=cycles,
        **_friction_arguments(friction),
    )
    mu = None if friction is None else _friction_columns(friction, n)
    R, p, alpha, eta = _blocks(half_diagonal, frequency_parameter, theta_cr, restitution, n)
    motion_rows = _motions(pulse, record, scale, amplitude, period, cycles, n)
    kind, mp, times, samples, vsamples = motion_rows
    p, eta = (np.ascontiguousarray(x, dtype=float) for x in (p, eta))
    rows = (p, alpha, eta, kind, mp, times, samples, vsamples)
    linear_ok = set(wanted) <= set(_auto.COVERED_OUTPUTS + _auto.BOOKKEEPING_OUTPUTS)

    check = _needs_check(wanted, model)

    def solve(rows, demand=False):
        if kernel_model is not None:
            return _run(rows, np.arange(n), kernel_model, rtol, max_steps, demand), np.full(
                n, _CODES[kernel_model], np.int8
            )
        motion = (pulse if record is None else None, cycles)
        return _auto_rows(rows, motion, rtol, max_steps, linear_ok, demand)

    out, codes = _unsolved(n) if _contact_only(wanted, model) else solve(rows, check)
    cols = _columns(out, codes, housner=model == "auto")
    if "conditioning" in wanted:
        cols["conditioning"] = _conditioning(out, solve(_perturbed_rows(rows))[0])
    if check:
        _add_contact_outputs(cols, rows, codes, method, rtol, max_steps)
    if model != "rocking":
        motions = contact_model.RowMotions(pulse, record, mp, amplitude, period, cycles, n)
        _add_contact_model(cols, rows, mu, model, motions, rtol)
    result = {name: cols[name] for name in wanted}
    if not as_dataset:
        return result
    inputs = {"frequency_parameter": p, theta_cr[0]: alpha, "restitution": eta}
    inputs.update({} if half_diagonal is None else {"half_diagonal": R})
    inputs.update({} if mu is None else {"friction_static": mu[0], "friction_kinetic": mu[1]})
    inputs.update(_motion_inputs(record, mp, amplitude, period, cycles, n))
    source = "record" if record is not None else f"{pulse} pulse"
    return batch_dataset(result, inputs, method, rtol, source)


def _contact_only(wanted, model) -> bool:
    """Whether the contact model answers every row and nothing asked for needs Housner's
    model (``model="contact"`` without ``friction_demand``): it is then not run."""
    return model == "contact" and not _needs_check(wanted, model)


def _unsolved(n):
    """(kernel rows, model codes) of n rows Housner's model did not run: the rows of scenes
    at rest (:func:`.outputs.rows_at_rest`), code 0, for the contact model to write over."""
    return outputs.rows_at_rest(n), np.zeros(n, np.int8)


def _controls(method, rtol, max_steps, half_diagonal, frequency_parameter):
    """(rtol, max_steps) checked, with the loose-tolerance warning of the nonlinear kernel;
    a ValueError unless exactly one of half_diagonal and frequency_parameter is given."""
    rtol = _validate.rtol(rtol)
    max_steps = _validate.max_steps(max_steps)
    if method == "nonlinear":
        _auto.warn_loose_tolerance(rtol)
    if (half_diagonal is None) == (frequency_parameter is None):
        raise ValueError("give exactly one of half_diagonal or frequency_parameter")
    return rtol, max_steps


def _columns(out, codes, housner=False) -> dict:
    """The kernels' rows ``out`` (:data:`.outputs.KERNEL_ROW`) and the model ``codes`` as
    output arrays (copies: the contact model's pass overwrites rows); with ``housner`` (under
    ``model="auto"``) also Housner's answer as ``overturned_rocking`` and ``status_rocking``,
    kept before the friction check and the contact model write over its rows."""
    cols = {name: np.array(out[name]) for name in out.dtype.names}
    cols["model"] = codes.copy()
    if housner:
        cols["overturned_rocking"] = cols["overturned"].astype(bool)
        cols["status_rocking"] = cols["status"].copy()
    return cols


def _add_contact_outputs(cols, rows, codes, method, rtol, max_steps):
    """Add the friction demand and lift-off of each scene to ``cols`` (a scene whose contact
    pass reached the step limit gets that status)."""
    from ._batch_contact import contact_rows

    demand, lift_off, limited = contact_rows(rows, codes, method, rtol, max_steps, cols)
    cols["status"] = np.where(limited, STATUS_STEP_LIMIT, cols["status"])
    cols.update(zip(CONTACT_OUTPUTS, (demand, lift_off), strict=True))


def _needs_check(wanted, model) -> bool:
    """Whether the friction check of Housner's model (:func:`_add_contact_outputs`) runs:
    ``"auto"`` decides by it; under ``"contact"`` only ``friction_demand`` needs it (the
    contact model gives its own ``lift_off``)."""
    asked = set(CONTACT_OUTPUTS) & set(wanted)
    return model == "auto" or "friction_demand" in asked or (model == "rocking" and bool(asked))


def _check_model(model, friction, method):
    """A ValueError naming ``model`` for a value outside :data:`CONTACT_CHOICES`, the contact
    model without ``friction``, or ``"contact"`` with the linear method."""
    if model not in CONTACT_CHOICES:
        raise ValueError(f"model must be one of {list(CONTACT_CHOICES)}, got {model!r}")
    if model != "rocking" and friction is None:
        raise ValueError(
            f"model={model!r} runs the contact model, which needs friction= (mu, or "
            "(mu_s, mu_k)); give it, or model='rocking'"
        )
    if model == "contact" and method == "linear":
        raise ValueError(
            "model='contact' runs the contact model on every row (a nonlinear model): "
            "method='linear' does not apply; give method='nonlinear' or 'auto'"
        )


def _friction_arguments(friction) -> dict:
    """The friction columns of :func:`simulate_batch` by name, for the common length."""
    if friction is None:
        return {}
    if isinstance(friction, tuple):
        if len(friction) != 2:
            raise ValueError(f"friction: a tuple is (mu_s, mu_k), got {len(friction)} values")
        return {"friction[0]": friction[0], "friction[1]": friction[1]}
    return {"friction": friction}


def _friction_columns(friction, n) -> tuple:
    """(mu_s, mu_k), each of length n, from ``friction`` (:func:`simulate_batch`): in
    (0, MAX_FRICTION], mu_k <= mu_s; a ValueError naming the argument otherwise."""
    if not isinstance(friction, tuple):  # one coefficient: mu_k = mu_s
        static = _column("friction", friction, n, 0.0, MAX_FRICTION, high_open=False)
        return static, static.copy()
    static, kinetic = (
        _column(name, value, n, 0.0, MAX_FRICTION, high_open=False)
        for name, value in zip(("friction[0]", "friction[1]"), friction, strict=True)
    )
    if np.any(kinetic > static):
        i = int(np.flatnonzero(kinetic > static)[0])
        raise ValueError(
            f"friction: row {i}: the kinetic coefficient {float(kinetic[i])!r} exceeds the static "
            f"{float(static[i])!r} (give (mu_s, mu_k) with mu_s >= mu_k)"
        )
    return static, kinetic


def _add_contact_model(cols, rows, mu, model, motions, rtol):
    """Run the contact model on the rows of ``cols`` that ``model`` gives it (all of them, or
    under ``"auto"`` those of :func:`_beyond_housner`), all at once
    (:func:`.contact_model.contact_rows`), writing its outputs over Housner's there; the
    other rows get the slide outputs of a block that did not slip (:func:`_no_slip`). A row
    the kernel could not answer, which the ``solve_ivp`` reference did, has ``model``
    :data:`MODEL_CONTACT_REFERENCE`."""
    p, alpha, eta, kind, mp, times, samples, vsamples = rows
    n = p.size
    chosen = _beyond_housner(cols, mu[0]) if model == "auto" else np.ones(n, bool)
    cols.update(_no_slip(cols))
    idx = np.flatnonzero(chosen)
    if not idx.size:  # Housner's model answered every row
        return
    kernel = outputs.names("kernel")
    untimed = [name for name in kernel if "contact" not in outputs.OUTPUTS[name].models]
    for name in untimed:  # the kernel outputs the contact model leaves out
        cols[name][idx] = outputs.OUTPUTS[name].fill
    cols["model"][idx] = MODEL_CONTACT
    found, referred = contact_model.contact_rows(
        p[idx],
        alpha[idx],
        eta[idx],
        (mu[0][idx], mu[1][idx]),
        (kind, mp[idx], times, samples, vsamples),
        rtol,
        lambda j: motions[idx[j]],
    )
    for name, values in found.items():
        cols.setdefault(name, np.zeros(n, values.dtype))[idx] = values
    cols["model"][idx[referred]] = MODEL_CONTACT_REFERENCE


def _beyond_housner(cols, mu_s):
    """The rows whose answer ``"auto"`` takes from the contact model: a friction demand
    above ``mu_s``, a lift-off, or an overturning (the fall of an overturning block unloads
    the base, so it ends in slip or flight before it lies flat: the contact model times the
    slip and gives the slide that Housner's model cannot)."""
    over = cols["overturned"].astype(bool)
    return (cols["friction_demand"] > mu_s) | (cols["lift_off"] != 0) | over


def _no_slip(cols) -> dict:
    """The slide outputs (:data:`SLIDE_OUTPUTS`) of rows Housner's model answers: no slip
    and no flight, regime 0 (never lifted) or 2 (rocked); NaN where the block overturned
    (the fall unloads the base, whose slip lies outside that model) or the row failed."""
    lifted = (cols["max_rotation"] > 0.0) | (cols["n_impacts"] > 0)
    unknown = cols["overturned"].astype(bool) | (cols["status"] != 0)
    zero = np.where(unknown, np.nan, 0.0)
    out = {name: zero.copy() for name in SLIDE_OUTPUTS if name != "regime"}
    out["first_slip_time"] = np.full(zero.size, np.nan)
    out["regime"] = np.where(lifted, 2, 0).astype(np.int8)
    return out


def _perturbed_rows(rows):
    """``rows`` with every amplitude (a pulse's, a record's scale: column 0 of the kernel
    rows) times 1 + :data:`.conditioning.CONDITIONING_STEP`."""
    mp = rows[4].copy()
    mp[:, 0] *= 1.0 + conditioning.CONDITIONING_STEP
    return rows[:4] + (mp,) + rows[5:]


def _conditioning(out, out_perturbed):
    """The ``conditioning`` output (:func:`.conditioning.peak_change`) of the kernel outputs
    of the rows and of their perturbed copies; NaN where either run reached the step limit."""
    change = conditioning.peak_change(
        out["max_rotation"],
        out["overturned"],
        out_perturbed["max_rotation"],
        out_perturbed["overturned"],
    )
    ok = (out["status"] == 0) & (out_perturbed["status"] == 0)
    return np.where(ok, change, np.nan)


def _run(rows, idx, model, rtol, max_steps, demand=False):
    """The kernel rows (:data:`.outputs.KERNEL_ROW`) of the rows ``idx`` under one model, with
    the friction demand where the kernel computes it if ``demand`` (:mod:`._demand`). The
    exact linear record solver has constant coefficients: a record with a vertical component
    runs the kernel."""
    p, alpha, eta, kind, mp, times, samples, vsamples = rows
    args = (p[idx], alpha[idx], eta[idx])
    if model == _rocking.MODEL_LINEAR and kind == mk.KIND_TRIG:
        return _linear.trig_batch(*args, mp[idx])
    if model == _rocking.MODEL_LINEAR and kind == mk.KIND_RECORD and not vsamples.size:
        return _linear_record.record_batch(*args, mp[idx, 0], times, samples)
    trig = kind == mk.KIND_TRIG and model != _rocking.MODEL_TABLE and not vsamples.size
    kernel = _BATCH_KERNELS[trig, numba.get_num_threads() == 1]  # trig: compiles in half
    return kernel(*args, model, kind, mp[idx], times, samples, vsamples, rtol, max_steps, demand)


def _auto_rows(rows, motion, tolerance, max_steps, linear_ok=True, demand=False):
    """``method="auto"``: rest, linear or nonlinear row by row (see :mod:`._auto`); the
    linear model only if ``linear_ok`` (no output outside its bound was asked for), and only
    under one-cycle trigonometric pulses, the one case its error table covers (none is known
    under records: see :func:`simulate_batch`). ``motion``: (pulse name or None, cycles);
    ``demand``: the kernels compute the friction demand (:func:`_run`)."""
    p, alpha, eta, kind, mp, times, samples, vsamples = rows
    pulse, cycles = motion
    n = p.size
    if pulse is not None:
        psi = np.abs(mp[:, 0]) / (G * np.tan(alpha))
    else:  # max |u_h''| / ((g + u_v'') tan alpha): exact with or without a vertical
        psi = uplift_ratio(mp[:, 0], alpha, samples, vsamples)
    codes = np.full(n, _auto.MODEL_NONLINEAR, np.int8)
    codes[psi < 1.0] = _auto.MODEL_REST
    if linear_ok and pulse is not None and kind == mk.KIND_TRIG:
        one_cycle = np.broadcast_to(np.asarray(cycles), (n,)) == 1
        omega = mp[:, 1] / p
        bound = _auto.linearization_bound(pulse, eta, alpha, psi, omega)
        codes[(codes == _auto.MODEL_NONLINEAR) & one_cycle & (bound <= tolerance)] = (
            _auto.MODEL_LINEAR
        )
    out = outputs.rows_at_rest(n)
    for code, model, rtol in (
        (_auto.MODEL_LINEAR, _rocking.MODEL_LINEAR, tolerance),
        (_auto.MODEL_NONLINEAR, _rocking.MODEL_NONLINEAR, _auto.kernel_rtol(tolerance)),
    ):
        idx = np.flatnonzero(codes == code)
        if idx.size:
            out[idx] = _run(rows, idx, model, rtol, max_steps, demand)
    ratio = out["max_rotation"] / alpha
    small = np.flatnonzero((codes == _auto.MODEL_NONLINEAR) & (ratio < _auto.SMALL_ROTATION))
    rtols = _auto.kernel_rtol_small(tolerance, ratio[small])
    for rtol in np.unique(rtols):
        idx = small[rtols == rtol]
        out[idx] = _run(rows, idx, _rocking.MODEL_NONLINEAR, rtol, max_steps, demand)
    return out, codes
