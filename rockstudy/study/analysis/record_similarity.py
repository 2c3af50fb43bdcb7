"""Self-similarity on records: does the fragility of blocks of different sizes collapse when
the intensity is expressed in the record groups?

For each size class of blocks (bins of the half-diagonal R) the median overturning intensity
theta is fitted from a record design (:mod:`rockstudy.study.designs.records`: the lognormal
fit of IDA capacities, or the binomial fit of stripes and clouds, as in
:mod:`rockstudy.study.analysis.record_fragility`). The spread of those medians across size classes
measures how far the measure is from collapsing the sizes:

- ``ratio``: the largest median over the smallest (1 for a complete collapse);
- ``log_std``: the standard deviation of ln theta across classes (0 for a complete collapse).

In dimensional terms (PGA in g) the medians spread apart: a larger block needs a stronger
record (Housner 1963). In the record groups of paper 000's similarity, PGA / (g tan alpha)
within bins of omega_p / p (the pulse's frequency over the block's p), or PGV p / (g tan alpha),
they collapse to the extent that the pulse governs overturning. The bands come from
resampling the records (with replacement), the same resample for every class, so they are the
bands of the spread itself.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from ...motions import measures
from ..spec.design_kinds import kind_of
from .fragility_fit import CONF_LEVEL, N_BOOT, NO_MAXIMUM, SEED, fit_binomial_limit, separation
from .motion_axes import per_motion
from .record_fragility import fit_capacities, ida_arrays, quoted, stripe_arrays

__all__ = ["FREQUENCY_GROUP", "size_class_medians", "size_classes", "size_edges", "size_label"]

#: Variable on (record, structure) whose bins condition the collapse (omega_p / p).
FREQUENCY_GROUP = "pulse_frequency_ratio"


def size_edges(ds: xr.Dataset, size_bins=3) -> np.ndarray:
    """Edges [m] of the size classes of the blocks by half-diagonal R.

    Parameters
    ----------
    size_bins : int or array_like
        A number of classes of equal count (quantiles of R over the structures), or the bin
        edges [m] (increasing; a block outside them belongs to no class).
    """
    if "half_diagonal" not in ds or not np.all(np.isfinite(ds["half_diagonal"].values)):
        raise ValueError(
            "size_bins: size classes need the half_diagonal R of every structure (give the "
            "structures as blocks or with half_diagonal)"
        )
    R = np.asarray(ds["half_diagonal"].values, float)
    if np.ndim(size_bins) == 0:
        k = int(size_bins)
        if k != size_bins or k < 2:
            raise ValueError(
                f"size_bins must be a whole number >= 2 or bin edges, got {size_bins!r}"
            )
        if np.unique(R).size < k:
            raise ValueError(
                f"size_bins: {k} classes need at least {k} distinct half_diagonal values, "
                f"the design has {np.unique(R).size}"
            )
        edges = np.quantile(R, np.linspace(0.0, 1.0, k + 1))
        edges[-1] = np.nextafter(edges[-1], np.inf)
        return edges
    edges = np.asarray(size_bins, float)
    if edges.ndim != 1 or edges.size < 3 or np.any(np.diff(edges) <= 0):
        raise ValueError(
            f"size_bins: edges must be increasing, at least 3 of them, got {size_bins!r}"
        )
    return edges


def size_label(low: float, high: float) -> str:
    """The name of a size class in words: 'R 0.3 to 0.776 m'."""
    return f"R {low:.3g} to {high:.3g} m"


def size_classes(ds: xr.Dataset, size_bins=3) -> dict:
    """{label: boolean mask over ``structure``}: blocks binned by half-diagonal R [m]
    (:func:`size_edges`); empty classes are left out."""
    edges = size_edges(ds, size_bins)
    idx = np.digitize(np.asarray(ds["half_diagonal"].values, float), edges)
    return {
        size_label(edges[i - 1], edges[i]): idx == i
        for i in range(1, edges.size)
        if np.any(idx == i)
    }


def _frequency_bands(ds, frequency_bins) -> dict:
    """{label: boolean mask over (record, structure)}: all points, or bins of omega_p / p."""
    shape = (ds.sizes["record"], ds.sizes["structure"])
    if frequency_bins is None:
        return {"all": np.ones(shape, bool)}
    w = ds[FREQUENCY_GROUP].transpose("record", "structure").values
    finite = np.isfinite(w) & (w > 0)
    if np.ndim(frequency_bins) == 0:
        k = int(frequency_bins)
        if k != frequency_bins or k < 1 or not finite.any():
            raise ValueError(
                "frequency_bins must be None, a whole number >= 1 (bins of equal count) or "
                f"bin edges, and the records need pulses; got {frequency_bins!r}"
            )
        edges = np.quantile(w[finite], np.linspace(0.0, 1.0, k + 1))
        edges[-1] = np.nextafter(edges[-1], np.inf)
    else:
        edges = np.asarray(frequency_bins, float)
        if edges.ndim != 1 or edges.size < 2 or np.any(np.diff(edges) <= 0):
            raise ValueError(f"frequency_bins: edges must be increasing, got {frequency_bins!r}")
    idx = np.where(finite, np.digitize(np.where(finite, w, 0.0), edges), 0)
    return {
        f"omega_p/p {edges[i - 1]:.3g} to {edges[i]:.3g}": idx == i for i in range(1, edges.size)
    }


def _median_fitter(ds, im, period):
    """A function (record rows, mask on (record, structure)) -> (theta, points, no maximum)
    of the design's fit (outcomes separated in the intensity or without a rise: theta at the
    limit of :func:`~rockstudy.study.analysis.fragility_fit.fit_binomial_limit`), and the
    quoted unit of ``im``."""
    needs_period = im in measures.MEASURES and measures.MEASURES[im].needs_period
    if needs_period and period is None and np.isfinite(ds.attrs.get("im_period", np.nan)):
        period = ds.attrs["im_period"]
    if kind_of(ds, default="stripes").capacities:
        cap, top, cens, ok = ida_arrays(ds, im, period)
        x = np.where(cens, top, cap)  # capacities, and the censoring levels

        def fit(rows, mask):
            keep = (ok & mask)[rows]
            c, t, z = cap[rows], top[rows], cens[rows]
            theta = fit_capacities(c[keep & ~z], t[keep & z])[0] if keep.any() else np.nan
            return theta, x[rows][keep], False

    else:
        x, y, ok = stripe_arrays(ds, im, period)
        y = y.astype(float)
        extra = (slice(None), slice(None)) + (None,) * (x.ndim - 2)

        def fit(rows, mask):
            keep = (ok & mask[extra])[rows]
            if not keep.any():
                return np.nan, np.zeros(0), False
            xs, ys, ones = x[rows][keep], y[rows][keep], np.ones(int(keep.sum()))
            no_fit = separation(xs, ys, ones)[0] in NO_MAXIMUM
            return fit_binomial_limit(xs, ys, ones)[0], xs, no_fit

    return fit, quoted(im)[0]


@per_motion
def size_class_medians(
    ds: xr.Dataset,
    im: str,
    period=None,
    size_bins=3,
    frequency_bins=None,
    *,
    n_boot: int = N_BOOT,
    conf_level: float = CONF_LEVEL,
    seed: int = SEED,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Median overturning intensity theta of each size class, and its spread across classes.

    Parameters
    ----------
    ds : xarray.Dataset
        A record design (:func:`~rockstudy.study.designs.records.incremental_dynamic_analysis`,
        :func:`~rockstudy.study.designs.records.multiple_stripes` or ``cloud``).
    im, period : str, float
        The intensity measure (one of :func:`~rockstudy.study.analysis.record_fragility.names`) and
        the period [s] of one that needs it.
    size_bins : int or array_like
        Size classes (:func:`size_classes`).
    frequency_bins : None, int or array_like
        None: all points together; else bins of omega_p / p (a number of bins of equal count,
        or edges) within which the spread is measured separately. Points whose record has no
        pulse belong to no bin.
    n_boot, conf_level, seed
        Bands by resampling the records.

    Returns
    -------
    (medians, spread) : pandas.DataFrame, pandas.DataFrame
        ``medians`` indexed by (frequency band, size class): ``theta`` [quoted unit], its band
        ``theta_lo``/``theta_hi``, ``n`` (points), ``im_min``, ``im_max``, ``theta_in_range``,
        ``no_maximum`` (outcomes separated in the intensity, or without a rise:
        :data:`~rockstudy.study.analysis.fragility_fit.NO_MAXIMUM`; no fit, ``theta`` NaN,
        the class left out of the spread; its resamples enter the band at their limit,
        :func:`~rockstudy.study.analysis.fragility_fit.fit_binomial_limit`).
        ``spread`` indexed by frequency band: ``ratio`` (largest over smallest median) and
        ``log_std`` (standard deviation of ln theta) over the classes whose median lies within
        their sampled intensities (``classes`` of them; NaN if fewer than 2), with bands, and
        ``unit``.
    """
    fit, unit = _median_fitter(ds, im, period)
    classes = size_classes(ds, size_bins)
    bands = _frequency_bands(ds, frequency_bins)
    n_rec = ds.sizes["record"]
    every = np.arange(n_rec)
    rng = np.random.default_rng(seed)
    resamples = [rng.integers(0, n_rec, n_rec) for _ in range(int(n_boot))]
    q = [50 * (1 - conf_level), 50 * (1 + conf_level)]
    med_rows, spread_rows = [], []
    for band, bmask in bands.items():
        masks = {c: bmask & cmask[None, :] for c, cmask in classes.items()}
        fitted = {c: fit(every, m) for c, m in masks.items()}
        inside = {}
        for c, (theta, xs, no_fit) in fitted.items():
            lo, hi = (float(xs.min()), float(xs.max())) if xs.size else (np.nan, np.nan)
            theta = np.nan if no_fit else theta  # the limit of no fit is no estimate
            # within the sampled intensities, up to rounding (a single capacity c is fitted
            # as exp(ln c))
            inside[c] = bool(xs.size and lo * (1 - 1e-12) <= theta <= hi * (1 + 1e-12))
            med_rows.append(
                {
                    "band": band,
                    "size class": c,
                    "theta": theta,
                    "n": int(xs.size),
                    "im_min": lo,
                    "im_max": hi,
                    "theta_in_range": inside[c],
                    "no_maximum": no_fit,
                }
            )
        used = [c for c in classes if inside[c]]
        boot = np.array([[fit(rows, masks[c])[0] for c in classes] for rows in resamples])
        boot = boot.reshape(len(resamples), len(classes))
        for k, row in enumerate(med_rows[-len(classes) :]):
            lo_hi = _quantiles(boot[:, k], q)
            row["theta_lo"], row["theta_hi"] = lo_hi
        cols = [list(classes).index(c) for c in used]
        ratio, log_std = _spread(np.array([fitted[c][0] for c in used]))
        boot_spread = np.array([_spread(b[cols]) for b in boot]) if boot.size else np.zeros((0, 2))
        spread_rows.append(
            {
                "band": band,
                "ratio": ratio,
                "log_std": log_std,
                "classes": len(used),
                "ratio_lo": _quantiles(boot_spread[:, 0], q)[0] if boot.size else np.nan,
                "ratio_hi": _quantiles(boot_spread[:, 0], q)[1] if boot.size else np.nan,
                "log_std_lo": _quantiles(boot_spread[:, 1], q)[0] if boot.size else np.nan,
                "log_std_hi": _quantiles(boot_spread[:, 1], q)[1] if boot.size else np.nan,
                "unit": unit,
            }
        )
    medians = pd.DataFrame(med_rows).set_index(["band", "size class"])
    medians["unit"] = unit
    return medians, pd.DataFrame(spread_rows).set_index("band")


def _spread(theta) -> tuple[float, float]:
    """(largest / smallest, std of ln) of the finite positive medians; NaN if fewer than 2."""
    theta = np.asarray(theta, float)
    theta = theta[np.isfinite(theta) & (theta > 0)]
    if theta.size < 2:
        return np.nan, np.nan
    return float(theta.max() / theta.min()), float(np.std(np.log(theta)))


def _quantiles(values, q) -> tuple[float, float]:
    values = np.asarray(values, float)
    values = values[~np.isnan(values)]
    if not values.size:
        return np.nan, np.nan
    lo, hi = np.percentile(values, q, method="inverted_cdf")
    return float(lo), float(hi)
