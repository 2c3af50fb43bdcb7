"""The mean annual rate of overturning of a lognormal fragility at a site (Cornell et al.
2002), which intensity levels it comes from, and the probability of an overturning in a number
of years."""

from __future__ import annotations

import numpy as np
from scipy.special import log_ndtr, ndtr

from .. import _validate
from .curves import LOG_HUGE, HazardCurve, _slopes
from .units import to_si, units_for

__all__ = ["annual_rate", "MAX_DISPERSION", "MAX_YEARS", "probability_in", "rate_deaggregation"]

#: The largest dispersion beta of a fragility: ln C of a capacity C spread by more than 10
#: (its 16-84 % range a factor e^20, about 5e8) says nothing of an object, and beyond it
#: Cornell's exp(k^2 beta^2 / 2) leaves floating point for any hazard slope k above 3.8.
MAX_DISPERSION = 10.0
#: The longest exposure time [yr], that of a study's ``[hazard] years``.
MAX_YEARS = 1e6


def _fragility(median, dispersion, hazard, units):
    """(ln theta, beta) broadcast together, with theta in the hazard's units."""
    if not isinstance(hazard, HazardCurve):
        raise TypeError(f"hazard must be a HazardCurve, got {type(hazard).__name__}")
    units = units_for(hazard.im, hazard.units if units is None else units)
    med = _array("median", median, lambda a: a > 0.0, f"finite and > 0 (in {units})")
    beta = _array(
        "dispersion",
        dispersion,
        lambda a: (a >= 0.0) & (a <= MAX_DISPERSION),
        f"finite and in [0, {MAX_DISPERSION:g}]",
    )
    factor = to_si(hazard.im, units) / to_si(hazard.im, hazard.units)
    return _broadcast(median=np.log(med) + np.log(factor), dispersion=beta)


def _array(name, value, allowed, label):
    """``value`` as a float array, or a ValueError naming ``name`` and its first value that is
    not finite or not ``allowed`` (a function of the array; ``label`` says what is), or a
    :class:`rockstudy._validate.NotANumberError` for strings and booleans."""
    arr = _validate.numbers_array(name, value)
    with np.errstate(invalid="ignore"):
        bad = np.flatnonzero(~(np.isfinite(arr) & allowed(arr)))
    if bad.size:
        raise ValueError(f"{name} must be {label}, got {float(arr.flat[bad[0]])!r}")
    return arr


def _broadcast(**arrays):
    """The ``arrays`` broadcast together, or a ValueError naming them and their shapes."""
    try:
        return np.broadcast_arrays(*arrays.values())
    except ValueError:
        shapes = [f"{k} (shape {np.shape(v)})" for k, v in arrays.items()]
        raise ValueError(
            f"{', '.join(shapes[:-1])} and {shapes[-1]} do not broadcast together: give "
            "arrays of one shape, or of shapes numpy broadcasts (a scalar, or a length-1 axis)"
        ) from None


def _finite(rates, mu, beta):
    """``rates``, or a ValueError where one is beyond floating point (naming the first
    fragility, theta = exp(mu) in the hazard's units, and beta, that gives it)."""
    bad = ~np.isfinite(rates)
    if not bad.any():
        return rates
    where = np.unravel_index(int(np.flatnonzero(bad)[0]), bad.shape)[: np.ndim(mu)]
    theta, b = float(np.exp(np.asarray(mu)[where])), float(np.asarray(beta)[where])
    raise ValueError(
        f"annual_rate: lambda_OT of the fragility of median {theta:.4g} and dispersion "
        f"{b:g} is beyond floating point (above {np.exp(LOG_HUGE):.3g} /yr): its capacity "
        "reaches far below the hazard curve's first level, where the curve is extrapolated as "
        "a power law x^-k that grows without bound as x -> 0 (Cornell's k0 theta^-k "
        "exp(k^2 beta^2 / 2) for a power law); the integral has no finite value to give"
    )


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
    with np.errstate(over="ignore"):  # (an overflow is refused by the caller, :func:`_finite`)
        out = np.where(beta > 0.0, np.exp(log_e), np.where(inside, np.exp(sharp), 0.0))
    return np.where(below, 0.0, out)


