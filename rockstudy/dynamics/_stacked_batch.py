"""The rows of a batch of two stacked blocks through the numba kernel (private): the motions
and assemblies packed into the arrays of :func:`._stacked_scene.stacked_batch`, and its
outputs as the columns of :data:`.two_body_batch.STACKED_OUTPUTS`."""

from __future__ import annotations

import numpy as np

from ._stacked_model import pack_geometry
from ._stacked_scene import stacked_batch


def _pack_motions(motions):
    """(kinds, params (n, 4), times, samples, offsets) of the rows' motions: each row's
    samples at offsets[i]:offsets[i + 1] of the concatenated arrays (a record shared by the
    rows, scaled by its params, is stored once per row: a few MB at most)."""
    specs = [m.kernel_spec() for m in motions]
    if any(np.size(spec[4]) for spec in specs):
        raise ValueError(
            "motion: StackedBlocks takes a horizontal ground motion only (a vertical "
            "component is not modelled for two blocks yet)"
        )
    kinds = np.array([spec[0] for spec in specs], dtype=np.int64)
    params = np.array([np.asarray(spec[1], dtype=float) for spec in specs]).reshape(-1, 4)
    sizes = [np.size(spec[2]) for spec in specs]
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    times = np.concatenate([np.asarray(spec[2], dtype=float) for spec in specs])
    samples = np.concatenate([np.asarray(spec[3], dtype=float) for spec in specs])
    return kinds, params, times, samples, offsets


def _geometries(structures) -> np.ndarray:
    """The kernel's geometry array of each row (computed once per distinct assembly)."""
    cache = {}
    rows = [cache.setdefault(s, pack_geometry(s)) for s in structures]
    return np.ascontiguousarray(rows, dtype=float)


def kernel_rows(structures, motions, rtol, max_steps, t_max=None) -> dict:
    """The numba kernel's columns of the rows: max_rotation_lower/upper, overturned,
    overturned_body (code), overturn_time, n_impacts and status (1 where a phase reached
    ``max_steps`` steps, or the run its cap of phases, or an impact had no consistent
    post-impact regime: the row's history is incomplete). ``t_max`` [s] ends every row's
    history there (as :func:`.stacked_reference.simulate_stacked`'s); by default at rest
    after the motion or at a fall."""
    geoms = _geometries(structures)
    kinds, params, times, samples, offsets = _pack_motions(motions)
    n = geoms.shape[0]
    out, codes = np.empty((n, 3)), np.empty((n, 4), dtype=np.int64)
    t_end = np.inf if t_max is None else float(t_max)
    args = (geoms, kinds, params, times, samples, offsets, rtol, int(max_steps), t_end)
    stacked_batch(*args, out, codes)
    return {
        "max_rotation_lower": out[:, 0],
        "max_rotation_upper": out[:, 1],
        "overturned": codes[:, 1].astype(bool),
        "overturned_body": codes[:, 2].astype(np.int8),
        "overturn_time": out[:, 2],
        "n_impacts": codes[:, 3],
        "status": codes[:, 0].astype(np.int8),
    }
