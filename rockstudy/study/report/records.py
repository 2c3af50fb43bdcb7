"""The report of a record design (cloud, multiple stripes or IDA).

From a dataset of :mod:`rockstudy.study.designs.records` (or a result cube of the same layout):
the record list with each record's intensity measures and pulse period; fragility curves with
bands against PGA [g], PGV [m/s], Sa(T) [g], PGA / a_up and PGV p / a_up (a_up the uplift
acceleration), by block size; the efficiency of the intensity measures; IDA curves, stripe
points or the cloud; a per-record breakdown; and, when the blocks span sizes, the
self-similarity of the fragility on records (:mod:`rockstudy.study.analysis.record_similarity`).
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pandas as pd

from ...motions import measures as _ms
from ..analysis import record_fragility as rf
from ..analysis import record_similarity as rsim
from ..analysis.fragility_fit import BAND_COLUMNS, N_BOOT
from ..analysis.sampled import fragility_curve
from ..designs.records import STATUS_FREE_FALL, failed_points
from ..spec.design_kinds import DESIGN_KINDS, design_kind, kind_of
from ..spec.feasibility import DEFAULT_MAX_SCALE_FACTOR
from . import floors
from . import objects as ro
from ._page import (
    _FRAGILITY_NAMES,
    _capacities_as_measured,
    _log_ticks,
    _names,
    _Page,
    _plt,
    dataset_of,
    draw_fits,
    object_colors,
    separation_note,
    shown_separation,
)
from .objects import ReportContext, _fits, _section, _structure_title
from .risk import section as risk_section
from .sliding import contact_section, regime_section
from .sliding import section as sliding_section
from .states import section as states_section
from .two_body import section as two_body_section

__all__ = [
    "DESIGNS",
    "FREQUENCY_BINS",
    "GROUP_NAMES",
    "im_label",
    "record_report",
    "REPORT_UNITS",
    "SECTIONS",
    "UPLIFT_NOTE",
]

#: Designs this report reads (``ds.attrs["design"]``): every kind of the registry.
DESIGNS = tuple(DESIGN_KINDS)

#: The dimensionless group of the pulse in words (the measures' and ratios' labels are those of
#: the registry, :func:`rockstudy.motions.measures.label`).
GROUP_NAMES = {"pulse_amplitude_ratio": "pulse amplitude omega_p A_p / a_up [-]"}
#: Units of the report's accelerations: as given (a study's scale_to.units) -> as shown.
REPORT_UNITS = {"g": "g", "m/s^2": "m/s^2", "m/s2": "m/s^2"}
#: What the page's ratios divide by, said once at its top.
UPLIFT_NOTE = (
    "a_up is each structure's uplift acceleration: g tan alpha of a block, g lambda of another "
    "structure (eq. 10 of [003]); p its frequency parameter."
)

#: Frequency bins of omega_p / p (of equal count) within which PGA / a_up is compared.
FREQUENCY_BINS = 3


def im_label(im: str, period=None) -> str:
    """An intensity measure's name in words with its quoted unit, e.g. 'Sa(T = 0.5 s) [g]'
    (the registry's label; the name itself if it is no measure)."""
    if im in GROUP_NAMES:
        return GROUP_NAMES[im]
    if im in _ms.MEASURES or im in _ms.RATIOS:
        return _ms.label(im, period)
    return im if period is None else f"{im}(T = {float(period):.3g} s)"


def _measures(ds) -> list[tuple[str, float | None]]:
    """The measures of the fragility section: PGA, PGV, Sa at the design's (or the first
    stored) period, the two dimensionless groups, and the design's own measure (one
    registered by :func:`rockstudy.motions.register_measure` too)."""
    out = [("pga", None), ("pgv", None)]
    periods = np.asarray(ds["period"].values, float) if "period" in ds.coords else np.zeros(0)
    t = ds.attrs.get("im_period", np.nan)
    if periods.size:
        out.append(("sa", float(t) if np.isfinite(t) else float(periods[0])))
    out += [("pga_ratio", None), ("pgv_ratio", None)]
    own = ds.attrs.get("im")
    if own in _ms.MEASURES and own not in ("pga", "pgv", "sa") and own in ds:
        out.append((own, float(t) if _ms.MEASURES[own].needs_period else None))
    return out


def _fit(ds, im, period, edges, n_boot, by=None):
    """The design's fragility table against ``im``, by size class when there are sizes (or
    ``by`` a coordinate, e.g. ``"structure"`` for named objects)."""
    fit = rf.fragility_of(ds)
    by = by if edges is None else "half_diagonal"
    with shown_separation():  # said on the page (separation_note)
        table = fit(ds, im=im, period=period, by=by, bins=edges, n_boot=n_boot)
    if edges is not None:  # analysis labels bins "lo-hi" in %g: name them in words
        table.index = [
            rsim.size_label(lo, hi)
            for lo, hi in (map(float, g.split("-")) for g in table.index.astype(str))
        ]
    table.index.name = "block size" if edges is not None else "object" if by else "blocks"
    return table


# ------------------------------------------------------------------------------ sections


def _summary(page, ds, relabel=str):
    kind = kind_of(ds)
    rows = {
        "design": kind.description,
        "records": int(ds.sizes["record"]),
        "structures": int(ds.sizes["structure"]),
        "simulations": int(ds.attrs.get("n_simulations", 0)),
    }
    for name, n in failed_points(ds["status"].values).items():
        rows[f"points that failed ({name})"] = n
    if not kind.capacities:  # a stripe point whose scaled vertical reaches -g is not run
        rows["points not run (free fall)"] = int((ds["status"].values == STATUS_FREE_FALL).sum())
    if kind.scaled:
        rows["scaling measure"] = relabel(
            im_label(
                ds.attrs.get("im", "pga"),
                ds.attrs["im_period"] if np.isfinite(ds.attrs.get("im_period", np.nan)) else None,
            )
        )
    if kind.levels:
        rows["levels"] = int(ds.sizes["level"])
    if kind.capacities:
        rows["ladder step (relative)"] = float(ds.attrs.get("step", np.nan))
        rows["bisection tolerance (relative)"] = float(ds.attrs.get("tolerance", np.nan))
        reason = ds["censored_reason"].values
        rows["capacities censored: standing at the top of the range"] = int((reason == 1).sum())
        rows["capacities censored: free fall above (vertical reaches -g)"] = int(
            (reason == 2).sum()
        )
        rows["blocks seen to survive above their first overturning"] = int(
            (ds["survives_above_capacity"].values == 1).sum()
        )
    else:
        rows["overturned points"] = int(ds["overturned"].values.sum())
    page.table(pd.Series(rows, dtype=object).to_frame("value"), "summary", "The design")


def _stored_measures(ds, period: bool) -> list[str]:
    """The measures of the registry the design stores per record, with (``period=True``) or
    without a period: the listed ones and those it was asked for (a RotD50 hazard's, ...)."""
    return [k for k, m in _ms.MEASURES.items() if m.needs_period == period and k in ds]


def _record_list(page, ds):
    scalars = _stored_measures(ds, False)
    cols = {im_label(k): ds[k].values * _ms.quoted(k)[1] for k in scalars}
    table = pd.DataFrame(cols, index=_names(ds))
    if "pga" in scalars:  # g next to m/s^2
        table.insert(table.columns.get_loc(im_label("pga")) + 1, "PGA [m/s^2]", ds["pga"].values)
    periods = np.asarray(ds["period"].values, float) if "period" in ds.coords else []
    for name in _stored_measures(ds, True):
        for j, t in enumerate(periods):
            table[im_label(name, t)] = ds[name].values[:, j] * _ms.quoted(name)[1]
    table["pulse period T_p [s]"] = ds["pulse_period"].values
    table["pulse amplitude A_p [m/s]"] = ds["pulse_amplitude"].values
    table["pulse indicator (Baker 2007) [-]"] = ds["pulse_indicator"].values
    table["pulse-like (indicator > 0.85)"] = ds["pulse_indicator"].values > 0.85
    table.index.name = "record"
    page.table(
        table,
        "records",
        "The records (unscaled): intensity measures (Sa at the damping "
        f"{float(ds.attrs.get('damping', 0.05)):.3g}) and the dominant velocity pulse "
        "(Mavroeidis-Papageorgiou fit)",
    )


def _fragility(page, ds, edges, n_boot):
    measures = _measures(ds)
    plt = _plt()
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))
    axes = axes.ravel()
    tables = []
    for ax, (im, period) in zip(axes, measures, strict=False):
        try:
            t = _fit(ds, im, period, edges, n_boot)
        except ValueError as err:
            page.text(f"Fragility against {im_label(im, period)}: {err}")
            ax.set_visible(False)
            continue
        low, high = np.nanmin(t["im_min"]), np.nanmax(t["im_max"])
        if not (np.isfinite(low) and np.isfinite(high) and high > low > 0):
            ax.set_visible(False)
            continue
        grid = np.geomspace(low, high, 200)
        separation_note(page, t, f"Fragility against {im_label(im, period)}")
        if draw_fits(ax, grid, fragility_curve(t, grid), t, _log_ticks):
            ax.set(xlabel=im_label(im, period), ylabel="probability of overturning")
        t.insert(0, "intensity", im_label(im, period))
        tables.append(t)
    for ax in axes[len(measures) :]:
        ax.set_visible(False)
    if not tables:
        plt.close(fig)
        return
    if not any(ax.get_visible() for ax in axes):  # every fit separated: no curve to show
        plt.close(fig)
    else:
        _record_fragility_figure(page, fig, ds, edges)
    _record_fragility_table(page, tables)


