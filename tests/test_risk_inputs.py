"""The inputs of rockstudy.risk and of a study's ``[hazard]``: every bad one refused naming it.

Oracles: the contract itself (a ValueError or TypeError naming the argument or the field, one
line, never a quote of the file); the file's own period against the one given; Cornell et al.
(2002)'s closed form k0 theta^-k exp(k^2 beta^2 / 2) to show which answers overflow float64
(exp(709.8) is its largest); the file kinds of ``os.stat``.
"""

import math
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from _helpers import HAZARD_STUDY as STUDY
from _helpers import cli, time_limit

from rockstudy import UnitsWarning
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.risk import HazardCurve, annual_rate, probability_in, rate_deaggregation
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.spec import schema as spec

DATA = Path(__file__).resolve().parents[1] / "data"
POWER = HazardCurve.power_law(2e-4, 2.3, units="g")
#: A line a file must never see quoted back (the shape of /etc/passwd's first line).
SECRET = "root:x:0:0:root:/root:/bin/bash"


def _study_text(file, im="pga", extra="", period=0.5):
    """The museum study of the [hazard] tests with a hazard file and design periods."""
    hazard = f'[hazard]\nkind = "file"\nfile = "{file}"\nim = "{im}"\n{extra}'
    text = STUDY.format(records=DATA / "records", hazard=hazard)
    return text.replace("periods = [0.5]", f"periods = [{period}]")


def _problems(tmp_path, text):
    with pytest.raises(spec.StudyError) as err:
        spec.validate_text(text, base_dir=tmp_path)
    return err.value.problems


def _openquake(path, imt, poe, levels=(0.1, 0.2, 0.4)):
    columns = ",".join(f"poe-{x}" for x in levels)
    values = ",".join(str(p) for p in poe)
    path.write_text(f"# investigation_time=1.0, imt='{imt}'\nlon,lat,{columns}\n0,0,{values}\n")
    return path


# ------------------------------------------------------------------ the period of a file


def test_a_period_that_disagrees_with_the_file_is_refused_naming_both(tmp_path):
    path = _openquake(tmp_path / "sa.csv", "SA(0.5)", [0.5, 0.1, 0.01])
    with pytest.raises(ValueError, match=r"^period=1\.0 .*SA\(0\.5\).*0\.5 s"):
        HazardCurve.from_csv(path, period=1.0)
    assert HazardCurve.from_csv(path, period=0.5).period == 0.5  # the file's own: taken
    assert HazardCurve.from_csv(path).period == 0.5
    pga = _openquake(tmp_path / "pga.csv", "PGA", [0.5, 0.1, 0.01])
    with pytest.raises(ValueError, match=r"^period=1\.0 .*PGA.*no period"):
        HazardCurve.from_csv(pga, period=1.0)


def test_a_study_period_that_disagrees_with_the_file_is_refused_naming_both(tmp_path):
    _openquake(tmp_path / "sa.csv", "SA(0.5)", [0.5, 0.1, 0.01])
    for periods in ("1.0", "0.5, 1.0"):
        found = _problems(tmp_path, _study_text("sa.csv", "sa", "period = 1.0", periods))
        assert len(found) == 1 and found[0].startswith("hazard.period: period=1.0"), found
        assert "SA(0.5)" in found[0], found
    study = spec.validate_text(_study_text("sa.csv", "sa", "period = 0.5"), base_dir=tmp_path)
    assert study.hazard.curve().period == 0.5


# ------------------------------------------------------------- what may be read as a file


