"""Analyses of result cubes: Sobol' indices, fragility curves, and the collapse of responses
onto the dimensionless groups of [000].

Each function takes an ``xarray.Dataset`` (a cube from :func:`rockstudy.study.run_study`, or
any dataset on a ``sample`` dimension) and returns pandas or xarray objects.

Failed samples (``status`` 2) follow an explicit policy: ``"error"`` (refuse), ``"drop"``
(drop them; for Sobol' the whole Saltelli block of each failed base sample) or ``"impute"``
(replace the output by the mean of the successful samples). Overturning is an outcome, not a
failure.
"""

from __future__ import annotations

import difflib
import json
import warnings
from itertools import combinations_with_replacement
from typing import Literal, NamedTuple

import numpy as np
import pandas as pd
import xarray as xr
from scipy import special
from scipy.spatial import cKDTree

from ..._warnings import caller_stacklevel
from ..spec.schema import Study
from .fragility_fit import (
    BAND_COLUMNS,
    CONF_LEVEL,
    N_BOOT,
    NO_MAXIMUM,
    SEED,
    binomial_covariance,
    bootstrap_rng,
    check_conf_level,
    check_n_boot,
    fit_binomial,
    fit_binomial_limit,
    fragility_row,
    lack_of_fit,
    no_maximum_row,
    percentile_intervals,
    probability_band,
    wald_intervals,
    warn_if_separated,
)

__all__ = [
    "check_variables",
    "collapse_metric",
    "FailedPolicy",
    "first_order_given_data",
    "fragility",
    "fragility_curve",
    "fragility_samples",
    "ROTATION_OUTPUTS",
    "sobol_convergence",
    "sobol_indices",
    "study_of",
    "unexplained_share",
    "UnexplainedShare",
    "warn_if_rotation_of_overturned",
]

FailedPolicy = Literal["error", "drop", "impute"]


def study_of(ds: xr.Dataset) -> Study:
    """The study a cube was made from (its ``study`` attribute), or a ValueError naming the
    attribute and what it must be (never quoting it)."""
    from pydantic import ValidationError

    text = ds.attrs.get("study")
    what = "attrs['study'] must be the JSON text of the study the cube was run from"
    if not isinstance(text, str | bytes):
        raise ValueError(f"{what}; it is {'missing' if text is None else type(text).__name__}")
    try:
        data = json.loads(text)
    except (ValueError, RecursionError):  # JSONDecodeError and UnicodeDecodeError alike
        raise ValueError(f"{what}; it is not JSON") from None
    try:
        return Study.model_validate(data)
    except ValidationError as exc:
        raise ValueError(
            f"{what}; it is JSON but no study ({exc.error_count()} problem(s))"
        ) from None


def _values(ds, output, failed: FailedPolicy):
    y = np.asarray(ds[output].values, dtype=float)
    bad = (ds["status"].values == 2) if "status" in ds else np.zeros(y.size, bool)
    bad |= ~np.isfinite(y)
    if bad.any():
        if failed == "error":
            raise ValueError(
                f"{int(bad.sum())} failed samples in {output!r}; choose failed='drop' or 'impute'"
            )
        if failed == "impute":
            y = np.where(bad, np.mean(y[~bad]), y)
    return y, bad


#: Outputs whose value for an overturned sample is a convention (the fall rotation pi/2, over
#: theta_cr for the ratio), not a rocking amplitude.
ROTATION_OUTPUTS = ("max_rotation", "max_rotation_ratio")


def warn_if_rotation_of_overturned(ds, output, who) -> None:
    """Warn when ``output`` is a peak rotation and some samples of ``ds`` overturned: their
    value is the fall rotation (pi/2, pi/(2 theta_cr) as a ratio), so indices of it on the
    whole design mix overturning with the rocking amplitude."""
    if output not in ROTATION_OUTPUTS or "overturned" not in ds:
        return
    n = int((ds["overturned"].values == 1).sum())
    if n:
        warnings.warn(
            f"{who}: {n} of {ds.sizes['sample']} samples overturned, and their {output} is the "
            "fall rotation pi/2 (over theta_cr for the ratio), which depends on theta_cr alone: "
            f"indices of {output} mix overturning with the rocking amplitude. Analyse "
            "'overturned' for overturning, and the survivors' rotation with "
            "first_order_given_data on ds.where(ds.overturned == 0, drop=True)",
            UserWarning,
            stacklevel=caller_stacklevel(),
        )


