"""Records with two horizontal components, the motion along an orientation psi, and the
measures of a pair (RotD50 and RotD100 of PGA and Sa).

Oracles: the rotation of a vector (a_psi^2 + a_(psi + pi/2)^2 = a_x^2 + a_y^2), the
components themselves (psi = 0 is x, psi = pi/2 is y), the mirror symmetry of Housner's
equation (psi + pi rocks the other way: ``rs.simulate`` of the mirrored one-component record),
the files the tests write, and pyrotd (the peer library of rotated spectra), to 1e-3.
"""

import math

import numpy as np
import pyrotd
import pytest
from _helpers import write_at2

from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.motions import Record, load_suite

DT = 0.005


def pair_samples(seed, n=2001):
    """Two smooth, different horizontal components [m/s^2] (windowed sines of periods 0.3
    to 1.5 s), zero at both ends."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT
    window = np.sin(np.pi * t / t[-1]) ** 2
    out = []
    for _ in range(2):
        periods = rng.uniform(0.3, 1.5, 4)
        phases = rng.uniform(0, 2 * np.pi, 4)
        amps = rng.uniform(0.5, 2.0, 4)
        wave = sum(
            a * np.sin(2 * np.pi * t / T + f) for a, T, f in zip(amps, periods, phases, strict=True)
        )
        out.append(window * wave)
    return out


def a_pair(seed=1, **kw):
    ax, ay = pair_samples(seed)
    return Record(ax, dt=DT, acceleration_y=ay, name=f"pair{seed}", **kw)


# ------------------------------------------------------------------ two-component records


def test_orientation_zero_and_right_angle_are_the_components():
    rec = a_pair()
    assert np.array_equal(rec.oriented(0.0).acceleration, rec.acceleration)
    y = rec.oriented(math.pi / 2).acceleration
    assert np.allclose(y, rec.acceleration_y, rtol=0, atol=1e-15 * rec.peak)
    assert rec.oriented(0.0).acceleration_y is None  # one component: the motion along psi


def test_orientations_rotate_the_vector_of_the_two_components():
    """a_psi and a_(psi + pi/2) are the components in the rotated axes: their squares sum to
    |a|^2, and psi + pi mirrors a_psi."""
    rec = a_pair(2)
    norm2 = rec.acceleration**2 + rec.acceleration_y**2
    for psi in (0.3, 1.1, 2.5):
        a = rec.oriented(psi).acceleration
        b = rec.oriented(psi + math.pi / 2).acceleration
        assert np.allclose(a**2 + b**2, norm2, rtol=1e-12, atol=1e-14)
        assert np.allclose(rec.oriented(psi + math.pi).acceleration, -a, atol=1e-14)
    assert rec.oriented(0.7).metadata["orientation"] == 0.7


def test_a_one_component_record_has_the_directions_zero_and_pi_only():
    ax, _ = pair_samples(3)
    rec = Record(ax, dt=DT, vertical=0.1 * ax)
    assert np.array_equal(rec.oriented(math.pi).acceleration, -ax)
    assert np.array_equal(rec.oriented(math.pi).vertical, rec.vertical)  # not upside down
    assert np.array_equal(rec.oriented(-2 * math.pi).acceleration, ax)
    with pytest.raises(ValueError, match="orientation = 0.3 rad.*one horizontal component"):
        rec.oriented(0.3)
    with pytest.raises(ValueError, match="orientation"):
        rec.oriented(float("nan"))


def test_scaled_scales_both_components_and_keeps_the_vertical_upright():
    ax, ay = pair_samples(4)
    rec = Record(ax, dt=DT, acceleration_y=ay, vertical=0.2 * ay)
    s = rec.scaled(-2.5)
    assert np.array_equal(s.acceleration, -2.5 * ax)
    assert np.array_equal(s.acceleration_y, -2.5 * ay)
    assert np.array_equal(s.vertical, rec.vertical * 2.5)


def test_bad_second_components_are_refused_naming_the_field():
    ax, ay = pair_samples(5)
    bad = ay.copy()
    bad[7] = np.nan
    with pytest.raises(ValueError, match="acceleration_y"):
        Record(ax, dt=DT, acceleration_y=bad)
    with pytest.raises(ValueError, match="acceleration_y has 2000 samples but acceleration has"):
        Record(ax, dt=DT, acceleration_y=ay[:-1])
    with pytest.raises(ValueError, match="acceleration_y"):
        Record(ax, dt=DT, acceleration_y="abc")
    with pytest.raises(ValueError, match=r"acceleration_y\[3\]"):
        Record(ax, dt=DT, acceleration_y=np.where(np.arange(ax.size) == 3, 1e30, ay))


# ---------------------------------------------------------------------------- files


def write_pair(folder, stem, seed, vertical=False):
    ax, ay = pair_samples(seed)
    write_at2(folder / f"{stem}000.AT2", Record(ax, dt=DT))
    write_at2(folder / f"{stem}090.AT2", Record(ay, dt=DT))
    if vertical:
        write_at2(folder / f"{stem}-UP.AT2", Record(0.3 * ax, dt=DT))
    return ax, ay


def in_file_precision(values):
    """The samples as an .AT2 file of write_at2 holds them (10 significant digits in g)."""
    return np.array([float(f"{v:.9e}") for v in values / STANDARD_GRAVITY]) * STANDARD_GRAVITY


def test_from_at2_reads_the_two_horizontal_components(tmp_path):
    ax, ay = write_pair(tmp_path, "RSN1_A", 6, vertical=True)
    rec = Record.from_at2(
        tmp_path / "RSN1_A000.AT2",
        h2=tmp_path / "RSN1_A090.AT2",
        vertical=tmp_path / "RSN1_A-UP.AT2",
    )
    assert np.array_equal(rec.acceleration, in_file_precision(ax))
    assert np.array_equal(rec.acceleration_y, in_file_precision(ay))
    assert np.array_equal(rec.vertical, in_file_precision(0.3 * ax))
    assert rec.dt == pytest.approx(DT, rel=1e-12) and rec.name == "RSN1_A000"


def test_from_at2_refuses_a_second_component_on_other_samples(tmp_path):
    ax, ay = write_pair(tmp_path, "B", 7)
    write_at2(tmp_path / "short.AT2", Record(ay[:-5], dt=DT))
    write_at2(tmp_path / "coarse.AT2", Record(ay, dt=2 * DT))
    for name in ("short.AT2", "coarse.AT2"):
        with pytest.raises(ValueError, match=rf"h2: .*{name} has .* samples at dt="):
            Record.from_at2(tmp_path / "B000.AT2", h2=tmp_path / name)


def test_load_suite_pairs_the_second_components_by_a_pattern(tmp_path):
    pairs = {
        stem: write_pair(tmp_path, stem, seed, vertical=True)
        for stem, seed in (("R1_", 8), ("R2_", 9))
    }
    suite = load_suite(tmp_path, h2=(r"000\.AT2$", "090.AT2"), vertical=(r"000\.AT2$", "-UP.AT2"))
    assert [r.name for r in suite] == ["R1_000", "R2_000"]
    for rec, (ax, ay) in zip(suite, pairs.values(), strict=True):
        assert np.array_equal(rec.acceleration, in_file_precision(ax))
        assert np.array_equal(rec.acceleration_y, in_file_precision(ay))
        assert np.array_equal(rec.vertical, in_file_precision(0.3 * ax))
    only_h2 = load_suite(tmp_path / "R*_0[09]0.AT2", h2=(r"000\.AT2$", "090.AT2"))
    assert [r.two_components and r.vertical is None for r in only_h2] == [True, True]


def test_load_suite_refuses_a_broken_pairing_naming_h2(tmp_path):
    write_pair(tmp_path, "R1_", 10)
    (tmp_path / "R1_045.AT2").write_text((tmp_path / "R1_090.AT2").read_text())
    with pytest.raises(ValueError, match=r"h2: the file .*R1_045.AT2.* does not match"):
        load_suite(tmp_path, h2=(r"000\.AT2$", "090.AT2"))
    with pytest.raises(ValueError, match=r"h2: the second horizontal file .*R1_091.AT2.* missing"):
        load_suite(tmp_path / "R1_000.AT2", h2=(r"000\.AT2$", "091.AT2"))
    with pytest.raises(ValueError, match="h2 must be None or a \\(regex, replacement\\) pair"):
        load_suite(tmp_path, h2="090")


# ------------------------------------------------------------------------- orientation

BLOCK = dict(half_diagonal=1.0, slenderness=0.2)


def rock(motion, **kw):
    import rockstudy as rs

    return rs.simulate(rs.Block(BLOCK["half_diagonal"], BLOCK["slenderness"]), motion, **kw)


def test_simulate_along_an_orientation_rocks_under_the_rotated_motion():
    """psi = 0 is the x component alone, psi = pi/2 the y component, and any psi the
    one-component record a_x cos(psi) + a_y sin(psi), each run by rs.simulate on its own."""
    ax, ay = pair_samples(11)
    pair = Record(ax, dt=DT, acceleration_y=ay)
    for psi, alone in (
        (0.0, ax),
        (math.pi / 2, ay),
        (0.9, math.cos(0.9) * ax + math.sin(0.9) * ay),
    ):
        got, want = rock(pair, orientation=psi), rock(Record(alone, dt=DT))
        assert want.max_rotation > 0.05 * BLOCK["slenderness"]  # it rocks
        assert got.max_rotation == pytest.approx(want.max_rotation, rel=1e-9)
        assert np.allclose(got.peak_rotations, want.peak_rotations, rtol=1e-9, atol=1e-12)
        assert got.info["orientation"] == psi
    assert rock(pair).max_rotation == rock(Record(ax, dt=DT)).max_rotation  # x by default


@pytest.mark.parametrize("scale", [1.0, 2.5])
def test_the_opposite_orientation_mirrors_the_response(scale):
    """psi + pi: the same peaks with the other sign, and an overturning to the other side
    (the oracle: rs.simulate of the mirrored one-component record)."""
    pair = a_pair(12).scaled(scale)
    psi = 0.6
    one = rock(pair, orientation=psi)
    other = rock(pair, orientation=psi + math.pi)
    alone = Record(
        -(math.cos(psi) * pair.acceleration + math.sin(psi) * pair.acceleration_y), dt=DT
    )
    oracle = rock(alone)
    assert other.overturned == oracle.overturned == one.overturned
    assert np.allclose(other.peak_rotations, oracle.peak_rotations, rtol=1e-9, atol=1e-12)
    assert np.allclose(other.peak_rotations, -one.peak_rotations, rtol=1e-7, atol=1e-10)
    assert other.max_rotation == pytest.approx(one.max_rotation, rel=1e-7)
    if scale > 1:
        assert one.overturned  # the case of an overturning
        assert np.sign(other.theta[-1]) == -np.sign(one.theta[-1]) != 0
        assert other.overturn_time == pytest.approx(one.overturn_time, rel=1e-7)


def test_an_orientation_off_the_axis_of_a_one_component_motion_is_refused():
    from rockstudy.motions import SinePulse

    ax, _ = pair_samples(13)
    with pytest.raises(ValueError, match="orientation = 0.5 rad: the record 'x' has one"):
        rock(Record(ax, dt=DT, name="x"), orientation=0.5)
    with pytest.raises(ValueError, match="orientation = 1.0 rad: the SinePulse has one"):
        rock(SinePulse(3.0, 0.5), orientation=1.0)
    mirrored = rock(SinePulse(3.0, 0.5), orientation=math.pi)
    oracle = rock(SinePulse(-3.0, 0.5))
    assert np.allclose(mirrored.peak_rotations, oracle.peak_rotations, rtol=1e-12)
    with pytest.raises(ValueError, match="orientation"):
        rock(a_pair(), orientation=float("inf"))


# ------------------------------------------------------------------- RotD50 and RotD100

PYROTD_ANGLES = np.arange(180)  # pyrotd's default: 0 to 179 degrees


def padded_pair(seed):
    """A pair followed by 90 s of rest: pyrotd's oscillator is a periodic (FFT) one, which
    equals the oscillator started at rest once the response has died out before the record
    repeats (at T = 2 s and 5 %, e^(-0.05 (2 pi / 2) 90) = 7e-7)."""
    ax, ay = pair_samples(seed)
    rest = np.zeros(20000 - ax.size)
    return Record(np.r_[ax, rest], dt=DT, acceleration_y=np.r_[ay, rest], name=f"pair{seed}")


@pytest.mark.parametrize("seed", [1, 2])
def test_pga_rotd_equals_pyrotd(seed):
    rec = padded_pair(seed)
    want = pyrotd.calc_rotated_percentiles(
        [rec.acceleration, rec.acceleration_y], PYROTD_ANGLES, [50, 100], method="rigorous"
    ).spec_accel
    assert rec.intensity_measure("pga_rotd50") == pytest.approx(want[0], rel=1e-12)
    assert rec.intensity_measure("pga_rotd100") == pytest.approx(want[1], rel=1e-12)
    # RotD100 at 1 degree: within cos(0.5 degree) of the peak of |a| over every direction
    vector = np.max(np.hypot(rec.acceleration, rec.acceleration_y))
    assert vector * math.cos(math.radians(0.5)) <= rec.intensity_measure("pga_rotd100") <= vector


@pytest.mark.parametrize("seed", [1, 2])
def test_sa_rotd_equals_pyrotd(seed):
    """pyrotd's pseudo-spectral acceleration (osc_type "psa", as the registry's sa), its
    oscillator upsampled 4 times for the peaks between samples; 1e-3 (measured: 2.0e-4)."""
    rec = padded_pair(seed)
    for period in (0.2, 0.5, 1.0, 2.0):
        want = pyrotd.calc_rotated_spec_accels(
            DT,
            rec.acceleration,
            rec.acceleration_y,
            [1.0 / period],
            0.05,
            percentiles=[50, 100],
            angles=PYROTD_ANGLES,
            max_freq_ratio=4 * (0.5 / DT) * period,  # 4 x the Nyquist frequency
        ).spec_accel
        for which, expected in zip(("sa_rotd50", "sa_rotd100"), want, strict=True):
            got = rec.intensity_measure(which, period=period, damping=0.05)
            assert got == pytest.approx(expected, rel=1e-3)


def test_sa_rotd_is_the_spectrum_along_each_angle():
    """The combined states of the two components give, angle by angle, the spectrum
    kernel's Sa of the oriented record (the median and the largest of those 180 values)."""
    rec = a_pair(14)
    for period in (0.05, 0.7):  # 0.05 s: the kernel's sub-steps (omega dt = 0.63)
        along = [rec.oriented(np.radians(d)).intensity_measure("sa", period) for d in range(180)]
        assert rec.intensity_measure("sa_rotd50", period) == pytest.approx(
            np.median(along), rel=1e-12
        )
        assert rec.intensity_measure("sa_rotd100", period) == pytest.approx(max(along), rel=1e-12)


