"""Issue 26, section 4 (and 3, first bullet): each of these gives one clear line and a
non-zero exit, never a traceback, and leaves no half-made store.

The command runs in this process (``rockstudy.cli.main``), but for Ctrl-C while its modules
load, which needs a real process; the oracle is the contract itself: one line, its words, the
exit code and the files on disk.
"""

import json
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest
from _helpers import (
    ROOT,
    cli,
    finished_run,
    one_error_line,
    rockstudy_run,
    run_on_scheduler_file,
    tree,
    write_study,
)


@pytest.mark.parametrize("value", ["nan", "-1", "inf", "0", "soon"])
def test_timeout_must_be_finite_seconds(tmp_path, value):
    study = write_study(tmp_path, n=20)
    code, _, err = rockstudy_run(study, tmp_path / "c.zarr", "--timeout", value)
    assert code == 2
    assert "--timeout" in one_error_line(err)
    assert not (tmp_path / "c.zarr").exists()


@pytest.mark.parametrize("content", [None, "garbage\x00\x01", '{"address": 3}'])
def test_a_scheduler_file_missing_or_garbage_is_one_line_in_time(tmp_path, content):
    study = write_study(tmp_path, n=20)
    sched = tmp_path / "sched.json"
    if content is not None:
        sched.write_text(content)
    out = tmp_path / "c.zarr"
    t0 = time.time()
    line = run_on_scheduler_file(study, out, sched)
    assert str(sched) in line and ("does not exist" if content is None else "not a dask") in line
    assert "--resume" not in line
    assert not out.exists()  # no half-made store
    # 3 s and the start-up (up to a minute and more on a loaded machine), never a wait for the
    # file without end (the subprocess timeout of 150 s fails the test)
    assert time.time() - t0 < 120


def test_tls_without_certificates_is_one_line(tmp_path):
    study = write_study(tmp_path, n=20)
    out = tmp_path / "c.zarr"
    code, _, err = cli(
        "run", study, "--out", out, "--scheduler", "tls://127.0.0.1:9", "--timeout", "3", "--quiet"
    )
    assert code == 1
    line = one_error_line(err)
    assert "--tls-ca-file" in line and "certificates" in line
    assert not out.exists()


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return finished_run(tmp_path_factory.mktemp("errors"), n=20)


@pytest.mark.parametrize("marker", ["list", "folder"])
def test_a_marker_that_is_no_marker_is_one_line_without_resume_advice(finished, tmp_path, marker):
    study, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    (out / ".rockstudy").unlink()
    if marker == "list":
        (out / ".rockstudy").write_text(json.dumps([1, 2]))
    else:
        (out / ".rockstudy").mkdir()
    before = tree(out)
    for extra in (["--resume"], []):
        code, _, err = rockstudy_run(study, out, *extra)
        assert code == 2
        line = one_error_line(err)
        assert ".rockstudy" in line and "new --out" in line and "--resume" not in line
    assert tree(out) == before


def test_a_read_only_out_does_not_advise_resume(tmp_path, monkeypatch, capsys):
    """The folder cannot be made (a read-only file system): nothing was saved, nothing to
    resume. In process, since root writes into a folder whatever its mode."""
    from rockstudy.cli import main
    from rockstudy.study.running import store

    def read_only(path, *args):
        raise OSError(30, "Read-only file system", str(path))

    monkeypatch.setattr(store, "claim", read_only)
    study = write_study(tmp_path, n=20)
    code = main(["run", str(study), "--out", str(tmp_path / "c.zarr"), "--quiet"])
    assert code == 1
    line = one_error_line(capsys.readouterr().err)
    assert "Read-only file system" in line and "nothing was saved" in line
    assert "--resume" not in line


READY_THEN_MAIN = """
import sys
import rockstudy.cli as cli
command = cli._dispatch
def dispatch(args):  # says when main has begun, then loads the command's modules
    print("ready", flush=True)
    return command(args)
cli._dispatch = dispatch
sys.exit(cli.main(sys.argv[1:]))
"""


