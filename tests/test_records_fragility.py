"""Fragility of record designs against independent oracles: data drawn from known lognormal
fragilities, scipy's own maximum-likelihood fits (plain and censored), a direct maximisation
of the binomial likelihood, and datasets built so that one measure collapses the capacities."""

import numpy as np
import pytest
import xarray as xr
from _helpers import ida_dataset as _ida_dataset
from scipy import optimize, stats

from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.constants import G
from rockstudy.study import analysis
from rockstudy.study.analysis import fragility_fit
from rockstudy.study.analysis import record_fragility as rf


def _binomial_data(theta, beta, levels, n, seed):
    rng = np.random.default_rng(seed)
    return rng.binomial(n, stats.norm.cdf(np.log(levels / theta) / beta))


def test_binomial_mle_recovers_a_known_fragility():
    levels = np.geomspace(0.1, 1.6, 10)
    z = _binomial_data(0.4, 0.35, levels, 4000, seed=3)
    theta, beta = rf.fit_binomial(levels, z, np.full(10, 4000))
    assert theta == pytest.approx(0.4, rel=0.02)
    assert beta == pytest.approx(0.35, rel=0.04)


def test_binomial_mle_maximises_the_binomial_likelihood():
    levels = np.array([0.2, 0.3, 0.45, 0.7, 1.0])
    n = np.array([20, 20, 15, 20, 10])
    z = _binomial_data(0.5, 0.5, levels, n, seed=5)

    def nll(q):  # direct, in (theta, beta), by scipy's binomial pmf
        if q[0] <= 0 or q[1] <= 0:
            return np.inf
        return -np.sum(stats.binom.logpmf(z, n, stats.norm.cdf(np.log(levels / q[0]) / q[1])))

    ref = optimize.minimize(
        nll,
        [0.6, 0.6],
        method="Nelder-Mead",
        options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 5000},
    ).x
    np.testing.assert_allclose(rf.fit_binomial(levels, z, n), ref, rtol=1e-5)


def test_binomial_without_outcome_change_has_no_fit():
    assert rf.fit_binomial([1.0, 2.0], [0, 0], [5, 5]) == (
        np.inf,
        pytest.approx(np.nan, nan_ok=True),
    )
    assert rf.fit_binomial([1.0, 2.0], [5, 5], [5, 5])[0] == 0.0
    with pytest.raises(ValueError, match="n_overturned"):
        rf.fit_binomial([1.0], [3], [2])


def test_ida_fit_is_scipy_lognormal_mle():
    c = np.random.default_rng(2).lognormal(np.log(0.3), 0.4, 25)
    shape, _, scale = stats.lognorm.fit(c, floc=0)
    np.testing.assert_allclose(rf.fit_capacities(c), (scale, shape), rtol=1e-6)


def test_censored_ida_fit_is_scipy_censored_mle():
    rng = np.random.default_rng(4)
    c = rng.lognormal(0.0, 0.5, 400)
    top = 1.4
    data = stats.CensoredData(uncensored=c[c <= top], right=np.full((c > top).sum(), top))
    shape, _, scale = stats.lognorm.fit(data, floc=0)
    np.testing.assert_allclose(
        rf.fit_capacities(c[c <= top], np.full((c > top).sum(), top)), (scale, shape), rtol=1e-4
    )
    assert rf.fit_capacities([], [1.0, 2.0])[0] == np.inf


