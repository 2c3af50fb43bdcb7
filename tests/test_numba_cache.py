"""Concurrent writes to numba's on-disk cache (rockstudy._numba_cache): the parallel
``rockstudy compile`` relies on a process saving a kernel only while it holds the lock of that
kernel's cache index. The oracle is the file system and the child process's own progress: a
save reached while another process holds the lock writes nothing until the lock is released.
"""

import fcntl
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

KERNEL = """
from numba import njit


@njit(cache=True)
def twice(x):
    return 2.0 * x
"""

CHILD = """
import sys
sys.path.insert(0, sys.argv[1])
from numba.core import caching
from rockstudy._numba_cache import serialize_cache_writes
assert serialize_cache_writes() and serialize_cache_writes()  # idempotent
locked = caching.IndexDataCacheFile.save


def announced(self, key, data):
    print("saving", flush=True)
    return locked(self, key, data)


caching.IndexDataCacheFile.save = announced
import kern
print(kern.twice(21.0), flush=True)
"""


def test_a_cache_save_waits_for_the_index_lock(tmp_path):
    (tmp_path / "kern.py").write_text(KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))
    probe = "import sys; sys.path.insert(0, sys.argv[1]); import kern; "
    probe += "print(kern.twice._cache._cache_file._index_path)"
    index = subprocess.run(
        [sys.executable, "-c", probe, str(tmp_path)], env=env, capture_output=True, text=True
    ).stdout.strip()
    assert index.endswith(".nbi")
    Path(index).parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(index + ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    fcntl.flock(fd, fcntl.LOCK_EX)
    child = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(CHILD), str(tmp_path)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout.readline().strip() == "saving"  # compiled, at the save
        time.sleep(1.0)
        assert child.poll() is None  # blocked on the lock we hold
        assert not os.path.exists(index)  # and nothing written
    finally:
        os.close(fd)  # releases the lock
    out, err = child.communicate(timeout=300)
    assert child.returncode == 0, err[-2000:]
    assert out.strip() == "42.0"
    assert os.path.exists(index) and list(Path(index).parent.glob("kern.twice-*.nbc"))
