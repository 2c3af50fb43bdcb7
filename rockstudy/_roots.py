"""The safeguarded Newton-bisection root finder, written once (private).

Every scalar root of the package (impacts, turning points and overturning of the kernels, the
first impact of the closed forms, the critical rotation of a mechanism, the peak of an
oscillator inside a step) is located by :func:`newton_bisect`: Newton steps from a bracket
that every iterate shrinks, with a bisection wherever Newton would leave it. It converges
quadratically near a simple root and never leaves the bracket.

``fdf`` is a module-level numba-jitted function ``fdf(x, args) -> (f, f')`` and ``args`` a
tuple of its parameters. :func:`newton_bisect` is inlined into each caller at numba's IR level
(``inline="always"``), so ``fdf`` becomes a direct call: the loop costs what a hand-written copy
does, and the caller stays in numba's on-disk cache (a jitted function passed to a separately
compiled function is typed by its address, which makes the caller uncachable and recompiles it
in every process; numba issues 2956 and 6972). From Python, with a Python ``fdf``, call
``newton_bisect.py_func``.
"""

from __future__ import annotations

from numba import njit

#: Cap on the halvings of a bisection of a time bracket down to adjacent doubles (where the
#: loops stop: about 50 for a bracket of seconds); the cap only guards against an endless loop.
ULP_BISECTIONS = 2000


@njit(cache=True, inline="always")
def newton_bisect(fdf, args, lo, hi, x0, sign_lo, tol, max_iter):
    """The root in [lo, hi] of f, where f changes sign, by Newton steps kept in the bracket.

    Parameters
    ----------
    fdf : callable
        ``fdf(x, args)`` returns f(x) and f'(x) (f' = 0 makes that step a bisection).
    args : tuple
        The parameters passed to ``fdf``.
    lo, hi : float
        The bracket: ``sign_lo * f >= 0`` at lo, < 0 at hi.
    x0 : float
        The first iterate, in [lo, hi] (the midpoint, or a better guess).
    sign_lo : float
        +1.0 where f >= 0 on the lo side of the root, -1.0 where f <= 0 there.
    tol : float
        Stop when a step or the bracket is below ``tol * max(1, |x|)`` (in the units of x).
    max_iter : int
        Cap on the evaluations of ``fdf``; the last iterate is returned when it is reached.

    Returns
    -------
    float
        The root (the last Newton or bisection iterate).
    """
    x = x0
    start = lo
    for _ in range(max_iter):
        f, df = fdf(x, args)
        near = sign_lo * f >= 0.0
        if near:
            lo = x
        else:
            hi = x
        xn = x - f / df if df != 0.0 else 0.5 * (lo + hi)
        # converged: a Newton step below tol from the far side, or from the near side towards
        # the far one. Not a near-side step that points back (f rising from 0 just past a start
        # at contact or a turning point: its tiny f / f' says nothing of the crossing sought
        # further on), nor one from the bracket's start (f = 0 there may be a start at contact,
        # theta = 0 right after an impact). A near-side step that rounds to nothing would
        # otherwise fail the bracket test below and fall to bisection from the far end: some
        # 30 evaluations instead of 2.
        forward = not near or (x != start and sign_lo * df < 0.0)
        if abs(xn - x) <= tol * max(1.0, abs(x)) and forward:
            return min(max(xn, lo), hi)
        if not lo < xn < hi:
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= tol * max(1.0, abs(x)) or hi - lo <= tol * max(1.0, abs(hi)):
            return xn
        x = xn
    return x
