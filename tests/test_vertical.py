"""Vertical shaking (issue 13 section 4): Housner's equation with gravity g + u_v''.

theta'' = -p^2 [(1 + u_v''/g) sin(alpha s - theta) + (u_h''/g) cos(alpha s - theta)], uplift
where |u_h''| > (g + u_v'') tan(alpha). Oracles: the free-rocking period with p^2 (1 + u_v''/g)
(closed form for the linearized block, quadrature of the energy integral for Housner's),
solve_ivp DOP853 at rtol 1e-12 on the equation written here, mirror symmetry, the uplift
threshold, the exact similarity of a constant vertical (a block of p^2 (1 + c/g) under
u_h'' g / (g + c)), and a Lagrangian of the rocking wall derived here from its geometry.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

import rockstudy as rs
from rockstudy.constants import STANDARD_GRAVITY, G
from rockstudy.motions import Record

ALPHA = 0.15
R_BLOCK = 1.0
P = math.sqrt(3 * G / (4 * R_BLOCK))


def constant_vertical(c, duration=20.0, dt=0.01, horizontal=0.0):
    n = int(round(duration / dt)) + 1
    return Record(np.full(n, float(horizontal)), dt=dt, vertical=np.full(n, float(c)))


# --- free rocking under a constant vertical acceleration --------------------------------


@pytest.mark.parametrize("c", [-0.5 * G, 0.0, 0.7 * G])
def test_constant_vertical_scales_the_linear_free_rocking_period(c):
    """Linearized block, eta = 1, from theta0 at rest: impacts at (2k+1) t1 with
    t1 = arccosh(1 / (1 - theta0/alpha)) / (p sqrt(1 + c/g)) (DESIGN oracle, p^2 -> p^2 (1+c/g))."""
    theta0 = 0.5 * ALPHA
    block = rs.Block(R_BLOCK, ALPHA, restitution=1.0)
    res = rs.simulate(
        block,
        constant_vertical(c),
        method="linear",
        rtol=1e-11,
        initial_rotation=theta0,
        t_max=19.0,
    )
    t1 = math.acosh(1.0 / (1.0 - theta0 / ALPHA)) / (P * math.sqrt(1.0 + c / G))
    n = int((19.0 / t1 - 1) // 2) + 1
    np.testing.assert_allclose(res.impact_times[:n], (2 * np.arange(n) + 1) * t1, rtol=1e-8)
    assert res.max_rotation == pytest.approx(theta0, rel=1e-9)


def _housner_quarter_period(theta0, p_eff):
    """Time from theta0 at rest to the impact, by quadrature of the energy integral
    theta'^2 / 2 = p^2 (cos(alpha - theta0) - cos(alpha - theta)), theta = theta0 (1 - u^2)."""

    def f(u):
        th = theta0 * (1.0 - u * u)
        gap = 2.0 * math.sin(ALPHA - 0.5 * (theta0 + th)) * math.sin(0.5 * (theta0 - th))
        return 2.0 * theta0 * u / math.sqrt(2.0 * gap)

    return quad(f, 0.0, 1.0, epsabs=0, epsrel=1e-13)[0] / p_eff


