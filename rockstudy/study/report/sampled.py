"""``rockstudy report RESULT``: one self-contained HTML page, its PNG figures and CSV tables.

Sections are chosen by what the cube holds: a summary of the outcomes; Sobol' indices (sobol
studies); fragility curves against dimensional and dimensionless intensities; spectra and
overturning maps (grid studies); and the self-similarity of the response (replicated designs:
the collapse metric, and the eta^2 law of [000] eq. 4.16 for the linear model).
"""

from __future__ import annotations

import html
import json
import math
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from ...constants import STANDARD_GRAVITY, G
from ...motions import measures
from ..analysis import sampled as analysis
from ..analysis.fragility_fit import BAND_COLUMNS, LACK_OF_FIT_LEVEL, N_BOOT, binned_outcomes
from ..designs.sampling import VARIABLES, target_attributes
from ..spec.design_kinds import DESIGN_KINDS
from ..spec.sampler_spec import SAMPLER_LAYOUTS
from ._page import (
    _FRAGILITY_NAMES,
    NOT_REACHED,
    _capacities_as_measured,
    _Page,
    _plt,
    _shown,
    dataset_of,
    draw_fits,
    separation_note,
    shown_separation,
)

__all__ = ["make_report", "SLENDER_LIMIT"]


def _summary(page, ds):
    status = ds["status"].values if "status" in ds else np.ones(ds.sizes["sample"])
    rows = {
        "samples": int(status.size),
        "computed": int((status == 1).sum()),
        "failed": int((status == 2).sum()),
        "pending": int((status == 0).sum()),
    }
    if "overturned" in ds:
        rows["overturned share of the computed samples"] = float(
            np.mean(ds["overturned"].values[status == 1] == 1)
        )
    if "max_rotation_ratio" in ds and "overturned" in ds:
        r = ds["max_rotation_ratio"].values[(ds["overturned"].values == 0) & (status == 1)]
        for q in (0.5, 0.9, 0.99):
            rows[
                f"peak rotation / critical rotation of the survivors, {int(q * 100)} % quantile"
            ] = float(np.quantile(r, q)) if r.size else float("nan")
    page.table(pd.Series(rows, dtype=object).to_frame("value"), "summary", "Outcomes")


def _sobol(page, ds, study):
    for output in ("max_rotation_ratio", "overturned"):
        if output not in ds:
            continue
        with warnings.catch_warnings():  # the caption says what the warning says
            warnings.simplefilter("ignore", UserWarning)
            t = analysis.sobol_indices(ds, output, failed="impute", num_resamples=200)
            conv = analysis.sobol_convergence(ds, output, failed="impute", num_resamples=20)
        fell = int((ds["overturned"].values == 1).sum()) if "overturned" in ds else 0
        mixed = (
            f" On the whole Saltelli design: the {fell} samples that overturned enter with "
            "their fall rotation (pi/2 over theta_cr), so these indices mix overturning with "
            "the rocking amplitude."
            if output in analysis.ROTATION_OUTPUTS and fell
            else ""
        )
        page.table(t, f"sobol_{output}", f"Sobol' indices of {output} (95 % bootstrap).{mixed}")
        conv.to_csv(page.out / f"sobol_convergence_{output}.csv")
        plt = _plt()
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 3.6))
        x = np.arange(len(t))
        a1.bar(x - 0.2, t["S1"], 0.4, yerr=t["S1_conf"], label="S1")
        a1.bar(x + 0.2, t["ST"], 0.4, yerr=t["ST_conf"], label="ST")
        a1.set_xticks(x, t.index, rotation=20)
        a1.set(title=f"Sobol' indices of {output}")
        a1.legend()
        for name in t.index:
            s = conv.xs(name, level="input")
            a2.semilogx(s.index, s["ST"], "o-", label=name)
        a2.set(xlabel="N (base samples)", ylabel="ST", title="convergence on nested prefixes")
        a2.legend(fontsize=7)
        fig.tight_layout()
        page.figure(
            fig, f"sobol_{output}", f"Sobol' indices of {output} and their convergence.{mixed}"
        )


