"""Helpers shared by the test modules: writers of small study and record files, the
``rockstudy`` command run in this process, small datasets of known capacities, a time limit.

Test modules import from here (and take fixtures from ``conftest.py``), never from one another
(tests/test_architecture.py holds that).
"""

import contextlib
import io
import logging
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import warnings
from pathlib import Path
from unittest import mock

import numpy as np
import xarray as xr

from rockstudy import simulate_batch
from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.motions import synthetic_near_fault

ROOT = Path(__file__).resolve().parents[1]
#: The installed ``rockstudy`` command (for the few tests that need a real process).
ROCKSTUDY = str(Path(sys.executable).with_name("rockstudy"))

# --------------------------------------------------------------------- the pulse studies

BASE = """
name = "t"
seed = 7
chunk_size = {chunk}

[sampler]
kind = "{sampler}"
n = {n}

[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 3.0 }}
slenderness = {{ dist = "uniform", low = 0.1, high = 0.3 }}

[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = {{ dist = "uniform", low = 0.8, high = 5.0 }}
period = {{ dist = "loguniform", low = 0.1, high = 2.0 }}

[run]
outputs = ["max_rotation", "overturned", "n_impacts", "first_impact_time"]
max_steps = {max_steps}
"""

SLOW = """
name = "slow"
seed = 11
chunk_size = {chunk}

[sampler]
kind = "monte_carlo"
n = {n}

[structure]
kind = "block"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 2.0 }}
slenderness = {{ dist = "uniform", low = 0.15, high = 0.3 }}

[motion]
kind = "stochastic"
pga_ratio = {{ dist = "uniform", low = 0.8, high = 2.5 }}
duration = 20.0

[run]
outputs = ["max_rotation", "overturned", "n_impacts"]
"""


def study_text(chunk=100, sampler="monte_carlo", n=600, max_steps=1_000_000):
    """The text of the pulse study of the study-layer tests."""
    return BASE.format(chunk=chunk, sampler=sampler, n=n, max_steps=max_steps)


def write_study(folder, n=60, chunk=10, seed=7, name="study.toml"):
    """The pulse study of ``n`` samples in chunks of ``chunk``, written to ``folder/name``."""
    path = Path(folder) / name
    path.write_text(study_text(chunk=chunk, n=n).replace("seed = 7", f"seed = {seed}"))
    return path


# ------------------------------------------------------------------ the rockstudy command


@contextlib.contextmanager
def _process_state_kept():
    """What a ``rockstudy`` command changes in its process, put back afterwards: the working
    folder, numpy's print options, dask's log levels and the registered intensity measures."""
    from rockstudy.motions import measures

    cwd = os.getcwd()
    printing = np.get_printoptions()
    loggers = ["distributed"] + [
        n for n in logging.root.manager.loggerDict if n.startswith("distributed.")
    ]
    levels = {name: logging.getLogger(name).level for name in loggers}
    registered = dict(measures.MEASURES)
    try:
        yield
    finally:
        os.chdir(cwd)
        np.set_printoptions(**printing)
        for name in logging.root.manager.loggerDict:
            if name.startswith("distributed."):
                logging.getLogger(name).setLevel(levels.get(name, logging.NOTSET))
        logging.getLogger("distributed").setLevel(levels["distributed"])
        measures.MEASURES.clear()
        measures.MEASURES.update(registered)


@contextlib.contextmanager
def _warnings_as_python_shows_them():
    """The warnings of the block, as a fresh Python process would show them on stderr (its
    default filters; not pytest's, which records them out of sight): yields the list that
    receives them; the warnings filters are put back afterwards."""
    with warnings.catch_warnings(record=True) as said:
        warnings.resetwarnings()
        warnings.simplefilter("default")
        for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning):
            warnings.simplefilter("ignore", category)
        warnings.simplefilter("ignore", ResourceWarning)
        yield said


