"""The result cube: a zarr store written chunk by chunk, with a ``status`` written last.

The template (design, outputs filled with their fill values, ``status`` = 0 pending, every
chunk file written) is written first. Each finished chunk is written into its own region (zarr
chunks are aligned with the study's chunks, so no two writers ever share a zarr chunk) in three
stages (:class:`ChunkWriter`): its outputs; the sha256 of every file of the chunk, ``status``
included (encoded beforehand in a staging array), into ``.rockstudy-chunks/<k>``; and its
``status`` file, moved in by one rename. A chunk whose status reads done and whose files match
those sums is finished; one whose status reads pending is pending; anything else is damaged. A
killed run resumes from the pending chunks.

The store never destroys what it did not write. A run claims a folder only if it is new (or
empty: nothing in it but, at most, a lock file), and writes a marker file ``.rockstudy`` into
it first (the study's sha256, the sha256 of every input file, the package version, and whether
the template is complete). Only that marker identifies a store: a lock file never does, and a
store whose marker is lost is resumed only if its cube's own attributes pass the marker's
checks. A marker is believed only where it agrees with the cube: the same study and input
files as the cube's attributes, and no finished chunk if it says the template is unfinished.
A run holds an exclusive lock (``.rockstudy.lock``, ``fcntl.flock``, naming its PID and
host once the run is accepted) for its whole life: a second run on the same store is refused
at once, and the lock of a killed run vanishes with its process, so ``--resume`` after SIGKILL
just works. The template records the sha256 of ``.zmetadata`` and of the design's files; every
other metadata file must read as its copy in ``.zmetadata``. On resume a chunk marked done
whose files are missing or differ is computed again and metadata files are restored from
``.zmetadata``; a reader (:func:`open_result`, :func:`verify_cube`) refuses a cube whose files
differ.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import importlib.metadata
import json
import os
import platform
import shutil
import socket
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from ...constants import STANDARD_GRAVITY, G
from ..spec.schema import Study
from .evaluate import OUTPUTS, STATUS_FAILED, STATUS_OK, STATUS_PENDING

_INT32 = np.iinfo(np.int32)
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


def chunk_bounds(n: int, size: int) -> list[tuple[int, int]]:
    """[start, stop) of each chunk of ``size`` rows."""
    return [(i, min(i + size, n)) for i in range(0, n, size)]


#: The layout of a store: 2 since every chunk's checksums cover its status and the arrays'
#: metadata is checked against the consolidated copy. A store of another layout is not resumed.
STORE_FORMAT = 2
MARKER = ".rockstudy"  # written first into every folder a run creates: what it holds
LOCK = ".rockstudy.lock"  # flock-ed by the run that writes the store, naming its PID and host
CHECKSUMS = ".rockstudy-chunks"  # the sha256 of each finished chunk's files
DONE = (STATUS_OK, STATUS_FAILED)
_OWN = {MARKER, LOCK}


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


def clear_template(path, names) -> None:
    """Remove a partly written template from a folder this run owns (its marker says so).

    ``names`` are the entries a template writes; anything else in the folder was not written by
    rockstudy, so the folder is refused whole (StoreError) and nothing is removed.
    """
    path = Path(path)
    if read_marker(path) is None:
        raise StoreError(f"{path} has no rockstudy marker: refusing to clear it")
    allowed = set(names) | _OWN | {".zattrs", ".zgroup", ".zmetadata", CHECKSUMS, MARKER + ".tmp"}
    foreign = sorted(entry.name for entry in path.iterdir() if entry.name not in allowed)
    if foreign:
        shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
        raise StoreError(
            f"{path} holds {shown}, which rockstudy did not write: nothing was removed; move "
            "them away, or run into a new --out"
        )
    for entry in path.iterdir():
        if entry.name in _OWN:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


def create_store(path, design: xr.Dataset, study: Study, inputs: dict | None = None) -> None:
    """Write the template cube: design, outputs filled with their fill values, status pending.

    ``path`` is a folder this run claimed (:func:`claim`); anything a killed template left in
    it is cleared first. The marker's ``template_complete`` is set last.
    """
    import dask
    import dask.array as da
    import zarr

    table = output_table(study)
    clear_template(path, [*design.variables, *table, "status", "error"])
    n = design.sizes["sample"]
    size = min(study.rows_per_chunk(), n)
    ds = design.copy()

    def lazy(fill, dtype, extra=None):  # written chunk by chunk: never whole in memory
        if extra is None:
            return ("sample", da.full(n, fill, dtype=dtype, chunks=size))
        width = ds.attrs["ida_steps"] if extra == "step" else ds.sizes[extra]
        return (("sample", extra), da.full((n, width), fill, dtype=dtype, chunks=(size, width)))

    for name, (long_name, units, dtype, fill, extra) in table.items():
        ds[name] = lazy(fill, dtype, extra)
        ds[name].attrs.update(long_name=long_name, units=units)
    ds["status"] = lazy(STATUS_PENDING, np.int8)
    ds["status"].attrs.update(long_name="0 pending, 1 ok, 2 failed", units="1")
    ds.attrs.update(
        study=study.normalized(),
        study_sha256=study.sha256(),
        inputs_sha256=json.dumps(inputs or {}),
        study_name=study.name,
        study_text=study.source_text or "",
        seed=study.seed,
        chunk_size=study.chunk_size,
        versions=json.dumps(package_versions()),
        store_format=STORE_FORMAT,
        Conventions="CF-1.8",
        gravity=G,  # [m/s^2] the physics' g: p = sqrt(3 g / 4 R), uplift g tan(alpha)
        record_g_unit=STANDARD_GRAVITY,  # [m/s^2] the unit g of records read in g
    )
    chunks = {
        name: {"chunks": (size,) + var.shape[1:]}
        for name, var in ds.data_vars.items()
        if var.dims[:1] == ("sample",)
    }
    with dask.config.set(scheduler="threads"), _quiet_about_our_files():
        ds.to_zarr(  # every chunk file is written (status included): a lost one is known
            Path(path),
            mode="a",
            encoding=chunks,
            zarr_format=2,
            consolidated=False,
            write_empty_chunks=True,
        )
        group = zarr.open_group(str(path), mode="r+", zarr_format=2)
        error = group.create_array("error", shape=(n,), chunks=(size,), dtype=str, fill_value="")
        error.attrs.update(  # variable-length: messages are stored whole
            _ARRAY_DIMENSIONS=["sample"], long_name="error message of a failed sample", units="1"
        )
        group.attrs["template_complete"] = 1
        zarr.consolidate_metadata(str(path), zarr_format=2)
    write_template_sums(path, design.variables)
    write_marker(path, template_complete=True)


def output_table(study: Study) -> dict:
    """The per-sample outputs of a study: name -> (long_name, units, dtype, fill, extra
    dimension or None)."""
    if study.design is not None:
        from ..designs.record_rows import outputs

        return outputs(study)
    out = {name: (*OUTPUTS[name], None) for name in study.run.outputs}
    if study.motion.kind == "record":
        from ..designs.record_rows import sample_outputs

        out.update(sample_outputs(study))
    return out


def _chunk_file(group, name, k) -> str:
    """The file of zarr chunk ``k`` (along ``sample``) of the array ``name``."""
    return str(k) + ".0" * (group[name].ndim - 1)


@contextlib.contextmanager
def _quiet_about_our_files():
    """zarr warns about files it does not know while listing a folder: our marker and lock."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Object at .rockstudy", UserWarning)
        yield


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


