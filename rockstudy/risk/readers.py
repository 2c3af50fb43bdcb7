"""Hazard-curve files: two columns (level, annual rate of exceedance) and OpenQuake's
``hazard_curve-*.csv`` (:meth:`rockstudy.risk.HazardCurve.from_csv`).

A file is read as record files are (:func:`rockstudy.motions.records.read_text_file`: a
regular file of bounded size, refused before reading otherwise), and every complaint names
the file and the line, never its contents.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np

from .. import _validate
from ..motions import measures
from ..motions.records import read_text_file

__all__ = ["OPENQUAKE_IMTS", "read_curve"]

#: OpenQuake's IMT names -> (rockstudy IM, the unit OpenQuake gives its levels in).
OPENQUAKE_IMTS = {
    "PGA": ("pga", "g"),
    "SA": ("sa", "g"),
    "PGV": ("pgv", "cm/s"),
    "PGD": ("pgd", "cm"),
}


def read_curve(cls, path, im, units, period, site):
    """The :class:`~rockstudy.risk.HazardCurve` (``cls``) of a file; the arguments are those
    of :meth:`~rockstudy.risk.HazardCurve.from_csv`."""
    for name, value in (("im", im), ("units", units)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{name} must be a name (a string) or None, got {value!r}")
    path = Path(path)
    try:
        text = read_text_file(path)
    except (OSError, ValueError) as err:
        raise ValueError(f"path: cannot read the hazard curve {err}") from None
    lines = [(n, ln.strip()) for n, ln in enumerate(text.splitlines(), 1) if ln.strip()]
    if lines and lines[0][1].startswith("#") and "investigation_time" in lines[0][1]:
        return _from_openquake(cls, path, lines, im, units, period, site)
    if im is None:
        raise ValueError(
            f"im: {path.name} is a two-column file, which does not name its intensity "
            f"measure: give im= (one of {list(measures.MEASURES)}) and units="
        )
    if site is not None:
        raise ValueError(f"site: {path.name} is a two-column file, the curve of one site")
    levels, rates, header = _two_columns(path, lines)
    _check_header_units(path, header, im, units)
    return cls(im, levels, rates, units, period, str(path))


def _two_columns(path, lines):
    """(levels, rates, (line number, the first column's name) or None) of a two-column
    file of (line number, text) ``lines``."""
    rows = [(n, ln) for n, ln in lines if not ln.startswith("#")]
    values, header = [], None
    for i, (n, ln) in enumerate(rows):
        cells = [c for c in re.split(r"[,;\s]+", ln) if c]
        try:
            nums = [float(c) for c in cells]
        except ValueError:
            if i == 0:  # a row of column names
                sep = r"[,;]" if re.search(r"[,;]", ln) else r"\s+"
                header = (n, re.split(sep, ln)[0].strip()) if ln else None
                continue
            raise ValueError(
                f"path: {path.name}, line {n} is not two numbers (level, annual rate of exceedance)"
            ) from None
        if len(nums) != 2:
            raise ValueError(
                f"path: {path.name}, line {n} has {len(nums)} values; a two-column hazard "
                "curve has level, annual rate of exceedance"
            )
        values.append(nums)
    if len(values) < 2:
        raise ValueError(f"path: {path.name} holds fewer than 2 rows of level, rate")
    arr = np.array(values)
    return arr[:, 0], arr[:, 1], header


#: Units a level column's name may state (``pga_g``, ``PGA [g]``, ``pgv (cm/s)``, ``sa_gal``):
#: the unit, and the pattern that finds it in the lowercased name, the longer units first.
_HEADER_UNITS = (
    ("cm/s^2", r"cm/s\^?2|gal\b"),
    ("m/s^2", r"(?<!c)m/s\^?2"),
    ("cm/s", r"cm/s(?!\^?2)"),
    ("m/s", r"(?<!c)m/s(?!\^?2)"),
    ("g", r"(?:^|[_\s\[(])g(?:$|[\])\s])"),
)


def _check_header_units(path, header, im, units) -> None:
    """A ValueError naming ``units`` where the level column's name states another unit (a
    column ``pga_g`` read as m/s^2 would shift every level by a factor of 9.8), or naming
    ``im`` where it names another measure."""
    if not header or not header[1]:
        return
    n, name = header[0], header[1].lower()
    named = re.match(r"(pga|pgv|pgd|sa|psv|sd)(?![a-z])", name)
    if named and named.group(1) != im:
        raise ValueError(
            f"im: {path.name}, line {n}: the level column's name says a {named.group(1)} "
            f"curve, but it is read as {im!r}; give im = {named.group(1)!r} (or rename the "
            "column)"
        )
    stated = next((u for u, pattern in _HEADER_UNITS if re.search(pattern, name)), None)
    allowed = measures.units_of(im)  # name -> factor to SI, the SI unit first
    given = next(iter(allowed)) if units is None else units
    if stated is None or given not in allowed:
        return
    if allowed.get(stated) != allowed[given]:
        raise ValueError(
            f"units: {path.name}, line {n}: the level column's name states it in {stated}, "
            f"but the levels are read in {given!r}; give units = {stated!r} (or rename the "
            "column)"
        )


_META = re.compile(r"(\w+)\s*=\s*('[^']*'|\"[^\"]*\"|[^,\s\"']+)")


def _openquake_imt(imt, path, n):
    """(im, period, OpenQuake's units) of an OpenQuake IMT name such as PGA or SA(0.2)."""
    m = re.fullmatch(r"(PGA|PGV|PGD)|SA\(\s*([0-9.eE+-]+)\s*\)", imt)
    try:
        period = None if m is None or m.group(1) else float(m.group(2))
    except ValueError:
        m = None
    if m is None:
        raise ValueError(
            f"path: {path.name}, line {n}: rockstudy reads PGA, PGV, PGD and SA(T) "
            "curves, not the imt given there"
        )
    if m.group(1):
        return (*OPENQUAKE_IMTS[m.group(1)][:1], None, OPENQUAKE_IMTS[m.group(1)][1])
    return "sa", period, "g"


def _check_period(period, imt, file_period, path) -> None:
    """A ValueError naming ``period`` (and the file's) where one was given that is not the
    file's: the file says which measure its curve is of."""
    if period is None:
        return
    period = _validate.number("period", period)
    if file_period is None:
        raise ValueError(
            f"period={period!r} was given, but {path.name} is a hazard curve of {imt}, which "
            "has no period; leave period out"
        )
    if not math.isclose(period, file_period, rel_tol=1e-9):
        raise ValueError(
            f"period={period!r} was given, but {path.name} is a hazard curve of {imt}, at "
            f"T = {file_period:g} s; give period = {file_period:g} (or leave it out), or a "
            f"file of SA({period:g})"
        )


def _header(path, lines):
    """(investigation time [yr], imt) of an OpenQuake file's first line."""
    n, text = lines[0]
    meta = {k: v.strip("'\"") for k, v in _META.findall(text)}
    try:
        years = float(meta["investigation_time"])
        imt = meta["imt"]
    except (KeyError, ValueError):
        raise ValueError(
            f"path: {path.name}, line {n}: the OpenQuake header needs investigation_time="
            "<years> and imt=<measure>"
        ) from None
    if not (math.isfinite(years) and years > 0.0):
        raise ValueError(
            f"path: {path.name}, line {n}: investigation_time must be > 0, got {years!r}"
        )
    return years, imt


def _site_row(path, lines, site):
    """(levels, poe, site index, the row's line number) of an OpenQuake file."""
    n, text = lines[1] if len(lines) > 1 else (lines[0][0] + 1, "")
    header = [c.strip() for c in text.split(",")]
    cols = [j for j, c in enumerate(header) if c.startswith("poe-")]
    try:
        levels = np.array([float(header[j][4:]) for j in cols])
    except ValueError:
        cols = []
    if not cols:
        raise ValueError(
            f"path: {path.name}, line {n}: expected the column names lon,lat[,depth] and "
            "poe-<level> columns"
        )
    rows = lines[2:]
    if not rows:
        raise ValueError(f"path: {path.name} has no site rows")
    if site is None and len(rows) > 1:
        raise ValueError(f"site: {path.name} holds {len(rows)} sites; choose one with site=0..")
    i = 0 if site is None else _validate.count("site", site, 0, len(rows) - 1)
    n, text = rows[i]
    cells = text.split(",")
    try:
        poe = np.array([float(cells[j]) for j in cols])
    except (ValueError, IndexError):
        raise ValueError(
            f"path: {path.name}, line {n}: site {i} needs a number in each of the "
            f"{len(cols)} poe-<level> columns"
        ) from None
    return levels, poe, i, n


def _certain_and_impossible(path, levels, poe, where):
    """(first, keep): the leading levels of poe 1 and the trailing ones of poe 0 are dropped
    (poe[first:keep] is kept); a ValueError where fewer than two levels are left or a poe of
    1 stands above a lower level of less. ``where`` names the row ("line 3, site 0")."""
    bad = np.flatnonzero(~(poe >= 0.0) | ~(poe <= 1.0))
    if bad.size:
        raise ValueError(
            f"path: {path.name}, {where}: probabilities of exceedance must lie in [0, 1]; "
            f"the one at level {levels[bad[0]]:g} is {poe[bad[0]]:g}"
        )
    for value, meaning in ((1.0, "certain exceedance in the investigation time"), (0.0, "")):
        if np.all(poe == value):
            raise ValueError(
                f"path: {path.name}, {where}: every level has poe {value:g} "
                f"({meaning or 'below the precision OpenQuake prints'}), so no level has a "
                "finite annual rate > 0: no hazard curve to read"
            )
    first = int(np.count_nonzero(np.cumprod(poe == 1.0)))  # leading certain exceedances
    keep = poe.size
    while keep > first and poe[keep - 1] == 0.0:
        keep -= 1
    above = np.flatnonzero(poe[first:keep] >= 1.0)
    if above.size:
        raise ValueError(
            f"path: {path.name}, {where}: probabilities of exceedance of 1 stand above lower "
            f"levels with less (at level {levels[first + above[0]]:g})"
        )
    if keep - first < 2:
        raise ValueError(
            f"path: {path.name}, {where}: only {keep - first} level has a poe strictly "
            "between 0 and 1; a hazard curve needs at least 2"
        )
    return first, keep


def _warn_dropped(path, first, dropped_top):
    for count, what in (
        (first, "lowest level(s) have poe 1"),
        (dropped_top, "highest level(s) have poe 0"),
    ):
        if count:
            warnings.warn(
                f"{path.name}: {count} {what} (no positive finite rate) and were dropped; the "
                "curve is extrapolated there as the power law of its nearest interval",
                UserWarning,
                stacklevel=5,  # the caller of HazardCurve.from_csv
            )


def _from_openquake(cls, path, lines, im, units, period, site):
    years, imt = _header(path, lines)
    oq_im, file_period, oq_units = _openquake_imt(imt, path, lines[0][0])
    if im is not None and im != oq_im:
        raise ValueError(f"im={im!r}, but {path.name} is a hazard curve of {imt} ({oq_im!r})")
    _check_period(period, imt, file_period, path)
    levels, poe, i, n = _site_row(path, lines, site)
    first, keep = _certain_and_impossible(path, levels, poe, f"line {n}, site {i}")
    allowed = measures.units_of(oq_im)
    if units is not None and allowed.get(units) != allowed[oq_units]:
        raise ValueError(
            f"units: OpenQuake writes the levels of {imt} in {oq_units}, so {path.name} is "
            f"read in {oq_units}, not {units!r}; leave units out (or give {oq_units!r})"
        )
    _warn_dropped(path, first, poe.size - keep)
    rates = -np.log1p(-poe[first:keep]) / years
    source = f"{path} (OpenQuake, {imt}, investigation_time {years:g} yr, site {i})"
    return cls(oq_im, levels[first:keep], rates, units or oq_units, file_period, source)