def _threads_cluster(workers):
    """A local cluster of ``workers`` threads in this process (for ``rockstudy run --workers``
    run in this process: no worker process to start)."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=1, threads_per_worker=workers or 1, processes=False, dashboard_address=":0"
    )


def cli(*args):
    """``rockstudy ARGS`` run in this process through ``rockstudy.cli.main``: (exit code,
    stdout, stderr). A local run's workers are threads of this process; its warnings are on
    stderr (after its lines) as Python shows them; the process state the command changes is
    put back (see ``_process_state_kept``)."""
    from rockstudy import cli as rockstudy_cli
    from rockstudy.study.running import runner

    out, err = io.StringIO(), io.StringIO()
    with (
        _process_state_kept(),
        _warnings_as_python_shows_them() as said,
        mock.patch.object(runner, "_local_cluster", _threads_cluster),
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        try:
            code = rockstudy_cli.main([str(a) for a in args])
        except SystemExit as exc:  # argparse's refusals
            code = exc.code
    shown = (warnings.formatwarning(w.message, w.category, w.filename, w.lineno) for w in said)
    return code, out.getvalue(), err.getvalue() + "".join(shown)


def rockstudy_run(study, out, *extra):
    """``rockstudy run STUDY --out OUT --workers 1 --quiet EXTRA`` in this process: (exit code,
    stdout, stderr)."""
    return cli("run", study, "--out", out, "--workers", "1", "--quiet", *extra)


def rockstudy_process(*args, timeout=300, **kw):
    """A real ``rockstudy ARGS`` process: (exit code, stdout, stderr)."""
    proc = subprocess.run(
        [ROCKSTUDY, *map(str, args)], capture_output=True, text=True, timeout=timeout, **kw
    )
    return proc.returncode, proc.stdout, proc.stderr


def one_line(text):
    """The one non-blank line of ``text`` (no traceback)."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in text, text
    return lines[0]


def one_error_line(err):
    """The one line of ``err``, which starts with ``error: ``."""
    line = one_line(err)
    assert line.startswith("error: "), err
    return line


def run_on_scheduler_file(study, out, sched):
    """The one error line of ``rockstudy run`` of ``study`` on the scheduler file ``sched``
    (with a timeout of 3 s), which must exit 1."""
    code, _, err = cli(
        "run", study, "--out", out, "--scheduler-file", sched, "--timeout", "3", "--quiet"
    )
    assert code == 1
    return one_error_line(err)


def assert_engine_results(cube):
    """The cube holds what the engine computes for its design rows (an independent call)."""
    ref = simulate_batch(
        half_diagonal=cube["half_diagonal"].values,
        slenderness=cube["slenderness"].values,
        pulse="sine",
        amplitude=cube["amplitude"].values,
        period=cube["period"].values,
    )
    assert np.all(cube["status"].values == 1)
    np.testing.assert_array_equal(cube["max_rotation"].values, ref["max_rotation"])
    np.testing.assert_array_equal(cube["n_impacts"].values, ref["n_impacts"])


