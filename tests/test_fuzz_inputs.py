"""Property-based fuzz (Hypothesis) of the inputs an engineer hands rockstudy: study files with
named objects (inline or a CSV), friction, hazard sections and record sets, and the Python
risk, registry, contact and plotting calls.

The generator is Hypothesis's: it builds each study from strategies over the formats real
files come in (PEER ``.AT2``, two- and three-column ``.dat``/``.txt``/``.csv`` records in g,
m/s^2 or cm/s^2, OpenQuake and two-column hazard curves, objects CSVs with friction columns)
and over the defects they come with (non-monotone or repeated times, NaN, text among the
samples, rows longer than their header, bare carriage returns, binary or system files, a
spectral period that contradicts the file's, counts beyond any need). The judge:

- ``validate`` ends in one of two ways only: the study is accepted, or a
  :class:`~rockstudy.study.StudyError` whose every line names a field; never another
  exception, never a hang (60 s), never a line that quotes a system file's content;
- an accepted study drops nothing: every record file of its set is one record of the design,
  every object of its CSV one structure, every row of its hazard file one level;
- a file with a defect that makes it no record (or no curve, or no table) is refused;
- an accepted study runs: a sample of them is evaluated in-process, chunk by chunk as the
  dask tasks would, and every row comes back ok.

The API fuzz calls the public functions with one or two arguments replaced by hostile values:
each call answers finitely or raises ValueError/TypeError naming an argument it was given.

``ROCKSTUDY_FUZZ_EXAMPLES`` sets the number of generated studies and calls (default 60 each;
the full fuzz runs 400).
"""

from __future__ import annotations

import math
import os
import re
import tempfile
import warnings
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from _helpers import time_limit
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

matplotlib.use("Agg")

import rockstudy as rs  # noqa: E402
from rockstudy import risk  # noqa: E402
from rockstudy.constants import STANDARD_GRAVITY  # noqa: E402
from rockstudy.study import StudyError, validate_text  # noqa: E402
from rockstudy.study.designs.sampling import make_design  # noqa: E402
from rockstudy.study.running.evaluate import STATUS_OK, evaluate_chunk  # noqa: E402

EXAMPLES = int(os.environ.get("ROCKSTUDY_FUZZ_EXAMPLES", "60"))
FUZZ = settings(
    max_examples=EXAMPLES,
    derandomize=True,  # the same examples on every machine: a failure reproduces
    deadline=None,
    database=None,
    suppress_health_check=list(HealthCheck),
)
#: A line of a system file (as in /etc/passwd): no message may quote it.
SYSTEM_LINE = "root:x:0:0:root:/root:/bin/bash"
UNITS = {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}
#: A field path at the start of a problem line: ``motion.files[2]``, ``structure.objects``, ...
FIELD = re.compile(r"""^[A-Za-z_][\w.\[\]\-]*(?: \((?:'[^']*'|"[^"]*")\))?[\w.\[\]]*:""")
SECONDS = 60


# ------------------------------------------------------------------------------ records

#: Defects that make a file no record: a study that lists it must be refused.
RECORD_DEFECTS = ("non-monotone times", "repeated time", "nan", "text among samples", "empty")
#: Variants real files come in, which must read.
RECORD_VARIANTS = ("plain", "crlf", "header row", "trailing blank")


def _wave(n, dt, peak):
    t = np.arange(n) * dt
    a = np.sin(2 * np.pi * t / 0.7) * np.exp(-(((t - 0.4 * t[-1]) / (0.3 * t[-1])) ** 2))
    return t, peak * a / np.max(np.abs(a))


def _at2_text(values, dt):
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "synthetic record written by the fuzz",
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS= {values.size}, DT= {dt:.4f} SEC",
    ]
    lines += ["  ".join(f"{v:.7E}" for v in values[i : i + 5]) for i in range(0, values.size, 5)]
    return "\n".join(lines) + "\n"


