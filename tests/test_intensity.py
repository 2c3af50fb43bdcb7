"""Intensity measures of records against independent oracles: scipy.signal.lsim (exact for a
linearly interpolated input), closed forms for constant and harmonic inputs, and trapezoidal
integrals (scipy.integrate)."""

import math

import numpy as np
import pytest
from _helpers import study_text
from scipy import integrate, optimize, signal

from rockstudy.constants import STANDARD_GRAVITY, G
from rockstudy.motions import Record, SinePulse, intensity
from rockstudy.motions.measures import MEASURES

KEYS = {
    "pga",
    "pgv",
    "pgd",
    "arias",
    "cav",
    "significant_duration",
    "mean_period",
    "spectrum_intensity",
    "sa",
}


def _random_record(n=1500, dt=0.01, seed=3):
    rng = np.random.default_rng(seed)
    return Record(rng.standard_normal(n), dt=dt, name="noise")


def _oscillator(period, zeta):
    w = 2 * math.pi / period
    return signal.StateSpace([[0, 1], [-w * w, -2 * zeta * w]], [[0], [1]], [[1, 0]], [[0]])


def _lsim_peak(record, period, zeta, refine):
    """Peak |u| by lsim on a grid refined ``refine`` times (the input is linear on it), then
    the free vibration after the record (zero input), also by lsim."""
    t = record.time
    tf = np.linspace(t[0], t[-1], (t.size - 1) * refine + 1)
    sys = _oscillator(period, zeta)
    _, y, x = signal.lsim(sys, -np.interp(tf, t, record.acceleration), tf)
    tail = np.linspace(0.0, 1.5 * period, 3000 * refine // 10 + 1)
    _, y2, _ = signal.lsim(sys, np.zeros(tail.size), tail, X0=x[-1])
    sample_peak = float(np.max(np.abs(y[::refine])))
    return max(np.max(np.abs(y)), np.max(np.abs(y2))), sample_peak


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.2])
@pytest.mark.parametrize(
    "period, refine, rtol", [(0.05, 100, 2e-4), (0.3, 40, 1e-5), (1.0, 40, 1e-5), (4.0, 20, 1e-5)]
)
def test_spectral_displacement_matches_lsim(zeta, period, refine, rtol):
    rec = _random_record(n=600)
    sd = rec.response_spectrum([period], damping=zeta)["sd"].values[0]
    ref, at_samples = _lsim_peak(rec, period, zeta, refine)
    assert sd == pytest.approx(ref, rel=rtol)
    assert sd >= at_samples * (1 - 1e-9)  # peaks between samples are not lost


@pytest.mark.parametrize("period", [0.05, 0.5, 3.0])
def test_non_uniform_steps_match_lsim(period):
    """Sample times on multiples of 1 ms with random steps of 2-7 ms: lsim on the uniform 1/20 ms
    grid that holds every sample (the input is linear on it) is exact."""
    rng = np.random.default_rng(11)
    ticks = np.concatenate(([0], np.cumsum(rng.integers(2, 8, 700))))
    acc = rng.standard_normal(ticks.size)
    rec = Record(acc, time=1e-3 * ticks)
    sd = rec.response_spectrum([period], damping=0.05)["sd"].values[0]
    fine = Record(np.interp(np.arange(ticks[-1] + 1), ticks, acc), dt=1e-3)
    ref, _ = _lsim_peak(fine, period, 0.05, 20)
    assert sd == pytest.approx(ref, rel=5e-5)


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.1])
def test_constant_input_closed_form(zeta):
    """A step a0 from rest: SD = a0 / omega^2 (1 + exp(-zeta pi / sqrt(1 - zeta^2)))."""
    a0, period = 2.0, 1.0
    rec = Record(np.full(6001, a0), dt=0.01)
    w = 2 * math.pi / period
    overshoot = math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta))
    sd = rec.response_spectrum([period], damping=zeta)["sd"].values[0]
    assert sd == pytest.approx(a0 / w**2 * (1 + overshoot), rel=1e-9)


