"""An IDA under ``model="auto"`` against Housner's rocking-only model: ``capacity_rocking``
and the ratio of the annual rates of overturning of the objects' report.

Oracles: an independent IDA run with ``model="rocking"`` on the same records and objects
(the rocking-only capacities, to the bisection tolerance), and Cornell et al.'s closed form
lambda = k0 theta^-k exp(k^2 beta^2 / 2) on a power-law hazard with the lognormal MLE of
each set of capacities (theta = exp(mean ln c), beta = std ln c): the ratio of the two rates.
A PGV hazard: the fragility is not cut at the uplift PGA, so the closed form is exact.
"""

from __future__ import annotations

import html

import numpy as np
import pytest
from _helpers import write_at2

import rockstudy as rs
from rockstudy.study.analysis import sliding
from rockstudy.study.designs.records import incremental_dynamic_analysis

PULSES = (0.5, 0.8, 1.2)
#: A block whose base slips (mu just above tan alpha: the friction demand exceeds mu as it
#: rocks) and one that rocks on a rough base.
BLOCKS = {"Amphora": (0.3, 0.25, 0.3), "Statue": (0.4, 0.2, 0.8)}
OPTIONS = dict(im="pga", step=0.1, tolerance=0.02, max_pga_ratio=6.0, scan=0)
K0, K = 1e-3, 2.4


def _records():
    return [
        rs.motions.synthetic_near_fault(pulse_period=tp, pga=2.0, seed=30 + i, duration=4.0)
        for i, tp in enumerate(PULSES)
    ]


def _structures():
    return {name: rs.Block(half_diagonal=r, slenderness=a) for name, (r, a, _) in BLOCKS.items()}


@pytest.fixture(scope="module")
def idas():
    records, structures = _records(), _structures()
    mu = [m for *_, m in BLOCKS.values()]
    auto = incremental_dynamic_analysis(records, structures, friction=mu, model="auto", **OPTIONS)
    rocking = incremental_dynamic_analysis(records, structures, **OPTIONS)
    return auto, rocking


def test_capacity_rocking_is_the_capacity_of_a_rocking_ida(idas):
    auto, rocking = idas
    assert auto["capacity_rocking"].dims == auto["capacity"].dims
    assert auto["capacity_rocking"].attrs["units"] == auto["capacity"].attrs["units"]
    np.testing.assert_array_equal(auto["censored_rocking"].values, rocking["censored"].values)
    ok = ~rocking["censored"].values
    assert ok.all()  # every record overturns both blocks: the fits below are uncensored
    for name in ("capacity", "capacity_scale"):
        got, want = auto[f"{name}_rocking"].values, rocking[name].values
        assert np.all(np.abs(np.log(got / want)) <= np.log1p(OPTIONS["tolerance"])), name
    # the contact model answered otherwise somewhere: the comparison is not of one answer
    assert not np.allclose(auto["capacity"].values, rocking["capacity"].values, rtol=1e-3)
    assert auto.attrs["n_simulations"] == int(
        auto["simulations"].sum() + rocking["simulations"].sum()
    )


def _cornell(capacities, status=None):
    """Cornell et al.'s annual rate of a lognormal fragility (MLE of ``capacities``, those of
    the points that did not fail: ``status`` 0, as the fit takes them) on the power-law
    hazard K0 x^-K."""
    capacities = np.ravel(capacities)
    if status is not None:
        capacities = capacities[np.ravel(status) == 0]
    ln = np.log(capacities)
    theta, beta = np.exp(ln.mean()), ln.std()
    return K0 * theta**-K * np.exp(0.5 * (K * beta) ** 2)


def test_the_ratio_of_rates_is_cornells_on_the_two_capacity_sets(idas):
    auto, rocking = idas
    hazard = rs.risk.HazardCurve.power_law(K0, K, im="pgv", units="m/s")
    out = sliding.contact_effect(auto, hazard, n_boot=0)
    pgv = auto["pgv"].values[:, None]  # the records' PGV [m/s], capacities in it
    for j, name in enumerate(BLOCKS):
        contact = _cornell(
            auto["capacity_scale"].values[:, j : j + 1] * pgv, auto["status"].values[:, j]
        )
        housner = _cornell(rocking["capacity_scale"].values[:, j : j + 1] * pgv)
        row = out.sel(structure=name)
        assert float(row["annual_rate_contact"]) == pytest.approx(contact, rel=1e-6)
        assert float(row["annual_rate_rocking"]) == pytest.approx(housner, rel=1e-6)
        assert float(row["ratio"]) == pytest.approx(contact / housner, rel=1e-6)
        assert int(row["n_overturned_rocking"]) == len(PULSES)


