"""The friction demand and lift-off of :func:`rockstudy.simulate_batch` rows (private).

The rocking kernel computes them on the way for Housner's block stepped by Taylor series
(:mod:`._demand`: pulses and records); a row that never lifts needs no run: its demand is
``max |u_h''| / (g + u_v'')`` exactly. The rows the kernel leaves uncomputed (NaN: the exact
linear solvers, the linearized block, DOP853 steps of a Ricker wavelet, a mapped free rocking
of a block stockier than :data:`._demand.FREE_ROCKING_SLENDERNESS`) and that lift are run
again, one by one, through the single-scene path of :func:`rockstudy.simulate` with the same
encoding, model and tolerance, and their histories go through
:func:`rockstudy.dynamics.contact.check_contact`. The batch's other outputs are untouched.
"""

from __future__ import annotations

import numpy as np

from ..constants import G
from ..motions import Motion
from ..motions import _kernels as mk
from . import _auto, _rocking, contact
from ._vertical import uplift_ratio
from .methods import StepLimitError
from .simulate import _kernel, _linear_exact


class _RowMotion(Motion):
    """One batch row's motion: its kernel encoding (kind, params, times, samples,
    vsamples)."""

    def __init__(self, spec):
        self._spec = spec

    def kernel_spec(self):
        return self._spec

    @property
    def duration(self) -> float:
        return float(self._spec[1][3])


def contact_rows(rows, codes, method, rtol, max_steps, kernel):
    """(friction_demand, lift_off) of every row: ``rows`` = (p, alpha, eta, kind, mp, times,
    samples, vsamples) as :func:`rockstudy.simulate_batch` encodes them, ``codes`` the model
    each row ran (:data:`rockstudy.dynamics._auto.MODEL_NAMES`), ``method`` and ``rtol`` the
    batch's (``"auto"`` reruns its nonlinear rows at the kernel's rtol, as it ran them),
    ``kernel`` the batch's output columns (``friction_demand`` and ``lift_off`` as the kernels
    computed them, NaN where not, and ``status``). A row whose history run reaches
    ``max_steps`` has a NaN demand, ``lift_off`` False and True in the third array (the batch
    gives it status 1); so has a row whose kernel reached it."""
    p, alpha, eta, kind, mp, times, samples, vsamples = rows
    failed = kernel["status"] != 0
    computed = ~np.isnan(kernel["friction_demand"])
    demand = np.where(failed, np.nan, kernel["friction_demand"])
    lift_off = computed & ~failed & (kernel["lift_off"] != 0)
    limited = failed.copy()
    rest = np.flatnonzero(~computed & ~failed)  # the rows whose demand the kernel left
    if not rest.size:
        return demand, lift_off, limited
    psi = _uplift_ratio(rows, rest)
    demand[rest] = psi * np.tan(alpha[rest])  # at rest throughout: max |u_h''| / (g + u_v'')
    linear_rows = codes[rest] == _auto.MODEL_LINEAR  # lift at g alpha, below g tan(alpha)
    lifts = psi >= np.where(linear_rows, alpha[rest] / np.tan(alpha[rest]), 1.0)
    for i in rest[lifts]:
        motion = _RowMotion((kind, mp[i], times, samples, vsamples))
        linear = codes[i] == _auto.MODEL_LINEAR
        run = _linear_exact if linear else _kernel
        model = _rocking.MODEL_LINEAR if linear else _rocking.MODEL_NONLINEAR
        k_rtol = _auto.kernel_rtol(rtol) if method == "auto" and not linear else rtol
        args = (p[i], alpha[i], eta[i], motion, model, k_rtol, None, max_steps, method)
        try:
            r = run(*args, (0.0, 0.0))
        except StepLimitError:
            demand[i], limited[i] = np.nan, True
            continue
        check = contact.check_contact(
            r.t, r.theta, r.theta_dot, motion, p[i], alpha[i], eta[i], linear, r.overturned
        )
        demand[i], lift_off[i] = check.friction_demand, check.lift_off
    return demand, lift_off, limited


def _uplift_ratio(rows, idx):
    """max |u_h''| / ((g + u_v'') tan alpha) of the rows ``idx`` of ``rows`` (as
    :func:`contact_rows` takes them): a record's by :func:`._vertical.uplift_ratio`, a
    pulse's |amplitude| / (g tan alpha)."""
    p, alpha, eta, kind, mp, times, samples, vsamples = rows
    if kind == mk.KIND_RECORD:
        return uplift_ratio(mp[idx, 0], alpha[idx], samples, vsamples)
    return np.abs(mp[idx, 0]) / (G * np.tan(alpha[idx]))
