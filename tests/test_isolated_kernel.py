"""The numba kernel of the block on an isolated base (simulate_batch(structure=IsolatedBlock))
against independent oracles:

- the solve_ivp reference (rs.simulate, a different integrator and event locator) on 200
  random scenes under pulses and generated records, both at rtol 1e-12;
- Housner's batch (the block on fixed ground) as the isolator stiffens: the physical
  difference is O((omega_g T_b)^2), so the error must fall as T_b^2;
- the closed form of a friction pendulum's base under a constant ground acceleration (a
  shifted harmonic oscillation of period 2 pi sqrt(R_fp / g) while it slides; stuck below
  mu g), with a block that cannot lift;
- the trend of Roussis & Odysseos (2017, "Rocking response of seismically-isolated rigid
  blocks under simple acceleration pulses and earthquake excitations", Open Constr. Build.
  Technol. J. 11:217, conclusion): isolation raises the ground acceleration that initiates
  rocking, the more so the longer the isolator's period.
"""

import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.motions import CosinePulse, Record, RickerWavelet, SinePulse
from rockstudy.structures import IsolatedBlock

G = 9.81
RTOL = 1e-12


def _record(seed, scale):
    """A generated record (dt 0.01 s, 1.5 s): two sines and smoothed noise under a taper."""
    t = np.arange(151) * 0.01
    rng = np.random.default_rng(seed)
    noise = np.convolve(rng.standard_normal(t.size), np.ones(5) / 5, mode="same")
    f1, f2 = rng.uniform(0.8, 3.0, 2)
    acc = np.sin(2 * np.pi * f1 * t) + 0.5 * np.sin(2 * np.pi * f2 * t + 0.4) + 0.3 * noise
    return Record(scale * acc * np.sin(np.pi * t / t[-1]), dt=0.01, name=f"generated {seed}")


def _scene(rng, i):
    """A random structure (linear isolator, or every fourth a friction pendulum) and motion."""
    block = rs.Block(rng.uniform(0.3, 1.5), rng.uniform(0.12, 0.35))
    ratio = rng.uniform(0.3, 5.0)
    if i % 4 == 3:
        iso = IsolatedBlock(
            block, ratio, isolator="friction_pendulum", radius=rng.uniform(0.5, 3.0),
            friction=rng.uniform(0.02, 0.1),
        )  # fmt: skip
    else:
        iso = IsolatedBlock(block, ratio, period=rng.uniform(0.5, 3.0), damping=rng.uniform(0, 0.3))
    amp = G * math.tan(block.slenderness) * rng.uniform(0.5, 6.0)
    kind = i % 4
    if kind == 0:
        motion = SinePulse(amplitude=amp, period=rng.uniform(0.2, 1.5))
    elif kind == 1:
        motion = CosinePulse(amplitude=amp, period=rng.uniform(0.2, 1.5))
    elif kind == 2:
        motion = RickerWavelet(amplitude=amp, period=rng.uniform(0.2, 1.5))
    else:
        motion = _record(i, amp)
    return iso, motion


def _kernel(structures, motions, factor=1.0):
    from rockstudy.dynamics.two_body_batch import isolated_rows

    scaled = [_scaled(m, factor) for m in motions]
    return isolated_rows(structures, scaled, RTOL, 10**7)


def _scaled(motion, factor):
    if factor == 1.0:
        return motion
    if isinstance(motion, Record):
        return motion.scaled(factor)
    return type(motion)(amplitude=motion.amplitude * factor, period=motion.period)


@pytest.mark.slow
def test_kernel_matches_the_reference_on_200_random_scenes():
    """Both at rtol 1e-12: overturning decisions identical outside the band where a 1e-9
    perturbation of the amplitude flips the kernel's own decision; max rotation and max
    isolator displacement within 10 rtol times the scene's condition S (the relative change
    of the kernel's result per relative perturbation of the amplitude, at least 1): a
    chaotic scene amplifies the integrators' rounding as it amplifies the perturbation."""
    rng = np.random.default_rng(37)
    scenes = [_scene(rng, i) for i in range(200)]
    structures, motions = zip(*scenes, strict=True)
    base = _kernel(structures, motions)
    up, down = _kernel(structures, motions, 1 + 1e-9), _kernel(structures, motions, 1 - 1e-9)
    band = (up["overturned"] != base["overturned"]) | (down["overturned"] != base["overturned"])
    checked = 0
    for i, (iso, motion) in enumerate(scenes):
        ref = rs.simulate(iso, motion, rtol=RTOL)
        if band[i]:
            continue
        assert bool(base["overturned"][i]) == ref.overturned, i
        checked += 1
        pairs = [("max_isolator_displacement", ref.max_isolator_displacement)]
        if not ref.overturned:
            pairs.append(("max_rotation", ref.max_rotation))
        for name, want in pairs:
            got = base[name][i]
            spread = max(abs(up[name][i] - got), abs(down[name][i] - got))
            cond = max(1.0, spread / (1e-9 * max(abs(got), 1e-300)))
            assert abs(got - want) <= 10 * RTOL * cond * abs(want) + 1e-300, (i, name, got, want)
    assert checked >= 190


