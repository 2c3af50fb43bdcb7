"""The marker of a store, and claiming a folder for a run.

The marker ``.rockstudy`` is written first into every folder a run creates: the study's
sha256, the sha256 of every input file, the package version, the store format, and whether
the template is complete. :func:`claim` takes a new or empty folder (nothing in it but, at
most, a lock file), or, with ``resume``, a store whose marker (or, where the marker is lost,
whose cube's own attributes) names the same study, input files, version and format, and
agrees with its cube. :func:`discard_if_unused` undoes a claim that nothing got into.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import platform
import shutil
from pathlib import Path

from ..spec.schema import Study
from ._checksums import _check_metadata, _finished_ledgers
from ._files import StoreError, _write_json, file_sha256
from ._lock import LOCK, StoreLock, _refuse_if_held

_PACKAGES = (
    "rockstudy",
    "numpy",
    "scipy",
    "numba",
    "xarray",
    "zarr",
    "dask",
    "distributed",
    "SALib",
    "pydantic",
)


def package_versions() -> dict:
    out = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


#: The layout of a store: 2 since every chunk's checksums cover its status and the arrays'
#: metadata is checked against the consolidated copy. A store of another layout is not resumed.
STORE_FORMAT = 2
MARKER = ".rockstudy"  # written first into every folder a run creates: what it holds


_OWN = {MARKER, LOCK}


def input_hashes(study: Study, base_dir=None) -> dict:
    """The sha256 of every input file of a study (its records, H and V, and the hazard curve's
    file of ``[hazard]``), keyed by their path relative to ``base_dir`` (absolute if outside
    it)."""
    if study.motion.kind != "record":
        return {}
    from ..spec.feasibility import record_pairs, record_path

    base = Path(Path.cwd() if base_dir is None else base_dir)
    paths = []
    for _, h, v in record_pairs(study.motion, base_dir):
        paths.extend((h, v) if v is not None else (h,))
    hazard = getattr(study, "hazard", None)
    if hazard is not None and hazard.kind == "file":
        paths.append(record_path(hazard.file, base_dir))
    out = {}
    for path in paths:
        key = (
            os.path.relpath(path, base)
            if not path.is_absolute() or path.is_relative_to(base)
            else str(path)
        )
        out[key] = file_sha256(path)
    return out


def read_marker(path) -> dict | None:
    """The marker of a store made by rockstudy, or None if the folder has none.

    Raises StoreError if ``.rockstudy`` is there but is not a marker (a folder, unreadable, not
    JSON, not a JSON object)."""
    marker = Path(path) / MARKER
    if not (marker.exists() or marker.is_symlink()):
        return None
    if not marker.is_file():
        raise StoreError(
            f"{marker} is not a rockstudy marker (not a regular file): {Path(path)} is not a "
            "store rockstudy can use; nothing was changed. Choose a new --out"
        )
    try:
        data = json.loads(marker.read_text())
    except (OSError, ValueError) as exc:
        raise StoreError(
            f"{marker} is damaged ({exc}); nothing was changed. The store cannot be checked: "
            "run into a new --out"
        ) from None
    if not isinstance(data, dict):
        raise StoreError(
            f"{marker} is damaged (a JSON {type(data).__name__}, not an object); nothing was "
            "changed. The store cannot be checked: run into a new --out"
        )
    return data


def write_marker(path, **fields) -> None:
    """Write (or update) the marker atomically: a temporary file renamed over it."""
    marker = Path(path) / MARKER
    data = {**(read_marker(path) or {}), **fields}
    _write_json(marker, data)


def _cube_attrs(path) -> dict | None:
    """The cube's own attributes, from its consolidated metadata; None if it has none."""
    try:
        attrs = json.loads((Path(path) / ".zmetadata").read_text())["metadata"][".zattrs"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return attrs if isinstance(attrs, dict) and "study_sha256" in attrs else None


def _legacy_marker(path, attrs) -> dict:
    """The marker of a store whose marker is gone, rebuilt from what its cube records: the
    study's sha256, its input files' sha256 and the rockstudy version. Raises StoreError where
    the cube does not record one of them (it cannot be checked, so it is not resumed)."""
    missing = []
    try:
        inputs = json.loads(attrs["inputs_sha256"])
        if not isinstance(inputs, dict):
            raise TypeError
    except (KeyError, TypeError, ValueError):
        missing.append("the sha256 of its input files")
        inputs = None
    try:
        version = json.loads(attrs["versions"])["rockstudy"]
    except (KeyError, TypeError, ValueError):
        missing.append("the rockstudy version that wrote it")
        version = None
    if not isinstance(attrs.get("study_sha256"), str):
        missing.append("its study's sha256")
    if not attrs.get("template_complete"):
        missing.append("a complete template")
    if missing:
        raise StoreError(
            f"{path} has no {MARKER} marker and its cube does not record {' or '.join(missing)}: "
            "resuming it cannot be checked, so it is refused; nothing was changed. Start afresh: "
            "run into a new --out (or move this folder away)"
        )
    return {
        "study_sha256": attrs["study_sha256"],
        "inputs_sha256": inputs,
        "rockstudy": version,
        "store_format": attrs.get("store_format", 1),
        "template_complete": True,
    }


def _user_entries(path) -> list[str]:
    """What a folder holds besides a lock file (a lock alone holds nothing of anyone's)."""
    return sorted(p.name for p in Path(path).iterdir() if p.name != LOCK)


def claim(path, study: Study, inputs: dict, resume: bool) -> tuple[StoreLock, bool]:
    """Take the folder ``path`` for a run of ``study``, or raise without changing anything.

    A new or empty folder (nothing in it but, at most, a lock file) is created, locked and
    marked. Anything else is used only with ``resume``, and only if its marker ``.rockstudy``
    (the one thing that identifies a store: a lock file never does) names the same study, input
    files and package version. A store whose marker is lost is resumed only if its cube's own
    attributes pass the same checks. Returns the held lock and whether the store's template is
    complete (False: nothing finished yet, the template is (re)written).
    """
    path = Path(path)
    lock = StoreLock(path)
    try:
        path.mkdir(parents=True)
        lock.made_folder = True
    except FileExistsError:
        if not path.is_dir():
            raise StoreError(f"{path} exists and is not a folder: choose a new --out") from None
    if not _user_entries(path):  # new or empty: ours, once locked (a racing run is refused)
        lock.acquire()
        try:
            if _user_entries(path):  # filled since it was listed: look again, from the start
                lock.release()
                return claim(path, study, inputs, resume)
            lock.announce()
            write_marker(path, **_identity(study, inputs), template_complete=False)
        except BaseException:
            lock.release()
            raise
        return lock, False
    marker = _marker_or_legacy(path)
    if not resume:
        _refuse_if_held(path)
        raise FileExistsError(
            f"{path} holds a rockstudy store: continue it with --resume, or choose a new --out"
        )
    _check_same(path, marker, study.sha256(), inputs)  # read only: nothing is touched yet
    _check_marker_agrees(path, marker)
    lock.acquire()
    try:
        marker = _marker_or_legacy(path)  # again, under the lock
        _check_same(path, marker, study.sha256(), inputs)
        _check_marker_agrees(path, marker)
        complete = bool(marker.get("template_complete"))
        if complete:
            _check_metadata(path)
        lock.announce()
        if read_marker(path) is None:  # a store that lost its marker, checked: marked again
            write_marker(path, **marker)
        return lock, complete
    except BaseException:
        lock.release()
        raise


def _marker_or_legacy(path) -> dict:
    """The marker of the store in ``path``, or one rebuilt from its cube (see
    :func:`_legacy_marker`); StoreError if the folder is not a rockstudy store."""
    marker = read_marker(path)
    if marker is not None:
        return marker
    attrs = _cube_attrs(path)
    if attrs is None:
        entries = _user_entries(path)
        shown = ", ".join(entries[:5]) + (", ..." if len(entries) > 5 else "")
        raise StoreError(
            f"{path} is not a rockstudy store (it holds {shown}): nothing was written; "
            "choose a new --out"
        )
    return _legacy_marker(path, attrs)


def _identity(study, inputs) -> dict:
    return {
        "study_sha256": study.sha256(),
        "inputs_sha256": inputs,
        "rockstudy": package_versions()["rockstudy"],
        "store_format": STORE_FORMAT,
    }


def _check_same(path, marker, sha, inputs) -> None:
    """Refuse to resume across a change of study, input file or rockstudy version."""
    if marker.get("study_sha256") != sha:
        raise ValueError(f"{path} holds a different study (sha256 mismatch); cannot resume")
    before = marker.get("inputs_sha256")
    if not isinstance(before, dict):
        raise StoreError(
            f"{path}: its marker does not record the sha256 of the input files, so resuming "
            "cannot be checked; nothing was changed. Start afresh: run into a new --out"
        )
    if before != inputs:
        changed = sorted(k for k in set(before) | set(inputs) if before.get(k) != inputs.get(k))
        raise StoreError(
            f"{path}: input file(s) {', '.join(changed)} changed since this store was started; "
            "resuming would mix results of different inputs: restore them, or run into a new "
            "--out"
        )
    if marker.get("store_format", 1) != STORE_FORMAT:
        raise StoreError(
            f"{path} was written in store format {marker.get('store_format', 1)} by an earlier "
            f"rockstudy; this one writes format {STORE_FORMAT} (every chunk's checksums cover its "
            "status): run the study into a new --out"
        )
    version = package_versions()["rockstudy"]
    if marker.get("rockstudy") != version:
        raise StoreError(
            f"{path} was started by rockstudy {marker.get('rockstudy')}, this is {version}: "
            "resuming would mix results of two versions; run into a new --out"
        )


def discard_if_unused(path, made_folder=True) -> None:
    """Undo a claim that nothing got into: remove the folder if this run made it, else only
    the marker and lock it wrote (the folder was empty before)."""
    path = Path(path)
    marker = read_marker(path)
    if marker is not None and not marker.get("template_complete"):
        if {entry.name for entry in path.iterdir()} <= _OWN:
            if made_folder:
                shutil.rmtree(path)
            else:
                for name in _OWN:
                    (path / name).unlink(missing_ok=True)


def template_complete(path) -> bool:
    """Whether a store's template was fully written (False only if it has not been)."""
    marker = read_marker(path)
    if marker is not None:
        return bool(marker.get("template_complete"))
    try:
        meta = (Path(path) / ".zmetadata").read_text()
    except FileNotFoundError:
        return False
    try:
        return bool(json.loads(meta)["metadata"][".zattrs"].get("template_complete"))
    except (ValueError, KeyError, TypeError) as exc:
        raise StoreError(f"{path}/.zmetadata is damaged ({exc}); nothing was changed") from None


def _marker_disagreement(path, marker) -> str | None:
    """What the marker says against the cube's own record (its attributes and checksums), or
    None if they agree. A marker that says the template is unfinished agrees with a cube that
    has finished no chunk: a run killed while writing its template leaves one."""
    attrs = _cube_attrs(path)
    if attrs is not None:
        if attrs.get("study_sha256") != marker.get("study_sha256"):
            return (
                "names another study than its cube's own attributes (a marker copied from "
                "another store?)"
            )
        try:
            inputs = json.loads(attrs["inputs_sha256"])
        except (KeyError, TypeError, ValueError):
            inputs = marker.get("inputs_sha256")  # not recorded in the cube: nothing to compare
        if inputs != marker.get("inputs_sha256"):
            return "names other input files than its cube's own attributes"
    finished = _finished_ledgers(path)
    if not marker.get("template_complete") and finished:
        return (
            f"says its template was never completed, but the cube holds {len(finished)} "
            "finished chunks"
        )
    return None


def _check_marker_agrees(path, marker) -> None:
    """Refuse (StoreError) a marker that disagrees with the cube: it is not believed."""
    what = _marker_disagreement(path, marker)
    if what is not None:
        raise StoreError(
            f"{path}: its marker {MARKER} {what}: it is not believed and nothing was changed. "
            "Restore the store's own marker, or run into a new --out"
        )
