"""Many scenes of the two-body systems (:class:`~rockstudy.structures.StackedBlocks`,
:class:`~rockstudy.structures.IsolatedBlock`) in one call: the ``structure=`` door of
:func:`rockstudy.dynamics.batch.simulate_batch`.

Each row is one structure under one motion (a pulse, or the record scaled by the row's
``scale``); the outputs carry the names of :func:`rockstudy.simulate`'s results for that
system (:data:`STACKED_OUTPUTS`, :data:`ISOLATED_OUTPUTS`). The rows of one class run through
that class's row function (:data:`ROW_FUNCTIONS`), which returns one column per output.
"""

from __future__ import annotations

import numpy as np

from ..motions.pulses import PULSES
from ..motions.records import Record
from ..structures.isolated import IsolatedBlock
from ..structures.stacked import StackedBlocks
from ._stacked_batch import kernel_rows
from .conditioning import perturbed

__all__ = [
    "CONDITIONING",
    "ISOLATED_OUTPUTS",
    "OVERTURNED_BODY",
    "ROW_FUNCTIONS",
    "STACKED_OUTPUTS",
    "isolated_rows",
    "row_motions",
    "stacked_rows",
    "two_body_batch",
]

#: Codes of ``overturned_body`` in a batch (CF ``flag_values``/``flag_meanings``).
OVERTURNED_BODY = {None: 0, "lower": 1, "upper": 2, "both": 3}

#: The outputs of a batch of :class:`StackedBlocks`: as :class:`.stacked_reference.StackedResult`
#: names them (``overturned_body`` as its code of :data:`OVERTURNED_BODY`), and ``status``
#: (0 ok, 1 the solver's cap of phases reached).
STACKED_OUTPUTS = (
    "max_rotation_lower",
    "max_rotation_upper",
    "overturned",
    "overturned_body",
    "overturn_time",
    "n_impacts",
    "status",
)

#: The outputs of a batch of :class:`IsolatedBlock`: as :class:`.isolated_result.IsolatedResult`
#: names them, and ``status``.
ISOLATED_OUTPUTS = (
    "max_rotation",
    "overturned",
    "max_isolator_displacement",
    "overturn_time",
    "n_impacts",
    "status",
)


#: The opt-in output of both classes (twice the cost: every row runs again with its
#: amplitude times 1 + 1e-9, :func:`.conditioning.perturbed`): the largest change of a peak
#: rotation over |peak| + :data:`PEAK_FLOOR` alpha of its body (the house's accuracy measure),
#: inf where the overturning decision or the overturned body changes. Above
#: :data:`.conditioning.ILL_CONDITIONED` no solver determines the row's peaks better.
CONDITIONING = "conditioning"

#: The floor of a peak in :data:`CONDITIONING`, a fraction of its body's alpha: a body that
#: barely moves (a peak of 1e-25 rad is rounding) has no relative change of its own.
PEAK_FLOOR = 1e-2


def _peaks(structure) -> dict:
    """{peak output: the slenderness of its body} of a two-body structure."""
    if isinstance(structure, StackedBlocks):
        lower, upper = structure.lower.slenderness, structure.upper.slenderness
        return {"max_rotation_lower": lower, "max_rotation_upper": upper}
    return {"max_rotation": structure.block.slenderness}


def row_motions(n, pulse="sine", amplitude=None, period=None, cycles=1, record=None, scale=1.0):
    """The motion of each of n rows: ``record`` scaled by the row's ``scale``, or the pulse
    ``pulse`` of the row's ``amplitude``, ``period`` (and ``cycles`` for the trigonometric
    pulses)."""
    if record is not None:
        if not isinstance(record, Record):
            raise TypeError(f"record must be a rockstudy Record, got {type(record).__name__}")
        return [record.scaled(float(s)) for s in np.broadcast_to(scale, (n,))]
    if pulse not in PULSES:
        raise ValueError(f"pulse must be one of {sorted(PULSES)}, got {pulse!r}")
    if amplitude is None or period is None:
        raise ValueError("a pulse needs amplitude [m/s^2] and period [s] (or give record=)")
    amp, per, cyc = (np.broadcast_to(x, (n,)) for x in (amplitude, period, cycles))
    cls = PULSES[pulse]
    takes_cycles = "cycles" in getattr(cls, "__dataclass_fields__", {})
    return [
        cls(float(a), float(t), int(c)) if takes_cycles else cls(float(a), float(t))
        for a, t, c in zip(amp, per, cyc, strict=True)
    ]


