"""Outcomes separated in the intensity (or not rising with it) have no maximum-likelihood
fragility: they are flagged, warned about and shown as such, never fitted. Oracles: a
brute-force profile of the binomial likelihood in beta (theta optimised at each beta, written
here with scipy's normal log-cdf), which rises monotonically towards beta = 0 if and only if
the outcomes are separated, and towards beta = infinity if and only if they do not rise (the
profile of a concave likelihood is concave in 1 / beta); data built to be separated, whose gap
is known by construction; data drawn from a known lognormal fragility, which must still be
recovered."""

import html
import warnings

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from scipy import optimize, stats

from rockstudy import SeparationWarning, risk
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.study import analysis
from rockstudy.study.analysis import fragility_fit
from rockstudy.study.analysis import record_fragility as rf
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.report._page import _Page, separation_note
from rockstudy.study.report.records import _fragility

BETAS = np.geomspace(1e3, 1e-5, 90)  # the profile's grid, from flat to a step


def _loglik(ln_theta, beta, x, z, n):
    """The binomial log-likelihood of eq. (11) of Baker (2015), without the constant."""
    u = (np.log(x) - ln_theta) / beta
    return np.sum(z * stats.norm.logcdf(u) + (n - z) * stats.norm.logcdf(-u))


def _profile(x, z, n):
    """max over theta of the log-likelihood at each beta of BETAS (bounded Brent in ln theta,
    to a tolerance well below beta)."""
    lx = np.log(x)
    out = []
    for beta in BETAS:
        lo, hi = lx.min() - 2.0 - 3.0 * beta, lx.max() + 2.0 + 3.0 * beta
        res = optimize.minimize_scalar(
            lambda q, b=beta: -_loglik(q, b, x, z, n),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-6 * beta, "maxiter": 2000},
        )
        out.append(-res.fun)
    return np.array(out)


def _rises_towards_zero(profile):
    """Whether the profile never falls as beta decreases, up to the tolerance of its inner
    maximisation (1e-6 in log-likelihood; where a maximum exists, the profile falls towards
    beta = 0 by orders of magnitude more, to -inf)."""
    return bool(np.all(np.diff(profile) >= -1e-6))


def _rises_towards_infinity(profile):
    """Whether the profile never rises as beta decreases (its maximum at the flattest curve)."""
    return bool(np.all(np.diff(profile) <= 1e-6))


def _random_data(rng):
    """A small dataset with both outcomes: a Bernoulli cloud, or stripes (a few levels with
    several trials, so that ties at one level occur)."""
    while True:
        if rng.random() < 0.5:
            x = np.exp(rng.normal(0.0, 0.5, rng.integers(4, 9)))
            n = np.ones(x.size)
        else:
            x = np.geomspace(0.2, 1.6, rng.integers(3, 6))
            n = rng.integers(2, 5, x.size).astype(float)
        beta = rng.uniform(0.02, 0.8) * (1.0 if rng.random() < 0.8 else -1.0)  # some fall
        p = stats.norm.cdf(np.log(x / np.exp(rng.normal(-0.3, 0.3))) / beta)
        z = rng.binomial(n.astype(int), p).astype(float)
        if 0 < z.sum() < n.sum():
            return x, z, n


