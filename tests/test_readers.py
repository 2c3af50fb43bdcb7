"""The record readers on small files the tests write themselves (no ../shared/records needed).

Both PEER ``.AT2`` header styles: the NGA one (``NPTS=   2048, DT=   .0066 SEC,``, with or
without filter information after it) and the older PEER strong-motion database one, whose
fourth line gives the two numbers first (``  3930    0.00500   NPTS, DT``). Values are
Fortran-style (``.1717907E-01``, ``-.4393325E-03``), five to a line, the last line short, with
trailing blanks, as in the distributed files. Two-column text: commas or blanks, ``#``
comments, and a first row of column names.
"""

import re
import warnings

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.motions import Record
from rockstudy.motions.records import UnitsError

VALUES_G = np.array(
    [0.01717907, 0.01723899, -0.0004393325, 0.0, -0.1250000, 0.3490000, -0.2, 0.0001096612]
)


def fortran(values):
    """Values as PEER writes them: ``.1717907E-01`` (no leading zero), 5 to a line."""

    def one(v):
        mantissa, exponent = f"{abs(v):.6E}".split("E")
        digits = mantissa.replace(".", "")
        e = int(exponent) + 1 if v != 0 else 0
        return f"{'-' if v < 0 else ' '}.{digits}E{e:+03d}".rjust(15)

    cells = [one(v) for v in values]
    return ["".join(cells[i : i + 5]) + "   " for i in range(0, len(cells), 5)]


NGA_HEADERS = {
    "plain": "NPTS=   {n}, DT=   .0050 SEC,                                             ",
    "filter": "NPTS=   {n}, DT=   .0050 SEC,   0 POLE @    30.00000 HZ,  -5 POLE @      .20000",
}


def write_at2(path, header_line, values=VALUES_G, units_line=None):
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "Test event, 1/1/2000, test station, 90",
        units_line or "ACCELERATION TIME SERIES IN UNITS OF G",
        header_line.format(n=len(values)),
        *fortran(values),
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def check(rec, values_g, dt):
    np.testing.assert_allclose(rec.acceleration, values_g * STANDARD_GRAVITY, rtol=1e-12, atol=0)
    assert rec.dt == pytest.approx(dt, rel=1e-12)
    assert rec.duration == pytest.approx((len(values_g) - 1) * dt, rel=1e-12)


def test_fortran_writer_writes_what_peer_writes():
    line = fortran([0.01717907, -0.0004393325])[0]
    assert line.split() == [".1717907E-01", "-.4393325E-03"]


@pytest.mark.parametrize("style", sorted(NGA_HEADERS))
def test_at2_nga_header(tmp_path, style):
    path = write_at2(tmp_path / "nga.AT2", NGA_HEADERS[style])
    rec = Record.from_at2(path)
    check(rec, VALUES_G, 0.005)
    assert rec.name == "nga"


def test_at2_older_header_numbers_first(tmp_path):
    lines = [
        "PACIFIC ENGINEERING AND ANALYSIS STRONG-MOTION DATA",
        " TEST EVENT 01/01/79, TEST STATION, 230",
        " ACCELERATION TIME HISTORY IN UNITS OF G",
        f" {len(VALUES_G)}    0.01000   NPTS, DT",
        *fortran(VALUES_G),
    ]
    path = tmp_path / "old.AT2"
    path.write_text("\n".join(lines) + "\n")
    check(Record.from_at2(path), VALUES_G, 0.01)


def test_at2_count_mismatch_and_units_are_refused(tmp_path):
    short = write_at2(tmp_path / "short.AT2", "NPTS=   {n}, DT=   .0050 SEC,", VALUES_G)
    text = short.read_text().replace(f"NPTS=   {len(VALUES_G)}", f"NPTS=   {len(VALUES_G) + 1}")
    short.write_text(text)
    with pytest.raises(ValueError, match="NPTS"):
        Record.from_at2(short)
    cms = write_at2(
        tmp_path / "cms.AT2",
        NGA_HEADERS["plain"],
        units_line="VELOCITY TIME SERIES IN UNITS OF CM/S",
    )
    with pytest.raises(ValueError, match="UNITS OF G"):
        Record.from_at2(cms)
    bad = write_at2(tmp_path / "bad.AT2", "no counts here")
    with pytest.raises(ValueError, match="NPTS and DT"):
        Record.from_at2(bad)