def _middle_third(values):
    """Samples in the middle third of a variable's range (quantiles 1/3 to 2/3)."""
    lo, hi = np.quantile(values, [1 / 3, 2 / 3])
    return (values >= lo) & (values <= hi)


_BANDS = {
    "period": "pulse period T_p in its middle third",
    "omega": "omega_g / p in its middle third",
}


#: The two views of the fragility: (intensity, pulse variable held to its middle third, axis
#: label). Dimensional first, then the groups of (6.1).
_FRAGILITY_VIEWS = (
    (
        "abs_amplitude",
        "period",
        "pulse amplitude a_g [m/s^2], pulse period T_p in its middle third",
    ),
    (
        "amplitude_ratio",
        "omega",
        "amplitude ratio a_g / a_up [-], omega_g / p in its middle third",
    ),
)


def _fragility(page, ds, study=None):
    """Fragility by block size: against a_g for pulses of similar period T_p (dimensional),
    and against a_g / (g tan alpha) for pulses of similar omega_g / p (the groups of 6.1)."""
    if "overturned" not in ds or "amplitude" not in ds or "half_diagonal" not in ds:
        return
    d = ds.assign(abs_amplitude=np.abs(ds["amplitude"]))
    bins = np.quantile(d["half_diagonal"].values, [0, 1 / 3, 2 / 3, 1])
    bins[-1] += 1e-12
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    tables = [
        t
        for ax, view in zip(axes, _FRAGILITY_VIEWS, strict=True)
        if (t := _fragility_view(page, ax, d, bins, *view)) is not None
    ]
    if not tables or not any(ax.get_visible() for ax in axes):
        plt.close(fig)
        if tables:  # every fit separated: the table, no curve
            _fragility_table(page, pd.concat(tables))
            _fragility_spread(page, tables)
        return
    axes[0].set_title("dimensional intensity")
    axes[1].set_title("dimensionless groups (6.1)")
    fig.tight_layout()
    page.figure(
        fig,
        "fragility",
        "Lognormal fragility curves (MLE, 90 % pointwise bands of the probability over both "
        "the median and beta) by "
        "block size: in dimensional terms the sizes spread apart, in the groups they "
        "collapse (to the extent the groups make the response self-similar); dashed: the "
        "median lies outside the sampled intensities; markers: the share of the samples that "
        "overturned in eight bins of equal count along the intensity, the data each curve is "
        "fitted to; a_up is the uplift acceleration (g tan alpha for a block)",
    )
    _lack_of_fit_warning(page, pd.concat(tables))
    _fragility_table(page, pd.concat(tables))
    _fragility_spread(page, tables)


def _fragility_view(page, ax, d, bins, im, band, label):
    """The fits by block size against ``im`` over the middle third of ``band``, drawn on
    ``ax`` with their bands; the table of the fits, or None (said on the page) when no block
    size saw both outcomes."""
    sub = d.isel(sample=np.flatnonzero(_middle_third(d[band].values)))
    try:
        with shown_separation():  # said on the page (separation_note)
            t = analysis.fragility(sub, im, by="half_diagonal", bins=bins, n_boot=N_BOOT)
    except ValueError as err:  # no block size saw both outcomes
        page.text(f"Fragility against {im}: {err}")
        return None
    # the samples of each fit, by its label, for the markers; then the groups by readable
    # names: "R 0.5 to 1.33 m" (analysis labels them by bins, "%g")
    fitted = analysis.fragility_samples(sub, im, by="half_diagonal", bins=bins)
    samples = [fitted[g] for g in t.index]
    t.index = [
        f"R {lo:.3g} to {hi:.3g} m"
        for lo, hi in (map(float, g.split("-")) for g in t.index.astype(str))
    ]
    t.index.name = "block size"
    t.insert(0, "intensity", im)
    t.insert(1, "band", band)
    grid = np.geomspace(float(sub[im].min()), float(sub[im].max()), 200)
    separation_note(page, t, f"Fragility against {im}")
    if draw_fits(ax, grid, analysis.fragility_curve(t, grid), t, _plain_log_ticks):
        _draw_observed(ax, samples)
        ax.set(xlabel=label, ylabel="probability of overturning")
    return t


