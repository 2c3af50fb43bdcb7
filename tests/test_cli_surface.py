"""The command line as a user meets it: ``rockstudy.cli.main`` in this process, its exit code,
stdout and stderr; a real process where a fresh numba cache is the point."""

import json
import math
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from _helpers import cli as rockstudy_cli

ROOT = Path(__file__).resolve().parents[1]
PULSE = ["--amplitude", "3.0", "--period", "0.5"]


def cli(*args):
    """``rockstudy ARGS`` in this process (``rockstudy.cli.main``): its exit code, stdout and
    stderr as a finished process's."""
    code, out, err = rockstudy_cli(*args)
    return subprocess.CompletedProcess(args, code, out, err)


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


def test_units_of_a_text_record_hints_in_cli_terms_and_inputs_without_noise(tmp_path):
    # 0.3 sin: in m/s^2 below the uplift g tan(0.2) = 1.99 m/s^2 (the block stays at rest);
    # in g (2.94 m/s^2) above it (the block rocks)
    record = tmp_path / "r.txt"
    t = np.arange(0, 2, 0.01)
    np.savetxt(record, np.column_stack([t, 0.3 * np.sin(2 * np.pi * t)]))
    block = ["simulate", "--half-diagonal", "1", "--slenderness", "0.2", "--record", str(record)]
    si = json.loads(cli(*block, "--units", "m/s2", "--json").stdout)
    in_g = json.loads(cli(*block, "--json").stdout)
    assert si["inputs"]["units"] == "m/s2" and in_g["inputs"]["units"] == "g"
    assert si["result"]["max_rotation"] == 0.0 and in_g["result"]["max_rotation"] > 0.0
    at2 = tmp_path / "r.AT2"
    at2.write_text("x\n")
    out = cli(*block[:-1], str(at2), "--units", "m/s2")
    assert out.returncode == 2 and "in g" in out.stderr
    three = tmp_path / "hv.txt"
    np.savetxt(three, np.column_stack([t, t, t]))
    out = cli(*block[:-1], str(three))
    assert out.returncode != 0 and "columns=(" not in out.stderr and "--units" in out.stderr
    text = cli("simulate", "--width", "0.45", "--height", "1.9", *PULSE).stdout
    lines = dict(line.split(None, 1) for line in text.splitlines() if line.strip())
    assert lines["width"] == "0.45" and lines["height"] == "1.9"
    assert lines["half_diagonal"] == f"{math.hypot(0.45, 1.9) / 2:.12g}"
    assert float(lines["slenderness"]) == pytest.approx(math.atan2(0.45, 1.9), rel=1e-11)


def test_method_choices_are_the_registry_methods_that_run_a_block():
    from rockstudy.cli import SIMULATE_METHODS
    from rockstudy.dynamics.methods import METHODS

    assert sorted(SIMULATE_METHODS) == sorted(
        m for m, i in METHODS.items() if "block" in i.structures
    )


def test_step_limit_is_one_line_and_exit_1():
    block = ["simulate", "--half-diagonal", "1", "--slenderness", "0.2", *PULSE]
    out = cli(*block, "--max-steps", "3")
    assert out.returncode == 1 and "Traceback" not in out.stderr
    assert out.stderr.strip() == (
        "error: nonlinear: more than max_steps=3 steps in one rocking phase (raise max_steps, "
        "or loosen rtol)"
    )
    assert cli(*block, "--max-steps", "100000").returncode == 0


def test_compile_groups_are_the_warm_up_groups_and_a_group_compiles_alone(tmp_path):
    """``rockstudy compile --group`` offers the warm-up's groups, and compiles only those: the
    closed forms into an empty cache leave no cache entry of the rocking kernels (dynamics/)."""
    from rockstudy.cli import _COMPILE_GROUPS
    from rockstudy.study.running._warmup import GROUPS

    assert list(_COMPILE_GROUPS) == list(GROUPS)
    cache = tmp_path / "cache"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run(
        [sys.executable, "-m", "rockstudy.cli", "compile", "--group", "closedforms"],
        capture_output=True, text=True, timeout=600, env=env,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    saved = [p.relative_to(cache).as_posix() for p in cache.rglob("*.nbi")]
    assert any("closedform" in p for p in saved), saved
    assert not any("dynamics" in p for p in saved), saved
    bad = cli("compile", "--group", "nope")
    assert bad.returncode == 2 and "invalid choice: 'nope'" in bad.stderr


def test_simulate_with_a_friction_coefficient_runs_the_contact_model(capsys):
    """Below uplift the rocking model's block moves with the ground: its friction demand is
    max |a_g| / g (the contact forces of a block at rest). Above mu the contact model slides
    it from the time a_g = mu g, sin(w t) = mu g / A; below, it stays put; no warning."""
    from rockstudy.cli import main
    from rockstudy.constants import G

    argv = ["simulate", "--width", "0.4", "--height", "1.6", "--amplitude", "1.0"]
    argv += ["--period", "0.5", "--json"]
    assert main(argv + ["--friction", "0.05"]) == 0
    out, err = capsys.readouterr()
    result = json.loads(out)
    assert result["inputs"]["friction"] == 0.05
    assert result["result"]["friction_demand"] == pytest.approx(1.0 / G, rel=1e-12)
    assert result["result"]["lift_off"] is False and err == ""
    slip = math.asin(0.05 * G / 1.0) / (2 * math.pi / 0.5)
    assert result["result"]["first_slip_time"] == pytest.approx(slip, rel=1e-9)
    assert result["result"]["max_slide"] > 0.0
    assert main(argv + ["--friction", "0.5"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and json.loads(out)["result"]["max_slide"] == 0.0
    assert main(argv + ["--friction", "20"]) == 2
    assert capsys.readouterr().err.strip() == "error: friction must lie in (0, 10], got 20.0"