def _record_fragility_figure(page, fig, ds, edges):
    fig.tight_layout()
    page.figure(
        fig,
        "record_fragility",
        "Lognormal fragility curves with 90 % pointwise bands of the probability over both "
        "the median and beta"
        + (" by block size" if edges is not None else "")
        + f": {kind_of(ds).text['fit']}"
        + "; dashed: the median lies outside the observed intensities",
    )


def _record_fragility_table(page, tables):
    fit = pd.concat(tables)
    fit.to_csv(page.out / "record_fragility_fit.csv")
    page.table(
        _capacities_as_measured(fit)
        .drop(columns=["unit", *BAND_COLUMNS])
        .rename(columns=_FRAGILITY_NAMES),
        "record_fragility",
        "Fragility parameters in each measure's units: median capacity, its 90 % band and "
        "the log-standard deviation beta (the maximum-likelihood estimate, dividing by n) "
        "with its band (the fitted numbers, flags and the covariance behind the bands of the "
        "curves are in record_fragility_fit.csv)",
    )


def _efficiency_frame(ctx, table, by=None) -> pd.DataFrame:
    """An efficiency table of :func:`rf.im_efficiency` as the page shows it: each measure's
    label and median capacity in the report's units (:func:`ro.quoted_to_report`), its
    power as it is (0.5 stays 0.5); indexed by measure, or by ``by`` (the column of its
    groups, e.g. "object") and measure."""
    rows = []
    for (label, group), r in table.iterrows():
        name, _, rest = label.partition("(T=")
        period = float(rest.rstrip(" s)")) if rest else None
        rows.append(
            {
                **({by: str(group)} if by else {}),
                "intensity measure": ctx.relabel(im_label(name, period)),
                "dispersion per power beta / k [-]": r["beta_linear"],
                "beta / k, lower": r["beta_linear_lo"],
                "beta / k, upper": r["beta_linear_hi"],
                "power k": float(r["power"]),
                "dispersion beta [-]": r["beta"],
                "median capacity": r["theta"] * ro.quoted_to_report(ctx.units, name),
                "points": int(r["n"]),
                "dimensionless": bool(r["dimensionless"]),
                "outcomes separated (no beta)": bool(r["separated"]),
                "no rise (no beta)": bool(r["no_rise"]),
            }
        )
    return pd.DataFrame(rows).set_index([by, "intensity measure"] if by else "intensity measure")


