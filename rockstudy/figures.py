"""Paper [000]'s figures, recomputed: ``rockstudy figures --out DIR`` (or ``make figures``).

Every figure is computed from the solvers and the closed forms when the command runs; nothing
is read from stored numbers.

- ``fig04_overturning.png``: overturning plots in (omega, a) for several eta: the classifier's
  modes, the closed-form boundaries (3.10), (3.18), (3.20)-(3.21), (3.30), (3.31), and the
  points where the exact linear solver disagrees.
- ``fig06_collapse.png``: two different blocks under one-cosine pulses with equal groups,
  in dimensional terms and collapsed in (4.11).
- ``fig08_spectra.png``: rocking spectra theta_max g / a_g against omega, linear solver (solid)
  and (4.13) (dashed), eta from 0.80 to 0.96.
- ``fig10_nonslender_overturning.png``: overturning boundaries of non-slender blocks
  (nonlinear) in the (5.3) groups for several alpha.
- ``fig11_nonslender_histories.png``: non-slender responses in (4.11) and in (6.1) groups.
- ``fig13_nonslender_spectra.png``: nonlinear spectra in (6.1) groups for several alpha.

and of paper [003]: ``fig003_03_wall_errors.png`` (the rocking wall's equivalent block: period,
overturning-time and uplift errors) and ``fig003_10_arch*.png`` (the arch's rocking parameters,
and its errors for two inclusion angles).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from . import closedform as cf
from . import similarity as sim
from ._warnings import LinearizationWarning
from .constants import G
from .dynamics import simulate, simulate_batch
from .structures import Block

__all__ = [
    "fig003_14",
    "fig003_arch",
    "fig003_frame",
    "fig003_wall",
    "fig04",
    "fig06",
    "fig08",
    "fig10",
    "fig11",
    "fig13",
    "make_all",
]

_MODE_COLORS = ["#dddddd", "#9ecae1", "#c7e9c0", "#fdae6b", "#e6550d"]


def _plot_roots(ax, w, roots, **kw):
    """Plot each root column as a curve, broken where it jumps between branches."""
    for k in range(roots.shape[1]):
        y = roots[:, k].copy()
        y[1:][np.abs(np.diff(y)) > 0.05 * np.nanmax(np.abs(y), initial=1.0)] = np.nan
        ax.plot(w, y, **kw)
        kw.pop("label", None)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _linear_modes(a, omega, eta):
    from .verification.validity import linear_outcomes

    return linear_outcomes(a, omega, eta)[0]


def fig04(path, etas=(0.7, 0.8, 0.9, 1.0)):
    """Overturning plots of [000] Fig. 4."""
    plt = _plt()
    from matplotlib.colors import ListedColormap

    w = np.linspace(0.3, 10, 240)
    a = np.linspace(1.0, 10, 240)
    W, A = np.meshgrid(w, a)
    fig, axes = plt.subplots(1, len(etas), figsize=(4.2 * len(etas), 4.2), sharey=True)
    styles = {
        "2": ("k", "-"),
        "1.2": ("C3", "-"),
        "1.1": ("C0", "-"),
        "1.1-approx": ("C0", "--"),
        "limit": ("0.3", ":"),
    }
    for ax, eta in zip(axes, etas, strict=True):
        modes = cf.overturning_mode_code(A, W, eta)
        ax.pcolormesh(
            W, A, modes, cmap=ListedColormap(_MODE_COLORS), vmin=-0.5, vmax=4.5, shading="auto"
        )
        for case, (color, ls) in styles.items():
            roots = cf.overturning_boundary(w, eta, case, a_max=10.5)
            _plot_roots(ax, w, roots, color=color, ls=ls, lw=1.2, label=f"({case})")
        sub = (slice(None, None, 6), slice(None, None, 6))
        sim_modes = _linear_modes(A[sub].ravel(), W[sub].ravel(), eta).reshape(A[sub].shape)
        bad = sim_modes != modes[sub]
        ax.plot(W[sub][bad], A[sub][bad], "x", color="m", ms=4, label="linear solver disagrees")
        ax.set_title(f"eta = {eta:g}")
        ax.set_xlabel(r"$\omega_g / p$")
        ax.set_ylim(1, 10)
    axes[0].set_ylabel(r"$a_g / (g\alpha)$")
    axes[-1].legend(fontsize=7, loc="upper right")
    fig.suptitle(
        "Overturning of the linearized block under a sine pulse: modes "
        + ", ".join(f"{i}={m}" for i, m in enumerate(cf.MODES)),
        fontsize=8,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig06(path):
    """Two blocks, one master curve: [000] Figs. 5-6 (one-cosine pulses, eta = 0.85)."""
    plt = _plt()
    b1 = Block(1.0, 0.10, restitution=0.85)
    p1 = sim.pulse_for(b1, omega=4.0, ratio=0.5, law="4.11", shape="cosine")
    b2 = Block(3.2, 0.04, restitution=0.85)
    g = sim.groups(b1, p1)
    p2 = sim.pulse_for(b2, omega=g["omega"], ratio=g["inverse_a"], law="4.11", shape="cosine")
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    for blk, pulse, ls in ((b1, p1, "-"), (b2, p2, "--")):
        res = simulate(blk, pulse, method="linear", t_max=12.0 / blk.frequency_parameter)
        label = f"R = {blk.half_diagonal:g} m, alpha = {blk.slenderness:g}"
        ax1.plot(res.t, res.theta, ls, label=label)
        tau, y = sim.to_groups(res.t, res.theta, blk, pulse, "4.11")
        ax2.plot(tau, y, ls, label=label)
    ax1.set(xlabel="t [s]", ylabel=r"$\theta$ [rad]", title="dimensional")
    ax2.set(
        xlabel=r"$\tau = p t$",
        ylabel=r"$\theta g / a_g$",
        title=r"groups (4.11): $\omega_g/p$ = 4, $g\alpha/a_g$ = 0.5",
    )
    ax1.legend(fontsize=8)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig08(path, ratios=(0.2, 0.4, 0.6), etas=(0.80, 0.84, 0.88, 0.92, 0.96)):
    """Rocking spectra of [000] Fig. 8: linear solver against (4.13)."""
    plt = _plt()
    w = np.geomspace(0.5, 15, 300)
    from .verification.validity import linear_outcomes

    fig, axes = plt.subplots(1, len(ratios), figsize=(4.2 * len(ratios), 3.8))
    for ax, ratio in zip(axes, ratios, strict=True):
        a = 1.0 / ratio
        for k, eta in enumerate(etas):
            out = linear_outcomes(a, w, eta)[1]
            y = np.where(out["overturned"], np.nan, out["max_rotation"] / 0.05 / a)
            ax.plot(w, y, color=f"C{k}", label=f"eta = {eta:.2f}")
            ax.plot(w, cf.max_rotation(a, w, eta, check=False) / a, "--", color=f"C{k}", lw=0.9)
        ax.set(
            xlabel=r"$\omega_g/p$",
            ylabel=r"$\theta_{max} g / a_g$",
            title=rf"$g\alpha/a_g$ = {ratio:g} (solid: solver, dashed: 4.13)",
        )
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _nonlinear_overturn(alpha, w, ratio, eta=0.85):
    """Overturned (bool) of a nonlinear block (p = 1) over (ratio, omega) in (5.3) groups."""
    R = 3 * G / 4
    Wg, Rg = np.meshgrid(w, ratio)
    out = simulate_batch(
        half_diagonal=R,
        slenderness=alpha,
        restitution=eta,
        pulse="sine",
        amplitude=(G * np.tan(alpha) / Rg).ravel(),
        period=(2 * np.pi / Wg).ravel(),
        rtol=1e-8,
    )
    return Wg, Rg, out["overturned"].reshape(Wg.shape)


def fig10(path, alphas_deg=(2, 5, 10, 15, 20)):
    """Overturning of non-slender blocks in (5.3) groups, [000] Fig. 10 (eta = 0.85)."""
    plt = _plt()
    w = np.linspace(0.5, 10, 120)
    ratio = np.linspace(0.08, 0.99, 120)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for k, deg in enumerate(alphas_deg):
        Wg, Rg, over = _nonlinear_overturn(np.radians(deg), w, ratio)
        ax.contour(Wg, Rg, over.astype(float), levels=[0.5], colors=[f"C{k}"])
        ax.plot([], [], color=f"C{k}", label=f"alpha = {deg} deg (nonlinear)")
    for case in ("2", "1.2", "1.1"):
        roots = cf.overturning_boundary(w, 0.85, case, a_max=13)
        _plot_roots(ax, w, 1.0 / roots, color="k", ls=":", lw=1)
    ax.plot([], [], "k:", label="closed form (slender limit)")
    ax.set(
        xlabel=r"$\omega_g/p$",
        ylabel=r"$g\tan\alpha / a_g$",
        ylim=(0.08, 1.0),
        title="overturning boundaries, eta = 0.85 (overturns below the curves)",
    )
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig11(path, alphas=(0.15, 0.2, 0.25, 0.3), ratio=0.75, omega=4.0, eta=0.85):
    """Non-slender responses in (4.11) and (6.1) groups, [000] Figs. 11-12."""
    plt = _plt()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8), sharex=True)
    for k, alpha in enumerate(alphas):
        blk = Block(1.0, alpha, restitution=eta)
        pulse = sim.pulse_for(blk, omega=omega, ratio=ratio, law="6.1")
        res = simulate(blk, pulse, t_max=14.0 / blk.frequency_parameter)
        tau, y411 = sim.to_groups(res.t, res.theta, blk, pulse, "4.11")
        _, y61 = sim.to_groups(res.t, res.theta, blk, pulse, "6.1")
        ax1.plot(tau, y411, color=f"C{k}", label=f"alpha = {alpha:g}")
        ax2.plot(tau, y61, color=f"C{k}", label=f"alpha = {alpha:g}")
    ax1.set(xlabel=r"$\tau$", ylabel=r"$\theta g / a_g$", title="(4.11): not self-similar")
    ax2.set(
        xlabel=r"$\tau$",
        ylabel=r"$\theta g / (a_g \cos\alpha)$",
        title="(6.1): practically self-similar",
    )
    ax1.legend(fontsize=8)
    fig.suptitle(
        rf"nonlinear, $g\tan\alpha/a_g$ = {ratio:g}, $\omega_g/p$ = {omega:g}, "
        f"eta = {eta:g}",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig13(path, alphas=(0.1, 0.2, 0.3), ratios=(0.5, 0.75), eta=0.85):
    """Nonlinear spectra in (6.1) groups for different slenderness, [000] Fig. 13."""
    plt = _plt()
    w = np.geomspace(0.5, 15, 200)
    R = 3 * G / 4
    fig, axes = plt.subplots(1, len(ratios), figsize=(5 * len(ratios), 3.8))
    for ax, ratio in zip(axes, ratios, strict=True):
        for k, alpha in enumerate(alphas):
            a_g = G * np.tan(alpha) / ratio
            out = simulate_batch(
                half_diagonal=R,
                slenderness=alpha,
                restitution=eta,
                pulse="sine",
                amplitude=a_g,
                period=2 * np.pi / w,
            )
            y = np.where(out["overturned"], np.nan, out["max_rotation"] * G / (a_g * np.cos(alpha)))
            ax.plot(w, y, color=f"C{k}", label=f"alpha = {alpha:g}")
        ax.set(
            xlabel=r"$\omega_g/p$",
            ylabel=r"$\theta_{max} g / (a_g\cos\alpha)$",
            title=rf"$g\tan\alpha/a_g$ = {ratio:g}, eta = {eta:g}",
        )
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


FIGURES = {
    "fig04_overturning.png": fig04,
    "fig06_collapse.png": fig06,
    "fig08_spectra.png": fig08,
    "fig10_nonslender_overturning.png": fig10,
    "fig11_nonslender_histories.png": fig11,
    "fig13_nonslender_spectra.png": fig13,
}


def make_all(out_dir="results/figures") -> list[Path]:
    """Compute and write every figure into ``out_dir``; returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    with warnings.catch_warnings():  # [000]'s figures are about the linearized model itself
        warnings.simplefilter("ignore", LinearizationWarning)
        for name, fn in FIGURES.items():
            fn(out / name)
            paths.append(out / name)
    return paths


