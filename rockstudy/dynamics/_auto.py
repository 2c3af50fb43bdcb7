"""Error bounds behind ``method="auto"``: which model a scene needs.

The linearization error of eq. (3.1) of [000] against Housner's eq. (2.2) scales as alpha^2
(both equations differ by sin x - x and cos x - 1 with |x| <= alpha, and the uplift levels by
tan alpha - alpha). For a trigonometric pulse of one cycle it is therefore

    |theta_max,lin / theta_max - 1| <= K(shape, eta, psi, omega) alpha^2,
    psi = |a_g| / (g tan alpha),  omega = omega_g / p,

with K measured on a grid by :func:`rockstudy.verification.accuracy.linearization_error_map` and
stored per cell (``rockstudy/data/linearization_bound.npz``; regenerate with
``python -m rockstudy.verification.accuracy``). A cell holds a finite K only where every
sample of the cell and of its eight neighbour cells survives in both models; K = inf
elsewhere, and the linear model is never used there. Overturning regions are left to the
kernel because they hold thin safe tongues narrower than any affordable grid.

What ``rtol`` covers (:data:`COVERED_OUTPUTS`): the relative error of the max rotation and
the overturning decision. ``overturn_time``, ``first_impact_time`` and ``n_impacts`` are
not bounded by the linear model's table, so ``auto`` runs the kernel on every row where a
caller asks for them. ``rtol`` is a measured accuracy, not a proven bound: the measurement
against scipy's solve_ivp, its quantiles and the scenes it cannot judge (a reference that
has not converged on chattering responses) are in docs/methods.rst
(``benchmarks/bench_auto_vs_scipy.py``).
"""

from __future__ import annotations

import warnings
from functools import lru_cache
from pathlib import Path

import numpy as np
from numba import njit

from .._warnings import LooseToleranceWarning

TABLE = Path(__file__).resolve().parents[1] / "data" / "linearization_bound.npz"

#: Factor on the tabulated bound (the table is a cell maximum on a finite grid).
SAFETY = 2.0

#: The kernel's max-rotation error on the work-precision set is below 3 rtol at p99 and
#: below 90 rtol at worst; ``auto`` runs it at this fraction of the accuracy asked for.
KERNEL_RTOL_FRACTION = 0.05
KERNEL_RTOL_RANGE = (1e-12, 1e-3)

#: ``auto`` never runs the kernel looser than this. Marginal scenes decide overturning on
#: digits the max-rotation accuracy does not need: theta_max within 1 % of alpha, or
#: chattering through thousands of impacts under long cosine pulses just above uplift. At
#: kernel rtol 5e-4 (auto at 1e-2) 8 robust decisions were wrong on the 400 x 400 grids of
#: benchmarks/bench_auto_decisions.py, none at 5e-6; the kernel's cost hardly
#: changes between the two (0.16 ms per work-precision scene at 1e-4 and at 1e-6).
KERNEL_RTOL_DECISIONS = 5e-6

#: Outputs whose accuracy ``rtol`` states for method="auto" (the table bounds these only).
COVERED_OUTPUTS = ("max_rotation", "overturned")
#: Outputs that say what ran, not what the block did: any model may produce them.
BOOKKEEPING_OUTPUTS = ("status", "steps", "model")

#: Codes of the ``model`` output of :func:`rockstudy.simulate_batch`.
MODEL_REST, MODEL_LINEAR, MODEL_NONLINEAR = 0, 1, 2
MODEL_NAMES = {MODEL_REST: "rest (no uplift)", MODEL_LINEAR: "linear", MODEL_NONLINEAR: "nonlinear"}


@lru_cache(maxsize=1)
def bound_table() -> dict:
    """The stored table: ``K`` on cells (shape, eta, alpha, psi, omega) and the node axes."""
    with np.load(TABLE) as z:
        tab = {k: z[k] for k in z.files}
    tab["K"] = tab["K"].astype(float)
    tab["shape_index"] = {str(s): i for i, s in enumerate(tab["shapes"])}
    return tab