@st.composite
def record_files(draw):
    """(file name, bytes, stored unit, defect or None): one record file."""
    fmt = draw(st.sampled_from(["at2", "dat", "txt3", "csv", "csv3"]))
    stored = "g" if fmt == "at2" else draw(st.sampled_from(list(UNITS)))
    n = draw(st.integers(60, 300))
    dt = draw(st.sampled_from([0.005, 0.01, 0.02]))
    pga_g = draw(st.sampled_from([0.08, 0.35, 0.9]))
    defect = draw(st.sampled_from((None,) * 24 + RECORD_DEFECTS))
    variant = draw(st.sampled_from(RECORD_VARIANTS))
    t, a = _wave(n, dt, pga_g * STANDARD_GRAVITY / UNITS[stored])
    if defect == "nan":
        a[draw(st.integers(0, n - 1))] = np.nan
    if fmt == "at2":
        text = "" if defect == "empty" else _at2_text(a, dt)
        if defect in ("non-monotone times", "repeated time"):
            defect = None  # an AT2 has no time column
        if defect == "text among samples":
            rows = text.split("\n")
            rows[6] = "these are not numbers"
            text = "\n".join(rows)
        return f"{fmt}.AT2", text.encode(), stored, defect
    i = draw(st.integers(1, n - 2))
    if defect == "non-monotone times":
        t[i], t[i + 1] = t[i + 1], t[i]
    if defect == "repeated time":
        t[i + 1] = t[i]
    three = fmt in ("txt3", "csv3")
    cols = [t, a] + ([0.4 * a] if three else [])
    sep = "," if fmt.startswith("csv") else " "
    rows = [sep.join(f"{x:.9g}" for x in row) for row in zip(*cols, strict=True)]
    if defect == "text among samples":
        rows[i] = "n/a"
    if variant == "header row":
        rows.insert(0, sep.join(["time", "horizontal", "vertical"][: len(cols)]))
    if defect == "empty":
        rows = []
    end = "\r\n" if variant == "crlf" else "\n"
    text = end.join(rows) + (end if rows else "")
    if variant == "trailing blank":
        text += end
    suffix = {"dat": ".dat", "txt3": ".txt", "csv": ".csv", "csv3": ".csv"}[fmt]
    return f"{fmt}{suffix}", text.encode(), stored, defect


# ------------------------------------------------------------------------------ objects

OBJECT_ROWS = [
    ("Statue A", "0.45", "1.9"),
    ("Bust <b>B</b>", "0.3", "0.9"),
    ("Stele & Co", "0.5", "2.2"),
    ("Urn", "0.35", "1.1"),
]
#: Objects CSV defects that must be refused.
CSV_DEFECTS = ("long row", "binary", "system file", "short row")
#: Objects CSV variants that may be refused or read (an empty trailing cell carries nothing),
#: but never read short.
CSV_VARIANTS = ("bare CR", "trailing comma")


@st.composite
def objects_section(draw):
    """(TOML of [structure], {file name: bytes}, number of objects, defect or None)."""
    n = draw(st.integers(1, 4))
    rows = OBJECT_ROWS[:n]
    friction = draw(st.sampled_from([None, None, "column", "inline", "bad"]))
    mode = draw(st.sampled_from(["inline", "csv", "csv"]))
    if mode == "inline":
        items = []
        for k, (name, w, h) in enumerate(rows):
            extra = ""
            if friction == "inline" and k == 0:
                extra = ", friction = 0.5"
            if friction == "bad" and k == 0:
                extra = ", friction = -0.2"
            items.append(f'{{ name = "{name}", width = {w}, height = {h}{extra} }}')
        toml = '[structure]\nkind = "objects"\nobjects = [\n  ' + ",\n  ".join(items) + "\n]\n"
        return toml, {}, n, ("bad friction" if friction == "bad" else None)
    defect = draw(st.sampled_from((None,) * 14 + CSV_DEFECTS + CSV_VARIANTS))
    header = ["name", "width", "height"] + (["friction"] if friction else [])
    body = []
    for name, w, h in rows:
        cells = [f'"{name}"' if "," in name else name, w, h]
        if friction:
            cells.append("-0.3" if friction == "bad" else "0.6")
        body.append(",".join(cells))
    if defect == "long row":
        body[-1] += ",,9"
    if defect == "short row":  # its height (a required column) missing
        body[-1] = ",".join(body[-1].split(",")[:2])
    if defect == "trailing comma":
        body[0] += ","
    text = ",".join(header) + "\n" + "\n".join(body) + "\n"
    if defect == "bare CR":
        text = text.replace("\n", "\r", 1)
    data = text.encode()
    if defect == "binary":
        data = bytes(range(256)) * 3 + SYSTEM_LINE.encode()
    if defect == "system file":
        data = (SYSTEM_LINE + "\n" + "daemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n").encode()
    toml = '[structure]\nkind = "objects"\nfile = "objects.csv"\n'
    bad = None if defect in CSV_VARIANTS else defect
    bad = bad or ("bad friction" if friction == "bad" else None)
    return toml, {"objects.csv": data}, n, bad


