"""``simulate(block, motion, friction=...)``: the contact model of :mod:`.slide_rock` for one
scene, as a :class:`~rockstudy.RockingResult` with the sliding outputs."""

from __future__ import annotations

import functools
import math
import warnings

import numba
import numpy as np

from .. import _validate
from .._warnings import AccuracyWarning, IncompleteReferenceWarning
from ..constants import G
from ..motions import _kernels as mk
from ..motions.pulses import PULSES
from ._contact_scene import MAX_STEPS, STATUS_NO_SOLUTION, contact_batch, contact_scene
from ._sliding import slide_record
from .constants import STATUS_UNCONVERGED
from .contact import ContactCheck, check_contact
from .methods import STATUS_STEP_LIMIT, StepLimitError
from .outputs import TIMED_REGIMES
from .result import RockingResult
from .slide_rock import REGIMES
from .slide_rock_reference import simulate_contact_reference

__all__ = [
    "CONTACT_METHODS",
    "SLIDING",
    "SOLVER",
    "KERNEL",
    "MIN_FRICTION",
    "contact_history",
    "contact_outputs",
    "contact_rows",
    "RowMotions",
    "regime_code",
    "ROW_OUTPUTS",
    "friction_pair",
    "refuse_options",
    "slides_only",
    "simulate_contact",
]

#: The methods that run the contact model: its numba kernel ("nonlinear", "auto") or its
#: scipy reference ("scipy").
CONTACT_METHODS = ("nonlinear", "scipy", "auto")

SLIDING = (
    "exact sliding kernel: the block cannot rock (mu_s < tan alpha); slip in closed form on "
    "each record segment"
)
SOLVER = (
    "contact model (rest, slide, rock, slide-rock, flight; Shenton & Jones 1991, Shenton "
    "1996) by its solve_ivp reference with events"
)
KERNEL = (
    "contact model (rest, slide, rock, slide-rock, flight; Shenton & Jones 1991, Shenton "
    "1996) by its event-driven numba kernel (DOP853, events on the dense output)"
)


#: The smallest friction coefficient the contact model takes. No base of the field is that
#: smooth (PTFE on steel is about 0.04), and below it a slide left after the motion, which
#: lasts |v| / (mu_k g), outlasts what the kernel follows (it stalls near 1e-15).
MIN_FRICTION = 1e-6


def friction_pair(friction, largest) -> tuple[float, float]:
    """(mu_s, mu_k) from ``friction``: one coefficient mu (mu_s = mu_k = mu) or a pair
    (mu_s, mu_k) with mu_s >= mu_k, each in [:data:`MIN_FRICTION`, ``largest``]; a
    ValueError naming ``friction`` otherwise."""
    pair = friction if isinstance(friction, (tuple, list)) else (friction, friction)
    if len(pair) != 2:
        raise ValueError(
            f"friction must be a coefficient mu or a pair (mu_s, mu_k), got {len(pair)} values"
        )
    static, kinetic = (_validate.number("friction", value) for value in pair)
    for value in (static, kinetic):
        if not (math.isfinite(value) and 0.0 < value <= largest):
            raise ValueError(f"friction must lie in (0, {largest:g}], got {value!r}")
        if value < MIN_FRICTION:
            raise ValueError(
                f"friction must lie in [{MIN_FRICTION:g}, {largest:g}] for the contact model, "
                f"got {value!r}"
            )
    if kinetic > static:
        raise ValueError(
            f"friction: the kinetic coefficient {kinetic!r} exceeds the static {static!r} "
            "(give (mu_s, mu_k) with mu_s >= mu_k)"
        )
    return static, kinetic


