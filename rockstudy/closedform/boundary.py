"""Overturning boundaries in the (a, omega) plane of [000] (Fig. 4), found as roots of the
closed-form residuals of :mod:`rockstudy.closedform.sine`."""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit, prange

from . import sine

__all__ = ["Case", "overturning_boundary"]

Case = Literal["2", "1.2", "1.1", "1.1-approx", "limit"]


@njit(cache=True)
def _residual(case, a, w, eta):
    if case == 0:
        return w - np.sqrt(a * a - 1.0) + a * np.exp(-sine._tau_ex(a, w))
    if case == 1:
        return eta * eta * (1.0 - sine._d0(a, w)) - 1.0
    if case == 2:
        return sine._case11_lhs(a, w, eta, sine._tau_i1(a, w))
    if case == 3:
        return sine._case11_lhs(a, w, eta, sine._tau_i1_hat(a, w))
    A, B, C = sine._abc(a, w)
    e = np.exp(sine._tau_ex(a, w))
    return A / e + B * e - 2.0


@njit(cache=True)
def _region_ok(case, a, w):
    """Each residual describes the boundary only inside its own region of [000] Fig. 4."""
    if case == 4:
        return True
    A, B, C = sine._abc(a, w)
    e = np.exp(sine._tau_ex(a, w))
    impact_in_pulse = A / e + B * e - 2.0 >= 0.0
    return impact_in_pulse if case >= 2 else not impact_in_pulse


@njit(cache=True, parallel=True)
def _roots(case, omega, eta, a_grid, max_roots):
    out = np.full((omega.shape[0], max_roots), np.nan)
    for i in prange(omega.shape[0]):
        w = omega[i]
        n = 0
        r0 = _residual(case, a_grid[0], w, eta)
        for j in range(1, a_grid.shape[0]):
            r1 = _residual(case, a_grid[j], w, eta)
            if n < max_roots and r0 == r0 and r1 == r1 and (r0 < 0.0) != (r1 < 0.0):
                lo, hi, flo = a_grid[j - 1], a_grid[j], r0
                for _ in range(60):
                    mid = 0.5 * (lo + hi)
                    fm = _residual(case, mid, w, eta)
                    if fm != fm:
                        break
                    if (fm < 0.0) == (flo < 0.0):
                        lo, flo = mid, fm
                    else:
                        hi = mid
                a = 0.5 * (lo + hi)
                if _region_ok(case, a, w):
                    out[i, n] = a
                    n += 1
            r0 = r1
    return out


_CASES = {"2": 0, "1.2": 1, "1.1": 2, "1.1-approx": 3, "limit": 4}


def overturning_boundary(omega, eta=1.0, case: Case = "1.2", a_max=20.0, n_grid=400, max_roots=4):
    """Values of a on one boundary curve of [000] Fig. 4, for each omega.

    Parameters
    ----------
    omega : array_like
        omega_g / p values (> 0).
    eta : float
        Coefficient of restitution (cases 1.1 and 1.2).
    case : {"2", "1.2", "1.1", "1.1-approx", "limit"}
        Overturning without impact (3.10); after one impact following the pulse (3.18); after
        one impact during the pulse (3.20-3.21, or the semi-analytical 3.30); the limit
        tau_i = p T_ex between impacts during and after the pulse (3.31).
    a_max, n_grid : float, int
        The roots are bracketed on a geometric grid of ``n_grid`` values of a in (1, a_max].
    max_roots : int
        Columns of the result.

    Returns
    -------
    ndarray of shape (len(omega), max_roots)
        The roots in increasing a, NaN-padded; only roots inside the region where the curve is a
        boundary (impact during or after the pulse) are kept.
    """
    try:
        code = _CASES[case]
    except KeyError:
        raise ValueError(f"case must be one of {sorted(_CASES)}, got {case!r}") from None
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    if np.any(~(omega > 0)):
        raise ValueError("omega must be > 0")
    if not 0.0 < eta <= 1.0:
        raise ValueError(f"eta must lie in (0, 1], got {eta!r}")
    if not a_max > 1.0:
        raise ValueError(f"a_max must be > 1, got {a_max!r}")
    a_grid = 1.0 + np.geomspace(1e-6, a_max - 1.0, n_grid)
    return _roots(code, omega, float(eta), a_grid, int(max_roots))