def sobol_indices(
    ds: xr.Dataset,
    output: str,
    names=None,
    second_order: bool | None = None,
    failed: FailedPolicy = "error",
    num_resamples: int = 1000,
    conf_level: float = 0.95,
    seed: int = 0,
) -> pd.DataFrame:
    """First-order and total Sobol' indices of ``output`` with bootstrap confidence intervals.

    The cube must hold a Saltelli design (a ``sobol`` study), whose distributed parameters are
    the inputs; ``names`` overrides them (e.g. for datasets made outside a study), in the order
    of the design's columns.

    Returns
    -------
    pandas.DataFrame
        Index: input names; columns ``S1``, ``S1_conf``, ``ST``, ``ST_conf``.
    """
    from SALib.analyze import sobol

    if names is None:
        study = study_of(ds)
        if study.sampler.kind != "sobol":
            raise ValueError("Sobol' indices need a sobol study (Saltelli design)")
        names = list(study.parameters())
        second_order = study.sampler.second_order if second_order is None else second_order
    second_order = bool(second_order)
    d = len(names)
    block = 2 * d + 2 if second_order else d + 2
    y, bad = _values(ds, output, failed)
    warn_if_rotation_of_overturned(ds, output, "sobol_indices")
    if y.size % block:
        raise ValueError(f"{y.size} samples is not a whole number of Saltelli blocks of {block}")
    if failed == "drop" and bad.any():
        keep = ~bad.reshape(-1, block).any(axis=1)
        y = y.reshape(-1, block)[keep].ravel()
    problem = {"num_vars": d, "names": list(names), "bounds": [[0.0, 1.0]] * d}
    res = sobol.analyze(
        problem,
        y,
        calc_second_order=second_order,
        num_resamples=num_resamples,
        conf_level=conf_level,
        seed=seed,
    )
    return pd.DataFrame(
        {k: res[k] for k in ("S1", "S1_conf", "ST", "ST_conf")},
        index=pd.Index(list(names), name="input"),
    )


def sobol_convergence(
    ds: xr.Dataset, output: str, names=None, second_order=None, failed: FailedPolicy = "error", **kw
) -> pd.DataFrame:
    """Sobol' indices on nested prefixes N = 2^k of the base samples (a convergence table).

    Returns a frame with a (N, input) index and the columns of :func:`sobol_indices`.
    """
    if names is None:
        study = study_of(ds)
        names = list(study.parameters())
        second_order = study.sampler.second_order if second_order is None else second_order
    block = 2 * len(names) + 2 if second_order else len(names) + 2
    n_base = ds.sizes["sample"] // block
    frames = []
    k = 4
    while 2**k <= n_base:
        sub = ds.isel(sample=slice(0, 2**k * block))
        t = sobol_indices(sub, output, names, second_order, failed, **kw)
        t.insert(0, "N", 2**k)
        frames.append(t.reset_index())
        k += 1
    return pd.concat(frames).set_index(["N", "input"])


def first_order_given_data(
    ds: xr.Dataset, output: str, variables, failed: FailedPolicy = "drop", seed: int = 0
) -> pd.DataFrame:
    """First-order indices of ``output`` on any variables of the cube (e.g. the dimensionless
    groups, which are not the sampler's inputs), by SALib's RBD-FAST on the given data."""
    from SALib.analyze import rbd_fast

    y, bad = _values(ds, output, failed)
    warn_if_rotation_of_overturned(ds, output, "first_order_given_data")
    x = np.column_stack([np.asarray(ds[v].values, float) for v in variables])
    keep = ~bad & np.all(np.isfinite(x), axis=1)
    x, y = x[keep], y[keep]
    problem = {
        "num_vars": len(variables),
        "names": list(variables),
        "bounds": [[float(c.min()), float(c.max())] for c in x.T],
    }
    res = rbd_fast.analyze(problem, x, y, seed=seed)
    return pd.DataFrame(
        {"S1": res["S1"], "S1_conf": res["S1_conf"]},
        index=pd.Index(list(variables), name="variable"),
    )


# ------------------------------------------------------------------------------ fragility