def _efficiency(page, ctx):
    page.table(
        _efficiency_frame(ctx, ctx.efficiency()),
        "im_efficiency",
        "Which measure predicts overturning best: the dispersion beta (MLE) of the fragility "
        "against each measure divided by the power k with which the measure follows a scale "
        "factor of the record (Arias intensity k = 2: its k-th root is as informative and "
        "linear), pooled over all "
        + ("objects" if ctx.objects else "blocks")
        + " (smaller is better; 90 % bands), dimensional and "
        "dimensionless; a measure in which the outcomes are separated (every overturned "
        "point at or above every one that stood), or in which they do not rise at all, has no "
        "beta and is not ranked",
    )
    if not ctx.objects:
        return
    with shown_separation():  # a separated measure: no beta, column "separated"
        table = rf.im_efficiency(ctx.ds, by="structure", n_boot=ctx.n_boot)
    page.table(
        _efficiency_frame(ctx, table, "object"),
        "im_efficiency_by_object",
        "The same for each object alone, ranked within it: the measure that best predicts "
        "the overturning of that object under these records (within one object a "
        "dimensional measure and its ratio to the object's uplift level differ by a "
        "constant and share their beta; pooled, the ratios can also bring objects of "
        "different sizes together)",
    )


def _representatives(ds, k=3) -> list[int]:
    """Up to k structures spanning the sizes (or the order) of the design."""
    key = ds["half_diagonal"].values if "half_diagonal" in ds else np.arange(ds.sizes["structure"])
    key = np.where(np.isfinite(key), key, np.arange(key.size))
    order = np.argsort(key, kind="stable")
    picks = np.unique(np.round(np.linspace(0, order.size - 1, min(k, order.size))).astype(int))
    return [int(order[i]) for i in picks]


