"""The block on an isolated base (rockstudy.structures.IsolatedBlock, the solve_ivp reference of
rockstudy.dynamics.isolated_reference), each against an independent oracle:

- the fixed-ground block (rs.simulate of the Block, a different solver) as the isolator
  stiffens with an infinitely heavy base;
- scipy.signal.lsim of the linear SDOF of base plus block while the block rests (first-order
  hold: exact for a record, linear between samples), and the first time its absolute
  acceleration passes g tan(alpha), root-found here on lsim's exact propagation;
- the energy balance of the Lagrangian (written here: kinetic and potential energy in the
  ground's frame, the work of the ground's inertia force and of the dashpot), and the momenta
  an impact conserves, computed here from the geometry of the block;
- Housner's restitution 1 - 1.5 sin^2(alpha) for an infinitely heavy base.
"""

import math

import numpy as np
import pytest
import scipy.integrate
import scipy.optimize
import scipy.signal

import rockstudy as rs
from rockstudy.motions import NoMotion, Record, SinePulse

G = 9.81


def _lsim_system(period, zeta):
    """The rest regime as state space: x'' + 2 zeta w x' + w^2 x = -u_g'', state (x, x'),
    outputs x and the base's absolute acceleration u_g'' + x'' = -(2 zeta w x' + w^2 x)."""
    w = 2.0 * math.pi / period
    A = np.array([[0.0, 1.0], [-w * w, -2.0 * zeta * w]])
    B = np.array([[0.0], [-1.0]])
    C = np.array([[1.0, 0.0], [-w * w, -2.0 * zeta * w]])
    return A, B, C, np.zeros((2, 1))


def _record(scale, seed=3):
    """A short synthetic record (dt 0.01 s, 3 s): two sines and smoothed noise, times scale."""
    t = np.arange(301) * 0.01
    rng = np.random.default_rng(seed)
    noise = np.convolve(rng.standard_normal(t.size), np.ones(5) / 5, mode="same")
    acc = np.sin(2 * np.pi * 1.3 * t) + 0.5 * np.sin(2 * np.pi * 3.1 * t + 0.4) + 0.3 * noise
    return Record(scale * acc * np.sin(np.pi * t / t[-1]), dt=0.01, name="synthetic")


# ----------------------------------------------------------------------- limits and oracles


def test_stiff_isolator_on_a_heavy_base_converges_to_the_block_on_fixed_ground():
    """The isolator's deformation is quasi-static, x_b ~ -u_g'' / omega_b^2, so the base's
    absolute acceleration differs from the ground's by O((omega_g T_b)^2): the max rotation
    must converge to the fixed-ground block's (a different solver: rs.simulate of the Block)
    at least as T_b^1.5 over T_b = 0.02, 0.01, 0.005 s and be within 1e-3 at 0.01 s."""
    block = rs.Block(1.0, 0.2)
    pulse = SinePulse(amplitude=4.0, period=0.5)
    fixed = rs.simulate(block, pulse, rtol=1e-12).max_rotation
    errors = []
    for period in (0.02, 0.01, 0.005):
        iso = rs.IsolatedBlock(block, base_mass_ratio=1e9, period=period, damping=0.0)
        errors.append(abs(rs.simulate(iso, pulse, rtol=1e-12).max_rotation / fixed - 1.0))
    assert errors[0] / errors[1] > 2.0**1.5 and errors[1] / errors[2] > 2.0**1.5, errors
    assert errors[1] < 1e-3, errors


def test_a_block_that_never_lifts_rides_the_linear_sdof_of_lsim():
    period, zeta = 0.8, 0.07
    block = rs.Block(0.5, 0.25)
    record = _record(1.0)
    sys_ = _lsim_system(period, zeta)
    _, y, _ = scipy.signal.lsim(sys_, record.acceleration, record.time, interp=True)
    limit = G * math.tan(block.slenderness)
    peak = np.max(np.abs(y[:, 1]))
    record = _record(0.8 * limit / peak)  # the base's acceleration peaks at 0.8 g tan(alpha)
    _, y, _ = scipy.signal.lsim(sys_, record.acceleration, record.time, interp=True)
    iso = rs.IsolatedBlock(block, base_mass_ratio=2.0, period=period, damping=zeta)
    r = rs.simulate(iso, record, rtol=1e-12, t_max=record.duration, t_eval=record.time)
    assert r.max_rotation == 0.0 and not r.uplift_times.size and not r.impact_times.size
    scale = np.max(np.abs(y[:, 0]))
    assert np.max(np.abs(r.base_displacement_eval - y[:, 0])) < 1e-8 * scale
    peak = _peak_displacement(sys_, record)  # between samples
    assert peak > scale and abs(r.max_isolator_displacement - peak) < 1e-9 * peak


