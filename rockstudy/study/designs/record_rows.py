"""Record designs in study files: cloud, stripes and IDA run on the study runner and store.

A study with a ``[design]`` table runs every record of its suite against every structure the
sampler draws (``sampler.n`` of them) [at every level of ``motion.scale_to.value``]. Its rows
on the store's ``sample`` dimension are (record, structure[, level]) in C order, and each
record is one chunk: one dask task, stored and hashed as any chunk, so an interrupted run
resumes at the records not yet done. A task calls the Python design functions of
:mod:`.records` on its record and structures (no second pipeline), and
:func:`design_dataset` folds the rows back into their layout: dims ``record``,
``structure`` [, ``level``] [, ``step``, ``period``], with each record's intensity measures,
pulse and groups, as :mod:`.records` returns them.

The store's per-row ``status`` (1 ok, 2 failed: the task raised) is ``run_status`` there, and
``status`` is the design's own (0 ok; else a simulation hit the step limit), as in the API.
"""

from __future__ import annotations

import json
import math
import warnings
from functools import lru_cache
from pathlib import Path

import numpy as np
import xarray as xr

from ..._warnings import UpliftWarning
from ...dynamics import outputs as _outputs
from ...motions import measures
from ...motions.building import ground_record, with_ground
from ...motions.suites import read_pair
from ...structures.block import uplift_acceleration_block
from ..spec.design_kinds import design_kind
from ..spec.feasibility import record_pairs, second_file
from . import ida_states, two_body_rows
from . import records as rd

__all__ = [
    "CONTACT_VARIABLES",
    "design_dataset",
    "design_measures",
    "design_motion",
    "design_rows",
    "empty_rows",
    "evaluate_rows",
    "GROUP_VARIABLES",
    "ida_steps",
    "load_record",
    "motion_axes",
    "motion_coords",
    "outputs",
    "PULSE_VARIABLES",
    "record_variables",
    "sample_measures",
    "sample_outputs",
    "scale_factors",
    "stored_periods",
    "suite_records",
    "STRUCTURE_VARIABLES",
    "uplift_column",
]

#: Per-record variables of the pulse in the design Dataset: (long_name, units).
PULSE_VARIABLES = {
    "pulse_period": ("period T_p of the extracted velocity pulse", "s"),
    "pulse_amplitude": ("amplitude of the extracted velocity pulse", "m s-1"),
    "pulse_indicator": ("pulse indicator (Baker 2007)", "1"),
}


def record_variables() -> dict:
    """Per-record variables of the design Dataset: (long_name, units) of every listed measure
    without a period (:mod:`rockstudy.motions.measures`) and of the pulse."""
    ms = measures.MEASURES
    return {**{k: (ms[k].label, ms[k].unit) for k in measures.listed(False)}, **PULSE_VARIABLES}


#: (record, structure) groups of the unscaled record (:func:`rockstudy.similarity.record_groups`),
#: relative to the structure's uplift acceleration a_up (g tan alpha for a block).
GROUP_VARIABLES = {
    "pga_ratio": ("PGA / a_up", "1"),
    "pgv_ratio": ("PGV p / a_up", "1"),
    "pulse_frequency_ratio": ("omega_p / p = 2 pi / (T_p p)", "1"),
    "pulse_amplitude_ratio": ("pulse amplitude omega_p v_p / a_up", "1"),
}
#: Per-structure variables taken from the design (not the chunks).
STRUCTURE_VARIABLES = (
    "half_diagonal",
    "slenderness",
    "restitution",
    "frequency_parameter",
    "critical_rotation",
    "uplift_acceleration",
)
_RUN = {
    "max_rotation": ("max |theta| (pi/2 if overturned)", "rad", "f8", np.nan),
    "overturned": ("overturned (1) or survived (0); -1 if failed", "1", "i1", -1),
    "n_impacts": ("impacts until rest; -1 if failed", "1", "i8", -1),
    "overturn_time": ("time at which |theta| reached pi/2 (NaN if it survived)", "s", "f8", np.nan),
}
_IDA = {
    "capacity": ("first overturning intensity, in the units of the design's im", "", "f8", np.nan),
    "capacity_scale": (
        "lowest scale seen to overturn (upper end of the final bracket)",
        "1",
        "f8",
        np.nan,
    ),
    "capacity_scale_lower": (
        "highest scale below it seen to survive (censored: the highest surviving rung)",
        "1",
        "f8",
        np.nan,
    ),
    "censored": ("1 if no rung overturned", "1", "i1", -1),
    "censored_reason": (
        "0 not censored, 1 standing at max_pga_ratio, 2 free fall above (u_v'' reaches -g)",
        "1",
        "i1",
        -1,
    ),
    "survives_above_capacity": (
        "1 if a simulated scale above the capacity survived",
        "1",
        "i1",
        -1,
    ),
    "highest_survival_scale": (
        "highest simulated scale above the capacity that survived (top of the switch band)",
        "1",
        "f8",
        np.nan,
    ),
    "switch_band_overturn_share": (
        "share of the simulated scales in the switch band that overturn",
        "1",
        "f8",
        np.nan,
    ),
    "rungs": ("ladder rungs simulated", "1", "i8", -1),
    "simulations": ("simulations run", "1", "i8", -1),
}
_STEPS = rd.STEP_VARIABLES
_BOOLS = ("censored", "survives_above_capacity")