@pytest.mark.parametrize("factor", [0.5, 2.0])
def test_friction_pendulum_base_under_a_constant_ground_acceleration(factor):
    """u_g'' = a0 constant, the block too squat to lift: below mu g the base stays stuck
    (x_b = 0); at a0 = 2 mu g it slides with x_b = x_eq (1 - cos(omega t)),
    x_eq = -(a0 - mu g) / omega^2, omega = sqrt(g / R_fp), and stops for good at
    t = pi / omega, x_b = 2 x_eq (the friction it then needs, a0 - 2 mu g = 0, is below
    mu g)."""
    mu, radius = 0.05, 1.0
    iso = IsolatedBlock(
        rs.Block(1.0, 0.4), 1.0, isolator="friction_pendulum", radius=radius, friction=mu
    )
    a0 = factor * mu * G
    w = math.sqrt(G / radius)
    record = Record(np.full(301, a0), dt=0.01, name="constant")
    res = rs.simulate(iso, record, rtol=RTOL, t_max=3.0)
    rows = rs.simulate_batch(structure=iso, record=record, rtol=RTOL)
    assert res.max_rotation == 0.0 and rows["max_rotation"][0] == 0.0
    if factor < 1.0:
        assert res.max_isolator_displacement == 0.0
        assert rows["max_isolator_displacement"][0] == 0.0
        return
    x_eq = -(a0 - mu * G) / w**2
    sliding = res.t <= math.pi / w
    exact = x_eq * (1.0 - np.cos(w * res.t[sliding]))
    np.testing.assert_allclose(res.base_displacement[sliding], exact, rtol=0, atol=1e-9 * abs(x_eq))
    stop = res.t[np.argmax(res.base_displacement <= 2 * x_eq * (1 - 1e-12))]
    assert stop == pytest.approx(math.pi / w, rel=1e-9)
    assert res.max_isolator_displacement == pytest.approx(2 * abs(x_eq), rel=1e-9)
    assert rows["max_isolator_displacement"][0] == pytest.approx(2 * abs(x_eq), rel=1e-9)


def test_stiff_isolator_converges_to_housners_batch_as_tb_squared():
    """A heavy base on a stiffening isolator: the base's absolute acceleration differs from
    the ground's by O((omega_g T_b)^2) (x_b ~ -u_g'' / omega_b^2), so the kernel's max
    rotation must approach Housner's batch (the block on fixed ground, another kernel) with
    the error falling as T_b^2: a log-log slope of 2 (fitted over 40 to 5 ms: 1.7-2.5) and
    a factor 3-6 per halving. The ~1e-3 left at 0.01 s under this 0.6 s pulse is the physics,
    not the solver (so no 1e-6 bound)."""
    block = rs.Block(1.0, 0.2)
    amp, tp = 3.0, 0.6
    fixed = rs.simulate_batch(
        half_diagonal=block.half_diagonal, slenderness=block.slenderness, amplitude=amp,
        period=tp, rtol=RTOL,
    )["max_rotation"][0]  # fmt: skip
    periods = np.array([0.04, 0.02, 0.01, 0.005])
    isos = [IsolatedBlock(block, 1e6, period=tb, damping=0.05) for tb in periods]
    got = rs.simulate_batch(structure=isos, amplitude=amp, period=tp, rtol=RTOL)["max_rotation"]
    errors = np.abs(got - fixed) / fixed
    assert 0.0 < fixed < 1.0
    for coarse, fine in zip(errors[:-1], errors[1:], strict=True):
        assert 3.0 < coarse / fine < 6.0, errors
    slope = np.polyfit(np.log(periods), np.log(errors), 1)[0]
    assert 1.7 < slope < 2.5, (slope, errors)
    assert errors[2] < 2e-3


def test_isolation_raises_the_acceleration_that_initiates_rocking():
    """Roussis & Odysseos (2017), conclusion: regardless of block size and pulse period,
    isolation raises the pulse amplitude that initiates rocking (above g tan(alpha), the
    fixed-ground threshold of Housner), and the more so the longer the isolator's period;
    checked at isolation periods T_b = 2-4 s, longer than the pulses' (an isolator tuned
    near the pulse's period amplifies it instead: at T_b = 0.5 s under a 0.3 s pulse the
    block lifts at 0.77 g tan(alpha))."""
    for radius, tp in ((0.5, 0.3), (2.0, 0.8)):
        block = rs.Block(radius, 0.2)
        limit = G * math.tan(block.slenderness)
        amps = limit * np.geomspace(0.5, 50.0, 120)
        thresholds = []
        for tb in (2.0, 3.0, 4.0):
            iso = IsolatedBlock(block, 1.0, period=tb, damping=0.1)
            rows = rs.simulate_batch(structure=iso, amplitude=amps, period=tp, rtol=1e-10)
            lifted = rows["max_rotation"] > 0.0
            assert lifted.any()
            thresholds.append(amps[np.argmax(lifted)])
        assert thresholds[0] > limit
        assert all(a < b for a, b in zip(thresholds[:-1], thresholds[1:], strict=True)), thresholds


