"""The record report of named objects (issue 24 section 2): per object, by name. Oracles:
single-scene simulations of each object under each scaled record (which record governs and
between which levels each object first overturns), the objects' own uplift level g tan(alpha),
and the records' own PGA (the scale factors beyond ``max_scale_factor``)."""

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _helpers import unit_sine_record

import rockstudy as rs
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.constants import G
from rockstudy.motions import load_suite
from rockstudy.study.designs.records import multiple_stripes
from rockstudy.study.report.records import record_report

DATA = Path(__file__).resolve().parents[1] / "data" / "records"
OBJECTS = {
    "Statue A": rs.Block.from_dimensions(width=0.45, height=1.9),
    "Vase": rs.Block(half_diagonal=0.4, slenderness=0.3, restitution=0.85),
}


@pytest.fixture(scope="module")
def records():
    return load_suite([DATA / "NF03_Tp0.80s_H.AT2", DATA / "NF06_Tp1.70s_H.AT2"])


def _text(page):
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page.read_text()))


def test_capacity_table_and_governing_record_per_object(tmp_path, records):
    levels = np.array([0.2, 0.4, 0.8, 1.6]) * G_UNIT
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    page = record_report(ds, tmp_path / "r", n_boot=5)
    table = pd.read_csv(tmp_path / "r" / "object_capacity.csv", index_col=0)
    assert list(table.index) == list(OBJECTS)
    names = [r.name for r in records]
    for obj, block in OBJECTS.items():
        first = {}  # the oracle: each scaled record alone, level by level
        for rec in records:
            over = [rs.simulate(block, rec.scaled(x / rec.peak)).overturned for x in levels]
            first[rec.name] = levels[over.index(True)] / G_UNIT if any(over) else np.inf
            k = over.index(True) if any(over) else -1
            cell = table.loc[obj, rec.name]
            if k < 0:
                assert cell == f"above {levels[-1] / G_UNIT:.3g}"
            elif k == 0:
                assert cell == f"at or below {levels[0] / G_UNIT:.3g}"
            else:
                assert cell == f"{levels[k - 1] / G_UNIT:.3g} to {levels[k] / G_UNIT:.3g}"
        lowest = min(first.values())
        governing = table.loc[obj, "governing record(s) (lowest capacity)"]
        if np.isfinite(lowest):
            assert governing.split(", ") == [n for n in names if first[n] == lowest]
            assert table.loc[obj, "governing capacity"] == pytest.approx(lowest, rel=1e-9)
    # the per-object figures and the uplift level g tan(alpha) of each object
    out = tmp_path / "r"
    assert (out / "object_stripes.png").exists()
    if (out / "object_fragility.csv").exists():
        fit = pd.read_csv(out / "object_fragility.csv", index_col=0)
        for obj, block in OBJECTS.items():
            up = fit.loc[[obj], "uplift level, PGA [g]"].iloc[0]
            # g tan(alpha) with the physics' g, quoted in the unit g (standard gravity)
            assert up == pytest.approx(G * math.tan(block.slenderness) / G_UNIT, rel=1e-9)
    assert "Nothing overturned" not in _text(page)


def test_nothing_rocked_is_said_in_words(tmp_path, records):
    # every level below the uplift level g tan(alpha) of every object: nothing can rock
    lowest_uplift = min(G * math.tan(b.slenderness) for b in OBJECTS.values())
    levels = np.array([0.2, 0.5]) * lowest_uplift
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    assert float(np.nanmax(ds["max_rotation"].values)) == 0.0  # the oracle agrees
    page = record_report(ds, tmp_path / "r", n_boot=5)
    text = _text(page)
    assert "Nothing rocked" in text and "no fragility can be fitted" in text
    assert not (tmp_path / "r" / "object_fragility.png").exists()
    table = pd.read_csv(tmp_path / "r" / "object_capacity.csv", index_col=0)
    by_record = table[[r.name for r in records]]
    assert (by_record == f"above {levels[-1] / G_UNIT:.3g}").all().all()


