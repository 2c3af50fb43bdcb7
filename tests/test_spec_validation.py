"""Study files that cannot succeed are refused by validate, with one plain sentence per field;
record files are read safely and never leak their bytes."""

import math
import os
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from rockstudy import Block
from rockstudy.cli import main as cli_main
from rockstudy.study import StudyError, load_study, validate_text
from rockstudy.study.designs.sampling import make_design
from rockstudy.study.running.evaluate import evaluate_chunk, resolve_file
from rockstudy.study.spec.schema import Study

ROOT = Path(__file__).resolve().parents[1]

PULSE = """
name = "v"
seed = 7
chunk_size = 100

[sampler]
kind = "monte_carlo"
n = 50

[structure]
kind = "block"
half_diagonal = { dist = "uniform", low = 0.5, high = 3.0 }
slenderness = { dist = "uniform", low = 0.1, high = 0.3 }

[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = { dist = "uniform", low = 0.8, high = 5.0 }
period = { dist = "loguniform", low = 0.1, high = 2.0 }

[run]
rtol = 1e-8
outputs = ["max_rotation", "overturned"]
"""

RECORD = """
name = "r"
seed = 7
[sampler]
kind = "monte_carlo"
n = 8
[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.8, high = 1.2 }}
slenderness = 0.2
[motion]
kind = "record"
files = [{files}]
{scaling}
"""

STOCHASTIC = (
    PULSE.split("[motion]")[0]
    + """
[motion]
kind = "stochastic"
pga_ratio = { dist = "uniform", low = 0.8, high = 2.5 }
"""
)

PLUMBING = ("tagged-union", "function-after", "Input should", "Value error", "Extra inputs")


def refused(text, base_dir=None):
    """The problems of a study that must be refused; each a plain sentence."""
    with pytest.raises(StudyError) as info:
        validate_text(text) if base_dir is None else validate_text(text, base_dir=base_dir)
    message = str(info.value)
    for word in PLUMBING:
        assert word not in message, message
    return message


def record_study(files, scaling="pga_ratio = 2.0"):
    return RECORD.format(files=", ".join(f'"{f}"' for f in files), scaling=scaling)


def write_csv(path, t, a):
    path.write_text(
        "# t [s], a [g]\n" + "".join(f"{x!r}, {y!r}\n" for x, y in zip(t, a, strict=True))
    )
    return path


def test_pulse_study_is_valid():
    validate_text(PULSE)


# ------------------------------------------------------------------ derived parameters


def housner_eta(alpha):
    return 1.0 - 1.5 * math.sin(alpha) ** 2  # eq. (2.4) of [000]


@pytest.mark.parametrize("high", [1.2, 0.96])
def test_housner_restitution_checked_over_the_support(high):
    assert housner_eta(high) < 0  # the oracle: eta < 0 somewhere in the support
    text = PULSE.replace("low = 0.1, high = 0.3", f"low = 0.1, high = {high}")
    message = refused(text)
    assert "structure.slenderness" in message and "restitution" in message
    assert "0.9553" in message  # the allowed range: sin^2(alpha) < 2/3


def test_housner_restitution_positive_below_the_limit_is_valid():
    assert housner_eta(0.95) > 0
    validate_text(PULSE.replace("low = 0.1, high = 0.3", "low = 0.1, high = 0.95"))
    # a given restitution makes the Housner limit irrelevant
    validate_text(
        PULSE.replace("low = 0.1, high = 0.3", "low = 0.1, high = 1.2").replace(
            'slenderness = { dist = "uniform", low = 0.1, high = 1.2 }',
            'slenderness = { dist = "uniform", low = 0.1, high = 1.2 }\nrestitution = 0.8',
        )
    )


def test_block_from_dimensions_names_the_slenderness():
    alpha = math.atan2(1.0, 0.2)  # width 2, height 0.4
    assert housner_eta(alpha) < 0
    with pytest.raises(ValueError) as info:
        Block.from_dimensions(width=2, height=0.4)
    message = str(info.value)
    assert "slenderness" in message and "Housner" in message and "0.9553" in message
    assert not message.startswith("restitution must")
    assert Block.from_dimensions(width=2, height=0.4, restitution=0.5).restitution == 0.5


# ------------------------------------------------------------------ types and structure


