"""The result cube: a zarr store written chunk by chunk, with a ``status`` written last.

The template (design, outputs filled with their fill values, ``status`` = 0 pending) is written
first. Each finished chunk is written into its own region (zarr chunks are aligned with the
study's chunks, so no two writers ever share a zarr chunk), outputs first and ``status`` last:
a chunk whose status is not pending is complete. A killed run resumes from the pending chunks.

The store never destroys what it did not write. A run claims a folder only if it is new (or
empty), and writes a marker file ``.rockstudy`` into it first (the study's sha256, the sha256
of every input file, the package version, and whether the template is complete); a folder
without that marker is never written to. A run holds an exclusive lock (``.rockstudy.lock``,
``fcntl.flock``, naming its PID and host) for its whole life: a second run on the same store is
refused at once, and the lock of a killed run vanishes with its process, so ``--resume`` after
SIGKILL just works. Each finished chunk records the sha256 of its files
(``.rockstudy-chunks/<k>``); on resume a chunk marked done whose files are missing or differ is
computed again.
"""

from __future__ import annotations

import contextlib
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

from ..constants import STANDARD_GRAVITY, G
from .evaluate import OUTPUTS, STATUS_FAILED, STATUS_OK, STATUS_PENDING
from .spec import Study

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
    """The sha256 of every input file of a study (its records, H and V), keyed by their path
    relative to ``base_dir`` (absolute if outside it)."""
    if study.motion.kind != "record":
        return {}
    from .feasibility import record_pairs

    base = Path(Path.cwd() if base_dir is None else base_dir)
    out = {}
    for _, h, v in record_pairs(study.motion, base_dir):
        for path in (h, v) if v is not None else (h,):
            key = (
                os.path.relpath(path, base)
                if not path.is_absolute() or path.is_relative_to(base)
                else str(path)
            )
            out[key] = file_sha256(path)
    return out


def read_marker(path) -> dict | None:
    """The marker of a store made by rockstudy, or None if the folder has none."""
    marker = Path(path) / MARKER
    if not marker.is_file():
        return None
    try:
        return json.loads(marker.read_text())
    except (OSError, ValueError) as exc:
        raise StoreError(f"{marker} is damaged ({exc}); nothing was changed") from None


def write_marker(path, **fields) -> None:
    """Write (or update) the marker atomically: a temporary file renamed over it."""
    marker = Path(path) / MARKER
    data = {**(read_marker(path) or {}), **fields}
    tmp = marker.with_name(MARKER + ".tmp")
    tmp.write_text(json.dumps(data, indent=1))
    os.replace(tmp, marker)


def _legacy_store(path) -> bool:
    """A store written before markers existed: its consolidated metadata names a study."""
    try:
        meta = json.loads((Path(path) / ".zmetadata").read_text())
        return "study_sha256" in meta["metadata"][".zattrs"]
    except (OSError, ValueError, KeyError, TypeError):
        return False


class StoreLock:
    """An exclusive ``flock`` on ``<store>/.rockstudy.lock`` held for the life of a run.

    The kernel drops the lock when its process dies (even by SIGKILL), so a lock file left by a
    killed run is stale by construction and the next run takes it over. The file names the
    holder (PID, host, start time) for the message that refuses a second run.
    """

    def __init__(self, folder):
        self.path = Path(folder) / LOCK
        self.fd = None

    def acquire(self) -> None:
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
        os.ftruncate(fd, 0)
        holder = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "since": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
        os.write(fd, json.dumps(holder).encode())
        self.fd = fd

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)  # closing the descriptor drops the flock
            self.fd = None

    def __enter__(self):
        self.acquire()
        return self

    def __exit__(self, *exc):
        self.release()


def claim(path, study: Study, inputs: dict, resume: bool) -> tuple[StoreLock, bool]:
    """Take the folder ``path`` for a run of ``study``, or raise without changing anything.

    A new (or empty) folder is created, locked and marked. An existing one is used only with
    ``resume`` and only if it holds a rockstudy store of the same study, with the same input
    files and package version. Returns the held lock and whether the store's template is
    complete (False: nothing finished yet, the template is (re)written).
    """
    path = Path(path)
    sha = study.sha256()
    try:
        path.mkdir(parents=True)
        fresh = True
    except FileExistsError:
        fresh = False
    if not fresh:
        if not path.is_dir():
            raise StoreError(f"{path} exists and is not a folder: choose a new --out")
        if not resume:
            if (path / LOCK).is_file():
                with StoreLock(path):  # raises, naming the holder, if a run holds it
                    pass
            raise FileExistsError(f"{path} exists: pass resume=True (--resume) or a new path")
        entries = sorted(p.name for p in path.iterdir())
        if entries and MARKER not in entries and LOCK not in entries and not _legacy_store(path):
            shown = ", ".join(entries[:5]) + (", ..." if len(entries) > 5 else "")
            raise StoreError(
                f"{path} is not a rockstudy store (it holds {shown}): nothing was written; "
                "choose a new --out"
            )
    lock = StoreLock(path)
    lock.acquire()
    try:
        marker = read_marker(path)
        if marker is None and _legacy_store(path):  # written before markers: adopt it
            attrs = json.loads((path / ".zmetadata").read_text())["metadata"][".zattrs"]
            marker = {"study_sha256": attrs["study_sha256"], "template_complete": True}
            write_marker(path, **marker)
        if marker is None:  # new, or emptied: ours from here on
            write_marker(path, **_identity(study, inputs), template_complete=False)
            return lock, False
        _check_same(path, marker, sha, inputs)
        if not marker.get("template_complete"):
            return lock, False
        _check_metadata(path)
        return lock, True
    except BaseException:
        lock.release()
        raise