def _short_steps(block, fractions, dt=0.001, duration=1.5):
    """Records of one rectangular pulse of unit acceleration lasting ``fraction`` / p each, then
    rest (the stripes scale their peak, the pulse, to the level)."""
    p = block.frequency_parameter
    t = np.arange(0.0, duration, dt)
    return [
        rs.motions.Record(np.where(t < f / p, 1.0, 0.0), dt=dt, name=f"step {f}") for f in fractions
    ]


def test_nothing_overturned_but_rocked(tmp_path):
    """Steps of A = 1.05 tan(alpha) g, above uplift (the block rocks), lasting at most 0.5 / p.
    Housner's rectangular pulse (linearized) leaves the block at theta = (A - alpha)(cosh pt - 1),
    theta' / p = (A - alpha) sinh pt, and free rocking then reaches alpha only if
    (A - alpha)(e^pt - 1) > alpha: a step overturns only if it lasts over ln(A / (A - alpha)) / p
    (2.6 / p for the Vase, alpha = 0.3). Steps five times shorter cannot overturn it."""
    vase = OBJECTS["Vase"]
    alpha, fractions = vase.slenderness, (0.3, 0.5)
    amplitude = 1.05 * math.tan(alpha)
    assert all(f < 0.2 * math.log(amplitude / (amplitude - alpha)) for f in fractions)
    levels = np.array([1.05]) * G * math.tan(vase.slenderness)
    ds = multiple_stripes(_short_steps(vase, fractions), {"Vase": vase}, levels, rtol=1e-6)
    assert not ds["overturned"].values.any()
    assert (ds["max_rotation"].values > 0).all()
    text = _text(record_report(ds, tmp_path / "r", n_boot=5))
    assert "Nothing overturned" in text and "Nothing rocked" not in text


def test_scale_factor_warning_and_units(tmp_path, records):
    levels = np.array([0.5, 3.0]) * G_UNIT
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    page = record_report(ds, tmp_path / "r", n_boot=5, units="m/s^2", max_scale_factor=5)
    text = _text(page)
    factors = np.array([[x / r.peak for x in levels] for r in records])  # the records' PGA
    beyond = int((factors > 5).sum()) * len(OBJECTS)
    if beyond:
        assert f"{beyond} of {factors.size * len(OBJECTS)} stripe points" in text
        assert "max_scale_factor = 5" in text
    else:
        assert "max_scale_factor" not in text
    assert "[m/s^2]" in text and "PGA [g]" not in text.split("Records")[0]
    quiet = record_report(ds, tmp_path / "q", n_boot=5, max_scale_factor=1e6)
    assert "max_scale_factor" not in _text(quiet)
    with pytest.raises(ValueError, match="units"):
        record_report(ds, tmp_path / "bad", units="gee")
    with pytest.raises(ValueError, match="max_scale_factor"):
        record_report(ds, tmp_path / "bad", max_scale_factor=0.5)


# ------------------------------------------------------------------------------ friction


def test_friction_below_uplift_is_the_peak_ground_acceleration_and_flags(tmp_path, records):
    """Below uplift the block moves with the ground: its friction demand is max |a_g| / g,
    here the stripe level / g; a level whose demand exceeds mu is flagged, the others not."""
    lowest_uplift = min(G * math.tan(b.slenderness) for b in OBJECTS.values())
    levels = np.array([0.3, 0.6, 0.9]) * lowest_uplift
    mu = 0.5 * (levels[1] + levels[2]) / G  # between the second and the third level
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6, friction=mu)
    expect = np.broadcast_to(levels / G, ds["friction_demand"].shape)
    np.testing.assert_allclose(ds["friction_demand"].values, expect, rtol=1e-9)
    assert not ds["lift_off"].values.any()
    page = record_report(ds, tmp_path / "r", n_boot=5, friction=mu)
    text = _text(page)
    n_flag = len(records) * len(OBJECTS)  # the third level, every record and object
    assert f"{n_flag} of {ds['friction_demand'].size} scenes lie outside" in text
    table = pd.read_csv(tmp_path / "r" / "friction_check.csv", index_col=0)
    assert (table["scenes outside the model (demand > mu or lift-off)"] == 1).all()
    assert set(table.index) == {f"{o} / {r.name}" for o in OBJECTS for r in records}
    # per object: the Vase alone given a friction above every demand
    per_object = [mu, 1.0]
    text = _text(record_report(ds, tmp_path / "p", n_boot=5, friction=per_object))
    assert f"{len(records)} of {ds['friction_demand'].size} scenes lie outside" in text
    text = _text(record_report(ds, tmp_path / "q", n_boot=5, friction=1.0))
    assert "the block model holds" in text and "lie outside" not in text
    for bad in (-0.2, [0.3, 0.4, 0.5], np.nan):
        with pytest.raises(ValueError, match="friction"):
            record_report(ds, tmp_path / "bad", n_boot=5, friction=bad)


