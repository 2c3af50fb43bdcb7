"""The record report's sections on sliding, for a design run under the contact model: each
object's fragility of sliding P(max_slide > d) per slide limit d (a table and a figure of the
curves), its annual rate of exceeding each d at the site, how much the contact model changed
the annual rate of overturning against Housner's rocking-only model, and the regime each record
drove each object into (:mod:`rockstudy.study.analysis.sliding`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis import sliding
from ..analysis.fragility_fit import BAND_COLUMNS
from ..analysis.sampled import fragility_curve
from ._page import _plt, shown_separation
from .objects import FONT, _panels, quoted_to_report, si_to_report

__all__ = [
    "NESTED_NOTE",
    "STYLES",
    "both_fits",
    "contact_section",
    "fragility_panels",
    "nested_view",
    "regime_section",
    "section",
    "warn_crossed",
]

#: How the report counts an overturned point against a slide limit.
_OVERTURNED_NOTE = (
    "A point exceeds d where the block slid more than d or overturned: a block that "
    "overturned has lost its position, so an overturning counts as exceeding every slide limit."
)


def _limits(ctx):
    """The report's slide limits [m] (the design's, or the study's ``[design]``), or None."""
    given = ctx.ds.attrs.get("slide_limits")
    if not given and ctx.study is not None and ctx.study.design is not None:
        given = ctx.study.design.slide_limits
    return np.asarray(given, float) if given is not None and len(given) else None


def _contact(ctx) -> bool:
    """Whether the design ran the contact model (it stores the slide of its points, or of
    each point of an IDA curve)."""
    return bool({"max_slide", "slide_capacity", "step_max_slide"} & set(ctx.ds.variables))


def section(page, ctx):
    """Per object: the fragility of sliding per slide limit and, with a hazard curve, the
    annual rate of exceeding each limit."""
    if not (_contact(ctx) and ctx.objects):
        return
    page.heading("Sliding: fragility and annual rates per slide limit")
    _friction(page, ctx)
    limits = _limits(ctx)
    if limits is None:
        page.text(
            "The design ran the contact model, but gives no slide limits: give [design] "
            "slide_limits = [d1, d2, ...] (m) for the fragility of sliding P(max_slide > d)."
        )
        return
    try:
        table = both_fits(sliding.slide_fragility, ctx, limits)
    except ValueError as err:
        page.text(f"No fragility of sliding: {err}")
        return
    page.text(
        "The fragility of sliding P(max_slide > d | PGA) of each object, for each slide limit "
        "d, fitted as the design fits overturning ("
        + ctx.kind.text["fit"]
        + "). "
        + _OVERTURNED_NOTE
        + " "
        + NESTED_NOTE.format(states="slide limits", order="increasing with d")
    )
    warn_crossed(page, table, "slide limit d")
    titles = [f"d = {d:g} m" for d in limits]
    keys = [float(d) for d in limits]
    fragility_panels(page, ctx, nested_view(table), "slide_limit", keys, _FIGURE, titles)
    page.table(_fragility_table(table, ctx.units), "slide_fragility", _FRAGILITY_CAPTION)
    if ctx.hazard is not None:
        _rates(page, ctx, limits)


def _friction(page, ctx):
    """The friction coefficients (mu_s, mu_k) of each object, as the design ran them."""
    ds = ctx.ds
    if "friction_static" not in ds:
        return
    columns = {"friction_static": "mu_s (static)", "friction_kinetic": "mu_k (kinetic)"}
    frame = pd.DataFrame(
        {
            label: ds[name].max([d for d in ds[name].dims if d != "structure"]).values
            for name, label in columns.items()
        },
        index=pd.Index([str(v) for v in ds["structure"].values], name="object"),
    )
    page.table(
        frame,
        "friction",
        "The friction of each object's contact under the contact model: slip starts where "
        "the friction force would exceed mu_s times the normal force, and the friction force "
        "while it slips is mu_k times it",
    )


_FRAGILITY_CAPTION = "Fragility of sliding of each object per slide limit d (90 % bands)"
#: The figure of the fragility of sliding: (name, caption, y label).
_FIGURE = (
    "slide_fragility",
    "Fragility of sliding of each object, one panel per slide limit d: the nested lognormal "
    "fit of P(max_slide > d | PGA) (one beta for all limits of an object; an overturning "
    "counts as exceeding d), 90 % pointwise band from resampled records",
    "P(max_slide > d) [-]",
)


#: What the report says of the fits it shows.
NESTED_NOTE = (
    "The figure and the annual rates show the nested fit: one dispersion beta for all "
    "{states} of an object and medians {order} (a joint maximum likelihood of all of them), "
    "so that the curve of a worse one never lies above that of a milder one; the table gives "
    "each fitted apart (median, band, beta) beside the nested median and beta."
)


