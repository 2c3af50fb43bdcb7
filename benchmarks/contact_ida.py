"""An IDA study under the contact model: wall time of 8 records x 6 objects with friction.

The eight synthetic near-fault records shipped with rockstudy (data/records, with their
vertical components) against six museum objects, stocky ones that slide (mu < tan alpha)
and slender ones that rock (mu 0.3-0.8), in an IDA study (``[design] kind = "ida"``, the
default ladder, ``slide_limits = [0.05, 0.10]``) run by :func:`rockstudy.study.run_study` on
its default local cluster (``--workers`` processes of one thread), once under
``[run] model = "auto"`` and once under ``"contact"``. Prints the wall time of each run
(cluster start included) and the capacities found; the target is under 2 minutes on 2 cores.

    python benchmarks/contact_ida.py [--workers 2] [--step 0.01]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

RECORDS = Path(__file__).resolve().parent.parent / "data" / "records"
#: name, R [m], alpha [rad], mu: three stocky objects (mu < tan alpha) and three slender ones.
OBJECTS = """name,half_diagonal,slenderness,friction
Amphora,0.6,0.30,0.30
Bronze,0.5,0.40,0.35
Cabinet,1.5,0.45,0.45
Vase,0.4,0.25,0.50
Statue,1.2,0.15,0.60
Stele,1.0,0.12,0.80
"""
STUDY = """
name = "contact_ida_{model}"
seed = 1
[structure]
kind = "objects"
file = "objects.csv"
[motion]
kind = "record"
files = "{records}/*_H.AT2"
units = "g"
vertical = {{ match = '_H\\.AT2$', replace = "_UP.AT2" }}
[design]
kind = "ida"
im = "pga"
step = {step}
slide_limits = [0.05, 0.10]
[run]
model = "{model}"
"""


def run(model, step, workers, folder):
    """Wall seconds of the IDA study under ``model``, and its result."""
    from rockstudy.study import load_study, run_study
    from rockstudy.study.running.store import open_result

    path = folder / f"ida_{model}.toml"
    path.write_text(STUDY.format(model=model, records=RECORDS, step=step))
    study = load_study(path)
    t0 = time.perf_counter()
    run_study(study, folder / f"{model}.zarr", workers=workers, progress=False, netcdf=False)
    seconds = time.perf_counter() - t0
    return seconds, open_result(folder / f"{model}.zarr").load()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--step", type=float, default=0.01)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "objects.csv").write_text(OBJECTS)
        for model in ("auto", "contact"):
            seconds, ds = run(model, args.step, args.workers, folder)
            cap = ds["capacity"].values
            slides = ds["slide_capacity"].values
            print(
                f"model={model}: {ds.sizes['record']} records x {ds.sizes['structure']} objects "
                f"in {seconds:.1f} s wall ({args.workers} workers), "
                f"{int(ds.attrs['n_simulations'])} simulations; capacities found "
                f"{int(np.isfinite(cap).sum())}/{cap.size}, slide capacities "
                f"{int(np.isfinite(slides).sum())}/{slides.size}"
            )


if __name__ == "__main__":
    main()
