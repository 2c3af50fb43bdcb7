"""Two-body objects in studies: ``kind = "stacked"`` (a statue on a plinth that can rock) and
``kind = "isolated"`` (a block on a base isolator) in ``[structure] kind = "objects"``, through
the record designs, the cube and the report.

Oracles: :func:`rockstudy.simulate_batch` with ``structure=`` on the same scenes (the study's
plumbing, not the physics); the block object of the same statue for a plinth that cannot move
(the statue then rocks as Housner's block on rigid ground); the moment balance of the pair at
rest written here for its uplift; Cornell's closed form of the annual rate under a power-law
hazard, lambda = k0 theta^-k exp(k^2 beta^2 / 2), whose ratio for capacities all c times
another object's is c^-k for every resample of the records.
"""

import json
import math

import numpy as np
import pandas as pd
import pytest
from _helpers import (
    K0,
    K,
    lognormal_sample,
    pga_ida,
    unit_sine_record,
    write_at2,
    write_two_records,
)

from rockstudy import simulate_batch
from rockstudy.constants import G
from rockstudy.motions import Record
from rockstudy.risk import HazardCurve
from rockstudy.structures import Block, IsolatedBlock, StackedBlocks
from rockstudy.study import load_study, run_study
from rockstudy.study.report import make_report
from rockstudy.study.running.store import open_result
from rockstudy.study.spec.schema import ObjectSpec, ObjectsSpec, StudyError, validate_text

STATUE = (0.4, 1.6)  # width, height [m]

MUSEUM = """
name = "museum plinths"
seed = 1
[structure]
kind = "objects"
[[structure.objects]]
name = "Statue"
width = 0.4
height = 1.6
[[structure.objects]]
name = "Statue on plinth"
kind = "stacked"
width = 0.4
height = 1.6
plinth_width = 0.8
plinth_height = 1.0
compare_to = "Statue"
[[structure.objects]]
name = "Statue isolated"
kind = "isolated"
width = 0.4
height = 1.6
period = 2.0
damping = 0.1
base_mass_ratio = 1.0
isolator_capacity = {capacity}
compare_to = "Statue"
[motion]
kind = "record"
files = ["r0.AT2", "r1.AT2"]
[design]
kind = "cloud"
[hazard]
kind = "power_law"
im = "pga"
units = "g"
k0 = 1e-4
k = 2.5
"""

CAPACITY = 0.02  # [m]


def _text(page):
    return page.read_text() if hasattr(page, "read_text") else open(page).read()


@pytest.fixture(scope="module")
def museum(tmp_path_factory, client):
    """The museum study (two generated records, a statue alone, on its plinth and on an
    isolator) validated, run and reported once."""
    folder = write_two_records(tmp_path_factory.mktemp("museum"))
    path = folder / "museum.toml"
    path.write_text(MUSEUM.format(capacity=CAPACITY))
    study = load_study(path)
    out = folder / "cube.zarr"
    run_study(study, out, client=client, base_dir=folder, progress=False)
    page = make_report(out, folder / "report")
    return study, folder, open_result(out).load(), _text(page)


def _structures():
    statue = Block.from_dimensions(*STATUE)
    plinth = StackedBlocks(Block.from_dimensions(0.8, 1.0), statue)
    isolator = IsolatedBlock(statue, 1.0, 2.0, 0.1, CAPACITY)
    return statue, plinth, isolator


