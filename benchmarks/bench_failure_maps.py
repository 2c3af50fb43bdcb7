"""Failure maps (issue 6): where each method fails or degrades, over (psi, omega) and alpha.

psi = |a_g| / (g tan alpha) is the pulse peak over Housner's uplift level, omega = omega_g / p.
The reference is the nonlinear kernel at rtol 1e-11 (tested against scipy's DOP853 in
tests/test_engine.py). Panels, all on one-cycle sine pulses:

  1-2. linearized model (3.1): relative max-rotation error / alpha^2 at alpha = 0.05 and 0.3,
       overturning disagreements marked (what ``method="auto"`` reads its bound from);
  3.   nonlinear kernel at rtol 1e-3: relative max-rotation error (loose tolerance);
  4.   semi-implicit Euler at dt = 0.05 / p: error, with missed or spurious overturning;
  5.   chattering just above uplift (psi in (1, 1.2)): impacts per scene;
  6.   the kernel's error there at rtol 1e-6, where the response is 1e-4 ... 1e-1 alpha;
  7.   closed form (4.13) against the exact linear solver, and the (3.31) curve;
  8.   the complex formulation of [001] from rest at l = 1e-2 and 1e-3 (coarse grid).

Prints the shares the README quotes and writes benchmarks/results/failure_maps.{png,json}.

    python benchmarks/bench_failure_maps.py
"""

from __future__ import annotations

import json
import math
import sys
import time
import warnings
from pathlib import Path

import matplotlib
import numpy as np

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.verification.accuracy import (
    GRID_FREQUENCY,
    linearization_error_map,
    pulse_grid_batch,
    relative_max_rotation_error,
    tolerance_error_map,
)
from rockstudy.verification.validity import validity_map

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from bench_work_precision import _euler_scene  # noqa: E402

OUT = Path(__file__).parent / "results"
PSI = np.geomspace(1.001, 20.0, 60)
OMEGA = np.geomspace(0.1, 30.0, 60)
P = GRID_FREQUENCY


def euler_map(ref, alpha=0.2, eta=0.9, dt_p=5e-2):
    """Semi-implicit Euler at a fixed step dt = dt_p / p against the kernel (``ref``)."""
    dt = dt_p / P
    mx = np.empty((PSI.size, OMEGA.size))
    ov = np.empty(mx.shape, bool)
    for i, ps in enumerate(PSI):
        for j, w in enumerate(OMEGA):
            pulse = rs.motions.SinePulse(ps * G * math.tan(alpha), 2 * np.pi / (w * P))
            t = np.arange(0.0, pulse.duration + 20.0 / P, dt)
            acc = np.asarray(pulse.ground_acceleration(t), dtype=float)
            mx[i, j], ov[i, j], _ = _euler_scene(P, alpha, eta, acc, dt)
    return relative_max_rotation_error({"max_rotation": mx, "overturned": ov}, ref)


def _rocking(ref):
    """Scenes where the reference rocks and survives (relative errors are meaningful)."""
    return (ref["max_rotation"] > 0) & ~ref["overturned"]


def _stats(err, mask):
    e = err[mask]
    fin = e[np.isfinite(e)]
    return {
        "scenes": int(mask.sum()),
        "median_error": float(np.median(fin)) if fin.size else None,
        "p90_error": float(np.percentile(fin, 90)) if fin.size else None,
        "overturn_disagreement_all": float(np.isinf(err).mean()),
    }


def complex_map(alpha=0.2, eta=0.9, ls=(1e-2, 1e-3), n=8):
    psi, omega = np.geomspace(1.1, 8.0, n), np.geomspace(0.5, 10.0, n)
    ref = pulse_grid_batch("sine", psi, omega, alpha, eta, rtol=1e-11)
    blk = rs.Block(half_diagonal=3 * G / (4 * P * P), slenderness=alpha, restitution=eta)
    errs = []
    for ell in ls:
        mx = np.empty((n, n))
        ov = np.empty((n, n), bool)
        for i, ps in enumerate(psi):
            for j, w in enumerate(omega):
                pulse = rs.motions.SinePulse(ps * G * math.tan(alpha), 2 * np.pi / (w * P))
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", rs.AccuracyWarning)
                    r = rs.simulate(blk, pulse, method="complex", l=ell)
                mx[i, j], ov[i, j] = r.max_rotation, r.overturned
        errs.append(relative_max_rotation_error({"max_rotation": mx, "overturned": ov}, ref))
    return psi, omega, errs, _rocking(ref)


def _panel(ax, x, y, z, title, label, vmin=1e-6, vmax=1e1, marks=None):
    zz = np.where(np.isfinite(z), np.clip(z, vmin, vmax), np.nan)
    im = ax.pcolormesh(
        y, x, zz, norm=matplotlib.colors.LogNorm(vmin, vmax), shading="nearest", cmap="viridis"
    )
    if marks is not None and marks.any():
        ii, jj = np.nonzero(marks)
        ax.plot(y[jj], x[ii], "r.", ms=2, label="overturning disagrees")
        ax.legend(fontsize=6, loc="upper right")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("omega = omega_g / p")
    ax.set_ylabel("psi = a_g / (g tan alpha)")
    ax.set_title(title, fontsize=9)
    plt.colorbar(im, ax=ax, label=label)