def test_ida_fragility_units_closed_form_and_band_coverage():
    rng = np.random.default_rng(7)
    pga = rng.uniform(2.0, 6.0, 30)
    cap_g = rng.lognormal(np.log(0.5), 0.3, 30)  # capacities in g
    ds = _ida_dataset((cap_g * G_UNIT / pga)[:, None], pga, pga / 10, [G_UNIT * 0.2], [2.7])
    t = rf.ida_fragility(ds)
    assert t.loc["all", "unit"] == "g"
    assert t.loc["all", "theta"] == pytest.approx(np.exp(np.mean(np.log(cap_g))), rel=1e-12)
    assert t.loc["all", "beta"] == pytest.approx(np.std(np.log(cap_g)), rel=1e-12)
    assert t.loc["all", "theta_in_range"]
    # the 90 % band of the median covers the true median ~90 % of the time
    hits = 0
    for seed in range(300):
        c = np.random.default_rng(seed).lognormal(np.log(0.5), 0.3, 12)
        r = rf.ida_fragility(
            _ida_dataset((c * G_UNIT)[:, None], np.full(12, 1.0), np.ones(12), [1.0], [1.0])
        )
        hits += r.loc["all", "theta_lo"] <= 0.5 <= r.loc["all", "theta_hi"]
    assert 0.85 <= hits / 300 <= 0.95


def test_fragility_median_outside_the_data_is_flagged():
    rng = np.random.default_rng(9)
    cap = rng.lognormal(0.0, 0.5, (40, 1))
    top = 0.6  # most blocks stand at the top of the range: the median lies above it
    ds = _ida_dataset(
        np.minimum(cap, top), np.full(40, G_UNIT), np.ones(40), [1.0], [1.0], censored=cap > top
    )
    ds["capacity_scale_lower"] = ds["capacity_scale_lower"].where(~ds["censored"], top)
    t = rf.ida_fragility(ds, n_boot=50)
    assert t.loc["all", "theta"] > t.loc["all", "im_max"]
    assert not t.loc["all", "theta_in_range"]
    # stripes whose levels stay below the median
    levels = np.array([0.1, 0.15, 0.2])
    stripes = xr.Dataset(
        {
            "pga": ("record", np.full(50, G_UNIT)),
            "overturned": (
                ("record", "structure", "level"),
                (rng.random((50, 1, 3)) < stats.norm.cdf(np.log(levels / 1.0) / 0.4)),
            ),
            "status": (("record", "structure", "level"), np.zeros((50, 1, 3), np.int64)),
            "scale": (("record", "structure", "level"), np.broadcast_to(levels, (50, 1, 3))),
        },
        coords={"level": levels * G_UNIT, "structure": [0]},
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan},
    )
    s = rf.stripe_fragility(stripes, n_boot=50)
    assert s.loc["all", "unit"] == "g"
    assert s.loc["all", "im_max"] == pytest.approx(0.2)
    assert not s.loc["all", "theta_in_range"] and not s.loc["all", "band_in_range"]


def test_stripe_fragility_recovers_the_fragility_of_its_points():
    rng = np.random.default_rng(11)
    levels = np.geomspace(0.1, 1.0, 8)
    n_rec = 400
    y = rng.random((n_rec, 1, 8)) < stats.norm.cdf(np.log(levels / 0.35) / 0.45)
    ds = xr.Dataset(
        {
            "pga": ("record", rng.uniform(1.0, 5.0, n_rec)),
            "overturned": (("record", "structure", "level"), y),
            "status": (("record", "structure", "level"), np.zeros(y.shape, np.int64)),
        },
        coords={"level": levels * G_UNIT, "structure": [0]},
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan},
    )
    ds["scale"] = (xr.DataArray(levels * G_UNIT, dims="level") / ds["pga"]).broadcast_like(
        ds["overturned"]
    )
    t = rf.stripe_fragility(ds, n_boot=40)
    assert t.loc["all", "theta"] == pytest.approx(0.35, rel=0.06)
    assert t.loc["all", "beta"] == pytest.approx(0.45, rel=0.12)
    assert t.loc["all", "theta_lo"] < t.loc["all", "theta"] < t.loc["all", "theta_hi"]


