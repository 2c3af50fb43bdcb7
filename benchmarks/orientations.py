"""A record design over orientations: the cost of 8 orientations against 1.

Writes ``--records`` synthetic two-component records (x and y files) to a temporary folder and
runs the same design study (``--design``, default an IDA in ``pga_rotd50``; four blocks) with
``[design] orientations = 1`` and ``= 8``, each row as a task evaluates it
(:func:`rockstudy.study.designs.record_rows.evaluate_rows`, in this process, after a warm-up
that compiles the kernels), and prints the wall time of each and their ratio. The target: 8
orientations cost at most 8 times one.

    python benchmarks/orientations.py [--records 2] [--design ida]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

STUDY = """
name = "orientations_{n}"
seed = 1
[sampler]
kind = "lhs"
n = 4
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.4, high = 1.2 }}
slenderness = {{ dist = "uniform", low = 0.15, high = 0.25 }}
[motion]
kind = "record"
files = "{folder}"
h2 = {{ match = '_X\\.AT2$', replace = "_Y.AT2" }}
{scale}
[design]
kind = "{design}"
orientations = {n}
{options}
"""
DESIGNS = {
    "ida": ("", 'im = "pga_rotd50"\nstep = 0.02'),
    "stripes": (
        'scale_to = { im = "pga_rotd50", value = { dist = "grid", values = [2.0, 4.0, 6.0] } }',
        "",
    ),
    "cloud": ("", ""),
}


def write_pairs(folder: Path, n: int) -> None:
    """``n`` synthetic near-fault pairs p<i>_X.AT2, p<i>_Y.AT2."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from _helpers import write_at2

    from rockstudy.motions import synthetic_near_fault

    for i in range(n):
        for part, seed, tp in (("X", 10 + i, 0.6 + 0.2 * i), ("Y", 30 + i, 0.9 + 0.1 * i)):
            rec = synthetic_near_fault(pulse_period=tp, pga=3.0, seed=seed, duration=8.0)
            write_at2(folder / f"p{i}_{part}.AT2", rec)


def seconds(folder: Path, n: int, design: str) -> tuple[float, int]:
    """Wall seconds of every row of the study over ``n`` orientations, and its rows."""
    from rockstudy.study import load_study
    from rockstudy.study.designs.record_rows import evaluate_rows
    from rockstudy.study.designs.sampling import make_design

    scale, options = DESIGNS[design]
    path = folder / f"orientations_{n}.toml"
    text = STUDY.format(n=n, folder=folder, design=design, scale=scale, options=options)
    path.write_text(text)
    study = load_study(path)
    rows = make_design(study, folder)
    cols = {k: v.values for k, v in rows.data_vars.items() if v.dims == ("sample",)}
    cols["sample"] = rows["sample"].values
    start = time.perf_counter()
    evaluate_rows(study, cols, folder)
    return time.perf_counter() - start, int(cols["sample"].size)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=2)
    parser.add_argument("--design", choices=list(DESIGNS), default="ida")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        write_pairs(folder, args.records)
        seconds(folder, 1, args.design)  # warm-up: numba kernels, records read
        one, rows_one = seconds(folder, 1, args.design)
        eight, rows_eight = seconds(folder, 8, args.design)
    print(f"{args.design}, {args.records} records x 4 blocks")
    print(f"1 orientation : {one:8.2f} s ({rows_one} rows)")
    print(f"8 orientations: {eight:8.2f} s ({rows_eight} rows)")
    print(f"ratio         : {eight / one:8.2f} (target <= 8)")


if __name__ == "__main__":
    main()
