"""``simulate(block, motion, friction=...)``: the contact model of :mod:`.slide_rock` for one
scene, as a :class:`~rockstudy.RockingResult` with the sliding outputs."""

from __future__ import annotations

import functools
import math

import numpy as np

from .. import _validate
from ..constants import G
from ..motions import _kernels as mk
from ._contact_scene import MAX_STEPS, STATUS_NO_SOLUTION, contact_scene
from ._sliding import slide_record
from .contact import ContactCheck, check_contact
from .methods import StepLimitError
from .result import RockingResult
from .slide_rock import REGIMES
from .slide_rock_reference import simulate_contact_reference

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


def friction_pair(friction, largest) -> tuple[float, float]:
    """(mu_s, mu_k) from ``friction``: one coefficient mu (mu_s = mu_k = mu) or a pair
    (mu_s, mu_k) with mu_s >= mu_k, each in (0, ``largest``]; a ValueError naming
    ``friction`` otherwise."""
    pair = friction if isinstance(friction, (tuple, list)) else (friction, friction)
    if len(pair) != 2:
        raise ValueError(
            f"friction must be a coefficient mu or a pair (mu_s, mu_k), got {len(pair)} values"
        )
    static, kinetic = (_validate.number("friction", value) for value in pair)
    for value in (static, kinetic):
        if not (math.isfinite(value) and 0.0 < value <= largest):
            raise ValueError(f"friction must lie in (0, {largest:g}], got {value!r}")
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


def simulate_contact(p, alpha, eta, motion, friction, method, rtol, t_max, rocking):
    """The contact model of the block (p, alpha, eta) under ``motion`` with ``friction`` =
    (mu_s, mu_k), as a :class:`~rockstudy.RockingResult`: its ``friction_demand`` is that of
    Housner's no-slip model on the same scene (``rocking()`` runs it, on first use), its
    ``lift_off`` the contact model's own. The exact sliding kernel runs the scenes of
    :func:`slides_only`, the ``solve_ivp`` reference those of ``method="scipy"``, the
    event-driven kernel (:mod:`._contact_scene`) the others; a kernel scene that reaches its
    step limit raises :class:`~rockstudy.dynamics.methods.StepLimitError`, one without a
    solution (Painleve's paradox) a ValueError."""
    radius = 0.75 * G / (p * p)
    if slides_only(motion, friction, alpha, method, t_max):
        r, info = _sliding_kernel(motion, friction), {"solver": SLIDING}
    elif method != "scipy":
        r = _contact_kernel(radius, alpha, eta, motion, friction, method, rtol, t_max)
        info = {"solver": KERNEL, "steps": r["steps"]}
    else:
        r = simulate_contact_reference(
            radius, alpha, eta, motion, *friction, rtol=rtol, t_max=t_max
        )
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
