"""Record suites in study files: designs on the runner and store, scale targets, bad input.

The oracle of a design study is the Python design function of :mod:`records_designs` called
directly on the suite read by :func:`load_suite` (the study goes through spec -> design rows ->
dask tasks -> zarr store -> folding; the function through none of them).
"""

import html
import math
import shutil

import numpy as np
import pytest
import scipy.signal
from _helpers import (
    RECORD_STUDY_HEAD as HEAD,
)
from _helpers import (
    chromium_figures,
    rows_study,
    run_rows,
    write_at2,
    write_near_fault_pairs,
)

import rockstudy as rs
from rockstudy import simulate_batch
from rockstudy.constants import STANDARD_GRAVITY, G
from rockstudy.motions import Record, load_suite
from rockstudy.study import StudyError, load_study, run_study
from rockstudy.study.designs import records as rd
from rockstudy.study.designs.sampling import make_design
from rockstudy.study.running.evaluate import STATUS_OK
from rockstudy.study.running.store import open_result


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    """A folder of three synthetic near-fault records: horizontal and vertical .AT2 files."""
    return write_near_fault_pairs(tmp_path_factory.mktemp("records"))


MOTION = """
[motion]
kind = "record"
files = "RECORDS/*_H.AT2"
"""
HV = """
[motion]
kind = "record"
files = "RECORDS"
vertical = { match = '_H\\.AT2$', replace = "_UP.AT2" }
"""

DESIGNS = {
    "cloud": '[design]\nkind = "cloud"\nperiods = [0.3, 1.0]\n',
    "stripes": (
        'scale_to = { im = "sa", period = 0.5, value = { dist = "grid", values = [2.0, 6.0] } }\n'
        '[design]\nkind = "stripes"\nperiods = [1.0]\n'
    ),
    "ida": '[design]\nkind = "ida"\nim = "pgv"\ntolerance = 0.02\nscan = 2\n',
}


def design_study(folder, kind, where, motion=MOTION):
    text = HEAD + motion.replace("RECORDS", str(folder)) + DESIGNS[kind]
    text += '[run]\noutputs = ["max_rotation", "overturned"]\n'
    path = where / f"{kind}.toml"
    path.write_text(text)
    return load_study(path)


def python_api(kind, records, cube):
    structures = {
        "half_diagonal": cube["half_diagonal"].values,
        "slenderness": cube["slenderness"].values,
    }
    if kind == "cloud":
        return rd.cloud(records, structures, periods=[0.3, 1.0])
    if kind == "stripes":
        return rd.multiple_stripes(
            records, structures, [2.0, 6.0], im="sa", period=0.5, periods=[1.0]
        )
    return rd.incremental_dynamic_analysis(records, structures, im="pgv", tolerance=0.02, scan=2)


@pytest.mark.parametrize("kind", ["cloud", "stripes", "ida"])
def test_design_study_cube_equals_the_python_design(suite, client, tmp_path, kind):
    study = design_study(suite, kind, tmp_path)
    out = tmp_path / "cube.zarr"
    report = run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    assert report.failed_samples == 0 and report.chunks_total == 3  # one record per chunk
    cube = open_result(out).load()
    records = load_suite(str(suite / "*_H.AT2"))
    api = python_api(kind, records, cube)
    assert dict(cube.sizes) == dict(api.sizes)
    assert list(cube["record_name"].values) == [r.name for r in records]
    for name, var in api.variables.items():
        if var.dtype.kind in "OU":
            continue
        got = cube[name]
        assert got.dims == var.dims, name
        np.testing.assert_allclose(
            np.asarray(got.values, float),
            np.asarray(var.values, float),
            rtol=1e-12,
            atol=0,
            equal_nan=True,
            err_msg=name,
        )
    for key in ("design", "im", "im_period", "n_simulations", "damping", "tolerance"):
        if key in api.attrs:
            np.testing.assert_equal(cube.attrs[key], api.attrs[key], err_msg=key)
    assert np.all(cube["run_status"].values == STATUS_OK)
    nc = open_result(out.with_suffix(".nc")).load()  # the export has the same layout
    assert dict(nc.sizes) == {d: n for d, n in api.sizes.items() if n}  # netCDF3: no empty dims
    for name in ("max_rotation", "capacity", "scale"):
        if name in api:
            np.testing.assert_allclose(nc[name], api[name], rtol=1e-12, equal_nan=True)


