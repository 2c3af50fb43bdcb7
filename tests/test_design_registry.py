"""The registry of record design kinds drives every layer: each registered kind is accepted by
the study schema, makes its rows, is fitted and rated by the fitters its entry names, and gets
its report sections. Every kind is taken from the registry, none is listed here.

Oracles: single-scene simulations (:func:`rockstudy.simulate`) of the record scaled as the
design says (each point's outcome; an IDA's capacity overturns and the scale below it
stands), and the entry's own declarations (a ``level`` dimension, scale factors, capacities).
"""

import re

import numpy as np
import pytest

import rockstudy as rs
from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.motions import synthetic_near_fault
from rockstudy.study import StudyError, validate_text
from rockstudy.study.analysis import record_fragility as rf
from rockstudy.study.analysis import risk as analysis_risk
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.designs import record_rows
from rockstudy.study.designs import records as rd
from rockstudy.study.designs.sampling import make_design
from rockstudy.study.report import objects as ro
from rockstudy.study.report.records import record_report
from rockstudy.study.spec.design_kinds import DESIGN_KINDS, design_kind, kind_of

KINDS = list(DESIGN_KINDS.values())
LEVELS_G = (0.1, 0.8)  # stripe levels of PGA [g]: the lower stands, the upper overturns
BLOCKS = {"half_diagonal": [0.5, 1.0], "slenderness": [0.2, 0.2]}
RTOL = 1e-8


def write_csv(path, record):
    """A record file of ``record``: time [s] and acceleration [g], at full precision."""
    t = np.arange(record.acceleration.size) * record.dt
    np.savetxt(path, np.column_stack([t, record.acceleration / STANDARD_GRAVITY]), "%.17g", ",")


@pytest.fixture(scope="module")
def record():
    return synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=3, duration=4.0)


def _study_text(kind, folder) -> str:
    """A study of ``kind`` made from its entry: levels on a grid where the kind has them, the
    IDA's options (coarse, to be quick) where it gives capacities."""
    scale_to = (
        f'scale_to = {{ im = "pga", units = "g", value = {{ dist = "grid", values = '
        f"{list(LEVELS_G)} }} }}\n"
        if kind.levels
        else ""
    )
    options = "step = 0.05\ntolerance = 0.02\nscan = 2\n" if kind.capacities else ""
    return (
        'name = "registry"\nseed = 1\n[sampler]\nkind = "lhs"\nn = 2\n'
        '[structure]\nkind = "block"\n'
        'half_diagonal = { dist = "uniform", low = 0.4, high = 1.2 }\n'
        'slenderness = { dist = "uniform", low = 0.15, high = 0.25 }\n'
        f'[motion]\nkind = "record"\nfiles = "{folder}/*.csv"\n{scale_to}'
        f'[design]\nkind = "{kind.name}"\n{options}'
        '[run]\noutputs = ["max_rotation", "overturned"]\n'
    )


def _api(kind, record, structures):
    """The kind's design function (its entry's ``run``) on one record, with the arguments
    its declarations call for."""
    kw = {"rtol": RTOL}
    if kind.levels:
        kw["levels"] = np.array(LEVELS_G) * STANDARD_GRAVITY
    if kind.capacities:
        kw.update(step=0.05, tolerance=0.02, scan=2)
    return getattr(rd, kind.run)([record], structures, **kw)


def _check_points(ds, kind, record, blocks):
    """Each point's outcome against a single simulation of the record scaled as stored."""
    for j, block in enumerate(blocks):
        if kind.capacities:
            cap = float(ds["capacity_scale"].values[0, j])
            low = float(ds["capacity_scale_lower"].values[0, j])
            if np.isfinite(cap):
                assert rs.simulate(block, record.scaled(cap), rtol=RTOL).overturned
            assert not rs.simulate(block, record.scaled(low), rtol=RTOL).overturned
            continue
        over = ds["overturned"].isel(record=0, structure=j)
        scales = ds["scale"].isel(record=0, structure=j) if kind.levels else xr_ones(over)
        for s, o in zip(np.ravel(scales.values), np.ravel(over.values), strict=True):
            assert bool(o) == rs.simulate(block, record.scaled(float(s)), rtol=RTOL).overturned