def test_im_efficiency_ranks_the_collapsing_measure_first():
    # capacities that are exactly a fixed PGV p / (g tan alpha), times 5 % scatter, over blocks
    # of different sizes: PGA in g spreads apart, the dimensionless PGV collapses them
    rng = np.random.default_rng(12)
    n_rec, p = 30, np.array([1.5, 3.0, 6.0])
    uplift = G * np.tan(np.array([0.2, 0.15, 0.25]))
    pga, pgv = rng.uniform(2, 8, n_rec), rng.uniform(0.2, 1.0, n_rec)
    target = 1.2 * np.exp(0.05 * rng.standard_normal((n_rec, 3)))
    scale = target * uplift / (pgv[:, None] * p)
    ds = _ida_dataset(scale, pga, pgv, uplift, p)
    table = rf.im_efficiency(ds, candidates=("pga", "pgv", "sa", "pga_ratio", "pgv_ratio"))
    best = table.index[0][0]
    assert best == "pgv_ratio"
    assert table.loc[("pgv_ratio", "all"), "beta"] == pytest.approx(
        np.std(np.log(target)), rel=1e-9
    )
    assert table.loc[("pgv_ratio", "all"), "dimensionless"]
    assert table.loc[("pga", "all"), "beta"] > 5 * table.loc[("pgv_ratio", "all"), "beta"]
    assert "sa(T=1 s)" in table.index.get_level_values("im")
    # within one block, a measure and its ratio share beta
    per = rf.im_efficiency(ds, candidates=("pga", "pga_ratio"), by="structure")
    np.testing.assert_allclose(
        per.xs("pga", level="im")["beta"].sort_index(),
        per.xs("pga_ratio", level="im")["beta"].sort_index(),
        rtol=1e-12,
    )


def test_intensity_in_quoted_units_and_bad_names():
    ds = _ida_dataset([[2.0]], [G_UNIT / 2], [0.3], [G_UNIT * 0.2], [2.0])
    ds["arias"] = ("record", [0.5])
    assert rf.intensity(ds, "pga", scale="capacity_scale").item() == pytest.approx(1.0)
    assert rf.intensity(ds, "pgv", scale="capacity_scale").item() == pytest.approx(0.6)
    assert rf.intensity(ds, "arias", scale="capacity_scale").item() == pytest.approx(2.0)
    assert rf.intensity(ds, "sa", 1.0, scale="capacity_scale").item() == pytest.approx(1.0)
    assert rf.intensity(ds, "sa", 1.0).attrs["unit"] == "g"
    with pytest.raises(ValueError, match="im must be one of"):
        rf.intensity(ds, "pgz")
    with pytest.raises(ValueError, match="period: 2.0 s is not stored"):
        rf.intensity(ds, "sa", 2.0)
    with pytest.raises(ValueError, match="needs a period"):
        rf.intensity(ds, "sa")
    with pytest.raises(ValueError, match="im='cav' is not stored"):
        rf.intensity(ds, "cav")
    with pytest.raises(ValueError, match="by must be"):
        rf.ida_fragility(ds, by="nothing")


# ------------------------------------------------------------------ bands over theta and beta

_X = 0.5 * np.exp(np.array([-2.0, 2.0]) * 0.4)  # theta e^{-+2 beta} of theta 0.5, beta 0.4
_TRUE = stats.norm.cdf([-2.0, 2.0])


def _coverage(tables):
    """Share of fitted tables whose pointwise band of P holds the true P at each of _X."""
    hits = [
        (c.lower.values <= _TRUE) & (_TRUE <= c.upper.values)
        for c in (analysis.fragility_curve(t, _X).isel(group=0) for t in tables)
    ]
    return np.mean(hits, axis=0)


@pytest.mark.parametrize("n", [10, 30, 100])
def test_ida_bands_of_p_cover_the_true_fragility(n):
    # capacities drawn from the known lognormal: the 90 % pointwise bands hold the true P at
    # theta e^{-+2 beta} at least 85 % of the time (the bands that varied theta alone at the
    # point beta held it 54-72 % of the time)
    rng = np.random.default_rng(100 + n)
    tables = []
    for _ in range(150):
        c = 0.5 * np.exp(0.4 * rng.standard_normal(n))
        ds = _ida_dataset((c * G_UNIT)[:, None], np.ones(n), np.ones(n), [1.0], [1.0])
        tables.append(rf.ida_fragility(ds))
    assert tables[0].loc["all", "p_band"] == "noncentral_t"
    assert np.all(_coverage(tables) >= 0.85)


