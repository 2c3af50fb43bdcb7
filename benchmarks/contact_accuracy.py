"""Accuracy of the contact model's kernel against its scipy reference on random record scenes.

Records: the five real ones of shared/records (``ROCKSTUDY_RECORDS`` to move it) and the eight
synthetic near-fault records shipped with rockstudy (:mod:`rockstudy.motions.shipped`, with
their vertical components), each cut to ``--window`` seconds around its peak (the
reference's cost grows with the samples it crosses in motion). Scenes: R 0.3-3 m, alpha
0.05-0.5, mu 0.1-1.0, the record scaled to a peak of 0.8-4 times g min(tan alpha, mu) (rows
whose scaled vertical would fall below -0.95 g are drawn again). The kernel
(:func:`rockstudy.dynamics._contact_scene.contact_batch`, exact sliding where mu < tan
alpha) runs at ``--rtol`` (1e-10), the reference (``solve_ivp`` DOP853 with events) at
1e-12. Printed: the distribution of the relative errors of max |theta| and max |u| (over
max(|x|) + 1e-2 alpha, resp. 1e-2 R alpha: see FLOOR), in units of rtol; the scenes whose
decisions (overturned, lift-off, slipped, impact count) differ, and whether each lies in the
threshold band (the reference's decision flips when the amplitude moves by 1e-6 of itself);
the scenes the kernel flagged (status != 0, or not ``converged``); and, of the scenes beyond
10 rtol, those that are ill-conditioned (the kernel's own answer moves by more than the error
when the amplitude moves by 1e-9 of itself: the reference at rtol 1e-12 cannot be closer than
that).

    python benchmarks/contact_accuracy.py [--scenes 2000] [--rtol 1e-10] [--window 8]
"""

from __future__ import annotations

import argparse
import math
import os
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
BAND = 1e-6
#: The floors of the relative errors, in units of alpha and R alpha: at rtol 1e-10, 10 rtol of
#: them is ten times the reference's absolute tolerances (1e-12 alpha, 1e-12 R alpha), its
#: error floor (the measure of tests/test_contact_kernel.py).
FLOOR = 1e-2


def window(t, a_h, a_v, seconds):
    """The record cut to ``seconds`` from 2 s before its peak (time from 0)."""
    k0 = max(0, int(np.searchsorted(t, t[np.argmax(np.abs(a_h))] - 2.0)))
    k1 = int(np.searchsorted(t, t[k0] + seconds))
    cut = slice(k0, max(k1, k0 + 2))
    return t[cut] - t[k0], a_h[cut], None if a_v is None else a_v[cut]


def records(seconds):
    """[(name, t, a_h, a_v or None)] of the shared and the shipped records, windowed."""
    import rockstudy as rs
    from rockstudy.motions.shipped import write_shipped_suite

    out = []
    for name in SHARED:
        path = RECORDS / name
        if not path.exists():
            continue
        if name.endswith(".AT2"):
            rec = rs.motions.Record.from_at2(path)
        else:
            rec = rs.motions.Record.from_csv(path, units="g")
        out.append((name, np.asarray(rec.time), np.asarray(rec.acceleration), None))
    with tempfile.TemporaryDirectory() as folder:
        write_shipped_suite(folder)
        for h in sorted(Path(folder).glob("*_H.AT2")):
            rec = rs.motions.Record.from_at2(h)
            up = rs.motions.Record.from_at2(h.with_name(h.name.replace("_H.", "_UP.")))
            out.append(
                (
                    h.stem,
                    np.asarray(rec.time),
                    np.asarray(rec.acceleration),
                    np.asarray(up.acceleration),
                )
            )
    return [(name, *window(t, a, v, seconds)) for name, t, a, v in out]


def scenes(rng, n, a_h, a_v):
    """n random rows (R, alpha, mu, scale) for one record."""
    from rockstudy.constants import G

    rows = []
    while len(rows) < n:
        alpha, radius, mu = rng.uniform(0.05, 0.5), rng.uniform(0.3, 3.0), rng.uniform(0.1, 1.0)
        peak = rng.uniform(0.8, 4.0) * G * min(math.tan(alpha), mu)
        scale = peak / np.max(np.abs(a_h))
        if a_v is not None and scale * np.min(a_v) <= -0.95 * G:
            continue
        rows.append((radius, alpha, mu, scale))
    return np.array(rows)


def kernel_rows(t, a_h, a_v, rows, rtol):
    """The kernel's batch rows and its CPU seconds."""
    from rockstudy.constants import G
    from rockstudy.dynamics._contact_scene import contact_batch
    from rockstudy.motions import Record

    rec = Record(a_h, time=t, vertical=a_v)
    kind, _, times, samples, vsamples = rec.kernel_spec()
    radius, alpha, mu, scale = rows.T
    n = len(rows)
    mp = np.column_stack([scale, np.zeros(n), np.zeros(n), np.full(n, rec.duration)])
    eta = 1.0 - 1.5 * np.sin(alpha) ** 2
    p = np.sqrt(0.75 * G / radius)
    t0 = time.process_time()
    out = contact_batch(p, alpha, eta, mu, mu, (kind, mp, times, samples, vsamples), rtol)
    return out, time.process_time() - t0


