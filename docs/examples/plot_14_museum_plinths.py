"""
The museum's statues on their plinths and one on an isolator
============================================================

Two marble statues of the museum
(:ref:`the museum example <sphx_glr_auto_examples_plot_10_museum.py>`) stand on marble plinths
that can rock themselves, and the curators consider a base isolator for the Kouros.
Does the plinth raise or lower the annual rate of overturning against the statue on rigid
ground, and what would the isolator buy? The study file ``studies/museum_plinths.toml``
holds the job; this example runs it and reads the cube:

1. **Objects** (``[structure] kind = "objects"``): each statue as a block on rigid ground;
   the same statue on its plinth (``kind = "stacked"``: :class:`rockstudy.StackedBlocks`,
   marble on marble, density ratio 1; either body's overturning is the object's); the Kouros
   on an isolator (``kind = "isolated"``: :class:`rockstudy.IsolatedBlock`, T_b = 2.5 s,
   zeta_b = 0.10, a base as heavy as the statue, a displacement capacity of 0.30 m). Each
   two-body object names its statue on rigid ground with ``compare_to``.
2. **Records**: the eight synthetic near-fault records shipped in ``data/records``
   (horizontal components; :mod:`rockstudy.motions.shipped`).
3. **IDA** in PGA (rungs 10 % apart, bisection to 2 %); the pairs run the two-body numba
   kernels (``rockstudy.simulate_batch(structure=...)``).
4. **Hazard**: the synthetic site curve ``data/hazard/site_pga.csv`` (not a real site), the
   annual rate of overturning lambda_OT of each object with its 90 % band from resamples of
   the records, and the ratio of each pair's rates over the same resamples
   (:func:`rockstudy.study.analysis.two_body.pair_ratios`), as the study's report tables it.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from distributed import Client

from rockstudy.constants import G
from rockstudy.risk import HazardCurve
from rockstudy.study import load_study, open_result, run_study
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.analysis.two_body import over_capacity, pair_ratios

ROOT = next(p for p in (Path.cwd(), *Path.cwd().parents) if (p / "data" / "records").is_dir())

study = load_study(ROOT / "studies" / "museum_plinths.toml")
work = Path(tempfile.mkdtemp())
with Client(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=":0") as c:
    run_study(study, work / "cube.zarr", client=c, progress=False, netcdf=False,
              base_dir=ROOT / "studies")
ds = open_result(work / "cube.zarr").load()
names = [str(n) for n in ds["structure"].values]
print("first overturning PGA [g] (NaN: the record did not overturn the object)")
print((ds["capacity"] / G).to_pandas().round(2).to_string())

# %%
# Which body falls, and the isolator's travel
# -------------------------------------------
# ``overturned_body`` at each object's capacity: 1 the plinth, 2 the statue, 3 both (-1: no
# plinth, or the record did not overturn it). The isolator's displacement is stored at the
# highest scale the statue stood at; the study's report warns where it passes the capacity.
print(ds["overturned_body"].to_pandas().loc[:, [n for n in names if "plinth" in n]].to_string())
over = over_capacity(ds)
for name in over["structure"].values:
    o = over.sel(structure=name)
    print(f"{name}: {int(o['over'])} of {int(o['scenes'])} records move the isolator beyond "
          f"{float(o['isolator_capacity']):.2f} m (largest {float(o['largest']):.2f} m)")

# %%
# Ranked by the annual rate of overturning
# ----------------------------------------
hazard = HazardCurve.from_csv(ROOT / "data" / "hazard" / "site_pga.csv", im="pga", units="g")
risk = object_risk(ds, hazard, years=50, n_boot=200, seed=0)
table = risk[["status", "theta", "beta", "annual_rate", "annual_rate_lo", "annual_rate_hi"]]
table = table.to_pandas().sort_values("annual_rate")
print(table.to_string(float_format=lambda v: f"{v:.3g}"))

kind = {n: ("isolated" if "isolated" in n else "plinth" if "plinth" in n else "rigid")
        for n in names}
colour = {"rigid": "C0", "plinth": "C1", "isolated": "C2"}
fig, ax = plt.subplots(figsize=(8, 3.8))
order = list(table.index)
rate = table["annual_rate"].values
err = np.array([rate - table["annual_rate_lo"].values, table["annual_rate_hi"].values - rate])
for label, c in colour.items():
    mine = [j for j, n in enumerate(order) if kind[n] == label]
    ax.errorbar(rate[mine], mine, xerr=err[:, mine], fmt="o", color=c, capsize=3,
                label={"rigid": "on rigid ground", "plinth": "on its plinth",
                       "isolated": "on an isolator"}[label])
ax.set_yticks(range(len(order)), order)
ax.set_xscale("log")
ax.set_xlabel("annual rate of overturning lambda_OT [1/yr] (IDA; 90 % band)", fontsize=10)
ax.legend(fontsize=8, loc="lower right")
ax.tick_params(labelsize=9)
fig.tight_layout()

# %%
# What the plinth and the isolator buy
# ------------------------------------
# The ratio of each two-body object's annual rate to that of its statue on rigid ground
# (``compare_to``), with its 90 % band over the same resamples of the records for both
# (below 1 the plinth or the isolator lowers the rate).
ratios = pair_ratios(ds, hazard, years=50, n_boot=200, seed=0)
print(ratios.to_pandas().to_string(float_format=lambda v: f"{v:.3g}"))
fig, ax = plt.subplots(figsize=(8, 2.8))
pairs = [str(p) for p in ratios["pair"].values]
r = ratios["ratio"].values
err = np.array([r - ratios["ratio_lo"].values, ratios["ratio_hi"].values - r])
ax.errorbar(r, range(len(pairs)), xerr=err, fmt="o", capsize=3, color="k")
ax.set_yticks(range(len(pairs)), pairs)
ax.axvline(1.0, color="k", lw=1, ls=":")
ax.set_xscale("log")
ax.set_xlabel("annual rate over that of the statue on rigid ground (90 % band)", fontsize=10)
ax.tick_params(labelsize=9)
fig.tight_layout()

# %%
# How to read it. A plinth that rocks is not rigid ground: the pair lifts at the first of the
# statue's own uplift and the pair's as one body about a plinth corner, and here the statue
# falls off its plinth in every overturning (``overturned_body`` 2). The plinth moves the
# capacities both ways (both statues survive NF01 on rigid ground but not on their plinths),
# and the ratios say by how much the rates move, each band from the same resamples of the
# records: the Kouros's plinth lowers its rate a little, the Satyr's changes it within its band.
# The isolator, tuned to 2.5 s, filters the short pulses (NF02 to NF05 need 1.8 to 3.8 times
# the rigid-ground PGA to overturn the Kouros) but resonates with the longest ones (NF07, NF08),
# where the isolated statue falls at a lower PGA than on rigid ground: the capacities spread
# over a factor of 25, the fitted beta is large, the lognormal puts much probability at low
# PGA, and the annual rate and its band are wide. The base also travels beyond its stated
# capacity, which the model (no end stop) does not describe: those scenes are outside it.
#
# The ladder's 10 % rungs keep the example short. Rocking is not monotonic in intensity, and
# a coarse ladder can step over a first overturning: with rungs 5 % apart (``step = 0.05``)
# the Kouros on rigid ground first falls under NF03 at 0.68 g, not at the 1.04 g found here.
# Eight records are few; the bands say so.
