"""Lognormal fragility fits, shared by the Monte Carlo analyses
(:func:`rockstudy.study.analysis.fragility`) and the record designs
(:mod:`rockstudy.study.analysis.record_fragility`), and pointwise bands of the fitted curve.

A lognormal fragility is P(x) = Phi(ln(x / theta) / beta): theta the median capacity, beta the
dispersion. **beta is the maximum-likelihood estimate everywhere**: for capacities (IDA), the
standard deviation of ln c dividing by n, not n - 1; for outcomes (stripes, clouds, Monte Carlo
samples), the binomial MLE of Baker (2015), eq. (11). Every band is built on the same estimate.
Outcomes separated in the intensity (every overturned trial at or above every one that stood)
have no MLE: :func:`separation` says so exactly, and the fits return NaN and warn
(:class:`~rockstudy.SeparationWarning`) instead of the step an optimiser would stop near.

Pointwise bands of P(x) vary **both** parameters (a band that moves theta alone and keeps the
point beta is far too narrow in the tails, where the uncertainty of beta dominates):

- ``"likelihood"`` (outcomes, and censored capacities): the Wald interval of the probit
  u(x) = ln(x / theta) / beta, var u = g' C g with g = du / d(ln theta, ln beta) =
  (-1 / beta, -u) and C the inverse information of (ln theta, ln beta) (the expected
  information of the binomial likelihood; the observed information of the censored one);
  the band is Phi(u -+ z se(u)), z the normal quantile of the level.
- ``"record_bootstrap"`` (IDA capacities of several structures per record, which share
  their record and are not independent): the same probit interval, with C the covariance
  of (ln theta, ln beta) over fits to records resampled with replacement.
- ``"noncentral_t"`` (uncensored capacities, one per record): exact. With s the standard
  deviation of ln c (n - 1) and u = (ln x - mu) / sigma, sqrt(n) (ln x - mean ln c) / s
  follows the noncentral t with n - 1 degrees of freedom and noncentrality sqrt(n) u (Owen
  1968, sec. 3); inverting it in the noncentrality gives the band of Phi(u) at every x with
  the nominal coverage.

Measured coverage of the 90 % bands of the true P at x = theta e^{+-2 beta}:
``benchmarks/bench_fragility_coverage.py``.

Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic structural
analysis. Earthquake Spectra 31(1), 579-599.
Owen, D. B. (1968). A survey of properties and applications of the noncentral
t-distribution. Technometrics 10(3), 445-478.
"""

from __future__ import annotations

import numbers
import warnings

import numpy as np
from scipy import optimize, special, stats

from ... import _validate
from ..._warnings import SeparationWarning, caller_stacklevel

__all__ = [
    "BAND_COLUMNS",
    "BAND_METHODS",
    "binned_outcomes",
    "binomial_covariance",
    "bootstrap_rng",
    "capacities_covariance",
    "check_conf_level",
    "check_n_boot",
    "CONF_LEVEL",
    "fit_binomial",
    "fit_binomial_limit",
    "fit_capacities",
    "fragility_row",
    "lack_of_fit",
    "LACK_OF_FIT_LEVEL",
    "MAX_BOOT",
    "MIN_EXPECTED",
    "N_BOOT",
    "NO_MAXIMUM",
    "no_maximum_row",
    "percentile_intervals",
    "probability_band",
    "SEED",
    "SEPARATED",
    "separation",
    "separation_message",
    "SEPARATIONS",
    "wald_intervals",
    "warn_if_separated",
]

_LOG_SQRT_2PI = 0.5 * np.log(2.0 * np.pi)
#: how the pointwise band of P(x) of a fitted row is formed (see the module docstring).
#: Resamples (of records, or of samples) behind every bootstrapped band, unless a call gives
#: ``n_boot``: the fitting functions, the reports and the risk integral share it.
N_BOOT = 200
#: The confidence level of every band, unless a call gives ``conf_level``.
CONF_LEVEL = 0.9
#: The seed of every bootstrap, unless a call gives ``seed``.
SEED = 0