#: The contact check of a scene (a study's ``friction``): (long_name, units, dtype, fill).
CONTACT_VARIABLES = {
    "friction_demand": (
        "friction demand max |F_h / F_v| at the contact (inf with a lift-off)",
        "1",
        "f8",
        np.nan,
    ),
    "lift_off": ("1 if the vertical contact force was not compressive somewhere", "1", "i1", -1),
}


def _float(long_name, units):
    return (long_name, units, "f8", np.nan)


def outputs(study) -> dict:
    """The per-row outputs of a design study: name -> (long_name, units, dtype, fill, extra
    dimension or None). ``kernel_status`` is the design's ``status`` (0 ok)."""
    de = study.design
    kind = design_kind(de.kind)
    out = {k: (*_float(*v), None) for k, v in record_variables().items()}
    for k in measures.listed(True):
        m = measures.MEASURES[k]
        out[k] = (f"{m.label}(T) of the unscaled record", m.unit, "f8", np.nan, "period")
    for k in design_measures(study):
        m = measures.MEASURES[k]
        extra = "period" if m.needs_period else None
        out[k] = (f"{m.label} of the unscaled record", m.unit, "f8", np.nan, extra)
    out.update({k: (*_float(*v), None) for k, v in GROUP_VARIABLES.items()})
    if kind.capacities:
        out.update({k: (*v, None) for k, v in _IDA.items()})
        im = de.ida().im
        unit = "1" if im in measures.RATIOS else measures.measure(im).unit
        out["capacity"] = (_IDA["capacity"][0], unit, "f8", np.nan, None)
        for k in _STEPS:
            out[k] = (k.replace("_", " ") + " of each simulated point", "1", "f8", np.nan, "step")
        out.update(_ida_contact_outputs(study, unit))
        out.update(_state_outputs(study, unit))
    else:
        out.update({k: (*v, None) for k, v in _RUN.items()})
        if kind.levels:
            out["scale"] = ("factor applied to the record", "1", "f8", np.nan, None)
        out["censored"] = (
            "1 if not run: the scaled vertical reaches -g (free fall; kernel_status 2)",
            "1",
            "i1",
            -1,
            None,
        )
    if study.friction_coefficients() is not None:  # the contact check (spec.Study.friction)
        for name in ("friction_demand", "lift_off"):
            out[name] = (*CONTACT_VARIABLES[name], None)
    if study.run.model != "rocking" and not kind.capacities:  # rockstudy.dynamics.outputs
        for name in rd.MODEL_KEYS:
            o = _outputs.OUTPUTS[name]
            out[name] = (o.long_name, o.units, o.store_dtype, o.fill, None)
    if study.run.model != "rocking":  # rd._friction_variables: the contact of each object
        for name in ("friction_static", "friction_kinetic"):
            out[name] = (name.replace("_", " ") + " coefficient", "1", "f8", np.nan, None)
    if study.run.model == "auto" and not kind.capacities:  # rd.ROCKING_KEYS
        long_name = "overturned (1) under Housner's rocking-only model; -1 if failed"
        out["overturned_rocking"] = (long_name, *_RUN["overturned"][1:], None)
    if _two_body(study) is not None:  # two_body_rows: at the IDA's capacity, or each point
        ida = two_body_rows.ida_outputs_attributes() if kind.capacities else {}
        for name, (long_name, *rest) in two_body_rows.TWO_BODY_VARIABLES.items():
            out[name] = (ida.get(name, {}).get("long_name", long_name), *rest, None)
    out["kernel_status"] = (
        "0 ok; 1 a simulation hit the step limit; 2 not run: free fall; 4 the contact model's "
        "answer did not converge with rtol (an IDA: the OR of its points' codes)",
        "1",
        "i8",
        -1,
        None,
    )
    return out


def design_measures(study) -> tuple[str, ...]:
    """The measures a design study stores per record besides the listed ones
    (:func:`.records.stored_measures`): those of its scaling (``design.im`` of an IDA,
    ``motion.scale_to.im`` of stripes) and of its ``[hazard]`` not listed, e.g. ``pga_rotd50``."""
    kind = design_kind(study.design.kind)
    im = study.design.ida().im if kind.capacities else None
    if kind.levels:
        im = study.motion.scale_to.im
    hazard = () if study.hazard is None else (study.hazard.im,)
    return rd.stored_measures(im, hazard)