def _propagate(sys_, record, states, k, tau):
    """The state (x, x') at tau in [t_k, t_k+1] by lsim's exact propagation from sample k
    (first-order hold of the record's samples); ``states`` are lsim's states at the samples."""
    t, acc = record.time, record.acceleration
    if tau == t[k]:
        return states[k]
    u = [acc[k], np.interp(tau, t, acc)]
    _, _, x = scipy.signal.lsim(sys_, u, [0.0, tau - t[k]], X0=states[k], interp=True)
    return x[-1]


def _first_crossing(sys_, record, limit):
    """The first time the base's absolute acceleration reaches |a| = limit, from lsim: the
    sample interval where it first does, then Brent's root on :func:`_propagate`."""
    t = record.time
    _, y, states = scipy.signal.lsim(sys_, record.acceleration, t, interp=True)
    k = int(np.flatnonzero(np.abs(y[:, 1]) >= limit)[0]) - 1
    side = math.copysign(1.0, y[k + 1, 1])
    out = sys_[2][1]

    def excess(tau):
        return side * out @ _propagate(sys_, record, states, k, tau) - limit

    return scipy.optimize.brentq(excess, t[k], t[k + 1], xtol=1e-14), side


def _peak_displacement(sys_, record):
    """max |x| between the samples, from lsim: x' = 0 root-found by Brent's method on
    :func:`_propagate` in the intervals beside the largest sample."""
    t = record.time
    _, _, states = scipy.signal.lsim(sys_, record.acceleration, t, interp=True)
    k = int(np.argmax(np.abs(states[:, 0])))
    best = abs(states[k, 0])
    for j in (k - 1, k):
        v0, v1 = states[j, 1], states[j + 1, 1]
        if v0 * v1 < 0.0:

            def velocity(tau, j=j):
                return _propagate(sys_, record, states, j, tau)[1]

            tau = scipy.optimize.brentq(velocity, t[j], t[j + 1], xtol=1e-14)
            best = max(best, abs(_propagate(sys_, record, states, j, tau)[0]))
    return best


def test_the_block_lifts_when_the_base_acceleration_first_passes_g_tan_alpha():
    period, zeta = 0.8, 0.07
    block = rs.Block(0.5, 0.25)
    limit = G * math.tan(block.slenderness)
    sys_ = _lsim_system(period, zeta)
    record = _record(1.0)
    _, y, _ = scipy.signal.lsim(sys_, record.acceleration, record.time, interp=True)
    record = _record(1.5 * limit / np.max(np.abs(y[:, 1])))
    t_lift, side = _first_crossing(sys_, record, limit)
    iso = rs.IsolatedBlock(block, base_mass_ratio=2.0, period=period, damping=zeta)
    r = rs.simulate(iso, record, rtol=1e-12)
    assert r.uplift_times.size and abs(r.uplift_times[0] - t_lift) < 1e-9
    # a positive base acceleration throws the block onto its negative pivot
    after = r.theta[(r.t > t_lift) & (r.theta != 0.0)]
    assert np.sign(after[0]) == -side


# --------------------------------------------------------------------- energy and momentum


def _energy_and_momentum(iso, x, xd, th, thd):
    """Per unit block mass, in the ground's frame: E = T + V (Lagrangian of Vassiliou & Makris
    2012 with the ground's inertia force taken as a load), and P the horizontal momentum of
    block and base relative to the ground. The side is that of theta (or theta' at 0)."""
    R, alpha = iso.block.half_diagonal, iso.block.slenderness
    M, w = 1.0 + iso.base_mass_ratio, 2.0 * math.pi / iso.period
    s = np.where(th != 0.0, np.sign(th), np.sign(thd))
    s = np.where(s == 0.0, 1.0, s)  # at rest: cos(phi) = cos(alpha) on either side
    phi = s * alpha - th
    T = 0.5 * M * xd**2 + R * np.cos(phi) * xd * thd + 0.5 * (4.0 / 3.0) * R**2 * thd**2
    V = G * R * np.cos(phi) + 0.5 * M * w * w * x**2
    return T + V, M * xd + R * np.cos(phi) * thd