def test_units_other_than_g_on_at2_files_alone_are_refused_by_load_suite(tmp_path):
    """An .AT2 file is in g whatever units says: a suite of them alone with other units is
    refused (the setting would change nothing), and read in g with units g."""
    from rockstudy.motions import load_suite

    folder = tmp_path / "suite"
    folder.mkdir()
    write_at2(folder / "a.AT2", "NPTS=   {n}, DT=   .0050 SEC,", VALUES_G)
    for units in ("m/s2", "m/s^2", "cm/s2"):
        with pytest.raises(ValueError, match=rf"^units: '{re.escape(units)}' does not apply"):
            load_suite(folder, units=units)
    (rec,) = load_suite(folder, units="g")
    np.testing.assert_allclose(rec.acceleration, np.asarray(VALUES_G) * STANDARD_GRAVITY)


TIMES = np.array([0.0, 0.02, 0.04, 0.06, 0.08])
ACC = np.array([0.0, 0.1, -0.25, 0.349, -0.05])


@pytest.mark.parametrize(
    "text",
    [
        "time,acceleration\n" + "".join(f"{t},{a}\n" for t, a in zip(TIMES, ACC, strict=True)),
        "# El Centro-like test file\n# t [s]  a [g]\n"
        + "".join(f"{t:.7e} {a:.7e}\n" for t, a in zip(TIMES, ACC, strict=True)),
        '"t [s]", "a [g]"\n' + "".join(f"{t}, {a}\n" for t, a in zip(TIMES, ACC, strict=True)),
    ],
    ids=["csv-header-row", "blanks-comments", "quoted-header"],
)
def test_two_column_text(tmp_path, text):
    path = tmp_path / "rec.csv"
    path.write_text(text)
    rec = Record.from_csv(path, units="g")
    np.testing.assert_allclose(rec.acceleration, ACC * STANDARD_GRAVITY, rtol=1e-12)
    np.testing.assert_allclose(rec.time, TIMES, rtol=0, atol=1e-15)
    assert rec.dt == pytest.approx(0.02)


def test_two_column_units(tmp_path):
    path = tmp_path / "rec.txt"
    path.write_text("".join(f"{t} {a}\n" for t, a in zip(TIMES, ACC, strict=True)))
    np.testing.assert_allclose(Record.from_csv(path, units="m/s2").acceleration, ACC)
    path.write_text("".join(f"{t} {100 * a}\n" for t, a in zip(TIMES, ACC, strict=True)))
    np.testing.assert_allclose(Record.from_csv(path, units="cm/s2").acceleration, ACC)
    np.testing.assert_allclose(Record.from_csv(path, units="gal").acceleration, ACC)  # 1 cm/s^2
    with pytest.raises(ValueError, match="units"):
        Record.from_csv(path, units="cm/s")  # a velocity


def test_two_column_errors_name_the_problem(tmp_path):
    three = tmp_path / "three.csv"
    three.write_text("0,1,2\n0.1,1,2\n")
    with pytest.raises(ValueError, match="2 columns"):
        Record.from_csv(three)
    backwards = tmp_path / "backwards.csv"
    backwards.write_text("0,0.1\n0.02,0.2\n0.01,0.3\n")
    with pytest.raises(ValueError, match="time must be strictly increasing"):
        Record.from_csv(backwards)


# ------------------------------------------------------------------ extreme records (issue 26)

AT2_HEAD = "PEER NGA RECORD\nsynthetic\nACCELERATION TIME SERIES IN UNITS OF G\n"
WAVE = [0.01, -0.02, 0.03, -0.01, 0.0, 0.02]


