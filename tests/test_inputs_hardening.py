"""Inputs that are not what they should be -- an objects CSV of the wrong shape or of another
kind of file, a scheduler file that is a pipe or a device, a registered measure that returns
nonsense, API arguments out of the study file's ranges -- are refused in one line naming the
file (and line) or the argument and what was expected, never the contents of a file.
Oracles: the documented ranges and file rules, and the messages' own promises (no file
content, no traceback)."""

from pathlib import Path

import pytest
import test_objects

from rockstudy.study import StudyError, load_study

suite = test_objects.suite  # a folder of one small record (fixture)
STUDY_OBJECTS = test_objects.STUDY_OBJECTS


def _objects_problem(tmp_path, suite, content: bytes, file="objects.csv"):
    """The one problem of a study whose objects CSV holds ``content``."""
    if content is not None:
        (tmp_path / file).write_bytes(content)
    path = tmp_path / "study.toml"
    path.write_text(STUDY_OBJECTS.format(objects=f"file = {file!r}", folder=suite))
    with pytest.raises(StudyError) as err:
        load_study(path)
    problems = [p for p in err.value.problems if p.startswith("structure")]
    assert len(problems) == 1, err.value.problems
    assert "\n" not in problems[0]
    return problems[0]


@pytest.mark.parametrize(
    ("content", "line"),
    [
        (b"name,width,height\nA,0.4,2.0\nZ,0.3,1.2,,9\n", 3),  # longer than the header
        (b"name,width,height\nZ,0.3,1.2,,9\nA,0.4,2.0\n", 2),  # the long row first
        (b"name,width,height,\nA,0.4,2.0,7\n", 2),  # a cell under a column without a name
        (b"name,width,height\nA,0.4,2.0\rB,0.5,2.0\n", 2),  # a carriage return alone
        (b'name,width,height\n"A,0.4,2.0\nB,0.5,2.0\n', 3),  # a quote left open
    ],
)
def test_objects_csv_of_the_wrong_shape_names_the_line(tmp_path, suite, content, line):
    text = _objects_problem(tmp_path, suite, content)
    assert text.startswith("structure.file:") and "objects.csv" in text
    assert f"line {line}:" in text
    assert "0.3" not in text and "1.2" not in text and "0.4" not in text  # no cell quoted


def test_objects_csv_trailing_empty_cells_are_nothing(tmp_path, suite):
    """Spreadsheets end rows with empty cells: they carry nothing and are no error."""
    (tmp_path / "objects.csv").write_text("name,width,height,\nA,0.4,2.0,\nB,0.5,2.5,,\n")
    path = tmp_path / "study.toml"
    path.write_text(STUDY_OBJECTS.format(objects='file = "objects.csv"', folder=suite))
    study = load_study(path)
    got = [(o.name, o.width, o.height) for o in study.structure.objects]
    assert got == [("A", 0.4, 2.0), ("B", 0.5, 2.5)]


def test_objects_file_of_another_kind_is_named_not_quoted(tmp_path, suite):
    passwd = b"root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n"
    text = _objects_problem(tmp_path, suite, passwd, file="passwd")
    assert "passwd" in text and "line 1:" in text
    assert "root:" not in text and "bash" not in text and "daemon" not in text
    binary = bytes(range(1, 256)) * 2  # no NUL: read as latin-1 text
    text = _objects_problem(tmp_path, suite, binary, file="blob.csv")
    assert "blob.csv" in text and "line 2:" in text
    assert not any(chr(b) in text for b in range(0x80, 0x100))
    assert "\x01" not in text and "\x7f" not in text
    text = _objects_problem(tmp_path, suite, b"name,colour\nA,red\n")
    assert "line 1: column 2 of the header" in text and "red" not in text


# ------------------------------------------------------------------------------ scheduler files

import os  # noqa: E402
import time  # noqa: E402

from test_cli_errors import run_on_scheduler_file  # noqa: E402
from test_store_safety import write_study  # noqa: E402


@pytest.mark.parametrize("kind", ["fifo", "device", "large"])
def test_a_scheduler_file_that_is_no_file_is_one_line_in_time(tmp_path, kind):
    """A pipe would be read without end, a device or a huge file fill the memory."""
    study = write_study(tmp_path, n=20)
    sched = tmp_path / "sched.json"
    if kind == "fifo":
        os.mkfifo(sched)
    elif kind == "device":
        sched = Path("/dev/zero")
    else:
        sched.write_text('{"address": "tcp://127.0.0.1:9", "pad": "' + "x" * 2**20 + '"}')
    out = tmp_path / "c.zarr"
    t0 = time.time()
    line = run_on_scheduler_file(study, out, sched, timeout=90)
    expect = {"fifo": "a FIFO", "device": "a character device", "large": "MiB allowed"}[kind]
    assert str(sched) in line and expect in line and "not a dask scheduler file" in line
    assert not out.exists()
    assert time.time() - t0 < 60  # the start-up; no wait on the pipe


# ------------------------------------------------------------------------------ registered measures

import math  # noqa: E402

import numpy as np  # noqa: E402

from rockstudy.motions import Record, measures, register_measure  # noqa: E402


def _raises(record):
    raise RuntimeError("no\nluck")


@pytest.mark.parametrize(
    ("function", "says"),
    [
        (lambda r: math.nan, "is nan"),
        (lambda r: math.inf, "is inf"),
        (lambda r: -0.5, "is -0.5"),
        (lambda r: np.float64(-1e-3), "is -0.001"),
        (_raises, "failed (RuntimeError: no luck)"),
    ],
)
def test_a_measure_that_is_no_finite_number_on_a_record_is_not_registered(function, says):
    with pytest.raises(ValueError) as err:
        register_measure("odd_one", function, unit="m", power=1)
    text = str(err.value)
    assert "'odd_one'" in text and says in text and "not registered" in text
    assert "\n" not in text
    assert "odd_one" not in measures.MEASURES


def test_a_measure_that_fails_on_one_record_is_named_where_that_record_is_measured():
    """A measure may pass the probe and fail on another record: ValueError naming the
    measure and the record there, and nothing else is changed."""

    def short_only(record):
        if record.duration > 6.0:
            raise ArithmeticError("too long")
        return record.duration

    register_measure("short_only", short_only, unit="s", power=0)
    try:
        short = Record(np.sin(np.arange(300) * 0.1), dt=0.01, name="short")
        long = Record(np.sin(np.arange(900) * 0.1), dt=0.01, name="long")
        assert short.intensity_measures()["short_only"] == pytest.approx(short.duration)
        with pytest.raises(ValueError, match="'short_only' of the record 'long' failed"):
            long.intensity_measures()
        assert long.intensity_measure("pga") == pytest.approx(np.max(np.abs(long.acceleration)))
    finally:
        measures.unregister_measure("short_only")
    assert "short_only" not in long.intensity_measures()  # the process goes on without it