def test_censored_ida_bands_of_p_cover_the_true_fragility():
    rng = np.random.default_rng(3)
    top = 0.5 * np.exp(0.4)  # about 16 % of the blocks stand at the top of the range
    hits = []
    for _ in range(150):
        c = 0.5 * np.exp(0.4 * rng.standard_normal(30))
        cap, cens = c[c <= top], np.full((c > top).sum(), top)
        theta, beta = rf.fit_capacities(cap, cens)
        cov = fragility_fit.capacities_covariance(cap, cens, theta, beta)
        lo, hi = fragility_fit.probability_band(_X, theta, beta, 30, cov, "likelihood", 0.9)
        hits.append((lo <= _TRUE) & (_TRUE <= hi))
    assert np.all(np.mean(hits, axis=0) >= 0.85)
    # the IDA table of the last draw says the same through its band columns
    ds = _ida_dataset(
        (np.minimum(c, top) * G_UNIT)[:, None],
        np.ones(30),
        np.ones(30),
        [1.0],
        [1.0],
        (c > top)[:, None],
    )
    ds["capacity_scale_lower"] = ds["capacity_scale_lower"].where(~ds["censored"], top * G_UNIT)
    table = rf.ida_fragility(ds, n_boot=0)
    assert table.loc["all", "p_band"] == "likelihood"
    curve = analysis.fragility_curve(table, _X).isel(group=0)
    np.testing.assert_allclose([curve.lower.values, curve.upper.values], [lo, hi], rtol=1e-6)


def _cloud(level_g, overturned):
    y = np.asarray(overturned, bool)[:, None]
    return xr.Dataset(
        {
            "pga": ("record", np.asarray(level_g, float) * G_UNIT),
            "overturned": (("record", "structure"), y),
            "status": (("record", "structure"), np.zeros(y.shape, np.int64)),
        },
        coords={"structure": [0]},
        attrs={"design": "cloud"},
    )


def test_cloud_bands_of_p_cover_the_true_fragility():
    # clouds of 40 independent records, one level each, with the outcome "capacity <= level"
    rng = np.random.default_rng(4)
    tables = []
    for _ in range(150):
        level = 0.5 * np.exp(0.4 * rng.standard_normal(40))
        capacity = 0.5 * np.exp(0.4 * rng.standard_normal(40))
        tables.append(rf.stripe_fragility(_cloud(level, capacity <= level), n_boot=0))
    assert np.all(_coverage(tables) >= 0.85)


def test_binomial_covariance_matches_the_scatter_of_the_fits():
    # the covariance of (ln theta, ln beta) against the scatter of 300 independent refits
    rng = np.random.default_rng(5)
    level = 0.5 * np.exp(rng.uniform(-3, 3, 400) * 0.4)
    fits = []
    for _ in range(300):
        y = rng.random(level.size) < stats.norm.cdf(np.log(level / 0.5) / 0.4)
        fits.append(np.log(rf.fit_binomial(level, y, np.ones(level.size))))
    cov = fragility_fit.binomial_covariance(level, np.ones(level.size), 0.5, 0.4)
    np.testing.assert_allclose(np.cov(np.array(fits).T), cov, rtol=0.25, atol=0.1 * cov[0, 0])


def test_stripe_covariance_is_clustered_by_record():
    # the same outcome repeated for 4 blocks of each record: 4 times the points, no more
    # information; the sandwich clustered by record sees it, the independent information not
    rng = np.random.default_rng(6)
    level = 0.5 * np.exp(0.6 * rng.standard_normal(60))
    y = 0.5 * np.exp(0.4 * rng.standard_normal(60)) <= level
    one = rf.stripe_fragility(_cloud(level, y), n_boot=0)
    four = _cloud(level, y).isel(structure=[0, 0, 0, 0]).assign_coords(structure=np.arange(4))
    rep = rf.stripe_fragility(four, n_boot=0)
    assert rep.loc["all", "theta"] == pytest.approx(one.loc["all", "theta"], rel=1e-6)
    assert rep.loc["all", "var_ln_theta"] == pytest.approx(
        one.loc["all", "var_ln_theta"] * 60 / 59, rel=0.35
    )