from rockstudy.study import load_study, run_study  # noqa: E402
from rockstudy.study.report import make_report  # noqa: E402
from rockstudy.study.running.store import open_result  # noqa: E402

FRICTION_STUDY = """
name = "museum friction"
seed = 1
friction = 0.6
[structure]
kind = "objects"
objects = [
  {{ name = "Statue A", width = 0.45, height = 1.9, friction = 0.07 }},
  {{ name = "Vase", half_diagonal = 0.4, slenderness = 0.3, restitution = 0.85 }},
]
[motion]
kind = "record"
files = ["{a}", "{b}"]
scale_to = {{ im = "pga", units = "g", value = {{ dist = "grid", values = [0.05, 0.1] }} }}
[design]
kind = "stripes"
"""


def test_friction_in_an_objects_study_cube_report_and_run_warning(client, tmp_path, capsys):
    """Levels below the uplift of both objects: each scene's demand is its level in g (the
    oracle); Statue A's mu 0.07 lies between the levels, the Vase's (the study's 0.6) above."""
    a, b = DATA / "NF03_Tp0.80s_H.AT2", DATA / "NF06_Tp1.70s_H.AT2"
    path = tmp_path / "museum.toml"
    path.write_text(FRICTION_STUDY.format(a=a, b=b))
    study = load_study(path)
    np.testing.assert_array_equal(study.friction_coefficients(), [0.07, 0.6])
    out = tmp_path / "cube.zarr"
    run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    cube = open_result(out).load()
    levels_g = np.array([0.05, 0.1]) * G_UNIT / G  # "g" of units: 9.80665 m/s^2
    demand = cube["friction_demand"].transpose("record", "structure", "level").values
    np.testing.assert_allclose(demand, np.broadcast_to(levels_g, demand.shape), rtol=1e-9)
    text = _text(make_report(out, tmp_path / "report"))
    assert "2 of 8 scenes lie outside" in text  # Statue A at 0.1 g under both records
    table = pd.read_csv(tmp_path / "report" / "friction_check.csv", index_col=0)
    flagged = table["scenes outside the model (demand > mu or lift-off)"]
    assert flagged.filter(like="Statue A").tolist() == [1, 1]
    assert flagged.filter(like="Vase").tolist() == [0, 0]
    from rockstudy.cli import _contact_warning

    _contact_warning(study, out)
    assert "warning: 2 of 8 scenes lie outside" in capsys.readouterr().err


def test_friction_in_a_monte_carlo_study(client, tmp_path):
    """A Monte Carlo pulse study with friction stores the contact check: below uplift (the
    pulse amplitude a fraction of g tan alpha) the demand is a_g / g."""
    text = """
name = "mc friction"
seed = 3
friction = 0.15
[sampler]
kind = "monte_carlo"
n = 16
[structure]
kind = "block"
half_diagonal = { dist = "uniform", low = 0.5, high = 2.0 }
slenderness = { dist = "uniform", low = 0.2, high = 0.3 }
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = { dist = "uniform", low = 0.2, high = 0.9 }
period = { dist = "uniform", low = 0.3, high = 1.0 }
"""
    path = tmp_path / "mc.toml"
    path.write_text(text)
    study = load_study(path)
    assert {"friction_demand", "lift_off"} <= set(study.run.outputs)
    out = tmp_path / "mc.zarr"
    run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    cube = open_result(out).load()
    a_g = cube["amplitude"].values
    np.testing.assert_allclose(cube["friction_demand"].values, a_g / G, rtol=1e-9)
    page = make_report(out, tmp_path / "report")
    n = int((a_g / G > 0.15).sum())
    assert 0 < n < a_g.size
    assert f"{n} of {a_g.size} scenes lie outside" in _text(page)


