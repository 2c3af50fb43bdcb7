"""Named objects: ``[structure] kind = "objects"``, given in the study or in a CSV file.

An object has a name, a kind of :data:`.structures.KINDS` (a block by default) and the fields
of its kind's physics class; :class:`ObjectsSpec` lists them. ``file`` names a CSV file of
:data:`OBJECT_COLUMNS`, read relative to the study file's folder into ``objects`` before the
study is validated (``_read_objects_file``); its problems name the file and the line, never a
cell.
"""

from __future__ import annotations

import csv
import io
from typing import Literal

import numpy as np
from pydantic import Field, PrivateAttr, create_model, field_validator, model_validator

from .friction_spec import Friction, as_pair, coefficient, friction_pair, friction_value
from .parameters import MAX_STUDY_BYTES, _a_name, _describe, _Model
from .structures import KINDS, TWO_BODY_KINDS, FieldError, check_object, object_fields

__all__ = ["OBJECT_COLUMNS", "OBJECT_KINDS", "ObjectSpec", "ObjectsSpec"]


#: Kinds an object of ``[structure] kind = "objects"`` may be (the registry
#: :data:`.structures.KINDS`).
OBJECT_KINDS = tuple(KINDS)


class _ObjectBase(_Model):
    """One named object of a kind of :data:`.structures.KINDS` (by default a block: ``width``
    and ``height`` [m], or ``half_diagonal`` [m] and ``slenderness`` [rad]; restitution by
    default Housner's), with the fields of its kind as its physics class takes them."""

    name: str = Field(min_length=1)
    kind: Literal[OBJECT_KINDS] = "block"
    #: The friction coefficient mu of this object's contact, or a pair [mu_s, mu_k]
    #: (overrides the study's friction; :mod:`.friction_spec`).
    friction: Friction | None = None
    #: The kinetic coefficient mu_k beside a ``friction`` mu_s (an objects CSV file's way to
    #: give the pair; needs the object's own ``friction``, a single number >= it).
    friction_kinetic: float | None = None
    #: A two-body object's plain twin: the name of a block object of the same statue (its
    #: width and height), which the report puts beside it ("what the plinth/isolator buys").
    compare_to: str | None = Field(default=None, min_length=1)
    _params: tuple = PrivateAttr(default=None)
    _structure: object = PrivateAttr(default=None)
    _printable = field_validator("name")(lambda value: _a_name(value))
    _pair = field_validator("friction", mode="before")(lambda value: as_pair(value))
    _friction = field_validator("friction")(lambda value: friction_value(value))

    @model_validator(mode="after")
    def _kinetic(self):
        """``friction_kinetic`` needs the object's ``friction`` as one number >= it."""
        if self.friction_kinetic is not None:
            if self.friction is None or isinstance(self.friction, tuple):
                raise ValueError(
                    "friction_kinetic (mu_k) needs the object's friction as one number (mu_s), "
                    "not " + ("none" if self.friction is None else "a pair [mu_s, mu_k]")
                )
            kinetic = coefficient(self.friction_kinetic, "friction_kinetic (mu_k)")
            if kinetic > self.friction:
                raise ValueError(
                    f"friction_kinetic (mu_k) {kinetic!r} exceeds the object's friction (mu_s) "
                    f"{self.friction!r}: give mu_s >= mu_k"
                )
        return self

    def friction_pair(self, default) -> tuple[float, float]:
        """(mu_s, mu_k) of the object's contact: its own ``friction`` (with its
        ``friction_kinetic``), else ``default`` (the study's; NaNs where neither gives one)."""
        if self.friction_kinetic is not None:
            return (self.friction, self.friction_kinetic)
        return friction_pair(default if self.friction is None else self.friction)

    @model_validator(mode="after")
    def _shape(self):
        given = {f: getattr(self, f) for f in object_fields() if getattr(self, f) is not None}
        structure, rocking = check_object(f"object {self.name!r}", self.kind, given)
        R = float(getattr(structure, "half_diagonal", np.nan))
        self._params = (*rocking, R)
        self._structure = structure
        if self.compare_to is not None and self.kind not in TWO_BODY_KINDS:
            raise FieldError(
                "compare_to",
                f"object {self.name!r}: compare_to is for the kinds {list(TWO_BODY_KINDS)} "
                f"(a statue on its plinth or isolator), not a {self.kind}",
            )
        return self

    def two_body(self):
        """The :class:`~rockstudy.structures.StackedBlocks` or
        :class:`~rockstudy.structures.IsolatedBlock` of a two-body object; None otherwise."""
        return self._structure if self.kind in TWO_BODY_KINDS else None

    def statue(self):
        """The rocking body of the object (a :class:`~rockstudy.structures.Block`): the
        statue of a stacked object, the block of an isolated one, the block itself; None for
        another structure."""
        s = self._structure
        return (
            getattr(s, "upper", None)
            or getattr(s, "block", None)
            or (s if self.kind == "block" else None)
        )

    def geometry(self) -> tuple[float, float]:
        """(half-diagonal R [m], NaN for a structure without one; theta_cr [rad], the
        equivalent block's slenderness), as the design functions store them."""
        return self._params[4], self._params[1]

    def uplift(self) -> float:
        """The ground acceleration that starts the object rocking [m/s^2]: g tan(alpha) of a
        block, g lambda of another structure (eq. 10 of [003];
        :func:`rockstudy.structures.uplift_acceleration`)."""
        return self._params[3]

    def rocking(self) -> tuple[float, float, float]:
        """(p [rad/s], theta_cr [rad], eta) of the equivalent block of the object's physics
        class (:func:`rockstudy.structures.block_parameters`)."""
        return self._params[:3]


