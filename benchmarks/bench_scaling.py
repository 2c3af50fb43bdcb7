"""Scaling benchmark (issue 14, 6): what a scene costs, and what dask adds on top.

One run measures, on one core unless said otherwise:

1. cost per scene (CPU time) against record length: Kanai-Tajimi records (``stochastic_record``, dt
   0.01 s, the envelope stretched with the duration) of 5 to 80 s, nonlinear kernel at rtol
   1e-8 and the exact linear solver (``simulate_batch``, one thread);
2. cost per scene against the number of scenes per ``simulate_batch`` call (1 ... 1000, or
   10^4 with ``--big``), on sine pulses and on a 20 s record: the fixed cost of a call;
3. throughput of a pulse study and a record study run by the study runner
   (``run_study`` on a started local dask cluster of 1 and 2 single-threaded workers) against
   the bare kernel on the same scenes (one thread, CPU time), with the overheads separated: design,
   template and chunk writes (timed in the client), the work of each task outside the kernel
   (dask's task stream), the workers' start and kernel load (first task on fresh workers), and
   what is left (scheduling and idle workers); plus the round trip and throughput of empty
   dask tasks, and a chunk-size sweep of the pulse study on 2 workers.

The blocks are those of issue 14: R 0.5-3 m, alpha 0.1-0.3, peak ground acceleration
0.8-6 g tan(alpha). From the measured per-task overheads it prints what 64 workers need: the
chunk size for 90 % parallel efficiency. The study parts are wall times, and grow with the
machine's load (printed): on a shared machine the dask overheads are upper bounds.
Writes benchmarks/results/scaling.json.

    python benchmarks/bench_scaling.py [--scenes 200] [--durations 5 10 20 40 80]
        [--study-pulse 20000] [--study-record 2000] [--workers 1 2] [--big]
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import shutil
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from rockstudy.constants import G
from rockstudy.dynamics.batch import simulate_batch
from rockstudy.motions import stochastic_record
from rockstudy.study import make_design, run_study, validate_text
from rockstudy.study.running import runner, store
from rockstudy.study.running.evaluate import _run_rows, evaluate_chunk

OUT = Path(__file__).parent / "results"
RTOL = 1e-8
DT = 0.01  # record sample step [s]
STUDY_RECORD_SECONDS = 20.0

# The blocks and peak ground accelerations of issue 14, under sine pulses or one record.
STUDY = """
name = "scaling_{kind}"
seed = 14
chunk_size = {chunk}
[sampler]
kind = "monte_carlo"
n = {n}
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 3.0 }}
slenderness = {{ dist = "uniform", low = 0.1, high = 0.3 }}
[motion]
{motion}
[run]
rtol = 1e-8
outputs = ["max_rotation", "overturned"]
"""
PULSE = """kind = "pulse"
shape = "sine"
amplitude_ratio = { dist = "uniform", low = 0.8, high = 6.0 }
period = { dist = "loguniform", low = 0.1, high = 2.0 }"""
RECORD = """kind = "record"
files = ["{path}"]
units = "m/s2"
pga_ratio = {{ dist = "uniform", low = 0.8, high = 6.0 }}"""


def study_of(kind, n, chunk, path=None):
    motion = PULSE if kind == "pulse" else RECORD.format(path=path)
    return validate_text(STUDY.format(kind=kind, n=n, chunk=chunk, motion=motion))


def blocks(n, seed=14):
    """R [m], alpha [rad] and the peak ground acceleration over g tan(alpha) of issue 14."""
    rng = np.random.default_rng(seed)
    return rng.uniform(0.5, 3.0, n), rng.uniform(0.1, 0.3, n), rng.uniform(0.8, 6.0, n)


def cpu_seconds(fn, min_total=0.3, min_repeat=3, max_repeat=200):
    """Least CPU time of this process over repeats of fn() (at least min_repeat, and min_total
    seconds): numba runs on one thread here, and CPU time hardly moves with the machine's load,
    where wall time does (the machine is shared)."""
    times = []
    t_start = time.perf_counter()
    while len(times) < max_repeat and (
        len(times) < min_repeat or time.perf_counter() - t_start < min_total
    ):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return float(np.min(times))


def record_call(rec, R, alpha, ratio, method="nonlinear", n=None):
    n = R.size if n is None else n
    return simulate_batch(
        half_diagonal=R[:n],
        slenderness=alpha[:n],
        record=rec,
        scale=ratio[:n] * G * np.tan(alpha[:n]) / rec.peak,
        method=method,
        rtol=RTOL,
        outputs=("max_rotation", "overturned", "steps"),
    )


def pulse_call(R, alpha, ratio, period, n):
    return simulate_batch(
        half_diagonal=R[:n],
        slenderness=alpha[:n],
        pulse="sine",
        amplitude=ratio[:n] * G * np.tan(alpha[:n]),
        period=period[:n],
        rtol=RTOL,
        outputs=("max_rotation", "overturned", "steps"),
    )


def record_length_curve(durations, n):
    """1. Cost per scene against the record's duration (nonlinear and exact linear)."""
    R, alpha, ratio = blocks(n)
    rows = []
    for d in durations:
        rec = stochastic_record(peak=1.0, duration=d, dt=DT, seed=int(d * 100))
        record_call(rec, R, alpha, ratio, n=2)
        record_call(rec, R, alpha, ratio, "linear", n=2)
        out = record_call(rec, R, alpha, ratio)
        t_nl = cpu_seconds(lambda rec=rec: record_call(rec, R, alpha, ratio), min_repeat=1)
        t_lin = cpu_seconds(lambda rec=rec: record_call(rec, R, alpha, ratio, "linear"))
        rows.append(
            {
                "duration_s": d,
                "samples": rec.acceleration.size,
                "nonlinear_us_per_scene": 1e6 * t_nl / n,
                "nonlinear_scenes_per_s": n / t_nl,
                "linear_us_per_scene": 1e6 * t_lin / n,
                "linear_scenes_per_s": n / t_lin,
                "median_steps": float(np.median(out["steps"])),
                "overturned_share": float(np.mean(out["overturned"])),
            }
        )
    d = np.array([r["duration_s"] for r in rows])
    fits = {}
    for key in ("nonlinear", "linear"):
        c = np.array([r[f"{key}_us_per_scene"] for r in rows])
        slope, intercept = np.polyfit(d, c, 1)
        fits[key] = {"us_per_scene_per_s_of_record": slope, "us_per_scene_at_0_s": intercept}
    return rows, fits


