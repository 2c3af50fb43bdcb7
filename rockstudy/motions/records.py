"""Sampled ground-motion records: PEER NGA ``.AT2`` files and two-column text files."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _validate
from ..constants import G
from . import _kernels
from .base import Motion

_UNITS = {"g": G, "m/s2": 1.0, "m/s^2": 1.0, "cm/s2": 0.01, "cm/s^2": 0.01}


def _unit_factor(units: str) -> float:
    try:
        return _UNITS[units]
    except KeyError:
        raise ValueError(f"units must be one of {sorted(_UNITS)}, got {units!r}") from None


@dataclass(frozen=True, eq=False)
class Record(Motion):
    """A sampled acceleration history, linearly interpolated between samples.

    Parameters
    ----------
    acceleration : array_like
        Ground acceleration samples [m/s^2]; finite everywhere.
    dt : float, optional
        Uniform time step [s]. Give either ``dt`` or ``time``.
    time : array_like, optional
        Strictly increasing sample times [s]; shifted so that the first sample is at t = 0.
    name : str
        A label for plots and results.
    """

    acceleration: np.ndarray
    dt: float | None = None
    time: np.ndarray | None = None
    name: str = ""
    _times: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        acc = _validate.finite_array("acceleration", self.acceleration)
        if acc.size < 2:
            raise ValueError("acceleration must hold at least 2 samples")
        if (self.dt is None) == (self.time is None):
            raise ValueError("give exactly one of dt (uniform step) or time (sample times)")
        if self.dt is not None:
            dt = _validate.positive("dt", self.dt)
            times = dt * np.arange(acc.size)
        else:
            times = _validate.finite_array("time", self.time)
            if times.size != acc.size:
                raise ValueError(
                    f"time has {times.size} values but acceleration has {acc.size}; "
                    "they must be the same length"
                )
            steps = np.diff(times)
            if np.any(steps <= 0):
                i = int(np.flatnonzero(steps <= 0)[0])
                raise ValueError(
                    f"time must be strictly increasing; time[{i + 1}] = {times[i + 1]!r} "
                    f"follows time[{i}] = {times[i]!r}"
                )
            times = times - times[0]
            dt = float(np.median(steps))
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "dt", float(dt))
        object.__setattr__(self, "time", times)
        object.__setattr__(self, "_times", times)

    @property
    def duration(self) -> float:
        return float(self._times[-1])

    @property
    def peak(self) -> float:
        return float(np.max(np.abs(self.acceleration)))

    def scaled(self, factor: float) -> Record:
        """The same record with every sample multiplied by ``factor`` (negative mirrors)."""
        return Record(self.acceleration * float(factor), time=self._times, name=self.name)

    def kernel_spec(self):
        params = np.array([1.0, 0.0, 0.0, self.duration])
        return _kernels.KIND_RECORD, params, self._times, self.acceleration

    @classmethod
    def from_at2(cls, path) -> Record:
        """Read a PEER NGA ``.AT2`` file (acceleration in g), returned in m/s^2.

        Both header styles are read: ``NPTS= 2048, DT= .0066 SEC`` (with or without filter
        information after it) and the older ``2048 0.0066 NPTS, DT``.
        """
        path = Path(path)
        lines = path.read_text().splitlines()
        if len(lines) < 5:
            raise ValueError(f"{path}: too short to be a PEER .AT2 file")
        header = lines[3]
        m = re.search(r"NPTS\s*=\s*(\d+)\s*,\s*DT\s*=\s*([-+0-9.Ee]+)", header, re.I)
        if m:
            npts, dt = int(m.group(1)), float(m.group(2))
        else:
            m = re.match(r"\s*(\d+)\s+([-+0-9.Ee]+)", header)
            if not m:
                raise ValueError(f"{path}: line 4 does not give NPTS and DT: {header.strip()!r}")
            npts, dt = int(m.group(1)), float(m.group(2))
        values = np.array(" ".join(lines[4:]).split(), dtype=float)
        if values.size != npts:
            raise ValueError(f"{path}: header says NPTS={npts} but {values.size} values follow")
        if "UNITS OF G" not in lines[2].upper():
            raise ValueError(f"{path}: line 3 must state 'UNITS OF G', got {lines[2].strip()!r}")
        return cls(values * G, dt=dt, name=path.stem)

    @classmethod
    def from_csv(cls, path, units: str = "g", delimiter: str | None = None) -> Record:
        """Read a two-column text file of time [s] and acceleration in ``units``.

        Lines starting with ``#`` are skipped, and so is a first row of column names; columns
        may be separated by commas or blanks.

        Parameters
        ----------
        path : path-like
        units : {"g", "m/s2", "cm/s2"}
            Units of the acceleration column.
        delimiter : str, optional
            Column separator; by default commas or white space.
        """
        factor = _unit_factor(units)
        path = Path(path)
        text = path.read_text()
        if delimiter is None:
            text = text.replace(",", " ")
        rows = [r for r in text.splitlines() if r.strip() and not r.lstrip().startswith("#")]
        names = 1 if rows and re.match(r"\s*[A-Za-z_\"']", rows[0]) else 0  # a header row
        data = np.loadtxt(rows[names:], delimiter=delimiter, ndmin=2)
        if data.shape[1] != 2:
            raise ValueError(
                f"{path}: expected 2 columns (time, acceleration), found {data.shape[1]}"
            )
        return cls(data[:, 1] * factor, time=data[:, 0], name=path.stem)
