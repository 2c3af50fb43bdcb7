"""Structures that reduce to a rocking block (paper [003]): Table I, the wall, the arch.

Table I has no transcription; every entry here is derived by angular-momentum balance about the
new pivots (restitution) and by the mechanism kinematics (p, theta_cr, lambda):

- point mass on a rigid massless strut: p^2 = g / R, eta = cos 2 alpha;
- thin conical shell (a spire) of height H and base radius r: centre of mass at H/3, so
  R = sqrt(r^2 + H^2/9), alpha = atan(3 r / H); I_O = m (H^2/6 + 5 r^2/4), p^2 = g R / (I_O/m);
  eta = 1 - 2 m r^2 / I_O (the general result for a symmetric body on pivots at +-b);
- symmetric two-column frame with beam-to-columns mass ratio gamma: p^2 = (3g/4R) (1 + 2 gamma)
  / (1 + 3 gamma), eta = (1 - 3/2 sin^2 alpha + 3 gamma cos 2 alpha) / (1 + 3 gamma).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import combinations

import numpy as np

from .. import _validate
from ..constants import G
from . import _jet as jt
from .mechanism import Mechanism, RockingParameters

__all__ = [
    "Arch",
    "AsymmetricFrame",
    "ConicalShell",
    "four_bar_mechanism",
    "HINGE_TOLERANCE",
    "PointMassStrut",
    "restitution_symmetric_body",
    "RockingWall",
    "SymmetricFrame",
]


def _leaning(R, alpha, phi):
    """Centre of a body of half-diagonal R leaning over a pivot at the origin: (x, y)."""
    return R * jt.sin(alpha - phi), R * jt.cos(alpha - phi)


def restitution_symmetric_body(inertia_pivot: float, mass: float, half_base: float) -> float:
    r"""Restitution of a symmetric rigid body rocking on pivots at +-b, by angular-momentum
    balance about the new pivot (Housner 1963; [003] Table I):

    .. math:: \eta = 1 - 2 m b^2 / I_O
    """
    return 1.0 - 2.0 * mass * half_base**2 / inertia_pivot


class _Symmetric:
    """A structure rocking the same way in both directions."""

    def mechanism(self) -> Mechanism:
        raise NotImplementedError

    def restitution_value(self) -> float:
        raise NotImplementedError

    def rocking_parameters(self) -> RockingParameters:
        """The rocking parameters (one direction: the structure is symmetric)."""
        return self.mechanism().rocking_parameters(self.restitution_value())

    def equivalent_block(self, kappa="kappa1"):
        """The equivalent rocking block (see :meth:`RockingParameters.equivalent_block`)."""
        params = self.rocking_parameters()
        if not params.restitution > 0:
            raise ValueError(f"{type(self).__name__} needs a restitution (in (0, 1]) to rock")
        return params.equivalent_block(kappa)


@dataclass(frozen=True)
class PointMassStrut(_Symmetric):
    """A point mass on a rigid massless strut with a rigid base of half-width R sin(alpha)."""

    half_diagonal: float
    slenderness: float

    def __post_init__(self):
        _validate.positive("half_diagonal", self.half_diagonal)
        _validate.in_open_interval("slenderness", self.slenderness, 0, math.pi / 2, "(0, pi/2)")

    def mechanism(self):
        R, a = self.half_diagonal, self.slenderness

        def pose(phi):
            x, y = _leaning(R, a, phi)
            return [x], [y], [-phi]

        return Mechanism((1.0,), (0.0,), pose)

    def restitution_value(self):
        """eta = cos 2 alpha (angular momentum about the new pivot)."""
        return math.cos(2 * self.slenderness)


@dataclass(frozen=True)
class ConicalShell(_Symmetric):
    """A thin conical shell (e.g. a masonry spire) rocking on its base circle.

    Parameters
    ----------
    height : float
        H [m].
    base_radius : float
        r [m].
    """

    height: float
    base_radius: float

    def __post_init__(self):
        _validate.positive("height", self.height)
        _validate.positive("base_radius", self.base_radius)

    @property
    def inertia_pivot(self) -> float:
        """I_O / m about a base point, for the rocking plane: H^2/6 + 5 r^2/4 [m^2]."""
        return self.height**2 / 6 + 1.25 * self.base_radius**2

    def mechanism(self):
        H, r = self.height, self.base_radius
        R, a = math.hypot(r, H / 3), math.atan2(3 * r, H)
        ig = self.inertia_pivot - R * R

        def pose(phi):
            x, y = _leaning(R, a, phi)
            return [x], [y], [-phi]

        return Mechanism((1.0,), (ig,), pose)

    def restitution_value(self):
        return restitution_symmetric_body(self.inertia_pivot, 1.0, self.base_radius)


@dataclass(frozen=True)
class SymmetricFrame(_Symmetric):
    """Two identical rocking columns (R, alpha) under a rigid beam, gamma = m_beam / m_columns."""

    half_diagonal: float
    slenderness: float
    mass_ratio: float

    def __post_init__(self):
        _validate.positive("half_diagonal", self.half_diagonal)
        _validate.in_open_interval("slenderness", self.slenderness, 0, math.pi / 2, "(0, pi/2)")
        if not (math.isfinite(self.mass_ratio) and self.mass_ratio >= 0):
            raise ValueError(f"mass_ratio must be >= 0, got {self.mass_ratio!r}")

    def mechanism(self):
        R, a, gam = self.half_diagonal, self.slenderness, self.mass_ratio
        span = 4 * R

        def pose(phi):
            x1, y1 = _leaning(R, a, phi)
            # the beam rides on the column tops (the corners diagonal to the pivots)
            return [x1, x1 + span, 2 * x1 + 0.5 * span], [y1, y1, 2 * y1], [-phi, -phi, 0 * phi]

        col = 0.5
        return Mechanism((col, col, gam), (col * R * R / 3, col * R * R / 3, 0.0), pose)

    def restitution_value(self):
        a, gam = self.slenderness, self.mass_ratio
        return (1 - 1.5 * math.sin(a) ** 2 + 3 * gam * math.cos(2 * a)) / (1 + 3 * gam)


@dataclass(frozen=True)
class RockingWall(_Symmetric):
    """Out-of-plane rocking of a wall restrained at the top: two blocks (each R, alpha) hinged at
    mid-height, the top sliding vertically (the slider-crank of eq. 21 of [003])."""

    half_diagonal: float
    slenderness: float
    restitution: float | None = None

    def __post_init__(self):
        _validate.positive("half_diagonal", self.half_diagonal)
        _validate.in_open_interval("slenderness", self.slenderness, 0, math.pi / 4, "(0, pi/4)")
        if self.restitution is not None:
            _validate.restitution(self.restitution)

    def mechanism(self):
        R, a = self.half_diagonal, self.slenderness

        def pose(phi):
            x1, y1 = _leaning(R, a, phi)
            return [x1, x1], [y1, 3 * y1], [-phi, phi]

        return Mechanism((1.0, 1.0), (R * R / 3, R * R / 3), pose, phi_max=2 * a)

    def restitution_value(self):
        return np.nan if self.restitution is None else self.restitution

    @staticmethod
    def equivalent_parameters(half_diagonal, slenderness):
        r"""(p_eq [rad/s], theta_cr [rad]) of the wall's linearized equivalent block (kappa_1 =
        1/2), on arrays: eq. (23) of [003],

        .. math:: p_{eq} = \sqrt{2}\, p = \sqrt{3 g / (2 R)}, \qquad \theta_{cr} = 2 \alpha

        (what :meth:`equivalent_block` gives from the mechanism, in closed form).
        """
        R = np.asarray(half_diagonal, float)
        return np.sqrt(1.5 * G / R), 2.0 * np.asarray(slenderness, float)

    @staticmethod
    def uplift_acceleration_of(slenderness):
        r"""The wall's uplift acceleration g lambda [m/s^2], on arrays: eq. (10) of [003] on
        eq. (21) at phi = 0, where sin(alpha) = (u_g'' / 2 g) cos(alpha):

        .. math:: \lambda = 2 \tan\alpha

        (what :func:`rockstudy.structures.uplift_acceleration` gives from the mechanism, in
        closed form; not g tan(theta_cr) = g tan(2 alpha) of the equivalent block).
        """
        return 2.0 * G * np.tan(np.asarray(slenderness, float))


def _sector(r, t, psi1, psi2):
    """Area, centroid (x, y) and polar moment about the centroid of an annular sector between
    angles psi1 < psi2 (from the vertical, clockwise) of centreline radius r and thickness t."""
    ri, re = r - t / 2, r + t / 2
    dpsi = psi2 - psi1
    area = r * t * dpsi
    mid = 0.5 * (psi1 + psi2)
    half = 0.5 * dpsi
    dist = (2.0 / 3.0) * (re**3 - ri**3) / (re**2 - ri**2) * np.sin(half) / half
    polar_origin = (re**4 - ri**4) / 4 * dpsi
    return area, dist * np.sin(mid), dist * np.cos(mid), polar_origin - area * dist**2


def _rotate(vx, vy, beta):
    c, s = jt.cos(beta), jt.sin(beta)
    return c * vx - s * vy, s * vx + c * vy


def _four_bar(A, B0, C0, D, phi):
    """Four-bar linkage with ground pivots A, D: (B, C, beta_BC, beta_CD) when AB turns by phi."""
    bx, by = _rotate(B0[0] - A[0], B0[1] - A[1], phi)
    bx, by = bx + A[0], by + A[1]
    l2 = np.hypot(C0[0] - B0[0], C0[1] - B0[1])
    l3 = np.hypot(C0[0] - D[0], C0[1] - D[1])
    dx, dy = D[0] - bx, D[1] - by
    d = jt.sqrt(dx * dx + dy * dy)
    a = (l2 * l2 - l3 * l3 + d * d) / (2 * d)
    h = jt.sqrt(l2 * l2 - a * a)
    ux, uy = dx / d, dy / d
    # branch: the side of BD on which C lies at rest
    side = np.sign((B0[0] - D[0]) * (C0[1] - D[1]) - (B0[1] - D[1]) * (C0[0] - D[0]))
    cx = bx + a * ux + side * h * uy
    cy = by + a * uy - side * h * ux
    beta2 = jt.atan2(cy - by, cx - bx) - np.arctan2(C0[1] - B0[1], C0[0] - B0[0])
    beta3 = jt.atan2(cy - D[1], cx - D[0]) - np.arctan2(C0[1] - D[1], C0[0] - D[0])
    return (bx, by), (cx, cy), beta2, beta3


def four_bar_mechanism(A, B0, C0, D, bodies, phi_max=math.pi / 4) -> Mechanism:
    """A four-bar rocking mechanism (ground pivots A and D; blocks AB, BC, CD).

    ``bodies`` lists (mass, centre of mass at rest, inertia about it) of AB, BC and CD. The
    generalized coordinate is the rotation of AB in the sense that raises the centre of mass
    (rocking, not falling, V' > 0), and x is mirrored if needed so that the structure leans
    towards -x as phi grows (B_nl > 0: a ground acceleration towards -x lifts it).
    """

    def pose(phi, sense, mirror):
        (bx, by), _, beta2, beta3 = _four_bar(A, B0, C0, D, phi * sense)
        xs, ys = [], []
        for (_, (gx, gy), _), base, moved, beta in zip(
            bodies,
            (A, B0, D),
            ((A[0], A[1]), (bx, by), (D[0], D[1])),
            (phi * sense, beta2, beta3),
            strict=True,
        ):
            rx, ry = _rotate(gx - base[0], gy - base[1], beta)
            xs.append(mirror * (rx + moved[0]))
            ys.append(ry + moved[1])
        return xs, ys, [phi * sense, beta2, beta3]

    masses = tuple(float(b[0]) for b in bodies)
    inertias = tuple(float(b[2]) for b in bodies)
    t0 = Mechanism(masses, inertias, lambda phi: pose(phi, 1.0, 1.0)).terms(np.array([0.0]))
    sense = 1.0 if t0["G"][0] < 0 else -1.0  # G = -V'/g < 0: the rotation lifts the mass
    mirror = 1.0 if sense * t0["B"][0] > 0 else -1.0
    return Mechanism(masses, inertias, lambda phi: pose(phi, sense, mirror), phi_max=phi_max)


#: Spacing [rad] of the joint angles at which the arch's hinge search stops refining: lambda
#: is then within about its square (relative) of its least value.
HINGE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Arch(_Symmetric):
    """A circular masonry arch rocking as a four-hinge (three-block) mechanism, sec. 5.2 of [003].

    The hinges are those of the quasi-static collapse mechanism under a uniform horizontal
    acceleration: the admissible four-hinge mechanism (hinges alternating between intrados and
    extrados, each opening on the correct side) of least uplift multiplier lambda, found by a
    coarse-to-fine search over joint angles. The mechanism reflects about the crown at phi = 0.

    Parameters
    ----------
    inclusion_angle : float
        beta [rad], in (0, 2 pi) (pi: semicircular).
    thickness : float
        t_a [m], in (0, radius).
    radius : float
        r_a [m], the centreline radius.
    restitution : float, optional
        eta; no derivation is offered for the arch.
    """

    inclusion_angle: float
    thickness: float
    radius: float
    restitution: float | None = None
    _hinges: dict = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        _validate.positive("radius", self.radius)
        _validate.in_open_interval(
            "inclusion_angle", self.inclusion_angle, 0.0, 2 * math.pi, "(0, 2 pi) rad"
        )
        _validate.in_open_interval("thickness", self.thickness, 0.0, self.radius, "(0, radius) m")
        if self.restitution is not None:
            _validate.restitution(self.restitution)
        object.__setattr__(self, "_hinges", self._search())
        if not self._hinges["uplift"] > 0:
            raise ValueError(
                f"thickness: the arch (t/r = {self.thickness / self.radius:.4f}) cannot stand "
                f"under its own weight (collapse multiplier {self._hinges['uplift']:.4f} <= 0); "
                "it needs more thickness (a semicircle: t/r > 0.1075)"
            )

    def restitution_value(self):
        return np.nan if self.restitution is None else self.restitution

    # -- geometry ---------------------------------------------------------------------------
    def _point(self, psi, face):
        rr = self.radius + face * self.thickness / 2
        return rr * np.sin(psi), rr * np.cos(psi)

    def _evaluate(self, psi, faces, phi=0.0):
        """lambda and admissibility of hinge sets psi (4, n) with faces (4,) (+1 extrados)."""
        r, t = self.radius, self.thickness
        pts = [self._point(psi[i], faces[i]) for i in range(4)]
        A, B0, C0, D = (np.asarray(p) for p in pts)
        (bx, by), (cx, cy), beta2, beta3 = _four_bar(
            A, B0, C0, D, jt.Jet.variable(np.full(psi.shape[1], phi))
        )
        x_total = 0.0
        y_total = 0.0
        for k, (pivot, beta) in enumerate(
            ((A, jt.Jet.variable(np.full(psi.shape[1], phi))), ((bx, by), beta2), (D, beta3))
        ):
            area, gx, gy, _ = _sector(r, t, psi[k], psi[k + 1])
            if k == 1:
                ox, oy = gx - B0[0], gy - B0[1]
                rx, ry = _rotate(ox, oy, beta)
                X, Y = bx + rx, by + ry
            else:
                rx, ry = _rotate(gx - pivot[0], gy - pivot[1], beta)
                X, Y = rx + pivot[0], ry + pivot[1]
            x_total = x_total + area * X.d1
            y_total = y_total + area * Y.d1
        lam = y_total / x_total
        sense = np.sign(x_total)
        omega = [sense * 1.0, sense * beta2.d1, sense * beta3.d1]
        rel = [omega[0], omega[1] - omega[0], omega[2] - omega[1], -omega[2]]
        ok = np.ones(psi.shape[1], bool)
        for i in range(4):
            ok &= faces[i] * rel[i] > 0
        return lam, ok

    def _search(self):
        """Least lambda over admissible hinge sets: all sets of 4 of 25 joints for both face
        patterns, then levels of local refinement of the best (each a 7^4 grid at a third of
        the previous spacing) until the spacing is below :data:`HINGE_TOLERANCE`."""
        beta = self.inclusion_angle
        grid = np.linspace(-beta / 2, beta / 2, 25)
        psi = grid[np.array(list(combinations(range(grid.size), 4))).T]
        best = None
        for faces in ((1, -1, 1, -1), (-1, 1, -1, 1)):
            cand = self._best(psi, np.array(faces))
            if cand is not None and (best is None or cand[0] < best[0]):
                best = (*cand, np.array(faces))
        if best is None:
            raise ValueError("no admissible four-hinge mechanism: check the arch geometry")
        h = grid[1] - grid[0]
        while h > HINGE_TOLERANCE:  # lambda is quadratic about its least: error ~ h^2
            h /= 3
            local = [
                np.clip(best[1][i] + h * np.arange(-3, 4), -beta / 2, beta / 2) for i in range(4)
            ]
            psi = np.array([m.ravel() for m in np.meshgrid(*local, indexing="ij")])
            psi = psi[:, np.all(np.diff(psi, axis=0) > 0, axis=0)]
            cand = self._best(psi, best[2])
            if cand is not None and cand[0] <= best[0]:
                best = (*cand, best[2])
        return {"uplift": best[0], "angles": best[1], "faces": best[2]}

    def _best(self, psi, faces):
        """(lambda, hinge angles) of the admissible candidate of least lambda, or None."""
        with np.errstate(all="ignore"):
            lam, ok = self._evaluate(psi, faces)
        lam = np.where(ok & np.isfinite(lam), lam, np.inf)
        j = int(np.argmin(lam))
        return (float(lam[j]), psi[:, j].copy()) if np.isfinite(lam[j]) else None

    @property
    def hinges(self) -> dict:
        """Hinge angles psi (from the crown, clockwise) [rad], faces (+1 extrados, -1
        intrados) and the collapse multiplier lambda of the mechanism found."""
        return dict(self._hinges)

    def mechanism(self):
        psi, faces = self._hinges["angles"], self._hinges["faces"]
        r, t = self.radius, self.thickness
        hinges = [np.array(self._point(psi[i], faces[i])) for i in range(4)]
        secs = [_sector(r, t, psi[k], psi[k + 1]) for k in range(3)]
        bodies = [(a, (gx, gy), j) for a, gx, gy, j in secs]
        return four_bar_mechanism(*hinges, bodies, phi_max=math.pi / 4)


@dataclass(frozen=True)
class AsymmetricFrame:
    """Two rocking columns of different heights under a rigid beam (a four-bar linkage,
    sec. 5.1 of [003]); the mechanism differs with the direction of rocking.

    Geometry (our reading of Fig. 4, whose image was not transcribed): both columns are
    2b wide; the left column AB is 2H high on the ground, the right column CD is 2H1 high
    standing on ground raised by 2(H - H1), so the tops are level; the beam, 2h deep, spans
    the outer faces over the length L and rests on the column tops. Each column rocks about
    a base corner and the beam about the diagonally opposite top corner.

    Parameters
    ----------
    half_width : float
        b [m].
    height, height_right : float
        H and H1 [m], the half-heights of the left and right columns.
    beam_length, beam_half_depth : float
        L and h [m].
    mass_left, mass_beam, mass_right : float
        m_AB, m_BC, m_CD [kg] (or any consistent unit).
    restitution : float, optional
        eta (no derivation is offered for the asymmetric frame).
    """

    half_width: float
    height: float
    height_right: float
    beam_length: float
    beam_half_depth: float
    mass_left: float = 1.0
    mass_beam: float = 1.0
    mass_right: float = 1.0
    restitution: float | None = None

    def __post_init__(self):
        for name in (
            "half_width",
            "height",
            "height_right",
            "beam_length",
            "beam_half_depth",
            "mass_left",
            "mass_beam",
            "mass_right",
        ):
            _validate.positive(name, getattr(self, name))
        if self.beam_length <= 4 * self.half_width:
            raise ValueError("beam_length must exceed the two column widths, 4 * half_width")
        if self.restitution is not None:
            _validate.restitution(self.restitution)

    @property
    def _dims(self):
        return (
            self.half_width,
            self.height,
            self.height_right,
            self.beam_length,
            self.beam_half_depth,
        )

    def mechanism(self, direction: int = 1) -> Mechanism:
        """The mechanism for rocking towards +x (direction 1) or -x (direction -1)."""
        if direction not in (1, -1):
            raise ValueError(f"direction must be 1 or -1, got {direction!r}")
        b, H, H1, L, h = self._dims
        base_r = 2 * (H - H1)
        # towards -x the columns turn about their left base corners, the beam about the right
        # top corners; towards +x, mirror the corners
        if direction == -1:
            A, B0 = np.array([0.0, 0.0]), np.array([2 * b, 2 * H])
            D, C0 = np.array([L - 2 * b, base_r]), np.array([L, 2 * H])
        else:
            A, B0 = np.array([2 * b, 0.0]), np.array([0.0, 2 * H])
            D, C0 = np.array([L, base_r]), np.array([L - 2 * b, 2 * H])
        m1, m2, m3 = self.mass_left, self.mass_beam, self.mass_right
        bodies = [
            (m1, (b, H), m1 * (b * b + H * H) / 3),
            (m2, (L / 2, 2 * H + h), m2 * (L * L + 4 * h * h) / 12),
            (m3, (L - b, base_r + H1), m3 * (b * b + H1 * H1) / 3),
        ]
        return four_bar_mechanism(A, B0, C0, D, bodies, phi_max=math.pi / 4)

    def rocking_parameters(self) -> tuple[RockingParameters, RockingParameters]:
        """(positive, negative): the rocking parameters of each direction (eqs. 26-38)."""
        eta = np.nan if self.restitution is None else self.restitution
        return (
            self.mechanism(1).rocking_parameters(eta),
            self.mechanism(-1).rocking_parameters(eta),
        )

    def equivalent_block(self, kappa="kappa1"):
        """One equivalent block for both directions: the two directions' rocking parameters
        averaged, as [003] sec. 6.2 suggests for frames of small asymmetry."""
        pos, neg = self.rocking_parameters()
        if not pos.restitution > 0:
            raise ValueError("AsymmetricFrame needs a restitution (in (0, 1]) to rock")
        mean = RockingParameters(
            *[
                0.5 * (getattr(pos, f) + getattr(neg, f))
                for f in (
                    "frequency_parameter",
                    "critical_rotation",
                    "uplift",
                    "uplift_linearized",
                    "restitution",
                    "scale",
                )
            ]
        )
        return mean.equivalent_block(kappa)

    def uplift_closed_form(self) -> tuple[float, float]:
        """lambda_p, lambda_n by virtual work at rest, eq. (33) of [003] in the form consistent
        with (36) (the transcription's +- placement is not: at H1 = H it must give tan alpha):

        .. math::
            \\lambda = \\frac{b}{H}
            \\frac{m_{AB} + [1 + H/H_1 \\mp \\frac{2b}{L'}(1 - H/H_1)] m_{BC} + (H/H_1) m_{CD}}
                 {m_{AB} + 2[1 \\pm \\frac{b h}{L' H}(1 - H/H_1)] m_{BC} + m_{CD}}

        with L' = L - 2b the distance between the beam's two top hinges, upper signs for
        rocking towards +x.
        """
        b, H, H1, L, h = self._dims
        m1, m2, m3 = self.mass_left, self.mass_beam, self.mass_right
        lp = L - 2 * b
        out = []
        for sign in (1, -1):
            num = m1 + (1 + H / H1 - sign * 2 * b / lp * (1 - H / H1)) * m2 + H / H1 * m3
            den = m1 + 2 * (1 + sign * b * h / (lp * H) * (1 - H / H1)) * m2 + m3
            out.append(b / H * num / den)
        return tuple(out)