# ------------------------------------------------------------------------------ hazard

HAZARD_LEVELS_G = np.array([0.02, 0.05, 0.1, 0.2, 0.4, 0.8, 1.5])
HAZARD_RATES = 1e-4 * HAZARD_LEVELS_G**-2.2


@st.composite
def hazard_section(draw, design_kind):
    """(TOML of [hazard], {file name: bytes}, number of levels or None, defect or None)."""
    kind = draw(st.sampled_from([None, "power_law", "two columns", "openquake"]))
    if kind is None:
        return "", {}, None, None
    if kind == "power_law":
        k0, k = draw(st.sampled_from([("2e-4", "2.3"), ("2e-4", "8.0"), ("-1", "2"), ("1e6", "2")]))
        bad = None if (k0, k) == ("2e-4", "2.3") else f"power law {k0}, {k}"
        toml = f'[hazard]\nkind = "power_law"\nk0 = {k0}\nk = {k}\nim = "pga"\nunits = "g"\n'
        return toml, {}, None, bad
    defect = draw(st.sampled_from((None,) * 10 + ("rows cut", "system file", "period", "poe 1")))
    if kind == "two columns":
        lines = [f"{x:.6g},{r:.6g}" for x, r in zip(HAZARD_LEVELS_G, HAZARD_RATES, strict=True)]
        if defect == "rows cut":
            lines[3] = "0.2"
        text = "pga_g,annual_rate\n" + "\n".join(lines) + "\n"
        period = ""
        n_levels = HAZARD_LEVELS_G.size
        if defect in ("period", "poe 1"):
            defect = None
    else:
        imt = "SA(0.5)"
        poes = 1.0 - np.exp(-HAZARD_RATES * 50.0)
        if defect == "poe 1":
            poes = np.ones_like(poes)
        head = (
            f"#,,,,,\"generated_by='OpenQuake engine 3.16', investigation_time=50.0, imt='{imt}'\""
        )
        cols = "lon,lat,depth," + ",".join(f"poe-{x:g}" for x in HAZARD_LEVELS_G)
        row = "12.5,41.9,0.0," + ",".join(f"{p:.6g}" for p in poes)
        written = np.array([float(f"{p:.6g}") for p in poes])
        n_levels = int(np.count_nonzero((written > 0) & (written < 1)))  # poe 1: dropped, warned
        if defect == "rows cut":
            row = row.rsplit(",", 2)[0]
        text = f"{head}\n{cols}\n{row}\n"
        given = draw(st.sampled_from([0.5, 1.0]))
        period = f"period = {given}\n"
        if defect == "period":
            defect = None
        if given != 0.5:
            defect = defect or "period differs from the file's"
    data = text.encode()
    if defect == "system file":
        data = (SYSTEM_LINE + "\n").encode()
    im = "pga" if kind == "two columns" else "sa"
    toml = f'[hazard]\nkind = "file"\nfile = "hazard.csv"\nim = "{im}"\nunits = "g"\n{period}'
    return toml, {"hazard.csv": data}, n_levels, defect


