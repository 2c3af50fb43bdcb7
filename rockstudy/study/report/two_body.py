"""The record report's section on two-body objects (a statue on its plinth, a block on an
isolator): their outputs per object, a warning where an isolator moves beyond its stated
capacity, and, for each object given with its plain twin (``compare_to``), the ratio of their
annual rates of overturning with its band: what the plinth or the isolator buys
(:mod:`rockstudy.study.analysis.two_body`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis.two_body import over_capacity, pair_ratios, study_pairs

__all__ = ["BODY_NAMES", "section"]

#: ``overturned_body`` in words (its codes:
#: :data:`rockstudy.dynamics.two_body_batch.OVERTURNED_BODY`).
BODY_NAMES = {1: "the plinth", 2: "the statue", 3: "both"}


def _two_body(ds) -> list[int]:
    """The indices of the objects with a plinth or an isolator: those with a two-body output
    anywhere (an overturned body, a rotation of the plinth, an isolator displacement; an
    IDA's object that never overturned has ``overturned_body`` -1 but its rotations)."""
    marks = [
        ds["overturned_body"] >= 0 if "overturned_body" in ds else None,
        ds["max_rotation_lower"].notnull() if "max_rotation_lower" in ds else None,
        ds["max_isolator_displacement"].notnull() if "max_isolator_displacement" in ds else None,
    ]
    seen = [v.any([d for d in v.dims if d != "structure"]).values for v in marks if v is not None]
    return [j for j in range(ds.sizes["structure"]) if any(s[j] for s in seen)]


def section(page, ctx):
    """The two-body section, when the design has an object with a plinth or an isolator."""
    ds = ctx.ds
    objects = _two_body(ds)
    if not objects:
        return
    page.heading("Statues on plinths and isolators")
    _outputs(page, ctx, objects)
    _capacity_warning(page, ctx)
    _pairs(page, ctx)


def _largest(ds, name, j) -> float:
    """The largest finite value of ``name`` of object ``j`` over its scenes (NaN if none)."""
    if name not in ds:
        return np.nan
    v = ds[name].isel(structure=j).values.astype(float)
    return float(np.nanmax(v)) if np.isfinite(v).any() else np.nan


def _outputs(page, ctx, objects):
    """One row per two-body object: how many scenes overturned which body (of a statue on a
    plinth; empty for a block on an isolator), the largest rotations and isolator
    displacement."""
    ds, ida = ctx.ds, ctx.kind.capacities
    rows = {}
    for j in objects:
        body = ds["overturned_body"].isel(structure=j).values if "overturned_body" in ds else []
        row = {"scenes": int(np.size(body))}
        plinth = np.isfinite(_largest(ds, "max_rotation_lower", j))  # no plinth: no bodies
        for code, words in BODY_NAMES.items():
            row[f"overturned: {words}"] = int(np.sum(np.asarray(body) == code)) if plinth else None
        row["largest rotation of the plinth [rad]"] = _largest(ds, "max_rotation_lower", j)
        row["largest rotation of the statue on it [rad]"] = _largest(ds, "max_rotation_upper", j)
        row["largest isolator displacement [m]"] = _largest(ds, "max_isolator_displacement", j)
        rows[str(ds["structure"].values[j])] = row
    frame = pd.DataFrame.from_dict(rows, orient="index").rename_axis("object")
    where = (
        "the rotations and the displacement at the highest scale each object stood at below "
        "its first overturning (capacity_scale_lower), the body at that overturning"
        if ida
        else "over every scene"
    )
    page.table(
        frame,
        "two_body_outputs",
        "Each statue on a plinth or block on an isolator: which body overturned (the plinth, "
        "the statue or both; either is the object's overturning in the fragility and the "
        f"rates) and its largest rotations and isolator displacement, {where}",
        hide_empty=[c for c in frame if c.startswith("largest")],
    )


def _capacity_warning(page, ctx):
    """A warning naming each isolated object and record whose isolator displacement exceeds
    the object's ``isolator_capacity``, with counts."""
    over = over_capacity(ctx.ds)
    if not over.data_vars or not int(over["over"].sum()):
        return
    labels = dict(zip(map(str, ctx.ds["record"].values), ctx.record_names(), strict=True))
    parts = []
    for name in over["structure"].values:
        o = over.sel(structure=name)
        if not int(o["over"]):
            continue
        by = o["over_by_record"]
        counts = zip(by["record"].values, by.values, strict=True)
        records = ", ".join(f"{labels[str(r)]} ({int(n)})" for r, n in counts if n)
        parts.append(
            f"{name}: {int(o['over'])} of {int(o['scenes'])} scenes exceed its isolator "
            f"capacity {float(o['isolator_capacity']):.4g} m (largest "
            f"{float(o['largest']):.4g} m), under {records}"
        )
    page.warning(
        "The isolator moves beyond its stated capacity (isolator_capacity): "
        + "; ".join(parts)
        + ". The model has no stop there: past it the isolator would hit its end, which the "
        "results do not describe."
    )


def _pairs(page, ctx):
    """Each two-body object beside its plain twin (``compare_to``): the ratio of their annual
    rates of overturning with its band, when the report has a hazard."""
    pairs = study_pairs(ctx.ds)
    if not pairs:
        return
    if ctx.hazard is None:
        page.text(
            "The study pairs objects with their plain twins (compare_to), but gives no [hazard]: "
            "no annual rates, so no ratio of them."
        )
        return
    out = pair_ratios(ctx.ds, ctx.hazard, pairs, ctx.years, n_boot=ctx.n_boot)
    frame = pd.DataFrame(
        {
            "plain twin": out["plain"].values,
            "lambda_OT [1/yr]": out["annual_rate"].values,
            "status": out["status"].values,
            "lambda_OT of the plain twin [1/yr]": out["annual_rate_plain"].values,
            "status of the plain twin": out["status_plain"].values,
            "ratio": out["ratio"].values,
            "ratio, 5 %": out["ratio_lo"].values,
            "ratio, 95 %": out["ratio_hi"].values,
            "resamples": out["n_resamples"].values,
        },
        index=pd.Index([str(v) for v in out["pair"].values], name="object"),
    )
    page.table(
        frame,
        "plinth_isolator_ratio",
        "What the plinth or the isolator buys: each object's annual rate of overturning over "
        "that of the same statue on rigid ground (its compare_to), from the same fits as the "
        "annual-rate table; below 1 the plinth or isolator lowers the rate. The band (90 %) "
        "is that of the ratio over the same resamples of the records for both objects; NaN "
        "where either rate is not estimable (see each status)",
    )
