"""The batch kernels' output rows (private): one :data:`.outputs.KERNEL_ROW` per scene."""

from __future__ import annotations

import numpy as np
from numba import njit

from .outputs import KERNEL_ROW


@njit(cache=True)
def new_rows(n):
    """An array of n :data:`KERNEL_ROW` records, to be filled by :func:`write_row`."""
    return np.empty(n, KERNEL_ROW)


@njit(cache=True, inline="always")
def write_row(out, i, r):
    """Write the outcome ``r`` of a scene (a namedtuple with a field per ``"kernel"`` output
    of :data:`.outputs.OUTPUTS`) into row i of ``out`` (:func:`new_rows`)."""
    row = out[i]
    row.status = r.status
    row.max_rotation = r.max_rotation
    row.overturned = r.overturned
    row.n_impacts = r.n_impacts
    row.overturn_time = r.overturn_time
    row.steps = r.steps
    row.first_impact_time = r.first_impact_time
    row.peak_time = r.peak_time
    row.friction_demand = r.friction_demand
    row.lift_off = r.lift_off
