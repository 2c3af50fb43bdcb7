"""The report: sections by what the cube holds, rendered in headless Chromium."""

import re

import matplotlib.image as mpimg
import numpy as np
import pytest
from _helpers import chromium_figures, rocking_with_falls

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


def test_fragility_section_marks_medians_outside_the_sampled_range(tmp_path):
    """Small blocks overturn at a median 1.6 inside the sampled 1-3 (in both intensities),
    the largest at 8, far above it: the page and its table show that median as not reached,
    and the fitted numbers keep their flags in fragility_fit.csv."""
    import pandas as pd
    import xarray as xr
    from scipy import stats

    from rockstudy.study.report import sampled as report

    rng = np.random.default_rng(7)
    n = 6000
    R = np.exp(rng.uniform(np.log(0.3), np.log(5.0), n))
    ratio = rng.uniform(1.0, 3.0, n)
    small = R < np.quantile(R, 2 / 3)
    theta, beta = np.where(small, 1.6, 8.0), np.where(small, 0.3, 0.8)
    over = (rng.random(n) < stats.norm.cdf(np.log(ratio / theta) / beta)).astype(np.int8)
    ds = xr.Dataset(
        {
            "half_diagonal": ("sample", R),
            "amplitude": ("sample", ratio),  # a_g = ratio in m/s^2: the same medians
            "amplitude_ratio": ("sample", ratio),
            "period": ("sample", rng.uniform(0.5, 1.0, n)),
            "omega": ("sample", rng.uniform(1.0, 2.0, n)),
            "overturned": ("sample", over),
        }
    )
    page = report._Page(tmp_path)
    report._fragility(page, ds)
    fit = pd.read_csv(tmp_path / "fragility_fit.csv", index_col=0)
    shown = pd.read_csv(tmp_path / "fragility.csv", index_col=0)
    large = fit["theta"] > 4
    assert large.sum() == 2 and (fit["im_max"] <= 3.0).all()
    assert not fit["theta_in_range"][large].any() and fit["theta_in_range"][~large].all()
    assert (shown["median capacity"][large.values] == report.NOT_REACHED).all()
    np.testing.assert_allclose(shown["median capacity"][~large.values].astype(float), 1.6, rtol=0.1)
    html_text = "".join(page.parts)
    assert report.NOT_REACHED in html_text


