"""Analyses of result cubes.

``sampled`` analyses a sampled study's cube (Sobol' indices, fragility, the collapse onto the
dimensionless groups); ``record_fragility`` fits the fragility of record designs and ranks
intensity measures; ``record_similarity`` checks whether block sizes collapse on records;
``fragility_fit`` holds the lognormal fits and bands they share; ``risk`` turns each named
object's fragility and a site's hazard curve into its annual rate of overturning; ``sliding``
fits the fragility of sliding P(max_slide > d) of designs under the contact model, its annual
rate, and the ratio of the annual rates of overturning of the contact and rocking-only models;
``states`` fits the fragility of each damage state short of overturning and its annual rate;
``nested_fit`` fits nested slide limits and damage states with one beta and ordered medians,
so that their curves never cross.
"""

from .sampled import (
    ROTATION_OUTPUTS,
    UnexplainedShare,
    collapse_metric,
    first_order_given_data,
    fragility,
    fragility_curve,
    sobol_convergence,
    sobol_indices,
    study_of,
    unexplained_share,
)

__all__ = [
    "ROTATION_OUTPUTS",
    "UnexplainedShare",
    "collapse_metric",
    "first_order_given_data",
    "fragility",
    "fragility_curve",
    "sobol_convergence",
    "sobol_indices",
    "study_of",
    "unexplained_share",
]