@pytest.mark.parametrize(
    "edit, field",
    [
        (("rtol = 1e-8", 'rtol = "1e-8"'), "run.rtol"),
        (("half_diagonal = { dist", "half_diagonal = true\nx = { dist"), "structure.half_diagonal"),
        (("seed = 7", "seed = true"), "seed"),
        (("n = 50", "n = 50.0"), "sampler.n"),
        (("n = 50", "n = 1e12"), "sampler.n"),
        (('shape = "sine"', 'shape = "sine"\ndirection = true'), "motion.direction"),
        (("chunk_size = 100", 'chunk_size = "100"'), "chunk_size"),
    ],
)
def test_wrong_types_are_errors(edit, field):
    message = refused(PULSE.replace(*edit))
    assert f"{field}: must be" in message, message


@pytest.mark.parametrize(
    "nested",
    [
        "x = " + "[" * 100_000 + "]" * 100_000,
        "x = " + "{a = " * 100_000 + "1" + "}" * 100_000,
        "[" + "a." * 100_000 + "b]\nc = 1",
    ],
    ids=["arrays", "inline-tables", "dotted-keys"],
)
def test_deep_nesting_is_a_clear_error(nested):
    message = refused(nested + "\n")
    assert "nest" in message


def test_wrong_distribution_name_is_one_plain_sentence():
    text = PULSE.replace('dist = "uniform", low = 0.5', 'dist = "unifrom", low = 0.5')
    with pytest.raises(StudyError) as info:
        validate_text(text)
    kinds = ", ".join(repr(name) for name in _distribution_names())
    assert info.value.problems == [
        f"structure.half_diagonal.dist: must be one of {kinds}, got the string 'unifrom'"
    ]


def _distribution_names():
    """The ``dist`` names of the schema's distributions, in the order of its union."""
    from typing import get_args

    from rockstudy.study.spec.distributions import Distribution

    union = get_args(Distribution)[0]
    return [get_args(cls.model_fields["dist"].annotation)[0] for cls in get_args(union)]


def test_typo_names_the_key():
    message = refused(PULSE.replace("period = {", "perod = {"))
    assert "motion.perod: is not a setting" in message and "motion.period" not in message


# ------------------------------------------------------------------ non-finite values


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("low = 0.5, high = 3.0", "low = 0.5, high = inf", "structure.half_diagonal.high"),
        ("low = 0.5, high = 3.0", "low = nan, high = 3.0", "structure.half_diagonal.low"),
        (
            '{ dist = "uniform", low = 0.8, high = 5.0 }',
            '{ dist = "choice", values = [1.0, nan] }',
            "motion.amplitude_ratio.values[1]",
        ),
        (
            '{ dist = "uniform", low = 0.1, high = 0.3 }',
            '{ dist = "truncnormal", mean = nan, sigma = 0.1, low = 0.1, high = 0.3 }',
            "structure.slenderness.mean",
        ),
        (
            '{ dist = "loguniform", low = 0.1, high = 2.0 }',
            '{ dist = "loguniform", low = 1e-300, high = 1e300 }',
            "motion.period",
        ),
        (
            '{ dist = "loguniform", low = 0.1, high = 2.0 }',
            '{ dist = "lognormal", median = 1.0, sigma = 200.0 }',
            "motion.period",
        ),
        ("rtol = 1e-8", "rtol = nan", "run.rtol"),
    ],
)
def test_non_finite_values_are_refused(old, new, field):
    assert old in PULSE
    message = refused(PULSE.replace(old, new))
    assert f"{field}:" in message, message


def test_every_value_the_samplers_draw_is_finite_at_the_limits():
    """The bounds allowed by the checks above give finite designs at the extreme draws."""
    text = PULSE.replace(
        '{ dist = "loguniform", low = 0.1, high = 2.0 }',
        '{ dist = "lognormal", median = 1.0, sigma = 1.0 }',
    )  # sigma 1: draws e^(+-8.1) s, within the solvers' periods (sigma 5 reaches 1e-18 s)
    design = make_design(validate_text(text))
    assert all(np.all(np.isfinite(design[v].values)) for v in design.data_vars)


# ------------------------------------------------------------------ records


