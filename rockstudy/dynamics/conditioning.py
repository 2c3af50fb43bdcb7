"""Conditioning of a scene: how far its peak moves under a tiny change of the amplitude.

A rocking response is a chain of uplifts and impacts. Where one of them is grazed (an impact
at a speed near the rest speed, a dip that just touches theta = 0, the ground just reaching
the uplift level), the response has a jump in the amplitude nearby, and a change of the
amplitude in the ninth digit can move the peak in the third. Two correct solvers differ on
such a scene by whatever their rounding does there, and neither value is more right than
the other: the scene, not the solver, decides the precision. :func:`peak_change` measures
it, by running the scene again with the amplitude (a pulse's, or a record's scale) times
1 + :data:`CONDITIONING_STEP`; a scene is ill-conditioned where the relative change of
max |theta| exceeds :data:`ILL_CONDITIONED`. ``simulate(..., conditioning=True)`` and
``simulate_batch(outputs=[..., "conditioning"])`` report it (opt-in: it costs a second run).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..motions import Record
from ..motions.pulses import NoMotion

__all__ = ["CONDITIONING_STEP", "ILL_CONDITIONED", "peak_change", "perturbed", "WELL_CONDITIONED"]

#: Relative change of the amplitude with which the conditioning is measured.
CONDITIONING_STEP = 1e-9
#: Relative change of max |theta| (under :data:`CONDITIONING_STEP`) above which a scene is
#: ill-conditioned: its peak is not determined to better than this by the amplitude's ninth
#: digit.
ILL_CONDITIONED = 1e-3
#: Relative change up to which a scene is well conditioned: the rounding of each step, amplified
#: by change / CONDITIONING_STEP, stays below 10 rtol at rtol 1e-10, and the kernel and the
#: scipy reference agree that closely (between the two, they differ by about 1e-5 times the
#: change; benchmarks/bench_solver_agreement.py, docs/methods.rst).
WELL_CONDITIONED = 1e-5


def peak_change(max_rotation, overturned, max_perturbed, overturned_perturbed):
    """The relative change |max' - max| / max of the largest rotation [rad] between a scene
    and its copy with the amplitude times 1 + :data:`CONDITIONING_STEP`: inf where the
    overturning decision changes, 0 where both overturn or neither lifts (array_like in,
    float array out)."""
    m0, m1 = np.asarray(max_rotation, float), np.asarray(max_perturbed, float)
    o0, o1 = np.asarray(overturned, bool), np.asarray(overturned_perturbed, bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(m1 - m0) / m0
    rel = np.where((m0 == 0.0) & (m1 == 0.0), 0.0, rel)
    rel = np.where(o0 & o1, 0.0, rel)
    return np.where(o0 != o1, np.inf, rel)


def perturbed(motion):
    """``motion`` with its amplitude (a pulse's ``amplitude``, a record's samples) times
    1 + :data:`CONDITIONING_STEP`; a :class:`~rockstudy.motions.NoMotion` as it is."""
    factor = 1.0 + CONDITIONING_STEP
    if isinstance(motion, Record):
        return motion.scaled(factor)
    if isinstance(motion, NoMotion):
        return motion
    if dataclasses.is_dataclass(motion) and hasattr(motion, "amplitude"):
        return dataclasses.replace(motion, amplitude=motion.amplitude * factor)
    raise TypeError(
        f"conditioning: cannot scale the amplitude of a {type(motion).__name__} "
        "(a Record or a pulse with an amplitude is needed)"
    )
