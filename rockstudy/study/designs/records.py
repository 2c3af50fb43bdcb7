"""Record designs on top of :func:`rockstudy.simulate_batch`: cloud, multiple-stripe analysis
and incremental dynamic analysis (IDA) by a ladder refined by bisection.

Each design runs one batch call per record (all structures and scales of the record in it; IDA
one call per record and iteration: a few ladder rungs of every structure, or one bisection
step) and returns an :class:`xarray.Dataset` on the dimensions
``record`` and ``structure`` (and ``level`` for stripes, ``step`` for the IDA points), with each
record's intensity measures (:meth:`rockstudy.motions.Record.intensity_measures`), its pulse
(:meth:`rockstudy.motions.Record.pulse`) and its dimensionless groups for each structure
(:func:`rockstudy.similarity.record_groups`) as variables, all of the unscaled record, and
``vertical_component`` (whether the record has one: without, nothing overturns below a
structure's uplift PGA, which :func:`rockstudy.study.analysis.risk.object_risk` uses). The
intensity of a scaled record is its unscaled value times ``scale`` (``scale`` squared for Arias
intensity); :func:`rockstudy.study.analysis.record_fragility.intensity` forms it in quoted units.

A floor motion (:func:`rockstudy.motions.floor_motion`) is simulated as the object feels it,
but measured, scaled and reported in its ground record's measures
(:func:`rockstudy.motions.building.ground_record`): the building is linear, so the ground
record scaled by s gives the floor motion scaled by s, and the capacities are in the measure
of the site's hazard curve.

Rocking is not monotonic in intensity: a block that overturns at one scale can survive a
higher one. The IDA reports the first overturning rung of a ladder of 1 % steps (refined by
bisection) and the switch band above it, where the block is seen to survive again.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import xarray as xr

from ... import _validate
from ...constants import G
from ...dynamics import outputs as _outputs
from ...dynamics import simulate_batch
from ...dynamics._vertical import uplift_ratio
from ...dynamics.batch import CONTACT_OUTPUTS, MODEL_CONTACT, SLIDE_OUTPUTS
from ...dynamics.constants import STATUS_MAX_STEPS, STATUS_UNCONVERGED
from ...dynamics.methods import MAX_STEPS
from ...dynamics.simulate import check_friction
from ...motions import Record
from ...motions import intensity as _im
from ...motions import measures as _ms
from ...motions.building import ground_record
from ...structures.block import (
    block_parameters,
    frequency_parameter,
    restitution_housner,
    uplift_acceleration,
    uplift_acceleration_block,
)
from ..spec.feasibility import free_fall_scale
from ..spec.ida_options import IdaOptions
from . import ida_slides, ida_states, two_body_rows

__all__ = [
    "CENSORED_REASONS",
    "stored_measures",
    "cf_flags",
    "cloud",
    "failed_points",
    "FAILURES",
    "incremental_dynamic_analysis",
    "multiple_stripes",
    "record_labels",
    "STATUS_FREE_FALL",
    "STEP_KINDS",
    "STEP_MODEL_VARIABLES",
    "STEP_VARIABLES",
]

_STRUCTURE_KEYS = (
    "half_diagonal",
    "frequency_parameter",
    "critical_rotation",
    "slenderness",  # the block's name of critical_rotation (an alias)
    "restitution",
    "uplift_acceleration",  # a_up [m/s^2]; g tan(critical_rotation) (a block's) if not given
)


# ------------------------------------------------------------------------------ inputs


def _records(records) -> list[Record]:
    records = list(records) if isinstance(records, (list, tuple)) else [records]
    if not records:
        raise ValueError("records: give at least one Record")
    for i, r in enumerate(records):
        if not isinstance(r, Record):
            raise TypeError(f"records[{i}] must be a rockstudy Record, got {type(r).__name__}")
    return records


def _is_structure(value) -> bool:
    return (
        hasattr(value, "equivalent_block")
        or hasattr(value, "frequency_parameter")
        or two_body_rows.is_two_body(value)
    )


def _named(structures: dict) -> tuple[list[str], list]:
    """The names and structures of a dict ``{name: structure}`` (names: non-empty strings
    without a NUL character, as in a study file)."""
    for i, (name, value) in enumerate(structures.items()):
        if not isinstance(name, str) or not name.strip() or "\0" in name:
            raise ValueError(
                f"structures: object {i} has the name {name!r}; give a non-empty str without "
                "a NUL character"
            )
        if not _is_structure(value):
            raise TypeError(
                f"structures[{name!r}] must be a rockstudy Block or provide equivalent_block() "
                f"(a dict of names -> structures), got {type(value).__name__}"
            )
    return list(structures), list(structures.values())


def _structures(structures) -> dict:
    """Arrays over ``structure``: p [rad/s], alpha [rad], eta, R [m] (NaN if unknown) and the
    uplift acceleration [m/s^2] (:func:`rockstudy.structures.uplift_acceleration` of a
    structure; of a dict of arrays, its ``uplift_acceleration`` or else a block's g tan(alpha));
    and ``names`` (a list of str, or None) for a dict ``{name: structure}``."""
    names, two_body = None, None
    if isinstance(structures, dict) and "two_body" in structures:  # two_body_rows
        structures = dict(structures)
        two_body = two_body_rows.two_body_column({"two_body": structures.pop("two_body")})
    if isinstance(structures, dict) and not structures:
        raise ValueError("structures: give at least one structure")
    if isinstance(structures, dict) and any(_is_structure(v) for v in structures.values()):
        names, structures = _named(structures)
    columns = two_body_rows.design_columns(structures)
    if columns is not None:  # structures with a plinth or an isolator: their columns
        two_body = two_body_rows.two_body_column({"two_body": columns.pop("two_body")})
        structures = columns
    if isinstance(structures, dict):
        unknown = set(structures) - set(_STRUCTURE_KEYS)
        if unknown:
            raise ValueError(
                f"structures: unknown keys {sorted(unknown)}; allowed {list(_STRUCTURE_KEYS)}"
            )
        if ("half_diagonal" in structures) == ("frequency_parameter" in structures):
            raise ValueError("structures: give exactly one of half_diagonal or frequency_parameter")
        if ("critical_rotation" in structures) == ("slenderness" in structures):
            raise ValueError(
                "structures: give critical_rotation [rad] (or its alias for a block, "
                "slenderness), exactly once"
            )
        theta_cr = "slenderness" if "slenderness" in structures else "critical_rotation"
        arrays = {k: np.atleast_1d(np.asarray(v, float)) for k, v in structures.items()}
        n = int(np.prod(np.broadcast_shapes(*(a.shape for a in arrays.values()))))
        arrays = {k: np.broadcast_to(a, (n,)).ravel() for k, a in arrays.items()}
        alpha = arrays[theta_cr]
        _check(f"structures.{theta_cr}", alpha, 0.0, math.pi / 2)
        if "half_diagonal" in arrays:
            R = arrays["half_diagonal"]
            _check("structures.half_diagonal", R, 0.0, math.inf)
            p = np.array([frequency_parameter(r) for r in R])
        else:
            R = np.full(n, np.nan)
            p = arrays["frequency_parameter"]
            _check("structures.frequency_parameter", p, 0.0, math.inf)
        if "restitution" in arrays:
            eta = arrays["restitution"]
            _check("structures.restitution", eta, 0.0, 1.0 + 1e-300)
        else:
            eta = np.array([restitution_housner(a) for a in alpha])
        if "uplift_acceleration" in arrays:
            uplift = arrays["uplift_acceleration"]
            _check("structures.uplift_acceleration", uplift, 0.0, math.inf)
        else:
            uplift = uplift_acceleration_block(alpha)
    else:
        items = list(structures)
        if not items:
            raise ValueError("structures: give at least one structure")
        params = np.array([block_parameters(s) for s in items], float).reshape(-1, 3)
        p, alpha, eta = params.T
        R = np.array([float(getattr(s, "half_diagonal", np.nan)) for s in items])
        uplift = np.array([uplift_acceleration(s) for s in items])
    return {
        "frequency_parameter": p,
        "critical_rotation": alpha,
        "restitution": eta,
        "half_diagonal": R,
        "uplift_acceleration": uplift,
        "names": names,
        "two_body": two_body,
    }


def _check(name, arr, low, high):
    bad = ~np.isfinite(arr) | (arr <= low) | (arr >= high)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{i}] = {arr[i]!r} is outside ({low:g}, {high:g})")


def _friction_check(friction, contact, n: int) -> bool:
    """Whether the design computes the friction check (``friction_demand``, ``lift_off``):
    ``friction`` is the friction coefficient mu in (0, 10]
    (:data:`~rockstudy.dynamics.simulate.MAX_FRICTION`), one number or one per structure
    (``n``; NaN: none for that structure), or None. ``contact`` is its deprecated spelling
    (True or False, with a FutureWarning). A ValueError or TypeError names ``friction`` (or
    ``contact``) otherwise."""
    if contact is not None:
        contact = _validate.flag("contact", contact)
        warnings.warn(
            "contact= of the record designs is deprecated: give friction=mu, the friction "
            "coefficient of the contact check (as simulate(friction=) and a study's friction)",
            FutureWarning,
            stacklevel=3,
        )
    if friction is None:
        return bool(contact)
    if isinstance(friction, tuple):  # (mu_s, mu_k): each checked as one mu (their order by
        return all(_friction_check(f, None, n) for f in _friction_pair(friction))  # the model)
    if np.ndim(friction) == 0:
        check_friction(friction)
        return True
    mu = np.asarray(friction, dtype=object)
    if mu.ndim != 1 or mu.size != n:
        raise ValueError(f"friction: give one number or one per structure ({n}), got {friction!r}")
    for m in mu:  # NaN: no coefficient for that structure
        if not (isinstance(m, float) and math.isnan(m)):
            check_friction(m)
    return True


def _target(im, period, periods):
    """Check the scaling measure (:func:`rockstudy.motions.measures.scale_targets`); return the
    periods to store (with ``period`` for a measure that needs one)."""
    m = _ms.target(im)
    periods = [] if periods is None else [float(t) for t in np.atleast_1d(periods)]
    if m.needs_period:
        if period is None:
            raise ValueError(f"im={im!r} needs a period [s]")
        period = float(_im.check_periods(period)[0])
        if period not in periods:
            periods.append(period)
    elif period is not None:
        raise ValueError(f"period is only for the measures that need one, not im={im!r}")
    return period, np.array(sorted(periods), float)


def _record_measure(record, im, period, damping, structures):
    """The unscaled record's measure ``im`` [SI, or dimensionless], per structure (array)."""
    ratio = _ms.RATIOS.get(im)
    base = im if ratio is None else ratio.base
    value = record.intensity_measure(base, period=period, damping=damping)
    value = np.full(structures["critical_rotation"].size, value)
    if ratio is not None:
        p = structures["frequency_parameter"]
        value = value * p**ratio.p_power / structures["uplift_acceleration"]
    if not np.all(np.isfinite(value) & (value > 0)):
        raise ValueError(
            f"im={im!r}: the record {record.name!r} has {base} = {float(value[0])!r}, so no "
            "scale factor reaches a target level"
        )
    return value


def _scale_for(level, measure, im):
    """Scale factor(s) that bring ``measure`` to ``level``: the ratio to the power 1 / k of
    the measure (:func:`rockstudy.motions.measures.power`; Arias k = 2)."""
    ratio = level / measure
    return ratio ** (1.0 / _ms.power(im))


# ------------------------------------------------------------------------------ tables


def stored_measures(im=None, extra_measures=()) -> tuple[str, ...]:
    """The measures of the registry a design stores per record besides the listed ones
    (:func:`rockstudy.motions.measures.listed`): that of ``im`` (a scale target; none for a
    ratio, whose measure is listed) and ``extra_measures`` (names of the registry), those
    not listed, in order: e.g. ``pga_rotd50``, a measure of a pair of components."""
    if isinstance(extra_measures, str):
        extra_measures = (extra_measures,)
    names = [] if im is None else [_ms.target(im).name]
    names += [_ms.measure(k, "extra_measures").name for k in extra_measures]
    return tuple(k for k in dict.fromkeys(names) if not _ms.MEASURES[k].listed)


def _unlisted_values(grounds, names, periods, damping) -> dict:
    """The variables of the measures ``names`` (:func:`stored_measures`) of the ground
    records: on ``record``, and on ``period`` too for those that need one."""
    data = {}
    for k in names:
        m = _ms.MEASURES[k]
        if m.needs_period and not len(periods):
            raise ValueError(f"extra_measures: {k!r} needs a period [s]: give it in periods")
        if m.needs_period:
            values = [[r.intensity_measure(k, t, damping) for t in periods] for r in grounds]
            data[k] = (("record", "period"), np.array(values, float).reshape(-1, len(periods)))
        else:
            values = [r.intensity_measure(k, damping=damping) for r in grounds]
            data[k] = ("record", np.array(values, float))
    return data


def _record_dataset(records, structures, periods, damping, unlisted=()) -> xr.Dataset:
    """Measures of the unscaled records (on ``record``; on ``period`` too for those that need
    one), those of ``unlisted`` (:func:`stored_measures`) too, and their groups for each
    structure."""
    grounds = [ground_record(r) for r in records]  # a floor motion reports its ground's
    ims = [r.intensity_measures(periods=periods, damping=damping) for r in grounds]
    pulses = [r.pulse() for r in grounds]
    data = {k: ("record", np.array([m[k] for m in ims], float)) for k in _ms.listed(False)}
    for k in _ms.listed(True) if len(periods) else ():  # (netCDF-3 reads no empty inner axis)
        data[k] = (
            ("record", "period"),
            np.array([m[k] for m in ims], float).reshape(len(ims), len(periods)),
        )
    data.update(_unlisted_values(grounds, unlisted, periods, damping))
    data["pulse_period"] = ("record", np.array([q.period for q in pulses], float))
    data["pulse_amplitude"] = ("record", np.array([q.amplitude for q in pulses], float))
    data["pulse_indicator"] = ("record", np.array([q.indicator for q in pulses], float))
    data["vertical_component"] = ("record", np.array([r.vertical is not None for r in records]))
    data["measured_motion"] = ("record", np.array([ground_record(r) is r for r in records]))
    data["uplift_bounds"] = ("structure", two_body_rows.uplift_bounds(structures))
    for k, v in structures.items():
        if k not in ("names", "two_body"):
            data[k] = ("structure", v)
    data["slenderness"] = data["critical_rotation"]  # the block's name, kept
    names = structures.get("names")  # None: sampled structures, numbered
    ds = xr.Dataset(
        data,
        coords={
            "record": record_labels([r.name for r in records]),
            "structure": np.arange(structures["critical_rotation"].size)
            if names is None
            else np.array(names, dtype=object),
            "period": periods,
            "record_name": ("record", np.array([r.name for r in records], dtype=object)),
        },
        attrs={"damping": damping},
    )
    up, p = ds["uplift_acceleration"], ds["frequency_parameter"]
    w_p = xr.where(ds["pulse_amplitude"] > 0, 2.0 * np.pi / ds["pulse_period"], np.nan)
    ds["pga_ratio"] = ds["pga"] / up
    ds["pgv_ratio"] = ds["pgv"] * p / up
    ds["pulse_frequency_ratio"] = w_p / p
    ds["pulse_amplitude_ratio"] = w_p * ds["pulse_amplitude"] / up
    ratios = ("pga_ratio", "pgv_ratio", "pulse_frequency_ratio", "pulse_amplitude_ratio")
    units = {
        **{k: m.unit for k, m in _ms.MEASURES.items()},
        "pulse_period": "s",
        "pulse_amplitude": "m/s",
        **dict.fromkeys(ratios, "1"),
    }
    for k, unit in units.items():  # every intensity measure carries its units
        if k in ds:
            ds[k].attrs["units"] = unit
    return ds


def record_labels(names) -> np.ndarray:
    """The ``record`` coordinate: each record's name, with ``#2``, ``#3`` ... after a name that
    is already taken (a suite may hold one record twice, or several unnamed ones)."""
    seen: dict[str, int] = {}
    labels = []
    for name in map(str, names):
        seen[name] = seen.get(name, 0) + 1
        labels.append(name if seen[name] == 1 else f"{name}#{seen[name]}")
    if len(set(labels)) < len(labels):  # a given name that reads like a numbered one
        labels = [f"{k}: {x}" for k, x in enumerate(map(str, names))]
    return np.array(labels, dtype=object)


def _run(record, structures, idx, scales, method, rtol, max_steps, outputs=None, model=None):
    """simulate_batch on the structures ``idx`` (array) at ``scales`` (same length);
    ``model`` = (model, friction of each structure) runs the contact model
    (:func:`rockstudy.simulate_batch`'s ``model`` and ``friction``)."""
    if two_body_rows.two_body_column(structures) is not None:  # their rows: structure=
        single = {**structures, "two_body": None}
        args = (method, rtol, max_steps, outputs, model)
        blocks = lambda i, s: _run(record, single, i, s, *args)  # noqa: E731
        return two_body_rows.run_points(
            record, structures, idx, scales, rtol, max_steps, outputs, model, blocks
        )
    contact_model = {}
    if model is not None:
        contact_model = {"model": model[0], "friction": (model[1][0][idx], model[1][1][idx])}
    return simulate_batch(
        frequency_parameter=structures["frequency_parameter"][idx],
        critical_rotation=structures["critical_rotation"][idx],
        restitution=structures["restitution"][idx],
        record=record,
        scale=scales,
        method=method,
        rtol=rtol,
        max_steps=max_steps,
        outputs=outputs,
        **contact_model,
    )


def _friction_pair(friction) -> tuple:
    """(mu_s, mu_k) of a design's ``friction``: a tuple (mu_s, mu_k) as
    :func:`rockstudy.simulate_batch` takes it (each one or one per structure), else
    (friction, friction)."""
    if not isinstance(friction, tuple):
        return friction, friction
    if len(friction) != 2:
        raise ValueError(f"friction: a tuple is (mu_s, mu_k), got {len(friction)} values")
    return friction


def _contact_model(model, friction, n):
    """(model, (mu_s, mu_k) of each of the n structures: shape (2, n)) for :func:`_run`, or
    None under Housner's model (``model="rocking"``, where ``friction`` gives the friction
    check only); a ValueError naming the argument otherwise (the contact model needs every
    mu, and mu_s >= mu_k)."""
    if model == "rocking":
        return None
    if model not in ("contact", "auto"):
        raise ValueError(f"model must be 'rocking', 'contact' or 'auto', got {model!r}")
    if friction is None:
        raise ValueError(f"model={model!r} runs the contact model, which needs friction=")
    pair = []
    for mu in map(np.asarray, _friction_pair(friction)):
        if mu.ndim > 1 or mu.size not in (1, n):
            raise ValueError(f"friction: give one coefficient or one per structure ({n})")
        if np.isnan(mu.astype(float)).any():
            raise ValueError(f"friction: model={model!r} needs a coefficient for every structure")
        pair.append(np.broadcast_to(mu.astype(float).ravel(), (n,)))
    if np.any(pair[1] > pair[0]):
        j = int(np.flatnonzero(pair[1] > pair[0])[0])
        raise ValueError(
            f"friction: structure {j}: the kinetic coefficient {pair[1][j]!r} exceeds the "
            f"static {pair[0][j]!r} (give (mu_s, mu_k) with mu_s >= mu_k)"
        )
    return model, np.stack(pair)


def _friction_variables(ds, model):
    """``ds`` with ``friction_static`` and ``friction_kinetic`` (mu_s, mu_k of each structure)
    under the contact model (``model`` of :func:`_contact_model`)."""
    if model is not None:
        for name, mu in zip(("friction_static", "friction_kinetic"), model[1], strict=True):
            ds[name] = (
                "structure",
                np.array(mu),
                {"units": "1", "long_name": name.replace("_", " ") + " coefficient"},
            )
    return ds


#: What a design keeps of the contact model: the model of each point, its slip and regimes.
MODEL_KEYS = ("model", *SLIDE_OUTPUTS)
#: The contact model's outputs of each point of an IDA curve (:data:`MODEL_KEYS`).
STEP_MODEL_VARIABLES = tuple(f"step_{k}" for k in MODEL_KEYS)


#: Kept under ``model="auto"`` besides :data:`MODEL_KEYS`: Housner's overturning decision of
#: every point (the rocking-only answer, which "auto" computes first).
ROCKING_KEYS = ("overturned_rocking",)
#: The batch outputs of Housner's answer under ``model="auto"`` (its decision and status).
HOUSNER_OUTPUTS = ("overturned_rocking", "status_rocking")


def _keys(contact, model):
    """The outputs a design keeps: :data:`_OUT`, the friction check with ``contact``,
    :data:`MODEL_KEYS` under the contact model (``model`` not None) and :data:`ROCKING_KEYS`
    under ``"auto"``."""
    keys = _OUT + (CONTACT_OUTPUTS if contact else ()) + (() if model is None else MODEL_KEYS)
    return keys + (ROCKING_KEYS if _auto(model) else ())


def _auto(model) -> bool:
    """Whether ``model`` (:func:`_contact_model`'s) is ``"auto"``."""
    return model is not None and model[0] == "auto"


def _rocking_decision(run):
    """Housner's ``overturned`` of each point of an ``"auto"`` run ``run`` (int8, -1 where
    Housner's model failed): the batch's ``overturned_rocking``, -1 where its
    ``status_rocking`` is not 0 on a point the contact model answered (``model`` 3, or 4 by
    its reference) and where the point's ``status`` is not 0 on the others (Housner's
    answer, its friction check included)."""
    decision = np.asarray(run["overturned_rocking"], np.int8).copy()
    answered = np.asarray(run["model"]) >= MODEL_CONTACT
    status = np.where(answered, run["status_rocking"], run["status"])
    decision[status != 0] = -1
    return decision


_OUT = ("max_rotation", "overturned", "n_impacts", "overturn_time", "status")
#: ``status`` of a stripe point not run: its scaled vertical reaches -g (free fall), where
#: Housner's model does not apply; the point is censored (``censored``), the others run.
STATUS_FREE_FALL = 2
#: The failures a design's ``status`` names, by the bit of the code that says each (a point's
#: status is its batch row's; an IDA's, per record and structure, the OR of its points').
FAILURES = {STATUS_MAX_STEPS: "step limit", STATUS_UNCONVERGED: "not converged"}


def failed_points(status) -> dict:
    """{failure name of :data:`FAILURES`: the number of entries of ``status`` (a design's)
    that carry it}."""
    status = np.asarray(status, np.int64)
    return {name: int(np.count_nonzero(status & code)) for code, name in FAILURES.items()}


def _run_below_free_fall(
    record, st, idx, scales, method, rtol, max_steps, contact=False, model=None
):
    """:func:`_run` on the points whose |scale| stays below the record's free-fall scale;
    the others get ``status`` :data:`STATUS_FREE_FALL`, NaN rotation and time, no overturning
    and -1 impacts. With ``contact``, also ``friction_demand`` (NaN where not run) and
    ``lift_off`` (see :func:`rockstudy.simulate_batch`); with ``model`` (:func:`_contact_model`)
    the contact model's outputs (their failed-row fill where not run)."""
    ok = np.abs(scales) < free_fall_scale(record)
    out = {
        "max_rotation": np.full(scales.size, np.nan),
        "overturned": np.zeros(scales.size, bool),
        "n_impacts": np.full(scales.size, -1, np.int64),
        "overturn_time": np.full(scales.size, np.nan),
        "status": np.full(scales.size, STATUS_FREE_FALL, np.int64),
    }
    keys = _keys(contact, model) + two_body_rows.keys(st)
    out.update(two_body_rows.point_fills(st, scales.size))
    if contact:
        out.update(
            friction_demand=np.full(scales.size, np.nan), lift_off=np.zeros(scales.size, bool)
        )
    for name in MODEL_KEYS if model is not None else ():
        entry = _outputs.OUTPUTS[name]
        out[name] = np.full(scales.size, entry.fill, entry.store_dtype)
    if ROCKING_KEYS[0] in keys:
        out[ROCKING_KEYS[0]] = np.zeros(scales.size, np.int8)
    if ok.any():
        wanted = None
        if contact or model is not None:
            wanted = tuple(k for k in keys if k not in ROCKING_KEYS)
            wanted += HOUSNER_OUTPUTS if _auto(model) else ()
        run = _run(record, st, idx[ok], scales[ok], method, rtol, max_steps, wanted, model)
        if ROCKING_KEYS[0] in keys:
            run[ROCKING_KEYS[0]] = _rocking_decision(run)
        for k in keys:
            out[k][ok] = run[k]
    return out


# ------------------------------------------------------------------------------ cloud


def cloud(
    records,
    structures,
    periods=(),
    damping: float = 0.05,
    method: str = "nonlinear",
    rtol: float = 1e-8,
    max_steps: int = MAX_STEPS,
    friction=None,
    contact: bool | None = None,
    model: str = "rocking",
    damage_states=None,
    extra_measures=(),
) -> xr.Dataset:
    """Every structure under every record, unscaled (a cloud analysis).

    Parameters
    ----------
    records : Record or sequence of Record
        E.g. from :func:`rockstudy.motions.load_suite`.
    structures : sequence or dict
        Blocks or structures with ``equivalent_block()``; or a dict ``{name: structure}`` of
        them (named objects: the ``structure`` coordinate then carries the names, str, and
        every output keeps them); or a dict of arrays (broadcast) with
        ``critical_rotation`` [rad] (or its alias for a block, ``slenderness``), one of
        ``half_diagonal`` [m] or ``frequency_parameter`` [rad/s], and optionally
        ``restitution`` (default Housner's) and ``uplift_acceleration`` [m/s^2], the ground
        acceleration that starts each structure rocking (default g tan(critical_rotation), a
        block's; give g lambda, eq. 10 of [003], for another structure). The dataset carries
        the critical rotation as ``critical_rotation`` and as ``slenderness``, and the uplift
        acceleration (:func:`rockstudy.structures.uplift_acceleration` of each structure) as
        ``uplift_acceleration``: the groups ``pga_ratio`` etc. are relative to it.
    periods : array_like
        Periods T [s] of the stored spectral accelerations ``sa``.
    damping : float
        Damping ratio of ``sa`` and the spectrum intensity.
    method, rtol, max_steps
        As in :func:`rockstudy.simulate_batch`.
    friction : float or array_like or tuple, optional
        The friction coefficient mu in (0, 10] (one, or one per structure; NaN: none for that
        structure), or a tuple (mu_s, mu_k) of them with mu_s >= mu_k (the contact model's
        static and kinetic coefficients, stored as ``friction_static`` and
        ``friction_kinetic`` on ``structure`` under it), as ``simulate(friction=)`` and a
        study's ``friction``: the design then
        also gives ``friction_demand`` (max abs(F_h / F_v) at the contact; below uplift
        max abs(u_h'') / g) and ``lift_off`` of every point, as
        :attr:`rockstudy.RockingResult.friction_demand` (each point that lifts is run again
        with a history: 1-40 ms a point), for the friction check of the report
        (:func:`~rockstudy.study.report.records.record_report` with the same ``friction``).
    contact : bool, optional
        Deprecated spelling of the friction check without a coefficient (FutureWarning):
        give ``friction`` instead.
    model : {"rocking", "contact", "auto"}
        "contact" or "auto" with ``friction`` (one mu or one per structure, none NaN) runs
        the contact model as :func:`rockstudy.simulate_batch` does, and keeps ``model``,
        ``max_slide``, ``residual_slide``, ``first_slip_time``, ``time_slide``,
        ``time_slide_rock``, ``time_flight`` and ``regime`` of every point ("auto" also
        ``overturned_rocking``: Housner's decision of every point, the rocking-only answer
        of :func:`rockstudy.study.analysis.sliding.contact_effect`); "rocking"
        (default): Housner's model (with the friction check where ``friction`` is given).
    damage_states : mapping, optional
        ``{name: limit}`` (see :mod:`.ida_states`): checked, and kept as
        ``attrs["damage_states"]`` for the fits of each state
        (:mod:`rockstudy.study.analysis.states`).
    extra_measures : sequence of str
        Measures of the registry stored per record besides those it lists
        (:func:`rockstudy.motions.measures.listed`), e.g. ``pga_rotd50`` (a measure of a
        pair: every record needs two horizontal components) for a hazard curve in it; one
        that needs a period is stored at ``periods``. A design stores its own ``im`` so.

    Returns
    -------
    xarray.Dataset
        ``max_rotation`` [rad], ``overturned``, ``n_impacts``, ``overturn_time`` [s] and
        ``status`` on (record, structure), with the record and structure tables. A record
        whose vertical component reaches -g is not run (free fall): ``censored`` and
        ``status`` :data:`STATUS_FREE_FALL` on its points.
    """
    records = _records(records)
    st = _structures(structures)
    contact = _friction_check(friction, contact, st["critical_rotation"].size)
    _, periods = _target("pga", None, periods)
    ds = _record_dataset(records, st, periods, damping, stored_measures(None, extra_measures))
    idx = np.arange(st["critical_rotation"].size)
    ones = np.ones(idx.size)
    model = _contact_model(model, friction, idx.size)
    states = ida_states.damage_states(damage_states, model is not None)
    outs = [
        _run_below_free_fall(r, st, idx, ones, method, rtol, max_steps, contact, model)
        for r in records
    ]
    for k in _keys(contact, model) + two_body_rows.keys(st):
        ds[k] = (("record", "structure"), np.array([o[k] for o in outs]))
    ds["censored"] = ds["status"] == STATUS_FREE_FALL
    ds = _friction_variables(ds, model)
    n_run = int((~ds["censored"]).sum())
    ds.attrs.update(design="cloud", method=method, rtol=rtol, n_simulations=n_run)
    return _with_states(ds, states)


def _with_states(ds, states):
    """``ds`` with the damage ``states`` (if any) as ``attrs["damage_states"]``."""
    if states:
        ds.attrs["damage_states"] = ida_states.states_attr(states)
    return ds


# ------------------------------------------------------------------------------ stripes


def multiple_stripes(
    records,
    structures,
    levels,
    im: str = "pga",
    period=None,
    periods=(),
    damping: float = 0.05,
    method: str = "nonlinear",
    rtol: float = 1e-8,
    max_steps: int = MAX_STEPS,
    friction=None,
    contact: bool | None = None,
    model: str = "rocking",
    damage_states=None,
    extra_measures=(),
) -> xr.Dataset:
    """Multiple-stripe analysis: every record scaled to each intensity level, every structure.

    Parameters
    ----------
    levels : array_like
        Target values (> 0) of ``im``, in its SI units (``pga``, ``sa`` [m/s^2], ``pgv``
        [m/s], ...; see :data:`rockstudy.motions.measures.MEASURES`) or dimensionless for
        ``pga_ratio`` = PGA / (g tan alpha) and ``pgv_ratio`` = PGV p / (g tan alpha), whose
        scale factor differs from structure to structure.
    im : str
        One of :func:`rockstudy.motions.measures.scale_targets`: a measure of the registry
        with a power > 0 (one registered by :func:`rockstudy.motions.register_measure` too),
        ``pga_ratio`` or ``pgv_ratio``.
    period : float, optional
        T [s] of ``sa``, ``psv``, ``sd`` (and of any measure that needs one).
    records, structures, periods, damping, method, rtol, max_steps, friction, contact, model
    damage_states, extra_measures
        As in :func:`cloud` (``im`` is stored always).

    Returns
    -------
    xarray.Dataset
        The outputs of :func:`cloud` on (record, structure, level), and ``scale`` (the factor
        applied to each record), with ``level`` as a coordinate and ``im`` in the attributes.
        A point whose scaled vertical component reaches -g (free fall, outside Housner's
        model) is not run: ``censored`` is True there and ``status`` is
        :data:`STATUS_FREE_FALL` (2), which the fragility fits leave out; the record's
        other points run.
    """
    records = _records(records)
    st = _structures(structures)
    contact = _friction_check(friction, contact, st["critical_rotation"].size)
    period, periods = _target(im, period, periods)
    levels = np.atleast_1d(np.asarray(levels, float))
    if levels.ndim != 1 or not levels.size or not np.all(np.isfinite(levels) & (levels > 0)):
        raise ValueError(f"levels must be one or more finite numbers > 0, got {levels!r}")
    ds = _record_dataset(records, st, periods, damping, stored_measures(im, extra_measures))
    n = st["critical_rotation"].size
    idx = np.repeat(np.arange(n), levels.size)
    model = _contact_model(model, friction, n)
    states = ida_states.damage_states(damage_states, model is not None)
    scales, outs = [], []
    for r in records:
        measure = _record_measure(ground_record(r), im, period, damping, st)
        s = _scale_for(levels[None, :], measure[:, None], im)
        scales.append(s)
        args = (method, rtol, max_steps, contact, model)
        outs.append(_run_below_free_fall(r, st, idx, s.ravel(), *args))
    dims = ("record", "structure", "level")
    ds = ds.assign_coords(level=levels)
    ds["scale"] = (dims, np.array(scales))
    for k in _keys(contact, model) + two_body_rows.keys(st):
        ds[k] = (dims, np.array([o[k] for o in outs]).reshape(len(records), n, levels.size))
    ds["censored"] = ds["status"] == STATUS_FREE_FALL
    ds = _friction_variables(ds, model)
    ds.attrs.update(
        design="stripes",
        im=im,
        im_period=np.nan if period is None else period,
        method=method,
        rtol=rtol,
        n_simulations=int((~ds["censored"]).sum()),
    )
    return _with_states(ds, states)


# ------------------------------------------------------------------------------ IDA


def cf_flags(meanings: dict) -> dict:
    """CF attributes of a flag variable: ``flag_values`` and ``flag_meanings``, one
    space-separated string of words (spaces within a meaning become underscores), as netCDF
    writers need."""
    return {
        "flag_values": np.array(list(meanings), np.int64),
        "flag_meanings": " ".join(m.replace(" ", "_") for m in meanings.values()),
    }


#: ``censored_reason`` of a capacity (CF flag values and meanings).
CENSORED_REASONS = {0: "not censored", 1: "standing at max_pga_ratio", 2: "free fall above"}
#: ``step_kind`` of a simulated point of an IDA curve.
STEP_KINDS = {0: "ladder rung", 1: "bisection", 2: "scan above the first overturning"}
#: Rungs of each structure run in one batch call while the ladder climbs.
_RUNGS_PER_CALL = 8


def incremental_dynamic_analysis(
    records,
    structures,
    im: str = IdaOptions.im,
    period=IdaOptions.period,
    step: float = IdaOptions.step,
    tolerance: float = IdaOptions.tolerance,
    max_pga_ratio: float = IdaOptions.max_pga_ratio,
    scan: int = IdaOptions.scan,
    periods=(),
    damping: float = 0.05,
    method: str = "nonlinear",
    rtol: float = 1e-8,
    max_steps: int = MAX_STEPS,
    friction=None,
    contact: bool | None = None,
    model: str = "rocking",
    slide_limits=(),
    damage_states=None,
    extra_measures=(),
) -> xr.Dataset:
    """The first overturning intensity of each structure under each record, by a ladder.

    For each record, all structures climb together, a few rungs per
    :func:`rockstudy.simulate_batch` call:

    1. **Ladder.** The lowest rung is the scale below which the block cannot leave rest
       (PGA = g alpha without a vertical component; with one, the exact scale at which
       abs(u_h'') first reaches (g + u_v'') alpha, lower under a downward vertical); it is
       simulated like every other rung. Successive rungs differ by the factor ``1 + step``
       (1 % by default) up to PGA = ``max_pga_ratio`` a_up, the structure's uplift
       acceleration (g tan(alpha) of a block, g lambda of another structure, eq. 10 of
       [003]). The climb stops at the
       first rung that overturns; a block standing on every rung is *censored* (reason 1).
    2. **Bisect** (geometrically) between the last surviving rung and the first overturning
       one until their ratio is at most ``1 + tolerance``: the capacity is the upper end.
    3. **Scan** ``scan`` levels from the first overturning rung up to the top, to see the
       survivals above the capacity (the *switch band*, from the capacity to the highest
       scale seen to survive).

    **Vertical component.** The vertical is scaled by abs(scale) and acts as gravity g + u_v''.
    At scales where u_v'' reaches -g (free fall) Housner's model does not apply: the ladder
    stops below that scale, and a block that has not overturned there is censored (reason
    2) at its highest surviving rung; the censored fit of
    :func:`~rockstudy.study.analysis.record_fragility.ida_fragility` takes it as such.

    **The guarantee.** Every rung below the capacity was simulated and survived, so the
    capacity is within ``tolerance`` of the lowest overturning scale of the ladder's grid,
    and no overturning window wider than a step (the factor ``1 + step``) lies below it.
    A window narrower than the step can fall between two rungs and be missed: rocking is
    not monotonic in intensity. Against a dense scan of 1500 log-spaced levels
    (benchmarks/bench_ida.py, step 1 %), the first overturning window was narrower than the
    step in 22 of 25 pairs of five real records x five museum objects and in 38 of 48
    synthetic pairs, and the ladder landed above it in 13 of 25 (median 2.6 % higher, at
    most 1.40 times) and 16 of 48 (median 1.7 %, at most 2.48 times); it never missed a
    window at least one step wide. See docs/records.rst.

    Parameters
    ----------
    im : str
        The measure the capacity is reported in (see :func:`multiple_stripes`); the
        capacities in every other measure follow from ``capacity_scale``.
    step, tolerance, max_pga_ratio, scan
        See :class:`IdaOptions` (ranges checked; a ValueError names the option).
    records, structures, period, periods, damping, method, rtol, max_steps
        As in :func:`multiple_stripes`. ``friction`` (and its deprecated spelling
        ``contact``): also ``friction_demand`` and ``lift_off`` (see :func:`cloud`) at
        ``capacity_scale_lower``, the highest scale simulated below
        the first overturning (of a censored block: the highest it stood at).
        ``method="linear"`` runs the exact piecewise solution of the linearized model for
        records without a vertical component.
    model : {"rocking", "contact", "auto"}
        "contact" or "auto" with ``friction`` (one mu or one per structure) takes every
        overturning decision from the contact model (:func:`rockstudy.simulate_batch`'s
        ``model``), with the same ladder, bisection and guarantee; the lowest rung is then
        the scale below which the block neither lifts nor slips (abs(u_h'') below
        (g + u_v'') min(alpha, mu_s) everywhere), and every point keeps the contact
        model's outputs (``step_model``, ``step_max_slide``, ...). "auto" also climbs
        every ladder under Housner's model (the same ladder, bisection and scan; the rocking
        kernel, cheap beside the contact model) and keeps its answer: ``capacity_rocking``
        (as ``capacity``), ``capacity_scale_rocking``, ``capacity_scale_lower_rocking``,
        ``censored_rocking``, ``status_rocking`` and ``simulations_rocking``, the
        rocking-only answer of :func:`rockstudy.study.analysis.sliding.contact_effect`.
    slide_limits : sequence of float
        Slides d [m] (> 0, increasing; under the contact model only): ``slide_capacity``,
        the first scale at which ``max_slide`` > d (see :func:`.ida_slides.slide_scales`).
    damage_states : mapping, optional
        ``{name: limit}``: damage states on the peak rotation ratio ``|theta|/alpha`` (a limit
        in (0, 1], 1 = overturning) or, under the contact model, on the peak slide
        (``{"slide": d}``, d [m]): ``state_capacity``, the first scale at which each state is
        reached, bisected as the overturning capacity (see :mod:`.ida_states`).
    extra_measures : sequence of str
        As in :func:`cloud` (``im`` is stored always: ``capacity`` is in it).

    Returns
    -------
    xarray.Dataset
        On (record, structure): ``capacity`` (in the units of ``im``; NaN if censored),
        ``capacity_scale`` and ``capacity_scale_lower`` (the final bracket; for a censored
        block the highest scale seen to survive), ``censored`` and ``censored_reason``
        (:data:`CENSORED_REASONS`), ``survives_above_capacity`` (a simulated scale above the
        capacity survived), ``highest_survival_scale`` (the highest such scale: the top of the
        switch band; NaN if none), ``switch_band_overturn_share`` (share of the simulated
        scales inside the switch band that overturn), ``rungs`` (ladder rungs simulated),
        ``simulations`` and ``status`` (0 ok; else the OR of its points' batch codes: 1 a
        simulation hit the step limit, 4 the contact model's answer did not converge, as
        :data:`FAILURES` names them). On
        (record, structure, step), in increasing scale (NaN-padded): every simulated point,
        ``step_scale``, ``step_max_rotation``, ``step_overturned`` and ``step_kind``
        (:data:`STEP_KINDS`): the IDA curves; under the contact model also ``step_<name>``
        for each of :data:`MODEL_KEYS`. With ``slide_limits``: ``slide_capacity`` (in the
        units of ``capacity``) and ``slide_capacity_scale`` on (slide_limit, record,
        structure), NaN where max_slide never exceeded d below the largest rung. With
        ``damage_states``: ``state_capacity`` (in the units of ``capacity``; the overturning
        state's is ``capacity``) and ``state_capacity_scale`` on (damage_state, record,
        structure), NaN where the state was not reached, with ``damage_demand`` and
        ``damage_limit`` on ``damage_state`` and ``attrs["damage_states"]``. ``rungs``
        counts the rungs of both climbs. Attributes: the options and ``n_simulations``.
    """
    options = IdaOptions(im, period, step, tolerance, max_pga_ratio, scan)
    records = _records(records)
    st = _structures(structures)
    n = st["critical_rotation"].size
    contact = _friction_check(friction, contact, n)
    model = _contact_model(model, friction, n)
    limits = ida_slides.slide_limits(slide_limits, model)
    states = ida_states.damage_states(damage_states, model is not None)
    period, periods = _target(im, period, periods)
    ds = _record_dataset(records, st, periods, damping, stored_measures(im, extra_measures))
    measure = np.array(
        [_record_measure(ground_record(r), im, period, damping, st) for r in records]
    )
    args = (options, method, rtol, max_steps, model, limits, states)
    results = [_ida_record(r, st, *args) for r in records]
    ds = _ida_tables(ds, results, model is not None)
    if contact:
        ds["friction_demand"], ds["lift_off"] = _ida_contact(
            records, st, ds, method, rtol, max_steps
        )
    ds["capacity"] = _capacity(ds["capacity_scale"], ds["censored"], measure, im)
    if two_body_rows.keys(st):
        ds = ds.assign(two_body_rows.ida_outputs(records, st, ds, rtol, max_steps))
    if _auto(model):  # Housner's ladder, from the answers the "auto" points gave on the way
        housner = (options, method, rtol, max_steps, None, NO_LIMITS)
        rocking = [
            _ida_record(r, st, *housner, known=res["housner"])
            for r, res in zip(records, results, strict=True)
        ]
        ds = _ida_rocking(ds, rocking, measure, im)
    if limits.size:
        ds = ida_slides.slide_tables(ds, results, limits, measure, _ms.power(im))
    if states:
        ds = ida_states.state_tables(ds, results, states, measure, _ms.power(im))
    ds["censored_reason"].attrs.update(cf_flags(CENSORED_REASONS))
    ds = _friction_variables(ds, model)
    ds.attrs.update(
        design="ida",
        **options.attrs(),
        method=method,
        rtol=rtol,
        n_simulations=sum(
            int(ds[k].sum()) for k in ("simulations", "simulations_rocking") if k in ds
        ),
    )
    return ds


def _capacity(scale, censored, measure, im) -> tuple:
    """The ``capacity`` variable: the capacity scales ``scale`` (record, structure) in the
    measure ``im`` of each record (``measure``), NaN where ``censored``."""
    return (
        ("record", "structure"),
        np.where(censored, np.nan, measure * scale ** _ms.power(im)),
        {
            "units": "1" if im in _ms.RATIOS else _ms.MEASURES[im].unit,
            "long_name": f"overturning {im} (first overturning level)",
        },
    )


#: No slide limits: Housner's ladder of an IDA under ``model="auto"`` has no slide capacities.
NO_LIMITS = np.empty(0)
#: The variables of an IDA kept under ``model="auto"`` for Housner's rocking-only ladder as
#: ``<name>_rocking`` (besides ``capacity_rocking``).
IDA_ROCKING_VARIABLES = ("capacity_scale", "capacity_scale_lower", "censored", "status")


def _ida_rocking(ds, results, measure, im):
    """``ds`` with the rocking-only twins of its capacities: the per-record results of
    :func:`_ida_record` under Housner's model (the same ladder, bisection and scan) as
    ``capacity_rocking``, ``<name>_rocking`` for :data:`IDA_ROCKING_VARIABLES` and
    ``simulations_rocking``."""
    dims = ("record", "structure")
    table = {k: np.array([res[k] for res in results]) for k in _IDA_FLOATS + _IDA_INTS}
    censored = table["censored_reason"] > 0
    for k in IDA_ROCKING_VARIABLES[:2]:
        ds[f"{k}_rocking"] = (dims, table[k].astype(float))
    ds["censored_rocking"] = (dims, censored)
    ds["status_rocking"] = (dims, table["status"].astype(np.int64))
    ds["simulations_rocking"] = (dims, table["simulations"].astype(np.int64))
    ds["capacity_rocking"] = _capacity(ds["capacity_scale_rocking"], censored, measure, im)
    ds["capacity_rocking"].attrs["long_name"] += " under Housner's rocking-only model"
    return ds


_IDA_FLOATS = (
    "capacity_scale",
    "capacity_scale_lower",
    "highest_survival_scale",
    "switch_band_overturn_share",
)
_IDA_INTS = ("censored_reason", "rungs", "simulations", "status")
STEP_VARIABLES = ("step_scale", "step_max_rotation", "step_overturned", "step_kind")


def _ida_contact(records, st, ds, method, rtol, max_steps):
    """(friction_demand, lift_off) on (record, structure) at the highest scale below each
    first overturning (``capacity_scale_lower``)."""
    idx = np.arange(ds.sizes["structure"])
    demand = np.full((len(records), idx.size), np.nan)
    lift = np.zeros(demand.shape, bool)
    for i, r in enumerate(records):
        s = ds["capacity_scale_lower"].values[i]
        ok = np.isfinite(s) & (s > 0)
        if ok.any():
            run = _run(r, st, idx[ok], s[ok], method, rtol, max_steps, CONTACT_OUTPUTS)
            demand[i, ok], lift[i, ok] = run["friction_demand"], run["lift_off"]
    dims = ("record", "structure")
    return (dims, demand), (dims, lift)


def _ida_tables(ds, results, contact_model=False):
    """The per-record results of :func:`_ida_record` as (record, structure[, step]) arrays;
    ``contact_model``: with the contact model's outputs of each point."""
    dims = ("record", "structure")
    for k in _IDA_FLOATS:
        ds[k] = (dims, np.array([res[k] for res in results], float))
    for k in _IDA_INTS:
        ds[k] = (dims, np.array([res[k] for res in results], np.int64))
    ds["censored"] = ds["censored_reason"] > 0
    ds["survives_above_capacity"] = np.isfinite(ds["highest_survival_scale"])
    n_step = max(max(len(h) for h in res["history"]) for res in results)
    names = STEP_VARIABLES + (STEP_MODEL_VARIABLES if contact_model else ())
    steps = np.full((len(results), ds.sizes["structure"], max(n_step, 1), len(names)), np.nan)
    for i, res in enumerate(results):
        for j, h in enumerate(res["history"]):
            if h:
                steps[i, j, : len(h)] = sorted(h)
    for c, k in enumerate(names):
        ds[k] = (dims + ("step",), steps[..., c])
    return ds


def _rest_scale(record, alpha, ceiling):
    """Per structure, a scale at or below which |u_h''| stays under (g + u_v'') alpha
    everywhere: neither model lifts the block (eq. 2.2 of [000] with gravity g + u_v''; the
    linearized model's threshold g alpha is the lower one). Exact without a vertical;
    with one, found by bisection on the uplift ratio (increasing in the scale) below
    ``ceiling`` (the free-fall scale)."""
    g_alpha = G * alpha / record.peak
    if record.vertical is None:
        return g_alpha
    _, _, _, samples, vsamples = record.kernel_spec()
    slope = np.arctan(alpha)  # tan(arctan alpha) = alpha: the linearized threshold

    def ratio(s):
        with np.errstate(divide="ignore"):  # at the ceiling itself g + u_v'' reaches 0
            return uplift_ratio(s, slope, samples, vsamples)

    lo = g_alpha * ceiling / (g_alpha + ceiling) if math.isfinite(ceiling) else g_alpha / 2
    hi = np.minimum(g_alpha * 2.0, ceiling)
    while True:  # widen until the block lifts at hi or hi reaches the free fall
        lifts = ratio(hi) > 1.0
        grow = ~lifts & (hi < ceiling)
        if not grow.any():
            break
        hi = np.where(grow, np.minimum(hi * 2.0, ceiling), hi)
    for _ in range(60):
        mid = np.sqrt(lo * hi)
        up = ratio(mid) > 1.0
        lo, hi = np.where(up, lo, mid), np.where(up, mid, hi)
    return np.where(lifts, lo, ceiling)


def _rest_slope(st, model):
    """The slope of the level (g + u_v'') x below which nothing moves, per structure: the
    linearized rest level alpha; under the contact model (``model``) also mu_s, below which
    the base cannot slip."""
    alpha = st["critical_rotation"]
    return alpha if model is None else np.minimum(alpha, model[1][0])


def _ladder(low, top, ceiling, q):
    """The rungs of one structure: low q^k below min(top, ceiling), then top if it is below
    the free-fall ceiling (at least one rung, every rung below the ceiling)."""
    limit = min(top, ceiling)
    low = min(low, limit if top < ceiling else ceiling / q)
    rungs = low * q ** np.arange(math.ceil(math.log(limit / low) / math.log(q)) + 1)
    rungs = rungs[rungs < limit]
    return np.append(rungs, top) if top < ceiling else rungs


class _Points:
    """Runs batches of (structure, scale) points of one record and keeps every outcome: a
    row (scale, max_rotation, overturned, kind[, the contact model's :data:`MODEL_KEYS`])
    per point (``model``: as :func:`_run`'s).

    Under ``model="auto"`` it also keeps Housner's decision and status of each point
    (:data:`HOUSNER_OUTPUTS`, computed by "auto" first) in :attr:`housner`: {scale:
    (overturned, status)} per structure; Housner's ladder of the same record (``model``
    None) is given them as ``known`` and runs only the points not among them (their
    ``max_rotation``, which no caller of Housner's ladder reads, is NaN in its history)."""

    def __init__(self, record, st, method, rtol, max_steps, model=None, known=None):
        n = st["critical_rotation"].size
        self.args = (record, st, method, rtol, max_steps)
        self.model = model
        self.keys = _IDA_OUT + (() if model is None else MODEL_KEYS)
        self.history = [[] for _ in range(n)]
        self.sims = np.zeros(n, np.int64)
        self.status = np.zeros(n, np.int64)
        self.housner = [{} for _ in range(n)] if known is None else known

    def outcomes(self, idx, scales, kind) -> dict:
        """The outputs (:attr:`keys`) of the structures ``idx`` at ``scales``, kept."""
        out = self._housner_outcomes(idx, scales) if self.model is None else self._run(idx, scales)
        extra = [np.asarray(out[k], float) for k in self.keys[len(_IDA_OUT) :]]
        for r, (j, s) in enumerate(zip(idx, scales, strict=True)):
            point = (s, out["max_rotation"][r], float(out["overturned"][r]), kind)
            self.history[j].append(point + tuple(float(e[r]) for e in extra))
        np.add.at(self.sims, idx, 1)
        np.bitwise_or.at(self.status, idx, np.asarray(out["status"], np.int64))
        return out

    def _run(self, idx, scales) -> dict:
        """:func:`_run` on the points, keeping Housner's answer under ``"auto"``."""
        record, st, method, rtol, max_steps = self.args
        keys = self.keys + (HOUSNER_OUTPUTS if _auto(self.model) else ())
        out = _run(record, st, idx, scales, method, rtol, max_steps, keys, self.model)
        if _auto(self.model):
            answers = zip(
                idx, scales, out["overturned_rocking"], out["status_rocking"], strict=True
            )
            for j, s, over, status in answers:
                self.housner[j][s] = (bool(over), int(status))
        return out

    def _housner_outcomes(self, idx, scales) -> dict:
        """Housner's outputs of the points: those of :attr:`housner` as known, the others
        run."""
        record, st, method, rtol, max_steps = self.args
        known = np.array([s in self.housner[j] for j, s in zip(idx, scales, strict=True)], bool)
        out = {
            "max_rotation": np.full(idx.size, np.nan),
            "overturned": np.zeros(idx.size, bool),
            "status": np.zeros(idx.size, np.int64),
        }
        for r in np.flatnonzero(known):
            out["overturned"][r], out["status"][r] = self.housner[idx[r]][scales[r]]
        if not known.all():
            new = ~known
            run = _run(record, st, idx[new], scales[new], method, rtol, max_steps, self.keys)
            for k, values in out.items():
                values[new] = run[k]
        return out

    def column(self, name) -> int:
        """The column of the contact model's output ``name`` in a row of :attr:`history`."""
        return 4 + self.keys.index(name) - len(_IDA_OUT)

    def run(self, idx, scales, kind):
        """Whether each point overturned (:meth:`outcomes`)."""
        return self.outcomes(idx, scales, kind)["overturned"]


_IDA_OUT = ("max_rotation", "overturned")


def _overturned(out):
    """Whether each point of a batch's outputs overturned."""
    return np.asarray(out["overturned"], bool)


def _climb(points, ladders, start=None, crossed=_overturned):
    """Climb every structure's ladder from its rung ``start`` (default 0; at the ladder's
    end: not climbed), ``_RUNGS_PER_CALL`` rungs per structure and call, until its first
    rung where ``crossed(outputs)`` holds (default: it overturns). Returns that rung's
    index (-1: none) and the number of rungs simulated in all, per structure."""
    sizes = np.array([r.size for r in ladders])
    done = np.zeros(sizes.size, np.int64) if start is None else np.array(start, np.int64)
    first = np.full(sizes.size, -1)
    active = np.flatnonzero(done < sizes)
    while active.size:
        ks = [np.arange(done[j], min(done[j] + _RUNGS_PER_CALL, sizes[j])) for j in active]
        rows = np.repeat(active, [k.size for k in ks])
        ks = np.concatenate(ks)
        scales = np.array([ladders[j][k] for j, k in zip(rows, ks, strict=True)])
        over = crossed(points.outcomes(rows, scales, 0))
        for j in active:
            sel = rows == j
            if over[sel].any():
                first[j] = ks[sel][np.argmax(over[sel])]
            done[j] += sel.sum()
        active = active[(first[active] < 0) & (done[active] < sizes[active])]
    return first, done


def _ida_record(
    record, st, options, method, rtol, max_steps, model=None, limits=(), states=(), known=None
):
    """Ladder, bisection and scan of all structures under one record, the slide
    capacities of ``limits`` and those of the damage ``states`` (see the public function;
    ``model`` as :func:`_run`'s; ``known``: Housner's answers of ``"auto"`` points, as
    :class:`_Points` takes them)."""
    n = st["critical_rotation"].size
    pga = record.peak
    if not pga > 0:
        raise ValueError(f"records: the record {record.name!r} has PGA 0; it cannot be scaled")
    ceiling = free_fall_scale(record)
    top = options.max_pga_ratio * st["uplift_acceleration"] / pga
    low = np.broadcast_to(_rest_scale(record, _rest_slope(st, model), ceiling), (n,))
    ladders = [_ladder(low[j], top[j], ceiling, 1.0 + options.step) for j in range(n)]
    points = _Points(record, st, method, rtol, max_steps, model, known)
    first, done = _climb(points, ladders)
    found = first >= 0
    hi, lo = np.full(n, np.nan), np.full(n, np.nan)
    for j in range(n):  # censored: the top rung survived; rung 0 overturned: no lower end
        k = first[j]
        if found[j]:
            hi[j], lo[j] = ladders[j][k], ladders[j][k - 1] if k > 0 else np.nan
        else:
            lo[j] = ladders[j][-1]
    while True:  # bisect between the last surviving and the first overturning rung
        active = np.flatnonzero(found & (hi > lo * (1.0 + options.tolerance)))
        if not active.size:
            break
        s = np.sqrt(lo[active] * hi[active])
        over = points.run(active, s, 1)
        hi[active[over]] = s[over]
        lo[active[~over]] = s[~over]
    _scan(points, ladders, done, found, options.scan)
    band = [_switch_band(h, c) for h, c in zip(points.history, hi, strict=True)]
    capacity_scale = np.where(found, hi, np.nan)
    alpha = np.broadcast_to(st["critical_rotation"], (n,))
    damage = ida_states.state_scales(
        points, ladders, states, alpha, capacity_scale, options.tolerance
    )
    slides = ida_slides.slide_scales(points, ladders, done, limits, options.tolerance, _climb)
    reason = np.where(found, 0, np.where(top < ceiling, 1, 2))
    return {
        "capacity_scale": capacity_scale,
        "capacity_scale_lower": lo,
        "censored_reason": reason,
        "highest_survival_scale": np.array([b[0] for b in band]),
        "switch_band_overturn_share": np.array([b[1] for b in band]),
        "rungs": done,
        "simulations": points.sims,
        "status": points.status,
        "history": points.history,
        "slide_capacity_scale": slides,
        "state_capacity_scale": damage,
        "housner": points.housner,
    }


def _scan(points, ladders, done, found, scan):
    """``scan`` scales geometric from the highest rung simulated to the top of the ladder,
    for the structures that overturned below the top."""
    rows, scales = [], []
    for j in np.flatnonzero(found):
        start, end = ladders[j][done[j] - 1], ladders[j][-1]
        if scan and end > start:
            rows.append(np.full(scan, j))
            scales.append(start * (end / start) ** (np.arange(1, scan + 1) / scan))
    if rows:
        points.run(np.concatenate(rows), np.concatenate(scales), 2)


def _switch_band(history, capacity):
    """(highest scale above ``capacity`` seen to survive, share of the simulated scales in
    [capacity, that scale] that overturn); NaNs if none survives above it."""
    if not history or not np.isfinite(capacity):
        return np.nan, np.nan
    points = np.array(history)
    s, over = points[:, 0], points[:, 2]
    above = (s > capacity) & (over == 0)
    if not above.any():
        return np.nan, np.nan
    top = s[above].max()
    inside = (s >= capacity) & (s <= top)
    return float(top), float(over[inside].mean())
