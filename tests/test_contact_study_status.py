"""A point whose contact model answer did not converge (batch ``status`` 4,
:data:`rockstudy.dynamics.constants.STATUS_UNCONVERGED`) stays a failure of that kind in the
designs, their analyses and the report: an IDA's ``status`` carries the code (the OR of its
points' codes), the regimes name it "not converged", and the report counts it apart from the
step limit.

Oracle: the status the batch gave each point, marked here by a wrapper of simulate_batch on
known points (an unconverged row is a stick-slip decision within 10 rtol of its threshold:
no ladder of scales lands on one by chance)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from rockstudy.dynamics.constants import STATUS_MAX_STEPS, STATUS_UNCONVERGED
from rockstudy.motions import stochastic_record
from rockstudy.study.analysis import sliding
from rockstudy.study.designs import records as rd

RADIUS = np.array([0.8, 0.5])
ALPHA = np.array([0.2, 0.35])
MU = np.array([0.6, 0.25])


def _marking(real, code, calls):
    """simulate_batch that gives ``code`` to the first row of the call numbers ``calls``."""
    seen = []

    def run(**kw):
        out = real(**kw)
        if len(seen) in calls:
            out["status"] = np.array(out["status"])
            out["status"][0] = code
        seen.append(np.atleast_1d(kw["scale"]).size)
        return out

    return run


def _ida(monkeypatch, code, calls):
    monkeypatch.setattr(rd, "simulate_batch", _marking(rd.simulate_batch, code, calls))
    return rd.incremental_dynamic_analysis(
        [stochastic_record(3.0, duration=2.0, seed=5)],
        {"half_diagonal": RADIUS, "slenderness": ALPHA},
        step=0.1,
        tolerance=0.02,
        max_pga_ratio=3.0,
        scan=0,
        friction=MU,
        model="contact",
    )


@pytest.mark.parametrize("code", [STATUS_UNCONVERGED, STATUS_MAX_STEPS])
def test_an_ida_keeps_the_code_of_a_failed_rung_that_is_not_its_structures_last(monkeypatch, code):
    """The first call climbs several rungs of structure 0 at once; its first rung (not the
    last of the call) failed: the structure's status is that code, the other's 0."""
    ds = _ida(monkeypatch, code, calls={0})
    assert ds["status"].values.tolist() == [[code, 0]]


def test_an_ida_status_ors_the_codes_of_its_points(monkeypatch):
    """Two failed points of structure 0 of different kinds: both codes (1 | 4)."""
    monkeypatch.setattr(rd, "simulate_batch", _marking(rd.simulate_batch, STATUS_MAX_STEPS, {0}))
    ds = _ida(monkeypatch, STATUS_UNCONVERGED, calls={1})
    both = STATUS_MAX_STEPS | STATUS_UNCONVERGED
    assert ds["status"].values[0, 0] == both
    assert rd.failed_points(ds["status"].values) == {"step limit": 1, "not converged": 1}


def _stripes():
    dims = ("record", "structure", "level")
    shape = (2, 2, 3)
    status = np.zeros(shape, np.int64)
    status[0, 1, 2] = STATUS_UNCONVERGED
    status[1, 0, 0] = STATUS_MAX_STEPS
    status[1, 1, 1] = rd.STATUS_FREE_FALL
    return xr.Dataset(
        {
            "regime": (dims, np.full(shape, 2, np.int8)),
            "status": (dims, status),
        },
        coords={"record": ["r0", "r1"], "structure": ["A", "B"], "level": [0.1, 0.2, 0.3]},
        attrs={"design": "stripes"},
    )


def test_regimes_name_an_unconverged_point_apart_from_one_not_run():
    table = sliding.regimes(_stripes())
    assert table.loc[("B", "r0"), 0.3] == "not converged"
    assert table.loc[("A", "r1"), 0.1] == "not run"
    assert table.loc[("A", "r0"), 0.1] == "rock"
    assert (table == "not converged").to_numpy().sum() == 1


def test_the_report_counts_unconverged_points_apart_from_the_step_limit(tmp_path):
    """The design summary of the record report: one point of each failure, each named."""
    from rockstudy.study.report._page import _Page
    from rockstudy.study.report.records import _summary

    ds = _stripes()
    ds["overturned"] = xr.zeros_like(ds["status"])
    ds.attrs.update(im="pga", im_period=np.nan)
    _summary(_Page(tmp_path), ds)
    rows = pd.read_csv(tmp_path / "summary.csv", index_col=0)["value"]
    assert int(rows["points that failed (step limit)"]) == 1
    assert int(rows["points that failed (not converged)"]) == 1
    assert int(rows["points not run (free fall)"]) == 1
