"""Fragilities of nested events that cannot cross: one dispersion for all the states of an
object, and medians in the order of the nesting.

Slide limits and damage states nest: a block that slid more than d2 > d1 slid more than d1,
and a higher damage state is reached only past a lower one, so P(worse | x) <= P(milder | x)
at every intensity x. Lognormal curves Phi(ln(x / theta_k) / beta_k) fitted apart need not
keep that order: two lognormals of different beta always cross somewhere, and an engineer
may read a probability of the worse state above that of the milder one.

The nested fit keeps it. One dispersion beta is common to all the fitted states of an
object, each state keeps its median theta_k, and (ln theta_k, ln beta) maximise the summed
log-likelihood of all the states' data (the censored lognormal likelihood of IDA capacities,
or the binomial one of stripes and clouds; Baker 2015) under the constraint that a worse
state's median is at least that of each milder state it implies. Curves with a common beta
and ordered medians never cross. The constraint is met by pooling adjacent violators: the
free joint fit (BFGS) first; while a state's median lies above that of a worse state it
implies, the worst such pair shares one median and the fit is made again. Where the data
disagree with the order the two medians are thus pooled: for a fixed beta each state's
likelihood is log-concave in its ln theta, for which pooling adjacent violators gives the
constrained maximum (checked against a constrained optimiser in the tests).

The states are tied by ``above``: ``above[k]`` is the index of the next worse state that
state k's event is implied by (-1: none), a forest. Only the states whose own fit exists
(finite theta > 0 and beta > 0) enter the nested fit; a state not reached (theta inf), always
reached (theta 0) or without a fit keeps its own answer.

Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic structural
analysis. Earthquake Spectra 31(1), 579-599.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import optimize, special

from ..spec.design_kinds import kind_of
from . import record_fragility as rf
from .fragility_fit import (
    CONF_LEVEL,
    N_BOOT,
    SEED,
    bootstrap_rng,
    fit_binomial_limit,
    fit_capacities,
    percentile_intervals,
)
from .risk import _check_hazard, object_risk

__all__ = [
    "CAPACITIES",
    "OUTCOMES",
    "NestedStates",
    "crosses",
    "fragility_crossed",
    "fit_nested",
    "nested_above",
    "nested_table",
    "risk_frames",
    "shown_table",
    "rates_crossed",
    "separate_fit",
]

#: The data of a state as IDA capacities: (uncensored capacities, censoring levels).
CAPACITIES = "capacities"
#: The data of a state as points: (intensities, outcomes 0/1).
OUTCOMES = "outcomes"

_LOG_SQRT_2PI = 0.5 * np.log(2.0 * np.pi)


def _capacity_terms(mu, b, c, t):
    """(nll, d nll / d mu, d nll / d ln beta) of log capacities ``c`` and log censoring
    levels ``t`` of one state, at median ln theta = ``mu`` and dispersion ``b``."""
    u, v = (c - mu) / b, (t - mu) / b
    ls = special.log_ndtr(-v)
    h = np.exp(-0.5 * v * v - _LOG_SQRT_2PI - ls)  # hazard of the censored terms
    f = np.sum(0.5 * u * u) + u.size * np.log(b) - np.sum(ls)
    return f, -(np.sum(u) + np.sum(h)) / b, u.size - np.sum(u * u) - np.sum(h * v)


def _outcome_terms(mu, b, x, y):
    """As :func:`_capacity_terms` for the log intensities ``x`` and outcomes ``y`` (0/1) of
    one state's points: the binomial (probit) likelihood."""
    z = (x - mu) / b
    lc, ls = special.log_ndtr(z), special.log_ndtr(-z)
    pdf = -0.5 * z * z - _LOG_SQRT_2PI
    e = -(y * np.exp(pdf - lc) - (1.0 - y) * np.exp(pdf - ls))  # d nll / d z
    f = -np.sum(y * lc + (1.0 - y) * ls)
    return f, -np.sum(e) / b, -np.sum(e * z)


