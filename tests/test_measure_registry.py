"""The registry of intensity measures (issue 25 section 2): a measure registered in one call
appears in Record.intensity_measures(), scales a design, a study's scale_to, the fragility,
the IM efficiency and the report. Oracles: the measure recomputed with numpy on the scaled
record's own samples, the invariance of the lognormal fit under x -> x^2 (theta squared,
beta doubled), and the registry's refusals named by argument."""

import html
from pathlib import Path

import numpy as np
import pytest
from _helpers import rows_study, run_rows, write_near_fault_pairs

from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.constants import G
from rockstudy.motions import Record, load_suite, measures, register_measure
from rockstudy.study.analysis import record_fragility as rf
from rockstudy.study.designs.records import cloud, multiple_stripes
from rockstudy.study.report.records import record_report
from rockstudy.study.spec.schema import ScaleTo

DATA = Path(__file__).resolve().parents[1] / "data" / "records"
STRUCTURES = {"half_diagonal": [0.3, 1.0, 3.0], "slenderness": 0.2}
#: PGA levels [m/s^2] from 0.1 g to 3 g: both outcomes for these blocks (test_report_records)
PGA_LEVELS = np.geomspace(0.1, 3.0, 6) * G


def first_half_peak(record) -> float:
    """max |a| over the first half of the record [m/s^2], by numpy on its samples."""
    a = np.asarray(record.acceleration)
    return float(np.max(np.abs(a[record.time <= 0.5 * record.duration])))


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    """A folder of three synthetic near-fault records: horizontal and vertical .AT2 files."""
    return write_near_fault_pairs(tmp_path_factory.mktemp("records"))


@pytest.fixture
def registered():
    """Two measures registered for one test, and removed after it."""
    register_measure(
        "pga_first_half",
        first_half_peak,
        unit="m/s^2",
        power=1,
        quoted_unit="g",
        factor=1.0 / G_UNIT,
        label="PGA of the first half",
    )
    register_measure("pga_squared", lambda r: r.peak**2, unit="m^2/s^4", power=2)
    try:
        yield
    finally:
        for name in ("pga_first_half", "pga_squared"):
            measures.unregister_measure(name)


@pytest.fixture(scope="module")
def records():
    return load_suite([DATA / "NF03_Tp0.80s_H.AT2", DATA / "NF06_Tp1.70s_H.AT2"])


def test_a_registered_measure_is_listed_with_its_value(registered, records):
    for rec in records:
        ims = rec.intensity_measures(periods=[0.5])
        assert ims["pga_first_half"] == first_half_peak(rec)
        assert ims["pga_squared"] == pytest.approx(np.max(np.abs(rec.acceleration)) ** 2)
        assert ims["pga_first_half"] <= ims["pga"]
        # it scales a record as its power says: the scaled record's own samples agree
        scaled = rec.scaled_to(4.0, im="pga_squared")
        assert np.max(np.abs(scaled.acceleration)) == pytest.approx(2.0, rel=1e-12)


def test_a_design_scales_each_record_to_the_level_of_the_new_measure(registered, records):
    """multiple_stripes(im=name): every scaled record, rebuilt from the factor the design
    applied, has the level as its measure (recomputed by numpy on its samples)."""
    levels = np.array([0.5, 2.0, 6.0])
    ds = multiple_stripes(records, STRUCTURES, levels, im="pga_first_half", rtol=1e-6)
    assert ds.attrs["im"] == "pga_first_half"
    assert ds["pga_first_half"].attrs["units"] == "m/s^2"
    for i, rec in enumerate(records):
        for j, level in enumerate(levels):
            for k in range(ds.sizes["structure"]):
                s = float(ds["scale"].values[i, k, j])
                assert first_half_peak(rec.scaled(s)) == pytest.approx(level, rel=1e-12)
    # the measure of the scaled points in quoted units: the levels in g
    x = rf.intensity(ds, "pga_first_half")
    np.testing.assert_allclose(x.values, np.broadcast_to(levels / G_UNIT, x.shape), rtol=1e-12)
    assert x.attrs["unit"] == "g"


