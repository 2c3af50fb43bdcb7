"""The record report's annual-rate section: each named object's annual rate of overturning at
the site of a hazard curve, its probability in N years with a band by resampling the records,
ranked, and the deaggregation of the rate over the hazard's levels
(:func:`~rockstudy.study.analysis.risk.object_risk`)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import special

from ...motions import measures
from ..analysis.risk import object_risk, records_measure
from ._page import _log_ticks, _mpl_text, _plt, object_colors

__all__ = ["EXTRAPOLATED_SHARE", "MAX_DEAGGREGATION_LINES", "section"]


def section(page, ctx):
    """The annual probability of overturning of each object, when the report has a hazard."""
    if ctx.hazard is None:
        return
    page.heading("Annual probability of overturning")
    out = _risk(page, ctx.ds, ctx.hazard, ctx.years, ctx.im_label, ctx.n_boot)
    if out is not None and ctx.friction is not None and "friction_demand" in ctx.ds:
        _without_outside_scenes(page, ctx, out)


def _without_outside_scenes(page, ctx, out):
    """Each object's lambda_OT again without the records under which one of its scenes lies
    outside the block model (friction demand above mu, or lift-off): how much the rate rests
    on what the model does not describe."""
    from ..analysis.contact import outside_model

    ds = ctx.ds
    flags = outside_model(ds, ctx.friction)
    flags = flags.any([d for d in flags.dims if d not in ("record", "structure")])
    rows = {}
    for name in out["structure"].values:
        outside = flags.sel(structure=name).values
        rate = float(out["annual_rate"].sel(structure=name))
        if not outside.any() or not np.isfinite(rate):
            continue
        keep = np.flatnonzero(~outside)
        again = (
            object_risk(ds.isel(record=keep).sel(structure=[name]), ctx.hazard, n_boot=0)
            if keep.size
            else None
        )
        without = float(again["annual_rate"].values[0]) if again is not None else np.nan
        names = ctx.record_names()
        rows[str(name)] = {
            "records outside the model": ", ".join(names[k] for k in np.flatnonzero(outside)),
            "lambda_OT [1/yr]": rate,
            "lambda_OT without them [1/yr]": without,
            "ratio": without / rate,
            "status without them": str(again["status"].values[0]) if again is not None else "",
        }
    if not rows:
        return
    page.table(
        pd.DataFrame.from_dict(rows, orient="index").rename_axis("object"),
        "annual_overturning_within_model",
        "Each object's annual rate again without the records under which one of its scenes "
        "lies outside the rocking-block model (friction demand above mu, or lift-off: see the "
        "friction section), refitted and integrated the same way: a ratio far from 1 says "
        "the rate rests on shaking the block model does not describe",
    )


#: Most objects drawn in the deaggregation figure (the highest rates; all are in its CSV).
MAX_DEAGGREGATION_LINES = 10


#: Share of an object's annual rate from beyond the hazard curve's levels above which the
#: report warns (:func:`_risk`).
EXTRAPOLATED_SHARE = 0.1


def _share_beyond(out) -> np.ndarray:
    """Each object's share of lambda_OT from below the curve's first level and above its last
    (NaN without a rate)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ends = out["deaggregation"].isel(interval=[0, -1]).sum("interval")
        return (ends / out["annual_rate"]).values