ObjectSpec = create_model(
    "ObjectSpec",
    __base__=_ObjectBase,
    __doc__=_ObjectBase.__doc__,
    **{f: (float | None, None) for f in object_fields()},
)


class ObjectsSpec(_Model):
    """Named objects studied one by one in a record ``[design]``: ``objects`` lists them (the
    ``structure`` coordinate of the result carries their names), or ``file`` names a CSV file
    of the same columns (read relative to the study file's folder into ``objects`` when the
    study is validated)."""

    kind: Literal["objects"]
    objects: list[ObjectSpec] = Field(min_length=1)
    file: str | None = None

    @model_validator(mode="after")
    def _unique(self):
        seen = {}
        for i, o in enumerate(self.objects):
            if o.name in seen:
                raise ValueError(
                    f"object {i} is named {o.name!r} like object {seen[o.name]}; names must differ"
                )
            seen[o.name] = i
        for i, o in enumerate(self.objects):
            if o.compare_to is not None:
                plain = self.objects[seen[o.compare_to]] if o.compare_to in seen else None
                _check_pair(i, o, plain)
        return self

    def pairs(self) -> list[tuple[str, str]]:
        """(two-body object, its plain block object) of each ``compare_to``, in order."""
        return [(o.name, o.compare_to) for o in self.objects if o.compare_to is not None]

    def two_body(self) -> list:
        """The two-body structure of each object (None for the others), in order."""
        return [o.two_body() for o in self.objects]

    def rocking(self) -> np.ndarray:
        """(n, 3) array of (p [rad/s], theta_cr [rad], eta) of the objects, in order."""
        return np.array([o.rocking() for o in self.objects], float)

    def uplift(self) -> np.ndarray:
        """(n,) array of the objects' uplift accelerations [m/s^2] (:meth:`ObjectSpec.uplift`)."""
        return np.array([o.uplift() for o in self.objects], float)


def _check_pair(i, obj, block) -> None:
    """``compare_to`` of object ``i`` names a block object of its statue's width and height
    (to 1e-9), or a ValueError naming the field."""
    field = f"object {i} ({obj.name!r}): compare_to"
    if block is None or block.kind != "block":
        what = "no object" if block is None else f"a {block.kind}"
        raise ValueError(
            f"{field} must name a block object of the study; {obj.compare_to!r} is {what}"
        )
    a, b = obj.statue(), block.statue()
    if not (
        np.isclose(a.width, b.width, rtol=1e-9, atol=0)
        and np.isclose(a.height, b.height, rtol=1e-9, atol=0)
    ):
        raise ValueError(
            f"{field} names {block.name!r}, {b.width:.6g} x {b.height:.6g} m, not the same "
            f"statue as its {a.width:.6g} x {a.height:.6g} m (width x height)"
        )


