"""The report's table of two-body objects counts the overturned bodies of a statue on a plinth
only: a block on an isolator has no plinth, so its row must not say that no statue fell where
it overturned (its counts are left empty).

Oracle: simulate_batch(structure=IsolatedBlock) on the same scenes (how many overturn)."""

import numpy as np
import pandas as pd

from rockstudy import simulate_batch
from rockstudy.constants import G
from rockstudy.motions import Record
from rockstudy.structures import Block, IsolatedBlock, StackedBlocks
from rockstudy.study.designs.records import multiple_stripes
from rockstudy.study.report._page import _Page
from rockstudy.study.report.objects import ReportContext
from rockstudy.study.report.two_body import section

STATUE = Block.from_dimensions(0.4, 1.6)


def test_an_isolated_object_that_overturns_has_no_body_counts(tmp_path):
    t = np.arange(0.0, 4.0, 0.01)
    rec = Record(0.5 * G * np.sin(2 * np.pi * t / 2.0) * (t < 2.0), dt=0.01, name="r")
    isolated = IsolatedBlock(STATUE, 1.0, 2.0, 0.05)
    pair = StackedBlocks(Block.from_dimensions(0.8, 1.0), STATUE)
    objects = {"Isolated": isolated, "On plinth": pair}
    ds = multiple_stripes([rec], objects, levels=[0.5, 1.0, 2.0], im="pga")
    scales = ds["scale"].sel(structure="Isolated").values.ravel()
    fell = simulate_batch(structure=isolated, record=rec, scale=scales)["overturned"]
    assert fell.any()  # the scenes overturn the isolated statue
    section(_Page(tmp_path), ReportContext(ds, n_boot=10))
    table = pd.read_csv(tmp_path / "two_body_outputs.csv", index_col=0)
    bodies = [c for c in table if c.startswith("overturned: ")]
    assert table.loc["Isolated", bodies].isna().all()
    assert table.loc["On plinth", bodies].notna().all()
