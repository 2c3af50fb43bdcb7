"""The registry of intensity measures: every measure defined once, and read by everything.

A measure (:class:`Measure`) is its function of a :class:`~rockstudy.motions.Record`, its SI
unit, the unit users quote it in and the factor from SI to that unit, the power with which it
follows a scale factor of the record, whether it needs a period and a damping ratio, and a
label for reports. :meth:`Record.intensity_measures <rockstudy.motions.Record.intensity_measures>`,
:meth:`Record.scaled_to <rockstudy.motions.Record.scaled_to>`, the record designs
(``multiple_stripes(..., im=name)``, cloud, IDA), a study's ``scale_to`` and its feasibility
checks, the fragility and IM-efficiency tables and both reports read this registry, so a new
measure joins them all in one call of :func:`register_measure`::

    import numpy as np
    from rockstudy.motions import register_measure

    register_measure(
        "pga_first_half",
        lambda record: float(np.max(np.abs(record.acceleration[: record.acceleration.size // 2]))),
        unit="m/s^2", power=1, quoted_unit="g", factor=1 / 9.80665, label="PGA of the first half",
    )

Scaling power k: IM(s a_g) = abs(s)^k IM(a_g) for a record scaled by s. Amplitudes, spectral
values, CAV and spectrum intensity are linear in the record (k = 1); Arias intensity, an
integral of a_g^2, goes as s^2; durations and periods do not change (k = 0) and cannot be
scaled to.

The dimensionless scale targets of the record designs (:data:`RATIOS`, ``pga_ratio`` = PGA /
a_up and ``pgv_ratio`` = PGV p / a_up) are a measure of this registry divided by the structure's
uplift acceleration a_up (g tan alpha of a block, g lambda of another structure, eq. 10 of
[003]); they follow their measure's power.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..constants import STANDARD_GRAVITY
from . import intensity, rotd, units

__all__ = [
    "label",
    "listed",
    "Measure",
    "measure",
    "MEASURES",
    "power",
    "quoted",
    "Ratio",
    "RATIOS",
    "register_measure",
    "RESERVED",
    "scale_targets",
    "set_probe",
    "target",
    "unregister_measure",
]


@dataclass(frozen=True)
class Measure:
    """One intensity measure of the registry (see :func:`register_measure` for the fields).

    ``function(record)``; ``function(record, damping)`` if ``needs_damping``;
    ``function(record, period, damping)`` if ``needs_period`` (period [s], damping ratio).
    """

    name: str
    function: Callable
    unit: str
    power: float
    quoted_unit: str
    factor: float
    label: str
    needs_period: bool = False
    needs_damping: bool = False
    listed: bool = True
    #: Whether the function needs a record of two horizontal components (``acceleration_y``:
    #: the RotD measures of :mod:`rockstudy.motions.rotd`).
    needs_pair: bool = False
    #: A registered measure's values are checked (a finite number >= 0, its exceptions named);
    #: not the built-in ones', which are NaN where undefined (the duration of a silent record).
    checked: bool = False

    @property
    def scalable(self) -> bool:
        """True if a scale factor changes the measure (power != 0)."""
        return self.power != 0

    def of(self, record, period=None, damping: float = 0.05) -> float:
        """The measure of ``record`` [SI] (``period`` [s] and ``damping`` where it needs them).

        Raises ValueError naming the measure if its function returns no real number, and,
        for a registered measure, if it fails or returns NaN, an infinity or a negative value.
        """
        if not self.checked:
            return self._value(self._call(record, period, damping))
        where = f"the measure {self.name!r} of the record {getattr(record, 'name', '')!r}"
        try:
            value = self._call(record, period, damping)
        except Exception as exc:  # noqa: BLE001 - the user's function: named, in one line
            text = " ".join(str(exc).split())[:200]
            raise ValueError(f"{where} failed ({type(exc).__name__}: {text})") from None
        value = self._value(value)
        if not (math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{where} is {value!r}; a measure must be a finite number >= 0")
        return value

    def _call(self, record, period, damping):
        """The function's answer for ``record``, with the arguments it takes."""
        if self.needs_period:
            return self.function(record, period, damping)
        if self.needs_damping:
            return self.function(record, damping)
        return self.function(record)

    def _value(self, value) -> float:
        """The function's answer as a float, or ValueError naming the measure."""
        try:
            return _validate.number(f"the measure {self.name!r}", value)
        except ValueError as exc:
            raise ValueError(f"{exc} (its function must return a real number)") from None

    def quoted_label(self, period=None, unit: str | None = None) -> str:
        """The label with the quoted unit (or ``unit``, the one its values are shown in),
        e.g. 'PGA [g]' or 'Sa(T = 0.5 s) [g]'."""
        head = self.label if period is None else f"{self.label}(T = {float(period):.3g} s)"
        return f"{head} [{self.quoted_unit if unit is None else unit}]"


