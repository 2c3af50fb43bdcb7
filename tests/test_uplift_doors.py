"""One uplift acceleration for every structure kind, through every door.

A structure starts rocking when the ground acceleration reaches g lambda, eq. (10) of [003]
(lambda = G_nl(0) / B_nl(0); the smaller of the two directions of an asymmetric structure),
which is not g tan(theta_cr) of its equivalent block but for a block and the structures of
Table I. Oracles, independent of the code under test:

- the wall: lambda = 2 tan(alpha), eq. (21) of [003] at phi = 0;
- the asymmetric frame and the arch: lambda by virtual work at rest, written here from the
  geometry (rigid bodies turning about their hinges; the frame's beam about the instantaneous
  centre of the two columns' tops), the arch's hinges found by its own search (the least
  lambda of the admissible four-hinge mechanisms, refined by Nelder-Mead);
- the dynamics: ``rs.simulate`` of the structure's mechanism (eq. 8 of [003]) stays at rest
  just below the uplift PGA and rocks just above it.
"""

import json
import math
import warnings
from itertools import combinations

import numpy as np
import pytest
from _helpers import ARCH, FRAME, WALL, write_at2  # the examples of the kinds' tests
from scipy.optimize import minimize

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import Record, SinePulse, load_suite
from rockstudy.structures import Arch, AsymmetricFrame, Block, RockingWall

STRUCTURES = {
    "Wall": ("rocking_wall", WALL, RockingWall(**WALL)),
    "Frame": ("asymmetric_frame", FRAME, AsymmetricFrame(**FRAME)),
    "Arch": ("arch", ARCH, Arch(**ARCH)),
}


# ------------------------------------------------------------------ independent lambdas


def _cross(w, r):
    """Velocity w x r of a point at r from the centre of a rotation w (ccw positive)."""
    return np.array([-w * r[1], w * r[0]])


def _four_bar_work(A, B, C, D, bodies):
    """(sum m v_y, sum m v_x, relative rotations (ccw) at A, B, C, D) of a four-bar (ground
    pivots A and D; bodies AB, BC, CD of (mass, centroid)) moving from rest with AB turning
    at 1 rad/s ccw. By virtual work the horizontal load lambda m g that starts it moving is
    lambda = sum m v_y / |sum m v_x| in the sense that lifts the weights."""
    vb = _cross(1.0, B - A)
    # v_C = v_B + w2 x (C - B) = w3 x (C - D): two equations in (w2, w3)
    m = np.array([[-(C - B)[1], (C - D)[1]], [(C - B)[0], -(C - D)[0]]])
    w2, w3 = np.linalg.solve(m, -vb)
    vel = [
        _cross(1.0, bodies[0][1] - A),
        vb + _cross(w2, bodies[1][1] - B),
        _cross(w3, bodies[2][1] - D),
    ]
    vx = sum(b[0] * v[0] for b, v in zip(bodies, vel, strict=True))
    vy = sum(b[0] * v[1] for b, v in zip(bodies, vel, strict=True))
    return vy, vx, np.array([1.0, w2 - 1.0, w3 - w2, -w3])


def frame_lambda(b, H, H1, L, h, m1=1.0, m2=1.0, m3=1.0):
    """The asymmetric frame's smaller lambda of its two directions, by virtual work: columns
    2b wide, 2H and 2H1 high (the right one on ground raised by 2 (H - H1)), the beam 2h deep
    on the column tops, spanning L; each column turns about a base corner, the beam rides on
    the diagonally opposite top corners."""
    raised = 2 * (H - H1)
    out = []
    for lean in (-1, 1):  # pivots on the left (-1) or the right (1) base corners
        A = np.array([2 * b if lean > 0 else 0.0, 0.0])
        B = np.array([0.0 if lean > 0 else 2 * b, 2 * H])
        D = np.array([L if lean > 0 else L - 2 * b, raised])
        C = np.array([L - 2 * b if lean > 0 else L, 2 * H])
        bodies = [
            (m1, np.array([b, H])),
            (m2, np.array([L / 2, 2 * H + h])),
            (m3, np.array([L - b, raised + H1])),
        ]
        vy, vx, _ = _four_bar_work(A, B, C, D, bodies)
        out.append(abs(vy) / abs(vx))  # a column lifts about its pivot in one sense only
    return min(out)


def _sector(r, t, p1, p2):
    """Area and centroid of the arch between the joints at p1 < p2 (angles from the crown,
    clockwise)."""
    ri, re, half = r - t / 2, r + t / 2, (p2 - p1) / 2
    dist = 2 / 3 * (re**3 - ri**3) / (re**2 - ri**2) * math.sin(half) / half
    mid = (p1 + p2) / 2
    return r * t * (p2 - p1), np.array([dist * math.sin(mid), dist * math.cos(mid)])


