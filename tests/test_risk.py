"""rockstudy.risk: hazard curves and the annual rate of overturning.

Oracles: the closed form of Cornell et al. (2002) for a power-law hazard and a lognormal
fragility, lambda = k0 theta^-k exp(k^2 beta^2 / 2); the Gaussian integral for a hazard
quadratic in log-log (Vamvatsikos 2013's second-order form), tabulated on grids of known step;
scipy's quadrature of P(OT | x) |d lambda| for the deaggregation; Poisson probabilities; and
small OpenQuake files written here in the engine's two header styles (rate = -ln(1 - poe) / T
by hand).
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.stats import norm

from rockstudy import risk
from rockstudy.constants import STANDARD_GRAVITY as G_UNIT
from rockstudy.risk import HazardCurve, annual_rate, probability_in, rate_deaggregation

DATA = Path(__file__).resolve().parents[1] / "data" / "hazard"


def cornell(k0, k, theta, beta):
    """Cornell et al. (2002): power-law hazard k0 x^-k, lognormal capacity (theta, beta)."""
    return k0 * theta**-k * np.exp(0.5 * (k * beta) ** 2)


def second_order(c0, k1, k2, theta, beta):
    """E[exp(c0 - k1 Y - k2 Y^2)], Y ~ N(ln theta, beta^2): the expected second-order hazard
    at a lognormal capacity, by completing the square (a Gaussian integral)."""
    m, a, b = np.log(theta), -k2, -k1
    d = 1.0 - 2.0 * a * beta**2
    return np.exp(c0) / np.sqrt(d) * np.exp((a * m * m + b * m + 0.5 * b * b * beta**2) / d)


def test_power_law_matches_cornell_closed_form_broadcast():
    k0, k = 2e-4, 2.3
    hazard = HazardCurve.power_law(k0, k, im="pga", units="g")
    theta = np.array([[0.05], [0.3], [1.2], [4.0]])
    beta = np.array([0.0, 0.2, 0.45, 0.8])
    got = annual_rate(theta, beta, hazard)
    assert got.shape == (4, 4)
    np.testing.assert_allclose(got, cornell(k0, k, theta, beta), rtol=1e-10)


@pytest.mark.parametrize("k", [1.2, 2.3, 3.5])
def test_two_levels_far_from_the_fragility_still_give_the_closed_form(k):
    """The tails: a power law tabulated on two levels far above the fragility's mass is
    extrapolated as that power law, so the fragility below the grid counts in full."""
    hazard = HazardCurve("pga", [5.0, 8.0], [1e-3 * 5.0**-k, 1e-3 * 8.0**-k], units="g")
    assert annual_rate(0.2, 0.5, hazard) == pytest.approx(cornell(1e-3, k, 0.2, 0.5), rel=1e-10)
    hazard = HazardCurve("pga", [1e-3, 2e-3], [1e-3 * 1e-3**-k, 1e-3 * 2e-3**-k], units="g")
    assert annual_rate(0.2, 0.5, hazard) == pytest.approx(cornell(1e-3, k, 0.2, 0.5), rel=1e-10)


def test_curved_hazard_to_the_accuracy_of_its_grid():
    """ln lambda = c0 - k1 L - k2 L^2 tabulated with step d in L = ln x: the log-log chords lie
    below the concave ln lambda by k2 t (d - t) at t into an interval, at most k2 d^2 / 4 and
    k2 d^2 / 6 on average, so lambda_OT falls short by about k2 d^2 / 6 (relative), at most
    k2 d^2 / 4; the error falls as d^2."""
    c0, k1, k2 = -9.74, 2.98, 0.289
    theta, beta = 0.3, 0.45
    exact = second_order(c0, k1, k2, theta, beta)
    errors = []
    for d in (0.4, 0.2, 0.1):
        L = np.arange(np.log(theta) - 8 * beta, np.log(theta) + 8 * beta, d)
        hazard = HazardCurve("pga", np.exp(L), np.exp(c0 - k1 * L - k2 * L**2), units="g")
        err = annual_rate(theta, beta, hazard) / exact - 1.0
        assert -k2 * d * d / 4.0 <= err < 0.0
        assert err == pytest.approx(-k2 * d * d / 6.0, rel=0.05)
        errors.append(err)
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.05)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.05)


def test_sharp_capacity_is_the_hazard_at_the_capacity():
    hazard = HazardCurve("pga", [0.1, 0.2, 0.4], [1e-2, 3e-3, 5e-4], units="g")
    for theta in (0.05, 0.1, 0.15, 0.4, 0.7):
        assert annual_rate(theta, 0.0, hazard) == pytest.approx(hazard.rate(theta), rel=1e-12)
        # |d lambda| over [theta, inf), interval by interval: lambda(max(a, theta)) - lambda(b)
        lower, upper, parts = rate_deaggregation(theta, 0.0, hazard)
        a = np.maximum(lower, theta)
        expected = np.where(upper > theta, hazard.rate(a) - hazard.rate(upper), 0.0)
        np.testing.assert_allclose(parts, expected, rtol=1e-12, atol=1e-15)
    # between levels the interpolant is the power law through the two neighbours
    k = math.log(3e-3 / 5e-4) / math.log(2.0)
    assert hazard.rate(0.3) == pytest.approx(3e-3 * 1.5**-k, rel=1e-12)


def test_deaggregation_sums_and_matches_quadrature_on_each_interval():
    hazard = HazardCurve("pga", [0.1, 0.2, 0.4, 0.8], [1e-2, 3e-3, 5e-4, 4e-5], units="g")
    theta, beta = 0.35, 0.4
    lower, upper, parts = rate_deaggregation(theta, beta, hazard)
    assert lower[0] == 0.0 and upper[-1] == np.inf and parts.shape == (5,)
    assert parts.sum() == pytest.approx(annual_rate(theta, beta, hazard), rel=1e-12)

    def integrand(x):  # P(OT | x) |d lambda / dx|, the derivative by central differences
        h = 1e-6 * x
        return (
            norm.cdf(np.log(x / theta) / beta) * (hazard.rate(x - h) - hazard.rate(x + h)) / (2 * h)
        )

    for a, b, part in zip(lower, upper, parts, strict=True):
        expected = quad(integrand, max(a, 1e-9), b, epsrel=1e-10, limit=200)[0]
        assert part == pytest.approx(expected, rel=1e-6, abs=1e-14)


def truncated_cornell(k0, k, theta, beta, x_u):
    """The power-law rate of a lognormal fragility set to 0 below x_u, by parts:
    lambda(x_u) F(x_u) + E[k0 C^-k; C > x_u], the second a shifted normal's tail."""
    z = np.log(x_u / theta) / beta
    return k0 * x_u**-k * norm.cdf(z) + cornell(k0, k, theta, beta) * norm.cdf(-z - k * beta)