def reference(t, a_h, a_v, row, factor=1.0):
    """The reference's result of one row, its amplitude times ``factor``."""
    from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
    from rockstudy.motions import Record

    radius, alpha, mu, scale = row
    s = scale * factor
    rec = Record(s * a_h, time=t, vertical=None if a_v is None else s * a_v)
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate_contact_reference(radius, alpha, eta, rec, mu, mu, 1e-12)


def decisions(r):
    """(overturned, lift_off, slipped, impacts) of a kernel row or a reference dict."""
    n = int(r["n_impacts"]) if "n_impacts" in r else len(r["impact_times"])
    return (bool(r["overturned"]), bool(r["lift_off"]), not math.isnan(r["first_slip_time"]), n)


def compare(k, r, row):
    """(error of max |theta|, error of max |u|) relative to the reference (with floors)."""
    radius, alpha = row[0], row[1]
    e_theta = abs(k["max_rotation"] - r["max_rotation"]) / (abs(r["max_rotation"]) + FLOOR * alpha)
    e_u = abs(k["max_slide"] - r["max_slide"]) / (abs(r["max_slide"]) + FLOOR * radius * alpha)
    return e_theta, e_u


#: Relative change of the amplitude that measures a scene's conditioning (as the batch output
#: ``conditioning`` of the rocking model does).
CONDITIONING = 1e-9


def conditioning(t, a_h, a_v, row, k, rtol):
    """The relative change of the kernel's max |theta| and max |u| (the larger) when the
    amplitude moves by CONDITIONING."""
    moved = row.copy()
    moved[3] *= 1.0 + CONDITIONING
    out, _ = kernel_rows(t, a_h, a_v, moved[None, :], rtol)
    return max(compare(k, {f: out[f][0] for f in out.dtype.names}, row))


def quantiles(x, rtol):
    """Median, p90, p99 and max of x, in units of rtol."""
    x = np.asarray(x) / rtol
    q = np.quantile(x, [0.5, 0.9, 0.99, 1.0])
    return f"median {q[0]:.3g}  p90 {q[1]:.3g}  p99 {q[2]:.3g}  max {q[3]:.3g}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=2000)
    parser.add_argument("--rtol", type=float, default=1e-10)
    parser.add_argument("--window", type=float, default=8.0)
    parser.add_argument("--seed", type=int, default=36)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    recs = records(args.window)
    per = -(-args.scenes // len(recs))
    errs, mismatched, flagged, regimes, conds = [], [], 0, np.zeros(5), []
    unconverged = []  # (beyond 10 rtol, flagged not converged) of each scene compared
    cpu_k = cpu_r = 0.0
    for name, t, a_h, a_v in recs:
        rows = scenes(rng, per, a_h, a_v)
        out, seconds = kernel_rows(t, a_h, a_v, rows, args.rtol)
        cpu_k += seconds
        for i, row in enumerate(rows):
            k = {f: out[f][i] for f in out.dtype.names}
            if k["status"] != 0:
                flagged += 1
                continue
            t0 = time.process_time()
            r = reference(t, a_h, a_v, row)
            cpu_r += time.process_time() - t0
            errs.append(compare(k, r, row))
            unconverged.append((max(errs[-1]) > 10 * args.rtol, not k["converged"]))
            if max(errs[-1]) > 10 * args.rtol:
                conds.append(max(errs[-1]) <= conditioning(t, a_h, a_v, row, k, args.rtol))
            regimes += [
                k[f"time_{x}"] > 0 for x in ("rest", "slide", "rock", "slide_rock", "flight")
            ]
            if decisions(k) != decisions(r):
                band = any(
                    decisions(reference(t, a_h, a_v, row, 1 + s * BAND)) == decisions(k)
                    for s in (-1, 1)
                )
                mismatched.append((name, i, decisions(k), decisions(r), band))
        print(f"{name}: {len(rows)} scenes, {t.size} samples", flush=True)
    errs = np.array(errs)
    print(f"\n{len(errs)} scenes compared, kernel rtol {args.rtol:g}, reference rtol 1e-12")
    print("scenes entering rest, slide, rock, slide-rock, flight:", regimes.astype(int).tolist())
    print("max |theta| error / rtol:", quantiles(errs[:, 0], args.rtol))
    print("max |u| error / rtol:    ", quantiles(errs[:, 1], args.rtol))
    beyond = (errs > 10 * args.rtol).sum(axis=0)
    print(
        f"beyond 10 rtol: theta {beyond[0]}, u {beyond[1]} ({len(conds)} scenes, of which "
        f"{sum(conds)} ill-conditioned: the kernel's answer moves more than that error when "
        f"the amplitude moves by {CONDITIONING:g})"
    )
    print(
        f"decisions differing: {len(mismatched)} "
        f"(in the threshold band: {sum(m[-1] for m in mismatched)})"
    )
    for m in mismatched:
        print("   ", m)
    print(f"flagged by the kernel (status != 0): {flagged}")
    beyond_flag = np.array(unconverged, dtype=bool).reshape(-1, 2)
    print(
        f"flagged not converged (status 0): {beyond_flag[:, 1].sum()}, of which beyond 10 rtol: "
        f"{(beyond_flag[:, 0] & beyond_flag[:, 1]).sum()} (of {beyond_flag[:, 0].sum()})"
    )
    print(f"CPU: kernel {cpu_k:.1f} s, reference {cpu_r:.1f} s")


if __name__ == "__main__":
    main()