@pytest.mark.parametrize("span", [(0.3, 0.8), (0.2, 4.0), (0.015, 40.0), (1.2, 1.9)])
def test_every_log_axis_is_numbered(span):
    """A logarithmic axis of the reports carries at least three numbered ticks, however
    short its span (the right-hand panel of the size-collapse figure had none)."""
    from rockstudy.study.report._page import _log_ticks, _plt

    plt = _plt()
    fig, ax = plt.subplots()
    ax.plot(span, span)
    ax.set(xscale="log", yscale="log", xlim=span, ylim=span)
    _log_ticks(ax)
    _log_ticks(ax, "y")
    fig.canvas.draw()
    for axis in (ax.xaxis, ax.yaxis):
        labels = [t.get_text() for t in axis.get_ticklabels(minor=False)]
        labels += [t.get_text() for t in axis.get_ticklabels(minor=True)]
        ticks = list(axis.get_majorticklocs()) + list(axis.get_minorticklocs())
        shown = {float(t) for t, s in zip(ticks, labels, strict=True) if s}
        inside = [t for t in shown if span[0] <= t <= span[1]]
        assert len(inside) >= 3, (span, labels)
        for t in axis.get_ticklabels(minor=True) + axis.get_ticklabels():
            assert t.get_fontsize() >= 8
    plt.close(fig)


def test_ida_report_of_objects_sorted_curves_and_capacity(tmp_path):
    """An IDA of two objects under one sine cycle (overturning monotone in scale): the
    capacity table gives the PGA at first overturning, which a single-scene simulation
    confirms (it overturns there and stands at the lower bracket), and each drawn IDA curve
    climbs in scale even when the stored points are shuffled."""

    from rockstudy.study.designs.records import incremental_dynamic_analysis
    from rockstudy.study.report import objects as ro
    from rockstudy.study.report._page import _plt
    from rockstudy.study.report.records import ReportContext, im_label

    rec = unit_sine_record(1.5)
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    ds = incremental_dynamic_analysis(rec, objects, scan=0, step=0.05, tolerance=0.01)
    record_report(ds, tmp_path / "r", n_boot=5)
    table = pd.read_csv(tmp_path / "r" / "object_capacity.csv", index_col=0)
    for name, block in objects.items():
        cap = float(table.loc[name, rec.name])
        s_hi = cap * G / rec.peak
        assert rs.simulate(block, rec.scaled(s_hi * (1 + 1e-9))).overturned
        lower = float(ds["capacity_scale_lower"].sel(structure=name)[0])
        assert not rs.simulate(block, rec.scaled(lower)).overturned
        assert lower < s_hi <= lower * 1.0101
    rng = np.random.default_rng(0)
    shuffled = ds.copy(deep=True)
    perm = rng.permutation(ds.sizes["step"])
    for k in ("step_scale", "step_max_rotation", "step_overturned", "step_kind"):
        shuffled[k] = ds[k].isel(step=perm)
    ctx = ReportContext(shuffled)
    ctx.im_label = im_label
    fig, ax = _plt().subplots()
    ro._ida_curve(ax, ctx, 0, 0, 0.0)
    y = ax.lines[0].get_ydata()
    assert y.size > 3 and np.all(np.diff(y) > 0)
    _plt().close(fig)