def _draw_observed(ax, samples):
    """The samples each curve was fitted to (``samples``: its (intensities, outcomes), in the
    table's order), as the share overturned in 8 equal-count bins of the intensity (markers
    in the curve's colour, :func:`fragility_fit.binned_outcomes`)."""
    for k, (x, z) in enumerate(samples):
        at, share, _ = binned_outcomes(x, z == 1)
        ax.plot(at, share, "o", ms=4, color=f"C{k}", mec="k", mew=0.4)
    ax.plot([], [], "o", ms=4, color="0.6", mec="k", mew=0.4, label="samples, binned")
    ax.legend(fontsize=8)


def _lack_of_fit_warning(page, fit):
    """A warning naming the curves whose lognormal shape the samples reject (Hosmer-Lemeshow
    p below :data:`LACK_OF_FIT_LEVEL`)."""
    bad = fit[fit["lack_of_fit_p"] < LACK_OF_FIT_LEVEL]
    if bad.empty:
        return
    names = ", ".join(
        f"{g} against {_SHORT.get(r['intensity'], r['intensity'])} (p = {r['lack_of_fit_p']:.2g})"
        for g, r in bad.iterrows()
    )
    page.warning(
        f"The lognormal shape does not describe the samples of {names}: the Hosmer-Lemeshow "
        f"test rejects it at the {LACK_OF_FIT_LEVEL:g} level. Under pulses the probability of "
        "overturning need not rise to 1 with the amplitude (a short pulse topples a block "
        "only within a window of amplitudes); read those curves' medians and beta as a summary "
        "and the markers as the data."
    )


def _fragility_table(page, fit):
    """The fitted parameters: all of them in fragility_fit.csv, and on the page the medians
    as measured (g beside m/s^2), limits outside the sampled range read as not reached."""
    fit.to_csv(page.out / "fragility_fit.csv")
    shown = _capacities_as_measured(fit).drop(columns=list(BAND_COLUMNS))
    dimensional = (fit["intensity"] == "abs_amplitude").to_numpy()
    shown.insert(  # g next to m/s^2, read as not reached (or below) where the median is
        shown.columns.get_loc("theta") + 1,
        "median capacity [g] (a_g only)",
        [
            (v / STANDARD_GRAVITY if isinstance(v, float) else v) if dim else np.nan
            for v, dim in zip(shown["theta"], dimensional, strict=True)
        ],
    )
    page.table(
        shown.replace({"intensity": _SHORT, "band": _BANDS}).rename(columns=_FRAGILITY_NAMES),
        "fragility",
        "Fragility parameters (intensity: a_g [m/s^2] or a_g / a_up [-]): median "
        "capacity, its 90 % bootstrap band and the log-standard deviation beta (the MLE); a "
        "median "
        f"or band limit outside the group's sampled intensities (im_min-im_max) reads "
        f"'{NOT_REACHED}' (the fitted numbers and flags are in fragility_fit.csv)",
    )


def _fragility_spread(page, tables):
    """How far apart the block sizes' medians lie, for each intensity."""
    spread = []
    for t in tables:
        inside = t["theta"][t["theta_in_range"]]
        name = _SHORT.get(t["intensity"].iloc[0], t["intensity"].iloc[0])
        spread.append(
            f"{name}: {inside.max() / inside.min():.2f}"
            if inside.size >= 2
            else f"{name}: not measured (fewer than two medians within the sampled range)"
        )
    page.text(
        "Spread of the median capacity between block sizes (largest over smallest, medians within "
        "the sampled range only): " + ", ".join(spread)
    )


def _grid(page, ds, study=None):
    dims = list(ds.dims)
    if len(dims) != 2:
        return
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    y, x = dims
    for ax, var in zip(axes, ("overturned", "max_rotation_ratio"), strict=True):
        if var not in ds:
            continue
        val = ds[var].values.astype(float)
        if var == "max_rotation_ratio" and "overturned" in ds:
            val = np.where(ds["overturned"].values == 1, np.nan, val)
        mesh = ax.pcolormesh(ds[x].values, ds[y].values, val, shading="auto")
        fig.colorbar(mesh, ax=ax)
        ax.set(xlabel=x, ylabel=y, title=var, xscale="log", yscale="log")
    fig.tight_layout()
    page.figure(fig, "grid_maps", "Overturning map and rocking spectrum over the grid")


