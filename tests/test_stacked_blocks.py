"""Two stacked rocking blocks (StackedBlocks) against independent oracles: Housner's single
block where one body cannot move or has no mass, the composite rigid body where the upper
block never lifts, and the energy balance computed here from the bodies' geometry."""

import math

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics.stacked_reference import simulate_stacked
from rockstudy.motions import NoMotion, SinePulse
from rockstudy.structures import Block, EquivalentBlock, StackedBlocks


def _housner(block, motion):
    """Housner's single block by the solve_ivp reference at rtol 1e-12."""
    return rs.simulate(block, motion, method="scipy", rtol=1e-12)


def test_plinth_that_cannot_move_leaves_the_upper_block_housners():
    """A wide, heavy plinth never lifts: the statue on it, centred or not, is Housner's
    block on the ground."""
    lower, upper = Block(6.0, 0.9), Block(0.5, 0.2)
    for amplitude, period, offset in ((3.0, 0.6, 0.0), (2.2, 1.0, -2.0), (5.0, 0.3, 1.5)):
        motion = SinePulse(amplitude=amplitude, period=period)
        pair = StackedBlocks(lower, upper, density_ratio=0.5, offset=offset)
        r = rs.simulate(pair, motion, rtol=1e-12)
        assert not np.any(np.isin(r.regime, ["lower", "both"]))  # the plinth stayed put
        ref = _housner(upper, motion)
        assert r.overturned == ref.overturned
        assert r.max_rotation_upper == pytest.approx(ref.max_rotation, rel=1e-9)
        assert r.max_rotation_lower == 0.0
        assert r.overturned_body == ("upper" if ref.overturned else None)
        ds = r.to_xarray()
        assert ds.attrs["max_rotation_upper"] == r.max_rotation_upper
        np.testing.assert_array_equal(ds["theta_upper"].values, r.theta_upper)


def test_upper_block_of_vanishing_mass_leaves_the_lower_block_housners():
    """density_ratio 1e-9: the plinth rocks as Housner's block alone."""
    lower, upper = Block(1.0, 0.25), Block(0.2, 0.7)  # a squat statue: it does not fall off
    for amplitude, period in ((4.0, 0.8), (6.0, 0.5)):
        motion = SinePulse(amplitude=amplitude, period=period)
        r = rs.simulate(StackedBlocks(lower, upper, density_ratio=1e-9), motion, rtol=1e-12)
        ref = _housner(lower, motion)
        assert ref.max_rotation > 0.02  # the plinth rocks
        assert r.overturned == ref.overturned
        assert r.max_rotation_lower == pytest.approx(ref.max_rotation, rel=1e-7)


def _composite(lower, upper, density_ratio):
    """The locked assembly as one rigid body about a lower corner (Table I of [003]: a body's
    p^2 = m g R_c / I_O, theta_cr = atan(b / y_c)), and Housner's restitution of a body whose
    pivots are 2 b apart, eta = 1 - 2 m b^2 / I_O: (p, alpha, eta, y_c, m's, I's)."""
    b1, h1, b2, h2 = lower.width / 2, lower.height / 2, upper.width / 2, upper.height / 2
    m1, m2 = 4 * b1 * h1, density_ratio * 4 * b2 * h2
    m = m1 + m2
    yc = (m1 * h1 + m2 * (2 * h1 + h2)) / m
    i_g = m1 * (b1**2 + h1**2) / 3 + m1 * (yc - h1) ** 2
    i_g += m2 * (b2**2 + h2**2) / 3 + m2 * (2 * h1 + h2 - yc) ** 2
    i_o = i_g + m * (b1**2 + yc**2)
    p = math.sqrt(m * G * math.hypot(b1, yc) / i_o)
    return p, math.atan2(b1, yc), 1 - 2 * m * b1**2 / i_o