def test_a_rocking_or_contact_ida_has_no_rocking_only_answer(idas):
    _, rocking = idas
    hazard = rs.risk.HazardCurve.power_law(K0, K, im="pgv", units="m/s")
    with pytest.raises(ValueError, match="capacity_rocking.*model='auto'"):
        sliding.contact_effect(rocking, hazard, n_boot=0)


STUDY = """
name = "museum_ida_rocking"
seed = 1
friction = 0.3
structure = {{ kind = "objects", file = "objects.csv" }}
motion = {{ kind = "record", files = "{folder}" }}
[run]
model = "{model}"
[design]
kind = "ida"
im = "pga"
step = 0.1
tolerance = 0.02
max_pga_ratio = 6.0
scan = 0
[hazard]
kind = "power_law"
k0 = {k0}
k = {k}
im = "pgv"
units = "m/s"
"""
OBJECTS = "name,friction,half_diagonal,slenderness\n" + "".join(
    f"{name},{mu},{r},{a}\n" for name, (r, a, mu) in BLOCKS.items()
)


def _study(tmp_path, model):
    """Run the IDA study on the generated records and write its report: (dataset, page,
    report folder)."""
    from distributed import Client

    from rockstudy.study import load_study, run_study
    from rockstudy.study.report import make_report
    from rockstudy.study.running.store import open_result

    folder = tmp_path / "records"
    folder.mkdir()
    for i, rec in enumerate(_records()):
        write_at2(folder / f"r{i}.AT2", rec)
    (tmp_path / "objects.csv").write_text(OBJECTS)
    path = tmp_path / "ida.toml"
    path.write_text(STUDY.format(folder=folder, model=model, k0=K0, k=K))
    cube = tmp_path / "cube.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(load_study(path), cube, client=c, base_dir=tmp_path, progress=False)
    page = make_report(cube, tmp_path / "report")
    return open_result(cube).load(), page.read_text(), page.parent


def test_an_auto_ida_study_reports_the_ratio_per_object(tmp_path, idas):
    import pandas as pd

    _, rocking = idas
    ds, page, folder = _study(tmp_path, "auto")
    np.testing.assert_allclose(
        ds["capacity_rocking"].values, rocking["capacity"].values, rtol=OPTIONS["tolerance"]
    )
    assert ds["censored_rocking"].dtype == bool
    assert "<h2>Contact model against the rocking-only model</h2>" in page
    table = pd.read_csv(folder / "contact_vs_rocking.csv", index_col="object")
    pgv = ds["pgv"].values[:, None]
    for j, name in enumerate(BLOCKS):
        contact = _cornell(
            ds["capacity_scale"].values[:, j : j + 1] * pgv, ds["status"].values[:, j]
        )
        housner = _cornell(ds["capacity_scale_rocking"].values[:, j : j + 1] * pgv)
        row = table.loc[name]
        assert row["ratio contact / rocking-only"] == pytest.approx(contact / housner, rel=1e-6)
        assert row["records overturned, rocking-only"] == len(PULSES)


def test_a_contact_ida_study_says_the_comparison_needs_auto(tmp_path):
    _, page, _ = _study(tmp_path, "contact")
    assert "<h2>Contact model against the rocking-only model</h2>" in page
    assert html.escape('the rocking-only answer needs model = "auto"') in page
    assert not (tmp_path / "report" / "contact_vs_rocking.csv").exists()


def test_the_rocking_twins_names_are_reserved_for_the_store():
    from rockstudy.motions import measures
    from rockstudy.study.designs import record_rows  # noqa: F401  (reserves the names)

    with pytest.raises(ValueError, match="'capacity_rocking' is reserved"):
        measures.register_measure("capacity_rocking", lambda r: 1.0, unit="1", power=1.0)