def _reference_rows(structures, motions, rtol, read) -> dict:
    """The outputs ``read(result)`` of each (structure, motion) row, by the ``solve_ivp``
    reference of :func:`rockstudy.simulate` one row at a time; ``n_impacts`` and ``status``
    (1 where the reference's history is incomplete) come along."""
    from .simulate import simulate

    cols = {}
    for structure, motion in zip(structures, motions, strict=True):
        res = simulate(structure, motion, rtol=rtol)
        row = read(res)
        row["n_impacts"] = len(res.impact_times)
        row["status"] = 0 if res.info.get("complete", True) else 1
        for name, value in row.items():
            cols.setdefault(name, []).append(value)
    return _typed(cols)


def stacked_rows(structures, motions, rtol, max_steps) -> dict:
    """The :data:`STACKED_OUTPUTS` of each (structure, motion) row, by the event-driven
    numba kernel (:mod:`._stacked_scene`, rows in parallel): the model and the history of
    the ``solve_ivp`` reference :func:`.stacked_reference.simulate_stacked`; ``status`` 1
    where a phase reached ``max_steps`` steps (the row's outputs are then incomplete)."""
    return kernel_rows(structures, motions, rtol, max_steps)


def isolated_rows(structures, motions, rtol, max_steps) -> dict:
    """The :data:`ISOLATED_OUTPUTS` of each (structure, motion) row, by the numba kernel
    (:mod:`._isolated_scene`, the rows in parallel): the reference's model and events,
    ``status`` 1 where a row reached ``max_steps`` steps, the reference's impact cap or its
    tail cap after the motion."""
    from ._isolated_scene import O_IMPACTS, O_OVER, O_STATUS, O_THETA, O_TIME, O_X, run_rows
    from .isolated_reference import MAX_IMPACTS

    out = run_rows(structures, motions, rtol, max_steps, MAX_IMPACTS)
    columns = (O_THETA, O_OVER, O_X, O_TIME, O_IMPACTS, O_STATUS)
    return _typed({k: out[:, c] for k, c in zip(ISOLATED_OUTPUTS, columns, strict=True)})


def conditioning_of(rows, structures, motions, rtol, max_steps, cols) -> np.ndarray:
    """The :data:`CONDITIONING` of each row whose outputs are ``cols``: the rows run again
    through ``rows`` with each motion's amplitude times 1 + 1e-9, and the largest change
    of a peak over |peak| + :data:`PEAK_FLOOR` alpha; inf where the decision or the
    overturned body changes."""
    twin = rows(structures, [perturbed(m) for m in motions], rtol, max_steps)
    alphas = [_peaks(s) for s in structures]
    change = np.zeros(len(structures))
    for name in alphas[0]:
        floor = PEAK_FLOOR * np.array([a[name] for a in alphas])
        change = np.maximum(change, np.abs(twin[name] - cols[name]) / (np.abs(cols[name]) + floor))
    moved = cols["overturned"] != twin["overturned"]
    if "overturned_body" in cols:
        moved |= cols["overturned_body"] != twin["overturned_body"]
    return np.where(moved, np.inf, change)


_DTYPES = {"overturned": bool, "overturned_body": np.int8, "n_impacts": np.int64}
_DTYPES["status"] = np.int8

#: The row function and the outputs of each two-body class.
ROW_FUNCTIONS = {
    StackedBlocks: (stacked_rows, STACKED_OUTPUTS),
    IsolatedBlock: (isolated_rows, ISOLATED_OUTPUTS),
}


def _typed(cols) -> dict:
    return {k: np.asarray(v, dtype=_DTYPES.get(k, float)) for k, v in cols.items()}


def _structures(structure, n):
    """The structure of each of n rows, all of one two-body class."""
    items = [structure] if isinstance(structure, tuple(ROW_FUNCTIONS)) else list(structure)
    if not items:
        raise ValueError("structure is empty: give a structure or a non-empty sequence")
    kinds = {type(s) for s in items}
    if len(kinds) > 1 or not kinds <= set(ROW_FUNCTIONS):
        names = ", ".join(sorted(c.__name__ for c in ROW_FUNCTIONS))
        raise TypeError(f"structure must be one of {names}, or a sequence of one of them")
    if len(items) not in (1, n):
        raise ValueError(f"structure has {len(items)} rows, the other arguments {n}")
    return items * n if len(items) == 1 else items


