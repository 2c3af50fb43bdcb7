"""Record designs on top of :func:`rockstudy.simulate_batch`: cloud, multiple-stripe analysis
and incremental dynamic analysis (IDA) by bracketing and bisection.

Each design runs one batch call per record (all structures and scales of the record in it; IDA
one call per record and iteration) and returns an :class:`xarray.Dataset` on the dimensions
``record`` and ``structure`` (and ``level`` for stripes, ``step`` for the IDA points), with each
record's intensity measures (:meth:`rockstudy.motions.Record.intensity_measures`), its pulse
(:meth:`rockstudy.motions.Record.pulse`) and its dimensionless groups for each structure
(:func:`rockstudy.similarity.record_groups`) as variables, all of the unscaled record. The
intensity of a scaled record is its unscaled value times ``scale`` (``scale`` squared for Arias
intensity); :func:`rockstudy.study.records_fragility.intensity` forms it in quoted units.

Rocking is not monotonic in intensity: a block that overturns at one scale can survive a
higher one. IDA reports the first overturning level and flags resurrection found by a coarse
scan above it.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .. import similarity
from ..constants import G
from ..dynamics import simulate_batch
from ..motions import Record
from ..motions import intensity as _im
from ..structures.block import block_parameters, frequency_parameter, restitution_housner

#: Dimensionless targets: name -> the record measure it divides by the uplift acceleration
#: (``pga_ratio`` = PGA / (g tan alpha), ``pgv_ratio`` = PGV p / (g tan alpha)).
DIMENSIONLESS = {"pga_ratio": "pga", "pgv_ratio": "pgv"}
#: Measures a record can be scaled to (Arias intensity goes as the scale squared).
SCALABLE = ("pga", "pgv", "pgd", "arias", "cav", "spectrum_intensity", "sa", "psv", "sd") + tuple(
    DIMENSIONLESS
)
_SCALARS = tuple(k for k in _im.UNITS if k not in _im.SPECTRAL)
_STRUCTURE_KEYS = ("half_diagonal", "frequency_parameter", "slenderness", "restitution")


# ------------------------------------------------------------------------------ inputs


def _records(records) -> list[Record]:
    records = list(records) if isinstance(records, (list, tuple)) else [records]
    if not records:
        raise ValueError("records: give at least one Record")
    for i, r in enumerate(records):
        if not isinstance(r, Record):
            raise ValueError(f"records[{i}] must be a rockstudy Record, got {type(r).__name__}")
    return records


def _structures(structures) -> dict:
    """Arrays over ``structure``: p [rad/s], alpha [rad], eta, R [m] (NaN if unknown) and the
    uplift acceleration [m/s^2] (:func:`rockstudy.similarity.uplift_acceleration`)."""
    if isinstance(structures, dict):
        unknown = set(structures) - set(_STRUCTURE_KEYS)
        if unknown:
            raise ValueError(
                f"structures: unknown keys {sorted(unknown)}; allowed {list(_STRUCTURE_KEYS)}"
            )
        if ("half_diagonal" in structures) == ("frequency_parameter" in structures):
            raise ValueError("structures: give exactly one of half_diagonal or frequency_parameter")
        if "slenderness" not in structures:
            raise ValueError("structures: slenderness is required")
        arrays = {k: np.atleast_1d(np.asarray(v, float)) for k, v in structures.items()}
        n = int(np.prod(np.broadcast_shapes(*(a.shape for a in arrays.values()))))
        arrays = {k: np.broadcast_to(a, (n,)).ravel() for k, a in arrays.items()}
        alpha = arrays["slenderness"]
        _check("structures.slenderness", alpha, 0.0, math.pi / 2)
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
        uplift = G * np.tan(alpha)
    else:
        items = list(structures)
        if not items:
            raise ValueError("structures: give at least one structure")
        params = np.array([block_parameters(s) for s in items], float).reshape(-1, 3)
        p, alpha, eta = params.T
        R = np.array([float(getattr(s, "half_diagonal", np.nan)) for s in items])
        uplift = np.array([similarity.uplift_acceleration(s) for s in items])
    return {
        "frequency_parameter": p,
        "slenderness": alpha,
        "restitution": eta,
        "half_diagonal": R,
        "uplift_acceleration": uplift,
    }


def _check(name, arr, low, high):
    bad = ~np.isfinite(arr) | (arr <= low) | (arr >= high)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{i}] = {arr[i]!r} is outside ({low:g}, {high:g})")


def _target(im, period, periods):
    """Check the scaling measure; return the periods to store (with ``period`` for sa)."""
    if im not in SCALABLE:
        raise ValueError(f"im must be one of {list(SCALABLE)}, got {im!r}")
    periods = [] if periods is None else [float(t) for t in np.atleast_1d(periods)]
    if im in _im.SPECTRAL:
        if period is None:
            raise ValueError(f"im={im!r} needs a period [s]")
        period = float(_im.check_periods(period)[0])
        if period not in periods:
            periods.append(period)
    elif period is not None:
        raise ValueError(f"period is only for {_im.SPECTRAL}, not im={im!r}")
    return period, np.array(sorted(periods), float)


def _record_measure(record, im, period, damping, structures):
    """The unscaled record's measure ``im`` [SI, or dimensionless], per structure (array)."""
    base = DIMENSIONLESS.get(im, im)
    value = record.intensity_measure(base, period=period, damping=damping)
    value = np.full(structures["slenderness"].size, value)
    if im == "pgv_ratio":
        value = value * structures["frequency_parameter"]
    if im in DIMENSIONLESS:
        value = value / structures["uplift_acceleration"]
    if not np.all(np.isfinite(value) & (value > 0)):
        raise ValueError(
            f"im={im!r}: the record {record.name!r} has {base} = {float(value[0])!r}, so no "
            "scale factor reaches a target level"
        )
    return value