def arch_lambda_at(psi, faces, r, t):
    """lambda of the arch's four-hinge mechanism with hinges at angles psi (increasing) on
    the faces (+1 extrados, -1 intrados); inf if it is not admissible (every joint must open
    on the side away from its hinge) or does not lift its weight."""
    pairs = zip(psi, faces, strict=True)
    pts = [(r + f * t / 2) * np.array([math.sin(p), math.cos(p)]) for p, f in pairs]
    bodies = [_sector(r, t, psi[k], psi[k + 1]) for k in range(3)]
    try:
        vy, vx, rel = _four_bar_work(*pts, bodies)
    except np.linalg.LinAlgError:
        return math.inf
    sense = np.sign(faces[0] * rel[0])  # the sense in which the hinge at A opens
    if not (np.all(np.asarray(faces) * rel * sense > 0) and vy * sense > 0):
        return math.inf
    return vy * sense / abs(vx)


def arch_lambda(beta, t, r):
    """The least lambda over admissible four-hinge mechanisms: a grid of joints, then
    Nelder-Mead from the best point."""
    grid = np.linspace(-beta / 2, beta / 2, 17)
    best = (math.inf, None, None)
    for faces in ((1, -1, 1, -1), (-1, 1, -1, 1)):
        for psi in combinations(grid, 4):
            lam = arch_lambda_at(psi, faces, r, t)
            if lam < best[0]:
                best = (lam, np.array(psi), faces)

    def f(x):
        x = np.clip(np.sort(x), -beta / 2, beta / 2)
        return arch_lambda_at(x, best[2], r, t)

    res = minimize(f, best[1], method="Nelder-Mead", options=dict(xatol=1e-10, fatol=1e-14))
    return float(res.fun)


def test_independent_lambdas_against_the_physics_classes():
    """The structures' own uplift acceleration is g lambda of eq. (10), not g tan(theta_cr)
    of the equivalent block (they differ here by 1.5 % to 24 %)."""
    wall, frame, arch = (STRUCTURES[k][2] for k in ("Wall", "Frame", "Arch"))
    expect = {
        "Wall": 2 * math.tan(WALL["slenderness"]),
        "Frame": frame_lambda(0.2, 1.5, 1.2, 3.0, 0.2, m2=2.0),
        "Arch": arch_lambda(math.pi, 0.2, 1.0),
    }
    for name, s in (("Wall", wall), ("Frame", frame), ("Arch", arch)):
        a_up = rs.structures.uplift_acceleration(s)
        # (the arch: its hinge search refines a grid to 1e-9 rad: lambda within ~1e-18)
        assert a_up == pytest.approx(G * expect[name], rel=1e-12), name
        assert a_up >= G * expect[name] * (1 - 1e-9), name  # no mechanism below the least
        assert rs.similarity.uplift_acceleration(s) == a_up
        theta_cr = s.equivalent_block().slenderness
        assert abs(G * math.tan(theta_cr) / a_up - 1) > 0.01, name
    # at the class's own hinges, eq. (10) of the mechanism is the virtual work exactly
    h = arch.hinges
    lam = arch_lambda_at(h["angles"], h["faces"], 1.0, 0.2)
    assert rs.structures.uplift_acceleration(arch) == pytest.approx(G * lam, rel=1e-9)
    block = Block(1.0, 0.2)
    assert rs.structures.uplift_acceleration(block) == G * math.tan(0.2)


def _rocks(structure, motion) -> bool:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.simulate(structure, motion).max_rotation > 0


@pytest.mark.parametrize("name", list(STRUCTURES))
def test_the_dynamics_start_at_the_uplift_acceleration(name):
    """The mechanism (eq. 8 of [003]) stays at rest under a slow sine pulse of peak 0.999
    a_up, and rocks at 1.001 a_up (both directions: a full sine)."""
    s = STRUCTURES[name][2]
    a_up = rs.structures.uplift_acceleration(s)
    assert not _rocks(s, SinePulse(0.999 * a_up, 4.0))
    assert _rocks(s, SinePulse(1.001 * a_up, 4.0))


# ------------------------------------------------------------------ the doors