def _error_panels(path, ds, xname, xlabel, title):
    """Period, overturning-time (kappa_1, kappa_2) and uplift errors against one parameter."""
    plt = _plt()
    fig, axes = plt.subplots(1, 4, figsize=(17, 3.8))
    x = ds[xname].values
    for j, r in enumerate(ds.amplitude.values):
        axes[0].plot(x, ds.period_ratio.values[:, j], "o-", ms=3, label=f"phi/phi_cr = {r:g}")
    for ax, var, k in (
        (axes[1], "overturn_time_ratio_kappa1", "kappa_1"),
        (axes[2], "overturn_time_ratio_kappa2", "kappa_2"),
    ):
        for j, r in enumerate(ds.acceleration.values):
            ax.plot(x, ds[var].values[:, j], "o-", ms=3, label=f"u_g''/(g lambda) = {r:g}")
        ax.set(xlabel=xlabel, ylabel="t_over,blockeq / t_over,mech", title=f"overturning, {k}")
    axes[3].plot(x, ds.uplift_ratio.values, "ko-", ms=3)
    axes[3].set(xlabel=xlabel, ylabel="lambda_lin / lambda", title="uplift")
    axes[0].set(xlabel=xlabel, ylabel="T_blockeq / T_mech", title="free-rocking period")
    axes[0].legend(fontsize=7)
    axes[1].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig003_wall(path):
    """[003] Fig. 3: the rocking wall's equivalent block, errors against slenderness."""
    from .structures import RockingWall
    from .verification.equivalent_errors import error_map

    alphas = np.linspace(0.03, 0.35, 12)
    ds = error_map([RockingWall(1.0, a) for a in alphas], {"slenderness": alphas})
    _error_panels(path, ds, "slenderness", "alpha [rad]", "rocking wall (slider-crank)")


