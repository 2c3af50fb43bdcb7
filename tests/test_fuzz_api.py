"""Fuzz of the public Python API: every call gives a ValueError or TypeError that
names the argument, or a finite answer, within a time bound. Never another exception, a NaN
or an infinity handed back without a word, or a hang.

A seeded generator takes each public entry point with sane arguments and replaces one
argument at a time by a hostile value (0, negative, 1e-300, 1e300, NaN, inf, a string, a
boolean, None, a list, a subnormal), plus hand-written cases of reported failures and the
extremes of the ranges. Each call is one test (its id is the reproducer), so a failure names
the call. No call is exempt.
"""

from __future__ import annotations

import math
import random
import warnings
from functools import lru_cache

import numpy as np
import pytest
from _helpers import time_limit

import rockstudy as rs
import rockstudy.study as study_api
from rockstudy.motions import (
    CosinePulse,
    HalfSinePulse,
    Record,
    RickerWavelet,
    SinePulse,
    synthetic_near_fault,
)
from rockstudy.motions.stochastic import stochastic_record

#: Entry points whose docstrings promise NaN outside their domain (a marked answer).
NAN_DOCUMENTED = ("closedform.",)

SEED = 20261127
#: Seconds one call may take (kernels are compiled before the clock starts).
CALL_SECONDS = 30
N_CALLS_MIN = 200
#: Hostile values tried on each argument (drawn from HOSTILE by the seeded generator).
PER_ARGUMENT = 6

HOSTILE = {
    "zero": 0.0,
    "negative": -1.0,
    "tiny": 1e-300,
    "huge": 1e300,
    "nan": math.nan,
    "inf": math.inf,
    "-inf": -math.inf,
    "string": "1",
    "bool": True,
    "none": None,
    "list": [1.0, 2.0],
    "subnormal": 5e-324,
}


@lru_cache(maxsize=1)
def record() -> Record:
    """A short, pulse-like record (4 s at 0.01 s)."""
    return synthetic_near_fault(pulse_period=1.0, pga=3.0, seed=3, duration=4.0, dt=0.01)


@lru_cache(maxsize=1)
def noise() -> Record:
    """White noise: no velocity pulse."""
    return Record(np.random.default_rng(1).standard_normal(1000), dt=0.01, name="noise")


@lru_cache(maxsize=1)
def designs() -> dict:
    """A cloud, a stripes design and an IDA on one record and two blocks (cheap)."""
    from rockstudy.study import cloud, incremental_dynamic_analysis, multiple_stripes

    blocks = [rs.Block(1.0, 0.2), rs.Block(2.0, 0.25)]
    recs = [record(), record().scaled(0.8)]
    return {
        "cloud": cloud(recs, blocks, periods=[0.5]),
        "stripes": multiple_stripes(recs, blocks, levels=[2.0, 4.0, 8.0], periods=[0.5]),
        "ida": incremental_dynamic_analysis(recs, blocks, scan=1, tolerance=0.1),
    }


def _block():
    return rs.Block(1.0, 0.2)


def _simulate(**kw):
    return rs.simulate(kw.pop("structure", _block()), kw.pop("motion", SinePulse(3.0, 0.5)), **kw)


def _batch(**kw):
    return rs.simulate_batch(**kw)


def _design(name):
    def call(**kw):
        return getattr(study_api, name)(**kw)

    return call


def _fragility(name, design):
    def call(**kw):
        return getattr(study_api, name)(designs()[design], **kw)

    return call


def _method(name, rec=record):
    def call(**kw):
        return getattr(rec(), name)(**kw)

    return call


