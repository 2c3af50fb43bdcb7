"""The fragility of sliding, P(max_slide > d | IM), and its annual rate per slide limit
(rockstudy.study.analysis.sliding), against independent oracles: the binomial likelihood
maximised here by scipy, the closed-form lognormal MLE of complete capacities, and Cornell et
al.'s closed form k0 theta^-k exp(k^2 beta^2 / 2) on a power-law hazard."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy import optimize, stats

from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.study.analysis import sliding

NAMES = ["Amphora", "Bronze"]
LEVELS_G = np.array([0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0])  # PGA [g]
D0 = 0.02  # [m]


def _capacities(n_rec, theta, beta, seed):
    """Lognormal capacities [g] of n_rec records (rows) x len(theta) objects."""
    z = np.random.default_rng(seed).standard_normal((n_rec, len(theta)))
    return np.asarray(theta) * np.exp(np.asarray(beta) * z)


def _stripes(n_rec=25, seed=3):
    """A stripes design of two objects at PGA levels: a record whose 'slide capacity' is C
    slides max_slide = D0 x / C at level x, and overturns (max_slide NaN) where x > 3 C."""
    c = _capacities(n_rec, [0.35, 0.5], [0.4, 0.6], seed)
    x = np.broadcast_to(LEVELS_G, (n_rec, 2, LEVELS_G.size))
    slide = D0 * x / c[:, :, None]
    over = x > 3.0 * c[:, :, None]
    dims = ("record", "structure", "level")
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),  # scale = PGA in g
            "scale": (dims, x.copy()),
            "max_slide": (dims, np.where(over, np.nan, slide)),
            "overturned": (dims, over),
            "status": (dims, np.zeros(x.shape, int)),
        },
        coords={
            "record": np.arange(n_rec),
            "structure": np.array(NAMES, dtype=object),
            "level": LEVELS_G,
        },
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan, "slide_limits": [D0]},
    )
    return ds, c, x, over


def _binomial_mle(x, y):
    """The lognormal fit maximising sum y ln Phi + (1 - y) ln(1 - Phi), by Nelder-Mead."""

    def nll(p):
        z = (np.log(x) - p[0]) / np.exp(p[1])
        return -np.sum(y * stats.norm.logcdf(z) + (1 - y) * stats.norm.logsf(z))

    start = [np.log(np.median(x)), np.log(0.5)]
    best = optimize.minimize(nll, start, method="Nelder-Mead", options={"xatol": 1e-10})
    best = optimize.minimize(nll, best.x, method="Nelder-Mead", options={"xatol": 1e-12})
    return np.exp(best.x[0]), np.exp(best.x[1])


@pytest.mark.parametrize("factor", [1.0, 4.0])
def test_stripes_slide_fragility_is_the_binomial_mle_of_exceedance(factor):
    """P(max_slide > d): the binomial MLE of 'slid more than d or overturned' at each point.
    At d = 4 D0 the slide alone exceeds d above 4 C, but the block overturns above 3 C: the
    overturned points (max_slide NaN) count as exceeding, so the fit is that of x > 3 C."""
    ds, c, x, over = _stripes()
    d = factor * D0
    table = sliding.slide_fragility(ds, limits=[d], n_boot=0)
    for j, name in enumerate(NAMES):
        y = (x[:, j] > factor * c[:, j, None]) | over[:, j]
        theta, beta = _binomial_mle(x[:, j].ravel(), y.ravel().astype(float))
        row = table.loc[(d, name)]
        assert row["theta"] == pytest.approx(theta, rel=1e-5)
        assert row["beta"] == pytest.approx(beta, rel=1e-5)
        assert row["n"] == x[:, j].size


def test_the_design_limits_are_the_default_and_bad_limits_are_refused():
    ds, *_ = _stripes()
    table = sliding.slide_fragility(ds, n_boot=0)
    assert list(table.index.get_level_values("slide_limit").unique()) == [D0]
    for bad in ([], [0.0], [-0.1], [np.nan]):
        with pytest.raises(ValueError, match="limits"):
            sliding.slide_fragility(ds, limits=bad, n_boot=0)
    with pytest.raises(ValueError, match="max_slide"):
        sliding.slide_fragility(ds.drop_vars("max_slide"), n_boot=0)


def _ida(n_rec=30, seed=5):
    """An IDA of two objects at PGA = scale g: slide capacities C at D0 and 2 C at 2 D0, and
    an overturning capacity 1.5 C that caps the second limit; one record of object 0 never
    slides past 2 D0 (NaN) but overturns."""
    c = _capacities(n_rec, [0.3, 0.45], [0.35, 0.5], seed)
    slide = np.stack([c, 2.0 * c]) * STANDARD_GRAVITY  # units of capacity: m/s^2
    slide[1, 0, 0] = np.nan
    rs = ("record", "structure")
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),
            "capacity_scale": (rs, 1.5 * c),
            "capacity_scale_lower": (rs, 1.5 * c * 0.99),
            "censored": (rs, np.zeros(c.shape, bool)),
            "status": (rs, np.zeros(c.shape, int)),
            "slide_capacity": (("slide_limit",) + rs, slide),
            # a horizontal suite and low uplift PGAs: object_risk of overturning would cut the
            # fragility below them; sliding does not need uplift
            "vertical_component": ("record", np.zeros(n_rec, bool)),
            "uplift_acceleration": ("structure", np.array([0.25, 0.4]) * STANDARD_GRAVITY),
        },
        coords={
            "record": np.arange(n_rec),
            "structure": np.array(NAMES, dtype=object),
            "slide_limit": [D0, 2 * D0],
        },
        attrs={"design": "ida", "im": "pga", "im_period": np.nan, "slide_limits": [D0, 2 * D0]},
    )
    expected = {D0: c, 2 * D0: np.minimum(2.0 * np.nan_to_num(c, nan=np.inf), 1.5 * c)}
    expected[2 * D0][0, 0] = 1.5 * c[0, 0]  # never slid past 2 D0: its overturning
    return ds, expected


def _lognormal_mle(c):
    """(theta, beta) of complete capacities: exp(mean ln c), std(ln c) dividing by n."""
    return float(np.exp(np.mean(np.log(c)))), float(np.std(np.log(c)))


def test_ida_slide_fragility_fits_the_slide_capacities_capped_by_overturning():
    ds, expected = _ida()
    table = sliding.slide_fragility(ds, n_boot=0)
    for d, caps in expected.items():
        for j, name in enumerate(NAMES):
            theta, beta = _lognormal_mle(caps[:, j])
            assert table.loc[(d, name), "theta"] == pytest.approx(theta, rel=1e-9)
            assert table.loc[(d, name), "beta"] == pytest.approx(beta, rel=1e-9)


def test_an_ida_limit_not_stored_is_refused_by_name():
    ds, _ = _ida()
    with pytest.raises(ValueError, match="slide limits"):
        sliding.slide_fragility(ds, limits=[0.5], n_boot=0)


def test_annual_rate_per_slide_limit_is_cornells_closed_form():
    """lambda(max_slide > d) = k0 theta^-k exp(k^2 beta^2 / 2) for a power-law hazard
    k0 x^-k and the lognormal fragility of the slide capacities, the whole lognormal (no
    cut at the uplift PGA, which lies below theta here and would lower the rate)."""
    ds, expected = _ida()
    k0, k = 1e-4, 2.5
    hazard = risk.HazardCurve.power_law(k0, k, im="pga", units="g")
    out = sliding.slide_risk(ds, hazard, n_boot=0, min_overturning=1)
    assert list(out["structure"].values) == NAMES
    for d, caps in expected.items():
        for j, name in enumerate(NAMES):
            theta, beta = _lognormal_mle(caps[:, j])
            closed = k0 * theta**-k * np.exp(k**2 * beta**2 / 2)
            got = out.sel(slide_limit=d, structure=name)
            assert float(got["annual_rate"]) == pytest.approx(closed, rel=1e-9)
            assert str(got["status"].values) == "ok"
            assert int(got["n_exceeding"]) == caps.shape[0]
            assert not bool(got["truncated_at_uplift"])


def _binomial_rate(x, y, k0, k):
    theta, beta = _binomial_mle(x.ravel(), y.ravel().astype(float))
    return k0 * theta**-k * np.exp(k**2 * beta**2 / 2)


def test_contact_effect_is_the_ratio_of_the_two_models_annual_rates_of_overturning():
    """Under "auto" the design keeps Housner's decision (overturned_rocking): the ratio of the
    annual rates of overturning, contact over rocking-only, each Cornell's closed form of its
    own binomial MLE (a design that does not say its records are horizontal: no cut)."""
    ds, c, x, _ = _stripes(n_rec=30, seed=11)
    contact = x > 1.2 * c[:, :, None]
    rocking = x > 0.8 * c[:, :, None] * np.exp(0.3 * np.sin(np.arange(x.size))).reshape(x.shape)
    ds["overturned"] = (ds["scale"].dims, contact)
    ds["overturned_rocking"] = (ds["scale"].dims, rocking)
    k0, k = 2e-4, 2.0
    hazard = risk.HazardCurve.power_law(k0, k, im="pga", units="g")
    out = sliding.contact_effect(ds, hazard, n_boot=0, min_overturning=1)
    for j, name in enumerate(NAMES):
        want_c = _binomial_rate(x[:, j], contact[:, j], k0, k)
        want_r = _binomial_rate(x[:, j], rocking[:, j], k0, k)
        got = out.sel(structure=name)
        assert float(got["annual_rate_contact"]) == pytest.approx(want_c, rel=1e-4)
        assert float(got["annual_rate_rocking"]) == pytest.approx(want_r, rel=1e-4)
        assert float(got["ratio"]) == pytest.approx(want_c / want_r, rel=2e-4)
        assert int(got["n_overturned_rocking"]) == int(rocking[:, j].sum())


def test_the_rocking_only_rate_needs_auto():
    ds, *_ = _stripes()
    hazard = risk.HazardCurve.power_law(1e-4, 2.0, im="pga", units="g")
    with pytest.raises(ValueError, match="auto"):
        sliding.contact_effect(ds, hazard, n_boot=0)


def test_regimes_name_each_records_regime_per_object_and_level():
    ds, *_ = _stripes(n_rec=3)
    code = np.arange(ds["max_slide"].size).reshape(ds["max_slide"].shape) % 5
    ds["regime"] = (ds["scale"].dims, code.astype(np.int8))
    ds["status"][1, 0, 2] = 1  # a point that hit the step limit
    table = sliding.regimes(ds)
    assert table.loc[("Bronze", 2), LEVELS_G[3]] == sliding.REGIME_NAMES[int(code[2, 1, 3])]
    assert table.loc[("Amphora", 1), LEVELS_G[2]] == "not run"
    assert table.shape == (2 * 3, LEVELS_G.size)


def test_rates_of_nested_limits_that_cross_are_flagged():
    """Every record's capacity at 2 D0 is above its capacity at D0 (the exceedances nest), but
    a far wider spread at 2 D0 makes its lognormal's rate the higher (Cornell's closed form,
    k0 theta^-k exp(k^2 beta^2 / 2)): the smaller limit is flagged ``crossed``."""
    ds, _ = _ida()
    c = ds["slide_capacity"].isel(slide_limit=0).values / STANDARD_GRAVITY
    z = np.random.default_rng(2).standard_normal(c.shape)
    wide = c * np.exp(3.0 * np.abs(z))
    ds["slide_capacity"][1] = wide * STANDARD_GRAVITY
    ds["capacity_scale"][:] = 100.0  # overturning far above both
    k0, k = 1e-4, 2.5
    out = sliding.slide_risk(ds, risk.HazardCurve.power_law(k0, k, "pga", "g"), n_boot=0)
    for j, name in enumerate(NAMES):
        rate = [
            k0 * t**-k * np.exp(k**2 * b**2 / 2)
            for t, b in map(_lognormal_mle, (c[:, j], wide[:, j]))
        ]
        assert rate[1] > rate[0]  # the case this test builds
        flags = out["crossed"].sel(structure=name).values
        assert flags.tolist() == [True, False]
