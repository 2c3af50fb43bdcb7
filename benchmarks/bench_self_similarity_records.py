"""The flagship on records (issue 13 section 9), through the Python API: blocks of three size
classes under a record suite, an IDA (first overturning PGA, bisection to 2 %), and the spread
of the median capacity across the size classes, dimensional and in the record groups. Writes
benchmarks/results/self_similarity_records.json and a report per suite.

    NUMBA_NUM_THREADS=2 python benchmarks/bench_self_similarity_records.py

Suites: the eight synthetic near-fault records shipped in data/records (horizontal
components), and, when ../shared/records is there, those plus the five real records in it.
Blocks: R on a log grid of 9 values from 0.3 to 5 m x alpha in {0.15, 0.2, 0.25}, Housner's
restitution, nonlinear model; size classes are the three thirds of the R grid.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from rockstudy.motions import load_suite
from rockstudy.study.analysis.record_similarity import size_class_medians
from rockstudy.study.designs.records import incremental_dynamic_analysis
from rockstudy.study.report.records import record_report

ROOT = Path(__file__).resolve().parents[1]
OUT = Path(__file__).parent / "results"
SHARED = ROOT.parent / "shared" / "records"
#: (label, measure, omega_p / p bins, pulse-like records only)
CASES = (
    ("PGA [g]", "pga", None, False),
    ("PGV [m/s]", "pgv", None, False),
    ("PGA / (g tan alpha)", "pga_ratio", None, False),
    ("PGA / (g tan alpha) in 3 bins of omega_p / p", "pga_ratio", 3, False),
    ("PGV p / (g tan alpha)", "pgv_ratio", None, False),
    ("PGV p / (g tan alpha), pulse-like records only", "pgv_ratio", None, True),
)


def structures():
    R, alpha = np.meshgrid(np.geomspace(0.3, 5.0, 9), [0.15, 0.2, 0.25])
    return {"half_diagonal": R.ravel(), "slenderness": alpha.ravel()}


def measure(ds, n_boot=200):
    rows = []
    for label, im, bins, pulse_only in CASES:
        sub = (
            ds.isel(record=np.flatnonzero(ds["pulse_indicator"].values > 0.85))
            if pulse_only
            else ds
        )
        _, spread = size_class_medians(sub, im, frequency_bins=bins, n_boot=n_boot)
        for band, r in spread.iterrows():
            rows.append(
                {
                    "measure": label,
                    "band": band,
                    "records": int(sub.sizes["record"]),
                    **{k: float(r[k]) for k in ("ratio", "ratio_lo", "ratio_hi", "log_std")},
                    "classes": int(r["classes"]),
                }
            )
    return rows


def main():
    suites = {"synthetic": load_suite(str(ROOT / "data" / "records" / "*_H.AT2"))}
    if SHARED.is_dir():
        suites["shared+synthetic"] = load_suite(SHARED) + suites["synthetic"]
    OUT.mkdir(exist_ok=True)
    result = {}
    for name, records in suites.items():
        t0 = time.perf_counter()
        ds = incremental_dynamic_analysis(
            records, structures(), im="pga", tolerance=0.02, periods=(0.5, 1.0)
        )
        t_ida = time.perf_counter() - t0
        rows = measure(ds)
        t1 = time.perf_counter()
        record_report(ds, OUT / f"self_similarity_records_{name}", title=f"flagship, {name}")
        t_report = time.perf_counter() - t1
        result[name] = {
            "records": [str(n) for n in ds["record_name"].values],
            "simulations": int(ds.attrs["n_simulations"]),
            "censored": int(ds["censored"].sum()),
            "survive_above_capacity": int(ds["survives_above_capacity"].sum()),
            "ida_seconds": round(t_ida, 1),
            "report_seconds": round(t_report, 1),
            "spread": rows,
        }
        print(
            f"\n{name}: {len(records)} records x 27 blocks, {ds.attrs['n_simulations']} sims, "
            f"IDA {t_ida:.1f} s, report {t_report:.1f} s"
        )
        for r in rows:
            print(
                f"  {r['measure']:<48} {r['band']:<26} max/min {r['ratio']:.3g} "
                f"[{r['ratio_lo']:.3g}, {r['ratio_hi']:.3g}]  std ln {r['log_std']:.3g}"
            )
    (OUT / "self_similarity_records.json").write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