def batch_size_curve(sizes):
    """2. Cost per scene against the number of scenes per call (fixed cost of a call)."""
    n_max = max(sizes)
    R, alpha, ratio = blocks(n_max, seed=15)
    period = np.random.default_rng(16).uniform(0.1, 2.0, n_max)
    rec = stochastic_record(peak=1.0, duration=STUDY_RECORD_SECONDS, dt=DT, seed=2000)
    pulse_call(R, alpha, ratio, period, 2)
    record_call(rec, R, alpha, ratio, n=2)
    rows = []
    for n in sizes:
        t_p = cpu_seconds(lambda n=n: pulse_call(R, alpha, ratio, period, n))
        t_r = cpu_seconds(
            lambda n=n: record_call(rec, R, alpha, ratio, n=n), min_repeat=3 if n < 1000 else 1
        )
        rows.append(
            {
                "scenes_per_call": n,
                "pulse_us_per_scene": 1e6 * t_p / n,
                "record_us_per_scene": 1e6 * t_r / n,
            }
        )
    return rows


def _noop(x):
    return x


def dask_floor(client, n_tasks=400):
    """Round trip of one empty task (submit, wait) and throughput of many empty tasks."""
    client.submit(_noop, -1, pure=False).result()
    lat = []
    for i in range(30):
        t0 = time.perf_counter()
        client.submit(_noop, i, pure=False).result()
        lat.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    client.gather(client.map(_noop, range(n_tasks), pure=False))
    wall = time.perf_counter() - t0
    return {
        "empty_task_round_trip_ms": 1e3 * float(np.median(lat)),
        "empty_tasks_per_s": n_tasks / wall,
    }


def _timed_chunk(study_json, cols, base_dir=None):
    """evaluate_chunk, with the CPU time of the task in its result (taken out before the write;
    this function travels to the workers by value)."""
    t0 = time.process_time()
    result = evaluate_chunk(study_json, cols, base_dir)
    result["_task_cpu_s"] = time.process_time() - t0
    return result


class _ClientTimers:
    """Time the client spends creating the store template (CPU) and writing finished chunks
    (wall), and the CPU time the tasks report."""

    def __init__(self):
        self.template = self.writes = self.task_cpu = 0.0
        self.chunks = 0

    def __enter__(self):
        self._create, self._write = store.create_store, store.ChunkWriter.write
        self._task, runner.evaluate_chunk = runner.evaluate_chunk, _timed_chunk
        timers = self

        def create(*a, **k):
            t0 = time.process_time()
            try:
                return timers._create(*a, **k)
            finally:
                timers.template += time.process_time() - t0

        def write(writer, start, stop, result):
            timers.task_cpu += result.pop("_task_cpu_s")
            t0 = time.perf_counter()
            try:
                return timers._write(writer, start, stop, result)
            finally:
                timers.writes += time.perf_counter() - t0
                timers.chunks += 1

        store.create_store, store.ChunkWriter.write = create, write
        return self

    def __exit__(self, *exc):
        store.create_store, store.ChunkWriter.write = self._create, self._write
        runner.evaluate_chunk = self._task