_TERMS = {CAPACITIES: _capacity_terms, OUTCOMES: _outcome_terms}


def _joint_nll(p, kind, data, group, m):
    """The summed negative log-likelihood of all states (per point) and its gradient at
    p = (ln theta of each group of states sharing a median, ln beta); ``group`` the group
    of each state."""
    b = np.exp(p[-1])
    f, g_mu, g_s = 0.0, np.zeros(len(data)), 0.0
    for k, (a, z) in enumerate(data):
        fk, g_mu[k], sk = _TERMS[kind](p[group[k]], b, a, z)
        f, g_s = f + fk, g_s + sk
    grad = np.append(np.bincount(group, weights=g_mu, minlength=p.size - 1), g_s)
    return f / m, grad / m


def _grouped_fit(kind, data, group, mu, beta, m):
    """(ln theta of each state, beta): the joint MLE with the states of a group (``group``)
    sharing one median, from the medians ``mu`` (their mean per group) and ``beta``."""
    n = int(group.max()) + 1
    start = np.bincount(group, weights=mu, minlength=n) / np.bincount(group, minlength=n)
    res = optimize.minimize(
        _joint_nll,
        np.append(start, np.log(beta)),
        args=(kind, data, group, m),
        jac=True,
        method="BFGS",
        options={"gtol": 1e-9},
    )
    return res.x[:-1][group], float(np.exp(res.x[-1]))


def _ordered_fit(kind, data, above, mu, beta, m):
    """(ln theta, beta) of the states maximising the joint likelihood with ln theta of each
    state at most that of the state above it: the free joint MLE, then, while a state's
    median lies above that of the state above it, the worst such pair pooled (one median)
    and the fit made again (pool adjacent violators)."""
    group = np.arange(len(data))
    while True:
        group = np.unique(group, return_inverse=True)[1]
        mu, beta = _grouped_fit(kind, data, group, mu, beta, m)
        tied = np.array([a >= 0 and group[k] != group[a] for k, a in enumerate(above)])
        gap = np.where(tied, mu - mu[np.maximum(above, 0)], -np.inf)
        if not gap.size or gap.max() <= 1e-10:
            return mu, beta
        k = int(np.argmax(gap))
        group = np.where(group == group[k], group[above[k]], group)


def _fitted(separate) -> np.ndarray:
    """Whether each state's own fit exists: finite theta > 0 and beta > 0."""
    t, b = (np.array(v, float) for v in zip(*separate, strict=True))
    with np.errstate(invalid="ignore"):
        return np.isfinite(t) & (t > 0) & np.isfinite(b) & (b > 0)


def _restricted(above, keep) -> list[int]:
    """``above`` among the states ``keep`` only: each kept state tied to its nearest kept
    state above it, renumbered."""
    index = {k: i for i, k in enumerate(np.flatnonzero(keep))}
    out = []
    for k in index:
        a = above[k]
        while a >= 0 and a not in index:
            a = above[a]
        out.append(index[a] if a >= 0 else -1)
    return out


def fit_nested(kind, data, above, separate) -> tuple[np.ndarray, np.ndarray]:
    """The nested fit of an object's states (see the module).

    Parameters
    ----------
    kind : str
        :data:`CAPACITIES` (``data`` per state: (uncensored capacities, censoring levels))
        or :data:`OUTCOMES` (per state: (intensities, outcomes 0/1)), all > 0, in one unit.
    data : sequence of tuple of array_like
        Each state's data.
    above : sequence of int
        The next worse state of each (-1: none); a forest.
    separate : sequence of (theta, beta)
        Each state's own fit (:func:`separate_fit`): which states enter, and the start.

    Returns
    -------
    (theta, beta) : numpy.ndarray
        Per state: the nested fit where the state's own fit exists (one beta for all of
        them), its own fit elsewhere.
    """
    theta, beta = (np.array(v, float) for v in zip(*separate, strict=True))
    keep = _fitted(separate)
    if keep.sum() < 2:
        return theta, beta
    index = np.flatnonzero(keep)
    sub_above = np.array(_restricted(list(above), keep), int)
    second = np.log if kind == CAPACITIES else np.asarray  # log levels, or the outcomes
    logs = [
        (np.log(np.asarray(data[k][0], float)), second(np.asarray(data[k][1], float)))
        for k in index
    ]
    m = sum(a.size + (z.size if kind == CAPACITIES else 0) for a, z in logs)
    start = np.mean(np.log(beta[index]))
    mu, common = _ordered_fit(kind, logs, sub_above, np.log(theta[index]), np.exp(start), m)
    theta[index], beta[index] = np.exp(mu), common
    return theta, beta


