"""What every part of the store shares: :class:`StoreError`, the sha256 of a file, and the
atomic write of a JSON file (the marker, the checksums, restored metadata)."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path


class StoreError(RuntimeError):
    """A store that cannot be used as asked: not ours, in use, another study, or damaged.

    Nothing was changed when it is raised."""


def file_sha256(path) -> str:
    """The sha256 of a file's contents."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _write_json(target, data) -> None:
    """Write ``data`` as JSON into ``target`` atomically (a temporary file renamed over it)."""
    target = Path(target)
    tmp = target.with_name(target.name + ".tmp")
    tmp.write_text(json.dumps(data))
    os.replace(tmp, target)
