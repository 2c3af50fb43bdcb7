"""The ``ds.rocking`` accessor of result cubes (rockstudy.study.analysis.accessor).

Oracles: outcomes drawn from known lognormal fragilities (the fit recovers theta and beta within
the sampling error), scipy's lognormal MLE of uncensored IDA capacities (``norm.fit``), a direct
maximisation of the Bernoulli likelihood by scipy, the analytic Sobol' indices of the Ishigami
function, the within-set share of pure noise in a replicated design ((k - 1) / k), Cornell's
closed form of the annual rate, and flags counted by hand. Each cube kind must reach the fit
its kind calls for, and a keyword or a Dataset the accessor cannot serve is refused by name.
"""

import ast
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from _helpers import constructed_ida, ishigami_analytic, ishigami_cube
from _helpers import ida_dataset as _ida_dataset
from scipy import optimize, stats

import rockstudy.study  # noqa: F401 - registers ds.rocking
from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.constants import G
from rockstudy.study import load_study, make_design, validate_text
from rockstudy.study.analysis import fragility_fit, record_fragility, record_similarity, sampled
from rockstudy.study.analysis import risk as object_risk_module

MC = """
name = "accessor_mc"
seed = 2
[sampler]
kind = "monte_carlo"
n = 4000
replicates = 4
[structure]
kind = "block"
half_diagonal = { dist = "loguniform", low = 0.3, high = 3.0 }
slenderness = { dist = "uniform", low = 0.1, high = 0.3 }
restitution = { dist = "uniform", low = 0.7, high = 0.9 }
[motion]
kind = "pulse"
amplitude_ratio = { dist = "loguniform", low = 0.5, high = 8.0 }
frequency_ratio = { dist = "loguniform", low = 0.5, high = 8.0 }
"""


def _probit(x, theta, beta):
    return stats.norm.cdf(np.log(x / theta) / beta)


@pytest.fixture(scope="module")
def mc_cube():
    """A replicated Monte Carlo cube (4000 group points x 4) whose outcomes are drawn from a
    known lognormal fragility in amplitude_ratio: median 1.5 for blocks under R = 1 m, 3.0
    above, beta 0.4."""
    study = validate_text(MC)
    ds = make_design(study)
    rng = np.random.default_rng(7)
    theta = np.where(ds["half_diagonal"].values < 1.0, 1.5, 3.0)
    p = _probit(ds["amplitude_ratio"].values, theta, 0.4)
    ds["overturned"] = ("sample", (rng.random(p.size) < p).astype(np.int8))
    ds["status"] = ("sample", np.ones(p.size, np.int8))
    ds.attrs["study"] = study.normalized()
    return ds


def test_monte_carlo_fragility_recovers_the_known_lognormal(mc_cube):
    assert mc_cube.rocking.kind == "monte_carlo"
    assert mc_cube.rocking.study.name == "accessor_mc"
    table = mc_cube.rocking.fragility("amplitude_ratio", by="half_diagonal", bins=[0.3, 1, 3.1])
    low, high = table.iloc[0], table.iloc[1]
    # ~8000 Bernoulli trials per group over the whole curve: theta to ~1.5 %, beta to ~3 %
    assert low.theta == pytest.approx(1.5, rel=0.05) and high.theta == pytest.approx(3.0, rel=0.05)
    assert low.beta == pytest.approx(0.4, rel=0.1) and high.beta == pytest.approx(0.4, rel=0.1)
    assert low.theta_lo < 1.5 < low.theta_hi and high.theta_lo < 3.0 < high.theta_hi


def test_the_fit_of_an_ida_is_scipys_lognormal_mle_of_the_capacities():
    rng = np.random.default_rng(3)
    n_rec, pga = 40, rng.uniform(2.0, 6.0, 40)
    cap_g = 0.35 * np.exp(0.45 * rng.standard_normal(n_rec))  # capacities in g of PGA
    ds = _ida_dataset((cap_g * G_UNIT / pga)[:, None], pga, pga / 8, [1.0], [2.0])
    assert ds.rocking.kind == "ida"
    row = ds.rocking.fragility(n_boot=0).loc["all"]
    mu, sigma = stats.norm.fit(np.log(cap_g))  # scipy's MLE (dividing by n)
    assert row.theta == pytest.approx(np.exp(mu), rel=1e-10)
    assert row.beta == pytest.approx(sigma, rel=1e-10)
    assert row.p_band == "noncentral_t"  # the capacity fit's exact band, not the binomial's


