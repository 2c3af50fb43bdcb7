"""The spread of fragility medians across block sizes (records_similarity), on cases whose
answer is known: exact similarity (paper 000) and capacities constructed from known medians."""

import math

import numpy as np
import pytest
from _helpers import constructed_ida

from rockstudy.motions import Record, synthetic_near_fault
from rockstudy.structures.block import frequency_parameter
from rockstudy.study.analysis.record_similarity import size_class_medians, size_classes
from rockstudy.study.designs.records import incremental_dynamic_analysis

R = np.array([0.4, 1.2, 3.6])
ALPHA = 0.2
TOL = 0.01


@pytest.fixture(scope="module")
def similar_ida():
    """Three blocks (R 0.4, 1.2, 3.6 m, one alpha and eta) and three records, the same
    near-fault record stretched in time by p_0 / p_j. Block k under record j sees the pulse at
    omega_p / p proportional to p_j / p_k: on the diagonal (j = k) the three blocks are exactly
    similar (Housner's equation in tau = p t is the same; [000] section 4), so their
    capacities coincide in PGA, in g, and in PGA / (g tan alpha)."""
    base = synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=11, noise_ratio=0.5, dt=0.004)
    p = np.array([frequency_parameter(r) for r in R])
    records = [
        Record(base.acceleration, dt=base.dt * p[0] / pj, name=f"stretched {k}")
        for k, pj in enumerate(p)
    ]
    structures = {"half_diagonal": R, "slenderness": ALPHA, "restitution": 0.9}
    return incremental_dynamic_analysis(records, structures, im="pga", tolerance=TOL, scan=0)


def test_exact_similarity_gives_no_spread_within_a_frequency_bin(similar_ida):
    ds = similar_ida
    w = ds["pulse_frequency_ratio"].values
    assert np.ptp(np.diag(w)) / np.mean(np.diag(w)) < 1e-3  # the diagonal shares omega_p / p
    # bins with edges between the distinct values of omega_p / p (ratios of sqrt(3))
    step = math.sqrt(3.0)
    centre = float(np.mean(np.diag(w)))
    edges = centre * step ** (np.arange(-2.5, 3.0, 1.0))
    for im in ("pga", "pga_ratio"):
        medians, spread = size_class_medians(
            ds, im, size_bins=np.array([0.3, 1.0, 2.0, 4.0]), frequency_bins=edges, n_boot=20
        )
        diagonal = spread.loc[spread.index[2]]
        assert diagonal["classes"] == 3
        assert 1.0 <= diagonal["ratio"] <= 1.0 + 2 * TOL
        assert diagonal["log_std"] <= TOL
        assert diagonal["ratio_hi"] <= 1.0 + 2 * TOL
        two = spread.loc[spread.index[[1, 3]]]  # off the diagonal: two classes each
        assert (two["classes"] == 2).all() and (two["ratio"] <= 1.0 + 2 * TOL).all()


def test_pooled_over_frequencies_the_sizes_spread_apart(similar_ida):
    """Without conditioning on omega_p / p, each size sees the record at other frequency
    ratios and the medians differ (larger blocks are safer: Housner's size effect)."""
    medians, spread = size_class_medians(
        similar_ida, "pga", size_bins=np.array([0.3, 1.0, 2.0, 4.0]), n_boot=0
    )
    theta = medians["theta"].to_numpy()
    assert theta[-1] > theta[0] * (1 + 10 * TOL)
    assert spread.loc["all", "ratio"] == pytest.approx(theta.max() / theta.min(), rel=1e-12)
    assert medians["unit"].iloc[0] == "g"


def test_ratio_and_log_std_of_known_medians():
    theta = np.array([0.2, 0.5, 1.1])
    medians, spread = size_class_medians(constructed_ida(theta), "pga", size_bins=3, n_boot=50)
    np.testing.assert_allclose(medians["theta"], theta, rtol=1e-12)
    row = spread.loc["all"]
    assert row["ratio"] == pytest.approx(1.1 / 0.2, rel=1e-12)
    assert row["log_std"] == pytest.approx(np.std(np.log(theta)), rel=1e-12)
    assert row["ratio_lo"] <= row["ratio"] <= row["ratio_hi"]
    same = size_class_medians(constructed_ida([0.7, 0.7, 0.7]), "pga", n_boot=50)[1]
    assert same.loc["all", "ratio"] == pytest.approx(1.0, abs=1e-12)
    assert same.loc["all", "ratio_hi"] == pytest.approx(1.0, abs=1e-12)


def test_bad_size_bins_name_the_argument():
    ds = constructed_ida([0.2, 0.5, 1.1])
    with pytest.raises(ValueError, match="size_bins"):
        size_classes(ds, 5)
    with pytest.raises(ValueError, match="size_bins"):
        size_classes(ds, [1.0, 0.5, 2.0])
    with pytest.raises(ValueError, match="size_bins"):
        size_classes(ds.assign(half_diagonal=("structure", [np.nan, 1.0, 2.0])), 3)
