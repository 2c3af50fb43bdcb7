"""Sliding as a second demand of a record design under the contact model: the fragility
P(max_slide > d | IM) for each slide limit d, its annual rate at a site, and how much the
contact model changed the annual rate of overturning against Housner's rocking-only model.

A design run with ``model="contact"`` or ``"auto"`` (a study's ``[run] model``) stores each
point's ``max_slide`` [m], the peak slip of the base relative to the ground. For a slide limit
d (a study's ``[design] slide_limits``) a point *exceeds* d where its ``max_slide`` > d **or
where the block overturned**: a block that overturned has certainly lost its position (its
slide after the fall is not a quantity of the model: NaN where Housner's model answered).
Each limit then reads as the design's outcome of its points, and is fitted as overturning is:

- stripes and clouds: the binomial maximum-likelihood fit of the exceedances
  (:func:`~rockstudy.study.analysis.record_fragility.stripe_fragility`, Baker 2015);
- an IDA: the lognormal fit of the slide capacities ``slide_capacity`` (on ``slide_limit``,
  ``record``, ``structure``, in the units of ``capacity``: the first simulated intensity at
  which max_slide > d, NaN if not reached), each capped by the record's overturning capacity
  (an overturning exceeds every limit), censored at the highest scale seen to stand where
  neither was reached (:func:`~rockstudy.study.analysis.record_fragility.ida_fragility`).

The annual rate of exceeding d is Cornell et al.'s integral of that fragility over the hazard
curve (:func:`~rockstudy.study.analysis.risk.object_risk`, with its bootstrap band), of the
whole lognormal: a block slides below its uplift PGA, so the fragility is not cut there.

Under ``model="auto"`` Housner's model runs first on every scene, and the design keeps its
decision as ``overturned_rocking``; an IDA climbs every ladder under Housner's model too and
keeps ``capacity_rocking``: :func:`contact_effect` fits both and gives, per object, the ratio
of the annual rates of overturning, contact model over rocking-only.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from ...dynamics.batch import MODEL_CONTACT
from ...dynamics.constants import STATUS_UNCONVERGED
from ..designs.records import IDA_ROCKING_VARIABLES
from ..spec.design_kinds import kind_of
from . import record_fragility as rf
from .motion_axes import per_motion
from .nested_fit import nested_above, rates_crossed, risk_frames, shown_table
from .risk import object_risk

__all__ = [
    "NOT_CONVERGED",
    "REGIME_NAMES",
    "contact_effect",
    "exceeds_slide",
    "limit_design",
    "regimes",
    "rocking_design",
    "slide_fragility",
    "slide_limits",
    "slide_risk",
]

#: The ``regime`` output of the contact model (the most involved regime a scene entered).
REGIME_NAMES = {0: "rest", 1: "slide", 2: "rock", 3: "slide-rock", 4: "flight"}
#: What :func:`regimes` says of a point whose contact model answer did not converge.
NOT_CONVERGED = "not converged"


def slide_limits(ds: xr.Dataset, limits=None) -> np.ndarray:
    """The slide limits d [m]: ``limits`` (one or more, > 0), else the design's
    (``attrs["slide_limits"]``, a study's ``[design] slide_limits``); a ValueError without
    any, or without the contact model's ``max_slide`` (or an IDA's ``slide_capacity``)."""
    if not ({"max_slide", "slide_capacity"} & set(ds.variables)):
        raise ValueError(
            "ds: holds no max_slide: run the design with the contact model (model='contact' "
            "or 'auto' with friction; a study's [run] model)"
        )
    given = ds.attrs.get("slide_limits") if limits is None else limits
    d = np.atleast_1d(np.asarray([] if given is None else given, float))
    if d.ndim != 1 or not d.size or not np.all(np.isfinite(d) & (d > 0)):
        raise ValueError(
            f"limits: give one or more slide limits > 0 [m] (or the design's [design] "
            f"slide_limits), got {given!r}"
        )
    return d


def exceeds_slide(ds: xr.Dataset, d: float) -> xr.DataArray:
    """True at each point of stripes or a cloud whose ``max_slide`` exceeds ``d`` [m] or that
    overturned (an overturned block has lost its position)."""
    return (ds["max_slide"] > d) | (ds["overturned"] == 1)


def _ida_slide_scale(ds, d):
    """The scale factor of each record at which each structure first slid more than ``d``
    (from ``slide_capacity``, in the units of ``capacity``), or first overturned if lower;
    NaN where neither happened."""
    im = ds.attrs.get("im", "pga")
    period = ds.attrs.get("im_period", np.nan)
    stored = rf._stored(ds, im, period if np.isfinite(period) else None)
    stored_limits = np.asarray(ds["slide_limit"].values, float)
    hit = np.flatnonzero(np.isclose(stored_limits, d, rtol=1e-12, atol=0.0))
    if not hit.size:
        raise ValueError(
            f"limits: the IDA stores slide_capacity at slide limits {list(stored_limits)} m, "
            f"not at {d!r}"
        )
    cap = ds["slide_capacity"].isel(slide_limit=hit[0], drop=True)
    scale = (cap / stored) ** (1.0 / rf.power(im))
    overturning = ds["capacity_scale"].where(ds["censored"] == 0)
    return np.fmin(scale, overturning).transpose("record", "structure")


def limit_design(ds: xr.Dataset, d: float) -> xr.Dataset:
    """The design ``ds`` with overturning replaced by exceeding the slide limit ``d`` [m]: for
    stripes and clouds ``overturned`` := :func:`exceeds_slide`; for an IDA the capacities
    (``capacity_scale``) := the first scale at which the slide exceeded ``d`` or the block
    overturned, censored (at ``capacity_scale_lower``) where neither happened. Every fitter of
    overturning then fits P(max_slide > d)."""
    view = ds.copy()
    if kind_of(ds).capacities:
        if "slide_capacity" not in ds:
            raise ValueError(
                "ds: an IDA needs slide_capacity (on slide_limit, record, structure) for the "
                "fragility of sliding: run it with the contact model and slide_limits"
            )
        scale = _ida_slide_scale(ds, d)
        view["capacity_scale"] = scale
        view["censored"] = np.isnan(scale)
        return view
    view["overturned"] = exceeds_slide(ds, d)
    return view


def rocking_design(ds: xr.Dataset) -> xr.Dataset:
    """The design ``ds`` with the outcome of Housner's rocking-only model as its own, both
    kept by ``model="auto"``: ``overturned_rocking`` as ``overturned`` (stripes and clouds;
    its -1, Housner's model failed, as ``status`` 1, and a point only the contact model
    failed on as ``status`` 0);
    for an IDA ``capacity_rocking``, ``capacity_scale_rocking``,
    ``capacity_scale_lower_rocking``, ``censored_rocking`` and ``status_rocking`` as
    ``capacity``, ``capacity_scale`` ... (Housner's ladder)."""
    ida = kind_of(ds).capacities
    needed = "capacity_rocking" if ida else "overturned_rocking"
    if needed not in ds:
        raise ValueError(
            f"ds: holds no {needed} (Housner's answer): the rocking-only answer needs "
            "model='auto' (a study's [run] model = \"auto\"), which runs Housner's model "
            + ("on every ladder too" if ida else "on every scene first")
        )
    view = ds.copy()
    if not ida:  # -1: Housner's model failed there; the contact model's failures are not its
        rocking = ds["overturned_rocking"]
        answered = ds["model"] >= MODEL_CONTACT if "model" in ds else False
        view["status"] = xr.where(rocking < 0, 1, xr.where(answered, 0, ds["status"]))
        view["overturned"] = rocking.clip(min=0).astype(ds["overturned"].dtype)
        return view
    for name in ("capacity", *IDA_ROCKING_VARIABLES):
        view[name] = ds[f"{name}_rocking"]
    return view


def _n_overturned(design) -> xr.DataArray:
    """Per structure, the points (records of an IDA) that ran and overturned."""
    if kind_of(design).capacities:
        over = design["censored"] == 0
    else:
        over = design["overturned"] == 1
    return over.where(design["status"] == 0, False).sum([k for k in over.dims if k != "structure"])


@per_motion
def slide_fragility(
    ds: xr.Dataset,
    limits=None,
    im: str | None = None,
    period=None,
    by="structure",
    nested: bool = False,
    **kw,
) -> pd.DataFrame:
    """Lognormal fragility of sliding, P(max_slide > d | IM), for each slide limit d.

    Parameters
    ----------
    ds : xarray.Dataset
        A cloud or stripes design run under the contact model (``max_slide``), or an IDA
        with ``slide_capacity``.
    limits : array_like, optional
        The slide limits d [m] (default the design's ``attrs["slide_limits"]``).
    im, period, by, kw
        As the design's overturning fitter
        (:func:`~rockstudy.study.analysis.record_fragility.fragility_of`); one curve per
        structure by default.
    nested : bool
        False (default): each limit fitted apart. True: the nested fit
        (:mod:`~rockstudy.study.analysis.nested_fit`), one beta for all limits of a group
        and medians increasing with d, so that the curves never cross.

    Returns
    -------
    pandas.DataFrame
        The fitter's table with an outer index level ``slide_limit`` [m], ``fit``
        ("separate" or "nested") and ``crossed`` (True at a limit whose curve lies below a
        larger limit's somewhere in the observed range: the fits made apart cross there);
        a nested table has ``crossed_separate``, the flag of the fits made apart.
    """
    d = slide_limits(ds, limits)
    views = [limit_design(ds, x) for x in d]
    keys, above = [float(x) for x in d], nested_above(d)
    return shown_table(ds, views, keys, above, "slide_limit", nested, im, period, by, **kw)


def _concat_objects(frames, dim, values, order):
    """The per-object Datasets ``frames`` (each ranked its own way) in the structure order
    ``order``, concatenated along ``dim`` with coordinate ``values``."""
    frames = [f.sel(structure=order) for f in frames]
    return xr.concat(frames, dim=pd.Index(values, name=dim), combine_attrs="drop_conflicts")


@per_motion
def slide_risk(
    ds: xr.Dataset, hazard, limits=None, years: float = 50.0, nested: bool = False, **kw
) -> xr.Dataset:
    """The annual rate of exceeding each slide limit d at the site of ``hazard``, per object.

    :func:`~rockstudy.study.analysis.risk.object_risk` of :func:`limit_design` at each d,
    with the whole lognormal (``uplift_cut=False``: a block slides below its uplift PGA);
    with ``nested`` of the nested fits (:mod:`~rockstudy.study.analysis.nested_fit`: one
    beta for all limits of an object, medians increasing with d; ``attrs["fit"]`` says
    which). Its variables on (``slide_limit``, ``structure``), the structures in the
    design's order; ``n_overturning`` is named ``n_exceeding`` (records under which the
    object slid more than d or overturned) and ``status`` reads "exceeded d" for
    "overturned"; ``crossed`` is True at a limit whose rate lies below that of a larger
    limit (the fits of nested exceedances, made apart, cross there: read the two rates as
    about equal; never for the nested fits, whose ``crossed_separate`` is the flag of the
    fits made apart). ``kw``: ``n_boot``, ``conf_level``, ``seed``, ``min_overturning``
    (the records that must exceed d for "ok").
    """
    d = slide_limits(ds, limits)
    views = [limit_design(ds, x) for x in d]
    cuts = [False] * d.size
    out = _nested_risk(
        ds, views, "slide_limit", d, nested_above(d), hazard, years, cuts, nested, kw
    )
    out["slide_limit"].attrs.update(units="m", long_name="slide limit d of P(max_slide > d)")
    return out.rename(n_overturning="n_exceeding")


def _nested_risk(ds, views, dim, values, above, hazard, years, cuts, nested, kw):
    """The per-state risks of the design views ``views`` on ``dim`` (coordinate
    ``values``), with ``crossed`` (and with ``nested`` ``crossed_separate`` and
    ``annual_rate_separate``, the flag and the rate of the fits made apart) and
    ``attrs["fit"]``."""
    frames = risk_frames(views, above, hazard, years, cuts, nested, **kw)
    out = _concat_objects(frames, dim, values, ds["structure"].values)
    out["crossed"] = _crossed(out["annual_rate"], dim, above)
    if nested:
        alone = risk_frames(views, above, hazard, years, cuts, False, **{**kw, "n_boot": 0})
        rates = _concat_objects(alone, dim, values, ds["structure"].values)["annual_rate"]
        out["crossed_separate"] = _crossed(rates, dim, above)
        out["annual_rate_separate"] = rates
    out.attrs["fit"] = "nested" if nested else "separate"
    return out


def _crossed(rate: xr.DataArray, dim, above) -> xr.DataArray:
    """True where the rate of a state is below that of a worse state (of ``above``): the
    data nest (a slide past the larger d is past the smaller), but lognormals fitted apart
    may cross; read such rates as about equal."""
    values = rate.transpose(dim, "structure").values
    flags = rates_crossed(values, above)
    return xr.DataArray(
        flags, dims=(dim, "structure"), coords=rate.transpose(dim, "structure").coords
    )


@per_motion
def contact_effect(ds: xr.Dataset, hazard, years: float = 50.0, **kw) -> xr.Dataset:
    """Per object: the annual rate of overturning under the contact model (the design's
    answer) and under Housner's rocking-only model (``overturned_rocking`` of
    ``model="auto"``; an IDA's ``capacity_rocking``, its ladder under Housner's model), and
    their ratio: each through :func:`~rockstudy.study.analysis.risk.object_risk`, the
    design's own fitter and integral.

    Returns
    -------
    xarray.Dataset
        On ``structure`` (the design's order): ``annual_rate`` and ``status`` of each model
        (``annual_rate_contact``, ``annual_rate_rocking``, ``status_contact``,
        ``status_rocking``), the overturning points of each (``n_overturned_contact``,
        ``n_overturned_rocking``; of an IDA the records under which it overturned), and
        ``ratio`` = contact / rocking (NaN where either rate is not estimable; inf where only
        the rocking one is 0).
    """
    order = ds["structure"].values
    rock = rocking_design(ds)
    out = xr.Dataset(coords={"structure": order})
    for name, design in (("contact", ds), ("rocking", rock)):
        risk = object_risk(design, hazard, years, **kw).sel(structure=order)
        out[f"annual_rate_{name}"] = risk["annual_rate"]
        out[f"status_{name}"] = risk["status"]
        out[f"n_overturned_{name}"] = _n_overturned(design)
    with np.errstate(divide="ignore", invalid="ignore"):
        out["ratio"] = out["annual_rate_contact"] / out["annual_rate_rocking"]
    out.attrs.update(im=hazard.im, units=hazard.units, years=float(years))
    return out


@per_motion
def regimes(ds: xr.Dataset) -> pd.DataFrame:
    """Which regime each record drove each object into: the ``regime`` output (the most
    involved regime entered, :data:`REGIME_NAMES`) as names, index (object, record), one
    column (a cloud) or one per level (stripes); "not converged" where the contact model's
    answer did not converge with rtol (``status`` 4), "not run" where a point did not run
    (or failed otherwise). A design over floors and orientations gives the table of each
    (floor, orientation) under those outer index levels
    (:func:`~rockstudy.study.analysis.motion_axes.per_motion`)."""
    if "regime" not in ds:
        raise ValueError("ds: holds no regime: run the design with the contact model")
    dims = [k for k in ("structure", "record", "level") if k in ds["regime"].dims]
    code = ds["regime"].where(ds["status"] == 0).transpose(*dims).values
    unconverged = (ds["status"] == STATUS_UNCONVERGED).transpose(*dims).values
    text = np.vectorize(
        lambda c: "not run" if np.isnan(c) else REGIME_NAMES.get(int(c), "?"), otypes=[object]
    )
    names = np.where(unconverged, NOT_CONVERGED, text(code))
    index = pd.MultiIndex.from_product(
        [ds["structure"].values, ds["record"].values], names=["structure", "record"]
    )
    columns = ds["level"].values if "level" in dims else ["regime"]
    n = len(index)
    return pd.DataFrame(names.reshape(n, -1), index=index, columns=columns)