def _from_csv_in_a_process(path, seconds=60):
    """HazardCurve.from_csv(path) in a child process: (returncode, stderr, seconds taken)."""
    code = (
        "import sys\nfrom rockstudy.risk import HazardCurve\n"
        "try:\n    HazardCurve.from_csv(sys.argv[1], im='pga')\n"
        "except ValueError as exc:\n    print(exc, file=sys.stderr)\n    sys.exit(3)\n"
    )
    t0 = time.time()
    proc = subprocess.run(
        [sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=seconds
    )
    return proc.returncode, proc.stderr.strip(), time.time() - t0


def test_a_device_a_fifo_and_a_huge_file_are_refused_before_reading(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    code, err, _ = _from_csv_in_a_process(fifo)  # (a hang fails by the timeout)
    assert code == 3 and "FIFO" in err and str(fifo) in err, err
    with pytest.raises(ValueError, match="path: .*/dev/zero.*character device"):
        HazardCurve.from_csv("/dev/zero", im="pga")
    big = tmp_path / "big.csv"
    with open(big, "wb") as f:  # sparse: no disk used
        f.truncate(2**30)
    with pytest.raises(ValueError, match=r"big\.csv.*1\.02e\+03 MiB, more than the"):
        HazardCurve.from_csv(big, im="pga")


@pytest.mark.parametrize("command", ["validate", "run"])
def test_a_study_whose_hazard_file_is_a_fifo_or_a_device_is_one_line(tmp_path, command):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    for name, what in (("pipe.csv", "FIFO"), ("/dev/zero", "character device")):
        (tmp_path / "s.toml").write_text(_study_text(name))
        args = [tmp_path / "s.toml"] + (["--out", tmp_path / "c.zarr"] * (command == "run"))
        with time_limit(120, f"rockstudy {command} of a study on {name}"):  # a read would hang
            code, _, err = cli(command, *args)
        assert code != 0 and "Traceback" not in err, err
        assert "hazard.file" in err and what in err, err
        assert not (tmp_path / "c.zarr").exists()


# ------------------------------------------------------------ no file content in messages


def _message(path, **kw):
    with pytest.raises(ValueError) as err:
        HazardCurve.from_csv(path, **kw)
    text = str(err.value)
    assert SECRET not in text and "root" not in text and "\n" not in text, text
    return text


def test_two_column_errors_name_the_line_not_its_content(tmp_path):
    path = tmp_path / "passwd"
    path.write_text(f"{SECRET}\ndaemon:x:1:1:daemon:/usr/sbin\n")
    assert "line 2" in _message(path, im="pga")
    path.write_text(f"0.1, 1e-2\n\n{SECRET}\n")
    assert "line 3" in _message(path, im="pga")
    path.write_text(f"0.1, 1e-2, 5\n{SECRET}\n")
    assert "line 1" in _message(path, im="pga")
    path.write_text(f"{SECRET} g, rate\n0.1, 1e-2\n0.2, 1e-3\n")  # a header naming a unit
    assert "line 1" in _message(path, im="pga", units="m/s^2")


@pytest.mark.parametrize(
    ("text", "line"),
    [
        (f"# investigation_time=1.0 {SECRET}\nlon,lat,poe-0.1\n0,0,0.1\n", "line 1"),
        (f"# investigation_time=1.0, imt='{SECRET}'\nlon,lat,poe-0.1\n0,0,0.1\n", "line 1"),
        (f"# investigation_time=1.0, imt='PGA'\nlon,lat,{SECRET}\n0,0,0.1\n", "line 2"),
        (f"# investigation_time=1.0, imt='PGA'\nlon,lat,poe-0.1,poe-0.2\n0,0,{SECRET}\n", "line 3"),
        ("# investigation_time=1.0, imt='PGA'\nlon,lat,poe-0.1,poe-0.2\n0,0,0.5,1.0\n", "line 3"),
    ],
)
def test_openquake_errors_name_the_line_not_its_content(tmp_path, text, line):
    path = tmp_path / "h.csv"
    path.write_text(text)
    assert line in _message(path)


def test_a_study_hazard_file_is_never_quoted(tmp_path):
    (tmp_path / "passwd").write_text(f"{SECRET}\ndaemon:x:1:1:daemon:/usr/sbin\n")
    found = "\n".join(_problems(tmp_path, _study_text("passwd")))
    assert "hazard.file" in found and "line 2" in found and "daemon" not in found, found


# ----------------------------------------------------------- certain and impossible poe


@pytest.mark.parametrize(
    ("poe", "says"), [(1.0, "every level has poe 1"), (0.0, "every level has poe 0")]
)
def test_a_curve_of_poe_1_or_0_everywhere_is_one_clear_line(tmp_path, poe, says):
    path = _openquake(tmp_path / "h.csv", "PGA", [poe] * 3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning leaks before the error
        text = _message(path)
    assert says in text and "site 0" in text and "array" not in text, text


# ---------------------------------------------------------- strings and booleans, ranges


def _file_with_two_sites(tmp_path):
    path = tmp_path / "two.csv"
    path.write_text(
        "# investigation_time=1.0, imt='PGA'\nlon,lat,poe-0.1,poe-0.2\n0,0,0.5,0.1\n1,1,0.4,0.1\n"
    )
    return path


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: HazardCurve("pga", ["0.05", "0.1"], [1e-2, 1e-3]), "levels"),
        (lambda: HazardCurve("pga", [True, 2.0], [1e-2, 1e-3]), "levels"),
        (lambda: HazardCurve("pga", [0.05, 0.1], [1e-2, "1e-3"]), "rates"),
        (lambda: HazardCurve("pga", [0.05, 0.1], [np.True_, 1e-3]), "rates"),
        (lambda: HazardCurve("sa", [0.05, 0.1], [1e-2, 1e-3], period="1.0"), "period"),
        (lambda: HazardCurve("sa", [0.05, 0.1], [1e-2, 1e-3], period=True), "period"),
        (lambda: HazardCurve.power_law("2e-4", 2.3), "k0"),
        (lambda: HazardCurve.power_law(2e-4, True), "k"),
        (lambda: annual_rate("0.3", 0.4, POWER), "median"),
        (lambda: annual_rate(True, 0.4, POWER), "median"),
        (lambda: annual_rate(0.3, [0.4, False], POWER), "dispersion"),
        (lambda: annual_rate(0.3, 0.4, POWER, threshold="0.1"), "threshold"),
        (lambda: rate_deaggregation(0.3, "0.4", POWER), "dispersion"),
        (lambda: probability_in("50", 1e-3), "years"),
        (lambda: probability_in(True, 1e-3), "years"),
        (lambda: probability_in(50, [1e-3, True]), "rate"),
        (lambda: POWER.rate("0.3"), "x"),
        (lambda: POWER.rate([0.3, True]), "x"),
    ],
)
def test_strings_and_booleans_are_not_numbers(call, name):
    with pytest.raises((TypeError, ValueError), match=f"^{name} must be a number"):
        call()


