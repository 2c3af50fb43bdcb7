"""One units module: what is an acceleration is read from a measure's unit in the registry, every
door that reads a unit name (a study's ``scale_to``, a hazard curve, a record file, the CLI's
``--units``) accepts the same names with the same factor, a registered measure may be a study's
hazard measure, and the names the record designs store cannot be taken by a measure.

Oracles, written here and not read from the package: the factors of the units to SI (1 g =
9.80665 m/s^2 by the CGPM's definition of standard gravity, 1 gal = 1 cm/s^2 = 0.01 m/s^2,
1 cm = 0.01 m, a g s is 9.80665 m/s), and the names of the variables the record designs store
(read from their own tables).
"""

import argparse
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from rockstudy import cli
from rockstudy.motions import Record, measures, register_measure
from rockstudy.risk import HazardCurve
from rockstudy.study.designs import record_rows, records
from rockstudy.study.report import _page
from rockstudy.study.report import risk as report_risk
from rockstudy.study.report.objects import ReportContext, quoted_to_report
from rockstudy.study.report.records import im_label
from rockstudy.study.spec import schema as spec

DATA = Path(__file__).resolve().parents[1] / "data"

#: Every unit name any door reads -> its value in SI (m/s^2, m/s, m or s), by definition.
SI_VALUE = {
    "m/s^2": 1.0,
    "m/s2": 1.0,
    "g": 9.80665,
    "cm/s^2": 0.01,
    "cm/s2": 0.01,
    "gal": 0.01,
    "m/s": 1.0,
    "cm/s": 0.01,
    "g s": 9.80665,
    "m": 1.0,
    "cm": 0.01,
    "s": 1.0,
}
#: The SI unit of each name above.
DIMENSION = {
    **dict.fromkeys(("m/s^2", "m/s2", "g", "cm/s^2", "cm/s2", "gal"), "m/s^2"),
    **dict.fromkeys(("m/s", "cm/s", "g s"), "m/s"),
    **dict.fromkeys(("m", "cm"), "m"),
    "s": "s",
}

HALF = "half_pga_units_module"  # an acceleration quoted in g
GAL = "gal_pga_units_module"  # an acceleration written "m s^-2" and quoted in gal
SPEED = "pga_speed_units_module"  # named like an acceleration, but a velocity


@pytest.fixture(scope="module")
def own_measures():
    try:
        register_measure(
            HALF,
            lambda r: 0.5 * r.peak,
            unit="m/s^2",
            power=1,
            quoted_unit="g",
            factor=1 / 9.80665,
            label="half PGA",
        )
        register_measure(
            GAL, lambda r: r.peak, unit="m s^-2", power=1, quoted_unit="gal", factor=100.0
        )
        register_measure(SPEED, lambda r: 0.1 * r.peak, unit="m/s", power=1)
        yield
    finally:
        for name in (HALF, GAL, SPEED):
            if name in measures.MEASURES:
                measures.unregister_measure(name)


# ------------------------------------------------------------------ acceleration-ness


def test_an_acceleration_is_known_by_its_unit_not_its_name(own_measures):
    assert measures.is_acceleration("pga") and measures.is_acceleration("sa")
    assert measures.is_acceleration(HALF) and measures.is_acceleration(GAL)
    assert not measures.is_acceleration(SPEED)  # "pga" in its name, m/s its unit
    assert not measures.is_acceleration("pgv") and not measures.is_acceleration("arias")
    assert not measures.is_acceleration("pga_ratio")  # dimensionless


def _captured(monkeypatch):
    """Each figure the page embeds: name -> (x label, [(x data, label) of each line])."""
    figures = {}
    original = _page._Page.figure

    def figure(self, fig, name, caption):
        ax = fig.axes[0]
        lines = [(np.asarray(ln.get_xdata(), float), ln.get_label()) for ln in ax.lines]
        figures[name] = (ax.get_xlabel(), lines)
        return original(self, fig, name, caption)

    monkeypatch.setattr(_page._Page, "figure", figure)
    return figures


def _stated_unit(label: str) -> str:
    return re.search(r"\[([^\]]+)\][^\[]*$", label).group(1)


