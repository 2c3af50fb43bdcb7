"""The record report's damage-state section, from a small museum study of stripes with
``[design] damage_states`` and a hazard curve: a table and a figure of every state's
fragility per object, the annual rate of each state; object and state names escaped.
Oracles: the points that reached each state, counted here from the stored rotations, and
their binomial fit by scipy (probit form)."""

from __future__ import annotations

import html

import numpy as np
import pandas as pd
import pytest
from _helpers import write_at2
from scipy import optimize, stats

import rockstudy as rs

OBJECTS = """name,half_diagonal,slenderness
Amphora,0.3,0.3
<b>Bronze & Co</b>,0.5,0.2
"""
STUDY = """
name = "museum <states>"
seed = 1
[structure]
kind = "objects"
file = "objects.csv"
[motion]
kind = "record"
files = "{folder}"
scale_to = {{ im = "pga", value = {{ dist = "grid", values = [2.0, 3.5, 6.0, 10.0, 16.0] }} }}
[design]
kind = "stripes"
damage_states = {{ "<chipped>" = 0.2, displaced = 0.6, overturned = 1.0 }}
[hazard]
kind = "power_law"
k0 = 2e-4
k = 2.3
im = "pga"
units = "g"
"""
NAME = "<b>Bronze & Co</b>"
STATES = {"<chipped>": 0.2, "displaced": 0.6, "overturned": 1.0}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """Run the study (4 generated records), write its report; (dataset, page, folder)."""
    from distributed import Client

    from rockstudy.study import load_study, run_study
    from rockstudy.study.report import make_report
    from rockstudy.study.running.store import open_result

    tmp_path = tmp_path_factory.mktemp("states")
    folder = tmp_path / "records"
    folder.mkdir()
    for i, tp in enumerate((0.3, 0.45, 0.6, 0.8)):
        rec = rs.motions.synthetic_near_fault(pulse_period=tp, pga=2.0, seed=7 + i, duration=2.5)
        write_at2(folder / f"r{i}.AT2", rec)
    (tmp_path / "objects.csv").write_text(OBJECTS)
    path = tmp_path / "museum.toml"
    path.write_text(STUDY.format(folder=folder))
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(load_study(path), cube, client=c, base_dir=tmp_path, progress=False)
    page = make_report(cube, tmp_path / "report")
    return open_result(cube).load(), page.read_text(), page.parent


def _probit_mle(x, y):
    """(theta, beta) maximising the binomial likelihood of Phi(a + b ln x), by BFGS."""

    def nll(p):
        z = p[0] + p[1] * np.log(x)
        return -np.sum(y * stats.norm.logcdf(z) + (1 - y) * stats.norm.logsf(z))

    a, b = optimize.minimize(nll, [0.0, 2.0], method="BFGS", options={"gtol": 1e-10}).x
    return np.exp(-a / b), 1.0 / b


def test_the_state_table_fits_the_points_that_reached_each_state(report):
    """Per state and object: the table's points and median are those of the stored points
    that rocked to at least the state's share of alpha (or overturned), fitted here."""
    ds, _, folder = report
    table = pd.read_csv(folder / "state_fragility.csv", index_col=[0, 1])
    assert sorted(set(table.index.get_level_values(0))) == sorted(STATES)
    fitted = 0
    for j, obj in enumerate(["Amphora", NAME]):
        point = ds.isel(structure=j)
        x = (point["scale"] * point["pga"]).values.ravel()  # PGA [m/s^2]
        ratio = (point["max_rotation"] / point["critical_rotation"]).values.ravel()
        over = point["overturned"].values.ravel() == 1
        for name, limit in STATES.items():
            y = over if limit == 1.0 else over | (ratio >= limit)
            row = table.loc[(name, obj)]
            assert int(row["points"]) == x.size
            if 0 < y.sum() < y.size and np.isfinite(row["beta (MLE)"]):
                theta, _ = _probit_mle(x, y.astype(float))
                assert row["median PGA [m/s^2]"] == pytest.approx(theta, rel=1e-3), (name, obj)
                fitted += 1
    assert fitted >= 3


def test_the_page_shows_the_states_figure_and_rates_with_names_escaped(report):
    ds, page, folder = report
    assert "Damage states: fragility and annual rates per state" in page
    assert (folder / "state_fragility.png").exists()
    rates = pd.read_csv(folder / "annual_states.csv", index_col=[0, 1])
    assert set(rates.index.get_level_values(1)) == {"Amphora", NAME}
    finite = rates["lambda(state), nested fit [1/yr]"].dropna()
    assert finite.size >= 3 and (finite > 0).all()
    assert "<chipped>" not in page and html.escape("<chipped>") in page
    assert NAME not in page
