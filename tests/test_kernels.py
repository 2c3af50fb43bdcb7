"""Building blocks of the kernels and the batch entry point."""

import math

import numpy as np
import pytest

from rockstudy.constants import G
from rockstudy.dynamics import _rocking
from rockstudy.dynamics._dop853 import hermite5
from rockstudy.dynamics.batch import simulate_batch


def test_quintic_hermite_reproduces_quintics_exactly():
    rng = np.random.default_rng(0)
    c = rng.normal(size=6)
    t0, h = 0.3, 0.7
    poly = np.polynomial.Polynomial(c)
    d1, d2, d3 = poly.deriv(1), poly.deriv(2), poly.deriv(3)
    ends = [(poly(x), d1(x), d2(x)) for x in (t0, t0 + h)]
    for s in np.linspace(0, 1, 11):
        v, d, a = hermite5(s, h, *ends[0], *ends[1])
        x = t0 + s * h
        assert v == pytest.approx(poly(x), abs=1e-12)
        assert d == pytest.approx(d1(x), abs=1e-11)
        assert a == pytest.approx(d2(x), abs=1e-10)
    assert d3(t0) != 0  # the test polynomial is a genuine quintic


def test_free_rocking_map_against_energy_balance():
    """Peak after an impact: cos(alpha - theta_m) = cos(alpha) + (eta v)^2 / (2 p^2)."""
    p, alpha, eta = 3.0, 0.2, 0.85
    u, v = 0.05, -0.4  # moving towards the impact
    over, peak, n = _rocking.free_rocking_map(u, v, p, alpha, eta, 0, 1e-4 * p * alpha)
    v0sq = v * v + 2 * p * p * (math.cos(alpha - u) - math.cos(alpha))
    expected = alpha - math.acos(math.cos(alpha) + eta**2 * v0sq / (2 * p * p))
    assert not over and peak == pytest.approx(expected, rel=1e-14)
    # impacts until the post-impact speed drops below the rest threshold
    w = math.sqrt(v0sq)
    assert n == next(k for k in range(1, 1000) if w * eta**k < 1e-4 * p * alpha)
    # beyond the unstable equilibrium and moving outwards: overturns
    assert _rocking.free_rocking_map(alpha * 1.01, 0.01, p, alpha, eta, 0, 1e-4)[0]
    # just below alpha at rest: survives
    assert not _rocking.free_rocking_map(alpha * 0.99, 0.0, p, alpha, eta, 0, 1e-4)[0]


def test_batch_broadcasts_and_validates():
    out = simulate_batch(
        half_diagonal=[0.5, 1.0, 2.0],
        slenderness=0.2,
        pulse="sine",
        amplitude=2.0 * G * math.tan(0.2),
        period=0.5,
    )
    assert out["max_rotation"].shape == (3,)
    assert set(out) >= {"max_rotation", "overturned", "n_impacts", "overturn_time", "status"}
    with pytest.raises(ValueError, match=r"slenderness\[1\]"):
        simulate_batch(half_diagonal=1.0, slenderness=[0.2, 2.0], amplitude=3.0, period=0.5)
    with pytest.raises(ValueError, match="half_diagonal"):
        simulate_batch(half_diagonal=[-1.0], slenderness=0.2, amplitude=3.0, period=0.5)
    with pytest.raises(ValueError, match="restitution"):
        simulate_batch(
            half_diagonal=1.0, slenderness=0.2, restitution=1.5, amplitude=3.0, period=0.5
        )
    with pytest.raises(ValueError, match="pulse"):
        simulate_batch(
            half_diagonal=1.0, slenderness=0.2, pulse="sawtooth", amplitude=3.0, period=0.5
        )
    with pytest.raises(ValueError, match="period"):
        simulate_batch(half_diagonal=1.0, slenderness=0.2, amplitude=3.0, period=np.nan)
    with pytest.raises(ValueError, match="method"):
        simulate_batch(
            half_diagonal=1.0, slenderness=0.2, amplitude=3.0, period=0.5, method="complex-ish"
        )


def test_batch_rows_do_not_depend_on_batch_composition():
    rng = np.random.default_rng(3)
    n = 64
    kw = dict(
        half_diagonal=rng.uniform(0.5, 3, n),
        slenderness=rng.uniform(0.05, 0.3, n),
        amplitude=rng.uniform(1, 6, n),
        period=rng.uniform(0.2, 1.5, n),
    )
    full = simulate_batch(**kw)
    part = simulate_batch(**{k: v[10:20] for k, v in kw.items()})
    for key in ("max_rotation", "overturned", "n_impacts"):
        np.testing.assert_array_equal(full[key][10:20], part[key])


def test_kernel_variants_compile_under_their_own_names():
    """The factories' two variants of a kernel (general, trig-only) have their own qualified
    names: numba names a compiled closure, and its cache entry, by that name and a counter of
    the compiling process, so two variants of one name, each compiled first in its own process,
    collided when a third process loaded both (``_rocking._variant_named``)."""
    variants = (
        (_rocking._phase, _rocking._phase_trig),
        (_rocking.scene, _rocking.scene_trig),
        (
            _rocking.scene_batch,
            _rocking.scene_batch_trig,
            _rocking.scene_batch_serial,
            _rocking.scene_batch_trig_serial,
        ),
    )
    assert len({kernel.py_func.__qualname__ for group in variants for kernel in group}) == 8


def test_a_batch_on_one_thread_equals_the_parallel_batch():
    """A study's workers run the batch on one thread (the serial kernels); the outputs do not
    depend on the number of threads, for pulses and records alike."""
    import numba

    from rockstudy.motions import stochastic_record

    rng = np.random.default_rng(5)
    alpha = rng.uniform(0.1, 0.3, 40)
    common = dict(half_diagonal=rng.uniform(0.3, 3.0, 40), slenderness=alpha)
    record = stochastic_record(peak=1.0, duration=3.0, dt=0.01, seed=2)
    runs = []
    for threads in (numba.config.NUMBA_NUM_THREADS, 1):
        numba.set_num_threads(threads)
        try:
            runs.append(
                (
                    simulate_batch(
                        pulse="sine", amplitude=3 * G * np.tan(alpha), period=0.5, **common
                    ),
                    simulate_batch(record=record, scale=3 * G * np.tan(alpha), **common),
                )
            )
        finally:
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    for parallel, serial in zip(*runs, strict=True):
        for key in ("max_rotation", "overturned", "n_impacts", "first_impact_time"):
            np.testing.assert_array_equal(parallel[key], serial[key])


def test_tallies_start_empty_with_integer_counts():
    tallies = _rocking.new_tallies(0.25)
    assert tallies.shape == (1,) and tallies.dtype == _rocking.TALLIES
    assert tallies[0]["max_rotation"] == 0.25 and np.isnan(tallies[0]["first_impact_time"])
    counts = [name for name in _rocking.TALLIES.names if name.startswith("n_") or name == "steps"]
    assert len(counts) == 6
    assert all(_rocking.TALLIES[name] == np.int64 and tallies[0][name] == 0 for name in counts)
