"""
Fragility from records
======================

An engineer's workflow: one object, a suite of ground motions, a ladder of intensities, and
the probability of overturning against intensity. Here the object is a 0.4 m x 1.6 m statue
(R = 0.82 m, alpha = 0.245 rad), the suite is twelve seeded synthetic records (Kanai-Tajimi
filtered noise under a Jennings envelope: no file needed), each scaled to 25 levels of peak
ground acceleration. Every record runs all its scales in one :func:`rockstudy.simulate_batch`
call; the lognormal fragility curve is fitted by maximum likelihood.
"""

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

import rockstudy as rs
from rockstudy.study import analysis

G = 9.81
statue = rs.Block.from_dimensions(width=0.4, height=1.6)
p, alpha, eta = rs.structures.block_parameters(statue)
levels = np.linspace(0.1, 1.5, 25) * G  # target PGA [m/s^2]

pga, overturned, record_id = [], [], []
for k in range(12):
    rec = rs.motions.stochastic_record(peak=1.0, duration=12.0, dt=0.01, seed=100 + k)
    out = rs.simulate_batch(half_diagonal=statue.half_diagonal, slenderness=alpha,
                            record=rec, scale=levels / rec.peak)
    pga.append(levels / G)
    overturned.append(out["overturned"])
    record_id.append(np.full(levels.size, k))
ds = xr.Dataset({"pga_g": ("sample", np.concatenate(pga)),
                 "overturned": ("sample", np.concatenate(overturned)),
                 "record": ("sample", np.concatenate(record_id))})

table = analysis.fragility(ds, "pga_g")
print(table[["theta", "beta", "n"]])

fig, ax = plt.subplots(figsize=(7, 4.2))
share = ds.groupby("pga_g").mean()["overturned"]
ax.plot(share.pga_g, share, "ko", ms=4, label="share of the 12 records that overturn it")
x = np.linspace(0.05, 1.6, 200)
curve = analysis.fragility_curve(table, x)
ax.plot(x, curve.probability.isel(group=0), "C3", label="lognormal fit (MLE)")
ax.fill_between(x, curve.lower.isel(group=0), curve.upper.isel(group=0), color="C3", alpha=0.2,
                label="90 % band of the median")
ax.axvline(np.tan(alpha), color="0.5", ls=":", label=r"uplift, $\tan\alpha$")
ax.set_xlabel("PGA [g]")
ax.set_ylabel("P(overturning)")
ax.legend()
fig.tight_layout()
