"""Fuzz of generated study files: each ends in a clear validate error naming the field, or in
a run whose every sample succeeds. Never a traceback, a hang, or failed samples.

A seeded generator writes valid studies (every structure, motion and sampler kind, small n)
and broken ones (typos, wrong types, inf/NaN, out-of-range and derived values, bad record
files, sizes beyond the machine, deep nesting, garbage, hostile strings). All are validated
in-process as ``load_study`` does for ``rockstudy validate``; a handful also through the real
command line. The accepted ones are run in-process, chunk evaluation without dask (the
function each dask task runs), and every sample must come back ok with finite outputs.
"""

import json
import math
import random
import subprocess
from collections import Counter
from pathlib import Path
from typing import get_args

import numpy as np
import pytest
from _helpers import cli, time_limit

from rockstudy.dynamics import outputs as outputs_table
from rockstudy.motions.suites import RECORD_SUFFIXES
from rockstudy.study import StudyError, load_study
from rockstudy.study.designs.sampling import make_design
from rockstudy.study.running.evaluate import STATUS_OK, evaluate_chunk
from rockstudy.study.spec.samplers import SAMPLERS, kinds_laid_out
from rockstudy.study.spec.schema import Output

N_FILES = 240
SEED = 20261125
PLUMBING = ("tagged-union", "function-after", "Input should", "Value error", "Extra inputs")
HOSTILE = [
    "<script>alert(document.domain)</script>",
    "\"'><img src=x onerror=alert(1)>",
    "../../../etc/passwd",
    "\u202eevil\u0000nul",
    "x" * 5000,
]


# ---------------------------------------------------------------------- TOML writing


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else repr(v)  # inf, -inf and 1e+16 are TOML as written
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)  # JSON string escapes are TOML basic-string escapes
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return "{ " + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + " }"


def toml_key(k):
    return k if k.replace("_", "").replace("-", "").isalnum() and k.isascii() else json.dumps(k)