def tree(folder):
    """Every file of a folder and its bytes (the lock names its last holder: left out)."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(Path(folder).rglob("*"))
        if p.is_file() and p.name != ".rockstudy.lock"
    }


def finished_run(folder, n=60, chunk=10):
    """A finished run of the pulse study in ``folder``: (study file, store)."""
    study = write_study(folder, n=n, chunk=chunk)
    out = Path(folder) / "cube.zarr"
    code, _, err = rockstudy_run(study, out)
    assert code == 0, err
    return study, out


# ------------------------------------------------------------------------------ records


def write_at2(path, record):
    """A PEER .AT2 file of ``record`` (in g)."""
    values = record.acceleration / STANDARD_GRAVITY
    lines = [
        "PEER STRONG MOTION DATABASE RECORD",
        "synthetic near-fault record for the tests",
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS= {values.size}, DT= {record.dt:.4f} SEC",
    ]
    lines += [" ".join(f"{v:.9e}" for v in values[i : i + 5]) for i in range(0, values.size, 5)]
    path.write_text("\n".join(lines) + "\n")


def write_ground_pairs(folder, n, x, y, duration):
    """``n`` ground pairs of synthetic near-fault pulses in ``folder``: ``p{i}_X.AT2`` and
    ``p{i}_Y.AT2`` for i = 0 .. n - 1.

    ``x`` and ``y`` describe the two components as ``(period, step, pga, seed)``: pair i's
    component is the pulse of period ``period + step * i`` s, that ``pga`` (in g) and seed
    ``seed + i``, ``duration`` s long.
    """
    for i in range(n):
        for part, (period, step, pga, seed) in (("X", x), ("Y", y)):
            rec = synthetic_near_fault(
                pulse_period=period + step * i, pga=pga, seed=seed + i, duration=duration
            )
            write_at2(folder / f"p{i}_{part}.AT2", rec)
    return folder


def write_near_fault_pairs(folder):
    """Three synthetic near-fault records in ``folder``: horizontal ``nf{i}_H.AT2`` and
    vertical ``nf{i}_UP.AT2`` files."""
    from rockstudy.motions import Record

    for i, tp in enumerate((0.5, 0.8, 1.2)):
        rec = synthetic_near_fault(
            pulse_period=tp, pga=3.0, seed=10 + i, duration=5.0, vertical=True
        )
        write_at2(folder / f"nf{i}_H.AT2", rec)
        write_at2(folder / f"nf{i}_UP.AT2", Record(rec.vertical, dt=rec.dt))
    return folder


def write_two_records(folder):
    """Two small synthetic near-fault records ``r0.AT2``, ``r1.AT2`` in ``folder``."""
    for i, tp in enumerate((0.5, 1.0)):
        rec = synthetic_near_fault(pulse_period=tp, pga=3.0, seed=20 + i, duration=4.0)
        write_at2(folder / f"r{i}.AT2", rec)
    return folder


def unit_sine_record(omega_ratio, half_diagonal=1.0):
    """One cycle of a unit sine pulse, then rest: overturning is monotone in its scale."""
    from rockstudy.motions import Record
    from rockstudy.structures.block import frequency_parameter

    T = 2 * np.pi / (omega_ratio * frequency_parameter(half_diagonal))
    dt = T / 200
    t = np.arange(0, 3 * T, dt)
    return Record(np.where(t <= T, np.sin(2 * np.pi * t / T), 0.0), dt=dt, name="sine")


#: The head of the block studies on records: three Latin-hypercube blocks.
RECORD_STUDY_HEAD = """
name = "designs"
seed = 5
[sampler]
kind = "lhs"
n = 3
[structure]
kind = "block"
half_diagonal = { dist = "uniform", low = 0.3, high = 1.2 }
slenderness = { dist = "uniform", low = 0.15, high = 0.25 }
"""

#: A museum study of listed objects on a folder of records, in stripes of PGA.
STUDY_OBJECTS = """
name = "museum"
seed = 1
[structure]
kind = "objects"
{objects}
[motion]
kind = "record"
files = "{folder}"
scale_to = {{ im = "pga", value = {{ dist = "grid", values = [2.0, 5.0] }} }}
[design]
kind = "stripes"
"""

#: An IDA museum study on the package's records (``{records}``) and a ``{hazard}`` section.
HAZARD_STUDY = """
name = "museum"
seed = 1
[structure]
kind = "objects"
objects = [{{ name = "Statue <A> & B", width = 0.45, height = 1.9 }}]
[motion]
kind = "record"
files = "{records}/NF0[12]*_H.AT2"
[design]
kind = "ida"
periods = [0.5]
{hazard}
"""


def rows_study(folder, where, motion_extra, n=6):
    """A Monte Carlo block study of ``n`` rows on the ``*_H.AT2`` records of ``folder``."""
    from rockstudy.study import load_study

    text = RECORD_STUDY_HEAD.replace('kind = "lhs"\nn = 3', f'kind = "monte_carlo"\nn = {n}') + (
        f'[motion]\nkind = "record"\nfiles = "{folder}/*_H.AT2"\n{motion_extra}\n'
        '[run]\noutputs = ["max_rotation", "overturned"]\n'
    )
    path = where / "rows.toml"
    path.write_text(text)
    return load_study(path)


def run_rows(study, where):
    """Every row of ``study`` evaluated as one task would: (design, outputs); all succeed."""
    from rockstudy.study.designs.sampling import make_design
    from rockstudy.study.running.evaluate import STATUS_OK, evaluate_chunk

    design = make_design(study, where)
    cols = {k: v.values for k, v in design.data_vars.items() if v.dims == ("sample",)}
    cols["sample"] = design["sample"].values
    out = evaluate_chunk(study.normalized(), cols, where)
    assert np.all(out["status"] == STATUS_OK), out["error"]
    return design, out


#: Real records of the shared folder (``records_dir``) used by the rocking tests.
REAL_RECORD_FILES = [
    "RSN126_GAZLI_GAZ000.AT2",
    "RSN183_IMPVALL.H_H-E08140.AT2",
    "RSN948_NORTHR_CAM009.AT2",
    "RSN982_NORTHR_JEN292.AT2",
    "elcentro_NS.dat",
]


def load_real_record(records_dir, name):
    """A real record of the shared folder (.AT2, or a two-column file in g)."""
    import rockstudy as rs

    path = records_dir / name
    return (
        rs.motions.Record.from_at2(path)
        if name.endswith(".AT2")
        else rs.motions.Record.from_csv(path, units="g")
    )


#: Examples of the structure kinds' fields (a frame, an arch, a rocking wall).
FRAME = dict(
    half_width=0.2,
    height=1.5,
    height_right=1.2,
    beam_length=3.0,
    beam_half_depth=0.2,
    mass_beam=2.0,
    restitution=0.8,
)
ARCH = dict(inclusion_angle=math.pi, thickness=0.2, radius=1.0, restitution=0.7)
WALL = dict(half_diagonal=1.5, slenderness=0.12, restitution=0.85)


# ------------------------------------------------------------- datasets of known capacities

#: A power-law hazard lambda(x) = K0 x^-K, x in g.
K0, K = 2e-4, 2.3


def pga_ida(capacities_g, censored=None, names=None):
    """An IDA dataset of capacities [g of PGA] on (record, structure): every record has a
    PGA of 1 g, so the capacity scale is the capacity in g."""
    cap = np.asarray(capacities_g, float)
    cens = np.zeros(cap.shape, bool) if censored is None else np.asarray(censored)
    n_rec, n_st = cap.shape
    names = names or [f"object {j}" for j in range(n_st)]
    return xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, G_UNIT)),
            "capacity_scale": (("record", "structure"), np.where(cens, np.nan, cap)),
            "capacity_scale_lower": (("record", "structure"), cap / 1.001),
            "censored": (("record", "structure"), cens),
            "status": (("record", "structure"), np.zeros(cap.shape, int)),
        },
        coords={"structure": names},
        attrs={"design": "ida", "im": "pga"},
    )


def lognormal_sample(theta, beta, n, seed):
    """``n`` draws of a lognormal of median ``theta`` and log standard deviation ``beta``."""
    return theta * np.exp(beta * np.random.default_rng(seed).standard_normal(n))


def ida_dataset(capacity_scale, pga, pgv, uplift, p, censored=None, sa=None):
    """A dataset shaped like records_designs.incremental_dynamic_analysis's output."""
    cap = np.asarray(capacity_scale, float)
    cens = np.zeros(cap.shape, bool) if censored is None else np.asarray(censored)
    sa = np.asarray(pga, float)[:, None] if sa is None else sa
    ds = xr.Dataset(
        {
            "pga": ("record", np.asarray(pga, float)),
            "pgv": ("record", np.asarray(pgv, float)),
            "sa": (("record", "period"), sa),
            "uplift_acceleration": ("structure", np.asarray(uplift, float)),
            "frequency_parameter": ("structure", np.asarray(p, float)),
            "capacity_scale": (("record", "structure"), np.where(cens, np.nan, cap)),
            "capacity_scale_lower": (("record", "structure"), cap / 1.01),
            "censored": (("record", "structure"), cens),
            "status": (("record", "structure"), np.zeros(cap.shape, np.int64)),
        },
        coords={"period": [1.0], "structure": np.arange(cap.shape[1])},
        attrs={"design": "ida", "im": "pga", "im_period": np.nan},
    )
    ds["pga_ratio"] = ds["pga"] / ds["uplift_acceleration"]
    ds["pgv_ratio"] = ds["pgv"] * ds["frequency_parameter"] / ds["uplift_acceleration"]
    return ds


