"""Analyses of cubes: Sobol' (SALib's analytic Ishigami indices through the study's own
design and analysis), fragility, collapse."""

import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from _helpers import ishigami_analytic, ishigami_cube, rocking_with_falls

from rockstudy.study import analysis, make_design, validate_text

SOBOL_PULSE = """
name = "sobol_pulse_design"
seed = 5
[sampler]
kind = "sobol"
n = 256
[structure]
kind = "block"
half_diagonal = { dist = "loguniform", low = 0.3, high = 5.0 }
slenderness = { dist = "uniform", low = 0.05, high = 0.35 }
restitution = { dist = "uniform", low = 0.75, high = 0.95 }
[motion]
kind = "pulse"
amplitude_ratio = { dist = "uniform", low = 1.0, high = 4.0 }
period = { dist = "loguniform", low = 0.1, high = 2.0 }
"""


def test_ishigami_indices_through_the_study_pipeline():
    ds, names = ishigami_cube()
    assert ds.sizes["sample"] == 2**13 * (len(names) + 2)  # Saltelli, first order
    table = analysis.sobol_indices(ds, "y", num_resamples=200)  # names from the study
    assert list(table.index) == names
    s1, st = ishigami_analytic()
    # within SALib's own confidence intervals (and a small absolute floor)
    assert np.all(np.abs(table["S1"] - s1) <= np.maximum(2 * table["S1_conf"], 0.02))
    assert np.all(np.abs(table["ST"] - st) <= np.maximum(2 * table["ST_conf"], 0.02))
    conv = analysis.sobol_convergence(ds, "y", num_resamples=50)
    ns = conv.index.get_level_values("N").unique()
    assert list(ns) == [2**k for k in range(4, 14)]
    err = [abs(conv.loc[(n, names[1]), "S1"] - s1[1]) for n in ns]
    assert err[-1] < err[0]


def test_failed_policy_for_sobol():
    ds, names = ishigami_cube(n=2**10)
    status = ds.status.values.copy()
    status[7] = 2
    bad = ds.assign(status=("sample", status))
    with pytest.raises(ValueError, match="failed"):
        analysis.sobol_indices(bad, "y")
    dropped = analysis.sobol_indices(bad, "y", failed="drop", num_resamples=20)
    assert dropped.shape == (3, 4)


def test_fragility_recovers_known_parameters():
    rng = np.random.default_rng(0)
    theta, beta = 2.5, 0.35
    im = np.exp(rng.uniform(np.log(0.5), np.log(10), 4000))
    p = 0.5 * (1 + np.vectorize(math.erf)(np.log(im / theta) / (beta * math.sqrt(2))))
    over = (rng.random(im.size) < p).astype(np.int8)
    size = np.where(rng.random(im.size) < 0.5, 1.0, 2.0)
    ds = xr.Dataset(
        {"pga_ratio": ("sample", im), "overturned": ("sample", over), "size": ("sample", size)}
    )
    table = analysis.fragility(ds, "pga_ratio", n_boot=100)
    row = table.loc["all"]
    assert row.theta == pytest.approx(theta, rel=0.05)
    assert row.beta == pytest.approx(beta, rel=0.1)
    assert row.theta_lo < theta < row.theta_hi
    assert row.theta_in_range and row.band_in_range
    by = analysis.fragility(ds, "pga_ratio", by="size", n_boot=20)
    assert set(by.index) == {1.0, 2.0}
    curve = analysis.fragility_curve(table, [1.0, 2.5, 8.0])
    np.testing.assert_allclose(curve.probability.sel(group="all").values[1], 0.5, atol=0.05)
    assert bool((curve.lower <= curve.upper + 1e-12).all())


