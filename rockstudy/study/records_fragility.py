"""Fragility from record designs (:mod:`rockstudy.study.records_designs`): the binomial
maximum-likelihood fit of stripes (Baker 2015), the lognormal fit of IDA capacities, and the
efficiency of intensity measures.

A lognormal fragility is P(overturning | IM = x) = Phi(ln(x / theta) / beta): theta the median
capacity, beta the dispersion. Intensities are in the units users quote (:data:`QUOTED_UNITS`:
PGA and Sa in g, PGV in m/s, the dimensionless groups of [000] as they are).

Every table carries the observed intensity range (``im_min``, ``im_max``) and the flags
``theta_in_range`` and ``band_in_range``: a median outside the data is an extrapolation of the
lognormal shape, to be read as "not reached within the sampled range" (or "below it").

Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic structural
analysis. Earthquake Spectra 31(1), 579-599.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr
from scipy import optimize, special, stats

from ..constants import G
from .analysis import fragility_row

#: measure -> (quoted unit, factor from SI to it).
QUOTED_UNITS = {
    "pga": ("g", 1.0 / G),
    "sa": ("g", 1.0 / G),
    "pgv": ("m/s", 1.0),
    "psv": ("m/s", 1.0),
    "pgd": ("m", 1.0),
    "sd": ("m", 1.0),
    "arias": ("m/s", 1.0),
    "cav": ("m/s", 1.0),
    "spectrum_intensity": ("m", 1.0),
    "pga_ratio": ("-", 1.0),
    "pgv_ratio": ("-", 1.0),
    "pulse_amplitude_ratio": ("-", 1.0),
}
_SPECTRAL = ("sa", "psv", "sd")
_LOG_SQRT_2PI = 0.5 * np.log(2.0 * np.pi)
#: candidates of :func:`im_efficiency` (with ``sa`` at every stored period).
DEFAULT_CANDIDATES = (
    "pga",
    "pgv",
    "cav",
    "spectrum_intensity",
    "sa",
    "pga_ratio",
    "pgv_ratio",
    "pulse_amplitude_ratio",
)


def intensity(ds: xr.Dataset, im: str, period=None, scale: str = "scale") -> xr.DataArray:
    """The intensity measure ``im`` of each simulated point of a record design, in quoted units.

    The unscaled record's value (``ds[im]``, per record or per record and structure) times the
    scale factor ``ds[scale]`` (squared for Arias intensity); for a cloud (no scale variable),
    the unscaled value. ``scale="capacity_scale"`` gives the IDA capacities in ``im``.

    Parameters
    ----------
    im : str
        A key of :data:`QUOTED_UNITS`.
    period : float, optional
        T [s] of ``sa``, ``psv`` or ``sd``: one of the dataset's ``period`` values. ``psv`` and
        ``sd`` follow from the stored ``sa``.
    """
    if im not in QUOTED_UNITS:
        raise ValueError(f"im must be one of {sorted(QUOTED_UNITS)}, got {im!r}")
    unit, factor = QUOTED_UNITS[im]
    if (im if im not in _SPECTRAL else "sa") not in ds:
        raise ValueError(f"im={im!r} is not stored in the dataset")
    if im in _SPECTRAL:
        if period is None:
            raise ValueError(f"im={im!r} needs a period [s]")
        stored = np.asarray(ds["period"].values, float)
        hit = np.flatnonzero(np.isclose(stored, float(period), rtol=1e-12, atol=0.0))
        if not hit.size:
            raise ValueError(f"period: {period!r} s is not stored; the dataset has {list(stored)}")
        w = 2.0 * np.pi / stored[hit[0]]
        base = ds["sa"].isel(period=hit[0], drop=True) / w ** {"sa": 0, "psv": 1, "sd": 2}[im]
    else:
        if period is not None:
            raise ValueError(f"period is only for {_SPECTRAL}, not im={im!r}")
        base = ds[im]
    value = base * factor
    if scale in ds:
        value = value * ds[scale] ** (2.0 if im == "arias" else 1.0)
    return value.rename(im).assign_attrs(unit=unit)


def _label(im, period):
    return im if period is None else f"{im}(T={float(period):g} s)"


# ------------------------------------------------------------------------------ fits


def fit_binomial(im, n_overturned, n_total, start=None) -> tuple[float, float]:
    """Maximum-likelihood lognormal fragility of stripe data, eq. (11) of Baker (2015).

    .. math:: \\max_{\\theta, \\beta} \\sum_j \\ln \\binom{n_j}{z_j}
              + z_j \\ln \\Phi(\\ln(x_j / \\theta) / \\beta)
              + (n_j - z_j) \\ln[1 - \\Phi(\\ln(x_j / \\theta) / \\beta)]

    Parameters
    ----------
    im : array_like
        Intensity levels x_j (> 0); single points (``n_total`` 1) make it the Bernoulli fit of
        a cloud.
    n_overturned, n_total : array_like
        z_j overturned out of n_j.

    Returns
    -------
    (theta, beta)
        Median capacity in the units of ``im``, and dispersion. ``inf``/NaN or 0/NaN when the
        outcome never or always happened (no fit).
    """
    x = np.log(np.asarray(im, float))
    z = np.asarray(n_overturned, float)
    n = np.asarray(n_total, float)
    if not (x.shape == z.shape == n.shape) or np.any(z > n) or np.any(z < 0):
        raise ValueError("im, n_overturned and n_total must match, with 0 <= n_overturned <= n")
    n_sum = n.sum()
    if z.sum() == 0:
        return np.inf, np.nan
    if z.sum() == n.sum():
        return 0.0, np.nan

    def nll(q):
        beta = np.exp(np.clip(q[1], -12.0, 6.0))
        u = (x - q[0]) / beta
        lp, lq, ld = special.log_ndtr(u), special.log_ndtr(-u), -0.5 * u * u - _LOG_SQRT_2PI
        r = (z * np.exp(ld - lp) - (n - z) * np.exp(ld - lq)) / n_sum  # d loglik / du, per trial
        return -np.sum(z * lp + (n - z) * lq) / n_sum, np.array([np.sum(r) / beta, np.sum(r * u)])

    if start is None:
        w = n / n.sum()
        sd = np.sqrt(np.sum(w * (x - np.sum(w * x)) ** 2))
        start = np.array([np.sum(w * x), np.log(max(sd, 0.1))])
    res = optimize.minimize(nll, start, jac=True, method="BFGS", options={"gtol": 1e-9})
    with np.errstate(over="ignore"):
        return float(np.exp(res.x[0])), float(np.exp(res.x[1]))


def fit_capacities(capacities, censored_at=None, start=None) -> tuple[float, float]:
    """Maximum-likelihood lognormal fit of IDA capacities.

    Without censoring it is closed form: ln theta = mean(ln c), beta = std(ln c) (the MLE,
    dividing by n). Capacities censored at ``censored_at`` (the block stood up to that level)
    enter through the survival function, and the fit is numerical:

    .. math:: \\max \\sum_{uncensored} \\ln \\phi(u_i) - \\ln\\beta
              + \\sum_{censored} \\ln[1 - \\Phi(u_k)], \\quad u = (\\ln c - \\ln\\theta) / \\beta

    ``start`` = (ln theta, ln beta) starts the numerical fit (default: the uncensored fit).

    Returns
    -------
    (theta, beta)
        ``inf``/NaN if every capacity is censored; NaN if fewer than 2 are not.
    """
    c = np.log(np.asarray(capacities, float))
    cens = np.log(np.asarray([] if censored_at is None else censored_at, float))
    if c.size + cens.size == 0:
        raise ValueError("capacities: no capacity to fit")
    if c.size == 0:
        return np.inf, np.nan
    if c.size < 2:
        return float(np.exp(c[0])) if not cens.size else np.nan, np.nan
    mu, beta = float(np.mean(c)), float(np.std(c))
    if not cens.size:
        return float(np.exp(mu)), beta

    def nll(q):  # q = (ln theta, ln beta), with the exact gradient
        b = np.exp(q[1])
        u, v = (c - q[0]) / b, (cens - q[0]) / b
        ls = special.log_ndtr(-v)
        h = np.exp(-0.5 * v * v - _LOG_SQRT_2PI - ls)  # hazard of the censored terms
        m = u.size + v.size  # mean over the points: a gradient tolerance independent of n
        f = -(np.sum(-0.5 * u * u - q[1]) + np.sum(ls)) / m
        grad = -np.array([(np.sum(u) + np.sum(h)) / b, np.sum(u * u - 1.0) + np.sum(h * v)]) / m
        return f, grad

    start = [mu, np.log(max(beta, 0.05))] if start is None else start
    res = optimize.minimize(nll, start, jac=True, method="BFGS", options={"gtol": 1e-9})
    with np.errstate(over="ignore"):
        return float(np.exp(res.x[0])), float(np.exp(res.x[1]))


# ------------------------------------------------------------------------------ tables


def _groups(ds, by, bins):
    """{label: boolean mask over ``structure``}."""
    n = ds.sizes["structure"]
    if by is None:
        return {"all": np.ones(n, bool)}
    if by == "structure":
        return {int(s): np.arange(n) == k for k, s in enumerate(ds["structure"].values)}
    if by not in ds or ds[by].dims != ("structure",):
        raise ValueError(f"by must be None, 'structure' or a variable on structure, got {by!r}")
    g = np.asarray(ds[by].values)
    if bins is None:
        return {v: g == v for v in np.unique(g)}
    idx = np.digitize(g, bins)
    return {f"{bins[i - 1]:g}-{bins[i]:g}": idx == i for i in range(1, len(bins))}


def _row(label, theta, beta, band, n, x, unit, by):
    return {**fragility_row(label, theta, beta, band, n, x, by), "unit": unit}


def _percentiles(boot, conf_level):
    q = [50 * (1 - conf_level), 50 * (1 + conf_level)]
    with np.errstate(invalid="ignore"):
        (t_lo, b_lo), (t_hi, b_hi) = np.percentile(boot, q, axis=0, method="inverted_cdf")
    return (t_lo, t_hi), (b_lo, b_hi)


def stripe_fragility(
    ds: xr.Dataset,
    im: str | None = None,
    period=None,
    by=None,
    bins=None,
    n_boot: int = 200,
    conf_level: float = 0.9,
    seed: int = 0,
) -> pd.DataFrame:
    """Lognormal fragility of a stripe (or cloud) design by the binomial MLE (Baker 2015).

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`~rockstudy.study.records_designs.multiple_stripes` or
        :func:`~rockstudy.study.records_designs.cloud`.
    im, period : str, float
        The intensity measure (default the stripes' own); any other stored measure makes the
        points single Bernoulli trials at their own intensities.
    by, bins
        One curve per ``structure``, per value of a variable on ``structure`` (e.g.
        ``half_diagonal``), or per bin of it (edges); default one curve for all.
    n_boot, conf_level, seed
        Bands of theta and beta by resampling records (with replacement).

    Returns
    -------
    pandas.DataFrame
        One row per group: ``theta`` [quoted unit], ``beta``, their bands, ``n`` (points),
        ``im_min``, ``im_max``, ``theta_in_range``, ``band_in_range`` and ``unit``. Points that
        failed (``status`` != 0) or have no finite intensity are left out.
    """
    im = ds.attrs.get("im", "pga") if im is None else im
    if period is None and im in _SPECTRAL and np.isfinite(ds.attrs.get("im_period", np.nan)):
        period = ds.attrs["im_period"]
    x_all = intensity(ds, im, period).broadcast_like(ds["overturned"])
    dims = ds["overturned"].dims
    x_all = x_all.transpose(*dims).values
    y_all = ds["overturned"].values.astype(float)
    ok = np.isfinite(x_all) & (x_all > 0) & (ds["status"].transpose(*dims).values == 0)
    unit = QUOTED_UNITS[im][0]
    rng = np.random.default_rng(seed)
    n_rec = ds.sizes["record"]
    rows = []
    for label, mask in _groups(ds, by, bins).items():
        x, y, keep = x_all[:, mask], y_all[:, mask], ok[:, mask]
        fit = fit_binomial(x[keep], y[keep], np.ones(int(keep.sum())))
        boot = []
        for _ in range(n_boot if np.isfinite(fit[1]) else 0):
            k = rng.integers(0, n_rec, n_rec)
            kk = keep[k]
            boot.append(fit_binomial(x[k][kk], y[k][kk], np.ones(int(kk.sum())), start=np.log(fit)))
        band = _percentiles(np.array(boot), conf_level) if boot else ((fit[0],) * 2, (np.nan,) * 2)
        rows.append(_row(label, *fit, band, keep.sum(), x[keep], unit, by))
    return pd.DataFrame(rows).set_index(by or "group")


def _fit_records(cap, top, censored, keep, rows, start=None):
    """fit_capacities on the records ``rows`` (an index or a resample) of (record, structure)
    arrays: capacities where not censored, censoring levels where censored."""
    kk, cc = keep[rows], censored[rows]
    return fit_capacities(cap[rows][kk & ~cc], top[rows][kk & cc], start)


def ida_fragility(
    ds: xr.Dataset,
    im: str | None = None,
    period=None,
    by=None,
    bins=None,
    conf_level: float = 0.9,
    n_boot: int = 200,
    seed: int = 0,
) -> pd.DataFrame:
    """Lognormal fit of IDA capacities (first overturning levels) in any stored measure.

    Without censored capacities the fit is closed form (:func:`fit_capacities`) and so are its
    bands: ln theta +- t_{n-1} s / sqrt(n), and beta from the chi-square interval of the
    variance (s the standard deviation with n - 1). With censored capacities (blocks still
    standing at the top of the range) the fit is the censored MLE and the bands come from
    resampling records. The fragility reads P(first overturning at or below x); a block that
    resurrects above it is counted as overturned (see ``resurrection`` in the dataset).

    Parameters and returns as in :func:`stripe_fragility` (``n`` counts capacities, censored
    ones included; ``im_min``/``im_max`` span capacities and censoring levels).
    """
    im = ds.attrs.get("im", "pga") if im is None else im
    if period is None and im in _SPECTRAL and np.isfinite(ds.attrs.get("im_period", np.nan)):
        period = ds.attrs["im_period"]
    cap = intensity(ds, im, period, scale="capacity_scale").transpose("record", "structure").values
    top = intensity(ds, im, period, scale="capacity_scale_lower")
    top = top.transpose("record", "structure").values
    cens_all = ds["censored"].transpose("record", "structure").values
    ok = ds["status"].transpose("record", "structure").values == 0
    ok &= np.where(cens_all, np.isfinite(top), np.isfinite(cap)) & (
        np.where(cens_all, top, cap) > 0
    )
    unit = QUOTED_UNITS[im][0]
    rng = np.random.default_rng(seed)
    n_rec = ds.sizes["record"]
    rows = []
    for label, mask in _groups(ds, by, bins).items():
        c, t, cens, keep = cap[:, mask], top[:, mask], cens_all[:, mask], ok[:, mask]

        theta, beta = _fit_records(c, t, cens, keep, slice(None))
        n_unc = int((keep & ~cens).sum())
        if not cens[keep].any() and n_unc >= 2:
            s = np.std(np.log(c[keep]), ddof=1)
            half = stats.t.ppf(0.5 + conf_level / 2, n_unc - 1) * s / np.sqrt(n_unc)
            chi = stats.chi2.ppf([0.5 + conf_level / 2, 0.5 - conf_level / 2], n_unc - 1)
            band = (
                (theta * np.exp(-half), theta * np.exp(half)),
                tuple(np.sqrt((n_unc - 1) * s**2 / chi)),
            )
        elif np.isfinite(beta):
            boot = [
                _fit_records(c, t, cens, keep, rng.integers(0, n_rec, n_rec), np.log([theta, beta]))
                for _ in range(n_boot)
            ]
            band = _percentiles(np.array(boot), conf_level)
        else:
            band = (theta, theta), (np.nan, np.nan)
        x = np.where(cens, t, c)[keep]
        rows.append(_row(label, theta, beta, band, keep.sum(), x, unit, by))
    return pd.DataFrame(rows).set_index(by or "group")


def im_efficiency(
    ds: xr.Dataset, candidates=DEFAULT_CANDIDATES, by=None, bins=None, n_boot: int = 100, **kw
) -> pd.DataFrame:
    """Which intensity measure predicts overturning best: the dispersion beta of each.

    The smaller beta, the more efficient the measure (the less record-to-record scatter of the
    overturning intensity). For an IDA the betas are those of the capacities expressed in each
    measure (:func:`ida_fragility`); for stripes or a cloud, those of the binomial fit against
    each measure (:func:`stripe_fragility`). Pooled over all structures by default: within one
    block, a dimensional measure and its dimensionless ratio differ by a constant and share
    their beta; across blocks of different sizes and slenderness only the groups of [000]
    can collapse the capacities.

    Parameters
    ----------
    candidates : sequence
        Measure names (``"sa"`` expands to every stored period) or ``(name, period)`` pairs.
    by, bins, n_boot, kw
        Passed to the fit (``n_boot`` resamples for the bands, where they are bootstrapped).

    Returns
    -------
    pandas.DataFrame
        Index (``im``, ``group``), sorted by beta within each group; columns of the fit and
        ``dimensionless``.
    """
    fit = ida_fragility if ds.attrs.get("design") == "ida" else stripe_fragility
    specs = []
    for c in candidates:
        if isinstance(c, tuple):
            specs.append(c)
        elif c in _SPECTRAL:
            specs.extend((c, float(t)) for t in np.asarray(ds["period"].values, float))
        else:
            specs.append((c, None))
    frames = []
    for name, period in specs:
        if name == "pulse_amplitude_ratio" and not np.isfinite(ds[name].values).any():
            continue  # no record has a pulse
        t = fit(ds, im=name, period=period, by=by, bins=bins, n_boot=n_boot, **kw)
        t.insert(0, "im", _label(name, period))
        t["dimensionless"] = QUOTED_UNITS[name][0] == "-"
        frames.append(t.reset_index())
    table = pd.concat(frames, ignore_index=True)
    group = by or "group"
    table = table.sort_values([group, "beta"], kind="stable")
    return table.set_index(["im", group])
