"""Analyses of cubes: Sobol' (SALib's Ishigami through our code), fragility, collapse."""

import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from rockstudy.study import analysis


def ishigami_cube(n=2**13, seed=3):
    from SALib.sample import sobol as sobol_sample
    from SALib.test_functions import Ishigami

    problem = {"num_vars": 3, "names": ["x1", "x2", "x3"], "bounds": [[-math.pi, math.pi]] * 3}
    x = sobol_sample.sample(problem, n, calc_second_order=False, seed=seed)
    y = Ishigami.evaluate(x)
    ds = xr.Dataset({"y": ("sample", y), "status": ("sample", np.ones(y.size, np.int8))})
    for j, name in enumerate(problem["names"]):
        ds[name] = ("sample", x[:, j])
    return ds


def ishigami_analytic(a=7.0, b=0.1):
    v1 = 0.5 * (1 + b * math.pi**4 / 5) ** 2
    v2 = a * a / 8
    v13 = b * b * math.pi**8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return np.array([v1, v2, 0.0]) / v, np.array([v1 + v13, v2, v13]) / v


def test_ishigami_indices_through_our_analysis():
    ds = ishigami_cube()
    table = analysis.sobol_indices(
        ds, "y", names=["x1", "x2", "x3"], second_order=False, num_resamples=200
    )
    s1, st = ishigami_analytic()
    # within SALib's own confidence intervals (and a small absolute floor)
    assert np.all(np.abs(table["S1"] - s1) <= np.maximum(2 * table["S1_conf"], 0.02))
    assert np.all(np.abs(table["ST"] - st) <= np.maximum(2 * table["ST_conf"], 0.02))
    conv = analysis.sobol_convergence(
        ds, "y", names=["x1", "x2", "x3"], second_order=False, num_resamples=50
    )
    ns = conv.index.get_level_values("N").unique()
    assert list(ns) == [2**k for k in range(4, 14)]
    err = [abs(conv.loc[(n, "x2"), "S1"] - s1[1]) for n in ns]
    assert err[-1] < err[0]


def test_failed_policy_for_sobol():
    ds = ishigami_cube(n=2**10)
    status = ds.status.values.copy()
    status[7] = 2
    bad = ds.assign(status=("sample", status))
    with pytest.raises(ValueError, match="failed"):
        analysis.sobol_indices(bad, "y", names=["x1", "x2", "x3"], second_order=False)
    dropped = analysis.sobol_indices(
        bad, "y", names=["x1", "x2", "x3"], second_order=False, failed="drop", num_resamples=20
    )
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
    # the smooth-fit cross-check on an unreplicated design
    assert analysis.unexplained_share(ds, "similar", ["g1", "g2"]) < 0.02
    assert analysis.unexplained_share(ds, "noise", ["g1", "g2"]) > 0.9


def test_first_order_given_data_finds_the_driver():
    rng = np.random.default_rng(2)
    x = rng.random((4000, 3))
    ds = xr.Dataset({f"v{j}": ("sample", x[:, j]) for j in range(3)})
    ds["y"] = ("sample", np.sin(2 * np.pi * x[:, 0]) + 0.1 * x[:, 1])
    t = analysis.first_order_given_data(ds, "y", ["v0", "v1", "v2"])
    assert isinstance(t, pd.DataFrame)
    assert t.loc["v0", "S1"] > 0.8 and t.loc["v2", "S1"] < 0.1
