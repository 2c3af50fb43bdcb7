"""The fragility and annual rate of each damage state (rockstudy.study.analysis.states),
against independent oracles: the binomial likelihood of the points that reached a state,
maximised here by scipy in its probit form; the closed-form lognormal MLE of complete
capacities; and Cornell et al.'s closed form k0 theta^-k exp(k^2 beta^2 / 2) on a power-law
hazard."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from scipy import optimize, stats

from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.study.analysis import states as st
from rockstudy.study.analysis.risk import object_risk

NAMES = ["Amphora", "Bronze"]
ALPHA = np.array([0.2, 0.3])
LEVELS_G = np.array([0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.3])  # PGA [g]
STATES = {"chipped": 0.25, "displaced": 0.5, "overturned": 1.0}
K0, K = 1e-4, 2.5


def _capacities(n_rec, theta, beta, seed):
    """Lognormal capacities [g] of n_rec records (rows) x len(theta) objects."""
    z = np.random.default_rng(seed).standard_normal((n_rec, len(theta)))
    return np.asarray(theta) * np.exp(np.asarray(beta) * z)


def _stripes(n_rec=25, seed=3):
    """Stripes of two objects at PGA levels x [g]: under a record of 'capacity' C an object
    rocks to max_rotation = alpha x / C and overturns where x > C (max_rotation pi/2)."""
    c = _capacities(n_rec, [0.4, 0.6], [0.4, 0.5], seed)
    x = np.broadcast_to(LEVELS_G, (n_rec, 2, LEVELS_G.size)).copy()
    ratio = x / c[:, :, None]
    over = ratio > 1.0
    dims = ("record", "structure", "level")
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),  # scale = PGA in g
            "scale": (dims, x),
            "max_rotation": (dims, np.where(over, np.pi / 2, ratio * ALPHA[None, :, None])),
            "overturned": (dims, over),
            "status": (dims, np.zeros(x.shape, int)),
            "critical_rotation": ("structure", ALPHA),
        },
        coords={
            "record": np.arange(n_rec),
            "structure": np.array(NAMES, dtype=object),
            "level": LEVELS_G,
        },
        attrs={"design": "stripes", "im": "pga", "im_period": np.nan},
    )
    ds.attrs["damage_states"] = json.dumps(STATES)
    return ds, x, ratio, over


def _probit_mle(x, y):
    """(theta, beta) maximising the binomial likelihood of Phi(a + b ln x), by BFGS:
    theta = exp(-a / b), beta = 1 / b."""

    def nll(p):
        z = p[0] + p[1] * np.log(x)
        return -np.sum(y * stats.norm.logcdf(z) + (1 - y) * stats.norm.logsf(z))

    best = optimize.minimize(nll, [0.0, 2.0], method="BFGS", options={"gtol": 1e-10})
    a, b = best.x
    return np.exp(-a / b), 1.0 / b


@pytest.mark.parametrize("name", list(STATES))
def test_stripes_state_fragility_is_the_binomial_mle_of_reaching_it(name):
    """P(state | PGA): the binomial MLE of 'rocked to at least limit x alpha, or
    overturned' at each point (the overturning state: overturned alone)."""
    ds, x, ratio, over = _stripes()
    table = st.state_fragility(ds, states=name, n_boot=0)
    for j, obj in enumerate(NAMES):
        y = (ratio[:, j] >= STATES[name]) | over[:, j]
        theta, beta = _probit_mle(x[:, j].ravel(), y.ravel().astype(float))
        row = table.loc[(name, obj)]
        assert row["theta"] == pytest.approx(theta, rel=1e-4)
        assert row["beta"] == pytest.approx(beta, rel=1e-4)


def _ida(n_rec=30, seed=5, vertical=True):
    """An IDA of two objects at PGA = scale g: overturning capacity C, state capacities
    0.3 C (chipped), 0.6 C (displaced) and, on the slide, 0.8 C (fall_off)."""
    c = _capacities(n_rec, [0.5, 0.7], [0.35, 0.5], seed)
    factors = {"chipped": 0.3, "displaced": 0.6, "fall_off": 0.8, "overturned": 1.0}
    rs = ("record", "structure")
    ds = xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, STANDARD_GRAVITY)),
            "capacity_scale": (rs, c),
            "capacity_scale_lower": (rs, c * 0.99),
            "censored": (rs, np.zeros(c.shape, bool)),
            "status": (rs, np.zeros(c.shape, int)),
            "state_capacity_scale": (
                ("damage_state",) + rs,
                np.stack([f * c for f in factors.values()]),
            ),
            "step_max_slide": (rs + ("step",), np.zeros(c.shape + (1,))),
            "vertical_component": ("record", np.full(n_rec, vertical)),
            "uplift_acceleration": ("structure", np.array([0.03, 0.03]) * STANDARD_GRAVITY),
        },
        coords={
            "record": np.arange(n_rec),
            "structure": np.array(NAMES, dtype=object),
            "damage_state": list(factors),
        },
        attrs={"design": "ida", "im": "pga", "im_period": np.nan},
    )
    states = {"chipped": 0.25, "displaced": 0.5, "fall_off": {"slide": 0.1}, "overturned": 1.0}
    ds.attrs["damage_states"] = json.dumps(states)
    return ds, {k: f * c for k, f in factors.items()}


