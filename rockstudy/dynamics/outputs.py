"""The batch outputs, declared once: what :func:`rockstudy.simulate_batch` returns and a study
stores.

Each entry of :data:`OUTPUTS` gives an output's name, the dtype :func:`simulate_batch` returns
it in, its CF units and long name, how a study stores it (dtype and the fill value of a failed
row), the models that compute it and the stage that does. Everything else is read from here:
the row the batch kernels write (:data:`KERNEL_ROW`, one field per ``"kernel"`` output),
:data:`rockstudy.dynamics.batch.OUTPUTS`, the variables of a batch dataset, the outputs of a
study's runner (:data:`rockstudy.study.running.evaluate.OUTPUTS`) and the outputs a study file
may ask for (``run.outputs``).

Adding an output: an entry here, and the kernels that compute it (for a ``"kernel"`` output,
the field of their outcome and :func:`._rows.write_row`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "KERNEL_MODELS",
    "KERNEL_ROW",
    "MODELS",
    "OUTPUTS",
    "STAGES",
    "STUDY_OUTPUTS",
    "TIMED_REGIMES",
    "Output",
    "names",
    "rows_at_rest",
]

#: The models a batch runs (:func:`rockstudy.simulate_batch`): Housner's block by the
#: Taylor/DOP853 kernel, the linearized block by the same kernel (a record with a vertical
#: component), the exact piecewise linear solution under a trigonometric pulse and under a
#: record, the rest of ``method="auto"`` (no uplift, nothing integrated), and the planar
#: contact model (:func:`rockstudy.dynamics.contact_model.contact_outputs`: rest, slide, rock,
#: slide-rock, flight) of ``model="contact"`` or ``"auto"``.
MODELS = ("nonlinear", "linear", "exact_linear", "exact_linear_record", "rest", "contact")
#: The models whose kernel writes a row of :data:`KERNEL_ROW`.
KERNEL_MODELS = MODELS[:4]
#: Where an output is computed: in every batch kernel's row (``kernel``), by
#: :func:`simulate_batch` around the kernels (``batch``), by its contact pass (``contact``: the
#: friction check of Housner's model), by the contact model (``contact_model``: with
#: ``model="contact"`` or ``"auto"``) or by its conditioning pass (``conditioning``), by a
#: study from another output (``study``), or kept of Housner's answer under ``model="auto"``
#: before the contact model writes over its rows (``rocking_only``, asked for by name).
STAGES = ("kernel", "batch", "contact", "contact_model", "conditioning", "study", "rocking_only")


@dataclass(frozen=True)
class Output:
    """One batch output.

    Attributes
    ----------
    name : str
        The name it has in :func:`rockstudy.simulate_batch`, a batch dataset and a study.
    dtype : str
        The numpy dtype :func:`rockstudy.simulate_batch` returns it in.
    units : str
        CF units.
    long_name : str
        What it is.
    store_dtype : str
        The dtype a study stores it in.
    fill : float or int
        A study's value for a row that failed.
    models : tuple of str
        The models of :data:`MODELS` that compute it.
    stage : str
        Where it is computed (:data:`STAGES`).
    in_study : bool
        Whether a study's ``run.outputs`` may name it.
    at_rest : float or int
        Its value for a scene that never lifts (``"kernel"`` outputs: what ``method="auto"``
        gives the rows it decides are at rest without a kernel).
    in_row : bool
        Whether the batch kernels write it in their row (:data:`KERNEL_ROW`) although another
        stage completes it: the friction check, which the rocking kernel computes on the way
        (:mod:`._demand`; NaN where it did not) and :func:`simulate_batch` completes.
    """

    name: str
    dtype: str
    units: str
    long_name: str
    store_dtype: str
    fill: float | int
    models: tuple = KERNEL_MODELS
    stage: str = "kernel"
    in_study: bool = True
    at_rest: float | int = 0
    in_row: bool = False

    def __post_init__(self):
        if self.stage not in STAGES:
            raise ValueError(f"{self.name}: stage must be one of {STAGES}, got {self.stage!r}")
        if not set(self.models) <= set(MODELS):
            raise ValueError(f"{self.name}: models must be among {MODELS}, got {self.models}")


#: The regimes of the contact model (:data:`rockstudy.dynamics.slide_rock.REGIMES`) whose
#: seconds are batch outputs (``time_<regime>``): those outside Housner's model, 0 for every
#: scene it answers.
TIMED_REGIMES = ("slide", "slide_rock", "flight")

_NAN = float("nan")
_BLOCK_MODELS = ("nonlinear", "linear")
#: The models of the outputs that the contact model computes too.
_WITH_CONTACT = (*KERNEL_MODELS, "contact")
#: The models of the contact model's outputs: the contact model, and Housner's wherever
#: ``model="auto"`` keeps its answer (the friction held and the block never flew: no slip).
_SLIDING_MODELS = (*_BLOCK_MODELS, "rest", "contact")


def _f8(name, units, long_name, **where):
    """A float output (a study stores it as such, NaN for a failed row)."""
    return Output(name, "f8", units, long_name, "f8", _NAN, **where)


def _int(name, dtype, long_name, store_dtype="i8", **where):
    """A count or code without units (a study stores it as ``store_dtype``, -1 for a failed
    row)."""
    return Output(name, dtype, "1", long_name, store_dtype, -1, **where)


#: The batch outputs, in the order :func:`rockstudy.simulate_batch` returns them.
OUTPUTS = {
    o.name: o
    for o in (
        _int(
            "status",
            "i8",
            "0 ok, 1 step limit reached (the contact model: its cap of phases), 4 the contact "
            "model's answer did not converge with rtol",
            in_study=False,
            models=_WITH_CONTACT,
        ),
        _f8("max_rotation", "rad", "max |theta| (pi/2 if overturned)", models=_WITH_CONTACT),
        _int("overturned", "bool", "overturned (1) or survived (0)", "i1", models=_WITH_CONTACT),
        _int("n_impacts", "i8", "impacts until rest", models=_WITH_CONTACT),
        _f8(
            "overturn_time",
            "s",
            "time at which |theta| reached pi/2 (NaN if it survived)",
            at_rest=_NAN,
            models=_WITH_CONTACT,
        ),
        _int(
            "steps",
            "i8",
            "integrator steps (DOP853 or Taylor; 0 for the exact solvers, -1 for the contact "
            "model, which does not count them)",
        ),
        _f8(
            "first_impact_time",
            "s",
            "time of the first impact (NaN if none)",
            at_rest=_NAN,
            models=_WITH_CONTACT,
        ),
        _f8(
            "peak_time",
            "s",
            "time at which |theta| reached max_rotation (the overturning time if overturned; "
            "NaN if it never rocked, and under the contact model, which does not time it)",
            at_rest=_NAN,
        ),
        _int(
            "model",
            "i1",
            "model that ran: 0 rest (no uplift), 1 linear, 2 nonlinear, 3 contact model, 4 "
            "contact model by its solve_ivp reference (its kernel reached the step limit)",
            "i1",
            models=MODELS,
            stage="batch",
        ),
        _f8(
            "max_rotation_ratio",
            "1",
            "max |theta| / theta_cr",
            stage="study",
            models=_WITH_CONTACT,
        ),
        _f8(
            "friction_demand",
            "1",
            "friction demand max |F_h / F_v| at the contact of Housner's no-slip model (inf "
            "with a lift-off)",
            models=_BLOCK_MODELS,
            stage="contact",
            at_rest=_NAN,
            in_row=True,
        ),
        _int(
            "lift_off",
            "i1",
            "1 if the vertical contact force was not compressive somewhere (the contact "
            "model: the block flew)",
            "i1",
            models=(*_BLOCK_MODELS, "contact"),
            stage="contact",
            in_row=True,
        ),
        _f8(
            "max_slide",
            "m",
            "max |slip| of the base relative to the ground (NaN if Housner's model answered "
            "and the block overturned)",
            models=_SLIDING_MODELS,
            stage="contact_model",
        ),
        _f8(
            "residual_slide",
            "m",
            "slip of the base relative to the ground at the end (NaN if overturned)",
            models=_SLIDING_MODELS,
            stage="contact_model",
        ),
        _f8(
            "first_slip_time",
            "s",
            "time at which the base first slipped (NaN if it never did, or if Housner's "
            "model answered and the block overturned)",
            models=_SLIDING_MODELS,
            stage="contact_model",
        ),
        *(
            _f8(
                f"time_{regime}",
                "s",
                f"seconds in the {label} regime (NaN if Housner's model answered and the "
                "block overturned)",
                models=_SLIDING_MODELS,
                stage="contact_model",
            )
            for regime, label in ((r, r.replace("_", "-")) for r in TIMED_REGIMES)
        ),
        _int(
            "regime",
            "i1",
            "most involved regime entered: 0 rest, 1 slide, 2 rock, 3 slide-rock, 4 flight",
            "i1",
            models=_SLIDING_MODELS,
            stage="contact_model",
        ),
        # Housner's answer of every row under model="auto" (which runs it first): opt-in
        _int(
            "overturned_rocking",
            "bool",
            "overturned (1) or survived (0) under Housner's rocking-only model, which "
            "model='auto' runs first on every row",
            "i1",
            models=(*KERNEL_MODELS, "rest"),
            stage="rocking_only",
            in_study=False,
        ),
        _int(
            "status_rocking",
            "i8",
            "status of Housner's rocking-only model on the row (its kernel's: 0 ok, 1 step "
            "limit), which model='auto' runs first on every row",
            models=(*KERNEL_MODELS, "rest"),
            stage="rocking_only",
            in_study=False,
        ),
        _f8(
            "conditioning",
            "1",
            "relative change of max |theta| under 1e-9 in the amplitude",
            models=MODELS,
            stage="conditioning",
            in_study=False,
        ),
    )
}


def names(*stages: str) -> tuple:
    """The names of the outputs computed at ``stages`` (:data:`STAGES`), in table order."""
    unknown = set(stages) - set(STAGES)
    if unknown:
        raise ValueError(f"stages must be among {STAGES}, got {sorted(unknown)}")
    return tuple(o.name for o in OUTPUTS.values() if o.stage in stages)


#: The outputs a study may ask for (``run.outputs``), in table order.
STUDY_OUTPUTS = tuple(o.name for o in OUTPUTS.values() if o.in_study)
#: The row every batch kernel writes per scene: one field per ``"kernel"`` output, and the
#: friction check's outputs that the kernels compute on the way (``in_row``).
KERNEL_ROW = np.dtype(
    [(o.name, o.dtype) for o in OUTPUTS.values() if o.stage == "kernel" or o.in_row]
)


def rows_at_rest(n):
    """n kernel rows (:data:`KERNEL_ROW`) of scenes that never lift: each output's
    ``at_rest`` value."""
    out = np.empty(n, KERNEL_ROW)
    for name in KERNEL_ROW.names:
        out[name] = OUTPUTS[name].at_rest
    return out