def both_fits(fitter, ctx, *args) -> pd.DataFrame:
    """The table of ``fitter`` (:func:`~rockstudy.study.analysis.sliding.slide_fragility`
    or :func:`~rockstudy.study.analysis.states.state_fragility`) fitted apart, with the
    nested fit's ``nested_theta``, ``nested_beta`` and band columns beside (``nested_*``),
    the intensities in the report's units."""
    with shown_separation():  # the table says which fits are separated
        apart = fitter(ctx.ds, *args, im="pga", n_boot=ctx.n_boot)
        nested = fitter(ctx.ds, *args, im="pga", n_boot=ctx.n_boot, nested=True)
    f = quoted_to_report(ctx.units, "pga")
    for table in (apart, nested):
        for col in ("theta", "theta_lo", "theta_hi", "im_min", "im_max"):
            table[col] = table[col] * f
    shown = ["theta", "beta", "theta_lo", "theta_hi", *BAND_COLUMNS]
    return apart.join(nested[shown].add_prefix("nested_"))


def nested_view(table) -> pd.DataFrame:
    """The nested fit of a table of :func:`both_fits` under the fitter's column names."""
    nested = [c for c in table.columns if c.startswith("nested_")]
    out = table.drop(columns=[c.removeprefix("nested_") for c in nested])
    return out.rename(columns={c: c.removeprefix("nested_") for c in nested})


def warn_crossed(page, table, what):
    """A warning where the fits made apart cross (``crossed``) in a table of
    :func:`both_fits`."""
    if bool(table["crossed"].any()):
        page.warning(
            f"Fitted apart, the curves of a milder and a worse {what} cross in the observed "
            "range for some objects (column 'fits apart cross'): the worse would read as more "
            "likely there. The figure and the annual rates show the nested fit, which cannot "
            "cross."
        )


def _fragility_table(table, units) -> pd.DataFrame:
    """The fits of :func:`both_fits` as shown."""
    columns = {
        "theta": f"median PGA [{units}]",
        "theta_lo": "median, lower",
        "theta_hi": "median, upper",
        "beta": "beta (MLE)",
        "n": "points",
        "separated": "outcomes separated (no fit)",
        "no_rise": "no rise with the intensity (no fit)",
        "crossed": "fits apart cross",
        "nested_theta": f"nested median PGA [{units}]",
        "nested_beta": "nested beta (common)",
    }
    shown = table[list(columns)].rename(columns=columns)
    shown.index = shown.index.set_names(["slide limit d [m]", "object"])
    return shown


#: The line styles of the states of a panel per object, in order (then repeated).
STYLES = ("-", "--", "-.", ":")


def fragility_panels(page, ctx, table, level, keys, figure, titles=None):
    """The fitted curves P(x) of ``table`` (outer index level ``level``, the states
    ``keys``; inner the objects) with their pointwise bands, as a figure of ``page``:
    one panel per state titled ``titles`` with a curve per object (its colour), or
    (``titles`` None) one panel per object with a curve per state (:data:`STYLES`).
    ``figure`` = (name, caption, y label); no figure without a fit or an intensity range."""
    low, high = np.nanmin(table["im_min"]), np.nanmax(table["im_max"])
    if not (np.isfinite(low) and np.isfinite(high) and high >= low > 0):
        return
    grid = np.geomspace(low / 1.2, high * 1.2, 200)
    curves = [fragility_curve(table.xs(k, level=level), grid) for k in keys]
    if titles is None:
        objects = [str(o) for o in ctx.ds["structure"].values]
        styles = [STYLES[k % len(STYLES)] for k in range(len(keys))]
        lines = [
            [(c, o, s, ctx.text(str(k))) for c, s, k in zip(curves, styles, keys, strict=True)]
            for o in objects
        ]
        titles = [ctx.text(o) for o in objects]
    else:
        lines = [[(c, g, "-", ctx.text(str(g))) for g in c.group.values] for c in curves]
    fig, axes = _panels(len(titles))
    for ax, title, panel in zip(axes, titles, lines, strict=True):
        for curve, group, style, label in panel:
            c = curve.sel(group=group)
            if not np.isfinite(c.probability.values).any():
                continue
            color = ctx.colors[str(group)]
            ax.plot(grid, c.probability, style, color=color, label=label)
            ax.fill_between(grid, c.lower, c.upper, alpha=0.15, color=color)
        _axes(ax, ctx, title, figure[2])
    if not any(ax.lines for ax in axes):  # no fit at all: the table says why
        _plt().close(fig)
        return
    fig.tight_layout()
    page.figure(fig, figure[0], figure[1])


def _axes(ax, ctx, title, ylabel):
    """A fragility panel's scales, labels, ticks and legend."""
    ax.set(xscale="log", ylim=(-0.02, 1.02))
    ax.set_title(title, fontsize=FONT + 1)
    ax.set_xlabel(f"PGA [{ctx.units}]", fontsize=FONT + 1)
    ax.set_ylabel(ylabel, fontsize=FONT + 1)
    ctx.log_ticks(ax)
    ax.tick_params(labelsize=FONT)
    if ax.lines:
        ax.legend(fontsize=FONT, loc="lower right")


