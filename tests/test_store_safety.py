"""The study store never destroys, overwrites, mixes or loses work (issue 12, section 1).

Every test runs ``rockstudy run`` on small pulse studies (one worker): in this process
(``rockstudy.cli.main``, its worker a thread), but for a second run beside a running one and a
killed run, which are real processes. Results are checked against the engine called directly
(:func:`rockstudy.simulate_batch`), not against the store itself.
"""

import json
import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from _helpers import (
    ROCKSTUDY,
    assert_engine_results,
    one_error_line,
    rockstudy_run,
    tree,
    write_study,
)


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run: (folder, study file, store)."""
    folder = tmp_path_factory.mktemp("finished")
    study = write_study(folder)
    out = folder / "cube.zarr"
    code, _, err = rockstudy_run(study, out)
    assert code == 0, err
    return folder, study, out


# ------------------------------------------------------------------ never writes where it may not


def test_resume_into_a_user_folder_touches_nothing(tmp_path):
    study = write_study(tmp_path)
    user = tmp_path / "thesis"
    (user / "sub").mkdir(parents=True)
    (user / "thesis.tex").write_text("\\documentclass{article}")
    (user / "sub" / "data.csv").write_text("1,2\n")
    before = tree(user)
    code, _, err = rockstudy_run(study, user, "--resume")
    assert code != 0
    one_error_line(err)
    assert "not a rockstudy store" in err
    assert tree(user) == before  # not one file added, changed or removed
    assert not (tmp_path / "thesis.nc").exists()


def test_export_never_replaces_what_it_did_not_write(tmp_path):
    study = write_study(tmp_path, n=20)
    out = tmp_path / "cube.zarr"
    foreign = tmp_path / "cube.nc"
    foreign.write_text("my own cube.nc")
    code, _, err = rockstudy_run(study, out)
    assert code != 0
    one_error_line(err)
    assert "--overwrite" in err and foreign.read_text() == "my own cube.nc"
    assert not out.exists()  # refused before anything ran
    code, _, err = rockstudy_run(study, out, "--overwrite")
    assert code == 0, err
    assert_engine_results(xr.open_dataset(foreign).load())
    # a folder named like the export is refused in one line, and left alone
    other = tmp_path / "other.zarr"
    (tmp_path / "other.nc" / "inside").mkdir(parents=True)
    code, _, err = rockstudy_run(study, other, "--overwrite")
    assert code != 0
    one_error_line(err)
    assert "is a folder" in err and (tmp_path / "other.nc" / "inside").is_dir()


# ------------------------------------------------------------ one run per store, kills survive


def _lock_holder(out):
    try:
        return json.loads((out / ".rockstudy.lock").read_text())
    except (OSError, ValueError):
        return None


def test_second_run_is_refused_and_a_killed_runs_lock_is_stale(tmp_path):
    study = write_study(tmp_path)
    out = tmp_path / "cube.zarr"
    with socket.socket() as s:  # a scheduler nobody answers at: the first run waits, locked
        s.bind(("127.0.0.1", 0))
        nowhere = f"tcp://127.0.0.1:{s.getsockname()[1]}"
    first = subprocess.Popen(
        [ROCKSTUDY, "run", str(study), "--out", str(out), "--scheduler", nowhere,
         "--timeout", "600", "--quiet"],
        start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        t0 = time.time()
        while (_lock_holder(out) or {}).get("pid") != first.pid and time.time() - t0 < 60:
            time.sleep(0.05)
        assert (_lock_holder(out) or {}).get("pid") == first.pid, "the first run never started"
        t0 = time.time()
        for extra in (["--resume"], []):  # a second run, in this process
            code, _, err = rockstudy_run(study, out, *extra)
            assert code != 0
            one_error_line(err)
            assert f"PID {first.pid}" in err and "in use" in err, err
        assert first.poll() is None and time.time() - t0 < 60  # refused at once
    finally:
        os.killpg(first.pid, signal.SIGKILL)
        first.wait()
    code, _, err = rockstudy_run(study, out, "--resume")  # the killed run's lock is stale
    assert code == 0, err
    assert_engine_results(xr.open_zarr(out).load())
    assert_engine_results(xr.open_dataset(out.with_suffix(".nc")).load())


# ------------------------------------------------------------------ damage is found, not trusted


def _truncate(path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


@pytest.mark.parametrize(
    "damage, count",
    [
        ("chunks", 3),  # a lost chunk file, a truncated output chunk, a truncated status chunk
        ("variable", 6),  # a lost variable: every chunk of it
    ],
)
def test_resume_recomputes_chunks_that_do_not_read_back(finished, tmp_path, damage, count):
    folder, study, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    if damage == "chunks":
        (out / "max_rotation" / "5").unlink()
        _truncate(out / "overturned" / "2")
        _truncate(out / "status" / "3")
    else:
        shutil.rmtree(out / "n_impacts")
    code, stdout, err = rockstudy_run(study, out, "--resume")
    assert code == 0, err
    assert "did not read back whole" in err and f"computed {count} chunks" in stdout
    assert_engine_results(xr.open_zarr(out).load())
    assert_engine_results(xr.open_dataset(out.with_suffix(".nc")).load())


def test_damaged_metadata_is_reported_never_replaced(finished, tmp_path):
    folder, study, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    _truncate(out / ".zmetadata")
    before = tree(out)
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code != 0
    one_error_line(err)
    assert ".zmetadata is damaged" in err
    other = write_study(tmp_path, seed=8, name="other.toml")  # another study over the damage
    code, _, err = rockstudy_run(other, out, "--resume")
    assert code != 0
    one_error_line(err)
    assert "different study" in err
    assert tree(out) == before


# ------------------------------------------------------------------ inputs and versions


RECORD_STUDY = """
name = "records"
seed = 3
chunk_size = 10