def ida_steps(study) -> int:
    """Most simulations one structure of the study can take in the IDA: the ladder (from at
    least half the rest scale g theta_cr / PGA, which a downward vertical can lower by at
    most that, up to max_pga_ratio a_up, in steps of ``1 + step``), the bisection (from
    ``1 + step`` down to ``1 + tolerance``) and the scan."""
    o = study.design.ida()
    span = 2.0 * o.max_pga_ratio * study.largest_uplift_over_rest() * _slip_span(study)
    ladder = math.ceil(math.log(span) / math.log1p(o.step)) + 2
    ratio = math.log1p(o.step) / math.log1p(o.tolerance)
    bisect = math.ceil(math.log2(ratio)) + 1 if ratio > 1 else 0
    return ladder + bisect * (1 + len(_slide_limits(study)) + _state_bisections(study)) + o.scan


def _slip_span(study) -> float:
    """How far below the rest level g theta_cr the contact model's ladder starts: at most
    theta_cr / mu_s (its lowest rung is the slip level g min(theta_cr, mu_s);
    :func:`.records.incremental_dynamic_analysis`), 1 under Housner's model."""
    if study.run.model == "rocking":
        return 1.0
    mu = float(np.min(study.friction_coefficients()))
    return max(1.0, study.largest_critical_rotation() / mu)


def _slide_limits(study) -> list:
    """The slides d [m] of an IDA's slide capacities: ``design.slide_limits`` (under the
    contact model: validated by the study)."""
    return list(study.design.slide_limits) if study.run.model != "rocking" else []


def _damage_states(study) -> tuple:
    """The damage states of the design (:meth:`.DesignSpec.states`; a slide state needs the
    contact model, which the study checked)."""
    return study.design.states(contact=study.run.model != "rocking")


def _state_bisections(study) -> int:
    """How many damage states an IDA bisects (all but overturning, which is the capacity)."""
    return sum(not s.overturning for s in _damage_states(study))


def _state_outputs(study, unit) -> dict:
    """An IDA's damage-state capacities (extra dimension ``damage_state``; ``unit``: that of
    ``capacity``), with ``design.damage_states``."""
    if not _damage_states(study):
        return {}
    return {
        name: (ida_states.LONG_NAMES[name], units, "f8", np.nan, "damage_state")
        for name, units in (("state_capacity", unit), ("state_capacity_scale", "1"))
    }


def design_rows(study, structures: dict, base_dir=None) -> xr.Dataset:
    """The rows (record, structure[, level]) of a design study on ``sample``, in C order.

    ``structures`` holds the sampler's structure columns (``sampler.n`` of each). The record
    files (named in the attribute ``record_files``) are listed, not read.
    """
    pairs = suite_records(study.motion, base_dir)
    floors, angles = motion_axes(study)
    n_motions = len(pairs) * len(floors) * (1 if angles is None else angles.size)
    n_rec, n_st, n_lev = n_motions, len(structures["critical_rotation"]), study.levels()
    rec, st, lev = (a.ravel() for a in np.indices((n_rec, n_st, n_lev)))
    data = {k: ("sample", np.asarray(v)[st]) for k, v in structures.items()}
    data.update(record=("sample", rec), structure=("sample", st), level_index=("sample", lev))
    coords = {"sample": np.arange(rec.size)}
    kind = design_kind(study.design.kind)
    if kind.levels:
        coords["level"] = ("level", study.motion.scale_to.levels())
    coords["period"] = ("period", stored_periods(study))
    if kind.capacities and _slide_limits(study):
        coords["slide_limit"] = ("slide_limit", np.array(_slide_limits(study)), {"units": "m"})
    if kind.capacities and _damage_states(study):  # numbered here; named by design_dataset
        coords["damage_state"] = ("damage_state", np.arange(len(_damage_states(study))))
    ds = xr.Dataset(data, coords=coords)
    names = [str(h) if v is None else [str(h), str(v)] for _, h, v, _ in pairs]
    ds.attrs.update(
        record_files=json.dumps(names),
        record_names=json.dumps([Path(h).stem for _, h, _, _ in pairs]),
        **_axes_attrs(study, pairs),
        record_design=study.design.kind,
        structures=n_st,
    )
    if study.structure.kind == "objects":
        ds.attrs["structure_names"] = json.dumps([o.name for o in study.structure.objects])
    if kind.capacities:
        ds.attrs["ida_steps"] = ida_steps(study)
    return ds


def suite_records(motion, base_dir=None) -> list[tuple]:
    """The records of a record motion: ``(field, horizontal, vertical or None, second
    horizontal or None)`` files, as :func:`.feasibility.record_pairs` lists them, each with
    its second horizontal component named by ``motion.h2`` (:func:`.feasibility.second_file`)."""
    return [(f, h, v, second_file(motion, h)) for f, h, v in record_pairs(motion, base_dir)]


def motion_axes(study) -> tuple[list[int], np.ndarray | None]:
    """The floors of a design study (``[0]`` on the ground) and its orientations [rad] (None
    without ``design.orientations``): every record runs on each (floor, orientation), motion
    ``(record * floors + floor) * orientations + orientation`` of the rows' ``record``."""
    floors = study.motion.floors() if study.motion.kind == "record" else [0]
    return floors, study.design.angles()