def _ctrl_c_as_in_a_terminal():
    """In the child before it starts: SIGINT at its default, as a shell starts a foreground
    job, whatever this test process inherited (a child inherits an ignored SIGINT, and
    Python then installs no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_while_the_modules_load_is_one_line(tmp_path):
    """Ctrl-C as soon as the command has begun, while it loads numpy, xarray, dask: one line,
    exit 130 (Python's own would be a KeyboardInterrupt traceback and -2). Before ``main``
    begins (the interpreter's start and ``import rockstudy.cli``, tens of ms) Python's own
    handling applies."""
    import sys

    study = write_study(tmp_path, n=20)
    proc = subprocess.Popen(
        [sys.executable, "-c", READY_THEN_MAIN, "run", str(study), "--out",
         str(tmp_path / "c.zarr"), "--quiet"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=_ctrl_c_as_in_a_terminal,
    )  # fmt: skip
    assert proc.stdout.readline() == "ready\n"
    proc.send_signal(signal.SIGINT)  # main has just started: the command's modules load
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    lines = [line for line in err.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and "interrupted" in lines[0] and "Traceback" not in err, err
    assert not (tmp_path / "c.zarr").exists()


DUPLICATE = """
name = "dup"
seed = 1

[sampler]
kind = "lhs"
n = 2

[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 1.0, high = 2.0 }}
slenderness = 0.2

[motion]
kind = "record"
files = [{files}]
units = "g"
scale_to = {{ im = "pga_ratio", value = {{ dist = "grid", values = [1.0, 2.0] }} }}

[design]
kind = "stripes"
periods = [0.5]
"""


def test_a_design_that_lists_a_file_twice_is_refused(tmp_path):
    """A record design runs each record once: the same file under two spellings is refused,
    naming the second entry and the first."""
    folder = tmp_path / "records"
    folder.mkdir()
    shipped = [shutil.copy(p, folder) for p in sorted((ROOT / "data/records").glob("*_H.AT2"))[:2]]
    first, second = (Path(p) for p in shipped)
    again = first.parent / ".." / first.parent.name / first.name
    files = ", ".join(f'"{p}"' for p in (first, second, again))
    study = tmp_path / "dup.toml"
    study.write_text(DUPLICATE.format(files=files))
    code, _, err = cli("validate", study)
    assert code == 2 and "Traceback" not in err
    assert "motion.files[2]" in err and "already motion.files[0]" in err


def test_messages_show_numbers_not_numpy_reprs(tmp_path, monkeypatch, capsys):
    """A message built with ``{value!r}`` from a numpy scalar reads as a number on the command
    line (numpy 2 would print ``np.float64(-13.45)``)."""
    import numpy as np

    from rockstudy import study as study_package
    from rockstudy.cli import main

    def refuse(path):
        raise ValueError(f"vertical: reaches {np.float64(-13.45)!r} m/s^2 at {np.int64(3)!r}")

    monkeypatch.setattr(study_package, "load_study", refuse)
    try:
        code = main(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "c.zarr")])
    finally:
        np.set_printoptions(legacy=False)  # this test process's default again
    assert code == 2
    line = one_error_line(capsys.readouterr().err)
    assert "reaches -13.45 m/s^2 at 3" in line and "np." not in line


def test_the_free_fall_message_names_plain_numbers():
    """The engine's own message (rockstudy.dynamics) holds floats, not numpy reprs."""
    import numpy as np

    from rockstudy.dynamics._vertical import refuse_free_fall

    with pytest.raises(ValueError) as info:  # -13.45 m/s^2 at scale 1 is below -g
        refuse_free_fall(np.array([-3.0, -13.45]), np.array([1.0, 2.0]), batch=True)
    assert "np." not in str(info.value) and "reaches -13.45 m/s^2 at scale[0] = 1.0" in str(
        info.value
    )