@pytest.mark.parametrize("units", ["m/s^2", "g", "cm/s^2"])
def test_the_hazard_figure_states_the_unit_its_levels_are_drawn_in(
    tmp_path, monkeypatch, own_measures, units
):
    """A curve of a measure quoted in g, given in m/s^2: its axis says m/s^2, not g."""
    figures = _captured(monkeypatch)
    levels_si = np.geomspace(0.05, 5.0, 12)  # [m/s^2]
    curve = HazardCurve(HALF, levels_si / SI_VALUE[units], 1e-2 * levels_si**-2.0, units=units)
    own = np.array([1.2, 2.5, 4.0])  # each record's own half PGA [m/s^2]
    ds = xr.Dataset({HALF: ("record", own)})
    out = xr.Dataset({"uplift": ("structure", [np.nan])})
    report_risk._hazard_figure(_page._Page(tmp_path), ds, curve, out)
    xlabel, lines = figures["hazard_curve"]
    unit = SI_VALUE[_stated_unit(xlabel)]
    drawn = dict((label, x) for x, label in lines)
    np.testing.assert_allclose(drawn["hazard curve, as read"] * unit, levels_si, rtol=1e-12)
    np.testing.assert_allclose(drawn["the records, unscaled"] * unit, own, rtol=1e-12)


def test_the_deaggregation_figure_states_the_unit_of_its_intervals(
    tmp_path, monkeypatch, own_measures
):
    figures = _captured(monkeypatch)
    edges_si = np.array([0.5, 1.0, 2.0, 4.0, 8.0])  # [m/s^2]
    n = edges_si.size - 1
    out = xr.Dataset(
        {
            "annual_rate": ("structure", [1e-3]),
            "uplift": ("structure", [np.nan]),
            "im_lower": ("interval", np.r_[0.0, edges_si[:-1], edges_si[-1]]),
            "im_upper": ("interval", np.r_[edges_si[0], edges_si[1:], np.inf]),
            "deaggregation": (("structure", "interval"), np.full((1, n + 2), 1e-3 / (n + 2))),
        },
        coords={"structure": ["vase"]},
        attrs={"im": HALF, "units": "m/s^2"},
    )
    report_risk._deaggregation_figure(_page._Page(tmp_path), out)
    xlabel, lines = figures["deaggregation"]
    centres = np.sqrt(edges_si[:-1] * edges_si[1:])
    x = next(x for x, label in lines if label == "vase")
    np.testing.assert_allclose(x * SI_VALUE[_stated_unit(xlabel)], centres, rtol=1e-12)


@pytest.mark.parametrize("units", ["g", "m/s^2"])
def test_a_report_shows_every_acceleration_in_its_units(own_measures, units):
    """A measure of acceleration quoted in gal, in a report in g or m/s^2: its label and its
    values in the report's unit."""
    ctx = ReportContext(ds=xr.Dataset(), units=units)
    label = ctx.relabel(im_label(GAL))
    assert _stated_unit(label) == units
    value_in_gal = 250.0
    shown = value_in_gal * quoted_to_report(units, GAL)
    assert shown * SI_VALUE[units] == pytest.approx(value_in_gal * SI_VALUE["gal"], rel=1e-12)
    # a velocity keeps its own unit, whatever its name says
    assert _stated_unit(ctx.relabel(im_label(SPEED))) == "m/s"
    assert quoted_to_report(units, SPEED) == 1.0


@pytest.mark.parametrize(
    "unit, factor, said",
    [
        ("m/s", 1 / 9.80665, r"quoted_unit 'g' is a unit of m/s\^2, not of the measure's"),
        ("m/s^2", 0.5, r"factor = 0.5 is not the factor from m/s\^2 to 'g'"),
        ("m/s^2", 1.0, r"factor = 1.0 is not the factor"),
    ],
)
def test_a_quoted_unit_of_the_table_must_have_its_dimension_and_factor(unit, factor, said):
    with pytest.raises(ValueError, match=said):
        register_measure(
            "bad_quote_units_module",
            lambda r: 1.0,
            unit=unit,
            power=1,
            quoted_unit="g",
            factor=factor,
        )
    assert "bad_quote_units_module" not in measures.MEASURES


# ------------------------------------------------------------------ one alias table