def stop_zarr_io(timeout: float = 60.0) -> None:
    """Stop zarr's IO event loop and wait for its thread, before the process exits.

    zarr runs its IO on an event loop in a thread, and stops it at exit (``atexit``) by joining
    that thread for 0.2 s only, then closing the loop: on a busy machine the thread has not
    stopped yet and exit prints ``RuntimeError: Cannot close a running event loop``.
    This waits up to ``timeout`` seconds instead; zarr's own clean-up then has nothing left to
    do. Does nothing if zarr never started its loop.
    """
    import sys

    sync = sys.modules.get("zarr.core.sync")
    if sync is None:
        return
    with sync._get_lock():  # noqa: SLF001 - the lock zarr's own clean-up takes
        loop, thread = sync.loop[0], sync.iothread[0]
        if loop is None:
            return
        loop.call_soon_threadsafe(loop.stop)
        if thread is not None:
            thread.join(timeout)
        if loop.is_running():  # still stuck after the timeout: left to zarr's clean-up
            return
        loop.close()
        sync.loop[0] = sync.iothread[0] = None


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


def _write_json(target, data) -> None:
    """Write ``data`` as JSON into ``target`` atomically (a temporary file renamed over it)."""
    target = Path(target)
    tmp = target.with_name(target.name + ".tmp")
    tmp.write_text(json.dumps(data))
    os.replace(tmp, target)