#: Relative tolerance of the constructed IDA's capacities (their lower bracket).
IDA_TOL = 0.01


def constructed_ida(theta, beta=0.4, n_rec=7):
    """IDA layout with capacities ln c_jk = ln theta_k + beta z_j, z symmetric about 0: the
    lognormal MLE median of class k is exactly theta_k [g]."""
    z = np.linspace(-1.5, 1.5, n_rec)
    cap = np.asarray(theta)[None, :] * np.exp(beta * z)[:, None]  # PGA [g]
    n = len(theta)
    return xr.Dataset(
        {
            "pga": ("record", np.full(n_rec, G_UNIT)),  # 1 g: the scale is the capacity in g
            "half_diagonal": ("structure", np.geomspace(0.3, 5.0, n)),
            "capacity_scale": (("record", "structure"), cap),
            "capacity_scale_lower": (("record", "structure"), cap / (1 + IDA_TOL)),
            "censored": (("record", "structure"), np.zeros((n_rec, n), bool)),
            "status": (("record", "structure"), np.zeros((n_rec, n), np.int64)),
        },
        attrs={"design": "ida", "im": "pga"},
    )


def rocking_with_falls(n=4000, seed=3):
    """Samples whose survivors' peak rotation ratio depends on the amplitude alone, and whose
    overturned samples carry the fall rotation pi/2 over alpha (the cube's convention): any
    index of alpha on the ratio comes from the falls."""
    rng = np.random.default_rng(seed)
    alpha, amp = rng.uniform(0.05, 0.3, n), rng.uniform(1.0, 5.0, n)
    over = (amp > 2.0).astype(np.int8)  # all but the weakest pulses overturn
    ratio = np.where(over == 1, 0.5 * np.pi / alpha, 0.1 * amp)
    return xr.Dataset(
        {
            "slenderness": ("sample", alpha),
            "amplitude_ratio": ("sample", amp),
            "overturned": ("sample", over),
            "max_rotation_ratio": ("sample", ratio),
        }
    )