def _similarity(page, ds, study):
    law_411 = study.motion.amplitude_a is not None
    groups = ["a" if law_411 else "uplift_ratio", "omega", "restitution"]
    surv = ds.isel(sample=np.flatnonzero(ds["overturned"].values == 0))
    # the response of the design's law: theta / alpha (4.10; theta g / a_g differs by the group
    # factor 1 / a only) or theta g / (a_g cos alpha) = theta * uplift_ratio / sin(alpha) (6.1)
    response = (
        surv["max_rotation"] / surv["slenderness"]
        if law_411
        else surv["max_rotation"] * surv["uplift_ratio"] / np.sin(surv["slenderness"])
    )
    surv = surv.assign(law_response=response)
    rows = {}
    for label, sel in (
        ("all", slice(None)),
        ("slender (alpha < 0.12)", surv["slenderness"].values < 0.12),
        ("non-slender (alpha > 0.2)", surv["slenderness"].values > 0.2),
    ):
        sub = surv if label == "all" else surv.isel(sample=np.flatnonzero(sel))
        try:
            collapse = analysis.collapse_metric(sub, "law_response", groups)
        except ValueError:  # too few survivors share a group point in this subset
            collapse = "not replicated (too few survivors share a group point)"
        row = {"collapse metric (design groups)": collapse}
        for law, resp, law_groups in (
            (
                "(4.11)",
                sub["max_rotation"] * G / (sub["a"] * G * sub["slenderness"]),
                ["a", "omega", "restitution"],
            ),
            (
                "(6.1)",
                sub["max_rotation"]
                / (sub["uplift_ratio"] ** -1 * np.tan(sub["slenderness"]) * sub["cos_alpha"]),
                ["uplift_ratio", "omega", "restitution"],
            ),
        ):
            share = analysis.unexplained_share(sub.assign(resp=resp), "resp", law_groups)
            row[f"unexplained share, {law} groups"] = share.value
            row[f"its floor, {law} groups"] = share.floor
        rows[label] = {**row, "samples": sub.sizes["sample"]}
    page.table(
        pd.DataFrame(rows).T,
        "collapse",
        "Share of the variance of the survivors' response within group points "
        f"({', '.join(groups)}), and left unexplained by a smooth fit over each law's "
        "groups, next to that fit's floor (the share it leaves for a smooth, cubic response of "
        "the groups alone on the same samples; a lower estimate: values within a few times "
        "the floor cannot be told from complete similarity with this many samples)",
    )
    if study.run.method == "linear" and study.motion.amplitude_a is not None:
        _eta_law(page, surv)


def _eta_law(page, surv):
    """The restitution law (4.14)-(4.16) of [000] against the cube's linear responses."""
    from ...closedform import d0_star, limit_residual

    a, w, eta = (surv[v].values for v in ("a", "omega", "restitution"))
    after = limit_residual(a, w) < 0  # first impact after the pulse
    x = eta**2 * (1 - d0_star(a, w))
    law = 0.5 * x
    th = surv["max_rotation_ratio"].values
    ok = after & np.isfinite(x) & (x > 0) & (th >= law * 0.5)
    err = np.abs(law[ok] / th[ok] - 1)
    edges = np.array([0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.0])
    idx = np.digitize(x[ok], edges)
    rows = {
        f"{edges[i - 1]:g}-{edges[i]:g}": {
            "median rel. error": float(np.median(err[idx == i])),
            "samples": int((idx == i).sum()),
        }
        for i in range(1, len(edges))
        if np.any(idx == i)
    }
    page.table(
        pd.DataFrame(rows).T,
        "eta_law",
        "eta^2 law theta_m/alpha ~ eta^2 (1 - D0*) / 2 (eq. 4.14 with the expansion of "
        "4.13) against the linear solver, by x = eta^2 (1 - D0*), impacts after the pulse",
    )
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(law[ok], th[ok], ".", ms=2)
    lim = [law[ok].min(), law[ok].max()]
    ax.plot(lim, lim, "k--", lw=1)
    ax.set(xlabel="eta^2 (1 - D0*) / 2", ylabel="theta_max / alpha (solver)")
    fig.tight_layout()
    page.figure(fig, "eta_law", "The eta^2 law against the solver")


