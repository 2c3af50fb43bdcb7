"""The record report's section on damage states short of overturning, for a design with
damage states (``[design] damage_states``): each object's fragility of every state (a
table, and a figure with one panel per object and one curve per state) and, with a hazard
curve, its annual rate of reaching each state (:mod:`rockstudy.study.analysis.states`)."""

from __future__ import annotations

import pandas as pd

from ..analysis import states as an
from . import sliding as sliding_report

__all__ = ["section"]

#: How the report reads a state (its definition, in words).
_STATES_NOTE = (
    "A point reaches a state on the rotation where its peak rotation abs(theta) reaches the "
    "state's share of the critical rotation alpha, and a state on the slide where the block "
    "slid more than the state's slide; a point that overturned has reached every state, and "
    "the state of ratio 1 is overturning itself."
)


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
        table = sliding_report.both_fits(an.state_fragility, ctx)
    except ValueError as err:
        page.text(f"No fragility of the damage states: {err}")
        return
    page.text(
        "The fragility P(state reached | PGA) of each object for each damage state ("
        + "; ".join(f"{s.name}: {_definition(s)}" for s in states)
        + "), fitted as the design fits overturning ("
        + ctx.kind.text["fit"]
        + "). "
        + _STATES_NOTE
        + " "
        + sliding_report.NESTED_NOTE.format(states="states", order=_ORDER)
    )
    sliding_report.warn_crossed(page, table, "state")
    names = [s.name for s in states]
    view = sliding_report.nested_view(table)
    sliding_report.fragility_panels(page, ctx, view, "damage_state", names, _FIGURE)
    page.table(_fragility_table(table, ctx.units), "state_fragility", _CAPTION)
    if ctx.hazard is not None:
        _rates(page, ctx)


_CAPTION = "Fragility of each damage state of each object (90 % bands)"
#: How the nested fit orders the states' medians.
_ORDER = "ordered as the states nest (on each demand by its limit, overturning above every state)"
#: The figure of the states' fragility: (name, caption, y label).
_FIGURE = (
    "state_fragility",
    "Fragility of the damage states, one panel per object and one curve per state: the "
    "nested lognormal fit of P(state reached | PGA) (one beta for all states of an object; "
    "an overturning reaches every state), 90 % pointwise band from resampled records",
    "P(state reached) [-]",
)


def _fragility_table(table, units) -> pd.DataFrame:
    """The fits of :func:`~rockstudy.study.analysis.states.state_fragility` as shown (the
    columns of the fragility of sliding's table)."""
    shown = sliding_report._fragility_table(table, units)
    shown.index = shown.index.set_names(["damage state", "object"])
    return shown


def _rates(page, ctx):
    """The annual rate of reaching each damage state, per object, with its band."""
    try:
        out = an.state_risk(ctx.ds, ctx.hazard, years=ctx.years, n_boot=ctx.n_boot, nested=True)
    except ValueError as err:
        page.text(f"No annual rates of the damage states: {err}")
        return
    columns = {
        "status": "status",
        "n_reaching": "records reaching the state",
        "annual_rate": "lambda(state), nested fit [1/yr]",
        "annual_rate_lo": "lambda, nested fit, 5 %",
        "annual_rate_hi": "lambda, nested fit, 95 %",
        "annual_rate_separate": "lambda(state), fitted apart [1/yr]",
        "probability": f"P({ctx.years:g} yr)",
        "return_period": "return period [yr]",
        "crossed_separate": "fitted apart: below a worse state's rate",
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
        "'reached the state'. " + _ESTIMATORS,
    )


#: How the two rates of the states' table differ (and which one the overturning table gives).
_ESTIMATORS = (
    "Two estimators: 'nested fit' (with its band) fits all states of an object at once, with "
    "one beta, so that a worse state's rate never exceeds a milder one's; 'fitted apart' fits "
    "each state alone. The overturning row fitted apart is the rate of the table of "
    "overturning; its nested rate differs from it by the shared beta."
)
