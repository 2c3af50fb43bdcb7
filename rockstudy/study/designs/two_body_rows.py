"""The two-body objects of a record design (a statue on its plinth, a block on an isolator):
their scenes run the two-body system, :func:`rockstudy.simulate_batch` with ``structure=``.

The designs of :mod:`.records` call :func:`rockstudy.simulate_batch` through one function
(``records._run``) on the structures' columns; a design whose structures carry ``two_body``
(one :class:`~rockstudy.structures.StackedBlocks`, :class:`~rockstudy.structures.IsolatedBlock`
or None per structure) sends the rows of those structures here (:func:`run_points`), by class,
and the others to the block's path. Overturning of either body is the design's
``overturned`` (the failure of the capacities and the fragility curves); the two-body
outputs (:data:`TWO_BODY_VARIABLES`) come beside it, at their fill for a single body.
"""

from __future__ import annotations

import numpy as np

from ...dynamics import simulate_batch
from ...structures import IsolatedBlock, StackedBlocks
from ...structures.block import block_parameters, uplift_acceleration
from ..spec.structures import two_body_parameters

__all__ = [
    "design_columns",
    "ida_outputs",
    "ida_outputs_attributes",
    "is_two_body",
    "keys",
    "point_fills",
    "run_points",
    "TWO_BODY_VARIABLES",
    "two_body_column",
]

#: The two-body outputs a design stores: (long_name, units, dtype, fill).
TWO_BODY_VARIABLES = {
    "max_rotation_lower": (
        "max abs(theta) of the plinth on the ground (NaN: no plinth)",
        "rad",
        "f8",
        np.nan,
    ),
    "max_rotation_upper": (
        "max abs(theta) of the statue relative to its plinth (NaN: no plinth)",
        "rad",
        "f8",
        np.nan,
    ),
    "overturned_body": (
        "the body that overturned: 0 none, 1 the plinth, 2 the statue, 3 both; -1 no plinth",
        "1",
        "i1",
        -1,
    ),
    "max_isolator_displacement": (
        "max abs(displacement) of the isolator (NaN: no isolator)",
        "m",
        "f8",
        np.nan,
    ),
}

#: What the designs read of every point besides :data:`TWO_BODY_VARIABLES` (their fills for
#: a point not run are the designs' own).
_COMMON = ("max_rotation", "overturned", "n_impacts", "overturn_time", "status")


def two_body_column(structures) -> np.ndarray | None:
    """The ``two_body`` column of a design's structures (an object array: a two-body
    structure or None per structure), or None when no structure has two bodies."""
    column = structures.get("two_body") if isinstance(structures, dict) else None
    if column is None or all(s is None for s in column):
        return None
    return np.asarray(column, dtype=object)


def uplift_bounds(structures) -> np.ndarray:
    """Per structure, whether its uplift acceleration bounds the ground PGA below which it
    cannot move: not for a block on an isolator, whose base can amplify the ground's
    acceleration (:func:`rockstudy.study.analysis.risk.cut_levels`)."""
    column = two_body_column(structures)
    n = structures["critical_rotation"].size
    if column is None:
        return np.ones(n, bool)
    return np.array([not isinstance(s, IsolatedBlock) for s in column])


def is_two_body(structure) -> bool:
    """Whether ``structure`` has two bodies (a statue on a plinth, a block on an isolator)."""
    return isinstance(structure, (StackedBlocks, IsolatedBlock))


def design_columns(structures) -> dict | None:
    """The columns a record design takes for a list of structures of which some have two
    bodies (as a study gives them): ``frequency_parameter``, ``critical_rotation``,
    ``restitution`` and ``uplift_acceleration`` of each (a two-body structure's by
    :func:`~rockstudy.study.spec.structures.two_body_parameters`, another's as a block's) and
    the ``two_body`` column; None for a list without a two-body structure (or not a list)."""
    if not isinstance(structures, (list, tuple)) or not any(map(is_two_body, structures)):
        return None
    rows = [
        two_body_parameters(s) if is_two_body(s) else (*block_parameters(s), uplift_acceleration(s))
        for s in structures
    ]
    p, theta, eta, a_up = np.array(rows, float).T
    return dict(
        frequency_parameter=p,
        critical_rotation=theta,
        restitution=eta,
        uplift_acceleration=a_up,
        two_body=[s if is_two_body(s) else None for s in structures],
    )


def keys(structures) -> tuple:
    """The outputs a design keeps beside its own for these structures: the two-body ones
    when some structure has two bodies."""
    return tuple(TWO_BODY_VARIABLES) if two_body_column(structures) is not None else ()


def point_fills(structures, n: int) -> dict:
    """The two-body outputs of ``n`` points not run (their fills), if the design has any."""
    return {
        name: np.full(n, fill, dtype)
        for name, (_, _, dtype, fill) in TWO_BODY_VARIABLES.items()
        if name in keys(structures)
    }


