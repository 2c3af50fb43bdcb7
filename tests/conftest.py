"""Fixtures shared by the test modules: the shared real records (``records_dir``) and one
in-process dask client (``client``).

The shared real records are for the tests that need them (``records_dir``).

They are looked for in ``ROCKSTUDY_RECORDS`` if set, else in ``../shared/records`` beside the
project. Without them those tests are skipped on a workstation, but under CI (``CI=true``) a
missing folder fails them: a CI run must not pass by skipping the real-record tests. The
record readers themselves are tested on files the tests write (tests/test_readers.py).
"""

import os
from pathlib import Path

import pytest

from rockstudy._numba_cache import serialize_cache_writes

# The tests run in several processes (pytest-xdist): their numba cache saves must not race.
serialize_cache_writes()

#: The test files that take longest, run first: the two processes take files in the order
#: collected, so a long file collected late would leave one process working alone at the end.
LONGEST_FIRST = (
    "test_first_result.py",
    "test_study.py",
    "test_run_cli.py",
    "test_contact_kernel.py",
)


def pytest_collection_modifyitems(items):
    """Put the items of :data:`LONGEST_FIRST` first (a stable sort: the rest keep their
    order)."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


RECORDS = Path(
    os.environ.get("ROCKSTUDY_RECORDS")
    or Path(__file__).resolve().parents[1].parent / "shared" / "records"
)


def _under_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


@pytest.fixture(scope="session")
def client():
    """One in-process dask client for the whole session (each xdist worker has its own): a
    local cluster of threads in the test process, so that ``run_study(..., client=client)``
    starts no worker process. The tests of the worker processes themselves (kills, Ctrl-C,
    lost workers) start their own clusters or real ``rockstudy run`` processes."""
    import dask
    from distributed import Client

    from rockstudy.study.running.runner import NO_PROFILER

    dask.config.set(NO_PROFILER)  # the profiler's thread can crash CPython 3.11 (runner.py)
    with Client(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=":0") as c:
        yield c


@pytest.fixture(scope="session")
def records_dir():
    if not RECORDS.is_dir():
        message = f"shared records not found at {RECORDS} (set ROCKSTUDY_RECORDS)"
        if _under_ci():
            pytest.fail(f"CI=true: {message}", pytrace=False)
        pytest.skip(message)
    return RECORDS