def _identity(study, inputs) -> dict:
    return {
        "study_sha256": study.sha256(),
        "inputs_sha256": inputs,
        "rockstudy": package_versions()["rockstudy"],
    }


def _check_same(path, marker, sha, inputs) -> None:
    """Refuse to resume across a change of study, input file or rockstudy version."""
    if marker.get("study_sha256") != sha:
        raise ValueError(f"{path} holds a different study (sha256 mismatch); cannot resume")
    before = marker.get("inputs_sha256")
    if before is not None and before != inputs:
        changed = sorted(k for k in set(before) | set(inputs) if before.get(k) != inputs.get(k))
        raise StoreError(
            f"{path}: input file(s) {', '.join(changed)} changed since this store was started; "
            "resuming would mix results of different inputs: restore them, or run into a new "
            "--out"
        )
    version = package_versions()["rockstudy"]
    if marker.get("rockstudy", version) != version:
        raise StoreError(
            f"{path} was started by rockstudy {marker['rockstudy']}, this is {version}: "
            "resuming would mix results of two versions; run into a new --out"
        )


def _check_metadata(path) -> None:
    """The consolidated metadata of a complete template must read; else report, never rebuild."""
    try:
        json.loads((Path(path) / ".zmetadata").read_text())["metadata"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise StoreError(
            f"{path}/.zmetadata is damaged ({type(exc).__name__}: {exc}); nothing was changed. "
            "If the arrays' own metadata are intact, rebuild it with python -c \"import zarr; "
            f"zarr.consolidate_metadata('{path}', zarr_format=2)\" and --resume again"
        ) from None


def discard_if_unused(path) -> None:
    """Remove a folder this run created if nothing but its marker and lock got into it."""
    path = Path(path)
    marker = read_marker(path)
    if marker is not None and not marker.get("template_complete"):
        if {entry.name for entry in path.iterdir()} <= _OWN:
            shutil.rmtree(path)


def clear_template(path) -> None:
    """Remove a partly written template from a folder this run owns (its marker says so)."""
    path = Path(path)
    if read_marker(path) is None:
        raise StoreError(f"{path} has no rockstudy marker: refusing to clear it")
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

    clear_template(path)
    n = design.sizes["sample"]
    size = min(study.rows_per_chunk(), n)
    ds = design.copy()

    def lazy(fill, dtype, extra=None):  # written chunk by chunk: never whole in memory
        if extra is None:
            return ("sample", da.full(n, fill, dtype=dtype, chunks=size))
        width = ds.attrs["ida_steps"] if extra == "step" else ds.sizes[extra]
        return (("sample", extra), da.full((n, width), fill, dtype=dtype, chunks=(size, width)))

    for name, (long_name, units, dtype, fill, extra) in output_table(study).items():
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
        ds.to_zarr(Path(path), mode="a", encoding=chunks, zarr_format=2, consolidated=False)
        group = zarr.open_group(str(path), mode="r+", zarr_format=2)
        error = group.create_array("error", shape=(n,), chunks=(size,), dtype=str, fill_value="")
        error.attrs.update(  # variable-length: messages are stored whole
            _ARRAY_DIMENSIONS=["sample"], long_name="error message of a failed sample", units="1"
        )
        group.attrs["template_complete"] = 1
        zarr.consolidate_metadata(str(path), zarr_format=2)
    write_marker(path, template_complete=True)


def output_table(study: Study) -> dict:
    """The per-sample outputs of a study: name -> (long_name, units, dtype, fill, extra
    dimension or None)."""
    if study.design is not None:
        from .record_studies import outputs

        return outputs(study)
    out = {name: (*OUTPUTS[name], None) for name in study.run.outputs}
    if study.motion.kind == "record":
        from .record_studies import sample_outputs

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


class ChunkWriter:
    """Writes finished chunks straight into the zarr arrays of a cube: the outputs, their
    checksums, and ``status`` last.

    The arrays were created by :func:`create_store` with the study's chunks, so each chunk
    write touches its own zarr chunks only. The sha256 of every file of the chunk goes to
    ``.rockstudy-chunks/<k>``: a resume trusts a chunk only if its files still match.
    """

    def __init__(self, path):
        import zarr

        self.path = Path(path)
        self.group = zarr.open_group(str(path), mode="r+", zarr_format=2)
        self.size = self.group["status"].chunks[0]
        (self.path / CHECKSUMS).mkdir(exist_ok=True)

    def write(self, start: int, stop: int, result: dict) -> None:
        import zarr

        # every chunk file is written, even one equal to the fill value: a done chunk whose
        # file is missing is then known to be lost (see chunks_to_compute)
        with zarr.config.set({"array.write_empty_chunks": True}):
            names = [name for name in result if name != "status"]
            for name in names:
                self.group[name][start:stop] = result[name]
            k = start // self.size
            sums = {
                name: file_sha256(self.path / name / _chunk_file(self.group, name, k))
                for name in names
                if self.group[name].size  # an array of no values has no chunk files
            }
            target = self.path / CHECKSUMS / str(k)
            tmp = target.with_name(f"{k}.tmp")
            tmp.write_text(json.dumps(sums))
            os.replace(tmp, target)
            self.group["status"][start:stop] = result["status"]


def _chunk_intact(path, group, names, k) -> bool:
    """Whether chunk ``k`` of every variable in ``names`` still has the checksum it was
    written with."""
    try:
        sums = json.loads((path / CHECKSUMS / str(k)).read_text())
        return all(
            file_sha256(path / name / _chunk_file(group, name, k)) == sums[name]
            for name in names
            if group[name].size
        )
    except (OSError, ValueError, KeyError, TypeError):
        return False


def read_status(path) -> np.ndarray:
    """The per-sample status array of a store (0 pending, 1 ok, 2 failed)."""
    return xr.open_zarr(Path(path), consolidated=True)["status"].values


def _consolidated(path) -> dict:
    return json.loads((Path(path) / ".zmetadata").read_text())["metadata"]


def _restore_metadata(path, meta) -> list[str]:
    """Rewrite the per-array metadata files that are missing, from the consolidated copy."""
    restored = []
    for key, value in meta.items():
        target = Path(path) / key
        if not target.exists():
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(json.dumps(value, indent=4))
            restored.append(key)
    return restored


def chunks_to_compute(path, design: xr.Dataset, size: int) -> tuple[list, list]:
    """The chunks a resume must compute: ``(pending, damaged)``.

    A chunk marked done is trusted only if its status reads 1 or 2 and the files of every
    per-sample output still have the sha256 recorded when they were written
    (:class:`ChunkWriter`); otherwise its files are removed, it is marked pending again and
    listed in ``damaged``. The
    design variables are compared with ``design`` (made again from the study) and rewritten
    where they differ. Metadata files missing beside the consolidated ``.zmetadata`` are
    restored from it.
    """
    import zarr

    path = Path(path)
    meta = _consolidated(path)
    _restore_metadata(path, meta)
    group = zarr.open_group(str(path), mode="r+", zarr_format=2)
    for name in design.variables:
        want = design[name].values
        try:
            same = np.array_equal(group[name][:], want, equal_nan=want.dtype.kind == "f")
        except Exception:  # noqa: BLE001 - any unreadable design chunk is written again
            same = False
        if not same:
            group[name][:] = want
    results = sorted(
        key.split("/")[0]
        for key in meta
        if key.endswith("/.zarray") and key.split("/")[0] not in design.variables
    )
    outputs = [name for name in results if name != "status"]
    pending, damaged = [], []
    n = design.sizes["sample"]
    for k, (a, b) in enumerate(chunk_bounds(n, size)):
        try:
            status = group["status"][a:b]
        except Exception:  # noqa: BLE001 - a status chunk that does not decode: recompute
            status = np.full(b - a, -1)
        if np.all(status == STATUS_PENDING):
            pending.append((a, b))
        elif not (np.all(np.isin(status, DONE)) and _chunk_intact(path, group, outputs, k)):
            damaged.append((a, b))
            (path / CHECKSUMS / str(k)).unlink(missing_ok=True)
            for name in results:  # never merged into: a damaged file may not decode
                (path / name / _chunk_file(group, name, k)).unlink(missing_ok=True)
            group["status"][a:b] = np.full(b - a, STATUS_PENDING, np.int8)
    return pending, damaged


def open_result(path) -> xr.Dataset:
    """Open a result cube (zarr or netCDF); grid studies come back on their grid dimensions."""
    path = Path(path)
    if path.suffix == ".nc":
        ds = xr.open_dataset(path)
    else:
        ds = xr.open_zarr(path, consolidated=True)
    if "record_design" in ds.attrs and "sample" in ds.dims:
        from .record_studies import design_dataset

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
        from .record_studies import design_dataset

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