@dataclass(frozen=True)
class Ratio:
    """A dimensionless scale target: the measure ``base`` times p^``p_power`` divided by the
    uplift acceleration a_up of each structure (g tan(alpha) of a block); it follows the power
    of ``base``."""

    base: str
    p_power: int
    label: str


#: name -> :class:`Measure`, in registration order (the order of the tables and reports).
MEASURES: dict[str, Measure] = {}

#: The dimensionless scale targets of the record designs (see docs/records.rst).
RATIOS = {
    "pga_ratio": Ratio("pga", 0, "PGA / a_up"),
    "pgv_ratio": Ratio("pgv", 1, "PGV p / a_up"),
}

#: Names a measure may not take: name -> who stores it beside the measures (the dimensionless
#: scale targets here; the record designs add the variables of their tables when imported,
#: :func:`reserve_names`).
RESERVED: dict[str, str] = dict.fromkeys(RATIOS, "the dimensionless scale targets (RATIOS)")


def reserve_names(names, owner: str) -> None:
    """Reserve ``names`` for ``owner`` (words naming who stores them beside the measures, for
    the message): :func:`register_measure` then refuses them. Called by the modules that store
    variables beside the measures (the record designs, at import), which the registry cannot
    import.

    Raises
    ------
    ValueError
        Naming the measure and ``owner`` if a measure already has one of ``names`` (registered
        before ``owner`` was imported): its values would be overwritten; nothing is reserved.
    """
    names = [_text("names", n) for n in names]
    taken = [n for n in names if n in MEASURES]
    if taken:
        raise ValueError(
            f"the measure {taken[0]!r} takes a name reserved for {owner}, which store it beside "
            "the measures (its values would be overwritten): register it under another name"
        )
    for n in names:
        RESERVED.setdefault(n, owner)


_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")


def _flag(name: str, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _text(name: str, value) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"{name} must be a non-empty string, got {value!r}")
    return value


def _check_name(name, replace: bool) -> str:
    if not isinstance(name, str) or not _NAME.match(name) or len(name) > 64:
        raise ValueError(
            f"name must be a lower-case identifier (letters, digits, '_', starting with a "
            f"letter, at most 64 characters), got {name!r}"
        )
    if name in RESERVED:
        raise ValueError(f"name {name!r} is reserved ({RESERVED[name]} store it); choose another")
    if name in MEASURES and not replace:
        raise ValueError(f"name {name!r} is already a measure; give replace=True to redefine it")
    return name


#: An SI unit of base units with non-zero powers (``m/s^2``, ``m^2/s^4``, ``kg m/s``, and
#: ``m^0.5/s`` for the root of a velocity), or ``1`` for a dimensionless measure.
_POWER = r"(\^-?([1-9][0-9]*(\.[0-9]+)?|0\.[0-9]*[1-9][0-9]*))?"  # 2, -1, 0.5; never 0
_SI_UNIT = re.compile(rf"(1|(m|s|kg|rad){_POWER}([ */](m|s|kg|rad){_POWER})*)\Z")


def _check_unit(unit) -> str:
    unit = _text("unit", unit)
    if not _SI_UNIT.match(unit):
        raise ValueError(
            f"unit must be an SI unit of m, s, kg and rad with non-zero powers, like 'm/s^2', "
            f"'m^2/s^4' or 'm^0.5/s' ('1' for none), got {unit!r}"
        )
    return unit