BAND_METHODS = ("likelihood", "record_bootstrap", "noncentral_t", "none")


def check_conf_level(conf_level) -> float:
    """``conf_level`` as a float strictly between 0 and 1, or a ValueError naming it."""
    if isinstance(conf_level, bool) or not isinstance(conf_level, numbers.Real):
        raise ValueError(f"conf_level must be a number in (0, 1), got {conf_level!r}")
    if not 0.0 < float(conf_level) < 1.0:  # NaN fails too
        raise ValueError(f"conf_level must be in (0, 1), got {conf_level!r}")
    return float(conf_level)


#: The most resamples of a bootstrap band: ten times the 1,000 or so that a percentile interval
#: is usually formed from. Each resample refits every structure, so the bound keeps a call
#: finite (1e9 resamples ran without end).
MAX_BOOT = 10_000


def check_n_boot(n_boot) -> int:
    """``n_boot`` as an int in [0, :data:`MAX_BOOT`], or a ValueError naming it."""
    return _validate.count("n_boot", n_boot, 0, MAX_BOOT)


def bootstrap_rng(seed) -> np.random.Generator:
    """The random generator of a bootstrap, seeded by ``seed``: a whole number >= 0 (as a
    study's), or a ValueError naming it."""
    return np.random.default_rng(_validate.count("seed", seed, 0))


# ------------------------------------------------------------------------------ fits


def _binomial_nll(q, x, z, n):
    """Negative binomial log-likelihood per trial of q = (ln theta, ln beta), and its exact
    gradient (through the Mills ratios)."""
    beta = np.exp(np.clip(q[1], -12.0, 6.0))
    u = (x - q[0]) / beta
    lp, lq, ld = special.log_ndtr(u), special.log_ndtr(-u), -0.5 * u * u - _LOG_SQRT_2PI
    m = n.sum()
    r = (z * np.exp(ld - lp) - (n - z) * np.exp(ld - lq)) / m  # d loglik / du, per trial
    return -np.sum(z * lp + (n - z) * lq) / m, np.array([np.sum(r) / beta, np.sum(r * u)])


def _outcomes(im, n_overturned, n_total):
    """(ln x, z, n) of outcome data as float arrays, or a ValueError."""
    im = np.asarray(im, float)
    z = np.asarray(n_overturned, float)
    n = np.asarray(n_total, float)
    if not (im.shape == z.shape == n.shape) or np.any(z > n) or np.any(z < 0):
        raise ValueError("im, n_overturned and n_total must match, with 0 <= n_overturned <= n")
    bad = im[~(np.isfinite(im) & (im > 0))]
    if bad.size:
        raise ValueError(f"im: intensities must be finite and > 0, got {bad[:3].tolist()}")
    return np.log(im), z, n


#: What :func:`separation` says of outcome data: only ``"overlap"`` has a maximum.
SEPARATIONS = ("overlap", "quasi", "complete", "no rise", "one outcome")
#: The kinds of :data:`SEPARATIONS` whose likelihood rises as beta -> 0 ...
SEPARATED = ("quasi", "complete")
#: ... and those without a maximum of the likelihood at all (no fit, but not "one outcome").
NO_MAXIMUM = (*SEPARATED, "no rise")


def _separation(x, z, n):
    """(kind, ln s, ln o) of :func:`separation` on validated log data."""
    stood, fell = x[z < n], x[z > 0]
    if not (stood.size and fell.size):
        return "one outcome", np.nan, np.nan
    s, o = float(stood.max()), float(fell.min())
    if s < o:
        return "complete", s, o
    # the score of b = 1 / beta at b = 0 has the sign of this difference of mean ln x
    rise = np.sum(z * x) / np.sum(z) - np.sum((n - z) * x) / np.sum(n - z)
    tried = x[n > 0]
    if tried.min() == tried.max() or rise <= 0.0:  # one level, or no rise
        return "no rise", s, o
    return ("quasi" if s == o else "overlap"), s, o


