"""Pulse extraction: the wavelet method (default; Baker 2007, Shahi & Baker 2014) and the
Mavroeidis-Papageorgiou fit, on known pulses in broadband, low-frequency and white noise, on
noise alone, and on the shared real records against a published T_p."""

import math

import numpy as np
import pytest
from scipy import integrate, signal

from rockstudy.motions import Record, stochastic_record
from rockstudy.motions.mavroeidis import mp_pulse_acceleration, mp_pulse_velocity
from rockstudy.motions.pulse_extraction import baker_indicator
from rockstudy.motions.wavelet_pulse import _db4, _kernel

DT = 0.005

# (T_p [s], A [m/s], gamma, nu [rad])
PULSES = [
    (0.4, 0.3, 2.2, 3.0),
    (0.6, 0.4, 2.0, 0.0),
    (1.0, 0.3, 3.0, 2.0),
    (1.5, 0.8, 1.8, 1.0),
    (2.0, 0.5, 1.3, 4.0),
    (3.0, 1.0, 2.5, math.pi / 2),
    (5.0, 0.6, 1.5, -0.5),
    (8.0, 1.0, 2.0, 0.3),
]


def _noise(duration, seed, corner, order=4):
    """Kanai-Tajimi noise under a Jennings envelope, high-passed (Butterworth) above ``corner``."""
    rec = stochastic_record(1.0, duration=duration, dt=DT, seed=seed)
    sos = signal.butter(order, corner, "highpass", fs=1 / DT, output="sos")
    return signal.sosfiltfilt(sos, rec.acceleration)


def _pulse_record(period, amplitude, gamma, phase, seed, noise_ratio=1.5):
    """Known pulse centred at 0.35 of the record plus noise whose peak acceleration is
    ``noise_ratio`` times the pulse's, kept above 2 / T_p (out of the pulse's own band: a pulse
    buried in noise of its own frequency cannot be told apart from it)."""
    duration = max(20.0, 6 * period)
    t = DT * np.arange(int(round(duration / DT)) + 1)
    pulse = mp_pulse_acceleration(t, amplitude, period, gamma, phase, 0.35 * duration)
    noise = _noise(duration, seed, 2.0 / period)
    noise *= noise_ratio * np.max(np.abs(pulse)) / np.max(np.abs(noise))
    return Record(pulse + noise, dt=DT)


def test_model_acceleration_is_the_derivative_of_the_velocity():
    t = np.linspace(0, 6, 60001)
    v = mp_pulse_velocity(t, 0.7, 1.3, 2.1, 0.4, 3.0)
    a = mp_pulse_acceleration(t, 0.7, 1.3, 2.1, 0.4, 3.0)
    np.testing.assert_allclose(integrate.cumulative_trapezoid(a, t, initial=0), v, atol=1e-7)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("period, amplitude, gamma, phase", PULSES)
def test_recovers_period_and_amplitude(period, amplitude, gamma, phase, seed):
    pulse = _pulse_record(period, amplitude, gamma, phase, seed).pulse(method="mavroeidis")
    assert pulse.period == pytest.approx(period, rel=0.05)
    assert pulse.amplitude == pytest.approx(amplitude, rel=0.10)
    assert pulse.pulse_like
    start = 0.35 * max(20.0, 6 * period) - 0.5 * gamma * period
    assert pulse.start == pytest.approx(start, abs=0.15 * period)


def test_noiseless_pulse_exactly():
    """Without noise the fit returns the pulse, up to the O(dt^2) of integrating the sampled
    acceleration into velocity."""
    pulse = _pulse_record(2.5, 0.9, 1.7, 1.2, seed=0, noise_ratio=0.0).pulse(method="mavroeidis")
    assert pulse.period == pytest.approx(2.5, rel=1e-4)
    assert pulse.amplitude == pytest.approx(0.9, rel=1e-4)
    assert pulse.gamma == pytest.approx(1.7, rel=1e-4)
    assert pulse.phase == pytest.approx(1.2, abs=1e-4)
    assert pulse.indicator == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_broadband_noise_alone_is_not_pulse_like(seed):
    """Noise with the low-frequency fall-off of real spectra (2nd-order high-pass at 0.3 Hz)."""
    acc = 3.0 * _noise(30.0, seed, 0.3, order=2)
    for method in ("wavelet", "mavroeidis"):
        assert not Record(acc, dt=DT).pulse(method).pulse_like


def test_baker_indicator_limits():
    assert baker_indicator(0.0, 0.0) == pytest.approx(1.0, abs=1e-9)
    assert baker_indicator(1.0, 1.0) < 1e-5
    # on Baker's (2007) boundary 14.6 x + 20.5 y = 23.3 the indicator is one half
    assert baker_indicator(0.5, (23.3 - 7.3) / 20.5) == pytest.approx(0.5)


def test_still_record_has_no_pulse():
    for method in ("wavelet", "mavroeidis"):
        pulse = Record(np.zeros(100), dt=0.01).pulse(method)
        assert pulse.amplitude == 0.0 and pulse.indicator == 0.0


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("method", ["wavelet", "mavroeidis"])
def test_white_noise_has_no_pulse_and_none_outside_the_record(seed, method):
    """Issue 26: white noise got T_p = 1325 s starting at -196 s with indicator 0.9998. A pulse
    outside the record or longer than it is not a pulse."""
    rec = Record(np.random.default_rng(seed).standard_normal(3000), dt=0.01)
    pulse = rec.pulse(method)
    assert pulse.period < rec.duration
    if method == "wavelet":
        assert not pulse.pulse_like
        assert 0.0 <= pulse.start < pulse.end <= rec.duration
    else:  # the M-P fit may call the random-walk velocity of white noise a pulse (docs)
        end = pulse.center + 0.5 * pulse.gamma * pulse.period
        assert pulse.indicator == 0.0 or (
            pulse.start >= -0.5 * pulse.period and end <= rec.duration + 0.5 * pulse.period
        )