def check_variables(ds, **fields) -> None:
    """A ValueError naming the keyword whose variable (a name, or None: not given) ``ds``
    lacks, with the closest names it has."""
    for field, name in fields.items():
        if name is not None and name not in ds:
            close = difflib.get_close_matches(str(name), [str(v) for v in ds.data_vars], 3)
            hint = f" (did you mean {', '.join(map(repr, close))}?)" if close else ""
            raise ValueError(f"{field}: {name!r} is not a variable of the dataset{hint}")


def fragility(
    ds: xr.Dataset,
    intensity: str,
    outcome: str = "overturned",
    by=None,
    bins=None,
    *,
    n_boot: int = N_BOOT,
    conf_level: float = CONF_LEVEL,
    seed: int = SEED,
    failed: FailedPolicy = "drop",
) -> pd.DataFrame:
    """Lognormal fragility curves P(outcome | intensity) fitted by maximum likelihood.

    The Bernoulli case of :func:`~rockstudy.study.analysis.fragility_fit.fit_binomial` (Baker 2015,
    eq. 11): ``beta`` is the maximum-likelihood estimate.

    Parameters
    ----------
    intensity : str
        The intensity measure variable (e.g. ``pga_ratio``, ``amplitude``).
    outcome : str
        A 0/1 variable (default ``overturned``).
    by : str, optional
        Fit one curve per group of this variable; with ``bins`` (edges) for continuous ones.
    n_boot : int
        Bootstrap resamples (of the samples, refitting both parameters) for the intervals of
        theta and beta; 0 gives their Wald intervals from the information instead.
    conf_level : float
        Level of every band, in (0, 1).

    Returns
    -------
    pandas.DataFrame
        One row per group: ``theta`` (median capacity), ``beta`` (log-standard deviation, the
        MLE), their intervals, the number of samples ``n``, the observed intensity range
        ``im_min``-``im_max`` of the group, two flags: ``theta_in_range`` (the median lies
        within the observed intensities) and ``band_in_range`` (so does its whole band), and
        the covariance of (ln theta, ln beta) from which :func:`fragility_curve` forms the
        pointwise band of P over both parameters (``p_band`` "likelihood"), and
        ``lack_of_fit_p``, the p-value of the Hosmer-Lemeshow test of the fitted lognormal on
        the samples (:func:`~rockstudy.study.analysis.fragility_fit.lack_of_fit`): below
        0.01 the lognormal shape does not describe them (NaN without a fit).
        A median outside the data is an extrapolation of the lognormal shape, not a
        measurement: read it as "not reached within the sampled range" (or "below it").
        A group whose outcome never changes has no fit: its ``theta`` and band are ``inf``
        (the outcome never happened: not reached) or ``0`` (it always happened: below the
        sampled range), its ``beta`` NaN. A group whose outcomes are separated in the
        intensity (every overturned sample at or above every survivor:
        :func:`~rockstudy.study.analysis.fragility_fit.separation`) has no maximum of the
        likelihood: ``separated`` is True, ``theta`` and ``beta`` are NaN, ``theta_lo`` /
        ``theta_hi`` are the gap in which the median lies (the highest survivor, the lowest
        overturned intensity), with a :class:`~rockstudy.SeparationWarning`; so does a group
        whose overturned samples do not lie higher in the intensity than the survivors
        (``no_rise`` True; theta, beta and band NaN). Such bootstrap resamples enter at their
        limit (:func:`~rockstudy.study.analysis.fragility_fit.fit_binomial_limit`). Groups
        with fewer than 10 samples are left out.
    """
    n_boot, conf_level = check_n_boot(n_boot), check_conf_level(conf_level)
    rng = bootstrap_rng(seed)
    rows = []
    for name, (x, z) in fragility_samples(ds, intensity, outcome, by, bins, failed).items():
        if z.size >= 10:
            rows.append(_bernoulli_row(name, x, z, by, n_boot, conf_level, rng))
    if not rows:
        raise ValueError(
            f"no group has 10 samples with a finite, positive {intensity!r}: "
            "no fragility curve can be fitted"
        )
    return pd.DataFrame(rows).set_index(by or "group")


