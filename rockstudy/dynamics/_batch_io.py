"""The inputs and outputs of a batch (:func:`rockstudy.dynamics.batch.simulate_batch`): which
outputs a call returns, and its dataset with CF units."""

from __future__ import annotations

import numpy as np

from . import outputs

__all__: list[str] = []

#: The outputs returned by default (:data:`.outputs.OUTPUTS`: the kernels' and the model).
OUTPUTS = outputs.names("kernel", "batch")
#: Outputs returned only when ``outputs`` names them (the rocking kernel computes them on the
#: way; the rows it leaves out are run again with a history: see :mod:`._batch_contact`).
CONTACT_OUTPUTS = outputs.names("contact")
#: Returned only when ``outputs`` names it: every row is run again with its amplitude times
#: 1 + 1e-9 (:mod:`.conditioning`), which doubles the cost.
CONDITIONING_OUTPUTS = outputs.names("conditioning")
#: Returned by default with ``model="contact"`` or ``"auto"`` (and only then): the slip and
#: the regimes, by the contact model (:func:`.contact_model.contact_outputs`).
SLIDE_OUTPUTS = outputs.names("contact_model")
#: Returned only when ``outputs`` names them, with ``model="auto"``: Housner's decision and
#: status of every row, which "auto" computes before the contact model answers some rows.
ROCKING_OUTPUTS = outputs.names("rocking_only")


#: long name and CF units of the inputs and outputs of :func:`simulate_batch`
BATCH_UNITS = {
    **{o.name: (o.long_name, o.units) for o in outputs.OUTPUTS.values()},
    "half_diagonal": ("half-diagonal R", "m"),
    "frequency_parameter": ("frequency parameter p", "rad s-1"),
    "slenderness": ("slenderness alpha", "rad"),
    "critical_rotation": ("critical rotation theta_cr", "rad"),
    "restitution": ("coefficient of restitution eta", "1"),
    "amplitude": ("pulse amplitude a_g", "m s-2"),
    "period": ("pulse period T_p", "s"),
    "cycles": ("pulse cycles", "1"),
    "scale": ("factor on the record", "1"),
    "friction_static": ("static friction coefficient mu_s", "1"),
    "friction_kinetic": ("kinetic friction coefficient mu_k", "1"),
}


def batch_dataset(result, inputs, method, rtol, motion):
    """The outputs of :func:`simulate_batch` with its inputs as ``scene`` coordinates."""
    import xarray as xr

    def var(name, values):
        long_name, units = BATCH_UNITS.get(name, (name, "1"))
        return ("scene", np.asarray(values), {"long_name": long_name, "units": units})

    return xr.Dataset(
        {k: var(k, v) for k, v in result.items()},
        coords={k: var(k, v) for k, v in inputs.items()},
        attrs={"method": method, "rtol": rtol, "motion": motion},
    )


def requested_outputs(outputs, model="rocking", friction=False):
    """The output names to return, in the order of :data:`OUTPUTS`, ``status`` included: by
    default :data:`OUTPUTS`, with ``friction`` the friction check (:data:`CONTACT_OUTPUTS`;
    under ``model="contact"`` its ``lift_off`` only: the demand needs Housner's model run
    with a history), and under the contact model :data:`SLIDE_OUTPUTS`."""
    allowed = OUTPUTS + CONTACT_OUTPUTS + SLIDE_OUTPUTS + CONDITIONING_OUTPUTS + ROCKING_OUTPUTS
    if outputs is None:
        check = ("lift_off",) if model == "contact" else CONTACT_OUTPUTS
        slides = SLIDE_OUTPUTS if model != "rocking" else ()
        names = OUTPUTS + (check if friction else ()) + slides
    else:
        names = [outputs] if isinstance(outputs, str) else list(outputs)
    unknown = sorted(set(names) - set(allowed))
    if unknown:
        raise ValueError(f"outputs: unknown name(s) {unknown}; allowed: {list(allowed)}")
    if model == "rocking" and set(names) & set(SLIDE_OUTPUTS):
        raise ValueError(
            f"outputs: {sorted(set(names) & set(SLIDE_OUTPUTS))} come from the contact model: "
            "give friction= and model='contact' or 'auto'"
        )
    if model != "auto" and set(names) & set(ROCKING_OUTPUTS):
        raise ValueError(
            f"outputs: {sorted(set(names) & set(ROCKING_OUTPUTS))} keep Housner's answer "
            f"under model='auto', which runs it before the contact model, not model={model!r}"
        )
    if model != "rocking" and "conditioning" in names:
        raise ValueError(
            f"outputs: conditioning is computed for Housner's model only, not model={model!r}"
        )
    return tuple(name for name in allowed if name in names or name == "status")
