"""Block geometry and Housner's restitution, eq. (2.2) and (2.4) of [000]."""

import math

import numpy as np
import pytest
from scipy.integrate import dblquad

import rockstudy as rs
from rockstudy.constants import G


def rectangle_inertia(b, h):
    """Polar moments of a uniform 2b x 2h rectangle of unit mass, by numerical integration:
    about its centre of mass and about a bottom corner [m^2]."""

    def polar(x0, y0):
        val, _ = dblquad(lambda y, x: (x - x0) ** 2 + (y - y0) ** 2, 0, 2 * b, 0, 2 * h)
        return val / (4 * b * h)

    return polar(b, h), polar(0.0, 0.0)


@pytest.mark.parametrize("width, height", [(0.2, 1.0), (0.6, 2.4), (1.0, 1.5)])
def test_frequency_parameter_of_a_rectangle(width, height):
    """p^2 = m g R / I_O for rotation about a corner O (Housner): with I_O integrated over the
    rectangle, not taken from a formula."""
    blk = rs.Block.from_dimensions(width=width, height=height)
    _, i_corner = rectangle_inertia(width / 2, height / 2)
    R = math.hypot(width / 2, height / 2)
    assert blk.frequency_parameter == pytest.approx(math.sqrt(G * R / i_corner), rel=1e-10)


@pytest.mark.parametrize("width, height", [(0.2, 1.0), (0.6, 2.4), (1.0, 1.5)])
def test_housner_restitution_by_momentum_balance(width, height):
    """Angular momentum about the new pivot O' is conserved through the impact (Housner):
    before it, the block turns at w about O, so H_O' = I_G w + m (r_O'G x v_G) with
    v_G = w x r_OG; after it, H_O' = I_O' w+. eta = w+ / w, with the moments integrated."""
    blk = rs.Block.from_dimensions(width=width, height=height)
    b, h = width / 2, height / 2
    i_centre, i_corner = rectangle_inertia(b, h)
    w = 1.0  # rotation about O = (0, 0), just before O' = (2b, 0) lands
    r_og = np.array([b, h])
    v_g = w * np.array([-r_og[1], r_og[0]])  # w e_z x r_OG
    r_pg = r_og - np.array([2 * b, 0.0])
    h_before = i_centre * w + (r_pg[0] * v_g[1] - r_pg[1] * v_g[0])
    assert blk.restitution == pytest.approx(h_before / (i_corner * w), rel=1e-10)


def test_from_dimensions_recovers_R_and_alpha():
    blk = rs.Block.from_dimensions(width=0.6, height=2.4)
    assert blk.half_diagonal == pytest.approx(math.hypot(0.3, 1.2))
    assert math.tan(blk.slenderness) == pytest.approx(0.3 / 1.2)
    assert blk.width == pytest.approx(0.6) and blk.height == pytest.approx(2.4)


def test_user_restitution_is_kept():
    assert rs.Block(1.0, 0.2, restitution=0.9).restitution == 0.9


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"half_diagonal": -1.0, "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": 0.0, "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": float("nan"), "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": 1.0, "slenderness": 0.0}, "slenderness"),
        ({"half_diagonal": 1.0, "slenderness": math.pi / 2}, "slenderness"),
        ({"half_diagonal": 1.0, "slenderness": -0.1}, "slenderness"),
        ({"half_diagonal": 1.0, "slenderness": 0.2, "restitution": 0.0}, "restitution"),
        ({"half_diagonal": 1.0, "slenderness": 0.2, "restitution": 1.2}, "restitution"),
        # issue 26: beyond the ranges (the kernels divided by zero at alpha = 1e-300), and
        # values that are no numbers
        ({"half_diagonal": 1.0, "slenderness": 1e-300}, "slenderness"),
        ({"half_diagonal": 1e-300, "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": 1e300, "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": "1", "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": True, "slenderness": 0.2}, "half_diagonal"),
        ({"half_diagonal": 1.0, "slenderness": 0.2, "restitution": "0.5"}, "restitution"),
    ],
)
def test_bad_block_input_names_the_argument(kwargs, field):
    with pytest.raises(ValueError, match=field):
        rs.Block(**kwargs)


def test_bad_dimensions_name_the_argument():
    with pytest.raises(ValueError, match="width"):
        rs.Block.from_dimensions(width=-0.1, height=1.0)
    with pytest.raises(ValueError, match="height"):
        rs.Block.from_dimensions(width=0.1, height=0.0)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: rs.motions.SinePulse(amplitude=5.0, period=1e-300), "period"),
        (lambda: rs.motions.RickerWavelet(amplitude=5.0, period=1e300), "period"),
        (lambda: rs.motions.SinePulse(amplitude=1e300, period=0.5), "amplitude"),
        (lambda: rs.motions.SinePulse(amplitude="5", period=0.5), "amplitude"),
        (lambda: rs.motions.SinePulse(amplitude=5.0, period=0.5, cycles=10**9), "cycles"),
        (lambda: rs.motions.synthetic_near_fault(pulse_period=1e6, pga=4.0), "pulse_period"),
        (lambda: rs.motions.synthetic_near_fault(1.0, 4.0, duration=1e6, dt=1e-5), "duration"),
        (lambda: rs.motions.synthetic_near_fault(1.0, 4.0, vertical="yes"), "vertical"),
    ],
)
def test_pulses_and_synthetic_records_refuse_naming_the_argument(make, field):
    """Issue 26: SinePulse(period=1e-300) gave a ZeroDivisionError in the kernel, and
    synthetic_near_fault(pulse_period=1e6) ran a minute in 8 GB; both are range errors now."""
    with pytest.raises(ValueError, match=rf"^{field}"):
        make()


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"dt_out": "0.1"}, "dt_out"),
        ({"dt_out": True}, "dt_out"),
        ({"dt_out": 1e-12}, "dt_out"),  # 5e11 output times: refused with a memory estimate
    ],
)
def test_simulate_refuses_output_grids_naming_the_argument(kwargs, field):
    blk, pulse = rs.Block(1.0, 0.2), rs.motions.SinePulse(0.5, 0.5)
    with pytest.raises(ValueError, match=rf"^{field}") as err:
        rs.simulate(blk, pulse, t_max=1.0, **kwargs)
    if kwargs["dt_out"] == 1e-12:
        assert "GiB" in str(err.value)


def test_simulate_batch_refuses_a_record_with_pulse_arguments():
    rec = rs.motions.Record([0.0, 1.0, -1.0, 0.0], dt=0.01)
    with pytest.raises(ValueError, match="record= takes no amplitude, period"):
        rs.simulate_batch(half_diagonal=1.0, slenderness=0.2, record=rec, amplitude=1.0, period=0.5)
