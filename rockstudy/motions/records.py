"""Sampled ground-motion records: PEER NGA ``.AT2`` files and text files of columns."""

from __future__ import annotations

import math
import os
import re
import stat
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _validate
from .._warnings import UnitsWarning
from ..constants import STANDARD_GRAVITY
from . import _kernels, intensity, measures
from .base import Motion, axis_sign, check_orientation
from .pulse_extraction import extract_pulse
from .units import acceleration_units
from .wavelet_pulse import extract_wavelet_pulse

__all__ = [
    "COLUMNS",
    "IMPOSSIBLE_PGA",
    "MAX_RECORD_BYTES",
    "not_a_file",
    "PULSE_METHODS",
    "read_record",
    "read_text_file",
    "Record",
    "UnitsError",
    "WEAK_PGA",
    "WEAKEST_PGA",
]

#: Largest record file read [bytes]: a PEER record is ~0.1 MB; anything beyond this is no record.
MAX_RECORD_BYTES = 64 * 2**20

#: Factor to m/s^2 of each acceleration unit of the package's one table of units
#: (:mod:`rockstudy.motions.units`); "g" is standard gravity (the PEER convention).
_UNITS = acceleration_units()

#: A PGA no ground motion reaches [m/s^2] (the largest recorded is about 4 g): a file that
#: reads above it is in other units than those it was read in (cm/s^2 read as g: 100 times).
IMPOSSIBLE_PGA = 10.0 * STANDARD_GRAVITY

#: The weakest PGA of a strong-motion record read from a file [m/s^2]: accelerographs trigger
#: near 0.005 g and no block rocks below g tan(alpha), so a record that reads below 0.0005 g is
#: in other units than those it was read in (a file in g read as cm/s^2 reads 100 times low:
#: El Centro 1940's 0.35 g would read 0.00036 g).
WEAKEST_PGA = 5e-4 * STANDARD_GRAVITY

#: A PGA below which a record read from a file is warned of [m/s^2] (:class:`UnitsWarning`):
#: weaker than the trigger level of most accelerographs, so possibly in other units.
WEAK_PGA = 5e-3 * STANDARD_GRAVITY

#: Methods of :meth:`Record.pulse`.
PULSE_METHODS = {"wavelet": extract_wavelet_pulse, "mavroeidis": extract_pulse}

#: Column names :meth:`Record.from_csv` reads.
COLUMNS = ("time", "horizontal", "vertical")