@pytest.mark.parametrize("site", ["0", True, 0.0, -1, 2])
def test_site_is_a_whole_number_of_the_file(tmp_path, site):
    path = _file_with_two_sites(tmp_path)
    with pytest.raises((TypeError, ValueError), match=r"^site must be a whole number in \[0, 1\]"):
        HazardCurve.from_csv(path, site=site)
    assert HazardCurve.from_csv(path, site=np.int64(1)).rates[0] == pytest.approx(-math.log(0.6))


def test_the_rate_of_a_level_outside_the_curve_s_domain_is_refused():
    for x in (0.0, -0.3, np.nan):
        with pytest.raises(ValueError, match="^x must be > 0"):
            POWER.rate(x)
    assert POWER.rate(0.3) == pytest.approx(2e-4 * 0.3**-2.3, rel=1e-12)
    assert POWER.rate(np.inf) == 0.0  # the limit of k0 x^-k
    # 2e-4 (1e-300)^-2.3 = 2e686 /yr: beyond float64, refused without a warning first
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match="^x: the rate of exceeding 1e-300 g is beyond"):
            POWER.rate(1e-300)
        with pytest.raises(ValueError, match="^annual_rate: .*beyond floating point"):
            annual_rate(0.3, 0.4, POWER, threshold=1e-300)


