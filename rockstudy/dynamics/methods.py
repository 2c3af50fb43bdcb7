"""The registry of solution methods: each method once, with what it can run.

:func:`rockstudy.simulate` and :func:`rockstudy.simulate_batch` both read :data:`METHODS`
through :func:`method_for`, so an unsupported combination (a method that has no batch
kernel, a vertical component under the single-ODE formulation, a friction demand that a
method does not compute, ...) is refused by both with one message. Both also share the step
limit :data:`MAX_STEPS` and its semantics (:class:`StepLimitError`).
"""

from __future__ import annotations

from dataclasses import dataclass

from .constants import STATUS_MAX_STEPS

__all__ = [
    "MAX_STEPS",
    "Method",
    "method_for",
    "METHODS",
    "STATUS_STEP_LIMIT",
    "StepLimitError",
    "supports",
    "unsupported_message",
]

#: Default cap on the integrator steps in one rocking phase, for :func:`rockstudy.simulate`
#: (exceeded: :class:`StepLimitError`) and :func:`rockstudy.simulate_batch` (exceeded: the
#: row's ``status`` is :data:`STATUS_STEP_LIMIT`), and the default of a study's
#: ``run.max_steps``.
MAX_STEPS = 1_000_000
#: The ``status`` of a batch row that reached the step limit (0: ok).
STATUS_STEP_LIMIT = STATUS_MAX_STEPS


class StepLimitError(RuntimeError):
    """A rocking phase took more than ``max_steps`` integrator steps (:data:`MAX_STEPS` by
    default). :func:`rockstudy.simulate` raises it; :func:`rockstudy.simulate_batch` marks the
    same scene with ``status`` :data:`STATUS_STEP_LIMIT` instead.

    Attributes
    ----------
    method : str
        The method that ran.
    max_steps : int
        The limit that was reached.
    """

    def __init__(self, method: str, max_steps: int):
        super().__init__(
            f"{method}: more than max_steps={max_steps} steps in one rocking phase (raise "
            "max_steps, or loosen rtol)"
        )
        self.method = method
        self.max_steps = max_steps


@dataclass(frozen=True)
class Method:
    """A solution method and what it can run.

    Attributes
    ----------
    name : str
        The ``method=`` string.
    summary : str
        What it solves, in one line.
    structures : tuple of str
        ``"block"`` (a :class:`~rockstudy.Block`) and/or ``"mechanism"`` (a structure with a
        ``mechanism()``: a wall, an arch, a frame).
    mechanism_model : str
        On a structure with a ``mechanism()``: ``"mechanism"`` (eq. 8 of [003]) or
        ``"equivalent block"`` (its kappa_1 equivalent block, with a warning).
    records : bool
        Runs sampled records (every method also runs the analytic pulses).
    vertical : bool
        Takes a record's vertical component (gravity g + u_v'').
    friction_demand : bool
        Gives ``friction_demand`` and ``lift_off`` (for a block).
    batch : bool
        Runs in :func:`rockstudy.simulate_batch`.
    """

    name: str
    summary: str
    structures: tuple = ("block", "mechanism")
    mechanism_model: str = "equivalent block"
    records: bool = True
    vertical: bool = True
    friction_demand: bool = True
    batch: bool = False


METHODS = {
    m.name: m
    for m in (
        Method(
            "nonlinear",
            "Housner's eq. (2.2) of [000] (a mechanism: eq. 8 of [003]), event-driven kernel",
            mechanism_model="mechanism",
            batch=True,
        ),
        Method("linear", "the linearized eq. (3.1) of [000], exact piecewise", batch=True),
        Method("scipy", "Housner's eq. (2.2) of [000] by scipy's solve_ivp (reference)"),
        Method("scipy-linear", "the linearized eq. (3.1) of [000] by scipy's solve_ivp"),
        Method(
            "mechanism",
            "the mechanism, eq. (8) of [003], by the tabulated kernel",
            structures=("mechanism",),
            mechanism_model="mechanism",
            friction_demand=False,
        ),
        Method(
            "complex",
            "the single-ODE formulation of [001] (Housner's model as l -> 0)",
            vertical=False,
            friction_demand=False,
        ),
        Method(
            "auto",
            "the cheapest method whose error bound meets rtol",
            mechanism_model="mechanism",
            batch=True,
        ),
    )
}

#: need -> (what a method does to meet it, in a message; the hint after the methods)
_NEEDS = {
    "batch": ("run in simulate_batch", "or call simulate() scene by scene"),
    "block": ("run a Block", "or give a structure with a mechanism(): a wall, an arch, a frame"),
    "mechanism": ("run a structure with a mechanism()", ""),
    "records": ("run a sampled record", ""),
    "vertical": (
        "take a record's vertical component",
        "or run Record(record.acceleration, time=record.time) for the horizontal alone",
    ),
    "friction_demand": ("compute the friction demand and lift-off of a Block", ""),
}


def supports(method: Method, need: str) -> bool:
    """Whether ``method`` has the capability ``need`` (a key of the registry's needs)."""
    if need in ("block", "mechanism"):
        return need in method.structures
    return bool(getattr(method, need))


def unsupported_message(name: str, need: str) -> str:
    """The one message by which both entry points refuse method ``name`` for ``need``."""
    what, hint = _NEEDS[need]
    able = sorted(m for m, info in METHODS.items() if supports(info, need))
    return f"method={name!r} does not {what}; the methods that do: {able}" + (
        f" ({hint})" if hint else ""
    )


def method_for(
    name,
    *,
    batch: bool = False,
    structure: str = "block",
    record: bool = False,
    vertical: bool = False,
    friction_demand: bool = False,
) -> Method:
    """The registered method ``name``, checked against what the call needs.

    Parameters
    ----------
    name : str
        A key of :data:`METHODS`.
    batch : bool
        The call is :func:`rockstudy.simulate_batch`.
    structure : {"block", "mechanism"}
        What is rocked: a block, or a structure with a ``mechanism()``.
    record, vertical : bool
        The motion is a sampled record; it has a vertical component.
    friction_demand : bool
        The call asks for the friction demand (``friction=`` or the ``friction_demand`` and
        ``lift_off`` outputs).

    Returns
    -------
    Method

    Raises
    ------
    ValueError
        For an unknown name, listing the methods; for the first need the method lacks (in
        the order of the parameters), naming the methods that have it.
    """
    info = METHODS.get(name) if isinstance(name, str) else None
    if info is None:
        raise ValueError(f"method must be one of {sorted(METHODS)}, got {name!r}")
    for need, wanted in (
        ("batch", batch),
        (structure, True),
        ("records", record),
        ("vertical", vertical),
        ("friction_demand", friction_demand),
    ):
        if wanted and not supports(info, need):
            raise ValueError(unsupported_message(name, need))
    return info