def main():
    t0 = time.perf_counter()
    summary = {}
    lin = linearization_error_map("sine", PSI, OMEGA, (0.05, 0.3), 0.9)
    tol = tolerance_error_map("sine", PSI, OMEGA, (0.2,), 0.9, (1e-3, 1e-6))
    chat_psi = np.geomspace(1.0001, 1.2, 60)
    chat = pulse_grid_batch("sine", chat_psi, OMEGA, 0.2, 0.9, rtol=1e-12)
    chat_loose = pulse_grid_batch("sine", chat_psi, OMEGA, 0.2, 0.9, rtol=1e-6)
    chat_auto = pulse_grid_batch("sine", chat_psi, OMEGA, 0.2, 0.9, rtol=1e-6, method="auto")
    chat_err = relative_max_rotation_error(chat_loose, chat)
    chat_auto_err = relative_max_rotation_error(chat_auto, chat)
    ref02 = pulse_grid_batch("sine", PSI, OMEGA, 0.2, 0.9, rtol=1e-11)
    eul = euler_map(ref02)
    val = validity_map(a=np.geomspace(1.01, 20, 60), omega=OMEGA, eta=(0.9,), alpha=(0.05,))
    cpsi, comega, cerr, crock = complex_map()

    for k, al in enumerate(lin.alpha.values):
        e = lin.error.isel(eta=0, alpha=k).values
        rock = ~lin.overturned.isel(eta=0, alpha=k).values
        summary[f"linear_alpha_{al:g}"] = _stats(e, rock) | {
            "median_error_over_alpha2": float(np.nanmedian(np.where(rock, e, np.nan)) / al**2)
        }
    for k, rt in enumerate(tol.rtol.values):
        e = tol.error.isel(rtol=k, alpha=0).values
        summary[f"kernel_rtol_{rt:g}"] = _stats(e, _rocking(ref02)) | {
            "share_error_above_100_rtol": float(np.mean(e > 100 * rt)),
            "impact_count_differs": float(np.mean(tol.impact_count_error.isel(rtol=k) != 0)),
        }
    summary["euler_dt_0.05_over_p"] = _stats(eul, _rocking(ref02))
    summary["chattering_psi_1_to_1.2"] = {
        "median_impacts": float(np.median(chat["n_impacts"])),
        "max_impacts": int(chat["n_impacts"].max()),
        "kernel_rtol_1e-6_share_above_1e-6": float(np.mean(chat_err > 1e-6)),
        "auto_1e-6_share_above_1e-6": float(np.mean(chat_auto_err > 1e-6)),
    }
    cf_err = val.max_rotation_error.isel(eta=0).values
    during = val.impact_during_pulse.isel(eta=0).values
    summary["closed_form_4_13"] = {
        "median_error_below_3_31": float(np.nanmedian(np.where(during, cf_err, np.nan))),
        "median_error_above_3_31": float(np.nanmedian(np.where(~during, cf_err, np.nan))),
    }
    for ell, e in zip((1e-2, 1e-3), cerr, strict=True):
        summary[f"complex_l_{ell:g}_from_rest"] = _stats(e, crock)

    fig, axes = plt.subplots(2, 4, figsize=(22, 9))
    ax = axes.ravel()
    for k, al in enumerate(lin.alpha.values):
        e = lin.scaled_error.isel(eta=0, alpha=k).values
        _panel(
            ax[k],
            PSI,
            OMEGA,
            e,
            f"linear (3.1) error / alpha^2, alpha = {al:g}, eta = 0.9",
            "rel. error / alpha^2",
            1e-3,
            1e4,
            np.isinf(e),
        )
    e = tol.error.isel(rtol=0, alpha=0).values
    _panel(
        ax[2],
        PSI,
        OMEGA,
        e,
        "nonlinear kernel, rtol 1e-3 (alpha 0.2)",
        "rel. error",
        1e-8,
        1e0,
        np.isinf(e),
    )
    _panel(
        ax[3],
        PSI,
        OMEGA,
        eul,
        "semi-implicit Euler, dt = 0.05 / p (alpha 0.2)",
        "rel. error",
        1e-4,
        1e1,
        np.isinf(eul),
    )
    _panel(
        ax[4],
        chat_psi,
        OMEGA,
        chat["n_impacts"].astype(float),
        "chattering just above uplift: impacts per scene",
        "impacts",
        1,
        1e5,
    )
    _panel(
        ax[5],
        chat_psi,
        OMEGA,
        chat_err,
        "kernel rtol 1e-6 there (auto 1e-6 fixes it)",
        "rel. error",
        1e-9,
        1e0,
        np.isinf(chat_err),
    )
    A = val.a.values
    _panel(
        ax[6],
        A,
        OMEGA,
        cf_err.T,  # dims (omega, a) -> (a, omega)
        "(4.13) vs exact linear solver; line: (3.31)",
        "rel. error",
        1e-12,
        1e1,
    )
    lim = rs.closedform.limit_residual(*np.meshgrid(A, OMEGA, indexing="ij"))
    ax[6].contour(OMEGA, A, lim, levels=[0.0], colors="w", linewidths=1)
    _panel(
        ax[7],
        cpsi,
        comega,
        cerr[0],
        "complex [001] from rest, l = 1e-2",
        "rel. error",
        1e-3,
        1e2,
        np.isinf(cerr[0]),
    )
    ax[6].set_ylabel("a = a_g / (g alpha)")
    fig.suptitle("rockstudy failure maps (one-cycle sine pulses; reference: kernel rtol 1e-11)")
    fig.tight_layout()
    OUT.mkdir(exist_ok=True)
    fig.savefig(OUT / "failure_maps.png", dpi=110)
    summary["seconds"] = time.perf_counter() - t0
    (OUT / "failure_maps.json").write_text(json.dumps(summary, indent=2))
    print(json.dumps(summary, indent=2))


if __name__ == "__main__":
    main()
