"""The batch outputs are declared once (rockstudy.dynamics.outputs), and ``peak_time`` is the
time of the largest peak by every batch kernel, also when it falls in the free rocking after
the motion (the free-rocking map, timed in closed form)."""

import math
import typing
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rockstudy as rs
from rockstudy.dynamics import _free_map, _rocking, _rows, batch, outputs
from rockstudy.motions import Record, SinePulse, stochastic_record

G = 9.81
#: The agreement asked of peak_time with simulate()'s largest peak [s].
PEAK_TIME_TOL = 1e-9
#: Scenes kept for the peak-time comparison: max |theta| below this fraction of alpha. Nearer
#: the top the time to the peak grows as log(1 / (alpha - theta_max)) and both solvers' times
#: are ill-conditioned (a 1e-12 change of the state moves it by more than 1e-9 s).
WELL_CONDITIONED = 0.8


def _scenes(n, seed):
    rng = np.random.default_rng(seed)
    R, alpha = rng.uniform(0.3, 4.0, n), rng.uniform(0.05, 0.3, n)
    amp = rng.uniform(1.0, 3.0, n) * G * np.tan(alpha)
    return R, alpha, amp, rng.uniform(0.2, 1.0, n), rng.uniform(0.5, 1.5, n)


def _strong_record(vertical=False):
    """A synthetic record cut while it shakes (2.5 s of 6 s): many blocks still rock at its
    end, so their largest peak can fall in the free rocking after it."""
    full = stochastic_record(3.0, duration=6.0, seed=3)
    acc = full.acceleration[: int(2.5 / full.dt)]
    return Record(acc, dt=full.dt, vertical=0.2 * np.roll(acc, 17) if vertical else None)


#: (method, motion) -> the kernel that runs it in a batch
CASES = {
    ("nonlinear", "sine"): "Taylor kernel, Housner's model",
    ("nonlinear", "record"): "Taylor kernel, Housner's model",
    ("linear", "sine"): "exact linear (trigonometric pulse)",
    ("linear", "record"): "exact linear (record)",
    ("linear", "vertical record"): "Taylor kernel, linearized model",
}


def _run_both(method, motion, n=120, seed=2):
    """simulate_batch and simulate on the same scenes: (batch outputs, durations, the
    simulate() results of the well-conditioned scenes that rocked and stand, by row)."""
    R, alpha, amp, tp, scale = _scenes(n, seed)
    rtol = 1e-12
    if motion == "sine":  # three cycles: impacts inside the pulse, then the map after it
        kw = dict(pulse="sine", amplitude=amp, period=tp, cycles=3)
        motions = [SinePulse(amplitude=a, period=t, cycles=3) for a, t in zip(amp, tp, strict=True)]
    else:
        rec = _strong_record(vertical=motion == "vertical record")
        kw = dict(record=rec, scale=scale)
        motions = [rec.scaled(s) for s in scale]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = rs.simulate_batch(half_diagonal=R, slenderness=alpha, method=method, rtol=rtol, **kw)
    keep = (
        ~out["overturned"]
        & (out["max_rotation"] > 0)
        & (out["max_rotation"] < WELL_CONDITIONED * alpha)
    )
    sims = {}
    for i in np.flatnonzero(keep):
        block = rs.Block(half_diagonal=R[i], slenderness=alpha[i])
        sims[i] = rs.simulate(block, motions[i], method=method, rtol=rtol)
    return out, np.array([m.duration for m in motions]), sims


@pytest.mark.parametrize("method, motion", list(CASES), ids=lambda x: str(x))
def test_peak_time_is_the_time_of_the_largest_peak_of_simulate(method, motion):
    """peak_time from simulate_batch equals simulate().peak_times at the largest |peak| to
    1e-9 s, for each batch kernel; among the scenes, peaks reached in the free rocking after
    the motion, after an impact inside it (where the batch maps the free rocking in closed
    form while simulate integrates it)."""
    out, dur, sims = _run_both(method, motion)
    mapped = 0
    for i, r in sims.items():
        k = np.argmax(np.abs(r.peak_rotations))
        assert abs(r.peak_rotations[k]) == pytest.approx(out["max_rotation"][i], rel=1e-8)
        assert abs(out["peak_time"][i] - r.peak_times[k]) <= PEAK_TIME_TOL, (i, dur[i])
        mapped += r.peak_times[k] > dur[i] and out["first_impact_time"][i] < dur[i]
    assert mapped >= 5, f"only {mapped} scenes peak in the mapped free rocking"