def _responses(page, ctx):
    """IDA curves, stripe points or the cloud, for up to three blocks spanning the sizes (the
    per-object panels' drawing; markers of the records offset in x, survivors hollow)."""
    ds, kind = ctx.ds, ctx.kind
    draw = getattr(ro, kind.draw)
    names = _names(ds)
    picks = _representatives(ds)
    plt = _plt()
    fig, axes = plt.subplots(1, len(picks), figsize=(4.4 * len(picks), 4), squeeze=False)
    spread = 0.015 * (np.arange(len(names)) - (len(names) - 1) / 2)
    for ax, j in zip(axes[0], picks, strict=True):
        for i in range(len(names)):
            draw(ax, ctx, i, j, spread[i])
        ax.set(
            xlabel="peak rotation / slenderness, theta_max / alpha [-]",
            ylabel=f"PGA of the scaled record [{ctx.units}]",
            yscale="log",
            xlim=(-0.04, 1.08),
            title=_structure_title(ds, j),
        )
        if kind.capacities and (span := ro.ida_axis(ctx, j)) is not None:
            ax.set_ylim(*span)
        _log_ticks(ax, "y")
    if len(names) <= 15:
        ro._shared_legend(fig, axes[0][0], len(names))
    else:
        fig.tight_layout()
    page.figure(
        fig,
        f"{kind.name}_points",
        f"{kind.text['points']}, for blocks spanning the design's sizes; crosses: overturned "
        "(drawn at theta_max / alpha = 1)"
        + kind.text["points_note"]
        + "; markers of the records offset slightly in x so that none hides another",
    )