def test_the_cube_holds_what_simulate_batch_gives_on_the_same_scenes(museum):
    study, folder, cube, _ = museum
    _, plinth, isolator = _structures()
    for i, name in enumerate(("r0", "r1")):
        rec = Record.from_at2(folder / f"{name}.AT2")
        at = cube.isel(record=i)
        kw = dict(record=rec, scale=1.0, rtol=study.run.rtol, max_steps=study.run.max_steps)
        stacked = simulate_batch(structure=plinth, **kw)
        one = at.sel(structure="Statue on plinth")
        for k in ("max_rotation_lower", "max_rotation_upper", "overturned_body", "overturned"):
            np.testing.assert_allclose(float(one[k]), float(stacked[k][0]), rtol=1e-12)
        isolated = simulate_batch(structure=isolator, **kw)
        one = at.sel(structure="Statue isolated")
        for k in ("max_rotation", "max_isolator_displacement", "overturned"):
            np.testing.assert_allclose(float(one[k]), float(isolated[k][0]), rtol=1e-12)
        # outputs an object has not: NaN, and -1 for the body of an object without a plinth
        block = at.sel(structure="Statue")
        assert np.isnan(block["max_rotation_lower"]) and np.isnan(block["max_rotation_upper"])
        assert np.isnan(block["max_isolator_displacement"]) and int(block["overturned_body"]) == -1
        assert np.isnan(at.sel(structure="Statue on plinth")["max_isolator_displacement"])
        assert int(at.sel(structure="Statue isolated")["overturned_body"]) == -1
    assert (cube["status"] == 0).all()


def test_the_report_tables_the_outputs_and_warns_of_the_isolator_capacity(museum):
    study, folder, cube, text = museum
    _, _, isolator = _structures()
    over = []
    for name in ("r0", "r1"):
        rec = Record.from_at2(folder / f"{name}.AT2")
        u = simulate_batch(structure=isolator, record=rec, rtol=study.run.rtol)
        if u["max_isolator_displacement"][0] > CAPACITY:
            over.append(name)
    assert over  # the capacity is small enough that some scene exceeds it
    words = f"Statue isolated: {len(over)} of 2 scenes exceed its isolator capacity 0.02 m"
    assert words in text
    for name in over:
        assert f"{name} (1)" in text
    table = pd.read_csv(folder / "report" / "two_body_outputs.csv", index_col=0)
    assert set(table.index) == {"Statue on plinth", "Statue isolated"}
    largest = cube["max_isolator_displacement"].sel(structure="Statue isolated").max()
    assert table.loc["Statue isolated", "largest isolator displacement [m]"] == pytest.approx(
        float(largest), rel=1e-12
    )
    pairs = pd.read_csv(folder / "report" / "plinth_isolator_ratio.csv", index_col=0)
    assert list(pairs.index) == ["Statue on plinth", "Statue isolated"]
    assert (pairs["plain twin"] == "Statue").all()
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = pairs["lambda_OT [1/yr]"] / pairs["lambda_OT of the plain twin [1/yr]"]
    np.testing.assert_allclose(pairs["ratio"], ratio, rtol=1e-12)


def test_the_pairing_ratio_is_that_of_the_rates_with_its_band_from_the_same_resamples(tmp_path):
    """Capacities all c times the statue's: every resample's ratio of Cornell rates is c^-k;
    and the isolator's warning counts the scenes beyond its capacity, by record."""
    from rockstudy.study.report._page import _Page
    from rockstudy.study.report.objects import ReportContext
    from rockstudy.study.report.two_body import section

    plain = lognormal_sample(0.3, 0.4, 8, seed=4)
    c = 1.7
    ds = pga_ida(np.c_[plain, c * plain], names=["Statue", "Statue isolated"])
    ds = ds.assign_coords(record=[f"rec {i}" for i in range(8)])
    shift = np.zeros((8, 2)) * np.nan
    shift[:, 1] = np.linspace(0.01, 0.08, 8)  # 3 of 8 beyond 0.055 m
    ds["max_isolator_displacement"] = (("record", "structure"), shift)
    objects = [
        {"name": "Statue"},
        {"name": "Statue isolated", "compare_to": "Statue", "isolator_capacity": 0.055},
    ]
    ds.attrs["study"] = json.dumps({"structure": {"kind": "objects", "objects": objects}})
    page = _Page(tmp_path)
    ctx = ReportContext(ds, n_boot=40)
    ctx.hazard = HazardCurve.power_law(K0, K, im="pga", units="g")
    section(page, ctx)
    row = pd.read_csv(tmp_path / "plinth_isolator_ratio.csv", index_col=0).iloc[0]
    for column in ("ratio", "ratio, 5 %", "ratio, 95 %"):
        assert row[column] == pytest.approx(c**-K, rel=1e-9)
    assert row["resamples"] == 40
    rates = row["lambda_OT [1/yr]"], row["lambda_OT of the plain twin [1/yr]"]
    assert row["ratio"] == pytest.approx(rates[0] / rates[1], rel=1e-12)
    text = "".join(page.parts)
    assert "Statue isolated: 3 of 8 scenes exceed its isolator capacity 0.055 m" in text
    assert "under rec 5 (1), rec 6 (1), rec 7 (1)" in text


