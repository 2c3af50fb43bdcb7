"""The synthetic near-fault records shipped in ``data/records``, and the script that writes them.

``python -m rockstudy.motions.shipped --write data/records`` regenerates the files bit for bit
(same seeds, same numbers, same text), so studies and tests run on realistic records in a
clone that has no ``../shared``. They are PEER ``.AT2`` files with a header that says they are
synthetic and gives the generator, the seed and the parameters.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..constants import STANDARD_GRAVITY as G_UNIT
from .synthetic import synthetic_near_fault

__all__ = [
    "at2_text",
    "SHIPPED_DT",
    "SHIPPED_SUITE",
    "shipped_suite_texts",
    "SHIPPED_VERTICAL_RULE",
    "write_shipped_suite",
]

#: The synthetic near-fault suite shipped in ``data/records`` (no download needed): name,
#: pulse period T_p [s], PGA [g] and seed of each record, each with a vertical component.
SHIPPED_SUITE = (
    ("NF01", 0.4, 0.45, 101),
    ("NF02", 0.6, 0.40, 102),
    ("NF03", 0.8, 0.50, 103),
    ("NF04", 1.0, 0.35, 104),
    ("NF05", 1.3, 0.45, 105),
    ("NF06", 1.7, 0.40, 106),
    ("NF07", 2.2, 0.50, 107),
    ("NF08", 3.0, 0.35, 108),
)
#: Time step [s] of the shipped records (they need T_p > 20 dt = 0.2 s).
SHIPPED_DT = 0.01
#: H/V pairing of the shipped files for :func:`rockstudy.motions.load_suite` (``vertical=``).
SHIPPED_VERTICAL_RULE = (r"_H\.AT2$", "_UP.AT2")


def at2_text(acceleration_g, dt: float, title: str, description: str) -> str:
    """A PEER NGA ``.AT2`` file's text: four header lines, then the values in g, five a line.

    Parameters
    ----------
    acceleration_g : array_like
        Acceleration [g].
    dt : float
        Time step [s].
    title, description : str
        Header lines 1 and 2 (one line each).
    """
    values = np.asarray(acceleration_g, dtype=float)
    for name, line in (("title", title), ("description", description)):
        if "\n" in line or "\r" in line:
            raise ValueError(f"{name} must be one line")
    rows = ["".join(f"{v:15.7E}" for v in values[i : i + 5]) for i in range(0, values.size, 5)]
    header = [
        title,
        description,
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS= {values.size:7d}, DT= {dt:9.4f} SEC",
    ]
    return "\n".join(header + rows) + "\n"


def shipped_suite_texts() -> dict[str, str]:
    """File name -> text of every file of the shipped suite (:data:`SHIPPED_SUITE`).

    Each record ``NAME`` gives ``NAME_TpX.XXs_H.AT2`` (horizontal, the pulse) and
    ``NAME_TpX.XXs_UP.AT2`` (vertical); the headers say they are synthetic and give the
    generator, the seed and the parameters.
    """
    texts = {}
    for name, period, pga_g, seed in SHIPPED_SUITE:
        rec = synthetic_near_fault(
            pulse_period=period, pga=pga_g * G_UNIT, seed=seed, vertical=True, dt=SHIPPED_DT
        )
        call = (
            f"rockstudy.motions.synthetic_near_fault(pulse_period={period!r}, "
            f"pga={pga_g!r}*g, seed={seed!r}, vertical=True, dt={SHIPPED_DT!r}; "
            "other arguments default)"
        )
        stem = f"{name}_Tp{period:.2f}s"
        for part, values, what in (
            ("H", rec.acceleration, "horizontal (pulse)"),
            ("UP", rec.vertical, "vertical"),
        ):
            texts[f"{stem}_{part}.AT2"] = at2_text(
                values / G_UNIT,
                SHIPPED_DT,
                f"SYNTHETIC near-fault record {name}, {what}: not a recording "
                f"(python -m rockstudy.motions.shipped --write data/records)",
                call,
            )
    return texts


def write_shipped_suite(folder) -> list:
    """Write the shipped suite into ``folder`` (created if missing); return the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, text in shipped_suite_texts().items():
        path = folder / name
        path.write_bytes(text.encode("ascii"))
        paths.append(path)
    return paths


def _main(argv=None) -> int:
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m rockstudy.motions.shipped",
        description="Regenerate the shipped synthetic near-fault records (bit for bit).",
    )
    parser.add_argument("--write", metavar="FOLDER", required=True, help="e.g. data/records")
    args = parser.parse_args(argv)
    for path in write_shipped_suite(args.write):
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(_main())