def separation(im, n_overturned, n_total) -> tuple[str, float, float]:
    """Whether outcomes are separated in the intensity: whether :func:`fit_binomial` has an MLE.

    The fragility is the probit model P = Phi(a + b ln x) with a = -ln(theta) / beta and
    b = 1 / beta > 0. Its binomial MLE exists (finite and unique) if and only if the data
    *overlap*, that is, are neither completely nor quasi-completely separated (Albert and
    Anderson 1984 for the logistic link; Silvapulle 1981 for binomial response models, the
    probit among them). With one covariate and b > 0, and s the highest intensity at which a
    trial stood (z_j < n_j), o the lowest at which one overturned (z_j > 0):

    - ``"complete"``, s < o: a step at any theta in (s, o) classifies every trial; the
      log-likelihood rises to 0 as beta -> 0, with theta anywhere in [s, o];
    - ``"quasi"``, s = o: the outcomes are mixed at exactly one level, the only level at which
      both occur, below it every trial stood and above it every one overturned; the
      log-likelihood rises as beta -> 0, theta -> s, towards the binomial log-likelihood of
      that level at its observed proportion;
    - ``"no rise"``: the trials that overturned do not lie higher in ln x, on average, than
      those that stood (or all lie at one level). The log-likelihood is concave in (a, b);
      its derivative in b at b = 0 (a flat curve P = the overall proportion p) is
      proportional to sum_j (z_j - n_j p) ln x_j, which is <= 0 exactly then, so the
      maximum over b > 0 lies at b -> 0: beta -> infinity, a flat curve, theta not
      identifiable (an optimiser stops at some large beta, which would read as a fit);
    - ``"overlap"``, s > o with a rise: the MLE exists, finite and unique;
    - ``"one outcome"``: every trial stood or every one overturned (no fit at all).

    In the first two the dispersion is not identifiable: the data say that theta lies in
    [s, o], not how spread the capacities are; in the third the data show no increasing
    fragility at all. The checks are exact (order statistics and the sign of a sum), not a
    threshold on a fitted beta.

    Returns
    -------
    (kind, s, o)
        ``kind`` one of :data:`SEPARATIONS`; s and o in the units of ``im`` (NaN for
        ``"one outcome"``).

    Albert, A. and Anderson, J. A. (1984). On the existence of maximum likelihood estimates in
    logistic regression models. Biometrika 71(1), 1-10.
    Silvapulle, M. J. (1981). On the existence of maximum likelihood estimators for the
    binomial response models. Journal of the Royal Statistical Society B 43(3), 310-313.
    """
    kind, s, o = _separation(*_outcomes(im, n_overturned, n_total))
    return kind, float(np.exp(s)), float(np.exp(o))


def separation_message(kind, low, high, unit="") -> str:
    """The words of a :class:`~rockstudy.SeparationWarning` for ``kind`` (of
    :data:`NO_MAXIMUM`) and the gap [``low``, ``high``]."""
    if kind == "no rise":
        return (
            "the trials that overturned do not lie higher in the intensity (on average, in "
            "ln x) than those that stood: no increasing lognormal fragility fits them; the "
            "likelihood rises as beta -> infinity (a flat curve) and has no maximum, so "
            "theta and beta are not identifiable (NaN)"
        )
    how = "completely" if kind == "complete" else "quasi-completely"
    mixed = "" if kind == "complete" else " (both occur at one level only)"
    unit = f" {unit}" if unit and unit != "-" else ""
    return (
        f"the outcomes are {how} separated in the intensity: every trial that overturned lies "
        f"at or above every one that stood{mixed}, so the likelihood rises as beta -> 0 and "
        f"has no maximum; beta is not identifiable (NaN) and the median lies between "
        f"{low:.4g} and {high:.4g}{unit} (Albert and Anderson 1984)"
    )