TEMPLATE_SUMS = "template"  # in CHECKSUMS: the sha256 of .zmetadata and of the design's files
_METADATA = (".zarray", ".zattrs", ".zgroup")  # the files of zarr v2 metadata
_MARKER_VARIABLE = f"{MARKER} (the store's marker)"


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


def read_status(path) -> np.ndarray:
    """The per-sample status array of a store (0 pending, 1 ok, 2 failed)."""
    return xr.open_zarr(Path(path), consolidated=True)["status"].values


def _consolidated(path) -> dict:
    return json.loads((Path(path) / ".zmetadata").read_text())["metadata"]


def _restore_metadata(path, meta) -> list[str]:
    """Rewrite the metadata files that are missing or differ, from the consolidated copy
    (checked by its sha256); StoreError for one the copy does not list."""
    restored = []
    for key in _metadata_differences(path, meta):
        if key not in meta:
            raise StoreError(
                f"{path} holds a metadata file {key} that its .zmetadata does not list: "
                "nothing was changed; move it away, or run into a new --out"
            )
        target = Path(path) / key
        target.parent.mkdir(parents=True, exist_ok=True)
        _write_json(target, meta[key])
        restored.append(key)
    return restored


def chunks_to_compute(path, design: xr.Dataset, size: int) -> tuple[list, list]:
    """The chunks a resume must compute: ``(pending, damaged)``.

    A chunk marked done is trusted only if every file of it, ``status`` included, still has
    the sha256 recorded when it was written (see :func:`_chunk_finished`); otherwise its files
    are removed, it is marked pending again and listed in ``damaged``. The design variables are
    compared with ``design`` (made again from the study) and rewritten where they differ.
    Metadata files that are missing or differ from the consolidated ``.zmetadata`` are
    restored from it.
    """
    import zarr

    path = Path(path)
    meta = _consolidated(path)
    missing = [n for n in design.data_vars if f"{n}/.zarray" not in meta]
    if missing:  # a store written before the design had them (e.g. uplift_acceleration)
        raise StoreError(
            f"{path}: the store lacks the design variable(s) {missing} that this rockstudy "
            "writes (it was made by an earlier version); run the study into a new store"
        )
    _restore_metadata(path, meta)
    group = zarr.open_group(str(path), mode="r+", zarr_format=2)
    with zarr.config.set({"array.write_empty_chunks": True}):
        for name in design.variables:
            want = design[name].values
            try:
                same = np.array_equal(group[name][:], want, equal_nan=want.dtype.kind == "f")
            except Exception:  # noqa: BLE001 - any unreadable design chunk is written again
                same = False
            if not same:
                group[name][:] = want
        write_template_sums(path, design.variables)  # the design as it now reads
        results = _results_with_values(meta, read_template_sums(path)["results"])
        pending, damaged = [], []
        bounds = chunk_bounds(design.sizes["sample"], size)
        for k, (rows, status) in enumerate(
            zip(bounds, _status_chunks(group["status"], bounds), strict=True)
        ):
            try:
                finished = _chunk_finished(path, results, k, status)
            except _ChunkDamage:
                damaged.append(rows)
                _reset_chunk(path, group, results, k, rows)
                continue
            if not finished:
                pending.append(rows)
    return pending, damaged


def _reset_chunk(path, group, results, k, rows) -> None:
    """Remove the files of chunk ``k`` (never merged into: a damaged file may not decode) and
    its checksums, and mark it pending."""
    (path / CHECKSUMS / str(k)).unlink(missing_ok=True)
    for name, ndim in results.items():
        (path / name / (str(k) + ".0" * (ndim - 1))).unlink(missing_ok=True)
    group["status"][rows[0] : rows[1]] = np.full(rows[1] - rows[0], STATUS_PENDING, np.int8)