def _stripes(levels, overturned, pga):
    y = np.asarray(overturned)
    ds = xr.Dataset(
        {
            "pga": ("record", pga),
            "overturned": (("record", "structure", "level"), y),
            "status": (("record", "structure", "level"), np.zeros(y.shape, np.int64)),
        },
        coords={"level": levels * G_UNIT, "structure": [0]},
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan},
    )
    scale = xr.DataArray(levels * G_UNIT, dims="level") / ds["pga"]
    return ds.assign(scale=scale.broadcast_like(ds["overturned"]))


def _bernoulli_mle(x, y):
    """(theta, beta) maximising sum y ln P + (1 - y) ln(1 - P), by Nelder-Mead on scipy's
    normal log-cdf (no code of the package)."""

    def nll(q):
        u = (np.log(x) - q[0]) / np.exp(q[1])
        return -np.sum(y * stats.norm.logcdf(u) + (1 - y) * stats.norm.logsf(u))

    q = optimize.minimize(
        nll,
        [np.mean(np.log(x)), 0.0],
        method="Nelder-Mead",
        options={"xatol": 1e-9, "fatol": 1e-12},
    ).x
    return np.exp(q[0]), np.exp(q[1])


def test_stripes_and_clouds_get_the_binomial_fit():
    rng = np.random.default_rng(11)
    levels, n_rec = np.geomspace(0.1, 1.0, 8), 300
    y = rng.random((n_rec, 1, 8)) < _probit(levels, 0.35, 0.45)
    ds = _stripes(levels, y, rng.uniform(1.0, 5.0, n_rec))
    assert ds.rocking.kind == "stripes"
    row = ds.rocking.fragility(n_boot=0).loc["all"]
    assert row.p_band == "likelihood"
    assert row.theta == pytest.approx(0.35, rel=0.07) and row.beta == pytest.approx(0.45, rel=0.15)
    x = np.broadcast_to(levels, y.shape).ravel()
    np.testing.assert_allclose([row.theta, row.beta], _bernoulli_mle(x, y.ravel()), rtol=1e-5)
    # a cloud: each record at its own PGA, one Bernoulli trial each
    level_g = np.exp(rng.uniform(np.log(0.05), np.log(2.0), 400))
    over = rng.random(400) < _probit(level_g, 0.5, 0.6)
    cloud = xr.Dataset(
        {
            "pga": ("record", level_g * G_UNIT),
            "overturned": (("record", "structure"), over[:, None]),
            "status": (("record", "structure"), np.zeros((400, 1), np.int64)),
        },
        coords={"structure": [0]},
        attrs={"design": "cloud"},
    )
    row = cloud.rocking.fragility(im="pga", n_boot=0).loc["all"]
    np.testing.assert_allclose([row.theta, row.beta], _bernoulli_mle(level_g, over), rtol=1e-5)
    assert row.theta == pytest.approx(0.5, rel=0.15) and row.beta == pytest.approx(0.6, rel=0.25)


