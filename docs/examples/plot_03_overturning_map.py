"""
The overturning map and the closed-form boundaries of [000]
===========================================================

Which slender blocks overturn under a one-cycle sine pulse, over the plane of the frequency
ratio omega = omega_g / p and the amplitude a = a_g / (g alpha)? The map is computed scene by
scene with the exact linear solver (the model of the closed forms) and with Housner's equation,
and the boundary curves of [000] Fig. 4 are drawn over it: overturning without impact (3.10),
after one impact following the pulse (3.18) and after one impact during the pulse (3.20-3.21),
separated by the limit (3.31).
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs

G, R, alpha, eta = 9.81, 1.0, 0.05, 0.9
p = np.sqrt(3 * G / (4 * R))
omega = np.linspace(0.5, 10.0, 160)
a = np.linspace(1.01, 12.0, 160)
W, A = np.meshgrid(omega, a)

fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
for ax, method in zip(axes, ("linear", "nonlinear")):
    out = rs.simulate_batch(half_diagonal=R, slenderness=alpha, restitution=eta, pulse="sine",
                            amplitude=(A * G * alpha).ravel(),
                            period=(2 * np.pi / (W * p)).ravel(), method=method)
    over = out["overturned"].reshape(A.shape)
    ax.pcolormesh(W, A, over, cmap="Greys", vmin=0, vmax=2.5, shading="auto")
    for case, color, label in (("2", "C3", "(3.10) no impact"),
                               ("1.2", "C0", "(3.18) impact after the pulse"),
                               ("1.1", "C2", "(3.20)-(3.21) impact during the pulse"),
                               ("limit", "C1", "(3.31) limit")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rs.ClosedFormValidityWarning)
            curves = rs.closedform.overturning_boundary(omega, eta=eta, case=case, a_max=12.0)
        for k in range(curves.shape[1]):
            ax.plot(omega, curves[:, k], color=color, lw=1.3, label=label if k == 0 else None)
    ax.set_title(f"{method} model (grey: overturns)")
    ax.set_xlabel(r"$\omega = \omega_g / p$")
axes[0].set_ylabel(r"$a = a_g / (g\,\alpha)$")
axes[0].set_ylim(1, 12)
axes[1].legend(loc="upper left", fontsize=8)
fig.tight_layout()
