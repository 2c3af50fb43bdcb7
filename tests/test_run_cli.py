"""``rockstudy run`` as an operator meets it (issue 12, run-time parts of sections 2 and 3):
failed samples, Ctrl-C, scripts without a main guard, worker counts, schedulers without
workers or out of reach, operational errors, TLS, and no dashboard nobody asked for.

The runs are on small pulse studies: in this process (``rockstudy.cli.main``) where the
message is the point, real ``rockstudy run`` processes where the process is (Ctrl-C, a file
size limit, TLS from dask's environment, a clean exit).
"""

import os
import resource
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from _helpers import ROCKSTUDY, SLOW, cli, rockstudy_process, study_text

from rockstudy.study import run_study, validate_text

DASK = str(Path(sys.executable).with_name("dask"))


def write_study(folder, n=40, chunk=10, max_steps=1_000_000, motion="pulse"):
    path = Path(folder) / "study.toml"
    text = SLOW.format(chunk=chunk, n=n) if motion == "stochastic" else None
    path.write_text(text or study_text(chunk=chunk, n=n, max_steps=max_steps))
    return path


def error_lines(stderr):
    lines = [line for line in stderr.strip().splitlines() if line.strip()]
    assert "Traceback" not in stderr, stderr
    return lines


# ------------------------------------------------------------------ failed samples


def test_failed_samples_exit_nonzero_with_a_summary(tmp_path):
    study = write_study(tmp_path, max_steps=3)
    out = tmp_path / "cube.zarr"
    code, _, err = cli("run", study, "--out", out, "--workers", "1", "--quiet")
    assert code == 1, err
    cube = xr.open_zarr(out)
    failed = int((cube.status.values == 2).sum())
    assert 0 < failed < cube.sizes["sample"]  # blocks that never uplift need no step
    assert f"{failed} of {cube.sizes['sample']} samples failed" in err
    assert f"{failed:8d} x kernel stopped: more than max_steps=3 steps" in err
    assert out.with_suffix(".nc").is_file()  # the cube is complete and kept
    code, _, err = cli("run", study, "--out", out, "--resume", "--max-failed", "1", "--quiet")
    assert code == 0, err


def test_error_messages_are_stored_whole(tmp_path):
    from rockstudy.study.running.evaluate import evaluate_chunk

    record = tmp_path / ("a_long_folder_name_" * 6) / "record.txt"
    record.parent.mkdir()
    t = np.arange(0.0, 2.0, 0.01)
    np.savetxt(record, np.column_stack([t, 0.3 * np.sin(2 * np.pi * t)]))
    study = validate_text(
        study_text(n=2, chunk=2)
        .replace('kind = "pulse"', f'kind = "record"\nfiles = ["{record}"]\nscale = 1.0')
        .replace('shape = "sine"\n', "")
        .replace('amplitude_ratio = { dist = "uniform", low = 0.8, high = 5.0 }\n', "")
        .replace('period = { dist = "loguniform", low = 0.1, high = 2.0 }\n', "")
    )
    record.unlink()  # gone after validation: every row fails, naming the whole path
    cols = {
        "sample": np.arange(2),
        "frequency_parameter": np.full(2, 2.0),
        "critical_rotation": np.full(2, 0.2),
        "restitution": np.full(2, 0.94),
        "record": np.zeros(2, np.int64),
        "scale": np.ones(2),
    }
    result = evaluate_chunk(study.normalized(), cols)
    assert np.all(result["status"] == 2)
    assert all(str(record) in message for message in result["error"])
    assert len(str(record)) > 100


# ------------------------------------------------------------------ stopping and starting


def _wait_for_samples(out, proc, k, timeout=120):
    """Until the run ``proc`` has saved ``k`` samples in ``out`` (or ended)."""
    t0 = time.time()
    while time.time() - t0 < timeout and proc.poll() is None:
        try:
            if (xr.open_zarr(out, consolidated=True).status.values != 0).sum() >= k:
                return
        except Exception:  # noqa: BLE001 - not written yet
            pass
        time.sleep(0.2)