def test_design_study_ida_capacity_against_an_independent_dense_scan(suite, client, tmp_path):
    """The study's IDA capacities, checked against a dense scan of 1500 log-spaced levels
    per record and block (simulate_batch on each record read afresh): the capacity overturns,
    the scale below it survives, and every dense level below it that overturns lies in a
    window narrower than the ladder step (the dense scan survives within one step above it)."""
    study = design_study(suite, "ida", tmp_path)
    out = tmp_path / "cube.zarr"
    run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    cube = open_result(out).load()
    q = 1.0 + cube.attrs["step"]
    checked = narrow = 0
    for i, rec in enumerate(load_suite(str(suite / "*_H.AT2"))):
        for j in range(cube.sizes["structure"]):
            R, a = float(cube["half_diagonal"][j]), float(cube["slenderness"][j])
            grid = np.geomspace(0.5 * G * a / rec.peak, 30 * G * np.tan(a) / rec.peak, 1500)
            over = simulate_batch(half_diagonal=R, slenderness=a, record=rec, scale=grid)[
                "overturned"
            ]
            c, lo = float(cube["capacity_scale"][i, j]), float(cube["capacity_scale_lower"][i, j])
            if np.isfinite(c):
                ends = simulate_batch(half_diagonal=R, slenderness=a, record=rec, scale=[lo, c])
                assert list(ends["overturned"]) == [False, True]
            else:  # censored: it stood on every rung, the top one included
                assert bool(cube["censored"][i, j]) and lo == pytest.approx(grid[-1], rel=1e-9)
            for k in np.flatnonzero(over & (grid < lo)):
                step_above = (grid > grid[k]) & (grid <= grid[k] * q)
                assert (~over[step_above]).any(), (i, j, grid[k], c)
                narrow += 1
            checked += 1
    print(f"IDA study vs dense scan: {checked} pairs, {narrow} narrow levels below the capacity")
    assert checked == 9


def test_hv_pairs_run_with_their_vertical_or_are_refused_before_the_run(suite, client, tmp_path):
    """A folder of H/V pairs: each record is read with its vertical file; if the solvers take
    vertical shaking the cube equals the Python design on the same pairs, else the study is
    refused by validation (never run without its vertical)."""
    from rockstudy.study.spec.feasibility import vertical_refusal

    if vertical_refusal() is not None:
        with pytest.raises(StudyError, match="motion.vertical"):
            design_study(suite, "cloud", tmp_path, HV)
        return
    study = design_study(suite, "cloud", tmp_path, HV)
    out = tmp_path / "cube.zarr"
    run_study(study, out, client=client, base_dir=tmp_path, progress=False, netcdf=False)
    cube = open_result(out).load()
    records = load_suite(suite, vertical=(r"_H\.AT2$", "_UP.AT2"))
    assert all(r.vertical is not None for r in records) and len(records) == 3
    api = python_api("cloud", records, cube)
    np.testing.assert_allclose(cube["max_rotation"], api["max_rotation"], rtol=1e-12)
    assert cube["vertical_component"].values.all() and api["vertical_component"].values.all()


def test_stripes_levels_at_free_fall_are_stored_censored_and_the_others_run(
    suite, client, tmp_path
):
    """H/V pairs scaled to PGA levels on both sides of each record's free-fall level (where
    the scaled vertical reaches -g): those above are stored as censored (kernel_status 2), the
    others run and equal single-scene simulations; the record's task does not fail."""
    records = load_suite(suite, vertical=(r"_H\.AT2$", "_UP.AT2"))
    falls = [rd.free_fall_scale(r) * r.peak for r in records]  # PGA [m/s^2] at free fall
    levels = [0.5 * min(falls), 0.9 * min(falls), 1.5 * max(falls)]
    grid = ", ".join(f"{v!r}" for v in levels)
    text = HEAD + HV.replace("RECORDS", str(suite))
    text += f'scale_to = {{ im = "pga", value = {{ dist = "grid", values = [{grid}] }} }}\n'
    text += '[design]\nkind = "stripes"\n[run]\noutputs = ["max_rotation", "overturned"]\n'
    path = tmp_path / "falls.toml"
    path.write_text(text)
    out = tmp_path / "cube.zarr"
    report = run_study(load_study(path), out, client=client, base_dir=tmp_path, progress=False)
    assert report.failed_samples == 0
    cube = open_result(out).load()
    censored = cube["censored"].values
    assert censored[..., 2].all() and not censored[..., :2].any()
    assert (cube["status"].values[..., 2] == 2).all()
    assert np.all(cube["run_status"].values == STATUS_OK)
    for i, rec in enumerate(records):
        b = rs.Block(float(cube["half_diagonal"][0]), float(cube["slenderness"][0]))
        one = rs.simulate(b, rec.scaled(float(cube["scale"][i, 0, 1])))
        assert bool(cube["overturned"][i, 0, 1]) == one.overturned