def _refuse(outputs, model) -> None:
    """A ValueError for what the two-body rows do not give: the contact model, the friction
    check (the designs' other outputs)."""
    extra = sorted(set(outputs or ()) - set(_COMMON) - set(TWO_BODY_VARIABLES))
    if model is not None or extra:
        what = f"model={model[0]!r}" if model is not None else f"the outputs {extra}"
        raise ValueError(
            f"structures: a two-body object (StackedBlocks, IsolatedBlock) runs Housner-type "
            f"rocking of its bodies only, not {what}: leave the friction and the contact "
            "model out of a design of two-body objects"
        )


def _two_body_part(record, structures, scales, rtol, max_steps) -> dict:
    """The design's outputs of points of one two-body class (``structures``, one a point)."""
    out = simulate_batch(
        structure=list(structures), record=record, scale=scales, rtol=rtol, max_steps=max_steps
    )
    n = len(structures)
    part = point_fills({"two_body": structures}, n)
    part.update({k: v for k, v in out.items() if k in TWO_BODY_VARIABLES})
    if isinstance(structures[0], StackedBlocks):  # two rotations, no single one
        out["max_rotation"] = np.full(n, np.nan)
    return {**part, **{k: out[k] for k in _COMMON}}


def run_points(record, structures, idx, scales, rtol, max_steps, outputs, model, blocks) -> dict:
    """The outputs of the points (structure ``idx``, ``scales``) of a design under
    ``record``: the two-body structures' by :func:`rockstudy.simulate_batch` (``structure=``,
    one call per class), the others by ``blocks(idx, scales)`` (the block's path); the
    design's ``outputs`` (or :data:`_COMMON`) and :data:`TWO_BODY_VARIABLES`, in point
    order. ``model``: the design's contact model (refused for two-body points)."""
    column = two_body_column(structures)[idx]
    scales = np.asarray(scales, float)
    n = idx.size
    wanted = tuple(outputs or _COMMON) + ("status",)
    parts = []
    single = np.flatnonzero([s is None for s in column])
    if single.size:
        parts.append((single, blocks(idx[single], scales[single])))
    for cls in (StackedBlocks, IsolatedBlock):
        rows = np.flatnonzero([isinstance(s, cls) for s in column])
        if rows.size:
            _refuse(outputs, model)
            part = _two_body_part(record, column[rows], scales[rows], rtol, max_steps)
            parts.append((rows, part))
    out = {}
    for rows, part in parts:
        for name in dict.fromkeys(wanted + tuple(TWO_BODY_VARIABLES)):
            if name in part:
                values = np.asarray(part[name])
                out.setdefault(name, _filled(name, n, values.dtype))[rows] = values
    for name, (_, _, dtype, fill) in TWO_BODY_VARIABLES.items():
        out.setdefault(name, np.full(n, fill, dtype))
    return out


def _filled(name, n, dtype) -> np.ndarray:
    """An array of ``n`` for the output ``name``: its two-body fill, else NaN or zero."""
    if name in TWO_BODY_VARIABLES:
        return np.full(n, TWO_BODY_VARIABLES[name][3], TWO_BODY_VARIABLES[name][2])
    return np.full(n, np.nan if np.issubdtype(dtype, np.floating) else 0, dtype)


def ida_outputs(records, structures, ds, rtol, max_steps) -> dict:
    """The two-body outputs of an IDA on (record, structure): the rotations and the isolator
    displacement at ``capacity_scale_lower`` (the highest scale simulated below the first
    overturning; of a censored object, the highest it stood at), and ``overturned_body`` at
    ``capacity_scale`` (the first overturning). One call a record (two points an object)."""
    column = two_body_column(structures)
    n_rec, n_st = len(records), column.size
    table = {k: np.tile(v, (n_rec, 1)) for k, v in point_fills(structures, n_st).items()}
    body = np.flatnonzero([s is not None for s in column])
    for i, record in enumerate(records):
        for name, scale_name in (("below", "capacity_scale_lower"), ("at", "capacity_scale")):
            s = ds[scale_name].values[i, body]
            ok = np.isfinite(s) & (s > 0)
            if not ok.any():
                continue
            run = run_points(record, structures, body[ok], s[ok], rtol, max_steps, None, None, None)
            for k in TWO_BODY_VARIABLES:
                if (k == "overturned_body") == (name == "at"):
                    table[k][i, body[ok]] = run[k]
    dims = ("record", "structure")
    attrs = ida_outputs_attributes()
    return {k: (dims, v, attrs[k]) for k, v in table.items()}


def ida_outputs_attributes() -> dict:
    """long_name and units of the two-body outputs of an IDA (at which scale each is)."""
    where = {"overturned_body": "at capacity_scale (the first overturning; -1 if censored)"}
    return {
        k: {
            "long_name": f"{long_name}, {where.get(k, 'at capacity_scale_lower')}",
            "units": units,
        }
        for k, (long_name, units, _, _) in TWO_BODY_VARIABLES.items()
    }
