"""Designs: the scenes a study runs, as an ``xarray.Dataset`` of inputs.

``sampling`` expands a study file into a Monte Carlo, Sobol', LHS or grid design
(:func:`~rockstudy.study.designs.sampling.make_design`); ``records`` runs record designs from
Python (cloud, multiple stripes, incremental dynamic analysis); ``record_rows`` lays a study
file's record design out as rows of the result cube, and folds the rows back.
"""

__all__: list[str] = []  # the modules are imported by name

# the record designs reserve the names of their variables in the measure registry when imported
# (rockstudy.motions.measures.reserve_names), whichever design module is imported first
from . import record_rows as _record_rows  # noqa: E402,F401