def test_validate_notes_the_levels_that_free_fall_censors(suite, tmp_path):
    """validate says, before the run, which records' verticals reach free fall at a level of
    the design (the free-fall scale computed here from the samples: g / max(-u_v''))."""
    records = load_suite(suite, vertical=(r"_H\.AT2$", "_UP.AT2"))
    falls = [G / -float(np.min(r.vertical)) * r.peak for r in records]  # PGA at free fall
    for levels, expected in (([0.5 * min(falls), 0.9 * min(falls)], 0), ([1.5 * max(falls)], 3)):
        grid = ", ".join(f"{v!r}" for v in levels)
        text = HEAD + HV.replace("RECORDS", str(suite))
        text += f'scale_to = {{ im = "pga", value = {{ dist = "grid", values = [{grid}] }} }}\n'
        text += '[design]\nkind = "stripes"\n'
        path = tmp_path / f"notes{expected}.toml"
        path.write_text(text)
        notes = [n for n in load_study(path).notes if "free fall" in n]
        assert len(notes) == expected, notes
        assert all("free fall" in n and "censored" in n and "_UP.AT2" in n for n in notes)


def test_an_interrupted_design_study_resumes_at_the_records_not_done(suite, client, tmp_path):
    import zarr

    study = design_study(suite, "stripes", tmp_path)
    out = tmp_path / "cube.zarr"
    run_study(study, out, client=client, base_dir=tmp_path, progress=False, netcdf=False)
    full = open_result(out).load()
    group = zarr.open_group(str(out), mode="r+", zarr_format=2)
    rows = group["status"].shape[0] // 3
    group["status"][rows : 2 * rows] = 0  # record 1 as a killed run leaves it: pending
    group["max_rotation"][rows : 2 * rows] = np.nan
    report = run_study(
        study, out, client=client, base_dir=tmp_path, progress=False, netcdf=False, resume=True
    )
    assert report.chunks_computed == [(rows, 2 * rows)]
    again = open_result(out).load()
    np.testing.assert_array_equal(again["max_rotation"].values, full["max_rotation"].values)
    assert np.isfinite(again["max_rotation"].values).all()


def test_a_record_that_fails_in_its_task_fails_its_rows_and_is_counted(suite, client, tmp_path):
    """A record spoiled after validation: its task fails, its rows are marked failed with the
    reader's message (naming the file), the other records are kept, and the run raises
    FailedSamplesError (max_failed is 0 by default)."""
    from rockstudy.study.running.runner import FailedSamplesError

    folder = tmp_path / "records"
    folder.mkdir()
    for f in sorted(suite.glob("*_H.AT2")):
        shutil.copy(f, folder / f.name)
    study = design_study(folder, "cloud", tmp_path)
    (folder / "nf1_H.AT2").write_text("PEER\nspoiled\nUNITS OF G\nNPTS= 9, DT= 0.01 SEC\n1 2\n")
    out = tmp_path / "cube.zarr"
    with pytest.raises(FailedSamplesError) as info:
        run_study(study, out, client=client, base_dir=tmp_path, progress=False, netcdf=False)
    assert info.value.report.failed_samples == 3  # the record's three structures
    assert any("nf1_H.AT2" in m for m in info.value.report.errors)
    cube = open_result(out).load()
    np.testing.assert_array_equal(cube["run_status"].values[:, 0], [1, 2, 1])
    assert np.isnan(cube["max_rotation"].values[1]).all()
    assert np.isfinite(cube["max_rotation"].values[[0, 2]]).all()


