"""Seismic risk of overturning: site hazard curves and the mean annual rate of overturning.

A fragility (the probability of overturning given an intensity measure x, lognormal with
median theta and dispersion beta) meets the site's hazard curve lambda(x), the mean annual
rate of exceeding x, in the total-probability integral of Cornell et al. (2002):

.. math:: \\lambda_{OT} = \\int_0^\\infty P(OT \\mid x) \\, |d\\lambda(x)|

and the probability of at least one overturning in t years is 1 - exp(-lambda_OT t)
(Poisson occurrences). Everything here is plain numpy and scipy: a physics-layer module.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.special import log_ndtr, ndtr

from .constants import STANDARD_GRAVITY
from .motions import measures
from .motions.records import IMPOSSIBLE_PGA

#: Units a hazard curve's levels may be given in: name -> (factor to SI, SI unit). An IM's SI
#: unit is that of the registry (:mod:`rockstudy.motions.measures`); its levels may be in any
#: unit here of that dimension ("g" is the unit g, standard gravity 9.80665 m/s^2, as for
#: records and ``scale_to``).
UNIT_FACTORS = {
    "g": (STANDARD_GRAVITY, "m/s^2"),
    "m/s^2": (1.0, "m/s^2"),
    "m/s2": (1.0, "m/s^2"),
    "cm/s^2": (0.01, "m/s^2"),
    "cm/s2": (0.01, "m/s^2"),
    "gal": (0.01, "m/s^2"),
    "m/s": (1.0, "m/s"),
    "cm/s": (0.01, "m/s"),
    "m": (1.0, "m"),
    "cm": (0.01, "m"),
    "s": (1.0, "s"),
}

#: OpenQuake's IMT names -> (rockstudy IM, the unit OpenQuake gives its levels in).
OPENQUAKE_IMTS = {
    "PGA": ("pga", "g"),
    "SA": ("sa", "g"),
    "PGV": ("pgv", "cm/s"),
    "PGD": ("pgd", "cm"),
}


def _units_for(im: str, units: str | None, name: str = "units") -> str:
    """``units`` checked against the dimension of ``im`` (its SI unit when None)."""
    si = measures.measure(im).unit
    if units is None or units == si:
        return si
    allowed = sorted(u for u, (_, dim) in UNIT_FACTORS.items() if dim == si)
    if units not in UNIT_FACTORS:
        raise ValueError(f"{name} of {im!r} must be one of {allowed}, got {units!r}")
    if UNIT_FACTORS[units][1] != si:
        raise ValueError(
            f"{name}={units!r} is not a unit of {im!r}, which is in {si}: use one of {allowed}"
        )
    return units


def _positive_increasing(name, values) -> np.ndarray:
    arr = np.array(values, dtype=float)
    if arr.ndim != 1 or arr.size < 2:
        raise ValueError(f"{name} must be a 1-D sequence of at least 2 numbers")
    bad = np.flatnonzero(~(np.isfinite(arr) & (arr > 0.0)))
    if bad.size:
        raise ValueError(
            f"{name} must be finite and > 0; {name}[{bad[0]}] = {float(arr[bad[0]])!r}"
        )
    return arr


@dataclass(frozen=True, eq=False)
class HazardCurve:
    """The mean annual rate of exceeding each level of an intensity measure at a site.

    Between its levels the curve is interpolated linearly in (ln x, ln lambda), a power law
    on each interval; below the first level and above the last it is extrapolated as the
    power law of the first and of the last interval (see :func:`annual_rate`).

    Parameters
    ----------
    im : str
        The intensity measure, a name of :data:`rockstudy.motions.measures.MEASURES` (``"pga"``,
        ``"pgv"``, ``"sa"``, ...).
    levels : array_like
        IM levels x, in ``units``: at least two, finite, > 0 and strictly increasing.
    rates : array_like
        Mean annual rates of exceeding each level [1/yr]: finite, > 0 and non-increasing,
        one per level; the last two must differ (the curve must fall above its last level).
    units : str, optional
        The units of ``levels``, one of :data:`UNIT_FACTORS` of the IM's dimension (e.g.
        ``"g"``, ``"m/s^2"`` or ``"cm/s^2"`` for ``pga``; ``"m/s"`` or ``"cm/s"`` for ``pgv``).
        Default: the IM's SI unit.
    period : float, optional
        The period T [s] of a spectral IM (``sa``, ``psv``, ``sd``): required for those,
        refused for the others.
    source : str
        Where the curve comes from (a file, a power law), for reports.
    """

    im: str
    levels: np.ndarray
    rates: np.ndarray
    units: str | None = None
    period: float | None = None
    source: str = ""

    def __post_init__(self):
        measures.measure(self.im)
        units = _units_for(self.im, self.units)
        levels = _positive_increasing("levels", self.levels)
        step = np.flatnonzero(np.diff(levels) <= 0.0)
        if step.size:
            i = int(step[0]) + 1
            raise ValueError(
                f"levels must be strictly increasing; levels[{i}] = {float(levels[i])!r} follows "
                f"levels[{i - 1}] = {float(levels[i - 1])!r}"
            )
        rates = _positive_increasing("rates", self.rates)
        if rates.size != levels.size:
            raise ValueError(
                f"rates has {rates.size} values but levels has {levels.size}: one rate per level"
            )
        up = np.flatnonzero(np.diff(rates) > 0.0)
        if up.size:
            i = int(up[0]) + 1
            raise ValueError(
                f"rates must be non-increasing (a rate of exceedance falls as the level rises); "
                f"rates[{i}] = {float(rates[i])!r} exceeds rates[{i - 1}] = {float(rates[i - 1])!r}"
            )
        if rates[-1] == rates[-2]:
            raise ValueError(
                "rates: the last two rates are equal, so the curve extrapolated above its last "
                "level would never fall to zero; end the curve where it still falls"
            )
        self._check_period()
        _check_plausible(self.im, levels, units)
        for arr in (levels, rates):
            arr.flags.writeable = False
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "levels", levels)
        object.__setattr__(self, "rates", rates)

    def _check_period(self):
        if measures.measure(self.im).needs_period:
            p = self.period
            if p is None or not (math.isfinite(float(p)) and float(p) > 0.0):
                raise ValueError(f"period: a {self.im!r} hazard curve needs its period T > 0 [s]")
            object.__setattr__(self, "period", float(p))
        elif self.period is not None:
            raise ValueError(
                f"period is only for the spectral measures (those that need one), not {self.im!r}"
            )

    def __repr__(self) -> str:
        return f"<HazardCurve {self.describe()}>"

    def describe(self) -> str:
        """The curve in words: its measure, levels and rates (as the reports quote it)."""
        at = f" at T = {self.period:g} s" if self.period is not None else ""
        return (
            f"{self.im.upper()}{at} hazard curve of {self.levels.size} levels, "
            f"{self.levels[0]:.4g} to {self.levels[-1]:.4g} {self.units}, annual rates of "
            f"exceedance {self.rates[0]:.4g} to {self.rates[-1]:.4g} /yr"
        )

    def to_si(self) -> HazardCurve:
        """The same curve with its levels in the IM's SI unit (e.g. g -> m/s^2)."""
        return self.to_units(measures.measure(self.im).unit)

    def to_units(self, units: str) -> HazardCurve:
        """The same curve with its levels in ``units`` (of the IM's dimension)."""
        units = _units_for(self.im, units)
        if units == self.units:
            return self
        factor = UNIT_FACTORS[self.units][0] / UNIT_FACTORS[units][0]
        return HazardCurve(
            self.im, self.levels * factor, self.rates, units, self.period, self.source
        )

    def rate(self, x):
        """The mean annual rate of exceeding ``x`` [1/yr] (``x`` in the curve's units, > 0):
        log-log interpolation between the levels, the end intervals' power laws beyond."""
        lx = np.log(np.asarray(x, dtype=float))
        lev, lr = np.log(self.levels), np.log(self.rates)
        k = _slopes(lev, lr)
        out = np.interp(lx, lev, lr)
        out = np.where(lx < lev[0], lr[0] - k[0] * (lx - lev[0]), out)
        out = np.where(lx > lev[-1], lr[-1] - k[-1] * (lx - lev[-1]), out)
        return np.exp(out)

    @classmethod
    def power_law(cls, k0, k, im="pga", units=None, period=None, levels=None) -> HazardCurve:
        """The power-law hazard lambda(x) = k0 x^-k (Cornell et al. 2002).

        Parameters
        ----------
        k0 : float
            The rate at x = 1 (in ``units``) [1/yr], > 0.
        k : float
            The log-log slope, > 0.
        im, units, period
            As for :class:`HazardCurve` (``k0`` depends on the units of x).
        levels : array_like, optional
            Where to tabulate it (default 40 levels over 1e-3 to 10 in ``units``); the
            log-log interpolation of :class:`HazardCurve` reproduces the power law exactly at
            every x, also outside the levels.
        """
        k0, k = _positive("k0", k0), _positive("k", k)
        x = np.geomspace(1e-3, 10.0, 40) if levels is None else np.asarray(levels, dtype=float)
        return cls(im, x, k0 * x**-k, units, period, f"power law {k0:g} x^-{k:g}")

    @classmethod
    def from_csv(cls, path, im=None, units=None, period=None, site=None) -> HazardCurve:
        """Read a hazard curve: a two-column text file, or an OpenQuake hazard-curve CSV.

        **Two columns**: IM level (in ``units``) and mean annual rate of exceedance [1/yr],
        separated by commas or blanks; lines starting with ``#`` and a first row of column
        names are skipped. ``im`` is required (the file does not say it).

        **OpenQuake**: the ``hazard_curve-*.csv`` that ``oq engine --export-outputs`` writes
        for classical PSHA, read as engine 3.11 to 3.23 write it (and its QA test files). Its
        first line is a ``#`` comment of ``key=value`` metadata, holding
        ``investigation_time=T`` and ``imt='PGA'`` (older versions: ``# ..., investigation_time
        =1.0,imt="PGA"``; newer ones wrap it as ``#,,,,,"generated_by=..., kind='mean', ...
        imt='SA(0.1)'"``); the second line names the columns ``lon,lat[,depth],poe-<level>,
        ...``; then one row per site. The values are probabilities of exceedance in T years,
        turned into annual rates as lambda = -ln(1 - poe) / T (Poisson). Levels follow
        OpenQuake's units: g for PGA and SA(T) (``im`` "sa", ``period`` T), cm/s for PGV,
        cm for PGD. Trailing levels of poe 0 (below OpenQuake's printed precision) are dropped
        with a warning; the curve is extrapolated there as the power law of its last interval.

        Parameters
        ----------
        path : str or Path
            The file.
        im : str, optional
            The IM; for an OpenQuake file it must match the file's ``imt`` when given.
        units : str, optional
            The units of the levels (default: the IM's SI unit for two columns, OpenQuake's
            for its files).
        period : float, optional
            The period [s] of a spectral IM in a two-column file.
        site : int, optional
            The row (from 0) of an OpenQuake file with several sites.
        """
        path = Path(path)
        try:
            lines = path.read_text().splitlines()
        except (OSError, UnicodeDecodeError) as err:
            raise ValueError(f"path: cannot read the hazard curve {str(path)!r}: {err}") from None
        lines = [ln.strip() for ln in lines if ln.strip()]
        if lines and lines[0].startswith("#") and "investigation_time" in lines[0]:
            return _from_openquake(path, lines, im, units, site)
        if im is None:
            raise ValueError(
                f"im: {path.name} is a two-column file, which does not name its intensity "
                f"measure: give im= (one of {list(measures.MEASURES)}) and units="
            )
        levels, rates, header = _two_columns(path, lines)
        _check_header_units(path, header, im, units)
        return cls(im, levels, rates, units, period, str(path))