@pytest.mark.parametrize(
    "scale", ["nan", "inf", "0.0", '{ dist = "uniform", low = -1.0, high = 1.0 }']
)
def test_record_scale_must_give_a_motion(tmp_path, scale):
    rec = write_csv(tmp_path / "r.csv", [0.0, 0.01, 0.02], [0.0, 0.1, -0.1])
    message = refused(record_study([rec], f"scale = {scale}"))
    assert "motion.scale" in message


SECRET = "SECRET_TOKEN_h5_0xDEADBEEF"


def bad_records(tmp_path):
    """Record files that cannot give a finite sample, each holding the secret marker."""
    d = tmp_path / "bad"
    d.mkdir()
    (d / "empty.csv").write_text("")
    (d / "binary.csv").write_bytes(b"\x89PNG\r\n\x1a\n\0\0" + SECRET.encode() + b"\0" * 40)
    (d / "nan.csv").write_text(f"# {SECRET}\n0.0, 0.1\n0.01, nan\n0.02, 0.1\n")
    (d / "backwards.csv").write_text(f"# {SECRET}\n0.0, 0.1\n0.02, 0.2\n0.01, 0.1\n")
    (d / "words.csv").write_text(f"0.0, 0.1\n{SECRET}, 0.2\n")
    (d / "folder.csv").mkdir()
    header = f"PEER {SECRET}\nline 2\nACCELERATION TIME SERIES IN UNITS OF G\n"
    (d / "short.AT2").write_text(header + "NPTS= 10, DT= .01 SEC\n0.1 0.2 0.3\n")
    (d / "header.AT2").write_text(header + f"{SECRET}\n0.1 0.2 0.3\n")
    (d / "units.AT2").write_text(f"PEER\nline 2\n{SECRET}\nNPTS= 3, DT= .01 SEC\n0.1 0.2 0.3\n")
    (d / "zero.csv").write_text("0.0, 0.0\n0.01, 0.0\n0.02, 0.0\n")  # cannot be scaled to a PGA
    files = sorted(p.name for p in d.iterdir())
    files += ["missing.csv", "/proc/self/environ", "/dev/zero"]
    return d, files


def test_bad_record_files_are_refused_by_name_without_their_bytes(tmp_path, monkeypatch):
    monkeypatch.setenv("H5_LEAK_CHECK", SECRET)  # would show in /proc/self/environ
    d, files = bad_records(tmp_path)
    for name in files:
        with pytest.raises(StudyError) as info:
            validate_text(record_study([name]), base_dir=d)
        message = str(info.value)
        assert "motion.files[0]" in message and Path(name).name in message, message
        assert SECRET not in message and "\\x" not in message, message
        assert "DEADBEEF" not in message


def test_run_never_stores_file_bytes_in_the_cube(tmp_path, monkeypatch):
    """A study naming /proc/self/environ (validation bypassed): the error stored per sample
    names the file and the reason, not the environment."""
    monkeypatch.setenv("H5_LEAK_CHECK", SECRET)
    text = record_study(["/proc/self/environ"], "scale = 1.0")
    study = Study.model_validate(tomllib.loads(text))  # the schema alone: files unchecked
    design = make_design(study)
    cols = {k: design[k].values for k in design.data_vars if design[k].dims == ("sample",)}
    cols["sample"] = design["sample"].values
    out = evaluate_chunk(study.normalized(), cols, base_dir=tmp_path)
    assert np.all(out["status"] == 2)
    for message in out["error"]:
        text = message.decode() if isinstance(message, bytes) else str(message)
        assert "/proc/self/environ" in text, text
        assert SECRET not in text and "H5_LEAK" not in text, text


def test_good_records_validate_and_times_are_checked(tmp_path):
    rec = write_csv(tmp_path / "r.csv", [0.0, 0.01, 0.02], [0.0, 0.1, -0.1])
    validate_text(record_study([rec.name]), base_dir=tmp_path)
    at2 = tmp_path / "x.AT2"
    at2.write_text("PEER\nline 2\nUNITS OF G\nNPTS= 3, DT= .01 SEC\n0.1 0.2 0.3\n")
    validate_text(record_study([str(at2)]))  # absolute: as written


