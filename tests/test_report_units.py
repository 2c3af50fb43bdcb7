"""Every number of the record report in the unit its label states, in a report in g and one
in m/s^2, and for a registered measure quoted in g.

Oracles, computed here from the dataset alone: the records' PGA [m/s^2] divided by the unit g
(standard gravity, 9.80665 m/s^2); the IDA capacities, scale x PGA, and their lognormal MLE
(the mean and standard deviation of their logarithms); for stripes, the probit MLE of the
outcomes against the measure, fitted here with scipy; the objects' uplift level g tan(alpha)
with the model's g. The figures' drawn data are read from the figures the page embeds.
"""

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _helpers import chromium_dom, chromium_figures
from scipy import optimize, special

import rockstudy as rs
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.constants import G
from rockstudy.motions import load_suite, measures, register_measure
from rockstudy.study.designs.records import cloud, incremental_dynamic_analysis, multiple_stripes
from rockstudy.study.report import _page
from rockstudy.study.report.records import record_report

DATA = Path(__file__).resolve().parents[1] / "data" / "records"
FILES = ["NF03_Tp0.80s_H.AT2", "NF05_Tp1.30s_H.AT2", "NF06_Tp1.70s_H.AT2"]
OBJECTS = {
    "Stele": rs.Block(half_diagonal=1.0, slenderness=0.25),
    "Vase": rs.Block(half_diagonal=0.4, slenderness=0.3),
}
#: The report's units -> its label and the value of one such unit in m/s^2.
UNITS = {"g": ("g", G_UNIT), "m/s^2": ("m/s^2", 1.0)}
#: A registered measure quoted in g (half the PGA) and one of power 0.5 (the PGA's root).
HALF, ROOT = "pga_half_units_test", "pga_root_units_test"


@pytest.fixture(scope="module")
def records():
    return load_suite([DATA / f for f in FILES])


@pytest.fixture(scope="module")
def own_measures():
    try:  # registered for this module only, whatever happens
        register_measure(
            HALF,
            lambda r: 0.5 * r.peak,
            unit="m/s^2",
            power=1,
            quoted_unit="g",
            factor=1 / G_UNIT,
            label="half PGA",
        )
        register_measure(ROOT, lambda r: math.sqrt(r.peak), unit="m^0.5/s", power=0.5)
        yield
    finally:
        for name in (HALF, ROOT):
            if name in measures.MEASURES:
                measures.unregister_measure(name)


@pytest.fixture(scope="module")
def ida(records):
    ds = incremental_dynamic_analysis(records, OBJECTS, step=0.2, tolerance=0.02, scan=2)
    assert not ds["censored"].values.any()  # the oracle below is the uncensored MLE
    return ds


@pytest.fixture(scope="module")
def stripes(records, own_measures):
    levels = np.array([0.2, 0.4, 0.8, 1.6]) * G_UNIT  # of the half PGA [m/s^2]
    return multiple_stripes(records, OBJECTS, levels, im=HALF)


@pytest.fixture
def drawn(monkeypatch):
    """The lines of every figure the page embeds: name -> [axes: [(x, y, style, colour,
    label)]], and name_ylim -> [each axes' y limits]."""
    figures = {}
    original = _page._Page.figure

    def figure(self, fig, name, caption):
        figures[name] = [
            [
                (
                    np.asarray(ln.get_xdata(), float),
                    np.asarray(ln.get_ydata(), float),
                    ln.get_linestyle(),
                    ln.get_color(),
                    ln.get_label(),
                )
                for ln in ax.lines
            ]
            for ax in fig.axes
            if ax.get_visible()
        ]
        figures[f"{name}_ylim"] = [ax.get_ylim() for ax in fig.axes if ax.get_visible()]
        return original(self, fig, name, caption)

    monkeypatch.setattr(_page._Page, "figure", figure)
    return figures


def _csv(out, name):
    return pd.read_csv(out / f"{name}.csv", index_col=0)


def _lognormal(values):
    """(median, beta) of the lognormal MLE of uncensored values."""
    ln = np.log(np.asarray(values, float).ravel())
    return float(np.exp(ln.mean())), float(ln.std())


def _probit(x, overturned):
    """(median, beta) of the MLE of P(overturned | x) = Phi(ln(x / median) / beta)."""
    ln, y = np.log(np.asarray(x, float).ravel()), np.asarray(overturned, bool).ravel()

    def nll(p):
        z = (ln - p[0]) / np.exp(p[1])
        return -(special.log_ndtr(z[y]).sum() + special.log_ndtr(-z[~y]).sum())

    start = [np.median(ln), np.log(max(ln.std(), 0.1))]
    res = optimize.minimize(
        nll, start, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-12}
    )
    return float(np.exp(res.x[0])), float(np.exp(res.x[1]))