def test_the_separation_check_agrees_with_the_profile_likelihood_on_random_data():
    rng = np.random.default_rng(2015)
    kinds = []
    for _ in range(30):
        x, z, n = _random_data(rng)
        kind, low, high = fragility_fit.separation(x, z, n)
        kinds.append(kind)
        profile = _profile(x, z, n)
        assert (kind in fragility_fit.SEPARATED) == _rises_towards_zero(profile), (x, z, n)
        assert (kind == "no rise") == _rises_towards_infinity(profile), (x, z, n)
        if kind == "no rise":
            with pytest.warns(SeparationWarning, match="do not lie higher"):
                assert np.isnan(fragility_fit.fit_binomial(x, z, n)).all()
        elif kind in fragility_fit.SEPARATED:
            with pytest.warns(SeparationWarning, match="separated"):
                theta, beta = fragility_fit.fit_binomial(x, z, n)
            assert np.isnan(theta) and np.isnan(beta)
            assert low == np.max(x[z < n]) and high == np.min(x[z > 0])
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("error", SeparationWarning)
                theta, beta = fragility_fit.fit_binomial(x, z, n)
            # the fit is the maximum the oracle's profile sees, within its grid
            assert np.isfinite(beta) and beta > 0
            best = profile.max()
            assert _loglik(np.log(theta), beta, x, z, n) >= best - 1e-6
    # the sample exercised every case
    assert {"overlap", "quasi", "complete", "no rise"} <= set(kinds), kinds


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, np.inf])
def test_an_intensity_that_is_not_positive_and_finite_is_refused_by_name(bad):
    for fit in (fragility_fit.separation, fragility_fit.fit_binomial):
        with pytest.raises(ValueError, match="im: intensities must be finite and > 0"):
            fit([0.5, bad], [0.0, 1.0], [1.0, 1.0])


def test_quasi_separation_is_a_tie_at_one_level_and_its_limit_is_that_level():
    x = np.array([0.1, 0.2, 0.4, 0.8])
    z, n = np.array([0.0, 0.0, 2.0, 5.0]), np.full(4, 5.0)  # mixed at 0.4 only
    assert fragility_fit.separation(x, z, n) == ("quasi", 0.4, 0.4)
    assert fragility_fit.fit_binomial_limit(x, z, n) == (pytest.approx(0.4, rel=1e-12), 0.0)
    z[1] = 1.0  # mixed at two levels: overlap, a finite fit
    assert fragility_fit.separation(x, z, n)[0] == "overlap"
    assert _rises_towards_zero(_profile(x, z, n)) is False


def test_outcomes_that_do_not_rise_have_no_fit_and_no_rate():
    """Overturning at the lower levels only (a falling trend), or at one level only: the
    likelihood of an increasing fragility has its supremum at beta -> infinity."""
    assert fragility_fit.separation([1.0, 1.0], [1.0, 2.0], [3.0, 3.0])[0] == "no rise"
    falling = np.array([[1, 0, 1, 0], [1, 1, 0, 0], [0, 1, 0, 0]])  # 2/3, 2/3, 1/3, 0
    ds = _stripes(falling, LEVELS)
    with pytest.warns(SeparationWarning, match="do not lie higher"):
        t = rf.stripe_fragility(ds, n_boot=20)
    row = t.loc["all"]
    assert row["no_rise"] and not row["separated"]
    assert np.isnan([row["theta"], row["beta"], row["theta_lo"], row["theta_hi"]]).all()
    hazard = risk.HazardCurve.power_law(2e-4, 2.3, im="pga", units="g")
    out = object_risk(ds, hazard, n_boot=20)
    assert str(out["status"].values[0]) == "no rise"
    for name in ("theta", "beta", "annual_rate", "annual_rate_hi", "probability"):
        assert np.isnan(out[name].values[0]), name


def _stripes(overturned, levels):
    """A stripes dataset of one block: records of PGA 1 g scaled to ``levels`` [g]."""
    y = np.asarray(overturned, bool)[:, None, :]
    n_rec = y.shape[0]
    shape = (n_rec, 1, levels.size)
    return xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, G_UNIT)),
            "overturned": (("record", "structure", "level"), y),
            "status": (("record", "structure", "level"), np.zeros(shape, np.int64)),
            "scale": (("record", "structure", "level"), np.broadcast_to(levels, shape)),
        },
        coords={"level": levels * G_UNIT, "structure": ["Vase"]},
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan},
    )


LEVELS = np.array([0.1, 0.2, 0.4, 0.8])


