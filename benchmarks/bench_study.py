"""Study-layer benchmark (issue 5), on this machine's 2 cores:

1. a Sobol' study with D = 5 and N = 2^13 (57,344 scenes), end to end on 2 workers: sampling,
   dask, zarr and the Sobol' analysis (SALib), including the cluster's start;
2. dask and storage overhead: the same run on an already started 2-worker cluster against
   calling the batch kernel directly on the same samples with 2 threads;
3. a Monte Carlo study of 10^6 scenes streamed to disk, with the peak memory of the client and
   of the workers.

Prints the figures and writes benchmarks/results/study.json.

    python benchmarks/bench_study.py [--mc 1000000]
"""

from __future__ import annotations

import argparse
import json
import resource
import shutil
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
import xarray as xr

from rockstudy.dynamics.batch import simulate_batch
from rockstudy.study import make_design, run_study, salib_problem, validate_text

OUT = Path(__file__).parent / "results"

SOBOL = """
name = "bench_sobol"
seed = 1
chunk_size = {chunk}
[sampler]
kind = "sobol"
n = 8192
[structure]
kind = "block"
half_diagonal = {{ dist = "loguniform", low = 0.3, high = 5.0 }}
slenderness = {{ dist = "uniform", low = 0.05, high = 0.35 }}
restitution = {{ dist = "uniform", low = 0.75, high = 0.95 }}
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = {{ dist = "uniform", low = 1.0, high = 4.0 }}
period = {{ dist = "loguniform", low = 0.1, high = 2.0 }}
[run]
outputs = ["max_rotation_ratio", "overturned"]
"""

MC = """
name = "bench_mc"
seed = 2
chunk_size = 50000
[sampler]
kind = "monte_carlo"
n = {n}
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 3.0 }}
slenderness = {{ dist = "uniform", low = 0.1, high = 0.3 }}
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = {{ dist = "uniform", low = 1.0, high = 5.0 }}
period = {{ dist = "loguniform", low = 0.1, high = 2.0 }}
[run]
outputs = ["max_rotation", "overturned", "n_impacts"]
"""


def sobol_analysis(path, study):
    from SALib.analyze import sobol

    ds = xr.open_zarr(path)
    y = ds["max_rotation_ratio"].values
    y = np.where(np.isfinite(y), y, np.pi / 2 / ds["critical_rotation"].values)
    return sobol.analyze(salib_problem(study), y, calc_second_order=False, seed=1)


def _kernel_seconds(design):
    kw = dict(
        frequency_parameter=design.frequency_parameter.values,
        slenderness=design.critical_rotation.values,
        restitution=design.restitution.values,
        pulse="sine",
        amplitude=design.amplitude.values,
        period=design.period.values,
    )
    simulate_batch(**{k: (v[:10] if isinstance(v, np.ndarray) else v) for k, v in kw.items()})
    t0 = time.perf_counter()
    simulate_batch(**kw)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mc", type=int, default=1_000_000)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="rockstudy-bench-"))
    result = {}
    try:
        # 1. end to end
        study = validate_text(SOBOL.format(chunk=4096))
        t0 = time.perf_counter()
        report = run_study(study, tmp / "sobol.zarr", workers=2, progress=False, netcdf=False)
        si = sobol_analysis(tmp / "sobol.zarr", study)
        result["sobol_end_to_end_seconds"] = time.perf_counter() - t0
        result["sobol_scenes"] = report.samples
        result["sobol_S1_max_rotation_ratio"] = dict(
            zip(salib_problem(study)["names"], map(float, si["S1"]), strict=True)
        )

        # 2. overhead on a started cluster against the kernel alone (2 threads), on the
        #    Sobol' study and on the Monte Carlo study of 3.
        from distributed import Client, LocalCluster

        numba.set_num_threads(2)
        mc = validate_text(MC.format(n=args.mc))
        with (
            LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cl,
            Client(cl) as client,
        ):
            warm = validate_text(SOBOL.format(chunk=4096).replace("n = 8192", "n = 64"))
            run_study(warm, tmp / "warm.zarr", client=client, progress=False, netcdf=False)
            for label, st in (("sobol", study), ("mc", mc)):
                t0 = time.perf_counter()
                design = make_design(st)
                design_seconds = time.perf_counter() - t0
                kernel = _kernel_seconds(design)
                t0 = time.perf_counter()
                rep = run_study(
                    st, tmp / f"{label}-layer.zarr", client=client, progress=False, netcdf=False
                )
                layer = time.perf_counter() - t0
                result[f"{label}_scenes"] = rep.samples
                result[f"{label}_kernel_direct_seconds_2_threads"] = kernel
                result[f"{label}_study_on_running_cluster_seconds"] = layer
                result[f"{label}_design_seconds"] = design_seconds
                # the design is needed either way; the layer adds dask and storage
                result[f"{label}_dask_and_storage_overhead"] = (layer - design_seconds) / kernel - 1
                shutil.rmtree(tmp / f"{label}-layer.zarr", ignore_errors=True)

        # 3. the Monte Carlo study from scratch (cluster start included), streamed to disk
        t0 = time.perf_counter()
        rep = run_study(mc, tmp / "mc.zarr", workers=2, progress=False, netcdf=True)
        result["mc_end_to_end_seconds_with_netcdf"] = time.perf_counter() - t0
        result["mc_client_peak_rss_MB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        result["mc_worker_peak_rss_MB"] = (
            resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        )
        result["mc_store_MB"] = (
            sum(f.stat().st_size for f in (tmp / "mc.zarr").rglob("*") if f.is_file()) / 2**20
        )
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    OUT.mkdir(exist_ok=True)
    (OUT / "study.json").write_text(json.dumps(result, indent=2))
    for key, value in result.items():
        print(f"{key:40s} {value}")


if __name__ == "__main__":
    main()