def test_an_object_that_never_overturned_reads_not_reached(tmp_path, records):
    """A stocky object beside a slender one: where (by the oracle, each scaled record alone)
    it never overturned, its median capacity is said in words, not as inf."""
    objects = {"Statue A": OBJECTS["Statue A"], "Plinth": rs.Block(2.0, 0.5)}
    levels = np.array([0.2, 0.4, 0.8]) * G_UNIT
    stood = all(
        not rs.simulate(objects["Plinth"], rec.scaled(x / rec.peak)).overturned
        for rec in records
        for x in levels
    )
    assert stood
    ds = multiple_stripes(records, objects, levels, rtol=1e-6)
    record_report(ds, tmp_path / "r", n_boot=5)
    fit = pd.read_csv(tmp_path / "r" / "object_fragility.csv", index_col=0)
    plinth = fit.loc[["Plinth"]]
    assert (plinth["median capacity"] == "not reached (never overturned)").all()
    statue = pd.to_numeric(fit.loc[["Statue A"], "median capacity"])
    assert np.isfinite(statue).all()


def test_an_ida_friction_warning_says_which_scenes_and_a_lift_off_reads_in_words(tmp_path):
    """The contact check of an IDA is at each record's highest scale below the first
    overturning: the warning says so, with the PGA range of those scenes; a scene that lifted
    off has no finite friction demand and its row says why."""

    from rockstudy.study.designs.records import incremental_dynamic_analysis

    rec = unit_sine_record(1.5)
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    ds = incremental_dynamic_analysis(rec, objects, scan=0, step=0.05, friction=0.05)
    text = _text(record_report(ds, tmp_path / "r", n_boot=5, friction=0.05))
    scenes = ds["capacity_scale_lower"].values * rec.peak / G_UNIT  # the PGA of each scene [g]
    assert "IDA: each scene is a record at the highest scale simulated below" in text
    assert f"here PGA {scenes.min():.3g} to {scenes.max():.3g} g" in text
    lifted = ds.copy(deep=True)
    lifted["friction_demand"][0, 1] = np.nan
    lifted["lift_off"][0, 1] = True
    record_report(lifted, tmp_path / "l", n_boot=5, friction=0.05)
    table = pd.read_csv(tmp_path / "l" / "friction_check.csv", index_col=0)
    column = "largest finite friction demand |F_h / F_v| [-]"
    assert table.loc[f"Urn / {rec.name}", column] == "lifted off (F_v < 0)"
    assert float(table.loc[f"Stele / {rec.name}", column]) > 0.05


@pytest.mark.parametrize("im", ["pga", "pga_ratio"])
def test_the_pga_fragility_drawn_is_zero_below_uplift_under_horizontal_records(records, im):
    """Drawn solid: 0 below each object's uplift PGA g tan(alpha) (1 in PGA / a_up: nothing
    can rock there) and the fitted lognormal Phi(ln(x / theta) / beta) above it; with a
    vertical component in the design, the whole lognormal."""
    from scipy.stats import norm

    from rockstudy.study.report import objects as ro
    from rockstudy.study.report._page import _plt
    from rockstudy.study.report.records import ReportContext, im_label

    levels = np.array([0.2, 0.4, 0.8, 1.6]) * G_UNIT
    ds = multiple_stripes(records, OBJECTS, levels, rtol=1e-6)
    for vertical in (False, True):
        ds["vertical_component"] = ("record", np.full(ds.sizes["record"], vertical))
        ctx = ReportContext(ds, n_boot=0)
        ctx.im_label = im_label
        t = ro._object_fit(ctx, im, None)  # two records: separated, so a fit is given
        t["theta"], t["beta"], t["p_band"] = [0.5, 0.8], [0.6, 0.4], "none"
        t[["var_ln_theta", "var_ln_beta", "cov_ln_theta_ln_beta"]] = 0.0
        fig, ax = _plt().subplots()
        assert ro._plot_objects(ax, ctx, t, im, None)
        solid = [ln for ln in ax.lines if ln.get_linestyle() == "-"]
        for name, line in zip(t.index, solid, strict=True):
            x, y = line.get_xdata(), line.get_ydata()
            fit = norm.cdf(np.log(x / t.loc[name, "theta"]) / t.loc[name, "beta"])
            x_u = G * math.tan(OBJECTS[name].slenderness) / G_UNIT if im == "pga" else 1.0
            expected = fit if vertical else np.where(x >= x_u, fit, 0.0)
            np.testing.assert_allclose(y, expected, rtol=1e-9, atol=1e-15)
            assert vertical or (x < x_u).any()
        _plt().close(fig)