def test_harmonic_input_closed_form():
    """u'' + w^2 u = -A sin(W t) from rest: u = -A / (w^2 - W^2) (sin W t - W / w sin w t),
    then free vibration of amplitude sqrt(u^2 + (v / w)^2) after the record."""
    A, Tg, period = 3.0, 0.7, 1.1
    W, w = 2 * math.pi / Tg, 2 * math.pi / period
    dt = Tg / 2000
    t = dt * np.arange(5 * 2000 + 1)  # five whole cycles
    rec = Record(A * np.sin(W * t), dt=dt)
    tt = np.linspace(0, t[-1], 2_000_001)
    c = -A / (w * w - W * W)
    u = c * (np.sin(W * tt) - W / w * np.sin(w * tt))
    v_end = c * (W * math.cos(W * t[-1]) - W * math.cos(w * t[-1]))
    expected = max(np.max(np.abs(u)), math.hypot(u[-1], v_end / w))
    sd = rec.response_spectrum([period], damping=0.0)["sd"].values[0]
    assert sd == pytest.approx(expected, rel=1e-5)


def test_spectrum_dataset_and_pseudo_relations():
    rec = _random_record()
    periods = [0.1, 0.5, 2.0]
    ds = rec.response_spectrum(periods, damping=0.05)
    assert set(ds.data_vars) == {"sa", "psv", "sd"}
    assert list(ds["period"].values) == periods
    assert ds["sa"].attrs["units"] == "m/s^2" and ds["psv"].attrs["units"] == "m/s"
    assert ds["sd"].attrs["units"] == "m" and ds["period"].attrs["units"] == "s"
    w = 2 * np.pi / np.array(periods)
    np.testing.assert_allclose(ds["sa"].values, w**2 * ds["sd"].values, rtol=1e-14)
    np.testing.assert_allclose(ds["psv"].values, w * ds["sd"].values, rtol=1e-14)


def test_short_period_sa_tends_to_pga():
    """A rigid oscillator follows the ground: Sa(T -> 0) -> PGA (up to its lag 2 zeta a'/omega)
    for a record that starts at zero."""
    rec = _random_record(dt=0.02)
    rec = Record(np.concatenate(([0.0], rec.acceleration)), dt=0.02)
    for period in (1e-4, 1e-9):
        sa = rec.intensity_measures(periods=[period])["sa"][0]
        assert sa == pytest.approx(rec.peak, rel=1e-3)


def test_short_period_sa_of_a_record_that_starts_with_a_step():
    """The record is zero before t = 0: its first value is a step, which a stiff oscillator
    overshoots by exp(-zeta pi / sqrt(1 - zeta^2)) (closed form of the step response)."""
    zeta = 0.05
    acc = np.array([2.0, 0.5, -1.0, 0.3, 0.0])
    rec = Record(acc, dt=0.02)
    expected = 2.0 * (1 + math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta)))
    for period in (2e-4, 1e-7, 1e-12):  # sub-stepped, then the rigid limit
        sa = rec.intensity_measures(periods=[period], damping=zeta)["sa"][0]
        assert sa == pytest.approx(expected, rel=2e-3)


def test_spectrum_sub_steps_short_periods_against_dense_lsim():
    """Issue 23: a 40-sample noise record at dt 0.02 s lost 23 % at T = 0.0258 s (omega dt > pi
    hid an oscillation). Oracle: lsim on a 400x sub-sampled piecewise-linear interpolant."""
    rec = Record(np.random.default_rng(1).standard_normal(40), dt=0.02)
    periods = [0.005, 0.0258, 0.04, 0.1]
    sd = rec.response_spectrum(periods, damping=0.05)["sd"].values
    for period, value in zip(periods, sd, strict=True):
        ref, _ = _lsim_peak(rec, period, 0.05, 400)
        assert value == pytest.approx(ref, rel=2e-5)
        assert value >= ref * (1 - 1e-6)


@pytest.mark.parametrize("period", [1e-300, 1e300, 0.0, -1.0, float("nan")])
def test_absurd_periods_are_refused(period):
    """Issue 26: Sa at 1e-300 s was NaN, at 1e300 s a SystemError from numba."""
    with pytest.raises(ValueError, match="periods"):
        _random_record(n=50).intensity_measures(periods=[period])