# ------------------------------------------------------------------------------ studies


@st.composite
def studies(draw):
    """(study text, {file name: bytes}, what an accepted study must hold, defects)."""
    recs = draw(st.lists(record_files(), min_size=1, max_size=3))
    declared = draw(st.sampled_from(["g", "g", "m/s2", "cm/s2"]))
    files, defects = {}, []
    for k, (name, data, _stored, defect) in enumerate(recs):
        files[f"records/r{k}_{name}"] = data
        if defect:
            defects.append(f"record {defect}")
    if any(n.endswith(".AT2") for n in files) and declared != "g":
        declared = "g"  # .AT2 files are in g whatever the units: a sure refusal, tested apart
    obj_toml, obj_files, n_obj, obj_defect = draw(objects_section())
    files.update(obj_files)
    if obj_defect:
        defects.append(f"objects {obj_defect}")
    design = draw(st.sampled_from(["cloud", "ida", "stripes"]))
    haz_toml, haz_files, n_levels, haz_defect = draw(hazard_section(design))
    files.update(haz_files)
    if haz_defect:
        defects.append(f"hazard {haz_defect}")
    top = draw(
        st.sampled_from(["", "", "friction = 0.6\n", "friction = 0.6\n", "friction = 20.0\n"])
    )
    if top == "friction = 20.0\n":
        defects.append("friction above 10")
    motion = f'[motion]\nkind = "record"\nfiles = "records"\nunits = "{declared}"\n'
    if design == "stripes":
        levels = '{ dist = "grid", values = [0.2, 0.5] }'
        motion += f'scale_to = {{ im = "pga", units = "g", value = {levels} }}\n'
    design_toml = f'[design]\nkind = "{design}"\n'
    if design == "ida":
        design_toml += "step = 0.1\nscan = 0\ntolerance = 0.05\nmax_pga_ratio = 8\n"
    if "SA(" in haz_files.get("hazard.csv", b"").decode("latin-1"):
        design_toml += "periods = [0.5]\n"
    text = f'name = "fuzz"\nseed = 3\n{top}{obj_toml}{motion}{design_toml}{haz_toml}'
    expect = {"records": len(recs), "objects": n_obj, "levels": n_levels}
    return text, files, expect, defects


def _write(folder: Path, files: dict) -> None:
    for name, data in files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)


def _judge_refusal(err: StudyError) -> None:
    assert err.problems, "a StudyError without problems"
    for line in err.problems:
        assert FIELD.match(line), f"a problem that names no field: {line!r}"
        assert SYSTEM_LINE not in line and "daemon:x:1:1" not in line, f"quotes a file: {line!r}"
        assert "Traceback" not in line and "\\x" not in line, line


def _run_in_process(study, base_dir) -> None:
    """Every row of the design evaluated as its dask task would: all ok and finite."""
    design = make_design(study, base_dir)
    cols = {k: design[k].values for k in design.data_vars if design[k].dims == ("sample",)}
    cols["sample"] = design["sample"].values
    size = study.rows_per_chunk()
    for a in range(0, cols["sample"].size, size):
        out = evaluate_chunk(
            study.normalized(), {k: v[a : a + size] for k, v in cols.items()}, base_dir
        )
        bad = out["status"] != STATUS_OK
        assert not bad.any(), f"{int(bad.sum())} rows failed: {set(out['error'][bad].tolist())}"


TALLY: dict[str, int] = {}


def _count(what):
    TALLY[what] = TALLY.get(what, 0) + 1