def _axes_attrs(study, pairs) -> dict:
    """The attributes of the motion axes (:func:`motion_axes`): ``floors`` (a list of floors)
    and ``orientations`` [rad] when given, and the second horizontal files."""
    floors, angles = motion_axes(study)
    out = {}
    if isinstance(getattr(study.motion, "floor", None), list):
        out["floors"] = json.dumps(floors)
    if angles is not None:
        out["orientations"] = json.dumps([float(a) for a in angles])
    if any(y is not None for *_, y in pairs):
        out["record_h2_files"] = json.dumps([None if y is None else str(y) for *_, y in pairs])
    return out


@lru_cache(maxsize=8)
def _suite(motion_json: str, base_dir) -> tuple:
    from ..spec.motion_spec import RecordSpec

    return tuple(suite_records(RecordSpec.model_validate(json.loads(motion_json)), base_dir))


@lru_cache(maxsize=32)
def _ground(motion_json: str, base_dir, index: int):
    """Record ``index`` of a study's suite on the ground (read once per process)."""
    from ..spec.motion_spec import RecordSpec

    motion = RecordSpec.model_validate(json.loads(motion_json))
    field, h, v, y = _suite(motion_json, base_dir)[index]
    return read_pair(h, v, motion.units, field, h2=y)


@lru_cache(maxsize=32)
def load_record(motion_json: str, base_dir, index: int):
    """Record ``index`` of a study's suite (read once per process), on the motion's floor
    when it names a building (:meth:`RecordSpec.floor_motion`)."""
    from ..spec.motion_spec import RecordSpec

    motion = RecordSpec.model_validate(json.loads(motion_json))
    return motion.floor_motion(_ground(motion_json, base_dir, index))


def design_motion(study, base_dir, index: int):
    """Motion ``index`` of a design study (:func:`motion_axes`): its record on its floor,
    along its orientation (:meth:`rockstudy.motions.Record.oriented`), with the ground
    record (both components) as the record a design measures
    (:func:`rockstudy.motions.building.ground_record`). A ValueError names the record and
    ``design.orientations`` if the record has one horizontal component."""
    floors, angles = motion_axes(study)
    n_or = 1 if angles is None else angles.size
    record, rest = divmod(int(index), len(floors) * n_or)
    floor, orientation = divmod(rest, n_or)
    ground = _ground(study.motion.model_dump_json(), base_dir, record)
    motion = study.motion.floor_motion(ground, floors[floor])
    if angles is None:
        return motion
    if ground.acceleration_y is None:
        raise ValueError(
            f"design.orientations: the record {ground.name!r} has one horizontal component; "
            "orientations need two (motion.h2 names each record's second one)"
        )
    return with_ground(motion.oriented(float(angles[orientation])), ground)


def stored_periods(study) -> np.ndarray:
    """Periods [s] of the stored ``sa``: ``design.periods`` and the period of a spectral target
    (as :mod:`.records` stores them), sorted."""
    de, periods = study.design, set(study.design.periods)
    kind = design_kind(de.kind)
    if kind.levels and study.motion.scale_to.period is not None:
        periods.add(study.motion.scale_to.period)
    if kind.capacities and de.period is not None:
        periods.add(de.period)
    return np.array(sorted(periods), float)


def _widths(study) -> dict:
    """Sizes of the extra dimensions of the outputs."""
    steps = design_kind(study.design.kind).capacities
    return {
        "period": stored_periods(study).size,
        "step": ida_steps(study) if steps else 0,
        "slide_limit": len(_slide_limits(study)) if steps else 0,
        "damage_state": len(_damage_states(study)) if steps else 0,
    }


def _ida_contact_outputs(study, unit) -> dict:
    """The IDA's outputs under the contact model: its outputs at each simulated point
    (``step_<name>``, extra dimension ``step``) and, with ``design.slide_limits``, the slide
    capacities (extra dimension ``slide_limit``; ``unit``: that of ``capacity``)."""
    if study.run.model == "rocking":
        return {}
    out = {}
    for name, step in zip(rd.MODEL_KEYS, rd.STEP_MODEL_VARIABLES, strict=True):
        o = _outputs.OUTPUTS[name]
        out[step] = (f"{o.long_name}, at each simulated point", o.units, "f8", np.nan, "step")
    if study.run.model == "auto":  # Housner's ladder too (rd._ida_rocking)
        out.update(_ida_rocking_outputs(unit))
    if _slide_limits(study):
        out["slide_capacity"] = (
            "first intensity at which max_slide exceeds slide_limit (NaN: not below the "
            "largest rung), in the units of the design's im",
            unit,
            "f8",
            np.nan,
            "slide_limit",
        )
        out["slide_capacity_scale"] = (
            "lowest scale seen to slide more than slide_limit",
            "1",
            "f8",
            np.nan,
            "slide_limit",
        )
    return out


def _ida_rocking_outputs(unit) -> dict:
    """The rocking-only twins an IDA keeps under ``model="auto"`` (``unit``: that of
    ``capacity``)."""
    out = {}
    for name in ("capacity", *rd.IDA_ROCKING_VARIABLES, "simulations"):
        long_name, units, dtype, fill = _IDA.get(name) or (
            "0 ok; 1 a simulation hit the step limit",
            "1",
            "i8",
            -1,
        )
        units = unit if name == "capacity" else units
        twin = (f"{long_name}, under Housner's rocking-only model", units, dtype, fill, None)
        out[f"{name}_rocking"] = twin
    return out


