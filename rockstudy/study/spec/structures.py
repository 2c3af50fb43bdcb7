"""The structure kinds of study files: one registry, read by the schema, the feasibility checks
and the designs.

Each :class:`StructureKind` names a physics class of :mod:`rockstudy.structures`, the fields an
object of that kind takes in ``[structure] kind = "objects"`` (as the class takes them, with
their ranges), whether its restitution is Housner's by default, required, or derived by the
class, and, for the kinds a ``[structure]`` table may sample from distributions, the
vectorized map from (half-diagonal, slenderness) to the equivalent block's (p, theta_cr).
The rocking parameters (p, theta_cr, eta) of an object are those of the equivalent block of its
physics class (:func:`rockstudy.structures.block_parameters`, paper [003]), and its uplift
acceleration is the structure's own (:func:`rockstudy.structures.uplift_acceleration`: g lambda,
eq. 10 of [003], which differs from g tan(theta_cr) of the equivalent block but for a block and
the structures of Table I): no formula is written here. A new structure kind is its class in
:mod:`rockstudy.structures` plus one entry of :data:`KINDS`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ...constants import G
from ...structures import (
    Arch,
    AsymmetricFrame,
    Block,
    ConicalShell,
    IsolatedBlock,
    PointMassStrut,
    RockingWall,
    StackedBlocks,
    SymmetricFrame,
    block_parameters,
    frequency_parameter,
    uplift_acceleration,
    uplift_acceleration_block,
)
from ...structures.block import HALF_DIAGONAL_RANGE, MIN_SLENDERNESS
from ...structures.isolated import MAX_BASE_MASS_RATIO, PERIOD_RANGE

__all__ = [
    "check_all",
    "check_object",
    "FieldError",
    "FieldErrors",
    "FieldRange",
    "KINDS",
    "object_fields",
    "SAMPLED_KINDS",
    "StructureKind",
    "TWO_BODY_KINDS",
    "two_body_parameters",
]


class FieldError(ValueError):
    """A problem of one field of a table, raised by a table's checks (so the message can
    name ``table.field``)."""

    def __init__(self, field, message):
        self.field = field
        super().__init__(message)


class FieldErrors(ValueError):
    """Several :class:`FieldError` of one table, raised together (:func:`check_all`)."""

    def __init__(self, errors):
        self.errors = list(errors)
        super().__init__("; ".join(f"{e.field}: {e}" for e in self.errors))


def check_all(*checks) -> None:
    """Run every check (a callable without arguments) of one table, and raise what they
    found together: so a study file's problems are all named at once, not one per run."""
    errors = []
    for check in checks:
        try:
            check()
        except FieldErrors as exc:
            errors.extend(exc.errors)
        except FieldError as exc:
            errors.append(exc)
    if len(errors) == 1:
        raise errors[0]
    if errors:
        raise FieldErrors(errors)


@dataclass(frozen=True)
class FieldRange:
    """The values a field of an object takes: ``low < value < high`` (``<=`` at an end marked
    closed), written ``label`` in messages, with its meaning ``doc``."""

    low: float
    high: float
    label: str
    doc: str
    low_closed: bool = False
    high_closed: bool = False

    def check(self, name: str, value: float, who: str) -> None:
        """Raise a :class:`FieldError` naming ``who`` and ``name`` if ``value`` is outside."""
        above = value >= self.low if self.low_closed else value > self.low
        below = value <= self.high if self.high_closed else value < self.high
        if not (above and below):
            raise FieldError(name, f"{who}: {name} must lie in {self.label}, got {value!r}")


_POSITIVE = "(0, inf)"
_R = FieldRange(
    *HALF_DIAGONAL_RANGE,
    "[{:g}, {:g}] m".format(*HALF_DIAGONAL_RANGE),
    "half-diagonal R [m]",
    low_closed=True,
    high_closed=True,
)
_ETA = FieldRange(0.0, 1.0, "(0, 1]", "restitution eta", high_closed=True)


def _length(doc):
    return FieldRange(0.0, math.inf, f"{_POSITIVE} m", doc)


def _slenderness(top, label):
    label = f"[{MIN_SLENDERNESS:g}, {label}) rad"
    return FieldRange(MIN_SLENDERNESS, top, label, "slenderness alpha [rad]", low_closed=True)