#: The arguments of :func:`~rockstudy.dynamics.batch.simulate_batch` that describe a block
#: (a two-body structure carries its own), and its options a two-body batch runs with.
_BLOCK_ARGUMENTS = ("half_diagonal", "frequency_parameter", "critical_rotation", "slenderness")
_BLOCK_ARGUMENTS += ("restitution", "friction")
_TWO_BODY_OPTIONS = {"model": "rocking", "method": "nonlinear"}


def _refuse_block_arguments(args):
    """A ValueError for the block columns and the options a two-body batch does not take."""
    given = [k for k in _BLOCK_ARGUMENTS if args[k] is not None]
    given += [f"{k}={args[k]!r}" for k, v in _TWO_BODY_OPTIONS.items() if args[k] != v]
    if given:
        raise ValueError(
            f"structure= takes no {', '.join(given)}: a two-body structure carries its own "
            "geometry and runs its own model"
        )


def _length(structure, columns) -> int:
    """The common length of the rows: the structure sequence's and the 1-D columns'."""
    sizes = {} if isinstance(structure, tuple(ROW_FUNCTIONS)) else {"structure": len(structure)}
    sizes.update({k: np.size(v) for k, v in columns.items() if v is not None and np.ndim(v)})
    lengths = {v for v in sizes.values() if v != 1}
    if len(lengths) > 1:
        raise ValueError(
            "the 1-D arguments must have one common length (or length 1), got "
            + ", ".join(f"{k}: {v}" for k, v in sizes.items())
        )
    return max(lengths, default=1)


def two_body_batch(args: dict):
    """The outputs of the rows of a two-body ``args["structure"]`` (one, or one per row)
    under their motions (:func:`row_motions`): ``args`` are the arguments of
    :func:`~rockstudy.dynamics.batch.simulate_batch`. A dict of arrays, only ``outputs`` (and
    ``status``) if given; an :class:`xarray.Dataset` on ``scene`` with ``as_dataset``."""
    _refuse_block_arguments(args)
    structure, outputs, record = args["structure"], args["outputs"], args["record"]
    columns = {k: args[k] for k in ("amplitude", "period", "cycles", "scale")}
    n = _length(structure, columns)
    structures = _structures(structure, n)
    rows, names = ROW_FUNCTIONS[type(structures[0])]
    wanted = names if outputs is None else ((outputs,) if isinstance(outputs, str) else outputs)
    unknown = sorted(set(wanted) - {*names, CONDITIONING})
    if unknown:
        raise ValueError(
            f"outputs: unknown name(s) {unknown} for {type(structures[0]).__name__}; "
            f"allowed: {[*names, CONDITIONING]}"
        )
    motions = row_motions(n, args["pulse"], record=record, **columns)
    cols = rows(structures, motions, args["rtol"], args["max_steps"])
    if CONDITIONING in wanted:
        cols[CONDITIONING] = conditioning_of(
            rows, structures, motions, args["rtol"], args["max_steps"], cols
        )
    result = {k: cols[k] for k in (*names, CONDITIONING) if k in wanted or k == "status"}
    if not args["as_dataset"]:
        return result
    motion = ("scale",) if record is not None else ("amplitude", "period", "cycles")
    coords = {k: np.broadcast_to(columns[k], (n,)) for k in motion}
    return _dataset(result, coords, type(structures[0]).__name__, args["rtol"])


def _dataset(result, coords, structure, rtol):
    """A two-body batch's outputs on ``scene``, with its motion columns as coordinates."""
    import xarray as xr

    data = {k: ("scene", v) for k, v in result.items()}
    if "overturned_body" in data:
        flags = {"flag_values": list(OVERTURNED_BODY.values())}
        flags["flag_meanings"] = "none lower upper both"
        data["overturned_body"] = ("scene", result["overturned_body"], flags)
    return xr.Dataset(
        data,
        coords={k: ("scene", v) for k, v in coords.items()},
        attrs={"structure": structure, "rtol": rtol},
    )