def empty_rows(study, n: int) -> dict:
    """The outputs of ``n`` rows, each at its fill value."""
    width = _widths(study)
    return {
        name: np.full((n,) if extra is None else (n, width[extra]), fill, dtype=dtype)
        for name, (_, _, dtype, fill, extra) in outputs(study).items()
    }


def _run_design(study, record, structures, levels, friction):
    """The design function of :mod:`.records` on one record (its kind's ``run``), with the
    friction coefficients of its structures (None: no friction check), under the study's
    ``[run] model``."""
    de, run = study.design, study.run
    kind = design_kind(de.kind)
    kw = dict(
        periods=de.periods,
        damping=de.damping,
        method=run.method,
        rtol=run.rtol,
        max_steps=run.max_steps,
    )
    kw["friction"] = friction
    kw["extra_measures"] = () if study.hazard is None else (study.hazard.im,)
    if run.model != "rocking":  # spec.Study._contact_model: every structure has its mu
        kw["model"] = run.model
        if kind.capacities:
            kw["slide_limits"] = _slide_limits(study)
    if kind.capacities and de.damage_states:
        kw["damage_states"] = de.damage_states
    if kind.levels:
        t = study.motion.scale_to  # its damping is design.damping (spec.Study._design)
        kw.update(levels=levels, im=t.im, period=t.period)
    if kind.capacities:
        kw.update(de.ida_options())
    return getattr(rd, kind.run)([record], structures, **kw)


def _structure_friction(pairs, st_ids) -> tuple:
    """(mu_s, mu_k) of the structures ``st_ids`` from the study's
    :meth:`~rockstudy.study.spec.Study.friction_pairs` (one pair: the study's, as floats)."""
    if pairs[0].size == 1:
        return float(pairs[0][0]), float(pairs[1][0])
    return pairs[0][st_ids], pairs[1][st_ids]


def evaluate_rows(study, cols: dict, base_dir=None) -> dict:
    """Outputs of design rows (any subset of one or more records' rows): one design call per
    record on the structures and levels the rows name. Raises if a design call does."""
    outs = outputs(study)
    width = _widths(study)
    result = empty_rows(study, cols["sample"].size)
    on_levels = design_kind(study.design.kind).levels
    levels_all = study.motion.scale_to.levels() if on_levels else np.ones(1)
    friction = study.friction_pairs()
    for r in np.unique(cols["record"]):
        rows = np.flatnonzero(cols["record"] == r)
        rec = design_motion(study, base_dir, int(r))
        st_ids, st_pos = np.unique(cols["structure"][rows], return_inverse=True)
        first = rows[np.unique(st_pos, return_index=True)[1]]
        structures = {
            "frequency_parameter": cols["frequency_parameter"][first],
            "critical_rotation": cols["critical_rotation"][first],
            "restitution": cols["restitution"][first],
            "uplift_acceleration": uplift_column(study, cols, first),
        }
        if _two_body(study) is not None:  # their scenes run the two-body system
            structures["two_body"] = _two_body(study)[cols["structure"][first]]
        lev_ids, lev_pos = np.unique(cols["level_index"][rows], return_inverse=True)
        mu = None if friction is None else _structure_friction(friction, st_ids)
        ds = _run_design(study, rec, structures, levels_all[lev_ids], mu)
        _fill(result, outs, ds, rows, st_pos, lev_pos, width)
    return result


def _two_body(study) -> np.ndarray | None:
    """The two-body structure of each named object (None for the others), or None when the
    study has no two-body object (:mod:`.two_body_rows`)."""
    if study.structure.kind != "objects":
        return None
    return two_body_rows.two_body_column({"two_body": study.structure.two_body()})


def _fill(result, outs, ds, rows, st_pos, lev_pos, width):
    """Copy a one-record design Dataset into the rows ``rows`` of ``result``."""
    for name, (*_, extra) in outs.items():
        if extra is not None and width[extra] == 0:  # no periods asked: nothing to copy
            continue
        src = "status" if name == "kernel_status" else name
        var = ds[src].isel(record=0) if "record" in ds[src].dims else ds[src]
        if "structure" in var.dims:
            var = var.isel(structure=xr.DataArray(st_pos, dims="row"))
        if "level" in var.dims:
            var = var.isel(level=xr.DataArray(lev_pos, dims="row"))
        values = np.asarray(var.values)
        if extra is None:
            result[name][rows] = np.broadcast_to(values, rows.shape).astype(result[name].dtype)
        elif extra == "period":
            result[name][rows] = np.broadcast_to(values, (rows.size, width["period"]))
        elif extra in ("slide_limit", "damage_state"):  # (slide_limit, row) of the design
            result[name][rows] = np.asarray(var.transpose("row", extra).values)
        else:  # IDA steps: (row, step), padded with NaN to the study's bound
            k = values.shape[-1]
            if k > width["step"]:
                raise RuntimeError(
                    f"the IDA took {k} simulations for one structure, more than the bound "
                    f"{width['step']} of ida_steps(); this is a bug of rockstudy"
                )
            result[name][rows, :k] = values


