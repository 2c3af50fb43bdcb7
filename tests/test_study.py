"""The study layer: schema, design, and runs that survive chunking, kills and lost workers."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from _helpers import ROCKSTUDY, ROOT, SLOW, study_text

from rockstudy.cli import main as cli_main
from rockstudy.study import StudyError, make_design, run_study, validate_text
from rockstudy.study.spec.schema import json_schema


def outputs(path):
    ds = xr.open_zarr(path)
    return {
        k: ds[k].values for k in ("max_rotation", "overturned", "n_impacts", "status") if k in ds
    }


def assert_same(a, b):
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


# ------------------------------------------------------------------------------- the schema


@pytest.mark.parametrize(
    "edit, field, words",
    [
        (("half_diagonal = {", "half_diagnal = {"), "structure.half_diagnal", "not a setting"),
        (
            ("low = 0.5, high = 3.0", "low = 3.0, high = 0.5"),
            "structure.half_diagonal",
            "low < high",
        ),
        (('kind = "monte_carlo"\nn = 600', 'kind = "sobol"\nn = 600'), "sampler", "2^k"),
        (("low = 0.1, high = 0.3", "low = -0.1, high = 0.3"), "structure.slenderness", "(0, pi/2)"),
        (("amplitude_ratio = {", "amplitude_rati = {"), "motion.amplitude_rati", "not a setting"),
        (
            ('outputs = ["max_rotation"', 'outputs = ["max_rotaton"'),
            "run.outputs[0]",
            "max_rotation",
        ),
        (("seed = 7", "seed = -7"), "seed", "must be >= 0"),
    ],
)
def test_schema_names_the_field(edit, field, words):
    text = study_text().replace(*edit)
    with pytest.raises(StudyError) as info:
        validate_text(text)
    message = str(info.value)
    assert field in message and words in message, message


def test_schema_reports_every_problem_and_distribution_bounds():
    text = (
        study_text()
        .replace("half_diagonal = {", "half_diagnal = {")
        .replace("seed = 7", "seed = -7")
    )
    with pytest.raises(StudyError) as info:
        validate_text(text)
    assert len(info.value.problems) >= 3  # the typo, the missing field, the seed
    bad = study_text().replace(
        '{ dist = "loguniform", low = 0.1, high = 2.0 }',
        '{ dist = "normal", mean = 1.0, sigma = 0.0 }',
    )
    with pytest.raises(StudyError, match="sigma"):
        validate_text(bad)
    schema = json_schema()
    assert {"sampler", "structure", "motion", "run", "seed"} <= set(schema["properties"])


def test_cli_validate(tmp_path, capsys):
    good = tmp_path / "good.toml"
    good.write_text(study_text())
    bad = tmp_path / "bad.toml"
    bad.write_text(study_text().replace("seed = 7", "sed = 7"))
    assert cli_main(["validate", str(good)]) == 0
    assert cli_main(["validate", str(good), str(bad)]) == 2
    assert "sed" in capsys.readouterr().err


def test_every_shipped_study_validates(tmp_path, records_dir):
    for path in sorted((ROOT / "studies").glob("*.toml")):
        # record paths are relative to the study file: point them at the shared records and
        # at the records and hazard curves shipped in data/
        copy = tmp_path / path.name
        text = path.read_text().replace("../../shared/records", str(records_dir))
        text = text.replace("../data/records", str(ROOT / "data" / "records"))
        copy.write_text(text.replace("../data/hazard", str(ROOT / "data" / "hazard")))
        assert cli_main(["validate", str(copy)]) == 0, path


# ------------------------------------------------------------------------------- the design


def test_design_groups_and_layouts():
    study = validate_text(study_text(sampler="sobol", n=64))
    ds = make_design(study)
    assert ds.sizes["sample"] == 64 * (4 + 2)  # Saltelli layout, first order: N (D + 2)
    p = ds.frequency_parameter
    np.testing.assert_allclose(ds.omega, 2 * np.pi / (ds.period * p))
    np.testing.assert_allclose(ds.amplitude, ds.amplitude_ratio * 9.81 * np.tan(ds.slenderness))
    np.testing.assert_allclose(ds.uplift_ratio * ds.amplitude_ratio, 1.0)
    grid = validate_text(
        study_text()
        .replace('kind = "monte_carlo"\nn = 600', 'kind = "grid"')
        .replace('{ dist = "uniform", low = 0.5, high = 3.0 }', "1.0")
        .replace('{ dist = "uniform", low = 0.1, high = 0.3 }', "0.2")
        .replace(
            '{ dist = "uniform", low = 0.8, high = 5.0 }',
            '{ dist = "grid", low = 1.1, high = 4.0, n = 5 }',
        )
        .replace(
            '{ dist = "loguniform", low = 0.1, high = 2.0 }',
            '{ dist = "grid", values = [0.2, 0.5, 1.0] }',
        )
    )
    g = make_design(grid)
    assert g.sizes["sample"] == 15 and g.attrs["grid_dims"] == ["amplitude_ratio", "period"]


# ------------------------------------------------------------------------------- runs


@pytest.fixture(scope="module")
def reference_run(tmp_path_factory, client):
    """The pulse study run on the session's in-process client (threads): the runs of worker
    processes below must give the same results."""
    out = tmp_path_factory.mktemp("ref") / "ref.zarr"
    report = run_study(validate_text(study_text(chunk=100)), out, client=client, progress=False)
    return out, report


def test_results_do_not_depend_on_chunks_or_workers(reference_run, tmp_path):
    ref, report = reference_run
    assert report.failed_samples == 0 and len(report.chunks_computed) == 6
    other = tmp_path / "other.zarr"
    run_study(validate_text(study_text(chunk=37)), other, workers=2, progress=False)
    assert_same(outputs(ref), outputs(other))
    ds = xr.open_zarr(ref)
    assert ds.attrs["study_sha256"] and json.loads(ds.attrs["versions"])["numpy"]
    for name, var in ds.data_vars.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name
    nc = xr.open_dataset(ref.with_suffix(".nc"))
    np.testing.assert_array_equal(nc["max_rotation"].values, ds["max_rotation"].values)


def test_failed_samples_are_recorded(tmp_path, client):
    out = tmp_path / "fail.zarr"
    report = run_study(
        validate_text(study_text(chunk=200, max_steps=3)),
        out,
        client=client,
        progress=False,
        max_failed=1.0,
    )
    ds = xr.open_zarr(out)
    failed = ds.status.values == 2
    assert report.failed_samples == failed.sum() > 0
    assert (ds.status.values == 1).sum() > 0  # blocks that never uplift need no step
    assert all("max_steps=3" in e for e in ds.error.values[failed])
    assert np.all(np.isnan(ds.max_rotation.values[failed]))


def test_the_run_says_how_much_of_its_time_was_compiling(tmp_path, monkeypatch, capsys):
    """The compile happens once, inside the run's time: the summary line says how much of it
    (the priming's own count of seconds), and nothing when every kernel was cached."""
    from rockstudy.study.running import runner

    (tmp_path / "s.toml").write_text(study_text(chunk=300))
    real = runner.prime_study

    def run(out):  # one worker process: the compile and its summary are the client's
        argv = ["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / out), "--quiet"]
        return cli_main(argv + ["--workers", "1"])

    assert run("a.zarr") == 0
    capsys.readouterr()
    assert run("c.zarr") == 0
    assert "compiling" not in capsys.readouterr().out  # all cached by the first run

    def cold(*args):  # as the priming reports a compile of 2.5 s
        real(*args)
        return {"compiled": 7, "seconds": 2.5}

    monkeypatch.setattr(runner, "prime_study", cold)
    assert run("b.zarr") == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert "computed 2 chunks in " in line and "s (2.5 s of it compiling kernels, once);" in line


def test_resume_refuses_another_study(reference_run, client):
    ref, _ = reference_run
    with pytest.raises(ValueError, match="different study"):
        run_study(
            validate_text(study_text(chunk=100).replace("seed = 7", "seed = 8")),
            ref,
            resume=True,
            client=client,
            progress=False,
        )
    with pytest.raises(FileExistsError):
        run_study(validate_text(study_text(chunk=100)), ref, client=client, progress=False)


def _status(path):
    try:
        return xr.open_zarr(path, consolidated=True).status.values
    except Exception:
        return None


def _wait_for(predicate, timeout):
    t0 = time.time()
    while time.time() - t0 < timeout:
        if predicate():
            return True
        time.sleep(0.2)
    return False


def test_sigkill_then_resume_is_bit_identical(tmp_path, client):
    study = tmp_path / "slow.toml"
    study.write_text(SLOW.format(chunk=40, n=1200))
    full = tmp_path / "full.zarr"  # uninterrupted, on the session's in-process client
    run_study(validate_text(study.read_text()), full, client=client, progress=False)
    killed = tmp_path / "killed.zarr"
    proc = subprocess.Popen(
        [ROCKSTUDY, "run", str(study), "--out", str(killed), "--workers", "2", "--quiet"],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        started = _wait_for(
            lambda: (s := _status(killed)) is not None and (s != 0).sum() >= 5 * 40, timeout=120
        )
        assert started, "the run never got going"
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    status = _status(killed)
    done_at_kill = [(a, a + 40) for a in range(0, 1200, 40) if np.all(status[a : a + 40] != 0)]
    assert 0 < len(done_at_kill) < 30
    report = run_study(
        validate_text(study.read_text()), killed, resume=True, workers=2, progress=False
    )
    recomputed = set(report.chunks_computed)
    assert not recomputed & set(done_at_kill)  # no finished chunk computed again
    assert recomputed | set(done_at_kill) == {(a, a + 40) for a in range(0, 1200, 40)}
    assert_same(outputs(full), outputs(killed))


def test_distributed_run_survives_a_killed_worker(tmp_path, client):
    sched_file = tmp_path / "scheduler.json"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    procs = [
        subprocess.Popen(
            [
                str(Path(sys.executable).with_name("dask")),
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(sched_file),
            ],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    ]
    try:
        assert _wait_for(sched_file.exists, 60)
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [
                        str(Path(sys.executable).with_name("dask")),
                        "worker",
                        "--scheduler-file",
                        str(sched_file),
                        "--nthreads",
                        "1",
                        "--nworkers",
                        "1",
                        "--no-dashboard",
                        "--host",
                        "127.0.0.1",
                    ],
                    env=env,
                    start_new_session=True,
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
            )
        from distributed import Client

        with Client(scheduler_file=str(sched_file)) as remote:
            remote.wait_for_workers(2, timeout=60)
        study = tmp_path / "slow.toml"
        study.write_text(SLOW.format(chunk=40, n=800))
        out = tmp_path / "dist.zarr"
        run = subprocess.Popen(
            [
                ROCKSTUDY,
                "run",
                str(study),
                "--out",
                str(out),
                "--scheduler-file",
                str(sched_file),
                "--quiet",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert _wait_for(lambda: (s := _status(out)) is not None and (s != 0).sum() >= 80, 120)
        os.killpg(procs[1].pid, signal.SIGKILL)  # one worker dies mid-run
        stdout, stderr = run.communicate(timeout=300)
        assert run.returncode == 0, stderr
        assert np.all(_status(out) == 1)
        ref = tmp_path / "ref.zarr"
        run_study(validate_text(study.read_text()), ref, client=client, progress=False)
        assert_same(outputs(ref), outputs(out))
    finally:
        for p in procs:
            try:
                os.killpg(p.pid, signal.SIGKILL) if p is not procs[0] else p.kill()
            except (ProcessLookupError, PermissionError):
                pass
            p.wait()


def test_grid_study_cube_holds_the_engine_results(tmp_path, client):
    from rockstudy import simulate_batch
    from rockstudy.study import open_result

    text = (
        study_text()
        .replace('kind = "monte_carlo"\nn = 600', 'kind = "grid"')
        .replace('{ dist = "uniform", low = 0.5, high = 3.0 }', "1.0")
        .replace('{ dist = "uniform", low = 0.1, high = 0.3 }', "0.2")
        .replace(
            '{ dist = "uniform", low = 0.8, high = 5.0 }',
            '{ dist = "grid", low = 1.1, high = 4.0, n = 5 }',
        )
        .replace(
            '{ dist = "loguniform", low = 0.1, high = 2.0 }',
            '{ dist = "grid", values = [0.2, 0.5, 1.0] }',
        )
    )
    out = tmp_path / "grid.zarr"
    run_study(validate_text(text), out, client=client, progress=False)
    for cube in (open_result(out), open_result(out.with_suffix(".nc"))):
        assert cube["max_rotation"].dims == ("amplitude_ratio", "period")
        A, T = np.meshgrid(cube.amplitude_ratio.values, cube.period.values, indexing="ij")
        amplitude = cube["amplitude"].values.ravel()  # the engine's input, to the last bit
        np.testing.assert_allclose(amplitude, A.ravel() * 9.81 * np.tan(0.2), rtol=1e-15)
        direct = simulate_batch(
            half_diagonal=1.0, slenderness=0.2, pulse="sine", amplitude=amplitude, period=T.ravel()
        )
        np.testing.assert_array_equal(cube["max_rotation"].values.ravel(), direct["max_rotation"])
        np.testing.assert_array_equal(cube["n_impacts"].values.ravel(), direct["n_impacts"])


def test_auto_study_meets_its_tolerance(tmp_path, client):
    """The shipped method="auto" study (rtol 1e-2), cut to 2000 samples: every sample records
    the model that ran, and >= 99 % are within 1 % of Housner's max rotation (kernel at
    rtol 1e-12) with the same overturning decision."""
    from rockstudy import simulate_batch
    from rockstudy.study import open_result
    from rockstudy.verification.accuracy import relative_max_rotation_error

    text = (ROOT / "studies" / "auto_method.toml").read_text().replace("n = 20000", "n = 2000")
    out = tmp_path / "auto.zarr"
    run_study(validate_text(text), out, client=client, progress=False)
    cube = open_result(out).compute()
    assert set(np.unique(cube["model"].values)) == {0, 1, 2}
    ref = simulate_batch(
        half_diagonal=cube["half_diagonal"].values,
        slenderness=cube["slenderness"].values,
        pulse="sine",
        amplitude=cube["amplitude"].values,
        period=cube["period"].values,
        rtol=1e-12,
    )
    got = {
        "max_rotation": cube["max_rotation"].values,
        "overturned": cube["overturned"].values.astype(bool),
    }
    assert np.mean(relative_max_rotation_error(got, ref) <= 1e-2) >= 0.99
