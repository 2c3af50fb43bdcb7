"""The chunks of a cube and their checksums.

:class:`ChunkWriter` writes each finished chunk in three stages: its outputs; the sha256 of
every file of the chunk, ``status`` included (encoded beforehand in a staging array), into
``.rockstudy-chunks/<k>``; and its ``status`` file, moved in by one rename.
:func:`_chunk_finished` tells a finished chunk (status done, files as summed) from a pending
one (status 0) and raises :class:`_ChunkDamage` for anything else. The template's sums
(``.rockstudy-chunks/template``: the sha256 of ``.zmetadata`` and of the design's files, and
the names of the result arrays) are written and read here, and :func:`_check_metadata` checks
the consolidated metadata when a run claims a store to resume.
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

import numpy as np

from ._files import StoreError, _write_json, file_sha256
from .evaluate import STATUS_FAILED, STATUS_OK, STATUS_PENDING


def chunk_bounds(n: int, size: int) -> list[tuple[int, int]]:
    """[start, stop) of each chunk of ``size`` rows."""
    return [(i, min(i + size, n)) for i in range(0, n, size)]


CHECKSUMS = ".rockstudy-chunks"  # the sha256 of each finished chunk's files
DONE = (STATUS_OK, STATUS_FAILED)


def _check_metadata(path) -> None:
    """The consolidated metadata of a complete template must be the one written (its sha256,
    where recorded) and must open; else report, never rebuild."""
    import zarr

    path = Path(path)
    advice = (
        "If the arrays' own metadata are intact, rebuild it with python -c \"import zarr; "
        f"zarr.consolidate_metadata('{path}', zarr_format=2)\" and --resume again"
    )
    sums = read_template_sums(path)
    if sums is None:  # written with the template, before its marker said it was complete
        raise StoreError(
            f"{path}: the sums of its metadata and design ({CHECKSUMS}/{TEMPLATE_SUMS}) are "
            "missing or unreadable, so the cube cannot be checked; nothing was changed. Run "
            "the study into a new --out"
        )
    try:
        json.loads((path / ".zmetadata").read_text())["metadata"]
        if file_sha256(path / ".zmetadata") != sums["files"].get(".zmetadata"):
            advice = "The cube cannot be trusted: run the study into a new --out"
            raise ValueError("it differs from the file written: its sha256 changed")
        group = zarr.open_group(str(path), mode="r", zarr_format=2, use_consolidated=True)
        for _, array in group.arrays():
            array.metadata  # noqa: B018 - decoding each array's metadata is the check
    except Exception as exc:  # noqa: BLE001 - whatever does not open: one line, nothing changed
        raise StoreError(
            f"{path}/.zmetadata is damaged ({type(exc).__name__}: {' '.join(str(exc).split())}); "
            f"nothing was changed. {advice}"
        ) from None


def _chunk_file(group, name, k) -> str:
    """The file of zarr chunk ``k`` (along ``sample``) of the array ``name``."""
    return str(k) + ".0" * (group[name].ndim - 1)


class ChunkWriter:
    """Writes finished chunks into the zarr arrays of a cube in three stages (:attr:`STAGES`):
    the outputs, then their checksums with that of the chunk's ``status``, then ``status``.

    The arrays were created by :func:`create_store` with the study's chunks, so each chunk
    write touches its own zarr chunks only. ``status`` is encoded first into a staging copy of
    its array (``.rockstudy-chunks/staging``), so that its sha256 is known before it is
    written: the checksums (``.rockstudy-chunks/<k>``) cover every file of the chunk, status
    included, and the status file then moves into the cube in one rename. A kill at any stage
    leaves the chunk pending (its status still reads 0) or finished and covered.
    """

    STAGES = ("outputs", "checksums", "status")

    def __init__(self, path):
        import zarr

        self.path = Path(path)
        self.group = zarr.open_group(str(path), mode="r+", zarr_format=2)
        self.size = self.group["status"].chunks[0]
        self.staging = _staging_array(self.path)

    def write(self, start: int, stop: int, result: dict) -> None:
        """Write the chunk ``[start, stop)`` whole: every stage of :meth:`stages`."""
        for stage in self.stages(start, stop, result):
            stage()

    def stages(self, start: int, stop: int, result: dict) -> list:
        """The writes of the chunk ``[start, stop)``, in order (one callable per stage)."""
        import zarr

        k = start // self.size
        names = [name for name in result if name != "status"]
        status_file = self.staging.path / str(k)

        def outputs():
            # every chunk file is written, even one equal to the fill value: a done chunk
            # whose file is missing is then known to be lost (see chunks_to_compute)
            with zarr.config.set({"array.write_empty_chunks": True}):
                for name in names:
                    self.group[name][start:stop] = result[name]

        def checksums():
            with zarr.config.set({"array.write_empty_chunks": True}):
                self.staging.array[start:stop] = result["status"]
            sums = {
                name: file_sha256(self.path / name / _chunk_file(self.group, name, k))
                for name in names
                if self.group[name].size  # an array of no values has no chunk files
            }
            sums["status"] = file_sha256(status_file)
            _write_json(self.path / CHECKSUMS / str(k), sums)

        def status():
            os.replace(status_file, self.path / "status" / str(k))

        return [outputs, checksums, status]


@dataclasses.dataclass
class _Staging:
    path: Path
    array: object


def _staging_array(path) -> _Staging:
    """An empty copy of the cube's ``status`` array (its metadata from ``.zmetadata``), in
    which a chunk's status is encoded before it moves into the cube."""
    import zarr

    folder = Path(path) / CHECKSUMS / "staging"
    folder.mkdir(parents=True, exist_ok=True)
    _write_json(folder / ".zarray", _consolidated(path)["status/.zarray"])
    return _Staging(folder, zarr.open_array(str(folder), mode="r+", zarr_format=2))


