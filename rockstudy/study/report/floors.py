"""The record report of a design over floors or orientations (dimensions ``floor`` and
``orientation`` of :func:`~rockstudy.study.designs.record_rows.design_dataset`).

The page names each floor and shows its median response spectrum beside the ground's, then
links a full record report per floor (and, over orientations, one for the worst orientation and
one for the median over orientations, :func:`~rockstudy.study.analysis.orientations.
orientation_summary`), and tables per object and record the capacity at the worst orientation
and the median one, with the fragility fitted to each.
"""

from __future__ import annotations

import html
import json

import numpy as np
import pandas as pd

from ...motions.suites import read_pair
from ..analysis import record_fragility as rf
from ..analysis.fragility_fit import N_BOOT
from ..analysis.orientations import ORIENTATION_SUMMARIES, orientation_summary
from ._page import _Page, _plt

__all__ = ["dimension_report", "floor_spectra", "has_dimensions"]

#: Periods [s] of the spectra of the floor figure.
SPECTRUM_PERIODS = np.geomspace(0.05, 4.0, 60)

_UNSCALED = (
    "Capacities are in the design's measure of the ground record (the site's hazard measure): "
    "the building is linear, so the ground record scaled by s gives every floor motion scaled by s."
)


def has_dimensions(ds) -> bool:
    """Whether a design dataset has a ``floor`` or an ``orientation`` dimension."""
    return bool({"floor", "orientation"} & set(ds.dims))


def _study_motion(ds):
    """The ``[motion]`` of the study stored with ``ds`` (None for a dataset of the API)."""
    study = ds.attrs.get("study")
    if study is None:
        return None
    from ..spec.motion_spec import RecordSpec

    return RecordSpec.model_validate(json.loads(study)["motion"])


def floor_spectra(ds, periods=SPECTRUM_PERIODS) -> pd.DataFrame | None:
    """The median over records of the 5 % spectral acceleration [m/s^2] of the ground and of
    every floor of ``ds`` (columns ``ground`` and ``floor k``, on ``period``), from the study's
    record files and building; None if the dataset names no building or no files."""
    motion = _study_motion(ds)
    if motion is None or motion.building is None or "record_files" not in ds.attrs:
        return None
    files = json.loads(ds.attrs["record_files"])
    floors = [int(k) for k in np.atleast_1d(ds["floor"].values if "floor" in ds else motion.floor)]
    columns = {"ground": []} | {f"floor {k}": [] for k in floors if k}
    for f in files:
        h, v = (f, None) if isinstance(f, str) else f
        ground = read_pair(h, v, motion.units)
        columns["ground"].append(ground.response_spectrum(periods)["sa"].values)
        for k in floors:
            if k:
                at = motion.floor_motion(ground, k)
                columns[f"floor {k}"].append(at.response_spectrum(periods)["sa"].values)
    data = {name: np.median(np.array(rows), axis=0) for name, rows in columns.items()}
    return pd.DataFrame(data, index=pd.Index(periods, name="period [s]"))


def _spectra_section(page, ds):
    table = floor_spectra(ds)
    if table is None:
        return
    page.heading("Floor spectra")
    fig, ax = _plt().subplots(figsize=(7, 4))
    for name in table:
        ax.loglog(
            table.index, table[name] / 9.80665, lw=2.5 if name == "ground" else 1.5, label=name
        )
    ax.set_xlabel("period T [s]")
    ax.set_ylabel("median Sa(T, 5 %) [g]")
    ax.legend()
    fig.tight_layout()
    page.figure(
        fig, "floor_spectra", "Median 5 % spectrum of the records on the ground and on each floor"
    )
    page.table(table, "floor_spectra", "Median 5 % Sa [m/s^2] over the records, per floor")


def _orientation_tables(page, ds, name, n_boot):
    """Per object and record, the capacity at the worst orientation and the median one, and
    the fragility fitted to each (an IDA over orientations)."""
    if "orientation" not in ds.dims or "capacity_scale" not in ds:
        return
    summaries = {w: orientation_summary(ds, w) for w in ORIENTATION_SUMMARIES}
    frame = pd.DataFrame(
        {
            f"capacity, {w} orientation" if w == "worst" else f"capacity, {w} over orientations": s[
                "capacity"
            ]
            .transpose("structure", "record")
            .values.ravel()
            for w, s in summaries.items()
        },
        index=pd.MultiIndex.from_product(
            [list(map(str, ds["structure"].values)), list(map(str, ds["record"].values))],
            names=["object", "record"],
        ),
    )
    unit = ds["capacity"].attrs.get("units", "")
    page.table(
        frame,
        f"{name}_orientation_capacities",
        f"Capacity [{unit}] per object and record at the worst orientation and the median "
        "over orientations (NaN: censored)",
    )
    fits = {
        w: rf.ida_fragility(s, by="structure", n_boot=n_boot)[["theta", "beta", "n"]]
        for w, s in summaries.items()
    }
    table = pd.concat(fits, axis=1)
    page.table(
        table,
        f"{name}_orientation_fragility",
        "Fragility (median theta, dispersion beta) of each object at the worst orientation and "
        "over orientations; for an object of unknown orientation sign the median one, and the "
        "worst one as its bound",
    )


def _slices(ds):
    """(label, folder name, dataset without the floor dimension) per floor."""
    if "floor" not in ds.dims:
        floor = _study_motion(ds)
        label = "" if floor is None or floor.building is None else f"floor {floor.floor}"
        return [(label, "design", ds)]
    return [
        (f"floor {int(k)}", f"floor_{int(k)}", ds.sel(floor=k, drop=True))
        for k in ds["floor"].values
    ]


def dimension_report(ds, out, report, title, *, n_boot=N_BOOT, **options):
    """Write the page of a design over floors or orientations into ``out`` (see the module):
    ``report`` (:func:`~rockstudy.study.report.records.record_report`) writes a full report
    per floor and summary into a folder beside it, with ``options``. Returns index.html."""
    page = _Page(out)
    _spectra_section(page, ds)
    page.text(_UNSCALED)
    for label, folder, part in _slices(ds):
        page.heading(label.capitalize() or "Design")
        if "orientation" in part.dims:
            n = part.sizes["orientation"]
            angles = part["orientation"].values.round(4).tolist()
            page.text(f"{n} orientations of the rocking plane, psi [rad]: {angles}")
            _orientation_tables(page, part, folder, n_boot)
            views = [(w, orientation_summary(part, w)) for w in ORIENTATION_SUMMARIES]
        else:
            views = [("", part)]
        for which, view in views:
            name = f"{folder}_{which}" if which else folder
            sub = f"{title}, {label}" if label else title
            sub += f", {ORIENTATION_SUMMARIES[which]}" if which else ""
            report(view, out / name, title=sub, n_boot=n_boot, **options)
            page.parts.append(f"<p><a href='{name}/index.html'>{html.escape(sub)}</a></p>")
    return page.write(f"rockstudy report: {title}", "")