def fig003_arch(path):
    """[003] Figs. 10-13: the arch's equivalent block, errors against the thickness ratio for a
    semicircular arch (beta = pi) and for beta = 2.4 rad."""
    from .structures import Arch
    from .verification.equivalent_errors import error_map

    plt = _plt()
    ratios = np.linspace(0.12, 0.22, 8)
    paths = []
    for beta in (math.pi, 2.4):
        ds = error_map([Arch(beta, t * 5.0, 5.0) for t in ratios], {"thickness_ratio": ratios})
        sub = Path(str(path).replace(".png", f"_beta{beta:.2f}.png"))
        _error_panels(
            sub, ds, "thickness_ratio", "t_a / r_a", f"arch, inclusion angle {beta:.3f} rad"
        )
        paths.append(sub)
    # the summary figure: the arch's rocking parameters (Fig. 10)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    for beta in (2.0, 2.4, 2.8, math.pi):
        rps = [Arch(beta, t * 5.0, 5.0).rocking_parameters() for t in ratios]
        axes[0].plot(
            ratios,
            [r.frequency_parameter * math.sqrt(5.0 / G) for r in rps],
            label=f"beta = {beta:.2f}",
        )
        axes[1].plot(ratios, [r.critical_rotation for r in rps])
        axes[2].plot(ratios, [r.uplift for r in rps])
    axes[0].set(xlabel="t_a / r_a", ylabel="p sqrt(r_a / g)")
    axes[1].set(xlabel="t_a / r_a", ylabel="phi_cr [rad]")
    axes[2].set(xlabel="t_a / r_a", ylabel="lambda")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


