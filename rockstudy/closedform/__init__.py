"""Closed-form solutions of the rocking block.

- :mod:`.sine`: the linearized block under a one-cycle sine pulse, paper [000] section 3-4:
  impact times and velocities, the overturning boundaries, the mode classifier, the
  max-rotation spectrum (4.13) and the restitution scaling law (4.14)-(4.16).
- :mod:`.boundary`: the boundary curves of [000] Fig. 4 as roots of those residuals.
- :mod:`.free`: free-rocking period (24) and time to overturn under constant acceleration (25)
  of paper [003].
"""

from .boundary import overturning_boundary
from .free import free_rocking_period, overturning_time_constant_acceleration
from .sine import (
    MODES,
    case2_residual,
    case11_residual,
    case11_residual_approx,
    case12_residual,
    d0_star,
    first_impact_time_after_pulse,
    first_impact_time_during_pulse,
    first_impact_time_during_pulse_approx,
    impact_velocity_after_pulse,
    impact_velocity_during_pulse,
    kappa,
    lambda_,
    limit_residual,
    max_rotation,
    max_rotation_small,
    overturning_mode,
    overturning_mode_code,
    pulse_end_time,
    restitution_scaling_function,
)

__all__ = [
    "MODES",
    "case2_residual",
    "case11_residual",
    "case11_residual_approx",
    "case12_residual",
    "d0_star",
    "first_impact_time_after_pulse",
    "first_impact_time_during_pulse",
    "first_impact_time_during_pulse_approx",
    "free_rocking_period",
    "impact_velocity_after_pulse",
    "impact_velocity_during_pulse",
    "kappa",
    "lambda_",
    "limit_residual",
    "max_rotation",
    "max_rotation_small",
    "overturning_boundary",
    "overturning_mode",
    "overturning_mode_code",
    "overturning_time_constant_acceleration",
    "pulse_end_time",
    "restitution_scaling_function",
]