def test_power_two_scales_by_the_square_root_and_fits_as_the_square(registered, records, tmp_path):
    """Stripes at levels PGA^2: the factor is sqrt(level) / PGA; the fragility against PGA^2 is
    that against PGA with theta squared and beta doubled (the binomial fit is invariant under
    x -> x^2), and the IM efficiency ranks both alike per power (beta / k). The report
    accepts the measures, labelled from the registry."""
    ds = multiple_stripes(records, STRUCTURES, PGA_LEVELS**2, im="pga_squared", rtol=1e-6)
    peaks = np.array([np.max(np.abs(r.acceleration)) for r in records])
    expected = np.broadcast_to(PGA_LEVELS[None, None, :] / peaks[:, None, None], ds["scale"].shape)
    np.testing.assert_allclose(ds["scale"].values, expected, rtol=1e-12)
    assert 0 < ds["overturned"].sum() < ds["overturned"].size  # both outcomes
    by_pga = rf.stripe_fragility(ds, im="pga", n_boot=0)
    by_sq = rf.stripe_fragility(ds, n_boot=0)  # the stripes' own: pga_squared
    assert by_sq["unit"].iloc[0] == "m^2/s^4" and by_pga["unit"].iloc[0] == "g"
    theta_si = by_pga["theta"].iloc[0] * G_UNIT  # PGA is quoted in the unit g
    assert by_sq["theta"].iloc[0] == pytest.approx(theta_si**2, rel=1e-5)
    assert by_sq["beta"].iloc[0] == pytest.approx(2 * by_pga["beta"].iloc[0], rel=1e-5)
    table = rf.im_efficiency(ds, n_boot=10)  # the defaults take every stored scalable measure
    names = {i[0] for i in table.index}
    assert {"pga", "pga_squared", "pga_first_half", "pga_ratio"} <= names
    row_sq, row_pga = table.loc[("pga_squared", "all")], table.loc[("pga", "all")]
    assert row_sq["power"] == 2 and row_sq["beta_linear"] == pytest.approx(
        row_pga["beta_linear"], rel=1e-5
    )
    page = record_report(ds, tmp_path / "report", n_boot=10)
    text = page.read_text()
    assert html.escape("PGA of the first half [g]") in text
    assert "pga squared [m^2/s^4]" in text
    assert "PGA of the first half [g]" in (tmp_path / "report" / "im_efficiency.csv").read_text()


def test_a_cloud_stores_the_measure_and_fits_it(registered, records):
    ds = cloud([r.scaled(3.0) for r in records], STRUCTURES, rtol=1e-6)
    expected = [first_half_peak(r.scaled(3.0)) for r in records]
    np.testing.assert_allclose(ds["pga_first_half"].values, expected, rtol=1e-12)
    x = rf.intensity(ds, "pga_first_half")
    np.testing.assert_allclose(x.values, np.array(expected) / G_UNIT, rtol=1e-12)


def test_a_study_scales_rows_to_the_new_measure(registered, suite, tmp_path):  # noqa: F811
    """scale_to = { im = "pga_first_half", units = "g" } in a study file: validated against
    the registry, and each row's record, scaled by the factor the run applied, has the target
    (recomputed by numpy on the record file's samples)."""
    study = rows_study(
        suite,
        tmp_path,
        'scale_to = { im = "pga_first_half", units = "g", value = { dist = "uniform", '
        "low = 0.2, high = 0.6 } }",
    )
    design, out = run_rows(study, tmp_path)
    files = sorted(suite.glob("*_H.AT2"))
    for i in range(design.sizes["sample"]):
        rec = Record.from_at2(files[design["record"].values[i]])
        target = design["target"].values[i]  # stored in SI
        assert first_half_peak(rec.scaled(out["scale"][i])) == pytest.approx(target, rel=1e-12)
        assert out["pga_first_half"][i] == pytest.approx(target, rel=1e-12)
        # the squared PGA of the scaled record follows its power 2
        assert out["pga_squared"][i] == pytest.approx(
            (np.max(np.abs(rec.acceleration)) * out["scale"][i]) ** 2, rel=1e-12
        )
    assert 0.2 * G_UNIT <= design["target"].min() <= design["target"].max()
    assert design["target"].max() <= 0.6 * G_UNIT


def test_scale_to_reads_the_registry(registered):
    t = ScaleTo.model_validate({"im": "pga_first_half", "units": "g", "value": 0.3})
    assert t.si_factor() == G_UNIT
    t = ScaleTo.model_validate({"im": "pga_squared", "value": 4.0})
    assert t.unit_label == "m^2/s^4"
    with pytest.raises(ValueError, match="units"):
        ScaleTo.model_validate({"im": "pga_squared", "units": "g", "value": 4.0})
    with pytest.raises(ValueError, match="im"):
        ScaleTo.model_validate({"im": "pga_thirds", "value": 4.0})


def test_an_unregistered_measure_is_unknown_everywhere(records):
    with pytest.raises(ValueError, match="im must be one of"):
        records[0].intensity_measure("pga_first_half")
    with pytest.raises(ValueError, match="im must be one of"):
        multiple_stripes(records, STRUCTURES, [1.0], im="pga_first_half")
    with pytest.raises(ValueError, match="must be one of"):
        ScaleTo.model_validate({"im": "pga_first_half", "value": 1.0})
    assert "pga_first_half" not in records[0].intensity_measures()


def test_a_measure_a_scale_factor_does_not_change_is_not_a_scale_target(records):
    register_measure("strong_part", lambda r: 0.5 * r.duration, unit="s", power=0)
    try:
        assert "strong_part" in records[0].intensity_measures()
        with pytest.raises(ValueError, match="does not change with a scale factor"):
            records[0].scaled_to(1.0, im="strong_part")
        with pytest.raises(ValueError, match="im must be one of"):
            multiple_stripes(records, STRUCTURES, [1.0], im="strong_part")
        with pytest.raises(ValueError, match="must be one of"):
            ScaleTo.model_validate({"im": "strong_part", "value": 1.0})
    finally:
        measures.unregister_measure("strong_part")