def at2_file(path, values, dt):
    body = "\n".join(f"{v:.6E}" for v in values)
    path.write_text(AT2_HEAD + f"NPTS= {len(values)}, DT= {dt} SEC\n" + body + "\n")
    return path


@pytest.mark.parametrize(
    "dt, values, field",
    [
        ("1e300", WAVE, "duration"),  # 5e300 s: no record lasts that long
        ("1e-300", WAVE, "dt"),
        ("1e-9", WAVE, "dt"),  # the mean period's spectrum alone would need 256 GiB
        (".01", [*WAVE[:3], 1e300, *WAVE[3:]], "acceleration[3]"),
        (".01", [*WAVE[:2], 1e-311, *WAVE[2:]], "acceleration[2]"),  # subnormal
    ],
)
def test_extreme_at2_files_are_refused_naming_file_and_field(tmp_path, dt, values, field):
    path = at2_file(tmp_path / "x.AT2", values, dt)
    with pytest.raises(ValueError) as err:
        Record.from_at2(path)
    assert str(path) in str(err.value) and f"{field}" in str(err.value), str(err.value)


def test_a_time_column_reaching_the_largest_float_is_refused(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("0.0, 0.1\n0.01, 0.2\n1.7e308, 0.1\n")
    with pytest.raises(ValueError, match=r"t\.csv: duration: .*1\.7e\+308 s"):
        Record.from_csv(path)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(dt=1e308), "duration"),  # 2e308 s: inf
        (dict(dt="0.01"), "dt"),
        (dict(dt=True), "dt"),
        (dict(dt=0.01, vertical="yes"), "vertical"),
        (dict(time=[0.0, 1e-9, 2e-9]), "time"),
    ],
)
def test_record_constructor_refuses_naming_the_argument(kwargs, field):
    with pytest.raises(ValueError, match=rf"^{field}"):
        Record(np.array([0.1, -0.2, 0.1]), **kwargs)


def test_records_at_the_edges_of_the_ranges_still_read():
    """Not a refusal too many: a 1e6 g-free record at the 1 MHz step, and a peak of 1e7."""
    fine = Record(np.array([0.1, -0.2, 0.1]), dt=1e-6)
    assert fine.duration == pytest.approx(2e-6)
    big = Record(np.array([0.0, 1e7, -1e7]), dt=0.01)
    assert big.peak == 1e7
    with pytest.raises(ValueError, match="factor = 2"):
        big.scaled(2.0)


# ------------------------------------------------------------------ special files (issue 26 §5)


def _special(tmp_path, kind):
    """A good record file and, beside it, the special file ``kind``; returns its path."""
    import os

    at2_file(tmp_path / "good.AT2", WAVE, ".01")
    bad = tmp_path / "x.AT2"
    if kind == "fifo":
        os.mkfifo(bad)
    elif kind == "dev-zero":
        bad.symlink_to("/dev/zero")
    elif kind == "dangling":
        bad.symlink_to(tmp_path / "nowhere.AT2")
    else:
        bad.mkdir()
    return bad


WHAT = {
    "fifo": "FIFO",
    "dev-zero": "character device",
    "dangling": "dangling symbolic link",
    "folder": "folder",
}


@pytest.mark.parametrize("kind", sorted(WHAT))
@pytest.mark.parametrize("how", ["glob", "folder", "list"])
def test_a_suite_never_skips_a_special_file(tmp_path, kind, how):
    """A glob, a folder or a list that finds a FIFO, a link to /dev/zero, a dangling link or a
    folder named x.AT2 is refused, naming the path and what it is (it used to be skipped)."""
    from rockstudy.motions import load_suite

    bad = _special(tmp_path, kind)
    source = {"glob": str(tmp_path / "*.AT2"), "folder": tmp_path, "list": [bad]}[how]
    with pytest.raises(ValueError) as err:
        load_suite(source)
    assert str(bad) in str(err.value) and WHAT[kind] in str(err.value), str(err.value)