FIGURES["fig003_03_wall_errors.png"] = fig003_wall
FIGURES["fig003_10_arch.png"] = fig003_arch


def fig003_14(path):
    """[003] Fig. 14: an asymmetric frame under a record-like motion (Kanai-Tajimi noise with a
    near-fault sine pulse in it) and under the pulse alone: the full mechanism against the
    equivalent block (kappa_1, directions averaged), phi = kappa theta."""
    from .motions import Record, SinePulse, stochastic_record
    from .structures import AsymmetricFrame

    plt = _plt()
    frame = AsymmetricFrame(0.3, 2.0, 1.6, 6.0, 0.25, 1.0, 1.5, 1.0, restitution=0.9)
    pos, neg = frame.rocking_parameters()
    lam = 0.5 * (pos.uplift + neg.uplift)
    pulse = SinePulse(1.4 * G * lam, 0.8)
    noise = stochastic_record(peak=0.8 * G * lam, duration=12.0, dt=0.005, seed=14)
    t = noise.time
    shifted = np.where(
        (t >= 3.0) & (t <= 3.0 + pulse.duration), pulse.ground_acceleration(t - 3.0), 0.0
    )
    record = Record(noise.acceleration + shifted, dt=noise.dt, name="record-like")
    block = frame.equivalent_block("kappa1")
    fig, axes = plt.subplots(2, 2, figsize=(12, 6), sharex="col")
    for col, (motion, label, t0) in enumerate(
        ((record, "record-like motion", 0.0), (pulse, "its pulse alone", 3.0))
    ):
        axes[0, col].plot(
            t0
            + np.asarray(
                motion.time if isinstance(motion, Record) else np.linspace(0, motion.duration, 400)
            ),
            (
                motion.acceleration
                if isinstance(motion, Record)
                else motion.ground_acceleration(np.linspace(0, motion.duration, 400))
            )
            / G,
            lw=0.8,
        )
        axes[0, col].set(ylabel="u_g'' / g", title=label)
        full = simulate(frame, motion, t_max=motion.duration + 6.0)
        eq = simulate(block, motion, method="linear", t_max=motion.duration + 6.0)
        axes[1, col].plot(t0 + full.t, full.theta, label="mechanism, eq. (8)")
        axes[1, col].plot(
            t0 + eq.t, eq.theta * block.scale, "--", label="equivalent block (kappa_1)"
        )
        axes[1, col].set(xlabel="t [s]", ylabel="phi [rad]")
    axes[1, 0].legend(fontsize=8)
    fig.suptitle(
        f"asymmetric frame: lambda_p = {pos.uplift:.3f}, lambda_n = {neg.uplift:.3f}", fontsize=10
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


FIGURES["fig003_14_frame_record.png"] = fig003_14


def fig003_frame(path):
    """[003] Figs. 5-8: the asymmetric frame's equivalent block in each direction, against the
    height ratio H1 / H."""
    from .structures import AsymmetricFrame
    from .verification.equivalent_errors import Direction, error_map

    ratios = np.linspace(0.6, 1.0, 9)
    frames = [AsymmetricFrame(0.3, 2.0, 2.0 * r, 6.0, 0.25, 1.0, 1.5, 1.0) for r in ratios]
    for d, name in ((1, "p"), (-1, "n")):
        ds = error_map([Direction(f, d) for f in frames], {"height_ratio": ratios})
        sub = Path(str(path).replace(".png", f"_{name}.png"))
        _error_panels(
            sub,
            ds,
            "height_ratio",
            "H1 / H",
            f"asymmetric frame, rocking {'+x' if d == 1 else '-x'} ({name})",
        )
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    for d, name in ((0, "p"), (1, "n")):
        rps = [f.rocking_parameters()[d] for f in frames]
        axes[0].plot(ratios, [r.frequency_parameter for r in rps], "o-", label=name)
        axes[1].plot(ratios, [r.critical_rotation / math.atan2(0.3, 2.0) for r in rps], "o-")
        axes[2].plot(ratios, [r.uplift for r in rps], "o-")
    axes[0].set(xlabel="H1 / H", ylabel="p [rad/s]")
    axes[1].set(xlabel="H1 / H", ylabel="phi_cr / alpha")
    axes[2].set(xlabel="H1 / H", ylabel="lambda")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


FIGURES["fig003_05_frame.png"] = fig003_frame