# ------------------------------------------------------------------- what overflows


def test_a_dispersion_beyond_its_range_is_refused():
    with pytest.raises(ValueError, match=r"^dispersion must be finite and in \[0, 10\]"):
        annual_rate(0.3, 50.0, POWER)
    assert annual_rate(0.3, 10.0, HazardCurve.power_law(2e-4, 0.5, units="g")) == pytest.approx(
        2e-4 * 0.3**-0.5 * math.exp(0.5 * 25.0), rel=1e-10
    )


@pytest.mark.parametrize(
    ("median", "beta", "k"),
    [(1e-300, 0.35, 2.3), (0.3, 8.0, 8.0)],
)
def test_a_rate_beyond_float64_is_refused_not_inf(median, beta, k):
    # Cornell's closed form: its logarithm is above ln(max float64) = 709.78
    assert math.log(2e-4) - k * math.log(median) + 0.5 * (k * beta) ** 2 > 709.8
    hazard = HazardCurve.power_law(2e-4, k, units="g")
    for call in (annual_rate, rate_deaggregation):
        with pytest.raises(ValueError, match="^annual_rate: .*beyond floating point"):
            call(median, beta, hazard)


def test_a_power_law_out_of_floating_point_names_k():
    with pytest.raises(ValueError, match=r"^k: the power law 0\.0002 x\^-1e\+06"):
        HazardCurve.power_law(2e-4, 1e6)
    with pytest.raises(ValueError, match=r"^k0: the power law 1e\+300 x\^-100"):
        HazardCurve.power_law(1e300, 100.0, levels=[0.5, 1.0])


def test_arguments_that_do_not_broadcast_are_named_with_their_shapes():
    with pytest.raises(
        ValueError, match=r"^median \(shape \(3,\)\) and dispersion \(shape \(2,\)\)"
    ):
        annual_rate([0.1, 0.2, 0.3], [0.1, 0.2], POWER)
    with pytest.raises(ValueError, match=r"threshold \(shape \(2,\)\)"):
        annual_rate([0.1, 0.2, 0.3], 0.2, POWER, threshold=[0.01, 0.02])
    with pytest.raises(ValueError, match=r"^years \(shape \(2,\)\) and rate \(shape \(3,\)\)"):
        probability_in([1.0, 2.0], [1e-3, 1e-2, 1e-1])


# ------------------------------------------------------------------ object_risk's counts


def _ida(n_rec=6):
    cap = np.geomspace(0.2, 0.6, n_rec)[:, None]
    return xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, G_UNIT)),
            "capacity_scale": (("record", "structure"), cap),
            "capacity_scale_lower": (("record", "structure"), cap / 1.001),
            "censored": (("record", "structure"), np.zeros(cap.shape, bool)),
            "status": (("record", "structure"), np.zeros(cap.shape, int)),
        },
        coords={"structure": ["Statue"]},
        attrs={"design": "ida", "im": "pga"},
    )


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"n_boot": 10**9}, r"^n_boot must be a whole number in \[0, 10000\]"),
        ({"n_boot": -1}, r"^n_boot must be a whole number in \[0, 10000\]"),
        ({"n_boot": True}, "^n_boot must be a whole number"),
        ({"min_overturning": -3}, "^min_overturning must be a whole number >= 1"),
        ({"min_overturning": "5"}, "^min_overturning must be a whole number"),
        ({"min_overturning": 2.5}, "^min_overturning must be a whole number"),
        ({"seed": -1}, "^seed must be a whole number >= 0"),
        ({"seed": "0"}, "^seed must be a whole number"),
        ({"years": "50"}, "^years must be a number"),
        ({"years": 1e7}, r"^years must lie in \(0, 1e\+06\]"),
    ],
)
def test_object_risk_counts_and_years_have_the_study_ranges(kw, match):
    t0 = time.time()
    with pytest.raises((TypeError, ValueError), match=match):
        object_risk(_ida(), POWER, **kw)
    assert time.time() - t0 < 10.0


