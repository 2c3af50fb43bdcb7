"""Floor motions of linear buildings (rockstudy.motions.Building, floor_motion).

Oracles: scipy.signal.lsim of the modal state-space system (first-order hold: exact for the
piecewise-linear record), the closed-form response of one linear oscillator to a sine, the
ground motion itself for a rigid building, and the closed-form modes of the uniform shear
chain (omega_j = 2 sqrt(k/m) sin((2j - 1) pi / (2 (2n + 1))), phi_jk = sin((2j - 1) pi k /
(2n + 1))).
"""

import math

import numpy as np
import pytest
import scipy.signal
from _helpers import RECORD_STUDY_HEAD, rows_study, run_rows, write_near_fault_pairs

from rockstudy.constants import G
from rockstudy.motions import Building, Record, floor_motion, load_suite
from rockstudy.study import load_study, run_study
from rockstudy.study.designs import records as rd
from rockstudy.study.running.store import open_result


def smooth_noise(n, dt, seed=0):
    """A band-limited random record [m/s^2] of n samples."""
    rng = np.random.default_rng(seed)
    b, a = scipy.signal.butter(4, 15.0 * 2 * dt)
    return 3.0 * scipy.signal.lfilter(b, a, rng.normal(size=n)) * np.hanning(n)


def lsim_floor(building, floor, t, acc):
    """The floor's absolute acceleration by lsim of the modal system: state (q_j, q_j') per
    mode, q'' = -acc - 2 zeta omega q' - omega^2 q; output acc + sum Gamma phi q''."""
    m = building.n_modes
    w = 2 * np.pi / building.periods
    z = building.damping
    A = np.zeros((2 * m, 2 * m))
    B = np.zeros((2 * m, 1))
    C = np.zeros((1, 2 * m))
    g = building.participation * building.mode_shapes[:, floor - 1]
    for j in range(m):
        A[2 * j, 2 * j + 1] = 1.0
        A[2 * j + 1, 2 * j] = -(w[j] ** 2)
        A[2 * j + 1, 2 * j + 1] = -2 * z[j] * w[j]
        B[2 * j + 1, 0] = -1.0
        C[0, 2 * j] = -g[j] * w[j] ** 2
        C[0, 2 * j + 1] = -g[j] * 2 * z[j] * w[j]
    D = np.array([[1.0 - g.sum()]])
    _, y, _ = scipy.signal.lsim((A, B, C, D), acc, t, interp=True)
    return y


def modal_building():
    """Three modes of a made-up building of four floors, each with its own damping."""
    return Building(
        periods=[0.8, 0.25, 0.12],
        mode_shapes=[[0.3, 0.6, 0.85, 1.0], [-0.9, -0.8, 0.1, 1.0], [1.2, -0.3, -1.0, 1.0]],
        participation=[1.3, -0.4, 0.15],
        damping=[0.02, 0.05, 0.1],
    )


@pytest.mark.parametrize("floor", [1, 3, 4])
@pytest.mark.parametrize("make", [modal_building, lambda: Building.uniform_shear(4, 0.6, 0.05)])
def test_floor_motion_equals_lsim_of_the_modal_system(make, floor):
    building = make()
    dt = 0.002
    acc = smooth_noise(5000, dt)
    t = dt * np.arange(acc.size)
    got = floor_motion(Record(acc, dt=dt, name="noise"), building, floor)
    want = lsim_floor(building, floor, t, acc)
    np.testing.assert_array_equal(got.time, t)
    assert np.max(np.abs(got.acceleration - want)) <= 1e-8 * np.max(np.abs(want))


