"""One-degree-of-freedom rocking mechanisms and their rocking parameters (paper [003], sec. 3).

A mechanism is a set of rigid bodies (mass, moment of inertia about the centre of mass) whose
poses are functions of the rocking amplitude phi >= 0 in one direction: a function
``pose(phi)`` returns, for each body, the position (x, y) of its centre of mass and its rotation
angle, as :class:`~rockstudy.structures._jet.Jet` objects, so that every derivative below is
exact. From the kinematics alone (Lagrange, eq. 7 of [003]):

- I_nl = sum m |r_G'|^2 + I_G beta'^2, J_nl = I_nl' / 2, G_nl = -V' / g, B_nl = sum m x_G'
  (eq. 8, with the ground acceleration pushing in -x);
- phi_cr from V'(phi_cr) = 0 (eq. 9) and lambda = G_nl(0) / B_nl(0) (eq. 10);
- the linearization at phi_cr (eqs. 11-13): I_eq, G_eq = -V''(phi_cr) / g, B_eq;
- kappa_1 = B_eq / G_eq (15, 19), kappa_2 = phi_cr / lambda (20), p_eq = sqrt(g G_eq / I_eq)
  and theta_cr = phi_cr / kappa (17), lambda_lin = G_eq phi_cr / B_eq (18).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .. import _validate
from ..constants import G
from ._jet import Jet

__all__ = [
    "CRITICAL_MAX_ITER",
    "CRITICAL_ROTATION_TOL",
    "EquivalentBlock",
    "Mechanism",
    "Pose",
    "RockingParameters",
]

# phi_cr to rounding [rad]: every rocking parameter of the equivalent block is read at it.
CRITICAL_ROTATION_TOL = 1e-15
# The bracket is one step of a 2001-point grid; Newton converges in about 5 evaluations of the
# kinematics, bisection alone in about 40 (each evaluation is a Python call on the linkage).
CRITICAL_MAX_ITER = 50


@dataclass(frozen=True)
class RockingParameters:
    """The rocking parameters of one direction of a structure (paper [003], sec. 2-3).

    Attributes
    ----------
    frequency_parameter : float
        p_eq [rad/s], eq. (17).
    critical_rotation : float
        phi_cr [rad], the mechanism's rotation at unstable equilibrium, eq. (9).
    uplift : float
        lambda = u_g,min'' / g, eq. (10).
    uplift_linearized : float
        lambda_lin, eq. (18).
    restitution : float
        eta.
    scale : float
        kappa_1 = B_eq / G_eq, eq. (15): theta = phi / kappa (14).
    """

    frequency_parameter: float
    critical_rotation: float
    uplift: float
    uplift_linearized: float
    restitution: float
    scale: float

    @property
    def kappa1(self) -> float:
        """kappa_1 = B_eq / G_eq, eqs. (15), (19) of [003]."""
        return self.scale

    @property
    def kappa2(self) -> float:
        """kappa_2 = phi_cr / lambda, eq. (20) of [003]."""
        return self.critical_rotation / self.uplift

    def equivalent_block(self, kappa: Literal["kappa1", "kappa2"] = "kappa1") -> EquivalentBlock:
        """The equivalent rocking block: p_eq, theta_cr = phi_cr / kappa, eta (eq. 16-17).

        ``kappa1`` keeps the linearized dynamics at phi_cr; ``kappa2`` also keeps the exact
        uplift acceleration (the linearized block lifts off at g theta_cr = g lambda).
        """
        k = {"kappa1": self.kappa1, "kappa2": self.kappa2}
        if kappa not in k:
            raise ValueError(f"kappa must be one of {sorted(k)}, got {kappa!r}")
        return EquivalentBlock(
            self.frequency_parameter, self.critical_rotation / k[kappa], self.restitution, k[kappa]
        )


@dataclass(frozen=True)
class EquivalentBlock:
    """A block given by its rocking parameters; :func:`rockstudy.simulate` accepts it.

    ``slenderness`` is theta_cr [rad]; ``scale`` is the kappa that maps the block's theta to the
    structure's phi = kappa theta (eq. 14 of [003]).
    """

    frequency_parameter: float
    slenderness: float
    restitution: float
    scale: float = 1.0

    def __post_init__(self):
        _validate.positive("frequency_parameter", self.frequency_parameter)
        _validate.in_open_interval(
            "slenderness", self.slenderness, 0.0, math.pi / 2, "(0, pi/2) rad (theta_cr)"
        )
        _validate.restitution(self.restitution)
        _validate.positive("scale", self.scale)


Pose = Callable[[Jet], tuple[list[Jet], list[Jet], list[Jet]]]


@dataclass(frozen=True)
class Mechanism:
    """A one-DOF mechanism in one rocking direction.

    Parameters
    ----------
    masses : sequence of float
        Body masses [kg] (any consistent unit: only ratios matter for the parameters).
    inertias : sequence of float
        Moments of inertia about each centre of mass [kg m^2].
    pose : callable
        ``pose(phi) -> (x_G, y_G, beta)``, lists of jets per body [m, m, rad].
    phi_max : float
        Largest amplitude at which the kinematics hold [rad].
    """

    masses: tuple
    inertias: tuple
    pose: Pose
    phi_max: float = math.pi / 2

    def terms(self, phi) -> dict:
        """I_nl, J_nl, G_nl, B_nl of eq. (8), V / g = sum m y_G and X = sum m x_G, with
        phi-derivatives, at phi."""
        xs, ys, betas = self.pose(Jet.variable(phi))
        inertia = 0.0
        inertia_d = 0.0
        b = 0.0
        b_d = 0.0
        v = 0.0
        v_d = 0.0
        v_dd = 0.0
        x_sum = 0.0
        for m, ig, x, y, beta in zip(self.masses, self.inertias, xs, ys, betas, strict=True):
            inertia = inertia + m * (x.d1**2 + y.d1**2) + ig * beta.d1**2
            inertia_d = inertia_d + 2 * m * (x.d1 * x.d2 + y.d1 * y.d2) + 2 * ig * beta.d1 * beta.d2
            b = b - m * x.d1
            b_d = b_d - m * x.d2
            v = v + m * y.value
            x_sum = x_sum + m * x.value
            v_d = v_d + m * y.d1
            v_dd = v_dd + m * y.d2
        return {
            "I": inertia,
            "dI": inertia_d,
            "J": 0.5 * inertia_d,
            "G": -v_d,
            "dG": -v_dd,
            "B": b,
            "dB": b_d,
            "V": v,
            "X": x_sum,
        }

    def critical_rotation(self) -> float:
        """phi_cr: the first root of V' in (0, phi_max), eq. (9) of [003]."""
        # the grid starts at phi = 0, where G_nl(0) = -lambda B_nl(0) < 0 for any lambda > 0:
        # phi_cr -> 0 with lambda (thin arches), so it may lie before the first grid step
        grid = np.linspace(0.0, self.phi_max, 2001)
        with np.errstate(invalid="ignore"):  # a linkage may lock before phi_max: NaN there
            g = self.terms(grid)["G"]
        if not g[0] < 0:
            raise ValueError(
                "the mechanism is not stable at rest (G_nl(0) >= 0: uplift multiplier lambda <= 0)"
            )
        sign = np.flatnonzero(g[1:] >= 0)
        if sign.size == 0:
            raise ValueError("no unstable equilibrium within the kinematic range")
        lo, hi = grid[sign[0]], grid[sign[0] + 1]
        from .._roots import newton_bisect  # here: importing the structures loads no numba

        def g_and_slope(x, _):
            t = self.terms(np.array([x]))
            return float(t["G"][0]), float(t["dG"][0])

        # Newton on G with its exact derivative, kept in the bracket (G < 0 below phi_cr)
        return newton_bisect.py_func(
            g_and_slope, (), lo, hi, 0.5 * (lo + hi), -1.0, CRITICAL_ROTATION_TOL, CRITICAL_MAX_ITER
        )

    def rocking_parameters(self, restitution: float) -> RockingParameters:
        """The rocking parameters of this direction (eqs. 9-20 of [003])."""
        t0 = self.terms(np.array([0.0]))
        uplift = float(-t0["G"][0] / t0["B"][0])
        phi_cr = self.critical_rotation()
        t = self.terms(np.array([phi_cr]))
        i_eq, g_eq, b_eq = float(t["I"][0]), float(t["dG"][0]), float(t["B"][0])
        if not g_eq > 0:
            raise ValueError("the equilibrium at phi_cr is not unstable (G_eq <= 0)")
        return RockingParameters(
            frequency_parameter=math.sqrt(G * g_eq / i_eq),
            critical_rotation=float(phi_cr),
            uplift=uplift,
            uplift_linearized=float(g_eq * phi_cr / b_eq),
            restitution=float(restitution),
            scale=b_eq / g_eq,
        )
