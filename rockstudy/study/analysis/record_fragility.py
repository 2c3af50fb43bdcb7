"""Fragility from record designs (:mod:`rockstudy.study.designs.records`): the binomial
maximum-likelihood fit of stripes (Baker 2015), the lognormal fit of IDA capacities, and the
efficiency of intensity measures.

A lognormal fragility is P(overturning | IM = x) = Phi(ln(x / theta) / beta): theta the median
capacity, beta the dispersion. Intensities are in the units users quote (:func:`quoted`, from
the registry of measures :mod:`rockstudy.motions.measures`: PGA and Sa in g, PGV in m/s, the
dimensionless groups of [000] as they are).

Every table carries the observed intensity range (``im_min``, ``im_max``) and the flags
``theta_in_range`` and ``band_in_range``: a median outside the data is an extrapolation of the
lognormal shape, to be read as "not reached within the sampled range" (or "below it"); and
``separated`` and ``no_rise``: outcomes separated in the intensity, or not rising with it,
have no fit (theta, beta NaN; a separated theta only bounded, see
:func:`~rockstudy.study.analysis.fragility_fit.separation`).

Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic structural
analysis. Earthquake Spectra 31(1), 579-599.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import xarray as xr
from scipy import stats

from ..._warnings import caller_stacklevel
from ...motions import measures
from ...motions.measures import MEASURES, RATIOS
from ..spec.design_kinds import DESIGN_KINDS, kind_of
from .fragility_fit import (
    CONF_LEVEL,
    N_BOOT,
    NO_MAXIMUM,
    SEED,
    binomial_covariance,
    bootstrap_rng,
    capacities_covariance,
    check_conf_level,
    check_n_boot,
    fit_binomial,
    fit_binomial_limit,
    fit_capacities,
    fragility_row,
    no_maximum_row,
    percentile_intervals,
    wald_intervals,
    warn_if_separated,
)
from .motion_axes import per_motion

__all__ = [
    "GROUPS",
    "default_candidates",
    "fit_binomial",
    "fit_capacities",
    "fragility_of",
    "ida_fragility",
    "im_efficiency",
    "intensity",
    "names",
    "power",
    "quoted",
    "stripe_fragility",
]

#: Dimensionless groups of the pulse fitted besides the measures and :data:`RATIOS`: name ->
#: power under a scale factor (omega_p A_p / (g tan alpha): A_p is linear in the record).
GROUPS = {"pulse_amplitude_ratio": 1}
#: Spectral measures not stored that follow from the stored ``sa``: name -> k in sa / omega^k.
_FROM_SA = {"psv": 1, "sd": 2}


def names() -> list[str]:
    """Every name :func:`intensity` takes: the registry's measures
    (:data:`rockstudy.motions.measures.MEASURES`), its ratios and :data:`GROUPS`."""
    return [*MEASURES, *RATIOS, *GROUPS]


def quoted(im: str) -> tuple[str, float]:
    """(quoted unit, factor from SI to it) of ``im``: the registry's (PGA and Sa in g);
    "-" for the dimensionless ratios and groups. ValueError naming ``im`` if unknown."""
    if im not in names():
        raise ValueError(f"im must be one of {names()}, got {im!r}")
    return ("-", 1.0) if im in GROUPS else measures.quoted(im)


def power(im: str) -> float:
    """The power with which ``im`` follows a scale factor of the record: the registry's; a
    ratio follows its measure (:func:`rockstudy.motions.measures.power`)."""
    return GROUPS[im] if im in GROUPS else measures.power(im)


def default_candidates(ds: xr.Dataset) -> tuple[str, ...]:
    """The candidates of :func:`im_efficiency` by default: every measure of the registry that a
    scale factor changes and ``ds`` stores (``sa`` at every stored period), the ratios and
    :data:`GROUPS`."""
    stored = tuple(k for k in measures.listed(False) + measures.listed(True) if k in ds)
    return tuple(k for k in stored if MEASURES[k].scalable) + (*RATIOS, *GROUPS)


def _needs_period(im: str) -> bool:
    return im in MEASURES and MEASURES[im].needs_period


def _stored(ds, im, period):
    """The unscaled value of ``im`` [SI] from ``ds``: a stored variable, at ``period`` for a
    measure that needs one (``psv`` and ``sd`` from the stored ``sa``)."""
    source = "sa" if im in _FROM_SA and im not in ds else im
    if source not in ds:
        raise ValueError(f"im={im!r} is not stored in the dataset")
    if not _needs_period(im):
        if period is not None:
            raise ValueError(f"period is only for the measures that need one, not im={im!r}")
        return ds[im]
    if period is None:
        raise ValueError(f"im={im!r} needs a period [s]")
    stored = np.asarray(ds["period"].values, float)
    hit = np.flatnonzero(np.isclose(stored, float(period), rtol=1e-12, atol=0.0))
    if not hit.size:
        raise ValueError(f"period: {period!r} s is not stored; the dataset has {list(stored)}")
    w = 2.0 * np.pi / stored[hit[0]]
    k = _FROM_SA[im] if source != im else 0
    return ds[source].isel(period=hit[0], drop=True) / w**k


def intensity(ds: xr.Dataset, im: str, period=None, scale: str = "scale") -> xr.DataArray:
    """The intensity measure ``im`` of each simulated point of a record design, in quoted units.

    The unscaled record's value (``ds[im]``, per record or per record and structure) times the
    scale factor ``ds[scale]`` to the measure's power (:func:`power`: squared for Arias
    intensity); for a cloud (no scale variable),
    the unscaled value. ``scale="capacity_scale"`` gives the IDA capacities in ``im``.

    Parameters
    ----------
    im : str
        One of :func:`names`: a measure of the registry stored in ``ds``, a ratio or a group.
    period : float, optional
        T [s] of ``sa``, ``psv``, ``sd`` (or any measure that needs one): one of the dataset's
        ``period`` values. ``psv`` and ``sd`` follow from the stored ``sa``.
    """
    unit, factor = quoted(im)
    base = _stored(ds, im, period)
    value = base * factor
    if scale in ds:
        value = value * ds[scale] ** power(im)
    return value.rename(im).assign_attrs(unit=unit, units=unit)


def _label(im, period):
    return im if period is None else f"{im}(T={float(period):g} s)"


def stripe_arrays(ds, im, period):
    """(intensity, overturned, usable) of stripes or a cloud as arrays on the dimensions of
    ``overturned`` (record first): each point's ``im`` in quoted units (:func:`intensity`),
    its outcome as stored, and whether it ran (``status`` 0) at a finite, positive
    intensity."""
    dims = ds["overturned"].dims
    x = intensity(ds, im, period).broadcast_like(ds["overturned"]).transpose(*dims).values
    y = ds["overturned"].transpose(*dims).values
    ok = np.isfinite(x) & (x > 0) & (ds["status"].transpose(*dims).values == 0)
    return x, y, ok


def ida_arrays(ds, im, period):
    """(capacities, censoring levels, censored, usable) of an IDA as arrays on (record,
    structure), in the quoted units of ``im``: the first overturning intensities, the highest
    levels seen to stand, whether no rung overturned (boolean), and whether the ladder ran
    (``status`` 0) with a finite, positive value of the one of the two that applies."""
    rs = ("record", "structure")
    cap = intensity(ds, im, period, scale="capacity_scale").transpose(*rs).values
    top = intensity(ds, im, period, scale="capacity_scale_lower").transpose(*rs).values
    cens = ds["censored"].transpose(*rs).values == 1  # -1 where a ladder failed
    x = np.where(cens, top, cap)
    ok = (ds["status"].transpose(*rs).values == 0) & np.isfinite(x) & (x > 0)
    return cap, top, cens, ok


# ------------------------------------------------------------------------------ tables


def _groups(ds, by, bins):
    """{label: boolean mask over ``structure``}."""
    n = ds.sizes["structure"]
    if by is None:
        return {"all": np.ones(n, bool)}
    if by == "structure":
        labels = [s if isinstance(s, str) else int(s) for s in ds["structure"].values]
        return {s: np.arange(n) == k for k, s in enumerate(labels)}
    if by not in ds or ds[by].dims != ("structure",):
        raise ValueError(f"by must be None, 'structure' or a variable on structure, got {by!r}")
    g = np.asarray(ds[by].values)
    if bins is None:
        return {v: g == v for v in np.unique(g)}
    idx = np.digitize(g, bins)
    return {f"{bins[i - 1]:g}-{bins[i]:g}": idx == i for i in range(1, len(bins))}


def _row(label, theta, beta, band, n, x, unit, by, cov, method, conf_level):
    row = fragility_row(label, theta, beta, band, n, x, by, cov, method, conf_level)
    return {**row, "unit": unit}


def _check(ds, fitter, conf_level, n_boot):
    """Validated (conf_level, n_boot); a ValueError if the fragility of ``ds``'s design kind
    (:mod:`rockstudy.study.spec.design_kinds`) is not ``fitter``. A dataset of no design
    kind with the outcomes of its points (``overturned``) is fitted as stripes."""
    conf_level, n_boot = check_conf_level(conf_level), check_n_boot(n_boot)
    name = ds.attrs.get("design")
    kind = DESIGN_KINDS.get(name) if isinstance(name, str) else None
    if kind is None and "overturned" in ds:
        kind = DESIGN_KINDS["stripes"]
    if kind is None or kind.fragility != fitter:
        fits = [k.name for k in DESIGN_KINDS.values() if k.fragility == fitter]
        other = f"; use {kind.fragility} for a {name!r} design" if kind is not None else ""
        raise ValueError(
            f"ds: {fitter} needs a dataset of design {' or '.join(map(repr, fits))}, got "
            f"design {name!r}{other}"
        )
    return conf_level, n_boot


def fragility_of(ds):
    """The fragility fitter of a record design's Dataset: its design kind's
    (:func:`stripe_fragility` or :func:`ida_fragility`)."""
    return globals()[kind_of(ds).fragility]


def _measure(ds, im, period):
    im = ds.attrs.get("im", "pga") if im is None else im
    if period is None and _needs_period(im) and np.isfinite(ds.attrs.get("im_period", np.nan)):
        period = ds.attrs["im_period"]
    return im, period


@per_motion
def stripe_fragility(
    ds: xr.Dataset,
    im: str | None = None,
    period=None,
    by=None,
    bins=None,
    *,
    n_boot: int = N_BOOT,
    conf_level: float = CONF_LEVEL,
    seed: int = SEED,
) -> pd.DataFrame:
    """Lognormal fragility of a stripe (or cloud) design by the binomial MLE (Baker 2015).

    ``beta`` is the maximum-likelihood estimate. The pointwise band of P(x)
    (:func:`~rockstudy.study.analysis.fragility_curve`) comes from the covariance of
    (ln theta, ln beta): the expected information where each record gives one point (a cloud
    of one block), else the sandwich clustered by record (a record's points are not
    independent); see :mod:`rockstudy.study.analysis.fragility_fit`.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`~rockstudy.study.designs.records.multiple_stripes` or
        :func:`~rockstudy.study.designs.records.cloud`.
    im, period : str, float
        The intensity measure (default the stripes' own); any other stored measure makes the
        points single Bernoulli trials at their own intensities.
    by, bins
        One curve per ``structure``, per value of a variable on ``structure`` (e.g.
        ``half_diagonal``), or per bin of it (edges); default one curve for all.
    n_boot, conf_level, seed
        Intervals of theta and beta by resampling records (with replacement) and refitting
        both; ``n_boot=0`` gives their Wald intervals instead. ``conf_level`` in (0, 1).
        Keywords only, in this order in every function that takes them (defaults
        :data:`~rockstudy.study.analysis.fragility_fit.N_BOOT`, ``CONF_LEVEL`` and ``SEED``).

    Returns
    -------
    pandas.DataFrame
        One row per group: ``theta`` [quoted unit], ``beta``, their intervals, ``n``
        (points), ``im_min``, ``im_max``, ``theta_in_range``, ``band_in_range``, the band
        columns of :func:`~rockstudy.study.analysis.fragility_fit.fragility_row` and ``unit``.
        Points that failed (``status`` != 0) or have no finite intensity are left out. A
        group whose outcomes are separated in the intensity (the stripes jump from 0 % to
        100 % overturned, or are mixed at one level only, with 0 % below and 100 % above it:
        :func:`~rockstudy.study.analysis.fragility_fit.separation`) has no maximum of the
        likelihood: ``separated`` True, ``theta`` and ``beta`` NaN, ``theta_lo`` /
        ``theta_hi`` the gap in which the median lies, and a
        :class:`~rockstudy.SeparationWarning`; so does a group whose overturned points do not
        lie higher in the intensity than those that stood (``no_rise`` True, theta, beta and
        their band NaN). Such bootstrap resamples enter at their limit
        (:func:`~rockstudy.study.analysis.fragility_fit.fit_binomial_limit`).
    """
    conf_level, n_boot = _check(ds, "stripe_fragility", conf_level, n_boot)
    im, period = _measure(ds, im, period)
    x_all, y_all, ok = stripe_arrays(ds, im, period)
    y_all = y_all.astype(float)
    record = np.broadcast_to(
        np.arange(ds.sizes["record"]).reshape((-1,) + (1,) * (x_all.ndim - 1)), x_all.shape
    )
    unit = quoted(im)[0]
    rng = bootstrap_rng(seed)
    n_rec = ds.sizes["record"]
    rows = []
    for label, mask in _groups(ds, by, bins).items():
        x, y, keep, rec = x_all[:, mask], y_all[:, mask], ok[:, mask], record[:, mask]
        ones = np.ones(int(keep.sum()))
        kind, low, high = warn_if_separated("stripe_fragility", label, x[keep], y[keep], ones, unit)
        if kind in NO_MAXIMUM:  # separated or no rise: no maximum, no fit
            row = no_maximum_row(label, kind, low, high, keep.sum(), x[keep], by, conf_level)
            rows.append({**row, "unit": unit})
            continue
        fit = fit_binomial(x[keep], y[keep], ones)
        cov = binomial_covariance(x[keep], ones, *fit, y[keep], rec[keep])
        if not np.isfinite(fit[1]):
            band, method = ((fit[0],) * 2, (np.nan,) * 2), "none"
        elif n_boot:
            boot = []
            for _ in range(n_boot):
                k = rng.integers(0, n_rec, n_rec)
                kk = keep[k]
                ones_k = np.ones(int(kk.sum()))
                boot.append(fit_binomial_limit(x[k][kk], y[k][kk], ones_k, np.log(fit)))
            band, method = percentile_intervals(np.array(boot), conf_level), "likelihood"
        else:
            band, method = wald_intervals(*fit, cov, conf_level), "likelihood"
        rows.append(_row(label, *fit, band, keep.sum(), x[keep], unit, by, cov, method, conf_level))
    return pd.DataFrame(rows).set_index(by or "group")


def fit_records(cap, top, censored, keep, rows, start=None):
    """fit_capacities on the records ``rows`` (an index or a resample) of (record, structure)
    arrays: capacities where not censored, censoring levels where censored."""
    kk, cc = keep[rows], censored[rows]
    return fit_capacities(cap[rows][kk & ~cc], top[rows][kk & cc], start)


def _exact_intervals(theta, beta, n, conf_level):
    """Intervals of theta and beta of n uncensored capacities, on the MLE beta:
    ln theta +- t_{n-1} beta / sqrt(n - 1), and sigma from n beta^2 / sigma^2 ~ chi2_{n-1}
    (the same as with the n - 1 standard deviation s: n beta^2 = (n - 1) s^2)."""
    half = stats.t.ppf(0.5 + conf_level / 2, n - 1) * beta / np.sqrt(n - 1)
    chi = stats.chi2.ppf([0.5 + conf_level / 2, 0.5 - conf_level / 2], n - 1)
    return (theta * np.exp(-half), theta * np.exp(half)), tuple(beta * np.sqrt(n / chi))


def _warn_equal_capacities(label, theta, n, unit):
    """Warn that the ``n`` capacities of group ``label`` are all ``theta``: beta = 0."""
    warnings.warn(
        f"ida_fragility: the {n} capacities of group {str(label)!r} are all {theta:.6g} {unit}: "
        "beta = 0 is a step, not a record-to-record dispersion (the same record more than "
        "once in the suite?); its intervals are NaN",
        UserWarning,
        stacklevel=caller_stacklevel(),
    )


@per_motion
def ida_fragility(
    ds: xr.Dataset,
    im: str | None = None,
    period=None,
    by=None,
    bins=None,
    *,
    n_boot: int = N_BOOT,
    conf_level: float = CONF_LEVEL,
    seed: int = SEED,
) -> pd.DataFrame:
    """Lognormal fit of IDA capacities (first overturning levels) in any stored measure.

    ``beta`` is the maximum-likelihood estimate: without censored capacities, the standard
    deviation of ln c dividing by n (:func:`fit_capacities`); every band is built on it.
    Without censoring the bands are exact: ln theta +- t_{n-1} beta / sqrt(n - 1), beta from
    the chi-square interval of n beta^2 / sigma^2, and the pointwise band of P(x) from the
    noncentral t (``p_band`` "noncentral_t"). With censored capacities (blocks still standing
    at the top of the range) the fit is the censored MLE, the intervals of theta and beta
    come from resampling records (``n_boot=0``: Wald intervals) and the band of P(x) from
    the observed information (``p_band`` "likelihood"). Where a group pools several
    structures, their capacities under one record are not independent: the intervals and
    the band of P(x) then come from resampling records (``p_band`` "record_bootstrap"; with
    ``n_boot=0`` the independent bands, with a warning). The fragility reads P(first
    overturning at or below x); a block that survives above it is counted as overturned (see
    ``survives_above_capacity`` in the dataset).

    Parameters and returns as in :func:`stripe_fragility` (``n`` counts capacities, censored
    ones included; ``im_min``/``im_max`` span capacities and censoring levels), with
    ``lack_of_fit_p``: the p-value of the Shapiro-Wilk test of ln(capacity)
    (:func:`capacities_lack_of_fit`) for a group of one structure without censored
    capacities, NaN otherwise; below 0.01 the capacities do not look lognormal.
    """
    conf_level, n_boot = _check(ds, "ida_fragility", conf_level, n_boot)
    im, period = _measure(ds, im, period)
    cap, top, cens_all, ok = ida_arrays(ds, im, period)
    unit = quoted(im)[0]
    rng = bootstrap_rng(seed)
    n_rec = ds.sizes["record"]
    rows = []
    for label, mask in _groups(ds, by, bins).items():
        c, t, cens, keep = cap[:, mask], top[:, mask], cens_all[:, mask], ok[:, mask]
        theta, beta = fit_records(c, t, cens, keep, slice(None))
        cov = capacities_covariance(c[keep & ~cens], t[keep & cens], theta, beta)
        n_unc = int((keep & ~cens).sum())
        pooled = int(mask.sum()) > 1  # several structures share each record
        if n_unc >= 2 and beta == 0.0:  # every capacity the same: no spread to fit or band
            band, method = ((np.nan, np.nan), (np.nan, np.nan)), "none"
            _warn_equal_capacities(label, theta, n_unc, unit)
        elif not cens[keep].any() and n_unc >= 2 and beta > 0 and not pooled:
            band, method = _exact_intervals(theta, beta, n_unc, conf_level), "noncentral_t"
        elif not np.isfinite(beta):
            band, method = ((theta, theta), (np.nan, np.nan)), "none"
        elif pooled and int(keep.any(axis=1).sum()) < 2:  # one record: no record-to-record
            band, method = ((np.nan, np.nan), (np.nan, np.nan)), "none"  # spread to see
        elif n_boot:
            boot = np.array(
                [
                    fit_records(
                        c, t, cens, keep, rng.integers(0, n_rec, n_rec), np.log([theta, beta])
                    )
                    for _ in range(n_boot)
                ]
            )
            band, method = percentile_intervals(boot, conf_level), "likelihood"
            if pooled:  # the capacities of one record are not independent: its resamples say
                good = np.all(np.isfinite(boot) & (boot > 0), axis=1)
                cov, method = np.cov(np.log(boot[good]).T), "record_bootstrap"
        else:
            band, method = wald_intervals(theta, beta, cov, conf_level), "likelihood"
            if pooled:
                warnings.warn(
                    f"ida_fragility: group {label!r} pools {int(mask.sum())} structures per "
                    "record and n_boot=0: its bands treat their capacities as independent, "
                    "which they are not (they share the record); give n_boot > 0 to resample "
                    "records",
                    UserWarning,
                    stacklevel=caller_stacklevel(),
                )
        x = np.where(cens, t, c)[keep]
        row = _row(label, theta, beta, band, keep.sum(), x, unit, by, cov, method, conf_level)
        complete = not pooled and not cens[keep].any() and beta > 0
        row["lack_of_fit_p"] = capacities_lack_of_fit(c[keep & ~cens]) if complete else np.nan
        rows.append(row)
    return pd.DataFrame(rows).set_index(by or "group")


def capacities_lack_of_fit(capacities) -> float:
    """p-value of the Shapiro-Wilk test of normality of ln(capacity) (Shapiro & Wilk 1965,
    scipy.stats.shapiro): whether the capacities of one structure under a suite look
    lognormal at all (its level is exact with both parameters estimated); NaN below 3."""
    c = np.asarray(capacities, float)
    return float(stats.shapiro(np.log(c)).pvalue) if c.size >= 3 else np.nan


def _specs(ds, candidates):
    """(name, period) of each candidate measure; a ValueError for none or an unknown one."""
    if isinstance(candidates, str) or len(candidates) == 0:
        raise ValueError(
            f"candidates must be a non-empty sequence of measures of {names()} "
            f"or (name, period) pairs, got {candidates!r}"
        )
    specs = []
    for c in candidates:
        if isinstance(c, tuple):
            specs.append(c)
        elif c not in names():
            raise ValueError(f"candidates: {c!r} is not one of {names()}")
        elif power(c) == 0:
            raise ValueError(
                f"candidates: {c!r} does not change with a scale factor (power 0), so its "
                "dispersion per power is undefined"
            )
        elif _needs_period(c):
            specs.extend((c, float(t)) for t in np.asarray(ds["period"].values, float))
        else:
            specs.append((c, None))
    return specs


@per_motion
def im_efficiency(
    ds: xr.Dataset, candidates=None, by=None, bins=None, *, n_boot: int = N_BOOT, **kw
) -> pd.DataFrame:
    """Which intensity measure predicts overturning best: the dispersion of each, per power.

    A measure that goes as the k-th power of a scale factor of the record (:func:`power`:
    Arias intensity k = 2) has, for the same information, k times the dispersion of one that
    goes linearly: IM^(1/k) is an equally informative, linear measure, and the fragility
    against it has exactly beta / k. So measures are compared by ``beta_linear`` = beta / k,
    the dispersion of ln(IM) / k; the smaller, the more efficient (the less record-to-record
    scatter of the overturning intensity). For an IDA the betas are those of the capacities
    expressed in each measure (:func:`ida_fragility`); for stripes or a cloud, those of the
    binomial fit against each measure (:func:`stripe_fragility`). Pooled over all
    structures by default: within one block, a dimensional measure and its dimensionless
    ratio differ by a constant and share their beta; across blocks of different sizes and
    slenderness only the groups of [000] can collapse the capacities.

    Parameters
    ----------
    candidates : sequence, optional
        Measure names (``"sa"`` expands to every stored period) or ``(name, period)`` pairs;
        at least one. Default :func:`default_candidates` (every stored measure that scales,
        a registered one too, the ratios and the pulse group).
    by, bins, n_boot, kw
        Passed to the fit (``n_boot`` resamples for the bands, where they are bootstrapped).

    Returns
    -------
    pandas.DataFrame
        Index (``im``, ``group``), sorted by ``beta_linear`` within each group; columns of
        the fit, ``power``, ``beta_linear`` (with ``beta_linear_lo``/``_hi``) and
        ``dimensionless``. A measure in which the outcomes are separated (``separated``) or do
        not rise (``no_rise``) has no beta (NaN, sorted last: not ranked), and warns
        (:class:`~rockstudy.SeparationWarning`).
    """
    fit = fragility_of(ds)
    candidates = default_candidates(ds) if candidates is None else candidates
    frames = []
    for name, period in _specs(ds, candidates):
        if name == "pulse_amplitude_ratio" and not np.isfinite(ds[name].values).any():
            continue  # no record has a pulse
        t = fit(ds, im=name, period=period, by=by, bins=bins, n_boot=n_boot, **kw)
        t.insert(0, "im", _label(name, period))
        t["power"] = power(name)
        for col in ("", "_lo", "_hi"):
            t[f"beta_linear{col}"] = t[f"beta{col}"] / power(name)
        t["dimensionless"] = quoted(name)[0] == "-"
        frames.append(t.reset_index())
    if not frames:
        raise ValueError(f"candidates: none of {list(candidates)!r} is stored with a value")
    table = pd.concat(frames, ignore_index=True)
    group = by or "group"
    table = table.sort_values([group, "beta_linear"], kind="stable")
    return table.set_index(["im", group])
