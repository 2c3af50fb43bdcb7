"""A mechanism's tables (private): eq. (8) of [003] on tabulated I, G, B and V.

Cubic Hermite interpolation of the columns (:func:`_hermite3`), the mechanism's u''
(:func:`_mechanism_accel`, called by the one right-hand side :func:`._rhs._accel`), its
critical rotation and the free-rocking map on its energy (:func:`_free_map_table`).
"""

from __future__ import annotations

import math

from numba import njit

from ..constants import G
from ._free_map import _impacts_until_rest
from ._taylor import NO_REFCOUNT
from .constants import (
    TAB_B,
    TAB_DB,
    TAB_DG,
    TAB_DI,
    TAB_DV,
    TAB_G,
    TAB_I,
    TAB_PHI,
    TAB_V,
    TABLE_BISECTIONS,
)


@njit(cache=True, inline="always")
def _hermite3(u, tab, col, dcol):
    """Cubic Hermite value and derivative of table column ``col`` (derivative ``dcol``) at u."""
    n = tab.shape[0]
    dphi = tab[1, TAB_PHI] - tab[0, TAB_PHI]
    i = min(max(int(u / dphi), 0), n - 2)
    x = (u - tab[i, TAB_PHI]) / dphi
    y0, y1 = tab[i, col], tab[i + 1, col]
    d0, d1 = tab[i, dcol] * dphi, tab[i + 1, dcol] * dphi
    x2 = x * x
    x3 = x2 * x
    val = (
        (2 * x3 - 3 * x2 + 1) * y0
        + (x3 - 2 * x2 + x) * d0
        + (-2 * x3 + 3 * x2) * y1
        + (x3 - x2) * d1
    )
    der = ((6 * x2 - 6 * x) * (y0 - y1) + (3 * x2 - 4 * x + 1) * d0 + (3 * x2 - 2 * x) * d1) / dphi
    return val, der


@njit(cache=True, **NO_REFCOUNT)
def _mechanism_accel(u, v, a_g, a_v, tab):
    """u'' of a mechanism from eq. (8) of [003]: I u'' + I'/2 u'^2 - G (g + a_v) = -B a_g.

    The vertical ground acceleration a_v [m/s^2, upwards] enters as gravity does: in the
    frame of the base every mass feels g + a_v downwards, so G g of eq. (8), the generalized
    force of the weights (-dV/dphi, V = g sum m_i y_i), becomes G (g + a_v).
    """
    inertia, d_inertia = _hermite3(u, tab, TAB_I, TAB_DI)
    g_nl = _hermite3(u, tab, TAB_G, TAB_DG)[0]
    b_nl = _hermite3(u, tab, TAB_B, TAB_DB)[0]
    return (g_nl * (G + a_v) - 0.5 * d_inertia * v * v - b_nl * a_g) / inertia


@njit(cache=True)
def _potential_level(level, lo, hi, tab):
    """u in [lo, hi] where V(u) = level, V increasing there (bisection on the table)."""
    for _ in range(TABLE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _hermite3(mid, tab, TAB_V, TAB_DV)[0] < level:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def _critical(tab):
    """phi_cr of a table: where G changes sign (bisection on the Hermite interpolant)."""
    g = tab[:, TAB_G]
    i = 0
    while i < g.shape[0] - 1 and g[i + 1] < 0.0:
        i += 1
    lo, hi = tab[i, TAB_PHI], tab[min(i + 1, g.shape[0] - 1), TAB_PHI]
    for _ in range(TABLE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _hermite3(mid, tab, TAB_G, TAB_DG)[0] < 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def _free_map_table(u, v, eta, tab, other, omega_rest):
    """:func:`free_rocking_map` for a tabulated mechanism: E = I(u) v^2 / 2 + g V(u) on this
    side's table, the other side's after an impact; the speed at the pivot is multiplied by
    eta at each impact. Returns (overturns, peak, impacts)."""
    fall = tab[-1, TAB_PHI]
    phi_cr = _critical(tab)
    barrier = _hermite3(phi_cr, tab, TAB_V, TAB_DV)[0]
    e = 0.5 * _hermite3(u, tab, TAB_I, TAB_DI)[0] * v * v / G + _hermite3(u, tab, TAB_V, TAB_DV)[0]
    peak = u
    if e >= barrier:
        if (u < phi_cr and v > 0.0) or (u >= phi_cr and v >= 0.0):
            return True, fall, 0
    elif u > phi_cr:
        return True, fall, 0
    elif v > 0.0:
        peak = _potential_level(e, u, phi_cr, tab)
    w = math.sqrt(max(2.0 * G * (e - tab[0, TAB_V]) / tab[0, TAB_I], 0.0))  # impact speed
    w1 = eta * w
    e1 = 0.5 * other[0, TAB_I] * w1 * w1 / G + other[0, TAB_V]
    phi_cr1 = _critical(other)
    if e1 >= _hermite3(phi_cr1, other, TAB_V, TAB_DV)[0]:
        return True, fall, 1
    peak = max(peak, _potential_level(e1, 0.0, phi_cr1, other))
    return False, peak, _impacts_until_rest(w1, omega_rest, eta)