def warn_if_separated(where, label, im, n_overturned, n_total, unit="") -> tuple:
    """:func:`separation` of the outcomes of group ``label``, with a
    :class:`~rockstudy.SeparationWarning` from ``where`` (the public function; the warning
    points at the user's call, :func:`~rockstudy._warnings.caller_stacklevel`) if they have
    no maximum (:data:`NO_MAXIMUM`)."""
    kind, low, high = separation(im, n_overturned, n_total)
    if kind in NO_MAXIMUM:
        message = f"{where}: group {str(label)!r}: {separation_message(kind, low, high, unit)}"
        warnings.warn(message, SeparationWarning, stacklevel=caller_stacklevel())
    return kind, low, high


def _binomial_mle(x, z, n, start):
    """The BFGS maximum of the binomial likelihood of overlapping log data."""
    if start is None:
        w = n / n.sum()
        sd = np.sqrt(np.sum(w * (x - np.sum(w * x)) ** 2))
        start = np.array([np.sum(w * x), np.log(max(sd, 0.1))])
    res = optimize.minimize(
        _binomial_nll, start, args=(x, z, n), jac=True, method="BFGS", options={"gtol": 1e-9}
    )
    with np.errstate(over="ignore"):  # a median far above the data: inf, flagged by callers
        return float(np.exp(res.x[0])), float(np.exp(res.x[1]))


def fit_binomial(im, n_overturned, n_total, start=None) -> tuple[float, float]:
    """Maximum-likelihood lognormal fragility of outcome data, eq. (11) of Baker (2015).

    .. math:: \\max_{\\theta, \\beta} \\sum_j \\ln \\binom{n_j}{z_j}
              + z_j \\ln \\Phi(\\ln(x_j / \\theta) / \\beta)
              + (n_j - z_j) \\ln[1 - \\Phi(\\ln(x_j / \\theta) / \\beta)]

    The maximum exists only where the outcomes overlap in the intensity and rise with it
    (:func:`separation`): separated outcomes give NaN, NaN with a
    :class:`~rockstudy.SeparationWarning` that names the interval in which theta lies, and
    outcomes without a rise NaN, NaN with one that says so.

    Parameters
    ----------
    im : array_like
        Intensity levels x_j (> 0); single points (``n_total`` 1) make it the Bernoulli fit of
        a cloud or of Monte Carlo samples.
    n_overturned, n_total : array_like
        z_j overturned out of n_j.
    start : array_like, optional
        (ln theta, ln beta) to start from.

    Returns
    -------
    (theta, beta)
        Median capacity in the units of ``im``, and dispersion (the MLE). ``inf``/NaN or
        0/NaN when the outcome never or always happened (no fit); NaN/NaN when the outcomes
        are separated or do not rise (no maximum).
    """
    x, z, n = _outcomes(im, n_overturned, n_total)
    kind, s, o = _separation(x, z, n)
    if kind == "one outcome":  # never (median not reached) or always (below the data)
        return (np.inf, np.nan) if z.sum() == 0 else (0.0, np.nan)
    if kind in NO_MAXIMUM:
        message = separation_message(kind, np.exp(s), np.exp(o))
        warnings.warn(f"fit_binomial: {message}", SeparationWarning, stacklevel=caller_stacklevel())
        return np.nan, np.nan
    return _binomial_mle(x, z, n, start)