def test_record_paths_are_relative_to_the_study_file(tmp_path, monkeypatch):
    study_dir, work = tmp_path / "study", tmp_path / "work"
    study_dir.mkdir()
    work.mkdir()
    write_csv(work / "r.csv", [0.0, 0.01, 0.02], [0.0, 0.1, -0.1])  # only in the working folder
    (study_dir / "s.toml").write_text(record_study(["r.csv"]))
    monkeypatch.chdir(work)
    assert resolve_file("r.csv", study_dir) == study_dir / "r.csv"  # never the working folder
    assert cli_main(["validate", str(study_dir / "s.toml")]) == 2
    shutil.copy(work / "r.csv", study_dir / "r.csv")
    assert load_study(study_dir / "s.toml").motion.files == ["r.csv"]
    assert cli_main(["validate", str(study_dir / "s.toml")]) == 0


def test_shipped_record_study_in_a_clone_without_records(tmp_path, capsys):
    clone = tmp_path / "clone" / "studies"
    clone.mkdir(parents=True)
    shutil.copy(ROOT / "studies" / "fragility_records.toml", clone)
    assert cli_main(["validate", str(clone / "fragility_records.toml")]) == 2
    err = capsys.readouterr().err
    assert "motion.files[0]" in err and "RSN126_GAZLI_GAZ000.AT2: no such file" in err


# ------------------------------------------------------------------ stochastic and sizes


@pytest.mark.parametrize(
    "setting, field",
    [
        ("duration = inf", "motion.duration"),
        ("dt = 1.0", "motion.dt"),
        ("decay = -1.0", "motion.decay"),
        ("duration = 0.01", "motion.duration"),
        ("duration = 1e7", "motion.duration"),  # beyond the 1e6 s of any record
        ("duration = 1e6\ndt = 1e-5", "motion.duration"),  # 10^11 points
        ("duration = 20000.0", "motion.duration"),  # 2e6 points > max_steps
    ],
)
def test_stochastic_settings_that_cannot_work(setting, field):
    message = refused(STOCHASTIC + setting + "\n")
    assert f"{field}:" in message, message
    if "1e-5" in setting:
        assert "GiB per sample" in message


def test_sizes_beyond_the_machine_are_estimated_and_refused():
    message = refused(PULSE.replace("n = 50", "n = 1000000000000"))
    assert "sampler:" in message and "GiB" in message and "1e+12 samples" in message
    grid = (
        PULSE.replace('kind = "monte_carlo"\nn = 50', 'kind = "grid"')
        .replace('{ dist = "uniform", low = 0.5, high = 3.0 }', "1.0")
        .replace('{ dist = "uniform", low = 0.1, high = 0.3 }', "0.2")
        .replace(
            '{ dist = "uniform", low = 0.8, high = 5.0 }',
            '{ dist = "grid", low = 1.1, high = 4.0, n = 100000000 }',
        )
        .replace(
            '{ dist = "loguniform", low = 0.1, high = 2.0 }',
            '{ dist = "grid", low = 0.1, high = 2.0, n = 100000000 }',
        )
    )
    message = refused(grid)  # 10^16 points: refused without making them
    assert "1e+16 samples" in message and "grid sizes" in message


def test_cli_validate_prints_plain_errors(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(PULSE.replace("rtol = 1e-8", 'rtol = "1e-8"'))
    assert cli_main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "run.rtol: must be a number, got the string '1e-8'" in err
    assert "Traceback" not in err


def test_validate_refuses_a_study_file_that_is_not_a_file(tmp_path, capsys):
    assert cli_main(["validate", str(tmp_path)]) == 2
    assert cli_main(["validate", "/dev/zero"]) == 2
    err = capsys.readouterr().err
    assert str(tmp_path) in err and "/dev/zero" in err
    assert os.path.isdir(tmp_path)


@pytest.mark.parametrize("rtol", ["1e-13", "1e-15", "1e-300"])
def test_rtol_below_what_the_solvers_take_is_refused(rtol):
    """The floor is the solvers' own (simulate_batch refuses below 1e-12): a study that
    validates must not fail at run time on its rtol."""
    message = refused(PULSE.replace("rtol = 1e-8", f"rtol = {rtol}"))
    assert "run.rtol: must be >= 1e-12" in message


def test_pulse_cycles_beyond_max_steps_are_refused():
    """10^6 cycles (each taking ~14 to 322 solver steps) cannot finish in 10^6 steps."""
    text = PULSE.replace('shape = "sine"', 'shape = "sine"\ncycles = 1000000')
    message = refused(text)
    assert "motion.cycles" in message and "run.max_steps = 1000000" in message
    validate_text(PULSE.replace('shape = "sine"', 'shape = "sine"\ncycles = 1000'))


# ------------------------------------------------------------------ ranges (issue 26)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ('name = "', 'name = "a\\u0000', "name"),  # a NUL character
        ("rtol = 1e-8", "rtol = 1e-8\nmax_steps = 10000000000000", "run.max_steps"),
        ("n = 50", "n = 50\nreplicates = 10000000", "sampler.replicates"),
    ],
)
def test_settings_beyond_their_range_are_refused(old, new, field):
    assert old in PULSE
    message = refused(PULSE.replace(old, new, 1))
    assert f"{field}:" in message, message


