"""The study layer: declarative TOML studies, samplers, dask execution and zarr result cubes.

Imports run one way: ``study`` uses the physics packages, never the reverse.
"""

from .records_designs import cloud, incremental_dynamic_analysis, multiple_stripes
from .records_fragility import ida_fragility, im_efficiency, stripe_fragility
from .risk_analysis import object_risk
from .runner import RunReport, run_study
from .sampling import make_design, salib_problem
from .spec import Study, StudyError, json_schema, load_study, validate_text
from .store import export_netcdf, open_result

__all__ = [
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
