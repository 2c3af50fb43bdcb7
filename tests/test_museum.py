"""The museum job through the command line (issue 24): ``studies/museum.toml`` validates as
shipped, and a reduced copy (three records, a coarse ladder) runs through ``rockstudy run``
and ``rockstudy report``, whose page ranks every object by its annual rate of overturning
with its name escaped. Oracles: the fit of the cube's capacities by
:func:`~rockstudy.study.analysis.record_fragility.ida_fragility` integrated by
:func:`rockstudy.risk.annual_rate` (Cornell's integral), the hazard file read on its own,
and html.escape of each name."""

import html
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _helpers import ROCKSTUDY

from rockstudy import risk
from rockstudy.study import load_study
from rockstudy.study.analysis import record_fragility as rf
from rockstudy.study.running.store import open_result

ROOT = Path(__file__).resolve().parents[1]
MUSEUM = ROOT / "studies" / "museum.toml"


def test_the_museum_study_validates_as_shipped():
    study = load_study(MUSEUM)
    assert [o.name for o in study.structure.objects][:2] == [
        "Kouros (marble)",
        "Hermes & Dionysus (marble)",
    ]
    curve = study.hazard.curve()
    table = np.loadtxt(ROOT / "data" / "hazard" / "site_pga.csv", delimiter=",", skiprows=2)
    np.testing.assert_array_equal(curve.rates, table[:, 1])
    assert (curve.im, curve.units, study.hazard.years) == ("pga", "g", 50)


def _reduced(tmp_path) -> Path:
    text = MUSEUM.read_text()
    records = ROOT / "data" / "records"
    text = text.replace('"../data/records/*_H.AT2"', f'"{records}/NF0[357]*_H.AT2"')
    text = text.replace('"../data/hazard/', f'"{ROOT}/data/hazard/')
    text = text.replace("step = 0.02", "step = 0.05").replace(
        "tolerance = 0.005", "tolerance = 0.05"
    )
    text = text.replace("scan = 4", "scan = 0")
    text = text.replace('"Satyr (marble)"', '"Satyr <i>Barberini</i> (marble)"')
    path = tmp_path / "museum.toml"
    path.write_text(text)
    return path


def _rockstudy(*args):
    proc = subprocess.run([ROCKSTUDY, *map(str, args)], capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


@pytest.mark.slow  # a real `rockstudy run` (a dask worker) and `rockstudy report`
def test_reduced_museum_runs_and_reports_a_ranked_escaped_table(tmp_path):
    path = _reduced(tmp_path)
    cube = tmp_path / "museum.zarr"
    _rockstudy("run", path, "--out", cube, "--workers", "1", "--quiet")
    _rockstudy("report", cube, "--out", tmp_path / "report")
    page = (tmp_path / "report" / "index.html").read_text()
    start = page.index("<h2>Annual probability of overturning</h2>")
    section = page[start : page.index("<h2>", start + 1)]
    names = [o.name for o in load_study(path).structure.objects]
    for name in names:
        assert f"<th>{html.escape(name)}</th>" in section, name
    assert "<i>Barberini</i>" not in page
    table = pd.read_csv(tmp_path / "report" / "annual_overturning.csv", index_col=0)
    assert sorted(table.index) == sorted(names)
    rates = table["lambda_OT [1/yr]"].to_numpy()
    fitted = rates[np.isfinite(rates)]
    assert np.all(np.diff(fitted) <= 0) and np.all(np.isfinite(rates[: fitted.size]))
    # in the page, in the same order as the CSV
    where = [section.index(f"<th>{html.escape(n)}</th>") for n in table.index]
    assert where == sorted(where)
    # each rate is Cornell's integral of the cube's own fragility fit against the hazard file
    fit = rf.ida_fragility(open_result(cube).load(), by="structure", n_boot=0)
    hazard = risk.HazardCurve.from_csv(
        ROOT / "data" / "hazard" / "site_pga.csv", im="pga", units="g"
    )
    # horizontal records: each fragility is 0 below the object's uplift PGA g tan(alpha) =
    # g b / h (the study's blocks are given by width 2b and height 2h), quoted in the unit g
    objects = {o.name: o for o in load_study(path).structure.objects}
    for name, row in table.iterrows():
        if row["status"] in ("ok", "few") and np.isfinite(row["lambda_OT [1/yr]"]):
            o = objects[name]
            a_up = 9.81 * o.width / o.height / 9.80665
            theta, beta = fit.loc[name, "theta"], fit.loc[name, "beta"]
            expected = risk.annual_rate(theta, beta, hazard, threshold=a_up)
            assert np.isclose(row["lambda_OT [1/yr]"], expected, rtol=1e-9), name
            whole = risk.annual_rate(theta, beta, hazard)
            assert np.isclose(row["lambda_OT, whole lognormal [1/yr]"], whole, rtol=1e-9), name
    assert (tmp_path / "report" / "deaggregation.png").stat().st_size > 10_000
