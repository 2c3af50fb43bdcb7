"""rockstudy: rocking structures in earthquakes.

Housner's rocking block, its linearization and closed forms (Dimitrakopoulos & DeJong 2012),
the single-ODE formulation (Prieto & Lourenco 2005), dynamically equivalent structures
(DeJong & Dimitrakopoulos 2014), and parametric studies on top.
"""

from . import closedform, motions, similarity, structures
from ._warnings import (
    AccuracyWarning,
    ClosedFormValidityWarning,
    ComplexAccuracyWarning,
    ComplexFromRestWarning,
    EquivalentBlockWarning,
    LinearizationWarning,
    LooseToleranceWarning,
)
from .dynamics import RockingResult, simulate, simulate_batch
from .structures import Block

__version__ = "0.1.0"

__all__ = [
    "AccuracyWarning",
    "Block",
    "ClosedFormValidityWarning",
    "ComplexAccuracyWarning",
    "ComplexFromRestWarning",
    "EquivalentBlockWarning",
    "LinearizationWarning",
    "LooseToleranceWarning",
    "RockingResult",
    "closedform",
    "motions",
    "similarity",
    "simulate",
    "simulate_batch",
    "structures",
    "__version__",
]
