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
import signal
import subprocess
import sys
from collections import Counter
from contextlib import contextmanager
from pathlib import Path
from typing import get_args

import numpy as np
import pytest

from rockstudy.study import StudyError, load_study
from rockstudy.study.evaluate import STATUS_OK, evaluate_chunk
from rockstudy.study.sampling import make_design
from rockstudy.study.spec import Output

N_FILES = 240
SEED = 20261125
ROCKSTUDY = str(Path(sys.executable).with_name("rockstudy"))
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
        kind = r.choice(["monte_carlo", "monte_carlo", "lhs", "sobol", "grid"])
        if kind == "sobol" and len(distributed) < 2:
            kind = "lhs"
        sampler = {"kind": kind}
        if kind == "grid":
            for part, k in distributed:
                lo, hi = self._bounds(part[k])
                part[k] = {"dist": "grid", "low": lo, "high": hi, "n": r.choice([2, 3])}
        elif kind == "sobol":
            sampler["n"] = r.choice([2, 4])
        else:
            sampler["n"] = r.randint(3, 16)
        outputs = list(get_args(Output))
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
        study[r.choice(["name", "description"])] = r.choice(HOSTILE)
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


@contextmanager
def time_limit(seconds, what):
    def fail(*_):
        raise TimeoutError(f"{what} took more than {seconds} s")

    old = signal.signal(signal.SIGALRM, fail)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def run_in_process(study, base_dir):
    """Evaluate every row as the dask tasks would, chunk by chunk; return the failures."""
    design = make_design(study, base_dir)
    cols = {k: design[k].values for k in design.data_vars if design[k].dims == ("sample",)}
    cols["sample"] = design["sample"].values
    n = cols["sample"].size
    problems = []
    for a in range(0, n, study.chunk_size):
        part = {k: v[a : a + study.chunk_size] for k, v in cols.items()}
        out = evaluate_chunk(study.normalized(), part, base_dir)
        bad = out["status"] != STATUS_OK
        if bad.any():
            problems.append(f"{int(bad.sum())} failed: {set(out['error'][bad].tolist())}")
        for name in study.run.outputs:
            if name in ("max_rotation", "max_rotation_ratio") and not np.all(
                np.isfinite(out[name])
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


def test_fuzz_files_through_the_real_cli(corpus):
    """A handful of the same files through ``rockstudy validate``: exit 2 with the problems,
    or 0 with ok; never a traceback."""
    folder, files = corpus
    picked = {}
    for path, cat, _ in files:  # one file of each category
        picked.setdefault(cat, path)
    paths = [str(p) for p in picked.values()]
    out = subprocess.run(
        [ROCKSTUDY, "validate", *paths], capture_output=True, text=True, timeout=300
    )
    assert "Traceback" not in out.stderr, out.stderr[-3000:]
    for cat, path in picked.items():
        if cat in ("valid", "hostile"):
            assert f"{path}: ok" in out.stdout, (cat, out.stdout, out.stderr[-2000:])
        else:
            assert f"{path}: " in out.stderr and "problem(s)" in out.stderr, (cat, out.stderr)
    assert out.returncode == 2