def test_energy_balance_without_impacts():
    """E(t) - E(0) = -int c x'^2 dt - int u_g'' P dt up to the first impact, to 1e-8 g R."""
    block = rs.Block(1.0, 0.2)
    iso = rs.IsolatedBlock(block, base_mass_ratio=1.5, period=1.0, damping=0.1)
    pulse = SinePulse(amplitude=6.0, period=1.0)
    first = rs.simulate(iso, pulse, rtol=1e-12)
    assert first.uplift_times.size
    end = first.impact_times[0] if first.impact_times.size else first.overturn_time
    t = np.linspace(0.0, min(end, pulse.duration), 40001)
    r = rs.simulate(iso, pulse, rtol=1e-12, t_eval=t, t_max=pulse.duration)
    x, xd = r.base_displacement_eval, r.base_velocity_eval
    E, P = _energy_and_momentum(iso, x, xd, r.theta_eval, r.theta_dot_eval)
    M, w = 1.0 + iso.base_mass_ratio, 2.0 * math.pi / iso.period
    power = -2.0 * iso.damping * M * w * xd**2 - pulse.amplitude * np.sin(2 * np.pi * t) * P
    work = scipy.integrate.simpson(power, x=t)
    assert np.max(np.abs(r.theta_eval)) > 0.05  # it rocked
    assert abs(E[-1] - E[0] - work) < 1e-8 * G * block.half_diagonal


@pytest.mark.parametrize("ratio", [0.3, 2.0, 50.0])
def test_impacts_conserve_both_momenta_and_create_no_energy(ratio):
    """At each impact (a repeated time in the history): the horizontal momentum of block and
    base and the block's angular momentum about the new pivot are conserved; the angular
    momentum about the pivot at +-b, written here from r x v + I_c omega:
    H = (I_c + h^2 - b^2) theta'- + h v-  before, (I_c + R^2) theta'+ + h v+ after."""
    block = rs.Block(1.0, 0.25)
    iso = rs.IsolatedBlock(block, base_mass_ratio=ratio, period=1.5, damping=0.05)
    r = rs.simulate(iso, NoMotion(), initial_rotation=0.2, rtol=1e-12, t_max=6.0)
    R, alpha = block.half_diagonal, block.slenderness
    b, h, i_c = R * math.sin(alpha), R * math.cos(alpha), R * R / 3.0
    M = 1.0 + ratio
    pairs = np.flatnonzero(np.diff(r.t) == 0.0)
    assert pairs.size >= 5
    for k in pairs:
        xd0, th0, xd1, th1 = (
            r.base_velocity[k],
            r.theta_dot[k],
            r.base_velocity[k + 1],
            r.theta_dot[k + 1],
        )
        assert M * xd1 + h * th1 == pytest.approx(M * xd0 + h * th0, rel=1e-12, abs=1e-14)
        z = np.zeros(2)
        E, _ = _energy_and_momentum(iso, z, np.array([xd0, xd1]), z, np.array([th0, th1]))
        assert E[1] < E[0]
        # both momenta conserved: the 2 x 2 system for (x_b'+, theta'+)
        h0 = (i_c + h * h - b * b) * th0 + h * xd0
        xd_want, th_want = np.linalg.solve([[h, i_c + R * R], [M, h]], [h0, M * xd0 + h * th0])
        if th1 == 0.0:  # the impacts died out (below the rest speed): the block settles
            assert abs(th_want) < 1e-4 * block.frequency_parameter * alpha
            continue
        assert np.sign(th0) == np.sign(th1)  # it rocks on, onto the other pivot
        assert (xd1, th1) == pytest.approx((xd_want, th_want), rel=1e-12, abs=1e-15)


def test_an_infinitely_heavy_base_gives_housner_restitution():
    block = rs.Block(1.0, 0.3)
    iso = rs.IsolatedBlock(block, base_mass_ratio=1e9, period=0.01, damping=0.0)
    r = rs.simulate(iso, NoMotion(), initial_rotation=0.2, rtol=1e-12, t_max=3.0)
    pairs = np.flatnonzero(np.diff(r.t) == 0.0)
    assert pairs.size >= 3
    ratios = r.theta_dot[pairs + 1] / r.theta_dot[pairs]
    np.testing.assert_allclose(ratios, 1.0 - 1.5 * math.sin(0.3) ** 2, rtol=1e-8)
    assert np.max(np.abs(r.base_velocity)) < 1e-8  # the base does not move


def test_a_lighter_base_takes_more_of_the_impact():
    """theta'+ / theta'- falls with the base's mass (the base recoils): the formula of
    isolated_restitution at gamma -> 0, (1/3 - sin^2 alpha) / (1/3 + sin^2 alpha), is the
    free block's."""
    alpha = 0.2
    light = rs.structures.isolated_restitution(alpha, 1e-12)
    s2 = math.sin(alpha) ** 2
    assert light == pytest.approx((1.0 / 3.0 - s2) / (1.0 / 3.0 + s2), rel=1e-10)
    values = [rs.structures.isolated_restitution(alpha, g) for g in (0.1, 1.0, 10.0, 1e6)]
    assert values == sorted(values) and values[-1] < 1.0 - 1.5 * s2


