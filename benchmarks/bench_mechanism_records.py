"""Mechanisms under records (issue 14 section 3): the tabulated mechanism kernel, eq. (8) of
[003], on the shipped synthetic records (data/records) and the shared real records.

Per (structure, record): ``--scenes`` scale factors (PGA 0.8-4 x g lambda), each scene one
kernel call with the free-rocking map, on one thread, timed in CPU seconds (best of
``--repeat``). This checkout and the source tree of ``--old-rev`` (:func:`run_at_rev` of
bench_records) are timed alternately, ``--rounds`` times each, the best kept. Accuracy of both
against the solve_ivp reference at rtol 1e-12 on the same tables (``simulate_reference(...,
table=)``): p99 and max of the relative max-rotation error where neither overturns, and the
overturning disagreements. Writes benchmarks/results/mechanism_records.json.

    python benchmarks/bench_mechanism_records.py [--rtol 1e-6] [--old-rev d89d318]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np
from bench_records import OUT, RECORDS, run_at_rev
from numba import njit

from rockstudy.dynamics import _rocking

HERE = Path(__file__).resolve().parent
SYNTHETIC = HERE.parent / "data" / "records"
#: (name, horizontal file, vertical file or None); the last four synthetic ones with their
#: vertical component.
RECORD_FILES = tuple(
    (
        f"NF0{i}",
        SYNTHETIC / f"NF0{i}_Tp{tp}s_H.AT2",
        SYNTHETIC / f"NF0{i}_Tp{tp}s_UP.AT2" if i > 4 else None,
    )
    for i, tp in enumerate(("0.40", "0.60", "0.80", "1.00", "1.30", "1.70", "2.20", "3.00"), 1)
) + tuple(
    (name.split(".")[0], RECORDS / name, None)
    for name in (
        "RSN126_GAZLI_GAZ000.AT2",
        "RSN183_IMPVALL.H_H-E08140.AT2",
        "RSN948_NORTHR_CAM009.AT2",
        "RSN982_NORTHR_JEN292.AT2",
        "elcentro_NS.dat",
    )
)
N_SCENES = 30


def structures():
    """The benchmark's mechanisms: a wall, a symmetric frame and an arch (bench_structures')."""
    from rockstudy.structures import Arch, RockingWall, SymmetricFrame

    return {
        "wall": RockingWall(1.0, 0.1, restitution=0.85),
        "frame": SymmetricFrame(1.0, 0.15, 0.5),
        "arch": Arch(math.pi, 0.75, 5.0, restitution=0.9),
    }


def load(path, vertical):
    import rockstudy as rs

    if path.suffix == ".AT2":
        return rs.motions.Record.from_at2(path, vertical=vertical)
    return rs.motions.Record.from_csv(path, units="g")


def scenes(structure, record, seed):
    """(p_eq, phi_cr, eta, tables, fall, scale factors): PGA 0.8-4 x g lambda."""
    from rockstudy.constants import G
    from rockstudy.dynamics._structure_tables import structure_parameters, structure_table

    rp = structure_parameters(structure)
    tab, fall = structure_table(structure)
    rng = np.random.default_rng(seed)
    scale = rng.uniform(0.8, 4.0, N_SCENES) * G * rp.uplift / record.peak
    return rp.frequency_parameter, rp.critical_rotation, rp.restitution, tab, fall, scale


@njit
def _run(p, alpha, eta, kind, mp, times, samples, vsamples, rtol, fall, tab, scale, out):
    """The kernel's (max rotation, overturned, steps) of each scale factor into ``out``."""
    log = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
    body = _rocking.Body(p, alpha, eta, _rocking.MODEL_TABLE, fall, tab)
    rest = _rocking.Start(0.0, 0.0)
    for i in range(scale.shape[0]):
        m = mp.copy()
        m[0] = mp[0] * scale[i]
        controls = _rocking.Controls(rtol, 10**7, True, _rocking.free_tail_end(p, eta, m[3]))
        r = _rocking.scene(body, (kind, m, times, samples, vsamples), controls, rest, log)
        out[i, 0], out[i, 1], out[i, 2] = r.max_rotation, r.overturned, r.steps


