"""Linear buildings and the motion of their floors: what an object standing on a floor feels.

A :class:`Building` is given by its modes (periods, mode shapes at the floors, participation
factors and damping ratios) or built as a uniform shear building
(:meth:`Building.uniform_shear`). :func:`floor_motion` returns the absolute acceleration of one
floor under a record, as a :class:`~rockstudy.motions.Record` on the record's own samples:

.. math:: \\ddot u_k(t) = \\ddot u_g(t) + \\sum_j \\Gamma_j \\phi_{jk} \\ddot q_j(t),

where q_j is the relative displacement of mode j's linear oscillator,
q_j'' + 2 zeta_j omega_j q_j' + omega_j^2 q_j = -u_g'', started at rest. Each oscillator is
advanced from sample to sample by the exact recursion for a piecewise-linear excitation that
the response spectrum uses (:func:`rockstudy.motions._spectrum.step_coefficients`), so the
floor motion is exact at the samples for the linearly interpolated record (no ODE solver).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import _validate
from . import intensity
from ._spectrum import _advance, step_coefficients
from .records import Record

__all__ = ["Building", "MAX_STOREYS", "floor_motion", "ground_record", "with_ground"]

#: Most storeys of :meth:`Building.uniform_shear` (and floors of a modal building).
MAX_STOREYS = 1000


def _modal_arrays(periods, mode_shapes, participation, damping) -> tuple:
    """The four modal fields as float arrays of matching sizes, or a ValueError naming the
    field: periods >= :data:`rockstudy.motions.intensity.MIN_PERIOD` s, one row of
    ``mode_shapes`` per mode (its value at floors 1..n), one participation factor per mode and
    a damping ratio in [0, 1) per mode (or one for all)."""
    low = intensity.MIN_PERIOD
    periods = _validate.real_array("periods", periods, low, math.inf, f"finite and >= {low:g} s")
    if periods.ndim != 1:
        raise ValueError(f"periods must be a list, one period [s] per mode, got {periods.ndim}-D")
    n = periods.size
    shapes = _validate.real_array("mode_shapes", mode_shapes)
    if shapes.ndim != 2 or shapes.shape[0] != n or not 1 <= shapes.shape[1] <= MAX_STOREYS:
        raise ValueError(
            f"mode_shapes must hold one row per mode ({n}), each the mode's value at floors "
            f"1..n (1 <= n <= {MAX_STOREYS}), got an array of shape {shapes.shape}"
        )
    gamma = _validate.real_array("participation", participation)
    if gamma.shape != (n,):
        raise ValueError(
            f"participation must hold one factor per mode ({n}), got shape {gamma.shape}"
        )
    zeta = _validate.real_array("damping", damping, 0.0, math.nextafter(1.0, 0.0), "in [0, 1)")
    if zeta.ndim == 0 or zeta.shape == (1,):
        zeta = np.full(n, float(zeta.flat[0]))
    if zeta.shape != (n,):
        raise ValueError(f"damping must be one ratio or one per mode ({n}), got shape {zeta.shape}")
    return periods, shapes, gamma, zeta


def _frozen(arr: np.ndarray) -> np.ndarray:
    arr = np.array(arr, dtype=float)
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, eq=False)
class Building:
    """A linear building by its modes, seen at its floors (numbered 1..n from the ground).

    Parameters
    ----------
    periods : array_like
        Period T_j [s] of each mode, >= 1e-12 s.
    mode_shapes : array_like
        Shape (modes, floors): row j is mode j's value phi_jk at floors k = 1..n.
    participation : array_like
        Participation factor Gamma_j of each mode (phi_j^T M 1 / phi_j^T M phi_j for the mass
        matrix M), in the normalisation of ``mode_shapes``: only Gamma_j phi_jk matters.
    damping : float or array_like
        Damping ratio zeta_j of each mode in [0, 1), or one for all.

    Raises
    ------
    ValueError
        Naming the field that is not numbers, not finite, out of range or of the wrong size.
    """

    periods: np.ndarray
    mode_shapes: np.ndarray
    participation: np.ndarray
    damping: np.ndarray

    def __post_init__(self):
        arrays = _modal_arrays(self.periods, self.mode_shapes, self.participation, self.damping)
        names = ("periods", "mode_shapes", "participation", "damping")
        for name, arr in zip(names, arrays, strict=True):
            object.__setattr__(self, name, _frozen(arr))

    @property
    def n_floors(self) -> int:
        """Floors above the ground (the columns of ``mode_shapes``)."""
        return int(self.mode_shapes.shape[1])

    @property
    def n_modes(self) -> int:
        """Modes of the building."""
        return int(self.periods.size)

    def floor_factors(self, floor: int) -> np.ndarray:
        """Gamma_j phi_jk of every mode j at ``floor`` k (1..n): the weight of mode j's
        relative acceleration in the floor's absolute acceleration."""
        floor = _validate.count("floor", floor, 1, self.n_floors)
        return self.participation * self.mode_shapes[:, floor - 1]

    @classmethod
    def uniform_shear(cls, n_storeys: int, period: float, damping: float) -> Building:
        """A shear building of ``n_storeys`` equal storey masses m and stiffnesses k.

        The modes are those of K phi = omega^2 M phi (M = m I; K tridiagonal, 2k on the
        diagonal but k at the roof, -k beside it), with k / m set so that the first period is
        ``period`` [s]; each mode shape is 1 at the roof, and Gamma_j = phi_j^T M 1 /
        phi_j^T M phi_j. Every mode is kept, with the damping ratio ``damping`` in [0, 1).
        """
        n = _validate.count("n_storeys", n_storeys, 1, MAX_STOREYS)
        period = _validate.positive("period", period)
        omega2, shapes = _shear_modes(n)
        periods = period * math.sqrt(omega2[0]) / np.sqrt(omega2)
        shapes = shapes / shapes[:, -1:]
        gamma = shapes.sum(axis=1) / np.einsum("jk,jk->j", shapes, shapes)
        return cls(periods, shapes, gamma, intensity.check_damping(damping))