def test_the_risk_section_says_the_jump_at_uplift_and_warns_of_extrapolated_rates(tmp_path):
    """An IDA of two objects under sine records (horizontal): the fragility is cut at g
    tan(alpha) and the table's P(OT) just above it is the fitted lognormal there; a hazard
    curve tabulated only far above the capacities puts most of each rate in its extrapolated
    lower tail, and the page warns."""
    from scipy.stats import norm

    from rockstudy import risk
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    recs = [unit_sine_record(tp) for tp in (0.6, 0.9, 1.2, 1.5, 2.0, 2.5)]
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    ds = incremental_dynamic_analysis(recs, objects, scan=0, step=0.05, tolerance=0.01)
    narrow = risk.HazardCurve.power_law(1e-4, 2.5, im="pga", units="g", levels=[5.0, 8.0])
    text = _text(record_report(ds, tmp_path / "r", n_boot=5, hazard=narrow))
    assert "P(OT) jumps there from 0 to the lognormal" in text
    assert "comes from beyond the hazard curve" in text
    table = pd.read_csv(tmp_path / "r" / "annual_overturning.csv", index_col=0)
    for name, block in objects.items():
        row = table.loc[name]
        x_u = G * math.tan(block.slenderness) / G_UNIT
        expected = norm.cdf(np.log(x_u / row["median [g]"]) / row["beta"])
        assert row["P(OT) just above it"] == pytest.approx(expected, rel=1e-9)
        assert row["fragility 0 below [g]"] == pytest.approx(x_u, rel=1e-12)
        assert row["share beyond the curve's levels"] > 0.1
    wide = risk.HazardCurve.power_law(1e-4, 2.5, im="pga", units="g", levels=[0.01, 9.0])
    text = _text(record_report(ds, tmp_path / "w", n_boot=5, hazard=wide))
    assert "comes from beyond the hazard curve" not in text


def test_the_rate_without_records_outside_the_model_is_refitted_without_them(tmp_path):
    """With a friction coefficient that the strongest-pulse records exceed, each object's
    rate is given again without the records under which it would slide: the lognormal
    refitted to the other capacities (scipy's normal fit of their logarithms) and integrated
    with its cut at g tan(alpha)."""
    from scipy.stats import norm

    from rockstudy import risk
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    recs = [unit_sine_record(tp) for tp in (0.6, 0.9, 1.2, 1.5, 2.0, 2.5)]
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    # the demand does not depend on mu: the report compares it with the mu below
    ds = incremental_dynamic_analysis(
        recs, objects, scan=0, step=0.05, tolerance=0.01, friction=0.5
    )
    demand = ds["friction_demand"].values  # (record, structure)
    mu = float(np.sort(demand.max(axis=1))[-2])  # the record of the largest demand exceeds it
    hazard = risk.HazardCurve.power_law(1e-4, 2.5, im="pga", units="g")
    record_report(ds, tmp_path / "r", n_boot=5, hazard=hazard, friction=mu)
    table = pd.read_csv(tmp_path / "r" / "annual_overturning_within_model.csv", index_col=0)
    assert len(table) >= 1
    for name, row in table.iterrows():
        j = list(objects).index(name)
        outside = (demand[:, j] > mu) | ds["lift_off"].values[:, j]
        assert row["records outside the model"].split(", ") == [
            r.name for r, o in zip(recs, outside, strict=True) if o
        ]
        pga = np.array([r.peak for r in recs]) / G_UNIT
        caps = np.log(ds["capacity_scale"].values[~outside, j] * pga[~outside])
        mu_ln, beta = norm.fit(caps)
        x_u = G * math.tan(objects[name].slenderness) / G_UNIT
        expected = risk.annual_rate(np.exp(mu_ln), beta, hazard, threshold=x_u)
        assert row["lambda_OT without them [1/yr]"] == pytest.approx(expected, rel=1e-9)