@njit
def _run_positional(p, alpha, eta, kind, mp, times, samples, vsamples, rtol, fall, tab, scale, out):
    """:func:`_run` for the kernels before ``scene`` took named inputs (an older ``--old-rev``)."""
    log = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
    for i in range(scale.shape[0]):
        m = mp.copy()
        m[0] = mp[0] * scale[i]
        t_tail = _rocking.free_tail_end(p, eta, m[3])
        mot = (kind, m, times, samples, vsamples)
        r = _rocking.scene(
            p, alpha, eta, _rocking.MODEL_TABLE, mot, rtol, True, t_tail, log, 10**7, 0.0, 0.0,
            fall, tab,
        )  # fmt: skip
        out[i, 0], out[i, 1], out[i, 2] = r[1], r[2], r[7]


def _run_scenes(p, alpha, eta, spec, rtol, fall, tab, scale):
    """(max rotation, overturned, steps) of each scale factor: an (n, 3) array."""
    out = np.empty((scale.size, 3))
    run = _run if hasattr(_rocking, "Body") else _run_positional
    run(p, alpha, eta, *spec, rtol, fall, tab, scale, out)
    return out


def time_kernel(rtol, repeat):
    """{structure/record: scenes/s/core and outputs} of the importable rockstudy."""
    import numba

    numba.set_num_threads(1)
    result = {}
    for j, (sname, structure) in enumerate(structures().items()):
        for i, (rname, path, vpath) in enumerate(RECORD_FILES):
            rec = load(path, vpath)
            p, alpha, eta, tab, fall, scale = scenes(structure, rec, 100 * j + i)
            spec = rec.kernel_spec()
            _run_scenes(p, alpha, eta, spec, rtol, fall, tab, scale[:1])  # compile
            best = np.inf
            for _ in range(repeat):
                t0 = time.process_time()
                out = _run_scenes(p, alpha, eta, spec, rtol, fall, tab, scale)
                best = min(best, time.process_time() - t0)
            result[f"{sname}/{rname}"] = {
                "scenes_per_s": scale.size / best,
                "max_rotation": out[:, 0].tolist(),
                "overturned": out[:, 1].astype(bool).tolist(),
                "steps": out[:, 2].tolist(),
            }
    return result


def reference(rtol=1e-12, cache=None):
    """{structure/record: (max rotations, overturned)} of solve_ivp on the same tables (about
    ten minutes: read from and written to the .npz file ``cache`` if given)."""
    from rockstudy.dynamics._rocking import MODEL_TABLE
    from rockstudy.dynamics.reference import simulate_reference

    if cache is not None and Path(cache).is_file():
        data = np.load(cache)
        return {k[4:]: (data[k], data["ovr/" + k[4:]]) for k in data.files if k[:4] == "max/"}
    result = {}
    for j, (sname, structure) in enumerate(structures().items()):
        for i, (rname, path, vpath) in enumerate(RECORD_FILES):
            rec = load(path, vpath)
            p, alpha, eta, tab, fall, scale = scenes(structure, rec, 100 * j + i)
            mx, ov = [], []
            for f in scale:
                r = simulate_reference(
                    p,
                    alpha,
                    eta,
                    rec.scaled(f),
                    MODEL_TABLE,
                    rtol,
                    free_map=True,
                    table=(tab, fall),
                )
                mx.append(r["max_rotation"])
                ov.append(r["overturned"])
            result[f"{sname}/{rname}"] = (np.array(mx), np.array(ov, bool))
    if cache is not None:
        arrays = {f"max/{k}": v[0] for k, v in result.items()}
        np.savez(cache, **arrays, **{f"ovr/{k}": v[1] for k, v in result.items()})
    return result


