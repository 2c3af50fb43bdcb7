"""Analysis and report benchmark (issue 7): the report of a 57,344-scene Sobol' cube, and the
flagship self-similarity studies (linear and nonlinear) end to end with their reports. Prints
the figures (and the collapse measured) and writes benchmarks/results/report.json.

    python benchmarks/bench_report.py
"""

from __future__ import annotations

import json
import shutil
import tempfile
import time
from pathlib import Path

import pandas as pd

from rockstudy.study import load_study, run_study, validate_text
from rockstudy.study.report import make_report

ROOT = Path(__file__).resolve().parents[1]
OUT = Path(__file__).parent / "results"


def main():
    from bench_study import SOBOL

    tmp = Path(tempfile.mkdtemp(prefix="rockstudy-report-"))
    result = {}
    try:
        run_study(
            validate_text(SOBOL.format(chunk=4096)),
            tmp / "sobol.zarr",
            workers=2,
            progress=False,
            netcdf=False,
        )
        t0 = time.perf_counter()
        make_report(tmp / "sobol.zarr", tmp / "sobol_report")
        result["report_57344_sobol_seconds"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        for name in (
            "self_similarity",
            "self_similarity_nonlinear",
            "self_similarity_61",
            "self_similarity_fragility",
        ):
            cube = tmp / f"{name}.zarr"
            run_study(
                load_study(ROOT / "studies" / f"{name}.toml"), cube, workers=2, progress=False
            )
            make_report(cube, tmp / f"{name}_report")
            for part in ("collapse", "fragility"):
                path = tmp / f"{name}_report" / f"{part}.csv"
                if path.exists():
                    table = pd.read_csv(path, index_col=0)
                    result[f"{name}_{part}"] = table.to_dict(orient="records")
        result["flagship_end_to_end_seconds"] = time.perf_counter() - t0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    OUT.mkdir(exist_ok=True)
    (OUT / "report.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