def sdof_absolute_acceleration(t, amplitude, w_g, period, zeta):
    """Closed form: absolute acceleration of a linear oscillator, at rest at t = 0, under the
    ground acceleration amplitude sin(w_g t): -2 zeta w u' - w^2 u, u the relative
    displacement (the steady state plus the free vibration that starts it at rest)."""
    w = 2 * np.pi / period
    wd = w * math.sqrt(1 - zeta**2)
    H = w**2 - w_g**2 + 2j * zeta * w * w_g
    p = -amplitude / H  # u_p = Im(p e^{i w_g t})
    up = np.imag(p * np.exp(1j * w_g * t))
    vp = np.imag(1j * w_g * p * np.exp(1j * w_g * t))
    c1 = -np.imag(p)
    c2 = (-np.imag(1j * w_g * p) + zeta * w * c1) / wd
    e = np.exp(-zeta * w * t)
    uh = e * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
    vh = -zeta * w * uh + e * wd * (-c1 * np.sin(wd * t) + c2 * np.cos(wd * t))
    return -2 * zeta * w * (vp + vh) - w**2 * (up + uh)


def test_one_mode_building_is_the_sdof_absolute_acceleration():
    period, zeta, w_g = 0.4, 0.05, 2 * np.pi / 0.7
    building = Building(periods=[period], mode_shapes=[[1.0]], participation=[1.0], damping=zeta)
    dt = 1e-4
    t = np.arange(0.0, 3.0, dt)
    got = floor_motion(Record(2.0 * np.sin(w_g * t), dt=dt), building, 1)
    want = sdof_absolute_acceleration(t, 2.0, w_g, period, zeta)
    # the record is the sine's chords: (w_g dt)^2 / 8 = 1e-7 of the sine between samples
    assert np.max(np.abs(got.acceleration - want)) <= 1e-6 * np.max(np.abs(want))


def test_a_rigid_building_moves_with_the_ground():
    acc = smooth_noise(2000, 0.01, seed=3)
    ground = Record(acc, dt=0.01, name="g")
    for floor in (1, 5):
        got = floor_motion(ground, Building.uniform_shear(5, 1e-4, 0.05), floor)
        assert np.max(np.abs(got.acceleration - acc)) <= 1e-6 * np.max(np.abs(acc))


@pytest.mark.parametrize("n", [1, 2, 5, 12])
def test_uniform_shear_modes_are_those_of_the_shear_chain(n):
    b = Building.uniform_shear(n, 0.9, 0.03)
    j = np.arange(1, n + 1)
    k = np.arange(1, n + 1)
    s = np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))  # omega_j / (2 sqrt(k/m))
    np.testing.assert_allclose(b.periods, 0.9 * s[0] / s, rtol=1e-12)
    phi = np.sin(np.outer(2 * j - 1, k) * np.pi / (2 * n + 1))
    gamma = phi.sum(axis=1) / (phi**2).sum(axis=1)
    want = gamma[:, None] * phi  # Gamma_j phi_jk: independent of the normalisation
    np.testing.assert_allclose(
        b.participation[:, None] * b.mode_shapes, want, rtol=1e-10, atol=1e-12
    )
    np.testing.assert_allclose(b.mode_shapes[:, -1], 1.0)  # the roof normalisation
    np.testing.assert_allclose(b.damping, 0.03)
    assert b.n_floors == b.n_modes == n


def test_floor_motion_keeps_vertical_names_floor_and_scales_linearly():
    dt = 0.01
    acc = smooth_noise(800, dt, seed=1)
    vertical = 0.5 * smooth_noise(800, dt, seed=2)
    ground = Record(acc, dt=dt, name="nf", vertical=vertical, metadata={"station": "X"})
    building = Building.uniform_shear(3, 0.5, 0.05)
    top = floor_motion(ground, building, 3)
    np.testing.assert_array_equal(top.vertical, vertical)
    assert top.name == "nf (floor 3)"
    assert top.metadata == {"station": "X", "building": building, "floor": 3, "ground": ground}
    assert floor_motion(ground, building, 0) is ground
    twice = floor_motion(ground.scaled(-2.0), building, 3)
    np.testing.assert_allclose(twice.acceleration, -2.0 * top.acceleration, rtol=1e-12)
    assert top.scaled(2.0).metadata["floor"] == 3


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(periods=[-0.5]), "periods"),
        (dict(periods=[0.5, float("nan")]), "periods"),
        (dict(mode_shapes=[[1.0, 2.0]]), "mode_shapes"),
        (dict(mode_shapes=[1.0]), "mode_shapes"),
        (dict(participation=[1.0, 2.0, 3.0]), "participation"),
        (dict(participation=["1"]), "participation"),
        (dict(damping=1.0), "damping"),
        (dict(damping=[0.05, 0.05, 0.05]), "damping"),
    ],
)
def test_building_refuses_bad_modes_naming_the_field(kwargs, field):
    good = dict(periods=[0.5, 0.2], mode_shapes=[[1.0], [1.0]], participation=[1.0, 0.1])
    good["damping"] = 0.05
    with pytest.raises(ValueError, match=f"^{field} "):
        Building(**{**good, **kwargs})


