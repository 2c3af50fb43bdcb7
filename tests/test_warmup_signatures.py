"""The warm-up's kernels are compiled once for every caller: ``simulate`` (from Python) and the
batch kernels (from numba) pass them arguments of the same numba types, so that a kernel
``rockstudy compile`` or a study left in the cache serves both."""

import math

import numpy as np

from rockstudy.constants import G


def _table_types(dispatcher):
    """The mechanism-table argument's numba type in each signature of a scene dispatcher."""
    return {sig[0].types[sig[0].fields.index("table")] for sig in dispatcher.signatures}


def test_simulate_and_batch_share_the_general_scene_kernel():
    """A block on a record, a mechanism on a pulse (both by :func:`rockstudy.simulate`) and a
    batch of blocks on a record run one compiled general scene, with a read-only table: a
    writable table from Python would compile the scene (and its ~20 callees) a second time."""
    from rockstudy.dynamics import _rocking, simulate, simulate_batch
    from rockstudy.dynamics._structure_tables import structure_table
    from rockstudy.motions import SinePulse, stochastic_record
    from rockstudy.structures import Block, PointMassStrut

    alpha = 0.2
    record = stochastic_record(peak=3.0 * G * math.tan(alpha), duration=1.0, dt=0.01, seed=0)
    simulate(Block(1.0, alpha), record)
    strut = PointMassStrut(1.0, alpha)
    simulate(strut, SinePulse(3.0 * G * math.tan(alpha), 0.5))
    simulate_batch(half_diagonal=1.0, slenderness=np.array([0.15, 0.2]), record=record, scale=1.0)
    tables = _table_types(_rocking.scene)
    assert len(tables) == 1 and not any(t.mutable for t in tables)
    assert not _rocking.NO_TABLE.flags.writeable
    assert not structure_table(strut)[0].flags.writeable  # a cached table stays as computed


def test_every_warm_up_group_has_a_start_and_starts_in_that_order(monkeypatch):
    """Each group of the warm-up has its place in the start order (the scenes' groups first,
    the batch groups last), whatever order ``--group`` names them in."""
    from rockstudy.study.running import _warmup

    assert sorted(_warmup.START_ORDER) == sorted(_warmup.GROUPS)
    started = []
    for name in _warmup.GROUPS:
        monkeypatch.setitem(_warmup.GROUPS, name, lambda name=name: started.append(name))
    monkeypatch.setattr(_warmup, "purge_stale_cache", lambda: 0)
    _warmup.compile_kernels(processes=1, groups=["batch-serial", "records", "demo"])
    assert started == ["demo", "records", "batch-serial"]
