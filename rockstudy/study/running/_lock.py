"""The lock of a store: an exclusive ``flock`` a run holds for its whole life.

A run holds ``.rockstudy.lock`` (``fcntl.flock``, naming its PID and host once the run is
accepted): a second run on the same store is refused at once, and the lock of a killed run
vanishes with its process, so ``--resume`` after SIGKILL just works. A lock file never
identifies a store: only its marker does (:mod:`._marker`).
"""

from __future__ import annotations

import json
import os
import socket
import time
from pathlib import Path

from ._files import StoreError

LOCK = ".rockstudy.lock"  # flock-ed by the run that writes the store, naming its PID and host


class StoreLock:
    """An exclusive ``flock`` on ``<store>/.rockstudy.lock`` held for the life of a run.

    The kernel drops the lock when its process dies (even by SIGKILL), so a lock file left by a
    killed run is stale by construction and the next run takes it over. The file names the
    holder (PID, host, start time) for the message that refuses a second run; it is written
    only by :meth:`announce`, once the run is accepted: a refused run leaves it as it was.
    """

    def __init__(self, folder):
        self.path = Path(folder) / LOCK
        self.fd = None
        self.made_folder = False  # set by claim() when it created the folder

    def acquire(self) -> None:
        """Take the lock (creating its file), or raise StoreError naming its holder."""
        import fcntl

        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.read(fd, 4096).decode("utf-8", "replace")
            os.close(fd)
            try:
                h = json.loads(holder)
                who = f"PID {h['pid']} on host {h['host']} (since {h['since']})"
            except (ValueError, KeyError, TypeError):
                who = "another process"
            raise StoreError(
                f"{self.path.parent} is in use by another rockstudy run, {who}: refused; wait "
                "for it to end (or stop it), then --resume"
            ) from None
        self.fd = fd

    def announce(self) -> None:
        """Write this process as the holder into the lock file (the lock is held)."""
        os.ftruncate(self.fd, 0)
        holder = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "since": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
        os.pwrite(self.fd, json.dumps(holder).encode(), 0)

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)  # closing the descriptor drops the flock
            self.fd = None

    def __enter__(self):
        self.acquire()
        return self

    def __exit__(self, *exc):
        self.release()


def _refuse_if_held(path) -> None:
    """Raise StoreError naming the holder if a run holds the lock of ``path``; changes nothing
    (a lock file that is not there is not created)."""
    if (Path(path) / LOCK).is_file():
        with StoreLock(path):  # released at once, never announced
            pass
