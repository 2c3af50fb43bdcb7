"""Nested fits of slide limits and damage states (rockstudy.study.analysis.nested_fit): one
beta for all states of an object and ordered medians, against independent oracles: the
summed log-likelihood of all states written here and maximised by scipy (unconstrained, or
under the order constraint by SLSQP); the closed form of complete capacities (each median
the geometric mean of its state's capacities, beta^2 the pooled mean square); Cornell et
al.'s k0 theta^-k exp(k^2 beta^2 / 2); and curves evaluated here on a wide grid."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from scipy import optimize, stats

from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.study.analysis import nested_fit as nf
from rockstudy.study.analysis import sliding
from rockstudy.study.analysis import states as st

NAMES = ["Amphora", "Bronze"]
D0 = 0.02  # [m]
K0, K = 1e-4, 2.5
TOP = 1.2  # [g] the top of every ladder: capacities above it are censored there


def _summed_nll(p, data, kind):
    """-sum of every state's log-likelihood at p = (ln theta_1 .. ln theta_K, ln beta)."""
    b, total = np.exp(p[-1]), 0.0
    for mu, (a, z) in zip(p[:-1], data, strict=True):
        if kind == nf.CAPACITIES:
            total -= np.sum(stats.norm.logpdf(np.log(a), mu, b))
            total -= np.sum(stats.norm.logsf(np.log(z), mu, b))
        else:
            u = (np.log(a) - mu) / b
            total -= np.sum(z * stats.norm.logcdf(u) + (1 - z) * stats.norm.logsf(u))
    return total


def _oracle(data, kind, start, ordered=False):
    """The maximum of the summed likelihood by scipy: BFGS then Nelder-Mead, or SLSQP under
    ln theta_1 <= ln theta_2 <= ... (``ordered``)."""
    fun = lambda p: _summed_nll(p, data, kind)  # noqa: E731
    if ordered:
        cons = [
            {"type": "ineq", "fun": lambda p, k=k: p[k + 1] - p[k]} for k in range(len(data) - 1)
        ]
        best = optimize.minimize(
            fun, start, method="SLSQP", constraints=cons, options={"ftol": 1e-14, "maxiter": 500}
        )
    else:
        best = optimize.minimize(fun, start, method="BFGS", options={"gtol": 1e-9})
        best = optimize.minimize(
            fun, best.x, method="Nelder-Mead", options={"xatol": 1e-11, "fatol": 1e-13}
        )
    return np.exp(best.x[:-1]), float(np.exp(best.x[-1]))


def _censored_states(seed, n=40):
    """Capacities of three nested states [g] under n records (each the one below times a
    lognormal factor >= 1), censored at TOP: per state (uncensored, censoring levels)."""
    rng = np.random.default_rng(seed)
    c = 0.4 * np.exp(0.45 * rng.standard_normal(n))
    states = [c, c * np.exp(0.3 * np.abs(rng.standard_normal(n)))]
    states.append(states[1] * np.exp(0.4 * np.abs(rng.standard_normal(n))))
    return [(s[s <= TOP], np.full(int((s > TOP).sum()), TOP)) for s in states]


@pytest.mark.parametrize("seed", [1, 2])
def test_joint_common_beta_mle_of_censored_capacities_is_scipys(seed):
    data = _censored_states(seed)
    assert all(z.size for _, z in data[1:])  # censoring present
    separate = [nf.separate_fit(nf.CAPACITIES, *d) for d in data]
    theta, beta = nf.fit_nested(nf.CAPACITIES, data, [1, 2, -1], separate)
    start = [np.log(t) for t, _ in separate] + [np.log(0.5)]
    want_theta, want_beta = _oracle(data, nf.CAPACITIES, start)
    assert np.all(np.diff(want_theta) > 0)  # the order constraint is not active here
    np.testing.assert_allclose(theta, want_theta, rtol=1e-6)
    assert beta[0] == beta[1] == beta[2] == pytest.approx(want_beta, rel=1e-6)


