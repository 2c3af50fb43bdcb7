"""The command line as a user meets it: the real ``rockstudy`` command in a subprocess."""

import json
import math
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PULSE = ["--amplitude", "3.0", "--period", "0.5"]


def cli(*args):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_NUM_THREADS": "1"}
    return subprocess.run(
        [sys.executable, "-m", "rockstudy.cli", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


def test_version_is_the_package_version():
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    out = cli("--version")
    assert out.returncode == 0 and out.stdout.strip() == f"rockstudy {version}"


@pytest.mark.parametrize("command", [[], ["simulate"], ["run"], ["report"], ["validate"]])
def test_help_has_no_markup_and_shows_defaults(command):
    out = cli(*command, "--help")
    assert out.returncode == 0
    assert "`" not in out.stdout and "default: None" not in out.stdout
    if command == ["simulate"]:
        for text in ("(default: nonlinear)", "(default: 1e-08)", "(default: 0.0)", "[m/s^2]"):
            assert text in out.stdout


def test_width_and_height_are_the_block_of_r_and_alpha():
    w, h = 0.4, 2.0
    by_size = json.loads(
        cli("simulate", "--width", str(w), "--height", str(h), *PULSE, "--json").stdout
    )
    inputs = by_size["inputs"]
    assert inputs["half_diagonal"] == pytest.approx(math.hypot(w, h) / 2, rel=1e-14)
    assert inputs["slenderness"] == pytest.approx(math.atan(w / h), rel=1e-14)
    by_r = json.loads(
        cli(
            "simulate",
            "--half-diagonal",
            repr(math.hypot(w, h) / 2),
            "--slenderness",
            repr(math.atan(w / h)),
            *PULSE,
            "--json",
        ).stdout
    )
    assert by_r["result"]["max_rotation"] == pytest.approx(
        by_size["result"]["max_rotation"], rel=1e-12
    )


def test_json_echoes_inputs_and_summarises_the_impacts(tmp_path):
    out = cli(
        "simulate",
        "--half-diagonal",
        "1",
        "--slenderness",
        "0.2",
        *PULSE,
        "--json",
        "--out",
        str(tmp_path / "h.csv"),
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["inputs"]["amplitude"] == 3.0 and data["inputs"]["pulse"] == "sine"
    assert data["inputs"]["restitution"] == pytest.approx(1 - 1.5 * math.sin(0.2) ** 2)
    impacts = data["result"]["impacts"]
    assert set(impacts) == {"count", "first", "last"} and impacts["count"] > 10
    assert 0 < impacts["first"] < impacts["last"]
    assert "impact_times" not in data["result"] and len(out.stdout) < 3000


def test_out_writes_the_history_as_csv_and_netcdf(tmp_path):
    import pandas as pd
    import xarray as xr

    base = ["simulate", "--half-diagonal", "1", "--slenderness", "0.2", *PULSE]
    base += ["--initial-rotation", "0.05"]
    assert cli(*base, "--out", str(tmp_path / "h.csv")).returncode == 0
    assert cli(*base, "--out", str(tmp_path / "h.nc")).returncode == 0
    csv = pd.read_csv(tmp_path / "h.csv")
    nc = xr.open_dataset(tmp_path / "h.nc")
    np.testing.assert_array_equal(csv["theta"].to_numpy(), nc["theta"].values)
    np.testing.assert_array_equal(csv["t"].to_numpy(), nc["time"].values)
    assert csv["theta"].iloc[0] == 0.05  # the initial rotation given
    assert nc["theta"].attrs["units"] == "rad"
    bad = cli(*base, "--out", str(tmp_path / "h.txt"))
    assert bad.returncode == 2 and ".csv or .nc" in bad.stderr


def test_contradictory_options_are_errors(tmp_path):
    record = tmp_path / "r.txt"
    t = np.arange(0, 2, 0.01)
    np.savetxt(record, np.column_stack([t, 0.3 * np.sin(2 * np.pi * t)]))
    block = ["simulate", "--half-diagonal", "1", "--slenderness", "0.2"]
    out = cli(*block, "--record", str(record), "--amplitude", "3")
    assert out.returncode == 2 and "--amplitude" in out.stderr
    out = cli(*block, *PULSE, "--scale", "2")
    assert out.returncode == 2 and "--scale" in out.stderr
    out = cli(*block, "--width", "1", "--height", "2", *PULSE)
    assert out.returncode == 2 and "not both" in out.stderr
    assert cli(*block, "--record", str(record), "--json").returncode == 0
