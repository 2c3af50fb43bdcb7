"""Evaluate a chunk of design rows: the function each dask task runs.

It takes plain numpy columns and the normalised study, calls the batch entry point of the
engine, and returns the requested outputs with a per-sample status (1 ok, 2 failed) and error
message. A row whose kernel fails (step limit, or an exception isolated by re-running the rows
one by one) is recorded as failed; overturning is an outcome, not a failure.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ...dynamics import outputs as _outputs
from ...dynamics.batch import CONTACT_OUTPUTS, SLIDE_OUTPUTS, simulate_batch
from ...dynamics.batch import OUTPUTS as BATCH_OUTPUTS
from ...motions import stochastic_record
from ..designs import record_rows
from ..spec.feasibility import record_path
from ..spec.schema import Study

__all__ = [
    "engine_outputs",
    "evaluate_chunk",
    "OUTPUTS",
    "resolve_file",
    "STATUS_FAILED",
    "STATUS_OK",
    "STATUS_PENDING",
]

STATUS_PENDING, STATUS_OK, STATUS_FAILED = 0, 1, 2


def _stored(output) -> tuple:
    """(long_name, units, dtype, fill value for failed rows) of a study's output, from its
    entry in :data:`rockstudy.dynamics.outputs.OUTPUTS` (the fill named where it is not NaN)."""
    fill = output.fill
    failed = "" if np.isnan(fill) else f"; {fill} if failed"
    return (output.long_name + failed, output.units, output.store_dtype, fill)


#: Outputs a study may keep: (long_name, units, dtype, fill value for failed rows)
OUTPUTS = {name: _stored(_outputs.OUTPUTS[name]) for name in _outputs.STUDY_OUTPUTS}


def resolve_file(name: str, base_dir) -> Path:
    """A record path as written in a study: see
    :func:`rockstudy.study.spec.feasibility.record_path`."""
    return record_path(name, base_dir)


def engine_outputs(study: Study) -> tuple:
    """The outputs of :func:`simulate_batch` that the study's outputs need (``auto`` runs the
    linear model only where no output outside its bound is asked for)."""
    names = {"max_rotation" if n == "max_rotation_ratio" else n for n in study.run.outputs}
    engine = BATCH_OUTPUTS + CONTACT_OUTPUTS + SLIDE_OUTPUTS
    return tuple(n for n in engine if n in names or n == "status")


def _model_arguments(study: Study) -> dict:
    """The contact model's arguments of :func:`simulate_batch` (``run.model`` and the
    study's ``friction``); none under ``"rocking"``, whose friction check the outputs ask
    for."""
    if study.run.model == "rocking":
        return {}
    return {"model": study.run.model, "friction": study.friction}


def _run_rows(study: Study, cols: dict, idx: np.ndarray, base_dir) -> dict:
    """Engine outputs for the rows ``idx`` of the chunk columns (may raise)."""
    mo = study.motion
    common = dict(
        frequency_parameter=cols["frequency_parameter"][idx],
        critical_rotation=cols["critical_rotation"][idx],
        restitution=cols["restitution"][idx],
        method=study.run.method,
        rtol=study.run.rtol,
        max_steps=study.run.max_steps,
        outputs=engine_outputs(study),
        **_model_arguments(study),
    )
    if mo.kind == "pulse":
        return simulate_batch(
            pulse=mo.shape,
            amplitude=cols["amplitude"][idx],
            period=cols["period"][idx],
            cycles=mo.cycles,
            **common,
        )
    uplift = record_rows.uplift_column(study, cols, idx)  # a_up: g tan(alpha) for a block
    if mo.kind == "record":
        out = {}
        rec_idx = cols["record"][idx]
        motion_json = mo.model_dump_json()
        for r in np.unique(rec_idx):
            sel = rec_idx == r
            rec = record_rows.load_record(motion_json, base_dir, int(r))
            scale = record_rows.scale_factors(study, rec, cols, idx[sel])
            part = simulate_batch(
                record=rec,
                scale=scale,
                **{k: (v[sel] if isinstance(v, np.ndarray) else v) for k, v in common.items()},
            )
            part.update(
                record_rows.sample_measures(
                    rec, scale, common["frequency_parameter"][sel], uplift[sel]
                )
            )
            for k, v in part.items():
                out.setdefault(k, np.empty(idx.size, np.asarray(v).dtype))[sel] = v
        return out
    out = {}
    for j, i in enumerate(idx):  # stochastic: one seeded record per sample
        seed = np.random.SeedSequence(study.seed, spawn_key=(2, int(cols["sample"][i])))
        rec = stochastic_record(
            peak=cols["pga_ratio"][i] * uplift[j],
            duration=mo.duration,
            dt=mo.dt,
            ground_frequency=mo.ground_frequency,
            ground_damping=mo.ground_damping,
            seed=seed,
        )
        part = simulate_batch(
            record=rec,
            **{k: (v[j : j + 1] if isinstance(v, np.ndarray) else v) for k, v in common.items()},
        )
        for k, v in part.items():
            out.setdefault(k, np.empty(idx.size, v.dtype))[j] = v[0]
    return out


def evaluate_chunk(study_json: str, cols: dict, base_dir=None) -> dict:
    """Outputs, ``status`` and ``error`` for one chunk of design columns.

    Parameters
    ----------
    study_json : str
        The normalised study (:meth:`Study.normalized`).
    cols : dict of ndarray
        Design columns of the chunk (``sample``, ``frequency_parameter``,
        ``critical_rotation``, ``restitution`` and the motion's columns).
    """
    import numba

    numba.set_num_threads(1)  # one task per core: no nested threading
    study = Study.model_validate(json.loads(study_json))
    if study.design is not None:
        return _design_chunk(study, cols, base_dir)
    n = cols["sample"].size
    wanted = study.run.outputs
    result = {name: np.full(n, OUTPUTS[name][3], dtype=OUTPUTS[name][2]) for name in wanted}
    status = np.full(n, STATUS_OK, dtype=np.int8)
    error = np.full(n, "", dtype=object)  # whole messages (a variable-length text array)
    try:
        raw = _run_rows(study, cols, np.arange(n), base_dir)
        failed = np.zeros(n, bool)
    except Exception:  # isolate the failing rows, keep the others
        raw, failed = _rows_one_by_one(study, cols, base_dir, error)
    kernel_failed = (raw["status"] != 0) & ~failed
    error[kernel_failed] = f"kernel stopped: more than max_steps={study.run.max_steps} steps"
    failed |= kernel_failed
    status[failed] = STATUS_FAILED
    ok = ~failed
    for name in wanted:
        if name == "max_rotation_ratio":
            values = raw["max_rotation"] / cols["critical_rotation"]
        else:
            values = raw[name]
        result[name][ok] = values[ok].astype(OUTPUTS[name][2])
    if study.motion.kind == "record":  # the record's measures and groups, per sample
        for name in record_rows.sample_outputs(study):  # (not the design's columns)
            result[name] = np.where(ok, raw[name], np.nan)
    result["status"] = status
    result["error"] = error
    return result


def _design_chunk(study, cols, base_dir) -> dict:
    """Outputs, ``status`` and ``error`` of rows of a record design (one record per chunk):
    a design call that raises fails its rows, with its message; a row whose simulations hit
    the step limit (the design's own status) fails too, its outputs kept."""
    n = cols["sample"].size
    try:
        result = record_rows.evaluate_rows(study, cols, base_dir)
        failed = result["kernel_status"] == 1  # 2: a free-fall point, censored, not failed
        message = f"kernel stopped: more than max_steps={study.run.max_steps} steps"
    except Exception as exc:  # recorded per row, never aborts the run
        result = record_rows.empty_rows(study, n)
        failed = np.ones(n, bool)
        message = f"{type(exc).__name__}: {exc}"
    result["status"] = np.where(failed, STATUS_FAILED, STATUS_OK).astype(np.int8)
    result["error"] = np.where(failed, message, "").astype(object)
    return result


def _rows_one_by_one(study, cols, base_dir, error):
    n = cols["sample"].size
    names = engine_outputs(study)
    if study.motion.kind == "record":
        names += tuple(record_rows.sample_outputs(study))
    raw = {k: np.zeros(n) for k in names}
    failed = np.zeros(n, bool)
    for i in range(n):
        try:
            one = _run_rows(study, cols, np.array([i]), base_dir)
            for k in raw:
                raw[k][i] = one[k][0]
        except Exception as exc:  # recorded per sample, never aborts the run
            failed[i] = True
            error[i] = f"{type(exc).__name__}: {exc}"  # whole
    return raw, failed