# ------------------------------------------------------- the contact check's arguments


@pytest.mark.parametrize("friction", ["0.5", True, [0.5, "x"], None])
def test_the_friction_of_the_contact_check_is_a_number(friction):
    import rockstudy.study  # noqa: F401 - registers ds.rocking

    ds = _ida().assign(
        friction_demand=(("record", "structure"), np.linspace(0.1, 0.9, 6)[:, None]),
        lift_off=(("record", "structure"), np.zeros((6, 1), int)),
    )
    # the oracle: the demands above 0.5 flagged, counted by hand
    assert int(ds.rocking.contact(0.5).sum()) == 3
    if friction is None:  # no study, no friction: refused as before
        with pytest.raises(ValueError, match="friction is required"):
            ds.rocking.contact()
        return
    with pytest.raises((TypeError, ValueError), match="^friction must be a number"):
        ds.rocking.contact(friction)


@pytest.mark.parametrize("contact", ["yes", 1])
def test_contact_of_the_record_designs_is_true_or_false(contact):
    from rockstudy.motions import Record
    from rockstudy.structures import Block
    from rockstudy.study.designs.records import (
        cloud,
        incremental_dynamic_analysis,
        multiple_stripes,
    )

    record = Record(np.sin(2 * np.pi * np.arange(201) * 0.01), dt=0.01)
    block = [Block(0.2, 0.6)]
    calls = (
        lambda: incremental_dynamic_analysis(record, block, contact=contact),
        lambda: multiple_stripes(record, block, [1.0], contact=contact),
        lambda: cloud(record, block, contact=contact),
    )
    for call in calls:
        with pytest.raises(TypeError, match="^contact must be True or False"):
            call()


@pytest.mark.parametrize("seed", [-1, "0", True, 1.0])
def test_the_seed_of_every_bootstrap_is_a_whole_number(seed):
    from rockstudy.study.analysis import record_fragility, sampled

    samples = xr.Dataset(
        {"im": ("sample", np.arange(1.0, 13.0)), "overturned": ("sample", np.arange(12) % 3 == 0)}
    )
    calls = (
        lambda: record_fragility.ida_fragility(_ida(), n_boot=2, seed=seed),
        lambda: sampled.fragility(samples, "im", n_boot=2, seed=seed),
    )
    for call in calls:
        with pytest.raises(ValueError, match="^seed must be a whole number >= 0"):
            call()
    table = record_fragility.ida_fragility(_ida(), n_boot=2, seed=3)
    assert np.isfinite(np.asarray(table["theta"], float)).all()


# ------------------------------------------------------------------ units of a hazard curve


def _site_curve():
    """The shipped synthetic site's PGA curve [g] and its 475-year PGA, found here by the
    log-log interpolation of the tabulated points (the oracle of the bounds below)."""
    data = np.loadtxt(DATA / "hazard" / "site_pga.csv", delimiter=",", skiprows=2)
    x, rate = data[:, 0], data[:, 1]
    x475 = float(np.exp(np.interp(np.log(1 / 475), np.log(rate[::-1]), np.log(x[::-1]))))
    return x, rate, x475


def test_a_curve_in_m_s2_read_as_g_is_refused_naming_units(tmp_path):
    """The site's curve written in m/s^2 (levels up to 9.8, no header) and read as g would
    put its 475-year PGA at 9.8 times the site's, 2.4 g, above any site's (2 g): refused,
    naming units, in Python and in a study; read in m/s^2 it is the site's curve."""
    x, rate, x475 = _site_curve()
    keep = x * G_UNIT <= 9.81
    path = tmp_path / "site_ms2.csv"
    np.savetxt(path, np.column_stack([x[keep] * G_UNIT, rate[keep]]), delimiter=",")
    assert x475 * G_UNIT > 2.0  # the premise: read as g, beyond the bound
    with pytest.raises(ValueError, match=r"^units: the curve reaches its 475-year rate"):
        HazardCurve.from_csv(path, im="pga", units="g")
    curve = HazardCurve.from_csv(path, im="pga", units="m/s^2")
    assert curve.to_units("g").rate(x475) == pytest.approx(1 / 475, rel=1e-9)
    hazard = f'[hazard]\nkind = "file"\nfile = "{path}"\nim = "pga"\nunits = "g"'
    text = STUDY.format(records=DATA / "records", hazard=hazard)
    with pytest.raises(spec.StudyError) as err:
        spec.validate_text(text, base_dir=tmp_path)
    assert any(p.startswith("hazard.units: the curve reaches") for p in err.value.problems)