def _shear_modes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues omega^2 (ascending) and mode shapes (one row each) of the uniform shear
    chain of n unit masses and unit storey stiffnesses, fixed at the ground."""
    from scipy.linalg import eigh_tridiagonal

    diagonal = np.full(n, 2.0)
    diagonal[-1] = 1.0
    omega2, vectors = eigh_tridiagonal(diagonal, np.full(n - 1, -1.0))
    return omega2, vectors.T


@njit(cache=True)
def _mode_coefficients(omegas, zetas, h, q):
    """q[j]: the 8 coefficients of one exact step of length h of mode j's oscillator."""
    for j in range(omegas.shape[0]):
        q[j] = step_coefficients(omegas[j], zetas[j], h)


@njit(cache=True)
def _modal_acceleration(omegas, zetas, factors, steps, acc):
    """sum_j factors_j q_j'' at every sample, q_j the oscillator q'' + 2 zeta_j omega_j q' +
    omega_j^2 q = -acc started at rest, advanced by the exact piecewise-linear recursion
    (:func:`~rockstudy.motions._spectrum.step_coefficients`) over ``steps`` [s]; the
    coefficients are computed again only where the step changes (a uniform record's steps
    are exactly equal: :func:`rockstudy.motions.intensity._steps`)."""
    m, n = omegas.shape[0], acc.shape[0]
    q = np.empty((m, 8))
    u, v = np.zeros(m), np.zeros(m)
    out = np.empty(n)
    out[0] = -acc[0] * np.sum(factors)
    h = -1.0
    for i in range(n - 1):
        if steps[i] != h:
            h = steps[i]
            _mode_coefficients(omegas, zetas, h, q)
        f0, f1 = -acc[i], -acc[i + 1]
        total = 0.0
        for j in range(m):
            w = omegas[j]
            u[j], v[j] = _advance(q[j], u[j], v[j], f0, f1)
            total += factors[j] * (f1 - 2.0 * zetas[j] * w * v[j] - w * w * u[j])
        out[i + 1] = total
    return out


