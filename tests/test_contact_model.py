"""The planar contact model of a free-standing block: rest, slide, rock, slide-rock, flight.

Oracles: Housner's no-slip model (the rocking kernel) where friction never limits; the
two-way rigid-plastic (Newmark) sliding block in closed form (a rectangular pulse; a sine
pulse, piecewise analytic with its stop times by Brent's method); the ground displacement
for a frictionless base; Shenton's initiation criteria with the slide-rock threshold derived
here from the contact forces at uplift; Newton-Euler (the contact forces as the centre of
mass's acceleration, the moment about it) for the slide-rock equations; angular momentum
about the new corner and Housner's eq. (2.4) of [000] for the impacts; the energy balance
(the ground's work = kinetic + potential + friction work + impact losses) on every history.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import slide_rock as sr
from rockstudy.dynamics.slide_rock_reference import simulate_contact_reference
from rockstudy.motions import NoMotion, Record, RickerWavelet, SinePulse
from rockstudy.structures import SymmetricFrame

R, ALPHA = 1.0, 0.2
BLOCK = rs.Block(half_diagonal=R, slenderness=ALPHA)
HOUSNER = 1.0 - 1.5 * math.sin(ALPHA) ** 2
UPLIFT = G * math.tan(ALPHA)


def step(a, duration=0.05):
    """A rectangular pulse of ground acceleration a [m/s^2] over [0, duration] s."""
    return Record([a, a], time=[0.0, duration])


# ---------------------------------------------------------------- friction that never limits


@pytest.mark.parametrize(
    "motion",
    [
        SinePulse(amplitude=1.6 * UPLIFT, period=0.6),
        RickerWavelet(amplitude=2.5 * UPLIFT, period=0.5),
        SinePulse(amplitude=3.0 * UPLIFT, period=0.5),  # overturns
    ],
)
def test_friction_above_the_demand_is_housners_model(motion):
    """mu = 10: the contact model is Housner's (another solver: the event-driven kernel)."""
    housner = rs.simulate(BLOCK, motion, rtol=1e-12)
    r = rs.simulate(BLOCK, motion, friction=10.0, rtol=1e-12)
    assert housner.friction_demand < 10.0
    assert r.max_rotation == pytest.approx(housner.max_rotation, rel=1e-10, abs=0)
    assert r.overturned == housner.overturned
    assert r.n_impacts == housner.n_impacts
    np.testing.assert_allclose(r.impact_times, housner.impact_times, rtol=0, atol=1e-9)
    assert r.friction_demand == pytest.approx(housner.friction_demand, rel=1e-12)
    assert r.lift_off is False and r.regime_times["slide"] == 0.0
    if not housner.overturned:
        assert r.max_slide == 0.0 and math.isnan(r.first_slip_time)
        assert r.regime_times["slide_rock"] == 0.0
    else:  # the fall past alpha unloads the base (N -> 0), which no friction holds
        passed = r.t[np.argmax(np.abs(r.theta) > ALPHA)]
        assert r.first_slip_time > passed and np.all(r.slide[r.t <= passed] == 0.0)


def test_a_hop_inside_one_step_is_an_impact():
    """A short hop after an impact (two impacts 2 ms apart, at 0.4137 s and 0.4155 s) lies
    inside one solver step: found on the dense output, as Housner's kernel finds it."""
    block = rs.Block(half_diagonal=1.5988511503453966, slenderness=0.2351825705740887)
    pulse = RickerWavelet(amplitude=5.814259505345361, period=0.3471664382827899)
    housner = rs.simulate(block, pulse, rtol=1e-12)
    assert np.min(np.diff(housner.impact_times[:3])) < 0.002
    # a touchy scene: Housner's kernel and his scipy reference differ by 1.6e-9 s in the
    # impact times and 7.6e-10 in the max rotation; the contact model's scipy reference lies
    # between, its kernel agrees with Housner's kernel
    reference = rs.simulate(block, pulse, rtol=1e-12, method="scipy")
    for method, oracle in (("scipy", reference), ("nonlinear", housner)):
        r = rs.simulate(block, pulse, friction=10.0, rtol=1e-12, method=method)
        assert r.n_impacts == housner.n_impacts
        np.testing.assert_allclose(r.impact_times, oracle.impact_times, rtol=0, atol=1e-9)
        assert r.max_rotation == pytest.approx(oracle.max_rotation, rel=1e-9)