@pytest.mark.parametrize(
    "kind, overturned, gap",
    [
        ("complete", np.tile([0, 0, 1, 1], (6, 1)), (0.2, 0.4)),  # 0 % then 100 %
        ("quasi", np.array([[0, 0, k < 3, 1] for k in range(6)]), (0.4, 0.4)),  # mixed once
    ],
)
def test_separated_stripes_are_flagged_warned_and_refused_a_rate(kind, overturned, gap):
    ds = _stripes(overturned, LEVELS)
    with pytest.warns(SeparationWarning, match="stripe_fragility: group 'all'"):
        t = rf.stripe_fragility(ds, n_boot=20)
    row = t.loc["all"]
    assert row["separated"] and not row["theta_in_range"]
    assert np.isnan(row["theta"]) and np.isnan(row["beta"])
    assert (row["theta_lo"], row["theta_hi"]) == pytest.approx(gap, rel=1e-12)
    curve = analysis.fragility_curve(t, np.geomspace(0.05, 1.0, 9))
    assert np.isnan(curve["probability"]).all()  # no step function drawn as a fit
    hazard = risk.HazardCurve.power_law(2e-4, 2.3, im="pga", units="g")
    out = object_risk(ds, hazard, n_boot=20)
    assert str(out["status"].values[0]) == "separated"
    for name in ("theta", "beta", "annual_rate", "annual_rate_lo", "probability"):
        assert np.isnan(out[name].values[0]), name


def test_the_monte_carlo_fragility_flags_a_separated_group_and_fits_the_other():
    rng = np.random.default_rng(3)
    x = np.exp(rng.normal(0.0, 0.6, 400))
    size = np.repeat([1.0, 2.0], 200)
    y = rng.random(400) < stats.norm.cdf(np.log(x / 1.1) / 0.35)
    y[size == 2.0] = x[size == 2.0] > 1.0  # the second group: a step, separated
    ds = xr.Dataset(
        {"im": ("sample", x), "size": ("sample", size), "overturned": ("sample", y)},
    )
    with pytest.warns(SeparationWarning, match="fragility: group '2.0'"):
        t = analysis.fragility(ds, "im", by="size", n_boot=50)
    assert t.loc[2.0, "separated"] and np.isnan(t.loc[2.0, "beta"])
    gap = (x[(size == 2.0) & (x <= 1.0)].max(), x[(size == 2.0) & (x > 1.0)].min())
    assert (t.loc[2.0, "theta_lo"], t.loc[2.0, "theta_hi"]) == pytest.approx(gap, rel=1e-12)
    assert not t.loc[1.0, "separated"]
    assert t.loc[1.0, "theta"] == pytest.approx(1.1, rel=0.1)
    assert t.loc[1.0, "beta"] == pytest.approx(0.35, rel=0.3)


def test_overlapping_stripes_from_a_known_lognormal_are_not_flagged_and_are_recovered():
    rng = np.random.default_rng(11)
    levels = np.geomspace(0.1, 1.0, 8)
    y = rng.random((400, 8)) < stats.norm.cdf(np.log(levels / 0.35) / 0.45)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SeparationWarning)
        t = rf.stripe_fragility(_stripes(y, levels), n_boot=0)
    row = t.loc["all"]
    assert not row["separated"]
    assert row["theta"] == pytest.approx(0.35, rel=0.05)
    assert row["beta"] == pytest.approx(0.45, rel=0.1)


def test_the_report_says_in_words_that_a_separated_fit_has_no_curve(tmp_path):
    ds = _stripes(np.tile([0, 0, 1, 1], (6, 1)), LEVELS)
    page = _Page(tmp_path)
    with warnings.catch_warnings():  # said on the page, not repeated on the console
        warnings.simplefilter("error", SeparationWarning)
        _fragility(page, ds, None, 20)
    source = "".join(page.parts)
    assert "class='warn'" in source
    assert "separated in the intensity" in source and "no curve is drawn" in source
    assert "outcomes separated (no fit)" in source  # the table's flag column
    assert page.figures == 0  # no step function drawn as if it were a fit


def test_the_separation_note_escapes_the_names_of_the_objects(tmp_path):
    evil = "<script>alert(1)</script> & co"
    table = pd.DataFrame(
        {"separated": [True, False], "no_rise": [False, False]}, index=[evil, "Vase"]
    )
    page = _Page(tmp_path)
    separation_note(page, table, "Fragility of the objects")
    source = "".join(page.parts)
    assert "<script>" not in source and html.escape(evil) in source
    assert "Vase" not in source  # only the separated objects are named
