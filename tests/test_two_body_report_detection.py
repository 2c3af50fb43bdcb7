"""The record report's two-body section finds every statue on a plinth and every block on an
isolator of a design, also one that never overturned (an IDA stores ``overturned_body`` -1 for
a censored object, but its rotations at the highest scale it stood at).

Oracle: the structures given to the design (which of them are two-body), not the report."""

import numpy as np

from rockstudy.constants import G
from rockstudy.motions import Record
from rockstudy.structures import Block, StackedBlocks
from rockstudy.study.designs.records import incremental_dynamic_analysis
from rockstudy.study.report.two_body import _two_body


def test_a_statue_on_a_plinth_that_never_overturns_is_in_the_two_body_section():
    pair = StackedBlocks(Block.from_dimensions(0.8, 1.0), Block.from_dimensions(0.4, 1.6))
    t = np.arange(0.0, 3.0, 0.01)
    rec = Record(0.3 * G * np.sin(2 * np.pi * t / 0.5) * (t < 1.0), dt=0.01, name="r")
    ds = incremental_dynamic_analysis([rec], [pair], max_pga_ratio=1.2, step=0.05, scan=0)
    assert bool(ds["censored"].all())  # it stands on every rung: no overturned body
    assert int(ds["overturned_body"].values.ravel()[0]) == -1
    assert _two_body(ds) == [0]