# ---------------------------------------------------------------- sliding (mu < tan alpha)


SOLVERS = {"nonlinear": "exact sliding kernel", "scipy": "contact model"}


@pytest.mark.parametrize("method", SOLVERS)
def test_rectangular_pulse_slides_as_newmarks_block(method):
    """a_g = A on [0, T], mu < tan(alpha) < A / g: the block never rotates; it slips back at
    u'' = -(A - mu g) until T, then decelerates at mu g: u(T) = -(A - mu g) T^2 / 2, it stops
    at A T / (mu g) with u = -(A - mu g) A T^2 / (2 mu g). Both solvers: the exact sliding
    kernel (a record, mu < tan alpha) and the solve_ivp reference."""
    mu, a, dur = 0.1, 0.5 * G, 0.3
    r = rs.simulate(BLOCK, step(a, dur), friction=mu, rtol=1e-12, method=method)
    assert r.info["solver"].startswith(SOLVERS[method])
    residual = -(a - mu * G) * a * dur**2 / (2 * mu * G)
    assert r.max_rotation == 0.0 and np.all(r.theta == 0.0) and r.n_impacts == 0
    assert r.residual_slide == pytest.approx(residual, rel=1e-10)
    assert r.max_slide == pytest.approx(-residual, rel=1e-10)
    at_end = r.slide[np.flatnonzero(r.t == dur)[0]]
    assert at_end == pytest.approx(-(a - mu * G) * dur**2 / 2, rel=1e-10)
    assert r.first_slip_time == 0.0
    assert r.regime_times["slide"] == pytest.approx(a * dur / (mu * G), rel=1e-10)
    assert r.regime_times["rock"] == r.regime_times["slide_rock"] == 0.0


@pytest.mark.parametrize("method", SOLVERS)
def test_static_friction_starts_and_kinetic_slides(method):
    """(mu_s, mu_k): below mu_s g the block rests; above it, it slides at mu_k."""
    mu_s, mu_k, dur = 0.15, 0.1, 0.3
    below = rs.simulate(BLOCK, step(0.14 * G, dur), friction=(mu_s, mu_k), method=method)
    assert below.max_slide == 0.0 and below.regime_times["slide"] == 0.0
    a = 0.16 * G
    r = rs.simulate(BLOCK, step(a, dur), friction=(mu_s, mu_k), rtol=1e-12, method=method)
    assert r.residual_slide == pytest.approx(-(a - mu_k * G) * a * dur**2 / (2 * mu_k * G), 1e-10)


def test_sliding_kernel_agrees_with_the_reference_on_random_records():
    """Two solvers of the sliding block: closed form per record segment (the kernel) and
    solve_ivp with events at rtol 1e-12, on random records, with vertical components and
    with mu_s > mu_k: the slip, its start and the time sliding within 1e-9."""
    rng = np.random.default_rng(11)
    for i in range(6):
        a = np.cumsum(rng.normal(0, 1, 200))
        rec = Record(
            0.4 * G * a / np.abs(a).max(),
            dt=0.01,
            vertical=rng.uniform(-0.3, 0.3, 200) * G if i % 2 else None,
        )
        mu = rng.uniform(0.05, 0.18)
        friction = (mu, mu * rng.uniform(0.6, 1.0)) if i >= 3 else mu
        k = rs.simulate(BLOCK, rec, friction=friction)
        r = rs.simulate(BLOCK, rec, friction=friction, method="scipy", rtol=1e-12)
        assert k.info["solver"].startswith("exact sliding kernel")
        assert k.max_slide == pytest.approx(r.max_slide, rel=1e-9)
        assert k.residual_slide == pytest.approx(r.residual_slide, abs=1e-9 * r.max_slide)
        assert k.first_slip_time == pytest.approx(r.first_slip_time, abs=1e-12)
        assert k.regime_times["slide"] == pytest.approx(r.regime_times["slide"], rel=1e-9)
        assert np.all(r.theta == 0.0) and np.all(k.theta == 0.0)