# ------------------------------------------------------------------------------ Ishigami

#: The Ishigami study: three uniform inputs, each mapped onto [-pi, pi].
ISHIGAMI = """
name = "ishigami"
seed = 3
[sampler]
kind = "sobol"
n = {n}
[structure]
kind = "equivalent_block"
frequency_parameter = {{ dist = "uniform", low = 1.0, high = 3.0 }}
critical_rotation = {{ dist = "uniform", low = 0.1, high = 0.2 }}
restitution = {{ dist = "uniform", low = 0.5, high = 0.9 }}
[motion]
kind = "pulse"
amplitude_ratio = 2.0
frequency_ratio = 1.0
"""


def ishigami_cube(n=2**13):
    """The Ishigami function on the study pipeline's own design: make_design draws the
    scrambled Sobol' points in the Saltelli layout and maps them through the three uniform
    distributions; each input is mapped back linearly onto [-pi, pi]."""
    from SALib.test_functions import Ishigami

    from rockstudy.study import make_design, validate_text

    study = validate_text(ISHIGAMI.format(n=n))
    ds = make_design(study)
    names = list(study.parameters())
    x = np.column_stack(
        [
            -math.pi + 2 * math.pi * (ds[name].values - dist.low) / (dist.high - dist.low)
            for name, dist in study.parameters().items()
        ]
    )
    assert x.min() >= -math.pi and x.max() <= math.pi
    ds["y"] = ("sample", Ishigami.evaluate(x))
    ds["status"] = ("sample", np.ones(ds.sizes["sample"], np.int8))
    ds.attrs["study"] = study.normalized()
    return ds, names