TEMPLATE_SUMS = "template"  # in CHECKSUMS: the sha256 of .zmetadata and of the design's files


def _files_of(path, name) -> list[Path]:
    """The chunk files of the array ``name`` (its metadata files left out)."""
    folder = Path(path) / name
    return sorted(p for p in folder.iterdir() if p.is_file() and not p.name.startswith("."))


def _arrays(meta) -> dict:
    """The arrays of a cube's consolidated metadata: name -> its ``.zarray``."""
    return {key.split("/")[0]: value for key, value in meta.items() if key.endswith("/.zarray")}


def write_template_sums(path, names) -> None:
    """Record the sha256 of the consolidated metadata and of every chunk file of the design
    variables ``names``, and the names of the result arrays (all the others), whose files each
    finished chunk's checksums must cover."""
    path = Path(path)
    files = {".zmetadata": file_sha256(path / ".zmetadata")}
    for name in names:
        for file in _files_of(path, name):
            files[f"{name}/{file.name}"] = file_sha256(file)
    results = sorted(set(_arrays(_consolidated(path))) - set(names))
    (path / CHECKSUMS).mkdir(exist_ok=True)
    _write_json(path / CHECKSUMS / TEMPLATE_SUMS, {"files": files, "results": results})


def read_template_sums(path) -> dict | None:
    """The sums written with the template (``files``: path -> sha256, ``results``: names), or
    None if they are missing or unreadable."""
    try:
        sums = json.loads((Path(path) / CHECKSUMS / TEMPLATE_SUMS).read_text())
        if isinstance(sums["files"], dict) and isinstance(sums["results"], list):
            return sums
    except (OSError, ValueError, KeyError, TypeError):
        pass
    return None


def _finished_ledgers(path) -> list[str]:
    """The chunks that have checksums in ``.rockstudy-chunks`` (written only once the
    template is complete)."""
    folder = Path(path) / CHECKSUMS
    return sorted(p.name for p in folder.iterdir() if p.name.isdigit()) if folder.is_dir() else []


class _ChunkDamage(Exception):
    """A chunk that is neither pending nor finished and covered: ``variable``, ``what``."""

    def __init__(self, variable, what):
        super().__init__(what)
        self.variable, self.what = variable, what


def _results_with_values(meta, names) -> dict:
    """Of the result arrays ``names``, those that hold values: name -> its number of
    dimensions (an array of no values has no chunk files)."""
    arrays = _arrays(meta)
    return {
        name: len(arrays[name]["shape"])
        for name in names
        if name in arrays and all(arrays[name]["shape"])
    }


def _chunk_finished(path, results, k, status) -> bool:
    """Whether chunk ``k`` is finished (True) or pending (False).

    Finished: its status reads 1 or 2, and every file of it (each of ``results``, a dict name
    -> number of dimensions, ``status`` included) has the sha256 in ``.rockstudy-chunks/<k>``.
    Pending: its status reads 0 (its checksums, if any, are those of a write a kill stopped
    before its status moved in). ``status`` is the chunk's decoded status (None if it does not
    decode). Raises :class:`_ChunkDamage` for anything else.
    """
    path = Path(path)
    if not (path / "status" / str(k)).is_file():
        raise _ChunkDamage("status", "its file is missing (every chunk has one from the start)")
    if status is None or not np.all(np.isin(status, (STATUS_PENDING, *DONE))):
        raise _ChunkDamage("status", "it does not decode to 0, 1 or 2")
    if np.all(status == STATUS_PENDING):
        return False
    if np.any(status == STATUS_PENDING):
        raise _ChunkDamage("status", "it is partly pending, partly done")
    try:
        sums = json.loads((path / CHECKSUMS / str(k)).read_text())
        if not isinstance(sums, dict):
            raise ValueError
    except (OSError, ValueError):
        raise _ChunkDamage(
            "status",
            f"it reads finished, but the checksums of its chunk ({CHECKSUMS}/{k}) are missing "
            "or unreadable",
        ) from None
    for name, ndim in results.items():
        try:
            same = file_sha256(path / name / (str(k) + ".0" * (ndim - 1))) == sums[name]
        except (OSError, KeyError):
            same = False
        if not same:
            raise _ChunkDamage(name, "its file is missing or differs from the one written")
    return True


def _status_chunks(status, bounds):
    """The decoded status of each chunk (None where it does not decode), read at once where
    the whole array decodes."""
    try:
        whole = status[:]
    except Exception:  # noqa: BLE001 - chunk by chunk, to find the one that does not decode
        whole = None
    for a, b in bounds:
        try:
            yield status[a:b] if whole is None else whole[a:b]
        except Exception:  # noqa: BLE001 - a status chunk that does not decode
            yield None


def _consolidated(path) -> dict:
    return json.loads((Path(path) / ".zmetadata").read_text())["metadata"]