def _scale_to(im, unit):
    """The factor to SI of ``unit`` for a study's scale_to of ``im``, or None if refused."""
    period = 0.5 if measures.measure(im).needs_period else None
    try:
        target = spec.ScaleTo(im=im, period=period, value=1.0, units=unit)
    except ValueError:
        return None
    return target.si_factor()


def _hazard(im, unit):
    """The factor to SI of ``unit`` for a hazard curve of ``im``, or None if refused."""
    period = 0.5 if measures.measure(im).needs_period else None
    levels_si = np.geomspace(0.05, 5.0, 12)
    try:
        curve = HazardCurve(
            im, levels_si / SI_VALUE.get(unit, 1.0), 1e-2 * levels_si**-2.0, unit, period
        )
    except ValueError:
        return None
    return float(np.median(curve.to_si().levels / curve.levels))


def _record_file(tmp_path, unit):
    """The factor to m/s^2 of ``unit`` for a two-column record file, or None if refused."""
    path = tmp_path / "rec.txt"
    t = np.arange(200) * 0.01
    a = 0.3 * np.sin(2 * np.pi * t) / SI_VALUE.get(unit, 1.0) * 9.80665  # 0.3 g
    np.savetxt(path, np.column_stack([t, a]))
    try:
        record = Record.from_csv(path, units=unit)
    except ValueError:
        return None
    return float(record.peak / np.max(np.abs(a)))


def _cli(tmp_path, unit):
    """The factor to m/s^2 of ``unit`` for ``rockstudy simulate --record --units``, or None if
    refused."""
    path = str(tmp_path / "rec.txt")
    sub = next(
        a for a in cli._parser()._actions if isinstance(a, argparse._SubParsersAction)
    ).choices["simulate"]
    choices = next(a for a in sub._actions if "--units" in a.option_strings).choices
    if unit not in choices:
        return None
    _record_file(tmp_path, unit)
    a = np.loadtxt(path)[:, 1]
    return float(cli._read_record(path, unit).peak / np.max(np.abs(a)))


#: Measures of each dimension the doors are tried with.
BY_DIMENSION = {"m/s^2": ["pga", "sa"], "m/s": ["pgv", "cav"], "m": ["pgd"]}


@pytest.mark.parametrize("dimension", list(BY_DIMENSION))
def test_every_door_accepts_every_unit_of_a_dimension_with_its_factor(tmp_path, dimension):
    names = [u for u, d in DIMENSION.items() if d == dimension]
    for im in BY_DIMENSION[dimension]:
        for unit in names:
            for door in (_scale_to, _hazard):
                assert door(im, unit) == pytest.approx(SI_VALUE[unit], rel=1e-12), (door, im, unit)
    if dimension == "m/s^2":  # the record files' units
        for unit in names:
            for door in (_record_file, _cli):
                assert door(tmp_path, unit) == pytest.approx(SI_VALUE[unit], rel=1e-9), (
                    door,
                    unit,
                )
            spec.RecordSpec.model_validate({"kind": "record", "files": "x", "units": unit})


@pytest.mark.parametrize("dimension", list(BY_DIMENSION))
def test_every_door_refuses_the_units_of_another_dimension(tmp_path, dimension):
    others = [u for u, d in DIMENSION.items() if d != dimension]
    for im in BY_DIMENSION[dimension]:
        for unit in others:
            assert _scale_to(im, unit) is None and _hazard(im, unit) is None, (im, unit)
    if dimension == "m/s^2":
        for unit in others:
            assert _record_file(tmp_path, unit) is None and _cli(tmp_path, unit) is None, unit


def test_a_measure_quoted_in_its_own_unit_is_read_in_it_by_every_door(own_measures):
    assert _scale_to(GAL, "gal") == pytest.approx(0.01, rel=1e-12)
    assert _hazard(GAL, "gal") == pytest.approx(0.01, rel=1e-12)
    assert _scale_to(GAL, "m s^-2") == 1.0 and _hazard(GAL, "m s^-2") == 1.0


# ------------------------------------------------------------------ hazard measures

#: The shipped museum study (records relative to its folder), its hazard section replaced.
MUSEUM = Path(__file__).resolve().parents[1] / "studies" / "museum.toml"


