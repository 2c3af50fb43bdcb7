"""
Work against precision: choosing a method
=========================================

Every method trades cost for accuracy. Twenty random sine-pulse scenes are run by the numba
kernel through :func:`rockstudy.simulate_batch` and by scipy's ``solve_ivp`` (DOP853 with
events) at several tolerances, and compared with ``solve_ivp`` at rtol 1e-12. The kernel is two
to three orders of magnitude cheaper at equal error; the linearized model is cheaper still but
carries a modelling error that no tolerance removes (it grows as alpha^2). The full chart, with
every method of rockstudy on 200 scenes, is ``benchmarks/bench_work_precision.py``.
"""

import time
import warnings

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs

rng = np.random.default_rng(3)
n = 20
R = rng.uniform(0.5, 3.0, n)
alpha = rng.uniform(0.1, 0.3, n)
amp = rng.uniform(1.5, 4.0, n) * 9.81 * np.tan(alpha)
period = rng.uniform(0.2, 1.5, n)
scenes = [(rs.Block(R[i], alpha[i]), rs.motions.SinePulse(amp[i], period[i])) for i in range(n)]
reference = np.array([rs.simulate(b, m, method="scipy", rtol=1e-12).max_rotation
                      for b, m in scenes])


def error(x):
    """p90 of the relative max-rotation error against the reference."""
    return np.percentile(np.abs(x / reference - 1), 90)


rs.simulate_batch(half_diagonal=R, slenderness=alpha, amplitude=amp, period=period)  # compile
points = {}
for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
    t0 = time.perf_counter()
    out = rs.simulate_batch(half_diagonal=R, slenderness=alpha, amplitude=amp, period=period,
                            rtol=rtol)
    points.setdefault("kernel (simulate_batch)", []).append(
        ((time.perf_counter() - t0) / n, error(out["max_rotation"])))
for rtol in (1e-4, 1e-6, 1e-8):
    t0 = time.perf_counter()
    x = np.array([rs.simulate(b, m, method="scipy", rtol=rtol).max_rotation for b, m in scenes])
    points.setdefault("scipy DOP853 + events", []).append(
        ((time.perf_counter() - t0) / n, error(x)))
with warnings.catch_warnings():
    warnings.simplefilter("ignore", rs.LinearizationWarning)  # the error is the point here
    t0 = time.perf_counter()
    out = rs.simulate_batch(half_diagonal=R, slenderness=alpha, amplitude=amp, period=period,
                            method="linear")
    points["exact linear solver (3.1)"] = [((time.perf_counter() - t0) / n,
                                            error(out["max_rotation"]))]

fig, ax = plt.subplots(figsize=(7, 4.5))
for (name, pts), marker in zip(points.items(), "osD"):
    cost, err = np.array(pts).T
    ax.loglog(cost * 1e3, np.maximum(err, 1e-16), marker + "-", label=name)
ax.set_xlabel("CPU time per scene [ms]")
ax.set_ylabel("max-rotation error, p90 (vs scipy at 1e-12)")
ax.legend()
fig.tight_layout()
for name, pts in points.items():
    for cost, err in pts:
        print(f"{name:30s} {cost * 1e3:9.3f} ms/scene  error {err:.1e}")