def test_keywords_that_do_not_apply_to_the_kind_are_named(mc_cube):
    ida = constructed_ida([0.2, 0.5, 1.1])
    with pytest.raises(ValueError, match="'outcome' does not apply to a 'ida' cube"):
        ida.rocking.fragility(outcome="overturned")
    with pytest.raises(ValueError, match="'period' does not apply to a 'monte_carlo' cube"):
        mc_cube.rocking.fragility("amplitude_ratio", period=1.0)
    with pytest.raises(ValueError, match="im is required") as err:
        mc_cube.rocking.fragility()
    named = re.search(r"inputs (\[.*\])", str(err.value)).group(1)
    for name in ast.literal_eval(named):  # only the cube's own inputs, no outputs
        assert name in mc_cube.data_vars and name not in mc_cube.rocking.study.run.outputs
    assert "amplitude_ratio" in named
    with pytest.raises(
        ValueError, match=r"^im: 'amplitud_ratio' is not a variable.*'amplitude_ratio'"
    ):
        mc_cube.rocking.fragility("amplitud_ratio")
    with pytest.raises(ValueError, match="efficiency: needs a record design"):
        mc_cube.rocking.efficiency()
    with pytest.raises(ValueError, match="risk: needs a record design"):
        mc_cube.rocking.risk(risk.HazardCurve.power_law(1e-4, 2.0, im="pga", units="g"))
    with pytest.raises(ValueError, match="sobol: applies to sampled studies"):
        ida.rocking.sobol("overturned")
    with pytest.raises(ValueError, match="need a sobol study"):  # the analysis' own refusal
        mc_cube.rocking.sobol("overturned")
    with pytest.raises(ValueError, match="'response' does not apply to a 'ida' record design"):
        ida.rocking.collapse("max_rotation")
    with pytest.raises(ValueError, match="'decimals' does not apply to a 'ida' cube"):
        ida.rocking.collapse(decimals=3)
    with pytest.raises(ValueError, match="'size_bins' does not apply to a 'monte_carlo' cube"):
        mc_cube.rocking.collapse("overturned", ["omega"], size_bins=3)
    with pytest.raises(ValueError, match="'candidates' does not apply"):
        ida.rocking.fragility(candidates=["pga"])
    with pytest.raises(ValueError, match="hazard is required"):
        ida.rocking.risk()
    with pytest.raises(ValueError, match="friction is required"):
        ida.rocking.contact()
    with pytest.raises(ValueError, match="no 'study' attribute"):
        ida.rocking.study  # noqa: B018


def test_a_dataset_that_is_not_a_cube_is_refused_naming_what_is_missing():
    plain = xr.Dataset({"pga_ratio": ("sample", [1.0, 2.0]), "overturned": ("sample", [0, 1])})
    with pytest.raises(ValueError, match="no 'study' attribute .* no 'design' attribute"):
        plain.rocking.fragility("pga_ratio")
    with pytest.raises(ValueError, match="no 'study' attribute"):
        plain.rocking.kind  # noqa: B018
    odd = plain.assign_attrs(design="tornado")
    with pytest.raises(ValueError, match=r"attrs\['design'\] must be one of"):
        odd.rocking.contact(0.5)


def test_sobol_indices_of_the_ishigami_function():
    ds, names = ishigami_cube(n=2**12)
    assert ds.rocking.kind == "sobol"
    table = ds.rocking.sobol("y", num_resamples=100)
    s1, st = ishigami_analytic()
    assert list(table.index) == names
    assert np.all(np.abs(table["S1"] - s1) <= np.maximum(2 * table["S1_conf"], 0.03))
    assert np.all(np.abs(table["ST"] - st) <= np.maximum(2 * table["ST_conf"], 0.03))
    conv = ds.rocking.sobol_convergence("y", num_resamples=20)
    assert list(conv.index.get_level_values("N").unique()) == [2**k for k in range(4, 13)]
    np.testing.assert_allclose(conv.loc[2**12, "S1"].values, table["S1"].values, atol=0.02)


def test_collapse_of_a_replicated_design(mc_cube):
    groups = ["uplift_ratio", "omega", "restitution"]
    # a response of the groups alone has no variance within a group point
    law = mc_cube["uplift_ratio"] * np.sin(mc_cube["omega"]) + mc_cube["restitution"]
    assert mc_cube.assign(law=law).rocking.collapse("law", groups) == pytest.approx(0, abs=1e-12)
    # pure noise: the within-set share of k = 4 replicates is (k - 1) / k
    noise = np.random.default_rng(1).standard_normal(mc_cube.sizes["sample"])
    share = mc_cube.assign(noise=("sample", noise)).rocking.collapse("noise", groups)
    assert share == pytest.approx(0.75, abs=0.02)
    # the cross-check of designs without replicates: noise is left unexplained, the law not
    left = mc_cube.assign(law=law, noise=("sample", noise)).rocking
    assert left.unexplained_share("noise", groups).value > 0.9
    assert left.unexplained_share("law", groups).value < 0.05
    # first-order indices on the groups: the law depends on uplift_ratio and omega only
    s1 = left.first_order_given_data("law", groups)["S1"]
    assert s1["restitution"] < 0.05 < s1["uplift_ratio"]


def test_collapse_of_a_record_design_spreads_the_known_medians():
    theta = np.array([0.2, 0.5, 1.1])
    medians, spread = constructed_ida(theta).rocking.collapse(size_bins=3, n_boot=20)
    np.testing.assert_allclose(medians["theta"], theta, rtol=1e-12)  # the design's own im
    assert spread.loc["all", "ratio"] == pytest.approx(1.1 / 0.2, rel=1e-12)


