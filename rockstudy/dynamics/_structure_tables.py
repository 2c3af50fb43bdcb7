"""Nonlinear dynamics of one-DOF rocking mechanisms, eq. (8) of [003].

The mechanism's I_nl, G_nl, B_nl and potential V are tabulated once, with their exact
derivatives, on a uniform grid of the amplitude phi in [0, phi_fall]; the event-driven DOP853
kernel of the block then integrates eq. (8) with cubic Hermite interpolation of the table, the
same impact rule (phi_dot+ = eta phi_dot- at phi = 0), the Zeno rule, and the closed-form
free-rocking map (energy I phi_dot^2 / 2 + V conserved between impacts) after the motion.
The mechanism is taken to have collapsed at phi_fall = min(kinematic limit, pi/2).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from . import _rocking


@lru_cache(maxsize=64)
def structure_parameters(structure):
    """``structure.rocking_parameters()`` of a (hashable, immutable) structure, computed once
    (the critical-rotation search costs milliseconds)."""
    return structure.rocking_parameters()


@lru_cache(maxsize=64)
def structure_table(structure, n: int = 4001):
    """The kernel's tables of a (hashable, immutable) structure, computed once: an array of
    shape (2, n, 9) for rocking towards +x and -x, and the collapse amplitude."""
    try:
        mechs = (structure.mechanism(1), structure.mechanism(-1))
    except TypeError:  # a symmetric structure: one mechanism for both directions
        mechs = (structure.mechanism(),) * 2
    tabs = [mechanism_table(m, n) for m in mechs]
    fall = min(t[1] for t in tabs)
    tabs = [mechanism_table(m, n, fall) for m in mechs] if tabs[0][1] != tabs[1][1] else tabs
    table = np.ascontiguousarray(np.stack([t[0] for t in tabs]))
    table.flags.writeable = False  # cached; and the kernels' type of a table (as NO_TABLE)
    return table, fall


def mechanism_table(mechanism, n: int = 4001, phi_fall: float | None = None):
    """The table of a :class:`~rockstudy.structures.Mechanism` and its collapse amplitude.

    Returns
    -------
    (table, phi_fall)
        ``table`` has the columns of ``_rocking.TAB_*`` on n nodes in [0, phi_fall]. Where the
        kinematics end before min(phi_max, pi/2) (a linkage locks), phi_fall is moved there.
    """
    if phi_fall is None:
        phi_fall = min(mechanism.phi_max, math.pi / 2)
    phi = np.linspace(0.0, phi_fall, n)
    with np.errstate(all="ignore"):
        t = mechanism.terms(phi)
    cols = [phi, t["I"], t["dI"], t["G"], t["dG"], t["B"], t["dB"], t["V"], -t["G"]]
    tab = np.column_stack([np.broadcast_to(np.asarray(c, float), phi.shape) for c in cols])
    bad = np.flatnonzero(~np.all(np.isfinite(tab), axis=1) | (tab[:, _rocking.TAB_I] <= 0))
    if bad.size:
        if bad[0] < 10:
            raise ValueError("the mechanism's kinematics fail right after phi = 0")
        return mechanism_table(mechanism, n, float(phi[bad[0] - 1]))
    return np.ascontiguousarray(tab), float(phi_fall)
