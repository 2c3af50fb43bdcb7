"""The README runs as written: every Python block executes in a fresh interpreter from the
project root, and every TOML block is a valid study. Nothing may need files outside the
repository (a downloaded clone has no ../shared)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
BLOCKS = re.findall(r"^```(\w+)\n(.*?)^```", README, flags=re.S | re.M)
PYTHON = [code for lang, code in BLOCKS if lang == "python"]
TOML = [code for lang, code in BLOCKS if lang == "toml"]


def test_readme_is_a_front_door():
    """The README stays short enough to read at once; the rest lives in the docs site."""
    assert len(README.splitlines()) <= 250


def test_readme_has_runnable_blocks():
    assert PYTHON, "the README shows no Python example"
    assert "../shared" not in README, "the README points outside the repository"


@pytest.mark.parametrize("code", PYTHON, ids=[f"python-{i}" for i in range(len(PYTHON))])
def test_python_block_runs(code, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    proc = subprocess.run(
        [sys.executable, "-W", "error::SyntaxWarning", "-c", code],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]


@pytest.mark.parametrize("text", TOML, ids=[f"toml-{i}" for i in range(len(TOML))])
def test_toml_block_is_a_valid_study(text):
    from rockstudy.study import validate_text

    validate_text(text)