def _per_record(page, ds):
    names = _names(ds)
    capacities = kind_of(ds).capacities
    rows = {}
    for i, name in enumerate(names):
        row = {"simulations": None, "failed points": int((ds["status"].values[i] != 0).sum())}
        if capacities:
            cap = rf.intensity(ds.isel(record=[i]), "pga", scale="capacity_scale").values[0]
            ratio = rf.intensity(ds.isel(record=[i]), "pga_ratio", scale="capacity_scale")
            ratio = ratio.values[0]
            row["simulations"] = int(ds["simulations"].values[i].sum())
            row["median capacity, PGA [g]"] = _median(cap)
            row["median capacity, PGA / a_up [-]"] = _median(ratio)
            row["lowest capacity, PGA [g]"] = (
                float(np.nanmin(cap)) if np.isfinite(cap).any() else np.nan
            )
            row["censored blocks"] = int((ds["censored"].values[i] == 1).sum())
            row["blocks seen to survive above their first overturning"] = int(
                (ds["survives_above_capacity"].values[i] == 1).sum()
            )
        else:
            over = ds["overturned"].values[i]
            row["simulations"] = int(over.size)
            row["overturned"] = int(over.sum())
            row["overturned share [-]"] = float(over.mean())
            surv = ds["max_rotation"].values[i] / np.broadcast_to(
                ds["slenderness"].values.reshape((-1,) + (1,) * (over.ndim - 1)), over.shape
            )
            surv = surv[over == 0]
            row["median theta_max / alpha of the survivors [-]"] = _median(surv)
        rows[name] = row
    table = pd.DataFrame(rows).T
    table.index.name = "record"
    page.table(table, "per_record", "Per-record breakdown over all blocks")


def _switch_band(page, ds):
    """Per record: the blocks seen to survive above their first overturning, the width of
    the switch band (highest survival / first overturning) and the share of the simulated
    scales inside it that overturn."""
    cap = ds["capacity_scale"].values
    high = ds["highest_survival_scale"].values
    share = ds["switch_band_overturn_share"].values
    names = _names(ds)
    rows = {}
    for i, name in enumerate([*names, "all records"]):
        sel = slice(None) if i == len(names) else [i]
        c, h, sh = cap[sel].ravel(), high[sel].ravel(), share[sel].ravel()
        seen = np.isfinite(h) & np.isfinite(c)
        rows[name] = {
            "blocks with a first overturning": int(np.isfinite(c).sum()),
            "of which seen to survive above it": int(seen.sum()),
            "switch band, highest survival / first overturning, median [-]": _median(
                h[seen] / c[seen]
            ),
            "switch band, largest [-]": float(np.max(h[seen] / c[seen])) if seen.any() else np.nan,
            "share of the scales in the band that overturn, median [-]": _median(sh[seen]),
        }
    table = pd.DataFrame(rows).T
    table.index.name = "record"
    page.table(
        table,
        "switch_band",
        "The switch band: from the first overturning (the capacity) to the highest scale at "
        "which the block was seen to survive, over the ladder rungs, the bisection and the scan "
        f"above it (step {float(ds.attrs.get('step', np.nan)):.3g}, "
        f"{int(ds.attrs.get('scan', 0))} scan levels); a capacity reads 'first overturning', "
        "not 'overturns at every higher level'",
    )


def _side_by_side(page, ida, stripes, edges, n_boot, by=None):
    """The fragility of the IDA and of the stripes on the same records and blocks, measure by
    measure and size class; a warning where their median bands do not overlap."""
    rows, plt = [], _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    for im, period in _measures(ida):
        try:
            t_ida = _fit(ida, im, period, edges, n_boot, by)
            t_str = _fit(stripes, im, period, edges, n_boot, by)
        except ValueError as err:
            page.text(f"Stripes and IDA against {im_label(im, period)}: {err}")
            continue
        for group in t_ida.index.intersection(t_str.index):
            a, b = t_ida.loc[group], t_str.loc[group]
            overlap = max(a["theta_lo"], b["theta_lo"]) <= min(a["theta_hi"], b["theta_hi"])
            rows.append(
                {
                    "intensity": im_label(im, period),
                    "group": group,
                    "IDA median": a["theta"],
                    "IDA median, lower": a["theta_lo"],
                    "IDA median, upper": a["theta_hi"],
                    "IDA beta": a["beta"],
                    "stripes median": b["theta"],
                    "stripes median, lower": b["theta_lo"],
                    "stripes median, upper": b["theta_hi"],
                    "stripes beta": b["beta"],
                    "bands overlap": bool(overlap),
                }
            )
        if im == "pga":
            _plot_pair(ax, t_ida, t_str, im, object_colors(ida["structure"].values) if by else {})
    if not rows:
        plt.close(fig)
        return
    table = pd.DataFrame(rows).set_index(["intensity", "group"])
    apart = table[~table["bands overlap"]]
    if len(apart):
        listed = "; ".join(f"{im} ({g})" for im, g in apart.index)
        page.text(
            f"Warning: the IDA and the stripes disagree beyond their 90 % bands of the median "
            f"in {len(apart)} of {len(table)} fits: {listed}. The IDA counts the first "
            "overturning; the stripes count overturning at each level, which survival above "
            "the first overturning lowers."
        )
    fig.tight_layout()
    page.figure(
        fig,
        "stripes_and_ida",
        "Fragility against PGA from the IDA (solid) and the stripes (dashed), with the bands "
        "of their medians",
    )
    page.table(table, "stripes_and_ida", "Stripes and IDA side by side (90 % bands)")


