"""Wall time of an incremental dynamic analysis of two-body objects: 8 records x 6 statues on
rocking plinths (:class:`~rockstudy.structures.StackedBlocks`), and the same 6 statues on base
isolators (:class:`~rockstudy.structures.IsolatedBlock`), through the design function a study
runs, :func:`rockstudy.study.designs.records.incremental_dynamic_analysis`, given the list of
structures (whose columns, :func:`rockstudy.study.designs.two_body_rows.design_columns`, are
those a study gives it; its scenes go to ``simulate_batch(structure=...)``, the numba kernels,
rows in parallel).

Records (horizontal components, whole): ``--records shipped`` (default) the eight synthetic
near-fault records shipped with rockstudy; ``--records mixed`` the real ones of shared/records
first (``ROCKSTUDY_RECORDS`` to move it; those present), then shipped ones up to
``--n-records``. The objects: 6 museum statues (width 0.3-0.6 m, height 0.9-2.3 m) on marble
plinths (density ratio 1) or on isolators (T_b 2-3 s, zeta_b 0.05-0.15, base mass ratio
0.5-2). The IDA takes the design's defaults (rungs 1 % apart from the uplift up to 30 times
it, bisection to 0.1 %, 24 levels scanned above the capacity) unless ``--step`` etc. say
otherwise. Printed per kind: the wall seconds (after a warm call that compiles the kernels),
the simulations run and the censored share.

    python benchmarks/two_body_ida.py [--records shipped|mixed] [--kinds stacked isolated]
"""

from __future__ import annotations

import argparse
import time

from contact_accuracy import record_counts, records

from rockstudy.motions import Record
from rockstudy.structures import Block, IsolatedBlock, StackedBlocks
from rockstudy.study.designs.records import incremental_dynamic_analysis

#: (statue width, height; plinth width, height) [m] of the six objects.
STATUES = (
    (0.45, 1.90, 0.70, 1.00),
    (0.50, 1.60, 0.80, 0.90),
    (0.60, 2.30, 0.90, 1.10),
    (0.35, 1.20, 0.50, 1.10),
    (0.30, 0.90, 0.45, 1.20),
    (0.40, 1.40, 0.60, 0.80),
)
#: (T_b [s], zeta_b, base mass ratio) of the six isolators.
ISOLATORS = ((2.5, 0.10, 1.0), (2.0, 0.05, 0.5), (3.0, 0.15, 2.0), (2.2, 0.10, 1.0),
             (2.8, 0.08, 1.5), (2.4, 0.12, 0.8))  # fmt: skip


def objects(kind: str) -> list:
    """The six two-body structures of ``kind`` ("stacked" or "isolated")."""
    out = []
    for (w, h, pw, ph), (period, damping, gamma) in zip(STATUES, ISOLATORS, strict=True):
        statue = Block.from_dimensions(w, h)
        if kind == "stacked":
            out.append(StackedBlocks(Block.from_dimensions(pw, ph), statue, density_ratio=1.0))
        else:
            out.append(IsolatedBlock(statue, gamma, period, damping))
    return out


def suite(which: str, n: int) -> list[Record]:
    """``n`` horizontal records: the shipped ones, or the shared real ones first."""
    recs = records(1e9)
    if which == "shipped":
        recs = [r for r in recs if r[0].startswith("NF")]
    return [Record(a, time=t, name=name) for name, t, a, _ in recs[:n]]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", choices=("shipped", "mixed"), default="shipped")
    ap.add_argument("--n-records", type=int, default=8)
    ap.add_argument("--kinds", nargs="+", default=["stacked", "isolated"])
    ap.add_argument("--step", type=float, default=0.01)
    ap.add_argument("--tolerance", type=float, default=0.001)
    ap.add_argument("--scan", type=int, default=24)
    ap.add_argument("--rtol", type=float, default=1e-8)
    args = ap.parse_args(argv)
    recs = suite(args.records, args.n_records)
    kw = dict(step=args.step, tolerance=args.tolerance, scan=args.scan, rtol=args.rtol)
    names = [r.name for r in recs]
    print(f"{record_counts(names)} ({args.records}): {', '.join(names)}")
    for kind in args.kinds:
        structures = objects(kind)  # the design's two_body column, as a study gives it
        incremental_dynamic_analysis(recs[:1], structures[:1], **kw)
        t0 = time.perf_counter()
        ds = incremental_dynamic_analysis(recs, structures, **kw)
        seconds = time.perf_counter() - t0
        print(
            f"IDA {len(recs)} records x 6 {kind} objects: {seconds:.1f} s wall, "
            f"{int(ds['simulations'].sum())} simulations, "
            f"{float(ds['censored'].mean()):.0%} censored"
        )


if __name__ == "__main__":
    main()