#: Entry points: id -> (callable taking keywords, sane keywords, arguments to fuzz).
TARGETS = {
    "Block": (rs.Block, dict(half_diagonal=1.0, slenderness=0.2, restitution=None), None),
    "Block.from_dimensions": (
        rs.Block.from_dimensions,
        dict(width=0.4, height=2.0, restitution=None),
        None,
    ),
    "SinePulse": (SinePulse, dict(amplitude=5.0, period=0.5, cycles=1), None),
    "CosinePulse": (CosinePulse, dict(amplitude=5.0, period=0.5, cycles=2), None),
    "HalfSinePulse": (HalfSinePulse, dict(amplitude=5.0, period=0.5), None),
    "RickerWavelet": (RickerWavelet, dict(amplitude=5.0, period=0.5), None),
    "simulate": (
        _simulate,
        dict(
            method="nonlinear",
            rtol=1e-8,
            t_max=3.0,
            initial_rotation=0.0,
            initial_velocity=0.0,
            max_steps=100000,
            dt_out=None,
        ),
        None,
    ),  # fmt: skip
    "simulate_batch[pulse]": (
        _batch,
        dict(
            half_diagonal=np.array([1.0, 2.0]),
            slenderness=0.2,
            restitution=0.9,
            amplitude=4.0,
            period=0.5,
            cycles=1,
            rtol=1e-8,
            max_steps=100000,
        ),
        None,
    ),  # fmt: skip
    "simulate_batch[record]": (
        _batch,
        dict(frequency_parameter=np.array([2.0, 3.0]), slenderness=0.2, scale=1.5),
        ["frequency_parameter", "slenderness", "scale"],
    ),
    "Record": (
        lambda **kw: Record(**kw),
        dict(acceleration=np.sin(np.arange(200) * 0.1), dt=0.01, name="r", vertical=None),
        None,
    ),
    "Record.scaled": (_method("scaled"), dict(factor=2.0), None),
    "Record.scaled_to": (_method("scaled_to"), dict(value=4.0, im="pga"), None),
    "Record.intensity_measures": (
        _method("intensity_measures"),
        dict(periods=[0.5], damping=0.05),
        None,
    ),
    "synthetic_near_fault": (
        synthetic_near_fault,
        dict(
            pulse_period=1.0,
            pga=3.0,
            seed=0,
            gamma=2.0,
            phase=0.0,
            noise_ratio=1.0,
            duration=6.0,
            dt=0.01,
        ),
        None,
    ),  # fmt: skip
    "stochastic_record": (
        stochastic_record,
        dict(peak=3.0, duration=5.0, dt=0.01, ground_frequency=15.0, ground_damping=0.6, seed=0),
        None,
    ),
    "closedform.max_rotation": (
        lambda **kw: rs.closedform.max_rotation(**kw),
        dict(a=2.0, omega=3.0, eta=0.9),
        None,
    ),
    "closedform.free_rocking_period": (
        lambda **kw: rs.closedform.free_rocking_period(**kw),
        dict(frequency_parameter=2.0, amplitude_ratio=0.5),
        None,
    ),
    "cloud": (
        _design("cloud"),
        dict(records=[], structures=None, periods=[0.5], damping=0.05),
        ["periods", "damping"],
    ),
    "multiple_stripes": (
        _design("multiple_stripes"),
        dict(records=[], structures=None, levels=[2.0, 4.0], im="pga"),
        ["levels"],
    ),
    "stripe_fragility": (
        _fragility("stripe_fragility", "stripes"),
        dict(n_boot=20, conf_level=0.9, seed=0),
        None,
    ),
    "ida_fragility": (
        _fragility("ida_fragility", "ida"),
        dict(n_boot=20, conf_level=0.9, seed=0),
        None,
    ),
}


def _fill(target, kwargs):
    """Late arguments that need objects (records, blocks)."""
    if target == "simulate_batch[record]":
        kwargs.setdefault("record", record())
    if target in ("cloud", "multiple_stripes"):
        kwargs["records"] = [record()]
        kwargs["structures"] = [rs.Block(1.0, 0.2)]
    return kwargs


