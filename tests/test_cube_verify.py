"""A cube is verified when it is read (issue 23, section 4): ``open_result``, ``rockstudy
report`` and ``rockstudy verify`` refuse a damaged cube in one line naming the damaged variable
and chunk. The oracle is the damage itself: each test damages one known file of a real small
run and checks that every door names that variable and that chunk.
"""

import json
import shutil

import pytest
from _helpers import cli, finished_run, one_line, rockstudy_run, tree

from rockstudy.study import open_result
from rockstudy.study.running.store import DamagedCube


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return finished_run(tmp_path_factory.mktemp("verify"), n=60, chunk=10)


def _flip(path, at=None):
    data = bytearray(path.read_bytes())
    at = len(data) // 2 if at is None else at
    data[at] ^= 0x01
    path.write_bytes(bytes(data))


def _zmetadata_dtype(out):
    """One byte of .zmetadata changed, the JSON still valid: max_rotation's float64 -> float32."""
    text = (out / ".zmetadata").read_text()
    meta = json.loads(text)["metadata"]["max_rotation/.zarray"]
    assert meta["dtype"] == "<f8"
    key = '"max_rotation/.zarray": {'
    head = text.index(key)
    at = text.index('"<f8"', head)
    (out / ".zmetadata").write_text(text[:at] + '"<f4"' + text[at + 5 :])
    json.loads((out / ".zmetadata").read_text())  # still valid JSON


DAMAGES = {  # name -> (damage, variable named, chunk named or None)
    "flipped output byte": (lambda o: _flip(o / "max_rotation" / "2"), "max_rotation", 2),
    "lost output chunk": (lambda o: (o / "n_impacts" / "4").unlink(), "n_impacts", 4),
    "truncated output": (
        lambda o: (o / "overturned" / "1").write_bytes((o / "overturned" / "1").read_bytes()[:5]),
        "overturned",
        1,
    ),
    "status that does not decode": (
        lambda o: (o / "status" / "3").write_bytes((o / "status" / "3").read_bytes()[:3]),
        "status",
        3,
    ),
    "flipped design byte": (lambda o: _flip(o / "half_diagonal" / "0"), "half_diagonal", None),
    "metadata dtype": (_zmetadata_dtype, ".zmetadata", None),
}


def test_an_intact_cube_verifies_in_one_line(finished):
    _, out = finished
    code, stdout, err = cli("verify", out)
    assert code == 0, err
    line = one_line(stdout)
    assert "intact" in line and "6 of 6 chunks" in line
    assert int(open_result(out)["status"].min()) == 1  # and it opens


@pytest.mark.parametrize("name", list(DAMAGES))
def test_each_door_refuses_a_damaged_cube_naming_variable_and_chunk(finished, tmp_path, name):
    _, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    damage, variable, chunk = DAMAGES[name]
    damage(out)
    before = tree(out)
    with pytest.raises(DamagedCube) as info:
        open_result(out)
    assert info.value.variable.split()[0] == variable and info.value.chunk == chunk
    named = f"'{variable}'" if variable != ".zmetadata" else ".zmetadata"
    where = "" if chunk is None else f"chunk {chunk} "
    for args in (("verify", out), ("report", out, "--out", tmp_path / "report")):
        code, stdout, err = cli(*args)
        assert code == 1, (args, stdout, err)
        line = one_line(err)
        assert named in line and where in line and "damaged" in line, line
    assert not (tmp_path / "report" / "index.html").exists()
    assert tree(out) == before  # reading changed nothing


def test_a_metadata_byte_flip_on_resume_is_one_line(finished, tmp_path):
    study, src = finished
    out = tmp_path / "cube.zarr"
    shutil.copytree(src, out)
    _zmetadata_dtype(out)
    before = tree(out)
    code, _, err = rockstudy_run(study, out, "--resume")
    assert code == 2
    assert ".zmetadata is damaged" in one_line(err)
    assert tree(out) == before


def test_what_a_run_did_not_write_has_nothing_to_verify(tmp_path):
    """A dataset saved with to_zarr carries no sums: open_result reads it as it is, and
    `rockstudy verify` says it cannot check it (exit 2), as for a path that is no folder."""
    import numpy as np
    import xarray as xr

    saved = tmp_path / "mine.zarr"
    xr.Dataset({"x": ("sample", np.arange(5.0))}).to_zarr(saved, consolidated=True)
    np.testing.assert_array_equal(open_result(saved)["x"].values, np.arange(5.0))
    for path, words in ((saved, "not written by rockstudy run"), (tmp_path / "no", "not a folder")):
        code, _, err = cli("verify", path)
        assert code == 2 and words in one_line(err)