@pytest.mark.parametrize("c", [-0.5 * G, 0.7 * G])
@pytest.mark.parametrize("amplitude", [0.05, 0.8])
def test_constant_vertical_scales_housners_free_rocking_period(c, amplitude):
    """Housner's equation, small and large amplitude: the quarter period is the quadrature
    with p sqrt(1 + c/g), and the impacts repeat every two quarter periods (eta = 1)."""
    theta0 = amplitude * ALPHA
    block = rs.Block(R_BLOCK, ALPHA, restitution=1.0)
    res = rs.simulate(block, constant_vertical(c), rtol=1e-11, initial_rotation=theta0, t_max=19.0)
    t1 = _housner_quarter_period(theta0, P * math.sqrt(1.0 + c / G))
    assert t1 != pytest.approx(_housner_quarter_period(theta0, P), rel=1e-3)  # c matters
    n = min(int((19.0 / t1 - 1) // 2) + 1, 20)
    np.testing.assert_allclose(res.impact_times[:n], (2 * np.arange(n) + 1) * t1, rtol=1e-8)
    assert res.max_rotation == pytest.approx(theta0, rel=1e-9)


# --- an oracle written here: solve_ivp on the equation in the amplitude ------------------


def oracle(accel, excess, times, ah, av, eta, rtol=1e-12):
    """Event-driven rocking from rest through the linearly interpolated record, up to its end.

    accel(u, v, sigma, a_h, a_v) is u'' on the side pushed by sigma a_h (sigma = sign of
    a_h at uplift, flipped at each impact); excess(a_h, a_v) >= 0 where the body lifts.
    Returns (max u, impact times). Uplift: the first sample with excess > 0, its segment
    bisected by Brent's method (the excess is convex between samples).
    """

    def at(t):
        return float(np.interp(t, times, ah)), float(np.interp(t, times, av))

    ex = np.array([excess(h, v) for h, v in zip(ah, av, strict=True)])
    i = int(np.flatnonzero(ex > 0)[0])
    t = brentq(lambda x: excess(*at(x)), times[i - 1], times[i], xtol=1e-15, rtol=1e-15)
    sigma = math.copysign(1.0, at(t)[0])
    u, v = 0.0, 0.0
    max_u, impacts = 0.0, []
    dur = times[-1]
    while t < dur:
        stop = times[min(np.searchsorted(times, t, side="right"), times.size - 1)]

        def rhs(x, y, sigma=sigma):
            h, w = at(x)
            return [y[1], accel(y[0], y[1], sigma, h, w)]

        def hit(x, y):
            return y[0]

        def peak(x, y):
            return y[1]

        hit.terminal, hit.direction, peak.direction = True, -1, -1
        sol = solve_ivp(
            rhs,
            (t, stop),
            [u, v],
            method="DOP853",
            rtol=rtol,
            atol=[rtol * ALPHA, rtol * P * ALPHA],
            events=(hit, peak),
        )
        if sol.y_events[1].size:
            max_u = max(max_u, float(np.max(sol.y_events[1][:, 0])))
        if sol.t_events[0].size:
            t = float(sol.t_events[0][0])
            impacts.append(t)
            u, v = 0.0, -eta * float(sol.y_events[0][0, 1])
            sigma = -sigma
            assert v > 1e-3 * P * ALPHA, "the scene must not come to rest in this oracle"
            continue
        t, u, v = float(sol.t[-1]), float(sol.y[0, -1]), float(sol.y[1, -1])
        max_u = max(max_u, u)
        assert u < 0.9 * math.pi / 2
    return max_u, np.array(impacts)


def housner_u(p, alpha):
    def accel(u, v, sigma, h, w):
        return -p * p * ((1.0 + w / G) * math.sin(alpha - u) - sigma * h / G * math.cos(alpha - u))

    def excess(h, w):
        return abs(h) - (G + w) * math.tan(alpha)

    return accel, excess


def harmonic_record(amp_h, amp_v, duration=4.0, dt=0.01, t_h=0.8, t_v=0.23):
    t = np.arange(0.0, duration + 0.5 * dt, dt)
    h = amp_h * np.sin(2 * math.pi * t / t_h) * np.exp(-0.3 * t)
    v = amp_v * np.sin(2 * math.pi * t / t_v + 0.7)
    return t, h, v


def test_harmonic_vertical_kernel_and_scipy_path_against_solve_ivp():
    eta = 0.9
    t, h, v = harmonic_record(2.2 * G * math.tan(ALPHA), 0.45 * G)
    rec = Record(h, time=t, vertical=v)
    block = rs.Block(R_BLOCK, ALPHA, restitution=eta)
    max_u, impacts = oracle(*housner_u(P, ALPHA), t, h, v, eta)
    assert impacts.size >= 4
    for method, rtol in (("nonlinear", 1e-12), ("scipy", 1e-12)):
        res = rs.simulate(block, rec, method=method, rtol=rtol, t_max=t[-1])
        assert res.max_rotation == pytest.approx(max_u, rel=1e-9), method
        np.testing.assert_allclose(res.impact_times, impacts, rtol=1e-9, err_msg=method)
    # the vertical matters: without it the answer is far from the oracle's
    flat = rs.simulate(block, Record(h, time=t), rtol=1e-10, t_max=t[-1])
    assert abs(flat.max_rotation - max_u) > 1e-3 * max_u


def test_mirror_symmetry_with_the_same_vertical():
    """u_h -> -u_h (Record.scaled(-1) keeps the vertical) gives theta -> -theta."""
    t, h, v = harmonic_record(2.2 * G * math.tan(ALPHA), 0.45 * G)
    rec = Record(h, time=t, vertical=v)
    mirrored = rec.scaled(-1.0)
    np.testing.assert_array_equal(mirrored.vertical, rec.vertical)
    block = rs.Block(R_BLOCK, ALPHA)
    for method in ("nonlinear", "linear", "scipy"):
        a = rs.simulate(block, rec, method=method, rtol=1e-10)
        b = rs.simulate(block, mirrored, method=method, rtol=1e-10)
        assert b.max_rotation == pytest.approx(a.max_rotation, rel=1e-12), method
        np.testing.assert_allclose(b.impact_times, a.impact_times, rtol=1e-12)
        np.testing.assert_allclose(b.theta, -a.theta, rtol=1e-12, atol=1e-15 * ALPHA)
    out = rs.simulate_batch(
        half_diagonal=R_BLOCK, slenderness=ALPHA, record=rec, scale=[1.0, -1.0], rtol=1e-10
    )
    assert out["max_rotation"][1] == pytest.approx(out["max_rotation"][0], rel=1e-12)
    # turning the vertical upside down is not a symmetry
    upside_down = rs.simulate(block, Record(h, time=t, vertical=-v), rtol=1e-10)
    assert abs(upside_down.max_rotation - a.max_rotation) > 1e-3 * a.max_rotation


# --- uplift threshold ----------------------------------------------------------------------


@pytest.mark.parametrize("c", [-0.3 * G, 0.4 * G])
@pytest.mark.parametrize(
    "method, threshold",
    [
        ("nonlinear", lambda c: (G + c) * math.tan(ALPHA)),
        ("scipy", lambda c: (G + c) * math.tan(ALPHA)),
        ("linear", lambda c: (G + c) * ALPHA),
        ("auto", lambda c: (G + c) * math.tan(ALPHA)),
    ],
)
def test_uplift_threshold_moves_with_gravity(c, method, threshold):
    block = rs.Block(R_BLOCK, ALPHA)
    for factor, lifts in ((1 - 1e-6, False), (1 + 1e-6, True)):
        rec = constant_vertical(c, duration=1.0, horizontal=factor * threshold(c))
        res = rs.simulate(block, rec, method=method, rtol=1e-10)
        assert (res.max_rotation > 0.0) == lifts, (factor, res.max_rotation)
        assert (res.impact_times.size > 0 or res.overturned) == lifts


@pytest.mark.parametrize("c", [-0.3 * G, 0.4 * G])
def test_batch_auto_rests_exactly_below_the_threshold(c):
    thr = (G + c) * math.tan(ALPHA)
    rec = constant_vertical(c, duration=1.0, horizontal=thr)
    out = rs.simulate_batch(
        half_diagonal=R_BLOCK,
        slenderness=ALPHA,
        record=rec,
        scale=[1 - 1e-6, 1 + 1e-6],
        method="auto",
    )
    np.testing.assert_array_equal(out["model"], [0, 2])
    assert out["max_rotation"][0] == 0.0 and out["max_rotation"][1] > 0.0


# --- a constant vertical is an exact similarity ----------------------------------------------


@pytest.mark.parametrize("method", ["nonlinear", "linear"])
def test_batch_constant_vertical_is_a_block_of_scaled_p(method):
    """With u_v'' = c throughout (and a long still tail, so that the block rests before the
    record ends), Housner's and the linearized equation are those of a block of
    p' = p sqrt(1 + c/g) under u_h'' g/(g + c), without vertical. The linear rows without
    vertical run the exact record solver; those with it, the kernel."""
    c = 0.35 * G
    dt, n = 0.01, 2001
    t = dt * np.arange(n)
    h = np.where(t < 1.0, np.sin(2 * math.pi * t), 0.0) * 2.4 * G * math.tan(ALPHA)
    vrec = Record(h, dt=dt, vertical=np.full(n, c))
    hrec = Record(h * G / (G + c), dt=dt)
    alpha = ALPHA * np.array([0.9, 1.2, 1.4, 1.55, 1.7, 2.0])  # rows: blocks, one record
    common = dict(slenderness=alpha, restitution=0.85, method=method, rtol=1e-11)
    a = rs.simulate_batch(frequency_parameter=P, record=vrec, **common)
    b = rs.simulate_batch(frequency_parameter=P * math.sqrt(1 + c / G), record=hrec, **common)
    assert a["overturned"].any() and not a["overturned"].all()
    np.testing.assert_array_equal(a["overturned"], b["overturned"])
    np.testing.assert_allclose(a["max_rotation"], b["max_rotation"], rtol=1e-8)
    for name in ("overturn_time", "first_impact_time"):
        np.testing.assert_allclose(a[name], b[name], rtol=1e-8, equal_nan=True)
    assert np.sum(a["n_impacts"] > 2) >= 2  # rows that rock and survive
    if method == "linear":
        lifted = a["max_rotation"] > 0
        assert np.all(a["steps"][lifted] > 0) and np.all(b["steps"] == 0)  # kernel vs exact


# --- a mechanism: the rocking wall of [003] from its own Lagrangian ---------------------------


def test_rocking_wall_under_vertical_against_its_lagrangian():
    """Two blocks (R, alpha, mass m, I_O = 4/3 m R^2 about the corner), the top one sliding:
    T = (I_O + 4 m R^2 sin^2(alpha - u)) u'^2, V = 4 m (g + u_v'') R cos(alpha - u), and the
    horizontal inertia forces do the work 2 m u_h'' R cos(alpha - u) per unit u. Lagrange:
    I u'' + I'/2 u'^2 + 4 m (g + u_v'') R sin(alpha - u) = 2 m R sigma u_h'' cos(alpha - u),
    I = 2 I_O + 8 m R^2 sin^2(alpha - u); uplift where |u_h''| > 2 (g + u_v'') tan alpha."""
    R, a, eta = 1.0, 0.1, 0.8
    wall = rs.structures.RockingWall(R, a, restitution=eta)
    i_o = 4.0 / 3.0 * R * R

    def accel(u, v, sigma, h, w):
        s, co = math.sin(a - u), math.cos(a - u)
        inertia = 2 * i_o + 8 * R * R * s * s
        half_di = -8 * R * R * s * co
        return (2 * R * sigma * h * co - 4 * (G + w) * R * s - half_di * v * v) / inertia

    def excess(h, w):
        return abs(h) - 2 * (G + w) * math.tan(a)

    t, h, v = harmonic_record(2.5 * G * math.tan(a), 0.5 * G, duration=3.0)
    rec = Record(h, time=t, vertical=v)
    max_u, impacts = oracle(accel, excess, t, h, v, eta, rtol=1e-11)
    assert impacts.size >= 3
    res = rs.simulate(wall, rec, method="mechanism", rtol=1e-10, t_max=t[-1])
    assert res.max_rotation == pytest.approx(max_u, rel=1e-6)
    np.testing.assert_allclose(res.impact_times, impacts, rtol=0, atol=1e-7)
    flat = rs.simulate(wall, Record(h, time=t), method="mechanism", rtol=1e-10, t_max=t[-1])
    assert abs(flat.max_rotation - max_u) > 1e-3 * max_u


# --- bad input ------------------------------------------------------------------------------


def test_free_fall_is_refused_before_any_integration():
    block = rs.Block(R_BLOCK, ALPHA)
    rec = constant_vertical(-G, duration=1.0, horizontal=1.0)
    for method in ("nonlinear", "linear", "scipy", "auto"):
        with pytest.raises(ValueError, match="vertical"):
            rs.simulate(block, rec, method=method)
    with pytest.raises(ValueError, match="vertical"):
        rs.simulate(rs.structures.RockingWall(1.0, 0.1, restitution=0.8), rec)
    half = constant_vertical(-0.6 * G, duration=1.0, horizontal=1.0)
    rs.simulate(block, half)  # fine unscaled
    with pytest.raises(ValueError, match=r"vertical.*scale\[2\]"):
        rs.simulate_batch(
            half_diagonal=1.0, slenderness=ALPHA, record=half, scale=[1.0, -1.5, -2.0]
        )
    with pytest.raises(ValueError, match="vertical"):
        rs.simulate(block, half.scaled(-2.0))


def test_complex_method_refuses_a_vertical_component():
    rec = constant_vertical(0.2 * G, duration=1.0, horizontal=1.0)
    with pytest.raises(ValueError, match="complex"):
        rs.simulate(rs.Block(R_BLOCK, ALPHA), rec, method="complex")


def test_hv_pair_of_different_lengths_or_steps_is_refused(tmp_path):
    with pytest.raises(ValueError, match="vertical"):
        Record(np.zeros(10), dt=0.01, vertical=np.zeros(9))
    h, v = tmp_path / "h.csv", tmp_path / "v.csv"
    h.write_text("".join(f"{0.01 * i} {0.001 * i}\n" for i in range(5)))
    v.write_text("".join(f"{0.02 * i} {0.001 * i}\n" for i in range(5)))
    with pytest.raises(ValueError, match=r"vertical: .*v\.csv"):
        Record.from_csv(h, vertical=v)


# --- three-column text records ----------------------------------------------------------------


def test_three_column_text_record(tmp_path):
    t = 0.01 * np.arange(6)
    h = np.array([0.0, 0.1, -0.2, 0.05, 0.0, 0.01])
    v = np.array([0.0, -0.05, 0.02, 0.0, 0.01, 0.0])
    path = tmp_path / "hv.txt"
    rows = zip(t, h, v, strict=True)
    path.write_text("# t h v\n" + "".join(f"{a}, {b}, {c}\n" for a, b, c in rows))
    rec = Record.from_csv(path, columns=("time", "horizontal", "vertical"))
    # a record in g is read with standard gravity (the PEER files' convention)
    np.testing.assert_allclose(rec.acceleration, h * STANDARD_GRAVITY, rtol=1e-15)
    np.testing.assert_allclose(rec.vertical, v * STANDARD_GRAVITY, rtol=1e-15)
    np.testing.assert_allclose(rec.time, t, rtol=1e-15)
    same = rs.motions.records.read_record(path, columns=("time", "horizontal", "vertical"))
    np.testing.assert_array_equal(same.vertical, rec.vertical)
    # two components without a time column, with dt
    bare = tmp_path / "hv_bare.txt"
    bare.write_text("".join(f"{b} {c}\n" for b, c in zip(h, v, strict=True)))
    rec2 = Record.from_csv(bare, columns=("horizontal", "vertical"), dt=0.01, units="m/s2")
    np.testing.assert_allclose(rec2.vertical, v, rtol=1e-15)
    assert rec2.dt == 0.01
    # a three-column file read as two columns says how to read it
    with pytest.raises(ValueError, match=r"hv\.txt: line 2 has 3 columns.*columns="):
        Record.from_csv(path)


def test_three_column_errors_name_file_and_line(tmp_path):
    path = tmp_path / "bad.txt"
    path.write_text("0 0.1 0.0\n0.01 0.2\n0.02 0.0 0.0\n")
    cols = ("time", "horizontal", "vertical")
    with pytest.raises(ValueError, match=r"bad\.txt: line 2 has 2 columns, expected 3"):
        Record.from_csv(path, columns=cols)
    path.write_text("0 0.1 0.0\n0.01 0.2 x\n")
    with pytest.raises(ValueError, match=r"bad\.txt: line 2 is not 3 numbers"):
        Record.from_csv(path, columns=cols)
    path.write_text("0 0.1 0.0\n0.01 0.2 nan\n")
    with pytest.raises(ValueError, match=r"bad\.txt: vertical"):
        Record.from_csv(path, columns=cols)
    with pytest.raises(ValueError, match="columns"):
        Record.from_csv(path, columns=("time", "vertical"))
    with pytest.raises(ValueError, match="dt"):
        Record.from_csv(path, columns=("horizontal", "vertical"))
    with pytest.raises(ValueError, match="vertical"):
        Record.from_csv(path, columns=cols, vertical=path)
