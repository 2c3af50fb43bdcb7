"""Outputs of the kernels over a broad set of scenes, for a bit-identity check of a refactoring.

``python bit_identity.py dump OUT.npz`` computes them with the rockstudy on the path;
``python bit_identity.py compare A.npz B.npz`` compares every array of A with B's
(np.array_equal, NaN equal) and prints the count; arrays new in B (an added output) are
listed. Run ``dump`` once per tree (PYTHONPATH=tree), then ``compare``.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np


def _batch_cases(rs, out):
    from rockstudy.motions import Record, stochastic_record

    rng = np.random.default_rng(7)
    n = 300
    R = rng.uniform(0.3, 8.0, n)
    alpha = rng.uniform(0.05, 0.4, n)
    amp_ratio = rng.uniform(0.8, 4.0, n)
    tp = rng.uniform(0.2, 2.0, n)
    rec = stochastic_record(3.0, duration=8.0, seed=3)
    vert = Record(rec.acceleration, dt=rec.dt, vertical=0.3 * np.roll(rec.acceleration, 37))
    for method in ("nonlinear", "linear", "auto"):
        for pulse in ("sine", "cosine", "half-sine", "ricker"):
            res = rs.simulate_batch(
                half_diagonal=R,
                slenderness=alpha,
                pulse=pulse,
                amplitude=amp_ratio * 9.81 * np.tan(alpha),
                period=tp,
                method=method,
            )
            for k, v in res.items():
                out[f"batch/{method}/{pulse}/{k}"] = np.asarray(v)
        for name, record in (("stoch", rec), ("stoch_vertical", vert)):
            scale = rng.uniform(0.3, 2.0, n)
            res = rs.simulate_batch(
                half_diagonal=R, slenderness=alpha, record=record, scale=scale, method=method
            )
            for k, v in res.items():
                out[f"batch/{method}/{name}/{k}"] = np.asarray(v)


def _result(out, key, r):
    for f in (
        "t",
        "theta",
        "theta_dot",
        "impact_times",
        "peak_times",
        "peak_rotations",
        "t_eval",
        "theta_eval",
        "theta_dot_eval",
    ):
        v = getattr(r, f)
        if v is not None:
            out[f"{key}/{f}"] = np.asarray(v)
    out[f"{key}/scalars"] = np.array(
        [r.max_rotation, float(r.overturned), r.overturn_time, r.n_impacts]
    )


def _simulate_cases(rs, out):
    from rockstudy.motions import (
        CosinePulse,
        HalfSinePulse,
        Record,
        RickerWavelet,
        SinePulse,
        stochastic_record,
    )
    from rockstudy.structures import PointMassStrut, RockingWall

    rec = stochastic_record(3.0, duration=6.0, seed=5)
    vert = Record(rec.acceleration, dt=rec.dt, vertical=0.3 * np.roll(rec.acceleration, 11))
    block = rs.Block(half_diagonal=1.2, slenderness=0.2)
    a = 9.81 * np.tan(0.2)
    motions = {
        "sine": SinePulse(amplitude=2.5 * a, period=0.8),
        "cosine": CosinePulse(amplitude=3.0 * a, period=1.0),
        "halfsine": HalfSinePulse(amplitude=4.0 * a, period=0.6),
        "ricker": RickerWavelet(amplitude=3.0 * a, period=0.7),
        "stoch": rec,
        "stoch_vertical": vert,
    }
    t_eval = np.linspace(0.0, 5.0, 97)
    for name, m in motions.items():
        for method in ("nonlinear", "linear", "auto"):
            r = rs.simulate(block, m, method=method, t_eval=t_eval)
            _result(out, f"sim/{name}/{method}", r)
        r = rs.simulate(block, m, initial_rotation=0.05, t_max=8.0)
        _result(out, f"sim/{name}/from_rotation", r)
    for sname, st in (("strut", PointMassStrut(1.0, 0.2)), ("wall", RockingWall(1.0, 0.15, 0.9))):
        for name in ("sine", "stoch", "stoch_vertical"):
            r = rs.simulate(st, motions[name], method="mechanism", t_eval=t_eval)
            _result(out, f"mech/{sname}/{name}", r)
    r = rs.simulate(block, motions["sine"], method="scipy")
    _result(out, "sim/sine/scipy", r)
    r = rs.simulate(block, motions["sine"], method="complex", rtol=1e-6)
    _result(out, "sim/sine/complex", r)


def dump(path):
    import rockstudy as rs

    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _batch_cases(rs, out)
        _simulate_cases(rs, out)
    np.savez(path, **out)
    print(rs.__file__, len(out), "arrays")


def _equal(a, b):
    """Arrays equal bit for bit, NaN equal to NaN (any dtype)."""
    if a.dtype.kind in "fc":
        return np.array_equal(a, b, equal_nan=True)
    return np.array_equal(a, b)


def compare(a, b):
    """Compare every array of A with B's; B may add arrays (a new output), listed apart, but
    not lack any of A's."""
    x, y = np.load(a), np.load(b)
    missing = sorted(set(x.files) - set(y.files))
    if missing:
        print("missing from B:", missing)
        return 1
    added = sorted(set(y.files) - set(x.files))
    if added:
        print(f"new in B (not compared): {len(added)}", added[:20])
    bad = [k for k in x.files if not _equal(x[k], y[k])]
    n_values = sum(x[k].size for k in x.files)
    print(f"{len(x.files)} arrays ({n_values} values): {len(bad)} differ", bad[:20])
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        dump(sys.argv[2])
    else:
        sys.exit(compare(sys.argv[2], sys.argv[3]))
