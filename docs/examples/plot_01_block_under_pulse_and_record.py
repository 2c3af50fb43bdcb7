"""
A block under a pulse and under a record
========================================

A 0.5 m x 2 m block (R = 1.03 m, alpha = 0.245 rad) rocks through a one-cycle sine pulse and
through a synthetic Kanai-Tajimi record. The rotation is drawn as theta / alpha: the block
overturns where |theta| reaches pi/2 and, without excitation, falls once |theta| passes alpha.
"""

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs

block = rs.Block.from_dimensions(width=0.5, height=2.0)
p, alpha, eta = rs.structures.block_parameters(block)  # eta: Housner's (2.4) of [000]
uplift = block.uplift_acceleration  # g tan(alpha): the ground acceleration that starts rocking
print(f"R = {block.half_diagonal:.3f} m, alpha = {alpha:.3f} rad, p = {p:.2f} rad/s, "
      f"eta = {eta:.3f}, uplift at {uplift:.2f} m/s^2")

# %%
# A sine pulse of twice the uplift acceleration
# ----------------------------------------------
pulse = rs.motions.SinePulse(amplitude=2.0 * uplift, period=0.8)
res = rs.simulate(block, pulse)
print(f"max rotation {res.max_rotation:.4f} rad = {res.max_rotation / alpha:.3f} alpha, "
      f"{res.impact_times.size} impacts, overturned: {res.overturned}")

# %%
# A record
# --------
# A seeded synthetic record (Kanai-Tajimi filtered noise under a Jennings envelope), scaled to a
# peak of three times the uplift acceleration. A PEER file of your own would be read with
# ``rs.motions.Record.from_at2(path)``.
record = rs.motions.stochastic_record(peak=3.0 * uplift, duration=15.0, dt=0.01, seed=7)
res_rec = rs.simulate(block, record)
print(f"record: max rotation {res_rec.max_rotation / alpha:.3f} alpha, "
      f"{res_rec.impact_times.size} impacts, overturned: {res_rec.overturned}")

# %%
# The rotation against time
# -------------------------
# ``res.plot()`` would draw this in one call; here both responses are drawn by hand from the
# dense output (``dt_out``: the state every 5 ms, as accurate as the integrator's steps), with
# the exact peaks (``peak_times``, ``peak_rotations``: every local maximum of |theta|).
res = rs.simulate(block, pulse, dt_out=0.005)
res_rec = rs.simulate(block, record, dt_out=0.005)
largest = np.abs(res_rec.peak_rotations).argmax()
print(f"record: {res_rec.peak_times.size} peaks, the largest "
      f"{res_rec.peak_rotations[largest] / alpha:.3f} alpha at {res_rec.peak_times[largest]:.2f} s "
      f"(overturned: {res_rec.overturned}; a fall is not a peak)")

fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=False)
for ax, r, name in ((axes[0], res, "sine pulse"), (axes[1], res_rec, "synthetic record")):
    ax.plot(r.t_eval, r.theta_eval / alpha, lw=1)
    ax.plot(r.peak_times, r.peak_rotations / alpha, "r.", ms=4, label="peaks")
    ax.plot(r.impact_times, np.zeros_like(r.impact_times), "k|", ms=8, label="impacts")
    ax.axhline(1, color="0.6", ls=":")
    ax.axhline(-1, color="0.6", ls=":")
    ax.set_ylabel(r"$\theta / \alpha$")
    ax.set_title(name)
    ax.legend(loc="upper right")
axes[1].set_xlabel("t [s]")
fig.tight_layout()
