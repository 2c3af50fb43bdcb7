"""The record readers on small files the tests write themselves (no ../shared/records needed).

Both PEER ``.AT2`` header styles: the NGA one (``NPTS=   2048, DT=   .0066 SEC,``, with or
without filter information after it) and the older PEER strong-motion database one, whose
fourth line gives the two numbers first (``  3930    0.00500   NPTS, DT``). Values are
Fortran-style (``.1717907E-01``, ``-.4393325E-03``), five to a line, the last line short, with
trailing blanks, as in the distributed files. Two-column text: commas or blanks, ``#``
comments, and a first row of column names.
"""

import numpy as np
import pytest

from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.motions import Record

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
    np.testing.assert_allclose(Record.from_csv(path, units="cm/s2").acceleration, ACC / 100)
    with pytest.raises(ValueError, match="units"):
        Record.from_csv(path, units="gal")


def test_two_column_errors_name_the_problem(tmp_path):
    three = tmp_path / "three.csv"
    three.write_text("0,1,2\n0.1,1,2\n")
    with pytest.raises(ValueError, match="2 columns"):
        Record.from_csv(three)
    backwards = tmp_path / "backwards.csv"
    backwards.write_text("0,0.1\n0.02,0.2\n0.01,0.3\n")
    with pytest.raises(ValueError, match="time must be strictly increasing"):
        Record.from_csv(backwards)