def test_too_long_a_period_for_the_step_is_refused():
    with pytest.raises(ValueError, match="periods.*too long"):
        _random_record(n=50, dt=0.01).response_spectrum([1e5])


def test_sine_record_cav_arias_duration_closed_forms():
    """Whole cycles of A sin(W t), N samples a cycle: the trapezoidal sums over the samples are
    exactly t_end / 2 for sin^2 (discrete orthogonality), so Arias = pi A^2 t_end / (4 g);
    CAV = 4 A / W per cycle (to O(dt^2)); the Husid curve is that of sin^2."""
    A, Tg, cycles = 2.0, 0.5, 6
    W = 2 * math.pi / Tg
    dt = Tg / 4000
    t = dt * np.arange(cycles * 4000 + 1)
    im = Record(A * np.sin(W * t), dt=dt).intensity_measures()
    assert set(im) == KEYS
    assert im["cav"] == pytest.approx(cycles * 4 * A / W, rel=1e-6)
    assert im["arias"] == pytest.approx(math.pi * A * A * t[-1] / (4 * G), rel=1e-12)
    husid = lambda s, q: (s / 2 - math.sin(2 * W * s) / (4 * W)) / (t[-1] / 2) - q  # noqa: E731
    d595 = optimize.brentq(husid, 0, t[-1], args=(0.95,)) - optimize.brentq(
        husid, 0, t[-1], args=(0.05,)
    )
    assert im["significant_duration"] == pytest.approx(d595, rel=1e-4)


def test_arias_of_a_sine_at_a_quarter_of_the_sampling_rate():
    """Issue 23: samples 0, A, 0, -A, ... The trapezoid over the samples gives the true Arias
    intensity of the sine, pi A^2 t_end / (4 g); the interpolated record gave 2/3 of it."""
    A, dt = 3.0, 0.01
    t = dt * np.arange(4 * 500 + 1)
    acc = A * np.sin(2 * math.pi * t / (4 * dt))
    arias = Record(acc, dt=dt).intensity_measures()["arias"]
    assert arias == pytest.approx(math.pi * A * A * t[-1] / (4 * G), rel=1e-9)


def test_baseline_correction_properties():
    """Velocity: the trapezoidal integral of the record less the constant that brings
    v(t_end) to zero (scipy). Displacement: the integral of that velocity on the linearly
    interpolated record (dense scipy trapezoid) less a cubic c2 t^2 + c3 t^3, and orthogonal
    to t^2 and t^3 (least squares)."""
    rec = _random_record()
    t, a = rec.time, rec.acceleration
    c = integrate.trapezoid(a, t) / t[-1]
    v = integrate.cumulative_trapezoid(a - c, t, initial=0.0)
    np.testing.assert_allclose(intensity.ground_velocity(t, a), v, atol=1e-12)
    d = intensity.ground_displacement(t, a)
    assert d[0] == 0.0
    x = t / t[-1]
    for basis in (x * x, x**3):
        assert abs(basis @ d) <= 1e-9 * np.linalg.norm(basis) * np.linalg.norm(d)
    tf = np.linspace(0, t[-1], (t.size - 1) * 20 + 1)
    vf = integrate.cumulative_trapezoid(np.interp(tf, t, a - c), tf, initial=0.0)
    raw = integrate.cumulative_trapezoid(vf, tf, initial=0.0)[::20]
    drift = raw - d  # a cubic without constant or linear term
    fit = np.polynomial.polynomial.polyfit(x, drift, [2, 3])
    np.testing.assert_allclose(
        drift, np.polynomial.polynomial.polyval(x, fit), atol=1e-5 * np.ptp(raw)
    )
    im = rec.intensity_measures()
    assert im["pgv"] == pytest.approx(np.max(np.abs(v)), rel=1e-12)
    assert im["pgd"] == np.max(np.abs(d))