def _scale_for(level, measure, im):
    """Scale factor(s) that bring ``measure`` to ``level`` (Arias goes as the square)."""
    ratio = level / measure
    return ratio ** (1.0 / _im.SCALING_POWER[DIMENSIONLESS.get(im, im)])


# ------------------------------------------------------------------------------ tables


def _record_dataset(records, structures, periods, damping) -> xr.Dataset:
    """Measures of the unscaled records (on ``record``) and their groups for each structure."""
    ims = [r.intensity_measures(periods=periods, damping=damping) for r in records]
    pulses = [r.pulse() for r in records]
    data = {k: ("record", np.array([m[k] for m in ims], float)) for k in _SCALARS}
    data["sa"] = (
        ("record", "period"),
        np.array([m["sa"] for m in ims], float).reshape(len(ims), len(periods)),
    )
    data["pulse_period"] = ("record", np.array([q.period for q in pulses], float))
    data["pulse_amplitude"] = ("record", np.array([q.amplitude for q in pulses], float))
    data["pulse_indicator"] = ("record", np.array([q.indicator for q in pulses], float))
    for k, v in structures.items():
        data[k] = ("structure", v)
    ds = xr.Dataset(
        data,
        coords={
            "record": np.arange(len(records)),
            "structure": np.arange(structures["slenderness"].size),
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
        **_im.UNITS,
        "pulse_period": "s",
        "pulse_amplitude": "m/s",
        **dict.fromkeys(ratios, "1"),
    }
    for k, unit in units.items():  # every intensity measure carries its units
        if k in ds:
            ds[k].attrs["units"] = unit
    return ds


def _run(record, structures, idx, scales, method, rtol, max_steps):
    """simulate_batch on the structures ``idx`` (array) at ``scales`` (same length)."""
    return simulate_batch(
        frequency_parameter=structures["frequency_parameter"][idx],
        slenderness=structures["slenderness"][idx],
        restitution=structures["restitution"][idx],
        record=record,
        scale=scales,
        method=method,
        rtol=rtol,
        max_steps=max_steps,
    )


_OUT = ("max_rotation", "overturned", "n_impacts", "overturn_time", "status")


# ------------------------------------------------------------------------------ cloud


def cloud(
    records,
    structures,
    periods=(),
    damping: float = 0.05,
    method: str = "nonlinear",
    rtol: float = 1e-8,
    max_steps: int = 1_000_000,
) -> xr.Dataset:
    """Every structure under every record, unscaled (a cloud analysis).

    Parameters
    ----------
    records : Record or sequence of Record
        E.g. from :func:`rockstudy.motions.load_suite`.
    structures : sequence or dict
        Blocks or structures with ``equivalent_block()``; or a dict of arrays (broadcast) with
        ``slenderness`` [rad], one of ``half_diagonal`` [m] or ``frequency_parameter``
        [rad/s], and optionally ``restitution`` (default Housner's).
    periods : array_like
        Periods T [s] of the stored spectral accelerations ``sa``.
    damping : float
        Damping ratio of ``sa`` and the spectrum intensity.
    method, rtol, max_steps
        As in :func:`rockstudy.simulate_batch`.

    Returns
    -------
    xarray.Dataset
        ``max_rotation`` [rad], ``overturned``, ``n_impacts``, ``overturn_time`` [s] and
        ``status`` on (record, structure), with the record and structure tables.
    """
    records = _records(records)
    st = _structures(structures)
    _, periods = _target("pga", None, periods)
    ds = _record_dataset(records, st, periods, damping)
    idx = np.arange(st["slenderness"].size)
    outs = [_run(r, st, idx, 1.0, method, rtol, max_steps) for r in records]
    for k in _OUT:
        ds[k] = (("record", "structure"), np.array([o[k] for o in outs]))
    ds.attrs.update(design="cloud", method=method, rtol=rtol, n_simulations=len(records) * idx.size)
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
    max_steps: int = 1_000_000,
) -> xr.Dataset:
    """Multiple-stripe analysis: every record scaled to each intensity level, every structure.

    Parameters
    ----------
    levels : array_like
        Target values (> 0) of ``im``, in its SI units (``pga``, ``sa`` [m/s^2], ``pgv``
        [m/s], ...; see :data:`rockstudy.motions.intensity.UNITS`) or dimensionless for
        ``pga_ratio`` = PGA / (g tan alpha) and ``pgv_ratio`` = PGV p / (g tan alpha), whose
        scale factor differs from structure to structure.
    im : str
        One of :data:`SCALABLE`.
    period : float, optional
        T [s] of ``sa``, ``psv`` and ``sd``.
    records, structures, periods, damping, method, rtol, max_steps
        As in :func:`cloud`.

    Returns
    -------
    xarray.Dataset
        The outputs of :func:`cloud` on (record, structure, level), and ``scale`` (the factor
        applied to each record), with ``level`` as a coordinate and ``im`` in the attributes.
    """
    records = _records(records)
    st = _structures(structures)
    period, periods = _target(im, period, periods)
    levels = np.atleast_1d(np.asarray(levels, float))
    if levels.ndim != 1 or not np.all(np.isfinite(levels) & (levels > 0)):
        raise ValueError(f"levels must be finite numbers > 0, got {levels!r}")
    ds = _record_dataset(records, st, periods, damping)
    n = st["slenderness"].size
    idx = np.repeat(np.arange(n), levels.size)
    scales, outs = [], []
    for r in records:
        s = _scale_for(levels[None, :], _record_measure(r, im, period, damping, st)[:, None], im)
        scales.append(s)
        outs.append(_run(r, st, idx, s.ravel(), method, rtol, max_steps))
    dims = ("record", "structure", "level")
    ds = ds.assign_coords(level=levels)
    ds["scale"] = (dims, np.array(scales))
    for k in _OUT:
        ds[k] = (dims, np.array([o[k] for o in outs]).reshape(len(records), n, levels.size))
    ds.attrs.update(
        design="stripes",
        im=im,
        im_period=np.nan if period is None else period,
        method=method,
        rtol=rtol,
        n_simulations=len(records) * n * levels.size,
    )
    return ds