#: short names in words for figure labels (the cube's long names are for the tables)
_SHORT = {
    "half_diagonal": "half-diagonal R [m]",
    "slenderness": "slenderness alpha [rad]",
    "restitution": "restitution eta [-]",
    "amplitude": "pulse amplitude a_g [m/s^2]",
    "abs_amplitude": "pulse amplitude a_g [m/s^2]",
    "amplitude_ratio": "amplitude ratio a_g / a_up (g tan alpha for a block) [-]",
    "amplitude_a": "a = a_g / (g alpha) [-]",
    "period": "pulse period T_p [s]",
    "frequency_ratio": "frequency ratio omega_g / p [-]",
    "omega": "frequency ratio omega_g / p [-]",
    "max_rotation_ratio": "peak rotation / critical rotation [-]",
    "overturned": "overturned (0 or 1)",
}


def _units(name):
    """'long name [units]' of a cube variable, in words (a measure's: the registry's label and
    its SI unit, as the cube stores it)."""
    if name in measures.MEASURES:
        long_name, units = measures.MEASURES[name].label, measures.MEASURES[name].unit
    else:
        long_name, units = VARIABLES.get(name, (name, "1"))
    return f"{long_name} [{'-' if units == '1' else units}]"


def _label(name):
    """A short label in words with units, for axes and legends."""
    return _SHORT.get(name) or _units(name)


def _plain_log_ticks(ax):
    """Tick labels of a logarithmic x axis as plain numbers (2, 3, 10), not 2 x 10^0; the
    minor ticks just below a decade (0.9, 9) unlabelled, where they would crowd its label."""
    from matplotlib.ticker import FuncFormatter

    def minor(v, _):
        return "" if round(v / 10.0 ** math.floor(math.log10(v))) == 9 else f"{v:g}"

    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(minor))
    ax.tick_params(axis="x", which="minor", labelsize=7)


def _study_file(page, study, ds=None):
    """The input distributions as a table, the study file as read when the run started (its
    text, stored with the run), and the study as the cube stores it (defaults filled in)."""
    rows = {}
    for name, dist in study.parameters().items():
        spec = dist.model_dump(mode="json")
        kind = spec.pop("dist")
        quantity = _units(name)
        if name == "target":  # a record's scale target, in its measure's units
            attrs = target_attributes(study.motion.scale_to)
            quantity = f"{attrs['long_name']} [{attrs['units']}]"
        rows[name] = {
            "quantity": quantity,
            "distribution": kind,
            "parameters": ", ".join(f"{k} = {_shown(v)}" for k, v in spec.items()),
        }
    if rows:
        page.table(
            pd.DataFrame(rows).T.rename_axis("parameter"),
            "inputs",
            "Input distributions of the sampled parameters",
        )
    text = None if ds is None else ds.attrs.get("study_text")
    if text:
        page.text("The study file, as read when the run started:")
        page.preformatted(str(text))
    else:
        page.text(
            "The study file's text was not stored with this result (a run of an older "
            "rockstudy, or a study given as an object)."
        )
    page.text("The study as stored in the result (defaults filled in):")
    page.preformatted(json.dumps(json.loads(study.normalized()), indent=2))


def _failures(page, ds):
    """Failed samples counted by their error message."""
    if "status" not in ds or "error" not in ds:
        return
    failed = ds["status"].values == 2
    if not failed.any():
        return
    messages = [
        m.decode("utf-8", "replace") if isinstance(m, bytes) else str(m)
        for m in ds["error"].values[failed]
    ]
    counts = pd.Series(messages, dtype=object).value_counts()
    page.heading("Failed samples")
    page.table(
        pd.DataFrame({"samples": counts.astype(object)}).rename_axis("message"),
        "failures",
        f"{int(failed.sum())} failed samples, counted by their error message",
    )


def _computed(ds):
    """The samples that were computed (status 1)."""
    if "status" not in ds:
        return ds
    return ds.isel(sample=np.flatnonzero(ds["status"].values == 1))