def refuse_options(method, x0, t_eval, conditioning):
    """A ValueError for what the contact model does not run (yet): another method, initial
    conditions, dense output, conditioning."""
    if method not in CONTACT_METHODS:
        raise ValueError(
            f"friction: method={method!r} does not run the contact model; use one of "
            f"{', '.join(repr(m) for m in CONTACT_METHODS)}"
        )
    for name, given in (
        ("initial_rotation/initial_velocity", x0 != (0.0, 0.0)),
        ("t_eval/dt_out", t_eval is not None),
        ("conditioning", bool(conditioning)),
    ):
        if given:
            raise ValueError(f"friction: {name} is not available with the contact model")


def slides_only(motion, friction, alpha, method, t_max) -> bool:
    """Whether the exact sliding kernel runs the scene: a record, mu_s < tan(alpha) (the
    block cannot rock: the base never carries more than mu_s N, below the uplift force),
    the history to its natural end, and a method other than "scipy" (the reference)."""
    kind = motion.kernel_spec()[0]
    return (
        kind == mk.KIND_RECORD
        and friction[0] < math.tan(alpha)
        and method != "scipy"
        and t_max is None
    )


def _sliding_kernel(motion, friction):
    """The reference's dict of a scene the sliding kernel runs (:mod:`._sliding`)."""
    _, mp, times, samples, vsamples = motion.kernel_spec()
    accel = mp[0] * np.asarray(samples, dtype=float)
    vert = abs(mp[0]) * np.asarray(vsamples, dtype=float)
    t, u, _, peak, first, slid = slide_record(
        np.asarray(times, dtype=float), accel, vert, *friction
    )
    end = max(float(t[-1]), float(times[-1]))
    zeros = np.zeros_like(t)
    return {
        "t": t,
        "theta": zeros,
        "theta_dot": zeros.copy(),
        "slide": u,
        "max_rotation": 0.0,
        "overturned": False,
        "impact_times": np.empty(0),
        "overturn_time": math.nan,
        "max_slide": peak,
        "residual_slide": float(u[-1]),
        "first_slip_time": first,
        "lift_off": False,
        "regime_times": {**dict.fromkeys(REGIMES, 0.0), "rest": end - slid, "slide": slid},
        "regime_sequence": None,
    }


def contact_history(p, alpha, eta, motion, friction, method, rtol, t_max) -> dict:
    """One scene of the contact model: the dict of
    :func:`~.slide_rock_reference.simulate_contact_reference` (``"energy"`` and
    ``"regime_sequence"`` from the reference only), from the exact sliding kernel where
    :func:`slides_only` allows it, from the reference for ``method="scipy"``, else from the
    event-driven kernel; ``"solver"`` says which ran (:data:`SLIDING`, :data:`SOLVER` or
    :data:`KERNEL`)."""
    if min(friction) < MIN_FRICTION:
        raise ValueError(
            f"friction must lie in [{MIN_FRICTION:g}, 10] for the contact model, got {friction!r}"
        )
    if slides_only(motion, friction, alpha, method, t_max):
        return {**_sliding_kernel(motion, friction), "solver": SLIDING}
    radius = 0.75 * G / (p * p)
    if method != "scipy":
        r = _contact_kernel(radius, alpha, eta, motion, friction, method, rtol, t_max)
        return {**r, "solver": KERNEL}
    r = simulate_contact_reference(radius, alpha, eta, motion, *friction, rtol=rtol, t_max=t_max)
    return {**r, "solver": SOLVER}