# ---------------------------------------------------------------- Monte Carlo rows, targets


def test_rows_scaled_to_sa_reach_it_by_an_independent_oscillator(suite, tmp_path):
    """scale_to = Sa(0.5 s) of a distribution: each sample's record, scaled by the factor the
    run applied, has that Sa, by scipy's exact solution of the oscillator (lsim)."""
    study = rows_study(
        suite,
        tmp_path,
        'scale_to = { im = "sa", period = 0.5, value = { dist = "uniform", low = 2, high = 8 } }',
    )
    design, out = run_rows(study, tmp_path)
    files = sorted(suite.glob("*_H.AT2"))
    w, zeta = 2.0 * np.pi / 0.5, 0.05
    system = scipy.signal.lti([-1.0], [1.0, 2.0 * zeta * w, w * w])
    for i in range(3):
        rec = Record.from_at2(files[design["record"].values[i]])
        t = rec.dt * np.arange(rec.acceleration.size + 400)  # and free vibration after it
        acc = np.concatenate([rec.acceleration * out["scale"][i], np.zeros(400)])
        _, u, _ = scipy.signal.lsim(system, acc, t, interp=True)
        sa = w * w * np.max(np.abs(u))
        assert sa == pytest.approx(design["target"].values[i], rel=2e-3)
        # the cube's groups are those of the scaled record
        alpha = design["critical_rotation"].values[i]
        assert out["pga_ratio"][i] == pytest.approx(
            np.max(np.abs(acc)) / (G * np.tan(alpha)), rel=1e-12
        )


def test_pga_ratio_is_scale_to_pga_ratio(suite, tmp_path):
    """The legacy pga_ratio and scale_to = { im = "pga_ratio" } apply the same factors, and the
    scaled record's peak is pga_ratio g tan(alpha)."""
    old = rows_study(suite, tmp_path, "pga_ratio = 2.5")
    new = rows_study(suite, tmp_path, 'scale_to = { im = "pga_ratio", value = 2.5 }')
    d_old, o_old = run_rows(old, tmp_path)
    _, o_new = run_rows(new, tmp_path)
    np.testing.assert_allclose(o_new["scale"], o_old["scale"], rtol=1e-14)
    # the factors agree to rounding (two orders of the same arithmetic), the responses to 1e-12
    np.testing.assert_allclose(o_new["max_rotation"], o_old["max_rotation"], rtol=1e-12)
    files = sorted(suite.glob("*_H.AT2"))
    peaks = np.array([Record.from_at2(files[r]).peak for r in d_old["record"].values])
    uplift = G * np.tan(d_old["critical_rotation"].values)
    np.testing.assert_allclose(peaks * o_old["scale"], 2.5 * uplift, rtol=1e-12)


# ---------------------------------------------------------------- bad input, before the run


def refused(tmp_path, motion, design="", field=None):
    text = HEAD + motion + design + '[run]\noutputs = ["max_rotation"]\n'
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(StudyError) as info:
        load_study(path)
    message = str(info.value)
    if field is not None:
        assert field in message, message
    return message


def test_ida_options_out_of_range_are_refused_naming_the_field(suite, tmp_path):
    motion = MOTION.replace("RECORDS", str(suite))
    for key, value in (
        ("tolerance", "1e-300"),
        ("tolerance", "0.9"),
        ("scan", "-1"),
        ("scan", "1000000"),
        ("step", "0.0"),
        ("max_pga_ratio", "1.0"),
    ):
        msg = refused(tmp_path, motion, f'[design]\nkind = "ida"\n{key} = {value}\n', key)
        assert f"design.{key}" in msg and "must be" in msg, msg
    msg = refused(tmp_path, motion, '[design]\nkind = "ida"\ngrowth = 1.5\n', "design.growth")
    assert "give step" in msg
    ok = design_study(suite, "ida", tmp_path)
    assert ok.design.ida() == rd.IdaOptions(im="pgv", tolerance=0.02, scan=2)