def test_overturning_stops_the_history_at_pi_over_2():
    block = rs.Block(0.3, 0.2)
    iso = rs.IsolatedBlock(block, base_mass_ratio=1.0, period=0.05, damping=0.05)
    r = rs.simulate(iso, SinePulse(amplitude=12.0, period=0.6))
    assert r.overturned and r.max_rotation == math.pi / 2
    assert abs(r.theta[-1]) == math.pi / 2 and r.t[-1] == r.overturn_time


# ------------------------------------------------------------------------- surface and input


def test_result_surface_and_capacity():
    iso = rs.IsolatedBlock(rs.Block(1.0, 0.2), 1.0, 2.0, 0.1, isolator_capacity=0.05)
    r = rs.simulate(iso, SinePulse(amplitude=3.0, period=1.0))
    assert r.method == "scipy" and r.info["complete"]
    assert r.max_isolator_displacement == pytest.approx(
        np.max(np.abs(r.base_displacement)), rel=1e-3
    )
    assert r.exceeds_capacity == (r.max_isolator_displacement > 0.05)
    ds = r.to_xarray()
    assert ds["base_displacement"].attrs["units"] == "m"
    np.testing.assert_array_equal(ds["theta"].values, r.theta)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"base_mass_ratio": 0.0}, "base_mass_ratio"),
        ({"base_mass_ratio": math.nan}, "base_mass_ratio"),
        ({"period": 0.0}, "period"),
        ({"period": 1e3}, "period"),
        ({"damping": -0.1}, "damping"),
        ({"damping": 1.5}, "damping"),
        ({"isolator_capacity": -1.0}, "isolator_capacity"),
        ({"block": rs.Block(1.0, 0.2, restitution=0.5)}, "block.restitution"),
        ({"block": rs.Block(1.0, 0.7), "base_mass_ratio": 1e-3}, "base_mass_ratio"),
    ],
)
def test_bad_structure_input_names_the_field(kwargs, field):
    args = {"block": rs.Block(1.0, 0.2), "base_mass_ratio": 1.0, "period": 2.0, "damping": 0.1}
    with pytest.raises(ValueError, match=field):
        rs.IsolatedBlock(**{**args, **kwargs})


def test_bad_types_and_options():
    with pytest.raises(TypeError, match="block"):
        rs.IsolatedBlock("block", 1.0, 2.0, 0.1)
    with pytest.raises(TypeError, match="period"):
        rs.IsolatedBlock(rs.Block(1.0, 0.2), 1.0, "2", 0.1)
    iso = rs.IsolatedBlock(rs.Block(1.0, 0.2), 1.0, 2.0, 0.1)
    pulse = SinePulse(amplitude=3.0, period=1.0)
    for kwargs, name in [
        ({"method": "linear"}, "method"),
        ({"friction": 0.5}, "friction"),
        ({"conditioning": True}, "conditioning"),
        ({"rtol": 1e-14}, "rtol"),
        ({"initial_rotation": 2.0}, "initial_rotation"),
    ]:
        with pytest.raises(ValueError, match=name):
            rs.simulate(iso, pulse, **kwargs)
    vertical = Record(np.ones(5), dt=0.01, vertical=np.ones(5))
    with pytest.raises(ValueError, match="vertical"):
        rs.simulate(iso, vertical)


def test_dense_output_ends_with_the_history():
    """Without t_max, times beyond the end of the history are refused (naming t_eval); dt_out
    gives the uniform grid up to that end; after an overturning the state is NaN."""
    iso = rs.IsolatedBlock(rs.Block(1.0, 0.2), 1.0, 1.0, 0.2)
    pulse = SinePulse(amplitude=3.0, period=0.5)
    r = rs.simulate(iso, pulse, dt_out=0.01)
    assert r.t_eval[0] == 0.0 and r.t_eval[-1] <= r.t[-1] < r.t_eval[-1] + 0.01
    with pytest.raises(ValueError, match="t_eval"):
        rs.simulate(iso, pulse, t_eval=[0.0, r.t[-1] + 1.0])
    falls = rs.IsolatedBlock(rs.Block(0.3, 0.2), 1.0, 0.05, 0.05)
    r = rs.simulate(falls, SinePulse(amplitude=12.0, period=0.6), t_eval=[0.0, 5.0])
    assert r.overturned and r.theta_eval[0] == 0.0 and np.isnan(r.theta_eval[1])