def _threshold(threshold, units, hazard):
    """ln x_u of ``threshold`` (in ``units``) in the hazard's units; None for no
    threshold."""
    if threshold is None:
        return None
    units = units_for(hazard.im, hazard.units if units is None else units)
    x_u = _array("threshold", threshold, lambda a: a > 0.0, f"finite and > 0 (in {units})")
    factor = to_si(hazard.im, units) / to_si(hazard.im, hazard.units)
    return np.log(x_u) + np.log(factor)


def _arguments(median, dispersion, hazard, units, threshold):
    """(ln theta, beta, ln x_u or None) checked and broadcast together, in the hazard's
    units."""
    mu, beta = _fragility(median, dispersion, hazard, units)
    cut = _threshold(threshold, units, hazard)
    if cut is None:
        return mu, beta, None
    return tuple(_broadcast(median=mu, dispersion=beta, threshold=cut))


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
        Its logarithmic standard deviation beta, in [0, :data:`MAX_DISPERSION`] = [0, 10]
        (0: a sharp capacity, lambda(theta)).
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

    Raises
    ------
    ValueError
        For an argument out of its range, arguments that do not broadcast together, or a
        lambda_OT beyond floating point (a capacity far below the hazard's levels, where its
        power-law extrapolation grows without bound).
    """
    mu, beta, cut = _arguments(median, dispersion, hazard, units, threshold)
    if cut is None:
        parts = _capacity_expectations(mu, beta, hazard)
    else:
        parts = _contributions(mu, beta, hazard, cut)
    with np.errstate(over="ignore", invalid="ignore"):
        out = _finite(parts.sum(axis=-1), mu, beta)
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
    mu, beta, cut = _arguments(median, dispersion, hazard, units, threshold)
    lower = np.concatenate([[0.0], hazard.levels])
    upper = np.concatenate([hazard.levels, [np.inf]])
    return lower, upper, _contributions(mu, beta, hazard, cut)


def _contributions(mu, beta, hazard, cut):
    """The contributions of :func:`rate_deaggregation` of checked arguments (ln theta, beta,
    ln x_u or None, broadcast together); a ValueError where one is beyond floating point."""
    parts = _capacity_expectations(mu, beta, hazard, cut)
    lev = np.log(hazard.levels)
    cdf = _fragility_at(lev, mu[..., None], beta[..., None])
    if cut is not None:
        cdf = np.where(lev >= cut[..., None], cdf, 0.0)
    edge = hazard.rates * cdf  # lambda(x_i) F(x_i) at each level
    zero = np.zeros(edge.shape[:-1] + (1,))
    with np.errstate(invalid="ignore"):  # (inf - inf: refused below)
        parts = parts + np.concatenate([zero, edge], -1) - np.concatenate([edge, zero], -1)
    if cut is not None:  # lambda(x_u) F(x_u) opens the interval x_u lies inside (at a
        # level, the edge term there opens the next), and those below x_u give nothing
        holds = np.searchsorted(lev, cut, side="right")[..., None]
        on_level = np.take(np.append(-np.inf, lev), holds) == cut[..., None]
        with np.errstate(over="ignore", invalid="ignore"):  # (refused below: :func:`_finite`)
            start = (np.exp(hazard.log_rate(cut)) * _fragility_at(cut, mu, beta))[..., None]
        start = np.where(on_level, 0.0, start)
        np.put_along_axis(parts, holds, np.take_along_axis(parts, holds, -1) + start, -1)
        parts = np.where(np.append(lev, np.inf) <= cut[..., None], 0.0, parts)
    return _finite(parts, mu, beta)


def probability_in(years, rate):
    """The probability of at least one occurrence in ``years`` of a Poisson process of mean
    annual rate ``rate``.

    .. math:: P = 1 - e^{-\\lambda t}

    Parameters
    ----------
    years : float or array_like
        The exposure time t [yr], > 0 and at most :data:`MAX_YEARS` (1e6, as a study's).
    rate : float or array_like
        lambda [1/yr], >= 0 (e.g. :func:`annual_rate`).

    Returns
    -------
    float or ndarray
        P, broadcast over ``years`` and ``rate``.
    """
    t = _array(
        "years",
        years,
        lambda a: (a > 0.0) & (a <= MAX_YEARS),
        f"finite and > 0 (at most {MAX_YEARS:g})",
    )
    lam = _array("rate", rate, lambda a: a >= 0.0, "finite and >= 0 [1/yr]")
    t, lam = _broadcast(years=t, rate=lam)
    out = -np.expm1(-lam * t)
    return float(out) if out.ndim == 0 else out