def test_joint_mle_of_outcomes_is_scipys_and_the_order_is_forced_where_data_disagree():
    """Two states of points whose own fits put the worse state's median below the milder
    one's: the nested fit is the constrained maximum (SLSQP), with both medians pooled."""
    rng = np.random.default_rng(4)
    x = np.exp(rng.uniform(np.log(0.05), np.log(2.0), 300))
    milder = (rng.uniform(size=x.size) < stats.norm.cdf(np.log(x / 0.5) / 0.5)).astype(float)
    worse = (rng.uniform(size=x.size) < stats.norm.cdf(np.log(x / 0.42) / 0.3)).astype(float)
    data = [(x, milder), (x, worse)]
    separate = [nf.separate_fit(nf.OUTCOMES, *d) for d in data]
    assert separate[1][0] < separate[0][0]  # the data disagree with the nesting
    theta, beta = nf.fit_nested(nf.OUTCOMES, data, [1, -1], separate)
    start = [np.log(0.45), np.log(0.46), np.log(0.4)]
    want_theta, want_beta = _oracle(data, nf.OUTCOMES, start, ordered=True)
    np.testing.assert_allclose(theta, want_theta, rtol=1e-5)
    assert beta[0] == pytest.approx(want_beta, rel=1e-5)
    assert theta[0] == theta[1]  # pooled: the constraint is active
    free = _oracle(data, nf.OUTCOMES, start)[0]
    assert free[1] < free[0]  # without the constraint the medians would cross


def _slide_ida(seed, n_rec=25, spread=2.5):
    """An IDA of two objects at PGA = scale g with slide capacities C at D0 and C times a
    wide lognormal factor >= 1 at 2 D0 (nested per record, a larger spread: the separate
    fits tend to cross); overturning far above both."""
    rng = np.random.default_rng(seed)
    c = 0.3 * np.exp(0.35 * rng.standard_normal((n_rec, 2)))
    wide = c * np.exp(spread * np.abs(rng.standard_normal(c.shape)))
    rs = ("record", "structure")
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),
            "capacity_scale": (rs, np.full(c.shape, 1e4)),
            "capacity_scale_lower": (rs, np.full(c.shape, 1e4 * 0.99)),
            "censored": (rs, np.zeros(c.shape, bool)),
            "status": (rs, np.zeros(c.shape, int)),
            "slide_capacity": (("slide_limit",) + rs, np.stack([c, wide]) * STANDARD_GRAVITY),
            "vertical_component": ("record", np.ones(n_rec, bool)),
        },
        coords={
            "record": np.arange(n_rec),
            "structure": np.array(NAMES, dtype=object),
            "slide_limit": [D0, 2 * D0],
        },
        attrs={"design": "ida", "im": "pga", "im_period": np.nan, "slide_limits": [D0, 2 * D0]},
    )
    return ds, c, wide


def _curves_nest(theta, beta):
    """Whether each curve lies at or above every worse one (later in the arrays) on a grid
    from 1e-4 to 1e4 times the medians' range, evaluated here."""
    x = np.geomspace(np.min(theta) * 1e-4, np.max(theta) * 1e4, 2001)
    p = stats.norm.cdf(np.log(x[None, :] / np.asarray(theta)[:, None]) / np.asarray(beta)[:, None])
    return bool(np.all(np.diff(p, axis=0) <= 1e-12))


def test_nested_slide_curves_never_cross_on_random_designs_whose_separate_fits_do():
    crossed_apart = 0
    for seed in range(8):
        ds, *_ = _slide_ida(seed)
        apart = sliding.slide_fragility(ds, n_boot=0)
        nested = sliding.slide_fragility(ds, n_boot=0, nested=True)
        assert set(apart["fit"]) == {"separate"} and set(nested["fit"]) == {"nested"}
        assert not nested["crossed"].any()
        np.testing.assert_array_equal(nested["crossed_separate"], apart["crossed"])
        for name in NAMES:
            t, b = (apart.xs(name, level=1)[k].values for k in ("theta", "beta"))
            crossed_apart += not _curves_nest(t, b)
            t, b = (nested.xs(name, level=1)[k].values for k in ("theta", "beta"))
            assert _curves_nest(t, b)
    assert crossed_apart >= 4  # the case this test is about