def quickstart_text(n):
    """The shipped quickstart study with n samples and a description that must be escaped."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "studies" / "quickstart.toml").read_text()
    text = re.sub(r"(?m)^n = \d+", f"n = {n}", text)
    text = re.sub(r"(?m)^chunk_size = \d+", f"chunk_size = {n}", text)
    return re.sub(r'(?m)^description = ".*"', 'description = "blocks <b>under</b> pulses"', text)


def test_monte_carlo_report_reads_as_a_design_note(tmp_path):
    """A Monte Carlo study's page: four figures (response, overturning map, first-order
    sensitivity, fragility) all decoded by the browser, the inputs table and the study itself
    (escaped), counts as integers, bins in three significant figures, no debug line."""
    import html as html_mod

    comment = "# a comment with <script>markup</script> & an ampersand, as typed"
    study_text = quickstart_text(600) + comment + "\n"
    study = validate_text(study_text)
    cube = tmp_path / "cube.zarr"
    run_study(study, cube, workers=1, progress=False)
    page = make_report(cube, tmp_path / "report")
    shown, total = chromium_figures(page)
    assert total >= 4 and shown == total
    names = {p.stem for p in (tmp_path / "report").glob("*.png")}
    assert {"response", "overturning_map", "first_order", "fragility"} <= names
    source = page.read_text()
    text = re.sub(r"<img[^>]*>", "", source)
    assert "figures rendered" not in text
    assert "<b>under</b>" not in text and html_mod.escape("<b>under</b>") in text
    assert "&quot;amplitude_ratio&quot;" in text  # the study as stored (defaults filled in)
    # the study file itself, as read when the run started: every line, comments too, escaped
    assert "<script>markup" not in text
    for line in study_text.splitlines():
        assert html_mod.escape(line) in text, line
    inputs = (tmp_path / "report" / "inputs.csv").read_text()
    assert "loguniform" in inputs and "pulse period T_p [s]" in inputs
    assert "<td>600</td>" in text and not re.search(r"<td>\d(\.\d+)?e\+\d+</td>", text)
    bins = re.findall(r"R (\S+) to (\S+) m", text)
    assert bins and all(len(v.replace(".", "").lstrip("0")) <= 3 for b in bins for v in b)
    assert "theta" not in (tmp_path / "report" / "fragility.csv").read_text().splitlines()[0]


def test_failed_samples_counted_by_message(tmp_path):
    import pandas as pd
    import xarray as xr

    from rockstudy.study.report import sampled as report

    status = np.array([1, 2, 2, 1, 2, 0], np.int8)
    error = np.array([b"", b"step limit", b"step limit", b"", b"bad record", b""])
    ds = xr.Dataset({"status": ("sample", status), "error": ("sample", error)})
    page = report._Page(tmp_path)
    report._failures(page, ds)
    counts = pd.read_csv(tmp_path / "failures.csv", index_col=0)["samples"]
    assert counts.to_dict() == {"step limit": 2, "bad record": 1}
    assert "<td>2</td>" in "".join(page.parts)


def test_cells_have_three_significant_figures_and_counts_are_integers():
    from rockstudy.study.report._page import _shown

    assert _shown(20000) == "20000" and _shown(np.int64(20000)) == "20000"
    assert (
        _shown(0.5000531) == "0.5" and _shown(1.33309) == "1.33" and _shown(123456.0) == "1.23e+05"
    )
    assert _shown(np.nan) == "" and _shown("not reached") == "not reached"


def test_median_in_g_reads_not_reached_where_the_median_is(tmp_path):
    """The fragility table's median in g follows the median in m/s^2: a median beyond the
    group's sampled intensities is 'not reached' in both columns, never a number in g."""
    import pandas as pd

    from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
    from rockstudy.study.analysis.fragility_fit import BAND_COLUMNS
    from rockstudy.study.report import sampled as report
    from rockstudy.study.report._page import NOT_REACHED

    fit = pd.DataFrame(
        {
            "intensity": ["abs_amplitude", "abs_amplitude"],
            "band": ["period", "period"],
            "theta": [5.0, 80.0],  # inside [2, 20], then beyond it
            "theta_lo": [4.0, 60.0],
            "theta_hi": [6.0, 99.0],
            "beta": [0.4, 0.5],
            "im_min": [2.0, 2.0],
            "im_max": [20.0, 20.0],
            **{c: [0.0, 0.0] for c in BAND_COLUMNS},
        },
        index=pd.Index(["R 0.5 to 1 m", "R 1 to 2 m"], name="block size"),
    )
    shown = {}

    class Page:
        out = tmp_path

        def table(self, df, name, caption):
            shown[name] = df

    report._fragility_table(Page(), fit)
    in_g = shown["fragility"]["median capacity [g] (a_g only)"].tolist()
    assert in_g[0] == pytest.approx(5.0 / G_UNIT, rel=1e-15)
    assert in_g[1] == NOT_REACHED


