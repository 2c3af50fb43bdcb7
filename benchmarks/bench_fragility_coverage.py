"""Coverage of the 90 % pointwise fragility bands (issue 23, section 2). Writes
benchmarks/results/fragility_coverage.json.

    python benchmarks/bench_fragility_coverage.py [--reps 400]

Data drawn from a known lognormal fragility (theta = 0.5 g, beta = 0.4); each replication is
fitted through the public functions and its band of P read by ``fragility_curve`` at
x = theta e^{-2 beta} and theta e^{+2 beta} (true P = Phi(-+2) = 0.023, 0.977). Coverage is the
share of replications whose band holds the true P (binomial standard error ~1.5 % at 400).

- ``ida``: n lognormal capacities (n = 10, 30, 100), ``ida_fragility``;
- ``ida_censored``: the same with the capacities above theta e^{beta} censored there (16 %);
- ``cloud``: 40 records, one level each (log-level spread 1 or 2 beta about theta), the
  outcome "capacity <= level", ``stripe_fragility`` on a cloud dataset;
- ``monte_carlo``: n = 100 and 300 independent samples (levels log-uniform over theta
  e^{+-3 beta}), ``analysis.fragility``.

Each case also gives the coverage of the band that varies theta alone at the point beta
(the bands before issue 23), from the same fits.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import xarray as xr
from scipy import stats

from rockstudy.constants import G
from rockstudy.study import analysis
from rockstudy.study.analysis import record_fragility as rf

OUT = Path(__file__).parent / "results"
THETA, BETA = 0.5, 0.4
X = THETA * np.exp(np.array([-2.0, 2.0]) * BETA)
TRUE = stats.norm.cdf([-2.0, 2.0])


def ida_dataset(capacity_g, censored_at=None):
    """One block, n records of PGA 1 g, capacities [g] (NaN where censored at the top)."""
    c = np.asarray(capacity_g, float)
    cens = np.zeros(c.size, bool) if censored_at is None else c > censored_at
    top = np.where(cens, np.inf if censored_at is None else censored_at, c / 1.01)
    return xr.Dataset(
        {
            "pga": ("record", np.full(c.size, G)),
            "capacity_scale": (("record", "structure"), np.where(cens, np.nan, c)[:, None]),
            "capacity_scale_lower": (("record", "structure"), top[:, None]),
            "censored": (("record", "structure"), cens[:, None]),
            "status": (("record", "structure"), np.zeros((c.size, 1), np.int64)),
        },
        coords={"structure": [0]},
        attrs={"design": "ida", "im": "pga", "im_period": np.nan},
    )


def cloud_dataset(level_g, overturned):
    """One block, one record per level [g] (its PGA), with its outcome."""
    y = np.asarray(overturned, bool)[:, None]
    return xr.Dataset(
        {
            "pga": ("record", np.asarray(level_g, float) * G),
            "overturned": (("record", "structure"), y),
            "status": (("record", "structure"), np.zeros(y.shape, np.int64)),
        },
        coords={"structure": [0]},
        attrs={"design": "cloud"},
    )


def hits(table):
    """(band holds the true P, theta-only band holds it) at the two x, from one table row."""
    curve = analysis.fragility_curve(table, X).isel(group=0)
    r = table.iloc[0]
    lo, hi = curve.lower.values, curve.upper.values
    with np.errstate(divide="ignore", invalid="ignore"):
        old_lo = stats.norm.cdf(np.log(X / r.theta_hi) / r.beta)
        old_hi = stats.norm.cdf(np.log(X / r.theta_lo) / r.beta)
    return (lo <= TRUE) & (TRUE <= hi), (old_lo <= TRUE) & (TRUE <= old_hi)


def capacities(rng, n):
    return THETA * np.exp(BETA * rng.standard_normal(n))


def run_case(make_table, reps, seed):
    rng = np.random.default_rng(seed)
    new, old = np.zeros(2), np.zeros(2)
    for _ in range(reps):
        a, b = hits(make_table(rng))
        new += a
        old += b
    return {
        "coverage": (new / reps).round(4).tolist(),
        "theta_only": (old / reps).round(4).tolist(),
    }


def cases():
    out = {}
    for n in (10, 30, 100):
        out[f"ida n={n}"] = lambda rng, n=n: rf.ida_fragility(ida_dataset(capacities(rng, n)))
        top = THETA * np.exp(BETA)
        out[f"ida_censored n={n}"] = lambda rng, n=n, top=top: rf.ida_fragility(
            ida_dataset(capacities(rng, n), top), n_boot=0
        )
    for spread in (1.0, 2.0):

        def cloud(rng, spread=spread):
            level = THETA * np.exp(spread * BETA * rng.standard_normal(40))
            return rf.stripe_fragility(cloud_dataset(level, capacities(rng, 40) <= level), n_boot=0)

        out[f"cloud 40 spread={spread:g} beta"] = cloud
    for n in (100, 300):

        def monte_carlo(rng, n=n):
            level = THETA * np.exp(rng.uniform(-3, 3, n) * BETA)
            over = (capacities(rng, n) <= level).astype(np.int8)
            ds = xr.Dataset({"im": ("sample", level), "overturned": ("sample", over)})
            return analysis.fragility(ds, "im", n_boot=0)

        out[f"monte_carlo n={n}"] = monte_carlo
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=400)
    args = ap.parse_args()
    result = {"theta": THETA, "beta": BETA, "x": X.tolist(), "true_p": TRUE.tolist()}
    result["reps"] = args.reps
    for k, (name, make) in enumerate(cases().items()):
        result[name] = run_case(make, args.reps, seed=k)
        print(
            f"{name:32s} band {result[name]['coverage']}  theta-only {result[name]['theta_only']}"
        )
    OUT.mkdir(exist_ok=True)
    (OUT / "fragility_coverage.json").write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