def fit_binomial_limit(im, n_overturned, n_total, start=None) -> tuple[float, float]:
    """:func:`fit_binomial` for the resamples of a bootstrap: the MLE where it exists, and
    where the resample is separated, the limit its likelihood rises towards, without a
    warning: beta = 0 (a step) and theta the geometric middle of the gap [s, o] of
    :func:`separation` (for quasi-separation, s itself, the limit of theta). The resamples of
    a small sample are often separated; leaving them out would bias the band of beta upwards,
    keeping whatever an optimiser stopped at would make it arbitrary. A resample without a
    rise (``"no rise"``) enters at its own limit: beta = inf, a flat curve, theta 0 or inf
    as its overall proportion is above or below one half (NaN at one half)."""
    x, z, n = _outcomes(im, n_overturned, n_total)
    kind, s, o = _separation(x, z, n)
    if kind == "one outcome":  # never (median not reached) or always (below the data)
        return (np.inf, np.nan) if z.sum() == 0 else (0.0, np.nan)
    if kind in SEPARATED:
        return float(np.exp(0.5 * (s + o))), 0.0
    if kind == "no rise":  # flat at the overall proportion p: theta -> 0 (p > 1/2) or inf
        p = z.sum() / n.sum()
        return (0.0 if p > 0.5 else np.inf if p < 0.5 else np.nan), np.inf
    return _binomial_mle(x, z, n, start)


def _censored_nll(q, c, cens):
    """Negative log-likelihood per point of q = (ln theta, ln beta) for log capacities ``c``
    and log censoring levels ``cens``, with its exact gradient."""
    b = np.exp(q[1])
    u, v = (c - q[0]) / b, (cens - q[0]) / b
    ls = special.log_ndtr(-v)
    h = np.exp(-0.5 * v * v - _LOG_SQRT_2PI - ls)  # hazard of the censored terms
    m = u.size + v.size  # mean over the points: a gradient tolerance independent of n
    f = -(np.sum(-0.5 * u * u - q[1]) + np.sum(ls)) / m
    grad = -np.array([(np.sum(u) + np.sum(h)) / b, np.sum(u * u - 1.0) + np.sum(h * v)]) / m
    return f, grad


def fit_capacities(capacities, censored_at=None, start=None) -> tuple[float, float]:
    """Maximum-likelihood lognormal fit of IDA capacities.

    Without censoring it is closed form: ln theta = mean(ln c), beta = std(ln c), the MLE
    (dividing by n). Capacities censored at ``censored_at`` (the block stood up to that level)
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
    start = [mu, np.log(max(beta, 0.05))] if start is None else start
    res = optimize.minimize(
        _censored_nll, start, args=(c, cens), jac=True, method="BFGS", options={"gtol": 1e-9}
    )
    with np.errstate(over="ignore"):
        return float(np.exp(res.x[0])), float(np.exp(res.x[1]))


# ------------------------------------------------------------------------------ lack of fit


def binned_outcomes(im, outcome, n_bins=8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The data a fitted curve is drawn against: the samples in ``n_bins`` groups of equal
    count along the intensity; returns each group's geometric-mean intensity, share of
    outcome and count."""
    im, outcome = np.asarray(im, float), np.asarray(outcome, float)
    groups = np.array_split(np.argsort(im, kind="stable"), max(1, min(n_bins, im.size)))
    at = np.array([np.exp(np.mean(np.log(im[g]))) for g in groups])
    share = np.array([np.mean(outcome[g]) for g in groups])
    return at, share, np.array([g.size for g in groups])


#: Fewest outcomes (and non-outcomes) a cell of the lack-of-fit test expects. Cells that
#: expect a fraction of an outcome make the chi-square law of the statistic fail (one such
#: event alone rejects); with cells of at least one, the test rejects 4.8 % of lognormal data
#: at the 5 % level over 600 samples and 5.8 % over 150 (400 draws each; with 5, the
#: textbook's count, 150 samples mostly left fewer than 3 cells).
MIN_EXPECTED = 1.0


def _cells(outcome, prob, n_groups):
    """(observed, expected, count) of the cells of :func:`lack_of_fit`: ``n_groups`` groups of
    equal count along the fitted probability, adjacent ones merged until each cell expects
    at least :data:`MIN_EXPECTED` outcomes and as many non-outcomes (a short last cell joins
    the one before)."""
    cells, acc = [], np.zeros(3)
    for g in np.array_split(np.argsort(prob, kind="stable"), n_groups):
        acc += (outcome[g].sum(), prob[g].sum(), g.size)
        if acc[1] >= MIN_EXPECTED and acc[2] - acc[1] >= MIN_EXPECTED:
            cells.append(acc)
            acc = np.zeros(3)
    if acc[2]:
        if cells:
            cells[-1] = cells[-1] + acc
        else:
            cells.append(acc)
    return np.array(cells)


