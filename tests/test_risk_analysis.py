"""Per-object risk of a record design (rockstudy.study.analysis.risk).

Oracles: Cornell et al. (2002)'s closed form lambda = k0 theta^-k exp(k^2 beta^2 / 2) for a
lognormal capacity and a power-law hazard, with the sampling error of the fit from the
delta method on the known lognormal; the hazard's units (g against m/s^2, the same site);
a tabulated curve against the power law it was tabulated from; objects that never or always
overturn, marked by what the data can say."""

import math

import numpy as np
import pytest
import xarray as xr
from _helpers import K0, K, lognormal_sample, pga_ida, unit_sine_record

from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.study.analysis.risk import object_risk


def test_rate_of_a_known_lognormal_capacity_matches_cornell_within_its_sampling_error():
    # two objects of known capacity distributions; 400 records
    n, truth = 400, [(0.3, 0.4), (0.6, 0.25)]
    cap = np.column_stack([lognormal_sample(t, b, n, s) for s, (t, b) in enumerate(truth)])
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(pga_ida(cap, names=["Statue", "Column"]), hazard, n_boot=100, seed=1)
    for name, (theta, beta) in zip(["Statue", "Column"], truth, strict=True):
        row = out.sel(structure=name)
        exact = K0 * theta**-K * np.exp(0.5 * (K * beta) ** 2)
        # delta method: var ln lambda = k^2 beta^2 / n + k^4 beta^4 / (2 n)
        sd = np.sqrt((K * beta) ** 2 / n + (K * beta) ** 4 / (2 * n))
        assert abs(np.log(float(row["annual_rate"]) / exact)) < 4 * sd
        # the fit's own numbers give Cornell's closed form exactly
        t_hat, b_hat = float(row["theta"]), float(row["beta"])
        closed = K0 * t_hat**-K * np.exp(0.5 * (K * b_hat) ** 2)
        assert float(row["annual_rate"]) == pytest.approx(closed, rel=1e-3)
        # the 90 % bootstrap band is about +-1.645 sd wide in log (within a third)
        half = 0.5 * np.log(float(row["annual_rate_hi"]) / float(row["annual_rate_lo"]))
        assert half == pytest.approx(1.645 * sd, rel=1 / 3)
        assert str(row["status"].values) == "ok"
    assert list(out["structure"].values) == ["Statue", "Column"]  # ranked: weaker first


def test_band_contains_the_point_estimate_and_is_seeded():
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 12, 3), lognormal_sample(0.8, 0.3, 12, 4)])
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    a = object_risk(pga_ida(cap), hazard, n_boot=200, seed=7)
    b = object_risk(pga_ida(cap), hazard, n_boot=200, seed=7)
    lam, lo, hi = (a[k].values for k in ("annual_rate", "annual_rate_lo", "annual_rate_hi"))
    assert np.all(lo < lam) and np.all(lam < hi)
    assert np.all(a["probability_lo"] < a["probability"])
    assert np.all(a["probability"] < a["probability_hi"])
    np.testing.assert_array_equal(lo, b["annual_rate_lo"].values)
    # probability in 50 yr is Poisson: 1 - exp(-50 lambda)
    np.testing.assert_allclose(a["probability"], -np.expm1(-50 * lam), rtol=1e-12)
    # the deaggregation sums to the rate
    np.testing.assert_allclose(a["deaggregation"].sum("interval"), lam, rtol=1e-9)


def test_units_g_or_si_give_the_same_rate():
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 15, 5)])
    in_g = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    in_si = in_g.to_units("m/s^2")
    a = object_risk(pga_ida(cap), in_g, n_boot=20)
    b = object_risk(pga_ida(cap), in_si, n_boot=20)
    assert b["annual_rate"].item() == pytest.approx(a["annual_rate"].item(), rel=1e-10)
    assert b["theta"].item() == pytest.approx(a["theta"].item() * G_UNIT, rel=1e-12)


def test_a_tabulated_curve_gives_the_rate_of_its_power_law_source():
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 15, 6), lognormal_sample(1.2, 0.3, 15, 8)])
    source = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    levels = np.geomspace(0.05, 2.0, 12)
    table = risk.HazardCurve("pga", levels, K0 * levels**-K, units="g")
    a = object_risk(pga_ida(cap), source, n_boot=0)
    b = object_risk(pga_ida(cap), table, n_boot=0)
    np.testing.assert_allclose(b["annual_rate"], a["annual_rate"], rtol=1e-9)