def newmark_sine(amplitude, period, mu, t_end):
    """Two-way rigid-plastic sliding block under a_g = A sin(w t) on [0, T] (then 0):
    (stop times, slip at each, max |slip|), the velocity and slip in closed form on each
    phase, each stop by Brent's method on the velocity."""
    w, a, f = 2 * math.pi / period, amplitude, mu * G

    def ground(t):
        return a * math.sin(w * t) if t <= period else 0.0

    def phase(t0, u0, slip):  # v(t), u(t) from rest at t0 slipping towards sign `slip`
        def v(t):
            tc = min(t, period)
            out = a / w * (math.cos(w * tc) - math.cos(w * t0)) - slip * f * (t - t0)
            return out

        def u(t):
            tc = min(t, period)
            inside = (
                a / w * ((math.sin(w * tc) - math.sin(w * t0)) / w - math.cos(w * t0) * (tc - t0))
            )
            after = a / w * (math.cos(w * tc) - math.cos(w * t0)) * (t - tc)
            return u0 + inside + after - slip * f * (t - t0) ** 2 / 2

        return v, u

    t, u0, peak, stops = 0.0, 0.0, 0.0, []
    while t < period:
        grid = np.linspace(t, period, 20001)
        above = [s for s in grid if abs(ground(s)) > f]
        if not above:
            break
        k = int(np.searchsorted(grid, above[0]))
        t0 = t if k == 0 else brentq(lambda s: abs(ground(s)) - f, grid[k - 1], grid[k], xtol=1e-15)
        slip = -math.copysign(1.0, ground(above[0]))
        v, u = phase(t0, u0, slip)
        scan = np.linspace(t0, t_end, 200001)[1:]
        vs = np.array([slip * v(s) for s in scan])
        j = int(np.argmax(vs <= 0.0))
        t = brentq(v, scan[j - 1] if j else t0 + 1e-12, scan[j], xtol=1e-15)
        u0 = u(t)
        peak = max(peak, abs(u0))
        stops.append((t, u0))
    return stops, peak


def test_sine_pulse_slides_as_newmarks_block_both_ways():
    amplitude, period, mu = 0.5 * G, 0.5, 0.1
    stops, peak = newmark_sine(amplitude, period, mu, 3.0)
    assert len(stops) >= 2 and stops[0][1] < 0 < stops[1][1] - stops[0][1]  # two ways
    r = rs.simulate(BLOCK, SinePulse(amplitude=amplitude, period=period), friction=mu, rtol=1e-12)
    assert np.all(r.theta == 0.0) and r.lift_off is False
    assert r.residual_slide == pytest.approx(stops[-1][1], rel=1e-9)
    assert r.max_slide == pytest.approx(peak, rel=1e-9)
    for t_stop, u_stop in stops:
        k = np.argmin(np.abs(r.t - t_stop))
        assert r.t[k] == pytest.approx(t_stop, abs=1e-9)
        assert r.slide[k] == pytest.approx(u_stop, rel=1e-9)


def test_frictionless_base_keeps_the_block_still_in_space():
    """mu = 0 (the reference solver; simulate takes mu > 0): u = -u_g, with the sine pulse's
    displacement u_g = (A / w) (t - sin(w t) / w) (at rest at t = 0), constant after it."""
    amplitude, period = 2.0, 0.5
    w = 2 * math.pi / period
    r = simulate_contact_reference(
        R, ALPHA, HOUSNER, SinePulse(amplitude=amplitude, period=period), 0.0, t_max=1.0
    )
    t = np.minimum(r["t"], period)
    u_g = amplitude / w * (t - np.sin(w * t) / w)
    np.testing.assert_allclose(r["slide"], -u_g, rtol=0, atol=1e-11 * u_g.max())
    assert r["max_slide"] == pytest.approx(amplitude * period / w, rel=1e-10)
    assert r["max_rotation"] == 0.0


