"""Time to first result (issue 14): importing compiles and loads no kernel, and after the
warm-up (``rockstudy compile``) a new process, or a dask worker, finds every kernel it runs in
numba's on-disk cache instead of compiling it.

The oracle is numba's own bookkeeping, observed in fresh subprocesses: every compilation goes
through ``numba.core.compiler.compile_extra`` and every cache load through
``numba.core.caching.Cache.load_overload``; the tests count the calls. (The timing targets are
measured by benchmarks/bench_first_result.py, not asserted here.)
"""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
)

COUNTER = """
import numba.core.caching, numba.core.compiler
counts = {"compiled": [], "loaded": 0}
_compile, _load = numba.core.compiler.compile_extra, numba.core.caching.Cache.load_overload

def compile_extra(typingctx, targetctx, func, *args, **kwargs):
    counts["compiled"].append(f"{func.__module__}.{func.__qualname__}")
    return _compile(typingctx, targetctx, func, *args, **kwargs)

def load_overload(self, *args, **kwargs):
    out = _load(self, *args, **kwargs)
    counts["loaded"] += out is not None
    return out

numba.core.compiler.compile_extra = compile_extra
numba.core.caching.Cache.load_overload = load_overload
"""


def run(args, cwd=ROOT, env=ENV, stderr=None):
    """Run ``python args`` in a fresh interpreter; return its standard output (and append its
    standard error to the list ``stderr``, if given)."""
    proc = subprocess.run(
        [sys.executable, *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=1800
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    if stderr is not None:
        stderr.append(proc.stderr)
    return proc.stdout


def run_python(code, cwd=ROOT):
    """Run ``code`` in a fresh interpreter; return the JSON it prints on its last line."""
    return json.loads(run(["-c", textwrap.dedent(code)], cwd).strip().splitlines()[-1])


def test_import_rockstudy_loads_neither_numba_nor_scipy(tmp_path):
    out = run_python(
        """
        import json, sys
        import rockstudy
        print(json.dumps(sorted(m for m in ("numba", "scipy") if m in sys.modules)))
        """,
        cwd=tmp_path,
    )
    assert out == []


def test_importing_every_package_compiles_and_loads_no_kernel(tmp_path):
    out = run_python(
        COUNTER
        + """
import json, sys
import rockstudy
from rockstudy import Block, closedform, motions, similarity, simulate, structures
import rockstudy.study, rockstudy.verification, rockstudy.cli
from rockstudy.closedform import max_rotation, overturning_mode
assert callable(max_rotation) and rockstudy.closedform.sine.d0_star.__name__ == "d0_star"
counts["scipy.signal"] = "scipy.signal" in sys.modules
print(json.dumps(counts))
""",
        cwd=tmp_path,
    )
    assert out == {"compiled": [], "loaded": 0, "scipy.signal": False}


def test_lazy_closed_forms_are_the_ufuncs():
    import pickle

    from rockstudy.closedform import sine

    a, w = np.array([1.5, 3.0]), np.array([0.5, 2.0])
    assert pickle.loads(pickle.dumps(sine.d0_star)) is sine.d0_star
    assert sine.d0_star.nin == 2 and sine.d0_star.types == ["dd->d"]
    # D0* in the product form of eq. (3.9) of [000], from its definition in numpy
    root, den = np.sqrt(a * a - 1.0), w * w + 1.0
    A, B, C = (w * w + w * root) / den, (w * w - w * root) / den, 2.0 * a / den
    e = np.exp((2.0 * np.pi - np.arcsin(1.0 / a)) / w)
    d0 = (A - 0.5 * w * C * e) * (B + 0.5 * w * C / e)
    np.testing.assert_allclose(sine.d0_star(a, w), d0, rtol=1e-13)
    np.testing.assert_allclose(sine.d0_star.outer(a, w).diagonal(), d0, rtol=1e-13)


RECORD_STUDY = """
name = "r"
seed = 3
chunk_size = 4
[sampler]
kind = "monte_carlo"
n = 4
[structure]
kind = "block"
half_diagonal = { dist = "uniform", low = 0.5, high = 3.0 }
slenderness = { dist = "uniform", low = 0.1, high = 0.3 }
[motion]
kind = "record"
files = ["rec.csv"]
units = "m/s2"
pga_ratio = { dist = "uniform", low = 1.5, high = 3.0 }
[run]
method = "METHOD"
outputs = ["max_rotation", "overturned"]
"""


@pytest.fixture(scope="module")
def warmed_up():
    """``rockstudy compile`` in its own process (fast when the cache is already primed)."""
    assert "rockstudy kernels ready" in run(["-m", "rockstudy.cli", "compile"])


def test_after_warm_up_a_new_process_compiles_nothing(warmed_up, tmp_path):
    """Entry points and argument variants beyond the warm-up's own calls, and study chunks
    (pulse, record and stochastic; every batch method) through the dask task function."""
    t = np.arange(0.0, 3.0, 0.01)
    acc = 4.0 * np.sin(2 * np.pi * t) * np.exp(-t)
    np.savetxt(tmp_path / "rec.csv", np.column_stack([t, acc]), delimiter=",")
    for method in ("nonlinear", "linear", "auto"):
        (tmp_path / f"rec_{method}.toml").write_text(RECORD_STUDY.replace("METHOD", method))
    out = run_python(
        COUNTER
        + f"""
import json, re, sys, warnings
import numpy as np
import rockstudy as rs
from rockstudy.motions import CosinePulse, HalfSinePulse, NoMotion, Record
from rockstudy.structures import RockingWall
from rockstudy.study import load_study, make_design, validate_text
from rockstudy.study.running.evaluate import evaluate_chunk

warnings.simplefilter("ignore")
tmp = {str(tmp_path)!r}
block = rs.Block(1.5, 0.15, 0.9)
rec = Record.from_csv(tmp + "/rec.csv", units="m/s2")
for motion in (CosinePulse(5.0, 0.3, cycles=2), HalfSinePulse(-4.0, 0.4), rec.scaled(2.0)):
    for method in ("nonlinear", "linear", "auto"):
        rs.simulate(block, motion, method=method, rtol=1e-6, t_max=4.0)
data = np.loadtxt(tmp + "/rec.csv", delimiter=",")
column = data[:, 1]  # a strided view
frozen = data[:, 1].copy()
frozen.setflags(write=False)
for acc in (column, frozen):
    rs.simulate(block, Record(acc, dt=0.01), method="nonlinear")
    rs.simulate_batch(half_diagonal=1.0, slenderness=0.2, record=Record(acc, dt=0.01))
rs.simulate(block, NoMotion(), initial_rotation=0.05, initial_velocity=0.1)
rs.simulate(RockingWall(1.0, 0.1, 0.85), CosinePulse(3.0, 0.4))
for method in ("nonlinear", "linear", "auto"):
    rs.simulate_batch(frequency_parameter=[2.0, 3.0], slenderness=0.2, restitution=[0.8, 0.9],
                      pulse="cosine", amplitude=6.0, period=[0.3, 0.6], cycles=2, method=method)
    rs.simulate_batch(half_diagonal=2.0, slenderness=[0.1, 0.2], record=rec, scale=[1.0, 3.0],
                      method=method, rtol=1e-6)
rs.closedform.max_rotation(np.array([2.0, 3.0]), 1.5, 0.9, check=False)
rs.closedform.case11_residual_approx(3.0, 1.0, 0.9, check=False)

def chunk(study, base_dir):
    design = make_design(study)
    cols = {{k: v.values for k, v in design.data_vars.items() if v.dims == ("sample",)}}
    cols["sample"] = design["sample"].values
    return evaluate_chunk(study.normalized(), cols, base_dir)

for name in ("quickstart", "auto_method", "wall_equivalent"):
    text = open(f"studies/{{name}}.toml").read()
    text = re.sub(r"(?m)^(n|chunk_size) = [0-9]+", r"\\1 = 8", text)
    chunk(validate_text(text), "studies")
for method in ("nonlinear", "linear", "auto"):
    chunk(load_study(tmp + f"/rec_{{method}}.toml"), tmp)
counts["signatures"] = {{
    f"{{m.__name__}}.{{n}}": len(d.signatures)
    for m in list(sys.modules.values()) if (m.__name__ or "").startswith("rockstudy")
    for n, d in vars(m).items() if type(d).__name__ == "CPUDispatcher" and d.signatures
}}
print(json.dumps(counts))
""",
    )
    assert out["compiled"] == [], out["compiled"]
    assert out["loaded"] > 0
    # one signature per kernel whatever the caller passes (layouts, read-only arrays, scalars)
    assert {k: v for k, v in out["signatures"].items() if v > 1} == {}


#: (name, cache hits, cache misses) of every kernel of a process (its dispatchers' own stats)
DISPATCHER_STATS = (
    "[(n, d.stats.cache_hits, d.stats.cache_misses) for m in list(__import__('sys').modules"
    ".values()) if (m.__name__ or '').startswith('rockstudy') for n, d in vars(m).items() "
    "if type(d).__name__ == 'CPUDispatcher']"
)


def test_a_cold_run_compiles_in_the_client_only_and_no_step_it_cannot_take(tmp_path):
    """From an empty numba cache, ``run_study`` of the quickstart's sine-pulse study compiles
    its kernels once, in the client, saying so, before any worker gets a chunk: every worker
    loads them and compiles nothing. The client compiles the Taylor steps of sine pulses and
    none of the others (the DOP853 step of Ricker wavelets and mechanisms, the record step,
    the mechanism's free-rocking map): ``scene_batch_trig_serial`` on one thread, whose pruned
    branches halve the compile of a pulse study. ``simulate`` of a block under a sine pulse
    then loads the scene kernel the run compiled (same signature) instead of compiling the
    general one (the demo after the quickstart study)."""
    text = (ROOT / "studies" / "quickstart.toml").read_text()
    text = text.replace("n = 20000", "n = 40").replace("= 2500", "= 10")
    assert 'method = "nonlinear"' in text
    code = (
        COUNTER
        + f"""
import json
from distributed import Client, LocalCluster
from rockstudy.study import run_study, validate_text

study = validate_text({text!r})
with (
    LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    as cluster,
    Client(cluster) as client,
):
    run_study(study, {str(tmp_path / "q.zarr")!r}, client=client, netcdf=False)
    stats = client.run(eval, {DISPATCHER_STATS!r}, {{}}).values()
workers = [[(n, sum(h.values()), sum(m.values())) for n, h, m in rows] for rows in stats]
print(json.dumps({{"client": counts["compiled"], "workers": workers}}))
"""
    )
    env = dict(ENV, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"), NUMBA_NUM_THREADS="1")
    err = []
    out = json.loads(run(["-c", code], tmp_path, env, err).strip().splitlines()[-1])
    assert len(out["workers"]) == 2
    for rows in out["workers"]:
        assert {name: misses for name, _, misses in rows if misses} == {}
    hits = {name: hits for rows in out["workers"] for name, hits, _ in rows}
    assert hits.get("scene_batch_trig_serial", 0) >= 1
    assert "compiling the numba kernels" in err[0]  # the cache was cold: the client said so
    names = {name.rsplit(".", 1)[-1] for name in out["client"]}
    assert {"scene_batch_trig_serial", "scene_trig", "phase_trig", "_taylor_trig_attempt"} <= names
    assert not names & {"_dop853_attempt", "step", "_taylor_attempt", "_free_map_table"}
    assert not names & {"scene_batch", "scene_batch_serial", "scene", "phase"}  # general ones
    assert "scene_batch_trig" not in names  # the parallel loop is not compiled for one thread
    code = (
        COUNTER
        + """
import json
from rockstudy import Block, simulate
from rockstudy.motions import SinePulse
r = simulate(Block(1.0, 0.2), SinePulse(5.0, 0.5), t_eval=[0.0, 0.1, 0.2])
print(json.dumps(counts["compiled"]))
"""
    )
    compiled = json.loads(run(["-c", code], tmp_path, env).strip().splitlines()[-1])
    names = {name.rsplit(".", 1)[-1] for name in compiled}
    assert not names & {"scene", "scene_trig", "phase", "phase_trig", "_taylor_trig_attempt"}


def test_run_says_when_it_compiles(monkeypatch, capsys):
    from rockstudy.study.running import runner

    def compiling(study_json, columns, base_dir, on_first_compile):
        on_first_compile()
        return {"compiled": 5, "seconds": 12.5}

    monkeypatch.setattr(runner, "prime_study", compiling)
    runner._prime("{}", {}, None, progress=True)
    err = capsys.readouterr().err
    assert "compiling the numba kernels" in err and "12.5 s" in err
    runner._prime("{}", {}, None, progress=False)
    assert capsys.readouterr().err == ""


def test_warm_up_clears_the_cache_when_a_kernel_source_changes(tmp_path, monkeypatch):
    """numba checks only each kernel's own file; a change in any kernel source (or in the
    constants) clears the package's cache before the warm-up compiles again."""
    from rockstudy.study.running._warmup import purge_stale_cache

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    (tmp_path / "pkg" / "__pycache__").mkdir(parents=True)
    kernel, other = tmp_path / "pkg" / "_k.py", tmp_path / "pkg" / "report.py"
    kernel.write_text("from numba import njit\n")
    other.write_text("import json\n")
    cached = [tmp_path / "pkg" / "__pycache__" / f"_k.f-3.py311.{ext}" for ext in ("nbi", "nbc")]

    def cache():
        for path in cached:
            path.write_bytes(b"x")

    cache()
    assert purge_stale_cache(tmp_path) == 2 and not any(p.exists() for p in cached)
    cache()
    assert purge_stale_cache(tmp_path) == 0  # nothing changed since
    other.write_text("import json, math\n")  # not a kernel source
    assert purge_stale_cache(tmp_path) == 0
    kernel.write_text("from numba import njit\nX = 2\n")
    assert purge_stale_cache(tmp_path) == 2 and not any(p.exists() for p in cached)


def test_compile_counter_sees_compilation_and_not_cache_hits():
    """The warm-up and the runner learn that numba compiles from its "numba:compile" event."""
    from numba import njit

    from rockstudy.study.running._warmup import _CompileCounter

    @njit  # no cache: compiled on its first call
    def twice(x):
        return 2.0 * x

    calls = []
    with _CompileCounter(lambda: calls.append(1)).listening() as counter:
        assert twice(1.5) == 3.0
    assert counter.count == 1 and calls == [1]
    with _CompileCounter(lambda: calls.append(1)).listening() as counter:
        twice(2.5)  # already compiled for float64
    assert counter.count == 0 and calls == [1]