# ------------------------------------------------------------------------------ IDA


def incremental_dynamic_analysis(
    records,
    structures,
    im: str = "pga",
    period=None,
    tolerance: float = 0.01,
    growth: float = 1.5,
    max_pga_ratio: float = 30.0,
    scan: int = 4,
    periods=(),
    damping: float = 0.05,
    method: str = "nonlinear",
    rtol: float = 1e-8,
    max_steps: int = 1_000_000,
) -> xr.Dataset:
    """The overturning intensity of each structure under each record, by bracket and bisection.

    For each record, all structures advance together, one :func:`rockstudy.simulate_batch`
    call per iteration:

    1. **Bracket.** Below the scale at which the PGA reaches g alpha (<= g tan alpha) the
       block never leaves rest (section 2 of [000]; g alpha for the linearized model), so it
       survives without a simulation. From there the scale is multiplied by ``growth`` until
       the block overturns, or until the PGA reaches ``max_pga_ratio`` g tan(alpha): a block
       still standing there is *censored* (its capacity exceeds that level).
    2. **Bisect** (geometrically) between the last surviving and the first overturning scale
       until their ratio is at most ``1 + tolerance``.
    3. **Scan** ``scan`` levels spaced geometrically from the capacity up to the top of the
       range; a block that survives one of them is flagged ``resurrection``.

    The capacity reported is the upper end of the final bracket: a scale at which the block
    was seen to overturn, within ``tolerance`` of the highest scale below it at which it
    survived. Every level below it that was simulated survived; an overturning window narrower
    than the bracket steps (a factor ``growth``) below it can be missed, as by any ladder, and
    so can a survival window narrower than the scan's steps. Under records such windows are
    common and narrow (0.4-1 % of the scale on the synthetic near-fault records of the tests
    and benchmarks/bench_ida.py): a "first overturning level" is always relative to the grid
    that looked for it.

    Parameters
    ----------
    im : str
        The measure the capacity is reported in (see :func:`multiple_stripes`); the
        capacities in every other measure follow from ``capacity_scale``.
    tolerance : float
        Relative width of the final bracket of the scale factor, hence of every measure linear
        in it (all but Arias intensity, which goes as its square), in (0, 1).
    growth : float
        Ratio of successive bracketing scales, > 1 + tolerance.
    max_pga_ratio : float
        Top of the range, PGA / (g tan alpha), > 1.
    scan : int
        Levels of the resurrection scan above each capacity (0: no scan).
    records, structures, period, periods, damping, method, rtol, max_steps
        As in :func:`multiple_stripes`.

    Returns
    -------
    xarray.Dataset
        On (record, structure): ``capacity`` (in the units of ``im``; NaN if censored),
        ``capacity_scale`` and ``capacity_scale_lower`` (the bracket), ``censored``,
        ``resurrection``, ``resurrection_scale`` (the lowest surviving scan scale above the
        capacity; NaN if none), ``simulations`` and ``status`` (0 ok; 1 if a simulation on
        which a decision rests hit the step limit). On (record, structure, step): every
        simulated point in the order run, ``step_scale``, ``step_max_rotation``,
        ``step_overturned`` (NaN-padded), for IDA curves. Attributes: ``n_simulations``,
        ``tolerance``, ``im``.
    """
    records = _records(records)
    st = _structures(structures)
    period, periods = _target(im, period, periods)
    if not 0.0 < tolerance < 1.0:
        raise ValueError(f"tolerance must lie in (0, 1), got {tolerance!r}")
    if not (math.isfinite(growth) and growth > 1.0 + tolerance):
        raise ValueError(f"growth must be a finite number > 1 + tolerance, got {growth!r}")
    if not (math.isfinite(max_pga_ratio) and max_pga_ratio > 1.0):
        raise ValueError(f"max_pga_ratio must be a finite number > 1, got {max_pga_ratio!r}")
    if int(scan) != scan or scan < 0:
        raise ValueError(f"scan must be a whole number >= 0, got {scan!r}")
    ds = _record_dataset(records, st, periods, damping)
    n = st["slenderness"].size
    measure = np.array([_record_measure(r, im, period, damping, st) for r in records])
    results = [
        _ida_record(r, st, tolerance, growth, max_pga_ratio, int(scan), method, rtol, max_steps)
        for r in records
    ]
    dims = ("record", "structure")
    for k in ("capacity_scale", "capacity_scale_lower", "resurrection_scale"):
        ds[k] = (dims, np.array([res[k] for res in results]))
    for k in ("censored", "resurrection"):
        ds[k] = (dims, np.array([res[k] for res in results], bool))
    for k in ("simulations", "status"):
        ds[k] = (dims, np.array([res[k] for res in results], np.int64))
    n_step = max(max(len(h) for h in res["history"]) for res in results)
    steps = np.full((len(records), n, max(n_step, 1), 3), np.nan)
    for i, res in enumerate(results):
        for j, h in enumerate(res["history"]):
            if h:
                steps[i, j, : len(h)] = h
    for c, k in enumerate(("step_scale", "step_max_rotation", "step_overturned")):
        ds[k] = (dims + ("step",), steps[..., c])
    power = _im.SCALING_POWER[DIMENSIONLESS.get(im, im)]
    ds["capacity"] = (
        dims,
        np.where(ds["censored"], np.nan, measure * ds["capacity_scale"] ** power),
        {
            "units": "1" if im in DIMENSIONLESS else _im.UNITS[im],
            "long_name": f"overturning {im} (first overturning level)",
        },
    )
    ds.attrs.update(
        design="ida",
        im=im,
        im_period=np.nan if period is None else period,
        tolerance=tolerance,
        growth=growth,
        max_pga_ratio=max_pga_ratio,
        method=method,
        rtol=rtol,
        n_simulations=int(ds["simulations"].sum()),
    )
    return ds


