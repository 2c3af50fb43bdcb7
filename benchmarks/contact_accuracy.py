"""Accuracy of the contact model of ``simulate_batch(model="contact")`` against its scipy
reference on random record and pulse scenes.

Sources: the five real records of shared/records (``ROCKSTUDY_RECORDS`` to move it; those
absent are left out and named on stderr), the eight synthetic near-fault records shipped
with rockstudy (:mod:`rockstudy.motions.shipped`, with their vertical components), each cut to
``--window`` seconds from 2 s before its peak (the reference's cost grows with the samples
it crosses in motion), and sine, cosine and half-sine pulses (period 0.2-2 s). Scene i
takes source i mod 16 and draws R 0.3-3 m, alpha 0.05-0.5, mu 0.1-1.0 and a peak of
0.5-5 times g min(tan alpha, mu) from its own seed (seed, i): rest, slide, rock, slide-rock
and flight all occur (the counts are printed). Rows whose scaled vertical would fall below
-0.95 g are drawn again.

Two steps, so that a long measurement runs in the background and resumes:

``run``: the reference (``solve_ivp`` DOP853 with events at rtol 1e-12, through
:func:`rockstudy.dynamics.contact_model.contact_outputs`) of the scenes ``--scenes``, one
process, each appended to ``--out`` (JSON lines) as it ends; scenes already there are
skipped.

``report``: ``simulate_batch(model="contact")`` at each ``--rtol`` (by default 1e-8, its
default, and 1e-10) on every scene of ``--out``, against the stored reference. Printed per
rtol: percentiles of the errors of max |theta| and max |u| in units of rtol (relative to
max(|x|) + 1e-2 alpha, resp. 1e-2 R alpha: the floors of the kernel's flag,
:mod:`rockstudy.dynamics._contact_flag`), of the rows the batch returned as answers and of
all rows; the rows beyond 10 rtol, flagged (``status`` != 0) or not; the rows whose
decisions (overturned, lift-off, slipped, impact count) differ from the reference's, and
whether each lies in the threshold band (the reference's own decision changes when the
amplitude moves by 1e-9 of itself: cached in ``--out`` + ``.band``); and the fraction
flagged.

    nice -n 10 python benchmarks/contact_accuracy.py run --scenes 2000 --out acc.jsonl
    python benchmarks/contact_accuracy.py report --out acc.jsonl
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RECORDS = Path(os.environ.get("ROCKSTUDY_RECORDS") or ROOT.parent / "shared" / "records")
SHARED = (
    "RSN126_GAZLI_GAZ000.AT2",
    "RSN183_IMPVALL.H_H-E08140.AT2",
    "RSN948_NORTHR_CAM009.AT2",
    "RSN982_NORTHR_JEN292.AT2",
    "elcentro_NS.dat",
)
SHIPPED = 8
PULSES = ("sine", "cosine", "half-sine")
#: Relative change of the amplitude under which a decision of the reference that changes
#: lies in the threshold band (the conditioning step of the rocking model's output).
BAND = 1e-9
#: The floors of the relative errors, in units of alpha and R alpha (those of the kernel's
#: convergence flag).
FLOOR = 1e-2
REFERENCE_RTOL = 1e-12
OUTPUTS = [
    "max_rotation",
    "max_slide",
    "overturned",
    "lift_off",
    "first_slip_time",
    "n_impacts",
    "status",
    "time_slide",
    "time_slide_rock",
    "time_flight",
    "regime",
]


def window(t, a_h, a_v, seconds):
    """The record cut to ``seconds`` from 2 s before its peak (time from 0)."""
    k0 = max(0, int(np.searchsorted(t, t[np.argmax(np.abs(a_h))] - 2.0)))
    k1 = int(np.searchsorted(t, t[k0] + seconds))
    cut = slice(k0, max(k1, k0 + 2))
    return t[cut] - t[k0], a_h[cut], None if a_v is None else a_v[cut]


@functools.cache
def shared_paths():
    """The paths of the shared records (:data:`SHARED`) found in :data:`RECORDS`; those
    absent are named on stderr, once, with the folder they were looked for in."""
    found = [RECORDS / name for name in SHARED if (RECORDS / name).exists()]
    missing = [name for name in SHARED if not (RECORDS / name).exists()]
    if missing:
        print(
            f"{len(missing)} of the {len(SHARED)} shared records not found in {RECORDS} "
            f"(ROCKSTUDY_RECORDS moves it), left out: {', '.join(missing)}",
            file=sys.stderr,
        )
    return found


def record_counts(names):
    """'n records (r real, s shipped)' of the record ``names`` (pulses are not counted)."""
    names = list(names)
    real = sum(name in SHARED for name in names)
    shipped = sum(name not in SHARED and name not in PULSES for name in names)
    return f"{real + shipped} records ({real} real, {shipped} shipped)"


def records(seconds):
    """[(name, t, a_h, a_v or None)] of the shared records found (:func:`shared_paths`) and
    the shipped ones, windowed."""
    import rockstudy as rs
    from rockstudy.motions.shipped import write_shipped_suite

    out = []
    for path in shared_paths():
        name = path.name
        if name.endswith(".AT2"):
            rec = rs.motions.Record.from_at2(path)
        else:
            rec = rs.motions.Record.from_csv(path, units="g")
        out.append((name, np.asarray(rec.time), np.asarray(rec.acceleration), None))
    with tempfile.TemporaryDirectory() as folder:
        write_shipped_suite(folder)
        for h in sorted(Path(folder).glob("*_H.AT2"))[:SHIPPED]:
            rec = rs.motions.Record.from_at2(h)
            up = rs.motions.Record.from_at2(h.with_name(h.name.replace("_H.", "_UP.")))
            vertical = np.asarray(up.acceleration)
            out.append((h.stem, np.asarray(rec.time), np.asarray(rec.acceleration), vertical))
    return [(name, *window(t, a, v, seconds)) for name, t, a, v in out]


def record_motions(seconds):
    """{name: Record} of :func:`records`."""
    from rockstudy.motions import Record

    return {name: Record(a, time=t, vertical=v) for name, t, a, v in records(seconds)}


def sources(recs):
    """The scene sources in order: the records' names, then the pulses'."""
    return [*recs, *PULSES]


def scene(i, seed, names, recs):
    """Scene i: dict(i, source, R, alpha, mu, scale (a record's) or amplitude and period
    (a pulse's)), drawn from the seed (seed, i)."""
    from rockstudy.constants import G

    rng = np.random.default_rng([seed, i])
    source = names[i % len(names)]
    while True:
        alpha, radius, mu = rng.uniform(0.05, 0.5), rng.uniform(0.3, 3.0), rng.uniform(0.1, 1.0)
        peak = rng.uniform(0.5, 5.0) * G * min(math.tan(alpha), mu)
        row = {"i": i, "source": source, "R": radius, "alpha": alpha, "mu": mu}
        if source in PULSES:
            return {**row, "amplitude": peak, "period": rng.uniform(0.2, 2.0)}
        rec = recs[source]
        scale = peak / float(np.max(np.abs(rec.acceleration)))
        vertical = rec.vertical
        if vertical is None or scale * float(np.min(vertical)) > -0.95 * G:
            return {**row, "scale": scale}


def motion(row, recs, factor=1.0):
    """The Motion of a scene, its amplitude times ``factor``."""
    from rockstudy.motions.pulses import PULSES as KINDS

    if row["source"] in PULSES:
        return KINDS[row["source"]](amplitude=row["amplitude"] * factor, period=row["period"])
    return recs[row["source"]].scaled(row["scale"] * factor)


def reference(row, recs, factor=1.0):
    """The reference's outputs of a scene (:func:`contact_outputs`, method "scipy")."""
    from rockstudy.constants import G
    from rockstudy.dynamics.contact_model import contact_outputs

    p = math.sqrt(0.75 * G / row["R"])
    eta = 1.0 - 1.5 * math.sin(row["alpha"]) ** 2
    mu = (row["mu"], row["mu"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = contact_outputs(
            p, row["alpha"], eta, motion(row, recs, factor), mu, REFERENCE_RTOL, None, "scipy"
        )
    return {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in out.items()}


def done(path):
    """The stored lines of ``path`` (a list of dicts; none if it does not exist)."""
    if not Path(path).exists():
        return []
    lines = Path(path).read_text().splitlines()
    return [json.loads(line) for line in lines if line.strip()]


def run(args):
    """Append the reference of every scene below ``--scenes`` not yet in ``--out``."""
    recs = record_motions(args.window)
    names = sources(recs)
    print(f"sources: {record_counts(names)} and {len(PULSES)} pulses")
    if args.out.exists():  # a line cut by a stopped run is dropped
        text = args.out.read_text()
        args.out.write_text(text[: text.rfind("\n") + 1])
    have = {d["i"] for d in done(args.out)}
    with open(args.out, "a") as f:
        for i in range(args.scenes):
            if i in have:
                continue
            row = {**scene(i, args.seed, names, recs), "window": args.window}
            t0 = time.process_time()
            ref = reference(row, recs)
            row.update(ref=ref, cpu=time.process_time() - t0)
            f.write(json.dumps(row, default=float) + "\n")
            f.flush()


def batch(rows, recs, rtol):
    """``simulate_batch(model="contact")`` outputs of the rows (one source), as a dict."""
    import rockstudy as rs

    first = rows[0]
    common = {
        "half_diagonal": np.array([r["R"] for r in rows]),
        "slenderness": np.array([r["alpha"] for r in rows]),
        "friction": np.array([r["mu"] for r in rows]),
        "model": "contact",
        "rtol": rtol,
        "outputs": OUTPUTS,
    }
    if first["source"] in PULSES:
        motion_args = {
            "pulse": first["source"],
            "amplitude": np.array([r["amplitude"] for r in rows]),
            "period": np.array([r["period"] for r in rows]),
        }
    else:
        motion_args = {
            "record": recs[first["source"]],
            "scale": np.array([r["scale"] for r in rows]),
        }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.simulate_batch(**common, **motion_args)


def decisions(r):
    """(overturned, lift_off, slipped, impact count) of an output row."""
    slip = r["first_slip_time"]
    slipped = slip is not None and not math.isnan(slip)
    return (bool(r["overturned"]), bool(r["lift_off"]), slipped, int(r["n_impacts"]))


def errors(k, r, row):
    """(error of max |theta|, error of max |u|) relative to the reference (with floors)."""
    radius, alpha = row["R"], row["alpha"]
    e_theta = abs(k["max_rotation"] - r["max_rotation"]) / (abs(r["max_rotation"]) + FLOOR * alpha)
    e_u = abs(k["max_slide"] - r["max_slide"]) / (abs(r["max_slide"]) + FLOOR * radius * alpha)
    return e_theta, e_u


def in_band(row, recs, kernel_decisions, cache):
    """Whether the reference's decisions move to the kernel's, or change at all, when the
    amplitude moves by BAND of itself (cached by scene)."""
    key = str(row["i"])
    if key not in cache:
        moved = [decisions(reference(row, recs, 1 + s * BAND)) for s in (-1, 1)]
        cache[key] = [list(m) for m in moved]
    moved = [tuple(m) for m in cache[key]]
    base = decisions(row["ref"])
    return any(m != base or m == kernel_decisions for m in moved)


def quantiles(x, rtol):
    """Median, p90, p99, p99.9 and max of x, in units of rtol."""
    if not len(x):
        return "(none)"
    q = np.quantile(np.asarray(x) / rtol, [0.5, 0.9, 0.99, 0.999, 1.0])
    return "median {:.3g}  p90 {:.3g}  p99 {:.3g}  p99.9 {:.3g}  max {:.3g}".format(*q)


def windowed(rows):
    """{window: the records cut to it (:func:`record_motions`)} of the scenes ``rows``."""
    return {w: record_motions(w) for w in {row["window"] for row in rows}}


def measure(rows, recs, rtol):
    """{scene: its outputs (:data:`OUTPUTS`) by the batch at ``rtol``} (``recs``: of
    :func:`windowed`)."""
    by_source = {}
    for row in rows:
        by_source.setdefault((row["source"], row["window"]), []).append(row)
    found = {}
    for (_, window), group in by_source.items():
        out = batch(group, recs[window], rtol)
        for j, row in enumerate(group):
            k = {name: out[name][j] for name in OUTPUTS}
            found[row["i"]] = k
    return found


def regimes(r):
    """Which of slide, slide-rock, flight and rock a reference row entered."""
    rocked = r["max_rotation"] > 0 and not (r["time_slide_rock"] or r["time_flight"])
    return np.array(
        [r["time_slide"] > 0, r["time_slide_rock"] > 0, r["time_flight"] > 0, rocked], int
    )


def report_rtol(rows, recs, rtol, cache):
    """Print the measurement of one rtol."""
    t0 = time.perf_counter()
    found = measure(rows, recs, rtol)
    seconds = time.perf_counter() - t0
    errs, flagged, mismatched = [], [], []
    for row in rows:
        k, r = found[row["i"]], row["ref"]
        if r["status"] != 0:
            continue
        errs.append(errors(k, r, row))
        flagged.append(int(k["status"]) != 0)
        if decisions(k) != decisions(r) and int(k["status"]) == 0:
            band = in_band(row, recs[row["window"]], decisions(k), cache)
            mismatched.append((row, decisions(k), band))
    errs, flagged = np.array(errs), np.array(flagged)
    worst = errs.max(axis=1)
    beyond = worst > 10 * rtol
    print(f"\nrtol {rtol:g}: {len(errs)} scenes, batch {seconds:.1f} s")
    print(f"  flagged (status != 0): {flagged.sum()} ({100 * flagged.mean():.2f} %)")
    for label, keep in (("answers (status 0)", ~flagged), ("all rows", np.ones_like(flagged))):
        print(f"  {label}: max |theta| error / rtol: {quantiles(errs[keep, 0], rtol)}")
        print(f"  {label}: max |u| error / rtol:     {quantiles(errs[keep, 1], rtol)}")
    print(
        f"  beyond 10 rtol: {beyond.sum()} (flagged {(beyond & flagged).sum()}, "
        f"unflagged {(beyond & ~flagged).sum()})"
    )
    for row, e in zip((r for r in rows if r["ref"]["status"] == 0), worst, strict=True):
        if e > 10 * rtol and not found[row["i"]]["status"]:
            print(f"    unflagged: scene {row['i']} {row['source']} {e / rtol:.3g} rtol")
    bands = sum(m[-1] for m in mismatched)
    print(f"  decisions differing (status 0): {len(mismatched)}, in the threshold band: {bands}")
    for row, kd, band in mismatched:
        print(f"    scene {row['i']} {row['source']}: kernel {kd} reference "
              f"{decisions(row['ref'])} band {band}")  # fmt: skip


def report(args):
    """Print the measurement of every rtol over the stored scenes."""
    rows = done(args.out)
    for row in rows:  # the scenes stored before windows were recorded: 8 s
        row.setdefault("window", 8.0)
    recs = windowed(rows)
    band_path = Path(str(args.out) + ".band")
    cache = json.loads(band_path.read_text()) if band_path.exists() else {}
    incomplete = sum(r["ref"]["status"] != 0 for r in rows)
    counts = sum((regimes(r["ref"]) for r in rows), np.zeros(4, int))
    cpu = sum(r["cpu"] for r in rows)
    print(
        f"{len(rows)} scenes ({sum(r['source'] in PULSES for r in rows)} pulses; on "
        f"{record_counts({r['source'] for r in rows})}), reference "
        f"rtol {REFERENCE_RTOL:g}: {cpu:.0f} CPU s; {incomplete} stopped at the reference's "
        "cap of phases (left out)"
    )
    print(f"  scenes entering slide, slide-rock, flight; rocking only: {counts.tolist()}")
    for rtol in args.rtol:
        report_rtol(rows, recs, rtol, cache)
    band_path.write_text(json.dumps(cache))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("step", choices=("run", "report"))
    parser.add_argument("--scenes", type=int, default=2000)
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-8, 1e-10])
    parser.add_argument("--window", type=float, default=8.0)
    parser.add_argument("--seed", type=int, default=36)
    parser.add_argument("--out", type=Path, default=Path("contact_accuracy.jsonl"))
    args = parser.parse_args()
    (run if args.step == "run" else report)(args)


if __name__ == "__main__":
    main()