def fragility_samples(
    ds, intensity, outcome="overturned", by=None, bins=None, failed: FailedPolicy = "drop"
) -> dict:
    """The samples :func:`fragility` fits, by group (its index labels): for each, the
    intensities and outcomes of the samples with a finite, positive intensity (and, with
    ``failed="drop"``, not failed)."""
    check_variables(ds, intensity=intensity, outcome=outcome, by=by)
    if bins is not None and by is None:
        raise ValueError("bins: bins the variable given as by=; give by= too, or no bins")
    y, bad = _values(ds, outcome, failed)
    im = np.asarray(ds[intensity].values, float)
    keep = ~bad & np.isfinite(im) & (im > 0)
    groups = {"all": keep}
    if by is not None:
        g = np.asarray(ds[by].values)
        if bins is not None:
            idx = np.digitize(g, bins)
            groups = {
                f"{bins[i - 1]:g}-{bins[i]:g}": keep & (idx == i) for i in range(1, len(bins))
            }
        else:
            groups = {v: keep & (g == v) for v in np.unique(g[keep])}
    return {name: (im[sel], y[sel]) for name, sel in groups.items()}


def _bernoulli_row(name, x, z, by, n_boot, conf_level, rng):
    """The fragility row of one group of samples: fit, intervals, covariance."""
    ones = np.ones(z.size)
    kind, low, high = warn_if_separated("fragility", name, x, z, ones)
    if kind in NO_MAXIMUM:  # separated or no rise: no maximum, no fit
        return no_maximum_row(name, kind, low, high, z.size, x, by, conf_level)
    theta, beta = fit_binomial(x, z, ones)
    if not np.isfinite(beta):  # no fit: the median lies beyond the data, on one side
        band = ((theta, theta), (np.nan, np.nan))
        return fragility_row(name, theta, beta, band, z.size, x, by, None, "none", conf_level)
    cov = binomial_covariance(x, ones, theta, beta)
    if n_boot:
        start = np.log([theta, beta])
        boot = np.array(
            [
                fit_binomial_limit(x[k], z[k], ones, start)
                for k in (rng.integers(0, z.size, z.size) for _ in range(n_boot))
            ]
        )
        band = percentile_intervals(boot, conf_level)
    else:
        band = wald_intervals(theta, beta, cov, conf_level)
    row = fragility_row(name, theta, beta, band, z.size, x, by, cov, "likelihood", conf_level)
    row["lack_of_fit_p"] = lack_of_fit(x, z, theta, beta)[2]
    return row


def fragility_curve(table: pd.DataFrame, im) -> xr.Dataset:
    """Evaluate fitted fragility curves at intensities ``im``, with pointwise bands of P.

    The bands vary both theta and beta: the method and level are the table's (``p_band``,
    ``conf_level``; see :func:`~rockstudy.study.analysis.fragility_fit.probability_band`). A group
    without a fit (beta NaN) gives NaN.

    Returns
    -------
    xarray.Dataset
        ``probability``, ``lower`` and ``upper`` on (``group``, ``intensity``).
    """
    missing = [c for c in ("theta", "beta", "n", *BAND_COLUMNS) if c not in table]
    if missing:
        raise ValueError(f"table: not a fragility table (no columns {missing})")
    im = np.asarray(im, float)
    p, lower, upper = [], [], []
    with np.errstate(divide="ignore", invalid="ignore"):
        for _, r in table.iterrows():
            cov = [
                [r.var_ln_theta, r.cov_ln_theta_ln_beta],
                [r.cov_ln_theta_ln_beta, r.var_ln_beta],
            ]
            lo, hi = probability_band(im, r.theta, r.beta, r.n, cov, r.p_band, r.conf_level)
            p.append(special.ndtr(np.log(im / r.theta) / r.beta))
            lower.append(lo)
            upper.append(hi)
    coords = {"group": table.index.astype(str).values, "intensity": im}
    dims = ("group", "intensity")
    return xr.Dataset(
        {"probability": (dims, p), "lower": (dims, lower), "upper": (dims, upper)}, coords=coords
    )


# ------------------------------------------------------------------------------ collapse