def _check_quoted(unit: str, quoted: str, factor: float) -> None:
    """A ValueError naming ``quoted_unit`` where it is a unit the package knows (a name of
    :data:`rockstudy.motions.units.UNITS`, or an SI unit) of another dimension than ``unit``,
    or ``factor`` where it is not that unit's factor from SI."""
    if quoted in units.UNITS:
        to_si, si = units.UNITS[quoted]
    elif _SI_UNIT.match(quoted):
        to_si, si = 1.0, quoted
    else:
        return  # a unit of the measure's own (its factor is the only definition)
    if units.dimension(si) != units.dimension(unit):
        raise ValueError(
            f"quoted_unit {quoted!r} is a unit of {si}, not of the measure's unit {unit!r}: "
            f"use one of {list(units.aliases(unit))}"
        )
    if not math.isclose(factor, 1.0 / to_si, rel_tol=1e-12):
        raise ValueError(
            f"factor = {factor!r} is not the factor from {unit} to {quoted!r}: give "
            f"factor = {1.0 / to_si!r}"
        )


def _check_power(power) -> float:
    power = _validate.number("power", power)
    if not (math.isfinite(power) and power >= 0.0):
        raise ValueError(
            f"power must be a finite number >= 0 (IM(s a) = |s|^power IM(a); 0: a scale factor "
            f"does not change it), got {power!r}"
        )
    return power


def register_measure(
    name: str,
    function: Callable,
    *,
    unit: str,
    power: float,
    quoted_unit: str | None = None,
    factor: float = 1.0,
    label: str | None = None,
    needs_period: bool = False,
    needs_damping: bool = False,
    listed: bool = True,
    replace: bool = False,
    needs_pair: bool = False,
) -> Measure:
    """Add an intensity measure to the registry: one call, and every reader has it.

    Parameters
    ----------
    name : str
        A lower-case identifier, not yet a measure (unless ``replace``) nor a name of
        :data:`RESERVED`.
    function : callable
        ``function(record) -> float`` [SI]; ``function(record, damping)`` if
        ``needs_damping``; ``function(record, period, damping)`` if ``needs_period``.
        ``record`` is a :class:`~rockstudy.motions.Record` (``.time`` [s],
        ``.acceleration`` [m/s^2]). Values are cached per record. It is tried on a small
        synthetic record when registered (at T = 1 s and 5 % damping where it takes them),
        and wherever it is used it must return a finite number >= 0: else a ValueError
        names the measure and the record (its own exceptions too, in one line).
    unit : str
        SI unit of the value, of m, s, kg and rad with non-zero powers, e.g. ``"m/s^2"`` or
        ``"m^2/s^4"`` (``"1"`` for a ratio); a target in a study may then be written in any
        unit of its dimension in :data:`rockstudy.motions.units.UNITS` (:func:`units_of`).
    power : float
        k >= 0 with IM(s a_g) = abs(s)^k IM(a_g) for the record scaled by s (1 for
        amplitudes, 2 for Arias intensity, 0 for durations: those cannot be scaled to).
    quoted_unit, factor : str, float
        The unit of tables and reports and the factor from SI to it (``"g"`` and
        ``1 / 9.80665``); default ``unit`` and 1. A name of
        :data:`rockstudy.motions.units.UNITS` (or an SI unit) must be of the dimension of
        ``unit``, with its factor.
    label : str, optional
        Words for reports, without the unit (default the name with spaces).
    needs_period, needs_damping : bool
        Whether the function takes a period [s] and a damping ratio.
    listed : bool
        Whether :meth:`~rockstudy.motions.Record.intensity_measures` and the designs list it
        (``psv`` and ``sd`` are not: they follow from ``sa``).
    replace : bool
        Redefine an existing measure.
    needs_pair : bool
        Whether the function needs a record of two horizontal components (``acceleration_y``,
        as RotD50): a study refuses it on records of one before the run. It is then tried on
        the synthetic record with a second component (its own samples in reverse order).

    Returns
    -------
    Measure
        The registered measure.

    Raises
    ------
    ValueError
        Naming the argument that is not allowed, and what is, or the measure if its function
        fails on the synthetic record (it is then not registered).
    """
    replace = _flag("replace", replace)
    name = _check_name(name, replace)
    if not callable(function):
        raise ValueError(f"function must be callable (record -> float), got {function!r}")
    unit = _check_unit(unit)
    power = _check_power(power)
    factor = _validate.positive("factor", factor)
    if quoted_unit is None and factor != 1.0:
        raise ValueError(f"factor = {factor!r} needs quoted_unit (the unit it converts SI to)")
    quoted = unit if quoted_unit is None else _text("quoted_unit", quoted_unit)
    _check_quoted(unit, quoted, factor)
    label = name.replace("_", " ") if label is None else _text("label", label)
    measure = Measure(
        name,
        function,
        unit,
        power,
        quoted,
        factor,
        label,
        _flag("needs_period", needs_period),
        _flag("needs_damping", needs_damping),
        _flag("listed", listed),
        _flag("needs_pair", needs_pair),
        checked=_PROBE_RECORD is not None,
    )
    if measure.checked:
        _probe(measure)
    MEASURES[name] = measure
    return measure


