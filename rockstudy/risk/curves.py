"""Site hazard curves: the mean annual rate of exceeding each level of an intensity measure,
their units, and the power law of Cornell et al. (2002)."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..constants import STANDARD_GRAVITY
from ..motions import measures
from ..motions.records import IMPOSSIBLE_PGA
from ..warnings import UnitsWarning
from .readers import read_curve
from .units import to_si, units_for

__all__ = [
    "DESIGN_LEVEL_BOUNDS",
    "DESIGN_RATE",
    "HazardCurve",
    "IMPOSSIBLE_LEVELS",
    "level_at_rate",
    "LOG_HUGE",
    "LOG_TINY",
    "RECORD_RATES",
    "suite_off_curve",
]


def _positive_increasing(name, values) -> np.ndarray:
    """``values`` as a 1-D float array of at least two finite numbers > 0, or a ValueError
    (a :class:`rockstudy._validate.NotANumberError` for strings and booleans) naming
    ``name``."""
    arr = np.array(_validate.numbers_array(name, values))
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
        The units of ``levels``, one of :func:`rockstudy.motions.measures.units_of` the IM:
        those of :data:`UNIT_FACTORS` of its dimension (e.g. ``"g"``, ``"m/s^2"``, ``"cm/s^2"``
        or ``"gal"`` for ``pga``; ``"m/s"``, ``"cm/s"`` or ``"g s"`` for ``pgv``) and its
        quoted unit. Default: the IM's SI unit.
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
        units = units_for(self.im, self.units)
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
        _check_design_level(self.im, levels, rates, units)
        for arr in (levels, rates):
            arr.flags.writeable = False
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "levels", levels)
        object.__setattr__(self, "rates", rates)

    def _check_period(self):
        if measures.measure(self.im).needs_period:
            if self.period is None:
                raise ValueError(f"period: a {self.im!r} hazard curve needs its period T > 0 [s]")
            p = _validate.number("period", self.period)
            if not (math.isfinite(p) and p > 0.0):
                raise ValueError(f"period: a {self.im!r} hazard curve needs its period T > 0 [s]")
            object.__setattr__(self, "period", p)
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

    @property
    def si_factor(self) -> float:
        """The factor from the curve's :attr:`units` to the SI unit of its IM."""
        return to_si(self.im, self.units)

    def to_si(self) -> HazardCurve:
        """The same curve with its levels in the IM's SI unit (e.g. g -> m/s^2)."""
        return self.to_units(measures.measure(self.im).unit)

    def to_units(self, units: str) -> HazardCurve:
        """The same curve with its levels in ``units`` (of the IM's dimension)."""
        units = units_for(self.im, units)
        if units == self.units:
            return self
        factor = self.si_factor / to_si(self.im, units)
        return HazardCurve(
            self.im, self.levels * factor, self.rates, units, self.period, self.source
        )

    def rate(self, x):
        """The mean annual rate of exceeding ``x`` [1/yr] (``x`` in the curve's units, > 0;
        inf gives 0): log-log interpolation between the levels, the end intervals' power laws
        beyond."""
        x = _validate.numbers_array("x", x)
        bad = np.flatnonzero(~(x > 0.0))
        if bad.size:
            raise ValueError(f"x must be > 0, got {float(x.flat[bad[0]])!r}")
        log_rate = self.log_rate(np.log(x))
        over = np.flatnonzero(log_rate >= LOG_HUGE)
        if over.size:
            raise ValueError(
                f"x: the rate of exceeding {float(x.flat[over[0]]):g} {self.units} is beyond "
                "floating point: the curve's power law below its first level grows without "
                "bound as x -> 0"
            )
        return np.exp(log_rate)

    def log_rate(self, log_x):
        """ln lambda at ln x = ``log_x`` (an array, -inf to inf): :meth:`rate` in logs, which
        never overflows."""
        lev, lr = np.log(self.levels), np.log(self.rates)
        k = _slopes(lev, lr)
        out = np.interp(log_x, lev, lr)
        out = np.where(log_x < lev[0], lr[0] - k[0] * (log_x - lev[0]), out)
        return np.where(log_x > lev[-1], lr[-1] - k[-1] * (log_x - lev[-1]), out)

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
            As for :class:`HazardCurve`. ``units`` is required where the IM's dimension has
            several units (``pga``: g, m/s^2, cm/s^2): ``k0`` is the rate at x = 1 in them, so
            the same k0 read in m/s^2 instead of g changes every rate by 9.81^k.
        levels : array_like, optional
            Where to tabulate it (default 40 levels over 1e-3 to 10 in ``units``); the
            log-log interpolation of :class:`HazardCurve` reproduces the power law exactly at
            every x, also outside the levels.
        """
        k0, k = _validate.positive("k0", k0), _validate.positive("k", k)
        x = (
            np.geomspace(1e-3, 10.0, 40)
            if levels is None
            else _positive_increasing("levels", levels)
        )
        _check_representable(k0, k, x)
        if units is None:
            choices = list(measures.units_of(im))
            if len(choices) > 1:
                raise ValueError(
                    f"units: a power law of {im!r} needs the units of x, since k0 is the rate "
                    f"at x = 1 in them (one of {choices})"
                )
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
            The period [s] of a spectral IM in a two-column file; for an OpenQuake file it
            must be the file's (``imt`` SA(T)) when given, and is refused for its other IMs.
        site : int, optional
            The row (from 0) of an OpenQuake file with several sites; not for a two-column
            file.

        The file must be a regular file of at most
        :data:`rockstudy.motions.records.MAX_RECORD_BYTES` (pipes, devices and folders are
        refused before reading); errors name the file and the line, never its contents.
        """
        return read_curve(cls, path, im, units, period, site)


