"""Rocking solvers: event-driven numba kernels, the exact linearized solution, the scipy
reference, and the batch entry point used by studies."""

from .._warnings import ComplexFromRestWarning
from .batch import simulate_batch
from .methods import MAX_STEPS, METHODS, StepLimitError
from .result import RockingResult
from .simulate import simulate

__all__ = [
    "MAX_STEPS",
    "METHODS",
    "ComplexFromRestWarning",
    "RockingResult",
    "StepLimitError",
    "simulate",
    "simulate_batch",
]