@pytest.mark.parametrize("kind", sorted(WHAT))
def test_validate_refuses_a_study_whose_glob_finds_a_special_file(tmp_path, kind):
    from rockstudy.study import StudyError, validate_text

    bad = _special(tmp_path, kind)
    text = (
        'name = "s"\nseed = 1\n[sampler]\nkind = "monte_carlo"\nn = 2\n[structure]\n'
        'kind = "block"\nhalf_diagonal = { dist = "uniform", low = 1.0, high = 2.0 }\n'
        'slenderness = 0.2\n[motion]\nkind = "record"\nfiles = "*.AT2"\nscale = 1.0\n'
    )
    with pytest.raises(StudyError) as err:
        validate_text(text, base_dir=tmp_path)
    message = str(err.value)
    assert "motion.files" in message and str(bad) in message and WHAT[kind] in message, message


@pytest.mark.parametrize("columns", [("time", "horizontal"), ("time", "horizontal", "vertical")])
def test_a_text_record_in_cm_s2_read_as_g_is_refused_naming_units(tmp_path, columns):
    """A record of 272 cm/s^2 read in the default units (g) would peak at 272 g: refused,
    naming units; read in cm/s2 it is 2.72 m/s^2."""
    t = np.arange(200) * 0.01
    a = 272.0 * np.sin(2 * np.pi * t)  # cm/s^2
    data = np.column_stack([t, a] + ([0.3 * a] if "vertical" in columns else []))
    path = tmp_path / "cms2.txt"
    np.savetxt(path, data)
    with pytest.raises(
        ValueError, match=r"units='g': its peak acceleration reads 272 g, beyond any ground motion"
    ):
        Record.from_csv(path, columns=columns)
    rec = Record.from_csv(path, units="cm/s2", columns=columns)
    assert np.max(np.abs(rec.acceleration)) == pytest.approx(2.72, rel=1e-3)
    a10 = np.column_stack([t, 9.99 * np.sin(2 * np.pi * t)])  # 9.99 g: strong, but read
    np.savetxt(path, a10)
    assert np.max(np.abs(Record.from_csv(path).acceleration)) <= 10 * STANDARD_GRAVITY


def test_a_suite_of_text_records_in_cm_s2_read_as_g_names_motion_units(tmp_path):
    """In a study file the refusal names motion.units, not the files (which were read)."""
    from rockstudy.study import StudyError, validate_text

    folder = tmp_path / "recs"
    folder.mkdir()
    t = np.arange(300) * 0.01
    np.savetxt(folder / "a.txt", np.column_stack([t, 272.0 * np.sin(2 * np.pi * t)]))
    study = (
        'name = "s"\nseed = 1\n[sampler]\nkind = "lhs"\nn = 4\n[structure]\nkind = "block"\n'
        'half_diagonal = { dist = "uniform", low = 0.5, high = 1.0 }\n'
        'slenderness = { dist = "uniform", low = 0.15, high = 0.3 }\n'
        '[motion]\nkind = "record"\nfiles = "recs"\nunits = "g"\n'
        'scale_to = { im = "pga_ratio", value = { dist = "grid", values = [1.0, 2.0] } }\n'
        '[design]\nkind = "stripes"\n'
    )
    with pytest.raises(StudyError) as err:
        validate_text(study, base_dir=tmp_path)
    assert "motion.units:" in str(err.value) and "272 g, beyond any ground motion" in str(err.value)
    validate_text(study.replace('units = "g"', 'units = "cm/s2"'), base_dir=tmp_path)


