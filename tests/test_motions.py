"""Ground motions: pulse definitions of DESIGN.md, the record readers and the generator."""

import math

import numpy as np
import pytest

from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.motions import (
    CosinePulse,
    HalfSinePulse,
    Record,
    RickerWavelet,
    SinePulse,
    stochastic_record,
)


def test_sine_pulse_definition():
    p = SinePulse(amplitude=3.0, period=0.8, cycles=2)
    t = np.linspace(0, 1.6, 101)
    np.testing.assert_allclose(
        p.ground_acceleration(t), 3.0 * np.sin(2 * np.pi * t / 0.8), atol=1e-14
    )
    assert p.duration == pytest.approx(1.6)
    assert p.ground_acceleration(1.7) == 0.0 and p.ground_acceleration(-0.1) == 0.0
    assert p.peak == 3.0


def test_cosine_and_half_sine_definitions():
    c = CosinePulse(amplitude=2.0, period=0.5)
    assert c.ground_acceleration(0.0) == pytest.approx(2.0)
    assert c.ground_acceleration(0.25) == pytest.approx(-2.0)
    h = HalfSinePulse(amplitude=-1.5, period=1.0)
    assert h.duration == 0.5
    assert h.ground_acceleration(0.25) == pytest.approx(-1.5)
    assert h.ground_acceleration(0.75) == 0.0


def test_ricker_starts_below_1e6_and_peaks_at_center():
    r = RickerWavelet(amplitude=4.0, period=0.7)
    assert abs(r.ground_acceleration(0.0)) <= 1e-6 * 4.0 * (1 + 1e-9)
    assert abs(r.ground_acceleration(0.0)) > 0.5e-6 * 4.0
    assert r.ground_acceleration(r.center) == pytest.approx(4.0, rel=1e-14)
    t = np.linspace(0, r.duration, 20001)
    assert np.max(np.abs(r.ground_acceleration(t))) == pytest.approx(4.0, rel=1e-12)
    f = 1 / 0.7
    x = (np.pi * f * (t - r.center)) ** 2
    np.testing.assert_allclose(r.ground_acceleration(t), 4.0 * (1 - 2 * x) * np.exp(-x), atol=1e-13)


@pytest.mark.parametrize(
    "bad",
    [
        {"amplitude": 0.0, "period": 1.0},
        {"amplitude": float("nan"), "period": 1.0},
        {"amplitude": 1.0, "period": -1.0},
        {"amplitude": 1.0, "period": 1.0, "cycles": 0},
    ],
)
def test_bad_pulse_input(bad):
    field = next(k for k, v in bad.items() if not (isinstance(v, float) and v == 1.0))
    with pytest.raises(ValueError, match=field):
        SinePulse(**bad)


RECORDS = {  # name: (points, dt) from shared/records/README.md
    "RSN126_GAZLI_GAZ000.AT2": (2048, 0.0066),
    "RSN183_IMPVALL.H_H-E08140.AT2": (7554, 0.005),
    "RSN948_NORTHR_CAM009.AT2": (3499, 0.01),
    "RSN982_NORTHR_JEN292.AT2": (5720, 0.005),
}


@pytest.mark.parametrize("name", sorted(RECORDS))
def test_at2_reader(records_dir, name):
    rec = Record.from_at2(records_dir / name)
    npts, dt = RECORDS[name]
    assert rec.acceleration.size == npts
    assert rec.dt == pytest.approx(dt)
    assert rec.duration == pytest.approx((npts - 1) * dt)
    first = float(open(records_dir / name).read().splitlines()[4].split()[0])
    assert rec.acceleration[0] == pytest.approx(first * STANDARD_GRAVITY)


def test_two_column_reader_el_centro(records_dir):
    rec = Record.from_csv(records_dir / "elcentro_NS.dat", units="g")
    assert rec.acceleration.size == 2688
    assert rec.dt == pytest.approx(0.02)
    assert rec.peak / STANDARD_GRAVITY == pytest.approx(0.349, abs=5e-4)


def test_record_interpolates_linearly():
    rec = Record([0.0, 2.0, -2.0], dt=0.5)
    np.testing.assert_allclose(
        rec.ground_acceleration([0.25, 0.5, 0.75, 1.0]), [1.0, 2.0, 0.0, -2.0]
    )
    assert rec.ground_acceleration(1.2) == 0.0


def test_record_rejects_nan_and_bad_time(tmp_path):
    with pytest.raises(ValueError, match="acceleration"):
        Record([0.0, np.nan, 1.0], dt=0.01)
    with pytest.raises(ValueError, match="time"):
        Record([0.0, 1.0, 2.0], time=[0.0, 0.02, 0.02])
    with pytest.raises(ValueError, match="time"):
        Record([0.0, 1.0, 2.0], time=[0.0, 0.02, 0.01])
    with pytest.raises(ValueError, match="dt"):
        Record([0.0, 1.0], dt=-0.01)
    bad = tmp_path / "bad.csv"
    bad.write_text("0.0, 0.1\n0.01, nan\n0.02, 0.0\n")
    with pytest.raises(ValueError, match="acceleration"):
        Record.from_csv(bad)
    with pytest.raises(ValueError, match="units"):
        Record.from_csv(bad, units="furlongs")


def test_stochastic_record_is_seeded_and_scaled():
    a = stochastic_record(peak=3.0, duration=10.0, dt=0.01, seed=7)
    b = stochastic_record(peak=3.0, duration=10.0, dt=0.01, seed=7)
    c = stochastic_record(peak=3.0, duration=10.0, dt=0.01, seed=8)
    np.testing.assert_array_equal(a.acceleration, b.acceleration)
    assert not np.allclose(a.acceleration, c.acceleration)
    assert a.peak == pytest.approx(3.0)
    assert a.duration == pytest.approx(10.0)
    # the envelope: quiet start, strong middle, decayed end
    acc = np.abs(a.acceleration)
    assert acc[:20].max() < 0.2 * 3.0
    assert acc[-50:].max() < 0.3 * 3.0


def test_stochastic_spectrum_follows_kanai_tajimi():
    from scipy.signal import welch

    wg, zg = 4 * math.pi, 0.4
    rec = stochastic_record(
        peak=1.0,
        duration=2000.0,
        dt=0.01,
        ground_frequency=wg,
        ground_damping=zg,
        rise=0.5,
        plateau_end=2000.0,
        seed=1,
    )
    f, psd = welch(rec.acceleration, fs=100.0, nperseg=512)
    w2 = (2 * np.pi * f) ** 2
    kt = (wg**4 + 4 * zg**2 * wg**2 * w2) / ((wg**2 - w2) ** 2 + 4 * zg**2 * wg**2 * w2)
    band = (f > 0.3) & (f < 6.0)
    ratio = psd[band] / kt[band]
    # the filtered noise has the Kanai-Tajimi shape: a flat ratio to the analytic PSD
    means = np.array([chunk.mean() for chunk in np.array_split(ratio, 6)])
    assert means.max() / means.min() < 1.15
    # while a white spectrum would not be flat against it
    assert kt[band].max() / kt[band].min() > 3