#: Hand-written cases of reported failures and the extremes of the ranges: (id, call, argument).
EXTRA = [
    ("case:SinePulse(period=1e-300)", lambda: SinePulse(5.0, period=1e-300), "period"),
    ("case:Block(1, 1e-300)", lambda: rs.Block(1, 1e-300), "slenderness"),
    ("case:simulate(dt_out=1e-12)", lambda: _simulate(dt_out=1e-12), "dt_out"),
    (
        "case:simulate_batch(record, amplitude, period)",
        lambda: rs.simulate_batch(
            half_diagonal=1.0, slenderness=0.2, record=record(), amplitude=1.0, period=0.5
        ),
        "record",
    ),
    ("case:simulate(dt_out='0.1')", lambda: _simulate(dt_out="0.1"), "dt_out"),
    ("case:simulate(dt_out=True)", lambda: _simulate(dt_out=True), "dt_out"),
    ("case:Block('1', 0.2)", lambda: rs.Block("1", 0.2), "half_diagonal"),
    (
        "case:Record(vertical='yes')",
        lambda: Record(np.ones(3), dt=0.01, vertical="yes"),
        "vertical",
    ),
    ("case:Record(dt=1e308)", lambda: Record(np.ones(3), dt=1e308), "duration"),
    (
        "case:synthetic_near_fault(pulse_period=1e6, pga=4.0)",
        lambda: synthetic_near_fault(pulse_period=1e6, pga=4.0),
        "pulse_period",
    ),
    (
        "case:intensity_measures(periods=[1e300])",
        lambda: record().intensity_measures(periods=[1e300]),
        "periods",
    ),
    (
        "case:sa at period 1e-300",
        lambda: record().intensity_measure("sa", period=1e-300),
        "period",
    ),
    ("case:arias of a record scaled by 1e300", lambda: record().scaled(1e300), "factor"),
    ("case:pulse() of white noise", lambda: _pulse_inside(noise()), "pulse"),
    (
        "case:multiple_stripes(levels=[])",
        lambda: _design("multiple_stripes")(**_fill("multiple_stripes", {"levels": []})),
        "levels",
    ),
    (
        "case:ida scan=-1",
        lambda: study_api.incremental_dynamic_analysis([record()], [rs.Block(1.0, 0.2)], scan=-1),
        "scan",
    ),
    (
        "case:ida scan=10**6",
        lambda: study_api.incremental_dynamic_analysis(
            [record()], [rs.Block(1.0, 0.2)], scan=10**6
        ),
        "scan",
    ),
    (
        "case:ida tolerance=1e-300",
        lambda: study_api.incremental_dynamic_analysis(
            [record()], [rs.Block(1.0, 0.2)], tolerance=1e-300
        ),
        "tolerance",
    ),
    (
        "case:stripe_fragility on an IDA",
        lambda: study_api.stripe_fragility(designs()["ida"]),
        "ds",
    ),
    (
        "case:ida_fragility on stripes",
        lambda: study_api.ida_fragility(designs()["stripes"]),
        "ds",
    ),
    (
        "case:im_efficiency(candidates=[])",
        lambda: study_api.im_efficiency(designs()["stripes"], candidates=[]),
        "candidates",
    ),
    (
        "case:stripe_fragility(conf_level=1.5)",
        lambda: study_api.stripe_fragility(designs()["stripes"], conf_level=1.5),
        "conf_level",
    ),
    (
        "case:stripe_fragility(n_boot=-1)",
        lambda: study_api.stripe_fragility(designs()["stripes"], n_boot=-1),
        "n_boot",
    ),
    (
        "case:stripe_fragility(conf_level=nan)",
        lambda: study_api.stripe_fragility(designs()["stripes"], conf_level=math.nan),
        "conf_level",
    ),
]


def _pulse_inside(rec):
    """A pulse() that is a pulse: inside the record and shorter than it (else a refusal)."""
    p = rec.pulse()
    if p.amplitude > 0 and p.indicator > 0.5:
        inside = 0.0 <= p.start <= p.end <= rec.duration and p.period <= rec.duration
        if not inside:
            return math.nan  # reported as a non-finite answer
    return p.period if p.amplitude > 0 else 0.0