#: Levels no ground motion reaches, in SI (the largest PGA recorded is about 4 g, the largest
#: PGV about 4 m/s): a hazard curve beyond them has its levels in other units than declared.
IMPOSSIBLE_LEVELS = {"pga": IMPOSSIBLE_PGA, "sa": 30.0 * STANDARD_GRAVITY, "pgv": 10.0}


def _check_plausible(im, levels, units) -> None:
    """A ValueError naming ``units`` where the highest level, read in ``units``, is beyond any
    ground motion (:data:`IMPOSSIBLE_LEVELS`): a curve in cm/s^2 read as g reaches
    hundreds of g."""
    limit = IMPOSSIBLE_LEVELS.get(im)
    top = float(levels[-1]) * to_si(im, units)
    if limit is None or top <= limit * (1.0 + 1e-9):  # (10 g in cm/s^2 rounds above it)
        return
    quoted = "g" if measures.is_acceleration(im) else measures.measure(im).unit
    shown = "" if units == quoted else f" = {top / to_si(im, quoted):.4g} {quoted}"
    raise ValueError(
        f"units: the levels reach {float(levels[-1]):.4g} {units}{shown} of "
        f"{im}, beyond any ground motion (above {limit / to_si(im, quoted):.3g} "
        f"{quoted}): are they in other units (cm/s^2 or gal read as g, cm/s as m/s)? give "
        "the units the levels are in"
    )


#: The annual rate of the usual design level: 10 % in 50 years (a 475-year return period).
DESIGN_RATE = 1.0 / 475.0

#: Where the level a curve of acceleration reaches at :data:`DESIGN_RATE` may lie, in g:
#: (refused below, warned below, warned above, refused above), for a peak measure (PGA) and a
#: spectral one (Sa, up to about 2.5 times PGA). Real sites' 475-year PGAs lie between about
#: 0.02 g (stable regions) and 1.2 g (next to the fastest faults); a curve in m/s^2 read as g
#: reads 9.8 times high, one in g read as m/s^2 9.8 times low.
DESIGN_LEVEL_BOUNDS = {False: (0.002, 0.02, 1.2, 2.0), True: (0.0, 0.002, 3.0, 5.0)}


def level_at_rate(levels, rates, rate: float) -> float:
    """The level x at which the curve's rate of exceedance is ``rate`` [1/yr]: the log-log
    interpolation of :meth:`HazardCurve.rate` inverted, its end intervals' power laws beyond
    (NaN where a flat end interval never reaches it)."""
    lev, lr, target = np.log(levels), np.log(rates), math.log(rate)
    k = _slopes(lev, lr)
    if target >= lr[0]:
        return math.exp(lev[0] - (target - lr[0]) / k[0]) if k[0] > 0.0 else math.nan
    if target <= lr[-1]:
        return math.exp(lev[-1] + (lr[-1] - target) / k[-1])
    i = int(np.flatnonzero(lr <= target)[0])  # lr[i - 1] > target >= lr[i]
    return math.exp(lev[i - 1] + (lr[i - 1] - target) / k[i - 1])


