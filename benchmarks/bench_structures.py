"""Equivalent-structure benchmark (issue 4): the arch's rocking parameters (hinge search
included) and the cost per scene of the full mechanism kernel against the block kernel, on the
same sine pulses. Prints medians and writes benchmarks/results/structures.json.

    python benchmarks/bench_structures.py
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numba
import numpy as np
from numba import njit

from rockstudy.constants import FALL_ROTATION, G
from rockstudy.dynamics import _rocking
from rockstudy.dynamics._structure_tables import structure_table
from rockstudy.motions.pulses import pulse_kernel_rows
from rockstudy.structures import Arch, RockingWall, SymmetricFrame

OUT = Path(__file__).parent / "results"


@njit
def _run(p, alpha, eta, model, kind, mp, fall, tab):
    z = np.zeros(2)
    log = (np.empty((0, 3)), np.empty(0), np.empty((0, 2)), np.empty((0, 3)))
    acc = 0.0
    for i in range(mp.shape[0]):
        r = _rocking.scene(
            p,
            alpha,
            eta,
            model,
            (kind, mp[i], z, z, z[:0]),
            1e-8,
            True,
            np.inf,
            log,
            10**6,
            0.0,
            0.0,
            fall,
            tab,
        )
        acc += r[1]
    return acc


def per_scene(structure, n=2000, repeat=5):
    rp = structure.rocking_parameters()
    tab, fall = structure_table(structure)
    rng = np.random.default_rng(0)
    amp = rng.uniform(1.05, 4.0, n) * G * rp.uplift
    kind, mp = pulse_kernel_rows("sine", amp, rng.uniform(0.2, 2.0, n))
    out = {}
    for label, model, p, alpha, fl, tb in (
        (
            "block_kernel",
            _rocking.MODEL_NONLINEAR,
            rp.frequency_parameter,
            rp.uplift,
            FALL_ROTATION,
            _rocking.NO_TABLE,
        ),
        (
            "mechanism_kernel",
            _rocking.MODEL_TABLE,
            rp.frequency_parameter,
            rp.critical_rotation,
            fall,
            tab,
        ),
    ):
        _run(p, alpha, 0.9, model, kind, mp[:5], fl, tb)
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            _run(p, alpha, 0.9, model, kind, mp, fl, tb)
            times.append(time.perf_counter() - t0)
        out[label] = float(np.median(times)) / n * 1e6
    out["ratio"] = out["mechanism_kernel"] / out["block_kernel"]
    return out


def main():
    numba.set_num_threads(1)
    result = {}
    times = []
    for _ in range(7):
        t0 = time.perf_counter()
        arch = Arch(math.pi, 0.75, 5.0, restitution=0.9)
        arch.rocking_parameters()
        times.append(time.perf_counter() - t0)
    result["arch_rocking_parameters_ms"] = float(np.median(times)) * 1e3
    for name, s in (
        ("wall", RockingWall(1.0, 0.1, restitution=0.85)),
        ("frame", SymmetricFrame(1.0, 0.15, 0.5)),
        ("arch", Arch(math.pi, 0.75, 5.0, restitution=0.9)),
    ):
        result[f"{name}_us_per_scene"] = per_scene(s)
    OUT.mkdir(exist_ok=True)
    (OUT / "structures.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