def test_objects_that_never_overturn_are_marked_with_an_upper_bound_not_a_rate():
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 10, 9), np.linspace(1.5, 3.0, 10)])
    cens = np.zeros(cap.shape, bool)
    cens[:, 1] = True  # the second object stood at the top of every IDA
    cens[:2, 0] = True  # the first, under two records
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(pga_ida(cap, cens, ["A", "B"]), hazard, n_boot=20)
    b = out.sel(structure="B")
    assert str(b["status"].values) == "none"
    assert np.isnan(float(b["annual_rate"])) and np.isnan(float(b["probability"]))
    # every capacity lies above the lowest standing level 1.5 / 1.001 g
    assert float(b["rate_upper_bound"]) == pytest.approx(K0 * (1.5 / 1.001) ** -K, rel=1e-9)
    a = out.sel(structure="A")
    assert str(a["status"].values) == "ok" and int(a["n_overturning"]) == 8
    assert list(out["structure"].values) == ["A", "B"]  # objects without a rate last


def test_few_overturning_records_are_marked():
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 10, 10)])
    cens = np.ones(cap.shape, bool)
    cens[:3, 0] = False
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(pga_ida(cap, cens), hazard, n_boot=10)
    assert str(out["status"].values[0]) == "few"
    assert int(out["n_overturning"].values[0]) == 3


def test_stripes_overturned_everywhere_give_a_lower_bound():
    levels = np.array([0.2, 0.4, 0.8])
    n_rec = 4
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, G_UNIT)),
            "scale": (("record", "structure", "level"), np.broadcast_to(levels, (n_rec, 1, 3))),
            "overturned": (("record", "structure", "level"), np.ones((n_rec, 1, 3), bool)),
            "status": (("record", "structure", "level"), np.zeros((n_rec, 1, 3), int)),
        },
        coords={"structure": ["Vase"], "level": levels},
        attrs={"design": "stripes", "im": "pga"},
    )
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(ds, hazard, n_boot=10)
    assert str(out["status"].values[0]) == "all"
    assert float(out["rate_lower_bound"].values[0]) == pytest.approx(K0 * 0.2**-K, rel=1e-9)
    assert np.isnan(out["annual_rate"].values[0])
    assert np.isnan(out["rate_upper_bound"].values[0])  # a design that does not say horizontal
    # horizontal records and an uplift PGA of 0.1 g: nothing overturns below it, P(OT) <= 1
    # above, so lambda(0.1 g) >= lambda_OT >= lambda(0.2 g)
    cut = ds.assign(
        vertical_component=("record", np.zeros(n_rec, bool)),
        uplift_acceleration=("structure", [0.1 * G_UNIT]),
    )
    out = object_risk(cut, hazard, n_boot=10)
    assert float(out["rate_upper_bound"].values[0]) == pytest.approx(K0 * 0.1**-K, rel=1e-9)
    assert float(out["rate_lower_bound"].values[0]) == pytest.approx(K0 * 0.2**-K, rel=1e-9)


def test_a_hazard_the_design_cannot_express_is_refused():
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 5, 11)])
    sa = risk.HazardCurve.power_law(K0, K, im="sa", units="g", period=0.5)
    with pytest.raises(ValueError, match="hazard: the design cannot express"):
        object_risk(pga_ida(cap), sa)
    dur = risk.HazardCurve.power_law(1.0, 1.0, im="significant_duration")
    no_fragility = "hazard: its im 'significant_duration' is not a measure a scale factor"
    with pytest.raises(ValueError, match=no_fragility):
        object_risk(pga_ida(cap), dur)
    with pytest.raises(TypeError, match="hazard must be"):
        object_risk(pga_ida(cap), "pga")
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    with pytest.raises(ValueError, match="years"):
        object_risk(pga_ida(cap), hazard, years=0)


def test_share_below_a_level_matches_the_closed_form_of_a_power_law():
    # int_0^u F |d lambda| = E[lambda(C); C < u] - lambda(u) F(u), both in closed form for
    # lambda = k0 x^-k and ln C ~ N(mu, beta^2)
    from scipy.stats import norm

    from rockstudy.study.analysis.risk import share_below

    theta, beta, u = 0.5, 0.6, 0.3
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g", levels=[0.01, 0.1, 1.0, 5.0])
    mu = np.log(theta)
    tail = (
        K0 * np.exp(-K * mu + 0.5 * (K * beta) ** 2) * norm.cdf((np.log(u) - mu) / beta + K * beta)
    )
    below = tail - K0 * u**-K * norm.cdf((np.log(u) - mu) / beta)
    total = K0 * theta**-K * np.exp(0.5 * (K * beta) ** 2)
    assert share_below(theta, beta, hazard, u) == pytest.approx(below / total, rel=1e-9)