def _museum_with_hazard_of(im):
    head = MUSEUM.read_text().split("[hazard]")[0]
    return head + f'[hazard]\nkind = "power_law"\nk0 = 2e-4\nk = 2.3\nim = "{im}"\nunits = "g"\n'


def test_a_registered_measure_can_be_a_study_hazard_measure(own_measures):
    study = spec.validate_text(_museum_with_hazard_of(HALF), base_dir=MUSEUM.parent)
    curve = study.hazard.curve()
    assert curve.im == HALF
    np.testing.assert_allclose(curve.rate([0.3]), 2e-4 * 0.3**-2.3, rtol=1e-12)


def test_an_unknown_hazard_measure_is_named_with_the_allowed_ones(own_measures):
    with pytest.raises(spec.StudyError) as err:
        spec.validate_text(_museum_with_hazard_of("pga_typo"), base_dir=MUSEUM.parent)
    problem = next(p for p in err.value.problems if "hazard.im" in p)
    assert "'pga_typo'" in problem
    for name in ("pga", "sa", "pgv", HALF):
        assert repr(name) in problem
    assert "'significant_duration'" not in problem  # a duration cannot be scaled to


# ------------------------------------------------------------------ reserved names


def _design_variables():
    """Every variable name the record designs' tables declare."""
    names = {
        *record_rows.PULSE_VARIABLES,
        *record_rows.GROUP_VARIABLES,
        *record_rows.STRUCTURE_VARIABLES,
        *record_rows._RUN,
        *record_rows._IDA,
        *record_rows.CONTACT_VARIABLES,
        *records.STEP_VARIABLES,
    }
    return sorted(names)


def test_no_design_variable_can_be_registered_as_a_measure():
    names = _design_variables()
    assert {"step_scale", "capacity_scale", "friction_demand", "rungs"} <= set(names)
    for name in names:
        owner = "scale targets" if name in measures.RATIOS else "record designs"
        with pytest.raises(ValueError, match=rf"{name!r}.*reserved.*{owner}"):
            register_measure(name, lambda r: 1.0, unit="m/s^2", power=1)
        assert name not in measures.MEASURES


def test_a_measure_registered_before_the_designs_reserve_its_name_is_refused():
    register_measure("late_name_units_module", lambda r: 1.0, unit="m/s^2", power=1)
    try:
        with pytest.raises(ValueError, match=r"'late_name_units_module'.*a test's table"):
            measures.reserve_names(["late_name_units_module"], "a test's table")
    finally:
        measures.unregister_measure("late_name_units_module")


# ------------------------------------------------------------------ the risk of any measure


def test_the_risk_of_a_measure_in_its_own_si_unit_is_that_of_the_same_measure_in_gal(
    own_measures,
):
    """GAL (quoted in gal) and a copy of it whose unit, "m s^-2", is in no table: the same
    records, the same curve in SI, so the same annual rate, and medians 100 apart (1 gal =
    0.01 m/s^2)."""
    from rockstudy import Block
    from rockstudy.motions import load_suite
    from rockstudy.study.analysis.risk import object_risk
    from rockstudy.study.designs.records import multiple_stripes

    copy = "si_copy_units_module"
    register_measure(copy, lambda r: r.peak, unit="m s^-2", power=1)
    try:
        suite = load_suite(sorted((DATA / "records").glob("*_H.AT2")))
        vase = {"vase": Block(half_diagonal=0.4, slenderness=0.3)}
        ds = multiple_stripes(suite, vase, np.array([4.0, 6.0, 9.0]), im="pga")
        levels_si = np.geomspace(0.5, 40.0, 12)
        rates = 1e-2 * levels_si**-2.0
        own = object_risk(ds, HazardCurve(copy, levels_si, rates, "m s^-2"), n_boot=0)
        gal = object_risk(ds, HazardCurve(GAL, levels_si / 0.01, rates, "gal"), n_boot=0)
    finally:
        measures.unregister_measure(copy)
    assert own["status"].values[0] == "ok"
    rate = own["annual_rate"].values[0]
    assert np.isfinite(rate) and rate > 0
    assert gal["annual_rate"].values[0] == pytest.approx(rate, rel=1e-9)
    assert gal["theta"].values[0] * 0.01 == pytest.approx(own["theta"].values[0], rel=1e-9)