def _sine_records(folder):
    """Two one-cycle sine pulses (overturning monotone in their scale) as AT2 files."""
    for i, ratio in enumerate((2.0, 3.0)):
        rec = unit_sine_record(ratio, half_diagonal=math.hypot(0.1, 0.4))
        write_at2(folder / f"s{i}.AT2", Record(3.0 * rec.acceleration, dt=rec.dt))
    return folder


RIGID_PLINTH = """
name = "rigid plinth"
seed = 1
[structure]
kind = "objects"
[[structure.objects]]
name = "Statue"
width = 0.2
height = 0.8
[[structure.objects]]
name = "Statue on a rigid plinth"
kind = "stacked"
width = 0.2
height = 0.8
plinth_width = 1.4
plinth_height = 1.0
density_ratio = 1e-3
compare_to = "Statue"
[motion]
kind = "record"
files = ["s0.AT2", "s1.AT2"]
[design]
kind = "ida"
step = 0.5
tolerance = 0.2
max_pga_ratio = 8
scan = 0
"""


@pytest.mark.slow  # the pair's scenes run the solve_ivp reference (about 100 s)
def test_a_plinth_that_cannot_move_gives_the_capacities_of_the_statue_alone(client, tmp_path):
    """A plinth as wide as it may be (Housner's restitution > 0) and a thousand times denser
    than the statue tips only near 1.4 g, above the statue's capacities: the statue on it is
    Housner's block on rigid ground, so its IDA capacities are the block object's (the same
    ladder: the pair lifts first at the statue's own g tan(alpha))."""
    folder = _sine_records(tmp_path)
    (folder / "rigid.toml").write_text(RIGID_PLINTH)
    study = load_study(folder / "rigid.toml")
    run_study(study, folder / "cube.zarr", client=client, base_dir=folder, progress=False)
    cube = open_result(folder / "cube.zarr").load()
    block, stacked = (cube.sel(structure=n) for n in ("Statue", "Statue on a rigid plinth"))
    assert not block["censored"].any()  # both records overturn the statue
    assert (block["capacity"] < G * _pair_uplift(1.4, 1.0, 0.2, 0.8, 1e-3)).all()  # m/s^2
    for k in ("capacity", "capacity_scale", "capacity_scale_lower"):
        np.testing.assert_allclose(stacked[k], block[k], rtol=1e-9)
    assert (stacked["overturned_body"] == 2).all()  # the statue, never the plinth
    assert (stacked["max_rotation_lower"] == 0).all()
    plinth = StackedBlocks(
        Block.from_dimensions(1.4, 1.0), Block.from_dimensions(0.2, 0.8), density_ratio=1e-3
    )
    for i in range(2):  # the stored rotation is the scene's at capacity_scale_lower
        rec = Record.from_at2(folder / f"s{i}.AT2")
        s = float(stacked["capacity_scale_lower"][i])
        run = simulate_batch(structure=plinth, record=rec, scale=s, rtol=study.run.rtol)
        assert float(stacked["max_rotation_upper"][i]) == pytest.approx(
            float(run["max_rotation_upper"][0]), rel=1e-12
        )
        assert not run["overturned"][0]