def test_the_uplift_share_is_given_for_a_pga_hazard():
    cap = np.column_stack([lognormal_sample(0.4, 0.8, 30, 12)])
    ds = pga_ida(cap)
    ds["pga_ratio"] = (("record", "structure"), np.full((30, 1), 1 / 0.2))  # uplift 0.2 g
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(ds, hazard, n_boot=0)
    assert out["uplift"].item() == pytest.approx(0.2, rel=1e-12)
    row = out.isel(structure=0)
    expected = _share_of_rate_below(row["theta"].item(), row["beta"].item(), 0.2)
    assert row["share_below_uplift"].item() == pytest.approx(expected, rel=1e-7)
    assert 0.05 < expected < 0.95


def _share_of_rate_below(theta, beta, level):
    """The share of lambda_OT = int F(x) |dlambda/dx| dx from x < ``level`` [g], F the
    lognormal fragility and lambda = K0 x^-K, by the trapezoidal rule in ln x on a fine grid
    (|dlambda/dx| dx = K K0 x^-K d(ln x)), from far below theta to where x^-K is negligible."""
    from scipy.stats import norm

    def rate(upper):
        u = np.linspace(math.log(theta) - 15 * beta, math.log(upper), 400_001)
        integrand = norm.cdf((u - math.log(theta)) / beta) * K * K0 * np.exp(-K * u)
        return np.trapezoid(integrand, u)

    whole = rate(theta * math.exp(15 * beta + 60 / K))  # x^-K down by e^-60 beyond
    return rate(level) / whole


def _truncated_cornell(theta, beta, x_u):
    """lambda(x_u) F(x_u) + E[k0 C^-k; C > x_u] of the power law k0 x^-k (by parts): the rate
    of the lognormal fragility set to 0 below x_u."""
    from scipy.stats import norm

    z = np.log(x_u / theta) / beta
    full = K0 * theta**-K * np.exp(0.5 * (K * beta) ** 2)
    return K0 * x_u**-K * norm.cdf(z) + full * norm.cdf(-z - K * beta)


def _two_objects(vertical):
    """A: capacities 0.45 exp(2 |Z|) g, all above its uplift at 0.45 g but spread so wide that
    the lognormal fitted to them (beta about 1.1) puts much of its mass below 0.45 g; B:
    about 0.6 g with beta 0.3, uplift at 0.05 g. The whole lognormal ranks A first (its wide
    lower tail); with the fragility 0 below uplift, B."""
    z = np.random.default_rng(21).standard_normal(300)
    cap = np.column_stack([0.45 * np.exp(2.0 * np.abs(z)), lognormal_sample(0.6, 0.3, 300, 22)])
    ds = pga_ida(cap, names=["A", "B"])
    ds["uplift_acceleration"] = ("structure", np.array([0.45, 0.05]) * G_UNIT)
    ds["vertical_component"] = ("record", np.arange(300) == 7 if vertical else np.zeros(300, bool))
    return ds


def test_without_vertical_shaking_the_fragility_is_zero_below_uplift():
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(_two_objects(False), hazard, n_boot=50, seed=3)
    assert list(out["structure"].values) == ["B", "A"]  # ranked by the truncated rate
    for name, x_u in (("A", 0.45), ("B", 0.05)):
        row = out.sel(structure=name)
        t, b = float(row["theta"]), float(row["beta"])
        assert bool(row["truncated_at_uplift"]) and float(row["uplift"]) == pytest.approx(x_u)
        rate = float(row["annual_rate"])
        assert rate == pytest.approx(_truncated_cornell(t, b, x_u), rel=1e-9)
        whole = K0 * t**-K * np.exp(0.5 * (K * b) ** 2)
        assert float(row["annual_rate_lognormal"]) == pytest.approx(whole, rel=1e-9)
        # what the truncation removed is the lognormal's share below uplift
        share = float(row["share_below_uplift"])
        assert rate == pytest.approx(whole * (1.0 - share), rel=1e-9)
        assert float(row["probability"]) == pytest.approx(-np.expm1(-50 * rate), rel=1e-12)
        assert float(row["annual_rate_lo"]) <= rate <= float(row["annual_rate_hi"])
        parts = row["deaggregation"].values
        assert parts.sum() == pytest.approx(rate, rel=1e-9)
        assert np.all(parts[out["im_upper"].values <= x_u] == 0.0)
    whole = out["annual_rate_lognormal"]
    assert float(whole.sel(structure="A")) > float(whole.sel(structure="B"))


