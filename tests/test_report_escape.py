"""Every string of a study file or a cube attribute reaches index.html escaped: hostile values
run no script in headless Chromium."""

import json
import re
import shutil

import pytest
import zarr
from _helpers import chromium_dom

from rockstudy.study import run_study, validate_text
from rockstudy.study.report import make_report

# a script that would mark the page if it ran, and the payload
MARK = "document.body.setAttribute('data-pwned','1')"
HOSTILE = [
    f"<script>{MARK}</script>",
    f'<img src=x onerror="{MARK}">',
    "<script>alert(document.domain)</script>",
    f'\'><svg onload="{MARK}">',
]

STUDY = """
name = {name}
description = {description}
seed = 5
chunk_size = 64
[sampler]
kind = "monte_carlo"
n = 64
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 2.0 }}
slenderness = 0.2
[motion]
kind = "pulse"
amplitude_ratio = {{ dist = "uniform", low = 1.0, high = 3.0 }}
period = 0.5
[run]
outputs = ["max_rotation", "overturned"]
"""


def dump_dom(page):
    out = chromium_dom(page, page.parent / "chromium-profile", budget_ms=3000)
    assert "</html>" in out.stdout, out.stderr[-2000:]
    return out.stdout


@pytest.fixture(scope="module")
def hostile_cube(tmp_path_factory, client):
    tmp = tmp_path_factory.mktemp("escape")
    text = STUDY.format(name=json.dumps(HOSTILE[0]), description=json.dumps(" ".join(HOSTILE)))
    cube = tmp / "cube.zarr"
    run_study(validate_text(text), cube, client=client, progress=False, netcdf=False)
    return cube


@pytest.mark.parametrize(
    "versions",
    [json.dumps({"rockstudy": HOSTILE[0], "numpy": HOSTILE[1]}), HOSTILE[2]],
    ids=["json", "raw"],
)
def test_hostile_strings_run_no_script(hostile_cube, tmp_path, versions):
    cube = tmp_path / "cube.zarr"
    shutil.copytree(hostile_cube, cube)
    group = zarr.open_group(str(cube), mode="r+", zarr_format=2)
    group.attrs["versions"] = versions  # a cube received from someone else, edited
    group.attrs["study_sha256"] = HOSTILE[1]
    zarr.consolidate_metadata(str(cube), zarr_format=2)
    page = make_report(cube, tmp_path / "report", verify=False)
    source = page.read_text()
    for payload in HOSTILE:
        assert payload not in source
    assert source.count("<script>") == 1  # the page's own figure check only
    dom = dump_dom(page)
    body = re.search(r"<body[^>]*>", dom).group()
    assert "data-pwned" not in body, body
    assert "<svg" not in dom and '<img src="x"' not in dom
    assert re.search(r"data-figures=\"\d+/\d+\"", body)  # the page's own script did run
    assert "&lt;script&gt;" in dom  # the hostile study name shows as text
