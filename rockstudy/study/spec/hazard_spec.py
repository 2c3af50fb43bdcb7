"""The ``[hazard]`` table of a study file: the site's hazard curve, a power law or a file.

A hazard file is read relative to the study file's folder into ``levels`` and ``rates``
before the study is validated (``_read_hazard_file``), so a stored study keeps its curve.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, Field, model_validator

from ...motions import measures
from ...risk import MAX_YEARS
from .parameters import _describe, _Model, _Period
from .structures import FieldError

__all__ = ["HazardSpec"]  # and HAZARD_MEASURES, read from the registry (__getattr__)


def __getattr__(name):
    """``HAZARD_MEASURES``: the measures a ``[hazard]`` curve may be of, read from the
    registry when asked (a measure registered after import is one)."""
    if name == "HAZARD_MEASURES":
        return tuple(measures.scalable())
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _hazard_im(name: str) -> str:
    """A measure a ``[hazard]`` curve may be of: one of the registry's measures of power > 0
    (:func:`rockstudy.motions.measures.scalable`, read when the study is validated, so a
    measure registered after import is one), or a ValueError listing them."""
    if name not in measures.scalable():
        raise ValueError(f"must be one of {list(measures.scalable())}, got {name!r}")
    return name


class HazardSpec(_Model):
    """The site's hazard curve, for the annual probability of overturning of each structure
    of a record ``[design]`` (:func:`rockstudy.study.analysis.risk.object_risk`).

    ``kind = "power_law"``: lambda(x) = ``k0`` x^-``k`` (x in ``units``); ``kind = "file"``:
    ``file``, a path relative to the study file, of two columns (level, annual rate of
    exceedance) or an OpenQuake hazard-curve CSV (:meth:`rockstudy.risk.HazardCurve.from_csv`).
    The file is read when the study is validated: its levels and rates are then part of the
    study (``levels``, ``rates``: not to be given by hand), so a stored result keeps the curve
    it was reported with. ``im`` is the measure (a measure of the registry of power > 0, a
    registered one too; ``sa``, ``psv`` and ``sd`` at a ``period`` [s] the design stores),
    ``units`` the units of its levels (:func:`rockstudy.motions.measures.units_of` the
    measure; default the IM's SI unit, or OpenQuake's for its files) and ``years`` the
    exposure time of the probability reported (default 50).
    """

    kind: Literal["power_law", "file"]
    im: Annotated[str, AfterValidator(_hazard_im)]
    units: str | None = None
    period: _Period | None = None
    years: float = Field(default=50.0, gt=0, le=MAX_YEARS)
    k0: float | None = Field(default=None, gt=0)
    k: float | None = Field(default=None, gt=0)
    file: str | None = None
    levels: list[float] | None = None
    rates: list[float] | None = None

    @model_validator(mode="after")
    def _curve(self):
        own = ("k0", "k") if self.kind == "power_law" else ("file", "levels", "rates")
        other = ("file", "levels", "rates") if self.kind == "power_law" else ("k0", "k")
        for name in other:
            if getattr(self, name) is not None:
                raise FieldError(name, f"does not apply to kind = {self.kind!r}")
        for name in own:
            if getattr(self, name) is None:
                raise FieldError(
                    name,
                    f"is required for kind = {self.kind!r}"
                    + (
                        " (read from file when the study file is validated)"
                        if name in ("levels", "rates")
                        else ""
                    ),
                )
        try:
            self.curve()
        except ValueError as exc:
            text = str(exc)
            field = next(
                (
                    f
                    for f in ("units", "period", "levels", "rates", "k0", "k")
                    if text.startswith(f)
                ),
                "file" if self.kind == "file" else "im",
            )
            raise FieldError(field, text.removeprefix(f"{field}: ")) from None
        return self

    def curve(self):
        """The :class:`rockstudy.risk.HazardCurve`."""
        from ...risk import HazardCurve

        if self.kind == "power_law":
            return HazardCurve.power_law(self.k0, self.k, self.im, self.units, self.period)
        return HazardCurve(self.im, self.levels, self.rates, self.units, self.period, self.file)


def _read_hazard_file(data, base_dir) -> str | None:
    """Read ``hazard.file`` (:meth:`rockstudy.risk.HazardCurve.from_csv`, relative to the
    study file's folder) into ``hazard.levels`` and ``hazard.rates`` of ``data``, in place
    (and ``units``, ``period`` where the file gives them); the problem as one line, or None."""
    hz = data.get("hazard")
    if not (isinstance(hz, dict) and hz.get("kind") == "file" and "file" in hz):
        return None
    given = [k for k in ("levels", "rates") if k in hz]
    if given:
        return f"hazard.{given[0]}: is read from hazard.file; give the file only"
    name = hz["file"]
    if not isinstance(name, str) or not name.strip():
        return f"hazard.file: must be the path of a hazard-curve file, got {_describe(name)}"
    from ...risk import HazardCurve
    from .feasibility import record_path

    args = {k: hz.get(k) for k in ("im", "units", "period")}
    plain = all(v is None or isinstance(v, str | float | int) for v in args.values())
    if args["im"] not in measures.scalable() or not plain:
        return None  # the schema names the bad field; the file is read once it is right
    path = record_path(name, base_dir)
    try:
        curve = HazardCurve.from_csv(path, **args)
    except (TypeError, ValueError, KeyError) as exc:
        text = str(exc)
        # a bad units, period or im is that field's problem, not the file's
        field = next((f for f in ("units", "period", "im") if text.startswith(f)), "file")
        return f"hazard.{field}: {text.removeprefix(f'{field}: ').removeprefix('path: ')}"
    hz["levels"], hz["rates"] = curve.levels.tolist(), curve.rates.tolist()
    hz["units"] = curve.units
    if curve.period is not None:
        hz["period"] = curve.period
    return None
