"""The regimes table and the two-body pair ratios of a record design over floors and
orientations, and where the fits' warnings point (rockstudy.study.analysis.motion_axes).

Oracles: each function applied to the design at one (floor, orientation), ``ds.sel(floor=f,
orientation=psi)``, which is the path without these dimensions that their own tests check;
and the file of this test module, from which the fits are called.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from _helpers import lognormal_sample, pga_ida

from rockstudy import UnitsWarning, risk
from rockstudy.study.analysis import sliding
from rockstudy.study.analysis.record_fragility import ida_fragility
from rockstudy.study.analysis.two_body import pair_ratios

FLOORS = [0, 2]
ANGLES = [0.0, math.pi / 2]
NAMES = ["Statue on plinth", "Statue"]
HAZARD = risk.HazardCurve.power_law(1e-4, 2.0, im="pga", units="g")


def over_motions(part):
    """The dataset ``part(k)`` of each (floor, orientation) k = 0, 1, .. as one design over
    the dimensions ``floor`` and ``orientation`` (:data:`FLOORS`, :data:`ANGLES`)."""
    rows = [
        xr.concat(
            [
                part(len(ANGLES) * i + j).expand_dims(orientation=[psi])
                for j, psi in enumerate(ANGLES)
            ],
            dim="orientation",
        )
        for i in range(len(FLOORS))
    ]
    return xr.concat(rows, dim=pd.Index(FLOORS, name="floor"))


def regimes_part(k):
    """Stripes (3 records, 2 objects, 3 levels) of regime codes drawn from the seed k, with a
    point that hit the step limit and one that did not converge."""
    rng = np.random.default_rng(k)
    dims, shape = ("record", "structure", "level"), (3, 2, 3)
    status = np.zeros(shape, np.int64)
    status[k % 3, 0, 1] = 1
    status[(k + 1) % 3, 1, 2] = sliding.STATUS_UNCONVERGED
    return xr.Dataset(
        {
            "regime": (dims, rng.integers(0, 5, shape).astype(np.int8)),
            "status": (dims, status),
        },
        coords={"record": ["r0", "r1", "r2"], "structure": NAMES, "level": [0.1, 0.2, 0.3]},
        attrs={"design": "stripes"},
    )


def pairs_part(k):
    """An IDA of 12 records on the two objects of :data:`NAMES`, capacities [g] drawn from
    the seed k (the plinth's the lower on some floors, the higher on others)."""
    plinth = lognormal_sample(0.3 + 0.1 * k, 0.4, 12, seed=k)
    statue = lognormal_sample(0.5, 0.3, 12, seed=10 + k)
    return pga_ida(np.column_stack([plinth, statue]), names=NAMES)


def test_regimes_over_floors_and_orientations_are_those_of_each_motion():
    ds = over_motions(regimes_part)
    table = sliding.regimes(ds)
    assert table.index.names == ["floor", "orientation", "structure", "record"]
    assert table.shape == (len(FLOORS) * len(ANGLES) * 2 * 3, 3)
    for f in FLOORS:
        for psi in ANGLES:
            pd.testing.assert_frame_equal(
                table.loc[(f, psi)], sliding.regimes(ds.sel(floor=f, orientation=psi))
            )


def test_regimes_over_floors_alone_are_those_of_each_floor():
    ds = over_motions(regimes_part).isel(orientation=0, drop=True)
    table = sliding.regimes(ds)
    assert table.index.names == ["floor", "structure", "record"]
    for f in FLOORS:
        pd.testing.assert_frame_equal(table.loc[f], sliding.regimes(ds.sel(floor=f)))


def test_pair_ratios_over_floors_and_orientations_are_those_of_each_motion():
    ds = over_motions(pairs_part)
    out = pair_ratios(ds, HAZARD, [tuple(NAMES)], n_boot=40, seed=3)
    assert out["ratio"].dims == ("floor", "orientation", "pair")
    assert list(out["plain"].values.ravel()) == ["Statue"] * len(FLOORS) * len(ANGLES)
    for f in FLOORS:
        for psi in ANGLES:
            want = pair_ratios(
                ds.sel(floor=f, orientation=psi), HAZARD, [tuple(NAMES)], n_boot=40, seed=3
            )
            xr.testing.assert_identical(out.sel(floor=f, orientation=psi, drop=True), want)


def _equal_capacities():
    """An IDA whose first object has the same capacity under every record (beta = 0: the
    fit warns)."""
    cap = np.column_stack([np.full(6, 0.4), lognormal_sample(0.5, 0.3, 6, seed=1)])
    return pga_ida(cap, names=NAMES)


@pytest.mark.parametrize("over_motions_too", [False, True])
def test_a_fits_warning_points_at_the_callers_line(over_motions_too):
    ds = over_motions(lambda k: _equal_capacities()) if over_motions_too else _equal_capacities()
    with pytest.warns(UserWarning, match="capacities of group 'Statue on plinth' are all") as said:
        ida_fragility(ds, by="structure", n_boot=0)
    assert {w.filename for w in said} == {__file__}


def test_a_warning_of_a_fit_inside_another_points_at_the_callers_line():
    """pair_ratios calls object_risk: a hazard curve under which the records' own PGA (1 g)
    is a once-in-1e8-years level warns from the user's call."""
    wrong = risk.HazardCurve.power_law(1e-8, 4.0, im="pga", units="g")
    with pytest.warns(UnitsWarning, match="hazard: the records' own pga") as said:
        pair_ratios(over_motions(pairs_part), wrong, [tuple(NAMES)], n_boot=0)
    assert {w.filename for w in said} == {__file__}