def test_imefficiency_ranks_equal_measures_of_different_powers_equal():
    # Arias intensity exactly proportional to PGA^2 over the records: the same information;
    # ln(Arias) spreads twice as far, and beta / power ranks the two equal
    rng = np.random.default_rng(13)
    pga = rng.uniform(2.0, 8.0, 25)
    ds = _ida_dataset(rng.lognormal(0.0, 0.5, (25, 1)), pga, pga / 10, [1.0], [1.0])
    ds["arias"] = ("record", 0.03 * pga**2)
    t = rf.im_efficiency(ds, candidates=("pga", "arias"))
    assert t.loc[("arias", "all"), "beta"] == pytest.approx(2 * t.loc[("pga", "all"), "beta"])
    assert t.loc[("arias", "all"), "beta_linear"] == pytest.approx(
        t.loc[("pga", "all"), "beta_linear"], rel=1e-9
    )
    assert t.loc[("arias", "all"), "power"] == 2 == 2 * t.loc[("pga", "all"), "power"]


def test_the_scaling_power_is_the_measures_own():
    # the table against the measures of a record and of the record scaled by 3
    from rockstudy.motions import Record
    from rockstudy.motions.measures import MEASURES

    t = np.arange(0, 4.0, 0.01)
    y = 0.7 * np.cos(3 * np.pi * t) * np.exp(-0.5 * t)  # a second component for the RotD ones
    rec = Record(np.sin(2 * np.pi * t) * np.exp(-0.3 * t), acceleration_y=y, dt=0.01, name="x")
    for k, m in MEASURES.items():
        p = m.power
        period = 0.5 if m.needs_period else None
        a = rec.intensity_measure(k, period=period)
        b = rec.scaled(3.0).intensity_measure(k, period=period)
        assert b == pytest.approx(3.0**p * a, rel=1e-9), k


def test_bad_fragility_arguments_are_named():
    ida = _ida_dataset([[1.0], [2.0], [3.0]], [G_UNIT] * 3, [1.0] * 3, [1.0], [1.0])
    cloud = _cloud([0.1, 0.2, 0.3], [0, 1, 1])
    with pytest.raises(ValueError, match="ds: stripe_fragility needs a dataset of design 'cloud'"):
        rf.stripe_fragility(ida)
    with pytest.raises(ValueError, match="ds: ida_fragility needs a dataset of design 'ida'"):
        rf.ida_fragility(cloud)
    with pytest.raises(ValueError, match="candidates must be a non-empty"):
        rf.im_efficiency(ida, candidates=[])
    with pytest.raises(ValueError, match="candidates: 'pgz' is not one of"):
        rf.im_efficiency(ida, candidates=["pgz"])
    for fit, ds in ((rf.ida_fragility, ida), (rf.stripe_fragility, cloud)):
        for bad in (1.5, float("nan"), 0.0, True, "0.9"):
            with pytest.raises(ValueError, match="conf_level must be"):
                fit(ds, conf_level=bad)
        for bad in (-1, 2.5, True):
            with pytest.raises(ValueError, match=r"n_boot must be a whole number in \[0, 10000\]"):
                fit(ds, n_boot=bad)