def test_a_crossing_of_separate_fits_in_the_observed_range_is_flagged():
    ds, c, wide = _slide_ida(0)
    table = sliding.slide_fragility(ds, n_boot=0)
    for name in NAMES:
        part = table.xs(name, level=1)
        x = np.geomspace(part["im_min"].min(), part["im_max"].max(), 2001)
        (t0, t1), (b0, b1) = part["theta"].values, part["beta"].values
        below = stats.norm.cdf(np.log(x / t0) / b0) < stats.norm.cdf(np.log(x / t1) / b1) - 1e-9
        assert bool(part["crossed"].iloc[0]) == bool(below.any())
        assert not part["crossed"].iloc[1]  # the largest limit has none above it


def test_nested_fit_of_complete_capacities_is_the_pooled_closed_form():
    """Without censoring the nested medians are each limit's geometric mean (when ordered)
    and beta^2 the mean of the limits' beta^2 weighted by their counts."""
    ds, c, wide = _slide_ida(3, spread=0.3)
    nested = sliding.slide_fragility(ds, n_boot=0, nested=True)
    for j, name in enumerate(NAMES):
        logs = [np.log(c[:, j]), np.log(wide[:, j])]
        row = nested.xs(name, level=1)
        np.testing.assert_allclose(row["theta"], [np.exp(v.mean()) for v in logs], rtol=1e-7)
        pooled = np.sqrt(np.mean([v.var() for v in logs]))  # equal counts
        np.testing.assert_allclose(row["beta"], pooled, rtol=1e-6)


def _state_ida(n_rec, beta, seed, censor=True):
    """An IDA of two objects at PGA = scale g whose three states have capacities
    theta_k exp(beta z) with ONE z per record and object (a common beta by construction,
    nested per record), the overturning state the last; censored at TOP (``censor``)."""
    z = np.random.default_rng(seed).standard_normal((n_rec, 2))
    medians = {"chipped": 0.25, "displaced": 0.45, "overturned": 0.8}
    caps = {k: m * np.exp(beta * z) for k, m in medians.items()}
    top = TOP if censor else np.inf
    over = caps["overturned"]
    cens = over > top
    rs = ("record", "structure")
    scale = np.stack([np.where(caps[k] > top, np.nan, caps[k]) for k in ("chipped", "displaced")])
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),
            "capacity_scale": (rs, np.where(cens, np.nan, over)),
            "capacity_scale_lower": (rs, np.where(cens, top, 0.99 * over)),
            "censored": (rs, cens),
            "status": (rs, np.zeros(over.shape, int)),
            "state_capacity_scale": (("damage_state",) + rs, scale),
            "vertical_component": ("record", np.ones(n_rec, bool)),
        },
        coords={
            "record": np.arange(n_rec),
            "structure": np.array(NAMES, dtype=object),
            "damage_state": ["chipped", "displaced"],
        },
        attrs={"design": "ida", "im": "pga", "im_period": np.nan},
    )
    ds.attrs["damage_states"] = json.dumps({"chipped": 0.3, "displaced": 0.6, "overturned": 1.0})
    return ds, caps


def test_ida_states_censored_path_is_the_joint_mle_of_scipy():
    ds, caps = _state_ida(30, 0.5, seed=7)
    assert ds["censored"].any() and np.isnan(ds["state_capacity_scale"]).any()
    table = st.state_fragility(ds, n_boot=0, nested=True)
    assert not table["crossed"].any()
    for j, name in enumerate(NAMES):
        data = [
            (c[:, j][c[:, j] <= TOP], np.full(int((c[:, j] > TOP).sum()), TOP))
            for c in caps.values()
        ]
        start = [np.log(np.median(c[:, j])) for c in caps.values()] + [np.log(0.5)]
        want_theta, want_beta = _oracle(data, nf.CAPACITIES, start)
        row = table.xs(name, level=1)
        np.testing.assert_allclose(row["theta"], want_theta, rtol=1e-6)
        np.testing.assert_allclose(row["beta"], want_beta, rtol=1e-6)


def test_nested_agrees_with_separate_fits_of_a_common_beta_within_sampling_error():
    """States generated with one beta (0.4) and n = 400 records: the separate fits do not
    cross in the data and the nested fit agrees with each of them within three standard
    errors of the MLE of n lognormal capacities (ln theta: beta / sqrt(n), beta:
    beta / sqrt(2 n)); the medians (uncensored) exactly."""
    n, beta = 400, 0.4
    ds, _ = _state_ida(n, beta, seed=11, censor=False)
    apart = st.state_fragility(ds, n_boot=0)
    nested = st.state_fragility(ds, n_boot=0, nested=True)
    assert not apart["crossed"].any()
    np.testing.assert_allclose(nested["theta"], apart["theta"], rtol=1e-7)
    ratio_theta = np.log(nested["theta"] / apart["theta"])
    assert np.all(np.abs(ratio_theta) <= 3 * beta / np.sqrt(n))
    assert np.all(np.abs(nested["beta"] - apart["beta"]) <= 3 * beta / np.sqrt(2 * n))


