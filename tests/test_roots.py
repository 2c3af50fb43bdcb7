"""The one safeguarded Newton-bisection root finder (rockstudy/_roots.py), against roots known in
closed form or published: the Dottie number (cos x = x), tan(1/2) (atan x = 1/2, where Newton
alone diverges from the bracket's end), a cube root from a flat start, and the bracket kept
whatever the iteration cap."""

import math

import pytest
from numba import njit

from rockstudy._roots import newton_bisect

DOTTIE = 0.7390851332151606416553120876738734  # the root of cos x = x (OEIS A003957)


def cos_minus_x(x, _):
    return math.cos(x) - x, -math.sin(x) - 1.0


def atan_minus_half(x, _):
    return math.atan(x) - 0.5, 1.0 / (1.0 + x * x)


def cube_minus(x, args):
    return x**3 - args[0], 3.0 * x * x


def one_minus_square(x, _):
    return 1.0 - x * x, -2.0 * x


@pytest.mark.parametrize(
    "fdf, args, lo, hi, x0, sign_lo, root",
    [
        (cos_minus_x, (), 0.0, 1.0, 0.5, 1.0, DOTTIE),
        # Newton alone from x = 10 jumps to about -88 and diverges: the bracket must hold it
        (atan_minus_half, (), -10.0, 10.0, 10.0, -1.0, math.tan(0.5)),
        # f' = 0 at the start: that step is a bisection
        (cube_minus, (8.0,), 0.0, 5.0, 0.0, -1.0, 2.0),
        (one_minus_square, (), 0.0, 3.0, 1.5, 1.0, 1.0),
    ],
)
def test_roots_known_in_closed_form(fdf, args, lo, hi, x0, sign_lo, root):
    x = newton_bisect.py_func(fdf, args, lo, hi, x0, sign_lo, 1e-16, 100)
    assert x == pytest.approx(root, rel=4e-16, abs=4e-16)


@pytest.mark.parametrize("max_iter", [1, 2, 3, 5])
def test_the_cap_returns_a_point_of_the_bracket(max_iter):
    x = newton_bisect.py_func(atan_minus_half, (), -10.0, 10.0, 10.0, -1.0, 1e-16, max_iter)
    assert -10.0 <= x <= 10.0


@njit
def _cos_minus_x(x, _):
    return math.cos(x) - x, -math.sin(x) - 1.0


@njit
def _atan_minus(x, args):
    return math.atan(x) - args[0], 1.0 / (1.0 + x * x)


@njit
def _jitted_roots():
    dottie = newton_bisect(_cos_minus_x, (), 0.0, 1.0, 0.5, 1.0, 1e-16, 100)
    tan_half = newton_bisect(_atan_minus, (0.5,), -10.0, 10.0, 10.0, -1.0, 1e-16, 100)
    return dottie, tan_half


def test_compiled_finder_inlined_into_a_kernel():
    dottie, tan_half = _jitted_roots()
    assert dottie == pytest.approx(DOTTIE, rel=4e-16)
    assert tan_half == pytest.approx(math.tan(0.5), rel=4e-16)


def _counted(fdf):
    calls = []

    def counted(x, args):
        calls.append(x)
        return fdf(x, args)

    return counted, calls


def exp_minus_inv_e(x, _):
    return math.exp(-x) - math.exp(-1.0), -math.exp(-x)


def test_a_root_reached_from_the_near_side_stops_there():
    """f = e^-x - e^-1 is convex and decreasing: Newton from the left stays left of the root
    (x = 1) and its last step rounds to nothing while f is still > 0. That is convergence,
    not a step out of the bracket to be replaced by bisections from the far end (which took
    some 30 evaluations)."""
    fdf, calls = _counted(exp_minus_inv_e)
    x = newton_bisect.py_func(fdf, (), 0.0, 3.0, 0.5, 1.0, 1e-16, 100)
    assert x == pytest.approx(1.0, rel=4e-16)
    assert len(calls) <= 8


def x_one_minus_x(x, _):
    return x * (1.0 - x), 1.0 - 2.0 * x


def test_a_zero_at_the_start_of_the_bracket_is_not_the_root():
    """f = 0 at the bracket's start (contact right after an impact) with the crossing sought
    further on (x = 1): a zero Newton step there is not convergence."""
    x = newton_bisect.py_func(x_one_minus_x, (), 0.0, 2.0, 0.0, 1.0, 1e-16, 100)
    assert x == pytest.approx(1.0, rel=4e-16)


@pytest.mark.parametrize("x0", [1e-300, 1e-18, 1e-17])
def test_a_step_back_towards_the_start_is_not_convergence(x0):
    """f = x (1 - x) rises from 0 at the bracket's start: from a first guess a few ulps past
    it, the near-side Newton step points back (f / f' ~ x0, below tol), which says nothing of
    the crossing sought at x = 1."""
    x = newton_bisect.py_func(x_one_minus_x, (), 0.0, 2.0, x0, 1.0, 1e-16, 100)
    assert x == pytest.approx(1.0, rel=4e-16)