def _plot_pair(ax, t_ida, t_str, im, colors):
    """The IDA's (solid) and the stripes' (dashed) fragility of each group against ``im``,
    an object in its colour of ``colors`` (by name; other groups in matplotlib's cycle)."""
    low = np.nanmin([t_ida["im_min"].min(), t_str["im_min"].min()])
    high = np.nanmax([t_ida["im_max"].max(), t_str["im_max"].max()])
    if not (np.isfinite(low) and np.isfinite(high) and high > low > 0):
        return
    grid = np.geomspace(low, high, 200)
    for table, style, what in ((t_ida, "-", "IDA"), (t_str, "--", "stripes")):
        curve = fragility_curve(table, grid)
        for g in curve.group.values:
            c = curve.sel(group=g)
            color = colors.get(str(g))
            (line,) = ax.plot(grid, c.probability, style, label=f"{what}: {g}", color=color)
            ax.fill_between(grid, c.lower, c.upper, alpha=0.15, color=line.get_color())
    ax.set(xscale="log", xlabel=im_label(im), ylabel="probability of overturning")
    _log_ticks(ax)
    ax.legend(fontsize=8)


def _median(values) -> float:
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    return float(np.median(values)) if values.size else np.nan


def _self_similarity(page, ds, edges, n_boot):
    """Medians of the size classes against PGA [g] (pooled), PGA / a_up within bins
    of omega_p / p, and PGV p / a_up (pooled), and their spread."""
    cases = [
        ("pga", None),
        ("pga_ratio", FREQUENCY_BINS if np.isfinite(ds["pulse_frequency_ratio"]).any() else None),
        ("pgv_ratio", None),
    ]
    spreads, medians = [], []
    for im, bins in cases:
        try:
            m, s = rsim.size_class_medians(
                ds, im, size_bins=edges, frequency_bins=bins, n_boot=n_boot
            )
        except ValueError as err:
            page.text(f"Self-similarity against {im_label(im)}: {err}")
            continue
        for frame in (m, s):
            frame.insert(0, "intensity", im_label(im))
        medians.append(m)
        spreads.append(s)
    if not spreads:
        return
    plt = _plt()
    fig, axes = plt.subplots(1, len(medians), figsize=(4.4 * len(medians), 3.8), squeeze=False)
    mids = np.sqrt(edges[:-1] * edges[1:])
    for ax, m in zip(axes[0], medians, strict=True):
        for band, sub in m.groupby(level="band", sort=False):
            theta = sub["theta"].to_numpy(float)
            x = mids[: theta.size]
            ok = np.isfinite(theta) & (theta > 0)
            if not ok.any():
                continue
            lo = np.where(ok, sub["theta_lo"].to_numpy(float), np.nan)
            hi = np.where(ok, sub["theta_hi"].to_numpy(float), np.nan)
            (line,) = ax.plot(x[ok], theta[ok], "o-", label=str(band))
            ax.fill_between(x[ok], lo[ok], hi[ok], alpha=0.2, color=line.get_color())
        ax.set(
            xscale="log",
            yscale="log",
            xlabel="block size, geometric middle of the class R [m]",
            ylabel=f"median capacity, {m['intensity'].iloc[0]}",
        )
        _log_ticks(ax)
        _log_ticks(ax, "y")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
    fig.tight_layout()
    page.figure(
        fig,
        "size_collapse",
        "Median overturning intensity of each size class (90 % bands by resampling the "
        "records): against PGA in g the sizes spread apart; in the record groups a flat line "
        "is a complete collapse",
    )
    table = pd.concat(spreads).rename(
        columns={
            "ratio": "largest / smallest median",
            "ratio_lo": "ratio, lower",
            "ratio_hi": "ratio, upper",
            "log_std": "std of ln median",
            "log_std_lo": "std of ln median, lower",
            "log_std_hi": "std of ln median, upper",
            "classes": "size classes with a median in range",
            "unit": "units",
        }
    )
    table.index.name = "records"
    page.table(
        table,
        "size_collapse",
        "Spread of the median capacity across the size classes (1 and 0: a complete "
        "collapse), with 90 % bands by resampling the records",
    )
    pd.concat(medians).to_csv(page.out / "size_class_medians.csv")


