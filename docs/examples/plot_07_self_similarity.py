"""
Self-similarity: one response for every block with the same groups
==================================================================

Section 4 of [000]: for the linearized model, theta / alpha depends only on the groups
(a, omega, tau, eta). Three blocks of very different size and slenderness are given sine pulses
chosen by :func:`rockstudy.similarity.pulse_for` so that their groups (omega, g alpha / a_g)
are equal; in dimensionless time tau = p t their histories coincide. Under Housner's nonlinear
equation the collapse is approximate, and better for slender blocks.
"""

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs

blocks = [rs.Block(0.3, 0.08, 0.9), rs.Block(1.5, 0.15, 0.9), rs.Block(5.0, 0.25, 0.9)]
fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
for ax, method in zip(axes, ("linear", "nonlinear")):
    for blk in blocks:
        pulse = rs.similarity.pulse_for(blk, omega=3.0, ratio=0.4, law="4.11")
        res = rs.simulate(blk, pulse, method=method, t_max=8.0 / blk.frequency_parameter * 3)
        tau = res.t * blk.frequency_parameter
        ax.plot(tau, res.theta / blk.slenderness, lw=1.2,
                label=f"R = {blk.half_diagonal} m, alpha = {blk.slenderness}")
    ax.set_title(f"{method} model")
    ax.set_xlabel(r"$\tau = p\,t$")
axes[0].set_ylabel(r"$\theta / \alpha$")
axes[0].legend(fontsize=8)
fig.tight_layout()