def _lognormal_mle(c):
    """(theta, beta) of complete capacities: exp(mean ln c), std(ln c) dividing by n."""
    return float(np.exp(np.mean(np.log(c)))), float(np.std(np.log(c)))


def test_ida_state_fragility_fits_each_states_capacities():
    ds, expected = _ida()
    table = st.state_fragility(ds, n_boot=0)
    assert list(table.index.get_level_values("damage_state").unique()) == list(expected)
    for name, caps in expected.items():
        for j, obj in enumerate(NAMES):
            theta, beta = _lognormal_mle(caps[:, j])
            assert table.loc[(name, obj), "theta"] == pytest.approx(theta, rel=1e-9)
            assert table.loc[(name, obj), "beta"] == pytest.approx(beta, rel=1e-9)


def test_annual_rate_per_state_is_cornells_closed_form():
    """lambda(state) = k0 theta^-k exp(k^2 beta^2 / 2) on a power-law hazard k0 x^-k for
    the lognormal fit of each state's capacities (records with a vertical component: no
    cut at the uplift PGA)."""
    ds, expected = _ida()
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = st.state_risk(ds, hazard, n_boot=0, min_overturning=1)
    assert out["annual_rate"].dims == ("damage_state", "structure")
    assert list(out["structure"].values) == NAMES
    assert list(out["damage_demand"].values) == ["rotation_ratio"] * 2 + ["slide", "rotation_ratio"]
    for name, caps in expected.items():
        for j, obj in enumerate(NAMES):
            theta, beta = _lognormal_mle(caps[:, j])
            got = out.sel(damage_state=name, structure=obj)
            closed = K0 * theta**-K * np.exp(K**2 * beta**2 / 2)
            assert float(got["annual_rate"]) == pytest.approx(closed, rel=1e-9)
            assert int(got["n_reaching"]) == caps.shape[0]
    rates = out["annual_rate"].sel(structure=NAMES[0]).values
    assert np.all(np.diff(rates) < 0)  # the nested states, rarer and rarer


def test_the_overturning_state_is_object_risk_and_a_slide_state_is_not_cut():
    """On horizontal records the overturning state's rate is object_risk's (cut at the
    uplift PGA), a rotation state is cut too, a slide state takes the whole lognormal
    (Cornell's closed form)."""
    ds, expected = _ida(vertical=False)
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    out = st.state_risk(ds, hazard, n_boot=0, min_overturning=1)
    plain = object_risk(ds, hazard, n_boot=0, min_overturning=1).sel(structure=NAMES)
    np.testing.assert_array_equal(
        out["annual_rate"].sel(damage_state="overturned").values, plain["annual_rate"].values
    )
    assert out["truncated_at_uplift"].sel(damage_state="chipped").values.all()
    assert not out["truncated_at_uplift"].sel(damage_state="fall_off").values.any()
    for j, obj in enumerate(NAMES):
        theta, beta = _lognormal_mle(expected["fall_off"][:, j])
        closed = K0 * theta**-K * np.exp(K**2 * beta**2 / 2)
        got = float(out["annual_rate"].sel(damage_state="fall_off", structure=obj))
        assert got == pytest.approx(closed, rel=1e-9)


def test_states_are_named_and_a_design_without_them_is_refused():
    ds, _ = _ida()
    with pytest.raises(ValueError, match=r"no damage states \['broken'\]"):
        st.state_fragility(ds, states=["broken"], n_boot=0)
    bare = ds.copy()
    bare.attrs = {k: v for k, v in ds.attrs.items() if k != "damage_states"}
    with pytest.raises(ValueError, match="holds no damage states"):
        st.state_fragility(bare, n_boot=0)
    with pytest.raises(ValueError, match="state_capacity_scale"):
        st.state_fragility(ds.drop_vars("state_capacity_scale"), n_boot=0)