def collapse_metric(
    ds: xr.Dataset, response: str, groups, decimals: int = 10, failed: FailedPolicy = "drop"
) -> float:
    """Share of the response variance that lies within sets of samples sharing the same groups.

    Samples are grouped by their (rounded) values of ``groups``; the metric is the within-set
    sum of squares over the total, both over the samples whose group point is replicated (a
    group point met once carries no within-set variance: it says nothing about similarity).
    It is 0 for a perfectly self-similar response and ~1 when the groups explain nothing.

    Raises
    ------
    ValueError
        If fewer than half of the samples share their group point with another sample: the
        design is not replicated (``[sampler] replicates = k`` draws the group points first),
        and the few coincident points it has (e.g. the Saltelli rows that differ only in an
        input outside the groups) do not stand for it. Use :func:`unexplained_share` on such
        designs. Also if the response has no variance over the replicated samples.
    """
    y, bad = _values(ds, response, failed)
    keys = np.column_stack([np.round(np.asarray(ds[g].values, float), decimals) for g in groups])[
        ~bad
    ]
    y = y[~bad]
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    replicated = counts[inverse] > 1
    if not replicated.mean() >= 0.5:
        raise ValueError(
            f"collapse_metric needs a replicated design: only {int(replicated.sum())} of the "
            f"{y.size} samples share their point of the groups {list(groups)} with another "
            "sample (at least half must). Draw the design with [sampler] replicates = k, or "
            "use unexplained_share on designs without replicated group points"
        )
    y, inverse = y[replicated], inverse[replicated]
    means = np.bincount(inverse, weights=y) / np.maximum(np.bincount(inverse), 1)
    within = np.sum((y - means[inverse]) ** 2)
    total = np.sum((y - y.mean()) ** 2)
    if not total > 0:
        raise ValueError(
            f"{response!r} is constant over the replicated samples: the share of its "
            "variance within group points is undefined"
        )
    return float(within / total)


class UnexplainedShare(NamedTuple):
    """The result of :func:`unexplained_share`."""

    #: share of the response variance left unexplained by the k-nearest-neighbour fit
    value: float
    #: the share the same fit leaves on these sample points for a smooth (cubic) response of
    #: the groups alone: a lower estimate of the estimator's floor at this sample size
    floor: float
    #: number of samples used
    n: int
    #: number of neighbours of the fit
    k: int


def _knn_unexplained(x, y, k):
    """Leave-one-out k-nearest-neighbour residual share of ``y`` over points ``x``."""
    _, idx = cKDTree(x).query(x, k=k + 1)
    fit = y[idx[:, 1:]].mean(axis=1)
    return float(np.sum((y - fit) ** 2) / np.sum((y - y.mean()) ** 2))


def _cubic_features(x):
    """All monomials of degree <= 3 in the columns of ``x`` (the constant included)."""
    terms = (c for deg in range(4) for c in combinations_with_replacement(range(x.shape[1]), deg))
    return np.column_stack([np.prod(x[:, list(c)], axis=1) for c in terms])


def unexplained_share(
    ds: xr.Dataset,
    response: str,
    groups,
    k: int = 10,
    failed: FailedPolicy = "drop",
    log_groups: bool = True,
) -> UnexplainedShare:
    """Cross-check on any random design: the share of the response variance left unexplained
    by a smooth fit over the groups (the mean of the k nearest neighbours in standardised,
    optionally logarithmic, group coordinates, leaving each sample out).

    The fit has a floor that depends on the number of samples: even an exactly self-similar
    response leaves a share unexplained, because the neighbours sit at other group points.
    The floor returned next to the value is the share the same fit leaves, on the same sample
    points, for the least-squares cubic in the groups fitted to the response (a smooth
    response of the same trend that depends on the groups only). It falls as the sample grows.
    It is a lower estimate: a response sharper than a cubic (steep near the overturning
    boundaries) leaves more even when exactly self-similar (the linear flagship's survivors,
    exactly similar: 0.046 against a floor of 0.018). A value within a few times its floor
    cannot be told from complete similarity with this many samples.

    Returns
    -------
    UnexplainedShare
        ``(value, floor, n, k)``.
    """
    y, bad = _values(ds, response, failed)
    x = np.column_stack([np.asarray(ds[g].values, float) for g in groups])
    keep = ~bad & np.all(np.isfinite(x), axis=1)
    x, y = x[keep], y[keep]
    if y.size <= k + 1 or not np.ptp(y) > 0:
        raise ValueError(
            f"unexplained_share needs more than k + 1 = {k + 1} samples and a response that "
            f"varies; {response!r} has {y.size} usable samples"
        )
    if log_groups and np.all(x > 0):
        x = np.log(x)
    x = (x - x.mean(axis=0)) / np.where(x.std(axis=0) > 0, x.std(axis=0), 1.0)
    features = _cubic_features(x)
    smooth = features @ np.linalg.lstsq(features, y, rcond=None)[0]
    floor = _knn_unexplained(x, smooth, k) if np.ptp(smooth) > 0 else 0.0
    return UnexplainedShare(_knn_unexplained(x, y, k), floor, int(y.size), int(k))
