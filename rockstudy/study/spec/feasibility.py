"""Checks of a valid study against the machine and the files it reads, before it runs.

The schema (:mod:`.schema`) checks what a study says; this module checks that it can work here:
every record file is a readable record, and the design and each sample fit in memory. Each
problem is one sentence naming the field, the quantity and what is allowed.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..._validate import DESIGN_SHARE, GIB, MAX_ACCELERATION, SAMPLE_SHARE, machine_memory
from ...constants import G
from ...motions import measures
from ...motions.suites import read_pair, suite_pairs, units_refusal
from ...risk import suite_off_curve
from ...structures.block import uplift_acceleration_block
from .design_kinds import design_kind
from .structures import KINDS

__all__ = [
    "DEFAULT_MAX_SCALE_FACTOR",
    "design_bytes",
    "draw_span",
    "free_fall_scale",
    "hazard_notes",
    "LARGE_OBJECT",
    "MAX_CHUNK_ROWS",
    "notes",
    "problems",
    "read_problems",
    "record_pairs",
    "second_file",
    "record_path",
    "size_notes",
    "UPLIFT_NOTE_GAP",
    "uplift_notes",
    "vertical_refusal",
]

#: Most rows of one chunk (one dask task): 10^7 rows hold about 3 GB.
MAX_CHUNK_ROWS = 10**7
#: Default of ``[design] max_scale_factor`` (and the bound of Monte Carlo rows scaled to a
#: target): larger scale factors are noted by validate.
DEFAULT_MAX_SCALE_FACTOR = 5.0

#: each), the status and the error message.
_ROW_BYTES = 8 * 20 + 128
#: Arrays of one synthesized record held at once (noise, filtered, envelope, times, samples).
_STOCHASTIC_ARRAYS = 6


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
    rows = min(study.rows_per_chunk(), study.samples())
    if study.design is None and rows > MAX_CHUNK_ROWS:
        found.append(
            f"chunk_size: each chunk would hold {rows:.4g} rows (min(chunk_size, n)), more "
            f"than the {MAX_CHUNK_ROWS:.0e} one dask task takes (about 3 GB); lower chunk_size"
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
        try:
            pairs = record_pairs(mo, base_dir)
        except ValueError as exc:
            return [*found, str(exc)]
        found += _units_problem(mo, pairs) + _record_problems(study, pairs)
        if study.design is not None:
            found += _named_twice(pairs)
        refusal = None if all(v is None for _, _, v in pairs) else vertical_refusal()
        if refusal:
            found.append(f"motion.vertical: {refusal}; give horizontal records only")
        if study.design is not None:
            rows = study.samples() * len(pairs)
            need = rows * (_ROW_BYTES + 8 * (30 + len(study.design.periods)))
            if need > DESIGN_SHARE * memory:
                found.append(
                    f"sampler.n: the design has {len(pairs)} records x {study.samples():.4g} "
                    f"structures and levels, about {need / GIB:.3g} GiB in memory, more than "
                    f"{DESIGN_SHARE:.0%} of this machine's {memory / GIB:.3g} GiB; reduce it"
                )
    return found


def notes(study, base_dir=None) -> list[str]:
    """What a runnable study will do that its author should know before the run: the records
    of a design whose vertical component reaches free fall (u_v'' = -g, where the block
    model no longer holds) at a scale the design reaches (those points are stored as
    censored, with their reason; the record's other points run); records scaled by more than
    ``design.max_scale_factor``; and targets so low that nothing can rock
    (:func:`_scaling_notes`); named objects larger than any rocking object
    (:func:`size_notes`); and structures whose equivalent block, which the study
    simulates, lifts off far from the structure's own uplift acceleration
    (:func:`uplift_notes`)."""
    mo = study.motion
    if mo.kind != "record":
        return uplift_notes(study) + size_notes(study)
    found = uplift_notes(study) + size_notes(study) + _scaling_notes(study, base_dir)
    found += hazard_notes(study, base_dir)
    if study.design is None:
        return found
    for field, h, v in record_pairs(mo, base_dir):
        if v is None:
            continue
        vfield = field.replace("files", "vertical") if isinstance(mo.vertical, list) else field
        rec = read_pair(h, v, mo.units, field, vfield, h2=second_file(mo, h))
        scaled = _largest_scaled_peak(study, rec)
        if scaled is None:
            continue
        peak = max(float(np.max(np.abs(rec.acceleration))), float(np.max(np.abs(rec.vertical))))
        free_fall, top = free_fall_scale(rec), scaled[1] / peak
        if top >= free_fall:
            found.append(
                f"{vfield}: {v.name} reaches free fall (u_v'' = -g) at scale {free_fall:.4g}, "
                f"and {scaled[0]} scales the pair up to {top:.4g}: the design's points at or "
                "above free fall are stored as censored (reason: free fall); the others run"
            )
    return found


#: Relative gap between g tan(theta_cr) of the equivalent block and the structure's uplift
#: acceleration g lambda above which validate notes it (a wall of alpha 0.1 reaches 1 %).
UPLIFT_NOTE_GAP = 0.01


def uplift_notes(study) -> list[str]:
    """The structures whose equivalent block (what the study simulates: p, theta_cr, eta)
    lifts off at g tan(theta_cr) more than :data:`UPLIFT_NOTE_GAP` away from the structure's
    own uplift acceleration a_up (g lambda, eq. 10 of [003]), which the ratios, the IDA's
    ladder, the notes and the reports use: between the two levels the simulated response is
    the block's, not the structure's."""
    st = study.structure
    if st.kind == "objects":
        found = []
        for i, o in enumerate(st.objects):
            eq, a_up = float(uplift_acceleration_block(o.rocking()[1])), o.uplift()
            if abs(eq / a_up - 1.0) > UPLIFT_NOTE_GAP:
                found.append(_uplift_note(f"structure.objects[{i}] ({o.name!r})", o.kind, eq, a_up))
        return found
    if st.kind == "equivalent_block":  # a block: it is what runs
        return []
    ends = np.array(draw_span(st.slenderness))
    _, theta_cr, a_up = KINDS[st.kind].sampled(np.ones(2), ends)
    eq = uplift_acceleration_block(theta_cr)
    gap = np.abs(eq / a_up - 1.0)
    j = int(np.argmax(gap))
    if gap[j] <= UPLIFT_NOTE_GAP:
        return []
    return [_uplift_note("structure.slenderness", st.kind, float(eq[j]), float(a_up[j]))]


#: Half-diagonal [m] of an equivalent block above which validate asks whether the sizes of
#: an object were given in metres (a statue 45 x 190 cm typed as 45 x 190 is 97.6 m).
LARGE_OBJECT = 50.0


def size_notes(study) -> list[str]:
    """Named objects whose equivalent block is larger than :data:`LARGE_OBJECT` (R = 3 g /
    (4 p^2)): sizes are read in metres, so centimetres give a block a hundred times too big."""
    if study.structure.kind != "objects":
        return []
    found = []
    for i, o in enumerate(study.structure.objects):
        half_diagonal = 0.75 * G / o.rocking()[0] ** 2
        if half_diagonal > LARGE_OBJECT:
            found.append(
                f"structure.objects[{i}] ({o.name!r}): its equivalent block has R = "
                f"{half_diagonal:.4g} m: sizes are in metres (centimetres would make it a "
                "hundred times too big)"
            )
    return found


def _uplift_note(field, kind, eq, a_up) -> str:
    side = "above" if eq > a_up else "below"
    return (
        f"{field}: the study runs the {kind}'s equivalent block, which lifts off at g "
        f"tan(theta_cr) = {eq:.4g} m/s^2, {abs(eq / a_up - 1):.1%} {side} the {kind}'s own "
        f"uplift acceleration {a_up:.4g} m/s^2 (g lambda, eq. 10 of [003]) that the ratios "
        "and uplift levels use: between the two the simulated response is the block's "
        "(rockstudy.simulate runs the mechanism)"
    )


def free_fall_scale(record) -> float:
    """The lowest |scale| at which the record's vertical u_v'' reaches -g (inf if never)."""
    v = record.vertical
    low = float(np.min(v)) if v is not None and v.size else 0.0
    return G / -low if low < 0 else math.inf


def _scaling_notes(study, base_dir) -> list[str]:
    """Notes on a record study scaled to a target (``scale_to`` or ``pga_ratio``; a stripes
    design or Monte Carlo rows) or run unscaled (a cloud design): the records whose largest
    scale factor exceeds ``design.max_scale_factor`` (5 by default), and, when every record
    is horizontal only and even the highest level leaves every record's PGA below the lowest
    uplift acceleration of the structures (:meth:`.study_model.Study.uplift_span`: g tan(alpha) of
    a block, g lambda of another structure, eq. 10 of [003]), that nothing can rock (no
    structure leaves rest)."""
    de = study.design
    kind = None if de is None else design_kind(de.kind)
    cloud = kind is not None and not kind.scaled  # the records as recorded: scale 1
    if not cloud and (study.motion.target() is None or (kind is not None and not kind.levels)):
        return []
    limit = DEFAULT_MAX_SCALE_FACTOR if de is None else de.max_scale_factor
    found, top_pga, horizontal = [], 0.0, True
    for field, h, v in record_pairs(study.motion, base_dir):
        rec = read_pair(h, v, study.motion.units, field, field, h2=second_file(study.motion, h))
        scaled = ("motion.files", 1.0) if cloud else _largest_scale(study, rec)
        if scaled is None:
            return found
        horizontal = horizontal and v is None
        top_pga = max(top_pga, scaled[1] * rec.peak)
        if scaled[1] > limit:
            found.append(
                f"{scaled[0]}: {h.name} is scaled by up to {scaled[1]:.3g}, more than "
                f"{'design.' if de else ''}max_scale_factor = {limit:g} (a record scaled far "
                "from what it recorded)"
            )
    uplift = study.uplift_span()[0]
    if horizontal and top_pga < uplift:
        found.append(
            f"{scaled[0]}: nothing can rock: the highest level brings every record to a PGA "
            f"of at most {top_pga:.4g} m/s^2, below the lowest uplift acceleration "
            f"{uplift:.4g} m/s^2 of the structures (g tan(alpha) of a block, g lambda of "
            "another structure; check the value and its units)"
        )
    return found


def hazard_notes(study, base_dir) -> list[str]:
    """A note, naming ``hazard.units``, where the records' own (unscaled) intensities lie far
    from the hazard curve (:func:`rockstudy.risk.suite_off_curve`)."""
    hazard = getattr(study, "hazard", None)
    if hazard is None or study.design is None:
        return []
    curve = hazard.curve()
    values = [
        read_pair(
            h, v, study.motion.units, field, field, h2=second_file(study.motion, h)
        ).intensity_measure(curve.im, period=curve.period, damping=study.design.damping)
        for field, h, v in record_pairs(study.motion, base_dir)
    ]
    said = suite_off_curve(curve, values)
    return [] if said is None else [f"hazard.units: {said}; check hazard.units and motion.units"]


def _named_twice(pairs) -> list[str]:
    """A design runs every record it lists once per structure and level: a file listed twice
    would count twice in its fragility, so it is refused (Monte Carlo rows may repeat one, to
    draw it more often)."""
    first, found = {}, []
    for field, h, _ in pairs:
        key = h.resolve()
        if key in first:
            found.append(
                f"{field}: names the file {str(h)!r} again (already {first[key]}); a design runs "
                "each record once: list it once"
            )
        first.setdefault(key, field)
    return found


def _units_problem(motion, pairs) -> list[str]:
    """``motion.units`` that cannot apply to the suite (:func:`units_refusal`)."""
    refusal = units_refusal([(h, v) for _, h, v in pairs], motion.units)
    return [f"motion.units: {refusal}"] if refusal else []


def _read_each(motion, pairs):
    """(field, file, record, problem) of each of ``pairs`` read in ``motion.units``: the
    record and None, or None and why it does not read (naming its field and file)."""
    for field, h, v in pairs:
        vfield = field.replace("files", "vertical") if isinstance(motion.vertical, list) else field
        try:
            y = second_file(motion, h)
            yield field, h, read_pair(h, v, motion.units, field, vfield, h2=y), None
        except (OSError, ValueError) as exc:
            yield field, h, None, (_reason(exc, h) if isinstance(exc, OSError) else str(exc))


def read_problems(motion, pairs) -> list[str]:
    """Each record of ``pairs`` that does not read in ``motion.units`` (a NaN, a bad header,
    units that make its peak impossible), each naming its field and file."""
    return [problem for *_, problem in _read_each(motion, pairs) if problem]


def _record_problems(study, pairs) -> list[str]:
    """Every record must read, fit the step limit and, if it is scaled to a target, have a
    non-zero measure to scale (each problem names the field and the file)."""
    max_steps, found = study.run.max_steps, []
    for field, h, rec, problem in _read_each(study.motion, pairs):
        if problem:
            found.append(problem)
            continue
        if rec.acceleration.size > max_steps:
            found.append(_too_long(field, rec.acceleration.size, max_steps))
        scaled = _largest_scaled_peak(study, rec)
        if scaled is not None and not scaled[1] <= MAX_ACCELERATION:
            found.append(
                f"{scaled[0]}: scales {h} to a peak of {scaled[1]:.4g} m/s^2, beyond the "
                f"{MAX_ACCELERATION:.0e} m/s^2 the solvers take (about a million g)"
            )
        for im, period, damping in _scaled_measures(study):
            base = measures.target(im).name  # a ratio's measure
            value = rec.intensity_measure(base, period=period, damping=damping)
            if not value > 0:
                found.append(
                    f"{field}: {h} has {base} = {value:g}; no scale factor brings it to a "
                    f"target {im} (give another record, or another measure)"
                )
                break
    return found


def draw_span(value) -> tuple[float, float]:
    """The smallest and largest value a fixed parameter or a distribution can give: its
    support, or where that is infinite (normal, lognormal) its values at the extreme
    probabilities the samplers draw."""
    if isinstance(value, (int, float)):
        return float(value), float(value)
    lo, hi = value.support()
    if not (math.isfinite(lo) and math.isfinite(hi)):
        ends = value.ppf(np.array([2.0**-53, 1.0 - 2.0**-53]))
        lo = lo if math.isfinite(lo) and lo > 0 else float(ends[0])
        hi = hi if math.isfinite(hi) else float(ends[1])
    return float(lo), float(hi)


def _largest_scaled_peak(study, rec) -> tuple[str, float] | None:
    """(field, the largest peak [m/s^2] of ``rec`` once scaled as the study asks), over the
    whole support of the study's distributions; None for an unscaled record or a measure of
    0 (refused on its own)."""
    mo, de = study.motion, study.design
    peak = float(np.max(np.abs(rec.acceleration)))
    if rec.vertical is not None:
        peak = max(peak, float(np.max(np.abs(rec.vertical))))
    uplift = study.uplift_span()[1]
    if de is not None and design_kind(de.kind).capacities:  # its ladder's top: max_pga_ratio a_up
        top = de.ida_options()["max_pga_ratio"] * uplift
        return "design.max_pga_ratio", top * peak / rec.peak if rec.peak > 0 else 0.0
    if mo.scale is not None:
        lo, hi = draw_span(mo.scale)
        return "motion.scale", max(abs(lo), abs(hi)) * peak
    scaled = _largest_scale(study, rec)
    return None if scaled is None else (scaled[0], scaled[1] * peak)


def _largest_scale(study, rec) -> tuple[str, float] | None:
    """(field, the largest factor on ``rec`` that its target asks), over the whole support of
    the study's distributions and structures; None without a target or for a measure of 0."""
    mo = study.motion
    uplift = study.uplift_span()[1]
    target = mo.target()
    if target is None or target.value is None:
        return None
    value = draw_span(target.value)[1] * target.si_factor()
    field = "motion.pga_ratio" if mo.pga_ratio is not None else "motion.scale_to.value"
    m = measures.target(target.im)
    ratio = measures.RATIOS.get(target.im)
    if ratio is not None:  # the largest base value: the stiffest block's uplift, the lowest p
        value = value * uplift
        if ratio.p_power:
            value = value / study.frequency_parameter_span()[0] ** ratio.p_power
    base = rec.intensity_measure(m.name, period=target.period, damping=target.damping)
    if not base > 0:
        return None
    return field, (value / base) ** (1.0 / m.power)


@lru_cache(maxsize=1)
def vertical_refusal() -> str | None:
    """Why the solvers refuse a record with a vertical component (None if they take it), as
    the batch entry point answers for a record at rest."""
    from ...dynamics import simulate_batch
    from ...motions import Record

    rest = Record(np.zeros(3), dt=0.01, vertical=np.zeros(3))
    try:
        simulate_batch(
            frequency_parameter=[2.0],
            slenderness=[0.2],
            restitution=[0.9],
            record=rest,
            scale=[1.0],
        )
    except NotImplementedError as exc:
        return str(exc)
    return None


def _scaled_measures(study) -> list[tuple]:
    """(im, period, damping) of every measure a study scales its records by."""
    target, de = study.motion.target(), study.design
    if de is not None and design_kind(de.kind).capacities:  # brackets by PGA, reports in im
        return [("pga", None, de.damping), (de.ida_options()["im"], de.period, de.damping)]
    return [] if target is None else [(target.im, target.period, target.damping)]


def record_pairs(motion, base_dir=None) -> list[tuple[str, Path, Path | None]]:
    """The records of a record motion: ``(field, horizontal file, vertical file or None)``,
    in order, without the files that ``motion.h2`` names as some record's second horizontal
    component (:func:`second_file`); see :func:`_listed_pairs`."""
    pairs = _listed_pairs(motion, base_dir)
    if getattr(motion, "h2", None) is None:
        return pairs
    pattern = re.compile(motion.h2.match)
    named = {h.with_name(pattern.sub(motion.h2.replace, h.name)).resolve() for _, h, _ in pairs}
    records = [p for p in pairs if Path(p[1]).resolve() not in named]
    for _, h, _ in records:
        second_file(motion, h)  # every record names its second component
    return records


def second_file(motion, horizontal) -> Path | None:
    """The second horizontal file of the record ``horizontal``: ``motion.h2``'s ``re.sub(match,
    replace, name)`` in the same folder (None without ``h2``); a ValueError naming
    ``motion.h2`` if the name does not match."""
    rule = getattr(motion, "h2", None)
    if rule is None:
        return None
    horizontal = Path(horizontal)
    if not re.search(rule.match, horizontal.name):
        raise ValueError(
            f"motion.h2: the file {str(horizontal)!r} does not match {rule.match!r} and is no "
            "record's second horizontal component; every file must be one or the other"
        )
    return horizontal.with_name(re.sub(rule.match, rule.replace, horizontal.name))


def _listed_pairs(motion, base_dir=None) -> list[tuple[str, Path, Path | None]]:
    """The records of a record motion: ``(field, horizontal file, vertical file or None)``,
    in order (a folder and a glob sorted by name), paths resolved by :func:`record_path`.

    Raises ValueError naming ``motion.files`` (or ``motion.vertical``) for a folder without
    record files, a glob without a match, a missing file or a file named twice.
    """
    files = motion.files
    rule = motion.vertical
    if isinstance(files, str):
        source = str(record_path(files, base_dir))
        vertical = None if rule is None else (rule.match, rule.replace)
        pairs = suite_pairs(source, vertical, "motion.files", "motion.vertical")
        return [("motion.files", h, v) for h, v in pairs]
    out = []
    for i, item in enumerate(files):
        field = f"motion.files[{i}]"
        if isinstance(item, str):
            h = record_path(item, base_dir)
            v = record_path(rule[i], base_dir) if isinstance(rule, list) else None
        else:
            h, v = record_path(item.horizontal, base_dir), record_path(item.vertical, base_dir)
        out.append((field, h, v))
    if hasattr(rule, "match"):  # a { match, replace } rule over the listed files
        pairs = suite_pairs(
            [h for _, h, _ in out], (rule.match, rule.replace), "motion.files", "motion.vertical"
        )
        return [("motion.files", h, v) for h, v in pairs]
    return out  # a file listed twice is drawn twice as often by Monte Carlo rows


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
