"""Inputs that are not what they should be -- an objects CSV of the wrong shape or of another
kind of file, a scheduler file that is a pipe or a device, a registered measure that returns
nonsense, API arguments out of the study file's ranges -- are refused in one line naming the
file (and line) or the argument and what was expected, never the contents of a file.
Oracles: the documented ranges and file rules, and the messages' own promises (no file
content, no traceback)."""

import logging
import math
import os
import resource
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from _helpers import (
    K0,
    ROCKSTUDY,
    STUDY_OBJECTS,
    K,
    lognormal_sample,
    one_error_line,
    pga_ida,
    run_on_scheduler_file,
    write_study,
    write_two_records,
)

import rockstudy as rs
from rockstudy import risk
from rockstudy.motions import HalfSinePulse, Record, measures, register_measure
from rockstudy.study import StudyError, load_study, run_study
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.designs import records as rd
from rockstudy.study.running import runner, store
from rockstudy.study.running.store import open_result
from rockstudy.study.spec.schema import MAX_FRICTION

# ------------------------------------------------------------------------------ objects CSV files


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    """A folder of two small synthetic records."""
    return write_two_records(tmp_path_factory.mktemp("records"))


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
    """Spreadsheets end rows with empty cells, and may begin the file with a byte-order mark:
    they carry nothing and are no error."""
    text = "\ufeffname,width,height,\r\nA,0.4,2.0,\r\nB,0.5,2.5,,\r\n"
    (tmp_path / "objects.csv").write_bytes(text.encode("utf-8"))
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
    line = run_on_scheduler_file(study, out, sched)
    expect = {"fifo": "a FIFO", "device": "a character device", "large": "MiB allowed"}[kind]
    assert str(sched) in line and expect in line and "not a dask scheduler file" in line
    assert not out.exists()
    assert time.time() - t0 < 60  # the start-up; no wait on the pipe


# ------------------------------------------------------------------------------ registered measures


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


# ------------------------------------------------------------------------------ API arguments


BLOCK = rs.Block(half_diagonal=1.0, slenderness=0.2)
PULSE = HalfSinePulse(amplitude=3.0, period=0.5)


@pytest.mark.parametrize("mu", [1e9, 10.5, 0.0, -1.0, math.inf, math.nan])
def test_simulate_takes_the_friction_range_of_a_study(mu):
    with pytest.raises(ValueError, match=r"friction must lie in \(0, 10\]"):
        rs.simulate(BLOCK, PULSE, friction=mu)


def test_simulate_takes_the_largest_friction_of_a_study():
    r = rs.simulate(BLOCK, PULSE, friction=MAX_FRICTION)
    assert r.friction_demand is not None
    assert MAX_FRICTION == 10.0  # the documented bound of both


@pytest.mark.parametrize("value", [-3, 0, 2.5, True, "5", None])
def test_object_risk_min_overturning_is_a_whole_number_of_records(value):
    cap = np.column_stack([lognormal_sample(0.4, 0.5, 10, 10)])
    hazard = risk.HazardCurve.power_law(K0, K, im="pga", units="g")
    with pytest.raises(ValueError, match="min_overturning must be a whole number >= 1"):
        object_risk(pga_ida(cap), hazard, n_boot=0, min_overturning=value)


def test_object_names_with_nul_are_refused_in_study_files(tmp_path, suite):
    path = tmp_path / "nul.toml"
    objects = 'objects = [{ name = "A\\u0000B", width = 0.4, height = 2.0 }]'
    path.write_text(STUDY_OBJECTS.format(objects=objects, folder=suite))
    with pytest.raises(StudyError) as err:
        load_study(path)
    assert err.value.problems == [
        "structure.objects[0] ('A\\x00B').name: must be a name: not blank, no NUL character"
    ]


def test_object_names_with_nul_are_refused_by_the_designs():
    record = Record(np.sin(np.arange(300) * 0.1), dt=0.01, name="r")
    with pytest.raises(ValueError, match="object 1 has the name 'B\\\\x00'"):
        rd.multiple_stripes([record], {"A": BLOCK, "B\0": BLOCK}, [2.0])


@pytest.mark.parametrize(
    ("kwargs", "says"),
    [
        ({"ax": "axes"}, "ax must be a matplotlib Axes (or None), got str"),
        ({"structure": 5}, "structure must be a name (a str) or None, got int"),
        ({"structure": 5, "motion": "x"}, "structure must be a name (a str) or None, got int"),
        ({"motion": ["x"]}, "motion must be a name (a str) or None, got list"),
    ],
)
def test_plot_refuses_arguments_of_the_wrong_type_before_drawing(kwargs, says):
    import matplotlib.pyplot as plt

    result = rs.simulate(BLOCK, PULSE)
    before = plt.get_fignums()
    with pytest.raises(TypeError) as err:
        result.plot(**kwargs)
    assert str(err.value) == says
    assert plt.get_fignums() == before  # no figure left half-drawn


