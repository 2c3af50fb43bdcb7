"""Closed-form solutions of the linearized rocking block under a sine pulse (paper [000]).

All functions broadcast over numpy arrays. Notation of [000]: a = a_g / (g alpha) (> 1 for
uplift), omega = omega_g / p, eta the coefficient of restitution; time tau = p t is measured
from the uplift, which happens at the phase psi = arcsin(1/a) of the pulse (eq. 3.3, with
the erratum 1/a for 1/alpha).
"""

from .sine import (
    d0_star,
    first_impact_time_after_pulse,
    impact_velocity_after_pulse,
    max_rotation,
    pulse_end_time,
    sine_constants,
)

__all__ = [
    "sine_constants",
    "pulse_end_time",
    "d0_star",
    "first_impact_time_after_pulse",
    "impact_velocity_after_pulse",
    "max_rotation",
]