def generated_calls():
    """(id, call, argument name) for every fuzzed call, in a fixed order."""
    rng = random.Random(SEED)
    calls = []
    for target, (fn, sane, names) in TARGETS.items():
        for name in names or list(sane):
            values = list(HOSTILE.items())
            rng.shuffle(values)
            for label, value in values[:PER_ARGUMENT]:
                if label == "none" and sane.get(name) is None:
                    continue  # None is the default there: not hostile
                kwargs = dict(sane)
                kwargs[name] = value

                def call(fn=fn, kwargs=kwargs, target=target):
                    return fn(**_fill(target, dict(kwargs)))

                calls.append((f"{target}({name}={label})", call, name))
    calls += EXTRA
    return calls


CALLS = generated_calls()


# ---------------------------------------------------------------------- judging an answer


def finite(x) -> bool:
    """Whether an answer is finite where it claims to be a number."""
    import xarray as xr

    if x is None or isinstance(x, (str, bool, np.bool_)):
        return True
    if isinstance(x, (int, float, np.integer, np.floating)):
        return math.isfinite(float(x))
    if isinstance(x, np.ndarray):
        return x.dtype.kind not in "fc" or bool(np.all(np.isfinite(x)))
    if isinstance(x, dict):  # simulate_batch: NaN times are documented (no impact, survived)
        if "max_rotation" in x:
            return finite(x["max_rotation"])
        return all(finite(v) for v in x.values())
    if isinstance(x, Record):
        return finite(x.acceleration) and finite(x.duration)
    if isinstance(x, rs.RockingResult):
        return finite(x.max_rotation) and finite(x.t)
    if isinstance(x, xr.Dataset):
        keep = [k for k in ("max_rotation", "sa", "scale") if k in x]
        return all(finite(x[k].values) for k in keep)
    if hasattr(x, "to_numpy"):  # a DataFrame of fragility fits: median and beta
        cols = [c for c in ("median", "beta") if c in getattr(x, "columns", [])]
        return all(finite(x[c].to_numpy(float)) for c in cols)
    for attr in ("peak", "duration", "frequency_parameter"):
        if hasattr(x, attr) and not finite(getattr(x, attr)):
            return False
    return True


def judge(call, name, seconds=CALL_SECONDS, nan_documented=False):
    """("refused" | "answered", None) or (failure, why) for one call; a NaN is a marked
    answer where ``nan_documented``."""
    try:
        with time_limit(seconds, "the call"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            answer = call()
    except TimeoutError as exc:
        return "hang", str(exc)
    except (ValueError, TypeError) as exc:
        message = str(exc)
        if name.lower() not in message.lower():
            return "unnamed", f"{type(exc).__name__} without {name!r}: {message[:300]}"
        return "refused", None
    except Exception as exc:  # a traceback for the user
        return "traceback", f"{type(exc).__name__}: {str(exc)[:300]}"
    if not finite(answer):
        if nan_documented and np.all(np.isnan(np.asarray(answer, float))):
            return "answered", None
        return "non-finite", f"a non-finite answer: {str(answer)[:300]}"
    return "answered", None


def warm_up():
    """Compile the kernels and build the shared objects before any call is timed."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _simulate()
        rs.simulate_batch(half_diagonal=1.0, slenderness=0.2, amplitude=4.0, period=0.5)
        rs.simulate_batch(half_diagonal=1.0, slenderness=0.2, record=record())
        designs()


@pytest.fixture(scope="module", autouse=True)
def compiled():
    warm_up()


def test_the_fuzz_is_large_enough():
    assert len(CALLS) >= N_CALLS_MIN
    assert len({c[0] for c in CALLS}) == len(CALLS)


@pytest.mark.parametrize("case", [pytest.param(c, id=c[0]) for c in CALLS])
def test_each_call_refuses_by_name_or_answers_finitely(case):
    label, call, name = case
    outcome, why = judge(call, name, nan_documented=label.startswith(NAN_DOCUMENTED))
    assert outcome in ("refused", "answered"), f"{label}: {outcome}: {why}"