@pytest.mark.parametrize("x_u", [0.004, 0.1, 0.25, 0.3, 0.8, 9.0])
def test_a_threshold_gives_the_truncated_closed_form(x_u):
    """Below, on, between and beyond the tabulated levels of a power law."""
    k0, k, theta, beta = 2e-4, 2.3, 0.5, 0.6
    hazard = HazardCurve.power_law(k0, k, im="pga", units="g", levels=[0.01, 0.1, 0.3, 1.0, 5.0])
    exact = truncated_cornell(k0, k, theta, beta, x_u)
    assert annual_rate(theta, beta, hazard, threshold=x_u) == pytest.approx(exact, rel=1e-12)
    lower, upper, parts = rate_deaggregation(theta, beta, hazard, threshold=x_u)
    assert parts.sum() == pytest.approx(exact, rel=1e-12)
    assert np.all(parts[upper <= x_u] == 0.0) and np.all(parts >= -1e-18)
    # the same threshold in m/s^2 with the median in m/s^2
    si = annual_rate(theta * G_UNIT, beta, hazard, units="m/s^2", threshold=x_u * G_UNIT)
    assert si == pytest.approx(exact, rel=1e-12)


def test_a_threshold_on_a_curved_hazard_matches_quadrature_interval_by_interval():
    hazard = HazardCurve("pga", [0.1, 0.2, 0.4, 0.8], [1e-2, 3e-3, 5e-4, 4e-5], units="g")
    theta, beta, x_u = 0.35, 0.4, 0.27
    lower, upper, parts = rate_deaggregation(theta, beta, hazard, threshold=x_u)

    def integrand(x):  # P(OT | x) |d lambda / dx| above x_u, by central differences
        h = 1e-6 * x
        return (
            norm.cdf(np.log(x / theta) / beta) * (hazard.rate(x - h) - hazard.rate(x + h)) / (2 * h)
        )

    for a, b, part in zip(lower, upper, parts, strict=True):
        expected = quad(integrand, max(a, x_u), b, epsrel=1e-10, limit=200)[0] if b > x_u else 0
        assert part == pytest.approx(expected, rel=1e-6, abs=1e-14)
    assert annual_rate(theta, beta, hazard, threshold=x_u) == pytest.approx(parts.sum(), rel=1e-12)