def _response(page, ds, study=None):
    """Distributions of the response: theta_max / theta_cr of the survivors, and the
    overturned share against the amplitude ratio."""
    if "max_rotation_ratio" not in ds or "overturned" not in ds:
        return
    d = _computed(ds)
    over = d["overturned"].values == 1
    ratio = d["max_rotation_ratio"].values[~over]
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 3.8))
    a1.hist(ratio, bins=40, range=(0.0, 1.0), color="C0")
    a1.set(
        xlabel="peak rotation / critical rotation, theta_max / theta_cr [-]",
        ylabel="survivors (count)",
        title=f"survivors: {int((~over).sum())} of {over.size}",
    )
    im = "amplitude_ratio" if "amplitude_ratio" in d else None
    if im is not None:
        x = d[im].values
        edges = np.quantile(x, np.linspace(0, 1, 11))
        idx = np.clip(np.digitize(x, edges) - 1, 0, 9)
        share = np.array([over[idx == i].mean() if np.any(idx == i) else np.nan for i in range(10)])
        a2.stairs(share, edges, fill=True, alpha=0.6, color="C3")
        a2.set(xlabel=_label(im), ylabel="overturned share [-]", ylim=(0, 1))
    else:
        a2.bar(
            ["survived", "overturned"], [int((~over).sum()), int(over.sum())], color=["C0", "C3"]
        )
        a2.set(ylabel="samples (count)")
    a2.set_title(f"overturned share {over.mean():.3g} ({int(over.sum())} samples)")
    fig.tight_layout()
    page.figure(
        fig,
        "response",
        "Left: the peak rotation over the critical rotation of the blocks that did not "
        "overturn. Right: the share of samples that overturned, in ten equally populated bins "
        "of the amplitude ratio",
    )


#: slenderness up to which the closed forms of [000] (linearized, slender) are drawn
SLENDER_LIMIT = 0.35


def _overturning_map(page, ds, study):
    """The samples in the plane of the groups (omega_g / p, a_g / (g tan alpha)), coloured by
    outcome, with the closed-form boundaries of [000] Fig. 4 (sine pulse, linearized slender
    block) where they apply."""
    if not {"omega", "amplitude_ratio", "overturned"} <= set(ds.variables):
        return
    from ...closedform import overturning_boundary

    d = _computed(ds)
    w, a, over = d["omega"].values, d["amplitude_ratio"].values, d["overturned"].values == 1
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5.6))
    ax.scatter(w[~over], a[~over], s=3, c="C0", alpha=0.4, lw=0, label="survived")
    ax.scatter(w[over], a[over], s=3, c="C3", alpha=0.4, lw=0, label="overturned")
    applies = (
        getattr(study.motion, "shape", None) == "sine"
        and float(d["critical_rotation"].max()) <= SLENDER_LIMIT  # of the block simulated
    )
    if applies:
        eta = float(np.median(d["restitution"].values)) if "restitution" in d else 1.0
        grid = np.geomspace(max(w.min(), 0.05), w.max(), 400)
        for case, style, label in (
            ("2", "k-", "no impact (3.10)"),
            ("1.2", "k--", f"one impact after the pulse (3.18), eta = {eta:.3g}"),
            ("1.1", "k:", f"one impact during the pulse (3.20-3.21), eta = {eta:.3g}"),
        ):
            roots = overturning_boundary(grid, eta=eta, case=case, a_max=float(a.max()) * 1.5)
            for k in range(roots.shape[1]):
                r = roots[:, k].copy()
                r[1:][np.abs(np.diff(np.log(r))) > 0.1] = np.nan  # no line across branches
                ax.plot(grid, r, style, lw=1.2, label=label if k == 0 else None)
        note = (
            "Lines: the closed-form boundaries of [000] Fig. 4 for a sine pulse and the "
            "linearized slender block, in a = a_g / (g alpha), which differs from "
            "a_g / (g tan alpha) by under 4 % for alpha <= 0.35; eta is the median restitution "
            "of the samples. They do not apply to other pulse shapes, records, or blocks that "
            "are not slender; for the nonlinear model they are a guide."
        )
    else:
        note = (
            "No closed-form boundary drawn: those of [000] Fig. 4 hold for a sine pulse on a "
            f"slender block (theta_cr <= {SLENDER_LIMIT}, of the block simulated) only."
        )
    ax.set(
        xscale="log",
        xlabel="frequency ratio omega_g / p [-]",
        ylabel="amplitude ratio a_g / a_up [-]",
        ylim=(float(a.min()) * 0.95, float(a.max()) * 1.05),
        title="overturning map over the dimensionless groups",
    )
    _plain_log_ticks(ax)
    # below the axes: inside, it would hide the points and curves it explains
    ax.legend(fontsize=8, markerscale=4, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3)
    fig.tight_layout()
    page.figure(
        fig,
        "overturning_map",
        "Samples in the plane of the groups, by outcome (a_up: the uplift acceleration, g tan "
        "alpha for a block). " + note,
    )


