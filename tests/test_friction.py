"""Friction demand and lift-off of a rocking block (issue 24 section 5).

Oracles: the contact force as the centre of mass's acceleration, by finite differences of its
position on an arbitrary trajectory; the moment balance about the centre of mass (Newton-Euler,
I_G = m R^2 / 3) against the pivot equation of motion; momentum for the impact impulse;
energy conservation for free rocking (restitution 1: every half-cycle is the same, so the
demand is a maximum over theta in closed form); the falling block's F_v = m g (1/2 - 3/2
cos phi)^2 from energy; below uplift, max |a_g| / (g + a_v) over the motion; the scipy
reference's states through the same force expressions.
"""

import math
import warnings

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import contact
from rockstudy.motions import CosinePulse, NoMotion, Record, RickerWavelet, SinePulse

ALPHA = 0.2
BLOCK = rs.Block(half_diagonal=1.2, slenderness=ALPHA)
P = BLOCK.frequency_parameter
R = 1.2
UPLIFT = G * math.tan(ALPHA)


def test_block_half_diagonal_from_p():
    """Rectangles of half-width b and half-height h: R = sqrt(b^2 + h^2), and the pendulum
    frequency about a corner p = sqrt(3 g / (4 R)) (I_O = 4/3 m R^2), written here."""
    b, h = np.array([0.1, 0.225, 0.5, 2.0]), np.array([0.8, 0.95, 0.5, 6.0])
    R_rect = np.hypot(b, h)
    p = np.sqrt(3 * G / (4 * R_rect))
    np.testing.assert_allclose(contact.half_diagonal(p), R_rect, rtol=1e-14)
    assert contact.half_diagonal(float(p[1])) == pytest.approx(R_rect[1], rel=1e-14)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_contact_force_is_the_centre_of_mass_acceleration(side):
    """F / m = a_G + g y: the position of G on an arbitrary trajectory theta(t) of a pivot
    moving with the ground, differentiated by a 4th-order central stencil."""
    t = np.linspace(0.1, 2.0, 7)
    th = lambda t: side * (0.05 + 0.08 * np.sin(2.3 * t))  # noqa: E731
    uh, uv = (lambda t: 0.3 * np.sin(1.7 * t)), (lambda t: 0.1 * np.cos(2.9 * t))  # noqa: E731

    def centre(t):  # G from the pivot: (-s R sin phi, R cos phi), phi = alpha - s theta
        phi = ALPHA - side * th(t)
        return uh(t) - side * R * np.sin(phi), uv(t) + R * np.cos(phi)

    h = 1e-3

    def second(f, t):
        return (-f(t + 2 * h) + 16 * f(t + h) - 30 * f(t) + 16 * f(t - h) - f(t - 2 * h)) / (
            12 * h * h
        )

    x_dd = second(lambda t: centre(t)[0], t)
    y_dd = second(lambda t: centre(t)[1], t)
    theta_dot = side * 0.08 * 2.3 * np.cos(2.3 * t)
    theta_ddot = -side * 0.08 * 2.3**2 * np.sin(2.3 * t)
    a_h, a_v = -0.3 * 1.7**2 * np.sin(1.7 * t), -0.1 * 2.9**2 * np.cos(2.9 * t)
    f_h, f_v = contact.contact_forces(th(t), theta_dot, theta_ddot, a_h, a_v, side, R, ALPHA)
    np.testing.assert_allclose(f_h, x_dd, rtol=0, atol=1e-7)
    np.testing.assert_allclose(f_v, y_dd + G, rtol=0, atol=1e-7)


