"""The record report's section on damage states short of overturning, for a design with
damage states (``[design] damage_states``): each object's fragility of every state (a
table, and a figure with one panel per object and one curve per state) and, with a hazard
curve, its annual rate of reaching each state (:mod:`rockstudy.study.analysis.states`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis import states as an
from ..analysis.sampled import fragility_curve
from . import sliding as sliding_report
from ._page import _plt, shown_separation
from .objects import FONT, _panels, quoted_to_report

__all__ = ["section"]

#: How the report reads a state (its definition, in words).
_STATES_NOTE = (
    "A point reaches a state on the rotation where its peak rotation abs(theta) reaches the "
    "state's share of the critical rotation alpha, and a state on the slide where the block "
    "slid more than the state's slide; a point that overturned has reached every state, and "
    "the state of ratio 1 is overturning itself."
)
#: The line styles of the states, in the design's order (then repeated).
_STYLES = ("-", "--", "-.", ":")


def _states(ctx):
    """The design's damage states, or None (the design has none)."""
    try:
        return an.design_states(ctx.ds)
    except ValueError:
        return None


def _definition(state) -> str:
    """A state's limit in words."""
    if state.demand == an.SLIDE:
        return f"max_slide > {state.limit:g} m"
    return f"abs(theta)/alpha >= {state.limit:g}"


def section(page, ctx):
    """Per object: the fragility of every damage state (a table and a figure) and, with a
    hazard curve, the annual rate of reaching each state."""
    states = _states(ctx)
    if not (states and ctx.objects):
        return
    page.heading("Damage states: fragility and annual rates per state")
    try:
        with shown_separation():  # the table says which fits are separated
            table = an.state_fragility(ctx.ds, im="pga", n_boot=ctx.n_boot)
    except ValueError as err:
        page.text(f"No fragility of the damage states: {err}")
        return
    f = quoted_to_report(ctx.units, "pga")
    for col in ("theta", "theta_lo", "theta_hi", "im_min", "im_max"):
        table[col] = table[col] * f
    page.text(
        "The fragility P(state reached | PGA) of each object for each damage state ("
        + "; ".join(f"{s.name}: {_definition(s)}" for s in states)
        + "), fitted as the design fits overturning ("
        + ctx.kind.text["fit"]
        + "). "
        + _STATES_NOTE
    )
    _figure(page, ctx, table, states)
    page.table(_fragility_table(table, ctx.units), "state_fragility", _CAPTION)
    if ctx.hazard is not None:
        _rates(page, ctx)


_CAPTION = "Fragility of each damage state of each object (90 % bands)"


def _fragility_table(table, units) -> pd.DataFrame:
    """The fits of :func:`~rockstudy.study.analysis.states.state_fragility` as shown (the
    columns of the fragility of sliding's table)."""
    shown = sliding_report._fragility_table(table, units)
    shown.index = shown.index.set_names(["damage state", "object"])
    return shown


def _figure(page, ctx, table, states):
    """One panel per object: its fitted P(state | PGA) for every state, with bands."""
    low, high = np.nanmin(table["im_min"]), np.nanmax(table["im_max"])
    if not (np.isfinite(low) and np.isfinite(high) and high >= low > 0):
        return
    objects = [str(o) for o in ctx.ds["structure"].values]
    fig, axes = _panels(len(objects))
    grid = np.geomspace(low / 1.2, high * 1.2, 200)
    curves = [fragility_curve(table.xs(s.name, level="damage_state"), grid) for s in states]
    for ax, name in zip(axes, objects, strict=True):
        color = ctx.colors[name]
        for k, (state, curve) in enumerate(zip(states, curves, strict=True)):
            c = curve.sel(group=name)
            if not np.isfinite(c.probability.values).any():
                continue
            style = _STYLES[k % len(_STYLES)]
            ax.plot(grid, c.probability, style, color=color, label=ctx.text(state.name))
            ax.fill_between(grid, c.lower, c.upper, alpha=0.12, color=color)
        ax.set(xscale="log", ylim=(-0.02, 1.02))
        ax.set_title(ctx.text(name), fontsize=FONT + 1)
        ax.set_xlabel(f"PGA [{ctx.units}]", fontsize=FONT + 1)
        ax.set_ylabel("P(state reached) [-]", fontsize=FONT + 1)
        ctx.log_ticks(ax)
        ax.tick_params(labelsize=FONT)
        if ax.lines:
            ax.legend(fontsize=FONT, loc="lower right")
    if not any(ax.lines for ax in axes):  # no fit of any state: the table says why
        _plt().close(fig)
        return
    fig.tight_layout()
    page.figure(
        fig,
        "state_fragility",
        "Fragility of the damage states, one panel per object and one curve per state: the "
        "lognormal fit of P(state reached | PGA) (an overturning reaches every state), 90 % "
        "pointwise band",
    )


def _rates(page, ctx):
    """The annual rate of reaching each damage state, per object, with its band."""
    try:
        out = an.state_risk(ctx.ds, ctx.hazard, years=ctx.years, n_boot=ctx.n_boot)
    except ValueError as err:
        page.text(f"No annual rates of the damage states: {err}")
        return
    columns = {
        "status": "status",
        "n_reaching": "records reaching the state",
        "annual_rate": "lambda(state) [1/yr]",
        "annual_rate_lo": "lambda, 5 %",
        "annual_rate_hi": "lambda, 95 %",
        "probability": f"P({ctx.years:g} yr)",
        "return_period": "return period [yr]",
    }
    frame = out[list(columns)].to_dataframe()[list(columns)].rename(columns=columns)
    frame.index = pd.MultiIndex.from_tuples(
        [(str(s), str(o)) for s, o in frame.index], names=["damage state", "object"]
    )
    page.table(
        frame,
        "annual_states",
        "Annual rate of reaching each damage state per object: the state's fragility "
        "integrated against the site's hazard curve (Cornell et al. 2002); a state on the "
        "rotation cut at the uplift PGA as overturning is, a state on the slide not (a block "
        "slides below its uplift PGA); statuses as for overturning, 'overturned' read as "
        "'reached the state'",
    )