def test_a_threshold_with_a_sharp_capacity_is_the_hazard_at_the_larger():
    hazard = HazardCurve("pga", [0.1, 0.2, 0.4], [1e-2, 3e-3, 5e-4], units="g")
    for theta, x_u in [(0.15, 0.3), (0.3, 0.15), (0.05, 0.07)]:
        got = annual_rate(theta, 0.0, hazard, threshold=x_u)
        assert got == pytest.approx(hazard.rate(max(theta, x_u)), rel=1e-12)


def test_a_threshold_broadcasts_and_is_checked():
    hazard = HazardCurve.power_law(2e-4, 2.3, im="pga", units="g")
    got = annual_rate([0.3, 0.5], [0.4, 0.6], hazard, threshold=[[0.1], [0.2]])
    expected = truncated_cornell(
        2e-4, 2.3, np.array([0.3, 0.5]), np.array([0.4, 0.6]), np.array([[0.1], [0.2]])
    )
    assert got.shape == (2, 2)
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="threshold"):
            annual_rate(0.3, 0.4, hazard, threshold=bad)


def test_probability_in_years():
    assert probability_in(50, 1 / 475) == pytest.approx(1 - math.exp(-50 / 475), rel=1e-15)
    assert probability_in(50, 0.0) == 0.0
    got = probability_in(np.array([1.0, 50.0]), np.array([[1e-3], [2e-3]]))
    assert got.shape == (2, 2)
    # tiny rates: no cancellation (1 - exp(-x) ~ x)
    assert probability_in(1.0, 1e-12) == pytest.approx(1e-12, rel=1e-9)


def test_units_convert_and_cannot_trap():
    hazard = HazardCurve.power_law(2e-4, 2.3, im="pga", units="g")
    si = hazard.to_si()
    assert si.units == "m/s^2"
    np.testing.assert_allclose(si.levels, hazard.levels * G_UNIT)
    np.testing.assert_allclose(si.rate(0.3 * G_UNIT), hazard.rate(0.3), rtol=1e-12)
    # a median given in m/s^2 against a hazard in g
    assert annual_rate(0.3 * G_UNIT, 0.4, hazard, units="m/s^2") == pytest.approx(
        annual_rate(0.3, 0.4, hazard), rel=1e-12
    )
    assert annual_rate(0.3 * G_UNIT, 0.4, si) == pytest.approx(
        annual_rate(0.3, 0.4, hazard), rel=1e-12
    )
    with pytest.raises(ValueError, match="units='m/s' is not a unit of 'pga'"):
        HazardCurve("pga", [0.1, 0.2], [1e-2, 1e-3], units="m/s")
    with pytest.raises(ValueError, match="units='g' is not a unit of 'pgv'"):
        annual_rate(0.3, 0.4, HazardCurve.power_law(1e-3, 2.0, im="pgv", units="m/s"), units="g")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"im": "PGA"}, "im must be one of"),
        ({"levels": [0.1]}, "levels must be a 1-D sequence of at least 2"),
        ({"levels": [0.1, -0.2]}, r"levels must be finite and > 0; levels\[1\]"),
        ({"levels": [0.2, 0.1]}, r"levels must be strictly increasing; levels\[1\]"),
        ({"levels": [0.1, np.nan]}, r"levels must be finite"),
        ({"rates": [1e-2, 2e-2]}, r"rates must be non-increasing.*rates\[1\]"),
        ({"rates": [1e-2, 0.0]}, r"rates must be finite and > 0; rates\[1\]"),
        ({"rates": [1e-2, 1e-2]}, "last two rates are equal"),
        ({"rates": [1e-2, 1e-3, 1e-4]}, "rates has 3 values but levels has 2"),
        ({"units": "furlong"}, "units of 'pga' must be one of"),
        ({"period": 0.5}, "period is only for the spectral"),
        ({"im": "sa"}, "period: a 'sa' hazard curve needs its period"),
    ],
)
def test_hazard_curve_refuses_bad_input_naming_the_argument(kwargs, match):
    args = {"im": "pga", "levels": [0.1, 0.2], "rates": [1e-2, 1e-3], "units": "g"} | kwargs
    with pytest.raises(ValueError, match=match):
        HazardCurve(**args)


