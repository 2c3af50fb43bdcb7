"""Pulse extraction on synthetic records of known pulse (Mavroeidis-Papageorgiou 2003) plus
broadband stochastic noise, and a look at the shared real records."""

import math

import numpy as np
import pytest
from scipy import integrate, signal

from rockstudy.motions import Record, stochastic_record
from rockstudy.motions.mavroeidis import mp_pulse_acceleration, mp_pulse_velocity
from rockstudy.motions.pulse_extraction import baker_indicator

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
    pulse = _pulse_record(period, amplitude, gamma, phase, seed).pulse()
    assert pulse.period == pytest.approx(period, rel=0.05)
    assert pulse.amplitude == pytest.approx(amplitude, rel=0.10)
    assert pulse.pulse_like
    start = 0.35 * max(20.0, 6 * period) - 0.5 * gamma * period
    assert pulse.start == pytest.approx(start, abs=0.15 * period)


def test_noiseless_pulse_exactly():
    """Without noise the fit returns the pulse, up to the O(dt^2) of integrating the sampled
    acceleration into velocity."""
    pulse = _pulse_record(2.5, 0.9, 1.7, 1.2, seed=0, noise_ratio=0.0).pulse()
    assert pulse.period == pytest.approx(2.5, rel=1e-4)
    assert pulse.amplitude == pytest.approx(0.9, rel=1e-4)
    assert pulse.gamma == pytest.approx(1.7, rel=1e-4)
    assert pulse.phase == pytest.approx(1.2, abs=1e-4)
    assert pulse.indicator == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_broadband_noise_alone_is_not_pulse_like(seed):
    """Noise with the low-frequency fall-off of real spectra (2nd-order high-pass at 0.3 Hz)."""
    acc = 3.0 * _noise(30.0, seed, 0.3, order=2)
    assert not Record(acc, dt=DT).pulse().pulse_like


def test_baker_indicator_limits():
    assert baker_indicator(0.0, 0.0) == pytest.approx(1.0, abs=1e-9)
    assert baker_indicator(1.0, 1.0) < 1e-5
    # on Baker's (2007) boundary 14.6 x + 20.5 y = 23.3 the indicator is one half
    assert baker_indicator(0.5, (23.3 - 7.3) / 20.5) == pytest.approx(0.5)


def test_still_record_has_no_pulse():
    pulse = Record(np.zeros(100), dt=0.01).pulse()
    assert pulse.amplitude == 0.0 and pulse.indicator == 0.0


def test_shared_records(records_dir):
    """Prints what the fit finds. The records' README names Jensen, Gazli and El Centro #8 as
    near-fault records with distinct pulses; the two Northridge/Imperial Valley far records
    (Arcadia, El Centro 1940) are not pulse-like."""
    found = {}
    for path in sorted(records_dir.glob("*.AT2")):
        found[path.stem] = Record.from_at2(path).pulse()
    found["elcentro_NS"] = Record.from_csv(records_dir / "elcentro_NS.dat").pulse()
    for name, p in found.items():
        print(
            f"{name}: T_p={p.period:.2f} s A={p.amplitude:.3f} m/s gamma={p.gamma:.2f} "
            f"start={p.start:.2f} s indicator={p.indicator:.3f}"
        )
    assert found["RSN982_NORTHR_JEN292"].pulse_like
    assert found["RSN126_GAZLI_GAZ000"].pulse_like
    assert not found["RSN948_NORTHR_CAM009"].pulse_like
    assert not found["elcentro_NS"].pulse_like
