"""The ``[hazard]`` section of a study file (issue 24 section 4). Oracles: the hazard files read
independently here (numpy on the two columns; the OpenQuake poe turned into rates by the
Poisson relation), the power law's formula, the sha256 of the file itself."""

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest
from _helpers import HAZARD_STUDY as STUDY
from _helpers import study_text

from rockstudy.study.running.store import input_hashes
from rockstudy.study.spec import schema as spec

DATA = Path(__file__).resolve().parents[1] / "data"


def _study(tmp_path, hazard):
    text = STUDY.format(records=DATA / "records", hazard=hazard)
    return spec.validate_text(text, base_dir=tmp_path)


def _problems(tmp_path, hazard, text=None):
    text = text or STUDY.format(records=DATA / "records", hazard=hazard)
    with pytest.raises(spec.StudyError) as err:
        spec.validate_text(text, base_dir=tmp_path)
    return "\n".join(err.value.problems)


def test_power_law_section(tmp_path):
    study = _study(
        tmp_path, '[hazard]\nkind = "power_law"\nk0 = 2e-4\nk = 2.3\nim = "pga"\nunits = "g"'
    )
    curve = study.hazard.curve()
    assert study.hazard.years == 50
    x = np.array([0.05, 0.3, 1.7])
    np.testing.assert_allclose(curve.rate(x), 2e-4 * x**-2.3, rtol=1e-12)
    assert curve.units == "g" and curve.im == "pga"


def test_two_column_file_relative_to_the_study_and_kept_in_the_stored_study(tmp_path):
    (tmp_path / "site.csv").write_bytes((DATA / "hazard" / "site_pga.csv").read_bytes())
    study = _study(
        tmp_path, '[hazard]\nkind = "file"\nfile = "site.csv"\nim = "pga"\nunits = "g"\nyears = 30'
    )
    table = np.loadtxt(DATA / "hazard" / "site_pga.csv", delimiter=",", skiprows=2)
    curve = study.hazard.curve()
    np.testing.assert_array_equal(curve.levels, table[:, 0])
    np.testing.assert_array_equal(curve.rates, table[:, 1])
    assert study.hazard.years == 30
    # the stored study (a result's attribute) holds the curve: no file needed to report it
    again = spec.Study.model_validate(json.loads(study.normalized())).hazard.curve()
    np.testing.assert_array_equal(again.rates, curve.rates)
    # and its file is hashed with the records
    hashes = input_hashes(study, tmp_path)
    assert hashes["site.csv"] == hashlib.sha256((tmp_path / "site.csv").read_bytes()).hexdigest()


def test_openquake_file(tmp_path):
    path = DATA / "hazard" / "site_pga_openquake.csv"
    study = _study(tmp_path, f'[hazard]\nkind = "file"\nfile = "{path}"\nim = "pga"')
    lines = path.read_text().splitlines()
    levels = np.array([float(c[4:]) for c in lines[1].split(",")[3:]])
    poe = np.array([float(c) for c in lines[2].split(",")[3:]])
    curve = study.hazard.curve()
    assert curve.units == "g"  # OpenQuake's unit of PGA
    np.testing.assert_allclose(curve.levels, levels, rtol=1e-15)
    np.testing.assert_allclose(curve.rates, -np.log1p(-poe) / 50.0, rtol=1e-12)


@pytest.mark.parametrize(
    "hazard, field",
    [
        ('kind = "power_law"\nk = 2.3\nim = "pga"', "hazard.k0"),
        ('kind = "power_law"\nk0 = -1.0\nk = 2.3\nim = "pga"', "hazard.k0"),
        ('kind = "power_law"\nk0 = 1e-4\nk = 2.3\nim = "pga"\nunits = "m/s"', "hazard.units"),
        ('kind = "power_law"\nk0 = 1e-4\nk = 2.3\nim = "duration"', "hazard.im"),
        (
            'kind = "power_law"\nk0 = 1e-4\nk = 2.3\nim = "sa"\nunits = "g"\nperiod = 1.0',
            "hazard.period",
        ),
        ('kind = "power_law"\nk0 = 1e-4\nk = 2.3\nim = "pga"\nyears = 0', "hazard.years"),
        ('kind = "power_law"\nk0 = 1e-4\nk = 2.3\nim = "pga"\nfile = "x.csv"', "hazard.file"),
        ('kind = "file"\nfile = "missing.csv"\nim = "pga"', "hazard.file"),
        ('kind = "file"\nfile = "x.csv"\nim = "pga"\nlevels = [1.0, 2.0]', "hazard.levels"),
        ('kind = "seismic"\nim = "pga"', "hazard.kind"),
    ],
)
def test_errors_name_the_field(tmp_path, hazard, field):
    text = _problems(tmp_path, "[hazard]\n" + hazard)
    assert field in text, text