def test_el_centro_drift_is_removed(records_dir):
    """Issue 23: El Centro 1940 had PGD 1.81 m with the constant offset alone; the polynomial
    baseline leaves a PGD below 0.4 m, while the processed PEER records change by < 0.5 %."""
    rec = Record.from_csv(records_dir / "elcentro_NS.dat")
    assert rec.intensity_measures()["pgd"] < 0.4
    for path in sorted(records_dir.glob("*.AT2")):
        r = Record.from_at2(path)
        t, a = r.time, r.acceleration
        c = integrate.trapezoid(a, t) / t[-1]
        v = integrate.cumulative_trapezoid(a - c, t, initial=0.0)
        d = integrate.cumulative_trapezoid(v, t, initial=0.0)
        assert r.intensity_measures()["pgd"] == pytest.approx(np.max(np.abs(d)), rel=5e-3)


def test_pgv_and_arias_against_trapezoidal_integrals():
    rec = _random_record()
    t, a = rec.time, rec.acceleration
    im = rec.intensity_measures()
    arias = math.pi / (2 * G) * integrate.trapezoid(a**2, t)
    assert im["arias"] == pytest.approx(arias, rel=1e-12)
    assert im["cav"] == pytest.approx(integrate.trapezoid(np.abs(a), t), rel=1e-12)


def test_huge_records_do_not_overflow_silently():
    """Samples scaled by 1e300 gave Arias and CAV = inf or NaN. A Record refuses them (beyond
    the 1e7 m/s^2 any motion reaches); the measures on raw samples: CAV is finite and scales,
    Arias (1e600) cannot be represented and is refused, naming the acceleration."""
    rec = _random_record(n=200)
    with pytest.raises(ValueError, match="factor"):
        rec.scaled(1e300)
    t, big = rec.time, rec.acceleration * 1e300
    assert intensity.cumulative_absolute_velocity(t, big) == pytest.approx(
        1e300 * rec.intensity_measures()["cav"], rel=1e-12
    )
    with pytest.raises(ValueError, match="acceleration"):
        intensity.arias_intensity(t, big)
    small = rec.acceleration * 1e-160  # a^2 underflows, the intensity does not
    assert intensity.arias_intensity(t, small) == pytest.approx(
        1e-320 * rec.intensity_measures()["arias"], rel=1e-6
    )


def test_cav_of_a_ramp_through_zero():
    """Samples 1, -1 over h: the trapezoid over the samples gives h (|1| + |-1|) / 2 = h."""
    assert Record([1.0, -1.0], dt=0.4).intensity_measures()["cav"] == pytest.approx(0.4, rel=1e-15)


def test_mean_period_of_two_tones():
    """A1 sin(2 pi f1 t) + A2 sin(2 pi f2 t) on exact FFT bins: the Rathje et al. (2004) mean
    period weights C^2, so T_m = (A1^2 / f1 + A2^2 / f2) / (A1^2 + A2^2) = 0.325 s here (the
    C^1 weights would give 0.4375 s, a flat weight 0.625 s)."""
    dt, n = 1 / 128, 2**14
    t = dt * np.arange(n)
    (a1, f1), (a2, f2) = (1.0, 1.0), (3.0, 4.0)
    acc = a1 * np.sin(2 * math.pi * f1 * t) + a2 * np.sin(2 * math.pi * f2 * t)
    tm = Record(acc, dt=dt).intensity_measures()["mean_period"]
    assert tm == pytest.approx((a1**2 / f1 + a2**2 / f2) / (a1**2 + a2**2), rel=1e-9)


def test_mean_period_refuses_a_step_that_resolves_no_frequency_of_its_band():
    """mean_period at dt 1e100 was NaN without a warning: a Record refuses the duration, and
    the measure on raw samples refuses the step."""
    samples = np.random.default_rng(0).standard_normal(64)
    with pytest.raises(ValueError, match="duration"):
        Record(samples, dt=1e100)
    with pytest.raises(ValueError, match="dt"):
        intensity.mean_period(1e100 * np.arange(64.0), samples)


def test_spectrum_intensity_of_a_step():
    """A step a0: PSV(T) = a0 T / (2 pi) (1 + overshoot), linear in T, so Housner's integral over
    0.1-2.5 s is a0 (1 + overshoot) (2.5^2 - 0.1^2) / (4 pi)."""
    a0, zeta = 1.5, 0.05
    overshoot = math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta))
    si = Record(np.full(12001, a0), dt=0.005).intensity_measures(damping=zeta)["spectrum_intensity"]
    assert si == pytest.approx(a0 * (1 + overshoot) * (2.5**2 - 0.1**2) / (4 * math.pi), rel=1e-9)