def warn_loose_tolerance(rtol):
    """Warn when the kernel runs above the tolerances measured in the failure maps."""
    if rtol > KERNEL_RTOL_RANGE[1]:
        warnings.warn(
            f"rtol = {rtol:g} is looser than 1e-3, the loosest tolerance at which every step of "
            "the nonlinear kernel was measured reliable: above it, with DOP853 steps (the "
            "Ricker wavelet, mechanisms), chattering scenes just above uplift got the "
            "overturning decision wrong (0.7 % of them at rtol 1e-2, 2.5 % at 1e-1 under sine "
            "pulses; none at 1e-3); use method='auto' with rtol = the accuracy you need",
            LooseToleranceWarning,
            stacklevel=3,
        )


def kernel_rtol(tolerance):
    """Integrator rtol that keeps the kernel's max-rotation error below ``tolerance`` and its
    overturning decisions right (at most :data:`KERNEL_RTOL_DECISIONS`)."""
    lo = KERNEL_RTOL_RANGE[0]
    return float(min(max(KERNEL_RTOL_FRACTION * tolerance, lo), KERNEL_RTOL_DECISIONS))


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


@njit(cache=True)
def _cell(nodes, x):
    """Index of the cell [nodes[i], nodes[i + 1]] holding x, or -1 outside the nodes."""
    if not nodes[0] <= x <= nodes[-1]:
        return -1
    return min(max(np.searchsorted(nodes, x, side="right") - 1, 0), nodes.size - 2)


@njit(cache=True)
def _bracket(nodes, x):
    """The nodes around x (the first node twice at or below it); (-1, -1) above the last."""
    if x <= nodes[0]:
        return 0, 0
    hi = np.searchsorted(nodes, x, side="left")
    return (-1, -1) if hi >= nodes.size else (hi - 1, hi)


@njit(cache=True)
def _lookup(K, eta_n, alpha_n, psi_n, omega_n, eta, alpha, psi, omega, out):
    """Largest tabulated K over the cell of (psi, omega) and the nodes around eta and alpha."""
    for i in range(eta.size):
        ip, iw = _cell(psi_n, psi[i]), _cell(omega_n, omega[i])
        e0, e1 = _bracket(eta_n, eta[i])
        a0, a1 = _bracket(alpha_n, alpha[i])
        if ip < 0 or iw < 0 or e1 < 0 or a1 < 0 or eta[i] < eta_n[0]:
            out[i] = np.inf
            continue
        k = max(K[e0, a0, ip, iw], K[e0, a1, ip, iw], K[e1, a0, ip, iw], K[e1, a1, ip, iw])
        out[i] = SAFETY * k * alpha[i] ** 2


def largest_slenderness():
    """Largest alpha [rad] in the table; beyond it the linear model is never chosen."""
    return float(bound_table()["alpha"][-1])


def table_covers(restitution, slenderness, psi, omega):
    """Whether (eta, alpha, psi, omega) lies inside the table's ranges (scalars)."""
    tab = bound_table()
    return bool(
        tab["eta"][0] <= restitution <= tab["eta"][-1]
        and slenderness <= largest_slenderness()
        and tab["psi"][0] <= psi <= tab["psi"][-1]
        and tab["omega"][0] <= omega <= tab["omega"][-1]
    )


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
    args = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in (restitution, slenderness, psi, omega))
    )
    out = np.full(args[0].shape, np.inf)
    if shape in tab["shape_index"]:
        flat = [np.array(a).ravel() for a in args]  # writable copies: one kernel signature
        res = np.empty(flat[0].size)
        K = tab["K"][tab["shape_index"][shape]]
        _lookup(K, tab["eta"], tab["alpha"], tab["psi"], tab["omega"], *flat, res)
        out = res.reshape(out.shape)
    return out