def _rates(page, ctx, limits):
    """The annual rate of exceeding each slide limit, per object, with its band."""
    try:
        out = sliding.slide_risk(
            ctx.ds, ctx.hazard, limits, ctx.years, n_boot=ctx.n_boot, nested=True
        )
    except ValueError as err:
        page.text(f"No annual rates of sliding: {err}")
        return
    columns = {
        "status": "status",
        "n_exceeding": "records exceeding d",
        "annual_rate": "lambda(max_slide > d) [1/yr]",
        "annual_rate_lo": "lambda, 5 %",
        "annual_rate_hi": "lambda, 95 %",
        "probability": f"P({ctx.years:g} yr)",
        "crossed_separate": "fitted apart: below a larger d's rate",
    }
    frame = out[list(columns)].to_dataframe()[list(columns)].rename(columns=columns)
    frame.index = pd.MultiIndex.from_tuples(
        [(d, str(o)) for d, o in frame.index], names=["slide limit d [m]", "object"]
    )
    if bool(out["crossed_separate"].any()):
        page.warning(
            "Fitted apart, the rate of exceeding a slide limit lies below that of a larger "
            "limit for some objects (column 'fitted apart: below a larger d's rate'): every "
            "slide past the larger d is past the smaller one, but the two lognormals fitted "
            "apart cross. The rates shown are those of the nested fit, which cannot."
        )
    page.table(
        frame,
        "annual_sliding",
        "Annual rate of exceeding each slide limit d per object: the fragility of sliding "
        "(the nested fit) integrated against the site's hazard curve (Cornell et al. 2002), the "
        "whole lognormal "
        "(a block slides below its uplift PGA); statuses as for overturning, 'overturned' "
        "read as 'exceeded d'",
    )


def contact_section(page, ctx):
    """Per object: how much the contact model changed the answer against Housner's
    rocking-only model (the ratio of the annual rates of overturning)."""
    if not (_contact(ctx) and ctx.objects):
        return
    page.heading("Contact model against the rocking-only model")
    if ctx.kind.capacities and "capacity_rocking" not in ctx.ds:
        page.text(
            'An IDA\'s ladder runs one model unless the design runs under model = "auto": '
            'the rocking-only answer needs model = "auto", which also climbs every ladder '
            "under Housner's model and keeps its capacities (capacity_rocking)."
        )
        return
    if not ctx.kind.capacities and "overturned_rocking" not in ctx.ds:
        page.text(
            'This design ran the contact model on every scene (model = "contact"): the '
            'rocking-only answer needs model = "auto", which runs Housner\'s model on every '
            "scene first and keeps its decision (overturned_rocking)."
        )
        return
    if ctx.hazard is None:
        page.text("The ratio of the annual rates of overturning needs the site's hazard curve.")
        return
    try:
        out = sliding.contact_effect(ctx.ds, ctx.hazard, ctx.years, n_boot=0)
    except ValueError as err:
        page.text(f"No comparison of the models' annual rates: {err}")
        return
    frame = out.to_dataframe()[
        [
            "n_overturned_rocking",
            "n_overturned_contact",
            "annual_rate_rocking",
            "annual_rate_contact",
            "ratio",
            "status_rocking",
            "status_contact",
        ]
    ]
    frame.index = pd.Index([str(v) for v in frame.index], name="object")
    counted = "records" if ctx.kind.capacities else "points"
    page.table(
        frame.rename(
            columns={
                "n_overturned_rocking": f"{counted} overturned, rocking-only",
                "n_overturned_contact": f"{counted} overturned, contact model",
                "annual_rate_rocking": "lambda_OT rocking-only [1/yr]",
                "annual_rate_contact": "lambda_OT contact model [1/yr]",
                "ratio": "ratio contact / rocking-only",
                "status_rocking": "status, rocking-only",
                "status_contact": "status, contact model",
            }
        ),
        "contact_vs_rocking",
        "How much the contact model changed each object's annual rate of overturning: "
        "Housner's rocking-only model (its decision on every scene, which model 'auto' runs "
        "first; of an IDA, its ladder climbed again under Housner's model) against the "
        "contact model's, each fitted and integrated the same way (point "
        "estimates); a ratio below 1: sliding spared the object, above 1: slip or flight "
        "toppled it where rocking alone would not",
    )


def regime_section(page, ctx):
    """Per object: the regime each record drove it into (the contact model's ``regime``)."""
    if not (ctx.objects and "regime" in ctx.ds):
        return
    page.heading("Regimes: what each record drove each object into")
    table = sliding.regimes(ctx.ds)
    names = dict(zip(map(str, ctx.ds["record"].values), ctx.record_names(), strict=True))
    table.index = pd.MultiIndex.from_tuples(
        [(str(o), names[str(r)]) for o, r in table.index], names=["object", "record"]
    )
    if "level" in ctx.ds.dims:
        f = si_to_report(ctx.units, ctx.ds.attrs.get("im", "pga"))
        table.columns = [f"{ctx.stripe_label()} = {v * f:.3g}" for v in table.columns]
    page.table(
        table,
        "regimes",
        "The most involved regime of the contact model each record drove each object into "
        "(rest < slide < rock < slide-rock < flight), per stripe level where the records are "
        "scaled; 'not converged': the contact model's answer did not converge with rtol (the "
        "point is left out of the fits); 'not run': the point did not run or failed otherwise",
    )