def _check_design_level(im, levels, rates, units) -> None:
    """For a curve of acceleration (:func:`rockstudy.motions.measures.is_acceleration`, by its
    measure's unit in the registry): a ValueError naming ``units`` where its 475-year level
    lies where no site's does (:data:`DESIGN_LEVEL_BOUNDS`), a
    :class:`~rockstudy.warnings.UnitsWarning` where few do."""
    if not measures.is_acceleration(im):
        return
    factor = to_si(im, units)
    x = level_at_rate(levels, rates, DESIGN_RATE) * factor / STANDARD_GRAVITY
    if not math.isfinite(x):
        return
    refuse_low, warn_low, warn_high, refuse_high = DESIGN_LEVEL_BOUNDS[
        measures.measure(im).needs_period
    ]
    shown = f"{x * STANDARD_GRAVITY / factor:.4g} {units}"
    shown += "" if units == "g" else f" = {x:.3g} g"
    said = f"units: the curve reaches its 475-year rate (1/475 per year) at {shown} of {im}"
    if x < refuse_low or x > refuse_high:
        raise ValueError(
            f"{said}, where no site's 475-year level lies ({refuse_low:g} to {refuse_high:g} "
            "g): are the levels in other units (m/s^2 read as g, or g as m/s^2)? give the "
            "units the levels are in"
        )
    if x < warn_low or x > warn_high:
        warnings.warn(
            f"{said}, where few sites' 475-year level lies ({warn_low:g} to {warn_high:g} g): "
            "check that the levels are in these units",
            UnitsWarning,
            stacklevel=4,
        )


def _slopes(log_levels, log_rates):
    """The log-log slope k of each interval, lambda ~ x^-k."""
    return -np.diff(log_rates) / np.diff(log_levels)


#: The natural logarithms of the smallest normal and of the largest float64.
LOG_TINY, LOG_HUGE = math.log(np.finfo(float).tiny), math.log(np.finfo(float).max)


def _check_representable(k0, k, levels) -> None:
    """A ValueError naming ``k0`` or ``k`` (whichever moves ln lambda = ln k0 - k ln x the
    more) where k0 x^-k leaves the range of float64 on ``levels`` (it would tabulate as 0 or
    inf)."""
    logs = np.log(levels)
    log_rates = math.log(k0) - k * logs
    if np.all((log_rates > LOG_TINY) & (log_rates < LOG_HUGE)):
        return
    name = "k0" if abs(math.log(k0)) >= k * float(np.max(np.abs(logs))) else "k"
    raise ValueError(
        f"{name}: the power law {k0:g} x^-{k:g} over the levels {levels[0]:g} to "
        f"{levels[-1]:g} has rates beyond floating point (float64 holds "
        f"{math.exp(LOG_TINY):.3g} to {math.exp(LOG_HUGE):.3g}); give a smaller k, a k0 nearer "
        "the rates of a real site, or levels nearer 1"
    )


#: The annual rates of exceedance between which a suite's own intensities are expected to lie
#: on the site's hazard curve: records chosen for a site are neither shaking it sees twice a
#: year nor shaking beyond its million-year level.
RECORD_RATES = (1e-6, 0.5)


def suite_off_curve(curve: HazardCurve, values) -> str | None:
    """Where a suite's own (unscaled) intensities ``values`` [SI] lie, by their median, outside
    :data:`RECORD_RATES` on ``curve``, what to say of it; else None. A curve in g read as
    m/s^2 (9.8 times low, which its own numbers cannot show) puts real records beyond its
    million-year level."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values) & (values > 0)]
    if not values.size:
        return None
    si = curve.to_si()
    rate = float(np.median(np.exp(si.log_rate(np.log(values)))))
    low, high = RECORD_RATES
    if low <= rate <= high:
        return None
    factor = curve.si_factor
    shown = f"{values.min() / factor:.3g} to {values.max() / factor:.3g} {curve.units}"
    where = "beyond its million-year level" if rate < low else "more often than every other year"
    return (
        f"the records' own {curve.im} ({shown}) lie where the hazard curve's annual rate is "
        f"{rate:.2g} by their median, {where} (a curve in g read as m/s^2 reads 9.8 times low)"
    )