OBJECTS = f"""
[[structure.objects]]
name = "Wall"
kind = "rocking_wall"
half_diagonal = 1.5
slenderness = 0.12
restitution = 0.85
[[structure.objects]]
name = "Frame"
kind = "asymmetric_frame"
half_width = 0.2
height = 1.5
height_right = 1.2
beam_length = 3.0
beam_half_depth = 0.2
mass_beam = 2.0
restitution = 0.8
[[structure.objects]]
name = "Arch"
kind = "arch"
inclusion_angle = {math.pi!r}
thickness = 0.2
radius = 1.0
restitution = 0.7
[[structure.objects]]
name = "Block"
width = 0.4
height = 2.0
"""
STUDY = """
name = "uplift"
seed = 1
[structure]
kind = "objects"
{objects}
[motion]
kind = "record"
files = "{folder}"
{scale}
[design]
kind = "{design}"
{options}
"""


def _sine_record(period=0.6, dt=0.005):
    t = np.arange(0, 2 * period, dt)
    return Record(np.where(t <= period, np.sin(2 * np.pi * t / period), 0.0), dt=dt, name="s")


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("uplift_records")
    write_at2(folder / "sine.AT2", _sine_record().scaled(G))
    return folder


def _study(tmp_path, folder, objects=OBJECTS, scale="", design="stripes", options=""):
    from rockstudy.study import load_study

    path = tmp_path / "uplift.toml"
    text = STUDY.format(objects=objects, folder=folder, scale=scale, design=design, options=options)
    path.write_text(text)
    return load_study(path)


def _objects():
    return {**{k: v[2] for k, v in STRUCTURES.items()}, "Block": Block.from_dimensions(0.4, 2.0)}


def test_pga_ratio_one_is_the_uplift_pga_by_both_doors(client, folder, tmp_path):
    """A stripes study at pga_ratio = 1 and the Python stripes on the same objects scale the
    record to the same PGA (1e-12), which is g lambda of each structure (the oracles above)
    and g tan(alpha) of the block; the cube carries it as uplift_acceleration."""
    from rockstudy.study import run_study
    from rockstudy.study.designs import records as rd
    from rockstudy.study.running.store import open_result

    scale = 'scale_to = { im = "pga_ratio", value = { dist = "grid", values = [1.0] } }'
    study = _study(tmp_path, folder, scale=scale)
    out = tmp_path / "cube.zarr"
    report = run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    assert report.failed_samples == 0
    cube = open_result(out).load()
    rec = load_suite(folder)[0]
    api = rd.multiple_stripes([rec], _objects(), [1.0], im="pga_ratio")
    names = list(cube["structure"].values)
    assert names == list(api["structure"].values) == ["Wall", "Frame", "Arch", "Block"]
    pga = cube["scale"].values.ravel() * rec.peak
    np.testing.assert_allclose(pga, api["scale"].values.ravel() * rec.peak, rtol=1e-12)
    np.testing.assert_allclose(cube["uplift_acceleration"].values, pga, rtol=1e-12)
    lam = {
        "Wall": 2 * math.tan(0.12),
        "Frame": frame_lambda(0.2, 1.5, 1.2, 3.0, 0.2, m2=2.0),
        "Block": math.tan(math.atan2(0.2, 1.0)),
    }
    for j, name in enumerate(names):
        if name in lam:
            assert pga[j] == pytest.approx(G * lam[name], rel=1e-12), name
    arch = STRUCTURES["Arch"][2]
    h = arch.hinges
    assert pga[2] == pytest.approx(G * arch_lambda_at(h["angles"], h["faces"], 1.0, 0.2), 1e-9)
    # the dynamics: each structure at rest just below its pga_ratio = 1, rocking above
    for j, name in enumerate(names):
        s = _objects()[name]
        assert not _rocks(s, rec.scaled(0.999 * pga[j] / rec.peak)), name
        assert _rocks(s, rec.scaled(1.001 * pga[j] / rec.peak)), name
    np.testing.assert_allclose(cube["pga_ratio"].values.ravel(), rec.peak / pga, rtol=1e-12)


