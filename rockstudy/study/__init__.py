"""The study layer: declarative TOML studies, samplers, dask execution and zarr result cubes.

Imports run one way: ``study`` uses the physics packages, never the reverse. Importing it
registers the ``rocking`` accessor of :class:`xarray.Dataset`
(:class:`~rockstudy.study.analysis.accessor.RockingAccessor`): ``ds.rocking.fragility()``.
"""

from .analysis.accessor import RockingAccessor
from .analysis.record_fragility import ida_fragility, im_efficiency, stripe_fragility
from .analysis.risk import object_risk
from .designs.records import cloud, incremental_dynamic_analysis, multiple_stripes
from .designs.sampling import make_design
from .running.runner import (
    FailedSamplesError,
    ResourceError,
    RunReport,
    SchedulerError,
    run_study,
)
from .running.store import DamagedCube, StoreError, export_netcdf, open_result
from .spec.ida_options import IdaOptionError
from .spec.samplers import salib_problem
from .spec.schema import Study, StudyError, json_schema, load_study, validate_text
from .spec.structures import FieldError, FieldErrors

__all__ = [
    "DamagedCube",
    "FailedSamplesError",
    "FieldError",
    "FieldErrors",
    "IdaOptionError",
    "ResourceError",
    "RockingAccessor",
    "SchedulerError",
    "StoreError",
    "RunReport",
    "cloud",
    "ida_fragility",
    "im_efficiency",
    "incremental_dynamic_analysis",
    "multiple_stripes",
    "object_risk",
    "stripe_fragility",
    "Study",
    "StudyError",
    "export_netcdf",
    "json_schema",
    "load_study",
    "make_design",
    "open_result",
    "run_study",
    "salib_problem",
    "validate_text",
]