def errors(res, ref):
    """Relative max-rotation errors where neither overturns, and the disagreements."""
    rel, wrong = [], 0
    for key, (ref_max, ref_over) in ref.items():
        mx = np.asarray(res[key]["max_rotation"])
        ov = np.asarray(res[key]["overturned"], bool)
        both = ~ov & ~ref_over & (ref_max > 0.0)  # (a structure that never lifts: exact)
        rel.extend(np.abs(mx[both] / ref_max[both] - 1.0))
        wrong += int(np.sum(ov != ref_over))
    rel = np.array(rel)
    return {
        "p99_rel_error": float(np.percentile(rel, 99)),
        "max_rel_error": float(rel.max()),
        "disagreements": wrong,
        "compared": int(rel.size),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rtol", type=float, nargs="+", default=[1e-6, 1e-8])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=2, help="alternations of new and old")
    ap.add_argument("--old-rev", default="d89d318", help="git revision of the old kernel")
    ap.add_argument("--ref-cache", help="an .npz file keeping the reference between runs")
    args = ap.parse_args()
    t_start = time.perf_counter()
    ref = reference(cache=args.ref_cache)
    results, summary = {}, {}
    for rtol in args.rtol:
        new, old = {}, {}
        for _ in range(args.rounds):  # alternate: the machine's load varies
            for acc, run in (
                (new, lambda rtol=rtol: time_kernel(rtol, args.repeat)),
                (
                    old,
                    lambda rtol=rtol: run_at_rev(
                        args.old_rev,
                        "bench_mechanism_records",
                        f"time_kernel({rtol!r}, {args.repeat})",
                    ),
                ),
            ):
                out = run()
                for key, r in out.items():
                    if key not in acc or r["scenes_per_s"] > acc[key]["scenes_per_s"]:
                        acc[key] = r
        print(f"rtol {rtol:g}, {N_SCENES} scenes per structure and record, one core (CPU time)")
        print(
            f"{'scene set':34s} {'new /s':>8s} {'old /s':>8s} {'x old':>6s} {'steps new/old':>14s}"
        )
        for key in new:
            n, o = new[key], old[key]
            results[f"{rtol:g}/{key}"] = {
                "new_scenes_per_s": n["scenes_per_s"],
                "old_scenes_per_s": o["scenes_per_s"],
                "speedup_vs_old": n["scenes_per_s"] / o["scenes_per_s"],
            }
            print(
                f"{key:34s} {n['scenes_per_s']:8.0f} {o['scenes_per_s']:8.0f} "
                f"{n['scenes_per_s'] / o['scenes_per_s']:6.2f} "
                f"{np.median(n['steps']):7.0f}/{np.median(o['steps']):.0f}"
            )
        for label, res in (("new", new), ("old", old)):
            tot = sum(N_SCENES / r["scenes_per_s"] for r in res.values())
            summary[f"{rtol:g}/{label}"] = {
                "scenes_per_s": len(res) * N_SCENES / tot,
                **errors(res, ref),
            }
        ratio = summary[f"{rtol:g}/new"]["scenes_per_s"] / summary[f"{rtol:g}/old"]["scenes_per_s"]
        summary[f"{rtol:g}/speedup_vs_old"] = ratio
        for label in ("new", "old"):
            s = summary[f"{rtol:g}/{label}"]
            print(
                f"  {label}: {s['scenes_per_s']:.0f} scenes/s/core overall, p99 error "
                f"{s['p99_rel_error']:.1e}, max {s['max_rel_error']:.1e}, disagreements "
                f"{s['disagreements']} of {s['compared']} compared"
            )
        print(f"  x{ratio:.2f} on the old kernel (total time of all scenes)", flush=True)
    summary["wall_s"] = time.perf_counter() - t_start
    meta = {
        "rtol": args.rtol,
        "scenes_per_structure_and_record": N_SCENES,
        "old_rev": args.old_rev,
        "timing": "CPU seconds of the process (time.process_time), best of repeats and rounds, "
        "1 thread",
        "machine": platform.processor() or platform.machine(),
        "load_average": os.getloadavg(),
    }
    OUT.mkdir(exist_ok=True)
    (OUT / "mechanism_records.json").write_text(
        json.dumps({"meta": meta, "scenes": results, "summary": summary}, indent=2)
    )


if __name__ == "__main__":
    main()