def _folded(cube, kind, shape, m_dims) -> dict:
    """The variables of a design's rows on their dimensions: ``shape`` is (records, the
    sizes of the motion axes ``m_dims``, structures); the levels of stripes follow. The
    record and group variables are the ground record's (the same on every motion)."""
    n_lev = cube.sizes.get("level", 1) if kind.levels else 1
    first = (0,) * len(m_dims)
    out = {}
    for name, var in cube.data_vars.items():
        if var.dims[:1] != ("sample",) or name in ("record", "structure", "level_index"):
            continue
        values = np.asarray(var.values).reshape(shape + (n_lev,) + var.shape[1:])
        new = "status" if name == "kernel_status" else "run_status" if name == "status" else name
        extra = var.dims[1:]
        if name in STRUCTURE_VARIABLES:
            out[new] = (("structure",), values[(0, *first, slice(None), 0)], var.attrs)
        elif name in record_variables() or name in measures.MEASURES:
            out[new] = (("record",) + extra, values[(slice(None), *first, 0, 0)], var.attrs)
        elif name in GROUP_VARIABLES:
            ground = values[(slice(None), *first)][:, :, 0]
            out[new] = (("record", "structure") + extra, ground, var.attrs)
        elif not kind.levels:
            dims = ("record", *m_dims, "structure") + extra
            out[new] = (dims, np.take(values, 0, axis=2 + len(m_dims)), var.attrs)
        else:
            out[new] = (("record", *m_dims, "structure", "level"), values, var.attrs)
    return out


def design_dataset(cube: xr.Dataset) -> xr.Dataset:
    """Fold a design study's rows (the store's cube) into the layout of :mod:`.records`:
    ``record`` [x ``floor``] [x ``orientation``] x ``structure`` [x ``level``] (the floor and
    orientation of a list of floors and of ``design.orientations``, :func:`motion_coords`),
    per-record and per-structure tables, attributes.
    """
    kind = design_kind(cube.attrs["record_design"])
    names = json.loads(cube.attrs["record_names"])
    n_rec, n_st = len(names), int(cube.attrs["structures"])
    axes = motion_coords(cube.attrs)
    m_dims = tuple(axes)
    study = json.loads(cube.attrs["study"])
    out = _folded(cube, kind, (n_rec, *(len(v) for v in axes.values()), n_st), m_dims)
    coords = {
        "record": rd.record_labels(names),
        "structure": (
            np.array(json.loads(cube.attrs["structure_names"]), dtype=object)
            if "structure_names" in cube.attrs
            else np.arange(n_st)
        ),
        "period": cube["period"].values,
        "record_name": ("record", np.array(names, dtype=object)),
        **axes,
    }
    if "slide_limit" in cube.coords:  # an IDA's slide capacities, as the API orders them
        coords["slide_limit"] = cube["slide_limit"]
        dims = ("slide_limit", "record", *m_dims, "structure")
        for k, (var_dims, values, var_attrs) in list(out.items()):
            if var_dims[-1:] == ("slide_limit",):
                out[k] = (dims, np.moveaxis(values, -1, 0), var_attrs)
    _fold_states(out, coords, cube, study, m_dims)  # an IDA's states, as the API orders them
    if kind.levels:
        coords["level"] = cube["level"].values
    ds = xr.Dataset(out, coords=coords)
    if "error" in ds:  # zarr reads the empty message (its fill value) back as NaN
        text = ds["error"].values
        ds["error"] = (
            ds["error"].dims,
            np.where([isinstance(m, str) for m in text.ravel()], text.ravel(), "")
            .reshape(text.shape)
            .astype(object),
        )
    files = json.loads(cube.attrs["record_files"])  # [horizontal, vertical] for a pair
    ds["vertical_component"] = ("record", np.array([isinstance(f, list) for f in files]))
    ds = ds.assign(_felt_motion(study, n_rec, n_st))
    if "uplift_acceleration" not in ds:  # a cube written before the design carried it
        ds["uplift_acceleration"] = ("structure", _old_uplift(ds, study))
    attrs = {k: v for k, v in cube.attrs.items() if k != "grid_dims"} | _states_attr(study)
    de = study["design"]
    if de.get("slide_limits"):  # the slide fragility's d (analysis.sliding)
        attrs["slide_limits"] = [float(d) for d in de["slide_limits"]]
    attrs.update(
        design=kind.name,
        method=study["run"]["method"],
        rtol=study["run"]["rtol"],
        damping=de["damping"],
    )
    if kind.levels:
        t = study["motion"]["scale_to"]
        attrs.update(im=t["im"], im_period=np.nan if t["period"] is None else t["period"])
    if kind.capacities:
        attrs.update(rd.IdaOptions.given(de).attrs())
        sims = [ds[k] for k in ("simulations", "simulations_rocking") if k in ds]
        attrs["n_simulations"] = int(sum(np.nansum(np.where(v >= 0, v, 0)) for v in sims))
        for k in _BOOLS + ("censored_rocking",) * ("censored_rocking" in ds):
            ds[k] = ds[k] == 1  # as the API: bool (a failed row: False, NaN capacity)
        steps = ds["step_scale"].values
        used = np.isfinite(steps.reshape(-1, steps.shape[-1])).any(axis=0)
        ds = ds.isel(step=slice(0, max(int(used.nonzero()[0].max(initial=-1)) + 1, 1)))
    else:  # as the API: bool, and the points not run are not simulations
        ds["censored"] = ds["censored"] == 1
        attrs["n_simulations"] = int((~ds["censored"]).sum())
    ds.attrs = attrs
    return ds


