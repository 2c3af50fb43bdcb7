"""Sampled ground-motion records: PEER NGA ``.AT2`` files and two-column text files."""

from __future__ import annotations

import re
import stat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _validate
from ..constants import G
from . import _kernels
from .base import Motion

#: Largest record file read [bytes]: a PEER record is ~0.1 MB; anything beyond this is no record.
MAX_RECORD_BYTES = 64 * 2**20

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
        lines = read_text_file(path).splitlines()
        if len(lines) < 5:
            raise ValueError(f"{path}: too short to be a PEER .AT2 file")
        header = lines[3]
        m = re.search(r"NPTS\s*=\s*(\d+)\s*,\s*DT\s*=\s*([-+0-9.Ee]+)", header, re.I)
        if not m:
            m = re.match(r"\s*(\d+)\s+([-+0-9.Ee]+)", header)
        try:
            npts, dt = int(m.group(1)), float(m.group(2))
        except (AttributeError, ValueError):
            raise ValueError(f"{path}: line 4 does not give NPTS and DT") from None
        if "UNITS OF G" not in lines[2].upper():
            raise ValueError(f"{path}: line 3 must state 'UNITS OF G'")
        tokens = " ".join(lines[4:]).split()
        if len(tokens) != npts:
            raise ValueError(f"{path}: header says NPTS={npts} but {len(tokens)} values follow")
        try:
            values = np.array(tokens, dtype=float)
        except ValueError:
            raise ValueError(f"{path}: the values after line 4 are not all numbers") from None
        return _build(path, lambda: cls(values * G, dt=dt, name=path.stem))

    @classmethod
    def from_csv(cls, path, units: str = "g", delimiter: str | None = None) -> Record:
        """Read a two-column text file of time [s] and acceleration in ``units``.

        Lines starting with ``#`` are skipped; columns may be separated by commas or blanks.

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
        text = read_text_file(path)
        if delimiter is None:
            text = text.replace(",", " ")
        lines = text.splitlines()
        try:
            data = np.loadtxt(lines, comments="#", delimiter=delimiter, ndmin=2)
        except ValueError:  # its message quotes the file: name the line instead
            raise ValueError(
                f"{path}: line {_first_bad_line(lines, delimiter)} is not two numbers "
                "(time, acceleration)"
            ) from None
        if data.shape[1] != 2:
            raise ValueError(
                f"{path}: expected 2 columns (time, acceleration), found {data.shape[1]}"
            )
        return _build(path, lambda: cls(data[:, 1] * factor, time=data[:, 0], name=path.stem))


def _first_bad_line(lines, delimiter) -> int:
    """1-based number of the first data line that is not two numbers (0 if none is)."""
    for i, line in enumerate(lines, 1):
        body = line.split("#", 1)[0]
        fields = body.split(delimiter) if delimiter else body.split()
        if not body.strip():
            continue
        try:
            values = [float(x) for x in fields]
        except ValueError:
            return i
        if len(values) != 2:
            return i
    return 0


def _build(path, make) -> Record:
    """Make the record, naming the file in any complaint about its samples."""
    try:
        return make()
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def read_text_file(path, max_bytes: int = MAX_RECORD_BYTES) -> str:
    """The text of a regular file of at most ``max_bytes``, refusing anything else.

    Folders, devices, pipes and pseudo-files (``/proc``) are refused before reading, and at
    most ``max_bytes + 1`` bytes are ever read. Messages name the file and the reason, never
    its contents.
    """
    path = Path(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such file") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot be read ({exc.strerror})") from None
    if stat.S_ISDIR(info.st_mode):
        raise ValueError(f"{path}: is a folder, not a file")
    if not stat.S_ISREG(info.st_mode):
        raise ValueError(f"{path}: is not a regular file (a device, pipe or socket)")
    if info.st_size == 0:
        raise ValueError(f"{path}: is empty (or a pseudo-file of the system)")
    if info.st_size > max_bytes:
        raise ValueError(
            f"{path}: is {info.st_size / 2**20:.3g} MiB, more than the {max_bytes / 2**20:.3g} "
            "MiB allowed for it"
        )
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise ValueError(f"{path}: cannot be read ({exc.strerror})") from None
    if len(data) != info.st_size:
        raise ValueError(f"{path}: changed size while it was read")
    if b"\0" in data:
        raise ValueError(f"{path}: holds binary data, not text")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")  # old headers; the numbers are ASCII either way


def read_record(path, units: str = "g") -> Record:
    """Read a record file: a PEER ``.AT2`` file (by its suffix), else two columns of time [s]
    and acceleration in ``units``."""
    if str(path).lower().endswith(".at2"):
        return Record.from_at2(path)
    return Record.from_csv(path, units=units)
