"""The report of a record design (issue 13 section 8), rendered in headless Chromium."""

import html as html_mod
import re
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
import pytest
from _helpers import chromium_figures

from rockstudy.constants import G
from rockstudy.motions import Record, load_suite
from rockstudy.study.designs.records import cloud, incremental_dynamic_analysis, multiple_stripes
from rockstudy.study.report import make_report
from rockstudy.study.report.records import record_report

DATA = Path(__file__).resolve().parents[1] / "data" / "records"
EVIL = "<script>alert(1)</script> & co"


@pytest.fixture(scope="module")
def records():
    """Two shipped synthetic near-fault records and a third whose name must be escaped."""
    shipped = load_suite([DATA / "NF03_Tp0.80s_H.AT2", DATA / "NF06_Tp1.70s_H.AT2"])
    third = shipped[0]
    evil = Record(third.acceleration[::-1] * 0.8, dt=third.dt, name=EVIL)
    return shipped + [evil]


STRUCTURES = {"half_diagonal": [0.3, 1.0, 3.0], "slenderness": 0.2}


def check_page(page, tmp_path, figures, tables):
    shown, total = chromium_figures(page)
    assert total == len(figures) and shown == total
    out = page.parent
    assert {p.stem for p in out.glob("*.png")} == set(figures)
    for png in out.glob("*.png"):
        img = mpimg.imread(png)
        assert np.unique(img.reshape(-1, img.shape[-1]), axis=0).shape[0] > 20, png
    assert set(tables) <= {p.stem for p in out.glob("*.csv")}
    source = page.read_text()
    text = re.sub(r"<img[^>]*>", "", source)
    # the record name from a file: escaped wherever it is shown, never live
    assert "<script>alert" not in text and html_mod.escape(EVIL) in text
    # numbers in three significant figures, counts as integers
    cells = re.findall(r"<td>([-+0-9.eE]+)</td>", text)
    assert cells
    for c in cells:
        digits = re.sub(r"e.*", "", c.lower()).replace("-", "").replace(".", "").lstrip("0")
        assert len(digits) <= 3, c
    assert "<td>3</td>" in text  # three records
    assert "print(" not in text and "DEBUG" not in text
    for name in ("PGA [g]", "PGV [m/s]", "PGA / a_up [-]", "PGV p / a_up [-]"):
        assert html_mod.escape(name) in text
    assert "pulse period T_p [s]" in text
    return text


@pytest.fixture(scope="module")
def ida(records):
    return incremental_dynamic_analysis(
        records, STRUCTURES, step=0.05, tolerance=0.05, scan=8, periods=(0.5,), rtol=1e-6
    )


def test_ida_report(tmp_path, records, ida):
    ds = ida
    page = record_report(ds, tmp_path / "report", title="ida <b>test</b>", n_boot=10)
    text = check_page(
        page,
        tmp_path,
        ["record_fragility", "ida_points", "size_collapse"],
        [
            "summary",
            "records",
            "record_fragility",
            "im_efficiency",
            "per_record",
            "size_collapse",
            "switch_band",
        ],
    )
    # the switch band of all records: the blocks seen to survive above their first
    # overturning, counted from the simulated points themselves
    band = pd.read_csv(tmp_path / "report" / "switch_band.csv", index_col=0)
    s, over = ds["step_scale"].values, ds["step_overturned"].values
    cap = ds["capacity_scale"].values[..., None]
    seen = ((s > cap) & (over == 0)).any(axis=-1).sum()
    assert band.loc["all records", "of which seen to survive above it"] == seen
    assert "survive above their first overturning" in text
    assert "<b>test</b>" not in text
    assert html_mod.escape("Sa(T = 0.5 s) [g]") in text
    eff = (tmp_path / "report" / "im_efficiency.csv").read_text()
    assert "PGV p / a_up [-]" in eff and "dimensionless" in eff
    medians = (tmp_path / "report" / "size_class_medians.csv").read_text()
    assert "R 0.3 to" in medians


def test_stripes_and_ida_side_by_side_warn_where_their_bands_part(tmp_path, records, ida):
    levels = np.geomspace(0.1, 3.0, 6) * G
    stripes = multiple_stripes(records, STRUCTURES, levels, periods=(0.5,), rtol=1e-6)
    page = record_report(ida, tmp_path / "same", n_boot=10, compare=stripes)
    table = pd.read_csv(tmp_path / "same" / "stripes_and_ida.csv")
    assert len(table) >= 5 and {"IDA median", "stripes median"} <= set(table.columns)
    text = page.read_text()
    agree = table["bands overlap"].all()
    assert ("disagree beyond their 90 % bands" in text) == (not agree)
    # the same stripes read as ten times stronger (their scales multiplied by 10): the
    # fragility against PGA moves tenfold, far outside the bands; the report must say so
    louder = stripes.assign(scale=stripes["scale"] * 10.0)
    page = record_report(louder, tmp_path / "apart", n_boot=10, compare=ida)
    assert "disagree beyond their 90 % bands" in page.read_text()
    with pytest.raises(ValueError, match="compare"):
        record_report(ida, tmp_path / "bad", compare=ida)


def test_stripes_report_and_the_dispatch_of_make_report(tmp_path, records):
    """Stripes at PGA levels; written as a cube, `rockstudy report` picks the record report
    by its design attribute."""
    ds = multiple_stripes(
        records,
        {"half_diagonal": [0.5, 2.0], "slenderness": 0.2},
        [0.1 * G, 0.3 * G, 0.9 * G],
        rtol=1e-6,
    )
    cube = tmp_path / "stripes.zarr"
    ds.assign_coords(record_name=ds["record_name"].astype(str)).to_zarr(cube, consolidated=True)
    page = make_report(cube, tmp_path / "report")
    check_page(
        page,
        tmp_path,
        ["record_fragility", "stripes_points"],
        ["summary", "records", "record_fragility", "im_efficiency", "per_record"],
    )


def test_cloud_report(tmp_path, records):
    scaled = [r.scaled(2.0) for r in records]
    ds = cloud(scaled, {"half_diagonal": [0.3, 0.6, 1.2, 2.4, 4.8], "slenderness": 0.15}, rtol=1e-6)
    assert 0 < ds["overturned"].sum() < ds["overturned"].size  # both outcomes
    page = record_report(ds, tmp_path / "report", n_boot=10)
    check_page(
        page,
        tmp_path,
        ["record_fragility", "cloud_points", "size_collapse"],
        ["summary", "records", "record_fragility", "im_efficiency", "per_record"],
    )


def test_unknown_design_is_refused(tmp_path, records):
    ds = cloud(records[:1], STRUCTURES, rtol=1e-6)
    ds.attrs["design"] = "ladder"
    with pytest.raises(ValueError, match="design"):
        record_report(ds, tmp_path)