def _capacities(ds):
    """The IDA capacities in PGA [m/s^2], (record, structure)."""
    return ds["capacity_scale"].values * ds["pga"].values[:, None]


@pytest.mark.parametrize("units", list(UNITS))
def test_ida_report_numbers_are_in_their_stated_units(tmp_path, ida, drawn, units):
    label, unit = UNITS[units]
    out = tmp_path / "r"
    record_report(ida, out, n_boot=5, units=units)
    cap = _capacities(ida)
    # records: PGA in g and in m/s^2 side by side
    rec = _csv(out, "records")
    assert rec["PGA [g]"].to_numpy() == pytest.approx(ida["pga"].values / G_UNIT, rel=1e-12)
    assert rec["PGA [m/s^2]"].to_numpy() == pytest.approx(ida["pga"].values, rel=1e-12)
    # the efficiency table, pooled over the objects: the lognormal of all capacities
    eff = _csv(out, "im_efficiency")
    theta, beta = _lognormal(cap / unit)
    row = eff.loc[f"PGA [{label}]"]
    assert row["median capacity"] == pytest.approx(theta, rel=1e-9)
    assert row["dispersion beta [-]"] == pytest.approx(beta, rel=1e-9)
    assert eff.loc["Arias intensity [m/s]", "power k"] == 2
    # per object: the lognormal of its own capacities; PGA / a_up shares PGA's beta
    by = pd.read_csv(out / "im_efficiency_by_object.csv", index_col=[0, 1])
    for j, name in enumerate(OBJECTS):
        theta, beta = _lognormal(cap[:, j] / unit)
        assert by.loc[(name, f"PGA [{label}]"), "median capacity"] == pytest.approx(theta, rel=1e-9)
        for im in (f"PGA [{label}]", "PGA / a_up [-]"):
            assert by.loc[(name, im), "dispersion beta [-]"] == pytest.approx(beta, rel=1e-9)
    # each object's fragility, its uplift level and its capacity under each record
    frag = _csv(out, "object_fragility")
    frag = frag[frag["intensity"] == f"PGA [{label}]"]
    cells = _csv(out, "object_capacity")
    names = [str(n) for n in ida["record_name"].values]
    for j, (name, block) in enumerate(OBJECTS.items()):
        theta, beta = _lognormal(cap[:, j] / unit)
        assert frag.loc[name, "median capacity"] == pytest.approx(theta, rel=1e-9)
        assert frag.loc[name, "beta (MLE)"] == pytest.approx(beta, rel=1e-9)
        uplift = G * math.tan(block.slenderness) / unit
        assert frag.loc[name, f"uplift level, PGA [{label}]"] == pytest.approx(uplift, rel=1e-9)
        got = cells.loc[name, names].to_numpy(float)
        assert got == pytest.approx(cap[:, j] / unit, rel=1e-9)
        # the fragility figure: the curve of the fitted lognormal, the dotted uplift level
        lines = [ln for ln in drawn["object_fragility"][0] if ln[4] == name]
        x, p = lines[0][0], lines[0][1]
        up = p > 0  # below the cut the drawn fragility is 0
        assert p[up] == pytest.approx(special.ndtr(np.log(x[up] / theta) / beta), abs=1e-9)
        dotted = [
            ln for ln in drawn["object_fragility"][0] if ln[2] == ":" and ln[3] == lines[0][3]
        ]
        assert dotted[0][0][0] == pytest.approx(uplift, rel=1e-9)
    # the IDA curves of each object: each record's scaled PGA
    for j in range(len(OBJECTS)):
        curves = [ln for ln in drawn["object_ida"][j] if ln[2] == "-"]
        for i, ln in enumerate(curves):
            pga = ida["step_scale"].values[i, j] * ida["pga"].values[i] / unit
            assert set(np.round(ln[1], 9)) <= set(np.round(pga, 9))
    # per record: the median capacity over the objects, in g as labelled
    per = _csv(out, "per_record")
    want = np.median(cap / G_UNIT, axis=1)
    assert per["median capacity, PGA [g]"].to_numpy(float) == pytest.approx(want, rel=1e-9)