@dataclass(frozen=True)
class StructureKind:
    """One kind of structure a study file names.

    Attributes
    ----------
    name : str
        The ``kind`` written in a study file.
    structure : type
        Its physics class (:mod:`rockstudy.structures`).
    fields : dict
        Field name -> :class:`FieldRange`: what an object of this kind takes, as the class
        takes it (``restitution`` among them unless the class derives it).
    required : tuple of tuple of str
        The alternative sets of fields an object must give (one of them, completely).
    restitution : {"housner", "required", "derived"}
        Housner's value by default (a block), to be given, or derived by the class.
    build : callable, optional
        ``build(values) -> structure`` from the given fields; the class's constructor if None.
    sampled : callable, optional
        ``sampled(half_diagonal, slenderness) -> (p, theta_cr, a_up)`` on arrays, for the
        kinds a ``[structure]`` table samples from distributions: the equivalent block's p
        [rad/s] and theta_cr [rad], and the structure's uplift acceleration a_up [m/s^2].
    slenderness_top : float
        The (open) upper end of the slenderness of a sampled kind [rad].
    rocking : callable, optional
        ``rocking(structure) -> (p, theta_cr, eta, a_up)`` for a kind without an equivalent
        block (the two-body kinds: :func:`two_body_parameters`); else the equivalent block's.
    """

    name: str
    structure: type
    fields: dict
    required: tuple
    restitution: Literal["housner", "required", "derived"]
    build: Callable | None = None
    sampled: Callable | None = None
    slenderness_top: float = math.pi / 2
    doc: str = field(default="", compare=False)
    rocking: Callable | None = None

    def make(self, values: dict):
        """The physics object of the given field values (a ValueError if the class refuses)."""
        return (self.build or self.structure)(**values)

    def parameters(self, values: dict) -> tuple[object, tuple[float, float, float, float]]:
        """The physics object, its equivalent block's (p [rad/s], theta_cr [rad], eta) and its
        own uplift acceleration a_up [m/s^2] (:func:`rockstudy.structures.uplift_acceleration`)."""
        structure = self.make(values)
        if self.rocking is not None:
            return structure, self.rocking(structure)
        return structure, (*block_parameters(structure), uplift_acceleration(structure))


def _block(width=None, height=None, half_diagonal=None, slenderness=None, restitution=None):
    if width is not None:
        return Block.from_dimensions(width, height, restitution)
    return Block(half_diagonal, slenderness, restitution)


def _block_sampled(half_diagonal, slenderness):
    p = np.vectorize(frequency_parameter, otypes=[float])(half_diagonal)
    return p, np.asarray(slenderness, float), uplift_acceleration_block(slenderness)


def _wall_sampled(half_diagonal, slenderness):
    p, theta_cr = RockingWall.equivalent_parameters(half_diagonal, slenderness)
    return p, theta_cr, RockingWall.uplift_acceleration_of(slenderness)


def _stacked(width, height, plinth_width, plinth_height, density_ratio=1.0, offset=0.0):
    """The statue (``width`` x ``height``) on its plinth: a :class:`StackedBlocks`."""
    plinth = Block.from_dimensions(plinth_width, plinth_height)
    return StackedBlocks(plinth, Block.from_dimensions(width, height), density_ratio, offset)


def _isolated(width, height, period, damping, base_mass_ratio, isolator_capacity=None):
    """The block (``width`` x ``height``) on its isolator: an :class:`IsolatedBlock`."""
    block = Block.from_dimensions(width, height)
    return IsolatedBlock(block, base_mass_ratio, period, damping, isolator_capacity)


def _stacked_uplift(s: StackedBlocks) -> float:
    """The ground acceleration that first lifts a stacked pair at rest [m/s^2]: the smaller
    of the statue's uplift on its plinth, g b_u / h_u, and the pair's as one rigid body
    about a corner of the plinth, g (m_l b_l + m_u (b_l - abs(e))) / (m_l h_l + m_u
    (2 h_l + h_u)) (moments of gravity and of the inertia forces about the corner; e the
    offset, the nearer corner the weaker side)."""
    lo, up = s.lower, s.upper
    b_l, h_l, b_u, h_u = lo.width / 2, lo.height / 2, up.width / 2, up.height / 2
    m_l, m_u = s.lower_mass, s.upper_mass
    pair = (m_l * b_l + m_u * (b_l - abs(s.offset))) / (m_l * h_l + m_u * (2 * h_l + h_u))
    return G * min(b_u / h_u, pair)