def test_objects_whose_capacities_do_not_look_lognormal_are_named_in_a_warning(tmp_path):
    """The warning names (escaped) the objects whose capacities the Shapiro-Wilk test rejects
    at 0.01, and only those."""
    from types import SimpleNamespace

    from rockstudy.study.report import objects as ro
    from rockstudy.study.report._page import _Page

    table = pd.DataFrame(
        {"intensity": ["PGA [g]"] * 3, "lack_of_fit_p": [0.2, 0.004, np.nan]},
        index=pd.Index(["Kouros", "<Urn & lid>", "Stele"], name="object"),
    )
    page = _Page(tmp_path)
    ro._capacities_not_lognormal(page, SimpleNamespace(), table)
    text = "".join(page.parts)
    assert "&lt;Urn &amp; lid&gt; in PGA [g] (p = 0.004)" in text
    assert "Kouros" not in text and "Stele" not in text
    quiet = _Page(tmp_path)
    ro._capacities_not_lognormal(quiet, SimpleNamespace(), table.iloc[[0, 2]])
    assert not quiet.parts


def test_the_risk_section_resamples_as_often_as_the_report_is_told(tmp_path):
    """``record_report(n_boot=...)`` reaches the annual rates: without resampling the risk
    table has no band, with it every band brackets its rate, and the page says how many
    resamples made it."""

    from rockstudy import risk
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    recs = [unit_sine_record(tp) for tp in (0.6, 0.9, 1.2, 1.5, 2.0, 2.5)]
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    ds = incremental_dynamic_analysis(recs, objects, scan=0, step=0.05, tolerance=0.01)
    hazard = risk.HazardCurve.power_law(1e-4, 2.5, im="pga", units="g")
    bands = []
    for n_boot in (0, 12):
        text = _text(record_report(ds, tmp_path / f"r{n_boot}", n_boot=n_boot, hazard=hazard))
        table = pd.read_csv(tmp_path / f"r{n_boot}" / "annual_overturning.csv", index_col=0)
        rate = table["lambda_OT [1/yr]"]
        low, high = table["lambda_OT, 5 %"], table["lambda_OT, 95 %"]
        bands.append((rate, low, high))
        assert (f"from {n_boot} resamples of the records" in text) == (n_boot > 0)
    rate, low, high = bands[0]
    assert low.isna().all() and high.isna().all()
    rate, low, high = bands[1]
    assert np.isfinite(rate).all() and ((low <= rate) & (rate <= high)).all()


def test_the_risk_section_draws_the_hazard_curve_with_the_records_on_it(tmp_path):
    """The hazard curve as read is drawn with each record's own PGA (max |a_g| of the record,
    in the curve's units) and each object's uplift level on it."""

    from rockstudy import risk
    from rockstudy.study.analysis.risk import records_measure
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    recs = [unit_sine_record(tp) for tp in (0.6, 0.9, 1.2, 1.5, 2.0, 2.5)]
    objects = {"Stele": rs.Block(1.0, 0.2), "Urn": rs.Block(0.5, 0.25)}
    ds = incremental_dynamic_analysis(recs, objects, scan=0, step=0.05, tolerance=0.01)
    hazard = risk.HazardCurve.from_csv(
        Path(__file__).resolve().parents[1] / "data" / "hazard" / "site_pga.csv",
        im="pga",
        units="g",
    )
    pga = np.array([np.max(np.abs(r.acceleration)) for r in recs])  # [m/s^2]
    np.testing.assert_allclose(records_measure(ds, hazard), pga, rtol=1e-12)
    text = _text(record_report(ds, tmp_path / "r", n_boot=0, hazard=hazard))
    assert (tmp_path / "r" / "hazard_curve.png").is_file()
    assert "hazard curve as it was read" in text