# ---------------------------------------------------------------- Shenton's initiation criteria


def threshold(mu, alpha):
    """a* / g where a step of ground acceleration starts slide-rock instead of rock:
    at uplift (theta = theta_dot = 0) Housner's theta'' = (3 / 4R) (a g cos alpha - g sin
    alpha) turns the contact force into F / m = a g - R theta'' cos alpha and
    N / m = g + R theta'' sin alpha; F = mu N solved for a."""
    s, c = math.sin(alpha), math.cos(alpha)
    return (mu * (4 - 3 * s * s) - 3 * s * c) / (4 - 3 * c * c - 3 * mu * s * c)


def test_slide_rock_threshold_is_the_contact_force_ratio_at_uplift():
    for mu in (0.25, 0.5, 0.8):
        a = threshold(mu, ALPHA)
        assert sr.slide_rock_threshold(mu, ALPHA) == pytest.approx(a, rel=1e-14)
        acc = 0.75 / R * (a * G * math.cos(ALPHA) - G * math.sin(ALPHA))  # side +1 for a_g < 0
        f, n = -a * G + R * acc * math.cos(ALPHA), G + R * acc * math.sin(ALPHA)
        assert abs(f) / n == pytest.approx(mu, rel=1e-13)
        assert sr.uplift_force_ratio(a, ALPHA) == pytest.approx(mu, rel=1e-13)
    assert sr.slide_rock_threshold(math.tan(ALPHA), ALPHA) == pytest.approx(math.tan(ALPHA))
    assert math.isnan(sr.slide_rock_threshold(0.1, ALPHA))
    assert sr.slide_rock_threshold(3.0, ALPHA) == math.inf  # F / N never reaches 3


def first_regime(a, friction):
    r = rs.simulate(BLOCK, step(a, 0.02), friction=friction, rtol=1e-10, method="scipy")
    moving = [name for _, name in r.info["regime_sequence"] if name != "rest"]
    return r, (moving[0] if moving else "rest")


@pytest.mark.parametrize(
    ("a_over_g", "mu", "expected"),
    [
        (0.09, 0.1, "rest"),  # below mu < tan alpha
        (0.19, 0.5, "rest"),  # below tan alpha < mu
        (0.15, 0.1, "slide"),  # mu < a < tan alpha
        (0.6, 0.1, "slide"),  # mu < tan alpha < a: sliding carries no more than mu N
        (0.21, 0.5, "rock"),
        (0.999 * threshold(0.5, ALPHA), 0.5, "rock"),
        (1.001 * threshold(0.5, ALPHA), 0.5, "slide_rock"),
        (1.001 * threshold(0.25, ALPHA), 0.25, "slide_rock"),
    ],
)
def test_initiation_from_rest_follows_shenton(a_over_g, mu, expected):
    r, regime = first_regime(-a_over_g * G, mu)
    assert regime == expected
    if expected == "rest":
        assert r.max_rotation == 0.0 and r.max_slide == 0.0
    if expected == "slide":
        assert np.all(r.theta == 0.0) and r.max_slide > 0.0
    if mu < math.tan(ALPHA):  # the sliding kernel runs these: it agrees
        kernel = rs.simulate(BLOCK, step(-a_over_g * G, 0.02), friction=mu)
        assert kernel.info["solver"].startswith("exact sliding kernel")
        # the reference's slip is good to its absolute tolerance, rtol R alpha
        assert kernel.max_slide == pytest.approx(r.max_slide, rel=1e-9, abs=1e-9 * R * ALPHA)
        assert kernel.first_slip_time == r.first_slip_time or expected == "rest"
    if expected == "rock":
        assert r.info["regime_sequence"][1][0] == 0.0 and r.max_rotation > 0.0


