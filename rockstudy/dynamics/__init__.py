"""Rocking solvers: event-driven numba kernels, the exact linearized solution, the scipy
reference, and the batch entry point used by studies."""

from .batch import simulate_batch
from .complex import ComplexFromRestWarning
from .result import RockingResult
from .simulate import simulate

__all__ = ["ComplexFromRestWarning", "RockingResult", "simulate", "simulate_batch"]
