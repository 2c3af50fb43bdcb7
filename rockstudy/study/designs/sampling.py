"""The design of a study: its input rows, derived rocking parameters and dimensionless groups.

Uniform numbers come from one root ``numpy.random.SeedSequence`` (Monte Carlo), a scrambled
Latin hypercube or scrambled Sobol' points in SALib's Saltelli layout, and are mapped through
each distribution's inverse CDF. The whole design is made before anything runs, so results do
not depend on chunking or on the number of workers.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ...constants import G
from ...structures.block import restitution_housner, uplift_acceleration_block
from ..spec.samplers import SAMPLERS
from ..spec.schema import Study
from ..spec.structures import KINDS

__all__ = ["make_design", "target_attributes", "unit_samples", "VARIABLES"]

#: CF-style attributes of every design variable.
VARIABLES = {
    "half_diagonal": ("half-diagonal R of the block", "m"),
    "slenderness": ("slenderness alpha (critical rotation theta_cr)", "rad"),
    "restitution": ("coefficient of restitution eta", "1"),
    "frequency_parameter": ("frequency parameter p", "rad s-1"),
    "critical_rotation": ("critical rotation theta_cr of the equivalent block", "rad"),
    "uplift_acceleration": (
        "uplift acceleration a_up of the structure: g tan(alpha) of a block, g lambda of "
        "another structure (eq. 10 of [003])",
        "m s-2",
    ),
    "amplitude": ("pulse amplitude a_g (signed)", "m s-2"),
    "amplitude_ratio": ("a_g / a_up (a_up = g tan alpha for a block)", "1"),
    "amplitude_a": ("a = a_g / (g alpha), eq. (3.6) of [000]", "1"),
    "period": ("pulse period T_p", "s"),
    "frequency_ratio": ("omega_g / p", "1"),
    "scale": ("factor on the record", "1"),
    "pga_ratio": ("peak ground acceleration / a_up (a_up = g tan alpha for a block)", "1"),
    "record": ("index of the record in the study's files", "1"),
    "omega": ("omega_g / p, eq. (3.6) of [000]", "1"),
    "a": ("a_g / (g alpha), eq. (3.6) of [000]", "1"),
    "inverse_a": ("g alpha / a_g, eq. (4.11) of [000]", "1"),
    "uplift_ratio": ("a_up / a_g (g tan(alpha) / a_g for a block, eqs. 5.3, 6.1 of [000])", "1"),
    "cos_alpha": ("cos(alpha), eq. (5.3) of [000]", "1"),
    "group_point": ("index of the group point (replicated designs)", "1"),
    "target": ("scale target of the record, in the units of motion.scale_to.im", "1"),
    "structure": ("index of the structure (record designs)", "1"),
    "level_index": ("index of the intensity level (stripes designs)", "1"),
}


def unit_samples(study: Study) -> np.ndarray:
    """Points in [0, 1)^D of the study's sampler (rows = samples), from the registry
    :data:`rockstudy.study.spec.samplers.SAMPLERS`."""
    kind = study.sampler.kind
    points = SAMPLERS[kind].points
    if points is None:
        with_points = ", ".join(k for k, s in SAMPLERS.items() if s.points is not None)
        raise ValueError(f"unit samples do not apply to sampler {kind!r}; they do to {with_points}")
    return points(study, len(study.parameters()))


def _inputs(study: Study) -> tuple[dict, dict]:
    """Columns of the distributed parameters, and the grid axes (grid sampler only)."""
    params = study.parameters()
    if not params:
        return {}, {}
    if study.sampler.kind == "grid":
        axes = {name: dist.points() for name, dist in params.items()}
        mesh = np.meshgrid(*axes.values(), indexing="ij")
        return {name: m.ravel() for name, m in zip(axes, mesh, strict=True)}, axes
    u = unit_samples(study)
    reps = study.sampler.replicates
    if reps > 1:  # group points first, then dimensional realizations of each
        groups = study.group_parameters()
        u = np.repeat(u, reps, axis=0)
        dims = [j for j, name in enumerate(params) if name not in groups]
        rng = np.random.default_rng(np.random.SeedSequence([study.seed, 3]))
        u[:, dims] = rng.random((u.shape[0], len(dims)))
    return {
        name: np.asarray(dist.ppf(u[:, j]), dtype=float)
        for j, (name, dist) in enumerate(params.items())
    }, {}


def _value(cols, spec, name, n):
    """A parameter's column: sampled, or the fixed number broadcast."""
    if name in cols:
        return cols[name]
    return np.full(n, float(getattr(spec, name)))