def _pair_uplift(wl, hl, wu, hu, rho):
    """The acceleration ratio a / g that tips a stacked pair at rest about a plinth corner:
    the composite centre of mass's horizontal arm over its height (masses from the areas)."""
    ml, mu = wl * hl, rho * wu * hu
    y = (ml * hl / 2 + mu * (hl + hu / 2)) / (ml + mu)
    return (wl / 2) / y


@pytest.mark.parametrize(
    "plinth, statue_first",
    [((0.8, 1.0), True), ((0.5, 2.0), False)],  # a squat plinth; a tall slender one
)
def test_a_stacked_object_in_a_design_lifts_at_the_first_of_its_two_uplifts(plinth, statue_first):
    statue = (0.4, 0.8)
    spec = ObjectsSpec(
        kind="objects",
        objects=[
            ObjectSpec(
                name="S",
                kind="stacked",
                width=statue[0],
                height=statue[1],
                plinth_width=plinth[0],
                plinth_height=plinth[1],
            )
        ],
    )
    own = statue[0] / statue[1]  # b / h of the statue on a resting plinth
    pair = _pair_uplift(*plinth, *statue, 1.0)
    assert (own < pair) == statue_first
    assert spec.uplift()[0] == pytest.approx(G * min(own, pair), rel=1e-12)
    p, theta_cr, eta = spec.rocking()[0]
    R = math.hypot(*statue) / 2
    assert p == pytest.approx(math.sqrt(0.75 * G / R), rel=1e-12)
    assert theta_cr == pytest.approx(math.atan(min(own, pair)), rel=1e-12)
    assert eta == pytest.approx(1 - 1.5 * math.sin(math.atan(own)) ** 2, rel=1e-12)


def test_an_isolated_object_lifts_at_its_blocks_uplift():
    spec = ObjectsSpec(
        kind="objects",
        objects=[
            ObjectSpec(
                name="I", kind="isolated", width=0.4, height=1.6, period=2.0, damping=0.1,
                base_mass_ratio=1.0,
            )
        ],
    )  # fmt: skip
    assert spec.uplift()[0] == pytest.approx(G * 0.25, rel=1e-12)
    assert spec.rocking()[0][1] == pytest.approx(math.atan(0.25), rel=1e-12)


def test_an_objects_file_takes_the_two_body_kinds_and_compare_to(tmp_path):
    write_two_records(tmp_path)
    (tmp_path / "objects.csv").write_text(
        "name,kind,width,height,plinth_width,plinth_height,compare_to\n"
        "Statue,block,0.4,1.6,,,\n"
        "Statue on plinth,stacked,0.4,1.6,0.8,1.0,Statue\n"
    )
    text = MUSEUM.split("[structure]")[0] + (
        '[structure]\nkind = "objects"\nfile = "objects.csv"\n'
        '[motion]\nkind = "record"\nfiles = ["r0.AT2"]\n[design]\nkind = "cloud"\n'
    )
    study = validate_text(text, base_dir=tmp_path)
    assert study.structure.pairs() == [("Statue on plinth", "Statue")]
    assert isinstance(study.structure.two_body()[1], StackedBlocks)


_BASE = """
name = "bad"
seed = 1
{top}
[structure]
kind = "objects"
objects = [
  {{ name = "Statue", width = 0.4, height = 1.6 }},
  {{ name = "Statue on plinth", kind = "stacked", width = {width}, height = 1.6, {stacked} }},
]
[motion]
kind = "record"
files = {files}
[design]
kind = "cloud"
{run}
"""
_PLINTH = "plinth_width = 0.8, plinth_height = 1.0"