def _risk_table(out) -> pd.DataFrame:
    """The ranked table of :func:`~rockstudy.study.analysis.risk.object_risk`, as shown."""
    unit, y = out.attrs["units"], f"{out.attrs['years']:g}"
    beyond = _share_beyond(out)
    with np.errstate(invalid="ignore", divide="ignore"):
        at_cut = special.ndtr(np.log(out["cut_level"] / out["theta"]) / out["beta"]).values
    counts = zip(out["n_overturning"].values, out["n_records"].values, strict=True)
    return pd.DataFrame(
        {
            "status": out["status"].values,
            f"median [{unit}]": out["theta"].values,
            "beta": out["beta"].values,
            "records overturning": [f"{int(a)} of {int(b)}" for a, b in counts],
            "lambda_OT [1/yr]": out["annual_rate"].values,
            "lambda_OT, 5 %": out["annual_rate_lo"].values,
            "lambda_OT, 95 %": out["annual_rate_hi"].values,
            "return period [yr]": out["return_period"].values,
            f"P({y} yr)": out["probability"].values,
            f"P({y} yr), 5 %": out["probability_lo"].values,
            f"P({y} yr), 95 %": out["probability_hi"].values,
            "share beyond the curve's levels": beyond,
            f"uplift [{unit}]": out["uplift"].values,
            f"fragility 0 below [{unit}]": out["cut_level"].values,
            "P(OT) just above it": at_cut,
            "lambda_OT, whole lognormal [1/yr]": out["annual_rate_lognormal"].values,
            "share below uplift": out["share_below_uplift"].values,
            "lambda_OT at most [1/yr]": out["rate_upper_bound"].values,
            "lambda_OT at least [1/yr]": out["rate_lower_bound"].values,
        },
        index=pd.Index([str(v) for v in out["structure"].values], name="object"),
    )


#: What each status of the risk table means.
_STATUS_NOTE = (
    "Status 'ok': at least 5 records overturned the object; 'few': fewer; "
    "'none': it never overturned, so no rate is estimable (an IDA gives an upper bound); "
    "'all': it overturned at every point (stripes give a lower bound, and under "
    "horizontal records an upper bound: the rate of exceeding the PGA below which its "
    "fragility is 0); 'separated': "
    "every point at which it overturned lies at or above every point at which it stood, "
    "so the fragility's dispersion cannot be estimated and no rate is given (a step "
    "function would be a guess, not an estimate); 'no rise': the points at which it "
    "overturned do not lie higher in the intensity than those at which it stood, so no "
    "increasing fragility fits them and no rate is given."
)


def _risk(page, ds, hazard, years, im_label, n_boot):
    """Per object: lambda_OT and P(``years``) with their 90 % bands by ``n_boot`` resamples of
    the records (none when 0),
    ranked, and the deaggregation figure (:func:`~rockstudy.study.analysis.risk.object_risk`)."""
    try:
        out = object_risk(ds, hazard, years=years, n_boot=n_boot)
    except ValueError as err:
        page.text(f"No annual rates: {err}")
        return None
    page.text(
        f"Hazard: the {hazard.describe()}, from {out.attrs['hazard_source'] or 'the study'}. "
        f"Each object's lognormal fragility in {im_label(hazard.im, hazard.period)} is "
        "integrated against it (Cornell et al. 2002); "
        + (
            f"the 90 % bands come from {n_boot} resamples of the records (with replacement, "
            "seed 0), each refitted and integrated again."
            if n_boot
            else "no bands (no resampling asked)."
        )
    )
    page.text(_STATUS_NOTE)
    if out["truncated_at_uplift"].values.any():
        page.text(
            "Below its uplift PGA (g tan alpha of a block, g lambda of another structure) an "
            "object cannot leave rest, so under these horizontal records (no vertical "
            "component) it cannot overturn there. Its fragility is therefore 0 below that PGA "
            "(or below the lower PGA at which the equivalent block the design simulates lifts "
            "off, g tan theta_cr: an arch's; column 'fragility 0 below') and the lognormal "
            "fitted to all its records above it (the median and beta are that fit's, not "
            "refitted for the cut), so P(OT) jumps there from 0 to the lognormal's value "
            "(column 'P(OT) just above it'). lambda_OT, its band, P and the ranking are those "
            "of this fragility. 'lambda_OT, whole lognormal' is Cornell et al.'s integral of "
            "the lognormal alone, and 'share below uplift' the part of it from below the uplift "
            "PGA: the lognormal's lower tail, not a simulated overturning. A large jump says the "
            "lognormal fits these records poorly near uplift."
        )
    below = out["overturned_below_uplift"].values
    if below.any():
        names = ", ".join(str(n) for n in out["structure"].values[below])
        page.warning(
            f"{names} overturned in the simulations at a PGA below the level at which the "
            "ground can lift it under horizontal records, which the block model forbids: its "
            "fragility is not cut there (the whole lognormal is integrated); check the design's "
            "records and structures."
        )
    table = _risk_table(out)
    beyond = table["share beyond the curve's levels"].to_numpy()
    wide = np.flatnonzero(beyond > EXTRAPOLATED_SHARE)
    if wide.size:
        names = ", ".join(str(out["structure"].values[j]) for j in wide)
        page.warning(
            f"More than {EXTRAPOLATED_SHARE:.0%} of the annual rate of {names} comes from "
            "beyond the hazard curve's levels, where it is extrapolated as the power law of its "
            "end interval (column 'share beyond the curve's levels'): extend the curve (or "
            "check its units)."
        )
    optional = [c for c in table if "at most" in c or "at least" in c or "uplift" in c]
    optional += [c for c in table if "below" in c or "just above" in c]
    terms = [c for c in table if "uplift" in c or "whole" in c or "beyond" in c or "below" in c]
    terms += [c for c in table if "just above" in c]
    page.table(
        table,
        "annual_overturning",
        f"Annual rate of overturning and probability in {years:g} years per object, ranked "
        "(highest first)",
        hide_empty=optional,
        show=[c for c in table if c not in terms],
    )
    page.table(
        table,
        "annual_overturning",
        "How each rate is made: the share from beyond the hazard curve's levels, the uplift "
        "level and the fragility's cut there, and the whole lognormal's rate",
        hide_empty=optional,
        show=terms,
    )
    _probability_bars(page, out)
    _hazard_figure(page, ds, hazard, out)
    _deaggregation_figure(page, out)
    return out