def _upper_contact_margins(lower, upper, p, alpha, motion, t, theta, omega):
    """s M_s at the upper block's base corners s = +1, -1 [N m per unit mass ratio]: the
    clockwise moment about the corner s of the lower top's contact on the upper block, from
    Newton-Euler on the upper block moving with the composite body (theta, omega) of
    Housner's equation with (p, alpha); >= 0 at both corners while the contact holds."""
    b1, h1, b2, h2 = lower.width / 2, lower.height / 2, upper.width / 2, upper.height / 2
    ug = motion.ground_acceleration(t)
    side = np.where(theta != 0, np.sign(theta), 1.0)
    acc = -(p**2) * (np.sin(alpha * side - theta) + ug / G * np.cos(alpha * side - theta))
    c, s = np.cos(theta), np.sin(theta)

    def place(x, y):  # a body point (x, y) from the pivot, after the tipping theta
        return x * c + y * s, -x * s + y * c

    gx, gy = place(-side * b1, 2 * h1 + h2)  # upper centre from the pivot
    ax = gy * acc - gx * omega**2  # d2/dt2 of (gx, gy): J r theta'' - Rot r theta'^2
    ay = -gx * acc - gy * omega**2
    fx, fy = ax + ug, ay + G  # contact force on the upper block per unit mass
    couple = (b2**2 + h2**2) / 3 * acc  # I theta'' about its centre per unit mass
    margins = []
    for corner in (1, -1):
        qx, qy = place(corner * b2 - side * b1, 2 * h1)
        rx, ry = gx - qx, gy - qy
        margins.append(corner * (couple - (rx * fy - ry * fx)))
    return np.array(margins)


def test_locked_assembly_is_one_rigid_body_about_the_lower_corner():
    """A squat statue on a slender plinth under a moderate pulse never lifts off its plinth
    (its contact moments, computed here, stay compressive): the assembly rocks as the rigid
    body whose p, alpha and restitution come from the composite centre of mass and inertia."""
    lower, upper, rho = Block(1.2, 0.15), Block(0.3, 0.6), 2.0
    p, alpha, eta = _composite(lower, upper, rho)
    motion = SinePulse(amplitude=2.0, period=0.6)
    ref = rs.simulate(EquivalentBlock(p, alpha, eta), motion, method="scipy", rtol=1e-12)
    assert 0.3 * alpha < ref.max_rotation < alpha and ref.impact_times.size  # it rocks, impacts
    t = np.linspace(0.0, ref.t[-1], 20001)
    dense = rs.simulate(
        EquivalentBlock(p, alpha, eta), motion, method="scipy", t_eval=t, rtol=1e-12
    )
    margins = _upper_contact_margins(
        lower, upper, p, alpha, motion, t, dense.theta_eval, dense.theta_dot_eval
    )
    assert margins.min() > 0.0  # the upper block never lifts
    r = rs.simulate(StackedBlocks(lower, upper, density_ratio=rho), motion, rtol=1e-12)
    assert r.max_rotation_upper == 0.0
    assert not r.overturned
    assert r.max_rotation_lower == pytest.approx(ref.max_rotation, rel=1e-9)
    n = min(4, ref.impact_times.size)
    np.testing.assert_allclose(r.impact_times[:n], ref.impact_times[:n], rtol=1e-9)


def _pivots(t, angle, rate):
    """The pivot corner (+1 or -1) of an interface on each history row: the sign of its
    angle; at an impact (an angle within 1e-12 of zero, the time repeated), the side it came
    from on the row before (-sign of its rate) and the side it goes to on the row after."""
    side = np.sign(angle)
    at_zero = np.abs(angle) < 1e-12
    before = np.r_[t[1:] == t[:-1], False]
    side[at_zero & before] = -np.sign(rate[at_zero & before])
    side[at_zero & ~before] = np.sign(rate[at_zero & ~before])
    return np.where(side == 0, 1.0, side)


