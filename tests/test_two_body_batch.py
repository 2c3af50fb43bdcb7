"""simulate_batch(structure=...): the two-body systems in a batch, against Housner's block in
the limits where a two-body system is one block, and the door's refusals."""

import numpy as np
import pytest

from rockstudy.dynamics.batch import simulate_batch
from rockstudy.structures import Block, IsolatedBlock, StackedBlocks


def test_stacked_batch_on_a_fixed_plinth_is_housners_batch():
    """A wide, heavy plinth never lifts: each row's statue is Housner's block of the rocking
    batch under the same pulse."""
    lower, upper = Block(6.0, 0.9), Block(0.5, 0.2)
    amplitude, period = np.array([1.5, 3.0, 5.0, 2.2]), np.array([0.6, 0.6, 0.3, 1.0])
    pair = StackedBlocks(lower, upper, density_ratio=0.5)
    got = simulate_batch(structure=pair, amplitude=amplitude, period=period, rtol=1e-10)
    ref = simulate_batch(
        half_diagonal=0.5, slenderness=0.2, amplitude=amplitude, period=period, rtol=1e-10
    )
    np.testing.assert_array_equal(got["overturned"], ref["overturned"])
    np.testing.assert_allclose(got["max_rotation_upper"], ref["max_rotation"], rtol=1e-7)
    assert np.all(got["max_rotation_lower"] == 0.0)
    np.testing.assert_array_equal(got["overturned_body"], np.where(ref["overturned"], 2, 0))


def test_isolated_batch_dataset_names_the_contract_outputs():
    """An isolated block's batch gives max_rotation, overturned and max_isolator_displacement
    per scene; an isolator of vanishing period leaves the block on fixed ground."""
    block = Block(0.6, 0.25)
    stiff = IsolatedBlock(block, base_mass_ratio=1.0, period=0.01, damping=0.05)
    ds = simulate_batch(structure=[stiff, stiff], amplitude=[2.0, 3.5], period=0.8, as_dataset=True)
    assert {"max_rotation", "overturned", "max_isolator_displacement"} <= set(ds.data_vars)
    ref = simulate_batch(half_diagonal=0.6, slenderness=0.25, amplitude=[2.0, 3.5], period=0.8)
    np.testing.assert_allclose(ds["max_rotation"].values, ref["max_rotation"], rtol=2e-3)
    assert np.all(ds["max_isolator_displacement"].values < 1e-3)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(slenderness=0.2), "takes no slenderness"),
        (dict(friction=0.5), "takes no friction"),
        (dict(method="linear"), "method='linear'"),
        (dict(outputs=["max_rotation"]), "unknown name"),
    ],
)
def test_two_body_batch_refuses_what_it_cannot_run(kwargs, match):
    pair = StackedBlocks(Block(1.0, 0.3), Block(0.4, 0.2))
    with pytest.raises(ValueError, match=match):
        simulate_batch(structure=pair, amplitude=1.0, period=1.0, **kwargs)


def test_two_body_batch_refuses_mixed_classes_and_lengths():
    pair = StackedBlocks(Block(1.0, 0.3), Block(0.4, 0.2))
    iso = IsolatedBlock(Block(0.4, 0.2), base_mass_ratio=1.0, period=2.0, damping=0.1)
    with pytest.raises(TypeError, match="structure must be one of"):
        simulate_batch(structure=[pair, iso], amplitude=1.0, period=1.0)
    with pytest.raises(ValueError, match="common length"):
        simulate_batch(structure=[pair, pair], amplitude=[1.0, 2.0, 3.0], period=1.0)