#: Columns of an objects CSV file (``[structure] kind = "objects"``, ``file = ...``).
OBJECT_COLUMNS = tuple(ObjectSpec.model_fields)


def _read_objects_file(data, base_dir) -> str | None:
    """Read ``structure.file`` (a CSV of :data:`OBJECT_COLUMNS`, a header line then one object a
    line; empty cells are left out) into ``structure.objects`` of ``data``, in place; the
    problem as one line naming the file and the line, never its contents, or None."""
    st = data.get("structure")
    if not (isinstance(st, dict) and st.get("kind") == "objects" and "file" in st):
        return None
    name = st["file"]
    if "objects" in st:
        return "structure.file: give objects or file, not both"
    if not isinstance(name, str) or not name.strip():
        return f"structure.file: must be the path of a CSV file, got {_describe(name)}"
    from ...motions.records import read_text_file
    from .feasibility import record_path

    path = record_path(name, base_dir)
    try:
        text = read_text_file(path, MAX_STUDY_BYTES)
        st["objects"] = _object_rows(text)
    except (OSError, ValueError) as exc:
        return f"structure.file: cannot read {str(path)!r} ({exc})"
    return None


def _object_rows(text: str) -> list[dict]:
    """The objects of the text of an objects CSV file, one dict a row without its empty cells;
    ValueError naming the line and what was expected (never a cell: the file may be anything).

    A row may be shorter than the header; cells beyond the header, or under a column without a
    name, must be empty. Blank lines are skipped.
    """
    expected = f"a header line of columns among {list(OBJECT_COLUMNS)}, then one object a line"
    reader = csv.reader(io.StringIO(text.removeprefix("\ufeff")))  # a spreadsheet's BOM
    rows = []
    try:
        for cells in reader:
            if any("\n" in c or "\r" in c for c in cells):
                raise ValueError(
                    f"line {reader.line_num}: a quoted cell spans lines; expected {expected}"
                )
            rows.append((reader.line_num, [c.strip() for c in cells]))
    except csv.Error:  # a carriage return inside a line, a cell over csv's size limit
        raise ValueError(
            f"line {reader.line_num}: is not a line of comma-separated cells (a carriage "
            f"return alone, or a cell too long); expected {expected}"
        ) from None
    rows = [(line, cells) for line, cells in rows if any(cells)]
    if not rows:
        raise ValueError(f"it holds no line; expected {expected}")
    header = _object_header(*rows[0], expected)
    if len(rows) == 1:
        raise ValueError(f"it holds no object after its header; expected {expected}")
    return [_object_row(line, cells, header) for line, cells in rows[1:]]


def _object_header(line: int, cells: list[str], expected: str) -> list[str]:
    """The column names of the header of an objects CSV file ('' for a column without a name,
    which must stay empty); ValueError naming the first column that is no object column."""
    for i, cell in enumerate(cells):
        if cell and cell not in OBJECT_COLUMNS:
            raise ValueError(
                f"line {line}: column {i + 1} of the header is not an object column; "
                f"expected {expected}"
            )
        if cell and cell in cells[:i]:
            raise ValueError(f"line {line}: column {i + 1} of the header repeats a column")
    if "name" not in cells:
        raise ValueError(f"line {line}: the header has no name column; expected {expected}")
    return cells


def _object_row(line: int, cells: list[str], header: list[str]) -> dict:
    """One object of an objects CSV file: its non-empty cells by column, names and kinds as
    text and the rest as numbers where they read as one; ValueError for a non-empty cell
    beyond the header or under a column without a name."""
    stray = [i for i, cell in enumerate(cells) if cell and (i >= len(header) or not header[i])]
    if stray:
        raise ValueError(
            f"line {line}: cell {stray[0] + 1} is not under a named column (the row has "
            f"{len(cells)} cells, the header names {sum(map(bool, header))} columns)"
        )
    return {
        header[i]: cell if header[i] in ("name", "kind", "compare_to") else _cell(cell)
        for i, cell in enumerate(cells)
        if cell
    }


def _cell(text: str):
    """A CSV cell: a number if it reads as one, else the text (the schema then names it)."""
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        return text