def test_fragility_and_probability_arguments_are_checked():
    hazard = HazardCurve.power_law(2e-4, 2.3, units="g")
    with pytest.raises(ValueError, match="median must be finite and > 0"):
        annual_rate([0.3, 0.0], 0.4, hazard)
    with pytest.raises(ValueError, match=r"dispersion must be finite and in \[0, 10\]"):
        annual_rate(0.3, -0.1, hazard)
    with pytest.raises(TypeError, match="hazard must be a HazardCurve"):
        annual_rate(0.3, 0.4, {"k0": 1.0})
    with pytest.raises(ValueError, match="years must be finite and > 0"):
        probability_in(0.0, 1e-3)
    with pytest.raises(ValueError, match="rate must be finite and >= 0"):
        probability_in(50, -1e-3)
    with pytest.raises(ValueError, match="k must be a finite number > 0"):
        HazardCurve.power_law(2e-4, 0.0)


def test_two_column_csv(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text("# my site\nlevel_g, rate\n0.1, 1e-2\n0.2, 3e-3\n\n0.4, 5e-4\n")
    hazard = HazardCurve.from_csv(path, im="pga", units="g")
    np.testing.assert_array_equal(hazard.levels, [0.1, 0.2, 0.4])
    np.testing.assert_array_equal(hazard.rates, [1e-2, 3e-3, 5e-4])
    assert hazard.units == "g" and str(path) in hazard.source
    (tmp_path / "blank.txt").write_text("0.1 1e-2\n0.2 3e-3\n")
    assert HazardCurve.from_csv(tmp_path / "blank.txt", im="pga").units == "m/s^2"
    with pytest.raises(ValueError, match="im: curve.csv is a two-column file"):
        HazardCurve.from_csv(path)
    (tmp_path / "three.csv").write_text("0.1,1e-2,5\n0.2,3e-3,6\n")
    with pytest.raises(ValueError, match="has 3 values"):
        HazardCurve.from_csv(tmp_path / "three.csv", im="pga")
    (tmp_path / "word.csv").write_text("0.1,1e-2\n0.2,abc\n")
    with pytest.raises(ValueError, match="is not two numbers"):
        HazardCurve.from_csv(tmp_path / "word.csv", im="pga")
    with pytest.raises(ValueError, match="path: cannot read"):
        HazardCurve.from_csv(tmp_path / "missing.csv", im="pga")


# The two header styles of OpenQuake's hazard_curve-*.csv (engine 3.11 and 3.15+).
OQ_OLD = (
    "# source_model_tree_path=('b1',), gsim_tree_path=('b1',), investigation_time=1.0,"
    'imt="PGA"\nlon,lat,depth,poe-0.1,poe-0.4,poe-0.6\n'
    "0.00000,0.00000,-0.10000,4.528811E-01,5.589804E-02,5.585141E-03\n"
)
OQ_NEW = (
    "#,,,,,\"generated_by='OpenQuake engine 3.15.0', start_date='2022-04-20T10:56:29', "
    "checksum=2704198065, kind='mean', investigation_time=50.0, imt='SA(0.1)'\"\n"
    "lon,lat,depth,poe-0.1000000,poe-0.4000000,poe-0.6000000,poe-0.9000000\n"
    "0.00000,0.00000,-0.10000,6.081918E-01,3.287217E-01,1.994702E-01,0.000000E+00\n"
    "1.00000,0.50000,-0.10000,5.0E-01,2.0E-01,1.0E-01,1.0E-03\n"
)


def test_openquake_csv_old_header(tmp_path):
    path = tmp_path / "hazard_curve-PGA.csv"
    path.write_text(OQ_OLD)
    hazard = HazardCurve.from_csv(path)
    assert (hazard.im, hazard.units, hazard.period) == ("pga", "g", None)
    np.testing.assert_array_equal(hazard.levels, [0.1, 0.4, 0.6])
    poe = np.array([4.528811e-01, 5.589804e-02, 5.585141e-03])
    np.testing.assert_allclose(hazard.rates, -np.log(1.0 - poe) / 1.0, rtol=1e-14)
    with pytest.raises(ValueError, match="im='pgv', but hazard_curve-PGA.csv is a hazard curve"):
        HazardCurve.from_csv(path, im="pgv")


def test_openquake_csv_new_header_sites_and_zero_poe(tmp_path):
    path = tmp_path / "hazard_curve-SA(0.1).csv"
    path.write_text(OQ_NEW)
    with pytest.raises(ValueError, match="holds 2 sites; choose one with site="):
        HazardCurve.from_csv(path)
    with pytest.warns(UserWarning, match="1 highest level"):
        first = HazardCurve.from_csv(path, site=0)
    assert (first.im, first.period, first.units) == ("sa", 0.1, "g")
    np.testing.assert_array_equal(first.levels, [0.1, 0.4, 0.6])
    poe = np.array([6.081918e-01, 3.287217e-01, 1.994702e-01])
    np.testing.assert_allclose(first.rates, -np.log(1.0 - poe) / 50.0, rtol=1e-14)
    second = HazardCurve.from_csv(path, im="sa", site=1)
    np.testing.assert_allclose(
        second.rates, -np.log(1.0 - np.array([0.5, 0.2, 0.1, 1e-3])) / 50.0, rtol=1e-14
    )
    with pytest.raises(ValueError, match=r"site must be a whole number in \[0, 1\]"):
        HazardCurve.from_csv(path, site=2)


def test_openquake_csv_refuses_what_it_cannot_read(tmp_path):
    path = tmp_path / "h.csv"
    path.write_text("# investigation_time=1.0, imt='MMI'\nlon,lat,poe-5\n0,0,0.1\n")
    with pytest.raises(ValueError, match="line 1: rockstudy reads PGA, PGV, PGD and SA"):
        HazardCurve.from_csv(path)
    path.write_text("# investigation_time=1.0, imt='PGA'\nlon,lat,poe-0.1,poe-0.2\n0,0,1.5,0.5\n")
    with pytest.raises(ValueError, match=r"must lie in \[0, 1\]"):
        HazardCurve.from_csv(path)
    path.write_text("# investigation_time=1.0, imt='PGA'\nlon,lat,poe-0.1,poe-0.2\n0,0,0.5,1.0\n")
    with pytest.raises(ValueError, match="of 1 stand above lower levels"):
        HazardCurve.from_csv(path)


def test_openquake_csv_certain_exceedance_at_the_lowest_levels(tmp_path):
    """A 50-year export at a high-hazard site prints poe 1 at its lowest levels (no finite
    rate): those levels are dropped with a warning, the others read as -ln(1 - poe) / T."""
    path = tmp_path / "hazard_curve-PGA.csv"
    path.write_text(
        "# investigation_time=50.0, imt='PGA'\nlon,lat,poe-0.05,poe-0.1,poe-0.2,poe-0.4\n"
        "0,0,1.0E+00,9.0E-01,4.0E-01,5.0E-02\n"
    )
    with pytest.warns(UserWarning, match="1 lowest level"):
        hazard = HazardCurve.from_csv(path)
    np.testing.assert_array_equal(hazard.levels, [0.1, 0.2, 0.4])
    np.testing.assert_allclose(hazard.rates, -np.log([0.1, 0.6, 0.95]) / 50.0, rtol=1e-14)
    path.write_text("# investigation_time=1.0, imt='PGV'\nlon,lat,poe-5,poe-10\n0,0,0.1,0.01\n")
    pgv = HazardCurve.from_csv(path)
    assert (pgv.im, pgv.units) == ("pgv", "cm/s")
    np.testing.assert_allclose(pgv.to_si().levels, [0.05, 0.10])


def test_shipped_site_curve_in_both_formats():
    """data/hazard/: the synthetic museum site, two columns and OpenQuake's CSV (50 years);
    both read to the same annual rates, through the return periods it was built on."""
    two = HazardCurve.from_csv(DATA / "site_pga.csv", im="pga", units="g")
    oq = HazardCurve.from_csv(DATA / "site_pga_openquake.csv")
    np.testing.assert_allclose(oq.levels, two.levels, rtol=1e-6)
    np.testing.assert_allclose(oq.rates, two.rates, rtol=1e-5)
    for level, period in ((0.05, 30.0), (0.25, 475.0), (0.5, 2475.0)):
        # log-log chords of a curve with k2 = 0.29 on steps d = 0.22 in ln x: k2 d^2 / 4 low
        assert two.rate(level) * period == pytest.approx(1.0, rel=4e-3)
    assert risk.probability_in(50, two.rate(0.25)) == pytest.approx(0.1, rel=0.01)


@pytest.mark.parametrize(
    "header, units, stated",
    [
        ("pga_g", "m/s2", "g"),
        ("pga_g", None, "g"),
        ("PGA [m/s^2]", "g", "m/s^2"),
        ("pga_gal", "g", "cm/s^2"),
    ],
)
def test_a_level_column_named_in_other_units_is_refused(tmp_path, header, units, stated):
    """A column ``pga_g`` read as m/s^2 would shift every level by 9.8: refused by name."""
    path = tmp_path / "h.csv"
    path.write_text(f"{header},annual_rate\n0.1,1e-2\n0.2,1e-3\n")
    with pytest.raises(ValueError, match=rf"^units: .*in {re.escape(stated)},"):
        HazardCurve.from_csv(path, im="pga", units=units)


@pytest.mark.parametrize("header, im", [("pga_g", "pgv"), ("sa_gal", "pga"), ("PGV [cm/s]", "pga")])
def test_a_level_column_named_for_another_measure_is_refused_naming_im(tmp_path, header, im):
    """The column says which measure the curve is of: read as another, the message names im
    (not the units, which would send the user round in circles)."""
    path = tmp_path / "h.csv"
    path.write_text(f"{header},annual_rate\n0.1,1e-2\n0.2,1e-3\n")
    named = header.split("_")[0].split(" ")[0].lower()
    with pytest.raises(ValueError, match=rf"^im: .*a {named} curve, but it is read as '{im}'"):
        HazardCurve.from_csv(path, im=im, units=None)


@pytest.mark.parametrize(
    "im, levels, units",
    [
        ("pga", [9.807, 98.07, 1961.0], "g"),  # cm/s^2 read as g
        ("pga", [0.5, 5.0, 20.0], "g"),  # m/s^2 read as g, to 2 g
        ("sa", [10.0, 100.0, 500.0], "g"),
        ("pgv", [1.0, 50.0, 300.0], "m/s"),  # cm/s read as m/s
    ],
)
def test_levels_beyond_any_ground_motion_are_refused_naming_units(im, levels, units):
    """The largest PGA ever recorded is about 4 g and PGV about 4 m/s: a curve reaching 20 g,
    or 300 m/s, is in other units than declared."""
    period = 0.5 if im == "sa" else None
    with pytest.raises(ValueError, match=r"^units: the levels reach .*beyond any ground motion"):
        HazardCurve(im, levels, [1e-1, 1e-3, 1e-5], units=units, period=period)
    # in their own units they read
    own = {"g": "cm/s^2", "m/s": "cm/s"}[units]
    curve = HazardCurve(im, levels, [1e-1, 1e-3, 1e-5], units=own, period=period)
    assert curve.levels[-1] == levels[-1]


def test_a_default_power_law_converts_to_every_unit_of_its_measure():
    """Its levels end at 10 g, the limit itself: in any unit it stays readable."""
    curve = HazardCurve.power_law(2e-4, 2.3, im="pga", units="g")
    # 1 g = 9.80665 m/s^2 (the standard gravity, by definition); 1 gal = 1 cm/s^2
    per_g = {"m/s^2": 9.80665, "cm/s^2": 980.665, "gal": 980.665, "g": 1.0}
    for units, factor in per_g.items():
        there = curve.to_units(units)
        assert there.units == units
        np.testing.assert_allclose(there.levels, curve.levels * factor, rtol=1e-15)
        np.testing.assert_array_equal(there.rates, curve.rates)
        assert there.levels[-1] == pytest.approx(10 * factor, rel=1e-15)  # the limit, 10 g


def test_an_openquake_curve_in_other_units_than_openquake_writes_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"^units: OpenQuake writes the levels of PGA in g"):
        HazardCurve.from_csv(DATA / "site_pga_openquake.csv", units="m/s^2")
    curve = HazardCurve.from_csv(DATA / "site_pga_openquake.csv", units="g")
    assert curve.units == "g"


@pytest.mark.parametrize("header, units", [("pga_g", "g"), ("PGA [m/s^2]", "m/s2"), ("level", "g")])
def test_a_level_column_in_its_own_units_reads(tmp_path, header, units):
    path = tmp_path / "h.csv"
    path.write_text(f"{header},annual_rate\n0.1,1e-2\n0.2,1e-3\n")
    curve = HazardCurve.from_csv(path, im="pga", units=units)
    np.testing.assert_array_equal(curve.levels, [0.1, 0.2])
    np.testing.assert_array_equal(curve.rates, [1e-2, 1e-3])