def contact_outputs(p, alpha, eta, motion, friction, rtol, t_max=None, method="auto") -> dict:
    """The batch outputs of one scene under the contact model (what
    :func:`rockstudy.simulate_batch` stores for a row its ``model`` runs the contact model on).

    Parameters
    ----------
    p, alpha, eta : float
        Frequency parameter [rad/s], slenderness [rad] and restitution of the block.
    motion : Motion
        The ground motion of the scene (a pulse, or a scaled record).
    friction : (float, float)
        (mu_s, mu_k), checked (:func:`friction_pair`).
    rtol : float
        Relative tolerance of the reference (the sliding kernel is exact).
    t_max : float, optional
        End of the history [s]; by default until the block rests after the motion.
    method : {"auto", "scipy"}
        The solver (:func:`contact_history`): the exact sliding kernel or the event-driven
        kernel (``"auto"``), or the ``solve_ivp`` reference (``"scipy"``).

    Returns
    -------
    dict
        Scalars named as the outputs of :mod:`.outputs` that the contact model computes:
        ``status`` (0, or 1 where the reference stopped at its cap of phases: an
        :class:`~rockstudy.IncompleteReferenceWarning` caught here), ``max_rotation``,
        ``overturned``, ``n_impacts``, ``overturn_time``, ``first_impact_time``,
        ``lift_off``, ``max_slide``, ``residual_slide``, ``first_slip_time``, the seconds in
        the regimes Housner's model has not (``time_slide``, ``time_slide_rock``,
        ``time_flight``) and ``regime`` (:func:`regime_code`).
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IncompleteReferenceWarning)
        try:
            r = contact_history(p, alpha, eta, motion, friction, method, rtol, t_max)
        except StepLimitError:  # the kernel did not converge: the row's failed fill
            return _failed_row()
    incomplete = any(issubclass(w.category, IncompleteReferenceWarning) for w in caught)
    impacts = np.asarray(r["impact_times"], float)
    times = r["regime_times"]
    return {
        "status": STATUS_STEP_LIMIT if incomplete else 0,
        "max_rotation": float(r["max_rotation"]),
        "overturned": bool(r["overturned"]),
        "n_impacts": impacts.size,
        "overturn_time": float(r["overturn_time"]),
        "first_impact_time": float(impacts[0]) if impacts.size else math.nan,
        "lift_off": bool(r["lift_off"]),
        "max_slide": float(r["max_slide"]),
        "residual_slide": float(r["residual_slide"]),
        "first_slip_time": float(r["first_slip_time"]),
        **{f"time_{name}": float(times[name]) for name in TIMED_REGIMES},
        "regime": regime_code(times),
    }


#: The outputs :func:`contact_outputs` gives, beside ``status``.
ROW_OUTPUTS = (
    "max_rotation", "overturned", "n_impacts", "overturn_time", "first_impact_time",
    "lift_off", "max_slide", "residual_slide", "first_slip_time",
    *(f"time_{name}" for name in TIMED_REGIMES), "regime",
)  # fmt: skip


def _failed_row() -> dict:
    """The outputs of a scene the kernel did not solve within its steps: ``status`` 1, NaN
    for a float, -1 for a count, False for a flag (no decision is claimed)."""
    fills = {"overturned": False, "lift_off": False, "n_impacts": -1, "regime": -1}
    return {"status": STATUS_STEP_LIMIT, **{k: fills.get(k, math.nan) for k in ROW_OUTPUTS}}


def regime_code(regime_times) -> int:
    """The most involved regime a block entered, as its index in
    :data:`~.slide_rock.REGIMES` (0 rest, 1 slide, 2 rock, 3 slide-rock, 4 flight): the last
    one of that order with time spent in it (``regime_times``: seconds by regime name)."""
    moving = enumerate(REGIMES[1:], start=1)
    return max((i for i, name in moving if regime_times.get(name, 0.0) > 0.0), default=0)


class RowMotions:
    """The Motion of each row of :func:`rockstudy.simulate_batch` (the record scaled by the row's
    scale, or the row's pulse), built on demand for the contact model."""

    def __init__(self, pulse, record, mp, amplitude, period, cycles, n):
        self.record, self.scale = record, mp[:, 0]
        if record is None:
            self.pulse = PULSES[pulse]
            columns = (amplitude, period, cycles)
            self.amplitude, self.period, self.cycles = (
                np.broadcast_to(np.asarray(x, dtype=float), (n,)) for x in columns
            )
            self.counted = pulse in ("sine", "cosine")  # the others take no cycles

    def __getitem__(self, i):
        if self.record is not None:
            return self.record.scaled(float(self.scale[i]))
        extra = {"cycles": int(self.cycles[i])} if self.counted else {}
        return self.pulse(amplitude=float(self.amplitude[i]), period=float(self.period[i]), **extra)


def contact_rows(p, alpha, eta, friction, motion_rows, rtol, motion_of):
    """The batch outputs of many scenes under the contact model, in one parallel call of the
    kernels (:func:`._contact_scene.contact_batch`: the exact sliding kernel where
    :func:`slides_only` allows it, the event-driven kernel elsewhere), each row the answer
    :func:`contact_outputs` gives its scene.

    A row the kernel cannot answer within :data:`._contact_scene.MAX_STEPS` steps (a
    chatter that does not settle) is run again by the ``solve_ivp`` reference
    (:func:`contact_outputs` with ``method="scipy"``; its ``status`` 1 where the reference
    stopped at its cap of phases). A row whose answer did not converge with rtol (the
    kernel's ``converged`` flag, :mod:`._contact_flag`) keeps it with ``status``
    :data:`~.constants.STATUS_UNCONVERGED` (4), to be used as no answer. A row without a
    solution (Painleve's paradox, mu_k > 4/3) has none under the reference either: a
    ValueError naming the row.

    Parameters
    ----------
    p, alpha, eta : array of float
        Frequency parameter [rad/s], slenderness [rad] and restitution of each row.
    friction : (array, array)
        (mu_s, mu_k) of each row, checked.
    motion_rows : tuple
        (kind, mp, times, samples, vsamples) of the rows, as
        :func:`rockstudy.simulate_batch` encodes them.
    rtol : float
        Relative tolerance.
    motion_of : callable
        motion_of(i): the Motion of row i (for the reference).

    Returns
    -------
    (dict, ndarray of bool)
        The outputs ``status`` and :data:`ROW_OUTPUTS` as arrays, and which rows the
        reference answered.
    """
    _refuse_smooth(friction)
    parallel = numba.get_num_threads() > 1
    out = contact_batch(p, alpha, eta, *friction, motion_rows, rtol, MAX_STEPS, parallel)
    _refuse_no_solution(out["status"], friction[1])
    unconverged = (out["status"] == 0) & ~out["converged"]
    cols = {"status": np.where(unconverged, STATUS_UNCONVERGED, out["status"]).astype(np.int64)}
    cols.update({name: out[name].copy() for name in ROW_OUTPUTS if name != "regime"})
    cols["regime"] = _regime_codes(out)
    referred = out["status"] != 0
    for i in np.flatnonzero(referred):
        friction_i = (float(friction[0][i]), float(friction[1][i]))
        one = contact_outputs(p[i], alpha[i], eta[i], motion_of(i), friction_i, rtol, None, "scipy")
        for name, value in one.items():
            cols[name][i] = value
    return cols, referred


def _refuse_smooth(friction):
    """A ValueError naming the first row whose friction is below :data:`MIN_FRICTION` (as
    :func:`contact_history` refuses one scene), before any run."""
    low = np.flatnonzero(np.minimum(*friction) < MIN_FRICTION)
    if low.size:
        i = int(low[0])
        pair = (float(friction[0][i]), float(friction[1][i]))
        raise ValueError(
            f"friction: row {i}: friction must lie in [{MIN_FRICTION:g}, 10] for the contact "
            f"model, got {pair!r}"
        )


def _refuse_no_solution(status, kinetic):
    """A ValueError naming the first row the kernel found without a solution."""
    bad = np.flatnonzero(status == STATUS_NO_SOLUTION)
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"friction: row {i}: mu_k = {float(kinetic[i])!r} gives the contact model no "
            "solution in this scene (Painleve's paradox, possible only for mu_k > 4/3)"
        )