def test_rotd_measures_scale_and_refuse_one_component():
    rec = a_pair(15)
    scaled = rec.scaled_to(0.4 * STANDARD_GRAVITY, im="pga_rotd50")
    assert scaled.intensity_measure("pga_rotd50") == pytest.approx(
        0.4 * STANDARD_GRAVITY, rel=1e-12
    )
    one = Record(rec.acceleration, dt=DT, name="x only")
    for name, period in (
        ("pga_rotd50", None),
        ("pga_rotd100", None),
        ("sa_rotd50", 1.0),
        ("sa_rotd100", 1.0),
    ):
        with pytest.raises(
            ValueError, match=rf"the measure '{name}' is of a pair .*'x only' has one"
        ):
            one.intensity_measure(name, period)
    assert "pga_rotd50" not in one.intensity_measures()  # not listed: one component has none


def test_simulate_batch_takes_an_orientation_per_row():
    """Rows of several orientations, interleaved: each row equals the batch of the
    one-component record along its angle, in the rows' order."""
    import rockstudy as rs

    pair = a_pair(16)
    psi = np.array([0.9, 0.0, 0.9 + math.pi, math.pi / 2, 0.9, 2.0])
    scale = np.array([1.0, 1.5, 1.0, 0.8, 2.0, 1.2])
    got = rs.simulate_batch(record=pair, orientation=psi, scale=scale, **BLOCK)
    for i, angle in enumerate(psi):
        along = math.cos(angle) * pair.acceleration + math.sin(angle) * pair.acceleration_y
        alone = rs.simulate_batch(record=Record(along, dt=DT), scale=scale[i], **BLOCK)
        for name, values in got.items():
            assert values[i] == pytest.approx(alone[name][0], rel=1e-9, nan_ok=True), name
    assert got["max_rotation"][0] == pytest.approx(got["max_rotation"][2], rel=1e-7)  # mirror
    ds = rs.simulate_batch(record=pair, orientation=psi, scale=scale, as_dataset=True, **BLOCK)
    assert np.array_equal(ds["orientation"].values, psi)
    assert np.array_equal(ds["scale"].values, scale)
    assert np.array_equal(ds["max_rotation"].values, got["max_rotation"])