def _db4_pulse_record(period, amplitude, dt, n, centre, noise):
    """A db4 wavelet of pseudo-period ``period`` in the velocity (amplitude = its peak) plus
    ``noise`` [m/s^2] in the acceleration; returns the record."""
    x, psi = _db4()
    import pywt

    scale = period * pywt.central_frequency("db4") / dt
    kernel = _kernel(scale, x, psi)
    v = np.zeros(n)
    i0 = int(centre / dt) - kernel.size // 2
    v[i0 : i0 + kernel.size] = amplitude * kernel / np.max(np.abs(kernel))
    acc = np.gradient(v, dt) + noise
    return Record(acc, dt=dt)


@pytest.mark.parametrize("period", [0.6, 1.0, 2.0, 3.5])
@pytest.mark.parametrize("kind", ["broadband", "low", "white"])
def test_wavelet_pulse_in_noise_is_recovered(period, kind):
    """A pure db4 wavelet in the velocity (its pseudo-period the truth) is found under
    broadband noise (Kanai-Tajimi, high-passed at 0.3 Hz, 2nd order: real spectra's fall-off),
    low-frequency noise (low-passed at 1 / T_p: noise in the pulse's own band) or white noise,
    each scaled so that its velocity peaks at 30 % of the pulse's."""
    dt, n = DT, int(30.0 / DT)
    rng = np.random.default_rng(7)
    if kind == "broadband":
        noise = _noise(30.0, 3, 0.3, order=2)[:n]
    elif kind == "low":
        sos = signal.butter(2, 1.0 / period, "lowpass", fs=1 / dt, output="sos")
        noise = signal.sosfiltfilt(sos, rng.standard_normal(n))
    else:
        noise = rng.standard_normal(n)
    noise_velocity = Record(noise, dt=dt).intensity_measures()["pgv"]
    noise *= 0.3 * 0.6 / noise_velocity
    pulse = _db4_pulse_record(period, 0.6, dt, n, 10.0, noise).pulse()
    # broadband noise peaks in velocity at 2-3 s, in the pulses' band: it moves the best scale
    # by up to 9 % (measured over 4 seeds x 4 periods); the others by up to 2 %
    assert pulse.period == pytest.approx(period, rel=0.10 if kind == "broadband" else 0.03)
    assert pulse.pulse_like
    assert pulse.start < 10.0 < pulse.end


def test_wavelet_pulse_without_noise_exactly():
    rec = _db4_pulse_record(1.3, 0.8, DT, 6000, 12.0, 0.0)
    pulse = rec.pulse()
    assert pulse.period == pytest.approx(1.3, rel=3e-3)
    assert pulse.indicator > 0.999
    assert pulse.amplitude == pytest.approx(0.8, rel=0.02)


def test_unknown_method_is_refused():
    with pytest.raises(ValueError, match="method"):
        Record(np.zeros(10), dt=0.01).pulse("baker")


def test_shared_records(records_dir):
    """The wavelet T_p of Jensen (RSN982) against its published value, and which records are
    pulse-like.

    Published: NGA-West2 (Shahi & Baker 2014) gives T_p = 3.16 s for RSN982, extracted in the
    orientation of the strongest pulse (rotated; Baker 2007 used fault-normal components). Our
    record is the 292 degree component as recorded, which carries a shorter pulse: the test
    can only check that its T_p lies below the rotated one and within a factor 2.5 of it,
    not the value. The two far records (Arcadia, El Centro 1940) are not pulse-like. Prints what
    each method finds."""
    found = {}
    for path in sorted(records_dir.glob("*.AT2")):
        found[path.stem] = Record.from_at2(path)
    found["elcentro_NS"] = Record.from_csv(records_dir / "elcentro_NS.dat")
    for name, rec in found.items():
        w, m = rec.pulse(), rec.pulse("mavroeidis")
        print(f"{name}: wavelet T_p={w.period:.2f} s PI={w.indicator:.3f}; M-P T_p={m.period:.2f}")
        assert 0.0 <= w.start < w.end <= rec.duration
    jensen = found["RSN982_NORTHR_JEN292"].pulse()
    assert jensen.pulse_like
    assert 3.16 / 2.5 < jensen.period < 3.16
    assert not found["RSN948_NORTHR_CAM009"].pulse().pulse_like
    assert not found["elcentro_NS"].pulse().pulse_like


@pytest.mark.parametrize("centre", [2.0, 4.0, 12.0])
def test_an_early_pulse_is_found_and_quiet_ground_around_the_record_changes_nothing(centre):
    """A long M-P pulse (T_p = 3 s) that arrives in the first seconds of a record, as in
    near-fault records, is found as well as a later one (T_p about 1.13 times the M-P period
    for gamma = 2, pulse-like); adding 15 s of ground at rest before and after the record
    (the same motion) leaves T_p and the indicator unchanged."""
    t = DT * np.arange(int(25.0 / DT) + 1)
    acc = mp_pulse_acceleration(t, 0.6, 3.0, 2.0, 0.0, centre)
    acc += 0.05 * np.max(np.abs(acc)) * _noise(25.0, 4, 0.5)[: t.size]
    quiet = np.zeros(int(15.0 / DT))
    found = Record(acc, dt=DT).pulse()
    padded = Record(np.concatenate([quiet, acc, quiet]), dt=DT).pulse()
    assert found.pulse_like and found.period == pytest.approx(1.13 * 3.0, rel=0.05)
    assert found.period == pytest.approx(padded.period, rel=1e-9)
    assert found.indicator == pytest.approx(padded.indicator, abs=0.02)
