"""
The contact model's regime map: what a block at rest does under a step of acceleration
======================================================================================

A rigid block (slenderness alpha = 0.25, so tan(alpha) = 0.255) stands at rest on a base with
Coulomb friction mu. The ground starts to accelerate horizontally at a constant a. Which
regime does the block enter: does it stay at rest, slide flat, rock about a corner that
sticks, or rock about a corner that slips (slide-rock)? Shenton (1996) answers with three
boundaries in the plane (mu, a/g):

- a = mu g (mu < tan alpha): the base cannot hold the block any more, and it slides;
- a = g tan(alpha) (mu > tan alpha): the moment of the inertial force overcomes that of the
  weight about a corner, and it rocks;
- a = a*(mu): the friction force a block needs at the instant it starts to rock reaches
  mu N, and the corner slips as it rises (slide-rock). From the contact forces at uplift,

  a*/g = (mu (1 + 3 cos^2 alpha) - 3 sin alpha cos alpha) /
  (1 + 3 sin^2 alpha - 3 mu sin alpha cos alpha),

  which starts at tan(alpha) for mu = tan(alpha) and goes to infinity as mu approaches
  (1 + 3 sin^2 alpha) / (3 sin alpha cos alpha) (1.65 here): above that the base always
  holds the rising corner.

The shading is :func:`rockstudy.dynamics.slide_rock.initiation_regime` (the test the
contact model's solver uses to leave rest) on a grid; the curves are the closed forms above;
the markers are full runs of :func:`rockstudy.simulate` with ``friction=mu`` under a 20 ms
step, marked by the first regime the block entered.
"""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import slide_rock as sr

alpha, R = 0.25, 1.0
tan = np.tan(alpha)
mu = np.linspace(0.02, 0.8, 240)
a = np.linspace(0.0, 1.5, 240)  # a / g
regime = np.array([[sr.initiation_regime(-ai * G, 0.0, m, m, R, alpha)[0] for m in mu]
                   for ai in a])
names = ["rest", "slide", "rock", "slide-rock"]
colors = ["#f0f0f0", "#9ecae1", "#fdd0a2", "#c7e9c0"]

fig, ax = plt.subplots(figsize=(8.5, 5.0))
ax.pcolormesh(mu, a, regime, cmap=ListedColormap(colors), vmin=-0.5, vmax=3.5, shading="auto")
low = mu[mu <= tan]
ax.plot(low, low, "k-", lw=1.5, label="a = mu g")
ax.plot([tan, mu[-1]], [tan, tan], "k--", lw=1.5, label="a = g tan(alpha)")
high = np.linspace(tan, mu[-1], 200)
threshold = np.array([sr.slide_rock_threshold(m, alpha) for m in high])
ax.plot(high, threshold, "k:", lw=2.0, label="a = a*(mu): slide-rock threshold")
ax.axvline(tan, color="0.4", lw=0.8)

# %%
# The same boundaries from full runs of the contact model: each marker is the first regime
# the block enters (its ``info["regime_sequence"]``) under a 20 ms step of acceleration -a.
markers = {"rest": "o", "slide": "s", "rock": "^", "slide_rock": "D"}
block = rs.Block(half_diagonal=R, slenderness=alpha)
seen = set()
for m in (0.1, 0.2, 0.3, 0.4, 0.6):
    for ag in (0.05, 0.15, 0.3, 0.5, 0.8, 1.2):
        step = rs.motions.Record([-ag * G, -ag * G], time=[0.0, 0.02])
        r = rs.simulate(block, step, friction=m, method="scipy")
        moving = [name for _, name in r.info["regime_sequence"] if name != "rest"]
        first = moving[0] if moving else "rest"
        ax.plot(m, ag, markers[first], color="k", ms=6, mfc="none",
                label=None if first in seen else f"run: {first.replace('_', '-')}")
        seen.add(first)

for name, color in zip(names, colors, strict=True):
    ax.fill_between([], [], color=color, label=name)
ax.set_xlabel("friction coefficient mu (mu_s = mu_k)")
ax.set_ylabel("step of ground acceleration a / g")
ax.set_title(f"Regime from rest, alpha = {alpha} (tan alpha = {tan:.3f})", fontsize=11)
ax.set_xlim(mu[0], mu[-1])
ax.set_ylim(a[0], a[-1])
ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
fig.tight_layout()

# %%
# How to read it. Left of tan(alpha) (the grey vertical line) the block can never rock from
# rest: a sliding base carries no more than mu N, below the force N tan(alpha) that lifts a
# corner, so the block slides whatever the acceleration. Right of it the block rocks once
# a > g tan(alpha), and its rising corner slips too where the acceleration exceeds a*(mu),
# which climbs steeply with mu: a base with mu = 0.3 holds the rising corner up to 0.44 g,
# one with mu = 0.6 up to 2.1 g.
for m in (0.3, 0.4, 0.6):
    print(f"mu = {m}: slide-rock above a = {sr.slide_rock_threshold(m, alpha):.3f} g")