def _check_columns(columns, dt) -> tuple:
    """The columns of a text record as a tuple of :data:`COLUMNS` names, or a ValueError."""
    if isinstance(columns, str):
        columns = (columns,)
    columns = tuple(columns)
    unknown = [c for c in columns if c not in COLUMNS]
    if unknown or len(set(columns)) != len(columns) or "horizontal" not in columns:
        raise ValueError(
            f"columns must name each column once, from {COLUMNS}, with 'horizontal' among "
            f"them, e.g. ('time', 'horizontal', 'vertical'); got {columns!r}"
        )
    if ("time" in columns) == (dt is not None):
        raise ValueError(
            f"columns={columns!r} with dt={dt!r}: give dt [s] exactly when there is no "
            "'time' column"
        )
    return columns


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
        Uniform time step [s]. Give either ``dt`` or ``time``. For a record given by ``time``
        it is set to the median of its steps, a summary: unequal steps are kept, and the
        motion and its measures use the times themselves.
    time : array_like, optional
        Strictly increasing sample times [s]; shifted so that the first sample is at t = 0
        (a file whose times start at 1 s starts its motion at 0).
    name : str
        A label for plots and results.
    vertical : array_like, optional
        Vertical ground acceleration [m/s^2], positive upwards, on the same samples.
    metadata : mapping, optional
        What the record is, for the reader (e.g. the building and floor of a floor motion,
        :func:`rockstudy.motions.floor_motion`); kept by :meth:`scaled`, never read by the
        motion or its measures.
    acceleration_y : array_like, optional
        The second horizontal component [m/s^2], at right angles to ``acceleration`` (the x
        component), on the same samples. The record still moves an object along x, and its
        measures are those of x; :meth:`oriented` gives the motion along any direction of the
        plane, and the measures of the pair (``pga_rotd50``, ``sa_rotd100``, ...) read both.

    Intensity measures (:meth:`intensity_measures`, :meth:`response_spectrum`, :meth:`pulse`) are
    computed once and cached; the sample arrays are read-only for that reason.
    """

    acceleration: np.ndarray
    dt: float | None = None
    time: np.ndarray | None = None
    name: str = ""
    vertical: np.ndarray | None = None
    metadata: dict | None = field(default=None, repr=False)
    acceleration_y: np.ndarray | None = field(default=None, repr=False)
    _times: np.ndarray = field(init=False, repr=False)
    _cache: dict = field(init=False, repr=False)

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise ValueError(f"name must be a string, got {type(self.name).__name__}")
        if not isinstance(self.metadata, Mapping | None):
            raise TypeError(f"metadata must be a mapping, got {type(self.metadata).__name__}")
        object.__setattr__(self, "metadata", dict(self.metadata or {}))
        acc = _samples("acceleration", self.acceleration)
        if acc.size < 2:
            raise ValueError("acceleration must hold at least 2 samples")
        if (self.dt is None) == (self.time is None):
            raise ValueError("give exactly one of dt (uniform step) or time (sample times)")
        if self.dt is not None:
            dt = _validate.positive("dt", self.dt)
            _check_timing(acc.size, dt * (acc.size - 1), dt, dt, "dt")
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
            _check_timing(acc.size, float(times[-1]), dt, float(np.min(steps)), "time")
        for name, what in _COMPONENTS.items():
            values = getattr(self, name)
            if values is not None:
                object.__setattr__(self, name, _component(name, values, acc.size, what))
        acc = acc.copy()
        times = np.array(times, dtype=float)
        acc.flags.writeable = False
        times.flags.writeable = False
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "dt", float(dt))
        object.__setattr__(self, "time", times)
        object.__setattr__(self, "_times", times)
        object.__setattr__(self, "_cache", {})

    @property
    def duration(self) -> float:
        return float(self._times[-1])

    @property
    def peak(self) -> float:
        return float(np.max(np.abs(self.acceleration)))

    def scaled(self, factor: float) -> Record:
        """The same record with every sample multiplied by ``factor`` (negative mirrors).

        Both horizontal components are multiplied by ``factor``; a vertical component by
        ``|factor|``: mirroring the horizontal directions does not turn the vertical upside
        down. The ground record of a floor motion (``metadata["ground"]``) is scaled too.
        """
        factor = _validate.number("factor", factor)
        if not math.isfinite(factor):
            raise ValueError(f"factor must be a finite number, got {factor!r}")
        with np.errstate(over="ignore", under="ignore"):  # refused below, naming the factor
            acc = self.acceleration * factor
            vertical = None if self.vertical is None else self.vertical * abs(factor)
            y = None if self.acceleration_y is None else self.acceleration_y * factor
        metadata = self.metadata
        if isinstance(metadata.get("ground"), Record):  # a floor motion's ground scales with it
            metadata = {**metadata, "ground": metadata["ground"].scaled(factor)}
        try:
            return self._replace(
                acceleration=acc, vertical=vertical, acceleration_y=y, metadata=metadata
            )
        except ValueError as exc:
            raise ValueError(f"factor = {factor:g} on the record {self.name!r}: {exc}") from None

    def scaled_to(self, value: float, im: str = "pga", period=None, damping: float = 0.05):
        """The record scaled so that its intensity measure ``im`` equals ``value``.

        Parameters
        ----------
        value : float
            Target, > 0, in the SI unit of ``im`` (:data:`rockstudy.motions.measures.MEASURES`).
        im : str
            A measure of the registry that changes with a scale factor (power k > 0: ``pga``,
            ``pgv``, ``pgd``, ``cav``, ``spectrum_intensity``, ``sa``, ``psv``, ``sd`` linearly,
            ``arias`` quadratically, and any measure registered with a power > 0); the factor
            is (value / current)^(1/k).
        period, damping
            For the measures that need them (``sa``, ``psv``, ``sd``): T [s] and zeta.
        """
        m = measures.measure(im)
        if not m.scalable:
            raise ValueError(f"im={im!r} does not change with a scale factor; cannot scale to it")
        value = _validate.positive("value", value)
        current = self.intensity_measure(im, period=period, damping=damping)
        if not (math.isfinite(current) and current > 0.0):
            raise ValueError(
                f"im={im!r}: the record {self.name!r} has {im} = {current!r}, "
                f"so no scale factor reaches {value!r}"
            )
        ratio = value / current
        return self.scaled(ratio ** (1.0 / m.power))

    def _cached(self, key, compute):
        if key not in self._cache:
            self._cache[key] = compute()
        return self._cache[key]

    def _spectral_displacement(self, periods, damping: float) -> np.ndarray:
        """SD [m] at ``periods``, cached per period: the periods not yet computed go to the
        spectrum kernel in one call (each period's value is independent of the others)."""
        periods = intensity.check_periods(periods)
        damping = intensity.check_damping(damping)
        missing = [t for t in np.unique(periods) if ("sd", float(t), damping) not in self._cache]
        if missing:
            sd = intensity.spectral_displacement(
                self._times, self.acceleration, np.array(missing), damping
            )
            self._cache.update(
                {("sd", float(t), damping): v for t, v in zip(missing, sd, strict=True)}
            )
        return np.array([self._cache[("sd", float(t), damping)] for t in periods])

    def intensity_measures(self, periods=(), damping: float = 0.05) -> dict:
        """The intensity measures of the (horizontal) record: every listed measure of the
        registry (:mod:`rockstudy.motions.measures`), in SI units.

        Parameters
        ----------
        periods : array_like
            Periods T [s] of the measures that need one (``sa``; may be empty).
        damping : float
            Damping ratio zeta in [0, 1) of ``sa`` and ``spectrum_intensity``.

        Returns
        -------
        dict
            ``pga`` [m/s^2], ``pgv`` [m/s], ``pgd`` [m], ``arias`` [m/s], ``cav`` [m/s],
            ``significant_duration`` [s] (5-95 %), ``mean_period`` [s] (Rathje et al. 2004),
            ``spectrum_intensity`` [m] (Housner 1952), every measure registered since, and
            ``sa`` [m/s^2] (and each registered measure that needs a period), an array over
            ``periods``. Arias, CAV and the Husid curve are trapezoids over the samples (as
            eqsig); see :mod:`rockstudy.motions.intensity` for definitions and the baseline
            corrections (a constant offset for the velocity, a least-squares c2 t^2 + c3 t^3
            for the displacement). PGD is still only as good as the record's processing:
            elcentro_NS.dat of the shared records, unfiltered, gives 0.33 m.

        Raises
        ------
        ValueError
            Naming ``periods`` outside [1e-12 s, 2 pi dt / 1e-5], ``dt`` too coarse for the
            mean period's band, or an ``acceleration`` whose Arias intensity overflows.
        """
        periods = intensity.check_periods(periods) if np.size(periods) else np.zeros(0)
        damping = intensity.check_damping(damping)
        out = {k: self.intensity_measure(k, damping=damping) for k in measures.listed(False)}
        if periods.size:  # the spectrum in one pass: the spectral measures read it per period
            self._spectral_displacement(periods, damping)
        for k in measures.listed(True):
            out[k] = np.array([self.intensity_measure(k, t, damping) for t in periods], float)
        return out

    def intensity_measure(self, im: str, period=None, damping: float = 0.05) -> float:
        """One intensity measure of the registry by name [SI] (see :meth:`intensity_measures`;
        also ``psv``, ``sd``), cached.

        ``period`` [s] is required by the measures that need one (``sa``, ``psv``, ``sd``) and
        refused by the others.
        """
        m = measures.measure(im)
        damping = intensity.check_damping(damping)
        if not m.needs_period:
            if period is not None:
                raise ValueError(f"period is only for the measures that need one, not im={im!r}")
        elif period is None:
            raise ValueError(f"im={im!r} needs a period [s]")
        else:
            period = float(intensity.check_periods(period)[0])
        zeta = damping if m.needs_period or m.needs_damping else None
        return self._cached(("im", m, period, zeta), lambda: m.of(self, period, damping))

    def response_spectrum(self, periods, damping: float = 0.05):
        """Elastic response spectrum (Nigam & Jennings 1969) as an :class:`xarray.Dataset`.

        ``sa`` [m/s^2] (pseudo-acceleration), ``psv`` [m/s] (pseudo-velocity) and ``sd`` [m]
        on ``period`` [s]; the damping is in the attributes.
        """
        periods = intensity.check_periods(periods)
        sd = self._spectral_displacement(periods, damping)
        return intensity.response_spectrum_dataset(periods, sd, intensity.check_damping(damping))

    def pulse(self, method: str = "wavelet"):
        """The velocity pulse of the record, with ``period`` [s] and ``indicator``.

        Parameters
        ----------
        method : {"wavelet", "mavroeidis"}
            ``"wavelet"``: Baker (2007) and Shahi & Baker (2014), db4 wavelets, T_p the
            pseudo-period of the largest wavelet, s dt / F_c (the period of the peak of the
            extracted pulse's 5 %-damped pseudo-velocity spectrum is ``psv_period``)
            (:class:`rockstudy.motions.wavelet_pulse.WaveletPulse`). ``"mavroeidis"``: a
            least-squares Mavroeidis-Papageorgiou (2003) pulse
            (:class:`rockstudy.motions.pulse_extraction.VelocityPulse`).
        """
        try:
            extract = PULSE_METHODS[method]
        except (KeyError, TypeError):
            raise ValueError(
                f"method must be one of {sorted(PULSE_METHODS)}, got {method!r}"
            ) from None
        return self._cached(("pulse", method), lambda: extract(self._times, self.acceleration))

    def _replace(self, **changes) -> Record:
        """This record with the fields ``changes`` (acceleration, name, vertical, metadata,
        acceleration_y) replaced, on the same times."""
        fields = {
            "acceleration": self.acceleration,
            "name": self.name,
            "vertical": self.vertical,
            "metadata": self.metadata,
            "acceleration_y": self.acceleration_y,
        }
        fields.update(changes)
        return Record(time=self._times, **fields)

    def _with_component(self, name: str, other: Record, path) -> Record:
        """This record with the component ``name`` (``vertical`` or ``acceleration_y``) the
        samples of ``other``, read from ``path``; a ValueError naming the field and the file
        unless they share this record's samples."""
        n, m = self.acceleration.size, other.acceleration.size
        if n != m or not np.allclose(other._times, self._times, rtol=1e-9, atol=1e-12):
            raise ValueError(
                f"{_FIELDS[name]}: {path} has {m} samples at dt={other.dt!r} s but the "
                f"horizontal record {self.name!r} has {n} at dt={self.dt!r} s; "
                f"{_COMPONENTS[name]} must be given on the same samples"
            )
        return self._replace(**{name: other.acceleration})

    def _with_vertical(self, vertical: Record, path) -> Record:
        """This record with the vertical component ``vertical`` read from ``path``."""
        return self._with_component("vertical", vertical, path)

    @property
    def two_components(self) -> bool:
        """Whether the record carries a second horizontal component (``acceleration_y``)."""
        return self.acceleration_y is not None

    def oriented(self, psi: float) -> Record:
        """The one-component record along the direction at angle ``psi`` [rad] from the x
        component towards y: a_psi(t) = a_x(t) cos(psi) + a_y(t) sin(psi).

        The vertical component and the metadata are kept; ``metadata["orientation"]`` is
        ``psi``. A one-component record has no y: only psi = 0 (itself) and psi = pi (itself
        mirrored, ``scaled(-1)``), up to a whole number of turns, are directions it has;
        other angles are refused.
        """
        psi = check_orientation(psi)
        c, s = math.cos(psi), math.sin(psi)
        if self.acceleration_y is None:
            c, s = axis_sign(psi, f"the record {self.name!r}"), 0.0
        y = 0.0 if self.acceleration_y is None else self.acceleration_y
        return self._cached(
            ("oriented", psi),
            lambda: self._replace(
                acceleration=c * self.acceleration + s * y,
                acceleration_y=None,
                metadata={**self.metadata, "orientation": psi},
            ),
        )

    def kernel_spec(self):
        params = np.array([1.0, 0.0, 0.0, self.duration])
        # writable copies: numba types read-only arrays apart, and one compiled signature per
        # kernel (the one ``rockstudy compile`` primes) must serve every record
        vsamples = _kernels.NO_VERTICAL if self.vertical is None else np.array(self.vertical)
        return (
            _kernels.KIND_RECORD,
            params,
            np.array(self._times),
            np.array(self.acceleration),
            vsamples,
        )

    @classmethod
    def from_at2(cls, path, vertical=None, h2=None) -> Record:
        """Read a PEER NGA ``.AT2`` file (acceleration in g), returned in m/s^2.

        g is standard gravity, 9.80665 m/s^2 (:data:`rockstudy.constants.STANDARD_GRAVITY`),
        the unit of PEER's processing: with it the record's own velocity and displacement are
        PEER's.

        Both header styles are read: ``NPTS= 2048, DT= .0066 SEC`` (with or without filter
        information after it) and the older ``2048 0.0066 NPTS, DT``. ``vertical`` is the path
        of the vertical component's ``.AT2`` file, and ``h2`` that of the second horizontal
        component (``acceleration_y``, e.g. the ``...090.AT2`` of a ``...000.AT2``), each on
        the same samples (NPTS and DT): else a ValueError naming the file.
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
        values = _at2_values(path, lines, npts)
        record = _build(path, lambda: cls(values * STANDARD_GRAVITY, dt=dt, name=path.stem))
        for name, other in (("acceleration_y", h2), ("vertical", vertical)):
            if other is not None:
                record = record._with_component(name, cls.from_at2(other), other)
        return record

    @classmethod
    def from_csv(
        cls,
        path,
        units: str = "g",
        delimiter: str | None = None,
        vertical=None,
        columns=("time", "horizontal"),
        dt: float | None = None,
    ) -> Record:
        """Read a text file of columns: by default two, time [s] and acceleration in ``units``.

        Lines starting with ``#`` are skipped, and so is a first row of column names; columns
        may be separated by commas or blanks.

        Parameters
        ----------
        path : path-like
        units : str
            Units of the acceleration columns (horizontal and vertical alike): an acceleration
            of :data:`rockstudy.motions.units.UNITS` (``"g"``, ``"m/s2"`` or ``"m/s^2"``,
            ``"cm/s2"``, ``"cm/s^2"`` or ``"gal"``).
        delimiter : str, optional
            Column separator; by default commas or white space.
        vertical : path-like, optional
            A file of the same format and samples holding the vertical component (not with a
            ``"vertical"`` column).
        columns : sequence of {"time", "horizontal", "vertical"}
            What the file's columns hold, in order; ``"horizontal"`` is required. An H/V
            record in one file: ``("time", "horizontal", "vertical")``, or
            ``("horizontal", "vertical")`` with ``dt``. The file must have exactly these
            columns on every line.
        dt : float, optional
            Uniform time step [s], given exactly when there is no ``"time"`` column.
        """
        factor = _unit_factor(units)
        columns = _check_columns(columns, dt)
        if vertical is not None and "vertical" in columns:
            raise ValueError(
                "vertical: give the vertical component as a column or as a file, not both"
            )
        path = Path(path)
        text = read_text_file(path)
        if delimiter is None:
            text = text.replace(",", " ")
        rows = [r for r in text.splitlines() if r.strip() and not r.lstrip().startswith("#")]
        names = 1 if rows and re.match(r"\s*[A-Za-z_\"']", rows[0]) else 0  # a header row
        ncol = len(columns)
        what = f"{ncol} numbers ({', '.join(columns)})"
        bad, found = _first_bad_line(text.splitlines(), delimiter, names, ncol)
        if bad:
            got = (
                f"has {found} columns, expected {ncol} columns ({', '.join(columns)})"
                if found
                else f"is not {what}"
            )
            raise ValueError(f"{path}: line {bad} {got}{_column_hint(columns)}")
        try:
            data = np.loadtxt(rows[names:], comments="#", delimiter=delimiter, ndmin=2)
        except ValueError:  # its message quotes the file: name the line instead
            raise ValueError(f"{path}: the data are not {what} on every line") from None
        if data.shape[1] != ncol:
            raise ValueError(
                f"{path}: expected {ncol} columns ({', '.join(columns)}), found "
                f"{data.shape[1]}{_column_hint(columns)}"
            )
        col = {name: data[:, i] for i, name in enumerate(columns)}
        vert = col["vertical"] * factor if "vertical" in col else None
        timing = {"time": col["time"]} if "time" in col else {"dt": dt}
        record = _build(
            path,
            lambda: cls(col["horizontal"] * factor, **timing, name=path.stem, vertical=vert),
        )
        _check_plausible_pga(path, record, units)
        if vertical is None:
            return record
        return record._with_vertical(
            cls.from_csv(vertical, units, delimiter, columns=columns, dt=dt), vertical
        )


#: Float arrays of a record's working length that its measures hold at once: the uniform
#: resampling, the mean period's zero-padded spectrum (complex: two each, and a power of 2
#: above its length) and the pulse scan's convolutions.
_WORK_ARRAYS = 12


#: The components a record may carry beside ``acceleration``: field -> what it is.
_COMPONENTS = {
    "vertical": "the vertical component",
    "acceleration_y": "the second horizontal component",
}

#: The argument that gives each component from a file.
_FIELDS = {"vertical": "vertical", "acceleration_y": "h2"}


def _component(name: str, values, n: int, what: str) -> np.ndarray:
    """The read-only samples of the component ``name`` (:data:`_COMPONENTS`), checked as
    :func:`_samples` and to be ``n`` long (the length of ``acceleration``)."""
    arr = _samples(name, values)
    if arr.size != n:
        raise ValueError(
            f"{name} has {arr.size} samples but acceleration has {n}; {what} must be given on "
            "the same samples"
        )
    arr = arr.copy()
    arr.flags.writeable = False
    return arr


def _samples(name: str, values) -> np.ndarray:
    """Finite samples [m/s^2] within +-MAX_ACCELERATION, none of them subnormal."""
    arr = _validate.finite_array(name, values)
    big = np.flatnonzero(np.abs(arr) > _validate.MAX_ACCELERATION)
    if big.size:
        i = int(big[0])
        raise ValueError(
            f"{name}[{i}] = {float(arr[i]):.4g} m/s^2 is beyond the +-"
            f"{_validate.MAX_ACCELERATION:.0e} m/s^2 allowed (about a million g; no ground "
            "motion comes near it): a wrong unit or a corrupt value?"
        )
    tiny = np.flatnonzero((arr != 0.0) & (np.abs(arr) < np.finfo(float).tiny))
    if tiny.size:
        i = int(tiny[0])
        raise ValueError(
            f"{name}[{i}] = {float(arr[i]):.4g} m/s^2 is subnormal (nonzero but below "
            f"{np.finfo(float).tiny:.3g}): it has lost its precision, and no scale factor "
            "brings it to a finite target; write it as 0 or check the file"
        )
    return arr


def _check_timing(n: int, duration: float, dt: float, smallest: float, field: str):
    """Refuse a record whose duration [s] or steps [s] are beyond :data:`MAX_DURATION` and
    :data:`MIN_STEP`, or whose measures would not fit in memory (``field`` is ``dt`` or
    ``time``; ``dt`` is the median step)."""
    if not (math.isfinite(duration) and duration <= _validate.MAX_DURATION):
        raise ValueError(
            f"duration: {n} samples at a step of {dt:.4g} s last {duration:.4g} s, "
            f"beyond the {_validate.MAX_DURATION:.0e} s allowed for a record (about 11.6 "
            "days; a wrong time unit or a corrupt value?)"
        )
    if smallest < _validate.MIN_STEP:
        raise ValueError(
            f"{field}: a step of {smallest:.4g} s is below the {_validate.MIN_STEP:.0e} s "
            "allowed (1 MHz, a thousand times any accelerograph's sampling rate)"
        )
    points = max(n, duration / dt + 1.0, 2.0 / (intensity.MEAN_PERIOD_DF * dt))
    _validate.check_memory(
        field,
        8.0 * _WORK_ARRAYS * points,
        f"the record's intensity measures work on {points:.4g} points ({n} samples over "
        f"{duration:.4g} s at a step of {dt:.4g} s)",
        "resample the record to a coarser step",
    )


def _column_hint(columns) -> str:
    """A hint for a file whose column count does not match ``columns``."""
    if columns == ("time", "horizontal"):
        return (
            "; for time, horizontal and vertical columns pass "
            "columns=('time', 'horizontal', 'vertical')"
        )
    return ""


def _first_bad_line(lines, delimiter, skip_names=0, ncol=2) -> tuple:
    """(1-based number, how many numbers it holds or 0) of the first data line that is not
    ``ncol`` numbers, (0, 0) if none is; the first ``skip_names`` non-blank rows (column
    names) are not data."""
    for i, line in enumerate(lines, 1):
        body = line.split("#", 1)[0]
        if skip_names and body.strip():
            skip_names -= 1
            continue
        fields = body.split(delimiter) if delimiter else body.split()
        if not body.strip():
            continue
        try:
            values = [float(x) for x in fields]
        except ValueError:
            return i, 0
        if len(values) != ncol:
            return i, len(values)
    return 0, 0


#: A Fortran double-precision exponent (1.5D-03), which some processing writes for E.
_FORTRAN_EXPONENT = re.compile(r"(?<=[0-9.])[Dd](?=[-+]?[0-9])")


def _at2_values(path, lines, npts) -> np.ndarray:
    """The ``npts`` samples after the header (line 5 on) of an ``.AT2`` file, in g: numbers
    (Fortran ``D`` exponents read as ``E``), with a text line after the last of them (``END
    OF DATA``) ignored; a ValueError naming the file and the line of anything else."""
    rows = [_FORTRAN_EXPONENT.sub("E", line).split() for line in lines[4:]]
    try:
        values = np.array([t for row in rows for t in row], dtype=float)
    except ValueError:
        values = None
    if values is not None and values.size == npts:
        return values
    numbers, at = [], None
    for i, row in enumerate(rows, start=5):
        for token in row:
            try:
                numbers.append(float(token))
            except ValueError:
                at = i
                break
        if at is not None:
            break
    trailer = at is not None and all(
        not re.search(r"[0-9]", t) for row in rows[at - 5 :] for t in row
    )
    if at is not None and not (trailer and len(numbers) == npts):
        raise ValueError(
            f"{path}: line {at} holds text where the samples are expected (numbers only, "
            f"after the 4 header lines)"
        )
    if len(numbers) != npts:
        raise ValueError(f"{path}: header says NPTS={npts} but {len(numbers)} values follow")
    return np.array(numbers)


class UnitsError(ValueError):
    """A record file whose samples, read in the units given, are beyond any ground motion."""


def _reads(peak, units) -> str:
    """A peak acceleration [m/s^2] as the file's numbers read it, and in g."""
    out = f"{peak / _UNITS[units]:.4g} {units}"
    return out if units == "g" else f"{out} = {peak / STANDARD_GRAVITY:.4g} g"


def _check_plausible_pga(path, record, units) -> None:
    """A :class:`UnitsError` naming ``units`` where a component read from ``path`` in
    ``units`` peaks beyond any ground motion (:data:`IMPOSSIBLE_PGA`), or where the horizontal
    one peaks below any strong-motion record (:data:`WEAKEST_PGA`); a :class:`UnitsWarning`
    below :data:`WEAK_PGA`."""
    peak = float(np.max(np.abs(record.acceleration)))
    if 0.0 < peak < WEAKEST_PGA:
        raise UnitsError(
            f"{path}: units={units!r}: its peak acceleration reads {_reads(peak, units)}, "
            f"below any strong-motion record (under {WEAKEST_PGA / STANDARD_GRAVITY:g} g; "
            "accelerographs trigger near 0.005 g): are the samples in other units (g read as "
            'cm/s^2)? give the units they are in (units="g" or "m/s2")'
        )
    if 0.0 < peak < WEAK_PGA:
        warnings.warn(
            f"{path}: units={units!r}: its peak acceleration reads {_reads(peak, units)}, "
            f"weaker than most accelerographs record (under {WEAK_PGA / STANDARD_GRAVITY:g} "
            "g): check that the samples are in these units",
            UnitsWarning,
            stacklevel=3,
        )
    for what, a in (("", record.acceleration), (" vertical", record.vertical)):
        peak = 0.0 if a is None else float(np.max(np.abs(a)))
        if peak > IMPOSSIBLE_PGA * (1.0 + 1e-9):
            raise UnitsError(
                f"{path}: units={units!r}: its{what} peak acceleration reads "
                f"{_reads(peak, units)}, beyond "
                f"any ground motion (above {IMPOSSIBLE_PGA / STANDARD_GRAVITY:g} g): are the "
                "samples in other units (cm/s^2 read as g)? give the units they are in "
                '(units="cm/s2" or "m/s2")'
            )


def _build(path, make) -> Record:
    """Make the record, naming the file in any complaint about its samples."""
    try:
        return make()
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def not_a_file(path) -> str | None:
    """What ``path`` is if it is not a regular file (following symbolic links), e.g. "a FIFO
    (named pipe)" or "a dangling symbolic link to 'x'"; None for a regular file."""
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        if path.is_symlink():
            return f"a dangling symbolic link to {os.readlink(path)!r}"
        return "missing"
    except OSError as exc:
        return f"unreadable ({exc.strerror or type(exc).__name__})"
    if stat.S_ISREG(mode):
        return None
    kinds = (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    what = next((name for test, name in kinds if test(mode)), "not a regular file")
    if path.is_symlink():
        what += f" (a symbolic link to {os.readlink(path)!r})"
    return what


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
    if not stat.S_ISREG(info.st_mode):
        raise ValueError(f"{path}: is {not_a_file(path)}, not a file")
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


def read_record(path, units: str = "g", columns=("time", "horizontal"), dt=None) -> Record:
    """Read a record file: a PEER ``.AT2`` file (by its suffix), else a text file of
    ``columns`` (time [s] and acceleration in ``units`` by default; see
    :meth:`Record.from_csv` for H/V columns)."""
    if str(path).lower().endswith(".at2"):
        return Record.from_at2(path)
    return Record.from_csv(path, units=units, columns=columns, dt=dt)


def _probe_record() -> Record:
    """A small synthetic record (5 s at 100 Hz: a 0.8 s sine pulse of about 0.3 g in a
    decaying 1.7 s oscillation) that every registered measure is tried on."""
    t = np.arange(500) * 0.01
    pulse = np.sin(2 * np.pi * t / 0.8) * np.exp(-((t - 1.5) ** 2))
    ringing = 0.3 * np.sin(2 * np.pi * t / 1.7) * np.exp(-0.5 * t)
    return Record(0.3 * STANDARD_GRAVITY * (pulse + ringing), dt=0.01, name="synthetic probe")


measures.set_probe(_probe_record())