@pytest.mark.parametrize("units", list(UNITS))
def test_stripes_of_a_measure_quoted_in_g_are_in_the_stated_units(tmp_path, stripes, drawn, units):
    label, unit = UNITS[units]
    out = tmp_path / "r"
    page = record_report(stripes, out, n_boot=5, units=units)
    text = re.sub(r"\s+", " ", page.read_text())
    levels = stripes["level"].values / unit  # of the half PGA [m/s^2] -> the report's unit
    over = stripes["overturned"].values == 1  # (record, structure, level)
    cells = _csv(out, "object_capacity")
    names = [str(n) for n in stripes["record_name"].values]
    for j, name in enumerate(OBJECTS):
        for i, rec in enumerate(names):
            k = int(np.argmax(over[i, j])) if over[i, j].any() else -1
            want = (
                f"above {levels[-1]:.3g}"
                if k < 0
                else f"at or below {levels[0]:.3g}"
                if k == 0
                else f"{levels[k - 1]:.3g} to {levels[k]:.3g}"
            )
            assert cells.loc[name, rec] == want
    assert f"half PGA [{label}]" in text
    assert ("0.2 to 0.4" if units == "g" else "1.96 to 3.92") in cells.to_numpy()
    # the efficiency table: the probit MLE against the half PGA (quoted in g) of every
    # point, pooled, in the report's unit; and the power of the root of the PGA
    eff = _csv(out, "im_efficiency")
    half = stripes["scale"].values * 0.5 * stripes["pga"].values[:, None, None] / G_UNIT
    theta, beta = _probit(half, over)
    row = eff.loc[f"half PGA [{label}]"]
    assert row["median capacity"] == pytest.approx(theta * G_UNIT / unit, rel=1e-5)
    assert row["dispersion beta [-]"] == pytest.approx(beta, rel=1e-5)
    assert eff.loc[f"{ROOT.replace('_', ' ')} [m^0.5/s]", "power k"] == 0.5
    # the stripe points of each object: the scaled PGA
    for j in range(len(OBJECTS)):
        curves = [ln for ln in drawn["object_stripes"][j] if ln[2] == "-"]
        for i, ln in enumerate(curves):
            pga = stripes["scale"].values[i, j] * stripes["pga"].values[i] / unit
            assert np.sort(ln[1]) == pytest.approx(np.sort(pga), rel=1e-12)


@pytest.mark.parametrize("units", list(UNITS))
def test_cloud_points_are_the_records_pga_in_the_stated_unit(tmp_path, records, drawn, units):
    label, unit = UNITS[units]
    ds = cloud(records, OBJECTS)
    out = tmp_path / "r"
    record_report(ds, out, n_boot=5, units=units)
    pga = ds["pga"].values / unit
    for ax in drawn["cloud_points"]:
        points = [ln for ln in ax if ln[2] in ("None", "none", "")]
        assert [p[1][0] for p in points] == pytest.approx(pga, rel=1e-12)
    over = (ds["overturned"].values == 1).T
    cells = _csv(out, "object_capacity")
    for j, name in enumerate(OBJECTS):
        want = np.min(pga[over[j]]) if over[j].any() else np.nan
        got = cells.loc[name, "governing capacity"]
        assert (np.isnan(got) and np.isnan(want)) or got == pytest.approx(want, rel=1e-12)


def test_each_object_has_one_colour_and_its_capacities_on_its_curve(tmp_path, ida, drawn):
    """The fragility, deaggregation and stripes-beside-IDA figures colour an object alike
    (and two objects apart); its IDA capacities are drawn beside its curve at the plotting positions
    (k - 1/2) / n of their ranks; each IDA panel's axis spans the capacities and the uplift
    level, with at most the margin of a factor 1.3 beyond them."""
    from rockstudy import risk

    hazard = risk.HazardCurve.power_law(
        1e-4, 2.5, im="pga", units="g", levels=np.geomspace(0.05, 3.0, 12)
    )
    records = load_suite([DATA / f for f in FILES])
    stripes = multiple_stripes(records, OBJECTS, np.array([0.3, 0.6, 1.2, 2.4]) * G_UNIT)
    record_report(ida, tmp_path / "r", n_boot=5, hazard=hazard, compare=stripes)
    cap = _capacities(ida) / G_UNIT
    colours = {}
    for figure in ("object_fragility", "deaggregation"):
        lines = [ln for ln in drawn[figure][0] if ln[4] in OBJECTS]
        colours[figure] = {ln[4]: ln[3] for ln in lines}
    assert colours["object_fragility"] == colours["deaggregation"]
    for ln in drawn["stripes_and_ida"][0]:  # "IDA: name" solid, "stripes: name" dashed
        what, _, name = ln[4].partition(": ")
        assert ln[3] == colours["deaggregation"][name] and what in ("IDA", "stripes")
    assert len(set(colours["deaggregation"].values())) == len(OBJECTS)
    for j, name in enumerate(OBJECTS):
        colour = colours["object_fragility"][name]
        marks = [ln for ln in drawn["object_fragility"][0] if ln[3] == colour and ln[2] == "None"]
        x, y = marks[0][0], marks[0][1]
        n = cap.shape[0]
        assert x == pytest.approx(np.sort(cap[:, j]), rel=1e-9)
        assert y == pytest.approx((np.arange(1, n + 1) - 0.5) / n, rel=1e-12)
    for j, block in enumerate(OBJECTS.values()):
        low, high = drawn["object_ida_ylim"][j]
        inside = np.append(cap[:, j], G * math.tan(block.slenderness) / G_UNIT)
        assert low <= inside.min() and high >= inside.max()
        assert low >= inside.min() / 1.3 - 1e-12 and high <= inside.max() * 1.3 + 1e-12