def test_friction_pendulum_input_is_checked():
    block = rs.Block(1.0, 0.2)
    fp = IsolatedBlock(block, 1.0, isolator="friction_pendulum", radius=2.0, friction=0.05)
    assert fp.period == pytest.approx(2 * math.pi * math.sqrt(2.0 / G))
    assert fp.friction_coefficient == 0.05
    cases = [
        ({"isolator": "rubber", "period": 2.0, "damping": 0.1}, "isolator"),
        ({"isolator": "friction_pendulum", "radius": 2.0}, "friction"),
        ({"isolator": "friction_pendulum", "friction": 0.1}, "radius"),
        ({"isolator": "friction_pendulum", "radius": 2.0, "friction": 1.5}, "friction"),
        ({"isolator": "friction_pendulum", "radius": -1.0, "friction": 0.1}, "radius"),
        (
            {"isolator": "friction_pendulum", "radius": 2.0, "friction": 0.1, "period": 2.0},
            "period",
        ),
        ({"period": 2.0, "damping": 0.1, "radius": 2.0}, "radius"),
        ({"damping": 0.1}, "period"),
    ]
    for kwargs, field in cases:
        with pytest.raises(ValueError, match=field):
            IsolatedBlock(block, 1.0, **kwargs)


def _sdof_sine_peak(period, zeta, amp, tp):
    """The peak ``|x_b|`` of x'' + 2 zeta w x' + w^2 x = -amp sin(2 pi t / tp) for
    0 <= t <= tp, free after, from rest: the particular solution and the homogeneous one by
    the matrix exponential, its velocity's zeros found by Brent's method on that solution."""
    import scipy.linalg
    import scipy.optimize

    w, wg = 2 * math.pi / period, 2 * math.pi / tp
    a_, b_ = np.linalg.solve(
        [[w * w - wg * wg, -2 * zeta * w * wg], [2 * zeta * w * wg, w * w - wg * wg]], [-amp, 0.0]
    )
    system = np.array([[0.0, 1.0], [-w * w, -2 * zeta * w]])

    def state(t):
        if t <= tp:
            xp = np.array(
                [
                    a_ * math.sin(wg * t) + b_ * math.cos(wg * t),
                    wg * (a_ * math.cos(wg * t) - b_ * math.sin(wg * t)),
                ]
            )
            return xp - scipy.linalg.expm(system * t) @ np.array([b_, wg * a_])
        return scipy.linalg.expm(system * (t - tp)) @ state(tp)

    grid = np.linspace(1e-3, tp + 3 * period, 3000)
    v = np.array([state(t)[1] for t in grid])
    peaks = [
        abs(
            state(scipy.optimize.brentq(lambda t: state(t)[1], grid[i], grid[i + 1], xtol=1e-15))[0]
        )
        for i in np.flatnonzero(np.sign(v[1:]) != np.sign(v[:-1]))
    ]
    return max(peaks)


def test_peak_base_displacement_of_a_resting_block_is_the_closed_form():
    """A block that never lifts rides the linear SDOF; its peak base displacement under a
    sine pulse, from the closed form, to 1e-12 in the reference and in the kernel (the
    reference once read its peaks off solve_ivp's dense output: 1.4e-11 off here)."""
    iso = IsolatedBlock(rs.Block(1.0, 0.2), 1.0, period=2.0, damping=0.1)
    pulse = SinePulse(amplitude=1.0, period=0.5)
    exact = _sdof_sine_peak(2.0, 0.1, 1.0, 0.5)
    ref = rs.simulate(iso, pulse, rtol=RTOL)
    rows = rs.simulate_batch(structure=iso, amplitude=1.0, period=0.5, rtol=RTOL)
    assert ref.max_rotation == 0.0 and rows["max_rotation"][0] == 0.0
    assert ref.max_isolator_displacement == pytest.approx(exact, rel=1e-12, abs=0)
    assert rows["max_isolator_displacement"][0] == pytest.approx(exact, rel=1e-12, abs=0)


def test_a_row_cut_short_by_max_steps_is_marked():
    """status 1 where a row reaches max_steps (its outputs cover only part of the history);
    0 on the same row given the steps it needs."""
    iso = IsolatedBlock(rs.Block(1.0, 0.2), 1.0, period=2.0, damping=0.1)
    rec = _record(5, 3.0)
    short = rs.simulate_batch(structure=iso, record=rec, rtol=1e-8, max_steps=20)
    full = rs.simulate_batch(structure=iso, record=rec, rtol=1e-8)
    assert short["status"][0] == 1 and full["status"][0] == 0