#: Levels no ground motion reaches, in SI (the largest PGA recorded is about 4 g, the largest
#: PGV about 4 m/s): a hazard curve beyond them has its levels in other units than declared.
IMPOSSIBLE_LEVELS = {"pga": IMPOSSIBLE_PGA, "sa": 30.0 * STANDARD_GRAVITY, "pgv": 10.0}


def _check_plausible(im, levels, units) -> None:
    """A ValueError naming ``units`` where the highest level, read in ``units``, is beyond any
    ground motion (:data:`IMPOSSIBLE_LEVELS`): a curve in cm/s^2 read as g reaches
    hundreds of g."""
    limit = IMPOSSIBLE_LEVELS.get(im)
    top = float(levels[-1]) * UNIT_FACTORS[units][0]
    if limit is None or top <= limit * (1.0 + 1e-9):  # (10 g in cm/s^2 rounds above it)
        return
    quoted = "g" if UNIT_FACTORS[units][1] == "m/s^2" else UNIT_FACTORS[units][1]
    shown = "" if units == quoted else f" = {top / UNIT_FACTORS[quoted][0]:.4g} {quoted}"
    raise ValueError(
        f"units: the levels reach {float(levels[-1]):.4g} {units}{shown} of "
        f"{im}, beyond any ground motion (above {limit / UNIT_FACTORS[quoted][0]:.3g} "
        f"{quoted}): are they in other units (cm/s^2 or gal read as g, cm/s as m/s)? give "
        "the units the levels are in"
    )


