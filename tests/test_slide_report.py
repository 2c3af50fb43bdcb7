"""The record report's sliding sections, from a small museum study of stripes under
``[run] model = "auto"`` with slide limits and a hazard curve: the slide fragility and annual
rates per limit, the contact model against the rocking-only model, the regimes; object names
escaped. Oracles: Housner's model run here by rs.simulate for the rocking-only decision,
counts of the stored points, and the page's text."""

from __future__ import annotations

import html
import json

import numpy as np
import pandas as pd
import pytest
from _helpers import write_at2

import rockstudy as rs
from rockstudy.motions.suites import read_pair
from rockstudy.study.analysis import sliding

#: A stocky amphora on a smooth base (mu 0.25 < tan 0.45: it slides), a bronze statue
#: (tan 0.3 < mu 0.6: it rocks) and a name to escape.
OBJECTS = """name,half_diagonal,slenderness,friction
Amphora,0.3,0.45,0.25
<b>Bronze & Co</b>,0.5,0.3,
"""
STUDY = """
name = "museum <sliding>"
seed = 1
friction = 0.6
[structure]
kind = "objects"
file = "objects.csv"
[motion]
kind = "record"
files = "{folder}"
scale_to = {{ im = "pga", value = {{ dist = "grid", values = [1.0, 2.5, 4.0, 6.5] }} }}
[design]
kind = "stripes"
slide_limits = [0.005, 0.05]
[run]
model = "{model}"
[hazard]
kind = "power_law"
k0 = 2e-4
k = 2.3
im = "pga"
units = "g"
"""
NAME = "<b>Bronze & Co</b>"


def _run(tmp_path, model):
    """Run the study (3 generated records) and write its report; (dataset, page, folder)."""
    from distributed import Client

    from rockstudy.study import load_study, run_study
    from rockstudy.study.report import make_report
    from rockstudy.study.running.store import open_result

    folder = tmp_path / "records"
    folder.mkdir()
    for i, tp in enumerate((0.3, 0.5, 0.8)):
        rec = rs.motions.synthetic_near_fault(pulse_period=tp, pga=2.0, seed=7 + i, duration=2.5)
        write_at2(folder / f"r{i}.AT2", rec)
    (tmp_path / "objects.csv").write_text(OBJECTS)
    path = tmp_path / "museum.toml"
    path.write_text(STUDY.format(folder=folder, model=model))
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(load_study(path), cube, client=c, base_dir=tmp_path, progress=False)
    page = make_report(cube, tmp_path / "report")
    return open_result(cube).load(), page.read_text(), page.parent


@pytest.fixture(scope="module")
def auto_study(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("auto"), "auto")


def test_auto_keeps_housners_decision_of_every_point(auto_study):
    """overturned_rocking is rs.simulate's decision without friction, point by point, and the
    report's comparison table counts those overturnings per object."""
    ds, _, folder = auto_study
    blocks = {"Amphora": (0.3, 0.45), NAME: (0.5, 0.3)}
    files = json.loads(ds.attrs["record_files"])
    counts = dict.fromkeys(blocks, 0)
    for r, f in enumerate(files):
        rec = read_pair(f)
        for s, (name, (R, alpha)) in enumerate(blocks.items()):
            block = rs.Block(half_diagonal=R, slenderness=alpha)
            for k in range(ds.sizes["level"]):
                scale = float(ds["scale"].isel(record=r, structure=s, level=k))
                housner = rs.simulate(block, rec.scaled(scale))
                got = int(ds["overturned_rocking"].isel(record=r, structure=s, level=k))
                assert got == int(housner.overturned), (r, name, k)
                counts[name] += int(housner.overturned)
    table = pd.read_csv(folder / "contact_vs_rocking.csv", index_col="object")
    assert table["points overturned, rocking-only"].to_dict() == counts
    assert counts[NAME] > 0  # the bronze overturns at the top levels
    assert ds.attrs["slide_limits"] == [0.005, 0.05]