@pytest.mark.parametrize("columns", [("time", "horizontal"), ("time", "horizontal", "vertical")])
def test_a_text_record_in_g_read_as_cm_s2_is_refused_naming_units(tmp_path, columns):
    """El Centro's 0.35 g read as cm/s^2 would peak at 0.0036 m/s^2 (0.00036 g), weaker than
    any strong-motion record and than the uplift of any block: refused, naming units; a
    record that reads between 0.0005 g and 0.005 g is read with a UnitsWarning; in g it is
    3.4 m/s^2 and read without a word."""
    t = np.arange(300) * 0.01
    a = 0.349 * np.sin(2 * np.pi * t)  # g
    data = np.column_stack([t, a] + ([0.5 * a] if "vertical" in columns else []))
    path = tmp_path / "in_g.txt"
    np.savetxt(path, data)
    with pytest.raises(UnitsError, match=r"units='cm/s2': its peak acceleration reads 0.349 cm/s2"):
        Record.from_csv(path, units="cm/s2", columns=columns)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rec = Record.from_csv(path, units="g", columns=columns)
    assert np.max(np.abs(rec.acceleration)) == pytest.approx(0.349 * STANDARD_GRAVITY, rel=1e-3)
    weak = np.column_stack([t, 2.0 * np.sin(2 * np.pi * t)])  # 2 cm/s^2 = 0.002 g
    np.savetxt(path, weak)
    with pytest.warns(rs.UnitsWarning, match="units='cm/s2'"):
        rec = Record.from_csv(path, units="cm/s2")
    assert np.max(np.abs(rec.acceleration)) == pytest.approx(0.02, rel=1e-3)


def test_a_suite_of_text_records_in_g_read_as_cm_s2_names_motion_units(tmp_path):
    """validate refuses the weak reading as a problem of motion.units."""
    from rockstudy.study import StudyError, validate_text

    t = np.arange(300) * 0.01
    np.savetxt(tmp_path / "a.txt", np.column_stack([t, 0.349 * np.sin(2 * np.pi * t)]))
    study = (
        'name = "s"\nseed = 1\n[structure]\nkind = "objects"\n'
        'objects = [{ name = "A", width = 0.4, height = 1.6 }]\n'
        '[motion]\nkind = "record"\nfiles = "a.txt"\nunits = "cm/s2"\n[design]\nkind = "cloud"\n'
    )
    with pytest.raises(StudyError) as err:
        validate_text(study, base_dir=tmp_path)
    assert "motion.units:" in str(err.value) and "below any strong-motion record" in str(err.value)
    validate_text(study.replace('units = "cm/s2"', 'units = "g"'), base_dir=tmp_path)


def test_at2_trailer_fortran_exponents_and_text_among_the_samples(tmp_path):
    """A text line after the samples (END OF DATA) is a trailer, not values; Fortran D
    exponents are numbers; text among the samples is refused naming its line."""
    path = write_at2(tmp_path / "end.AT2", NGA_HEADERS["plain"])
    path.write_text(path.read_text() + "END OF DATA\n")
    check(Record.from_at2(path), VALUES_G, 0.005)
    fortran_d = write_at2(tmp_path / "d.AT2", NGA_HEADERS["plain"])
    text = fortran_d.read_text().splitlines()
    samples = [" ".join(f"{float(v):.7E}".replace("E", "D") for v in r.split()) for r in text[4:]]
    fortran_d.write_text("\n".join(text[:4] + samples) + "\n")
    np.testing.assert_allclose(
        Record.from_at2(fortran_d).acceleration, VALUES_G * STANDARD_GRAVITY, rtol=1e-7
    )
    among = write_at2(tmp_path / "among.AT2", NGA_HEADERS["plain"])
    lines = among.read_text().splitlines()
    lines.insert(6, "  some text 1.0")
    among.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"among.AT2: line 7 holds text where the samples"):
        Record.from_at2(among)
    extra = write_at2(tmp_path / "extra.AT2", NGA_HEADERS["plain"])
    extra.write_text(extra.read_text() + "END OF DATA 2\n")  # a number in it: not a trailer
    with pytest.raises(ValueError, match="line"):
        Record.from_at2(extra)