def ishigami_analytic(a=7.0, b=0.1):
    """The first-order and total Sobol' indices of the Ishigami function (analytic)."""
    v1 = 0.5 * (1 + b * math.pi**4 / 5) ** 2
    v2 = a * a / 8
    v13 = b * b * math.pi**8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return np.array([v1, v2, 0.0]) / v, np.array([v1 + v13, v2, v13]) / v


# ------------------------------------------------------------------------------- others


@contextlib.contextmanager
def time_limit(seconds, what):
    """Raise TimeoutError in the block after ``seconds`` (SIGALRM; the main thread only)."""

    def fail(*_):
        raise TimeoutError(f"{what} took more than {seconds} s")

    old = signal.signal(signal.SIGALRM, fail)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def chromium_dom(page, profile, budget_ms=5000, extra=(), timeout=120):
    """``page`` opened in headless Chromium (its profile in the folder ``profile``) for
    ``budget_ms`` of virtual time: the finished process, its stdout the page's DOM."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    assert exe, "headless Chromium is needed (make test installs Debian's chromium)"
    return subprocess.run(
        [
            exe,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            *extra,
            f"--user-data-dir={profile}",
            f"--virtual-time-budget={budget_ms}",
            "--dump-dom",
            page.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def chromium_figures(page):
    """(figures shown, figures in total) of an HTML report page opened in headless Chromium."""
    out = chromium_dom(page, page.parent / "chromium-profile")
    # the page's own check writes "shown/total" into a data attribute, never into its text
    m = re.search(r'<body[^>]*data-figures="(\d+)/(\d+)"', out.stdout)
    assert m, out.stdout[-2000:]
    return int(m.group(1)), int(m.group(2))


def wide_runs(scales, flags, step):
    """The upper ends of the runs of consecutive True ``flags`` over increasing ``scales``
    that span at least one ladder step (a factor ``1 + step``): a rung lies inside each."""
    flags = np.asarray(flags, bool)
    edges = np.diff(np.concatenate(([0], flags.astype(np.int8), [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    wide = scales[stops] >= scales[starts] * (1.0 + step)
    return list(scales[stops][wide])


def random_stacked_scene(rng, seconds=(1.0, 2.0), peak=(1.0, 3.0)):
    """A random plinth and statue (plinth alpha 0.15-0.35, R 0.6-2 m; statue alpha 0.12-0.3,
    R 0.3-1.2 m and no wider than 0.9 of the plinth; density ratio 0.3-3) and a generated
    record at 0.02 s: ``seconds`` of smoothed white noise under a sine envelope, peaking at
    ``peak`` times G tan(min alpha) (G = 9.81 m/s^2, rockstudy.constants)."""
    from rockstudy.constants import G
    from rockstudy.motions.records import Record
    from rockstudy.structures import Block, StackedBlocks

    a1, r1, a2 = rng.uniform(0.15, 0.35), rng.uniform(0.6, 2.0), rng.uniform(0.12, 0.3)
    r2 = min(rng.uniform(0.3, 1.2), 0.9 * r1 * np.sin(a1) / np.sin(a2))
    pair = StackedBlocks(Block(r1, a1), Block(r2, a2), rng.uniform(0.3, 3.0))
    n = int(rng.uniform(*seconds) / 0.02)
    t = np.arange(n) * 0.02
    acc = np.convolve(rng.normal(size=n), np.ones(5) / 5, "same") * np.sin(np.pi * t / t[-1])
    acc *= G * np.tan(min(a1, a2)) * rng.uniform(*peak) / np.abs(acc).max()
    return pair, Record(np.r_[acc, 0.0], dt=0.02)
