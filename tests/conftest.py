from pathlib import Path

import pytest

RECORDS = Path(__file__).resolve().parents[1].parent / "shared" / "records"


@pytest.fixture(scope="session")
def records_dir():
    if not RECORDS.is_dir():
        pytest.skip(f"shared records not found at {RECORDS}")
    return RECORDS