def test_wide_tables_fit_a_page_1400_pixels_wide(tmp_path):
    """The eight shipped records under three objects (a records table of 17 columns, a
    capacity table of ten): rendered in headless Chromium 1,400 pixels wide, no table
    scrolls sideways and neither does the page."""

    records = load_suite(sorted(DATA.glob("*_H.AT2")))
    objects = {f"Object {k}": rs.Block(0.3 + 0.3 * k, 0.15 + 0.03 * k) for k in range(3)}
    page = record_report(cloud(records, objects, rtol=1e-6), tmp_path / "r", n_boot=5)
    shown, total = chromium_figures(page)
    assert shown == total > 0
    probe = (
        "<script>window.addEventListener('load',()=>{"
        "const w=[...document.querySelectorAll('div.wide')];"
        "const o=w.filter(d=>d.scrollWidth>d.clientWidth+1).length;"
        "document.body.dataset.overflow=o+'/'+w.length+'/'"
        "+document.documentElement.scrollWidth;});</script>"
    )
    probed = page.parent / "probe.html"
    probed.write_text(page.read_text().replace("</body>", probe + "</body>"))
    out = chromium_dom(probed, tmp_path / "profile", extra=["--window-size=1400,1000"])
    over, tables, width = map(int, re.search(r'data-overflow="([^"]*)"', out.stdout)[1].split("/"))
    assert tables >= 6 and over == 0
    assert width <= 1400


@pytest.mark.parametrize(
    ("im", "written", "shown"),
    [
        ("pga", "m/s^2", "m/s^2"),
        ("sa", "g", "g"),
        (HALF, "m/s^2", "m/s^2"),  # a registered measure quoted in g: an acceleration
        (HALF, "g", "g"),
        ("pgv", "m/s", "g"),  # no acceleration target: the accelerations in g
        ("pga_ratio", "-", "g"),
    ],
)
def test_a_study_report_shows_accelerations_in_the_units_of_its_target(
    own_measures, im, written, shown
):
    from types import SimpleNamespace

    from rockstudy.study.report.sampled import _acceleration_units

    target = SimpleNamespace(im=im, unit_label=written)
    assert _acceleration_units(SimpleNamespace(motion=SimpleNamespace(scale_to=target))) == shown


def test_the_deaggregation_is_a_density_in_ln_x_and_the_objects_are_ranked_by_p(
    drawn, tmp_path, monkeypatch
):
    """Each deaggregation line, times the widths in ln x of the hazard's intervals, adds up to
    the object's share of lambda_OT within the levels (from deaggregation.csv: uneven levels
    do not shape it); the ranked chart lists the objects by P(years), highest first."""
    from rockstudy import risk

    recs = [
        rs.motions.synthetic_near_fault(pulse_period=tp, pga=3.0, seed=k, duration=6.0)
        for k, tp in enumerate((0.5, 0.8, 1.0, 1.2, 1.4, 1.6))
    ]
    ds = incremental_dynamic_analysis(recs, OBJECTS, step=0.05, scan=0, tolerance=0.01)
    levels = np.array([0.01, 0.02, 0.1, 0.15, 0.3, 0.35, 0.8, 2.0])  # an uneven grid [g]
    hazard = risk.HazardCurve("pga", levels, 1e-4 * levels**-2.5, units="g")
    out = tmp_path / "r"
    labels = {}
    inner_figure = _page._Page.figure

    def figure(self, fig, name, caption):
        labels[name] = [t.get_text() for t in fig.axes[0].get_yticklabels()]
        return inner_figure(self, fig, name, caption)

    monkeypatch.setattr(_page._Page, "figure", figure)
    record_report(ds, out, n_boot=0, hazard=hazard)
    deagg = _csv(out, "deaggregation")
    table = _csv(out, "annual_overturning")
    inner = deagg.iloc[1:-1]  # the intervals between levels (the first and last are beyond)
    width = np.log(levels[1:] / levels[:-1])
    lines = {
        label: y for _, y, _, _, label in drawn["deaggregation"][0] if not label.startswith("_")
    }
    for name, y in lines.items():
        within = inner[name].sum() / table.loc[name, "lambda_OT [1/yr]"]
        assert np.sum(y * width) == pytest.approx(within, rel=1e-9)
    p = table["P(50 yr)"]
    ranked = p[p > 0].sort_values(ascending=False, kind="stable").index.tolist()
    assert len(ranked) >= 1 and labels["probability_ranked"] == ranked