def _hazard_figure(page, ds, hazard, out):
    """The hazard curve as it was read (in its units), with the records' own (unscaled)
    intensities and each object's uplift level on it: a curve read in the wrong units shows
    far from both."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.loglog(hazard.levels, hazard.rates, "o-", ms=3, color="k", label="hazard curve, as read")
    ax.axhline(1 / 475, color="0.5", ls="--", lw=1, label="1/475 per year")
    on_records = records_measure(ds, hazard) / hazard.si_factor
    if on_records.size:
        ax.plot(
            on_records,
            np.full(on_records.size, hazard.rates[0]),
            "|",
            ms=14,
            mew=1.5,
            color="tab:blue",
            label="the records, unscaled",
        )
    for j, level in enumerate(out["uplift"].values):
        if np.isfinite(level):
            ax.axvline(
                level,
                color="tab:red",
                ls=":",
                lw=1,
                label="uplift level of each object" if j == 0 else None,
            )
    ax.set_xlabel(measures.label(hazard.im, hazard.period, hazard.units), fontsize=10)
    ax.set_ylabel("annual rate of exceedance [1/yr]", fontsize=10)
    ax.tick_params(labelsize=9)
    ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    page.figure(
        fig,
        "hazard_curve",
        f"The site's hazard curve as it was read ({_mpl_text(hazard.describe())}), with the "
        "records' own intensities (ticks, before any scaling) and each object's uplift level "
        "(dotted): a curve or records read in the wrong units lie far from each other",
    )


def _probability_bars(page, out):
    """The objects ranked by their probability of overturning in the study's years, with the
    band of each as an error bar; objects without a rate are named beside."""
    p = out["probability"].values
    rated = np.flatnonzero(np.isfinite(p) & (p > 0))
    if not rated.size:
        return
    plt = _plt()
    names = [str(v) for v in out["structure"].values]
    rated = rated[np.argsort(-p[rated], kind="stable")]
    colors = object_colors(out["structure"].values)
    fig, ax = plt.subplots(figsize=(8, 0.9 + 0.32 * rated.size))
    y = np.arange(rated.size)
    lo, hi = out["probability_lo"].values[rated], out["probability_hi"].values[rated]
    band = np.isfinite(lo) & np.isfinite(hi)
    ax.barh(y, p[rated], color=[colors[names[j]] for j in rated], height=0.6)
    err = np.vstack([p[rated] - lo, hi - p[rated]])[:, band]
    ax.errorbar(p[rated][band], y[band], xerr=err, fmt="none", ecolor="k", capsize=3, lw=1)
    for yi, j in zip(y, rated, strict=True):  # the value beside each bar: small ones show too
        ax.annotate(
            f"{p[j]:.3g}",
            (0, yi),
            xytext=(4, 0),
            textcoords="offset points",
            va="center",
            fontsize=8,
            color="k",
        )
    ax.set_yticks(y, [_mpl_text(names[j]) for j in rated], fontsize=9)
    ax.invert_yaxis()
    ax.set_xlim(left=0.0)
    ax.set_xlabel(f"P(overturning in {out.attrs['years']:g} years)", fontsize=10)
    ax.tick_params(labelsize=9)
    fig.tight_layout()
    without = [f"{names[j]} ({out['status'].values[j]})" for j in range(p.size) if j not in rated]
    page.figure(
        fig,
        "probability_ranked",
        f"The objects ranked by their probability of overturning in {out.attrs['years']:g} "
        "years, highest first, with the 90 % band of each (resampling the records) where "
        "there is one" + (f"; no rate: {_mpl_text(', '.join(without))}" if without else ""),
    )


def _deaggregation_figure(page, out):
    """One line per object: the share of lambda_OT from each interval of the hazard's levels
    (in its units)."""
    fitted = np.isfinite(out["annual_rate"].values)
    if not fitted.any():
        page.text("No object has an annual rate: no deaggregation to show.")
        return
    plt = _plt()
    lo, hi = out["im_lower"].values[1:-1], out["im_upper"].values[1:-1]
    fig, ax = plt.subplots(figsize=(8, 4.5))
    shown = np.flatnonzero(fitted)[:MAX_DEAGGREGATION_LINES]  # ranked: the highest rates
    colors = object_colors(out["structure"].values)  # each object as in the other figures
    width = np.log(hi / lo)  # each interval's width in ln x: a density does not follow the grid
    for j in shown:
        share = out["deaggregation"].values[j, 1:-1] / out["annual_rate"].values[j] / width
        label = _mpl_text(str(out["structure"].values[j]))
        color = colors[str(out["structure"].values[j])]
        line = ax.plot(np.sqrt(lo * hi), share, "o-", ms=3, label=label, color=color)[0]
        if np.isfinite(out["uplift"].values[j]):
            ax.axvline(out["uplift"].values[j], color=line.get_color(), ls=":", lw=1)
    ax.set_xscale("log")
    label = measures.label(out.attrs["im"], out.attrs.get("period"), out.attrs["units"])
    ax.set_xlabel(f"{label}, interval centre", fontsize=10)
    ax.set_ylabel("share of lambda_OT per unit of ln x", fontsize=10)
    ax.tick_params(labelsize=9)
    _log_ticks(ax)
    ax.legend(fontsize=8)
    fig.tight_layout()
    page.figure(
        fig,
        "deaggregation",
        "Deaggregation: the share of each object's annual rate of overturning that comes from "
        "each interval between the hazard curve's levels, divided by the interval's width in "
        "ln x (a density, so an uneven grid of levels does not shape it; plotted at the "
        "interval's geometric centre; the area under each line over ln x is its share within "
        "the levels); "
        "dotted: each object's uplift PGA (g tan alpha of a block, g lambda of another "
        "structure), below which it cannot leave rest (where the table says '0 below "
        "uplift', nothing comes from there; elsewhere that share is the lognormal's lower "
        "tail, not a simulated overturning); the shares beyond the first and last level are "
        "in the table"
        + (
            f"; the {shown.size} highest rates of {int(fitted.sum())} are drawn"
            if fitted.sum() > shown.size
            else ""
        ),
    )
    frame = out["deaggregation"].to_pandas().T
    edges = zip(out["im_lower"].values, out["im_upper"].values, strict=True)
    frame.index = pd.Index(
        [f"{a:.4g}-{b:.4g}" for a, b in edges],
        name=f"{out.attrs['im']} interval [{out.attrs['units']}]; its part of lambda_OT [1/yr]",
    )
    frame.to_csv(page.out / "deaggregation.csv")


# ------------------------------------------------------------------------------ page