@pytest.mark.parametrize("kind, drawn", [("block", True), ("rocking_wall", False)])
def test_overturning_map_closed_forms_follow_the_simulated_block(tmp_path, kind, drawn):
    """The closed-form boundaries of [000] Fig. 4 hold for a slender block: they are drawn for
    blocks of alpha <= 0.3, not for walls of the same slenderness, whose equivalent block
    rocks on theta_cr = 2 alpha up to 0.6 (eq. 23 of [003])."""
    from types import SimpleNamespace

    import xarray as xr

    from rockstudy.structures import RockingWall
    from rockstudy.study.report import sampled as report

    rng = np.random.default_rng(0)
    alpha = rng.uniform(0.05, 0.3, 200)
    theta_cr = alpha if kind == "block" else RockingWall.equivalent_parameters(1.0, alpha)[1]
    ds = xr.Dataset(
        {
            "omega": ("sample", rng.uniform(1.0, 10.0, 200)),
            "amplitude_ratio": ("sample", rng.uniform(1.0, 5.0, 200)),
            "overturned": ("sample", (rng.uniform(size=200) < 0.3).astype(np.int8)),
            "slenderness": ("sample", alpha),
            "critical_rotation": ("sample", theta_cr),
            "restitution": ("sample", np.full(200, 0.9)),
        }
    )
    page = report._Page(tmp_path)
    report._overturning_map(page, ds, SimpleNamespace(motion=SimpleNamespace(shape="sine")))
    text = "".join(page.parts)
    assert ("No closed-form boundary drawn" in text) is not drawn
    assert ("Lines: the closed-form boundaries" in text) is drawn


def test_the_reports_first_order_indices_of_the_rotation_leave_out_the_falls(tmp_path):
    """The survivors' peak rotation ratio depends on the amplitude alone; the falls carry pi /
    (2 alpha). The report's index of alpha on the ratio is that of the survivors (near 0),
    not the one the falls make (large)."""
    from types import SimpleNamespace

    import pandas as pd

    from rockstudy.study.report import sampled as report

    ds = rocking_with_falls()
    study = SimpleNamespace(parameters=lambda: {"slenderness": None, "amplitude_ratio": None})
    page = report._Page(tmp_path)
    report._first_order(page, ds, study)
    t = pd.read_csv(tmp_path / "first_order.csv")
    ratio = t[(t["on"] == "inputs") & t["output"].str.contains("rotation")]
    s1 = dict(zip(ratio["variable"], ratio["S1"], strict=True))
    assert s1[report._label("slenderness")] < 0.05
    assert s1[report._label("amplitude_ratio")] > 0.9


def test_the_fragility_figure_draws_its_samples_and_warns_where_the_lognormal_misses(tmp_path):
    """Each curve is drawn over its samples: the share overturned in eight equal-count bins of
    the intensity, computed here with numpy. Outcomes whose probability levels off at 0.6 are
    named in a warning; lognormal ones are not."""
    import xarray as xr
    from scipy.stats import norm

    from rockstudy.study.report import sampled as report
    from rockstudy.study.report._page import _plt

    rng = np.random.default_rng(5)  # (the test rejects 1 % of lognormal data at 0.01)
    n = 3000
    size = rng.uniform(0.5, 3.0, n)
    amp = np.exp(rng.uniform(np.log(0.5), np.log(20.0), n))
    small = size < 1.5
    p = np.where(small, 0.6 * norm.cdf(np.log(amp / 2.0) / 0.3), norm.cdf(np.log(amp / 4.0) / 0.5))
    ds = xr.Dataset(
        {
            "half_diagonal": ("sample", size),
            "abs_amplitude": ("sample", amp),
            "period": ("sample", rng.uniform(0.5, 1.5, n)),
            "overturned": ("sample", (rng.uniform(size=n) < p).astype(np.int8)),
        }
    )
    page = report._Page(tmp_path)
    fig, ax = _plt().subplots()
    t = report._fragility_view(
        page, ax, ds, np.array([0.5, 1.5, 3.0 + 1e-12]), "abs_amplitude", "period", "a_g"
    )
    third = report._middle_third(ds["period"].values)
    markers = [ln for ln in ax.lines if ln.get_marker() == "o" and len(ln.get_xdata())]
    for line, sel in zip(markers, (small & third, ~small & third), strict=True):
        order = np.argsort(amp[sel], kind="stable")
        groups = np.array_split(order, 8)
        shares = [ds["overturned"].values[sel][g].mean() for g in groups]
        np.testing.assert_allclose(line.get_ydata(), shares, rtol=1e-12)
    report._lack_of_fit_warning(page, t)
    text = "".join(page.parts)
    assert "does not describe the samples of R 0.5 to 1.5 m" in text
    assert "R 1.5 to 3 m" not in text