@pytest.mark.parametrize(
    ("study", "says"),
    [
        ("not json {", "it is not JSON"),
        ("", "it is not JSON"),
        ('{"name": "x"}', "it is JSON but no study"),
        (b"\xff\xfe", "it is not JSON"),
    ],
)
def test_the_accessor_names_a_study_attribute_that_is_no_study(study, says):
    import rockstudy.study  # noqa: F401 - registers ds.rocking

    ds = xr.Dataset({"x": ("sample", [1.0])}, attrs={"study": study})
    for read in (lambda: ds.rocking.study, lambda: ds.rocking.kind):
        with pytest.raises(ValueError) as err:
            read()
        text = str(err.value)
        assert text.startswith("ds.rocking.study: attrs['study'] must be the JSON text")
        assert says in text and "Expecting" not in text and "\n" not in text


# ------------------------------------------------------------------------------ out of memory


def _limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (1_000_000_000, 1_000_000_000))


def test_out_of_memory_is_one_line_and_leaves_no_half_made_store(tmp_path):
    """Under a 1 GB address space the run cannot start its threads or workers."""
    study = write_study(tmp_path, n=60)
    out = tmp_path / "x.zarr"
    proc = subprocess.run(
        [ROCKSTUDY, "run", str(study), "--out", str(out), "--quiet"],
        capture_output=True, text=True, timeout=300, preexec_fn=_limit_memory,
    )  # fmt: skip
    assert proc.returncode == 1
    line = one_error_line(proc.stderr)
    assert "ran out of memory" in line and "__main__" not in line
    if out.exists():  # kept only if --resume continues it
        assert "continue with:" in line and store.read_marker(out)["template_complete"]
    else:
        assert "nothing was saved" in line


def test_an_event_loop_callback_out_of_memory_logs_no_traceback(caplog):
    """asyncio logs a callback's MemoryError itself (a cluster's thread out of memory); the
    command's own line says it, so that record is dropped and other errors still show."""
    from rockstudy import cli

    cli.main(["schema"])  # installs the filter
    log = logging.getLogger("asyncio")
    for exc in (MemoryError(), ValueError("a real bug")):
        try:
            raise exc
        except Exception:
            log.error("Exception in callback", exc_info=True)
    kinds = [r.exc_info[0] for r in caplog.records if r.name == "asyncio"]
    assert kinds == [ValueError]


def _read_or_empty(path) -> str:
    """The text of a /proc file, or '' if its process or thread has ended."""
    try:
        return Path(path).read_text()
    except OSError:
        return ""


def test_a_worker_killed_while_the_cluster_starts_is_one_line_without_script_advice(tmp_path):
    study = write_study(tmp_path, n=20)
    out = tmp_path / "y.zarr"
    proc = subprocess.Popen(
        [ROCKSTUDY, "run", str(study), "--out", str(out), "--quiet"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    killed, t0 = False, time.time()
    while not killed and proc.poll() is None and time.time() - t0 < 120:
        children = Path(f"/proc/{proc.pid}/task").glob("*/children")  # of every thread
        for pid in " ".join(_read_or_empty(f) for f in children).split():
            cmdline = _read_or_empty(Path(f"/proc/{pid}/cmdline"))
            if "spawn_main" in cmdline:  # a worker process, long before it has imported dask
                os.kill(int(pid), signal.SIGKILL)
                killed = True
        time.sleep(0.01)
    _, err = proc.communicate(timeout=300)
    assert killed and proc.returncode == 1, err
    line = one_error_line(err)
    assert "did not start" in line and "died" in line and "__main__" not in line
    assert "nothing was saved" in line and not out.exists()


def test_out_of_memory_after_a_chunk_keeps_a_store_that_resumes_whole(
    tmp_path, client, monkeypatch
):
    study = load_study(write_study(tmp_path, n=40, chunk=10))
    whole = tmp_path / "whole.zarr"
    run_study(study, whole, client=client, progress=False, netcdf=False)
    write, calls = store.ChunkWriter.write, []

    def write_then_fail(self, a, b, result):
        calls.append(a)
        if len(calls) == 2:
            raise MemoryError
        write(self, a, b, result)

    monkeypatch.setattr(store.ChunkWriter, "write", write_then_fail)
    out = tmp_path / "cut.zarr"
    with pytest.raises(runner.ResourceError, match="ran out of memory"):
        run_study(study, out, client=client, progress=False, netcdf=False)
    monkeypatch.setattr(store.ChunkWriter, "write", write)
    assert int((store.read_status(out) != 0).sum()) == 10  # the first chunk is kept
    report = run_study(study, out, client=client, progress=False, netcdf=False, resume=True)
    assert len(report.chunks_computed) == 3
    a, b = open_result(out).load(), open_result(whole).load()
    for name in ("max_rotation", "overturned", "n_impacts", "status"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


@pytest.mark.parametrize(
    ("text", "unguarded"),
    [
        ("run_study(study, 'c.zarr')\n", True),
        ("if __name__ == '__main__':\n    run_study(study, 'c.zarr')\n", False),
        ('if __name__=="__main__":\n    main()\n', False),
    ],
)
def test_the_script_advice_is_for_scripts_without_a_main_guard(
    tmp_path, monkeypatch, text, unguarded
):
    import sys
    import types

    script = tmp_path / "script.py"
    script.write_text(text)
    main = types.ModuleType("__main__")
    main.__file__ = str(script)
    monkeypatch.setitem(sys.modules, "__main__", main)
    assert runner._unguarded_script() is unguarded