#: The small synthetic record every registered measure is tried on (see :func:`set_probe`);
#: None while the built-in measures register, at import.
_PROBE_RECORD = None


def set_probe(record) -> None:
    """Try every measure registered from now on on ``record`` (at a period of 1 s and 5 %
    damping where it takes them), and check its values wherever it is used. Set once by
    :mod:`rockstudy.motions.records`, which defines records, after the built-in measures."""
    global _PROBE_RECORD
    _PROBE_RECORD = record


def _probe(measure: Measure) -> None:
    """ValueError naming the measure if it fails, or is not a finite number >= 0, on the
    probe record."""
    record = _PROBE_RECORD
    if measure.needs_pair and record.acceleration_y is None:
        record = record._replace(acceleration_y=record.acceleration[::-1].copy())
    try:
        measure.of(record, 1.0 if measure.needs_period else None, 0.05)
    except ValueError as exc:
        raise ValueError(f"function: {exc}; the measure is not registered") from None


def unregister_measure(name: str) -> None:
    """Remove a measure from the registry (ValueError naming ``name`` if it is none)."""
    if name not in MEASURES:
        raise ValueError(f"name must be one of {list(MEASURES)}, got {name!r}")
    del MEASURES[name]


def measure(name: str, argument: str = "im") -> Measure:
    """The measure ``name``, or a ValueError naming ``argument`` and listing the measures."""
    try:
        return MEASURES[name]
    except (KeyError, TypeError):
        raise ValueError(f"{argument} must be one of {list(MEASURES)}, got {name!r}") from None


def listed(period: bool) -> tuple[str, ...]:
    """Names of the listed measures with (``period=True``) or without a period."""
    return tuple(k for k, m in MEASURES.items() if m.listed and m.needs_period == period)


def scalable() -> tuple[str, ...]:
    """Names of the measures a scale factor changes (power > 0): those a record can be scaled
    to, and a study's ``[hazard]`` may be of."""
    return tuple(k for k, m in MEASURES.items() if m.scalable)


def scale_targets() -> tuple[str, ...]:
    """Names a record can be scaled to: every measure of power > 0, and :data:`RATIOS`."""
    return scalable() + tuple(RATIOS)


def target(name: str, argument: str = "im") -> Measure:
    """The measure behind a scale target (a ratio's base), or a ValueError naming
    ``argument`` and listing :func:`scale_targets`."""
    if name not in scale_targets():
        raise ValueError(f"{argument} must be one of {list(scale_targets())}, got {name!r}")
    return MEASURES[RATIOS[name].base] if name in RATIOS else MEASURES[name]


def power(name: str) -> float:
    """The scaling power of a measure or a ratio (its base measure's)."""
    return MEASURES[RATIOS[name].base if name in RATIOS else name].power


def quoted(name: str) -> tuple[str, float]:
    """(quoted unit, factor from SI) of a measure; ("-", 1) for a ratio."""
    if name in RATIOS:
        return "-", 1.0
    m = measure(name)
    return m.quoted_unit, m.factor


def label(name: str, period=None, unit: str | None = None) -> str:
    """Label with quoted unit (or ``unit``, the one its values are shown in) of a measure or
    a ratio, e.g. 'Sa(T = 0.5 s) [g]'."""
    if name in RATIOS:
        return f"{RATIOS[name].label} [-]"
    return measure(name).quoted_label(period, unit)


def units_of(name: str) -> dict[str, float]:
    """The units a value of the measure or ratio ``name`` may be written in: unit name ->
    factor to SI, the SI unit first. Those of :data:`rockstudy.motions.units.UNITS` of its
    dimension and its quoted unit; ``{"1": 1.0}`` for a ratio. Read by a study's
    ``scale_to`` and by hazard curves alike."""
    if name in RATIOS:
        return {"1": 1.0}
    m = measure(name)
    out = units.aliases(m.unit)
    out.setdefault(m.quoted_unit, 1.0 / m.factor)
    return out