[sampler]
kind = "monte_carlo"
n = 20

[structure]
kind = "block"
half_diagonal = 1.0
slenderness = 0.2

[motion]
kind = "record"
files = ["rec.txt"]
units = "g"
scale = {{ dist = "uniform", low = 0.5, high = 2.0 }}

[run]
outputs = ["max_rotation"]
"""


def _record(path, peak):
    t = np.arange(0.0, 4.0, 0.01)
    np.savetxt(path, np.column_stack([t, peak * np.sin(2 * np.pi * t)]))


def test_resume_refuses_changed_inputs_and_versions(tmp_path):
    _record(tmp_path / "rec.txt", 0.3)
    study = tmp_path / "records.toml"
    study.write_text(RECORD_STUDY.format())
    out = tmp_path / "cube.zarr"
    code, _, err = rockstudy_run(study, out)
    assert code == 0, err
    code, stdout, err = rockstudy_run(study, out, "--resume")  # nothing changed: nothing to do
    assert code == 0 and "computed 0 chunks" in stdout, err
    _record(tmp_path / "rec.txt", 0.4)  # the record changes between runs
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code != 0
    one_error_line(err)
    assert "rec.txt" in err and "changed" in err
    _record(tmp_path / "rec.txt", 0.3)
    marker = json.loads((out / ".rockstudy").read_text())
    assert marker["rockstudy"]  # the package version is recorded
    (out / ".rockstudy").write_text(json.dumps({**marker, "rockstudy": "0.0.0-older"}))
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code != 0
    one_error_line(err)
    assert "0.0.0-older" in err


# ------------------------------------------------------------------ valid settings that broke


FIXED = """
name = "fixed"
seed = 3000000000
chunk_size = 3000000000

[sampler]
kind = "monte_carlo"
n = 4

[structure]
kind = "block"
half_diagonal = 1.0
slenderness = 0.2