def test_the_report_has_the_sliding_sections_and_escapes_names(auto_study):
    ds, page, _ = auto_study
    for heading in (
        "Sliding: fragility and annual rates per slide limit",
        "Contact model against the rocking-only model",
        "Regimes: what each record drove each object into",
    ):
        assert f"<h2>{heading}</h2>" in page
    for csv in ("slide_fragility.csv", "annual_sliding.csv", "contact_vs_rocking.csv"):
        assert f"<a href='{csv}'>" in page
    assert "regimes.csv" in page
    assert NAME not in page  # never raw
    assert html.escape(NAME) in page
    assert "counts as exceeding every slide limit" in page
    # the regimes table names, per object, the regime of every record at every level
    table = sliding.regimes(ds)
    assert table.shape == (2 * 3, 4)
    assert (table.loc["Amphora"] != "rest").any(axis=None)
    # the amphora (mu < tan alpha) slides: its annual rate of exceeding the smaller limit is
    # at least that of the larger one
    out = sliding.slide_risk(ds, rs.risk.HazardCurve.power_law(2e-4, 2.3, "pga", "g"), n_boot=0)
    amph = out.sel(structure="Amphora")["annual_rate"].values
    if np.isfinite(amph).all():
        assert amph[0] >= amph[1]


def test_under_the_contact_model_the_report_says_the_rocking_only_rate_needs_auto(tmp_path):
    _, page, _ = _run(tmp_path, "contact")
    assert "<h2>Contact model against the rocking-only model</h2>" in page
    assert html.escape('the rocking-only answer needs model = "auto"') in page


def test_an_ida_with_slide_capacities_reports_its_sliding(tmp_path):
    """An IDA of named objects with ``slide_capacity`` (dims slide_limit, record, structure;
    in the units of ``capacity``; here half the overturning capacity at the smaller limit,
    and NaN, never reached, at the larger one): the report fits the slide capacities (the
    lognormal MLE of those at d1, the overturning capacities at d2: an overturning exceeds
    every limit), gives their annual rates, and says that an IDA has no rocking-only
    comparison."""
    from rockstudy.study.designs.records import incremental_dynamic_analysis
    from rockstudy.study.report import record_report

    records = [
        rs.motions.synthetic_near_fault(pulse_period=tp, pga=2.0, seed=20 + i, duration=4.0)
        for i, tp in enumerate((0.4, 0.6, 0.9, 1.2))
    ]
    blocks = {"Vase <i>": rs.Block(half_diagonal=0.4, slenderness=0.25)}
    ds = incremental_dynamic_analysis(records, blocks, step=0.1, tolerance=0.05, scan=0)
    cap = ds["capacity"].values
    ds["slide_capacity"] = (
        ("slide_limit", "record", "structure"),
        np.stack([cap / 2, cap * np.nan]),
    )
    ds = ds.assign_coords(slide_limit=[0.01, 0.05])
    ds.attrs["slide_limits"] = [0.01, 0.05]
    hazard = rs.risk.HazardCurve.power_law(2e-4, 2.3, "pga", "g")
    page = record_report(ds, tmp_path, n_boot=0, hazard=hazard).read_text()
    assert "<h2>Sliding: fragility and annual rates per slide limit</h2>" in page
    assert "An IDA&#x27;s ladder runs one model" in page
    table = pd.read_csv(tmp_path / "slide_fragility.csv", index_col=[0, 1])
    pga_g = ds["capacity_scale"].values[:, 0] * ds["pga"].values / rs.constants.STANDARD_GRAVITY
    for d, c in ((0.01, pga_g / 2), (0.05, pga_g)):
        row = table.loc[(d, "Vase <i>")]
        theta = np.exp(np.mean(np.log(c)))
        assert row["median PGA [g]"] == pytest.approx(theta, rel=1e-9)  # the report in g
        assert row["beta (MLE)"] == pytest.approx(np.std(np.log(c)), rel=1e-9)
    rates = pd.read_csv(tmp_path / "annual_sliding.csv", index_col=[0, 1])
    assert (
        rates.loc[(0.01, "Vase <i>"), "lambda(max_slide > d) [1/yr]"]
        > rates.loc[(0.05, "Vase <i>"), "lambda(max_slide > d) [1/yr]"]
    )