@pytest.mark.parametrize("method", ["nonlinear", "linear", "auto"])
def test_peak_time_of_an_overturned_or_resting_block(method):
    """An overturned block reaches max |theta| = pi/2 at its overturning; one that never lifts
    has no peak (NaN), the table's value at rest, also where ``auto`` runs no kernel."""
    alpha = np.array([0.2, 0.2, 0.2])
    ratio = np.array([6.0, 0.5, 1.5])  # overturns, never lifts, rocks
    out = rs.simulate_batch(
        half_diagonal=1.0,
        slenderness=alpha,
        amplitude=ratio * G * np.tan(alpha),
        period=0.5,
        method=method,
    )
    assert out["overturned"][0] and out["peak_time"][0] == out["overturn_time"][0]
    assert out["max_rotation"][1] == 0 and np.isnan(out["peak_time"][1])
    for name in outputs.names("kernel"):
        np.testing.assert_equal(out[name][1], outputs.OUTPUTS[name].at_rest)
    assert 0 < out["peak_time"][2] and not out["overturned"][2]


def _free_rocking_ivp(u, v, p, alpha, eta, linear):
    """Time [s] of the largest peak of free rocking from (u, v) by solve_ivp (rtol 1e-13):
    Housner's u'' = -p^2 sin(alpha - u) (or p^2 (u - alpha)) on one side, the speed times eta
    at an impact; integrated through the first impact to the next peak."""

    def rhs(_, y):
        return [y[1], p * p * ((y[0] - alpha) if linear else -math.sin(alpha - y[0]))]

    def impact(_, y):
        return y[0]

    def peak(_, y):
        return y[1]

    impact.terminal, impact.direction = True, -1
    peak.terminal, peak.direction = True, -1
    tol = dict(method="DOP853", rtol=1e-13, atol=1e-15)
    if v > 0:
        return solve_ivp(rhs, (0, 50), [u, v], events=peak, **tol).t_events[0][0]
    to_impact = solve_ivp(rhs, (0, 50), [u, v], events=impact, **tol)
    t1, w = to_impact.t_events[0][0], to_impact.y_events[0][0][1]
    after = solve_ivp(rhs, (0, 50), [0.0, -eta * w], events=peak, **tol)
    return t1 + after.t_events[0][0]


@pytest.mark.parametrize("model", [_rocking.MODEL_NONLINEAR, _rocking.MODEL_LINEAR])
def test_free_rocking_peak_time_against_an_integration(model):
    """The closed-form time of the largest free-rocking peak (an elliptic integral by Carlson's
    R_F for Housner's model, an atanh for the linearized one) agrees with solve_ivp to 1e-10,
    rising to the peak and falling to an impact first."""
    rng = np.random.default_rng(5)
    checked = 0
    while checked < 12:
        alpha, p = rng.uniform(0.03, 0.4), rng.uniform(1.5, 4.0)
        u = rng.uniform(0, 0.9) * alpha
        v = rng.uniform(-1, 1) * p * alpha * 0.5
        eta = rng.uniform(0.7, 0.98)
        over, peak, _ = _free_map.free_rocking_map(u, v, p, alpha, eta, model, 1e-6)
        if over or peak > WELL_CONDITIONED * alpha:
            continue
        got = _free_map.free_peak_time(u, v, p, alpha, eta, model)
        ref = _free_rocking_ivp(u, v, p, alpha, eta, model == _rocking.MODEL_LINEAR)
        assert got == pytest.approx(ref, abs=1e-10, rel=1e-10), (alpha, p, u, v, eta)
        checked += 1