def test_rest_ends_where_the_regime_test_says_so_to_the_last_bit():
    """The solver leaves rest where |a_h| - min(mu_s, tan alpha) (g + a_v) > 0; the regime
    it then enters must not be rest again, or the run stalls at that time (a ratio test
    |a_h| / (g + a_v) <= mu disagrees within an ulp). Values an ulp or two around mu g_e."""
    rng = np.random.default_rng(0)
    for _ in range(20000):
        mu, a_v = rng.uniform(0.05, 0.2), rng.uniform(-3, 3)
        a = np.nextafter(mu * (G + a_v), np.inf) * (1 + rng.integers(-2, 3) * 2.2e-16)
        leaves = abs(a) - mu * (G + a_v) > 0.0
        regime, _ = sr.initiation_regime(a, a_v, mu, mu, R, ALPHA)
        assert (regime != sr.REST) == leaves
        # above tan alpha the test is the rocking equation's: a block said to lift rises
        tan = math.tan(ALPHA) * (G + a_v) * (1 + rng.integers(-2, 3) * 2.2e-16)
        regime, side = sr.initiation_regime(tan, a_v, 0.5, 0.5, R, ALPHA)
        rises = side * sr.rocking_acceleration(0.0, tan, a_v, side, R, ALPHA) > 0.0
        assert (regime != sr.REST) == rises


# ---------------------------------------------------------------- equations and impacts