def _energy(lower, upper, rho, r):
    """Kinetic plus potential energy of the two blocks [J per unit thickness and density],
    zero upright at rest, on each history row of r, from the bodies' corners: each body's
    centre of mass and spin."""
    b1, h1, b2, h2 = lower.width / 2, lower.height / 2, upper.width / 2, upper.height / 2
    m1, m2 = 4 * b1 * h1, rho * 4 * b2 * h2
    th1, phi, om1, om_phi = r.theta_lower, r.theta_upper, r.theta_lower_dot, r.theta_upper_dot
    s1, s2 = _pivots(r.t, th1, om1), _pivots(r.t, phi, om_phi)
    th2, om2 = th1 + phi, om1 + om_phi

    def point(theta, x, y):  # position and d/dtheta of a body point (x, y) from a pivot
        c, s = np.cos(theta), np.sin(theta)
        return (x * c + y * s, -x * s + y * c), (-x * s + y * c, -x * c - y * s)

    (_, y1), (dx1, dy1) = point(th1, -s1 * b1, h1)
    (_, yq), (dxq, dyq) = point(th1, s2 * b2 - s1 * b1, 2 * h1)
    (_, y2), (dx2, dy2) = point(th2, -s2 * b2, h2)
    v1 = (dx1 * om1, dy1 * om1)
    v2 = (dxq * om1 + dx2 * om2, dyq * om1 + dy2 * om2)
    kin = 0.5 * m1 * (v1[0] ** 2 + v1[1] ** 2) + 0.5 * m1 * (b1**2 + h1**2) / 3 * om1**2
    kin += 0.5 * m2 * (v2[0] ** 2 + v2[1] ** 2) + 0.5 * m2 * (b2**2 + h2**2) / 3 * om2**2
    return kin + G * (m1 * (y1 - h1) + m2 * (yq + y2 - 2 * h1 - h2))


@pytest.mark.parametrize("initial", [(0.08, 0.0, 0.0, 0.0), (0.05, 0.1, 0.0, 0.0)])
def test_energy_is_conserved_between_impacts_and_never_created(initial):
    """Free rocking (locked, then both rocking): the energy computed here from the history
    stays constant to 1e-10 up to the first impact, and no impact raises it."""
    lower, upper, rho = Block(1.0, 0.2), Block(0.4, 0.25), 1.5
    r = simulate_stacked(
        StackedBlocks(lower, upper, rho), NoMotion(), rtol=1e-12, t_max=6.0, initial=initial
    )
    e = _energy(lower, upper, rho, r)
    assert r.impact_times.size >= 3
    first = np.searchsorted(r.t, r.impact_times[0])  # the row just before the first impact
    assert np.max(np.abs(e[: first + 1] - e[0])) <= 1e-10 * e[0]
    for t in r.impact_times:
        i = np.flatnonzero(r.t == t)
        assert e[i[-1]] <= e[i[0]] * (1 + 1e-12)  # after <= before
    assert np.all(np.diff(e) <= 1e-9 * e[0])  # never rises between or at impacts


def test_input_errors_name_the_field():
    lower, upper = Block(1.0, 0.3), Block(0.5, 0.2)
    with pytest.raises(TypeError, match="lower"):
        StackedBlocks("plinth", upper)
    with pytest.raises(TypeError, match="upper"):
        StackedBlocks(lower, 1.0)
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="density_ratio"):
            StackedBlocks(lower, upper, density_ratio=bad)
    with pytest.raises(TypeError, match="density_ratio"):
        StackedBlocks(lower, upper, density_ratio="1")
    with pytest.raises(ValueError, match="offset"):
        StackedBlocks(lower, upper, offset=lower.width / 2 - upper.width / 2 + 1e-3)
    with pytest.raises(ValueError, match="offset"):
        StackedBlocks(lower, upper, offset=math.nan)
    assert StackedBlocks(lower, upper, offset=-(lower.width - upper.width) / 2).offset < 0
    with pytest.raises(ValueError, match="upper"):
        StackedBlocks(lower, Block(0.5, 0.2, restitution=0.9))
    s = StackedBlocks(lower, upper)
    with pytest.raises(ValueError, match="method"):
        rs.simulate(s, SinePulse(3.0, 0.5), method="linear")
    with pytest.raises(ValueError, match="friction"):
        rs.simulate(s, SinePulse(3.0, 0.5), friction=0.5)
    with pytest.raises(ValueError, match="initial_rotation"):
        rs.simulate(s, SinePulse(3.0, 0.5), initial_rotation=0.1)