def test_the_rise_time_is_legendre_s_elliptic_integral():
    """Housner's rise time from rotation u at speed w to the peak is Legendre's F(phi, m) with
    m = 1 - b^2, sin^2 phi = (y^2 - b^2) / (y^2 m) (Byrd & Friedman 216.00), here by scipy's
    ellipkinc."""
    from scipy.special import ellipkinc

    nonlinear = _rocking.MODEL_NONLINEAR
    for alpha, u, w in [(0.2, 0.05, 0.1), (0.05, 0.0, 0.03), (0.01, 0.004, 0.004)]:
        k = 0.5 * w * w + 2 * math.sin(alpha - 0.5 * u) * math.sin(0.5 * u)
        y2 = math.sin(0.5 * (alpha - u)) ** 2
        b2 = math.sin(0.5 * alpha) ** 2 - 0.5 * k
        m = 1 - b2
        phi = math.asin(math.sqrt((y2 - b2) / (y2 * m)))
        peak = _free_map._rotation_at(k, alpha, nonlinear)
        got = _free_map._travel_time(u, w, peak, 0.0, alpha, nonlinear)
        assert got == pytest.approx(ellipkinc(phi, m), rel=1e-12)


def test_the_table_drives_the_schema_the_batch_and_the_runner():
    """The schema's allowed outputs, simulate_batch's outputs and variables, and the study
    runner's outputs are the table's entries."""
    from rockstudy.study.running import evaluate
    from rockstudy.study.spec import schema

    table = outputs.OUTPUTS.values()
    assert typing.get_args(schema.Output) == tuple(o.name for o in table if o.in_study)
    assert list(evaluate.OUTPUTS) == [o.name for o in table if o.in_study]
    for name, (_, units, dtype, fill) in evaluate.OUTPUTS.items():
        entry = outputs.OUTPUTS[name]
        assert (units, dtype) == (entry.units, entry.store_dtype)
        np.testing.assert_equal(fill, entry.fill)
    by_stage = {s: {o.name for o in table if o.stage == s} for s in outputs.STAGES}
    assert set(batch.OUTPUTS) == by_stage["kernel"] | by_stage["batch"]
    assert set(batch.CONTACT_OUTPUTS) == by_stage["contact"]
    assert set(batch.CONDITIONING_OUTPUTS) == by_stage["conditioning"]
    ds = rs.simulate_batch(
        frequency_parameter=2.0, critical_rotation=0.2, amplitude=3.0, period=1.0, as_dataset=True
    )
    assert list(ds.data_vars) == list(batch.OUTPUTS)
    for name in ds.data_vars:
        entry = outputs.OUTPUTS[name]
        assert ds[name].attrs == {"long_name": entry.long_name, "units": entry.units}
        assert ds[name].dtype == np.dtype(entry.dtype)


def test_every_batch_kernel_writes_its_row():
    """Each kernel returns the table's row (KERNEL_ROW), every field of it written: a scene that
    rocks and stands has its times where they are known and NaN where not."""
    block = dict(frequency_parameter=2.5, critical_rotation=0.2, restitution=0.8)
    pulse = dict(amplitude=1.5 * G * np.tan(0.2), period=0.5)
    record = dict(record=stochastic_record(3.0, duration=4.0, seed=3), scale=0.8)
    rows = {
        "nonlinear (trig)": rs.simulate_batch(**block, **pulse),
        "exact linear (trig)": rs.simulate_batch(**block, **pulse, method="linear"),
        "exact linear (record)": rs.simulate_batch(**block, **record, method="linear"),
        "nonlinear (record)": rs.simulate_batch(**block, **record),
    }
    for name, out in rows.items():
        assert not out["overturned"][0] and out["n_impacts"][0] > 0, name
        assert np.isnan(out["overturn_time"][0]), name
        assert 0 < out["first_impact_time"][0] and 0 < out["peak_time"][0], name
        for field in outputs.names("kernel"):
            assert out[field].dtype == np.dtype(outputs.OUTPUTS[field].dtype), (name, field)
    assert _rows.new_rows(3).dtype == outputs.KERNEL_ROW


def test_write_row_writes_every_field():
    """The row writer sets each field of KERNEL_ROW from the outcome of the same name."""
    from collections import namedtuple

    names = outputs.KERNEL_ROW.names
    outcome = namedtuple("Outcome", names)(*range(1, len(names) + 1))
    out = np.zeros(1, outputs.KERNEL_ROW).view(np.recarray)
    _rows.write_row.py_func(out, 0, outcome)
    for j, name in enumerate(names):
        assert out[name][0] == outcome[j] or (name == "overturned" and out[name][0]), name