#: p-value of a lack-of-fit test (:func:`lack_of_fit`, and the Shapiro-Wilk test of IDA
#: capacities) below which the reports say a lognormal fragility misses its data.
LACK_OF_FIT_LEVEL = 0.01


def lack_of_fit(im, outcome, theta, beta, n_groups=20) -> tuple[float, int, float]:
    """Hosmer-Lemeshow test of a lognormal fragility fitted to Bernoulli outcomes.

    The samples fall in ``n_groups`` groups of equal count along the fitted probability P(x),
    adjacent groups merged into cells that each expect at least :data:`MIN_EXPECTED`
    outcomes and non-outcomes; H = sum (O - E)^2 / (E (1 - E / n)) over the cells (O the
    outcomes, E = sum P(x_i), n the samples of a cell), against the chi-square law with
    cells - 2 degrees of freedom (Hosmer & Lemeshow 2000, sec. 5.2.2). A small p says the
    lognormal shape does not describe the data, e.g. a probability that levels off below 1.

    Returns
    -------
    (H, degrees of freedom, p)
        NaN (and 0 degrees of freedom) without a fit, or where fewer than 3 cells can be made.
    """
    im, outcome = np.asarray(im, float), np.asarray(outcome, float)
    if not (np.isfinite(theta) and np.isfinite(beta) and beta > 0 and im.size >= n_groups):
        return np.nan, 0, np.nan
    prob = special.ndtr(np.log(im / theta) / beta)
    o, e, n = _cells(outcome, prob, n_groups).T
    if o.size < 3:
        return np.nan, 0, np.nan
    h = float(np.sum((o - e) ** 2 / (e * (1.0 - e / n))))
    return h, o.size - 2, float(stats.chi2.sf(h, o.size - 2))


# ------------------------------------------------------------------------------ covariances


def _inverse(info):
    """Inverse of a 2x2 information matrix; NaN when it is not positive definite."""
    if not np.all(np.isfinite(info)) or np.linalg.det(info) <= 0 or info[0, 0] <= 0:
        return np.full((2, 2), np.nan)
    return np.linalg.inv(info)


def binomial_covariance(im, n_total, theta, beta, n_overturned=None, cluster=None):
    """Covariance of (ln theta, ln beta) of :func:`fit_binomial` at the fit (NaN without one).

    The inverse of the expected information, I = sum_j n_j phi(u_j)^2 / (P_j (1 - P_j))
    g_j g_j', g_j = (-1 / beta, -u_j). Points that share a ``cluster`` label (the same record
    at several levels or for several blocks: their outcomes are not independent) give the
    cluster-robust sandwich I^-1 (sum_c s_c s_c') I^-1 c / (c - 1) instead, s_c the score
    summed over cluster c (``n_overturned`` needed then).
    """
    if not (np.isfinite(beta) and 0.0 < theta < np.inf):
        return np.full((2, 2), np.nan)
    n = np.asarray(n_total, float)
    u = np.log(np.asarray(im, float) / theta) / beta
    lp, lq, ld = special.log_ndtr(u), special.log_ndtr(-u), -0.5 * u * u - _LOG_SQRT_2PI
    g = np.stack([np.full(u.shape, -1.0 / beta), -u])
    cov = _inverse((g * n * np.exp(2.0 * ld - lp - lq)) @ g.T)
    if cluster is None:
        return cov
    _, inv = np.unique(np.asarray(cluster), return_inverse=True)
    inv = inv.ravel()
    m = int(inv.max()) + 1
    if m == inv.size:  # one point per cluster: independent points
        return cov
    z = np.asarray(n_overturned, float)
    r = z * np.exp(ld - lp) - (n - z) * np.exp(ld - lq)  # d loglik / du per point
    score = np.stack([np.bincount(inv, r * g[0], m), np.bincount(inv, r * g[1], m)])
    return cov @ (score @ score.T) @ cov * m / (m - 1)


