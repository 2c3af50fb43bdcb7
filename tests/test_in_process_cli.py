"""The ``rockstudy`` command run in the test process (``_helpers.cli``) leaves the process as it
found it: the tests that run it in-process instead of in a real process must not change what
the tests after them see. The oracle is the process state itself, read before and after."""

import logging
import os
import warnings

import numpy as np
from _helpers import cli, write_study

from rockstudy.motions import measures


def _state():
    loggers = ["distributed"] + sorted(
        n for n in logging.root.manager.loggerDict if n.startswith("distributed.")
    )
    return {
        "cwd": os.getcwd(),
        "numpy": np.get_printoptions(),
        "loggers": {n: logging.getLogger(n).level for n in loggers},
        "filters": list(warnings.filters),
        "measures": dict(measures.MEASURES),
    }


def test_a_refused_run_changes_nothing_in_this_process(tmp_path):
    """A run that sets numpy's legacy printing and quietens dask's loggers, then is refused
    (its --out is a file): one error line, exit 2, and the process state as before."""
    study = write_study(tmp_path, n=20)
    (tmp_path / "taken").write_text("a file of the user")
    before = _state()
    code, out, err = cli("run", study, "--out", tmp_path / "taken", "--workers", "1")
    assert code == 2 and out == "" and err.startswith("error: "), err
    after = _state()
    new_loggers = set(after["loggers"]) - set(before["loggers"])
    assert all(after["loggers"][n] == logging.NOTSET for n in new_loggers)
    after["loggers"] = {n: after["loggers"][n] for n in before["loggers"]}
    assert after == before


def test_a_finished_run_changes_nothing_in_this_process(tmp_path):
    """A finished run in threads of this process: exit 0, its summary, and the state as before
    (the cluster it started is gone with it)."""
    study = write_study(tmp_path, n=20)
    before = _state()
    code, out, err = cli("run", study, "--out", tmp_path / "c.zarr", "--workers", "1", "--quiet")
    assert code == 0 and "20 samples in 2 chunks" in out, err
    after = _state()
    after["loggers"] = {n: after["loggers"][n] for n in before["loggers"]}
    assert after == before


def test_a_warning_of_the_command_is_on_its_stderr():
    """A Python warning the command lets through is on stderr, as a real process shows it
    (pytest would otherwise record it out of sight)."""
    code, _, err = cli(
        "simulate", "--half-diagonal", "1", "--slenderness", "0.2", "--amplitude", "3",
        "--period", "0.5", "--method", "complex",
    )  # fmt: skip
    assert code == 0 and "ComplexFromRestWarning" in err, err