def test_a_curve_whose_475_year_level_few_sites_reach_is_warned(tmp_path):
    """Between the warning and the refusal bounds (1.2 to 2 g for a PGA), a UnitsWarning."""
    x, rate, x475 = _site_curve()
    factor = 1.5 / x475  # the site's curve stretched to a 475-year PGA of 1.5 g
    keep = x * factor <= 9.0
    with pytest.warns(UnitsWarning, match="475-year"):
        curve = HazardCurve("pga", x[keep] * factor, rate[keep], units="g")
    assert curve.rate(1.5) == pytest.approx(1 / 475, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        HazardCurve("pga", x, rate, units="g")  # the site itself: no word


def test_a_power_law_of_an_acceleration_needs_its_units():
    """k0 is the rate at x = 1 in the units of x: without them the curve is refused, naming
    units; a measure of one unit (a duration) needs none."""
    with pytest.raises(ValueError, match=r"^units: a power law of 'pga' needs the units"):
        HazardCurve.power_law(2e-4, 2.3, im="pga")
    g, si = (HazardCurve.power_law(2e-4, 2.3, im="pga", units=u) for u in ("g", "m/s^2"))
    assert g.to_si().rate(3.0) / si.rate(3.0) == pytest.approx(G_UNIT**2.3, rel=1e-12)
    HazardCurve.power_law(1.0, 1.0, im="significant_duration")


def test_a_curve_in_g_read_as_m_s2_is_noted_against_the_records(tmp_path):
    """The site's curve in g read as m/s^2 reads 9.8 times low, which its own numbers cannot
    show; the shipped records' own PGAs then lie beyond its million-year level (their rate on
    it, computed here by log-log interpolation, is below 1e-6): validate notes hazard.units,
    and object_risk warns; read in g, neither says a word."""
    x, rate, _ = _site_curve()
    path = tmp_path / "site_plain.csv"
    np.savetxt(path, np.column_stack([x, rate]), delimiter=",")  # no header: units unstated
    from rockstudy.motions import load_suite

    records = load_suite(sorted((DATA / "records").glob("NF0[12]*_H.AT2")))
    pga = np.array([r.peak for r in records])  # [m/s^2]
    wrong = np.exp(np.interp(np.log(pga), np.log(x), np.log(rate)))  # x read in m/s^2
    assert np.median(wrong) < 1e-6 or pga.min() > x[-1]  # the premise (beyond its levels)
    notes = {}
    for units in ("m/s^2", "g"):
        hazard = f'[hazard]\nkind = "file"\nfile = "{path}"\nim = "pga"\nunits = "{units}"'
        study = spec.validate_text(STUDY.format(records=DATA / "records", hazard=hazard))
        notes[units] = [n for n in study.notes if n.startswith("hazard.units:")]
    assert len(notes["m/s^2"]) == 1 and "million-year level" in notes["m/s^2"][0]
    assert notes["g"] == []
    import rockstudy as rs
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    ds = incremental_dynamic_analysis(records, {"A": rs.Block(0.8, 0.25)}, step=0.1, scan=0)
    with pytest.warns(UnitsWarning, match="million-year"):
        object_risk(ds, HazardCurve.from_csv(path, im="pga", units="m/s^2"), n_boot=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnitsWarning)
        object_risk(ds, HazardCurve.from_csv(path, im="pga", units="g"), n_boot=0)