def _regime_codes(rows) -> np.ndarray:
    """:func:`regime_code` of each row of a contact batch (its ``time_<regime>`` fields)."""
    codes = np.zeros(rows.size, np.int8)
    for i, name in enumerate(REGIMES[1:], start=1):
        codes[rows[f"time_{name}"] > 0.0] = i
    return codes


def simulate_contact(p, alpha, eta, motion, friction, method, rtol, t_max, rocking):
    """The contact model of the block (p, alpha, eta) under ``motion`` with ``friction`` =
    (mu_s, mu_k), as a :class:`~rockstudy.RockingResult`: its ``friction_demand`` is that of
    Housner's no-slip model on the same scene (``rocking()`` runs it, on first use), its
    ``lift_off`` the contact model's own. The exact sliding kernel runs the scenes of
    :func:`slides_only`, the ``solve_ivp`` reference those of ``method="scipy"``, the
    event-driven kernel (:mod:`._contact_scene`) the others; a kernel scene that reaches its
    step limit raises :class:`~rockstudy.dynamics.methods.StepLimitError`, one without a
    solution (Painleve's paradox) a ValueError."""
    r = contact_history(p, alpha, eta, motion, friction, method, rtol, t_max)
    if r["solver"] == SLIDING:
        info = {"solver": SLIDING}
    elif r["solver"] == KERNEL:
        info = {"solver": KERNEL, "steps": r["steps"]}
    else:
        info = {
            "solver": SOLVER,
            "energy": {k: v for k, v in r["energy"].items() if k != "each_impact_loss"},
            "regime_sequence": r["regime_sequence"],
        }
    info.update(
        friction_static=friction[0],
        friction_kinetic=friction[1],
        frequency_parameter=float(p),
        critical_rotation=float(alpha),
        restitution=float(eta),
    )
    lift_off = bool(r["lift_off"])
    return RockingResult(
        r["t"],
        r["theta"],
        r["theta_dot"],
        float(r["max_rotation"]),
        bool(r["overturned"]),
        r["impact_times"],
        float(r["overturn_time"]),
        method,
        info,
        _contact=functools.partial(_housner_demand, rocking, motion, lift_off),
        slide=r["slide"],
        max_slide=float(r["max_slide"]),
        residual_slide=float(r["residual_slide"]),
        first_slip_time=float(r["first_slip_time"]),
        regime_times=r["regime_times"],
    )