def _felt_motion(study: dict, n_rec: int, n_st: int) -> dict:
    """``measured_motion`` on ``record`` (False where the objects feel a floor motion above
    the ground or the record along an orientation: not the motion whose measures the design
    stores) and ``uplift_bounds`` on ``structure`` (False for a block on an isolator), as
    :func:`rockstudy.study.designs.records.incremental_dynamic_analysis` gives them, for
    :func:`rockstudy.study.analysis.risk.cut_levels`."""
    floors = study["motion"].get("floor") or 0
    above = any(f > 0 for f in (floors if isinstance(floors, list) else [floors]))
    oriented = study["design"].get("orientations") is not None
    st = study["structure"]
    kinds = [o.get("kind", "block") for o in st.get("objects") or []] or ["block"] * n_st
    return {
        "measured_motion": ("record", np.full(n_rec, not (above or oriented))),
        "uplift_bounds": ("structure", np.array([k != "isolated" for k in kinds])),
    }


def motion_coords(attrs) -> dict:
    """The motion axes of a design's cube (its attributes ``floors`` and ``orientations``,
    :func:`motion_axes`): ``{"floor": floors, "orientation": angles [rad]}``, each only when
    the study gives it."""
    axes = {}
    if "floors" in attrs:
        axes["floor"] = np.array(json.loads(attrs["floors"]), np.int64)
    if "orientations" in attrs:
        axes["orientation"] = np.array(json.loads(attrs["orientations"]), float)
    return axes


def _fold_states(out, coords, cube, study: dict, m_dims=()) -> None:
    """With an IDA's damage states (``damage_state`` in the ``cube``), put their variables
    of ``out`` on (damage_state, record[, the motion axes ``m_dims``], structure) and name
    the states in ``coords`` (from the stored study's ``design.damage_states``)."""
    if "damage_state" not in cube.coords:
        return
    states = ida_states.damage_states(study["design"]["damage_states"], True)
    coords.update(ida_states.state_coords(states))
    for k, (var_dims, values, var_attrs) in list(out.items()):
        if var_dims[-1:] == ("damage_state",):
            out[k] = (
                ("damage_state", "record", *m_dims, "structure"),
                np.moveaxis(values, -1, 0),
                var_attrs,
            )


def _states_attr(study: dict) -> dict:
    """``{"damage_states": the states as JSON}`` of a stored study's design (for the fits of
    :mod:`rockstudy.study.analysis.states`), or {}."""
    if not study["design"].get("damage_states"):
        return {}
    states = ida_states.damage_states(study["design"]["damage_states"], True)
    return {"damage_states": ida_states.states_attr(states)}


def _old_uplift(ds, study: dict):
    """The uplift acceleration [m/s^2] of each structure of a cube written before the design
    carried it: g tan(theta_cr) for blocks (exact); for other structures NaN, with an
    :class:`UpliftWarning` (their stored PGA ratios are relative to g tan(theta_cr) of the
    equivalent block, not to the structure's own g lambda: run the study again)."""
    kinds = _structure_kinds(study)
    if kinds <= {"block", "equivalent_block"}:
        return uplift_acceleration_block(ds["critical_rotation"].values)
    warnings.warn(
        "the cube was written before the design carried each structure's uplift acceleration; "
        f"its structures of kind {sorted(kinds - {'block', 'equivalent_block'})} lift off at g "
        "lambda (eq. 10 of [003]), not at the g tan(theta_cr) of their equivalent block that "
        "its pga_ratio, pgv_ratio and pulse_amplitude_ratio are relative to: uplift_acceleration "
        "is NaN (no uplift level is drawn); run the study again for the right ones",
        UpliftWarning,
        stacklevel=3,
    )
    return np.full(ds.sizes["structure"], np.nan)


def _structure_kinds(study: dict) -> set:
    """The structure kinds of a (normalised) study's structures."""
    st = study["structure"]
    if st["kind"] != "objects":
        return {st["kind"]}
    return {o.get("kind") or "block" for o in st["objects"]}