def _of_survivors(ds, output):
    """The samples of ``ds`` that did not overturn, for a peak rotation (an overturned
    sample's is the fall rotation); every sample for another output."""
    if output not in analysis.ROTATION_OUTPUTS or "overturned" not in ds:
        return ds
    return ds.isel(sample=np.flatnonzero(ds["overturned"].values == 0))


def _first_order(page, ds, study):
    """First-order sensitivity (RBD-FAST on the given samples) on the inputs and on the
    dimensionless groups."""
    inputs = [v for v in study.parameters() if v in ds]
    groups = [v for v in ("omega", "amplitude_ratio", "slenderness") if v in ds]
    outputs = [v for v in ("max_rotation_ratio", "overturned") if v in ds]
    if not inputs or not outputs:
        return
    d = _computed(ds)
    if d.sizes["sample"] < 100:
        page.text("First-order sensitivity: not computed (fewer than 100 computed samples).")
        return
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
    tables = []
    for ax, (label, names) in zip(axes, (("inputs", inputs), ("groups", groups)), strict=True):
        x = np.arange(len(names))
        for k, out in enumerate(outputs):
            t = analysis.first_order_given_data(_of_survivors(d, out), out, names)
            t.index = [_label(n) for n in names]
            t.index.name = "variable"
            t.insert(0, "output", _label(out))
            t.insert(0, "on", label)
            tables.append(t)
            ax.bar(x + (k - 0.5) * 0.4, t["S1"], 0.4, yerr=t["S1_conf"], label=_label(out))
        ax.set_xticks(x, ["\n".join(textwrap.wrap(_label(n), 18)) for n in names], fontsize=8)
        ax.set(title=f"on the {label}", ylabel="first-order index S1 [-]")
        ax.legend(fontsize=7)
    fig.tight_layout()
    page.figure(
        fig,
        "first_order",
        "First-order sensitivity indices (RBD-FAST on the samples, with their 95 % intervals) of "
        "the peak rotation ratio of the blocks that did not overturn (an overturned block's "
        "ratio is its fall rotation over theta_cr, which depends on theta_cr alone) and of "
        "overturning on every sample, on the sampled inputs and on the groups",
    )
    page.table(pd.concat(tables), "first_order", "First-order indices")


def _version(versions) -> str:
    """rockstudy's version from a cube's ``versions`` attribute (JSON), as plain text: the
    attribute comes from a file that may have been made or edited by anyone."""
    try:
        value = json.loads(versions)
    except (TypeError, ValueError):
        return "?"
    return str(value.get("rockstudy", "?")) if isinstance(value, dict) else "?"


def _contact(page, ds, study):
    """The scenes outside the block model (friction demand above mu, or lift-off)."""
    mu = study.friction_coefficients()
    if mu is None or "friction_demand" not in ds:
        return
    from ..analysis.contact import outside_model, summary_line

    line = summary_line(ds, mu)
    if line:
        page.warning(line)
    else:
        page.text("No scene needs more friction than mu or lifts off: the block model holds.")
    flags = outside_model(ds, mu)
    page.table(
        pd.DataFrame(
            {
                "scenes": [int(ds["friction_demand"].notnull().sum())],
                "friction coefficient mu [-]": [float(mu[0])],
                "largest friction demand |F_h / F_v| [-]": [
                    float(ds["friction_demand"].where(np.isfinite(ds["friction_demand"])).max())
                ],
                "lift-offs": [int((ds["lift_off"] == 1).sum())],
                "scenes outside the model": [int(flags.sum())],
            },
            index=pd.Index(["all"], name="scenes"),
        ),
        "friction_check",
        "The contact check: the friction demand max |F_h / F_v| of each scene against mu",
    )