def test_ida_ladder_tops_at_max_pga_ratio_times_the_uplift_pga(folder, tmp_path):
    """The IDA's top rung (the scale a censored structure stands at) is max_pga_ratio g lambda
    by the Python door and by the study's rows."""
    from rockstudy.study.designs import record_rows
    from rockstudy.study.designs import records as rd
    from rockstudy.study.designs.sampling import make_design

    short = tmp_path / "short"  # a 0.05 s sine: nothing overturns below 1.5 a_up
    short.mkdir()
    write_at2(short / "short.AT2", _sine_record(0.05, 0.001).scaled(G))
    folder = short
    rec = load_suite(folder)[0]
    objects = _objects()
    api = rd.incremental_dynamic_analysis([rec], objects, step=0.5, max_pga_ratio=1.5, scan=0)
    top = api["capacity_scale_lower"].values[0] * rec.peak
    assert api["censored"].values.all()
    expect = [1.5 * rs.structures.uplift_acceleration(s) for s in objects.values()]
    np.testing.assert_allclose(top, expect, rtol=1e-12)
    np.testing.assert_allclose(expect[0], 1.5 * G * 2 * math.tan(0.12), rtol=1e-12)
    study = _study(tmp_path, folder, design="ida", options="step = 0.5\nmax_pga_ratio = 1.5")
    design = make_design(study, tmp_path)
    cols = {k: design[k].values for k in design.data_vars} | {"sample": design["sample"].values}
    got = record_rows.evaluate_rows(study, cols, tmp_path)
    np.testing.assert_allclose(got["capacity_scale_lower"] * rec.peak, expect, rtol=1e-12)


def _nothing_rocks(tmp_path, folder, objects, pga):
    from rockstudy.study.spec.feasibility import notes

    scale = f'scale_to = {{ im = "pga", value = {{ dist = "grid", values = [{pga!r}] }} }}'
    study = _study(tmp_path, folder, objects=objects, scale=scale)
    return any("nothing can rock" in n for n in notes(study, tmp_path))


def test_the_nothing_can_rock_note_follows_the_dynamics(folder, tmp_path):
    """Records brought to a PGA between g tan(theta_cr) and g lambda: the arch (g tan(theta_cr)
    < g lambda) cannot rock and gets the note; a stocky wall (g lambda < g tan(theta_cr))
    rocks and does not. The dynamics of each structure at that PGA decide."""
    rec = load_suite(folder)[0]
    arch = STRUCTURES["Arch"][2]
    lo, hi = G * math.tan(arch.equivalent_block().slenderness), G * arch_lambda(math.pi, 0.2, 1)
    assert lo < hi
    one = f'objects = [{{ name = "Arch", kind = "arch", inclusion_angle = {math.pi!r}, '
    one += "thickness = 0.2, radius = 1.0, restitution = 0.7 }]"
    pga = 0.5 * (lo + hi)
    assert not _rocks(arch, rec.scaled(pga / rec.peak))
    assert _nothing_rocks(tmp_path, folder, one, pga)
    wall = RockingWall(1.0, 0.5, 0.9)
    lo, hi = G * 2 * math.tan(0.5), G * math.tan(wall.equivalent_block().slenderness)
    assert lo < hi
    pga = 0.5 * (lo + hi)
    assert _rocks(wall, rec.scaled(pga / rec.peak))
    stocky = 'objects = [{ name = "Wall", kind = "rocking_wall", half_diagonal = 1.0, '
    stocky += "slenderness = 0.5, restitution = 0.9 }]"
    assert not _nothing_rocks(tmp_path, folder, stocky, pga)
    # and just below the wall's g lambda, nothing rocks, said and simulated
    assert not _rocks(wall, rec.scaled(0.999 * lo / rec.peak))
    assert _nothing_rocks(tmp_path, folder, stocky, 0.999 * lo)


SAMPLED = """
name = "walls"
seed = 3
[sampler]
kind = "monte_carlo"
n = 4
[structure]
kind = "rocking_wall"
half_diagonal = { dist = "uniform", low = 0.5, high = 3.0 }
slenderness = { dist = "uniform", low = 0.05, high = 0.4 }
restitution = 0.8
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = RATIO
period = 2.0
"""


@pytest.mark.parametrize("ratio", [0.995, 1.005])
def test_a_sampled_wall_lifts_off_at_amplitude_ratio_one(ratio):
    """A sampled wall's design carries a_up = 2 g tan(alpha) (eq. 21 of [003]); its pulse of
    amplitude_ratio just below 1 leaves the wall at rest, just above 1 rocks it."""
    from rockstudy.study.designs.sampling import make_design
    from rockstudy.study.spec.schema import validate_text

    ds = make_design(validate_text(SAMPLED.replace("RATIO", repr(ratio))))
    alpha = ds["slenderness"].values
    np.testing.assert_allclose(ds["uplift_acceleration"], 2 * G * np.tan(alpha), rtol=1e-12)
    np.testing.assert_allclose(ds["amplitude"], ratio * 2 * G * np.tan(alpha), rtol=1e-12)
    np.testing.assert_allclose(ds["uplift_ratio"], 1 / ratio, rtol=1e-12)
    for R, a, amp in zip(ds["half_diagonal"].values, alpha, ds["amplitude"].values, strict=True):
        assert _rocks(RockingWall(R, a, 0.8), SinePulse(amp, 2.0)) == (ratio > 1)