def uplift_column(study, cols: dict, idx) -> np.ndarray:
    """The uplift acceleration a_up [m/s^2] of the design rows ``idx``: the design column
    (:func:`rockstudy.structures.uplift_acceleration` of each structure); g tan(theta_cr) for
    blocks of a design made without it; a ValueError for other structures (their uplift is
    not g tan(theta_cr))."""
    if "uplift_acceleration" in cols:
        return cols["uplift_acceleration"][idx]
    kinds = _structure_kinds(json.loads(study.normalized()))
    if kinds <= {"block", "equivalent_block"}:
        return uplift_acceleration_block(cols["critical_rotation"][idx])
    raise ValueError(
        "the design has no uplift_acceleration column, and structures of kind "
        f"{sorted(kinds)} do not lift off at g tan(theta_cr): make the design again"
    )


# ------------------------------------------------------------------ Monte Carlo rows


#: power of |scale| with which each value of the velocity pulse follows the scale factor (the
#: measures follow their own, :func:`rockstudy.motions.measures.power`).
_PULSE_POWER = {"pulse_amplitude": 1, "pulse_period": 0, "pulse_indicator": 0}


def sample_outputs(study) -> dict:
    """Per-sample record outputs of a Monte Carlo record study: the factor applied, the
    measures of the scaled record and its groups (see :func:`sample_measures`)."""
    out = {"scale": ("factor applied to the record", "1", "f8", np.nan, None)}
    for k, (long_name, units) in {**record_variables(), **GROUP_VARIABLES}.items():
        out[k] = (f"{long_name} of the scaled record", units, "f8", np.nan, None)
    if study.motion.pga_ratio is not None:
        del out["pga_ratio"]  # a design column already
    if study.motion.scale is not None:
        del out["scale"]  # likewise
    return out


def sample_measures(record, scale, frequency_parameter, uplift) -> dict:
    """Measures and groups of ``record`` scaled by ``scale`` (arrays over samples), from the
    unscaled record's (cached) measures times |scale|^k, their power in the registry (linear
    ones k = 1, Arias intensity 2, durations and periods 0; the pulse's amplitude 1, its period
    and indicator 0); groups as in
    :func:`rockstudy.similarity.record_groups` (PGA / a_up, PGV p / a_up, omega_p / p and
    omega_p v_p / a_up, with ``uplift`` = a_up [m/s^2] the structures' uplift acceleration).
    A floor motion is measured by its ground record's measures
    (:func:`rockstudy.motions.building.ground_record`), as the designs measure it."""
    record = ground_record(record)
    ims = {k: v for k, v in record.intensity_measures().items() if k in measures.listed(False)}
    pulse = record.pulse()
    ims.update(
        pulse_period=pulse.period, pulse_amplitude=pulse.amplitude, pulse_indicator=pulse.indicator
    )
    s = np.abs(np.asarray(scale, float))
    out = {}
    for k, v in ims.items():
        out[k] = float(v) * s ** (_PULSE_POWER[k] if k in _PULSE_POWER else measures.power(k))
    w_p = 2.0 * np.pi / pulse.period if pulse.amplitude > 0 else np.nan
    out["pga_ratio"] = out["pga"] / uplift
    out["pgv_ratio"] = out["pgv"] * frequency_parameter / uplift
    out["pulse_frequency_ratio"] = w_p / frequency_parameter
    out["pulse_amplitude_ratio"] = w_p * out["pulse_amplitude"] / uplift
    out["scale"] = np.asarray(scale, float)
    return out


def scale_factors(study, record, cols, idx) -> np.ndarray:
    """The factor on ``record`` of the rows ``idx``: ``scale``; or the factor that brings
    its PGA to ``pga_ratio`` a_up (the structure's uplift acceleration, :func:`uplift_column`);
    or its ``scale_to.im`` to ``target``. A floor motion is scaled by its ground record's
    measure (:func:`rockstudy.motions.building.ground_record`: the building is linear, so the
    ground record scaled by s gives the floor motion scaled by s), as the designs scale it."""
    record = ground_record(record)
    alpha = cols["critical_rotation"][idx]
    uplift = uplift_column(study, cols, idx)
    if "scale" in cols:
        return cols["scale"][idx]
    if "pga_ratio" in cols:
        return cols["pga_ratio"][idx] * uplift / record.peak
    t = study.motion.scale_to
    structures = {
        "critical_rotation": alpha,
        "frequency_parameter": cols["frequency_parameter"][idx],
        "uplift_acceleration": uplift,
    }
    measure = rd._record_measure(record, t.im, t.period, t.damping, structures)
    return rd._scale_for(cols["target"][idx], measure, t.im)


#: Coordinates and variables of a record design's Dataset outside the tables above.
OTHER_VARIABLES = (
    "record",
    "record_name",
    "structure",
    "level",
    "level_index",
    "period",
    "step",
    "scale",
    "target",
    "status",
    "kernel_status",
    "censored",
    "vertical_component",
    "error",
)

# the names of the tables above cannot be a measure's (they are stored beside the measures)
measures.reserve_names(
    (
        *PULSE_VARIABLES,
        *GROUP_VARIABLES,
        *STRUCTURE_VARIABLES,
        *_RUN,
        *_IDA,
        *_ida_rocking_outputs("1"),
        *CONTACT_VARIABLES,
        *_STEPS,
        *OTHER_VARIABLES,
    ),
    "the record designs",
)
