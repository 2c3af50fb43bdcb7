"""Safe concurrent writes to numba's on-disk cache (private).

numba saves a kernel's machine code under a data file name chosen from the function's cache
index (``*.nbi``), and rewrites the index, without a lock (numba 0.58 to 0.68:
``numba.core.caching.IndexDataCacheFile.save``). Two processes that compile two signatures of
one function at the same time can both pick ``<name>.1.nbc``: one signature is then lost from
the index, or mapped to the other signature's machine code. :func:`serialize_cache_writes`
makes that read-choose-write step exclusive between processes (``fcntl.flock`` on a lock file
beside the index), so that processes may compile in parallel: ``rockstudy compile`` runs its
groups of kernels in a pool of processes (:mod:`rockstudy.study.running._warmup`).
"""

from __future__ import annotations

import contextlib
import functools
import os

_LOCKED = "_rockstudy_locked"


@contextlib.contextmanager
def _exclusive(path):
    """An exclusive ``flock`` on ``path`` (created if needed) while the block runs; no lock
    where ``fcntl`` is missing (Windows), where numba's own behaviour remains."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def serialize_cache_writes() -> bool:
    """Make numba's cache saves exclusive between processes (idempotent).

    Returns
    -------
    bool
        True if the save is (now) locked, False if this numba has no
        ``IndexDataCacheFile.save`` to wrap (its processes must then compile one at a time).
    """
    from numba.core import caching

    cls = getattr(caching, "IndexDataCacheFile", None)
    save = getattr(cls, "save", None)
    if save is None:
        return False
    if getattr(save, _LOCKED, False):
        return True

    @functools.wraps(save)
    def locked_save(self, key, data):
        with _exclusive(self._index_path + ".lock"):
            return save(self, key, data)

    setattr(locked_save, _LOCKED, True)
    cls.save = locked_save
    return True
