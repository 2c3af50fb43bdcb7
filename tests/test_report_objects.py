"""The record report of named objects (issue 24 section 2): per object, by name. Oracles:
single-scene simulations of each object under each scaled record (which record governs and
between which levels each object first overturns), the objects' own uplift level g tan(alpha),
and the records' own PGA (the scale factors beyond ``max_scale_factor``)."""

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import load_suite
from rockstudy.study.records_designs import multiple_stripes
from rockstudy.study.report_records import record_report

DATA = Path(__file__).resolve().parents[1] / "data" / "records"
OBJECTS = {
    "Statue A": rs.Block.from_dimensions(width=0.45, height=1.9),
    "Vase": rs.Block(half_diagonal=0.4, slenderness=0.3, restitution=0.85),
}


@pytest.fixture(scope="module")
def records():
    return load_suite([DATA / "NF03_Tp0.80s_H.AT2", DATA / "NF06_Tp1.70s_H.AT2"])


def _text(page):
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page.read_text()))


def test_capacity_table_and_governing_record_per_object(tmp_path, records):
    levels = np.array([0.2, 0.4, 0.8, 1.6]) * G
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    page = record_report(ds, tmp_path / "r", n_boot=5)
    table = pd.read_csv(tmp_path / "r" / "object_capacity.csv", index_col=0)
    assert list(table.index) == list(OBJECTS)
    names = [r.name for r in records]
    for obj, block in OBJECTS.items():
        first = {}  # the oracle: each scaled record alone, level by level
        for rec in records:
            over = [rs.simulate(block, rec.scaled(x / rec.peak)).overturned for x in levels]
            first[rec.name] = levels[over.index(True)] / G if any(over) else np.inf
            k = over.index(True) if any(over) else -1
            cell = table.loc[obj, rec.name]
            if k < 0:
                assert cell == f"above {levels[-1] / G:.3g}"
            elif k == 0:
                assert cell == f"at or below {levels[0] / G:.3g}"
            else:
                assert cell == f"{levels[k - 1] / G:.3g} to {levels[k] / G:.3g}"
        lowest = min(first.values())
        governing = table.loc[obj, "governing record (lowest capacity)"]
        if np.isfinite(lowest):
            assert first[governing] == lowest and governing in names
            assert table.loc[obj, "governing capacity"] == pytest.approx(lowest, rel=1e-9)
    # the per-object figures and the uplift level g tan(alpha) of each object
    out = tmp_path / "r"
    assert (out / "object_stripes.png").exists()
    if (out / "object_fragility.csv").exists():
        fit = pd.read_csv(out / "object_fragility.csv", index_col=0)
        for obj, block in OBJECTS.items():
            up = fit.loc[[obj], "uplift level, PGA [g]"].iloc[0]
            assert up == pytest.approx(math.tan(block.slenderness), rel=1e-9)
    assert "Nothing overturned" not in _text(page)


def test_nothing_rocked_is_said_in_words(tmp_path, records):
    # every level below the uplift level g tan(alpha) of every object: nothing can rock
    lowest_uplift = min(G * math.tan(b.slenderness) for b in OBJECTS.values())
    levels = np.array([0.2, 0.5]) * lowest_uplift
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    assert float(np.nanmax(ds["max_rotation"].values)) == 0.0  # the oracle agrees
    page = record_report(ds, tmp_path / "r", n_boot=5)
    text = _text(page)
    assert "Nothing rocked" in text and "no fragility can be fitted" in text
    assert not (tmp_path / "r" / "object_fragility.png").exists()
    table = pd.read_csv(tmp_path / "r" / "object_capacity.csv", index_col=0)
    assert (table.iloc[:, : len(records)] == f"above {levels[-1] / G:.3g}").all().all()


def test_nothing_overturned_but_rocked(tmp_path, records):
    # between uplift and overturning of the stockier Vase only: it rocks, none overturns
    vase = OBJECTS["Vase"]
    levels = np.array([1.05]) * G * math.tan(vase.slenderness)
    ds = multiple_stripes(records, {"Vase": vase}, levels, rtol=1e-6)
    if ds["overturned"].values.any() or not (ds["max_rotation"].values > 0).any():
        pytest.skip("the level did not give rocking without overturning")
    text = _text(record_report(ds, tmp_path / "r", n_boot=5))
    assert "Nothing overturned" in text and "Nothing rocked" not in text


def test_scale_factor_warning_and_units(tmp_path, records):
    levels = np.array([0.5, 3.0]) * G
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    page = record_report(ds, tmp_path / "r", n_boot=5, units="m/s^2", max_scale_factor=5)
    text = _text(page)
    factors = np.array([[x / r.peak for x in levels] for r in records])  # the records' PGA
    beyond = int((factors > 5).sum()) * len(OBJECTS)
    if beyond:
        assert f"{beyond} of {factors.size * len(OBJECTS)} stripe points" in text
        assert "max_scale_factor = 5" in text
    else:
        assert "max_scale_factor" not in text
    assert "[m/s^2]" in text and "PGA [g]" not in text.split("Records")[0]
    quiet = record_report(ds, tmp_path / "q", n_boot=5, max_scale_factor=1e6)
    assert "max_scale_factor" not in _text(quiet)
    with pytest.raises(ValueError, match="units"):
        record_report(ds, tmp_path / "bad", units="gee")
    with pytest.raises(ValueError, match="max_scale_factor"):
        record_report(ds, tmp_path / "bad", max_scale_factor=0.5)
