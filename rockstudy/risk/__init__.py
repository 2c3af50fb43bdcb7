"""Seismic risk of overturning: site hazard curves and the mean annual rate of overturning.

A fragility (the probability of overturning given an intensity measure x, lognormal with
median theta and dispersion beta) meets the site's hazard curve lambda(x), the mean annual
rate of exceeding x, in the total-probability integral of Cornell et al. (2002):

.. math:: \\lambda_{OT} = \\int_0^\\infty P(OT \\mid x) \\, |d\\lambda(x)|

and the probability of at least one overturning in t years is 1 - exp(-lambda_OT t)
(Poisson occurrences). Everything here is plain numpy and scipy: a physics-layer package, of
the hazard curves (:mod:`.curves`) and their units (:mod:`.units`), the files they are read from
(:mod:`.readers`) and the integral (:mod:`.integral`).
"""

from .curves import IMPOSSIBLE_LEVELS, RECORD_RATES, HazardCurve, suite_off_curve
from .integral import MAX_DISPERSION, MAX_YEARS, annual_rate, probability_in, rate_deaggregation
from .readers import OPENQUAKE_IMTS
from .units import UNIT_FACTORS

__all__ = [
    "IMPOSSIBLE_LEVELS",
    "MAX_DISPERSION",
    "MAX_YEARS",
    "OPENQUAKE_IMTS",
    "RECORD_RATES",
    "UNIT_FACTORS",
    "HazardCurve",
    "annual_rate",
    "probability_in",
    "rate_deaggregation",
    "suite_off_curve",
]