def test_sa_of_sampled_sine_pulse_matches_lsim_and_is_cached():
    pulse = SinePulse(3.0, 0.8)
    dt = 0.002
    t = dt * np.arange(int(pulse.duration / dt) + 1)
    rec = Record(pulse.ground_acceleration(t), dt=dt)
    periods = np.array([0.3, 0.8, 2.0])
    sa = rec.intensity_measures(periods=periods)["sa"]
    ref = [_lsim_peak(rec, T, 0.05, 20)[0] * (2 * np.pi / T) ** 2 for T in periods]
    np.testing.assert_allclose(sa, ref, rtol=1e-5)
    sa[:] = 0.0  # the caller's copy: the cache is not touched
    np.testing.assert_allclose(rec.intensity_measures(periods=periods)["sa"], ref, rtol=1e-5)
    assert rec.intensity_measure("sa", period=0.8) == pytest.approx(ref[1], rel=1e-5)


def test_empty_periods_and_units_table():
    im = _random_record().intensity_measures()
    assert im["sa"].shape == (0,)
    assert KEYS <= set(MEASURES)


def test_non_uniform_record_equals_uniform_one():
    """The same samples given by dt or by (non-uniform-looking) times give the same IMs."""
    rec = _random_record(n=800)
    jitter = Record(rec.acceleration, time=rec.time + 1e-13 * np.arange(800) % 3)
    a, b = rec.intensity_measures([0.5]), jitter.intensity_measures([0.5])
    for key in KEYS:
        np.testing.assert_allclose(a[key], b[key], rtol=1e-9)


def test_scaled_to_targets():
    rec = _random_record()
    assert rec.scaled_to(2.0, im="pga").peak == pytest.approx(2.0, rel=1e-14)
    assert rec.scaled_to(0.3, im="pgv").intensity_measures()["pgv"] == pytest.approx(0.3)
    assert rec.scaled_to(0.7, im="arias").intensity_measures()["arias"] == pytest.approx(0.7)
    scaled = rec.scaled_to(4.0, im="sa", period=0.5)
    assert scaled.intensity_measure("sa", period=0.5) == pytest.approx(4.0, rel=1e-12)


@pytest.mark.parametrize(
    "call, field",
    [
        (lambda r: r.intensity_measure("pgx"), "im"),
        (lambda r: r.scaled_to(1.0, im="spectral_velocity"), "im"),
        (lambda r: r.intensity_measures(periods=[0.5, -1.0]), "periods"),
        (lambda r: r.intensity_measures(periods=[0.0]), "periods"),
        (lambda r: r.response_spectrum([1.0], damping=1.0), "damping"),
        (lambda r: r.intensity_measure("sa"), "period"),
        (lambda r: r.intensity_measure("pga", period=1.0), "period"),
        (lambda r: r.scaled_to(-1.0), "value"),
        (lambda r: r.scaled_to(1.0, im="mean_period"), "mean_period"),
        (lambda r: r.scaled(float("nan")), "factor"),
    ],
)
def test_bad_input_names_the_field(call, field):
    with pytest.raises(ValueError, match=field):
        call(_random_record(n=50))


def test_scale_target_out_of_reach():
    still = Record(np.zeros(100), dt=0.01, name="still")
    with pytest.raises(ValueError, match="im='pga'.*'still'"):
        still.scaled_to(3.0, im="pga")


# --- vertical component (data model) --------------------------------------------------------


def _write_at2(path, values, dt):
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "test",
        "ACCELERATION TIME SERIES IN UNITS OF G",
    ]
    lines.append(f"NPTS=   {len(values)}, DT=   {dt:.4f} SEC")
    lines += [" ".join(f"{x:.7E}" for x in values[i : i + 5]) for i in range(0, len(values), 5)]
    path.write_text("\n".join(lines) + "\n")


