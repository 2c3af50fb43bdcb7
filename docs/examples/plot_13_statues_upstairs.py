"""
Statues on the third floor: eight orientations, three damage states
===================================================================

The museum's statues stand on the third floor of a five-storey building. The building filters
the ground shaking and amplifies it near its own periods; nobody knows in advance along which
direction each statue's rocking plane lies; and the owner cares about a chipped base or a
displaced statue as well as a fall. The job end to end:

1. **Records**: the eight synthetic near-fault records shipped in ``data/records`` have one
   horizontal component each, so this example **pairs them** into four two-component ground
   records: NF01 (x) with NF05 (y), NF02 with NF06, NF03 with NF07, NF04 with NF08. The pairs
   are synthetic, and their components independent: a real record's pair is correlated.
2. **The floor**: :func:`rockstudy.motions.floor_motion` of each pair on floor 3 of a uniform
   shear building of five storeys (first period 0.5 s, 5 % damping), both components.
3. **Orientations**: every floor pair turned to 8 angles psi = k pi / 8 of the rocking plane,
   a_psi = a_x cos(psi) + a_y sin(psi) (:meth:`~rockstudy.motions.Record.oriented`).
4. **Damage states**: chipped (abs(theta)/alpha reaches 0.2), displaced (0.5), overturned (1).
   An IDA finds the capacity of each state under each oriented floor motion, in the PGA of
   the **ground** record (the site hazard's measure; the building is linear, so scaling the
   ground scales the floor).
5. **Fragility and risk** per state, at the worst orientation and the median over
   orientations (:func:`~rockstudy.study.analysis.orientations.orientation_summary`), and the
   annual rate of reaching each state on the synthetic site hazard curve of
   ``data/hazard/site_pga.csv``. For a statue of unknown orientation sign the
   **median-orientation** fragility; the worst orientation is the bound.

The same job as a study: ``[motion] building = { uniform_shear = {...} }``, ``floor = 3`` and
``h2`` (each record's second horizontal file), ``[design] orientations = 8`` and
``damage_states``, with a ``[hazard]`` table (see :doc:`/buildings`).
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from scipy.stats import norm

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import Building, Record, floor_motion
from rockstudy.motions.building import with_ground
from rockstudy.risk import HazardCurve
from rockstudy.study.analysis.orientations import orientation_summary
from rockstudy.study.analysis.states import state_fragility, state_risk
from rockstudy.study.designs import records as rd

ROOT = next(p for p in (Path.cwd(), *Path.cwd().parents) if (p / "data" / "records").is_dir())

files = sorted((ROOT / "data" / "records").glob("*_H.AT2"))
single = [Record.from_at2(f) for f in files]
pairs = [
    Record(x.acceleration, time=x.time, acceleration_y=y.acceleration, name=f"{x.name}+{y.name}")
    for x, y in zip(single[:4], single[4:], strict=True)
]
building = Building.uniform_shear(n_storeys=5, period=0.5, damping=0.05)
FLOOR = 3
statues = {
    "Kouros": rs.Block.from_dimensions(width=0.45, height=1.90),
    "Athena": rs.Block.from_dimensions(width=0.60, height=2.30),
    "Satyr": rs.Block.from_dimensions(width=0.35, height=1.20),
}
STATES = {"chipped": 0.2, "displaced": 0.5, "overturned": 1.0}
print("building periods [s]:", np.round(building.periods, 3))

# %%
# The floor spectrum against the ground's
# ---------------------------------------
# The median 5 % spectrum of the x components on the ground and on floor 3. The floor
# amplifies the shaking near the building's first period (0.5 s) and its second (0.17 s),
# and passes little above it.
periods = np.geomspace(0.05, 4.0, 60)
floors = [floor_motion(p, building, FLOOR) for p in pairs]
ground_sa = np.median([p.response_spectrum(periods)["sa"].values for p in pairs], axis=0)
floor_sa = np.median([f.response_spectrum(periods)["sa"].values for f in floors], axis=0)
fig, ax = plt.subplots(figsize=(7, 4))
ax.loglog(periods, ground_sa / G, lw=2.5, label="ground")
ax.loglog(periods, floor_sa / G, lw=1.8, label=f"floor {FLOOR} of 5")
for T in building.periods[:2]:
    ax.axvline(T, color="0.6", ls=":", lw=1)
ax.set_xlabel("period T [s] (dotted: the building's first two periods)", fontsize=10)
ax.set_ylabel("median Sa(T, 5 %) [g]", fontsize=10)
ax.legend(fontsize=9)
fig.tight_layout()

# %%
# IDA at eight orientations, with three damage states
# ---------------------------------------------------
# One IDA per orientation, on the four floor pairs turned to psi, each measured on its ground
# pair (``with_ground``: the capacities are ground PGAs); stacked on a dimension
# ``orientation`` as a study over orientations stores them (without the IDA curves, whose
# number of steps differs between runs).
angles = np.pi * np.arange(8) / 8
runs = []
for psi in angles:
    motions = [with_ground(f.oriented(psi), p) for f, p in zip(floors, pairs, strict=True)]
    runs.append(
        rd.incremental_dynamic_analysis(
            motions, statues, im="pga", step=0.05, tolerance=0.01, damage_states=STATES
        ).drop_dims("step")
    )
ida = xr.concat(runs, dim=xr.DataArray(angles, dims="orientation", name="orientation"))
caps = ida["state_capacity"].transpose("damage_state", "record", "orientation", "structure")
print("capacity of each state [g], Kouros under the first pair, per orientation psi [deg]:")
kouros = caps.sel(structure="Kouros").isel(record=0) / G
print(kouros.assign_coords(orientation=np.degrees(angles).round(1)).to_pandas().round(3))

# %%
# Fragility per state: worst orientation and median over orientations
# ---------------------------------------------------------------------
# Per statue and record the worst orientation keeps the lowest capacity of each state (like
# RotD100), the median the median over the eight (like RotD50); each is fitted by a
# lognormal per state. Solid: median over orientations (the one to sign); dashed: worst.
# Each state is fitted apart: on four pairs the curves of nested states can cross (the
# worst-orientation fits of Athena's displaced and overturned states do); more records narrow
# them.
views = {w: orientation_summary(ida, w) for w in ("median", "worst")}
fits = {w: state_fragility(v, im="pga", n_boot=100) for w, v in views.items()}
pga = np.geomspace(0.1, 1.0, 200)
fig, axes = plt.subplots(1, 3, figsize=(11, 3.8), sharey=True)
for ax, name in zip(axes, statues, strict=True):
    for k, state in enumerate(STATES):
        for which, style in (("median", "-"), ("worst", "--")):
            row = fits[which].loc[(state, name)]
            p = norm.cdf(np.log(pga / row["theta"]) / row["beta"])  # theta in g
            label = state if which == "median" else None
            ax.plot(pga, p, style, color=f"C{k}", lw=1.8, label=label)
    ax.set_xscale("log")
    ax.set_xticks([0.1, 0.2, 0.3, 0.5, 1.0], ["0.1", "0.2", "0.3", "0.5", "1"])
    ax.set_title(name, fontsize=11)
    ax.set_xlabel("ground PGA [g]", fontsize=10)
    ax.tick_params(labelsize=9)
axes[0].set_ylabel("P(state reached | PGA)", fontsize=10)
axes[0].legend(fontsize=9, title="solid: median\ndashed: worst", title_fontsize=8)
fig.tight_layout()
table = fits["median"][["theta", "beta", "n"]].copy()  # the fits quote PGA in g
table["theta, worst"] = fits["worst"]["theta"]
print("median ground PGA [g] of each state (median over orientations; worst beside):")
print(table.round(3).to_string())

# %%
# Annual rates per state
# ----------------------
# Each state's fragility integrated against the site's hazard curve (Cornell et al. 2002),
# with 90 % bands by resampling the records (four pairs: wide bands). Bars: the median
# orientation, with their bands; black ticks: the worst orientation, the bound.
hazard = HazardCurve.from_csv(ROOT / "data" / "hazard" / "site_pga.csv", im="pga", units="g")
rates = {w: state_risk(v, hazard, years=50, n_boot=100, seed=0) for w, v in views.items()}
fig, ax = plt.subplots(figsize=(8, 4))
width = 0.25
x = np.arange(len(statues))
for k, state in enumerate(STATES):
    med = rates["median"].sel(damage_state=state)
    lam = med["annual_rate"].values
    err = np.array([lam - med["annual_rate_lo"].values, med["annual_rate_hi"].values - lam])
    ax.bar(x + (k - 1) * width, lam, width, yerr=err, capsize=3, color=f"C{k}", label=state)
    worst = rates["worst"].sel(damage_state=state)["annual_rate"].values
    label = "worst orientation" if k == 0 else None
    ax.plot(x + (k - 1) * width, worst, "k_", ms=14, mew=2, label=label)
ax.set_yscale("log")
ax.set_xticks(x, list(statues), fontsize=10)
ax.set_ylabel("annual rate of reaching the state [1/yr]", fontsize=10)
ax.legend(fontsize=9, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.1))
fig.tight_layout()
print(rates["median"]["annual_rate"].to_pandas().T.to_string(float_format=lambda v: f"{v:.3g}"))