def test_collapse_metric_zero_for_similar_one_for_noise():
    rng = np.random.default_rng(1)
    n_points, reps = 200, 5
    g1 = np.repeat(rng.uniform(1, 5, n_points), reps)
    g2 = np.repeat(rng.uniform(0.2, 1, n_points), reps)
    size = rng.uniform(0.5, 3, g1.size)  # a dimensional realization that does not matter
    similar = np.sin(g1) * g2
    ds = xr.Dataset(
        {
            "g1": ("sample", g1),
            "g2": ("sample", g2),
            "size": ("sample", size),
            "similar": ("sample", similar),
            "noise": ("sample", rng.random(g1.size)),
            "partly": ("sample", similar * size),
        }
    )
    assert analysis.collapse_metric(ds, "similar", ["g1", "g2"]) < 1e-12
    assert analysis.collapse_metric(ds, "noise", ["g1", "g2"]) > 0.7
    assert 0.05 < analysis.collapse_metric(ds, "partly", ["g1", "g2"]) < 0.9


def test_collapse_metric_refuses_a_design_without_replicated_group_points():
    """A Monte Carlo design (and the README's snippet on a sobol cube) has no two samples at
    one group point: the within-set variance is 0 by construction, so the metric would read
    'perfectly self-similar' for any response, even a dimensional one."""
    rng = np.random.default_rng(5)
    n = 2000
    g1, g2, size = rng.uniform(1, 5, n), rng.uniform(0.2, 1, n), rng.uniform(0.5, 3, n)
    ds = xr.Dataset(
        {
            "g1": ("sample", g1),
            "g2": ("sample", g2),
            "dimensional": ("sample", size * g1),  # depends on the size: not similar
        }
    )
    with pytest.raises(ValueError, match="unexplained_share"):
        analysis.collapse_metric(ds, "dimensional", ["g1", "g2"])


def test_collapse_metric_refuses_the_saltelli_coincidences():
    """In a Saltelli design of a pulse study, the rows that differ from their base row only in
    alpha share its (6.1) groups (g tan alpha / a_g, omega, eta): 2 of every 7 samples. Those
    pairs made the block size R itself look perfectly self-similar (metric 0.0)."""
    study = validate_text(SOBOL_PULSE)
    ds = make_design(study)
    with pytest.raises(ValueError, match="replicated design"):
        analysis.collapse_metric(ds, "half_diagonal", ["uplift_ratio", "omega", "restitution"])


def test_collapse_metric_counts_replicated_points_only():
    """K group points met twice with y = g -+ 1 (within-set SS 2K, total SS
    2 sum (g - mean g)^2 + 2K), plus samples at group points of their own, whose wild values
    must not dilute the share."""
    K = 50
    g = np.arange(K, dtype=float)
    keys = np.concatenate([g, g, 1000.0 + np.arange(20)])
    y = np.concatenate([g - 1, g + 1, np.full(20, 1e4)])
    ds = xr.Dataset({"g": ("sample", keys), "y": ("sample", y)})
    expected = 2 * K / (2 * np.sum((g - g.mean()) ** 2) + 2 * K)
    assert analysis.collapse_metric(ds, "y", ["g"]) == pytest.approx(expected, rel=1e-12)
    flat = ds.assign(y=("sample", np.ones(keys.size)))
    with pytest.raises(ValueError, match="constant"):
        analysis.collapse_metric(flat, "y", ["g"])


def test_unexplained_share_states_its_floor():
    """The floor is what the k-NN fit leaves for a response of the groups alone; an exactly
    similar response sits near it, a noisy one far above it, and it falls with n."""
    rng = np.random.default_rng(1)
    floors = []
    for n in (1000, 8000):
        g1, g2 = rng.uniform(1, 5, n), rng.uniform(0.2, 1, n)
        similar = np.tanh(2 * (g1 - 3)) * g2
        ds = xr.Dataset(
            {
                "g1": ("sample", g1),
                "g2": ("sample", g2),
                "similar": ("sample", similar),
                "noisy": ("sample", similar + 0.3 * rng.standard_normal(n)),
                "noise": ("sample", rng.random(n)),
            }
        )
        exact = analysis.unexplained_share(ds, "similar", ["g1", "g2"])
        assert isinstance(exact, analysis.UnexplainedShare)
        assert (exact.n, exact.k) == (n, 10)
        assert 0 < exact.value < 3 * exact.floor and exact.floor < 3 * exact.value
        noisy = analysis.unexplained_share(ds, "noisy", ["g1", "g2"])
        assert noisy.value > 5 * noisy.floor
        assert analysis.unexplained_share(ds, "noise", ["g1", "g2"]).value > 0.9
        floors.append(exact.floor)
    assert floors[1] < floors[0] / 2


