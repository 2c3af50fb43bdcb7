"""Record suites: a folder, a glob or a list of record files, read into :class:`Record` objects.

Every file named is read or the call fails: no record is silently skipped. A folder is read for
the files whose suffix is one of :data:`RECORD_SUFFIXES` (PEER ``.AT2`` acceleration files and
two-column text files); any other file must be named by a glob or a list.
"""

from __future__ import annotations

import glob
import re
from pathlib import Path

from .records import Record, UnitsError, not_a_file

__all__ = [
    "load_suite",
    "read_pair",
    "RECORD_SUFFIXES",
    "suite_files",
    "suite_pairs",
    "units_refusal",
]

#: Suffixes (case-insensitive) of the files read from a folder.
RECORD_SUFFIXES = (".at2", ".dat", ".txt", ".csv")


def _is_glob(text: str) -> bool:
    return any(c in text for c in "*?[")


def _refuse_non_files(paths, field: str, how: str) -> list[Path]:
    """``paths`` if every one is a regular file, else a ValueError naming the first that is
    not and what it is: a glob or folder that finds one never skips it silently."""
    for p in paths:
        what = not_a_file(p)
        if what:
            raise ValueError(
                f"{field}: {how} finds {str(p)!r}, which is {what}, not a record file; "
                "remove it or name the record files one by one"
            )
    return paths


def _expand(item, field: str = "source") -> list[Path]:
    """The record files named by one source item: a file, a folder or a glob."""
    text = str(item)
    if _is_glob(text):
        paths = sorted(Path(p) for p in glob.glob(text))
        if not paths:
            raise ValueError(f"{field}: the glob {text!r} matches no file")
        return _refuse_non_files(paths, field, f"the glob {text!r}")
    path = Path(item)
    if path.is_dir():
        paths = sorted(p for p in path.iterdir() if _suffix_ok(p))
        if not paths:
            raise ValueError(
                f"{field}: the folder {str(path)!r} holds no record files "
                f"(suffixes {', '.join(RECORD_SUFFIXES)}, any case)"
            )
        return _refuse_non_files(paths, field, f"the folder {str(path)!r}")
    what = not_a_file(path)
    if what == "missing":
        raise ValueError(f"{field}: {text!r} is neither a file, a folder nor a glob that matches")
    if what:
        raise ValueError(f"{field}: {text!r} is {what}, not a record file")
    return [path]


def _suffix_ok(path: Path) -> bool:
    return path.suffix.lower() in RECORD_SUFFIXES


def _read(path: Path, units: str, field: str) -> Record:
    """One record file; any failure is a ValueError naming ``field`` and the file."""
    try:
        if path.suffix.lower() == ".at2":
            return Record.from_at2(path)
        return Record.from_csv(path, units=units)
    except UnitsError as exc:  # the file is read; the units it was read in are wrong
        units_field = f"{field.rpartition('.')[0]}.units".lstrip(".")
        raise ValueError(f"{units_field}: {exc}") from exc
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"{field}: cannot read the record file {str(path)!r}: {exc}") from exc


def _name_rule(rule, field: str = "vertical", example="(r'\\d{3}\\.AT2$', '-UP.AT2')"):
    """The (compiled regex, replacement) of a pairing ``rule`` given as ``field``, or None."""
    if rule is None:
        return None
    what = "vertical" if field == "vertical" else "second horizontal component"
    try:
        if isinstance(rule, (str, bytes)):
            raise TypeError("a single string")
        pattern, replacement = rule
        return re.compile(pattern), str(replacement)
    except (TypeError, ValueError, re.error) as exc:
        raise ValueError(
            f"{field} must be None or a (regex, replacement) pair that maps a horizontal file "
            f"name to its {what} file's name, e.g. {example}; got {rule!r} ({exc})"
        ) from None