def test_efficiency_ranks_the_collapsing_measure_first():
    rng = np.random.default_rng(12)
    n_rec, p = 30, np.array([1.5, 3.0, 6.0])
    uplift = G * np.tan(np.array([0.2, 0.15, 0.25]))
    pga, pgv = rng.uniform(2, 8, n_rec), rng.uniform(0.2, 1.0, n_rec)
    target = 1.2 * np.exp(0.05 * rng.standard_normal((n_rec, 3)))  # capacities in PGV ratio
    ds = _ida_dataset(target * uplift / (pgv[:, None] * p), pga, pgv, uplift, p)
    table = ds.rocking.efficiency(["pga", "pgv", "pga_ratio", "pgv_ratio"], n_boot=20)
    assert table.index[0][0] == "pgv_ratio"
    assert table.loc[("pgv_ratio", "all"), "beta"] == pytest.approx(np.std(np.log(target)))
    with pytest.raises(ValueError, match="'period' does not apply"):
        ds.rocking.efficiency(period=1.0)


def test_risk_of_a_known_capacity_matches_cornell():
    k0, k, theta, beta = 2e-4, 2.3, 0.4, 0.3
    ds = constructed_ida([theta], beta=beta, n_rec=41)  # MLE median theta, dispersion ~beta
    hazard = risk.HazardCurve.power_law(k0, k, im="pga", units="g")
    out = ds.rocking.risk(hazard, years=30.0, n_boot=0)
    b = float(out["beta"][0])
    exact = k0 * theta**-k * np.exp(0.5 * (k * b) ** 2)  # Cornell et al. (2002)
    assert float(out["annual_rate"][0]) == pytest.approx(exact, rel=1e-3)
    assert float(out["probability"][0]) == pytest.approx(1 - np.exp(-30 * exact), rel=1e-3)


CLOUD = """
name = "accessor_cloud"
seed = 5
friction = 0.4
[sampler]
kind = "lhs"
n = 20
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.3, high = 1.2 }}
slenderness = {{ dist = "uniform", low = 0.15, high = 0.25 }}
[motion]
kind = "record"
files = "{records}/*.AT2"
[design]
kind = "cloud"
[hazard]
kind = "power_law"
im = "pga"
units = "g"
k0 = 2e-4
k = 2.3
years = 30
[run]
outputs = ["max_rotation", "overturned"]
"""


@pytest.fixture
def raw_record_cube(records_dir, tmp_path):
    """A cloud study's cube as the store writes it (one row per scene, on ``sample``), saved
    with to_zarr and read back with xarray alone; outcomes drawn from a lognormal fragility in
    PGA (median 0.25 g, beta 0.5), friction demands drawn at random."""
    path = tmp_path / "cloud.toml"
    path.write_text(CLOUD.format(records=records_dir))
    study = load_study(path)
    ds = make_design(study, tmp_path)
    rng = np.random.default_rng(5)
    n, n_rec = ds.sizes["sample"], len(json.loads(ds.attrs["record_names"]))
    pga = np.geomspace(0.05, 0.8, n_rec)[ds["record"].values] * G_UNIT
    over = rng.random(n) < _probit(pga / G_UNIT, 0.25, 0.5)
    ds = ds.assign(
        pga=("sample", pga),
        overturned=("sample", over.astype(np.int8)),
        censored=("sample", np.zeros(n, np.int8)),
        friction_demand=("sample", rng.uniform(0.1, 0.6, n)),
        lift_off=("sample", (rng.random(n) < 0.1).astype(np.int8)),
        kernel_status=("sample", np.zeros(n, np.int8)),
        status=("sample", np.ones(n, np.int8)),
    )
    ds.attrs["study"] = study.normalized()
    ds.to_zarr(tmp_path / "cube.zarr", zarr_format=2)
    return xr.open_zarr(tmp_path / "cube.zarr"), pga / G_UNIT, over


