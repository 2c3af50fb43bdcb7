"""Verifying a cube against the sha256 recorded when it was written.

:func:`verify_cube` checks the marker against the cube, the template's sums, every metadata
file against its copy in ``.zmetadata``, and each chunk; it raises :class:`DamagedCube`
naming the first damaged variable and chunk. :func:`_metadata_differences` also tells a
resume which metadata files to restore.
"""

from __future__ import annotations

import json
from pathlib import Path

from ._checksums import (
    CHECKSUMS,
    TEMPLATE_SUMS,
    _chunk_finished,
    _ChunkDamage,
    _consolidated,
    _results_with_values,
    _status_chunks,
    chunk_bounds,
    read_template_sums,
)
from ._files import StoreError, file_sha256
from ._marker import MARKER, _marker_disagreement, read_marker

_METADATA = (".zarray", ".zattrs", ".zgroup")  # the files of zarr v2 metadata
_MARKER_VARIABLE = f"{MARKER} (the store's marker)"


class DamagedCube(StoreError):
    """A cube whose files differ from what was written: ``variable`` and ``chunk`` (None for
    the metadata or the design) name the first damage found."""

    def __init__(self, message, variable, chunk=None):
        super().__init__(message)
        self.variable, self.chunk = variable, chunk


_RECOMPUTE = "rockstudy run ... --resume computes it again"
_RESTORE = "rockstudy run ... --resume restores it from the checked .zmetadata"
_AFRESH = "run the study again into a new --out"


def _damaged(path, what, variable, chunk=None, rows=None, advice=None):
    where = f"variable {variable!r}" + ("" if chunk is None else f", chunk {chunk}")
    where += "" if rows is None else f" (samples {rows[0]} to {rows[1] - 1})"
    if advice is None:
        advice = _RECOMPUTE if chunk is not None else _AFRESH
    return DamagedCube(
        f"{path} is damaged: {where}: {what}; it is not read. {advice}", variable, chunk
    )


def _verify_template(path, sums) -> int:
    """Check the files recorded at template time; the count checked."""
    for key, want in sums.items():
        variable, _, file = key.partition("/")
        try:
            same = file_sha256(Path(path) / key) == want
        except OSError:
            same = False
        if not same:
            what = "its file is missing or differs from the one written"
            if key == ".zmetadata":
                raise _damaged(path, what, ".zmetadata (the cube's metadata)")
            raise _damaged(path, f"{what} (chunk file {file})", variable)
    return len(sums)


def _metadata_files(path) -> set[str]:
    """The zarr metadata files of a cube (its own and each array's), relative to it."""
    path = Path(path)
    found = {name for name in _METADATA if (path / name).exists()}
    for folder in path.iterdir():
        if folder.is_dir() and not folder.name.startswith("."):
            found.update(f"{folder.name}/{n}" for n in _METADATA if (folder / n).exists())
    return found


def _metadata_differences(path, meta) -> list[str]:
    """The metadata files that are missing, differ from their copy in the consolidated
    metadata ``meta`` (itself checked by its sha256), or are not in it."""
    out = []
    for key in sorted(set(meta) | _metadata_files(path)):
        try:
            same = json.loads((Path(path) / key).read_text()) == meta[key]
        except (OSError, ValueError, KeyError):
            same = False
        if not same:
            out.append(key)
    return out


def _check_array_metadata(path, meta) -> int:
    """Raise DamagedCube naming the first metadata file that does not read as written; the
    count checked."""
    for key in _metadata_differences(path, meta):
        variable = key.rpartition("/")[0] or f"{key} (the cube's own metadata)"
        what = (
            f"its metadata file {key} is missing or differs from its copy in .zmetadata"
            if key in meta
            else f"it holds a metadata file {key} that .zmetadata does not list"
        )
        raise _damaged(path, what, variable, advice=_RESTORE if key in meta else _AFRESH)
    return len(meta)


def written_by_run(path) -> bool:
    """Whether a zarr folder was written by a run (:func:`run_study`): it has the marker, the
    checksums, or the attribute ``template_complete`` that only a run's template sets. A
    dataset saved with ``to_zarr`` has none of them."""
    path = Path(path)
    if (path / MARKER).exists() or (path / CHECKSUMS).exists():
        return True
    try:
        attrs = json.loads((path / ".zmetadata").read_text())["metadata"][".zattrs"]
        return "template_complete" in attrs
    except (OSError, ValueError, KeyError, TypeError):
        return False


def _check_template_state(path) -> None:
    """Refuse a cube whose marker disagrees with it (DamagedCube), or whose run stopped before
    its template was complete (StoreError: it holds nothing to verify)."""
    marker = read_marker(path)
    if marker is None:
        return
    what = _marker_disagreement(path, marker)
    if what is not None:
        raise _damaged(path, f"it {what}", _MARKER_VARIABLE)
    if not marker.get("template_complete"):
        raise StoreError(
            f"{path}: its run stopped before its template was complete, so it holds no results "
            f"yet: resume it (rockstudy run STUDY --out {path} --resume)"
        )


def verify_cube(path) -> dict:
    """Check a zarr cube written by a run against the sha256 recorded when it was written.

    Checked: the marker against the cube's own attributes; the consolidated metadata and the
    design's files (recorded with the template); every metadata file against its copy in the
    consolidated metadata; and each chunk (see :func:`_chunk_finished`): pending, or finished
    with every file of it, ``status`` included, as written. Returns ``{"chunks", "done",
    "files"}``; raises :class:`DamagedCube` (a StoreError) naming the first damaged variable
    and chunk, or StoreError for a folder that is not a cube a run finished writing the
    template of.
    """
    import zarr

    path = Path(path)
    if not path.is_dir():
        raise StoreError(f"{path} is not a folder: a zarr cube is a folder written by a run")
    if not written_by_run(path):
        raise StoreError(
            f"{path} was not written by rockstudy run (no marker, checksums or template "
            "attribute): it carries no checksums to verify"
        )
    _check_template_state(path)
    sums = read_template_sums(path)
    if sums is None:
        copied = not (path / MARKER).exists() and not (path / CHECKSUMS).exists()
        raise _damaged(
            path,
            f"the sums of its metadata and design ({CHECKSUMS}/{TEMPLATE_SUMS}) are missing or "
            "unreadable"
            + (
                " (a copy saved with to_zarr has none: open_result(..., verify=False) reads "
                "it unchecked)"
                if copied
                else ""
            ),
            ".zmetadata (the cube's metadata)",
        )
    files = _verify_template(path, sums["files"])
    try:
        meta = _consolidated(path)
        files += _check_array_metadata(path, meta)
        status = zarr.open_group(str(path), mode="r", zarr_format=2, use_consolidated=True)[
            "status"
        ]
        bounds = chunk_bounds(status.shape[0], status.chunks[0])
    except DamagedCube:
        raise
    except Exception as exc:  # noqa: BLE001 - metadata that does not open: one line
        raise _damaged(path, f"it does not open ({type(exc).__name__})", "status") from None
    results = _results_with_values(meta, sums["results"])
    done = 0
    for k, (rows, values) in enumerate(zip(bounds, _status_chunks(status, bounds), strict=True)):
        try:
            finished = _chunk_finished(path, results, k, values)
        except _ChunkDamage as exc:
            raise _damaged(path, exc.what, exc.variable, k, rows) from None
        done += finished
        files += len(results) if finished else 0
    return {"chunks": len(bounds), "done": done, "files": files}
