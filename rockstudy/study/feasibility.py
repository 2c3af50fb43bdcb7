"""Checks of a valid study against the machine and the files it reads, before it runs.

The schema (:mod:`.spec`) checks what a study says; this module checks that it can work here:
every record file is a readable record, and the design and each sample fit in memory. Each
problem is one sentence naming the field, the quantity and what is allowed.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..motions.records import read_record

GIB = 2.0**30
#: Bytes per design row: the ~20 design columns, the unit samples and the outputs (8 bytes
#: each), the status and the error message.
_ROW_BYTES = 8 * 20 + 128
#: Arrays of one synthesized record held at once (noise, filtered, envelope, times, samples).
_STOCHASTIC_ARRAYS = 6
#: Share of the memory the design (client) and one sample (worker) may take.
DESIGN_SHARE, SAMPLE_SHARE = 0.5, 0.25


def machine_memory() -> float:
    """Physical memory of this machine [bytes]."""
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def design_bytes(study) -> float:
    """Estimated memory of the whole design and its result columns [bytes]."""
    per_row = _ROW_BYTES + 8 * (2 * len(study.parameters()) + len(study.run.outputs))
    return float(study.samples()) * per_row


def problems(study, base_dir=None) -> list[str]:
    """Why ``study`` cannot produce a finite result for every sample here (empty if it can)."""
    found = []
    memory = machine_memory()
    need = design_bytes(study)
    if need > DESIGN_SHARE * memory:
        where = "the grid sizes" if study.sampler.kind == "grid" else "sampler.n"
        found.append(
            f"sampler: the design has {study.samples():.4g} samples, about {need / GIB:.3g} GiB "
            f"in memory, more than {DESIGN_SHARE:.0%} of this machine's {memory / GIB:.3g} GiB; "
            f"reduce {where}"
        )
    mo, max_steps = study.motion, study.run.max_steps
    if mo.kind == "stochastic":
        points = mo.points()
        need = 8.0 * _STOCHASTIC_ARRAYS * points
        if need > SAMPLE_SHARE * memory:
            found.append(
                f"motion.duration: each sample synthesizes a record of {points:.4g} points "
                f"(duration / dt + 1), about {need / GIB:.3g} GiB per sample, more than "
                f"{SAMPLE_SHARE:.0%} of this machine's {memory / GIB:.3g} GiB; shorten duration "
                "or coarsen dt"
            )
        elif points > max_steps:
            found.append(_too_long("motion.duration", points, max_steps))
    elif mo.kind == "record":
        for i, name in enumerate(mo.files):
            field = f"motion.files[{i}]"
            path = record_path(name, base_dir)
            try:
                rec = read_record(path, mo.units)
            except (OSError, ValueError) as exc:
                found.append(f"{field}: {_reason(exc, path)}")
                continue
            if rec.acceleration.size > max_steps:
                found.append(_too_long(field, rec.acceleration.size, max_steps))
            if mo.pga_ratio is not None and not rec.peak > 0:
                found.append(
                    f"{field}: {path} is zero everywhere; pga_ratio cannot scale it "
                    "(give scale, or another record)"
                )
    return found


def _reason(exc, path) -> str:
    """The reader's message, which names the file; an OSError's reason without its bytes."""
    if isinstance(exc, OSError) and not isinstance(exc, FileNotFoundError):
        return f"{path}: cannot be read ({exc.strerror or type(exc).__name__})"
    return str(exc)


def _too_long(field, points, max_steps) -> str:
    return (
        f"{field}: the record has {points:.4g} samples, more than run.max_steps = {max_steps}; "
        "the solver ends a step on every record sample while the block rocks, so rocking "
        "samples would fail. Shorten the record or raise run.max_steps"
    )


def record_path(name: str, base_dir=None) -> Path:
    """Where a record file named in a study is read from.

    An absolute path is used as written (that is the explicit choice). A relative path is
    relative to ``base_dir``: the folder of the study file (:func:`load_study` and the command
    line), or the working folder for a study given as text. Nothing else is tried.
    """
    path = Path(name)
    if path.is_absolute():
        return path
    return Path(Path.cwd() if base_dir is None else base_dir) / path
