"""The ``orientation`` column of :func:`rockstudy.simulate_batch` (private).

A batch runs one record's samples on every row (scaled row by row), and a record along another
orientation psi is other samples (a_x cos psi + a_y sin psi): the rows are grouped by psi and
each group runs as one batch under the record oriented at its angle
(:meth:`rockstudy.motions.Record.oriented`); the outputs are put back in the rows' order. So a
batch over k orientations costs k batches of its rows, at most. Pulses, of one horizontal
component, take psi = 0 and pi only (pi: the amplitude mirrored).
"""

from __future__ import annotations

import functools
import inspect

import numpy as np

from ..motions.base import axis_sign

__all__ = ["oriented_batch", "with_orientation"]

#: The arguments of :func:`rockstudy.simulate_batch` that broadcast to the rows.
COLUMNS = (
    "half_diagonal",
    "frequency_parameter",
    "critical_rotation",
    "slenderness",
    "restitution",
    "amplitude",
    "period",
    "cycles",
    "scale",
)


def with_orientation(common_length, column):
    """A decorator giving a batch function (:func:`rockstudy.simulate_batch`, keyword
    arguments only) the keyword argument ``orientation``, run by :func:`oriented_batch` with
    the batch's checks of its columns ``common_length`` and ``column``; None runs the batch
    as it is. The signature shown is the batch's with ``orientation`` last."""

    def decorate(batch):
        @functools.wraps(batch)
        def oriented(*, orientation=None, **arguments):
            if orientation is None:
                return batch(**arguments)
            return oriented_batch(batch, orientation, arguments, common_length, column)

        signature = inspect.signature(batch)
        extra = inspect.Parameter("orientation", inspect.Parameter.KEYWORD_ONLY, default=None)
        parameters = [*signature.parameters.values(), extra]
        oriented.__signature__ = signature.replace(parameters=parameters)
        return oriented

    return decorate


def oriented_batch(run, orientation, arguments: dict, common_length, column):
    """The outputs of ``run`` (:func:`rockstudy.simulate_batch`) on ``arguments`` (its
    keyword arguments) with the rows along the angles ``orientation`` [rad] (a scalar or one
    per row); ``common_length`` and ``column`` are the batch's checks of its columns. A
    dataset gains the ``orientation`` coordinate."""
    friction = arguments.get("friction")
    frictions = friction if isinstance(friction, tuple) else (friction,)
    n = common_length(
        orientation=orientation,
        **{k: arguments.get(k) for k in COLUMNS},
        **{f"friction{i}": f for i, f in enumerate(frictions)},
    )
    psi = column("orientation", orientation, n)
    if arguments.get("record") is None:
        return _oriented_pulses(run, psi, arguments)
    angles, group = np.unique(psi, return_inverse=True)
    parts = [
        (idx, run(**_rows(arguments, idx, n, angle)))
        for angle, idx in ((a, np.flatnonzero(group == g)) for g, a in enumerate(angles))
    ]
    return _merge(parts, n, psi)


def _oriented_pulses(run, psi, arguments):
    """Pulses along psi = 0 or pi: the amplitude times +1 or -1, row by row."""
    amplitude = arguments.get("amplitude")
    if amplitude is None:
        return run(**arguments)  # refused by the batch, which names what a pulse needs
    pulse = arguments.get("pulse", inspect.signature(run).parameters["pulse"].default)
    signs = np.array([axis_sign(float(p), f"the {pulse} pulse") for p in psi])
    out = run(**{**arguments, "amplitude": np.asarray(amplitude, dtype=float) * signs})
    return _with_orientation(out, psi) if arguments.get("as_dataset") else out


def _rows(arguments, idx, n, angle):
    """``arguments`` for the rows ``idx`` of n, with the record oriented at ``angle``."""
    out = dict(arguments)
    for name in COLUMNS:
        if out.get(name) is not None:
            out[name] = _subset(out[name], idx, n)
    friction = out.get("friction")
    if friction is not None:
        if isinstance(friction, tuple):
            out["friction"] = tuple(_subset(f, idx, n) for f in friction)
        else:
            out["friction"] = _subset(friction, idx, n)
    out["record"] = out["record"].oriented(float(angle))
    return out


def _subset(values, idx, n):
    """The rows ``idx`` of a column broadcast to n rows."""
    return np.broadcast_to(np.asarray(values), (n,))[idx]


def _merge(parts, n, psi):
    """The outputs of the groups [(row indices, outputs)] in the rows' order: a dict of
    arrays, or a dataset on ``scene`` with the ``orientation`` coordinate."""
    first = parts[0][1]
    if isinstance(first, dict):
        out = {}
        for name, values in first.items():
            out[name] = np.empty(n, dtype=np.asarray(values).dtype)
            for idx, part in parts:
                out[name][idx] = part[name]
        return out
    import xarray as xr

    order = np.argsort(np.concatenate([idx for idx, _ in parts]), kind="stable")
    merged = xr.concat([part for _, part in parts], dim="scene").isel(scene=order)
    return _with_orientation(merged, psi)


def _with_orientation(dataset, psi):
    """``dataset`` with the rows' orientations as the ``orientation`` coordinate."""
    attrs = {"long_name": "orientation psi (from the x component towards y)", "units": "rad"}
    return dataset.assign_coords(orientation=("scene", np.asarray(psi, dtype=float), attrs))
