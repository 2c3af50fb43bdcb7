"""Checks of a motion's vertical component before any integration (private).

With a vertical ground acceleration u_v'' [m/s^2, upwards] gravity is g + u_v'' in the frame
of the base (Housner's equation): a record is refused where u_v'' <= -g
(free fall, no contact force), and a block stays at rest while |u_h''| <= (g + u_v'') tan alpha.
"""

from __future__ import annotations

import numpy as np

from ..constants import G

#: Rows x samples evaluated at once by :func:`uplift_ratio` (bounds its memory).
_CHUNK = 2**22


def refuse_free_fall(vsamples, scale, batch=False) -> None:
    """ValueError naming ``vertical`` (and the scale and row in a batch) where the scaled
    vertical component |scale| u_v'' reaches -g anywhere.

    Parameters
    ----------
    vsamples : ndarray
        Vertical samples [m/s^2] of the kernel encoding (empty: no vertical, nothing to check).
    scale : float or ndarray
        The record's factor(s); the vertical is scaled by their absolute value.
    batch : bool
        Name the row of ``scale`` in the message.
    """
    if vsamples.size == 0:
        return
    lowest = np.abs(np.atleast_1d(np.asarray(scale, dtype=float))) * float(np.min(vsamples))
    bad = np.flatnonzero(~(lowest > -G))
    if bad.size:
        i = int(bad[0])
        where = f" at scale[{i}] = {float(np.atleast_1d(scale)[i])!r}" if batch else ""
        raise ValueError(
            f"vertical: the vertical ground acceleration reaches {float(lowest[i])!r} m/s^2"
            f"{where}, "
            f"at or below -g = {-G!r} m/s^2 (free fall: the base no longer carries the "
            "structure, which Housner's model does not describe); scale the record down"
        )


def uplift_ratio(scale, slenderness, samples, vsamples):
    """max over the record of |u_h''| / ((g + u_v'') tan alpha) per row [-]: the block lifts
    off somewhere iff it is > 1 (eq. 2.2 of [000] with gravity g + u_v''). Without a vertical
    it is the peak over g tan alpha. Exact for linear interpolation: between two samples
    |u_h''| - (g + u_v'') tan alpha is convex, so its largest value is at a sample.

    Parameters
    ----------
    scale, slenderness : ndarray
        The record's factor and alpha [rad] per row.
    samples, vsamples : ndarray
        Horizontal and vertical samples [m/s^2] (vsamples empty: no vertical).

    Returns
    -------
    ndarray
        One ratio per row (1-D, also for scalar inputs).
    """
    scale, tan = np.broadcast_arrays(
        np.abs(np.atleast_1d(np.asarray(scale, dtype=float))),
        np.tan(np.atleast_1d(np.asarray(slenderness, dtype=float))),
    )
    if vsamples.size == 0:
        return scale * np.max(np.abs(samples)) / (G * tan)
    out = np.empty(scale.shape)
    h = np.abs(samples)
    step = max(1, _CHUNK // samples.size)
    for i in range(0, out.size, step):
        s = scale[i : i + step, None]
        out[i : i + step] = np.max(s * h / (G + s * vsamples), axis=1) / tan[i : i + step]
    return out