def separate_fit(kind, a, z) -> tuple[float, float]:
    """A state's own fit, as the fitters of the annual rate make it: the censored lognormal
    MLE of capacities ``a`` (censoring levels ``z``), or the binomial MLE of the points at
    ``a`` with outcomes ``z`` (a separated sample at its limit, beta 0); (inf, NaN) where
    the state was never reached."""
    if kind == CAPACITIES:
        return fit_capacities(a, z) if np.size(a) else (np.inf, np.nan)
    z = np.asarray(z, float)
    if not z.any():
        return np.inf, np.nan
    return fit_binomial_limit(a, z, np.ones(z.size))


def nested_above(values, groups=None) -> list[int]:
    """``above`` of states that nest by ``values`` (larger: worse) within each group of
    ``groups`` (default one): each state tied to the next larger value of its group; the
    largest of each group to -1."""
    values = np.asarray(values, float)
    groups = np.zeros(values.size, int) if groups is None else np.asarray(groups)
    above = [-1] * values.size
    for g in np.unique(groups):
        members = np.flatnonzero(groups == g)
        ranked = members[np.argsort(values[members], kind="stable")]
        for lower, upper in zip(ranked[:-1], ranked[1:], strict=True):
            above[lower] = int(upper)
    return above


def _ancestors(above, k) -> list[int]:
    """The states above state k, nearest first."""
    out, a = [], above[k]
    while a >= 0:
        out.append(a)
        a = above[a]
    return out


def crosses(theta, beta, above, low, high, n=401) -> np.ndarray:
    """True at each state whose curve P = Phi(ln(x / theta) / beta) lies below that of a
    worse state (of ``above``) somewhere in [``low``, ``high``] (beyond 1e-9)."""
    x = np.geomspace(low, high, n)
    with np.errstate(divide="ignore", invalid="ignore"):
        p = special.ndtr(
            np.log(x[None, :] / np.asarray(theta, float)[:, None])
            / np.asarray(beta, float)[:, None]
        )
    p = np.where(np.isfinite(p), p, np.nan)
    out = np.zeros(len(above), bool)
    for k in range(len(above)):
        for a in _ancestors(above, k):
            with np.errstate(invalid="ignore"):
                out[k] |= bool(np.any(p[a] > p[k] + 1e-9))
    return out


def rates_crossed(rate, above) -> np.ndarray:
    """True at each state (axis 0 of ``rate``, the objects on axis 1) whose rate lies below
    that of a worse state of ``above``: the fits cross there (read the two rates as about
    equal)."""
    rate = np.asarray(rate, float)
    out = np.zeros(rate.shape, bool)
    for k in range(len(above)):
        for a in _ancestors(above, k):
            with np.errstate(invalid="ignore"):
                out[k] |= rate[k] < rate[a]
    return out


# ------------------------------------------------------------------------------ designs


def _state_arrays(view, im, period):
    """(kind, arrays on (record, structure, ...)) of one state's design view: an IDA's
    (capacities, censoring levels, censored, usable), or the points' (intensity, outcome,
    usable), in the quoted units of ``im``."""
    if kind_of(view).capacities:
        return CAPACITIES, rf.ida_arrays(view, im, period)
    j = view["overturned"].dims.index("structure")
    return OUTCOMES, tuple(np.moveaxis(a, j, 1) for a in rf.stripe_arrays(view, im, period))


