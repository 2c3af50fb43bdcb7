"""The report: sections by what the cube holds, rendered in headless Chromium."""

import re
import shutil
import subprocess

import matplotlib.image as mpimg
import numpy as np
import pytest

from rockstudy.study import run_study, validate_text
from rockstudy.study.report import make_report

SOBOL = """
name = "tiny_sobol"
seed = 3
chunk_size = 1024
[sampler]
kind = "sobol"
n = 256
[structure]
kind = "block"
half_diagonal = { dist = "loguniform", low = 0.3, high = 5.0 }
slenderness = { dist = "uniform", low = 0.05, high = 0.35 }
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = { dist = "uniform", low = 1.0, high = 4.0 }
period = { dist = "loguniform", low = 0.1, high = 2.0 }
[run]
outputs = ["max_rotation", "max_rotation_ratio", "overturned"]
"""

SIMILAR = """
name = "tiny_similarity"
seed = 4
chunk_size = 2000
[sampler]
kind = "monte_carlo"
n = 300
replicates = 4
[structure]
kind = "block"
half_diagonal = { dist = "loguniform", low = 0.3, high = 5.0 }
slenderness = { dist = "uniform", low = 0.05, high = 0.35 }
restitution = 0.85
[motion]
kind = "pulse"
amplitude_a = { dist = "loguniform", low = 1.02, high = 6.0 }
frequency_ratio = { dist = "loguniform", low = 0.5, high = 12.0 }
[run]
method = "linear"
outputs = ["max_rotation", "max_rotation_ratio", "overturned"]
"""


def chromium_figures(page):
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    assert exe, "headless Chromium is needed (make test installs Debian's chromium)"
    out = subprocess.run(
        [
            exe,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={page.parent / 'chromium-profile'}",
            "--virtual-time-budget=5000",
            "--dump-dom",
            page.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    m = re.search(r"figures rendered: (\d+)/(\d+)", out.stdout)
    assert m, out.stdout[-2000:]
    return int(m.group(1)), int(m.group(2))


@pytest.mark.parametrize("text", [SOBOL, SIMILAR], ids=["sobol", "similarity"])
def test_report_renders_in_chromium(tmp_path, text):
    study = validate_text(text)
    cube = tmp_path / "cube.zarr"
    run_study(study, cube, workers=1, progress=False)
    page = make_report(cube, tmp_path / "report")
    shown, total = chromium_figures(page)
    assert total >= 2 and shown == total
    pngs = sorted((tmp_path / "report").glob("*.png"))
    assert len(pngs) == total
    for png in pngs:
        img = mpimg.imread(png)
        assert np.unique(img.reshape(-1, img.shape[-1]), axis=0).shape[0] > 20, png
    csvs = {p.name for p in (tmp_path / "report").glob("*.csv")}
    assert "summary.csv" in csvs
    if study.sampler.kind == "sobol":
        assert {"sobol_max_rotation_ratio.csv", "sobol_convergence_overturned.csv"} <= csvs
    else:
        collapse = (tmp_path / "report" / "collapse.csv").read_text().splitlines()[1]
        assert float(collapse.split(",")[1]) < 1e-9  # complete similarity, linear model
