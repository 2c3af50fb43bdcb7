"""
A study, from its TOML file to its report
=========================================

A study is a file. This one draws 4,000 random blocks (R, alpha) under random sine pulses,
runs them on dask, stores the result cube and writes the HTML report. From a shell the same
three steps are::

    rockstudy validate study.toml
    rockstudy run study.toml --out cube.zarr
    rockstudy report cube.zarr --out report

Here they run in this process, on a small in-process dask cluster.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from distributed import Client

from rockstudy.study import analysis, load_study, open_result, run_study
from rockstudy.study.report import make_report

STUDY = """
name = "gallery-study"
description = "Monte Carlo: blocks (R, alpha) under sine pulses (a_g / (g tan alpha), T_p)"
seed = 7
chunk_size = 1000

[sampler]
kind = "monte_carlo"
n = 4000

[structure]
kind = "block"
half_diagonal = { dist = "uniform", low = 0.5, high = 3.0 }   # R [m]
slenderness = { dist = "uniform", low = 0.1, high = 0.3 }     # alpha [rad]

[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = { dist = "uniform", low = 1.0, high = 5.0 } # a_g / (g tan alpha)
period = { dist = "loguniform", low = 0.1, high = 2.0 }       # T_p [s]

[run]
method = "nonlinear"
rtol = 1e-8
outputs = ["max_rotation", "max_rotation_ratio", "overturned", "n_impacts"]
"""

work = Path(tempfile.mkdtemp())
(work / "study.toml").write_text(STUDY)
study = load_study(work / "study.toml")  # validated: a typo would raise, naming the field
with Client(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None) as c:
    run_study(study, work / "cube.zarr", client=c, progress=False, netcdf=False)
report = make_report(work / "cube.zarr", work / "report")
print("report written to", report)

# %%
# The cube
# --------
# Inputs, rocking parameters, dimensionless groups and outputs, on a ``sample`` dimension.
ds = open_result(work / "cube.zarr").load()
print(ds[["half_diagonal", "slenderness", "omega", "uplift_ratio", "overturned"]])

# %%
# Overturning over the groups, and fragility
# ------------------------------------------
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
over = ds["overturned"].values.astype(bool)
psi = 1 / ds["uplift_ratio"].values  # a_g / (g tan alpha)
axes[0].scatter(ds["omega"].values[~over], psi[~over], s=2, c="C0", label="survives")
axes[0].scatter(ds["omega"].values[over], psi[over], s=2, c="C3", label="overturns")
axes[0].set_xscale("log")
axes[0].set_xlabel(r"$\omega_g / p$")
axes[0].set_ylabel(r"$a_g / (g \tan\alpha)$")
axes[0].legend(markerscale=5)
table = analysis.fragility(ds, "amplitude_ratio", by="half_diagonal", bins=[0.5, 1.5, 3.0])
im = np.linspace(1, 5, 100)
curves = analysis.fragility_curve(table, im)
for g in curves.group.values:
    axes[1].plot(im, curves.probability.sel(group=g), label=f"R {g} m")
axes[1].set_xlabel(r"$a_g / (g \tan\alpha)$")
axes[1].set_ylabel("P(overturning)")
axes[1].legend()
fig.tight_layout()
print(table[["theta", "beta", "n"]])