def _take(kind, arrays, rows, cols):
    """A state's data (:func:`fit_nested`) of the records ``rows`` and structures ``cols``."""
    if kind == CAPACITIES:
        cap, top, cens, ok = (a[rows][:, cols] for a in arrays)
        return cap[ok & ~cens], top[ok & cens]
    x, y, ok = (a[rows][:, cols] for a in arrays)
    return x[ok], y[ok].astype(float)


class NestedStates:
    """The nested fits of the states of a design, each state a view of it whose outcome is
    that state (:func:`~rockstudy.study.analysis.sliding.limit_design`,
    :func:`~rockstudy.study.analysis.states.state_design`), tied by ``above``; the
    intensities in the quoted units of ``im`` (at ``period``)."""

    def __init__(self, views, above, im, period=None):
        arrays = [_state_arrays(v, im, period) for v in views]
        self.kind = arrays[0][0]
        self.arrays = [a for _, a in arrays]
        self.above = list(above)
        self._cache = {}

    def fit(self, rows, cols):
        """(theta, beta) of each state on the records ``rows`` (an index array) and the
        structures ``cols`` (pooled): the nested fit (:func:`fit_nested`)."""
        rows, cols = np.asarray(rows), np.atleast_1d(np.asarray(cols))
        key = (rows.tobytes(), cols.tobytes())
        if key not in self._cache:
            data = [_take(self.kind, a, rows, cols) for a in self.arrays]
            separate = [separate_fit(self.kind, *d) for d in data]
            self._cache[key] = fit_nested(self.kind, data, self.above, separate)
        return self._cache[key]

    def refit(self, k):
        """The ``refit(j, rows)`` of state ``k`` for
        :func:`~rockstudy.study.analysis.risk.object_risk`: its nested fit on object j."""

        def fit(j, rows):
            theta, beta = self.fit(rows, j)
            return theta[k], beta[k]

        return fit


def _bootstrap_band(nested, cols, n_rec, n_boot, conf_level, seed):
    """Per state: the percentile intervals ((theta_lo, theta_hi), (beta_lo, beta_hi)) and
    the covariance of (ln theta, ln beta) of the nested fits of records resampled with
    replacement; NaN without resamples."""
    rng = bootstrap_rng(seed)
    boot = np.array(
        [np.stack(nested.fit(rng.integers(0, n_rec, n_rec), cols), axis=1) for _ in range(n_boot)]
    ).reshape(n_boot, len(nested.above), 2)
    out = []
    for k in range(len(nested.above)):
        if not n_boot:
            out.append((((np.nan,) * 2, (np.nan,) * 2), np.full((2, 2), np.nan)))
            continue
        good = np.all(np.isfinite(boot[:, k]) & (boot[:, k] > 0), axis=1)
        cov = np.cov(np.log(boot[good, k]).T) if good.sum() > 2 else np.full((2, 2), np.nan)
        out.append((percentile_intervals(boot[:, k], conf_level), cov))
    return out


def _nested_row(row, theta, beta, band, cov, conf_level):
    """The separate fit's table ``row`` with the nested fit (theta, beta), its band and
    covariance in place of the state's own."""
    (t_lo, t_hi), (b_lo, b_hi) = band
    row = row.copy()
    row[["theta", "beta", "theta_lo", "theta_hi", "beta_lo", "beta_hi"]] = [
        theta,
        beta,
        t_lo,
        t_hi,
        b_lo,
        b_hi,
    ]
    row[["var_ln_theta", "cov_ln_theta_ln_beta", "var_ln_beta"]] = [cov[0, 0], cov[0, 1], cov[1, 1]]
    row["p_band"] = "record_bootstrap" if np.all(np.isfinite(cov)) else "none"
    row["conf_level"] = conf_level
    row["theta_in_range"] = bool(row["im_min"] <= theta <= row["im_max"])
    row["band_in_range"] = bool(row["im_min"] <= t_lo and t_hi <= row["im_max"])
    if "lack_of_fit_p" in row:
        row["lack_of_fit_p"] = np.nan
    return row