def test_a_spectral_hazard_at_a_stored_period_is_taken(tmp_path):
    study = _study(
        tmp_path,
        '[hazard]\nkind = "power_law"\nk0 = 1e-4\nk = 2.0\nim = "sa"\nperiod = 0.5\nunits = "g"',
    )
    assert study.hazard.curve().period == 0.5


def test_monte_carlo_studies_refuse_a_hazard(tmp_path):

    text = (
        study_text()
        + '\n[hazard]\nkind = "power_law"\nk0 = 1e-4\nk = 2.0\nim = "pga"\nunits = "g"\n'
    )
    assert "hazard: applies to a record [design]" in _problems(tmp_path, None, text)


@pytest.mark.parametrize("units", ["G", "m/s"])
def test_a_bad_unit_of_a_hazard_file_is_the_units_field(tmp_path, units):
    """The file is readable and its unit is what is wrong: the error names hazard.units (not
    hazard.file) and lists only units of the measure."""
    site = (DATA / "hazard" / "site_pga.csv").as_posix()
    text = _problems(
        tmp_path, f'[hazard]\nkind = "file"\nfile = "{site}"\nim = "pga"\nunits = "{units}"'
    )
    assert "hazard.units" in text and "hazard.file" not in text, text
    assert "'s'" not in text and "'cm'" not in text, text  # no unit of time or length offered


def test_a_file_in_other_units_or_of_another_measure_is_refused_naming_the_field(tmp_path):
    """A curve in cm/s^2 (a neutral column name) declared in g reaches hundreds of g: refused
    as hazard.units; a column named for PGA read as PGV: refused as hazard.im; an OpenQuake
    PGA curve (in g) declared in m/s^2: hazard.units."""
    levels = np.geomspace(0.01, 2.0, 25) * 980.665  # cm/s^2
    rows = "".join(f"{x},{1e-3 * (x / 980.665) ** -2.3}\n" for x in levels)
    (tmp_path / "cms.csv").write_text("pga,annual_rate\n" + rows)
    hazard = '[hazard]\nkind = "file"\nfile = "cms.csv"\nim = "pga"\nunits = "{}"'
    text = _problems(tmp_path, hazard.format("g"))
    assert text.startswith("hazard.units: the levels reach 1961 g of pga, beyond any"), text
    assert _study(tmp_path, hazard.format("cm/s^2")).hazard.curve().units == "cm/s^2"
    (tmp_path / "g.csv").write_bytes((DATA / "hazard" / "site_pga.csv").read_bytes())
    text = _problems(tmp_path, '[hazard]\nkind = "file"\nfile = "g.csv"\nim = "pgv"\nunits = "m/s"')
    assert text.startswith("hazard.im: g.csv, line 2: the level column's name says a pga curve")
    oq = DATA / "hazard" / "site_pga_openquake.csv"
    text = _problems(
        tmp_path, f'[hazard]\nkind = "file"\nfile = "{oq}"\nim = "pga"\nunits = "m/s^2"'
    )
    assert text.startswith("hazard.units: OpenQuake writes the levels of PGA in g"), text


def test_a_bad_hazard_unit_does_not_hide_a_bad_motion_unit(tmp_path):
    """Both units wrong (.AT2 records are in g; the hazard file's column says g): both named."""
    site = (DATA / "hazard" / "site_pga.csv").as_posix()
    hazard = f'[hazard]\nkind = "file"\nfile = "{site}"\nim = "pga"\nunits = "m/s2"'
    text = STUDY.format(records=DATA / "records", hazard=hazard).replace(
        'kind = "record"\n', 'kind = "record"\nunits = "m/s2"\n'
    )
    found = _problems(tmp_path, None, text)
    assert "hazard.units: site_pga.csv, line 2: the level column's name states it in g" in found
    assert "motion.units: 'm/s2' does not apply to .AT2 files" in found, found