def load_suite(source, vertical=None, units: str = "g", h2=None) -> list[Record]:
    """Read a suite of ground-motion records.

    Parameters
    ----------
    source : path-like, str or sequence
        A folder (its files with a suffix in :data:`RECORD_SUFFIXES`), a glob pattern
        (``"records/*.AT2"``: every file it matches), a file, or a sequence of these. An item
        of a sequence may also be an explicit ``(horizontal, vertical)`` pair of files.
        ``.AT2`` files are read by :meth:`Record.from_at2`, the others as two-column text
        (time [s], acceleration) by :meth:`Record.from_csv`.
    vertical : (str, str), optional
        H/V pairing: a regular expression and its replacement (``re.sub``) mapping each
        horizontal file's name to its vertical component's file name in the same folder, e.g.
        ``(r"\\d{3}\\.AT2$", "-UP.AT2")`` pairs ``RSN126_GAZLI_GAZ000.AT2`` with
        ``RSN126_GAZLI_GAZ-UP.AT2``. Files that are some record's vertical component are not
        read as horizontal records. A horizontal file whose name the expression does not match,
        or whose vertical file is missing, is an error.
    units : {"g", "m/s2", "m/s^2", "cm/s2", "cm/s^2"}
        Units of the acceleration column of text files (``.AT2`` files are in g: units other
        than g on ``.AT2`` files alone are refused).
    h2 : (str, str), optional
        Pairing of the two horizontal components, as ``vertical`` pairs verticals: a regular
        expression and its replacement mapping each (x) horizontal file's name to its second
        horizontal component's (``acceleration_y``), e.g. ``(r"000\\.AT2$", "090.AT2")``
        pairs ``RSN126_GAZLI_GAZ000.AT2`` with ``RSN126_GAZLI_GAZ090.AT2``. Files that are
        some record's second component are not read as records of their own; a file that is
        no record's component must match every pattern given (``vertical`` and ``h2``), and
        every file the patterns name must exist.

    Returns
    -------
    list of Record
        In the order of ``source`` (each folder and glob sorted by name); names are the file
        stems.

    Raises
    ------
    ValueError
        Naming the field (``source``, ``vertical`` or ``h2``) and the file: a folder or glob
        without record files, a file that cannot be read, a file listed twice, a missing
        vertical or second file, components of different lengths or steps, or ``units``
        other than g on ``.AT2`` files alone (``units``).
    """
    files = suite_files(source, vertical, h2=h2)
    refusal = units_refusal(files, units)
    if refusal:
        raise ValueError(f"units: {refusal}")
    return [read_pair(h, v, units, h2=y) for h, v, y in files]


def units_refusal(pairs, units: str) -> str | None:
    """Why ``units`` other than g cannot apply to a suite of ``.AT2`` files alone (None if it
    can): PEER's format is in g and is read in g whatever ``units`` says, so a setting that
    would change nothing is refused rather than ignored. ``pairs``: (horizontal, vertical or
    None) paths, as :func:`suite_pairs` gives them."""
    files = [p for pair in pairs for p in pair if p is not None]
    if units == "g" or any(Path(p).suffix.lower() != ".at2" for p in files):
        return None
    return (
        f"{units!r} does not apply to .AT2 files, which are in g (PEER's format, read in g "
        "whatever the units); units is the unit of text records' acceleration column: "
        "remove it, or give text files"
    )


def suite_pairs(
    source, vertical=None, field: str = "source", vertical_field: str = "vertical"
) -> list[tuple[Path, Path | None]]:
    """The (horizontal, vertical or None) files of a suite, without reading them.

    ``source`` and ``vertical`` are as in :func:`load_suite`; ``field`` and ``vertical_field``
    name them in the messages (a study names ``motion.files`` and ``motion.vertical``). Raises
    ValueError for a folder or glob without record files, a missing file, a file named twice,
    or a broken pairing.
    """
    return [(h, v) for h, v, _ in suite_files(source, vertical, field, vertical_field)]