def test_ctrl_c_prints_one_line_with_the_resume_command(tmp_path):
    study = write_study(tmp_path, n=400, chunk=10, motion="stochastic")
    out = tmp_path / "cube.zarr"
    proc = subprocess.Popen(
        [ROCKSTUDY, "run", str(study), "--out", str(out), "--workers", "1", "--quiet"],
        start_new_session=True,  # its own process group, as a terminal's foreground job
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # and Ctrl-C at its
        stdout=subprocess.PIPE,  # default, whatever this test process inherited
        stderr=subprocess.PIPE,
        text=True,
    )
    _wait_for_samples(out, proc, 20)
    os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C sends: the whole foreground group
    _, stderr = proc.communicate(timeout=120)
    lines = error_lines(stderr)
    assert proc.returncode == 130
    assert len(lines) == 1 and lines[0].startswith("interrupted: "), stderr
    assert f"samples are saved in {out}" in lines[0]
    assert f"rockstudy run {study} --out {out} --resume --workers 1" in lines[0]


def test_script_without_main_guard_gets_one_sentence(tmp_path):
    study = write_study(tmp_path, n=10)
    script = tmp_path / "plain.py"
    script.write_text(
        "from pathlib import Path\n"
        "from rockstudy.study import load_study, run_study\n"
        f"run_study(load_study({str(study)!r}), {str(tmp_path / 'cube.zarr')!r}, workers=1,"
        " progress=False)\n"
        "print('finished')\n"
    )
    proc = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path
    )
    text = proc.stdout + proc.stderr
    if proc.returncode == 0:  # it works
        assert text.count("finished") == 1
    else:  # or says in one sentence what to add
        assert 'if __name__ == "__main__":' in text
        assert len(text.splitlines()) < 40, text


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_worker_count_must_be_positive(tmp_path, workers):
    study = write_study(tmp_path)
    code, _, err = cli("run", study, "--out", tmp_path / "c.zarr", "--workers", workers)
    assert code == 2 and "--workers" in err and ">= 1" in err
    assert not (tmp_path / "c.zarr").exists()
    with pytest.raises(ValueError, match="workers"):
        run_study(validate_text(study.read_text()), tmp_path / "d.zarr", workers=int(workers))


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start(cmd, **kw):
    return subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True, **kw
    )


def _stop(procs):
    for p in procs:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        p.wait()


def _wait_for_port(port, timeout=60):
    t0 = time.time()
    while time.time() - t0 < timeout:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise AssertionError(f"nothing listens on {port}")