def test_a_record_study_cube_read_by_xarray_is_folded_and_uses_its_study(raw_record_cube):
    ds, pga_g, over = raw_record_cube
    assert "sample" in ds.dims and ds.rocking.kind == "cloud"
    row = ds.rocking.fragility(n_boot=0).loc["all"]
    np.testing.assert_allclose([row.theta, row.beta], _bernoulli_mle(pga_g, over), rtol=1e-5)
    # the study's [hazard] (power law, 30 years) is the default of risk
    out = ds.rocking.risk(n_boot=0)
    assert out.attrs["years"] == 30.0
    t, b = out["theta"].values, out["beta"].values
    fitted = np.isfinite(b)
    exact = 2e-4 * t[fitted] ** -2.3 * np.exp(0.5 * (2.3 * b[fitted]) ** 2)
    np.testing.assert_allclose(out["annual_rate_lognormal"].values[fitted], exact, rtol=1e-3)
    # horizontal records and a PGA hazard: the fragility is 0 below each uplift PGA (g
    # tan(alpha) of these blocks), except for the objects that these drawn outcomes
    # overturned below it (which the physics forbids): those keep the whole lognormal
    up_g = ds["uplift_acceleration"].values / G_UNIT  # per sample
    st = ds["structure"].values
    impossible = {j: bool(np.any(over[st == j] & (pga_g[st == j] < up_g[st == j]))) for j in st}
    refused = np.array([impossible[j] for j in out["structure"].values])
    np.testing.assert_array_equal(out["overturned_below_uplift"].values, refused)
    np.testing.assert_array_equal(out["truncated_at_uplift"].values, ~refused)
    assert refused.any() and not refused.all()
    cut = fitted & ~refused
    t, b, u = out["theta"].values[cut], out["beta"].values[cut], out["uplift"].values[cut]
    z = np.log(u / t) / b
    below = 2e-4 * u**-2.3 * stats.norm.cdf(z)
    above = 2e-4 * t**-2.3 * np.exp(0.5 * (2.3 * b) ** 2) * stats.norm.cdf(-z - 2.3 * b)
    np.testing.assert_allclose(out["annual_rate"].values[cut], below + above, rtol=1e-9)
    kept = fitted & refused
    whole = out["annual_rate_lognormal"].values[kept]
    np.testing.assert_array_equal(out["annual_rate"].values[kept], whole)
    # the study's friction (0.4) is the default of contact: demand above it, or lift-off
    flags = ds.rocking.contact()
    expected = (ds["friction_demand"].values > 0.4) | (ds["lift_off"].values == 1)
    n_rec = len(json.loads(ds.attrs["record_names"]))
    assert flags.dims == ("record", "structure")
    np.testing.assert_array_equal(flags.values, expected.reshape(n_rec, -1))


def test_rockstudy_study_on_first_use_registers_the_accessor(tmp_path):
    """``import rockstudy`` stays light (no study layer, no xarray); its ``study`` attribute
    loads the study layer, which registers ``ds.rocking``."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    code = (
        "import sys, rockstudy as rs\n"
        "light = 'rockstudy.study' not in sys.modules and 'xarray' not in sys.modules\n"
        "import xarray as xr\n"
        "before = hasattr(xr.Dataset, 'rocking')\n"
        "rs.study\n"
        "print(light, before, hasattr(xr.Dataset, 'rocking'))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.split() == ["True", "False", "True"]


def test_every_fragility_fit_is_the_shared_modules():
    """One lognormal/Bernoulli fitting module: the fits every analysis calls are those of
    fragility_fit, and no other module of the study layer runs an optimiser of its own but
    nested_fit, the joint fit of nested limits (one dispersion, ordered medians)."""
    for module in (sampled, record_fragility, record_similarity, object_risk_module):
        for name in ("fit_binomial", "fit_binomial_limit", "fit_capacities", "separation"):
            if hasattr(module, name):
                assert getattr(module, name) is getattr(fragility_fit, name), (module, name)
    study = Path(fragility_fit.__file__).resolve().parents[1]
    optimisers = []
    for path in study.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            if any(n.startswith("scipy.optimize") or n == "scipy.optimize" for n in names):
                optimisers.append(path.name)
    assert sorted(optimisers) == ["fragility_fit.py", "nested_fit.py"], optimisers


def test_bins_without_by_and_misspelt_variables_are_refused_by_name(mc_cube):
    with pytest.raises(ValueError, match=r"^bins: .*give by="):
        mc_cube.rocking.fragility("uplift_ratio", bins=[0.5, 1.0, 2.0])
    with pytest.raises(ValueError, match=r"^by: 'restitutoin' .*did you mean 'restitution'"):
        mc_cube.rocking.fragility("uplift_ratio", by="restitutoin")