@pytest.mark.parametrize(
    "motion, field",
    [
        ("amplitude = 1e300\nperiod = 0.5", "motion.amplitude"),
        ("amplitude = 5.0\nperiod = 1e-300", "motion.period"),
        ("amplitude_ratio = 2.0\nfrequency_ratio = 1e-9", "motion.frequency_ratio"),
        ("amplitude_ratio = 9000.0\nperiod = 0.5", "motion.amplitude_ratio"),
    ],
)
def test_pulse_settings_the_solvers_would_refuse_are_refused(motion, field):
    text = (
        'name = "p"\nseed = 1\n[sampler]\nkind = "monte_carlo"\nn = 4\n[structure]\n'
        'kind = "block"\nhalf_diagonal = { dist = "uniform", low = 0.5, high = 2.0 }\n'
        f'slenderness = 1.5707\nrestitution = 0.9\n[motion]\nkind = "pulse"\n{motion}\n'
    )
    message = refused(text)
    assert f"{field}:" in message, message


@pytest.mark.parametrize(
    "scaling, field",
    [
        ('scale_to = { im = "pgv", value = 1e300 }', "motion.scale_to.value"),
        ('scale_to = { im = "pga", value = 2e7 }', "motion.scale_to.value"),
        ("scale = 1e300", "motion.scale"),
        ("scale = 1e-300", "motion.scale"),
        ("pga_ratio = 1e300", "motion.pga_ratio"),
    ],
)
def test_a_scaled_record_beyond_the_solvers_range_is_refused(tmp_path, scaling, field):
    """Issue 26: a target that scales a record past 1e7 m/s^2 (or a scale that makes its
    samples vanish) failed at run time; validate refuses it, naming the field."""
    t = [0.0, 0.01, 0.02, 0.03]
    rec = write_csv(tmp_path / "r.csv", t, [0.0, 0.1, -0.1, 0.0])
    message = refused(record_study([rec], scaling))
    assert f"{field}:" in message, message


def test_a_scaled_record_within_range_is_accepted(tmp_path):
    """Not a refusal too many: a PGA target of 1e6 m/s^2 (about 1e5 g) is taken."""
    rec = write_csv(tmp_path / "r.csv", [0.0, 0.01, 0.02, 0.03], [0.0, 0.1, -0.1, 0.0])
    validate_text(record_study([rec], 'scale_to = { im = "pga", value = 1e6 }'))


def test_replicates_of_another_structure_kind_name_the_kind():
    """Replicates compare blocks (R, alpha) at one group point: a wall with its restitution
    given is refused for its kind, not told that its restitution is Housner's."""
    text = (Path(__file__).resolve().parents[1] / "studies" / "self_similarity_61.toml").read_text()
    wall = text.replace('kind = "block"', 'kind = "rocking_wall"').replace(
        "high = 0.35 }", "high = 0.3 }"
    )
    message = refused(wall)
    assert "sampler.replicates" in message and '"rocking_wall"' in message, message
    assert "Housner" not in message
    housner = text.replace('restitution = { dist = "uniform", low = 0.8, high = 0.96 }\n', "")
    assert "Housner" in refused(housner)