def _ida_record(record, st, tolerance, growth, max_pga_ratio, scan, method, rtol, max_steps):
    """Bracket, bisect and scan all structures of one record (see the public function)."""
    n = st["slenderness"].size
    pga = record.peak
    if not pga > 0:
        raise ValueError(f"records: the record {record.name!r} has PGA 0; it cannot be scaled")
    s_top = max_pga_ratio * G * np.tan(st["slenderness"]) / pga
    lo = G * st["slenderness"] / pga  # no uplift at or below: survives without a simulation
    hi = np.full(n, np.nan)
    history = [[] for _ in range(n)]
    sims = np.zeros(n, np.int64)
    status = np.zeros(n, np.int64)

    def run(idx, scales):
        out = _run(record, st, idx, scales, method, rtol, max_steps)
        for j, s, m, o in zip(idx, scales, out["max_rotation"], out["overturned"], strict=True):
            history[j].append((s, m, float(o)))
        np.add.at(sims, idx, 1)
        status[idx] |= out["status"] != 0
        return out["overturned"]

    censored = np.zeros(n, bool)
    active = np.arange(n)
    while active.size:  # 1. bracket
        s = np.minimum(lo[active] * growth, s_top[active])
        over = run(active, s)
        hi[active[over]] = s[over]
        lo[active[~over]] = s[~over]
        censored[active[~over & (s >= s_top[active])]] = True
        active = active[~over & (s < s_top[active])]
    while True:  # 2. bisect
        active = np.flatnonzero(~censored & (hi > lo * (1.0 + tolerance)))
        if not active.size:
            break
        s = np.sqrt(lo[active] * hi[active])
        over = run(active, s)
        hi[active[over]] = s[over]
        lo[active[~over]] = s[~over]
    resurrection_scale = np.full(n, np.nan)
    found = ~censored & (s_top > hi * (1.0 + tolerance))
    if scan and found.any():  # 3. scan above the capacity
        idx = np.flatnonzero(found)
        k = np.arange(1, scan + 1) / scan
        scales = hi[idx, None] * (s_top[idx, None] / hi[idx, None]) ** k[None, :]
        rows = np.repeat(idx, scan)
        over = run(rows, scales.ravel()).reshape(idx.size, scan)
        survived = np.where(~over, scales, np.inf).min(axis=1)
        resurrection_scale[idx] = np.where(np.isfinite(survived), survived, np.nan)
    return {
        "capacity_scale": np.where(censored, np.nan, hi),
        "capacity_scale_lower": lo,
        "censored": censored,
        "resurrection": np.isfinite(resurrection_scale),
        "resurrection_scale": resurrection_scale,
        "simulations": sims,
        "status": status,
        "history": history,
    }