def _positive(name, value) -> float:
    value = float(value)
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def _slopes(log_levels, log_rates):
    """The log-log slope k of each interval, lambda ~ x^-k."""
    return -np.diff(log_rates) / np.diff(log_levels)


def _two_columns(path, lines):
    """(levels, rates, the first column's name or None) of a two-column file."""
    rows = [ln for ln in lines if not ln.startswith("#")]
    values, header = [], None
    for i, ln in enumerate(rows):
        cells = [c for c in re.split(r"[,;\s]+", ln) if c]
        try:
            nums = [float(c) for c in cells]
        except ValueError:
            if i == 0:  # a row of column names
                sep = r"[,;]" if re.search(r"[,;]", ln) else r"\s+"
                header = re.split(sep, ln)[0].strip() or None
                continue
            raise ValueError(f"path: {path.name}: line {ln!r} is not two numbers") from None
        if len(nums) != 2:
            raise ValueError(
                f"path: {path.name}: line {ln!r} has {len(nums)} values; a two-column hazard "
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
    column ``pga_g`` read as m/s^2 would shift every level by a factor of 9.8)."""
    if not header:
        return
    name = header.lower()
    named = re.match(r"(pga|pgv|pgd|sa|psv|sd)(?![a-z])", name)
    if named and named.group(1) != im:
        raise ValueError(
            f"im: {path.name} names its level column {header!r}, a {named.group(1)} curve, "
            f"but it is read as {im!r}; give im = {named.group(1)!r} (or rename the column)"
        )
    stated = next((u for u, pattern in _HEADER_UNITS if re.search(pattern, name)), None)
    given = measures.measure(im).unit if units is None else units
    if stated is None or stated not in UNIT_FACTORS or given not in UNIT_FACTORS:
        return
    if UNIT_FACTORS[stated] != UNIT_FACTORS[given]:
        raise ValueError(
            f"units: {path.name} names its level column {header!r}, in {stated}, but the "
            f"levels are read in {given!r}; give units = {stated!r} (or rename the column)"
        )


_META = re.compile(r"(\w+)\s*=\s*('[^']*'|\"[^\"]*\"|[^,\s\"']+)")


def _openquake_imt(imt, path):
    """(im, period, OpenQuake's units) of an OpenQuake IMT name such as PGA or SA(0.2)."""
    m = re.fullmatch(r"(PGA|PGV|PGD)|SA\(\s*([0-9.eE+-]+)\s*\)", imt)
    if m is None:
        raise ValueError(
            f"path: {path.name} is a hazard curve of imt {imt!r}; rockstudy reads "
            "PGA, PGV, PGD and SA(T)"
        )
    if m.group(1):
        return (*OPENQUAKE_IMTS[m.group(1)][:1], None, OPENQUAKE_IMTS[m.group(1)][1])
    return "sa", float(m.group(2)), "g"


def _from_openquake(path, lines, im, units, site) -> HazardCurve:
    meta = {k: v.strip("'\"") for k, v in _META.findall(lines[0])}
    try:
        years = float(meta["investigation_time"])
        imt = meta["imt"]
    except (KeyError, ValueError):
        raise ValueError(
            f"path: {path.name}: the OpenQuake header needs investigation_time and imt, got "
            f"{lines[0]!r}"
        ) from None
    if not (math.isfinite(years) and years > 0.0):
        raise ValueError(f"path: {path.name}: investigation_time must be > 0, got {years!r}")
    oq_im, period, oq_units = _openquake_imt(imt, path)
    if im is not None and im != oq_im:
        raise ValueError(f"im={im!r}, but {path.name} is a hazard curve of {imt} ({oq_im!r})")
    header = [c.strip() for c in lines[1].split(",")] if len(lines) > 1 else []
    cols = [j for j, c in enumerate(header) if c.startswith("poe-")]
    if not cols:
        raise ValueError(f"path: {path.name}: no poe-<level> columns in {lines[1:2]!r}")
    rows = lines[2:]
    if not rows:
        raise ValueError(f"path: {path.name} has no site rows")
    if site is None and len(rows) > 1:
        raise ValueError(f"site: {path.name} holds {len(rows)} sites; choose one with site=0..")
    i = 0 if site is None else int(site)
    if not 0 <= i < len(rows):
        raise ValueError(f"site must lie in 0..{len(rows) - 1}, got {site!r}")
    try:
        cells = rows[i].split(",")
        levels = np.array([float(header[j][4:]) for j in cols])
        poe = np.array([float(cells[j]) for j in cols])
    except (ValueError, IndexError):
        raise ValueError(f"path: {path.name}: site row {rows[i]!r} is not numbers") from None
    if np.any(~(poe >= 0.0) | ~(poe <= 1.0)):
        raise ValueError(
            f"path: {path.name}: probabilities of exceedance must lie in [0, 1]; got {poe!r}"
        )
    first = int(np.count_nonzero(np.cumprod(poe == 1.0)))  # leading certain exceedances
    keep = poe.size
    while keep > first and poe[keep - 1] == 0.0:
        keep -= 1
    for count, what in (
        (first, "lowest level(s) have poe 1"),
        (poe.size - keep, "highest level(s) have poe 0"),
    ):
        if count:
            warnings.warn(
                f"{path.name}: {count} {what} (no positive finite rate) and were dropped; the "
                "curve is extrapolated there as the power law of its nearest interval",
                UserWarning,
                stacklevel=3,
            )
    if first == poe.size or np.any(poe[first:keep] >= 1.0):
        raise ValueError(
            f"path: {path.name}: probabilities of exceedance of 1 stand above lower levels "
            f"with less: {poe!r}"
        )
    if units is not None and UNIT_FACTORS.get(units) != UNIT_FACTORS[oq_units]:
        raise ValueError(
            f"units: OpenQuake writes the levels of {imt} in {oq_units}, so {path.name} is "
            f"read in {oq_units}, not {units!r}; leave units out (or give {oq_units!r})"
        )
    rates = -np.log1p(-poe[first:keep]) / years
    source = f"{path} (OpenQuake, {imt}, investigation_time {years:g} yr, site {i})"
    return HazardCurve(oq_im, levels[first:keep], rates, units or oq_units, period, source)


def _fragility(median, dispersion, hazard, units):
    """(ln theta, beta) broadcast together, with theta in the hazard's units."""
    if not isinstance(hazard, HazardCurve):
        raise TypeError(f"hazard must be a HazardCurve, got {type(hazard).__name__}")
    units = _units_for(hazard.im, units or hazard.units)
    med = _array("median", median, True, f" (in {units})")
    beta = _array("dispersion", dispersion, False)
    factor = UNIT_FACTORS[units][0] / UNIT_FACTORS[hazard.units][0]
    return np.broadcast_arrays(np.log(med * factor), beta)


def _array(name, value, strict, what=""):
    """``value`` as a float array, or a ValueError unless finite and > 0 (``strict``) or >= 0."""
    arr = np.asarray(value, dtype=float)
    if np.any(~np.isfinite(arr) | ((arr <= 0.0) if strict else (arr < 0.0))):
        raise ValueError(
            f"{name} must be finite and {'>' if strict else '>='} 0{what}, got {value!r}"
        )
    return arr


def _log_normal_mass(za, zb):
    """ln(Phi(zb) - Phi(za)) for za < zb (standard normal), without cancellation: on the
    lower half from the cdf, on the upper half from the survival function."""
    lo = za + zb < 0.0
    a, b = np.where(lo, za, -zb), np.where(lo, zb, -za)
    la, lb = log_ndtr(a), log_ndtr(b)
    with np.errstate(divide="ignore"):
        return lb + np.log1p(-np.exp(la - lb))


def _bins(hazard):
    """(lower edge, upper edge, ln rate at the anchor, ln anchor level, slope k) of the
    n + 1 intervals of the interpolated curve: (0, x_0], [x_0, x_1], ..., [x_{n-1}, inf),
    each a power law lambda = lambda_a (x / x_a)^-k anchored at a level x_a."""
    lev, lr = np.log(hazard.levels), np.log(hazard.rates)
    k = _slopes(lev, lr)
    lower = np.concatenate([[-np.inf], lev])
    upper = np.concatenate([lev, [np.inf]])
    anchor = np.concatenate([lev[:1], lev])
    log_rate = np.concatenate([lr[:1], lr])
    slope = np.concatenate([k[:1], k, k[-1:]])
    return lower, upper, log_rate, anchor, slope


def _capacity_expectations(mu, beta, hazard, cut=None):
    """E[lambda(C); C in bin, C > x_u] per bin (last axis) for a lognormal capacity C (ln C ~
    N(mu, beta^2)), in closed form: on a bin where lambda = lambda_a (x / x_a)^-k,
    E[C^-k; a < C < b] = exp(-k mu + k^2 beta^2 / 2) [Phi(z_b) - Phi(z_a)],
    z = (ln x - mu + k beta^2) / beta. ``cut`` is ln x_u (broadcast with ``mu``; None: no
    cut): each bin's lower edge is raised to it, and a bin wholly below it gives 0."""
    lower, upper, log_rate, anchor, k = _bins(hazard)
    mu, beta = mu[..., None], beta[..., None]
    if cut is not None:
        lower = np.maximum(lower, cut[..., None])
    spread = np.where(beta > 0.0, beta, 1.0)
    shift = mu - k * beta**2
    below = lower >= upper  # (a bin under the cut)
    with np.errstate(invalid="ignore"):
        za = np.where(below, -np.inf, (lower - shift) / spread)
        mass = _log_normal_mass(za, np.where(below, np.inf, (upper - shift) / spread))
    log_e = log_rate + k * (anchor - mu) + 0.5 * (k * beta) ** 2 + mass
    sharp = log_rate - k * (mu - anchor)  # beta = 0: lambda(theta) in the bin holding theta
    inside = (lower < mu) & (mu <= upper)
    out = np.where(beta > 0.0, np.exp(log_e), np.where(inside, np.exp(sharp), 0.0))
    return np.where(below, 0.0, out)


def _threshold(threshold, units, hazard, shape):
    """ln x_u of ``threshold`` (in ``units``) in the hazard's units, broadcast to ``shape``;
    None for no threshold."""
    if threshold is None:
        return None
    units = _units_for(hazard.im, units or hazard.units)
    x_u = _array("threshold", threshold, True, f" (in {units})")
    factor = UNIT_FACTORS[units][0] / UNIT_FACTORS[hazard.units][0]
    return np.broadcast_to(np.log(x_u * factor), shape)


def _fragility_at(log_x, mu, beta):
    """The lognormal fragility Phi((ln x - mu) / beta) (a step at mu for beta = 0)."""
    spread = np.where(beta > 0.0, beta, 1.0)
    return np.where(beta > 0.0, ndtr((log_x - mu) / spread), (log_x >= mu).astype(float))


def annual_rate(median, dispersion, hazard: HazardCurve, units: str | None = None, threshold=None):
    """The mean annual rate of overturning [1/yr] of a lognormal fragility at a site.

    .. math:: \\lambda_{OT} = \\int_0^\\infty \\Phi\\left(\\frac{\\ln(x/\\theta)}{\\beta}
              \\right) |d\\lambda(x)| = \\int_0^\\infty \\lambda(x) \\, dF_C(x)

    (Cornell et al. 2002, the total-probability integral of the SAC/FEMA framework; the
    second form, by parts, is the expected hazard at the capacity C, ln C ~ N(ln theta,
    beta^2)). The hazard is the :class:`HazardCurve` interpolated log-log between its levels,
    a power law on each interval, and extrapolated below its first level and above its last
    as the power laws of its end intervals: so the integral runs over all x, the fragility
    mass below and above the grid counted on those power laws, and on each interval it is
    integrated exactly, E[C^-k; a < C < b] being a normal probability times
    exp(-k ln theta + k^2 beta^2 / 2). The only approximation is the interpolation of the
    hazard: exact for a power-law hazard, where the result is Cornell et al.'s closed form
    k0 theta^-k exp(k^2 beta^2 / 2), and for a curved hazard within the error of its log-log
    interpolation (for ln lambda = c0 - k1 ln x - k2 ln^2 x on a grid of step d in ln x,
    lambda_OT low by about k2 d^2 / 6, at most k2 d^2 / 4, relatively). How much comes from
    beyond the grid is given by :func:`rate_deaggregation`.

    With a ``threshold`` x_u the fragility is 0 below it (an intensity at which the structure
    cannot overturn: below its uplift PGA a rocking structure without vertical shaking does
    not even leave rest) and the lognormal above it:

    .. math:: \\lambda_{OT} = \\int_{x_u}^\\infty \\Phi\\left(\\frac{\\ln(x/\\theta)}{\\beta}
              \\right) |d\\lambda(x)| = \\lambda(x_u) \\Phi\\left(\\frac{\\ln(x_u/\\theta)}
              {\\beta}\\right) + \\int_{x_u}^\\infty \\lambda(x) \\, dF_C(x)

    each interval's part again in closed form (for a power-law hazard k0 x^-k:
    k0 [x_u^-k Phi(z_u) + theta^-k exp(k^2 beta^2 / 2) Phi(-z_u - k beta)],
    z_u = ln(x_u / theta) / beta).

    Parameters
    ----------
    median : float or array_like
        The fragility's median theta, > 0, in ``units``.
    dispersion : float or array_like
        Its logarithmic standard deviation beta, >= 0 (0: a sharp capacity, lambda(theta)).
    hazard : HazardCurve
        The site's hazard curve of the same IM.
    units : str, optional
        The units of ``median`` and ``threshold`` (default: the hazard's, ``hazard.units``).
    threshold : float or array_like, optional
        x_u > 0, in ``units``: the fragility is 0 below it (default: none, the whole
        lognormal).

    Returns
    -------
    float or ndarray
        lambda_OT [1/yr], of the broadcast shape of ``median``, ``dispersion`` and
        ``threshold``.
    """
    if threshold is not None:
        out = rate_deaggregation(median, dispersion, hazard, units, threshold)[2].sum(axis=-1)
        return float(out) if out.ndim == 0 else out
    mu, beta = _fragility(median, dispersion, hazard, units)
    out = _capacity_expectations(mu, beta, hazard).sum(axis=-1)
    return float(out) if out.ndim == 0 else out


def rate_deaggregation(
    median, dispersion, hazard: HazardCurve, units: str | None = None, threshold=None
):
    """Which IM levels the annual rate of overturning comes from.

    The contribution of each interval of the hazard curve's levels to
    ``lambda_OT = int P(OT | x) |d lambda(x)|`` (:func:`annual_rate`): for [a, b],
    lambda(a) F(a) - lambda(b) F(b) + int_a^b lambda dF (by parts, each term in closed form on
    the interval's power law), with F the fragility. The first interval is (0, x_0] and the
    last [x_{n-1}, inf): what the extrapolation beyond the grid contributes. With a
    ``threshold`` x_u (the fragility 0 below it) the intervals below x_u give 0 and the one
    holding it lambda(x_u) F(x_u) - lambda(b) F(b) + int_{x_u}^b lambda dF.

    Parameters
    ----------
    median, dispersion, hazard, units, threshold
        As for :func:`annual_rate`.

    Returns
    -------
    lower, upper : ndarray
        The n + 1 interval edges, in the hazard's units (0 and inf at the ends).
    contributions : ndarray
        Each interval's share of lambda_OT [1/yr] on the last axis (they sum to it), of the
        broadcast shape of ``median`` and ``dispersion`` plus (n + 1,).
    """
    mu, beta = _fragility(median, dispersion, hazard, units)
    cut = _threshold(threshold, units, hazard, np.broadcast_shapes(mu.shape, np.shape(threshold)))
    if cut is not None:
        mu, beta, cut = np.broadcast_arrays(mu, beta, cut)
    parts = _capacity_expectations(mu, beta, hazard, cut)
    lev = np.log(hazard.levels)
    cdf = _fragility_at(lev, mu[..., None], beta[..., None])
    if cut is not None:
        cdf = np.where(lev >= cut[..., None], cdf, 0.0)
    edge = hazard.rates * cdf  # lambda(x_i) F(x_i) at each level
    zero = np.zeros(edge.shape[:-1] + (1,))
    parts = parts + np.concatenate([zero, edge], axis=-1) - np.concatenate([edge, zero], axis=-1)
    if cut is not None:  # lambda(x_u) F(x_u) opens the interval x_u lies inside (at a
        # level, the edge term there opens the next), and those below x_u give nothing
        holds = np.searchsorted(lev, cut, side="right")[..., None]
        on_level = np.take(np.append(-np.inf, lev), holds) == cut[..., None]
        start = (hazard.rate(np.exp(cut)) * _fragility_at(cut, mu, beta))[..., None]
        start = np.where(on_level, 0.0, start)
        np.put_along_axis(parts, holds, np.take_along_axis(parts, holds, -1) + start, -1)
        parts = np.where(np.append(lev, np.inf) <= cut[..., None], 0.0, parts)
    lower = np.concatenate([[0.0], hazard.levels])
    upper = np.concatenate([hazard.levels, [np.inf]])
    return lower, upper, parts


def probability_in(years, rate):
    """The probability of at least one occurrence in ``years`` of a Poisson process of mean
    annual rate ``rate``.

    .. math:: P = 1 - e^{-\\lambda t}

    Parameters
    ----------
    years : float or array_like
        The exposure time t [yr], > 0.
    rate : float or array_like
        lambda [1/yr], >= 0 (e.g. :func:`annual_rate`).

    Returns
    -------
    float or ndarray
        P, broadcast over ``years`` and ``rate``.
    """
    t = _array("years", years, True)
    lam = _array("rate", rate, False, " [1/yr]")
    out = -np.expm1(-lam * t)
    return float(out) if out.ndim == 0 else out
