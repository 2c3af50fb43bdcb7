"""
The museum: which objects overturn, and how likely is that in 50 years
======================================================================

A museum holds four marble statues and two stone columns. Which of them overturn under
near-fault shaking, at what intensity, and what is the annual probability of overturning at
the museum's site? The job end to end:

1. **Named objects**: a dict ``{name: Block}``; every output keeps the names. The restitution
   is Housner's, eq. (2.4) of [000], from each object's slenderness (marble on stone).
2. **Records**: the eight synthetic near-fault records shipped with rockstudy in
   ``data/records`` (horizontal components; no download).
3. **IDA and stripes**: the first overturning PGA of each object under each record
   (incremental dynamic analysis), and every record scaled to six PGA levels (stripes).
4. **Hazard**: the site's PGA hazard curve ``data/hazard/site_pga.csv``. It is **synthetic**:
   ``data/hazard/make_site_pga.py`` generates it as a second-order log-log law fitted through
   three return periods of a moderately active site (0.05 g at 30 years, 0.25 g at 475
   years, 0.5 g at 2,475 years); it is not the hazard of a real site.
5. **Risk**: each object's lognormal fragility integrated against the hazard (Cornell et al.
   2002), the annual rate of overturning lambda_OT, the probability in 50 years
   1 - exp(-50 lambda_OT), 90 % bands by resampling the records, and the deaggregation.
6. **Friction**: the block model assumes the base does not slide. The friction demand
   max abs(F_h / F_v) of every scene is compared with a friction coefficient of marble on
   stone, mu = 0.6.

The same job as a study file: ``studies/museum.toml`` (``rockstudy run`` then
``rockstudy report``), whose report ranks the same table.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.risk import HazardCurve
from rockstudy.study.designs import records as rd
from rockstudy.study.analysis.risk import object_risk

ROOT = next(p for p in (Path.cwd(), *Path.cwd().parents) if (p / "data" / "records").is_dir())

objects = {
    "Kouros (marble)": rs.Block.from_dimensions(width=0.45, height=1.90),
    "Hermes & Dionysus (marble)": rs.Block.from_dimensions(width=0.50, height=1.60),
    "Athena (marble)": rs.Block.from_dimensions(width=0.60, height=2.30),
    "Satyr (marble)": rs.Block.from_dimensions(width=0.35, height=1.20),
    "Ionic column": rs.Block.from_dimensions(width=0.60, height=4.20),
    "Doric column": rs.Block.from_dimensions(width=0.70, height=5.50),
}
for name, b in objects.items():
    print(f"{name:28s} R = {b.half_diagonal:.3f} m  alpha = {b.slenderness:.3f} rad  "
          f"eta = {b.restitution:.3f}  uplift PGA = {np.tan(b.slenderness):.3f} g")

records = rs.motions.load_suite(ROOT / "data" / "records" / "*_H.AT2")
print([r.name for r in records])

# %%
# IDA and stripes
# ---------------
# The IDA climbs a ladder of 2 % steps from the uplift of each object, refined by bisection to
# 0.5 %, and scans four levels above the capacity for survivals (rocking is not monotonic).
ida = rd.incremental_dynamic_analysis(records, objects, im="pga", step=0.02, tolerance=0.005,
                                      scan=4)
levels_g = np.array([0.15, 0.25, 0.4, 0.6, 0.9, 1.3])
stripes = rd.multiple_stripes(records, objects, levels_g * G, im="pga")
print(ida["capacity"].to_pandas().T.div(G).round(3))  # first overturning PGA [g]

# %%
# The hazard and the annual probability of overturning
# ----------------------------------------------------
hazard = HazardCurve.from_csv(ROOT / "data" / "hazard" / "site_pga.csv", im="pga", units="g")
print(hazard)
risk_ida = object_risk(ida, hazard, years=50, n_boot=200, seed=0)
risk_stripes = object_risk(stripes, hazard, years=50, n_boot=100, seed=0)

columns = ["status", "theta", "beta", "n_overturning", "annual_rate", "annual_rate_lo",
           "annual_rate_hi", "probability", "probability_lo", "probability_hi",
           "annual_rate_lognormal", "share_below_uplift"]
table = risk_ida[columns].to_pandas()
table = table.rename(columns={"theta": "median PGA [g]", "annual_rate": "lambda_OT [1/yr]",
                              "probability": "P(50 yr)"})
print("Ranked by the annual rate of overturning (IDA fragility, 90 % bands by 200 resamples "
      "of the records):")
print(table.to_string(float_format=lambda v: f"{v:.3g}"))
print("The same from the stripes (binomial fit):")
print(risk_stripes[["status", "theta", "beta", "annual_rate", "probability", "share_below_uplift"]]
      .to_pandas()
      .to_string(float_format=lambda v: f"{v:.3g}"))

# %%
# How to read it. PGA is a poor predictor of rocking under pulse-like records (the short
# 0.4 s pulse of NF01 needs several g to overturn anything), so beta is near 1 and the
# lognormal puts probability below each object's uplift PGA g tan(alpha), where it cannot even
# leave rest. The records are horizontal, so each fragility is set to 0 there
# (``truncated_at_uplift``): ``annual_rate`` and the ranking are those of that fragility,
# ``annual_rate_lognormal`` is the whole lognormal's rate and ``share_below_uplift`` the part of
# it that the truncation removed. The stripes fit differs from the IDA's: the stripes see the
# survivals above the first overturning (rocking is not monotonic in intensity), which the IDA's
# "first overturning" capacity does not count, and they have six levels only.
#
# Ranked probabilities in 50 years, with their bands
fig, ax = plt.subplots(figsize=(8, 4))
names = [str(n) for n in risk_ida["structure"].values]
p = risk_ida["probability"].values
err = np.array([p - risk_ida["probability_lo"].values, risk_ida["probability_hi"].values - p])
ax.barh(names[::-1], p[::-1], xerr=err[:, ::-1], color="C0", capsize=3)
ax.set_xlabel("probability of overturning in 50 years (IDA; 90 % band)", fontsize=10)
ax.tick_params(labelsize=9)
fig.tight_layout()

# %%
# Deaggregation: which PGA levels the annual rate comes from
# ----------------------------------------------------------
fig, ax = plt.subplots(figsize=(8, 4.5))
lo, hi = risk_ida["im_lower"].values[1:-1], risk_ida["im_upper"].values[1:-1]
for j, name in enumerate(names):
    share = risk_ida["deaggregation"].values[j, 1:-1] / risk_ida["annual_rate"].values[j]
    line, = ax.plot(np.sqrt(lo * hi), share, "o-", ms=3, label=name)
    ax.axvline(risk_ida["uplift"].values[j], color=line.get_color(), ls=":", lw=1)
ax.set_xscale("log")
ax.set_xlabel("PGA [g] (centre of the hazard curve's interval; dotted: uplift)", fontsize=10)
ax.set_ylabel("share of lambda_OT", fontsize=10)
ax.tick_params(labelsize=9)
ax.legend(fontsize=8)
fig.tight_layout()

# %%
# Would the base slide instead? The friction check
# ------------------------------------------------
# The friction demand max abs(F_h / F_v) at the contact, at every stripe scene of every
# object, against mu = 0.6 (marble on stone). A scene whose demand exceeds mu would slide,
# which the rocking model does not represent: its result is outside the model.
MU = 0.6
for name, b in objects.items():
    demand = []
    for k, rec in enumerate(records):
        scale = stripes["scale"].sel(structure=name).values[k]
        out = rs.simulate_batch(half_diagonal=b.half_diagonal, slenderness=b.slenderness,
                                record=rec, scale=scale, outputs=["friction_demand"])
        demand.append(out["friction_demand"])
    demand = np.array(demand)
    print(f"{name:28s} friction demand up to {np.max(demand):.2f}; scenes above mu = {MU}: "
          f"{int((demand > MU).sum())} of {demand.size}")