@pytest.mark.parametrize(
    "old, new, line",
    [
        ("rtol = 1e-8", "rtoll = 1e-8", "run.rtoll: is not a setting here; did you mean 'rtol'?"),
        ("seed = ", "chunksize = 9\nseed = ", "chunksize: is not a setting here; did you mean "),
        ("[sampler]", "[sampler]\nreplicate = 2", "did you mean 'replicates'?"),
    ],
)
def test_a_misspelt_setting_is_named_with_the_settings_it_resembles(old, new, line):
    """A typo names the field and the settings of its own table that it resembles."""
    assert old in PULSE
    assert line in refused(PULSE.replace(old, new, 1))


def test_a_misspelt_setting_of_a_kind_or_an_object_resembles_that_kinds_settings():
    """Inside a table chosen by its kind (the structure), and inside an object of a list."""
    quick = (Path(__file__).resolve().parents[1] / "studies" / "quickstart.toml").read_text()
    message = refused(quick.replace("slenderness = {", "slendernes = {"))
    assert "structure.slendernes: is not a setting here; did you mean 'slenderness'?" in message
    museum = (Path(__file__).resolve().parents[1] / "studies" / "museum.toml").read_text()
    message = refused(museum.replace("width = 0.50", "widht = 0.50", 1))
    assert ".widht: is not a setting here; did you mean 'width'?" in message
    assert "'rtol'" not in refused(quick.replace("seed = 2026", "seed = 2026\nzzz = 1"))


def test_every_range_problem_of_a_structure_is_named_at_once():
    """A negative half-diagonal does not hide a slenderness beyond pi/2 (one run, all named)."""
    quick = (Path(__file__).resolve().parents[1] / "studies" / "quickstart.toml").read_text()
    bad = quick.replace("low = 0.5, high = 3.0", "low = -0.5, high = 3.0").replace(
        "low = 0.1, high = 0.3", "low = 0.1, high = 1.7"
    )
    message = refused(bad)
    assert "structure.half_diagonal: the distribution must only give values > 0" in message
    assert "structure.slenderness: the distribution must only give values in (0, pi/2)" in message


def test_a_record_that_does_not_read_is_named_beside_an_objects_problem(tmp_path):
    """A NaN in a record file is reported in the same run as a negative width of an object."""
    folder = tmp_path / "recs"
    folder.mkdir()
    t = np.arange(300) * 0.01
    a = 0.3 * np.sin(2 * np.pi * t)
    a[50] = np.nan
    np.savetxt(folder / "a.txt", np.column_stack([t, a]))
    np.savetxt(folder / "b.txt", np.column_stack([t, 0.2 * np.sin(3 * np.pi * t)]))
    museum = (Path(__file__).resolve().parents[1] / "studies" / "museum.toml").read_text()
    museum = museum.split("[hazard]")[0].replace('"../data/records/*_H.AT2"', '"recs"')
    message = refused(museum.replace("width = 0.50", "width = -0.50", 1), base_dir=tmp_path)
    assert ".width: " in message and "got -0.5" in message
    assert "a.txt" in message and "NaN" in message


def test_the_stored_study_of_an_ida_shows_every_option_it_runs_with(tmp_path):
    """An IDA study that leaves its options out is stored with the values it runs with (the
    defaults documented for ``[design]``: step 0.01, tolerance 0.001, max_pga_ratio 30,
    scan 24, im pga), and the normalized study validates to itself."""
    import json

    records = Path(__file__).resolve().parents[1] / "data" / "records"
    text = (
        'name = "ida"\nseed = 1\n[structure]\nkind = "objects"\n'
        'objects = [{ name = "A", width = 0.4, height = 1.6 }]\n'
        f'[motion]\nkind = "record"\nfiles = "{records}/*_H.AT2"\n[design]\nkind = "ida"\n'
    )
    study = validate_text(text)
    design = json.loads(study.normalized())["design"]
    assert {k: design[k] for k in ("im", "step", "tolerance", "max_pga_ratio", "scan")} == {
        "im": "pga",
        "step": 0.01,
        "tolerance": 0.001,
        "max_pga_ratio": 30.0,
        "scan": 24,
    }
    again = Study.model_validate(json.loads(study.normalized()))
    assert again.normalized() == study.normalized()
    given = validate_text(text + "step = 0.05\nscan = 0\n")
    design = json.loads(given.normalized())["design"]
    assert design["step"] == 0.05 and design["scan"] == 0 and design["tolerance"] == 0.001
