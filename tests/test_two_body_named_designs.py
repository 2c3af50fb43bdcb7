"""The record designs of the Python API take two-body structures by name, as blocks:
``{name: StackedBlocks or IsolatedBlock or Block}`` (or a list of them). Each of their points
is the scene :func:`rockstudy.simulate_batch` gives with ``structure=`` at the point's scale
(the oracle: the batch door itself, not the design), and the design keeps the names."""

import numpy as np
import pytest

from rockstudy import simulate_batch
from rockstudy.constants import G
from rockstudy.motions import Record
from rockstudy.structures import Block, IsolatedBlock, StackedBlocks
from rockstudy.study.designs.records import multiple_stripes

STATUE = Block.from_dimensions(0.4, 1.6)
PAIR = StackedBlocks(Block.from_dimensions(0.8, 1.0), STATUE)
ISOLATED = IsolatedBlock(STATUE, 1.0, 2.0, 0.1)


def _record():
    t = np.arange(0.0, 3.0, 0.01)
    return Record(0.5 * G * np.sin(2 * np.pi * t / 0.6) * (t < 1.2), dt=0.01, name="r")


@pytest.mark.parametrize("as_list", [False, True])
def test_stripes_of_named_two_body_structures_are_their_batch_scenes(as_list):
    rec = _record()
    objects = {"Statue": STATUE, "On plinth": PAIR, "Isolated": ISOLATED}
    given = list(objects.values()) if as_list else objects
    ds = multiple_stripes([rec], given, levels=[1.0, 3.0, 6.0], im="pga")
    if not as_list:
        assert list(ds["structure"].values) == list(objects)
    for j, (kind, outputs) in enumerate(
        (
            (STATUE, ("max_rotation", "overturned")),
            (PAIR, ("max_rotation_lower", "max_rotation_upper", "overturned_body", "overturned")),
            (ISOLATED, ("max_rotation", "max_isolator_displacement", "overturned")),
        )
    ):
        at = ds.isel(record=0, structure=j)
        scales = at["scale"].values
        if isinstance(kind, Block):
            run = simulate_batch(
                half_diagonal=kind.half_diagonal, slenderness=kind.slenderness, record=rec,
                scale=scales,
            )  # fmt: skip
        else:
            run = simulate_batch(structure=kind, record=rec, scale=scales, rtol=1e-8)
        for k in outputs:
            np.testing.assert_allclose(
                at[k].values.astype(float), np.asarray(run[k], float), rtol=1e-12
            )
    assert int(ds.isel(record=0, structure=0)["overturned_body"].max()) == -1