def test_a_vertical_component_or_another_measure_keeps_the_whole_lognormal():
    """A vertical component can lift a block under a PGA below g tan(alpha); a PGV hazard has
    no uplift level: neither is truncated."""
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(_two_objects(True), hazard, n_boot=0)
    assert not out["truncated_at_uplift"].values.any()
    np.testing.assert_array_equal(out["annual_rate"], out["annual_rate_lognormal"])
    assert list(out["structure"].values) == ["A", "B"]
    # a design that does not say whether its records have a vertical component
    out = object_risk(_two_objects(False).drop_vars("vertical_component"), hazard, n_boot=0)
    assert not out["truncated_at_uplift"].values.any()


def test_record_designs_say_which_records_have_a_vertical_component():
    from rockstudy.motions import Record, stochastic_record
    from rockstudy.structures import Block
    from rockstudy.study.designs import records as rd

    h = stochastic_record(peak=2.0, duration=2.0, dt=0.01, seed=0)
    hv = Record(h.acceleration, dt=h.dt, vertical=h.acceleration / 4.0)
    ds = rd.cloud([h, hv], {"block": Block(1.0, 0.2)})
    np.testing.assert_array_equal(ds["vertical_component"].values, [False, True])
    ds = rd.cloud([h], {"block": Block(1.0, 0.2)})
    np.testing.assert_array_equal(ds["vertical_component"].values, [False])


def test_the_cut_is_where_the_simulated_block_lifts_when_that_is_lower():
    """An arch's equivalent block (what a design simulates) lifts off at g tan(theta_cr),
    below the arch's own g lambda: nothing overturns below the lower of the two, so the cut
    is there; the IDA's capacities of a real arch all lie above it."""

    from rockstudy.constants import G
    from rockstudy.structures import Arch, uplift_acceleration
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    arch = Arch(np.pi, 0.15, 1.0, 0.9)
    block_lifts = G * np.tan(arch.equivalent_block().slenderness) / G_UNIT  # [g]
    own = uplift_acceleration(arch) / G_UNIT
    assert block_lifts < own * 0.9  # (an arch: 14 % lower)
    recs = [unit_sine_record(tp) for tp in (2.0, 3.0, 4.0)]
    ida = incremental_dynamic_analysis(recs, {"arch": arch}, scan=0, step=0.05, tolerance=0.01)
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(ida, hazard, n_boot=0)
    row = out.isel(structure=0)
    assert bool(row["truncated_at_uplift"]) and not bool(row["overturned_below_uplift"])
    assert float(row["cut_level"]) == pytest.approx(block_lifts, rel=1e-12)
    assert float(row["uplift"]) == pytest.approx(own, rel=1e-12)
    capacities = ida["capacity"].values.ravel() / G_UNIT
    assert np.all(capacities[np.isfinite(capacities)] >= block_lifts)
    assert str(row["status"].values) == "few"  # all three records overturned it: 3 < 5
    t, b = float(row["theta"]), float(row["beta"])
    expected = _truncated_cornell(t, b, block_lifts)
    assert float(row["annual_rate"]) == pytest.approx(expected, rel=1e-9)


def test_an_overturning_below_the_cut_refuses_the_cut():
    """Data that the physics forbids (an overturning below uplift under horizontal records):
    the fragility is not cut, and the object is marked."""
    ds = _two_objects(False)
    cap = ds["capacity_scale"].values.copy()
    cap[3, 0] = 0.3  # below A's uplift at 0.45 g
    ds["capacity_scale"] = (("record", "structure"), cap)
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = object_risk(ds, hazard, n_boot=0)
    a, b = out.sel(structure="A"), out.sel(structure="B")
    assert bool(a["overturned_below_uplift"]) and not bool(a["truncated_at_uplift"])
    assert float(a["annual_rate"]) == float(a["annual_rate_lognormal"])
    assert bool(b["truncated_at_uplift"]) and not bool(b["overturned_below_uplift"])


def test_a_pgv_hazard_is_not_cut():
    """PGV has no uplift level: the whole lognormal, whatever the records."""
    ds = _two_objects(False)
    ds["pgv"] = ("record", np.full(ds.sizes["record"], 0.5))  # capacities in m/s: 0.5 x scale
    hazard = risk.HazardCurve.power_law(1e-4, 2.0, im="pgv", units="m/s")
    out = object_risk(ds, hazard, n_boot=0)
    assert not out["truncated_at_uplift"].values.any()
    assert np.all(np.isnan(out["cut_level"].values))
    np.testing.assert_array_equal(out["annual_rate"], out["annual_rate_lognormal"])
    t, b = out["theta"].values, out["beta"].values
    np.testing.assert_allclose(out["annual_rate"], 1e-4 * t**-2.0 * np.exp(2.0 * b**2), rtol=1e-9)