def fragility_crossed(table, keys, above) -> pd.Series:
    """Per row of a fragility ``table`` (outer level the states ``keys``, inner the
    groups): whether its curve lies below that of a worse state (of ``above``) of its group
    somewhere in the group's observed intensity range (:func:`crosses`)."""
    flags = pd.Series(False, index=table.index)
    for label in table.index.get_level_values(1).unique():
        rows = [(k, label) for k in keys]
        part = table.loc[rows]
        low, high = np.nanmin(part["im_min"].values), np.nanmax(part["im_max"].values)
        if np.isfinite(low) and np.isfinite(high) and 0 < low < high:
            hit = crosses(part["theta"].values, part["beta"].values, above, low, high)
            flags.loc[rows] = hit
    return flags


def nested_table(ds, views, keys, above, table, im=None, period=None, by="structure", **kw):
    """The fragility ``table`` of the states ``keys`` (outer index level, the design views
    ``views``, tied by ``above``) fitted apart, with the nested fit in place of each
    state's own: ``theta``, ``beta``, their intervals and the covariance of
    (ln theta, ln beta) from resampling records (``p_band`` "record_bootstrap"; NaN with
    ``n_boot=0``), ``fit`` "nested" and ``crossed_separate`` (the flag of the fits made
    apart); ``kw`` as the fitters' (``bins``, ``n_boot``, ``conf_level``, ``seed``)."""
    im, period = rf._measure(ds, im, period)
    nested = NestedStates(views, above, im, period)
    n_boot, conf_level = kw.get("n_boot", N_BOOT), kw.get("conf_level", CONF_LEVEL)
    out = table.copy()
    out["crossed_separate"] = fragility_crossed(table, keys, above)
    n_rec = ds.sizes["record"]
    for label, mask in rf._groups(ds, by, kw.get("bins")).items():
        cols = np.flatnonzero(mask)
        theta, beta = nested.fit(np.arange(n_rec), cols)
        bands = _bootstrap_band(nested, cols, n_rec, n_boot, conf_level, kw.get("seed", SEED))
        for k, key in enumerate(keys):
            band, cov = bands[k]
            out.loc[(key, label)] = _nested_row(
                out.loc[(key, label)], theta[k], beta[k], band, cov, conf_level
            )
    out["fit"] = "nested"
    return out


def shown_table(ds, views, keys, above, level, nested, im=None, period=None, by="structure", **kw):
    """The fragility table of the states ``keys`` (the outer index level ``level``) of the
    design ``ds``, each fitted by the design's fitter on its view in ``views``
    (:func:`~rockstudy.study.analysis.record_fragility.fragility_of`, with ``im``,
    ``period``, ``by`` and ``kw``): with ``nested`` the nested fit (:func:`nested_table`),
    else the fits made apart (``fit`` "separate"); ``crossed`` True at a curve that lies
    below that of a worse state of its group in the observed range (never, for the nested
    fit)."""
    tables = {
        key: rf.fragility_of(v)(v, im=im, period=period, by=by, **kw)
        for key, v in zip(keys, views, strict=True)
    }
    table = pd.concat(tables, names=[level])
    if nested:
        table = nested_table(ds, views, keys, above, table, im, period, by, **kw)
    else:
        table["fit"] = "separate"
    table["crossed"] = fragility_crossed(table, keys, above)
    return table


def risk_frames(views, above, hazard, years, cuts, nested, **kw):
    """:func:`~rockstudy.study.analysis.risk.object_risk` of each state's design view
    (``uplift_cut`` of each from ``cuts``) with the nested fits (``nested``: one
    :class:`NestedStates` for all, on the same resampled records) or the states' own."""
    states = None
    if nested:
        states = NestedStates(views, above, *_check_hazard(views[0], hazard))
    return [
        object_risk(v, hazard, years, uplift_cut=c, refit=states and states.refit(k), **kw)
        for k, (v, c) in enumerate(zip(views, cuts, strict=True))
    ]
