"""
Self-similarity on records
==========================

Blocks of three sizes (R from 0.3 to 5 m, one slenderness) under four of the synthetic
near-fault records that ship in ``data/records`` (made here by the same call, so no file is
needed). An IDA finds the first overturning PGA of every block under every record; the median
capacity of each size class is then compared in three measures. Against PGA in g the sizes
spread apart (larger blocks are safer); in the record groups of paper [000]'s similarity, PGA /
(g tan alpha) for records of similar omega_p / p, or PGV p / (g tan alpha), they come together.
"""

import matplotlib.pyplot as plt
import numpy as np

from rockstudy.constants import G
from rockstudy.motions import synthetic_near_fault
from rockstudy.motions.shipped import SHIPPED_DT, SHIPPED_SUITE
from rockstudy.study.analysis.record_similarity import size_class_medians
from rockstudy.study.designs.records import incremental_dynamic_analysis

records = [
    synthetic_near_fault(pulse_period=tp, pga=pga * G, seed=seed, dt=SHIPPED_DT)
    for name, tp, pga, seed in SHIPPED_SUITE[1::2]
]
blocks = {"half_diagonal": np.geomspace(0.3, 5.0, 9), "slenderness": 0.2}
ds = incremental_dynamic_analysis(records, blocks, im="pga", tolerance=0.03, scan=0)
print(f"{ds.attrs['n_simulations']} simulations")

fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
for ax, (im, bins, label) in zip(
    axes,
    [
        ("pga", None, "PGA [g]"),
        ("pga_ratio", 2, "PGA / (g tan alpha) [-]"),
        ("pgv_ratio", None, "PGV p / (g tan alpha) [-]"),
    ],
    strict=True,
):
    medians, spread = size_class_medians(ds, im, frequency_bins=bins, n_boot=50)
    print(label, spread[["ratio", "ratio_lo", "ratio_hi"]].round(3).to_string(), sep="\n")
    for band, sub in medians.groupby(level="band", sort=False):
        x = np.arange(len(sub))
        ax.errorbar(
            x,
            sub["theta"],
            yerr=[sub["theta"] - sub["theta_lo"], sub["theta_hi"] - sub["theta"]],
            fmt="o-",
            capsize=3,
            label=band,
        )
        ax.set_xticks(x, [c.replace(" to ", "-") for c in sub.index.get_level_values(1)])
    ax.set(yscale="log", ylabel=f"median capacity, {label}", xlabel="size class")
    ax.legend(fontsize=7)
fig.tight_layout()
plt.show()