def test_slide_rock_equations_balance_newton_euler():
    """The slide-rock accelerations through the general contact forces: F = -sigma mu N,
    and the moment of (F, N) at the corner about G turns the block, I_G theta'' =
    -(r x F)."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        th, om = rng.uniform(-0.3, 0.3), rng.uniform(-2, 2)
        side = math.copysign(1.0, th)
        slip, mu = rng.choice([-1.0, 1.0]), rng.uniform(0.0, 1.0)
        a_h, a_v = rng.uniform(-8, 8), rng.uniform(-4, 4)
        u_dd, th_dd, n = sr.slide_rock_accelerations(th, om, a_h, a_v, side, slip, mu, R, ALPHA)
        f_h, f_v = sr.contact_forces(th, om, th_dd, u_dd, a_h, a_v, side, R, ALPHA)
        assert f_v == pytest.approx(n, rel=1e-12)
        assert f_h == pytest.approx(-slip * mu * n, abs=1e-11)
        rx, ry = sr.corner_offset(th, side, R, ALPHA)
        assert R * R / 3 * th_dd == pytest.approx(-(rx * f_v - ry * f_h), abs=1e-11)


def angular_momentum(vx, vy, w, about):
    """Per unit mass, clockwise, about the point ``about`` (from G)."""
    rx, ry = -about[0], -about[1]  # G from the point
    return R * R / 3 * w - (rx * vy - ry * vx)


def test_sticking_impact_is_housners_restitution():
    """A rocking block lands on the other corner: the plastic, sticking impact conserves
    the angular momentum about the new corner, which is Housner's eq. (2.4) of [000]; with
    a slip before it, :func:`rocking_impact` is that conservation too."""
    for u_dot in (0.0, 0.3, -0.2):
        w = -1.3
        before = sr.centre_velocity(u_dot, 0.0, w, 1.0, R, ALPHA)
        (vx, vy, w_plus), (p_h, p_v), stuck = sr.corner_impact(
            *before, w, 0.0, -1.0, 10.0, 10.0, R, ALPHA
        )
        assert stuck and p_v > 0
        corner = sr.corner_offset(0.0, -1.0, R, ALPHA)
        assert angular_momentum(vx, vy, w_plus, corner) == pytest.approx(
            angular_momentum(*before, w, corner), rel=1e-13
        )
        assert w_plus == pytest.approx(
            sr.rocking_impact(u_dot, w, 1.0, HOUSNER, R, ALPHA), rel=1e-13
        )
        if u_dot == 0.0:
            assert w_plus == pytest.approx(HOUSNER * w, rel=1e-13)


def test_impacts_never_create_energy_and_respect_the_cone():
    rng = np.random.default_rng(3)
    for _ in range(2000):
        vx, vy, w = rng.uniform(-1, 1), rng.uniform(-1, 0), rng.uniform(-2, 2)
        th, corner = rng.uniform(-0.3, 0.3), rng.choice([-1.0, 1.0])
        mu = rng.uniform(0.0, 1.2)
        rx, ry = sr.corner_offset(th, corner, R, ALPHA)
        if sr.corner_velocity(vx, vy, w, rx, ry)[1] >= 0.0:
            continue  # the corner does not approach the base
        (ax, ay, aw), (p_h, p_v), stuck = sr.corner_impact(vx, vy, w, th, corner, mu, mu, R, ALPHA)
        assert sr.kinetic_energy(ax, ay, aw, R) <= sr.kinetic_energy(vx, vy, w, R) * (1 + 1e-13)
        assert p_v >= 0.0 and abs(p_h) <= mu * p_v * (1 + 1e-12)
        cx, cy = sr.corner_velocity(ax, ay, aw, rx, ry)
        assert cy == pytest.approx(0.0, abs=1e-12)
        if stuck:
            assert cx == pytest.approx(0.0, abs=1e-12)
        else:  # the corner slips on the way the friction impulse resists
            assert cx * p_h <= 1e-15


# ---------------------------------------------------------------- energy along histories


def lift_record():
    """The vertical falls to -0.96 g while the block rocks (as in test_friction)."""
    t = np.arange(0.0, 1.5, 0.01)
    a_h = np.interp(t, [0, 0.05, 0.35, 0.45, 0.6, 0.75, 1.5], [0, -1.2, -1.2, 0, 2, 0, 0]) * UPLIFT
    a_v = np.interp(t, [0, 0.5, 0.55, 0.7, 0.75, 1.5], [0, 0, -0.96, -0.96, 0, 0]) * G
    return Record(a_h, time=t, vertical=a_v)


SCENES = [
    (SinePulse(amplitude=1.6 * UPLIFT, period=0.6), (0.5, 0.5), "rock"),
    (SinePulse(amplitude=0.5 * G, period=0.5), (0.1, 0.1), "slide"),
    (RickerWavelet(amplitude=2.0 * UPLIFT, period=0.6), (0.21, 0.21), "slide_rock"),
    (RickerWavelet(amplitude=2.3 * UPLIFT, period=0.3), (0.25, 0.2), "slide_rock"),
    (SinePulse(amplitude=2.5 * UPLIFT, period=0.6), (0.25, 0.25), "slide_rock"),  # overturns
    (lift_record(), (0.6, 0.6), "slide_rock"),  # with a vertical component
]


@pytest.mark.parametrize(("motion", "friction", "regime"), SCENES)
def test_energy_balance_along_the_history(motion, friction, regime):
    """Work of the ground (in its frame: -m u_h'' x_G' - m u_v'' y_G') = kinetic + potential
    change + friction work + impact losses, to 1e-8 of the work; no impact gains energy."""
    r = simulate_contact_reference(R, ALPHA, HOUSNER, motion, *friction)
    assert r["regime_times"][regime] > 0.0
    e = r["energy"]
    spent = e["kinetic"] + e["potential_change"] + e["friction_work"] + e["impact_losses"]
    assert spent == pytest.approx(e["ground_work"], rel=1e-8)
    assert np.all(e["each_impact_loss"] >= -1e-14 * e["ground_work"])
    assert e["friction_work"] >= 0.0


def test_flight_is_ballistic_until_a_corner_lands():
    """A block rocking on its + corner at theta_dot = 3.3 rad/s: R theta_dot^2 cos(phi) > g,
    so N < 0 and it flies: theta = theta0 + w t, y_G = y0 + v_y t - g t^2 / 2, until the
    lower corner reaches the base, y_G = R cos(alpha - c theta); energy is conserved in the
    flight and the landing loses some."""
    theta0, w = 0.1, 3.3
    r = simulate_contact_reference(
        R, ALPHA, HOUSNER, NoMotion(), 0.5, initial_state=(theta0, w), t_max=3.0
    )
    assert r["lift_off"] and r["regime_sequence"][1] == (0.0, "flight")
    phi = ALPHA - theta0
    y0, vy = R * math.cos(phi), R * math.sin(phi) * w

    def gap(t):
        theta = theta0 + w * t
        lowest = max(R * math.cos(ALPHA - theta), R * math.cos(ALPHA + theta))
        return y0 + vy * t - G * t * t / 2 - lowest

    grid = np.linspace(1e-6, 2.0, 20001)
    k = int(np.argmax([gap(t) < 0 for t in grid]))
    landing = brentq(gap, grid[k - 1], grid[k], xtol=1e-15)
    assert r["impact_times"][0] == pytest.approx(landing, abs=1e-9)
    at = np.flatnonzero(r["t"] == r["impact_times"][0])[0]
    assert r["theta"][at] == pytest.approx(theta0 + w * landing, rel=1e-9)
    e = r["energy"]
    assert e["ground_work"] == 0.0 and e["impact_losses"] > 0.0
    total = e["kinetic"] + e["potential_change"] + e["friction_work"] + e["impact_losses"]
    assert total == pytest.approx(0.0, abs=1e-9 * e["impact_losses"])


# ---------------------------------------------------------------- interface


def test_result_outputs_and_arguments():
    r = rs.simulate(BLOCK, SinePulse(amplitude=0.5 * G, period=0.5), friction=0.1)
    ds = r.to_xarray()
    np.testing.assert_array_equal(ds["slide"].values, r.slide)
    assert ds["slide"].attrs["units"] == "m"
    summary = r.summary()
    for key in ("max_slide", "residual_slide", "first_slip_time", "regime_times"):
        assert key in summary
    plain = rs.simulate(BLOCK, SinePulse(amplitude=0.5 * G, period=0.5))
    assert (
        plain.max_slide is None
        and plain.regime_times is None
        and "max_slide" not in plain.summary()
    )
    pulse = SinePulse(amplitude=0.5 * G, period=0.5)
    with pytest.raises(ValueError, match="kinetic coefficient 0.2 exceeds the static 0.1"):
        rs.simulate(BLOCK, pulse, friction=(0.1, 0.2))
    with pytest.raises(ValueError, match="friction must lie in"):
        rs.simulate(BLOCK, pulse, friction=(0.1, 0.0))
    with pytest.raises(ValueError, match="method='linear' does not run the contact model"):
        rs.simulate(BLOCK, pulse, friction=0.3, method="linear")
    with pytest.raises(ValueError, match="t_eval/dt_out is not available"):
        rs.simulate(BLOCK, pulse, friction=0.3, dt_out=0.1, t_max=1.0)
    with pytest.raises(ValueError, match="the contact model runs a Block, not a SymmetricFrame"):
        rs.simulate(SymmetricFrame(1.0, 0.15, 0.5), pulse, friction=0.3)


@pytest.mark.parametrize("friction", [1e-300, 1e-15, (0.5, 1e-12)])
def test_a_friction_below_the_smallest_the_model_follows_is_refused_by_name(friction):
    """Below MIN_FRICTION a slide left after the motion lasts |v| / (mu_k g): refused, in
    simulate and in a batch, before any integration."""
    from rockstudy.dynamics.contact_model import MIN_FRICTION

    block, pulse = rs.Block(0.8, 0.2), rs.motions.SinePulse(4.0, 0.6)
    with pytest.raises(ValueError, match="friction must lie in") as err:
        rs.simulate(block, pulse, friction=friction)
    assert f"{MIN_FRICTION:g}" in str(err.value)
    with pytest.raises(ValueError, match="friction"):
        rs.simulate_batch(
            half_diagonal=0.8, slenderness=0.2, amplitude=4.0, period=0.6,
            friction=friction, model="contact",
        )  # fmt: skip