@pytest.mark.parametrize("linear", [False])
def test_equation_of_motion_balances_moments_about_the_centre_of_mass(linear):
    """The pivot's equation (2.2 of [000], gravity g + a_v) with the contact force: the moment
    of F about G turns the block, I_G theta_ddot = -(r x F), I_G = R^2 / 3 per unit mass."""
    rng = np.random.default_rng(4)
    th = rng.uniform(-0.3, 0.3, 50)
    side = np.where(th != 0, np.sign(th), 1.0)
    om = rng.uniform(-2, 2, 50)
    a_h, a_v = rng.uniform(-8, 8, 50), rng.uniform(-5, 5, 50)
    acc = contact.rocking_acceleration(th, a_h, a_v, side, P, ALPHA, linear)
    f_h, f_v = contact.contact_forces(th, om, acc, a_h, a_v, side, R, ALPHA)
    phi = ALPHA - side * th
    moment = side * R * np.sin(phi) * f_v + R * np.cos(phi) * f_h  # counter-clockwise
    np.testing.assert_allclose(R * R / 3.0 * acc, -moment, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("eta", [0.5, 0.8, None])
def test_impact_impulse_ratio_from_momentum(eta):
    """J = m (v_G+ - v_G-): v_G = omega x (G - pivot) about the old corner before and about
    the new one after, theta_dot+ = eta theta_dot-."""
    eta = 1 - 1.5 * math.sin(ALPHA) ** 2 if eta is None else eta
    b, hgt = R * math.sin(ALPHA), R * math.cos(ALPHA)
    w_minus = -1.3  # rocking on the + corner (x = +b), falling back: theta_dot < 0
    w_plus = eta * w_minus  # now on the - corner, rising
    # theta is a clockwise rotation: v = -w z x r, with r from the pivot to G = (0, h)
    v_minus = np.array([w_minus * hgt, w_minus * b])  # r = (-b, h)
    v_plus = np.array([w_plus * hgt, -w_plus * b])  # r = (+b, h)
    j = v_plus - v_minus
    assert j[1] > 0  # the ground pushes up
    assert abs(j[0] / j[1]) == pytest.approx(contact.impact_impulse_ratio(eta, ALPHA), rel=1e-14)


def test_falling_block_loses_contact_at_cos_phi_one_third():
    """From rest at theta = alpha with still ground, energy gives R theta_dot^2 =
    3/2 g (1 - cos phi), and F_v = m g (1/2 - 3/2 cos phi)^2: zero at cos phi = 1/3."""
    phi = np.linspace(-1.5, 0.0, 200)
    th = ALPHA - phi
    om = np.sqrt(1.5 * G * (1 - np.cos(phi)) / R)
    acc = contact.rocking_acceleration(th, 0.0, 0.0, 1.0, P, ALPHA)
    _, f_v = contact.contact_forces(th, om, acc, 0.0, 0.0, 1.0, R, ALPHA)
    np.testing.assert_allclose(f_v, G * (0.5 - 1.5 * np.cos(phi)) ** 2, atol=1e-12)


@pytest.mark.parametrize(
    "motion",
    [
        SinePulse(amplitude=0.9 * UPLIFT, period=0.37),
        CosinePulse(amplitude=-0.95 * UPLIFT, period=0.5, cycles=2),
        RickerWavelet(amplitude=0.8 * UPLIFT, period=0.3),
    ],
)
def test_below_uplift_demand_is_peak_ground_acceleration_over_g(motion):
    r = rs.simulate(BLOCK, motion)
    assert r.n_impacts == 0 and r.max_rotation == 0.0
    assert r.friction_demand == pytest.approx(abs(motion.amplitude) / G, rel=1e-13)
    assert r.lift_off is False


def test_below_uplift_with_vertical_is_max_over_samples():
    """With a vertical, |a_h| / (g + a_v): between samples a ratio of two linear functions,
    largest at a sample."""
    rng = np.random.default_rng(2)
    n = 400
    a_h = 0.85 * UPLIFT * np.sin(np.linspace(0, 9, n)) * rng.uniform(0.3, 1.0, n)
    a_v = 0.3 * G * rng.uniform(-1, 1, n)
    ratio = np.abs(a_h) / (G + a_v)
    scale = 0.97 * math.tan(ALPHA) / ratio.max()  # just below uplift
    rec = Record(scale * a_h, dt=0.01, vertical=a_v).scaled(1.0)
    r = rs.simulate(BLOCK, Record(scale * a_h, dt=0.01, vertical=a_v))
    assert r.n_impacts == 0 and r.max_rotation == 0.0
    expected = np.max(np.abs(scale * a_h) / (G + a_v))
    assert r.friction_demand == pytest.approx(expected, rel=1e-14)
    assert rec.peak == pytest.approx(np.max(np.abs(scale * a_h)))


def test_free_rocking_without_losses_matches_energy():
    """Restitution 1 and still ground: theta_dot^2 = 2 p^2 (cos(alpha - theta0) - cos(alpha -
    |theta|)) on every half-cycle, the impacts transmit no horizontal impulse, so the demand
    is the maximum over |theta| in [0, theta0] of |F_h| / F_v in closed form."""
    block = rs.Block(half_diagonal=R, slenderness=ALPHA, restitution=1.0)
    theta0 = 0.7 * ALPHA
    r = rs.simulate(block, NoMotion(), initial_rotation=theta0, t_max=6.0, rtol=1e-10)
    assert r.n_impacts >= 4
    th = np.linspace(0.0, theta0, 20001)
    om = -np.sqrt(2 * P * P * (np.cos(ALPHA - theta0) - np.cos(ALPHA - th)))
    acc = contact.rocking_acceleration(th, 0.0, 0.0, 1.0, P, ALPHA)
    f_h, f_v = contact.contact_forces(th, om, acc, 0.0, 0.0, 1.0, R, ALPHA)
    expected = np.max(np.abs(f_h) / f_v)
    assert r.friction_demand == pytest.approx(expected, rel=1e-8)
    assert r.lift_off is False


def dense_reference_demand(motion, end, n=200_001):
    """max |F_h| / F_v of the scipy reference (rtol 1e-12) through the force expressions: its
    dense output on n times in [0, end] (the rocking states, 0 < |theta| <= alpha) and its
    event-located impacts (theta = 0, before and after the jump of theta_dot)."""
    t = np.linspace(0.0, end, n)
    ref = rs.simulate(BLOCK, motion, method="scipy", rtol=1e-12, t_eval=t)
    th, om = ref.theta_eval, ref.theta_dot_eval
    ok = np.isfinite(th) & (th != 0.0) & (np.abs(th) <= ALPHA)
    t, th, om, side = t[ok], th[ok], om[ok], np.sign(th[ok])
    pair = np.flatnonzero((ref.theta[:-1] == 0) & (ref.t[1:] == ref.t[:-1]))
    before, after = ref.theta_dot[pair], ref.theta_dot[pair + 1]
    t = np.concatenate([t, ref.t[pair], ref.t[pair]])
    th = np.concatenate([th, 0 * before, 0 * after])
    om = np.concatenate([om, before, after])
    side = np.concatenate([side, -np.sign(before), np.sign(after)])
    a_h = motion(t)
    acc = contact.rocking_acceleration(th, a_h, 0.0, side, P, ALPHA)
    f_h, f_v = contact.contact_forces(th, om, acc, a_h, 0.0, side, R, ALPHA)
    return np.max(np.abs(f_h) / f_v)


@pytest.mark.parametrize(
    ("motion", "end"),
    [
        (SinePulse(amplitude=1.6 * UPLIFT, period=0.6), 2.0),
        (RickerWavelet(amplitude=2.5 * UPLIFT, period=0.5), 2.0),
        (SinePulse(amplitude=3 * UPLIFT, period=0.5), 0.6),  # overturns
    ],
)
def test_rocking_demand_matches_the_scipy_reference(motion, end):
    """The kernel's history through the force expressions against (1) the scipy reference's
    history through the same code (another solver) and (2) the reference's dense output on a
    grid of 1e-5 s and at its impacts (its maximum lies below the true one by the grid's
    reach). Above tan(alpha): every uplift needs tan alpha."""
    r = rs.simulate(BLOCK, motion, rtol=1e-10)
    ref = rs.simulate(BLOCK, motion, method="scipy", rtol=1e-10)
    assert r.n_impacts >= 1 or r.overturned
    assert r.friction_demand >= math.tan(ALPHA) * (1 - 1e-12)
    assert r.friction_demand == pytest.approx(ref.friction_demand, rel=1e-7)
    dense = dense_reference_demand(motion, end)
    assert dense <= r.friction_demand * (1 + 1e-9)
    assert r.friction_demand == pytest.approx(dense, rel=1e-6)
    assert r.lift_off is False and ref.lift_off is False


def test_the_demand_at_uplift_is_tan_alpha():
    """A pulse that just lifts the block: the demand is tan(alpha) (rest up to uplift, where
    both force expressions agree), plus what the brief rocking adds, but no more than the
    impulse ratio or the ratio shortly after uplift."""
    r = rs.simulate(BLOCK, SinePulse(amplitude=1.0001 * UPLIFT, period=0.5))
    assert r.n_impacts >= 1
    housner = 1 - 1.5 * math.sin(ALPHA) ** 2
    assert contact.impact_impulse_ratio(housner, ALPHA) < math.tan(ALPHA)
    assert r.friction_demand == pytest.approx(math.tan(ALPHA), rel=1e-3)


def lift_record():
    """The block rocks (the ground pushed to -x, 1.2 times its uplift level), then the ground
    swings to +x, twice the uplift level, while the vertical falls to -0.96 g: g + a_v = 0.04 g
    cannot hold the centripetal and horizontal terms, so F_v < 0 in the dip (0.5-0.75 s)."""
    t = np.arange(0.0, 1.5, 0.01)
    a_h = np.interp(t, [0, 0.05, 0.35, 0.45, 0.6, 0.75, 1.5], [0, -1.2, -1.2, 0, 2, 0, 0]) * UPLIFT
    a_v = np.interp(t, [0, 0.5, 0.55, 0.7, 0.75, 1.5], [0, 0, -0.96, -0.96, 0, 0]) * G
    return t, a_h, a_v


def test_strong_vertical_lift_off_is_flagged():
    t, a_h, a_v = lift_record()
    with_v = Record(a_h, time=t, vertical=a_v)
    r = rs.simulate(BLOCK, with_v)
    assert r.lift_off is True and r.friction_demand == math.inf
    when = r._contact_check().time
    assert r.n_impacts >= 1 and not r.overturned
    assert 0.5 <= when <= 0.75
    assert rs.simulate(BLOCK, with_v, method="scipy", rtol=1e-10).lift_off is True
    without = rs.simulate(BLOCK, Record(a_h, time=t))
    assert without.lift_off is False and math.isfinite(without.friction_demand)
    # the contact model follows the scene instead: the base slips (slide-rock) as it unloads
    contact = rs.simulate(BLOCK, with_v, friction=0.6)
    assert contact.friction_demand == math.inf and contact.regime_times["slide_rock"] > 0.0
    assert r.summary()["lift_off"] is True and r.summary()["friction_demand"] is None


def test_friction_runs_the_contact_model_without_a_warning():
    """simulate(friction=mu) runs the contact model (rockstudy.dynamics.slide_rock; its own
    tests in test_contact_model.py): below the rocking model's demand the block slips,
    above it it does not; the demand stays the rocking model's, and nothing warns."""
    pulse = SinePulse(amplitude=1.6 * UPLIFT, period=0.6)
    demand = rs.simulate(BLOCK, pulse).friction_demand
    assert issubclass(rs.ContactWarning, rs.AccuracyWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error", rs.ContactWarning)
        slips = rs.simulate(BLOCK, pulse, friction=0.15)
        holds = rs.simulate(BLOCK, pulse, friction=demand * 1.01)
    assert slips.friction_demand == holds.friction_demand == pytest.approx(demand, rel=1e-12)
    assert slips.max_slide > 0.0 and math.isfinite(slips.first_slip_time)
    assert holds.max_slide == 0.0 and math.isnan(holds.first_slip_time)


def test_friction_argument_and_where_there_is_no_demand():
    pulse = SinePulse(amplitude=1.6 * UPLIFT, period=0.6)
    with pytest.raises(ValueError, match=r"friction must lie in \(0, 10\]"):
        rs.simulate(BLOCK, pulse, friction=-0.5)
    with pytest.raises(ValueError, match="'complex' does not compute the friction demand"):
        rs.simulate(BLOCK, pulse, method="complex", friction=0.5)
    r = rs.simulate(BLOCK, pulse, method="complex")
    assert r.friction_demand is None and r.lift_off is None
    assert "friction_demand" not in r.summary()


def test_overturned_block_demand_stops_before_the_fall():
    """An overturning: the demand covers the rocking up to |theta| = alpha, not the fall,
    where F_v tends to 0 (see the falling-block test)."""
    r = rs.simulate(BLOCK, SinePulse(amplitude=3 * UPLIFT, period=0.5))
    assert r.overturned and r.lift_off is False and math.isfinite(r.friction_demand)
    assert r._contact_check().time < r.overturn_time


def test_linear_model_demand_near_the_nonlinear_for_a_stocky_block():
    """The linearized model's history through its own theta_ddot: within O(alpha^2) of
    Housner's for alpha = 0.05."""
    block = rs.Block(half_diagonal=1.0, slenderness=0.05)
    pulse = SinePulse(amplitude=2.0 * G * math.tan(0.05), period=0.4)
    lin = rs.simulate(block, pulse, method="linear")
    non = rs.simulate(block, pulse)
    assert lin.friction_demand == pytest.approx(non.friction_demand, rel=0.05**2 * 4)


def test_batch_friction_demand_rows():
    """simulate_batch(outputs=[..., "friction_demand", "lift_off"]): below uplift
    max |a_g| / g exactly; rows that rock as the scipy reference's demand (another solver);
    the other outputs bit for bit as without them, and not in the default outputs."""
    amps = np.array([0.5, 0.99, 1.6, 2.5]) * UPLIFT
    kw = dict(half_diagonal=R, slenderness=ALPHA, pulse="sine", amplitude=amps, period=0.6)
    plain = rs.simulate_batch(**kw, rtol=1e-10)
    assert "friction_demand" not in plain
    out = rs.simulate_batch(**kw, rtol=1e-10, outputs=[*plain, "friction_demand", "lift_off"])
    for name, values in plain.items():
        np.testing.assert_array_equal(out[name], values)
    np.testing.assert_allclose(out["friction_demand"][:2], amps[:2] / G, rtol=1e-14)
    for amp, demand in zip(amps[2:], out["friction_demand"][2:], strict=True):
        ref = rs.simulate(BLOCK, SinePulse(amplitude=amp, period=0.6), method="scipy", rtol=1e-10)
        assert demand == pytest.approx(ref.friction_demand, rel=1e-7)
    assert not out["lift_off"].any()


def test_batch_lift_off_and_vertical_rows():
    t, a_h, a_v = lift_record()
    rec = Record(a_h, time=t, vertical=a_v)
    scale = np.array([0.2, 1.0])
    out = rs.simulate_batch(
        half_diagonal=R,
        slenderness=ALPHA,
        record=rec,
        scale=scale,
        outputs=["friction_demand", "lift_off"],
    )
    assert out["lift_off"].tolist() == [False, True]
    assert out["friction_demand"][1] == math.inf
    expected = np.max(np.abs(0.2 * a_h) / (G + 0.2 * a_v))  # at rest throughout
    assert out["friction_demand"][0] == pytest.approx(expected, rel=1e-14)
    with pytest.raises(ValueError, match="allowed: .*'friction_demand', 'lift_off'"):
        rs.simulate_batch(
            half_diagonal=R, slenderness=ALPHA, amplitude=1.0, period=0.5, outputs=["friction"]
        )


def test_batch_linear_rows_between_the_two_uplift_levels_rock():
    """The linearized model lifts at g alpha, below the nonlinear g tan(alpha): a linear row
    with g alpha < a_g < g tan(alpha) rocks, so its demand is not the at-rest a_g / g (the
    demand of its simulated rocking history, max rotation > 0)."""
    alpha = 0.2
    amplitude = 1.005 * G * alpha  # above g alpha, below g tan(alpha) = 1.0135 g alpha
    out = rs.simulate_batch(
        half_diagonal=1.0,
        slenderness=alpha,
        pulse="sine",
        amplitude=amplitude,
        period=1.0,
        method="linear",
        outputs=["max_rotation", "friction_demand", "lift_off"],
    )
    res = rs.simulate(rs.Block(1.0, alpha), SinePulse(amplitude, 1.0), method="linear")
    assert out["max_rotation"][0] > 0.0 and res.max_rotation > 0.0
    assert out["friction_demand"][0] != pytest.approx(amplitude / G, rel=1e-6)
    assert out["friction_demand"][0] == pytest.approx(res.friction_demand, rel=1e-12)