def is_acceleration(name: str) -> bool:
    """Whether the measure ``name`` is an acceleration: its SI unit is of the dimension m s^-2
    (whatever its name; False for a ratio)."""
    return name not in RATIOS and units.dimension(measure(name).unit) == units.ACCELERATION


def acceleration_units() -> tuple[str, ...]:
    """Every unit an acceleration may be quoted in: those of the table
    (:func:`rockstudy.motions.units.acceleration_units`) and the quoted units of the
    accelerations of the registry (:func:`is_acceleration`)."""
    quoted = (m.quoted_unit for k, m in MEASURES.items() if is_acceleration(k))
    return tuple(dict.fromkeys((*units.acceleration_units(), *quoted)))


# ------------------------------------------------------------------------------ built-ins


def _peak_ground_velocity(record) -> float:
    return float(np.max(np.abs(intensity.ground_velocity(record.time, record.acceleration))))


def _peak_ground_displacement(record) -> float:
    d = intensity.ground_displacement(record.time, record.acceleration)
    return float(np.max(np.abs(d)))


def _spectral(omega_power: int) -> Callable:
    """SD(T, zeta) omega^omega_power of a record (0: SD [m], 1: PSV [m/s], 2: Sa [m/s^2])."""

    def function(record, period, damping):
        sd = record._spectral_displacement([period], damping)[0]
        return float(sd * (2.0 * math.pi / period) ** omega_power)

    return function


#: Measures of the samples (t, a) by :mod:`rockstudy.motions.intensity`: name, function, SI
#: unit, power, label (spectrum intensity takes the damping ratio too).
_SERIES = (
    ("arias", intensity.arias_intensity, "m/s", 2, "Arias intensity"),
    ("cav", intensity.cumulative_absolute_velocity, "m/s", 1, "CAV"),
    ("significant_duration", intensity.significant_duration, "s", 0, "significant duration 5-95 %"),
    ("mean_period", intensity.mean_period, "s", 0, "mean period T_m"),
    ("spectrum_intensity", intensity.spectrum_intensity, "m", 1, "spectrum intensity"),
)


def _of_samples(f: Callable) -> Callable:
    return lambda record, *args: f(record.time, record.acceleration, *args)


def _builtins():
    """The measures of :mod:`rockstudy.motions.intensity` (see its conventions), in the order
    of the tables."""
    to_g = {"quoted_unit": "g", "factor": 1.0 / STANDARD_GRAVITY}  # g the unit, as for records
    register_measure("pga", lambda r: r.peak, unit="m/s^2", power=1, label="PGA", **to_g)
    register_measure("pgv", _peak_ground_velocity, unit="m/s", power=1, label="PGV")
    register_measure("pgd", _peak_ground_displacement, unit="m", power=1, label="PGD")
    for name, f, unit, k, label in _SERIES:
        register_measure(
            name,
            _of_samples(f),
            unit=unit,
            power=k,
            label=label,
            needs_damping=name == "spectrum_intensity",
        )
    spectral = {"power": 1, "needs_period": True}
    register_measure("sa", _spectral(2), unit="m/s^2", label="Sa", **spectral, **to_g)
    register_measure("psv", _spectral(1), unit="m/s", label="PSV", listed=False, **spectral)
    register_measure("sd", _spectral(0), unit="m", label="Sd", listed=False, **spectral)
    _rotd_builtins(to_g, spectral)


def _rotd_builtins(to_g: dict, spectral: dict) -> None:
    """RotD50 and RotD100 of PGA and Sa (:mod:`rockstudy.motions.rotd`): measures of a pair
    of horizontal components, so not listed (a record of one component has none of them)."""
    for which, words in (("rotd50", "RotD50"), ("rotd100", "RotD100")):
        pair = {"unit": "m/s^2", "listed": False, "needs_pair": True, **to_g}
        register_measure(
            f"pga_{which}", rotd.pga_rotd(which), power=1, label=f"PGA {words}", **pair
        )
        register_measure(
            f"sa_{which}", rotd.sa_rotd(which), label=f"Sa {words}", **spectral, **pair
        )


_builtins()