def test_bad_record_suites_are_refused_naming_the_field(suite, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "notes.md").write_text("no records here")
    stripes = '[design]\nkind = "stripes"\n'
    grid = 'value = { dist = "grid", values = [1.0, 2.0] }'
    # a folder with no records
    msg = refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{empty}"\n',
        '[design]\nkind = "cloud"\n',
        "motion.files",
    )
    assert "holds no record files" in msg
    # a glob with no match
    msg = refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{suite}/*.xyz"\n',
        '[design]\nkind = "cloud"\n',
        "motion.files",
    )
    assert "matches no file" in msg
    # an unreadable file: its name in the message
    bad = tmp_path / "broken.AT2"
    bad.write_text("PEER\nx\nUNITS OF G\nNPTS= 10, DT= 0.01 SEC\n1 2 3\n")
    msg = refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = ["{suite}/nf1_H.AT2", "{bad}"]\n',
        '[design]\nkind = "cloud"\n',
        "motion.files[1]",
    )
    assert "broken.AT2" in msg
    # an H/V pair of different lengths
    short = tmp_path / "short_UP.AT2"
    write_at2(short, Record(np.ones(50), dt=0.005))
    msg = refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = ["{suite}/nf1_H.AT2"]\nvertical = ["{short}"]\n',
        '[design]\nkind = "cloud"\n',
        "motion.vertical[0]",
    )
    assert "samples" in msg
    # an IM name that does not exist, as a scale target and as the IDA's measure
    refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{suite}/*_H.AT2"\n'
        f'scale_to = {{ im = "pgx", {grid} }}\n',
        stripes,
        "motion.scale_to.im",
    )
    refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{suite}/*_H.AT2"\n',
        '[design]\nkind = "ida"\nim = "pgx"\n',
        "design.im",
    )
    # sa without its period
    refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{suite}/*_H.AT2"\n'
        f'scale_to = {{ im = "sa", {grid} }}\n',
        stripes,
        "motion.scale_to.period",
    )
    # a scale target the record cannot reach: PGA 0
    zero = tmp_path / "zero.AT2"
    write_at2(zero, Record(np.zeros(100), dt=0.01))
    msg = refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = ["{zero}"]\nscale_to = {{ im = "pga", {grid} }}\n',
        stripes,
        "motion.files[0]",
    )
    assert "zero.AT2" in msg
    # stripes need their levels as a grid; a cloud takes no scale
    refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{suite}/*_H.AT2"\n'
        'scale_to = { im = "pga", value = 3.0 }\n',
        stripes,
        "motion.scale_to.value",
    )
    refused(
        tmp_path,
        f'[motion]\nkind = "record"\nfiles = "{suite}/*_H.AT2"\npga_ratio = 2.0\n',
        '[design]\nkind = "cloud"\n',
        "motion.pga_ratio",
    )


def test_no_record_of_a_folder_is_skipped(suite, tmp_path):
    """A folder's files that are neither a horizontal record nor its vertical are refused by
    an H/V rule, not skipped."""
    folder = tmp_path / "mixed"
    shutil.copytree(suite, folder)
    shutil.copy(folder / "nf1_H.AT2", folder / "stray.AT2")
    msg = refused(
        tmp_path,
        HV.replace("RECORDS", str(folder)),
        '[design]\nkind = "cloud"\n',
        "motion.vertical",
    )
    assert "stray.AT2" in msg


def test_report_of_a_record_study_shows_its_file_and_target_units(suite, client, tmp_path):
    """Monte Carlo rows scaled to a PGV distribution: the report renders in Chromium, names the
    target in its units in the inputs table, and shows the study file as written."""

    from rockstudy.study.report import make_report

    study = rows_study(
        suite,
        tmp_path,
        'scale_to = { im = "pgv", value = { dist = "uniform", low = 0.2, high = 0.8 } }',
        n=40,
    )
    out = tmp_path / "cube.zarr"
    run_study(study, out, client=client, base_dir=tmp_path, progress=False, netcdf=False)
    cube = open_result(out)
    assert {"pgv", "pga_ratio", "pulse_frequency_ratio", "scale"} <= set(cube.data_vars)
    # each sample's scaled record has the PGV it was drawn: target = PGV of record x scale
    files = sorted(suite.glob("*_H.AT2"))
    pgv = np.array([Record.from_at2(f).intensity_measures()["pgv"] for f in files])
    np.testing.assert_allclose(
        pgv[cube["record"].values] * np.abs(cube["scale"].values), cube["target"].values, rtol=1e-12
    )
    page = make_report(out, tmp_path / "report")
    shown, total = chromium_figures(page)  # the page loads; its figures (if any) decode
    assert shown == total
    inputs = (tmp_path / "report" / "inputs.csv").read_text()
    assert "scale target pgv [m/s]" in inputs

    text = page.read_text()
    for line in (tmp_path / "rows.toml").read_text().splitlines():
        assert html.escape(line) in text, line


# ------------------------------------------------------------------------------ units and notes


def test_scale_to_in_g_runs_in_g(suite, tmp_path):
    """scale_to = { im = "pga", units = "g" }: each row's record, read afresh and scaled by the
    factor the run applied, has PGA = value x 9.80665 m/s^2 (the standard g)."""
    study = rows_study(
        suite,
        tmp_path,
        'scale_to = { im = "pga", units = "g", value = { dist = "uniform", '
        "low = 0.2, high = 0.4 } }",
    )
    design, out = run_rows(study, tmp_path)
    files = sorted(suite.glob("*_H.AT2"))
    for i in range(3):
        rec = Record.from_at2(files[design["record"].values[i]])
        pga_g = np.max(np.abs(rec.acceleration * out["scale"][i])) / STANDARD_GRAVITY
        assert 0.2 <= pga_g <= 0.4
        assert pga_g * STANDARD_GRAVITY == pytest.approx(design["target"].values[i], rel=1e-12)
    assert "written in g" in design["target"].attrs["long_name"]
    # stripes levels in g are the same design as levels in m/s^2
    levels = [0.3, 0.6]
    text = (
        HEAD
        + MOTION.replace("RECORDS", str(suite))
        + 'scale_to = { im = "pga", units = "g", value = { dist = "grid", values = [0.3, 0.6] } }\n'
        + '[design]\nkind = "stripes"\n'
    )
    (tmp_path / "g.toml").write_text(text)
    rows = make_design(load_study(tmp_path / "g.toml"), tmp_path)
    np.testing.assert_allclose(rows["level"].values, np.array(levels) * STANDARD_GRAVITY)


def _notes(tmp_path, text):
    path = tmp_path / "notes.toml"
    path.write_text(text)
    return load_study(path).notes


def test_validate_notes_big_scale_factors_and_levels_where_nothing_rocks(suite, tmp_path):
    records = load_suite(str(suite / "*_H.AT2"))
    pgas = np.array([float(r.peak) for r in records])
    base = HEAD + MOTION.replace("RECORDS", str(suite))
    # levels far above every PGA: every record is scaled beyond 5 (and beyond 2 if set)
    grid = f"[{float(6.0 * pgas.max())!r}]"
    stripes = f'scale_to = {{ im = "pga", value = {{ dist = "grid", values = {grid} }} }}\n'
    notes = _notes(tmp_path, base + stripes + '[design]\nkind = "stripes"\n')
    assert sum("max_scale_factor = 5" in n for n in notes) == len(records), notes
    lower = f"[{float(1.5 * pgas.max())!r}]"
    stripes = f'scale_to = {{ im = "pga", value = {{ dist = "grid", values = {lower} }} }}\n'
    notes = _notes(tmp_path, base + stripes + '[design]\nkind = "stripes"\n')
    assert not any("max_scale_factor" in n for n in notes)
    notes = _notes(
        tmp_path, base + stripes + '[design]\nkind = "stripes"\nmax_scale_factor = 1.2\n'
    )
    expect = int(np.sum(1.5 * pgas.max() / pgas > 1.2))
    assert sum("max_scale_factor = 1.2" in n for n in notes) == expect > 0
    # the slenderness of HEAD is in [0.15, 0.25]: g tan(0.15) = 1.48 m/s^2 is the lowest uplift
    uplift = G * math.tan(0.15)
    for level, silent in ((0.9 * uplift, False), (1.1 * uplift, True)):
        stripes = (
            f'scale_to = {{ im = "pga", value = {{ dist = "grid", values = [{level!r}] }} }}\n'
        )
        notes = _notes(tmp_path, base + stripes + '[design]\nkind = "stripes"\n')
        assert silent != any("nothing can rock" in n for n in notes), notes
    # 0.1 written in g: 0.98 m/s^2, below the uplift: the trap of values in g read as m/s^2
    stripes = 'scale_to = { im = "pga", units = "g", value = { dist = "grid", values = [0.1] } }\n'
    notes = _notes(tmp_path, base + stripes + '[design]\nkind = "stripes"\n')
    assert any("nothing can rock" in n for n in notes)


def test_validate_reports_a_bad_units_and_a_misspelt_folder_together(suite, tmp_path):
    text = (
        HEAD
        + MOTION.replace("RECORDS", str(suite) + "_misspelt")
        + (
            'scale_to = { im = "pga", units = "furlongs", '
            'value = { dist = "grid", values = [1.0] } }\n'
            '[design]\nkind = "stripes"\n'
        )
    )
    (tmp_path / "two.toml").write_text(text)
    with pytest.raises(StudyError) as err:
        load_study(tmp_path / "two.toml")
    problems = "\n".join(err.value.problems)
    assert "motion.scale_to.units" in problems and "furlongs" in problems
    assert "motion.files" in problems and "_misspelt" in problems


def test_cli_validate_prints_the_notes(suite, tmp_path, capsys):
    from rockstudy.cli import main

    text = HEAD + MOTION.replace("RECORDS", str(suite))
    text += 'scale_to = { im = "pga", units = "g", value = { dist = "grid", values = [0.1] } }\n'
    text += '[design]\nkind = "stripes"\n'
    (tmp_path / "n.toml").write_text(text)
    assert main(["validate", str(tmp_path / "n.toml")]) == 0
    assert "note: motion.scale_to.value: nothing can rock" in capsys.readouterr().out


def test_validate_notes_a_cloud_of_records_that_cannot_rock_the_objects(suite, tmp_path):
    """A cloud: the records as recorded. Objects whose uplift g tan(alpha) exceeds every
    record's PGA cannot rock (noted); an object below some record's PGA can (no note)."""
    top = max(float(r.peak) for r in load_suite(str(suite / "*_H.AT2")))
    for pga_ratio, noted in ((1.2, True), (0.8, False)):
        alpha = math.atan(pga_ratio * top / G)  # uplift g tan(alpha) = pga_ratio x top
        text = (
            'name = "cloud"\nseed = 1\n[structure]\nkind = "objects"\n'
            f'objects = [{{ name = "A", half_diagonal = 1.0, slenderness = {alpha!r} }}]\n'
            + MOTION.replace("RECORDS", str(suite))
            + '[design]\nkind = "cloud"\n'
        )
        notes = _notes(tmp_path, text)
        assert noted == any("nothing can rock" in n for n in notes), notes


def test_units_other_than_g_on_at2_files_alone_are_refused(suite, tmp_path):
    """PEER's .AT2 files are in g whatever motion.units says: a setting that would change
    nothing is refused by name; g, and the units of text records, are taken."""
    for units, refused in (('"m/s2"', True), ('"m/s^2"', True), ('"g"', False)):
        text = HEAD + MOTION.replace("RECORDS", str(suite)) + f"units = {units}\n"
        text += '[design]\nkind = "cloud"\n'
        (tmp_path / "u.toml").write_text(text)
        if refused:
            with pytest.raises(StudyError) as err:
                load_study(tmp_path / "u.toml")
            assert any(p.startswith("motion.units:") for p in err.value.problems)
        else:
            load_study(tmp_path / "u.toml")
    # a text record in m/s^2 (either spelling): the same peak as its .AT2 in g
    rec = load_suite(str(suite / "nf0_H.AT2"))[0]
    text_file = tmp_path / "nf0.txt"
    rows = zip(rec.time, rec.acceleration, strict=True)
    text_file.write_text("\n".join(f"{t!r} {a!r}" for t, a in rows))
    for units in ("m/s2", "m/s^2"):
        text = HEAD + f'[motion]\nkind = "record"\nfiles = ["{text_file.as_posix()}"]\n'
        text += f'units = "{units}"\n[design]\nkind = "cloud"\n'
        (tmp_path / "t.toml").write_text(text)
        study = load_study(tmp_path / "t.toml")
        assert study.motion.units == units
        again = load_suite([text_file], units=units)[0]
        assert again.peak == pytest.approx(rec.peak, rel=1e-15)
