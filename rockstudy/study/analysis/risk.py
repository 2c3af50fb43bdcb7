"""The annual probability of overturning of each object of a record design at a site.

Each object's lognormal fragility is fitted in the hazard curve's intensity measure (the IDA
capacities, or the binomial fit of stripes and clouds: :mod:`.record_fragility`), then
integrated against the site's hazard curve (:func:`rockstudy.risk.annual_rate`, Cornell et al.
2002): the mean annual rate of overturning lambda_OT and the probability of at least one
overturning in a number of years, 1 - exp(-lambda_OT t). Where the intensity is PGA and no
record has a vertical component, the fragility is 0 below each object's uplift PGA (the ground
cannot lift it there, eq. 10 of [003]) and the fitted lognormal above it; not where the
objects feel another motion than the measured record (a floor motion, a rocking plane at an
angle to the record's x component), nor for an object on an isolator, which can amplify the
ground. The band of lambda_OT comes from resampling the records with replacement (the records
are what the fragility is uncertain about), refitting the fragility and integrating again;
the deaggregation (:func:`rockstudy.risk.rate_deaggregation`) says which intensity levels the
rate comes from.

What the records cannot say is marked, not invented (``status``):

- ``"ok"``: the fit rests on at least ``min_overturning`` records under which the object
  overturned;
- ``"few"``: fewer such records: lambda_OT is given where a fit exists (an IDA needs two
  capacities; with one, NaN) but rests on little;
- ``"none"``: the object never overturned: lambda_OT is not estimable (NaN). An IDA gives
  ``rate_upper_bound`` = lambda(x_c), x_c the lowest level at which a record's IDA stopped
  standing: every capacity of these records lies above x_c, so the rate of the records'
  empirical capacity distribution is below lambda(x_c);
- ``"all"``: (stripes, clouds) the object overturned at every point: no fit; the rate of
  exceeding the lowest intensity simulated, ``rate_lower_bound``, is what it is at least,
  as far as the points say; where the fragility is cut (nothing overturns below the uplift
  PGA), the rate of exceeding the cut, ``rate_upper_bound``, is what it is at most;
- ``"separated"``: (stripes, clouds) every point at which the object overturned lies at or
  above every point at which it stood (:func:`.fragility_fit.separation`): the likelihood
  has no maximum, the data bound the median but not the dispersion beta, and lambda_OT of a
  lognormal fragility depends on beta strongly (Cornell et al.'s exp(k^2 beta^2 / 2) for a
  power-law hazard of slope k). No rate is given (theta, beta and lambda_OT NaN): a step
  function would be a guess presented as an estimate. More records near the gap, or a
  fixed beta from elsewhere with :func:`rockstudy.risk.annual_rate`, are what can help;
- ``"no rise"``: (stripes, clouds) the points at which the object overturned do not lie
  higher in the intensity, on average, than those at which it stood: no increasing
  fragility fits them (the likelihood rises as beta -> infinity, a flat curve), and a rate
  from such a fit would be meaningless (infinite for a power-law hazard). No rate is given;
- ``"no fit"``: the fit did not converge to a finite median and a dispersion of at most
  :data:`rockstudy.risk.MAX_DISPERSION` (a wider one says nothing of the object).

In the band, a resample whose points are separated enters at its limit
(:func:`.fragility_fit.fit_binomial_limit`: a step at the middle of its gap, rate lambda at
that level); one without a rise is left out (counted out of ``boot_valid``).

Cornell, C. A., Jalayer, F., Hamburger, R. O. and Foutch, D. A. (2002). Probabilistic basis
for 2000 SAC Federal Emergency Management Agency steel moment frame guidelines. Journal of
Structural Engineering 128(4), 526-533.
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from ... import _validate, risk
from ..._warnings import UnitsWarning, caller_stacklevel
from ...constants import G
from ...risk.units import to_si
from ..spec.design_kinds import design_kind, kind_of
from . import record_fragility as rf
from .fragility_fit import (
    CONF_LEVEL,
    N_BOOT,
    NO_MAXIMUM,
    SEED,
    bootstrap_rng,
    check_conf_level,
    check_n_boot,
    fit_binomial_limit,
    separation,
)
from .motion_axes import per_motion

__all__ = ["STATUSES", "object_risk", "records_measure", "share_below"]

#: What ``status`` of :func:`object_risk` says of an object's rate (module docstring).
STATUSES = ("ok", "few", "none", "all", "separated", "no rise", "no fit")


def _check_hazard(ds, hazard):
    """(im, period) of ``hazard`` if the design can express it, else a ValueError naming it."""
    if not isinstance(hazard, risk.HazardCurve):
        raise TypeError(f"hazard must be a rockstudy.risk.HazardCurve, got {type(hazard).__name__}")
    scalable = sorted(k for k, m in rf.MEASURES.items() if m.scalable)
    if hazard.im not in scalable:
        raise ValueError(
            f"hazard: its im {hazard.im!r} is not a measure a scale factor changes, so no "
            f"fragility is expressed in it; use a hazard curve of one of {scalable}"
        )
    try:
        rf.intensity(ds, hazard.im, hazard.period)
    except ValueError as err:
        raise ValueError(f"hazard: the design cannot express its IM: {err}") from None
    return hazard.im, hazard.period


def ida_fitter(ds, im, period):
    """(fit(j, rows) -> (theta, beta), count(j, rows) -> overturning records, lowest censoring
    level per object, no_maximum(j) -> None, lowest capacity per object) of an IDA, in quoted
    units."""
    cap, top, cens, ok = rf.ida_arrays(ds, im, period)

    def fit(j, rows):
        c, t, cc, kk = cap[:, j], top[:, j], cens[:, j], ok[:, j]
        if not (kk[rows] & ~cc[rows]).any():  # none overturned in these records
            return np.inf, np.nan
        return rf.fit_records(c, t, cc, kk, rows)

    def count(j, rows):
        return int((ok[rows, j] & ~cens[rows, j]).sum())

    with np.errstate(invalid="ignore"):
        lowest = np.nanmin(np.where(ok & cens, top, np.nan), axis=0, initial=np.inf)
        first = np.nanmin(np.where(ok & ~cens, cap, np.nan), axis=0, initial=np.inf)
    return fit, count, lowest, lambda j: None, first


def stripe_fitter(ds, im, period):
    """As :func:`ida_fitter` for stripes and clouds (binomial fit of the points, a separated
    resample at its limit); the third item is the lowest intensity simulated per object, the
    fourth the kind of :data:`.fragility_fit.NO_MAXIMUM` of all its points (None if they
    have a fit), the fifth the lowest intensity at which it overturned."""
    x, y, ok = rf.stripe_arrays(ds, im, period)
    y = y.astype(bool)
    j_axis = ds["overturned"].dims.index("structure")
    x, y, ok = (np.moveaxis(a, j_axis, 1) for a in (x, y, ok))  # (record, structure, ...)

    def fit(j, rows):
        kk = ok[rows, j]
        xs, ys = x[rows, j][kk], y[rows, j][kk]
        if not ys.any():
            return np.inf, np.nan
        return fit_binomial_limit(xs, ys.astype(float), np.ones(xs.size))

    def count(j, rows):
        hit = (ok & y)[rows, j]
        return int(hit.reshape(hit.shape[0], -1).any(axis=1).sum())

    lowest = np.nanmin(np.where(ok, x, np.nan).reshape(x.shape[0], x.shape[1], -1), axis=(0, 2))

    def no_maximum(j):
        kk = ok[:, j]
        kind = separation(x[:, j][kk], y[:, j][kk], np.ones(int(kk.sum())))[0]
        return kind if kind in NO_MAXIMUM else None

    hit = np.where(ok & y, x, np.nan).reshape(x.shape[0], x.shape[1], -1)
    first = np.nanmin(hit, axis=(0, 2), initial=np.inf)
    return fit, count, lowest, no_maximum, first


def _uplift(ds, hazard):
    """Each structure's uplift PGA in the hazard's units: the design's ``uplift_acceleration``
    (g tan(alpha) of a block, g lambda of another structure, eq. 10 of [003]), else PGA /
    pga_ratio (NaN for another IM, or where the design does not say it): below it a
    structure cannot even leave rest."""
    n = ds.sizes["structure"]
    if hazard.im != "pga":
        return np.full(n, np.nan)
    if "uplift_acceleration" in ds.variables:
        level = ds["uplift_acceleration"].transpose("structure").values.astype(float)
        return level / hazard.si_factor
    if not {"pga", "pga_ratio"} <= set(ds.variables):
        return np.full(n, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        level = (ds["pga"] / ds["pga_ratio"]).transpose("structure", ...).values.reshape(n, -1)
        level = np.nanmedian(np.where(np.isfinite(level) & (level > 0), level, np.nan), axis=1)
    return level / hazard.si_factor


def share_below(theta, beta, hazard, level, units=None) -> float:
    """The share of lambda_OT (:func:`rockstudy.risk.annual_rate`) that comes from intensities
    below ``level`` (in the hazard's units): what setting the fragility to 0 below ``level``
    takes away (``threshold``). NaN without a rate or a level."""
    if not (np.isfinite(level) and level > 0 and np.isfinite(theta) and np.isfinite(beta)):
        return np.nan
    whole = risk.annual_rate(theta, beta, hazard, units)
    factor = hazard.si_factor / to_si(hazard.im, units or hazard.units)
    above = risk.annual_rate(theta, beta, hazard, units, threshold=level * factor)
    return float(1.0 - above / whole) if whole > 0 else np.nan


def _rate(theta, beta, hazard, unit, cut=None):
    """lambda_OT of one fit, its fragility 0 below ``cut`` (in ``unit``; None: the whole
    lognormal); 0 for a median not reached (theta inf), NaN without a fit, for a flat one
    (beta inf, no rise) or one wider than :data:`rockstudy.risk.MAX_DISPERSION`."""
    if beta > risk.MAX_DISPERSION:  # (inf: no rise)
        return np.nan
    if theta == np.inf:
        return 0.0
    if not (np.isfinite(theta) and theta > 0 and np.isfinite(beta)):
        return np.nan
    return risk.annual_rate(theta, beta, hazard, units=unit, threshold=cut)


def cut_levels(ds, im, units, uplift):
    """Where each object's fragility is exactly 0, in the hazard's units (NaN: nowhere): for
    a PGA hazard when no record of the design has a vertical component
    (:func:`horizontal`), below the lower of its uplift PGA (g tan(alpha) of a block, g lambda
    of another structure, eq. 10 of [003]) and the g tan(theta_cr) at which the equivalent
    block that the design simulates lifts off (lower for an arch): below both the ground
    lifts neither, so P(OT | PGA) = 0. ``uplift`` (the structures' own uplift PGA) and the
    result are in ``units``."""
    if not (im == "pga" and horizontal(ds) and felt_as_measured(ds)):
        return np.full(ds.sizes["structure"], np.nan)
    level = uplift
    if "critical_rotation" in ds:
        lifts = G * np.tan(ds["critical_rotation"].transpose("structure").values.astype(float))
        level = np.fmin(uplift, lifts / to_si(im, units))
    if "uplift_bounds" in ds:  # an isolator can amplify the ground: no bound below
        level = np.where(ds["uplift_bounds"].transpose("structure").values, level, np.nan)
    return np.where(np.isfinite(level) & (level > 0), level, np.nan)


def cut_refused(level, first) -> np.ndarray:
    """True where an overturning was seen at an intensity below the cut ``level`` (beyond
    the round-off of the scales that produced it)."""
    with np.errstate(invalid="ignore"):
        return np.asarray(first < level * (1.0 - 1e-9))


def felt_as_measured(ds) -> bool:
    """False when the design says that its objects feel another motion than the record whose
    measures it stores (``measured_motion`` False on ``record``: a floor motion, measured by
    its ground record; a rocking plane at an angle psi to the x component): the stored PGA
    then does not bound the acceleration that lifts them, and no fragility is cut below it."""
    return "measured_motion" not in ds or bool(ds["measured_motion"].all())


def horizontal(ds) -> bool:
    """True when the design says that none of its records has a vertical component
    (``vertical_component`` on ``record``): then nothing lifts a structure, or overturns it,
    below its uplift PGA. A design that does not say is not taken as horizontal."""
    return "vertical_component" in ds and not bool(ds["vertical_component"].any())


def records_measure(ds, hazard) -> np.ndarray:
    """Each record's own (unscaled) value of the hazard's measure [SI] as the design stores
    it (empty where it does not)."""
    if hazard.im not in ds:
        return np.zeros(0)
    values = ds[hazard.im]
    if "period" in values.dims:
        if hazard.period is None or hazard.period not in values["period"].values:
            return np.zeros(0)
        values = values.sel(period=hazard.period)
    return np.asarray(values.values, float)


def _status(capacities, theta, beta, n_over, min_overturning, no_maximum):
    if n_over == 0:
        return "none"
    if not capacities and theta == 0.0 and beta != np.inf:
        return "all"
    if no_maximum is not None:
        return "no rise" if no_maximum == "no rise" else "separated"
    if not (np.isfinite(theta) and theta > 0 and 0 <= beta <= risk.MAX_DISPERSION):
        return "no fit" if n_over >= (2 if capacities else 1) else "few"
    return "ok" if n_over >= min_overturning else "few"


def _probability(years, rate):
    """P in ``years`` of each rate, NaN where the rate is NaN."""
    return np.where(np.isfinite(rate), risk.probability_in(years, np.nan_to_num(rate)), np.nan)


def _one_object(j, fitter, n_rec, boot_rows, hazard, unit, capacities, min_overturning, cut):
    """The point estimate, the bootstrap rates and the status of object ``j`` (its fragility
    0 below ``cut``, in ``unit``; None: the whole lognormal); and the rate of the whole
    lognormal."""
    fit, count, _, no_maximum, _ = fitter
    every = np.arange(n_rec)
    theta, beta = fit(j, every)
    n_over = count(j, every)
    status = _status(capacities, theta, beta, n_over, min_overturning, no_maximum(j))
    if status in ("separated", "no rise"):  # the limit of the fit is no estimate
        theta, beta = np.nan, np.nan
    whole = _rate(theta, beta, hazard, unit) if status in ("ok", "few") else np.nan
    rate = whole if cut is None or not np.isfinite(whole) else _rate(theta, beta, hazard, unit, cut)
    boot = np.full(len(boot_rows), np.nan)
    if np.isfinite(rate):
        boot = np.array([_rate(*fit(j, rows), hazard, unit, cut) for rows in boot_rows])
    return theta, beta, n_over, status, rate, boot, whole


@per_motion
def object_risk(
    ds: xr.Dataset,
    hazard: risk.HazardCurve,
    years: float = 50.0,
    *,
    n_boot: int = N_BOOT,
    conf_level: float = CONF_LEVEL,
    seed: int = SEED,
    min_overturning: int = 5,
    uplift_cut: bool = True,
    refit=None,
) -> xr.Dataset:
    """Per object: the fragility in the hazard's IM, lambda_OT, P(OT in ``years``) and bands.

    Parameters
    ----------
    ds : xarray.Dataset
        A record design (:func:`~rockstudy.study.designs.records.incremental_dynamic_analysis`,
        :func:`~rockstudy.study.designs.records.multiple_stripes` or
        :func:`~rockstudy.study.designs.records.cloud`), or a study's cube folded into that
        layout; named objects keep their names.
    hazard : rockstudy.risk.HazardCurve
        The site's hazard curve. Its IM must be one the design stores (``pga``, ``pgv``,
        ``pgd``, ``arias``, ``cav``, ``spectrum_intensity``, or ``sa``/``psv``/``sd`` at a
        stored period); its units may be any of :data:`rockstudy.risk.UNIT_FACTORS` of that
        IM (g, m/s^2, cm/s^2 for accelerations): the fragility is converted to them.
    years : float
        The exposure time t [yr] of the probability 1 - exp(-lambda_OT t), in (0, 1e6] (as a
        study's ``[hazard] years``: :data:`rockstudy.risk.MAX_YEARS`).
    n_boot : int
        Resamples of the records (with replacement) for the band: each refits the
        fragility and integrates again; a resample in which the object never overturns
        counts as a rate of 0 (its fitted median is not reached), one without a fit (fewer
        than two capacities) is left out (``boot_valid`` counts the rest). 0: no band; at
        most :data:`~rockstudy.study.analysis.fragility_fit.MAX_BOOT` (10,000).
    conf_level : float
        Level of the band, in (0, 1): the percentiles (1 -+ level) / 2 of the resampled rates.
    seed : int
        Seed of the resampling (the same seed gives the same band), a whole number >= 0 (as
        a study's).
    min_overturning : int
        Records under which an object must have overturned for ``status`` "ok" (fewer:
        "few", whatever the number of records: 3 of 3 records rest on 3 capacities), a whole
        number >= 1.
    uplift_cut : bool
        True (default): for a PGA hazard and horizontal records, the fragility is 0 below each
        object's uplift PGA (see ``truncated_at_uplift`` below). False: the whole lognormal,
        for a demand that needs no uplift (sliding: a block slides below its uplift PGA,
        :func:`~rockstudy.study.analysis.sliding.slide_risk`).
    refit : callable, optional
        ``refit(j, rows) -> (theta, beta)``, in the quoted units of the hazard's IM: the fit
        of object ``j`` on the records ``rows`` (an index array) in place of the design's
        own, for the point estimate and each resample (the nested fits of
        :mod:`~rockstudy.study.analysis.nested_fit`).

    Returns
    -------
    xarray.Dataset
        On ``structure``, ranked by ``annual_rate`` (highest first, objects without a rate
        last; a design over floors and orientations, on ``floor`` and ``orientation`` too,
        each fitted apart, keeps the design's order,
        :mod:`~rockstudy.study.analysis.motion_axes`): ``theta`` (median, in
        ``hazard.units``) and ``beta`` of the fragility,
        ``n_records``, ``n_overturning`` (records under which it overturned), ``status``
        (:data:`STATUSES`), ``annual_rate`` [1/yr] with ``annual_rate_lo``/``_hi`` (the band),
        ``probability`` in ``years`` with ``probability_lo``/``_hi``, ``return_period`` [yr],
        ``rate_upper_bound`` / ``rate_lower_bound`` (``"none"`` / ``"all"``, and
        ``rate_upper_bound`` of an ``"all"`` whose fragility is cut; NaN elsewhere),
        ``boot_valid`` (resamples that gave a rate), ``uplift`` (for a PGA hazard: the uplift
        PGA, g tan(alpha) of a block and g lambda of another structure, eq. 10 of [003], in
        ``hazard.units``), ``truncated_at_uplift`` (True where the fragility is 0 below
        ``cut_level``: a PGA hazard and no record with a vertical component (the design's
        ``vertical_component``), where P(OT | PGA) = 0 exactly below the lower of the uplift
        PGA and the g tan(theta_cr) at which the simulated equivalent block lifts off
        (:func:`cut_levels`); ``annual_rate``, its band and the probabilities are then those
        of the cut fragility, :func:`rockstudy.risk.annual_rate` with ``threshold``),
        ``cut_level`` (NaN where not cut), ``overturned_below_uplift`` (True where a
        simulation overturned the object below that level, which the model forbids: then it
        is not cut), ``annual_rate_lognormal``
        (the rate of the whole lognormal, Cornell et al.'s integral) and
        ``share_below_uplift`` (the share of ``annual_rate_lognormal`` from PGA below the
        uplift PGA: what the lognormal's lower tail adds, not what a simulation saw); and on
        (``structure``,
        ``interval``) ``deaggregation`` [1/yr], each interval's share of ``annual_rate``,
        with the edges ``im_lower``/``im_upper`` [``hazard.units``]; on (``structure``,
        ``resample``) ``annual_rate_resamples``, the rate of each resample of the band (the
        same resampled records for every object: a ratio of two objects' rates has its band
        from them, :func:`~rockstudy.study.analysis.two_body.pair_ratios`). Attributes: the hazard,
        ``years``, ``n_boot``, ``conf_level`` and ``seed``.
    """
    years = _validate.in_range(
        "years", years, 0.0, risk.MAX_YEARS, f"(0, {risk.MAX_YEARS:g}]", low_open=True
    )
    n_boot, conf_level = check_n_boot(n_boot), check_conf_level(conf_level)
    min_overturning = _validate.count("min_overturning", min_overturning, 1)
    kind = kind_of(ds)
    im, period = _check_hazard(ds, hazard)
    off = risk.suite_off_curve(hazard, records_measure(ds, hazard))
    if off is not None:
        warnings.warn(
            f"hazard: {off}; check the units of both", UnitsWarning, stacklevel=caller_stacklevel()
        )
    unit = rf.quoted(im)[0]
    fitter = globals()[kind.risk_fitter](ds, im, period)
    if refit is not None:
        fitter = (refit, *fitter[1:])
    n_rec = ds.sizes["record"]
    rng = bootstrap_rng(seed)
    boot_rows = [rng.integers(0, n_rec, n_rec) for _ in range(n_boot)]
    to_hazard = to_si(im, unit) / hazard.si_factor
    uplift = _uplift(ds, hazard)
    level = cut_levels(ds, hazard.im, hazard.units, uplift)
    if not uplift_cut:
        level = np.full(ds.sizes["structure"], np.nan)
    # an overturning seen below that level (which the physics forbids): the data and the cut
    # disagree, and the fragility is not cut
    refused = cut_refused(level, fitter[4] * to_hazard)
    cut = np.where(refused, np.nan, level)
    cuts = cut / to_hazard  # in the fragility's unit
    rows = [
        _one_object(
            j,
            fitter,
            n_rec,
            boot_rows,
            hazard,
            unit,
            kind.capacities,
            min_overturning,
            cuts[j] if np.isfinite(cuts[j]) else None,
        )
        for j in range(ds.sizes["structure"])
    ]
    attrs = {"design": kind.name, "n_boot": n_boot, "conf_level": conf_level, "seed": int(seed)}
    levels = (uplift, cut, refused)
    return _risk_dataset(ds, rows, fitter[2] * to_hazard, hazard, years, to_hazard, attrs, levels)


def _bands(boot, conf_level):
    """(lower, upper, count) of the finite resampled rates of each object (percentiles at
    resamples, without interpolation); NaN where none is finite."""
    valid = np.isfinite(boot).sum(axis=1)
    q = [50 * (1 - conf_level), 50 * (1 + conf_level)]
    lo, hi = np.full(len(boot), np.nan), np.full(len(boot), np.nan)
    for i, b in enumerate(boot):
        if valid[i]:
            lo[i], hi[i] = np.percentile(b[np.isfinite(b)], q, method="inverted_cdf")
    return lo, hi, valid


def _bounds(status, lowest, hazard, capacities, cut):
    """``rate_upper_bound`` (an IDA's "none"; stripes' "all" where the fragility is cut: P(OT)
    <= 1 from the cut on and 0 below it, so lambda_OT <= lambda(cut)) and ``rate_lower_bound``
    (stripes' "all")."""
    at = hazard.rate(np.where(np.isfinite(lowest) & (lowest > 0), lowest, 1.0))
    ok = np.isfinite(lowest) & (lowest > 0)
    cut_ok = np.isfinite(cut) & (cut > 0)
    at_cut = hazard.rate(np.where(cut_ok, cut, 1.0))
    everywhere = (not capacities) & (status == "all")
    upper = np.where(
        capacities & (status == "none") & ok, at, np.where(everywhere & cut_ok, at_cut, np.nan)
    )
    lower = np.where(everywhere & ok, at, np.nan)
    return upper, lower


def _risk_dataset(ds, rows, lowest, hazard, years, to_hazard, attrs, levels):
    """The Dataset of :func:`object_risk` from the objects' rows, ranked; ``levels`` are the
    objects' uplift and cut intensities in the hazard's units and where a cut was refused."""
    uplift, cut, refused = levels
    theta, beta, n_over, status, rate, boot, whole = (list(c) for c in zip(*rows, strict=True))
    theta, beta, rate, whole = (np.array(v, float) for v in (theta, beta, rate, whole))
    boot = np.array(boot, float).reshape(len(rows), -1)
    lo, hi, valid = _bands(boot, attrs["conf_level"])
    fitted = np.isfinite(rate)
    deagg_median = np.where(fitted, theta * to_hazard, 1.0)
    edge_lo, edge_hi, parts = risk.rate_deaggregation(
        deagg_median, np.where(fitted, beta, 0.0), hazard
    )
    cut_rows = np.flatnonzero(np.isfinite(cut))
    if cut_rows.size:  # the fragility 0 below the uplift PGA
        parts[cut_rows] = risk.rate_deaggregation(
            deagg_median[cut_rows],
            np.where(fitted, beta, 0.0)[cut_rows],
            hazard,
            threshold=cut[cut_rows],
        )[2]
    parts = np.where(fitted[:, None], parts, np.nan)
    status = np.array(status, dtype=object)
    capacities = design_kind(attrs["design"]).capacities
    upper, lower = _bounds(status, lowest, hazard, capacities, cut)
    v = {
        "theta": np.where(np.isfinite(theta), theta * to_hazard, theta),
        "beta": beta,
        "n_records": np.full(len(rows), ds.sizes["record"]),
        "n_overturning": np.array(n_over),
        "status": status.astype(str),
        "annual_rate": rate,
        "annual_rate_lo": lo,
        "annual_rate_hi": hi,
        "probability": _probability(years, rate),
        "probability_lo": _probability(years, lo),
        "probability_hi": _probability(years, hi),
        "return_period": np.where(rate > 0, 1.0 / np.where(rate > 0, rate, 1.0), np.nan),
        "rate_upper_bound": upper,
        "rate_lower_bound": lower,
        "boot_valid": valid,
        "uplift": uplift,
        "truncated_at_uplift": np.isfinite(cut),
        "cut_level": cut,
        "overturned_below_uplift": refused,
        "annual_rate_lognormal": whole,
        "share_below_uplift": np.array(
            [
                share_below(t * to_hazard, b, hazard, u) if f else np.nan
                for t, b, u, f in zip(theta, beta, uplift, fitted, strict=True)
            ]
        ),
    }
    out = xr.Dataset(
        {k: ("structure", a) for k, a in v.items()},
        coords={"structure": ds["structure"].values},
    )
    out["deaggregation"] = (("structure", "interval"), parts)
    out["annual_rate_resamples"] = (("structure", "resample"), boot)  # paired: same records
    out = out.assign_coords(im_lower=("interval", edge_lo), im_upper=("interval", edge_hi))
    order = np.argsort(np.where(fitted, -rate, np.inf), kind="stable")
    out = out.isel(structure=order)
    out.attrs.update(
        attrs,
        im=hazard.im,
        units=hazard.units,
        years=years,
        hazard=repr(hazard),
        hazard_source=hazard.source,
    )
    if hazard.period is not None:
        out.attrs["period"] = hazard.period
    return out