def suite_files(
    source, vertical=None, field: str = "source", vertical_field: str = "vertical", h2=None
) -> list[tuple[Path, Path | None, Path | None]]:
    """The (horizontal, vertical or None, second horizontal or None) files of a suite,
    without reading them: :func:`suite_pairs` with the ``h2`` pairing of :func:`load_suite`
    (named ``h2`` in the messages)."""
    items = list(source) if isinstance(source, (list, tuple)) else [source]
    if not items:
        raise ValueError(f"{field}: an empty list names no record")
    rules = {1: _name_rule(vertical, vertical_field), 2: _name_rule(h2, "h2", _H2_EXAMPLE)}
    files: list[list] = []
    for item in items:
        if isinstance(item, tuple):
            if len(item) != 2:
                raise ValueError(f"{field}: a pair must be (horizontal, vertical), got {item!r}")
            files.append([Path(item[0]), Path(item[1]), None])
        else:
            files.extend([p, None, None] for p in _expand(item, field))
    names = {1: vertical_field, 2: "h2"}
    rules = {slot: (rule, names[slot]) for slot, rule in rules.items() if rule is not None}
    if rules:
        files = _pair_by_name(files, rules)
    seen = {}
    for h, _, _ in files:
        key = h.resolve()
        if key in seen:
            raise ValueError(f"{field}: the file {str(h)!r} is named twice")
        seen[key] = h
    return [tuple(f) for f in files]


#: An example of an ``h2`` pairing, for its message.
_H2_EXAMPLE = "(r'000\\.AT2$', '090.AT2')"


def read_pair(
    horizontal,
    vertical=None,
    units: str = "g",
    field: str = "source",
    vertical_field="vertical",
    h2=None,
) -> Record:
    """One record from its horizontal file and, optionally, its vertical file and its second
    horizontal file ``h2`` (same samples); any failure is a ValueError naming the field
    (``field``, ``vertical_field``, ``h2``) and the file."""
    rec = _read(Path(horizontal), units, field)
    for name, path, where in (("acceleration_y", h2, "h2"), ("vertical", vertical, vertical_field)):
        if path is None:
            continue
        try:
            rec = rec._with_component(name, _read(Path(path), units, where), path)
        except ValueError as exc:
            text = str(exc)
            if text.startswith(f"{_COMPONENT_FIELD[name]}:"):
                text = text.partition(": ")[2]
            raise ValueError(text if text.startswith(where) else f"{where}: {text}") from None
    return rec


#: The field :meth:`Record._with_component` names in its messages.
_COMPONENT_FIELD = {"vertical": "vertical", "acceleration_y": "h2"}


def _pair_by_name(files, rules):
    """Fill each record's component files by the rules {slot: ((regex, replacement), field)}
    (slot 1 the vertical, 2 the second horizontal): a file some rule names from another is
    that record's component, every other file is a record and must match every rule."""
    named = set()
    for h, _, _ in files:
        for (pattern, replacement), _ in rules.values():
            if pattern.search(h.name):
                named.add(h.with_name(pattern.sub(replacement, h.name)).resolve())
    out, named_here = [], []
    for entry in files:
        h = entry[0]
        if h.resolve() in named:
            continue
        for slot, ((pattern, replacement), field) in rules.items():
            if entry[slot] is not None:
                continue  # an explicit (horizontal, vertical) pair
            if not pattern.search(h.name):
                raise ValueError(
                    f"{field}: the file {str(h)!r} does not match {pattern.pattern!r} and is no "
                    f"record's {_SLOTS[slot]}; every file must be one or the other"
                )
            entry[slot] = h.with_name(pattern.sub(replacement, h.name))
            named_here.append((entry[slot], h, field, _SLOTS[slot]))
        out.append(entry)
    for found in named_here:  # a file that matches no rule is named first, then one missing
        _refuse_missing(*found)
    return out


#: What each slot of a suite's (horizontal, vertical, second horizontal) files is.
_SLOTS = {1: "vertical component", 2: "second horizontal component"}


def _refuse_missing(path, horizontal, field, what):
    """A ValueError naming ``field`` where the component file ``path`` of ``horizontal`` is
    missing or not a file."""
    found = not_a_file(path)
    name = "vertical file" if what.startswith("vertical") else "second horizontal file"
    if found == "missing":
        raise ValueError(f"{field}: the {name} {str(path)!r} of {str(horizontal)!r} is missing")
    if found:
        raise ValueError(
            f"{field}: the {name} {str(path)!r} of {str(horizontal)!r} is {found}, not a file"
        )
