"""Truncated Taylor arithmetic (second order) for exact derivatives of mechanism kinematics.

A :class:`Jet` holds f, f' and f''/2 of a quantity with respect to the generalized coordinate,
as numpy arrays, so one evaluation over an array of coordinates gives values and exact first and
second derivatives (automatic differentiation, no finite differences).
"""

from __future__ import annotations

import numpy as np


class Jet:
    """c0 + c1 e + c2 e^2: a value and its first two Taylor coefficients."""

    __slots__ = ("c",)
    __array_ufunc__ = None  # numpy arrays defer to the Jet's reflected operators

    def __init__(self, c0, c1=0.0, c2=0.0):
        self.c = (
            np.asarray(c0, dtype=float),
            np.asarray(c1, dtype=float),
            np.asarray(c2, dtype=float),
        )

    @classmethod
    def variable(cls, x):
        """The independent variable at x: (x, 1, 0)."""
        x = np.asarray(x, dtype=float)
        return cls(x, np.ones_like(x), np.zeros_like(x))

    @property
    def value(self):
        return self.c[0]

    @property
    def d1(self):
        """First derivative."""
        return self.c[1]

    @property
    def d2(self):
        """Second derivative."""
        return 2.0 * self.c[2]

    def _compose(self, f0, f1, f2):
        """f(self) from f, f', f'' at self.value."""
        a0, a1, a2 = self.c
        return Jet(f0, f1 * a1, f1 * a2 + 0.5 * f2 * a1 * a1)

    @staticmethod
    def _lift(x):
        return x if isinstance(x, Jet) else Jet(x)

    def __add__(self, o):
        o = Jet._lift(o)
        return Jet(*(a + b for a, b in zip(self.c, o.c, strict=True)))

    __radd__ = __add__

    def __neg__(self):
        return Jet(*(-a for a in self.c))

    def __sub__(self, o):
        return self + (-Jet._lift(o))

    def __rsub__(self, o):
        return Jet._lift(o) - self

    def __mul__(self, o):
        o = Jet._lift(o)
        a, b = self.c, o.c
        return Jet(a[0] * b[0], a[0] * b[1] + a[1] * b[0], a[0] * b[2] + a[1] * b[1] + a[2] * b[0])

    __rmul__ = __mul__

    def __truediv__(self, o):
        o = Jet._lift(o)
        a, b = self.c, o.c
        c0 = a[0] / b[0]
        c1 = (a[1] - b[1] * c0) / b[0]
        c2 = (a[2] - b[1] * c1 - b[2] * c0) / b[0]
        return Jet(c0, c1, c2)

    def __rtruediv__(self, o):
        return Jet._lift(o) / self

    def __pow__(self, n):
        if n == 2:
            return self * self
        v = self.value
        return self._compose(v**n, n * v ** (n - 1), n * (n - 1) * v ** (n - 2))


def sin(a: Jet) -> Jet:
    s, c = np.sin(a.value), np.cos(a.value)
    return a._compose(s, c, -s)


def cos(a: Jet) -> Jet:
    s, c = np.sin(a.value), np.cos(a.value)
    return a._compose(c, -s, -c)


def sqrt(a: Jet) -> Jet:
    r = np.sqrt(a.value)
    return a._compose(r, 0.5 / r, -0.25 / (r * a.value))


def acos(a: Jet) -> Jet:
    v = a.value
    q = 1.0 - v * v
    return a._compose(np.arccos(v), -1.0 / np.sqrt(q), -v / q**1.5)


def atan2(y: Jet, x: Jet) -> Jet:
    """atan2 of jets: the angle at the base point plus atan(cross / dot) of the increments."""
    y, x = Jet._lift(y), Jet._lift(x)
    t0 = np.arctan2(y.value, x.value)
    cross = x.value * y - y.value * x
    dot = x.value * x + y.value * y
    u = cross / dot  # u.value == 0; atan(u) = u + O(u^3)
    return Jet(t0 + u.c[0], u.c[1], u.c[2])