def xr_ones(like):
    return like.copy(data=np.ones(like.shape))


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_each_kind_is_accepted_by_the_schema_and_makes_its_rows(kind, record, tmp_path):
    write_csv(tmp_path / "nf.csv", record)
    study = validate_text(_study_text(kind, tmp_path), base_dir=tmp_path)
    assert study.design.kind == kind.name
    assert study.levels() == (len(LEVELS_G) if kind.levels else 1)
    outputs = record_rows.outputs(study)
    assert ("capacity" in outputs) == kind.capacities
    assert ("overturned" in outputs) == (not kind.capacities)
    assert ("scale" in outputs) == kind.levels
    design = make_design(study, tmp_path)
    cols = {k: design[k].values for k in design.data_vars} | {"sample": design["sample"].values}
    rows = record_rows.evaluate_rows(study, cols, tmp_path)
    for k in range(design.sizes["sample"]):  # every row against a simulation
        block = rs.Block(
            half_diagonal=float(design["half_diagonal"].values[k]),
            slenderness=float(design["slenderness"].values[k]),
        )
        if kind.capacities:
            cap = rows["capacity_scale"][k]
            if np.isfinite(cap):
                assert rs.simulate(block, record.scaled(cap), rtol=RTOL).overturned
            low = rows["capacity_scale_lower"][k]
            assert not rs.simulate(block, record.scaled(low), rtol=RTOL).overturned
        else:
            scale = rows["scale"][k] if kind.levels else 1.0
            sim = rs.simulate(block, record.scaled(scale), rtol=RTOL)
            assert rows["overturned"][k] == sim.overturned


def test_the_schema_refuses_a_kind_not_registered_and_names_the_registered_ones(tmp_path):
    text = _study_text(KINDS[0], tmp_path).replace(f'kind = "{KINDS[0].name}"', 'kind = "nope"')
    write_csv(tmp_path / "nf.csv", synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=1))
    with pytest.raises(StudyError) as err:
        validate_text(text, base_dir=tmp_path)
    assert "design.kind" in str(err.value)
    assert all(repr(k.name) in str(err.value) for k in KINDS)


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_each_kind_drives_the_fits_the_rates_and_the_report(kind, record, tmp_path):
    pairs = zip(BLOCKS["half_diagonal"], BLOCKS["slenderness"], strict=True)
    blocks = [rs.Block(half_diagonal=r, slenderness=a) for r, a in pairs]
    ds = _api(kind, record, dict(BLOCKS))
    assert kind_of(ds) is kind
    assert ("level" in ds.dims) == kind.levels
    assert ("capacity" in ds) == kind.capacities
    if not kind.scaled:
        assert "scale" not in ds and "capacity_scale" not in ds
    _check_points(ds, kind, record, blocks)
    fit = rf.fragility_of(ds)
    assert fit is getattr(rf, kind.fragility)
    table = fit(ds, n_boot=0)
    assert len(table) == 1 and table["n"].iloc[0] > 0
    for other in {k.fragility for k in KINDS} - {kind.fragility}:  # the others refuse it
        with pytest.raises(ValueError, match=f"ds: {other} needs a dataset of design"):
            getattr(rf, other)(ds, n_boot=0)
    hazard = risk.HazardCurve.power_law(1e-4, 2.5, im="pga", units="g")
    rates = object_risk(ds, hazard, n_boot=0)
    assert rates.attrs["design"] == kind.name and rates.sizes["structure"] == 2
    page = record_report(ds, tmp_path / "r", n_boot=0).read_text()
    headings = re.findall(r"<h2[^>]*>([^<]*)</h2>", page)
    assert kind.text["heading"] in headings
    for section in kind.sections:
        assert section in headings
    for other in {s for k in KINDS for s in k.sections} - set(kind.sections):
        assert other not in headings


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_every_function_an_entry_names_exists_in_its_layer(kind):
    assert callable(getattr(rd, kind.run))
    assert callable(getattr(rf, kind.fragility))
    assert callable(getattr(analysis_risk, kind.risk_fitter))
    assert callable(getattr(ro, kind.capacity))
    assert callable(getattr(ro, kind.draw))
    assert design_kind(kind.name) is kind


def test_an_unknown_kind_is_refused_with_the_registered_ones():
    with pytest.raises(ValueError, match="design kind must be one of") as err:
        design_kind("nope")
    assert all(repr(k) in str(err.value) for k in DESIGN_KINDS)
    ds = _api(KINDS[0], synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=1), dict(BLOCKS))
    ds.attrs["design"] = "nope"
    for use in (rf.fragility_of, kind_of):
        with pytest.raises(ValueError, match=r"attrs\['design'\] must be one of"):
            use(ds)
