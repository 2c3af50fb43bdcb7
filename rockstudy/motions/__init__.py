"""Ground motions: analytic pulses, sampled records and stochastic synthesis."""

from .base import Motion
from .pulses import PULSES, CosinePulse, HalfSinePulse, NoMotion, RickerWavelet, SinePulse
from .records import Record
from .stochastic import envelope_jennings, kanai_tajimi_filter, stochastic_record

__all__ = [
    "Motion",
    "PULSES",
    "SinePulse",
    "CosinePulse",
    "HalfSinePulse",
    "RickerWavelet",
    "NoMotion",
    "Record",
    "stochastic_record",
    "envelope_jennings",
    "kanai_tajimi_filter",
]
