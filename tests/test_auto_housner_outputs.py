"""Under ``model="auto"`` simulate_batch returns, when asked, Housner's decision and status
of every row (``overturned_rocking``, ``status_rocking``: what "auto" computes before the
contact model answers some rows), and the record designs take the rocking-only answer from
them instead of running Housner's model again.

Oracles: Housner's model run alone by simulate_batch (``model="rocking"``) on the same rows,
and an IDA run with ``model="rocking"`` (the rocking-only ladder of an "auto" IDA must be
it, bit for bit)."""

from __future__ import annotations

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.motions import stochastic_record
from rockstudy.study.designs import records as rd

RADIUS = np.array([0.3, 0.4, 0.8, 0.5])
ALPHA = np.array([0.25, 0.2, 0.2, 0.35])
#: slips as it rocks, rocks on a rough base, rocks, slides (mu < tan alpha)
MU = np.array([0.3, 0.8, 0.6, 0.25])
OPTIONS = dict(im="pga", step=0.1, tolerance=0.02, max_pga_ratio=4.0, scan=2)


@pytest.fixture(scope="module")
def record():
    return stochastic_record(3.0, duration=3.0, seed=5)


def test_auto_returns_housners_own_decision_and_status_of_every_row(record):
    scales = np.geomspace(0.3, 3.0, 12)
    rows = dict(
        half_diagonal=np.repeat(RADIUS, scales.size),
        slenderness=np.repeat(ALPHA, scales.size),
        record=record,
        scale=np.tile(scales, RADIUS.size),
    )
    auto = rs.simulate_batch(
        **rows,
        friction=np.repeat(MU, scales.size),
        model="auto",
        outputs=("overturned", "model", "overturned_rocking", "status_rocking"),
    )
    housner = rs.simulate_batch(**rows, outputs=("overturned",))
    assert (auto["model"] >= 3).any() and (auto["model"] < 3).any()  # both models answered
    np.testing.assert_array_equal(auto["overturned_rocking"], housner["overturned"])
    np.testing.assert_array_equal(auto["status_rocking"], housner["status"])
    assert auto["overturned_rocking"].dtype == bool


@pytest.mark.parametrize("model", ["rocking", "contact"])
def test_housners_answer_is_refused_by_name_outside_auto(record, model):
    with pytest.raises(ValueError, match="overturned_rocking.*auto"):
        rs.simulate_batch(
            half_diagonal=0.5,
            slenderness=0.2,
            record=record,
            friction=0.5,
            model=model,
            outputs=("overturned_rocking",),
        )


def _counting(monkeypatch):
    """Count the rows simulate_batch runs under Housner's model alone (no friction)."""
    rows = []
    real = rd.simulate_batch

    def run(**kw):
        if kw.get("model") is None:
            rows.append(np.atleast_1d(kw["scale"]).size)
        return real(**kw)

    monkeypatch.setattr(rd, "simulate_batch", run)
    return rows


def test_an_auto_ida_climbs_housners_ladder_without_rerunning_its_points(record, monkeypatch):
    """capacity_rocking and its twins are those of a rocking IDA, bit for bit, while Housner's
    model alone runs fewer rows than that ladder holds: the points the "auto" ladder shares
    with it are answered by the Housner rows "auto" ran first."""
    structures = {"half_diagonal": RADIUS, "slenderness": ALPHA}
    rocking = rd.incremental_dynamic_analysis([record], structures, **OPTIONS)
    rows = _counting(monkeypatch)
    auto = rd.incremental_dynamic_analysis(
        [record], structures, friction=MU, model="auto", **OPTIONS
    )
    for name in ("capacity", "capacity_scale", "capacity_scale_lower", "censored", "status"):
        np.testing.assert_array_equal(auto[f"{name}_rocking"].values, rocking[name].values)
    np.testing.assert_array_equal(auto["simulations_rocking"], rocking["simulations"])
    assert sum(rows) < int(rocking["simulations"].sum())


def test_stripes_under_auto_run_housners_model_once(record, monkeypatch):
    """The rocking-only decision of stripes is Housner's own (the oracle: stripes under
    model='rocking'), with no second run of Housner's model."""
    structures = {"half_diagonal": RADIUS, "slenderness": ALPHA}
    levels = [2.0, 4.0, 8.0]
    rocking = rd.multiple_stripes([record], structures, levels)
    rows = _counting(monkeypatch)
    auto = rd.multiple_stripes([record], structures, levels, friction=MU, model="auto")
    assert (auto["model"] >= 3).any()
    want = np.where(rocking["status"] != 0, -1, rocking["overturned"])
    np.testing.assert_array_equal(auto["overturned_rocking"].values, want)
    assert sum(rows) == 0