def make_design(study: Study, base_dir=None) -> xr.Dataset:
    """All inputs of a study on the ``sample`` dimension, with the derived rocking parameters
    (p, alpha, eta), the motion in SI units and the dimensionless groups of [000].

    For grid studies the grid axes are kept as coordinates ``<name>_grid`` and the attribute
    ``grid_dims`` lists them, so :func:`rockstudy.study.running.store.open_result` can unstack.
    A study with a ``[design]`` gets the rows (record, structure[, level]) of
    :func:`.record_rows.design_rows`; ``base_dir`` is where its relative record paths are
    (the study file's folder), and a suite given as a folder or glob is listed there.
    """
    cols, axes = _inputs(study)
    # no distributed parameter: the fixed values, once on a grid, else the sampler's n times
    n = len(next(iter(cols.values()))) if cols else (study.sampler.n or 1)
    if study.sampler.replicates > 1:
        reps = study.sampler.replicates
        cols["group_point"] = np.repeat(np.arange(n // reps), reps)
    st, mo = study.structure, study.motion
    if st.kind == "objects":
        from .record_rows import design_rows

        return _attributes(design_rows(study, _object_columns(st), base_dir))
    data = _structure_columns(st, cols, n)
    if study.design is not None:
        from .record_rows import design_rows

        return _attributes(design_rows(study, data, base_dir))
    data.update(_MOTION_COLUMNS[mo.kind](study, cols, n, data, base_dir))
    data["cos_alpha"] = np.cos(data["critical_rotation"])
    if "group_point" in cols:
        data["group_point"] = cols["group_point"]
    ds = xr.Dataset(
        {k: ("sample", np.asarray(v)) for k, v in data.items()}, coords={"sample": np.arange(n)}
    )
    for name, values in axes.items():
        ds.coords[f"{name}_grid"] = (f"{name}_grid", values)
    ds.attrs["grid_dims"] = list(axes)
    ds = _attributes(ds)
    if "target" in ds:  # in the units of the measure it targets
        ds["target"].attrs.update(target_attributes(mo.scale_to))
    return ds


def _structure_columns(st, cols, n) -> dict:
    """The rocking parameters (p, theta_cr, eta) and the uplift acceleration of each row,
    and the half-diagonal and slenderness of a block or a wall."""
    if st.kind == "equivalent_block":
        p = _value(cols, st, "frequency_parameter", n)
        alpha = _value(cols, st, "critical_rotation", n)
        eta = _value(cols, st, "restitution", n)
        return dict(
            frequency_parameter=p,
            critical_rotation=alpha,
            restitution=eta,
            uplift_acceleration=uplift_acceleration_block(alpha),  # a block: g tan(theta_cr)
        )
    R = _value(cols, st, "half_diagonal", n)
    alpha0 = _value(cols, st, "slenderness", n)
    # the equivalent block of the kind's class, and the structure's own uplift acceleration
    p, alpha, uplift = KINDS[st.kind].sampled(R, alpha0)
    eta = (
        np.vectorize(restitution_housner, otypes=[float])(alpha0)
        if st.restitution == "housner"
        else _value(cols, st, "restitution", n)
    )
    return dict(
        half_diagonal=R,
        slenderness=alpha0,
        restitution=eta,
        frequency_parameter=p,
        critical_rotation=alpha,
        uplift_acceleration=uplift,
    )


def _pulse_columns(study, cols, n, data, base_dir) -> dict:
    """A pulse's amplitude and period in SI units, and the groups of eq. (3.6) of [000]; the
    amplitude ratio and uplift_ratio relative to the structure's uplift acceleration a_up
    (g tan(alpha) for a block)."""
    mo, p, alpha = study.motion, data["frequency_parameter"], data["critical_rotation"]
    out = {}
    uplift = data["uplift_acceleration"]
    if mo.amplitude is not None:
        ratio = _value(cols, mo, "amplitude", n) / uplift
    elif mo.amplitude_a is not None:
        out["amplitude_a"] = _value(cols, mo, "amplitude_a", n)
        ratio = out["amplitude_a"] * G * alpha / uplift
    else:
        ratio = _value(cols, mo, "amplitude_ratio", n)
    amp = mo.direction * ratio * uplift
    period = (
        _value(cols, mo, "period", n)
        if mo.frequency_ratio is None
        else 2.0 * np.pi / (_value(cols, mo, "frequency_ratio", n) * p)
    )
    out.update(
        amplitude=amp,
        amplitude_ratio=ratio,
        period=period,
        frequency_ratio=2.0 * np.pi / (period * p),
    )
    a_g = np.abs(amp)
    out.update(
        omega=2.0 * np.pi / (period * p),
        a=a_g / (G * alpha),
        inverse_a=G * alpha / a_g,
        uplift_ratio=uplift / a_g,
    )
    return out


def _record_columns(study, cols, n, data, base_dir) -> dict:
    """The record of each row (drawn from the suite) and its scale, PGA ratio or target."""
    mo = study.motion
    rng = np.random.default_rng(np.random.SeedSequence([study.seed, 1]))
    out = {"record": rng.integers(0, _suite_size(mo, base_dir), n).astype(np.int64)}
    if mo.scale is not None:
        out["scale"] = _value(cols, mo, "scale", n)
    elif mo.pga_ratio is not None:
        out["pga_ratio"] = _value(cols, mo, "pga_ratio", n)
    else:
        value, si = mo.scale_to.value, mo.scale_to.si_factor()  # written in units: to SI
        out["target"] = si * (cols["target"] if "target" in cols else np.full(n, float(value)))
    return out


def _stochastic_columns(study, cols, n, data, base_dir) -> dict:
    """A synthetic record's PGA ratio."""
    return {"pga_ratio": _value(cols, study.motion, "pga_ratio", n)}


#: Motion kind -> the design columns of its motion: (study, cols, n, structure columns,
#: base_dir) -> dict of columns.
_MOTION_COLUMNS = {
    "pulse": _pulse_columns,
    "record": _record_columns,
    "stochastic": _stochastic_columns,
}


def _object_columns(objects) -> dict:
    """The structure columns of named objects (one row each, in order; their names go to the
    design's ``structure_names`` attribute)."""
    geometry = np.array([o.geometry() for o in objects.objects], float)
    p, theta_cr, eta = objects.rocking().T
    return dict(
        half_diagonal=geometry[:, 0],
        slenderness=geometry[:, 1],
        restitution=eta,
        frequency_parameter=p,
        critical_rotation=theta_cr,
        uplift_acceleration=objects.uplift(),
    )


def target_attributes(scale_to) -> dict:
    """long_name and units of a record scale target ``scale_to``."""
    from ...motions import measures

    what = scale_to.im + ("" if scale_to.period is None else f"({scale_to.period:g} s)")
    written = "" if scale_to.units is None else f", written in {scale_to.units}"
    unit = "1" if scale_to.im in measures.RATIOS else measures.measure(scale_to.im).unit
    return {"long_name": f"scale target {what}{written}", "units": unit}


def _attributes(ds):
    """CF-style attributes of the design variables."""
    for name, var in ds.data_vars.items():
        long_name, units = VARIABLES[name]
        var.attrs.update(long_name=long_name, units=units)
    ds["sample"].attrs.update(long_name="sample index", units="1")
    return ds


def _suite_size(motion, base_dir) -> int:
    """Records of a record motion: its list of files, or those its folder or glob names."""
    if isinstance(motion.files, list) and not hasattr(motion.vertical, "match"):
        return len(motion.files)
    from ..spec.feasibility import record_pairs

    return len(record_pairs(motion, base_dir))
