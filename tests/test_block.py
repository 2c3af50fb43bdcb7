"""Block geometry and Housner's restitution, eq. (2.2) and (2.4) of [000]."""

import math

import pytest

import rockstudy as rs
from rockstudy.constants import G


def test_frequency_parameter_is_sqrt_3g_over_4R():
    for R in (0.1, 1.0, 7.3):
        assert rs.Block(R, 0.2).frequency_parameter == pytest.approx(
            math.sqrt(3 * G / (4 * R)), rel=1e-15
        )


def test_housner_restitution_by_momentum_balance():
    # angular momentum about the new pivot: I0 w- - 2 m b^2 w- ... = I0 w+, with I0 = 4/3 m R^2
    # gives eta = 1 - 2 m b^2 / I0 * ... = 1 - 3/2 sin^2(alpha)
    for alpha in (0.05, 0.2, 0.6):
        blk = rs.Block(1.0, alpha)
        b = math.sin(alpha)  # half-width for R = 1
        i0 = 4.0 / 3.0
        eta_momentum = (i0 - 2.0 * b * b) / i0
        assert blk.restitution == pytest.approx(eta_momentum, rel=1e-14)


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
