"""rockstudy: rocking structures in earthquakes.

Housner's rocking block, its linearization and closed forms (Dimitrakopoulos & DeJong 2012),
the single-ODE formulation (Prieto & Lourenco 2005), dynamically equivalent structures
(DeJong & Dimitrakopoulos 2014), and parametric studies on top.

The subpackages and the solvers are imported on first use (PEP 562 module ``__getattr__``):
``import rockstudy`` loads neither numba nor scipy, ``rockstudy.simulate`` does;
``rockstudy.study`` loads the study layer and registers the ``ds.rocking`` accessor of xarray.
The numba kernels are compiled once per install by ``rockstudy compile`` (``make setup`` runs
it).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from ._validate import NotANumberError
from .warnings import (
    AccuracyWarning,
    ClosedFormValidityWarning,
    ComplexAccuracyWarning,
    ComplexFromRestWarning,
    ContactWarning,
    EquivalentBlockWarning,
    IncompleteReferenceWarning,
    LinearizationWarning,
    LooseToleranceWarning,
    SeparationWarning,
    UnitsWarning,
    UpliftWarning,
)

if TYPE_CHECKING:  # what the lazy names below resolve to, for type checkers and IDEs
    from . import closedform, motions, risk, similarity, structures
    from .dynamics import RockingResult, StepLimitError, simulate, simulate_batch
    from .motions.records import UnitsError
    from .structures import Block, IsolatedBlock, StackedBlocks
    from .study.running.runner import FailedSamplesError, ResourceError, SchedulerError
    from .study.running.store import DamagedCube, StoreError
    from .study.spec.ida_options import IdaOptionError
    from .study.spec.schema import StudyError
    from .study.spec.structures import FieldError, FieldErrors

__version__ = "0.1.0"

#: Public name -> (module, attribute or None for the module itself), imported on first use.
_LAZY = {
    "Block": (".structures", "Block"),
    "StackedBlocks": (".structures", "StackedBlocks"),
    "IsolatedBlock": (".structures", "IsolatedBlock"),
    "RockingResult": (".dynamics", "RockingResult"),
    "simulate": (".dynamics", "simulate"),
    "simulate_batch": (".dynamics", "simulate_batch"),
    "StepLimitError": (".dynamics", "StepLimitError"),
    "closedform": (".closedform", None),
    "motions": (".motions", None),
    "risk": (".risk", None),
    "similarity": (".similarity", None),
    "UnitsError": (".motions.records", "UnitsError"),
    # the study layer's errors, each where it is raised (loading the study layer on first use)
    "StudyError": (".study.spec.schema", "StudyError"),
    "FieldError": (".study.spec.structures", "FieldError"),
    "FieldErrors": (".study.spec.structures", "FieldErrors"),
    "IdaOptionError": (".study.spec.ida_options", "IdaOptionError"),
    "StoreError": (".study.running.store", "StoreError"),
    "DamagedCube": (".study.running.store", "DamagedCube"),
    "SchedulerError": (".study.running.runner", "SchedulerError"),
    "ResourceError": (".study.running.runner", "ResourceError"),
    "FailedSamplesError": (".study.running.runner", "FailedSamplesError"),
    "structures": (".structures", None),
    # the study layer (xarray, dask, pydantic, scipy): on first use of ``rockstudy.study``,
    # which also registers the ``ds.rocking`` accessor of xarray Datasets
    "study": (".study", None),
}

__all__ = [
    "AccuracyWarning",
    "Block",
    "ClosedFormValidityWarning",
    "ComplexAccuracyWarning",
    "ComplexFromRestWarning",
    "ContactWarning",
    "EquivalentBlockWarning",
    "LinearizationWarning",
    "LooseToleranceWarning",
    "IncompleteReferenceWarning",
    "IsolatedBlock",
    "RockingResult",
    "SeparationWarning",
    "StackedBlocks",
    "UnitsWarning",
    "UpliftWarning",
    "StepLimitError",
    "UnitsError",
    "NotANumberError",
    "StudyError",
    "FieldError",
    "FieldErrors",
    "IdaOptionError",
    "StoreError",
    "DamagedCube",
    "SchedulerError",
    "ResourceError",
    "FailedSamplesError",
    "closedform",
    "motions",
    "risk",
    "similarity",
    "simulate",
    "simulate_batch",
    "structures",
    "warnings",
    "__version__",
]


def __getattr__(name: str):
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = importlib.import_module(module, __name__)
    if attr is not None:
        value = getattr(value, attr)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