def to_toml(study: dict) -> str:
    lines = [
        f"{toml_key(k)} = {toml_value(v)}" for k, v in study.items() if not isinstance(v, dict)
    ]
    for k, v in study.items():
        if isinstance(v, dict):
            lines.append(f"\n[{toml_key(k)}]")
            lines += [f"{toml_key(kk)} = {toml_value(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------- record files


def write_records(folder: Path):
    """Good records (a two-column file and an .AT2) and bad ones, by name."""
    folder.mkdir()
    t = np.arange(300) * 0.01
    a = 0.3 * np.sin(2 * np.pi * 1.5 * t) * np.exp(-0.5 * t)
    (folder / "good.csv").write_text(
        "".join(f"{x:.17g}, {y:.17g}\n" for x, y in zip(t, a, strict=True))
    )
    body = "\n".join(" ".join(f"{x:.6E}" for x in a[i : i + 5]) for i in range(0, a.size, 5))
    head = "PEER NGA RECORD\nsynthetic\nACCELERATION TIME SERIES IN UNITS OF G\n"
    (folder / "good.AT2").write_text(head + f"NPTS= {a.size}, DT= .0100 SEC\n" + body + "\n")
    bad = {
        "empty.csv": "",
        "nan.csv": "0.0, 0.1\n0.01, nan\n0.02, 0.1\n",
        "backwards.csv": "0.0, 0.1\n0.02, 0.2\n0.01, 0.1\n",
        "one_column.csv": "0.1\n0.2\n0.3\n",
        "words.csv": "time, acc\nsecret, 0.2\n",
        "short.AT2": head + "NPTS= 500, DT= .01 SEC\n0.1 0.2 0.3\n",
        "noheader.AT2": "just\nthree\nlines\n",
        "zero.csv": "0.0, 0.0\n0.01, 0.0\n0.02, 0.0\n",
    }
    for name, text in bad.items():
        (folder / name).write_text(text)
    (folder / "binary.csv").write_bytes(bytes(range(256)) * 4)
    (folder / "folder.csv").mkdir()
    broken = sorted(bad) + ["binary.csv", "folder.csv", "missing.csv"]
    return ["records/good.csv", "records/good.AT2"], ["records/" + b for b in broken] + [
        "/proc/self/environ",
        "/dev/zero",
    ]


# ---------------------------------------------------------------------- the generator


class Gen:
    def __init__(self, rng: random.Random, good_records):
        self.r = rng
        self.good_records = good_records

    def dist(self, low, high, positive=True):
        """A random distribution (or fixed number) within [low, high]."""
        r = self.r
        lo, hi = sorted((r.uniform(low, high), r.uniform(low, high)))
        if hi - lo < 1e-3 * (high - low):
            hi = lo + 0.1 * (high - low)
        kind = r.choice(["fixed", "uniform", "loguniform", "truncnormal", "triangular", "choice"])
        if kind == "fixed":
            return round(r.uniform(lo, hi), 4)
        if kind == "uniform":
            return {"dist": "uniform", "low": lo, "high": hi}
        if kind == "loguniform" and positive:
            return {"dist": "loguniform", "low": lo, "high": hi}
        if kind == "truncnormal":
            return {
                "dist": "truncnormal",
                "mean": (lo + hi) / 2,
                "sigma": hi - lo,
                "low": lo,
                "high": hi,
            }
        if kind == "triangular":
            return {"dist": "triangular", "low": lo, "mode": r.uniform(lo, hi), "high": hi}
        return {"dist": "choice", "values": [round(r.uniform(lo, hi), 4) for _ in range(3)]}

    def structure(self):
        r = self.r
        kind = r.choice(["block", "block", "rocking_wall", "equivalent_block"])
        if kind == "block":
            s = {
                "kind": kind,
                "half_diagonal": self.dist(0.3, 5.0),
                "slenderness": self.dist(0.05, 0.4),
            }
            if r.random() < 0.4:
                s["restitution"] = self.dist(0.6, 0.95)
            elif r.random() < 0.3:
                s["restitution"] = "housner"
            return s
        if kind == "rocking_wall":
            return {
                "kind": kind,
                "half_diagonal": self.dist(0.5, 4.0),
                "slenderness": self.dist(0.05, 0.3),
                "restitution": self.dist(0.6, 0.95),
            }
        return {
            "kind": kind,
            "frequency_parameter": self.dist(1.0, 5.0),
            "critical_rotation": self.dist(0.05, 0.4),
            "restitution": self.dist(0.6, 0.95),
        }

    def motion(self):
        r = self.r
        kind = r.choice(["pulse", "pulse", "pulse", "record", "stochastic"])
        if kind == "pulse":
            m = {"kind": kind, "shape": r.choice(["sine", "cosine", "half-sine", "ricker"])}
            which = r.choice(["amplitude", "amplitude_ratio", "amplitude_a"])
            m[which] = self.dist(*{"amplitude": (0.5, 10.0)}.get(which, (0.5, 6.0)))
            if r.random() < 0.5:
                m["period"] = self.dist(0.1, 2.0)
            else:
                m["frequency_ratio"] = self.dist(0.5, 12.0)
            if m["shape"] in ("sine", "cosine") and r.random() < 0.3:
                m["cycles"] = r.choice([1, 2, 3])
            if r.random() < 0.3:
                m["direction"] = r.choice([1, -1])
            return m
        if kind == "record":
            files = r.sample(self.good_records, r.choice([1, 2]))
            if r.random() < 0.3:  # a glob, relative to the study file
                files = "records/good.*"
            m = {"kind": kind, "files": files, "units": "g"}
            way = r.random()
            if way < 0.35:
                m["scale"] = self.dist(0.2, 3.0)
            elif way < 0.7:
                m["pga_ratio"] = self.dist(0.5, 5.0)
            else:  # a target measure: dimensional (SI) or a group
                im, low, high = r.choice(
                    [
                        ("pga", 1.0, 8.0),
                        ("pgv", 0.1, 1.0),
                        ("sa", 1.0, 10.0),
                        ("pga_ratio", 0.5, 5.0),
                        ("pgv_ratio", 0.2, 2.0),
                    ]
                )
                m["scale_to"] = {"im": im, "value": self.dist(low, high)}
                if im == "sa":
                    m["scale_to"]["period"] = r.choice([0.2, 0.5, 1.0])
            return m
        return {
            "kind": kind,
            "pga_ratio": self.dist(0.5, 3.0),
            "duration": r.choice([4.0, 8.0]),
            "dt": r.choice([0.01, 0.02]),
        }

    def study(self):
        r = self.r
        st, mo = self.structure(), self.motion()
        distributed = [
            (part, k)
            for part in (st, mo, mo.get("scale_to", {}))
            for k, v in part.items()
            if isinstance(v, dict) and k != "scale_to"
        ]
        if not distributed:  # at least one distributed parameter (all-fixed: issue 12, h4)
            key = "half_diagonal" if "half_diagonal" in st else "frequency_parameter"
            st[key] = {"dist": "uniform", "low": 1.0, "high": 2.0}
            distributed = [(st, key)]
        kind = r.choice([*kinds_laid_out("random"), *SAMPLERS])  # every sampler of the registry
        if SAMPLERS[kind].layout == "saltelli" and len(distributed) < 2:
            kind = r.choice(kinds_laid_out("random"))
        sampler = {"kind": kind}
        if SAMPLERS[kind].layout == "grid":
            for part, k in distributed:
                lo, hi = self._bounds(part[k])
                part[k] = {"dist": "grid", "low": lo, "high": hi, "n": r.choice([2, 3])}
        elif SAMPLERS[kind].layout == "saltelli":
            sampler["n"] = r.choice([2, 4])  # powers of two
        else:
            sampler["n"] = r.randint(3, 16)
        # the outputs of Housner's model (the contact model's need [run] model and friction)
        contact_model = outputs_table.names("contact_model")
        outputs = [name for name in get_args(Output) if name not in contact_model]
        method = r.choice(["nonlinear", "nonlinear", "linear", "auto"])
        run = {
            "method": method,
            "rtol": 1e-2 if method == "auto" else r.choice([1e-8, 1e-6]),
            "outputs": r.sample(outputs, r.randint(1, 4)),
        }
        return {
            "name": f"fuzz{r.randint(0, 10**6)}",
            "description": "generated",
            "seed": r.randint(0, 2**31 - 1),
            "chunk_size": r.choice([4, 16, 4096]),
            "sampler": sampler,
            "structure": st,
            "motion": mo,
            "run": run,
        }

    @staticmethod
    def _bounds(d):
        if not isinstance(d, dict):
            return d, d * 1.1
        if d["dist"] == "choice":
            return min(d["values"]), max(d["values"]) * 1.01
        return d["low"], d["high"]


def param_paths(study):
    """(section, key) of every numeric parameter, and (section, key, bound) of dist bounds."""
    out = []
    for sec in ("structure", "motion"):
        for k, v in study[sec].items():
            if (
                isinstance(v, float | int)
                and not isinstance(v, bool)
                and k not in ("cycles", "direction")
            ):
                out.append((sec, k, None))
            elif isinstance(v, dict):
                out += [(sec, k, b) for b, x in v.items() if isinstance(x, float)]
    return out


def mutate(g: Gen, study: dict, bad_records):
    """A broken (or hostile but valid) variant: (text or dict, category, field it must name)."""
    r = g.r
    cat = r.choice(
        [
            "typo",
            "type",
            "type",
            "nonfinite",
            "nonfinite",
            "range",
            "housner",
            "records",
            "records",
            "huge",
            "nesting",
            "hostile",
            "hostile",
            "structural",
            "garbage",
            "solver",
        ]
    )
    sec, key, bound = r.choice(param_paths(study))
    where = f"{sec}.{key}" + (f".{bound}" if bound else "")

    def put(value):
        if bound:
            study[sec][key][bound] = value
        else:
            study[sec][key] = value

    if cat == "typo":
        sec = r.choice(["structure", "motion", "sampler", "run"])
        key = r.choice([k for k in study[sec] if k != "kind"] or ["kind"])
        typo = key[:-1] if len(key) > 3 else key + "x"
        study[sec][typo] = study[sec].pop(key)
        return study, cat, f"{sec}.{typo}"
    if cat == "type":
        choice = r.randrange(5)
        if choice == 0:
            put(str(r.uniform(0.1, 1)))
            return study, cat, where
        if choice == 1:
            put(True)
            return study, cat, where
        if choice == 2:
            study["run"]["rtol"] = "1e-8"
            return study, cat, "run.rtol"
        if choice == 3 and "n" in study["sampler"]:
            study["sampler"]["n"] = float(study["sampler"]["n"])
            return study, cat, "sampler.n"
        study["seed"] = r.choice([True, "7", 7.5])
        return study, cat, "seed"
    if cat == "nonfinite":
        put(r.choice([math.inf, -math.inf, math.nan]))
        return study, cat, where
    if cat == "range":  # <= 0 is outside every parameter's range (a scale of 0 is no motion)
        sec, key, bound = r.choice([p for p in param_paths(study) if p[2] != "mean"])
        put(0.0 if key == "scale" and not bound else r.choice([-1.0, 0.0, -1e300]))
        return study, cat, f"{sec}.{key}"
    if cat == "housner":
        study["structure"] = {
            "kind": "block",
            "half_diagonal": 1.0,
            "slenderness": {"dist": "uniform", "low": 0.1, "high": r.uniform(0.96, 1.5)},
        }
        if study["sampler"]["kind"] == "grid":
            study["structure"]["slenderness"] = {"dist": "grid", "low": 0.1, "high": 1.2, "n": 2}
        study["sampler"].pop("replicates", None)
        return study, cat, "structure.slenderness"
    if cat == "records":
        files = list(g.good_records)
        bad = r.choice(bad_records)
        i = r.randrange(len(files) + 1)
        files.insert(i, bad)
        study["motion"] = {"kind": "record", "files": files, "pga_ratio": 2.0}
        if "zero" in bad or r.random() < 0.5:
            study["motion"]["pga_ratio"] = {"dist": "uniform", "low": 1.0, "high": 3.0}
        if study["sampler"]["kind"] == "grid":
            study["motion"]["pga_ratio"] = {"dist": "grid", "values": [1.0, 2.0]}
        if study["sampler"]["kind"] == "sobol":  # the new motion may leave Sobol' one parameter:
            study["sampler"] = {"kind": "lhs", "n": 4}  # one fault per file, the record's
        return study, cat, f"motion.files[{i}]"
    if cat == "huge":
        choice = r.randrange(4)
        if choice == 0:
            study["sampler"] = {"kind": "monte_carlo", "n": 10**12}
            _ungrid(study)
            return study, cat, "sampler"
        if choice == 1:
            study["sampler"] = {"kind": "grid"}
            study["structure"] = {
                "kind": "block",
                "half_diagonal": {"dist": "grid", "low": 0.5, "high": 2.0, "n": 10**8},
                "slenderness": {"dist": "grid", "low": 0.1, "high": 0.3, "n": 10**8},
            }
            study["motion"] = {"kind": "pulse", "amplitude_ratio": 2.0, "period": 0.5}
            return study, cat, "sampler"
        study["sampler"] = {"kind": "monte_carlo", "n": 4}
        study["motion"] = {
            "kind": "stochastic",
            "pga_ratio": 2.0,
            "duration": [1e7, 1e5, math.inf][choice - 2 if choice < 3 else r.randrange(3)],
        }
        _ungrid(study)
        return study, cat, "motion.duration"
    if cat == "solver":  # settings under which no sample can finish
        if study["motion"]["kind"] == "pulse" and r.random() < 0.5:
            study["motion"]["shape"] = "sine"
            study["motion"]["cycles"] = r.choice([10**4, 10**6])
            return study, cat, "motion.cycles"
        study["run"]["rtol"] = r.choice([1e-15, 1e-300])
        return study, cat, "run.rtol"
    if cat == "nesting":
        depth = r.choice([50, 2000, 100_000])
        text = to_toml(study) + r.choice(
            [
                "[extra]\nx = " + "[" * depth + "]" * depth + "\n",
                "[extra]\nx = " + "{a = " * depth + "1" + "}" * depth + "\n",
                "[" + "a." * depth + "b]\nc = 1\n",
            ]
        )
        return text, cat, "nest"
    if cat == "hostile":  # valid: strings are data, escaped where shown
        key, text = r.choice(["name", "description"]), r.choice(HOSTILE)
        study[key] = text
        if key == "name" and "\0" in text:  # a NUL is no name (issue 26)
            return study, "hostile", "name"
        return study, "hostile", None
    if cat == "structural":
        choice = r.randrange(4)
        if choice == 0:
            del study["structure"]["kind"]
            return study, cat, "structure.kind"
        if choice == 1:
            study["sampler"] = {"kind": "sobol", "n": 100}
            _ungrid(study)
            return study, cat, "sampler.n"
        if choice == 2 and bound:
            study[sec][key]["dist"] = "unifrom"
            return study, cat, f"{sec}.{key}.dist"
        del study["seed"]
        return study, cat, "seed"
    text = to_toml(study)
    garbage = r.choice(
        [text[: r.randrange(len(text))] + "= = =", "\x00\x01binary", "[[[", "name = 'x\n"]
    )
    return garbage, "garbage", ""  # any file-level message


def _ungrid(study):
    """Turn grid parameters into uniform ones (for a non-grid sampler)."""
    for sec in ("structure", "motion"):
        for k, v in study[sec].items():
            if isinstance(v, dict) and v.get("dist") == "grid":
                lo = v["low"] if "low" in v else min(v["values"])
                hi = v["high"] if "high" in v else max(v["values"]) * 1.01
                study[sec][k] = {"dist": "uniform", "low": lo, "high": hi}


# ---------------------------------------------------------------------- the test


def run_in_process(study, base_dir):
    """Evaluate every row as the dask tasks would, chunk by chunk; return the failures."""
    design = make_design(study, base_dir)
    cols = {k: design[k].values for k in design.data_vars if design[k].dims == ("sample",)}
    cols["sample"] = design["sample"].values
    n = cols["sample"].size
    problems = []
    size = study.rows_per_chunk()
    for a in range(0, n, size):
        part = {k: v[a : a + size] for k, v in cols.items()}
        out = evaluate_chunk(study.normalized(), part, base_dir)
        bad = out["status"] != STATUS_OK
        if bad.any():
            problems.append(f"{int(bad.sum())} failed: {set(out['error'][bad].tolist())}")
        for name in study.run.outputs:
            if (
                name in out
                and name in ("max_rotation", "max_rotation_ratio")
                and not np.all(np.isfinite(out[name]))
            ):
                problems.append(f"{name} not finite")
    for name, var in design.data_vars.items():
        if var.dtype.kind == "f" and not np.all(np.isfinite(var.values)):
            problems.append(f"design column {name} not finite")
    return problems


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    """The generated files: (path, category, field it must name or None if valid)."""
    folder = tmp_path_factory.mktemp("fuzz")
    good, bad = write_records(folder / "records")
    rng = random.Random(SEED)
    g = Gen(rng, good)
    files = []
    for i in range(N_FILES):
        study = g.study()
        if rng.random() < 0.3:
            content, cat, field = study, "valid", None
        else:
            content, cat, field = mutate(g, study, bad)
        path = folder / f"study_{i:03d}_{cat}.toml"
        if isinstance(content, dict):
            content = to_toml(content)
        path.write_bytes(content.encode("utf-8", "surrogatepass"))
        files.append((path, cat, field))
    return folder, files


def test_fuzz_each_file_is_refused_by_field_or_runs_clean(corpus, capsys):
    folder, files = corpus
    counts, anything_else, by_category = Counter(), [], Counter()
    for path, cat, field in files:
        try:
            with time_limit(20, f"validate {path.name}"):
                study = load_study(path)
        except StudyError as exc:
            message = str(exc)
            ok = all(w not in message for w in PLUMBING) and all(": " in p for p in exc.problems)
            if field is not None and field not in message:
                ok = False
            if ok:
                counts["refused"] += 1
                by_category[f"{cat}: refused"] += 1
            else:
                anything_else.append(f"{path.name}: unclear refusal (expected {field}): {message}")
            continue
        except Exception as exc:  # a traceback in the real CLI
            anything_else.append(f"{path.name}: {type(exc).__name__}: {exc}"[:500])
            continue
        mo = study.motion
        if study.samples() > 10**5 or (mo.kind == "stochastic" and mo.points() > 10**6):
            anything_else.append(f"{path.name} ({cat}): accepted a study too large to run")
            continue
        try:
            with time_limit(120, f"run {path.name}"):
                problems = run_in_process(study, folder)
        except Exception as exc:  # a traceback of the run
            problems = [f"{type(exc).__name__}: {exc}"]
        if problems:
            anything_else.append(f"{path.name} ({cat}): accepted but {problems}"[:800])
        else:
            counts["succeeded"] += 1
            by_category[f"{cat}: succeeded"] += 1
            if field is not None:
                anything_else.append(f"{path.name}: accepted although it breaks {field}")
    with capsys.disabled():
        print(
            f"\nfuzz of {len(files)} study files: {dict(counts)}, anything else: "
            f"{len(anything_else)}; by category: {dict(sorted(by_category.items()))}"
        )
    assert not anything_else, "\n".join(anything_else)
    assert len(files) >= 200 and counts["refused"] >= 50 and counts["succeeded"] >= 50


def _validate_in_process(paths, seconds=300):
    """``rockstudy validate PATHS`` through ``rockstudy.cli.main`` in this process (a file that
    would be read without end fails by the time limit): a finished process's fields."""
    with time_limit(seconds, "rockstudy validate"):
        code, out, err = cli("validate", *paths)
    return subprocess.CompletedProcess(["validate", *paths], code, out, err)


def test_fuzz_files_through_the_cli(corpus):
    """A handful of the same files through ``rockstudy validate``: exit 2 with the problems,
    or 0 with ok; never a traceback."""
    folder, files = corpus
    picked, valid = {}, set()
    for path, cat, field in files:  # one file of each category
        if cat not in picked:
            picked[cat] = path
            if field is None:
                valid.add(cat)
    paths = [str(p) for p in picked.values()]
    out = _validate_in_process(paths)
    assert "Traceback" not in out.stderr, out.stderr[-3000:]
    for cat, path in picked.items():
        if cat in valid:
            assert f"{path}: ok" in out.stdout, (cat, out.stdout, out.stderr[-2000:])
        else:
            assert f"{path}: " in out.stderr and "problem(s)" in out.stderr, (cat, out.stderr)
    assert out.returncode == 2


# ====================================================================== record studies
#
# A second generator (issue 26): record studies, most of them [design]s (cloud, stripes,
# IDA), over record files the test writes: good ones in every format (both .AT2 headers,
# two- and three-column text, H/V pairs, folders, globs) and pathological ones (extreme
# steps and values, a time column to 1.7e308, subnormals, a FIFO, a link to /dev/zero, a
# dangling link, a folder named x.AT2). Each file must be refused naming the field (and the
# file), or run with every record and every sample present and ok.

N_RECORD_FILES = 300
RECORD_SEED = 20261127
AT2_HEAD = "PEER NGA RECORD\nsynthetic\nACCELERATION TIME SERIES IN UNITS OF G\n"


def _wave(seed, n=200, dt=0.01):
    """A short pulse-like motion in g: a decaying sine plus a little noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    f = 1.0 + seed % 3
    return 0.3 * np.sin(2 * np.pi * f * t) * np.exp(-t) + 0.01 * rng.standard_normal(n)


def _at2(path, values, dt="0.0100", old_header=False):
    body = "\n".join(
        " ".join(f"{x:.6E}" for x in values[i : i + 5]) for i in range(0, len(values), 5)
    )
    head = (
        f"  {len(values)}   {dt}   NPTS, DT" if old_header else f"NPTS= {len(values)}, DT= {dt} SEC"
    )
    path.write_text(AT2_HEAD + head + "\n" + body + "\n")


def _csv(path, t, values, vertical=None):
    cols = [t, values] if vertical is None else [t, values, vertical]
    path.write_text(
        "".join(", ".join(f"{float(c[i])!r}" for c in cols) + "\n" for i in range(len(t)))
    )


#: Pathological record files: name -> (how to make it in a folder, words the refusal names).
def _pathological():
    import os

    t = np.arange(200) * 0.01
    w = _wave(99)
    big, tiny, huge_t = w.copy(), w.copy(), t.copy()
    big[7], tiny[3], huge_t[-1] = 1e300, 1e-320, 1.7e308
    return {
        "dt_huge.AT2": (lambda p: _at2(p, w, "1e300"), "duration"),
        "dt_tiny.AT2": (lambda p: _at2(p, w, "1e-300"), "dt"),
        "dt_nano.AT2": (lambda p: _at2(p, w, "1e-9"), "dt"),
        "value_huge.AT2": (lambda p: _at2(p, big, ".01"), "acceleration[7]"),
        "subnormal.AT2": (lambda p: _at2(p, tiny * 1e-3, ".01"), "subnormal"),
        "time_huge.csv": (lambda p: _csv(p, huge_t, w), "duration"),
        "nan.csv": (lambda p: p.write_text("0.0, 0.1\n0.01, nan\n0.02, 0.1\n"), "finite"),
        "empty.csv": (lambda p: p.write_text(""), "empty"),
        "fifo.AT2": (lambda p: os.mkfifo(p), "FIFO"),
        "zero_link.AT2": (lambda p: p.symlink_to("/dev/zero"), "device"),
        "dangling.AT2": (lambda p: p.symlink_to(p.with_name("nowhere.AT2")), "dangling"),
        "folder.AT2": (lambda p: p.mkdir(), "folder"),
        "short.AT2": (lambda p: p.write_text(AT2_HEAD + "NPTS= 500, DT= .01 SEC\n0.1\n"), "NPTS"),
    }


def write_record_suite(root: Path):
    """Good and pathological record files under ``root``; returns what the generator needs."""
    root.mkdir()
    good = []
    for i in range(4):
        _at2(root / f"g{i}.AT2", _wave(i), old_header=i % 2 == 1)
        good.append(f"g{i}.AT2")
    t = np.arange(200) * 0.01
    _csv(root / "g4.csv", t, _wave(4))
    good.append("g4.csv")
    _at2(root / "hv0_H.AT2", _wave(5))
    _at2(root / "hv0_UP.AT2", 0.2 * _wave(6))
    _at2(root / "hv1_H.AT2", _wave(7))
    _at2(root / "hv1_UP.AT2", 0.2 * _wave(8))
    (root / "suite").mkdir()
    for i in range(3):
        _at2(root / "suite" / f"s{i}.AT2", _wave(10 + i))
    bad = {}
    for name, (make, words) in _pathological().items():
        make(root / name)
        folder = root / f"bad_{Path(name).stem}"
        folder.mkdir()
        for i in range(2):
            _at2(folder / f"ok{i}.AT2", _wave(20 + i))
        make(folder / name)
        bad[name] = (words, folder)
    return good, bad


class RecordGen:
    """Record studies: valid ones, and one mutation each for the broken ones."""

    def __init__(self, rng, good, bad):
        self.r, self.good, self.bad = rng, good, bad

    def structure(self):
        r = self.r
        if r.random() < 0.8:
            s = {
                "kind": "block",
                "half_diagonal": {"dist": "uniform", "low": 0.5, "high": r.choice([1.0, 3.0])},
                "slenderness": {"dist": "uniform", "low": 0.1, "high": 0.3},
            }
            if r.random() < 0.3:
                s["restitution"] = 0.9
            return s
        return {
            "kind": "equivalent_block",
            "frequency_parameter": {"dist": "uniform", "low": 1.5, "high": 4.0},
            "critical_rotation": {"dist": "uniform", "low": 0.1, "high": 0.3},
            "restitution": 0.9,
        }

    def files(self):
        r = self.r
        way = r.random()
        if way < 0.5:
            return r.sample(self.good, r.randint(1, 3)), None, None
        if way < 0.65:
            return "suite", None, None
        if way < 0.8:
            return "suite/*.AT2", None, None
        if way < 0.9:
            return "hv*_H.AT2", {"match": "_H\\.AT2$", "replace": "_UP.AT2"}, None
        pairs = [{"horizontal": "hv0_H.AT2", "vertical": "hv0_UP.AT2"}]
        return pairs, None, None

    def study(self):
        r = self.r
        files, vertical, _ = self.files()
        motion = {"kind": "record", "files": files}
        if vertical:
            motion["vertical"] = vertical
        design_kind = r.choice(["cloud", "stripes", "ida", "ida", None])
        study = {
            "name": f"rec{r.randint(0, 10**6)}",
            "seed": r.randint(0, 2**31 - 1),
            "sampler": {"kind": r.choice(kinds_laid_out("random")), "n": r.randint(1, 3)},
            "structure": self.structure(),
            "motion": motion,
            "run": {"method": r.choice(["nonlinear", "nonlinear", "auto"]), "rtol": 1e-6,
                    "outputs": ["max_rotation", "overturned"]},
        }  # fmt: skip
        if study["run"]["method"] == "auto":
            study["run"]["rtol"] = 1e-2
        if design_kind is None:
            study["sampler"]["n"] = r.randint(2, 6)
            study["chunk_size"] = r.choice([2, 16])
            way = r.random()
            if way < 0.35:
                motion["scale"] = {"dist": "uniform", "low": 0.5, "high": 2.0}
            elif way < 0.7:
                motion["pga_ratio"] = {"dist": "uniform", "low": 0.8, "high": 3.0}
            else:
                motion["scale_to"] = {
                    "im": "pga",
                    "value": {"dist": "uniform", "low": 1.0, "high": 6.0},
                }
            return study
        design = {"kind": design_kind, "periods": r.sample([0.2, 0.5, 1.0], r.randint(0, 2))}
        if design_kind == "stripes":
            levels = sorted(r.sample([1.0, 1.5, 2.0, 3.0, 4.5], r.randint(1, 3)))
            motion["scale_to"] = {"im": "pga_ratio", "value": {"dist": "grid", "values": levels}}
        if design_kind == "ida":  # a short ladder (its options are checked elsewhere)
            design.update(step=0.25, tolerance=0.1, max_pga_ratio=8.0, scan=1)
        study["design"] = design
        return study


def mutate_record_study(g: RecordGen, study: dict):
    """A broken (or hostile but valid) variant: (text or dict, category, words it must name)."""
    r = g.r
    mo = study["motion"]
    cat = r.choice(
        ["file", "file", "folder", "glob", "range", "range", "counts", "name", "hostile"]
    )
    if cat in ("file", "folder", "glob"):
        name = r.choice(sorted(g.bad))
        words, folder = g.bad[name]
        mo.pop("vertical", None)
        if cat == "file":
            files = r.sample(g.good, r.randint(1, 2))
            i = r.randrange(len(files) + 1)
            files.insert(i, name)
            mo["files"] = files
            return study, f"{cat}:{name}", [f"motion.files[{i}]", name, words]
        mo["files"] = folder.name if cat == "folder" else f"{folder.name}/*"
        return study, f"{cat}:{name}", ["motion.files", name, words]
    if cat == "range":
        de = study.get("design")
        choices = ["name"]
        if de is not None:
            choices += ["damping", "periods"]
        if de is None:
            choices += ["scale", "pga_ratio", "target"]
        if de is not None and de["kind"] == "stripes":
            choices += ["levels"]
        what = r.choice(choices)
        if what == "damping":
            de["damping"] = r.choice([1.5, -0.1])
            return study, "range:damping", ["design.damping"]
        if what == "periods":
            de["periods"] = [r.choice([1e-300, 1e300, 0.0, -1.0])]
            return study, "range:periods", ["design.periods"]
        if what == "levels":
            mo["scale_to"]["value"]["values"] = [1.0, r.choice([1e300, 1e6])]
            return study, "range:levels", ["motion.scale_to.value"]
        if what in ("scale", "pga_ratio", "target"):
            for k in ("scale", "pga_ratio", "scale_to"):
                mo.pop(k, None)
            value = r.choice([1e300, 1e12])
            if what == "target":
                mo["scale_to"] = {"im": r.choice(["pga", "pgv"]), "value": value}
                return study, "range:target", ["motion.scale_to.value"]
            mo[what] = value
            return study, f"range:{what}", [f"motion.{what}"]
        study["run"]["max_steps"] = r.choice([0, 10**13])
        return study, "range:max_steps", ["run.max_steps"]
    if cat == "counts":
        what = r.choice(["n", "seed", "chunk"])
        if what == "n":
            study["sampler"]["n"] = r.choice([0, -3])
            return study, "counts:n", ["sampler.n"]
        if what == "seed":
            study["seed"] = -1
            return study, "counts:seed", ["seed"]
        study["chunk_size"] = r.choice([0, 10**13])
        return study, "counts:chunk", ["chunk_size"]
    if cat == "name":
        study["name"] = "a\0b"
        return study, "name:nul", ["name"]
    study["name"] = r.choice(HOSTILE[:3])  # markup and paths are data: valid
    return study, "hostile", None


def record_corpus(folder: Path, n_files: int, seed: int = RECORD_SEED):
    """Write ``n_files`` record studies under ``folder``: [(path, category, words)]."""
    good, bad = write_record_suite(folder / "recs")
    rng = random.Random(seed)
    g = RecordGen(rng, good, bad)
    files = []
    for i in range(n_files):
        study = g.study()
        if rng.random() < 0.4:
            content, cat, words = study, "valid", None
        else:
            content, cat, words = mutate_record_study(g, study)
        path = folder / "recs" / f"study_{i:03d}.toml"
        path.write_text(to_toml(content))
        files.append((path, cat, words))
    return files


def expected_records(study, base_dir) -> int:
    """How many records a study names, counted independently of the design code: the files
    of its list, or the entries its folder or glob finds (verticals not counted)."""
    import glob as _glob

    files = study.motion.files
    if isinstance(files, list):
        return len(files)
    path = Path(base_dir) / files
    names = (
        _glob.glob(str(path))
        if any(c in files for c in "*?[")
        else [str(p) for p in path.iterdir() if p.suffix.lower() in RECORD_SUFFIXES]
    )
    if study.motion.vertical is not None:
        names = [n for n in names if "_UP" not in n]
    return len(names)


def judge_record_study(path, cat, words, run=True):
    """One outcome for one file: (kind, detail) with kind refused / succeeded / a failure:
    traceback, hang, unclear, accepted-broken, dropped, failed-run."""
    try:
        with time_limit(60, f"validate {path.name}"):
            study = load_study(path)
    except StudyError as exc:
        message = str(exc)
        if any(w in message for w in PLUMBING) or not all(": " in p for p in exc.problems):
            return "unclear", message[:600]
        missing = [w for w in words or [] if w not in message]
        if words is None or missing:
            return "unclear", f"expected {words}, missing {missing}: {message[:600]}"
        return "refused", None
    except TimeoutError as exc:
        return "hang", str(exc)
    except Exception as exc:
        return "traceback", f"{type(exc).__name__}: {exc}"[:600]
    if words is not None:
        return "accepted-broken", f"accepted although it breaks {words}"
    if not run:
        return "succeeded", None
    try:
        with time_limit(60, f"run {path.name}"):
            design = make_design(study, path.parent)
            problems = run_in_process(study, path.parent)
    except TimeoutError as exc:
        return "hang", str(exc)
    except Exception as exc:
        return "traceback", f"run: {type(exc).__name__}: {exc}"[:600]
    if problems:
        return "failed-run", str(problems)[:600]
    if study.design is not None:
        n_rec = expected_records(study, path.parent)
        rows = n_rec * study.samples()
        found = np.unique(design["record"].values).size
        if found != n_rec or design["sample"].size != rows:
            return "dropped", f"{found} of {n_rec} records, {design['sample'].size} of {rows} rows"
    elif design["sample"].size != study.samples():
        return "dropped", f"{design['sample'].size} of {study.samples()} samples"
    return "succeeded", None


def fuzz_record_studies(folder: Path, n_files: int = N_RECORD_FILES, seed: int = RECORD_SEED):
    """Counts of outcomes (overall and by category) and the failures, for the test and for
    benchmarks/fuzz_report.py."""
    files = record_corpus(folder, n_files, seed)
    counts, by_category, failures = Counter(), Counter(), []
    for path, cat, words in files:
        kind, detail = judge_record_study(path, cat, words)
        counts[kind] += 1
        by_category[f"{cat.split(':')[0]}: {kind}"] += 1
        if kind not in ("refused", "succeeded"):
            failures.append(f"{path.name} ({cat}): {kind}: {detail}")
    return files, counts, by_category, failures


def test_fuzz_record_studies_refused_by_field_or_run_with_nothing_dropped(tmp_path, capsys):
    files, counts, by_category, failures = fuzz_record_studies(tmp_path)
    designs = sum(1 for p, _, _ in files if "[design]" in p.read_text())
    with capsys.disabled():
        print(
            f"\nfuzz of {len(files)} record study files ({designs} designs): {dict(counts)}; "
            f"by category: {dict(sorted(by_category.items()))}"
        )
    assert not failures, "\n".join(failures)
    assert len(files) >= 300 and designs > len(files) / 2
    assert counts["refused"] >= 100 and counts["succeeded"] >= 50


def _cli_block(stderr: str, path: str) -> str:
    """The problems the command line printed for ``path`` (its line and the indented ones)."""
    lines = stderr.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(f"{path}: "):
            block = [line]
            for more in lines[i + 1 :]:
                if not more.startswith("  "):
                    break
                block.append(more)
            return "\n".join(block)
    return ""


def test_record_study_files_through_the_cli(tmp_path):
    """One record study of each category through ``rockstudy validate``: exit 2 with the
    problems naming the field and the file, or ok; never a traceback."""
    files = record_corpus(tmp_path, 120)
    picked = {}
    for path, cat, words in files:
        picked.setdefault(cat.split(":")[0] if words is None else cat, (path, words))
    paths = [str(p) for p, _ in picked.values()]
    out = _validate_in_process(paths)
    assert "Traceback" not in out.stderr, out.stderr[-3000:]
    for path, words in picked.values():
        if words is None:
            assert f"{path}: ok" in out.stdout, (path, out.stdout, out.stderr[-2000:])
        else:
            block = _cli_block(out.stderr, str(path))
            assert block and all(w in block for w in words), (path, words, out.stderr[-3000:])
    assert out.returncode == 2 and len(picked) >= 8
