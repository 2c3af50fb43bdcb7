"""The two-body objects of a record design (a statue on its plinth, a block on an isolator):
their isolator's capacity, and what the plinth or the isolator buys.

A two-body object of a study names its plain twin with ``compare_to`` (a block object of the
same statue, :class:`~rockstudy.study.spec.objects_spec.ObjectSpec`): :func:`pair_ratios`
gives the ratio of their annual rates of overturning with its band, from the same resamples
of the records for both (:func:`~rockstudy.study.analysis.risk.object_risk`).
"""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

from .motion_axes import per_motion
from .risk import object_risk

__all__ = ["isolator_capacities", "over_capacity", "pair_ratios", "study_objects", "study_pairs"]


def study_objects(ds: xr.Dataset) -> list[dict]:
    """The named objects of the study a design's cube was run from (its ``study``
    attribute), as written; none for a design made in Python."""
    study = json.loads(ds.attrs.get("study", "{}"))
    structure = study.get("structure") or {}
    return list(structure.get("objects") or []) if structure.get("kind") == "objects" else []


def study_pairs(ds: xr.Dataset) -> list[tuple[str, str]]:
    """(two-body object, its plain block object) of each ``compare_to`` of the study."""
    return [(o["name"], o["compare_to"]) for o in study_objects(ds) if o.get("compare_to")]


def isolator_capacities(ds: xr.Dataset) -> dict:
    """``isolator_capacity`` [m] of each isolated object of the study that gives one."""
    return {
        o["name"]: float(o["isolator_capacity"])
        for o in study_objects(ds)
        if o.get("isolator_capacity") is not None
    }


def over_capacity(ds: xr.Dataset) -> xr.Dataset:
    """Per isolated object with a capacity: ``scenes`` (its points with a displacement),
    ``over`` (those whose ``max_isolator_displacement`` exceeds ``isolator_capacity``) and
    ``over_by_record`` (on record: how many of each record's), on ``structure``."""
    capacity = isolator_capacities(ds)
    names = [n for n in ds["structure"].values if n in capacity]
    if "max_isolator_displacement" not in ds or not names:
        return xr.Dataset()
    u = ds["max_isolator_displacement"].sel(structure=names)
    limit = xr.DataArray([capacity[n] for n in names], coords={"structure": names})
    over = u > limit  # a NaN (not run, failed) is not over
    rest = [d for d in u.dims if d not in ("structure", "record")]
    return xr.Dataset(
        {
            "isolator_capacity": limit,
            "scenes": u.notnull().sum([*rest, "record"]),
            "over": over.sum([*rest, "record"]),
            "over_by_record": over.sum(rest),
            "largest": u.max([*rest, "record"]),
        }
    )


def _paired_band(boot_a, boot_b, conf_level):
    """(lower, upper, count) of the ratio a / b over the resamples where both rates exist and
    b > 0 (percentiles at resamples, without interpolation, as the rates' own bands)."""
    ok = np.isfinite(boot_a) & np.isfinite(boot_b) & (boot_b > 0)
    if not ok.any():
        return np.nan, np.nan, 0
    q = [50 * (1 - conf_level), 50 * (1 + conf_level)]
    lo, hi = np.percentile(boot_a[ok] / boot_b[ok], q, method="inverted_cdf")
    return float(lo), float(hi), int(ok.sum())


@per_motion
def pair_ratios(ds: xr.Dataset, hazard, pairs=None, years: float = 50.0, **kw) -> xr.Dataset:
    """What a plinth or an isolator buys: per pair (two-body object, its plain twin), the
    ratio of their annual rates of overturning (two-body / plain: below 1, the plinth or the
    isolator lowers the rate) with its band.

    Both rates come from one :func:`~rockstudy.study.analysis.risk.object_risk` call on the
    two objects (the design's own fitter and integral), so each resample of the records is
    the same for both: the band is the percentiles of the resampled ratios (``conf_level``,
    those whose plain rate is > 0; ``n_resamples`` counts them).

    Parameters
    ----------
    ds : xarray.Dataset
        A record design of named objects (a study's cube folded, or a design's Dataset).
    hazard : rockstudy.risk.HazardCurve
        The site's hazard curve.
    pairs : list of (str, str), optional
        (two-body object, plain object) names; default the study's ``compare_to``
        (:func:`study_pairs`).
    years : float
        As :func:`~rockstudy.study.analysis.risk.object_risk`'s.
    **kw
        ``n_boot``, ``conf_level``, ``seed``, ``min_overturning`` of
        :func:`~rockstudy.study.analysis.risk.object_risk`.

    Returns
    -------
    xarray.Dataset
        On ``pair`` (the two-body object's name), with ``plain`` (its twin's name):
        ``annual_rate`` and ``status`` of each (``annual_rate_plain``, ``status_plain``),
        ``ratio`` (NaN where either rate is not estimable or both are 0; inf where only the
        plain one is 0), ``ratio_lo``, ``ratio_hi`` and ``n_resamples``. A design over
        floors and orientations gives those of each (floor, orientation), on those
        dimensions too (:func:`~rockstudy.study.analysis.motion_axes.per_motion`).
    """
    pairs = study_pairs(ds) if pairs is None else [tuple(p) for p in pairs]
    known = set(map(str, ds["structure"].values))
    for name in (n for p in pairs for n in p):
        if name not in known:
            raise ValueError(f"pairs: {name!r} is no object of the design; it has {sorted(known)}")
    rows = {}
    for obj, plain in pairs:
        out = object_risk(ds.sel(structure=[obj, plain]), hazard, years, **kw)
        a, b = (out.sel(structure=n) for n in (obj, plain))
        rate_a, rate_b = float(a["annual_rate"]), float(b["annual_rate"])
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.float64(rate_a) / np.float64(rate_b)
        boots = (a["annual_rate_resamples"].values, b["annual_rate_resamples"].values)
        band = _paired_band(*boots, out.attrs["conf_level"])
        rows[obj] = dict(
            plain=plain,
            annual_rate=rate_a,
            status=str(a["status"].values),
            annual_rate_plain=rate_b,
            status_plain=str(b["status"].values),
            ratio=float(ratio),
            ratio_lo=band[0],
            ratio_hi=band[1],
            n_resamples=band[2],
        )
    names = list(rows)
    data = {k: ("pair", [rows[n][k] for n in names]) for k in next(iter(rows.values()), {})}
    return xr.Dataset(data, coords={"pair": np.array(names, dtype=object)}, attrs={"years": years})