@FUZZ
@given(studies(), st.integers(0, 9))
def test_a_study_is_refused_by_field_or_accepted_whole_and_runs(case, pick):
    text, files, expect, defects = case
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _write(folder, files)
        (folder / "study.toml").write_text(text)
        try:
            with time_limit(SECONDS, "validate"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                study = validate_text(text, base_dir=folder)
        except StudyError as err:
            _judge_refusal(err)
            _count("refused")
            return
        assert not defects, f"accepted although {defects}:\n{text}"
        _count("accepted")
        from rockstudy.study.spec.feasibility import record_pairs

        assert len(record_pairs(study.motion, folder)) == expect["records"], "a record dropped"
        assert len(study.structure.objects) == expect["objects"], "an object dropped"
        if expect["levels"] is not None and study.hazard is not None:
            assert len(study.hazard.curve().levels) == expect["levels"], "a hazard level dropped"
        if pick == 0:  # one accepted study in ten runs, in-process
            with time_limit(SECONDS, "the run"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                _run_in_process(study, folder)
            _count("run")


# ------------------------------------------------------------------------------ API

#: Values that are no valid argument of a numeric parameter anywhere, or valid only in range.
HOSTILE = st.sampled_from(
    [
        "0.3",
        "50",
        "yes",
        True,
        False,
        None,
        math.nan,
        math.inf,
        -math.inf,
        -1.0,
        0.0,
        1e300,
        1e-300,
        10**9,
        -3,
        [0.1, "0.2"],
        [True, 2.0],
        [],
        np.array([np.nan, 1.0]),
        1 + 2j,
        object(),
        "parsecs",
        "x\x00y",
    ]
)


def _pga_curve():
    return risk.HazardCurve("pga", HAZARD_LEVELS_G, HAZARD_RATES, units="g")


@pytest.fixture(scope="module")
def design():
    """A small IDA of two named objects under three synthetic records."""
    from rockstudy.study.designs.records import incremental_dynamic_analysis

    recs = [
        rs.motions.synthetic_near_fault(pulse_period=tp, pga=4.0, seed=k, duration=4.0)
        for k, tp in enumerate((0.5, 0.8, 1.2))
    ]
    objects = {"A": rs.Block(0.8, 0.2), "B": rs.Block(0.5, 0.25)}
    return incremental_dynamic_analysis(recs, objects, step=0.1, scan=0, tolerance=0.05)


@pytest.fixture(scope="module")
def result():
    return rs.simulate(rs.Block(0.8, 0.2), rs.motions.SinePulse(4.0, 0.6))


def _templates(design, result, folder):
    """name -> (callable(**kwargs), valid kwargs)."""
    csv = folder / "curve.csv"
    csv.write_text(
        "pga,rate\n"
        + "".join(f"{x},{r}\n" for x, r in zip(HAZARD_LEVELS_G, HAZARD_RATES, strict=True))
    )
    H = _pga_curve()
    return {
        "HazardCurve": (
            lambda **k: risk.HazardCurve(**k),
            {"im": "pga", "levels": HAZARD_LEVELS_G, "rates": HAZARD_RATES, "units": "g"},
        ),
        "power_law": (
            lambda **k: risk.HazardCurve.power_law(**k),
            {"k0": 2e-4, "k": 2.3, "units": "g"},
        ),
        "from_csv": (
            lambda **k: risk.HazardCurve.from_csv(csv, **k),
            {"im": "pga", "units": "g", "site": None},
        ),
        "annual_rate": (
            lambda **k: risk.annual_rate(**k),
            {"median": 0.3, "dispersion": 0.4, "hazard": H, "units": "g"},
        ),
        "probability_in": (lambda **k: risk.probability_in(**k), {"years": 50.0, "rate": 1e-3}),
        "object_risk": (
            lambda **k: rs.study.object_risk(design, **k),
            {
                "hazard": H,
                "years": 50.0,
                "n_boot": 3,
                "conf_level": 0.9,
                "seed": 0,
                "min_overturning": 5,
            },
        ),
        "simulate": (
            lambda **k: rs.simulate(rs.Block(0.8, 0.2), rs.motions.SinePulse(4.0, 0.6), **k),
            {"friction": 0.6},
        ),
        "plot": (lambda **k: result.plot(**k), {"ax": None}),
        "contact": (lambda **k: design.rocking.contact(**k), {"friction": 0.5}),
        "risk accessor": (
            lambda **k: design.rocking.risk(**k),
            {"hazard": H, "years": 50.0, "n_boot": 3},
        ),
    }


def _finite(value) -> bool:
    import xarray as xr

    if isinstance(value, (xr.Dataset, xr.DataArray, risk.HazardCurve)) or value is None:
        return True  # a dataset may hold NaN where it says so (its status); a curve validated
    if hasattr(value, "figure") or hasattr(value, "get_figure"):
        return True  # an axes
    if isinstance(value, rs.RockingResult):
        return bool(np.isfinite(value.max_rotation) and np.isfinite(value.friction_demand))
    arr = np.asarray(value, dtype=float)
    return bool(np.all(np.isfinite(arr)))


@pytest.fixture(scope="module")
def templates(design, result, tmp_path_factory):
    return _templates(design, result, tmp_path_factory.mktemp("api"))


@FUZZ
@given(data=st.data())
def test_an_api_call_answers_finitely_or_names_its_argument(templates, data):
    import matplotlib.pyplot as plt

    name = data.draw(st.sampled_from(sorted(templates)))
    function, valid = templates[name]
    names = data.draw(st.lists(st.sampled_from(sorted(valid)), min_size=1, max_size=2, unique=True))
    kwargs = dict(valid)
    for arg in names:
        kwargs[arg] = data.draw(HOSTILE)
    try:
        with time_limit(20, name), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            value = function(**kwargs)
    except (ValueError, TypeError) as err:
        message = str(err)
        assert any(arg in message for arg in names), f"{name}{names}: {message!r}"
        assert "\n" not in message.strip() or name == "object_risk", message
        _count(f"api refused {name}")
        return
    finally:
        plt.close("all")
    assert _finite(value), f"{name}({kwargs}) -> {value!r}"
    _count(f"api answered {name}")


def _register(name, function, **kw):
    from rockstudy.motions import register_measure

    return register_measure(name, function, **kw)


MEASURE_FUNCTIONS = {
    "nan": lambda rec: math.nan,
    "inf": lambda rec: math.inf,
    "negative": lambda rec: -1.0,
    "raises": lambda rec: 1 / 0,
    "string": lambda rec: "1.0",
    "fine": lambda rec: float(np.max(np.abs(rec.acceleration))),
}


@FUZZ
@given(
    st.sampled_from(sorted(MEASURE_FUNCTIONS)),
    st.sampled_from(["m/s^2", "g", "parsecs", "", None]),
    st.sampled_from([1, 0.5, 0, -1, "1", True, math.nan]),
)
def test_a_registered_measure_is_checked_when_registered_and_harms_no_other(kind, unit, power):
    """A measure that cannot give a finite positive value, or a unit or power outside the
    registry's, is refused naming the measure (or the argument); whatever happened, the
    built-in measures of a record still come out finite."""
    from rockstudy.motions import measures

    name = f"fuzz_{kind}_{abs(hash((unit, str(power)))) % 10**6}"
    try:
        _register(name, MEASURE_FUNCTIONS[kind], unit=unit, power=power, replace=True)
    except (ValueError, TypeError) as err:
        message = str(err)
        assert name in message or any(w in message for w in ("unit", "power", "function")), message
        _count("measure refused")
    else:
        assert kind == "fine", f"a measure that returns {kind} was registered"
        assert unit not in ("parsecs", "", None) and power in (1, 0.5, 0), (unit, power)
        _count("measure registered")
    finally:
        measures.MEASURES.pop(name, None)
    rec = rs.motions.synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=1, duration=3.0)
    values = rec.intensity_measures()
    assert all(np.isfinite(v) for v in values.values() if np.ndim(v) == 0)


def test_zz_the_fuzz_reports_its_counts(capsys):
    """Prints the tallies (run with -s to see them); every kind of outcome was reached."""
    with capsys.disabled():
        print("\nfuzz tallies:", dict(sorted(TALLY.items())))
    assert TALLY.get("refused", 0) and TALLY.get("accepted", 0)