#: The sections of the record report, in order: each a function (page, ctx) that writes its
#: own heading (or nothing). Adding a section is adding one entry.
SECTIONS = [
    _section("Summary", lambda page, ctx: _summary(page, ctx.ds, ctx.relabel)),
    ro.outcome,
    ro.scale_factors,
    _section("Records", lambda page, ctx: _record_list(page, ctx.ds)),
    _section(
        "Fragility",
        lambda page, ctx: _fragility(page, ctx.ds, ctx.edges, ctx.n_boot),
        when=lambda ctx: _fits(ctx) and not ctx.objects,
    ),
    ro.object_fragility,
    risk_section,
    two_body_section,
    sliding_section,
    states_section,
    contact_section,
    _section(
        "Intensity-measure efficiency",
        lambda page, ctx: _efficiency(page, ctx),
        when=_fits,
    ),
    ro.object_capacity,
    ro.object_curves,
    _section(
        lambda ctx: ctx.kind.text["heading"],
        lambda page, ctx: _responses(page, ctx),
        when=lambda ctx: not ctx.objects or not ctx.kind.text["objects"],
    ),
    _section(
        "Switch band",
        lambda page, ctx: _switch_band(page, ctx.ds),
        when=lambda ctx: "Switch band" in ctx.kind.sections,
    ),
    _section(
        "Stripes and IDA side by side",
        lambda page, ctx: _compare(page, ctx),
        when=lambda ctx: ctx.compare is not None and _fits(ctx),
    ),
    ro.friction_check,
    regime_section,
    _section("Per-record breakdown", lambda page, ctx: _per_record(page, ctx.ds)),
    _section(
        "Self-similarity on records",
        lambda page, ctx: _self_similarity(page, ctx.ds, ctx.edges, ctx.n_boot),
        when=lambda ctx: ctx.edges is not None and _fits(ctx),
    ),
]


def _compare(page, ctx):
    ida, stripes = (ctx.ds, ctx.compare) if ctx.kind.capacities else (ctx.compare, ctx.ds)
    by = "structure" if ctx.objects else None
    _side_by_side(page, ida, stripes, ctx.edges, ctx.n_boot, by)


def _comparable(kind, compare) -> bool:
    """Whether ``compare`` can be shown beside a design of ``kind``: one of the two gives
    capacities (an IDA), the other the outcomes at levels (stripes)."""
    other = compare.attrs.get("design")
    if other not in DESIGN_KINDS:
        return False
    pair = (kind, design_kind(other))
    return any(a.capacities and not b.capacities and b.levels for a, b in (pair, pair[::-1]))


