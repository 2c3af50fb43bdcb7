"""The physics of the block on an isolated base, compiled for the numba kernel (private).

The equations are those of :mod:`rockstudy.dynamics.isolated`, numba functions there
(:func:`~rockstudy.dynamics.isolated.accelerations`, ``friction_demand``, ``impact_jump``);
this module adds the row's parameter vector, the right-hand side of the state
y = (x_b, x_b', theta, theta') and the regime decisions (uplift, stick or slide, settling)
the reference :mod:`rockstudy.dynamics.isolated_reference` takes in the same order.

A regime is (side, slide): side 0 (the block at rest on the base) or +-1 (rocking on that
pivot); slide +-1 (the base sliding that way; +1 for a linear isolator, where its sign is
immaterial) or 0 (a friction pendulum's base stuck to the ground).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..constants import FALL_ROTATION, G
from ..motions._kernels import KIND_RECORD, ground_acceleration
from ..structures.isolated import IsolatedBlock
from ._taylor import NO_REFCOUNT
from .constants import REST_FRACTION
from .isolated import IsolatedBody, accelerations, friction_demand, impact_jump

#: Indices of a row's parameter vector (:func:`row_parameters`).
P_R, P_ALPHA, P_M, P_OMEGA, P_ZETA, P_MU, P_ETA, P_HM, P_LIMIT, P_REST, P_P = range(11)
N_PARAMETERS = 11

_accelerations, _friction_demand, impact = accelerations, friction_demand, impact_jump


def row_parameters(structure: IsolatedBlock) -> np.ndarray:
    """The parameter vector of one :class:`IsolatedBlock` row: the body (R, alpha, M, omega_b,
    zeta_b, mu), the impact ratio eta and h / M, the uplift limit g tan(alpha), the rest speed
    of the reference (REST_FRACTION p alpha) and p."""
    body = IsolatedBody.of(structure)
    p = structure.block.frequency_parameter
    out = np.empty(N_PARAMETERS)
    out[:6] = body.core
    out[P_ETA] = structure.restitution
    out[P_HM] = body.radius * math.cos(body.slenderness) / body.mass
    out[P_LIMIT] = G * math.tan(body.slenderness)
    out[P_REST] = REST_FRACTION * p * body.slenderness
    out[P_P] = p
    return out


@njit(cache=True, **NO_REFCOUNT)
def ground(mot, t, k):
    """u_g''(t) [m/s^2] of the motion ``mot`` on record segment k, as
    :func:`~rockstudy.motions._kernels.ground_acceleration` gives it. A record's linear
    interpolation is written out here: that function counts references to the record's
    arrays at each call, ~14 calls per step, which cost about half a step (measured)."""
    kind, mp, times, samples = mot
    if kind != KIND_RECORD:
        return ground_acceleration(kind, mp, times, samples, t, k)
    if t < 0.0 or t > mp[3]:
        return 0.0
    w = (t - times[k]) / (times[k + 1] - times[k])
    return mp[0] * (samples[k] + w * (samples[k + 1] - samples[k]))


@njit(cache=True, **NO_REFCOUNT)
def rhs(t, y, par, mot, k, side, slide, out):
    """dy/dt of the state y = (x_b, x_b', theta, theta') into ``out``, under the motion
    ``mot`` = (kind, params, times, samples) on record segment k."""
    a_g = ground(mot, t, k)
    xdd, thdd = _accelerations(
        y[0], y[1], y[2], y[3], a_g, side, slide,
        par[P_R], par[P_ALPHA], par[P_M], par[P_OMEGA], par[P_ZETA], par[P_MU],
    )  # fmt: skip
    out[0], out[1], out[2], out[3] = y[1], xdd, y[3], thdd


@njit(cache=True, **NO_REFCOUNT)
def base_acceleration(x, xd, a_g, slide, par):
    """The base's absolute acceleration with the block at rest on it: the isolator's force
    while it slides (:func:`~rockstudy.dynamics.isolated.base_acceleration_at_rest`), the
    ground's while it sticks."""
    if slide == 0.0 and par[P_MU] > 0.0:
        return a_g
    w = par[P_OMEGA]
    return -(2.0 * par[P_ZETA] * w * xd + w * w * x + par[P_MU] * G * slide)


@njit(cache=True, **NO_REFCOUNT)
def lift_side(x, xd, a_g, slide, par):
    """The side a block at rest lifts onto (0: it stays), as
    :func:`~rockstudy.dynamics.isolated.uplift_side`."""
    a_b = base_acceleration(x, xd, a_g, slide, par)
    if a_b < -par[P_LIMIT]:
        return 1.0
    if a_b > par[P_LIMIT]:
        return -1.0
    return 0.0


@njit(cache=True, **NO_REFCOUNT)
def demand(y, a_g, side, par):
    """The friction a stuck base needs per unit isolated mass
    (:func:`~rockstudy.dynamics.isolated.friction_demand`)."""
    return _friction_demand(
        y[0], y[2], y[3], a_g, side, par[P_R], par[P_ALPHA], par[P_M], par[P_OMEGA]
    )


@njit(cache=True, **NO_REFCOUNT)
def slide_after_stop(y, a_g, side, par):
    """The base's regime when its velocity is 0 (y[1] = 0): stuck (0) while the friction it
    needs is at most mu g, else sliding in the direction of that need. A linear isolator
    slides on (+1)."""
    mu = par[P_MU]
    if mu == 0.0:
        return 1.0
    f = demand(y, a_g, side, par)
    if abs(f) <= mu * G:
        return 0.0
    return 1.0 if f > 0.0 else -1.0


@njit(cache=True, **NO_REFCOUNT)
def slide_after_jump(y, a_g, side, par):
    """The base's regime after its velocity jumped (an impact, a settling): sliding in the
    direction of x_b', or :func:`slide_after_stop` if it is 0."""
    if par[P_MU] == 0.0:
        return 1.0
    if y[1] != 0.0:
        return 1.0 if y[1] > 0.0 else -1.0
    return slide_after_stop(y, a_g, side, par)


@njit(cache=True, **NO_REFCOUNT)
def settled(y, slide, max_x, par):
    """Whether a block at rest after the motion, the base at (x_b, x_b'), can never lift
    again nor the base pass ``max_x``: the free isolator's energy (x_b'^2 + omega^2 x_b^2)/2
    does not grow (friction only takes energy), so ``|x_b|`` <= amp = sqrt(2 E) / omega
    and the base's acceleration <= omega^2 sqrt(1 + 4 zeta^2) amp + mu g. A stuck base with
    omega^2 ``|x_b|`` <= mu g never breaks away again."""
    w, zeta, mu = par[P_OMEGA], par[P_ZETA], par[P_MU]
    if slide == 0.0 and mu > 0.0:
        return w * w * abs(y[0]) <= mu * G
    amp = math.hypot(y[0], y[1] / w)
    accel = w * w * math.sqrt(1.0 + 4.0 * zeta * zeta) * amp + mu * G
    return amp <= max_x and accel < par[P_LIMIT]


#: ``|theta|`` at which the block has overturned [rad].
FALL = FALL_ROTATION