def capacities_covariance(capacities, censored_at, theta, beta) -> np.ndarray:
    """Covariance of (ln theta, ln beta) of :func:`fit_capacities`: diag(beta^2 / n, 1 / 2n)
    without censoring; with it, the inverse of the observed information (central differences
    of the exact gradient of the censored likelihood). NaN without a fit."""
    c = np.log(np.asarray(capacities, float))
    cens = np.log(np.asarray([] if censored_at is None else censored_at, float))
    if not (np.isfinite(beta) and 0.0 < theta < np.inf and beta > 0):
        return np.full((2, 2), np.nan)
    if not cens.size:
        return np.diag([beta**2 / c.size, 0.5 / c.size])
    q, h, m = np.log([theta, beta]), 1e-5, c.size + cens.size
    cols = [
        (_censored_nll(q + h * e, c, cens)[1] - _censored_nll(q - h * e, c, cens)[1]) / (2 * h)
        for e in np.eye(2)
    ]
    info = m * np.column_stack(cols)
    return _inverse(0.5 * (info + info.T))


# ------------------------------------------------------------------------------ bands


def probability_band(x, theta, beta, n, cov, method, conf_level):
    """Pointwise band (lower, upper) of P(x) = Phi(ln(x / theta) / beta) at intensities ``x``.

    ``method`` is one of :data:`BAND_METHODS` (module docstring); ``cov`` the covariance of
    (ln theta, ln beta) (for ``"likelihood"`` and ``"record_bootstrap"``); ``n`` the number
    of capacities (for ``"noncentral_t"``). NaN where there is no fit or no band.
    """
    x = np.asarray(x, float)
    nan = np.full(x.shape, np.nan)
    if method not in BAND_METHODS:
        raise ValueError(f"method must be one of {BAND_METHODS}, got {method!r}")
    if method == "none" or not (np.isfinite(beta) and beta > 0 and 0.0 < theta < np.inf):
        return nan, nan
    with np.errstate(divide="ignore"):
        u = np.log(x / theta) / beta
    if method == "noncentral_t":
        n = int(n)
        if n < 2:
            return nan, nan
        t = np.sqrt(n) * u * np.sqrt((n - 1) / n)  # sqrt(n) (ln x - mean) / s, s with n - 1
        lo = special.nctdtrinc(n - 1, 0.5 + conf_level / 2, t)
        hi = special.nctdtrinc(n - 1, 0.5 - conf_level / 2, t)
        return special.ndtr(lo / np.sqrt(n)), special.ndtr(hi / np.sqrt(n))
    cov = np.asarray(cov, float)
    if not np.all(np.isfinite(cov)):
        return nan, nan
    var = cov[0, 0] / beta**2 + 2.0 * u * cov[0, 1] / beta + u * u * cov[1, 1]
    half = special.ndtri(0.5 + conf_level / 2) * np.sqrt(np.maximum(var, 0.0))
    return special.ndtr(u - half), special.ndtr(u + half)


# ------------------------------------------------------------------------------ tables