def test_vertical_on_same_samples_and_scaled_consistently():
    rec = Record([0.0, 1.0, -2.0, 0.5], dt=0.01, vertical=[0.1, -0.2, 0.3, 0.0])
    mirrored = rec.scaled(-2.0)
    np.testing.assert_array_equal(mirrored.acceleration, [0.0, -2.0, 4.0, -1.0])
    np.testing.assert_array_equal(mirrored.vertical, [0.2, -0.4, 0.6, 0.0])
    np.testing.assert_array_equal(mirrored.time, rec.time)
    assert Record([1.0, 2.0], dt=0.1).vertical is None
    with pytest.raises(ValueError, match="vertical"):
        Record([0.0, 1.0, 2.0], dt=0.01, vertical=[0.0, 1.0])
    with pytest.raises(ValueError, match="vertical"):
        Record([0.0, 1.0], dt=0.01, vertical=[0.0, float("nan")])


def test_at2_pair(tmp_path):
    h, v = tmp_path / "h.AT2", tmp_path / "v.AT2"
    _write_at2(h, [0.1, 0.2, -0.1, 0.0, 0.05, 0.0], 0.01)
    _write_at2(v, [0.0, 0.05, 0.02, -0.01, 0.0, 0.0], 0.01)
    rec = Record.from_at2(h, vertical=v)
    np.testing.assert_allclose(
        rec.vertical, np.array([0.0, 0.05, 0.02, -0.01, 0.0, 0.0]) * STANDARD_GRAVITY
    )
    short, coarse = tmp_path / "short.AT2", tmp_path / "coarse.AT2"
    _write_at2(short, [0.0, 0.05, 0.02], 0.01)
    _write_at2(coarse, [0.0, 0.05, 0.02, -0.01, 0.0, 0.0], 0.02)
    for bad in (short, coarse):
        with pytest.raises(ValueError, match=f"vertical.*{bad.name}"):
            Record.from_at2(h, vertical=bad)


def test_csv_pair(tmp_path):
    h, v, bad = tmp_path / "h.csv", tmp_path / "v.csv", tmp_path / "bad.csv"
    h.write_text("0,0.1\n0.01,0.2\n0.02,-0.1\n")
    v.write_text("0 0.0\n0.01 0.05\n0.02 0.01\n")
    bad.write_text("0 0.0\n0.02 0.05\n0.04 0.01\n")
    rec = Record.from_csv(h, vertical=v)
    np.testing.assert_allclose(rec.vertical, np.array([0.0, 0.05, 0.01]) * STANDARD_GRAVITY)
    with pytest.raises(ValueError, match="vertical.*bad.csv"):
        Record.from_csv(h, vertical=bad)


# --- the shared real records ----------------------------------------------------------------


def test_shared_records_plausible(records_dir):
    """Physical checks on real records: Sa at a tiny period is the PGA, durations and mean
    periods lie within the record and the usual 0.1-2 s range. Prints the measures."""
    files = sorted(records_dir.glob("*.AT2"))
    recs = [Record.from_at2(f) for f in files] + [Record.from_csv(records_dir / "elcentro_NS.dat")]
    for rec in recs:
        im = rec.intensity_measures(periods=[1e-3, 1.0])
        print(rec.name, {k: np.round(v, 4) for k, v in im.items()})
        assert im["sa"][0] == pytest.approx(im["pga"], rel=2e-3)  # lag 2 zeta a'/omega
        assert 0 < im["significant_duration"] < rec.duration
        assert 0.1 < im["mean_period"] < 2.0
    elcentro = recs[-1]
    assert elcentro.peak / STANDARD_GRAVITY == pytest.approx(0.349, abs=0.001)  # README: 0.349 g


def test_a_study_cube_states_both_gravities(tmp_path):
    """The cube says which g the physics used and which g a record in g was read with."""
    import xarray as xr

    from rockstudy.study import make_design, validate_text
    from rockstudy.study.running.store import claim, create_store

    study = validate_text(study_text(chunk=10, n=20))
    out = tmp_path / "cube.zarr"
    lock, _ = claim(out, study, {}, resume=False)
    try:
        create_store(out, make_design(study), study)
    finally:
        lock.release()
    attrs = xr.open_zarr(out).attrs
    assert attrs["gravity"] == G == 9.81
    assert attrs["record_g_unit"] == STANDARD_GRAVITY == 9.80665