@pytest.mark.parametrize(
    "change, field",
    [
        (dict(stacked="plinth_width = 0.8"), "plinth_height"),
        (dict(stacked="plinth_width = 0.8, plinth_height = -1.0"), "plinth_height"),
        (dict(stacked=_PLINTH + ", density_ratio = 0"), "density_ratio"),
        (dict(stacked=_PLINTH + ", offset = 0.5"), "offset"),
        (dict(stacked=_PLINTH + ", period = 2.0"), "period"),
        (dict(stacked=_PLINTH + ', compare_to = "Vase"'), "compare_to"),
        (dict(stacked=_PLINTH + ', compare_to = "Statue"', width=0.3), "compare_to"),
        (dict(run='[run]\nmodel = "contact"', top="friction = 0.5"), "run.model"),
        (dict(run='[run]\nmethod = "linear"'), "run.method"),
        (dict(top="friction = 0.5"), "friction"),
        (dict(files='[{ horizontal = "r0.AT2", vertical = "r1.AT2" }]'), "motion.vertical"),
    ],
)
def test_bad_input_is_refused_naming_the_field(tmp_path, change, field):
    write_two_records(tmp_path)
    values = dict(top="", stacked=_PLINTH, files='["r0.AT2"]', run="", width=0.4)
    values.update(change)  # (width: the statue of the stacked object)
    text = _BASE.format(**values)
    with pytest.raises(StudyError) as err:
        validate_text(text, base_dir=tmp_path)
    assert field in str(err.value)
    assert "Traceback" not in str(err.value)


def test_compare_to_on_a_block_and_two_body_kinds_sampled_are_refused(tmp_path):
    write_two_records(tmp_path)
    values = dict(top="", stacked=_PLINTH, files='["r0.AT2"]', run="", width=0.4)
    text = _BASE.format(**values).replace(
        '{ name = "Statue", width = 0.4, height = 1.6 }',
        '{ name = "Statue", width = 0.4, height = 1.6, compare_to = "Statue on plinth" }',
    )
    with pytest.raises(StudyError, match="compare_to"):
        validate_text(text, base_dir=tmp_path)
    sampled = (
        'name = "bad"\nseed = 1\n[sampler]\nkind = "lhs"\nn = 4\n[structure]\n'
        'kind = "stacked"\nwidth = 0.4\nheight = 1.6\n[motion]\nkind = "record"\n'
        'files = ["r0.AT2"]\n[design]\nkind = "cloud"\n'
    )
    with pytest.raises(StudyError, match="structure.kind"):
        validate_text(sampled, base_dir=tmp_path)


def test_stripes_run_the_isolated_object_at_each_scale_as_simulate_batch_does():
    """The design's ``two_body`` column (as a study passes it): each stripe point of the
    isolated object is simulate_batch(structure=) at the point's scale; the block beside it
    keeps its own path and the two-body fills."""
    from rockstudy.study.designs.records import multiple_stripes
    from rockstudy.study.spec.structures import two_body_parameters

    statue, _, isolator = _structures()
    rec = unit_sine_record(2.0, half_diagonal=statue.half_diagonal)
    rows = [
        (statue.frequency_parameter, statue.slenderness, statue.restitution, G * 0.25),
        two_body_parameters(isolator),
    ]
    p, theta, eta, a_up = np.array(rows).T
    structures = dict(
        frequency_parameter=p,
        critical_rotation=theta,
        restitution=eta,
        uplift_acceleration=a_up,
        two_body=[None, isolator],
    )
    ds = multiple_stripes([rec], structures, levels=[1.0, 3.0], im="pga")
    scales = ds["scale"].isel(record=0, structure=1).values
    run = simulate_batch(structure=isolator, record=rec, scale=scales, rtol=1e-8)
    at = ds.isel(record=0, structure=1)
    for k in ("max_rotation", "max_isolator_displacement", "overturned"):
        np.testing.assert_allclose(at[k].values.astype(float), run[k].astype(float), rtol=1e-12)
    block = ds.isel(record=0, structure=0)
    assert np.isnan(block["max_isolator_displacement"]).all()
    expected = simulate_batch(
        frequency_parameter=p[0],
        critical_rotation=theta[0],
        restitution=eta[0],
        record=rec,
        scale=ds["scale"].isel(record=0, structure=0).values,
    )
    np.testing.assert_allclose(block["max_rotation"], expected["max_rotation"], rtol=1e-12)
