"""Damage states short of overturning: the fragility of each state of a record design,
P(state reached | IM), and its annual rate at a site.

A design's states (``attrs["damage_states"]``: a study's ``[design] damage_states`` or the
``damage_states=`` of the record designs; :mod:`rockstudy.study.spec.damage_states`) are
limits on the peak rotation ratio ``max_rotation / critical_rotation`` (abs(theta)/alpha,
reached where at least the limit) or on the contact model's peak slide (reached where
``max_slide`` > d); a point that overturned has reached every state, and the state of
limit 1 on the rotation ratio *is* overturning (its fits are those of overturning). Each
state then reads as the design's outcome of its points, and is fitted as overturning is:

- stripes and clouds: the binomial maximum-likelihood fit of the points that reached it
  (:func:`~rockstudy.study.analysis.record_fragility.stripe_fragility`, Baker 2015);
- an IDA: the lognormal fit of the state capacities ``state_capacity_scale`` (on
  ``damage_state``, ``record``, ``structure``; :mod:`rockstudy.study.designs.ida_states`),
  censored at the highest scale seen to stand where the state was not reached
  (:func:`~rockstudy.study.analysis.record_fragility.ida_fragility`).

The annual rate of reaching each state is Cornell et al.'s integral of that fragility over
the hazard curve (:func:`~rockstudy.study.analysis.risk.object_risk`, with its bootstrap
band): a state on the rotation keeps the cut of the fragility at the uplift PGA (nothing
rotates below it without a vertical component), a state on the slide does not (a block
slides below its uplift PGA).

A design over floors and orientations (dimensions ``floor``, ``orientation``) is fitted on
every floor and orientation apart, the result carrying them
(:mod:`~rockstudy.study.analysis.motion_axes`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from ..spec.damage_states import SLIDE, DamageState, damage_states
from ..spec.design_kinds import kind_of
from .motion_axes import per_motion
from .nested_fit import nested_above, shown_table
from .sliding import _nested_risk, exceeds_slide

__all__ = [
    "design_states",
    "reached",
    "state_above",
    "state_design",
    "state_fragility",
    "state_risk",
]


def design_states(ds: xr.Dataset, names=None) -> tuple[DamageState, ...]:
    """The damage states of the design ``ds`` (``attrs["damage_states"]``), all or those
    named in ``names`` (in that order); a ValueError naming what is missing."""
    given = ds.attrs.get("damage_states")
    if not given:
        raise ValueError(
            "ds: holds no damage states: run the design with damage_states (a study's "
            "[design] damage_states = {name = limit, ...})"
        )
    states = damage_states(given, model="max_slide" in ds or "step_max_slide" in ds)
    if names is None:
        return states
    by_name = {s.name: s for s in states}
    names = [str(n) for n in np.atleast_1d(names)]
    missing = [n for n in names if n not in by_name]
    if missing:
        raise ValueError(
            f"states: the design has no damage states {missing}; it has {list(by_name)}"
        )
    return tuple(by_name[n] for n in names)


def reached(ds: xr.Dataset, state: DamageState) -> xr.DataArray:
    """True at each point of stripes or a cloud that reached ``state``: overturned, or
    rotated to at least the limit times the critical rotation, or (a state on the slide)
    slid more than the limit (:func:`~rockstudy.study.analysis.sliding.exceeds_slide`).
    The overturning state is overturning alone."""
    over = ds["overturned"] == 1
    if state.demand == SLIDE:
        return exceeds_slide(ds, state.limit)
    if state.overturning:
        return over
    return over | (ds["max_rotation"] >= state.limit * ds["critical_rotation"])


def state_design(ds: xr.Dataset, state: DamageState) -> xr.Dataset:
    """The design ``ds`` with overturning replaced by reaching ``state``: for stripes and
    clouds ``overturned`` := :func:`reached`; for an IDA ``capacity_scale`` := the state's
    capacity scale, censored (at ``capacity_scale_lower``) where it was not reached. Every
    fitter of overturning then fits the state. The overturning state is ``ds`` itself."""
    if state.overturning:
        return ds
    view = ds.copy()
    if kind_of(ds).capacities:
        if "state_capacity_scale" not in ds:
            raise ValueError(
                "ds: an IDA needs state_capacity_scale (on damage_state, record, structure) "
                "for the fragility of a damage state: run it with damage_states"
            )
        scale = ds["state_capacity_scale"].sel(damage_state=state.name, drop=True)
        view["capacity_scale"] = scale.transpose("record", "structure")
        view["censored"] = np.isnan(view["capacity_scale"])
        return view
    view["overturned"] = reached(ds, state)
    return view


def state_above(states) -> list[int]:
    """The nesting of ``states`` (:mod:`~rockstudy.study.analysis.nested_fit`): on each
    demand a state is implied by the next larger limit, and the top of each demand by
    overturning (which reaches every state) where it is among ``states``."""
    above = nested_above([s.limit for s in states], [s.demand for s in states])
    top = [k for k, s in enumerate(states) if s.overturning]
    for k, s in enumerate(states):
        if above[k] < 0 and top and not s.overturning:
            above[k] = top[0]
    return above


@per_motion
def state_fragility(
    ds: xr.Dataset,
    states=None,
    im: str | None = None,
    period=None,
    by="structure",
    nested: bool = False,
    **kw,
) -> pd.DataFrame:
    """Lognormal fragility of each damage state, P(state reached | IM): the table of
    the design's overturning fitter
    (:func:`~rockstudy.study.analysis.record_fragility.fragility_of`, with ``im``,
    ``period``, ``by`` and ``kw``; one curve per structure by default) of
    :func:`state_design` for each of the states named in ``states`` (default all, in the
    design's order), with an outer index level ``damage_state`` (the names); with
    ``nested`` the nested fit (:mod:`~rockstudy.study.analysis.nested_fit`: one beta for all
    states of a group, medians ordered as the states nest, :func:`state_above`), whose
    curves never cross. ``fit`` says which ("separate" or "nested"), ``crossed`` is True at
    a state whose curve lies below that of a worse state somewhere in the observed range
    (the fits made apart cross there), and a nested table has ``crossed_separate``, the
    flag of the fits made apart."""
    chosen = design_states(ds, states)
    views = [state_design(ds, s) for s in chosen]
    above = state_above(chosen)
    names = [s.name for s in chosen]
    return shown_table(ds, views, names, above, "damage_state", nested, im, period, by, **kw)


@per_motion
def state_risk(
    ds: xr.Dataset, hazard, states=None, years: float = 50.0, nested: bool = False, **kw
) -> xr.Dataset:
    """The annual rate of reaching each damage state at the site of ``hazard``, per object.

    :func:`~rockstudy.study.analysis.risk.object_risk` of :func:`state_design` for each
    state (a state on the slide with the whole lognormal, ``uplift_cut=False``); with
    ``nested`` of the nested fits (:mod:`~rockstudy.study.analysis.nested_fit`: one beta
    for all states of an object, medians ordered as the states nest, :func:`state_above`;
    ``attrs["fit"]`` says which). Its variables on (``damage_state``, ``structure``), the
    structures in the design's order, with ``damage_demand`` and ``damage_limit`` on
    ``damage_state``; ``n_overturning`` is named ``n_reaching`` (records under which the
    object reached the state; ``status`` as :data:`~rockstudy.study.analysis.risk.STATUSES`,
    of the state); ``crossed`` is True at a state whose rate lies below that of a worse
    state (the fits made apart cross there: read the two rates as about equal; never for
    the nested fits, whose ``crossed_separate`` and ``annual_rate_separate`` are the flag
    and the rate of the fits made apart: the overturning state's is
    :func:`~rockstudy.study.analysis.risk.object_risk`'s rate, its nested rate is not, for
    it shares its beta with the other states).
    ``kw``: ``n_boot``, ``conf_level``, ``seed``, ``min_overturning`` (the records that
    must reach the state for "ok").
    """
    chosen = design_states(ds, states)
    views = [state_design(ds, s) for s in chosen]
    cuts = [s.demand != SLIDE for s in chosen]
    names = [s.name for s in chosen]
    above = state_above(chosen)
    out = _nested_risk(ds, views, "damage_state", names, above, hazard, years, cuts, nested, kw)
    out = out.assign_coords(
        damage_demand=("damage_state", [s.demand for s in chosen]),
        damage_limit=("damage_state", [s.limit for s in chosen]),
    )
    return out.rename(n_overturning="n_reaching")