def test_nested_state_risk_is_cornells_closed_form_of_the_nested_fit_and_flags_separate():
    """Complete capacities on records with a vertical component (no cut), "displaced" far
    wider than "chipped" (its separate rate the higher: flagged) and overturning at least
    "displaced" per record: each state's nested rate is k0 theta^-k exp(k^2 beta^2 / 2) of
    its geometric mean (ordered here) and the pooled beta; the separate flag is kept as
    ``crossed_separate``."""
    ds, caps = _state_ida(30, 0.4, seed=2, censor=False)
    z = np.abs(np.random.default_rng(0).standard_normal((30, 2)))
    wide = caps["chipped"] * np.exp(2.0 * z)
    over = np.maximum(caps["overturned"], wide)
    ds["state_capacity_scale"][1] = wide
    ds["capacity_scale"][:] = over
    ds["capacity_scale_lower"][:] = 0.99 * over
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = st.state_risk(ds, hazard, n_boot=0, min_overturning=1, nested=True)
    alone = st.state_risk(ds, hazard, n_boot=0, min_overturning=1)
    assert out.attrs["fit"] == "nested" and alone.attrs["fit"] == "separate"
    assert alone["crossed"].sel(damage_state="chipped").any()  # the case this test builds
    assert not out["crossed"].any()
    np.testing.assert_array_equal(out["crossed_separate"], alone["crossed"])
    for j, name in enumerate(NAMES):
        logs = [np.log(c) for c in (caps["chipped"][:, j], wide[:, j], over[:, j])]
        theta = np.exp([v.mean() for v in logs])
        assert np.all(np.diff(theta) > 0)
        b = np.sqrt(np.mean([v.var() for v in logs]))
        want = K0 * theta**-K * np.exp(K**2 * b**2 / 2)
        got = out["annual_rate"].sel(structure=name).values
        np.testing.assert_allclose(got, want, rtol=1e-6)


def test_nested_bands_come_from_resampled_records():
    ds, *_ = _slide_ida(1, spread=0.3)
    table = sliding.slide_fragility(ds, n_boot=50, nested=True)
    assert set(table["p_band"]) == {"record_bootstrap"}
    assert np.all(table["theta_lo"] <= table["theta"]) and np.all(
        table["theta"] <= table["theta_hi"]
    )
    assert np.all(table["beta_lo"] <= table["beta"]) and np.all(table["beta"] <= table["beta_hi"])