def test_a_measure_that_needs_a_period(records):
    """A measure of (record, period, damping): the geometric mean of Sa at T and 2T. A design
    stores it on (record, period) and scales to it; each scaled record, rebuilt from the
    factor, has the level as its measure (its response spectrum recomputed)."""

    def sa_avg(record, period, damping):
        sa = record.response_spectrum([period, 2 * period], damping)["sa"].values
        return float(np.sqrt(sa[0] * sa[1]))

    register_measure("sa_avg", sa_avg, unit="m/s^2", power=1, needs_period=True, label="Sa avg")
    try:
        rec = records[0]
        assert rec.intensity_measures(periods=[0.5, 1.0])["sa_avg"].shape == (2,)
        with pytest.raises(ValueError, match="needs a period"):
            rec.intensity_measure("sa_avg")
        ds = multiple_stripes(records, STRUCTURES, [3.0], im="sa_avg", period=0.5, rtol=1e-6)
        assert ds["sa_avg"].dims == ("record", "period")
        for i, r in enumerate(records):
            s = float(ds["scale"].values[i, 0, 0])
            assert sa_avg(r.scaled(s), 0.5, 0.05) == pytest.approx(3.0, rel=1e-9)
        assert rf.intensity(ds, "sa_avg", 0.5).values == pytest.approx(3.0, rel=1e-9)
    finally:
        measures.unregister_measure("sa_avg")


def f(record):
    return 1.0


@pytest.mark.parametrize(
    "kwargs, argument",
    [
        ({"name": "pga"}, "name 'pga' is already a measure"),
        ({"name": "PGA half"}, "name must be a lower-case identifier"),
        ({"name": 3}, "name must be"),
        ({"name": "scale"}, "name 'scale' is reserved"),
        ({"name": "pga_ratio"}, "name 'pga_ratio' is reserved"),
        ({"function": "max"}, "function must be callable"),
        ({"unit": ""}, "unit must be a non-empty string"),
        ({"unit": None}, "unit must be a non-empty string"),
        ({"unit": "parsecs"}, "unit must be an SI unit"),
        ({"unit": "m/s^2 "}, "unit must be an SI unit"),
        ({"power": -1}, "power must be a finite number >= 0"),
        ({"power": float("nan")}, "power must be a finite number >= 0"),
        ({"power": True}, "power must be a number"),
        ({"power": "1"}, "power must be a number"),
        ({"factor": 0.0}, "factor must be a finite number > 0"),
        ({"factor": 2.0}, "factor = 2.0 needs quoted_unit"),
        ({"quoted_unit": "", "factor": 2.0}, "quoted_unit must be"),
        ({"label": 3}, "label must be"),
        ({"needs_period": "yes"}, "needs_period must be True or False"),
        ({"needs_damping": 1}, "needs_damping must be True or False"),
        ({"listed": None}, "listed must be True or False"),
        ({"name": "pga", "replace": "yes"}, "replace must be True or False"),
    ],
)
def test_bad_registrations_are_refused_naming_the_argument(kwargs, argument):
    before = dict(measures.MEASURES)
    args = {"name": "new_measure", "function": f, "unit": "m/s^2", "power": 1, **kwargs}
    with pytest.raises(ValueError, match=argument.replace("(", r"\(")):
        register_measure(**args)
    assert measures.MEASURES == before  # nothing half-registered


def test_replace_redefines_and_the_records_recompute(records):
    """The record's values follow the registry: its PGD before, the replacement's value (the
    area under |a|, by hand: (0 + 3 + 4 + 1) m/s^2 x 0.01 s = 0.08 m/s), its PGD again."""
    rec = Record(np.array([0.0, 3.0, -4.0, 1.0]), dt=0.01)
    before = rec.intensity_measure("pgd")
    old = measures.MEASURES["pgd"]
    try:
        area = lambda r: float(np.abs(r.acceleration).sum() * r.dt)  # noqa: E731
        register_measure("pgd", area, unit="m/s", power=1, replace=True)
        assert rec.intensity_measure("pgd") == pytest.approx(0.08, rel=1e-15)
    finally:
        measures.MEASURES["pgd"] = old
    assert rec.intensity_measure("pgd") == before and before != pytest.approx(0.08)
    with pytest.raises(ValueError, match="name must be one of"):
        measures.unregister_measure("nothing")


def test_a_function_that_returns_no_number_is_named(records):
    with pytest.raises(ValueError, match="the measure 'broken' must be a number"):
        register_measure("broken", lambda r: "big", unit="m", power=1)
    assert "broken" not in measures.MEASURES