def _contact_kernel(radius, alpha, eta, motion, friction, method, rtol, t_max, max_steps=MAX_STEPS):
    """The reference's dict of a scene the event-driven kernel runs
    (:func:`._contact_scene.contact_scene`, at most ``max_steps`` steps); a scene it does
    not solve raises."""
    r = contact_scene(radius, alpha, eta, motion, *friction, rtol, t_max, max_steps)
    if r["status"] == STATUS_NO_SOLUTION:
        raise ValueError(
            f"friction: mu_k = {friction[1]!r} gives the contact model no solution in this "
            "scene (Painleve's paradox, possible only for mu_k > 4/3)"
        )
    if r["status"] != 0:
        raise StepLimitError(method, max_steps)
    if not r.get("converged", True):
        warnings.warn(
            f"the contact model's answer did not converge with rtol={rtol:g}: a friction "
            "decision (stick or slip, mu_s > mu_k) lay within 10 rtol of its threshold, where "
            "the answer jumps, its answer moved at rtol / 100, or the scene is ill-conditioned "
            "(its answer moves by more than 1e4 rtol when the amplitude moves by 1e-9)",
            AccuracyWarning,
            stacklevel=4,
        )
    r["regime_sequence"] = None
    return r


def _housner_demand(rocking, motion, lift_off):
    """The ContactCheck of a contact-model result: the friction demand of Housner's model
    (``rocking()``: its result), the contact model's lift-off."""
    h = rocking()
    info = h.info
    check = check_contact(
        h.t,
        h.theta,
        h.theta_dot,
        motion,
        info["frequency_parameter"],
        info["critical_rotation"],
        info["restitution"],
        False,
        h.overturned,
    )
    return ContactCheck(check.friction_demand, lift_off, check.time)
