"""Ground motions: analytic pulses, sampled records and stochastic synthesis."""

from .base import Motion
from .building import Building, floor_motion
from .mavroeidis import mp_pulse_acceleration, mp_pulse_velocity
from .measures import register_measure
from .pulse_extraction import VelocityPulse
from .pulses import PULSES, CosinePulse, HalfSinePulse, NoMotion, RickerWavelet, SinePulse
from .records import Record
from .stochastic import envelope_jennings, kanai_tajimi_filter, stochastic_record
from .suites import RECORD_SUFFIXES, load_suite
from .synthetic import synthetic_near_fault
from .wavelet_pulse import WaveletPulse

__all__ = [
    "Motion",
    "Building",
    "floor_motion",
    "PULSES",
    "SinePulse",
    "CosinePulse",
    "HalfSinePulse",
    "RickerWavelet",
    "NoMotion",
    "Record",
    "register_measure",
    "RECORD_SUFFIXES",
    "load_suite",
    "stochastic_record",
    "envelope_jennings",
    "kanai_tajimi_filter",
    "synthetic_near_fault",
    "VelocityPulse",
    "WaveletPulse",
    "mp_pulse_velocity",
    "mp_pulse_acceleration",
]