def record_report(
    ds,
    out,
    title: str = "Record design",
    description: str = "",
    *,
    n_boot: int = N_BOOT,
    appendix=None,
    compare=None,
    units: str = "g",
    max_scale_factor: float = DEFAULT_MAX_SCALE_FACTOR,
    friction=None,
    study=None,
    hazard=None,
    years: float = 50.0,
) -> Path:
    """Write the report of a record design into the folder ``out``; return its index.html.

    The page runs the sections of :data:`SECTIONS` in order. For named objects (the
    ``structure`` coordinate holds names) it answers per object: fragility, capacity under
    each record with the governing record, and the IDA curves or stripes of each object.
    When nothing overturned (or nothing rocked) it says so in words and fits nothing.

    Parameters
    ----------
    ds : xarray.Dataset or path-like
        From :func:`~rockstudy.study.designs.records.cloud`,
        :func:`~rockstudy.study.designs.records.multiple_stripes` or
        :func:`~rockstudy.study.designs.records.incremental_dynamic_analysis` (``design`` in its
        attributes), or a result cube of the same layout, or the path of one (read with
        :func:`~rockstudy.study.running.store.open_result`; as
        :func:`~rockstudy.study.report.sampled.make_report` takes either).
    out : path-like
        Folder of the page, its PNG figures and CSV tables (created if missing).
    title, description : str
        Shown (escaped) at the top of the page.
    n_boot : int
        Resamples of the records behind every band of the page: the fragilities', the
        efficiency table's and the annual rates' (default
        :data:`~rockstudy.study.analysis.fragility_fit.N_BOOT`); 0 gives the fits' Wald
        intervals and rates without bands.
    appendix : callable, optional
        Called with the page last, to add sections (a study's report adds its study file).
    compare : xarray.Dataset or path-like, optional
        The other of an IDA and a stripes design on the same records and structures: the
        page then shows both fragilities side by side and warns where their median bands
        do not overlap.
    units : {"g", "m/s^2"}
        Units of the accelerations of the per-object sections, the efficiency tables and
        the warnings (a study's ``scale_to.units``): every measure the registry quotes in g
        is shown in them, a registered one too; the record list, the size classes' fits and
        the per-record breakdown say their own unit (g beside m/s^2 for PGA).
    max_scale_factor : float
        A warning box lists the stripe points or IDA capacities whose record is scaled by
        more than this (> 1; a study's ``design.max_scale_factor``).
    friction : float or array_like, optional
        The friction coefficient mu (one, or one per structure): with ``friction_demand`` in
        ``ds`` (``friction=`` of the design functions, or a study's ``friction``) the page
        counts the scenes whose demand exceeds it or that lift off, with a warning box.
    study : rockstudy.study.spec.Study, optional
        The study the dataset was run from, for the sections that read its settings
        (``ReportContext.study``).
    hazard : rockstudy.risk.HazardCurve, optional
        The site's hazard curve: the page then ranks the objects by their annual rate of
        overturning, with the probability in ``years`` [yr] (default 50) and a deaggregation
        figure (:func:`~rockstudy.study.analysis.risk.object_risk`).
    """
    ds = dataset_of(ds, "ds")[0]
    compare = None if compare is None else dataset_of(compare, "compare")[0]
    kind = kind_of(ds)
    if units not in REPORT_UNITS:
        raise ValueError(f"units: must be one of {list(REPORT_UNITS)}, got {units!r}")
    if not (isinstance(max_scale_factor, (int, float)) and max_scale_factor > 1):
        raise ValueError(f"max_scale_factor: must be a number > 1, got {max_scale_factor!r}")
    if compare is not None and not _comparable(kind, compare):
        kinds = {kind.name, compare.attrs.get("design")}
        raise ValueError(
            f"compare: give a stripes design beside an IDA (or the reverse), got {kinds}"
        )
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if floors.has_dimensions(ds):  # a page per floor and orientation summary, linked
        options = dict(description=description, appendix=appendix, units=units, study=study)
        options.update(max_scale_factor=max_scale_factor, friction=friction, hazard=hazard)
        return floors.dimension_report(
            ds, out, record_report, title, n_boot=n_boot, years=years, **options
        )
    page = _Page(out)
    ctx = ReportContext(ds, n_boot, compare, REPORT_UNITS[units], float(max_scale_factor))
    ctx.friction, ctx.im_label, ctx.study = friction, im_label, study
    ctx.hazard, ctx.years = hazard, years
    for section in SECTIONS:
        section(page, ctx)
    if appendix is not None:
        appendix(page)
    meta = f"<p>{html.escape(description)}</p>" if description else ""
    meta += f"<p class='cap'>{html.escape(UPLIFT_NOTE)}</p>"
    return page.write(f"rockstudy report: {title}", meta)
