"""Dimensionless-orientationless groups of the rocking block and the transforms to and from them.

Paper [000], sections 4-6. For a block (p, alpha, eta) under a pulse (a_g, omega_g = 2 pi / T_p):

=========  ======================================  ==========================================
law        response                                 arguments
=========  ======================================  ==========================================
``4.10``   theta / alpha                            omega_g / p, a_g / (g alpha), p t, eta
``4.11``   theta g / a_g                            omega_g / p, g alpha / a_g, p t, eta
``5.3``    theta g / a_g                            omega_g / p, g tan(alpha) / a_g, cos alpha, eta
``6.1``    theta g / (a_g cos alpha)                omega_g / p, g tan(alpha) / a_g, eta
=========  ======================================  ==========================================

The linearized response is exactly self-similar in (4.10) and (4.11); the nonlinear response of
non-slender blocks only in (5.3), approximately in (6.1).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from . import _validate
from .constants import G
from .motions.pulses import PULSES, RickerWavelet
from .motions.records import Record
from .structures.block import Block, block_parameters
from .structures.block import uplift_acceleration as _uplift_acceleration

__all__ = [
    "LAWS",
    "Law",
    "block_for",
    "from_groups",
    "groups",
    "pulse_for",
    "record_groups",
    "rotation_scale",
    "to_groups",
    "uplift_acceleration",
]

Law = Literal["4.10", "4.11", "5.3", "6.1"]
LAWS = ("4.10", "4.11", "5.3", "6.1")


def _law(law):
    if law not in LAWS:
        raise ValueError(f"law must be one of {LAWS}, got {law!r}")
    return law


def _pulse_scales(pulse):
    try:
        return abs(float(pulse.amplitude)), 2.0 * math.pi / float(pulse.period)
    except AttributeError:
        raise TypeError(
            "the dimensionless groups need a pulse with an amplitude and a period "
            f"(SinePulse, CosinePulse, HalfSinePulse, RickerWavelet); got {type(pulse).__name__}"
        ) from None


def _block(structure):
    return block_parameters(structure)


def groups(structure, pulse) -> dict:
    """All dimensionless-orientationless groups of a block under a pulse.

    Returns
    -------
    dict
        ``omega`` = omega_g / p (3.6); ``a`` = a_g / (g alpha) (3.6, 4.10);
        ``inverse_a`` = g alpha / a_g (4.11); ``uplift_ratio`` = a_up / a_g (5.3, 6.1), with
        a_up the uplift acceleration (:func:`uplift_acceleration`: g tan(alpha) of a block,
        g lambda of another structure, eq. 10 of [003]);
        ``cos_alpha`` (5.3); ``eta``; and the scales ``p`` [rad/s] (tau = p t) and
        ``alpha`` [rad].
    """
    p, alpha, eta = _block(structure)
    a_g, w_g = _pulse_scales(pulse)
    return {
        "omega": w_g / p,
        "a": a_g / (G * alpha),
        "inverse_a": G * alpha / a_g,
        "uplift_ratio": uplift_acceleration(structure) / a_g,
        "cos_alpha": math.cos(alpha),
        "eta": eta,
        "p": p,
        "alpha": alpha,
    }


def rotation_scale(structure, pulse, law: Law = "4.11") -> float:
    """The rotation that the response of ``law`` divides theta by [rad].

    alpha (4.10); a_g / g (4.11, 5.3); a_g cos(alpha) / g (6.1).
    """
    _law(law)
    p, alpha, eta = _block(structure)
    a_g, _ = _pulse_scales(pulse)
    if law == "4.10":
        return alpha
    if law == "6.1":
        return a_g * math.cos(alpha) / G
    return a_g / G


def to_groups(t, theta, structure, pulse, law: Law = "4.11"):
    """Transform a response (a history or a peak) into the groups of ``law``.

    Parameters
    ----------
    t : array_like or None
        Times [s] (None for a peak).
    theta : array_like
        Rotations [rad].

    Returns
    -------
    (tau, response)
        tau = p t (None if t is None) and theta divided by :func:`rotation_scale`.
    """
    scale = rotation_scale(structure, pulse, law)
    p = _block(structure)[0]
    tau = None if t is None else p * np.asarray(t, dtype=float)
    return tau, np.asarray(theta, dtype=float) / scale


def from_groups(tau, response, structure, pulse, law: Law = "4.11"):
    """Inverse of :func:`to_groups`: (t [s], theta [rad]) of this structure and pulse."""
    scale = rotation_scale(structure, pulse, law)
    p = _block(structure)[0]
    t = None if tau is None else np.asarray(tau, dtype=float) / p
    return t, np.asarray(response, dtype=float) * scale


def _ratio_name(law):
    return "a" if law == "4.10" else "inverse_a" if law == "4.11" else "uplift_ratio"


def pulse_for(
    structure,
    omega: float,
    ratio: float,
    law: Law = "4.11",
    shape: str = "sine",
    sign: float = 1.0,
    **kwargs,
):
    """The pulse that gives ``structure`` the groups (omega, ratio) of ``law``.

    Parameters
    ----------
    omega : float
        omega_g / p > 0.
    ratio : float
        The slenderness group of the law: a = a_g / (g alpha) for 4.10, g alpha / a_g for 4.11,
        a_up / a_g for 5.3 and 6.1 (:func:`uplift_acceleration`: g tan(alpha) of a block);
        > 0.
    shape : {"sine", "cosine", "half-sine", "ricker"}
    sign : float
        +1 or -1: the direction of the pulse.
    kwargs
        Passed to the pulse (e.g. ``cycles``).
    """
    _law(law)
    omega = _validate.positive("omega", omega)
    ratio = _validate.positive("ratio", ratio)
    if shape not in PULSES:
        raise ValueError(f"shape must be one of {sorted(PULSES)}, got {shape!r}")
    p, alpha, _ = _block(structure)
    if law == "4.10":
        a_g = ratio * G * alpha
    elif law == "4.11":
        a_g = G * alpha / ratio
    else:
        a_g = uplift_acceleration(structure) / ratio
    period = 2.0 * math.pi / (omega * p)
    cls = PULSES[shape]
    if cls is RickerWavelet:
        return cls(math.copysign(a_g, sign), period)
    return cls(math.copysign(a_g, sign), period, **kwargs)


def block_for(pulse, omega: float, ratio: float, law: Law = "4.11", restitution=None) -> Block:
    """The block that has the groups (omega, ratio) of ``law`` under ``pulse``.

    omega fixes p, hence R = 3 g / (4 p^2); ratio fixes alpha (for 4.10 and 4.11) or
    tan(alpha) (5.3 and 6.1). ``restitution`` None gives Housner's (2.4), which differs between
    blocks of different alpha: pass eta to keep all the groups equal.
    """
    _law(law)
    omega = _validate.positive("omega", omega)
    ratio = _validate.positive("ratio", ratio)
    a_g, w_g = _pulse_scales(pulse)
    p = w_g / omega
    R = 3.0 * G / (4.0 * p * p)
    if law == "4.10":
        alpha = a_g / (G * ratio)
    elif law == "4.11":
        alpha = ratio * a_g / G
    else:
        alpha = math.atan(ratio * a_g / G)
    if not 0.0 < alpha < math.pi / 2:
        raise ValueError(f"ratio gives a slenderness {alpha!r} outside (0, pi/2)")
    return Block(R, alpha, restitution)


def uplift_acceleration(structure) -> float:
    """Ground acceleration that starts rocking [m/s^2].

    g tan(alpha) for a block (section 2 of [000]) or an equivalent block; g lambda for a
    structure with rocking parameters (eq. 10 of [003]), the smaller of the two directions of
    an asymmetric one (:func:`rockstudy.structures.uplift_acceleration`).
    """
    return _uplift_acceleration(structure)


def record_groups(structure, record: Record) -> dict:
    """The dimensionless intensities of a record for a structure: the record counterparts of
    paper [000]'s (a, omega).

    With a_up the uplift acceleration (:func:`uplift_acceleration`: g tan(alpha) for a block),
    p the frequency parameter of the (equivalent) block, and the record's dominant velocity
    pulse of period T_p and amplitude A (:meth:`rockstudy.motions.Record.pulse`):

    - ``pga_ratio`` = PGA / a_up: rocking can start only if it exceeds 1;
    - ``pgv_ratio`` = PGV p / a_up;
    - ``pulse_frequency_ratio`` = omega_p / p = 2 pi / (T_p p), the omega_g / p of (3.6);
    - ``pulse_amplitude_ratio`` = (2 pi A / T_p) / a_up: the pulse's acceleration amplitude
      omega_p A (that of a harmonic of velocity amplitude A) over a_up, the a_g / (g tan alpha)
      of (5.3). NaN when the record has no pulse (A = 0).

    PGA and PGV are those of :meth:`rockstudy.motions.Record.intensity_measure`.
    """
    if not isinstance(record, Record):
        raise TypeError(f"record must be a rockstudy Record, got {type(record).__name__}")
    p = _block(structure)[0]
    a_up = uplift_acceleration(structure)
    pga, pgv = record.intensity_measure("pga"), record.intensity_measure("pgv")
    pulse = record.pulse()
    w_p = 2.0 * math.pi / pulse.period if pulse.amplitude > 0 else math.nan
    return {
        "pga_ratio": pga / a_up,
        "pgv_ratio": pgv * p / a_up,
        "pulse_frequency_ratio": w_p / p,
        "pulse_amplitude_ratio": w_p * pulse.amplitude / a_up,
    }