[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = 2.0
period = 0.5

[run]
outputs = ["max_rotation", "overturned", "n_impacts"]
"""


def test_large_seed_and_chunk_and_all_fixed_parameters(tmp_path):
    study = tmp_path / "fixed.toml"
    study.write_text(FIXED)
    out = tmp_path / "cube.zarr"
    code, _, err = rockstudy_run(study, out)
    assert code == 0, err
    nc = xr.open_dataset(out.with_suffix(".nc")).load()
    assert int(nc.attrs["seed"]) == 3_000_000_000 and int(nc.attrs["chunk_size"]) == 3_000_000_000
    assert nc.sizes["sample"] == 4
    assert_engine_results(nc)


# ------------------------------------------------------------------ issue 26, section 1


def _lock_bytes(folder):
    lock = Path(folder) / ".rockstudy.lock"
    return lock.read_bytes() if lock.exists() else None


@pytest.mark.parametrize("extra", [["--resume"], []])
def test_a_stray_lock_never_makes_a_folder_of_user_files_a_store(tmp_path, extra):
    study = write_study(tmp_path, n=20)
    demo = tmp_path / "demo"
    demo.mkdir()
    (demo / "thesis.tex").write_text("precious")
    (demo / ".rockstudy.lock").touch()
    code, _, err = rockstudy_run(study, demo, *extra)
    assert code != 0
    one_error_line(err)
    assert (demo / "thesis.tex").read_text() == "precious"
    assert sorted(p.name for p in demo.iterdir()) == [".rockstudy.lock", "thesis.tex"]
    assert _lock_bytes(demo) == b""  # not even the lock was written to
    assert "resume=True" not in err


def _set_pending(out, stop):
    import zarr

    zarr.open_group(str(out), mode="r+", zarr_format=2)["status"][0:stop] = 0


def test_a_store_without_its_marker_is_adopted_only_if_its_cube_checks(tmp_path):
    _record(tmp_path / "rec.txt", 0.3)
    study = tmp_path / "records.toml"
    study.write_text(RECORD_STUDY.format())
    out = tmp_path / "cube.zarr"
    code, _, err = rockstudy_run(study, out)
    assert code == 0, err
    whole = xr.open_zarr(out)["max_rotation"].values
    _set_pending(out, 10)
    (out / ".rockstudy").unlink()
    _record(tmp_path / "rec.txt", 0.9)  # the record multiplied by 3
    before, lock = tree(out), _lock_bytes(out)
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code != 0
    one_error_line(err)
    assert "rec.txt" in err and "changed" in err
    assert tree(out) == before and _lock_bytes(out) == lock  # nothing changed, lock included
    _record(tmp_path / "rec.txt", 0.3)  # restored: the cube's own hashes now agree
    code, stdout, err = rockstudy_run(study, out, "--resume")
    assert code == 0 and "computed 1 chunks" in stdout, err
    assert (out / ".rockstudy").is_file()
    np.testing.assert_array_equal(xr.open_zarr(out)["max_rotation"].values, whole)


@pytest.mark.parametrize("lost", ["inputs_sha256", "versions", "template_complete"])
def test_a_store_without_marker_whose_cube_cannot_be_checked_is_refused(finished, tmp_path, lost):
    folder, study, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    (out / ".rockstudy").unlink()
    meta = json.loads((out / ".zmetadata").read_text())
    del meta["metadata"][".zattrs"][lost]
    (out / ".zmetadata").write_text(json.dumps(meta))
    before = tree(out)
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code != 0
    one_error_line(err)
    assert "new --out" in err and "afresh" in err
    assert tree(out) == before


def test_a_refused_run_leaves_the_lock_as_it_was(finished, tmp_path):
    folder, study, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    lock = _lock_bytes(out)
    assert lock  # the finished run named itself
    other = write_study(tmp_path, seed=8, name="other.toml")
    for args in ((study, out), (other, out, "--resume")):
        code, _, err = rockstudy_run(*args)
        assert code != 0
        one_error_line(err)
        assert "resume=True" not in err
        assert _lock_bytes(out) == lock


def test_an_existing_empty_folder_is_accepted(tmp_path):
    study = write_study(tmp_path, n=20)
    out = tmp_path / "empty"
    out.mkdir()
    code, _, err = rockstudy_run(study, out)
    assert code == 0, err
    assert_engine_results(xr.open_zarr(out).load())