def _check_phase_steps(periods, steps) -> None:
    """ValueError naming ``building.periods`` where omega dt < MIN_PHASE_STEP: the recursion's
    coefficients lose their digits there (as for the spectrum)."""
    longest = 2.0 * math.pi * float(np.min(steps)) / intensity.MIN_PHASE_STEP
    if np.any(periods > longest):
        raise ValueError(
            f"building.periods: T = {float(np.max(periods)):.6g} s is too long for this "
            f"record's step; floor motions are computed for T <= 2 pi dt / "
            f"{intensity.MIN_PHASE_STEP} = {longest:.6g} s"
        )


def floor_motion(record: Record, building: Building, floor: int) -> Record:
    """The absolute acceleration of a floor of a linear building under a ground record.

    Parameters
    ----------
    record : Record
        The ground motion (its horizontal component drives the building).
    building : Building
        The building, by its modes (:class:`Building`).
    floor : int
        0 (the ground: the record itself is returned) to ``building.n_floors``.

    Returns
    -------
    Record
        u_g'' + sum_j Gamma_j phi_j(floor) q_j'' on the record's own samples, exact for the
        linearly interpolated record, named ``"<name> (floor k)"``, with ``metadata``
        ``building``, ``floor`` and ``ground`` (the ground record itself: the record whose
        intensity measures a design reports, :func:`ground_record`), over the record's own.
        A vertical component is kept as it is: the building is taken as rigid vertically.
        A second horizontal component (``acceleration_y``) is filtered by the same modes (a
        building whose modes are the same in both directions); for other modes along y,
        give each direction its own building:
        ``floor_motion(record.oriented(psi), building_psi, floor)``.

    Raises
    ------
    TypeError
        If ``record`` is not a Record or ``building`` not a Building.
    ValueError
        Naming ``floor`` outside 0..n, or ``building.periods`` too long for the record's step.
    """
    if not isinstance(record, Record):
        raise TypeError(f"record must be a Record, got {type(record).__name__}")
    if not isinstance(building, Building):
        raise TypeError(f"building must be a Building, got {type(building).__name__}")
    floor = _validate.count("floor", floor, 0, building.n_floors)
    if floor == 0:
        return record
    steps = np.array(intensity._steps(record.time), dtype=float)
    _check_phase_steps(building.periods, steps)
    factors = building.floor_factors(floor)
    omegas, zetas = 2.0 * math.pi / building.periods, np.array(building.damping)

    def at_floor(ground):
        return ground + _modal_acceleration(omegas, zetas, factors, steps, np.array(ground))

    return Record(
        at_floor(record.acceleration),
        time=record.time,
        name=f"{record.name} (floor {floor})",
        vertical=record.vertical,
        metadata={**record.metadata, "building": building, "floor": floor, "ground": record},
        acceleration_y=None if record.acceleration_y is None else at_floor(record.acceleration_y),
    )


def ground_record(record: Record) -> Record:
    """The ground record of a motion: ``metadata["ground"]`` of a floor motion
    (:func:`floor_motion`, :func:`with_ground`), else the record itself.

    A building is linear, so scaling the ground record by s scales its floor motions by s: a
    design on floor motions can scale, measure and report intensities in the ground record's
    measures (those of the site's hazard curve) while the object feels the floor motion.
    """
    ground = record.metadata.get("ground")
    return ground if isinstance(ground, Record) else record


def with_ground(motion: Record, ground: Record) -> Record:
    """``motion`` (a floor motion, or a component of a pair: :meth:`Record.oriented`) with
    ``ground`` as its ground record (``metadata["ground"]``; see :func:`ground_record`)."""
    if not isinstance(ground, Record):
        raise TypeError(f"ground must be a Record, got {type(ground).__name__}")
    return motion._replace(metadata={**motion.metadata, "ground": ground})