def test_record_designs_carry_units():
    from rockstudy.motions import Record
    from rockstudy.motions.measures import MEASURES
    from rockstudy.study.designs.records import _record_dataset

    t = np.arange(0, 2.0, 0.01)
    rec = Record(np.sin(2 * np.pi * t), dt=0.01, name="x")
    st = {"critical_rotation": np.array([0.2]), "uplift_acceleration": np.array([G * np.tan(0.2)])}
    st["frequency_parameter"] = np.array([2.0])
    ds = _record_dataset([rec], st, np.array([0.5]), 0.05)
    stored = [k for k in MEASURES if k in ds]  # every registered measure the design keeps
    assert {"pga", "pgv", "sa"} <= set(stored)
    for k in stored:
        assert ds[k].attrs["units"] == MEASURES[k].unit, k
    assert ds["pga_ratio"].attrs["units"] == "1"


def test_capacities_that_share_a_record_are_not_counted_as_independent():
    """Six nearly equal blocks under each record: their capacities carry the record-to-record
    spread only once per record. Under one record there is no band at all; under 12 records
    drawn from a known lognormal, the 90 % band of the median covers the true median in about
    90 % of suites (the independent noncentral t over 72 capacities covered far less)."""
    blocks = np.linspace(1.0, 1.02, 6)
    one = _ida_dataset([2.0 * blocks], [1.0], [1.0], [1.0] * 6, [1.0] * 6)
    row = rf.ida_fragility(one, im="pga").loc["all"]
    assert row["p_band"] == "none" and np.isnan(row["theta_lo"])
    hits, runs = 0, 120
    for seed in range(runs):
        c = np.random.default_rng(seed).lognormal(np.log(0.5), 0.3, 12)  # per record [g]
        ds = _ida_dataset(
            (c * G_UNIT)[:, None] * blocks, np.ones(12), np.ones(12), [1.0] * 6, [1.0] * 6
        )
        r = rf.ida_fragility(ds, n_boot=200, seed=seed).loc["all"]
        assert r["p_band"] == "record_bootstrap"
        hits += r["theta_lo"] <= 0.5 * 1.01 <= r["theta_hi"]
    assert hits / runs >= 0.8


def test_ida_capacities_all_equal_are_flagged_not_given_a_zero_width_band():
    """Five records with one capacity (one record five times): beta = 0 is the MLE, but it
    measures no spread; the fit warns and gives no interval instead of theta_lo = theta_hi."""
    pga = np.full(5, 2.0)
    ds = _ida_dataset((np.full(5, 0.5) * G_UNIT / pga)[:, None], pga, pga / 10, [1.0], [2.7])
    with pytest.warns(UserWarning, match="all 0.5 g"):
        t = rf.ida_fragility(ds)
    row = t.loc["all"]
    assert row["theta"] == pytest.approx(0.5, rel=1e-12) and row["beta"] == 0.0
    assert np.isnan([row["theta_lo"], row["theta_hi"], row["beta_lo"], row["beta_hi"]]).all()
    assert row["p_band"] == "none"


def test_ida_lack_of_fit_is_shapiro_wilk_of_the_log_capacities_and_holds_its_level():
    """lack_of_fit_p of an IDA group is scipy's Shapiro-Wilk p of ln(capacity); on lognormal
    capacities it falls below 0.05 about 5 % of the time, and it rejects capacities drawn
    from two separate lognormals (two families of records)."""
    rng = np.random.default_rng(11)

    def fit(cap_g):
        n = cap_g.size
        ds = _ida_dataset((cap_g * G_UNIT)[:, None], np.ones(n), np.ones(n), [1.0], [1.0])
        return rf.ida_fragility(ds, n_boot=0).loc["all", "lack_of_fit_p"]

    cap = rng.lognormal(np.log(0.5), 0.3, 20)
    assert fit(cap) == pytest.approx(stats.shapiro(np.log(cap)).pvalue, rel=1e-12)
    level = np.mean([fit(rng.lognormal(np.log(0.5), 0.3, 20)) < 0.05 for _ in range(300)])
    assert 0.02 <= level <= 0.09
    two = np.concatenate(
        [rng.lognormal(np.log(0.2), 0.05, 15), rng.lognormal(np.log(1.5), 0.05, 15)]
    )
    assert fit(two) < 1e-3