def test_the_report_shows_the_nested_fit_and_flags_the_separate_fits_that_cross(tmp_path):
    """An IDA (4 generated records) whose smaller slide limit has nearly equal capacities
    and whose larger one is the overturning capacity (wide): fitted apart the curves cross.
    The report's table gives the fits apart with their flag and the nested medians and
    beta, its rates are those of the nested fit, and its page says so and warns."""
    import pandas as pd

    import rockstudy as rs
    from rockstudy.study.designs.records import incremental_dynamic_analysis
    from rockstudy.study.report import record_report

    records = [
        rs.motions.synthetic_near_fault(pulse_period=tp, pga=2.0, seed=20 + i, duration=4.0)
        for i, tp in enumerate((0.4, 0.6, 0.9, 1.2))
    ]
    blocks = {"Vase": rs.Block(half_diagonal=0.4, slenderness=0.25)}
    ds = incremental_dynamic_analysis(records, blocks, step=0.1, tolerance=0.05, scan=0)
    cap = ds["capacity"].values
    narrow = np.exp(np.mean(np.log(cap)) - 0.1) * (1 + 0.01 * np.arange(cap.size))[:, None]
    ds["slide_capacity"] = (
        ("slide_limit", "record", "structure"),
        np.stack([np.minimum(narrow, cap), cap * np.nan]),
    )
    ds = ds.assign_coords(slide_limit=[0.01, 0.05])
    ds.attrs["slide_limits"] = [0.01, 0.05]
    hazard = rs.risk.HazardCurve.power_law(2e-4, 2.3, "pga", "g")
    apart = sliding.slide_fragility(ds, im="pga", n_boot=0)
    assert apart["crossed"].any()  # the case this test builds
    nested = sliding.slide_fragility(ds, im="pga", n_boot=0, nested=True)
    page = record_report(ds, tmp_path, n_boot=0, hazard=hazard).read_text()
    assert "The figure and the annual rates show the nested fit" in page
    assert "Fitted apart, the curves of a milder and a worse slide limit d cross" in page
    table = pd.read_csv(tmp_path / "slide_fragility.csv", index_col=[0, 1])
    for (d, obj), row in table.iterrows():
        assert row["fits apart cross"] == apart.loc[(d, obj), "crossed"]
        assert row["median PGA [g]"] == pytest.approx(apart.loc[(d, obj), "theta"])
        assert row["nested median PGA [g]"] == pytest.approx(nested.loc[(d, obj), "theta"])
        assert row["nested beta (common)"] == pytest.approx(nested.loc[(d, obj), "beta"])
    rates = pd.read_csv(tmp_path / "annual_sliding.csv", index_col=[0, 1])
    want = sliding.slide_risk(ds, hazard, n_boot=0, nested=True)
    for (d, obj), row in rates.iterrows():
        got = row["lambda(max_slide > d) [1/yr]"]
        assert got == pytest.approx(float(want["annual_rate"].sel(slide_limit=d, structure=obj)))


def test_states_nest_on_each_demand_and_under_overturning():
    from rockstudy.study.spec.damage_states import DamageState

    states = [
        DamageState("displaced", "rotation_ratio", 0.5),
        DamageState("fall_off", "slide", 0.1),
        DamageState("chipped", "rotation_ratio", 0.25),
        DamageState("overturned", "rotation_ratio", 1.0),
        DamageState("slipped", "slide", 0.02),
    ]
    # chipped -> displaced -> overturned; slipped -> fall_off -> overturned
    assert st.state_above(states) == [3, 3, 0, -1, 1]


def test_nested_stripes_states_are_the_ordered_joint_binomial_mle():
    """Stripes of two objects at 8 PGA levels (25 records): each state's points reached it
    where the rotation ratio alpha x / C reached its limit or the block overturned (x > C);
    the nested fit of each object is the maximum of the summed binomial likelihood of its
    three states under ln theta_1 <= ln theta_2 <= ln theta_3 (SLSQP here)."""
    levels = np.array([0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.3])
    n_rec, limits = 25, {"chipped": 0.25, "displaced": 0.5, "overturned": 1.0}
    c = 0.5 * np.exp(0.45 * np.random.default_rng(3).standard_normal((n_rec, 2)))
    x = np.broadcast_to(levels, (n_rec, 2, levels.size)).copy()
    ratio = x / c[:, :, None]
    dims = ("record", "structure", "level")
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),
            "scale": (dims, x),
            "max_rotation": (dims, np.where(ratio > 1, np.pi / 2, 0.2 * ratio)),
            "overturned": (dims, ratio > 1),
            "status": (dims, np.zeros(x.shape, int)),
            "critical_rotation": ("structure", [0.2, 0.2]),
        },
        coords={"record": np.arange(n_rec), "structure": NAMES, "level": levels},
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan},
    )
    ds.attrs["damage_states"] = json.dumps(limits)
    table = st.state_fragility(ds, n_boot=0, nested=True)
    for j, name in enumerate(NAMES):
        xs = x[:, j].ravel()
        data = [(xs, ((ratio[:, j] >= lim) | (ratio[:, j] > 1)).ravel()) for lim in limits.values()]
        data = [(a, z.astype(float)) for a, z in data]
        start = [np.log(0.12), np.log(0.25), np.log(0.5), np.log(0.5)]
        want_theta, want_beta = _oracle(data, nf.OUTCOMES, start, ordered=True)
        row = table.xs(name, level=1)
        np.testing.assert_allclose(row["theta"], want_theta, rtol=1e-5)
        np.testing.assert_allclose(row["beta"], want_beta, rtol=1e-5)