def test_uniform_shear_and_floor_motion_refuse_bad_input_by_name():
    with pytest.raises(ValueError, match="n_storeys"):
        Building.uniform_shear(0, 0.5, 0.05)
    with pytest.raises(ValueError, match="n_storeys"):
        Building.uniform_shear(2.0, 0.5, 0.05)
    with pytest.raises(ValueError, match="period"):
        Building.uniform_shear(2, -0.5, 0.05)
    with pytest.raises(ValueError, match="damping"):
        Building.uniform_shear(2, 0.5, -0.1)
    building = Building.uniform_shear(3, 0.5, 0.05)
    ground = Record(np.ones(10), dt=0.01)
    for floor in (-1, 4, 1.0, True):
        with pytest.raises(ValueError, match=r"floor must be a whole number in \[0, 3\]"):
            floor_motion(ground, building, floor)
    with pytest.raises(TypeError, match="record"):
        floor_motion(np.ones(10), building, 1)
    with pytest.raises(TypeError, match="building"):
        floor_motion(ground, {"periods": [0.5]}, 1)
    with pytest.raises(ValueError, match="building.periods"):
        floor_motion(Record(np.ones(10), dt=1e-6), Building.uniform_shear(2, 5.0, 0.05), 1)
    with pytest.raises(TypeError, match="metadata"):
        Record(np.ones(10), dt=0.01, metadata=[1])


# --------------------------------------------------------------------------- studies


def study_text(folder, motion, design):
    """Three Latin-hypercube blocks on the ``*_H.AT2`` records of ``folder`` in ``design``,
    with ``motion``'s extra lines (the building and floor)."""
    return RECORD_STUDY_HEAD + (
        f'[motion]\nkind = "record"\nfiles = "{folder}/*_H.AT2"\n{motion}\n{design}\n'
        '[run]\noutputs = ["max_rotation", "overturned"]\n'
    )


SHEAR = "building = { uniform_shear = { n_storeys = 5, period = 0.5, damping = 0.05 } }"
MODAL = (
    "building = { periods = [0.8, 0.25], mode_shapes = [[0.5, 1.0], [-1.0, 1.0]], "
    "participation = [1.2, -0.2], damping = [0.02, 0.05] }"
)
STRIPES = (
    'scale_to = { im = "pga", value = { dist = "grid", values = [2.0, 6.0] } }\n'
    '[design]\nkind = "stripes"\nperiods = [0.5]'
)
CLOUD = '[design]\nkind = "cloud"\nperiods = [0.5]'


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    return write_near_fault_pairs(tmp_path_factory.mktemp("floor_records"))


