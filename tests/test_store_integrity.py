"""Every byte of a result cube that decides what it reads is covered by a checksum: the chunks
of every variable (``status`` included), the arrays' own metadata, and the marker's word on the
template. A damaged cube is refused on read and repaired or recomputed on ``--resume``, and a
kill at any stage of a chunk's write still resumes to the cube of an uninterrupted run.

The oracles are the damage itself (each test damages one known file of a real run and checks
that every door names it) and the uninterrupted run's cube, whose outputs are those of the
engine called directly (:func:`test_store_safety.assert_engine_results`).
"""

import json
import shutil

import numpy as np
import pytest
import xarray as xr
from _helpers import (
    assert_engine_results,
    cli,
    finished_run,
    one_error_line,
    one_line,
    rockstudy_run,
    tree,
    write_study,
)

from rockstudy.study import load_study, open_result
from rockstudy.study.designs.sampling import make_design
from rockstudy.study.running import store
from rockstudy.study.running.evaluate import evaluate_chunk
from rockstudy.study.running.store import DamagedCube, StoreError


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run of 60 samples in 6 chunks: (study file, store)."""
    return finished_run(tmp_path_factory.mktemp("integrity"), n=60, chunk=10)


def _copy(src, tmp_path):
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    return out


def _values(path):
    """Every variable of a cube as it reads with plain xarray, its own metadata and not."""
    out = {}
    for consolidated in (True, False):
        with xr.open_zarr(path, consolidated=consolidated) as ds:
            for name, var in ds.variables.items():
                values = var.values  # text: as text (its missing values are NaN objects)
                values = values.astype(str) if values.dtype.kind == "O" else values
                out[name, consolidated] = (var.dtype.str, dict(var.attrs), values)
    return out


def assert_same_cube(a, b):
    va, vb = _values(a), _values(b)
    assert va.keys() == vb.keys()
    for key, (dtype, attrs, values) in va.items():
        assert (dtype, attrs) == vb[key][:2], key
        np.testing.assert_array_equal(values, vb[key][2], err_msg=str(key))


def _refused_everywhere(out, tmp_path, variable, chunk, words=()):
    """open_result, `rockstudy verify` and `rockstudy report` refuse the cube in one line
    naming the damaged variable (and chunk), and change nothing."""
    before = tree(out)
    with pytest.raises(DamagedCube) as info:
        open_result(out)
    assert info.value.variable == variable and info.value.chunk == chunk, str(info.value)
    for args in (("verify", out), ("report", out, "--out", tmp_path / "report")):
        code, stdout, err = cli(*args)
        assert code == 1, (args, stdout, err)
        line = one_line(err)
        assert f"'{variable}'" in line and "damaged" in line, line
        assert chunk is None or f"chunk {chunk} " in line, line
        assert all(w in line for w in words), line
    assert not (tmp_path / "report" / "index.html").exists()
    assert tree(out) == before


def _resume(study, out, count):
    code, stdout, err = rockstudy_run(study, out, "--resume")
    assert code == 0, err
    assert f"computed {count} chunks" in stdout, stdout
    code, stdout, err = cli("verify", out)
    assert code == 0 and "intact: 6 of 6 chunks" in stdout, err


# ------------------------------------------------------------------ status is checksummed


def _xor_last_byte(path, mask=3):
    data = bytearray(path.read_bytes())
    data[-1] ^= mask
    path.write_bytes(bytes(data))


STATUS_DAMAGES = {
    "last byte of status/4 XOR 3": lambda o: _xor_last_byte(o / "status" / "4"),
    "status/4 deleted": lambda o: (o / "status" / "4").unlink(),
}


@pytest.mark.parametrize("name", list(STATUS_DAMAGES))
def test_a_damaged_status_chunk_is_refused_and_recomputed(finished, tmp_path, name):
    study, src = finished
    out = _copy(src, tmp_path)
    STATUS_DAMAGES[name](out)
    _refused_everywhere(out, tmp_path, "status", 4, words=("samples 40 to 49",))
    _resume(study, out, 1)
    assert_same_cube(out, src)
    assert_engine_results(xr.open_zarr(out).load())


# ------------------------------------------------------------------ the arrays' own metadata


def _edit_json(path, **changes):
    data = json.loads(path.read_text())
    data.update(changes)
    path.write_text(json.dumps(data, indent=4))


METADATA_DAMAGES = {  # name -> (damage, file named)
    "dtype": (lambda o: _edit_json(o / "max_rotation" / ".zarray", dtype="<f4"), ".zarray"),
    "fill value": (
        lambda o: _edit_json(
            o / "max_rotation" / ".zarray",
            fill_value=float(xr.open_zarr(o)["max_rotation"].values[3]),
        ),
        ".zarray",
    ),
    "units": (lambda o: _edit_json(o / "max_rotation" / ".zattrs", units="deg"), ".zattrs"),
    "lost .zattrs": (lambda o: (o / "max_rotation" / ".zattrs").unlink(), ".zattrs"),
}


@pytest.mark.parametrize("name", list(METADATA_DAMAGES))
def test_edited_array_metadata_is_refused_and_repaired_on_resume(finished, tmp_path, name):
    study, src = finished
    out = _copy(src, tmp_path)
    damage, file = METADATA_DAMAGES[name]
    damage(out)
    _refused_everywhere(out, tmp_path, "max_rotation", None, words=(f"max_rotation/{file}",))
    _resume(study, out, 0)  # the metadata is restored from the checksummed .zmetadata
    assert_same_cube(out, src)


# ------------------------------------------------------------------ the marker is checked


def _edit_marker(out, **changes):
    _edit_json(out / ".rockstudy", **changes)


def _refused_on_resume(study, out, words):
    before = tree(out)
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code == 2, err
    one_error_line(err)
    assert all(w in err for w in words), err
    assert tree(out) == before


def test_a_marker_saying_the_template_is_unfinished_on_a_finished_cube_is_refused(
    finished, tmp_path
):
    study, src = finished
    out = _copy(src, tmp_path)
    _edit_marker(out, template_complete=False)
    _refused_on_resume(study, out, ("marker", "template", "finished chunks"))


def test_a_marker_of_another_study_of_the_same_shape_is_refused(finished, tmp_path):
    study, src = finished
    other = write_study(tmp_path, n=60, chunk=10, seed=8, name="other.toml")
    out = _copy(src, tmp_path)
    _edit_marker(out, study_sha256=load_study(other).sha256())
    _refused_on_resume(other, out, ("marker", "another study"))
    code, _, err = cli("verify", out)
    assert code == 1 and "marker" in one_line(err)


def test_a_store_of_the_former_layout_is_not_resumed(finished, tmp_path):
    """A store written before every chunk's checksums covered its status (no store_format in
    its marker) is refused on resume, naming the format, and left as it was."""
    study, src = finished
    out = _copy(src, tmp_path)
    marker = json.loads((out / ".rockstudy").read_text())
    marker.pop("store_format")
    (out / ".rockstudy").write_text(json.dumps(marker))
    _refused_on_resume(study, out, ("store format 1", f"format {store.STORE_FORMAT}"))


# ------------------------------------------------------------------ a kill at any stage


def _run_in_process(study_file, out, stop=None):
    """Run a study into ``out`` without dask, chunk by chunk as the runner does; with
    ``stop = (k, stage)`` the write of chunk ``k`` ends after ``stage`` of ChunkWriter's
    stages, as a SIGKILL there would end it (later chunks are not written)."""
    study = load_study(study_file)
    base = study_file.parent
    design = make_design(study, base)
    inputs = store.input_hashes(study, base)
    lock, _ = store.claim(out, study, inputs, resume=False)
    try:
        store.create_store(out, design, study, inputs)
        writer = store.ChunkWriter(out)
        cols = {n: v.values for n, v in design.data_vars.items() if v.dims == ("sample",)}
        cols["sample"] = design["sample"].values
        for k, (a, b) in enumerate(store.chunk_bounds(design.sizes["sample"], 10)):
            result = evaluate_chunk(study.normalized(), {n: v[a:b] for n, v in cols.items()}, base)
            if stop is not None and k == stop[0]:
                for stage in writer.stages(a, b, result)[: stop[1]]:
                    stage()
                return
            writer.write(a, b, result)
    finally:
        lock.release()


@pytest.mark.parametrize("stage", [0, 1, 2, 3])
def test_a_kill_at_any_stage_of_a_chunk_write_resumes_bit_identical(finished, tmp_path, stage):
    study, src = finished
    out = tmp_path / "killed.zarr"
    _run_in_process(study, out, stop=(3, stage))
    code, stdout, err = cli("verify", out)  # a killed run is not damage
    assert code == 0, err
    done = 4 if stage == len(store.ChunkWriter.STAGES) else 3
    assert f"intact: {done} of 6 chunks finished" in stdout
    code, stdout, err = rockstudy_run(study, out, "--resume")
    assert code == 0, err
    assert f"computed {6 - done} chunks" in stdout and "did not read back" not in err
    assert_same_cube(out, src)


def test_a_template_never_finished_is_said_so_by_verify(finished, tmp_path, monkeypatch):
    study, src = finished

    def killed(*args):
        raise KeyboardInterrupt

    out = tmp_path / "cube.zarr"
    with monkeypatch.context() as patched, pytest.raises(KeyboardInterrupt):
        patched.setattr(store, "write_template_sums", killed)
        _run_in_process(study, out)
    code, _, err = cli("verify", out)
    line = one_line(err)
    assert code == 2 and "before its template was complete" in line and "--resume" in line, line
    assert "to_zarr" not in line
    with pytest.raises(StoreError, match="before its template was complete"):
        open_result(out)
    _resume(study, out, 6)
    assert_same_cube(out, src)
