"""Error bounds behind ``method="auto"``: which model a scene needs (issue 6).

The linearization error of eq. (3.1) of [000] against Housner's eq. (2.2) scales as alpha^2
(both equations differ by sin x - x and cos x - 1 with |x| <= alpha, and the uplift levels by
tan alpha - alpha). For a trigonometric pulse of one cycle it is therefore

    |theta_max,lin / theta_max - 1| <= K(shape, eta, psi, omega) alpha^2,
    psi = |a_g| / (g tan alpha),  omega = omega_g / p,

with K measured on a grid by :func:`rockstudy.dynamics.accuracy.linearization_error_map` and
stored as the largest value in each cell (``rockstudy/data/linearization_bound.npz``;
regenerate with ``python -m rockstudy.dynamics.accuracy``). A cell where the two models
disagree on overturning anywhere holds K = inf: the linear model is never used there.
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numpy as np

TABLE = Path(__file__).resolve().parents[1] / "data" / "linearization_bound.npz"

#: Factor on the tabulated bound (the table is a cell maximum on a finite grid).
SAFETY = 2.0

#: The kernel's max-rotation error on the work-precision set is below 3 rtol at p99 and
#: below 90 rtol at worst; ``auto`` runs it at this fraction of the accuracy asked for.
KERNEL_RTOL_FRACTION = 0.05
KERNEL_RTOL_RANGE = (1e-12, 1e-3)

#: Largest slenderness in the table [rad]; beyond it the linear model is never chosen.
LINEAR_ALPHA_MAX = 0.3

#: Codes of the ``model`` output of :func:`rockstudy.simulate_batch`.
MODEL_REST, MODEL_LINEAR, MODEL_NONLINEAR = 0, 1, 2
MODEL_NAMES = {MODEL_REST: "rest (no uplift)", MODEL_LINEAR: "linear", MODEL_NONLINEAR: "nonlinear"}


@lru_cache(maxsize=1)
def bound_table() -> dict:
    """The stored table: ``K`` on cells (shape, eta, alpha, psi, omega) and the node axes."""
    with np.load(TABLE) as z:
        return {k: z[k] for k in z.files}


def kernel_rtol(tolerance):
    """Integrator rtol that keeps the kernel's max-rotation error below ``tolerance``."""
    lo, hi = KERNEL_RTOL_RANGE
    return float(min(max(KERNEL_RTOL_FRACTION * tolerance, lo), hi))


#: Below this max rotation / alpha the kernel's error is set by its absolute scale (1e-3 alpha):
#: on chattering scenes its relative error grows as rtol alpha / theta_max, so ``auto`` runs
#: such rows again at an rtol scaled by theta_max / (SMALL_ROTATION alpha).
SMALL_ROTATION = 0.1


def kernel_rtol_small(tolerance, rotation_ratio):
    """Integrator rtol for a second run of rows whose max rotation / alpha came out below
    SMALL_ROTATION (array in, array out; rounded down to a power of ten, so that the rows
    run in a few groups)."""
    scale = np.clip(np.asarray(rotation_ratio) / SMALL_ROTATION, 1e-4, 1.0)
    rtol = np.maximum(kernel_rtol(tolerance) * scale, KERNEL_RTOL_RANGE[0])
    return 10.0 ** np.floor(np.log10(rtol))


def _cell(nodes, x):
    """Index of the cell [nodes[i], nodes[i + 1]] holding x, or -1 outside the nodes."""
    i = np.searchsorted(nodes, x, side="right") - 1
    inside = (x >= nodes[0]) & (x <= nodes[-1])
    return np.where(inside, np.clip(i, 0, nodes.size - 2), -1)


def _bracket(nodes, x):
    """The two nodes around x (the same node twice at or beyond the ends); -1 above."""
    hi = np.searchsorted(nodes, x, side="left")
    lo = np.clip(hi - 1, 0, nodes.size - 1)
    hi = np.where(hi >= nodes.size, -1, hi)
    return np.where(x <= nodes[0], 0, lo), hi


def linearization_bound(shape, restitution, slenderness, psi, omega):
    """Upper bound of the relative max-rotation error of the linear model (inf if none).

    Parameters
    ----------
    shape : {"sine", "cosine", "half-sine"}
        One-cycle trigonometric pulse.
    restitution, slenderness, psi, omega : array_like
        eta, alpha [rad], |a_g| / (g tan alpha) and omega_g / p, broadcast together.

    Returns
    -------
    ndarray
        SAFETY K alpha^2 from the stored cell maxima; inf where the table has no bound
        (outside its range, or a cell where the models disagree on overturning).
    """
    tab = bound_table()
    shapes = [str(s) for s in tab["shapes"]]
    eta, alpha, psi, omega = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in (restitution, slenderness, psi, omega))
    )
    if shape not in shapes:
        return np.full(eta.shape, np.inf)
    K = tab["K"][shapes.index(shape)]
    ip, iw = _cell(tab["psi"], psi), _cell(tab["omega"], omega)
    e0, e1 = _bracket(tab["eta"], eta)
    a0, a1 = _bracket(tab["alpha"], alpha)
    out = np.full(eta.shape, np.inf)
    ok = (ip >= 0) & (iw >= 0) & (e1 >= 0) & (a1 >= 0) & (eta >= tab["eta"][0])
    if ok.any():
        i, j = ip[ok], iw[ok]
        k = np.maximum.reduce([K[e, a, i, j] for e in (e0[ok], e1[ok]) for a in (a0[ok], a1[ok])])
        out[ok] = SAFETY * k * alpha[ok] ** 2
    return out


def trig_uplifts(psi):
    """Whether a one-cycle trigonometric pulse of peak ratio psi lifts the block: the ground
    must exceed g tan(alpha), eq. (2.3) of [000]; below it the block stays at rest."""
    return np.asarray(psi) > 1.0


def peak_ratio(amplitude, slenderness, g):
    """psi = |a_g| / (g tan alpha)."""
    return np.abs(amplitude) / (g * np.tan(slenderness))


def angular_frequency_ratio(period, frequency_parameter):
    """omega = omega_g / p = 2 pi / (T_p p)."""
    return 2.0 * math.pi / (np.asarray(period) * np.asarray(frequency_parameter))