def write(tmp_path, text, name="floors.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "building, floor, design", [(SHEAR, 3, STRIPES), (MODAL, 2, CLOUD)], ids=["shear", "modal"]
)
def test_a_study_on_a_floor_runs_the_design_on_the_floor_motions(
    suite, client, tmp_path, building, floor, design
):
    text = study_text(suite, f"{building}\nfloor = {floor}", design)
    study = load_study(write(tmp_path, text))
    out = tmp_path / "cube.zarr"
    report = run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    assert report.failed_samples == 0
    cube = open_result(out).load()
    spec = study.motion.building.building()
    records = [floor_motion(r, spec, floor) for r in load_suite(str(suite / "*_H.AT2"))]
    st = {"half_diagonal": cube["half_diagonal"].values, "slenderness": cube["slenderness"].values}
    if design is STRIPES:
        api = rd.multiple_stripes(records, st, [2.0, 6.0], im="pga", periods=[0.5])
    else:
        api = rd.cloud(records, st, periods=[0.5])
    for name in ("max_rotation", "pga", "sa"):
        np.testing.assert_allclose(cube[name], api[name], rtol=1e-12, equal_nan=True)
    grounds = load_suite(str(suite / "*_H.AT2"))
    if design is STRIPES:
        ground = rd.multiple_stripes(grounds, st, [2.0, 6.0], im="pga", periods=[0.5])
    else:
        ground = rd.cloud(grounds, st, periods=[0.5])
    for name in ("pga", "sa"):  # measured on the ground record, as the site's hazard
        np.testing.assert_allclose(cube[name], ground[name], rtol=1e-12)
    assert not np.allclose(api["max_rotation"], ground["max_rotation"], equal_nan=True)


@pytest.mark.parametrize(
    "motion, message",
    [
        (f"{SHEAR}\nfloor = 6", "motion.floor: must be in 0..5"),
        (f"{SHEAR}\nfloor = [1, 1]", "motion.floor: a list of floors must name distinct"),
        (SHEAR, "motion.floor: is required with building"),
        ("floor = 2", "motion.building: is required with floor"),
        (
            "building = { periods = [0.5], mode_shapes = [[1.0, 0.5]], participation = [1.0, 2.0],"
            " damping = 0.05 }\nfloor = 1",
            "motion.building.participation: must hold one factor per mode",
        ),
        (
            "building = { periods = [-0.5], mode_shapes = [[1.0]], participation = [1.0],"
            " damping = 0.05 }\nfloor = 1",
            "motion.building.periods: must be finite",
        ),
        (
            "building = { periods = [0.5], mode_shapes = [[1.0]] }\nfloor = 1",
            "motion.building.participation: is required",
        ),
        (
            "building = { uniform_shear = { n_storeys = 0, period = 0.5, damping = 0.05 } }\n"
            "floor = 1",
            "motion.building.uniform_shear.n_storeys: must be >= 1",
        ),
        (
            "building = { uniform_shear = { n_storeys = 2, period = 0.5, damping = 0.05 },"
            " periods = [0.5] }\nfloor = 1",
            "motion.building.periods: give either uniform_shear",
        ),
    ],
)
def test_a_study_refuses_a_bad_building_or_floor_by_name(suite, tmp_path, motion, message):
    from rockstudy.study import StudyError

    text = study_text(suite, motion, CLOUD)
    with pytest.raises(StudyError) as err:
        load_study(write(tmp_path, text))
    assert message in str(err.value)


def test_a_study_on_a_floor_takes_a_ground_hazard_curve(suite, tmp_path):
    hazard = '[hazard]\nkind = "power_law"\nim = "pga"\nk0 = 1e-4\nk = 2.5\nunits = "g"\n'
    for floor in (0, 2):
        text = study_text(suite, f"{SHEAR}\nfloor = {floor}", CLOUD) + hazard
        study = load_study(write(tmp_path, text))
        assert study.hazard is not None and study.motion.floor == floor


def test_monte_carlo_rows_on_a_floor_scale_the_ground_record(suite, tmp_path):
    study = rows_study(suite, tmp_path, f"{SHEAR}\nfloor = 3\npga_ratio = 2.5")
    design, out = run_rows(study, tmp_path)
    files = sorted(suite.glob("*_H.AT2"))
    building = Building.uniform_shear(5, 0.5, 0.05)
    for i, r in enumerate(design["record"].values):
        ground = Record.from_at2(files[r])
        floor = lsim_floor(building, 3, ground.time, ground.acceleration)
        uplift = G * np.tan(design["critical_rotation"].values[i])
        assert ground.peak * out["scale"][i] == pytest.approx(2.5 * uplift, rel=1e-9)
        assert out["pga"][i] == pytest.approx(ground.peak * abs(out["scale"][i]), rel=1e-9)
        assert np.max(np.abs(floor)) * out["scale"][i] != pytest.approx(2.5 * uplift, rel=1e-2)