def two_body_parameters(structure) -> tuple[float, float, float, float]:
    """(p [rad/s], theta_cr [rad], eta, a_up [m/s^2]) a record design uses for a two-body
    object (its groups, its IDA ladder): a_up, the ground acceleration that first lifts it
    at rest (a stacked pair: :func:`_stacked_uplift`; an isolated block: g tan(alpha), the
    base's acceleration that lifts it, which the isolator may reach under a smaller ground
    acceleration), theta_cr = arctan(a_up / g) (the ladder starts at g theta_cr), and the
    rocking body's p and restitution (the statue's on its plinth; the isolated block's on
    its base). The simulations themselves run the two-body system."""
    if isinstance(structure, StackedBlocks):
        a_up, body = _stacked_uplift(structure), structure.upper
        eta = body.restitution
    else:
        a_up, body = structure.uplift_acceleration, structure.block
        eta = structure.restitution
    return body.frequency_parameter, math.atan(a_up / G), eta, a_up


_MASS = FieldRange(0.0, math.inf, f"{_POSITIVE}", "mass (any consistent unit)")

#: The structure kinds of study files, by name (see the module docstring).
KINDS: dict[str, StructureKind] = {
    k.name: k
    for k in (
        StructureKind(
            "block",
            Block,
            {
                "width": _length("full width 2b [m]"),
                "height": _length("full height 2h [m]"),
                "half_diagonal": _R,
                "slenderness": _slenderness(math.pi / 2, "pi/2"),
                "restitution": _ETA,
            },
            (("width", "height"), ("half_diagonal", "slenderness")),
            "housner",
            build=_block,
            sampled=_block_sampled,
            doc="rectangular block (Housner 1963)",
        ),
        StructureKind(
            "rocking_wall",
            RockingWall,
            {
                "half_diagonal": _R,
                "slenderness": _slenderness(math.pi / 4, "pi/4"),
                "restitution": _ETA,
            },
            (("half_diagonal", "slenderness", "restitution"),),
            "required",
            sampled=_wall_sampled,
            slenderness_top=math.pi / 4,
            doc="out-of-plane wall restrained at the top, eq. (21)-(23) of [003]",
        ),
        StructureKind(
            "asymmetric_frame",
            AsymmetricFrame,
            {
                "half_width": _length("b, the columns' half-width [m]"),
                "height": _length("H, the left column's half-height [m]"),
                "height_right": _length("H1, the right column's half-height [m]"),
                "beam_length": _length("L, the beam's length [m]"),
                "beam_half_depth": _length("h, the beam's half-depth [m]"),
                "mass_left": _MASS,
                "mass_beam": _MASS,
                "mass_right": _MASS,
                "restitution": _ETA,
            },
            (
                (
                    "half_width",
                    "height",
                    "height_right",
                    "beam_length",
                    "beam_half_depth",
                    "restitution",
                ),
            ),
            "required",
            doc="two columns of different heights under a beam, sec. 5.1 of [003]",
        ),
        StructureKind(
            "arch",
            Arch,
            {
                "inclusion_angle": FieldRange(0.0, 2 * math.pi, "(0, 2 pi) rad", "beta [rad]"),
                "thickness": _length("t_a [m], below the radius"),
                "radius": _length("r_a, the centreline radius [m]"),
                "restitution": _ETA,
            },
            (("inclusion_angle", "thickness", "radius", "restitution"),),
            "required",
            doc="circular masonry arch, four-hinge mechanism, sec. 5.2 of [003]",
        ),
        StructureKind(
            "symmetric_frame",
            SymmetricFrame,
            {
                "half_diagonal": _R,
                "slenderness": _slenderness(math.pi / 2, "pi/2"),
                "mass_ratio": FieldRange(
                    0.0, math.inf, "[0, inf)", "m_beam / m_columns", low_closed=True
                ),
            },
            (("half_diagonal", "slenderness", "mass_ratio"),),
            "derived",
            doc="two identical columns under a rigid beam, Table I of [003]",
        ),
        StructureKind(
            "point_mass_strut",
            PointMassStrut,
            {"half_diagonal": _R, "slenderness": _slenderness(math.pi / 2, "pi/2")},
            (("half_diagonal", "slenderness"),),
            "derived",
            doc="point mass on a rigid massless strut, Table I of [003]",
        ),
        StructureKind(
            "conical_shell",
            ConicalShell,
            {
                "height": _length("H, the cone's height [m]"),
                "base_radius": _length("r, the base radius [m]"),
            },
            (("height", "base_radius"),),
            "derived",
            doc="thin conical shell (a spire), Table I of [003]",
        ),
        StructureKind(
            "stacked",
            StackedBlocks,
            {
                "width": _length("the statue's full width [m]"),
                "height": _length("the statue's full height [m]"),
                "plinth_width": _length("the plinth's full width [m]"),
                "plinth_height": _length("the plinth's full height [m]"),
                "density_ratio": FieldRange(0.0, math.inf, _POSITIVE, "rho_statue / rho_plinth"),
                "offset": FieldRange(
                    -math.inf, math.inf, "(-inf, inf) m", "the statue's axis from the plinth's"
                ),
            },
            (("width", "height", "plinth_width", "plinth_height"),),
            "derived",
            build=_stacked,
            rocking=two_body_parameters,
            doc="a statue on a plinth that can rock (Psycharis 1990)",
        ),
        StructureKind(
            "isolated",
            IsolatedBlock,
            {
                "width": _length("the block's full width [m]"),
                "height": _length("the block's full height [m]"),
                "period": FieldRange(
                    *PERIOD_RANGE,
                    "[{:g}, {:g}] s".format(*PERIOD_RANGE),
                    "the isolator's period T_b [s]",
                    low_closed=True,
                    high_closed=True,
                ),
                "damping": FieldRange(0.0, 1.0, "[0, 1]", "zeta_b", True, True),
                "base_mass_ratio": FieldRange(
                    0.0,
                    MAX_BASE_MASS_RATIO,
                    f"(0, {MAX_BASE_MASS_RATIO:g}]",
                    "m_base / m_block",
                    high_closed=True,
                ),
                "isolator_capacity": _length("the isolator's displacement capacity [m]"),
            },
            (("width", "height", "period", "damping", "base_mass_ratio"),),
            "derived",
            build=_isolated,
            rocking=two_body_parameters,
            doc="a block on a base isolator (Vassiliou & Makris 2012)",
        ),
    )
}