def fragility_row(
    label,
    theta,
    beta,
    band,
    n,
    im,
    by=None,
    cov=None,
    method="none",
    conf_level=np.nan,
    separated=False,
) -> dict:
    """One row of a fragility table: the fit (``beta`` the MLE), the bands of theta and beta,
    the sample count, the observed intensity range of ``im`` and whether the median
    (``theta_in_range``) and its whole band (``band_in_range``) lie inside it, and whether
    the outcomes are separated (``separated``, :func:`separation`: then theta and beta are
    NaN and the "band" of theta is the gap [s, o] in which the median lies) and whether they
    do not rise with the intensity at all (``no_rise``: theta, beta and band NaN; see
    :func:`no_maximum_row`); then what the
    pointwise band of P(x) needs (:func:`probability_band`): the covariance of
    (ln theta, ln beta) (``var_ln_theta``, ``cov_ln_theta_ln_beta``, ``var_ln_beta``), the
    method (``p_band``) and ``conf_level``. ``band`` is ((theta_lo, theta_hi),
    (beta_lo, beta_hi))."""
    (theta_lo, theta_hi), (beta_lo, beta_hi) = band
    im_min, im_max = (float(np.min(im)), float(np.max(im))) if np.size(im) else (np.nan, np.nan)
    cov = np.full((2, 2), np.nan) if cov is None else np.asarray(cov, float)
    return {
        by or "group": label,
        "theta": theta,
        "beta": beta,
        "theta_lo": theta_lo,
        "theta_hi": theta_hi,
        "beta_lo": beta_lo,
        "beta_hi": beta_hi,
        "n": int(n),
        "im_min": im_min,
        "im_max": im_max,
        "theta_in_range": bool(im_min <= theta <= im_max),
        "band_in_range": bool(im_min <= theta_lo and theta_hi <= im_max),
        "separated": bool(separated),
        "no_rise": False,
        "var_ln_theta": cov[0, 0],
        "cov_ln_theta_ln_beta": cov[0, 1],
        "var_ln_beta": cov[1, 1],
        "p_band": method,
        "conf_level": conf_level,
    }


#: columns of a fragility row that only serve the pointwise band of P(x).
BAND_COLUMNS = ("var_ln_theta", "cov_ln_theta_ln_beta", "var_ln_beta", "p_band", "conf_level")


def no_maximum_row(label, kind, low, high, n, im, by=None, conf_level=np.nan) -> dict:
    """The :func:`fragility_row` of outcomes without a maximum of the likelihood (``kind`` of
    :data:`NO_MAXIMUM`): no fit (theta, beta NaN), no band of P; separated outcomes have
    theta bounded by the gap [``low``, ``high``] (``separated``), outcomes without a rise
    not at all (``no_rise``)."""
    if kind not in NO_MAXIMUM:
        raise ValueError(f"kind must be one of {NO_MAXIMUM}, got {kind!r}")
    separated = kind in SEPARATED
    band = ((low, high) if separated else (np.nan, np.nan), (np.nan, np.nan))
    row = fragility_row(
        label, np.nan, np.nan, band, n, im, by, None, "none", conf_level, separated=separated
    )
    return {**row, "no_rise": kind == "no rise"}


def wald_intervals(theta, beta, cov, conf_level):
    """Wald intervals ((theta_lo, theta_hi), (beta_lo, beta_hi)) on the log scale from the
    covariance of (ln theta, ln beta); NaN without a covariance."""
    z = special.ndtri(0.5 + conf_level / 2)
    cov = np.asarray(cov, float)
    with np.errstate(invalid="ignore", over="ignore"):  # no information: an infinite band
        dt, db = z * np.sqrt(cov[0, 0]), z * np.sqrt(cov[1, 1])
        return (theta * np.exp(-dt), theta * np.exp(dt)), (beta * np.exp(-db), beta * np.exp(db))


def percentile_intervals(boot, conf_level):
    """((theta_lo, theta_hi), (beta_lo, beta_hi)) from bootstrap fits ``boot`` (rows of
    (theta, beta)): percentiles at bootstrap samples, without interpolation, so that an
    infinite median (not reached in a resample) stays infinite."""
    q = [50 * (1 - conf_level), 50 * (1 + conf_level)]
    with np.errstate(invalid="ignore"):
        (t_lo, b_lo), (t_hi, b_hi) = np.percentile(boot, q, axis=0, method="inverted_cdf")
    return (t_lo, t_hi), (b_lo, b_hi)
