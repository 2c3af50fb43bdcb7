"""
A rocking spectrum
==================

The maximum rotation of slender blocks under a one-cycle sine pulse, against the frequency
ratio omega = omega_g / p, for three amplitudes a = a_g / (g alpha). The closed form (4.13) of
[000] (the peak after the first impact that follows the pulse) is drawn with the exact linear
solver and with Housner's nonlinear equation on the same scenes.
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs

G = 9.81
alpha, R = 0.1, 1.0
p = np.sqrt(3 * G / (4 * R))
eta = 0.9
omega = np.linspace(1.0, 12.0, 300)

fig, ax = plt.subplots(figsize=(7, 4.5))
for a, color in ((1.5, "C0"), (3.0, "C1"), (6.0, "C2")):
    period = 2 * np.pi / (omega * p)
    amplitude = a * G * alpha
    for method, style in (("linear", "-"), ("nonlinear", "--")):
        out = rs.simulate_batch(half_diagonal=R, slenderness=alpha, restitution=eta,
                                pulse="sine", amplitude=amplitude, period=period, method=method)
        ratio = np.where(out["overturned"], np.nan, out["max_rotation"] / alpha)
        ax.plot(omega, ratio, style, color=color, lw=1.2,
                label=f"a = {a}, {method}" if method == "linear" else None)
    with warnings.catch_warnings():
        # (4.13) is approximate where the first impact comes during the pulse: it says so
        warnings.simplefilter("ignore", rs.ClosedFormValidityWarning)
        closed = rs.closedform.max_rotation(a, omega, eta)
    ax.plot(omega, closed, ":", color=color, lw=2)
ax.set_xlabel(r"$\omega = \omega_g / p$")
ax.set_ylabel(r"$\theta_{max} / \alpha$ (gaps: overturned)")
ax.set_ylim(0, 1.05)
ax.set_title("solid: exact linear solver, dashed: Housner, dotted: closed form (4.13)")
ax.legend()
fig.tight_layout()