def test_simulate_batch_orientation_of_one_component_motions():
    import rockstudy as rs

    pulses = dict(amplitude=4.0, period=0.6, **BLOCK)
    got = rs.simulate_batch(orientation=[0.0, math.pi], **pulses)
    mirrored = rs.simulate_batch(**{**pulses, "amplitude": [4.0, -4.0]})
    for name, values in got.items():
        assert np.array_equal(values, mirrored[name], equal_nan=True), name
    with pytest.raises(ValueError, match="orientation = 0.5 rad: the sine pulse has one"):
        rs.simulate_batch(orientation=0.5, **pulses)
    ax, _ = pair_samples(17)
    with pytest.raises(ValueError, match="orientation = 0.5 rad: the record 'x' has one"):
        rs.simulate_batch(record=Record(ax, dt=DT, name="x"), orientation=[0.0, 0.5], **BLOCK)
    with pytest.raises(ValueError, match=r"orientation\[1\] = nan"):
        rs.simulate_batch(record=a_pair(), orientation=[0.0, np.nan], **BLOCK)
    with pytest.raises(ValueError, match="orientation: 3, scale: 2"):
        rs.simulate_batch(record=a_pair(), orientation=[0, 1, 2], scale=[1, 2], **BLOCK)


def test_a_floor_motion_keeps_both_horizontal_components():
    """The building filters each direction alike (linear): the floor motion of the pair along
    psi is the floor motion of the ground motion along psi, and y is the floor motion of y."""
    from rockstudy.motions import Building, floor_motion

    pair = a_pair(18)
    building = Building.uniform_shear(5, 0.5, 0.05)
    floor = floor_motion(pair, building, 3)
    alone_y = floor_motion(Record(pair.acceleration_y, dt=DT), building, 3).acceleration
    assert np.allclose(floor.acceleration_y, alone_y, rtol=0, atol=1e-12 * np.max(abs(alone_y)))
    for psi in (0.4, 2.2):
        want = floor_motion(pair.oriented(psi), building, 3).acceleration
        got = floor.oriented(psi).acceleration
        assert np.allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))