def test_old_cubes_fall_back_for_blocks_and_warn_for_other_structures():
    """A cube written before the design carried the uplift acceleration: its blocks get g
    tan(theta_cr) (exact for a block); other structures NaN, with an UpliftWarning."""
    import xarray as xr

    from rockstudy._warnings import UpliftWarning
    from rockstudy.study.designs import record_rows

    ds = xr.Dataset({"critical_rotation": ("structure", np.array([0.2, 0.3]))})
    blocks = {"structure": {"kind": "objects", "objects": [{"kind": "block"}, {"kind": None}]}}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = record_rows._old_uplift(ds, blocks)
    np.testing.assert_array_equal(got, G * np.tan([0.2, 0.3]))
    mixed = json.loads(json.dumps(blocks))
    mixed["structure"]["objects"][1]["kind"] = "arch"
    with pytest.warns(UpliftWarning, match="g tan"):
        got = record_rows._old_uplift(ds, mixed)
    assert np.isnan(got).all()


def test_similarity_groups_and_pulses_use_the_structures_uplift():
    """``similarity.groups`` and ``pulse_for`` (laws 5.3, 6.1) take uplift_ratio = a_up / a_g
    of the structure: a wall's pulse of uplift_ratio 1.001 leaves it at rest, 0.999 rocks it
    (eq. 21 of [003]: a_up = 2 g tan alpha)."""
    wall = STRUCTURES["Wall"][2]
    a_up = 2 * G * math.tan(WALL["slenderness"])
    pulse = SinePulse(3.0, 2.0)
    assert rs.similarity.groups(wall, pulse)["uplift_ratio"] == pytest.approx(a_up / 3.0, 1e-12)
    for ratio, rocks in ((1.001, False), (0.999, True)):
        p = rs.similarity.pulse_for(wall, omega=0.5, ratio=ratio, law="5.3")
        assert p.amplitude == pytest.approx(a_up / ratio, rel=1e-12)
        assert _rocks(wall, p) == rocks


def test_validate_notes_where_the_equivalent_block_lifts_off_elsewhere(folder, tmp_path):
    """The study simulates the equivalent block, which lifts off at g tan(theta_cr): validate
    says so where that is more than 1 % from the structure's own g lambda (the arch: 24 %
    below; a sampled wall of alpha up to 0.4: tan(0.8) / (2 tan 0.4) - 1 = 17 % above), and
    not for a block."""
    from rockstudy.study.spec.feasibility import uplift_notes
    from rockstudy.study.spec.schema import validate_text

    notes = uplift_notes(_study(tmp_path, folder, design="cloud"))
    assert len(notes) == 3, notes  # the wall (1.5 %), the frame (1.2 %), the arch
    arch = next(n for n in notes if "'Arch'" in n)
    assert arch.startswith("structure.objects[2] ('Arch')") and "below" in arch
    # g tan(theta_cr) of the arch's equivalent block against g lambda (this file's own search)
    theta_cr = STRUCTURES["Arch"][2].equivalent_block().slenderness
    gap = 1 - math.tan(theta_cr) / arch_lambda(math.pi, 0.2, 1.0)
    assert f"{gap:.1%}" in arch
    (wall,) = uplift_notes(validate_text(SAMPLED.replace("RATIO", "2.0")))
    assert f"{math.tan(0.8) / (2 * math.tan(0.4)) - 1:.1%} above" in wall
    block = '[[structure.objects]]\nname = "B"\nwidth = 0.4\nheight = 2.0'
    assert uplift_notes(_study(tmp_path, folder, objects=block, design="cloud")) == []


def test_a_report_without_uplift_levels_says_so(folder, tmp_path):
    """An old cube of non-block structures opens with NaN uplift levels (above): the objects
    report draws no uplift line and says the levels are not stored."""
    import re

    from rockstudy.study.designs.records import multiple_stripes
    from rockstudy.study.report.records import record_report

    rec = load_suite(folder)[0]
    objects = {k: STRUCTURES[k][2] for k in ("Wall", "Arch")}
    ds = multiple_stripes([rec], objects, [0.1], rtol=1e-6)  # PGA 0.1 m/s^2: nothing rocks
    assert float(np.nanmax(ds["max_rotation"].values)) == 0.0
    ds["uplift_acceleration"] = ds["uplift_acceleration"] * np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        page = record_report(ds, tmp_path / "r", n_boot=5)
    text = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page.read_text()))
    assert "Nothing rocked" in text and "not stored in this cube" in text