def bare_kernel_seconds(study, base_dir):
    """The kernel alone (``simulate_batch`` on one thread) on the study's own scenes."""
    design = make_design(study)
    cols = {k: v.values for k, v in design.data_vars.items() if v.dims == ("sample",)}
    cols["sample"] = design["sample"].values
    n = cols["sample"].size
    _run_rows(study, cols, np.arange(min(n, 4)), base_dir)
    return cpu_seconds(lambda: _run_rows(study, cols, np.arange(n), base_dir), min_total=0.0)


def study_run(client, study, out, base_dir):
    """run_study on a started cluster, its parts separated (seconds)."""
    from distributed import get_task_stream

    t0 = time.process_time()
    make_design(study)
    design = time.process_time() - t0  # CPU, as the client's time below
    with _ClientTimers() as timers, get_task_stream(client) as ts:
        t0, c0 = time.perf_counter(), time.process_time()
        rep = run_study(study, out, client=client, base_dir=base_dir, progress=False, netcdf=False)
        wall, client_cpu = time.perf_counter() - t0, time.process_time() - c0
    tasks = [t for t in ts.data if str(t["key"]).startswith("rockstudy-chunk")]
    busy = sum(
        s["stop"] - s["start"] for t in tasks for s in t["startstops"] if s["action"] == "compute"
    )
    shutil.rmtree(out, ignore_errors=True)
    return {
        "scenes": rep.samples,
        "chunks": rep.chunks_total,
        "wall_s": wall,
        "design_s": design,
        "template_s": timers.template,
        "chunk_writes_s": timers.writes,
        "task_compute_s": busy,
        "task_cpu_s": timers.task_cpu,
        # the client process also runs the local scheduler: its CPU time per chunk (without the
        # design and the template, made once) is the serial cost that bounds the chunk rate
        "client_cpu_s": client_cpu,
    }


def worker_start(workers, study, base_dir):
    """Start a local cluster as the runner does, and time its first (kernel-loading) task."""
    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    client = Client(cluster)
    client.wait_for_workers(workers)
    started = time.perf_counter() - t0
    design = make_design(study)
    cols = {k: v.values[:1] for k, v in design.data_vars.items() if v.dims == ("sample",)}
    cols["sample"] = design["sample"].values[:1]
    js = study.normalized()
    t0 = time.perf_counter()
    client.gather(
        [
            client.submit(evaluate_chunk, js, cols, base_dir, pure=False, workers=[w])
            for w in client.scheduler_info()["workers"]
        ]
    )
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    client.submit(evaluate_chunk, js, cols, base_dir, pure=False).result()
    warm = time.perf_counter() - t0
    return (
        cluster,
        client,
        {
            "cluster_start_s": started,
            "first_task_on_fresh_workers_s": first,
            "warm_one_row_task_s": warm,
        },
    )


def study_section(args, tmp):
    """3. The runner against the bare kernel, with 1 and 2 workers, and a chunk-size sweep."""
    rec = stochastic_record(peak=1.0, duration=STUDY_RECORD_SECONDS, dt=DT, seed=3000)
    path = tmp / "kanai_tajimi_20s.txt"
    np.savetxt(path, np.column_stack([rec.time, rec.acceleration]), header="t [s], a [m/s2]")
    chunk_p, chunk_r = args.pulse_chunk, args.record_chunk
    studies = {
        "pulse": study_of("pulse", args.study_pulse, chunk_p),
        "record": study_of("record", args.study_record, chunk_r, path),
    }
    kernel = {k: bare_kernel_seconds(s, tmp) for k, s in studies.items()}
    res = {"kernel_cpu_s": kernel, "runs": {}, "dask_floor": {}}
    for w in args.workers:
        cluster, client, start = worker_start(w, studies["record"], tmp)
        try:
            res["dask_floor"][w] = dask_floor(client)
            for name, st in studies.items():
                r = study_run(client, st, tmp / f"{name}-{w}.zarr", tmp)
                r.update(start)
                r["workers"], r["study"] = w, name
                r["kernel_cpu_s"] = kernel[name]
                r["parallel_efficiency"] = kernel[name] / (w * r["wall_s"])
                r["scenes_per_s"] = r["scenes"] / r["wall_s"]
                r["task_overhead_ms"] = 1e3 * (r["task_cpu_s"] - kernel[name]) / r["chunks"]
                r["client_cpu_ms_per_chunk"] = (
                    1e3 * (r["client_cpu_s"] - r["design_s"] - r["template_s"]) / r["chunks"]
                )
                r["idle_worker_s"] = w * r["wall_s"] - r["task_compute_s"]
                res["runs"][f"{name}_{w}"] = r
            if w == max(args.workers):
                sweep = []
                for chunk in args.sweep:
                    st = study_of("pulse", args.study_pulse, chunk)
                    r = study_run(client, st, tmp / f"sweep-{chunk}.zarr", tmp)
                    r["chunk_size"] = chunk
                    sweep.append(r)
                n_chunks = np.array([r["chunks"] for r in sweep], float)
                walls = np.array([r["wall_s"] for r in sweep])
                slope, intercept = np.polyfit(n_chunks, walls, 1)
                res["chunk_sweep"] = {
                    "workers": w,
                    "rows": sweep,
                    "wall_s_per_chunk": slope,
                    "wall_s_at_0_chunks": intercept,
                }
        finally:
            client.close()
            cluster.close()
    return res