#: The kinds of two bodies (no equivalent block): their scenes run the two-body system.
TWO_BODY_KINDS = ("stacked", "isolated")

#: The kinds a ``[structure]`` table samples from distributions of R and alpha.
SAMPLED_KINDS = tuple(k for k, v in KINDS.items() if v.sampled is not None)


def object_fields() -> tuple[str, ...]:
    """Every field some kind of object takes, in registry order (the columns of a CSV)."""
    out = []
    for kind in KINDS.values():
        out += [f for f in kind.fields if f not in out]
    return tuple(out)


def _field_of(message: str, fields) -> str | None:
    """The field a physics class's ValueError names first (its messages start with it)."""
    head = message.replace(":", " ").replace("=", " ").split()
    return next((w for w in head[:1] if w in fields), None)


def _check_required(who, kind, values):
    """One of the kind's sets of required fields, completely, and nothing of another."""
    complete = [s for s in kind.required if set(s) <= set(values)]
    given = [f for s in kind.required for f in s if f in values]
    if len(complete) == 1 and len(given) == len(complete[0]):
        return
    if complete:
        name = next(f for f in given if f not in complete[0])
    else:
        started = [s for s in kind.required if set(s) & set(values)] or kind.required
        name = next(f for f in started[0] if f not in values)
    alternatives = " or ".join(" and ".join(s) for s in kind.required)
    raise FieldError(
        name, f"{who}: kind {kind.name!r} needs {alternatives}; got {list(values) or 'none'}"
    )


def check_object(who: str, kind_name: str, values: dict):
    """Validate an object's fields against its kind; return (structure, (p, theta_cr, eta,
    a_up)) (see :meth:`StructureKind.parameters`).

    ``values`` holds the given fields (None left out). Every problem is a :class:`FieldError`
    naming ``who`` (the object) and the field.
    """
    kind = KINDS.get(kind_name)
    if kind is None:
        raise FieldError("kind", f"{who}: kind must be one of {list(KINDS)}, got {kind_name!r}")
    for name, value in values.items():
        if name not in kind.fields:
            raise FieldError(
                name, f"{who}: {name} does not apply to a {kind.name}; it takes {list(kind.fields)}"
            )
        kind.fields[name].check(name, value, who)
    _check_required(who, kind, values)
    try:
        return kind.parameters(values)
    except ValueError as exc:
        name = _field_of(str(exc), values) or next(iter(values))
        raise FieldError(name, f"{who}: {exc}") from None
