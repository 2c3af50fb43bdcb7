"""The rocking-only view of an ``"auto"`` cloud (:func:`rocking_design`) takes Housner's
own status: a point where Housner's model failed (its step limit) is a failed point of
that view, never a survival, whichever model answered it under "auto"."""

import numpy as np

import rockstudy as rs
from rockstudy.study.analysis.sliding import rocking_design


def _suite():
    return [
        rs.motions.synthetic_near_fault(pulse_period=0.8, pga=g, seed=k)
        for k, g in enumerate((2.0, 6.0, 9.0))
    ]


def test_housners_step_limit_is_a_failure_of_the_rocking_view():
    objects = {"stele": rs.Block(1.0, 0.2), "bronze": rs.Block(0.5, 0.35)}
    ds = rs.study.cloud(_suite(), objects, friction=0.3, model="auto", max_steps=3)
    # the oracle: Housner's model alone at the same step limit
    for j, block in enumerate(objects.values()):
        for i, record in enumerate(_suite()):
            one = rs.simulate_batch(
                half_diagonal=block.half_diagonal,
                slenderness=block.slenderness,
                record=record,
                max_steps=3,
            )
            failed = one["status"][0] != 0
            rocking = int(ds["overturned_rocking"].values[i, j])
            assert (rocking == -1) == failed, (i, j)
            view = rocking_design(ds)
            assert int(view["status"].values[i, j]) == (1 if failed else 0)
            if not failed:
                assert rocking == int(one["overturned"][0])
    assert (ds["overturned_rocking"].values == -1).any()


def test_points_the_contact_model_answered_keep_housners_decision_and_status():
    """Under "auto" the contact model answers the points that slide or overturn; the
    rocking-only view gives each Housner's own decision (the oracle: simulate_batch without
    friction) and status 0."""
    objects = {"stele": rs.Block(1.0, 0.2), "bronze": rs.Block(0.5, 0.35)}
    ds = rs.study.cloud(_suite(), objects, friction=0.3, model="auto")
    view = rocking_design(ds)
    answered = np.asarray(ds["model"].values) >= 3
    assert answered.any()
    for j, block in enumerate(objects.values()):
        for i, record in enumerate(_suite()):
            one = rs.simulate_batch(
                half_diagonal=block.half_diagonal, slenderness=block.slenderness, record=record
            )
            assert int(view["overturned"].values[i, j]) == int(one["overturned"][0]), (i, j)
            assert int(view["status"].values[i, j]) == 0