def open_result(path, verify: bool = True) -> xr.Dataset:
    """Open a result cube (zarr or netCDF); grid studies come back on their grid dimensions.

    A zarr cube is first checked against the sha256 recorded when it was written
    (:func:`verify_cube`): a damaged one raises :class:`DamagedCube` naming the variable and
    chunk. ``verify=False`` skips the check (to look at a damaged cube). A netCDF export, and a
    dataset saved with ``to_zarr``, carry no checksums and are read as they are.
    """
    path = Path(path)
    if path.suffix == ".nc":
        ds = xr.open_dataset(path)
    else:
        if verify and written_by_run(path):  # a dataset saved with to_zarr has no sums
            verify_cube(path)
        ds = xr.open_zarr(path, consolidated=True)
    if "record_design" in ds.attrs and "sample" in ds.dims:
        from ..designs.record_rows import design_dataset

        return design_dataset(ds)
    grid = ds.attrs.get("grid_dims")
    if isinstance(grid, str):
        grid = json.loads(grid)
    if grid:
        ds = _unstack_grid(ds, list(grid))
    return ds


def _unstack_grid(ds, dims):
    shape = [ds.sizes[f"{d}_grid"] for d in dims]
    out = {}
    for name, var in ds.data_vars.items():
        if var.dims == ("sample",) and name not in dims:
            out[name] = (tuple(dims), var.values.reshape(shape), var.attrs)
    coords = {d: ds[f"{d}_grid"].values for d in dims}
    return xr.Dataset(out, coords=coords, attrs=ds.attrs)


def _netcdf_study(path) -> str | None:
    """The ``study_sha256`` attribute of a netCDF file, or None if it is not one of ours."""
    try:
        with xr.open_dataset(path, engine="scipy") as ds:
            return ds.attrs.get("study_sha256")
    except Exception:  # noqa: BLE001 - whatever it is, it is not an export we wrote
        return None


def check_export_target(out_path, study_sha: str, overwrite: bool = False) -> None:
    """Refuse, before anything runs, an export that would replace what this study did not write.

    A folder is never replaced; a file is replaced only if it is an export of the same study
    (an earlier or interrupted run of it) or ``overwrite`` is set.
    """
    out_path = Path(out_path)
    if out_path.is_dir():
        raise StoreError(
            f"{out_path} is a folder: the netCDF export cannot be written there; move it away "
            "or choose another --out"
        )
    if overwrite or not out_path.exists() or _netcdf_study(out_path) == study_sha:
        return
    raise StoreError(
        f"{out_path} exists and was not written by a run of this study: it was left as is; "
        "pass --overwrite to replace it, or choose another --out"
    )


def _nc3_attr(value):
    """netCDF3 attributes are 32-bit: larger integers (a seed >= 2**31) are kept as text."""
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        if not _INT32.min <= value <= _INT32.max:
            return str(value)
    return value


def export_netcdf(path, out_path) -> Path:
    """Write the finished cube as netCDF (scipy backend) beside the zarr store, streamed.

    The file is written under a temporary name inside the store and renamed at the end, so
    ``out_path`` is either the previous file or the complete export, never a partial one.
    """
    import dask

    out_path = Path(out_path)
    ds = xr.open_zarr(Path(path), consolidated=True)  # lazy: written chunk by chunk
    if "record_design" in ds.attrs:  # a record design is exported in its own layout
        from ..designs.record_rows import design_dataset

        ds = design_dataset(ds)
        empty = [d for d, size in ds.sizes.items() if size == 0]  # netCDF3 has none
        ds = ds.drop_dims(empty)
    ds.attrs["grid_dims"] = json.dumps(ds.attrs.get("grid_dims", []))
    ds.attrs = {k: _nc3_attr(v) for k, v in ds.attrs.items()}
    for name in list(ds.variables):
        var = ds[name]
        if var.dtype == np.int64:  # netCDF3 has no 64-bit integers: int32 if it fits
            lo, hi = (int(x) for x in dask.compute(var.min(), var.max(), scheduler="threads"))
            fits = var.size == 0 or (_INT32.min <= lo and hi <= _INT32.max)
            ds[name] = var.astype(np.int32 if fits else np.float64)
        elif var.dtype.kind in "OT":  # variable-length text: its width is needed, so load
            attrs = {k: v for k, v in var.attrs.items() if k != "_FillValue"}
            ds[name] = (var.dims, var.values.astype(object), attrs)
    tmp = Path(path) / ".export.nc.partial"
    with dask.config.set(scheduler="threads"):
        ds.to_netcdf(tmp, engine="scipy")
    os.replace(tmp, out_path)
    return out_path