def test_scheduler_without_workers_or_out_of_reach_is_said_in_time(tmp_path):
    study = write_study(tmp_path)
    port = _free_port()
    code, _, err = cli(
        "run", study, "--out", tmp_path / "a.zarr", "--scheduler", f"tcp://127.0.0.1:{port}",
        "--timeout", "3",
    )  # fmt: skip
    lines = error_lines(err)
    assert code == 1 and len(lines) == 1 and "cannot reach the dask scheduler" in lines[0], err
    sched = _start(
        [DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"]
    )
    try:
        _wait_for_port(port)
        t0 = time.time()
        code, _, err = cli(
            "run", study, "--out", tmp_path / "b.zarr", "--scheduler", f"tcp://127.0.0.1:{port}",
            "--timeout", "3",
        )  # fmt: skip
        lines = error_lines(err)
        assert code == 1 and len(lines) == 1, err
        assert "no worker joined the dask scheduler" in lines[0] and "within 3 s" in lines[0]
        assert "--resume" not in lines[0]  # nothing ran: nothing to resume, and
        assert not (tmp_path / "b.zarr").exists()  # no half-made store is left
        assert time.time() - t0 < 60
    finally:
        _stop([sched])


def test_lost_scheduler_is_one_error_line(tmp_path):
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    procs = [_start([DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port)], env=env)]
    try:
        _wait_for_port(port)
        worker = [DASK, "worker", address, "--nthreads", "1", "--nworkers", "1", "--no-dashboard"]
        procs.append(_start(worker, env=env))
        study = write_study(tmp_path, n=400, chunk=10, motion="stochastic")
        out = tmp_path / "cube.zarr"
        run = subprocess.Popen(
            [ROCKSTUDY, "run", str(study), "--out", str(out), "--scheduler", address, "--quiet",
             "--timeout", "5"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        _wait_for_samples(out, run, 20)
        _stop(procs[:1])  # the scheduler dies mid-run
        _, stderr = run.communicate(timeout=180)
        lines = error_lines(stderr)
        assert run.returncode == 1 and len(lines) == 1, stderr
        assert lines[0].startswith("error: ") and "samples are saved in" in lines[0]
        assert f"--out {out} --resume --scheduler {address}" in lines[0]
    finally:
        _stop(procs)


def _file_size_limit(limit):
    def apply():  # a full disk, as the run sees it: a write that fails with an OSError
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


def test_a_failing_write_is_one_error_line_and_resume_finishes(tmp_path):
    study = write_study(tmp_path, n=4000, chunk=500)
    out = tmp_path / "cube.zarr"
    proc = subprocess.run(
        [ROCKSTUDY, "run", str(study), "--out", str(out), "--workers", "1", "--quiet"],
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=_file_size_limit(64 * 1024),  # the netCDF export is larger
    )
    lines = error_lines(proc.stderr)
    assert proc.returncode == 1 and len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: ") and "4000 of 4000 samples are saved" in lines[0]
    assert f"rockstudy run {study} --out {out} --resume" in lines[0]
    assert not out.with_suffix(".nc").exists()  # no partial export left in its place
    code, _, err = cli("run", study, "--out", out, "--resume", "--workers", "1", "--quiet")
    assert code == 0, err
    assert np.all(xr.open_dataset(out.with_suffix(".nc")).status.values == 1)


# ------------------------------------------------------------------ clusters


def test_local_cluster_opens_no_dashboard_and_runs_no_profiler():
    """No dashboard; and no statistical profiler, whose thread reads the other threads'
    frames (it crashed CPython 3.11 in a test's cluster), whatever dask's config says."""
    import dask
    import distributed  # noqa: F401 - its config defaults, before they are changed

    from rockstudy.study.running.runner import _client

    with dask.config.set({"distributed.worker.profile.enabled": True}):
        client, cluster = _client(workers=1)
    try:
        callbacks = client.run(lambda dask_worker: sorted(dask_worker.periodic_callbacks))
        (names,) = callbacks.values()
        assert "heartbeat" in names and "profile" not in names
        port = cluster.scheduler.http_server._sockets  # noqa: SLF001
        ports = {sock.getsockname()[1] for sock in port.values()}
        assert 8787 not in ports
        # the workers' own HTTP servers (dask always starts one) serve nothing either
        services = [w["services"] for w in client.scheduler_info()["workers"].values()]
        workers = {s["dashboard"] for s in services if "dashboard" in s}
        assert len(workers) == 1  # the one worker's server was found
        for p in ports | workers:
            for page in ("/status", "/health", "/metrics", "/info/main/workers.html"):
                with pytest.raises(urllib.error.HTTPError) as info:
                    urllib.request.urlopen(f"http://127.0.0.1:{p}{page}", timeout=10)
                assert info.value.code == 404
    finally:
        client.close()
        cluster.close()


def _certificates(folder):
    """A throwaway CA and a certificate it signed for 127.0.0.1 (openssl)."""
    folder = Path(folder)
    cfg = folder / "san.cnf"
    cfg.write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    run = lambda *a: subprocess.run(["openssl", *a], check=True, capture_output=True)  # noqa: E731
    run("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=test-ca",
        "-keyout", folder / "ca.key", "-out", folder / "ca.pem")  # fmt: skip
    run("req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=127.0.0.1",
        "-keyout", folder / "node.key", "-out", folder / "node.csr")  # fmt: skip
    run("x509", "-req", "-in", folder / "node.csr", "-CA", folder / "ca.pem", "-CAkey",
        folder / "ca.key", "-CAcreateserial", "-days", "2", "-extfile", cfg,
        "-out", folder / "node.pem")  # fmt: skip
    return folder / "ca.pem", folder / "node.pem", folder / "node.key"


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl for test certificates")
def test_tls_scheduler_from_flags_and_from_dask_config(tmp_path):
    ca, cert, key = _certificates(tmp_path)
    tls = ["--tls-ca-file", ca, "--tls-cert", cert, "--tls-key", key]
    port = _free_port()
    address = f"tls://127.0.0.1:{port}"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    procs = [_start([DASK, "scheduler", "--host", address, "--no-dashboard", *tls], env=env)]
    try:
        _wait_for_port(port)
        procs.append(
            _start(
                [
                    DASK,
                    "worker",
                    address,
                    "--nthreads",
                    "1",
                    "--nworkers",
                    "1",
                    "--no-dashboard",
                    *tls,
                ],
                env=env,
            )  # fmt: skip
        )
        study = write_study(tmp_path)
        code, _, err = rockstudy_process(
            "run", study, "--out", tmp_path / "flags.zarr", "--scheduler", address, *tls,
            "--quiet", env=env,
        )  # fmt: skip
        assert code == 0, err
        config = {
            "DASK_DISTRIBUTED__COMM__TLS__CA_FILE": str(ca),
            "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT": str(cert),
            "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY": str(key),
        }
        code, _, err = rockstudy_process(
            "run", study, "--out", tmp_path / "config.zarr", "--scheduler", address, "--quiet",
            env={**env, **config},
        )  # fmt: skip
        assert code == 0, err
        a = xr.open_zarr(tmp_path / "flags.zarr").max_rotation.values
        b = xr.open_zarr(tmp_path / "config.zarr").max_rotation.values
        np.testing.assert_array_equal(a, b)
        assert np.all(np.isfinite(a))
    finally:
        _stop(procs)


# ------------------------------------------------------------------ a clean exit (issue 24)

BUSY_ZARR = """
import sys, time
import zarr
from zarr.core import sync
group = zarr.open_group(sys.argv[1], mode="r", zarr_format=2, use_consolidated=True)
group["status"][:]  # zarr's IO loop and thread are running
sync.loop[0].call_soon_threadsafe(time.sleep, 1.0)  # and busy when the process exits
from rockstudy.study.running.store import stop_zarr_io
stop_zarr_io()
"""


def test_exit_waits_for_zarrs_io_thread(tmp_path):
    """The cause of the intermittent ``RuntimeError: Cannot close a running event loop`` at
    the end of a run: zarr's exit hook joins its IO thread for 0.2 s, then closes the loop even
    if it still runs (a loaded machine). Here the thread is busy for 1 s as the process ends:
    :func:`stop_zarr_io`, which the command line calls last, leaves a clean stderr."""
    study = write_study(tmp_path, n=10)
    out = tmp_path / "cube.zarr"
    code, _, err = rockstudy_process("run", study, "--out", out, "--workers", "1", "--quiet")
    assert code == 0 and err == "", err
    proc = subprocess.run(
        [sys.executable, "-c", BUSY_ZARR, str(out)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    code, _, err = rockstudy_process("run", study, "--out", out, "--resume", "--quiet")
    assert code == 0 and err == "", err  # and runs end cleanly, again and again
    for _ in range(2):
        code, _, err = rockstudy_process("verify", out)
        assert code == 0 and err == "", err