def implications(res, workers=64, target=0.9):
    """Chunk sizes for ``target`` parallel efficiency on ``workers`` workers.

    A chunk of c scenes costs c t + o_w on its worker (t: kernel CPU per scene; o_w: the task's
    CPU outside the kernel) and o_s in the client and its scheduler, which handle the chunks one
    at a time (client CPU per chunk, without the design and the template). The efficiency is
    c t / max(c t + o_w, W o_s): at least ``target`` when c t >= o_w target / (1 - target) and
    c t >= target W o_s. CPU times, so that the machine's load does not inflate them.
    """
    w = max(int(k.split("_")[1]) for k in res["runs"])
    out = {}
    for name in ("pulse", "record"):
        r = res["runs"][f"{name}_{w}"]
        t = r["kernel_cpu_s"] / r["scenes"]
        o_w = max(r["task_cpu_s"] - r["kernel_cpu_s"], 0.0) / r["chunks"]
        o_s = max(r["client_cpu_s"] - r["design_s"] - r["template_s"], 0.0) / r["chunks"]
        c_worker = o_w * target / (1.0 - target) / t
        c_serial = target * workers * o_s / t
        out[name] = {
            "kernel_s_per_scene": t,
            "task_overhead_on_worker_s": o_w,
            "serial_per_chunk_s": o_s,
            "chunk_for_target_scenes": int(np.ceil(max(c_worker, c_serial))),
            "chunk_compute_for_target_s": max(c_worker, c_serial) * t,
            "max_chunks_per_s_serial": 1.0 / o_s if o_s > 0 else float("inf"),
        }
    return {"workers": workers, "target_efficiency": target, **out}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=200, help="scenes per record length")
    ap.add_argument("--durations", type=float, nargs="+", default=[5, 10, 20, 40, 80])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 10, 100, 1000])
    ap.add_argument("--study-pulse", type=int, default=20000, help="scenes of the pulse study")
    ap.add_argument("--study-record", type=int, default=2000, help="scenes of the record study")
    ap.add_argument("--pulse-chunk", type=int, default=2500)
    ap.add_argument("--record-chunk", type=int, default=250)
    ap.add_argument("--sweep", type=int, nargs="+", default=[500, 2000, 10000])
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--big", action="store_true", help="10x the scenes, and 10^4 per call")
    args = ap.parse_args()
    if args.big:
        args.scenes *= 10
        args.sizes = sorted(set(args.sizes) | {10000})
        args.study_pulse *= 10
        args.study_record *= 10
        args.record_chunk *= 4
        args.sweep = [s * 4 for s in args.sweep]
    numba.set_num_threads(1)
    load_start = os.getloadavg()[0]  # other processes on the machine: the figures scale with it
    t_start = time.perf_counter()
    tmp = Path(tempfile.mkdtemp(prefix="rockstudy-scaling-"))
    try:
        length_rows, length_fit = record_length_curve(args.durations, args.scenes)
        size_rows = batch_size_curve(args.sizes)
        studies = study_section(args, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    result = {
        "machine": {
            "python": platform.python_version(),
            "numba": numba.__version__,
            "cpus": os.cpu_count(),
            "load_average_1min_start_end": [load_start, os.getloadavg()[0]],
        },
        "rtol": RTOL,
        "record_length": {"scenes": args.scenes, "rows": length_rows, "fit": length_fit},
        "scenes_per_call": size_rows,
        "studies": studies,
        "implications": implications(studies),
        "seconds": time.perf_counter() - t_start,
    }
    OUT.mkdir(exist_ok=True)
    (OUT / "scaling.json").write_text(json.dumps(result, indent=2))
    report(result)
    print(f"wrote {OUT / 'scaling.json'} ({result['seconds']:.0f} s)")


def report(r):
    m = r["machine"]
    print(
        f"{m['cpus']} cpus, load average {m['load_average_1min_start_end'][0]:.1f} at the start, "
        f"{m['load_average_1min_start_end'][1]:.1f} at the end"
    )
    print(
        f"\n1. cost per scene against record length ({r['record_length']['scenes']} scenes, "
        "one thread, rtol 1e-8)"
    )
    print(
        f"{'record [s]':>10} {'nonlinear us':>13} {'scenes/s':>9} {'steps':>6} "
        f"{'linear us':>10} {'scenes/s':>9}"
    )
    for x in r["record_length"]["rows"]:
        print(
            f"{x['duration_s']:10.0f} {x['nonlinear_us_per_scene']:13.0f} "
            f"{x['nonlinear_scenes_per_s']:9.0f} {x['median_steps']:6.0f} "
            f"{x['linear_us_per_scene']:10.1f} {x['linear_scenes_per_s']:9.0f}"
        )
    for k, f in r["record_length"]["fit"].items():
        print(
            f"   {k}: {f['us_per_scene_at_0_s']:.0f} us + {f['us_per_scene_per_s_of_record']:.1f}"
            " us per second of record"
        )
    print("\n2. cost per scene against scenes per simulate_batch call (one thread)")
    print(f"{'scenes/call':>11} {'pulse us/scene':>15} {'20 s record us/scene':>21}")
    for x in r["scenes_per_call"]:
        print(
            f"{x['scenes_per_call']:11d} {x['pulse_us_per_scene']:15.1f} "
            f"{x['record_us_per_scene']:21.0f}"
        )
    s = r["studies"]
    print("\n3. study runner on a started local cluster against the bare kernel (one thread)")
    print(
        f"{'study':>10} {'W':>2} {'scenes':>7} {'chunks':>6} {'wall s':>7} {'kernel cpu':>10} "
        f"{'eff':>5} {'task ovh ms':>11} {'client ms/chunk':>15} {'writes s':>8} {'idle s':>7}"
    )
    for x in s["runs"].values():
        print(
            f"{x['study']:>10} {x['workers']:2d} {x['scenes']:7d} {x['chunks']:6d} "
            f"{x['wall_s']:7.2f} "
            f"{x['kernel_cpu_s']:10.2f} {x['parallel_efficiency']:5.2f} "
            f"{x['task_overhead_ms']:11.1f} {x['client_cpu_ms_per_chunk']:15.1f} "
            f"{x['chunk_writes_s']:8.2f} {x['idle_worker_s']:7.2f}"
        )
    for w, x in s["dask_floor"].items():
        print(
            f"   {w} worker(s): empty task round trip {x['empty_task_round_trip_ms']:.1f} ms, "
            f"{x['empty_tasks_per_s']:.0f} empty tasks/s"
        )
    for x in s["runs"].values():
        if x["workers"] == max(int(k.split("_")[1]) for k in s["runs"]):
            print(
                f"   cluster start {x['cluster_start_s']:.1f} s, first task on fresh workers "
                f"(import + kernel load) {x['first_task_on_fresh_workers_s']:.2f} s, warm "
                f"one-row task {1e3 * x['warm_one_row_task_s']:.0f} ms"
            )
            break
    sw = s.get("chunk_sweep")
    if sw:
        print(
            f"   pulse chunk sweep on {sw['workers']} workers: "
            + ", ".join(f"chunk {x['chunk_size']}: {x['wall_s']:.2f} s" for x in sw["rows"])
            + f"; {1e3 * sw['wall_s_per_chunk']:.1f} ms of wall per chunk"
        )
    im = r["implications"]
    print(f"\n4. implied for {im['workers']} workers at {im['target_efficiency']:.0%} efficiency")
    for name in ("pulse", "record"):
        x = im[name]
        print(
            f"   {name}: kernel {1e6 * x['kernel_s_per_scene']:.0f} us/scene, task overhead "
            f"{1e3 * x['task_overhead_on_worker_s']:.1f} ms, serial "
            f"{1e3 * x['serial_per_chunk_s']:.1f} ms/chunk "
            f"(<= {x['max_chunks_per_s_serial']:.0f} chunks/s): chunks of >= "
            f"{x['chunk_for_target_scenes']} scenes ({x['chunk_compute_for_target_s']:.2f} s)"
        )


if __name__ == "__main__":
    main()