def _fragility_data(theta, beta, im_range, n=4000, seed=0):
    rng = np.random.default_rng(seed)
    im = np.exp(rng.uniform(*np.log(im_range), n))
    p = 0.5 * (1 + np.vectorize(math.erf)(np.log(im / theta) / (beta * math.sqrt(2))))
    over = (rng.random(im.size) < p).astype(np.int8)
    return xr.Dataset({"pga_ratio": ("sample", im), "overturned": ("sample", over)})


def test_fragility_flags_a_median_outside_the_data():
    """Intensities sampled up to 2 while the true median capacity is 6: the data see only the
    lower tail, and the fitted median is an extrapolation the table must mark."""
    ds = _fragility_data(6.0, 0.5, (0.5, 2.0))
    row = analysis.fragility(ds, "pga_ratio", n_boot=50).loc["all"]
    assert row.im_min == pytest.approx(ds.pga_ratio.min()) and row.im_max <= 2.0
    assert row.theta > row.im_max
    assert not row.theta_in_range and not row.band_in_range
    inside = analysis.fragility(_fragility_data(1.0, 0.3, (0.5, 2.0)), "pga_ratio", n_boot=50)
    assert inside.loc["all"].theta_in_range and inside.loc["all"].band_in_range


def test_fragility_keeps_groups_whose_outcome_never_changes():
    """A block size that never overturns (or always does) has no curve to fit, but it is an
    answer: its median is not reached (inf) or lies below the sampled range (0)."""
    ds = _fragility_data(1.0, 0.3, (0.5, 2.0), n=600)
    n = ds.sizes["sample"]
    size = np.repeat([1.0, 2.0, 3.0], n // 3)
    over = ds.overturned.values.copy()
    over[size == 2.0], over[size == 3.0] = 0, 1
    ds = ds.assign(size=("sample", size), overturned=("sample", over))
    t = analysis.fragility(ds, "pga_ratio", by="size", n_boot=20)
    assert list(t.index) == [1.0, 2.0, 3.0]
    assert t.loc[2.0, "theta"] == np.inf and t.loc[2.0, "theta_hi"] == np.inf
    assert t.loc[3.0, "theta"] == 0.0 and np.isnan(t.loc[3.0, "beta"])
    assert not t.loc[[2.0, 3.0], "theta_in_range"].any()
    assert (t["n"] == n // 3).all()


def test_first_order_given_data_finds_the_driver():
    rng = np.random.default_rng(2)
    x = rng.random((4000, 3))
    ds = xr.Dataset({f"v{j}": ("sample", x[:, j]) for j in range(3)})
    ds["y"] = ("sample", np.sin(2 * np.pi * x[:, 0]) + 0.1 * x[:, 1])
    t = analysis.first_order_given_data(ds, "y", ["v0", "v1", "v2"])
    assert isinstance(t, pd.DataFrame)
    assert t.loc["v0", "S1"] > 0.8 and t.loc["v2", "S1"] < 0.1


def test_fragility_bands_of_p_cover_the_true_fragility():
    # independent Monte Carlo samples of a known lognormal fragility (theta 0.5, beta 0.4):
    # the 90 % pointwise bands of P hold the true P at theta e^{-+2 beta} at least 85 % of the
    # time over the two points, and 80 % at each (the former bands, theta alone at the point
    # beta: 53-64 %; with 200 samples the pooled share has a standard error of 1.5 %)
    x = 0.5 * np.exp(np.array([-2.0, 2.0]) * 0.4)
    true = np.array([0.022750131948179, 0.977249868051821])  # Phi(-+2)
    rng = np.random.default_rng(21)
    hits = []
    for _ in range(200):
        level = 0.5 * np.exp(rng.uniform(-3, 3, 150) * 0.4)
        over = (0.5 * np.exp(0.4 * rng.standard_normal(150)) <= level).astype(np.int8)
        ds = xr.Dataset({"im": ("sample", level), "overturned": ("sample", over)})
        c = analysis.fragility_curve(analysis.fragility(ds, "im", n_boot=0), x).isel(group=0)
        hits.append((c.lower.values <= true) & (true <= c.upper.values))
    assert np.mean(hits) >= 0.85 and np.all(np.mean(hits, axis=0) >= 0.8)


def test_fragility_bad_arguments_are_named():
    ds = xr.Dataset(
        {"im": ("sample", np.arange(1.0, 13.0)), "overturned": ("sample", np.arange(12) > 5)}
    )
    for bad in (1.5, float("nan"), -0.1):
        with pytest.raises(ValueError, match="conf_level must be"):
            analysis.fragility(ds, "im", conf_level=bad)
    with pytest.raises(ValueError, match=r"n_boot must be a whole number in \[0, 10000\]"):
        analysis.fragility(ds, "im", n_boot=-1)
    with pytest.raises(ValueError, match="'pga' is not a variable"):
        analysis.fragility(ds, "pga")
    with pytest.raises(ValueError, match="table: not a fragility table"):
        analysis.fragility_curve(ds.to_dataframe(), [1.0])


def test_first_order_of_a_rotation_warns_when_the_falls_are_in_it():
    """On every sample the falls give alpha a large index, and the call warns; on the
    survivors (as the report computes it) alpha has none and amplitude has it all."""
    ds = rocking_with_falls()
    names = ["slenderness", "amplitude_ratio"]
    with pytest.warns(UserWarning, match="fall rotation"):
        mixed = analysis.first_order_given_data(ds, "max_rotation_ratio", names)
    assert mixed.loc["slenderness", "S1"] > 0.3
    survivors = ds.where(ds.overturned == 0, drop=True)
    clean = analysis.first_order_given_data(survivors, "max_rotation_ratio", names)
    assert clean.loc["slenderness", "S1"] < 0.05 and clean.loc["amplitude_ratio", "S1"] > 0.9


def test_sobol_of_a_rotation_with_falls_warns():
    ds, names = ishigami_cube(n=2**8)
    over = (np.arange(ds.sizes["sample"]) % 5 == 0).astype(np.int8)
    ds = ds.assign(overturned=("sample", over), max_rotation_ratio=ds["y"])
    with pytest.warns(UserWarning, match="mix overturning with the rocking amplitude") as got:
        analysis.sobol_indices(ds, "max_rotation_ratio", num_resamples=10)
    assert {w.filename for w in got} == {__file__}, "the warning points at the caller's line"


def test_lack_of_fit_holds_its_level_and_rejects_a_probability_that_levels_off():
    """Outcomes drawn from a lognormal fragility: the Hosmer-Lemeshow p-value falls below
    0.05 in about 5 % of the fits (its nominal level). Outcomes whose probability levels off
    at 0.6 (a pulse too short to overturn the block whatever its strength) reject it."""
    from scipy.stats import norm

    rng = np.random.default_rng(8)
    p_values = []
    for _ in range(300):
        im = np.exp(rng.uniform(np.log(0.1), np.log(10.0), 600))
        over = (rng.uniform(size=im.size) < norm.cdf(np.log(im / 1.0) / 0.6)).astype(int)
        t = analysis.fragility(
            xr.Dataset({"im": ("sample", im), "o": ("sample", over)}), "im", outcome="o", n_boot=0
        )
        p_values.append(float(t["lack_of_fit_p"].iloc[0]))
    assert 0.02 <= np.mean(np.array(p_values) < 0.05) <= 0.09
    im = np.exp(rng.uniform(np.log(0.1), np.log(10.0), 600))
    levels_off = 0.6 * norm.cdf(np.log(im / 0.5) / 0.3)
    over = (rng.uniform(size=im.size) < levels_off).astype(int)
    t = analysis.fragility(
        xr.Dataset({"im": ("sample", im), "o": ("sample", over)}), "im", outcome="o", n_boot=0
    )
    assert float(t["lack_of_fit_p"].iloc[0]) < 1e-3
