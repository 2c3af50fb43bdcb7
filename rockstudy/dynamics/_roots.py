"""The safeguarded Newton-bisection iteration shared by the kernels' root finders (private).

Each finder evaluates its own function (a quintic Hermite interpolant, a step polynomial)
and hands the value and slope to :func:`newton_bisect_update`, which keeps the bracket and
chooses the next point.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def newton_bisect_update(x, f, df, sgn, lo, hi, tol):
    """One iteration towards the root in [lo, hi] where sgn * f changes from >= 0 (at lo) to
    < 0 (at hi), given f and its slope df at x: the bracket shrinks to the side of x that
    keeps the change, then a Newton step, or a bisection where Newton leaves the bracket.

    Returns (next x, lo, hi, converged): converged once the step or the bracket is <= tol.
    """
    if sgn * f >= 0.0:
        lo = x
    else:
        hi = x
    xn = x - f / df if df != 0.0 else 0.5 * (lo + hi)
    if not lo < xn < hi:
        xn = 0.5 * (lo + hi)
    return xn, lo, hi, abs(xn - x) <= tol or hi - lo <= tol