def _acceleration_units(study) -> str:
    """The units of a record study's report accelerations: those of ``scale_to.units`` for
    a target the registry says is an acceleration (g, else m/s^2), g otherwise."""
    target = getattr(study.motion, "scale_to", None)
    if target is None or target.im not in measures.MEASURES:
        return "g"
    if not measures.is_acceleration(target.im):
        return "g"
    return "g" if target.unit_label == "g" else "m/s^2"


def _laid_out(layout):
    """Whether a study's sampler has ``layout`` (a value of
    :data:`~rockstudy.study.spec.sampler_spec.SAMPLER_LAYOUTS`)."""
    return lambda study, ds: SAMPLER_LAYOUTS[study.sampler.kind] == layout


#: The sections of a sampled study's page between its summary and its study file, in order:
#: (heading, whether the study and its cube have the section, the function that writes it:
#: (page, ds, study)). A new section is one entry.
_SECTIONS = (
    ("Response", _laid_out("random"), _response),
    ("Overturning map", _laid_out("random"), _overturning_map),
    ("First-order sensitivity", _laid_out("random"), _first_order),
    ("Sensitivity", _laid_out("saltelli"), _sobol),
    ("Spectrum and overturning map", _laid_out("grid"), _grid),
    (
        "Fragility",
        lambda study, ds: (
            SAMPLER_LAYOUTS[study.sampler.kind] != "grid" and study.motion.kind == "pulse"
        ),
        _fragility,
    ),
    (
        "Friction and lift-off: where the block model stops",
        lambda study, ds: study.friction_coefficients() is not None and "friction_demand" in ds,
        _contact,
    ),
    (
        "Self-similarity",
        lambda study, ds: study.sampler.replicates > 1 and "overturned" in ds,
        _similarity,
    ),
)


def make_report(result, out=None, verify: bool = True) -> Path:
    """Write the report of a result cube into ``out`` (default: RESULT's name + '_report').

    ``result`` is the path of the cube or the cube itself, an :class:`xarray.Dataset` (as
    :func:`~rockstudy.study.report.records.record_report` takes either; then ``out`` is
    required). ``verify=False`` reads a cube's path without checking it against the
    checksums of its run (see :func:`~rockstudy.study.running.store.open_result`): a cube
    whose metadata was edited."""
    if isinstance(result, xr.Dataset) and out is None:
        raise ValueError("out: give the report's folder when result is a Dataset")
    ds, name = dataset_of(result, "result", verify)
    out = Path(out) if out is not None else Path(result).with_name(name + "_report")
    out.mkdir(parents=True, exist_ok=True)
    if ds.attrs.get("design") in DESIGN_KINDS:  # a record design
        from .records import record_report

        if "study" not in ds.attrs:  # a design run from Python and saved: no study file
            return record_report(ds, out, title=name or "Record design")
        study = analysis.study_of(ds)

        def study_section(page):
            page.heading("Study")
            _study_file(page, study, ds)

        hazard = study.hazard
        return record_report(
            ds,
            out,
            title=study.name,
            description=study.description,
            appendix=study_section,
            hazard=None if hazard is None else hazard.curve(),
            years=50.0 if hazard is None else hazard.years,
            units=_acceleration_units(study),
            max_scale_factor=study.design.max_scale_factor,
            friction=study.friction_coefficients(),
            study=study,
        )
    study = analysis.study_of(ds)
    page = _Page(out)
    page.heading("Summary")
    _summary(page, ds)
    _failures(page, ds)
    for heading, applies, section in _SECTIONS:
        if applies(study, ds):
            page.heading(heading)
            section(page, ds, study)
    page.heading("Study")
    _study_file(page, study, ds)
    meta = (
        f"<p>{html.escape(study.description)}</p><p class='cap'>study sha256 "
        f"{html.escape(str(ds.attrs.get('study_sha256', ''))[:16])}, seed {study.seed}, "
        f"rockstudy {html.escape(_version(ds.attrs.get('versions')))}</p>"
    )
    return page.write(f"rockstudy report: {study.name}", meta)
