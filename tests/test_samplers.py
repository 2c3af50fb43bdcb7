"""The samplers of a study file: one registry, and the defining property of each design.

Oracles: the definition of a Latin hypercube (one point in each of the n strata of every
column), SALib's Saltelli layout (per base point the rows A, AB_1 ... AB_D, B, where AB_j is A
with its column j taken from B), and the grid (every combination of the parameters' points).
"""

import itertools

import numpy as np
import pytest

from rockstudy.study import StudyError, json_schema, make_design, validate_text
from rockstudy.study.designs.sampling import unit_samples
from rockstudy.study.spec.samplers import SAMPLERS, kinds_laid_out

STUDY = """
name = "samplers"
seed = 3

[sampler]
kind = "{kind}"
{size}

[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 3.0 }}
slenderness = {{ dist = "uniform", low = 0.1, high = 0.3 }}

[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = {{ dist = "uniform", low = 0.8, high = 5.0 }}
period = {{ dist = "loguniform", low = 0.1, high = 2.0 }}
"""


def _study(kind, size="n = 64"):
    return validate_text(STUDY.format(kind=kind, size=size))


def test_every_sampler_of_the_registry_is_a_kind_of_the_schema_with_its_points():
    """The schema's sampler kinds are the registry's; every kind that takes n gives points in
    [0, 1)^D (one row a sample), and the one that does not (the grid) is refused by name."""
    text = str(json_schema())
    for kind, sampler in SAMPLERS.items():
        assert f"'{kind}'" in text, kind
        if sampler.takes_n:
            x = unit_samples(_study(kind))
            assert x.shape[1] == 4 and ((x >= 0.0) & (x < 1.0)).all(), kind
        else:
            with pytest.raises(ValueError, match=kind):
                unit_samples(_study(kind, ""))


def test_latin_hypercube_puts_one_point_in_each_stratum():
    n = 64
    x = unit_samples(_study("lhs", f"n = {n}"))
    assert x.shape == (n, 4)
    for column in x.T:
        assert np.array_equal(np.sort(np.floor(column * n)), np.arange(n))


def test_sobol_points_are_in_the_saltelli_layout():
    n, d = 64, 4
    x = unit_samples(_study("sobol", f"n = {n}")).reshape(n, d + 2, d)
    a, b = x[:, 0], x[:, d + 1]
    for j in range(d):
        ab = x[:, 1 + j]
        assert np.array_equal(ab[:, j], b[:, j])
        others = [k for k in range(d) if k != j]
        assert np.array_equal(ab[:, others], a[:, others])
    assert not np.array_equal(a, b)


GRID = """
name = "grid"
seed = 3

[sampler]
kind = "grid"

[structure]
kind = "block"
half_diagonal = { dist = "grid", low = 0.5, high = 3.0, n = 3 }
slenderness = { dist = "grid", values = [0.1, 0.2] }

[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = 2.0
period = 0.5
"""


def test_the_grid_is_every_combination_of_the_points():
    ds = make_design(validate_text(GRID))
    rows = set(zip(ds["half_diagonal"].values, ds["slenderness"].values, strict=True))
    assert ds.sizes["sample"] == 6
    assert rows == set(itertools.product([0.5, 1.75, 3.0], [0.1, 0.2]))


def test_a_sampler_the_schema_does_not_know_is_refused_by_name():
    with pytest.raises(StudyError, match="sampler.kind") as err:
        _study("halton")
    for kind in SAMPLERS:
        assert repr(kind) in str(err.value), kind


def test_replicates_and_record_designs_name_the_random_samplers():
    random = " and ".join(kinds_laid_out("random"))
    with pytest.raises(StudyError, match=f"replicates: applies to the {random} samplers"):
        _study("sobol", "n = 64\nreplicates = 2")
