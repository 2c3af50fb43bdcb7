"""The registry of structure kinds of study files (``rockstudy.study.spec.structures``).

Oracles: the closed forms of [003] written here (Table I for the block, the strut, the
conical shell and the symmetric frame, eq. 23 for the wall), each physics class of
``rockstudy.structures`` built directly where there is none (the arch), and single-scene
simulations of the frame's equivalent block alone under the same record ([003]'s equivalence).
"""

import math

import numpy as np
import pytest
from _helpers import ARCH, FRAME, WALL, write_at2  # the examples of the kinds

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.motions import Record
from rockstudy.structures import (
    Arch,
    AsymmetricFrame,
    Block,
    ConicalShell,
    IsolatedBlock,
    PointMassStrut,
    RockingWall,
    StackedBlocks,
    SymmetricFrame,
)
from rockstudy.study.spec.schema import OBJECT_COLUMNS, OBJECT_KINDS, ObjectSpec, json_schema
from rockstudy.study.spec.structures import KINDS, TWO_BODY_KINDS

#: kind -> (fields of a study object, the physics object built directly)
EXAMPLES = {
    "block": (dict(width=0.45, height=1.9), Block.from_dimensions(0.45, 1.9)),
    "rocking_wall": (WALL, RockingWall(1.5, 0.12, 0.85)),
    "asymmetric_frame": (
        FRAME,
        AsymmetricFrame(0.2, 1.5, 1.2, 3.0, 0.2, mass_beam=2.0, restitution=0.8),
    ),
    "arch": (ARCH, Arch(math.pi, 0.2, 1.0, restitution=0.7)),
    "symmetric_frame": (
        dict(half_diagonal=1.1, slenderness=0.2, mass_ratio=0.5),
        SymmetricFrame(1.1, 0.2, 0.5),
    ),
    "point_mass_strut": (
        dict(half_diagonal=0.8, slenderness=0.25),
        PointMassStrut(0.8, 0.25),
    ),
    "conical_shell": (dict(height=6.0, base_radius=1.0), ConicalShell(6.0, 1.0)),
    "stacked": (
        dict(width=0.4, height=1.6, plinth_width=0.8, plinth_height=1.0),
        StackedBlocks(Block.from_dimensions(0.8, 1.0), Block.from_dimensions(0.4, 1.6)),
    ),
    "isolated": (
        dict(width=0.4, height=1.6, period=2.0, damping=0.1, base_mass_ratio=1.0),
        IsolatedBlock(Block.from_dimensions(0.4, 1.6), 1.0, 2.0, 0.1),
    ),
}


def _expected(structure):
    b = structure if isinstance(structure, Block) else structure.equivalent_block()
    return (b.frequency_parameter, b.slenderness, b.restitution)


def test_every_kind_has_an_example_and_the_schema_takes_the_registry():
    assert set(EXAMPLES) == set(KINDS) == set(OBJECT_KINDS)
    fields = {f for k in KINDS.values() for f in k.fields}
    given = {"name", "kind", "friction", "friction_kinetic", "compare_to"}
    assert set(OBJECT_COLUMNS) == fields | given
    props = json_schema()["$defs"]["ObjectSpec"]["properties"]
    assert fields <= set(props)


def _housner_block(width, height):
    """(p, theta_cr, eta) of a rectangular block: p = sqrt(3 g / 4 R), alpha = atan(b / h),
    eta = 1 - 3/2 sin^2 alpha (Housner; eq. 3 and Table I of [003])."""
    R, alpha = math.hypot(width / 2, height / 2), math.atan2(width, height)
    return math.sqrt(0.75 * G / R), alpha, 1 - 1.5 * math.sin(alpha) ** 2


def _symmetric_frame(R, alpha, gamma):
    """(p, theta_cr, eta) of two columns (R, alpha) under a beam, gamma = m_beam / m_columns:
    Table I of [003] (DESIGN.md: derived by angular momentum about the new pivots)."""
    p2 = 0.75 * G / R * (1 + 2 * gamma) / (1 + 3 * gamma)
    eta = (1 - 1.5 * math.sin(alpha) ** 2 + 3 * gamma * math.cos(2 * alpha)) / (1 + 3 * gamma)
    return math.sqrt(p2), alpha, eta


def _conical_shell(H, r):
    """(p, theta_cr, eta) of a thin conical shell on its base circle: centre of mass at H/3,
    I_O / m = H^2/6 + 5 r^2/4 about a base point (the cone's H^2/18 + r^2/4 about its centre,
    moved by H/3 and r), p^2 = g R m / I_O, eta = 1 - 2 m r^2 / I_O (Table I of [003])."""
    R, inertia = math.hypot(r, H / 3), H * H / 6 + 1.25 * r * r
    return math.sqrt(G * R / inertia), math.atan2(3 * r, H), 1 - 2 * r * r / inertia


#: kind -> (fields of a study object, its (p, theta_cr, eta) by the closed forms of [003])
CLOSED_FORMS = {
    "block": (dict(width=0.45, height=1.9), _housner_block(0.45, 1.9)),
    # eq. (23): p_eq = sqrt(2) sqrt(3 g / 4 R), theta_cr = 2 alpha; eta as given
    "rocking_wall": (WALL, (math.sqrt(1.5 * G / 1.5), 2 * 0.12, 0.85)),
    "symmetric_frame": (
        dict(half_diagonal=1.1, slenderness=0.2, mass_ratio=0.5),
        _symmetric_frame(1.1, 0.2, 0.5),
    ),
    # p^2 = g / R (a pendulum), eta = cos 2 alpha
    "point_mass_strut": (
        dict(half_diagonal=0.8, slenderness=0.25),
        (math.sqrt(G / 0.8), 0.25, math.cos(0.5)),
    ),
    "conical_shell": (dict(height=6.0, base_radius=1.0), _conical_shell(6.0, 1.0)),
    # columns of equal heights: the beam translates, the symmetric frame of Table I with
    # gamma = m_beam / (m_left + m_right) = 2 / 2; eta as given
    "asymmetric_frame": (
        {**FRAME, "height_right": FRAME["height"]},
        _symmetric_frame(math.hypot(0.2, 1.5), math.atan2(0.2, 1.5), 1.0)[:2] + (0.8,),
    ),
}


def _design_parameters(kind, values):
    """(frequency_parameter, critical_rotation, restitution, slenderness, half_diagonal) of a
    one-object study's design columns."""
    from rockstudy.study.designs.sampling import _object_columns
    from rockstudy.study.spec.schema import ObjectsSpec

    spec = ObjectsSpec(kind="objects", objects=[ObjectSpec(name=kind, kind=kind, **values)])
    cols = _object_columns(spec)
    names = ("frequency_parameter", "critical_rotation", "restitution")
    return tuple(cols[n][0] for n in names), cols["slenderness"][0], cols["half_diagonal"][0]


@pytest.mark.parametrize("kind", list(CLOSED_FORMS))
def test_each_kind_in_a_design_has_the_parameters_of_the_papers_closed_forms(kind):
    values, expected = CLOSED_FORMS[kind]
    got, slenderness, half_diagonal = _design_parameters(kind, values)
    assert got == pytest.approx(expected, rel=1e-9)
    assert slenderness == pytest.approx(got[1], rel=1e-12)  # the block's alias
    R = values.get("half_diagonal", math.hypot(0.225, 0.95) if kind == "block" else np.nan)
    np.testing.assert_allclose(half_diagonal, R, rtol=1e-12)


def test_every_kind_has_a_closed_form_but_the_arch():
    """The arch's equivalent block comes from its hinge search ([003] sec. 5.2 has no closed
    form); its design columns are held to the physics class in the test below. The two-body
    kinds' are in test_two_body_study.py."""
    assert set(CLOSED_FORMS) == set(KINDS) - {"arch", *TWO_BODY_KINDS}


@pytest.mark.parametrize("kind", ["arch", "asymmetric_frame"])
def test_the_kinds_without_a_closed_form_carry_the_parameters_of_their_class(kind):
    """The arch, and the frame of unequal columns: the design columns are the equivalent block
    of the physics class built directly (the plumbing from study object to design)."""
    values, structure = EXAMPLES[kind]
    got, slenderness, half_diagonal = _design_parameters(kind, values)
    assert got == pytest.approx(_expected(structure), rel=1e-12)
    assert slenderness == pytest.approx(got[1], rel=1e-12)
    assert np.isnan(half_diagonal)


def test_closed_forms_of_the_wall_strut_and_symmetric_frame():
    # eq. (23) of [003]: p_wall = sqrt(2) sqrt(3 g / 4 R), theta_cr = 2 alpha
    R, a = np.array([0.5, 1.5, 4.0]), np.array([0.05, 0.12, 0.3])
    # and its uplift acceleration g lambda, eq. (21) at phi = 0: lambda = 2 tan(alpha)
    p, theta, a_up = KINDS["rocking_wall"].sampled(R, a)
    np.testing.assert_allclose(p, np.sqrt(2) * np.sqrt(0.75 * G / R), rtol=1e-14)
    np.testing.assert_allclose(theta, 2 * a, rtol=1e-14)
    np.testing.assert_allclose(a_up, 2 * G * np.tan(a), rtol=1e-14)
    for r, al in zip(R, a, strict=True):
        wall = RockingWall(r, al, 0.9)
        eq = wall.equivalent_block()
        assert (eq.frequency_parameter, eq.slenderness) == pytest.approx(
            (math.sqrt(1.5 * G / r), 2 * al), rel=1e-9
        )
        assert rs.structures.uplift_acceleration(wall) == pytest.approx(
            2 * G * math.tan(al), rel=1e-12
        )
    # Table I of [003]: strut p^2 = g / R, eta = cos 2 alpha; frame p^2 = (3g/4R)(1+2g)/(1+3g)
    strut = ObjectSpec(name="s", kind="point_mass_strut", half_diagonal=0.8, slenderness=0.25)
    assert strut.rocking() == pytest.approx((math.sqrt(G / 0.8), 0.25, math.cos(0.5)), rel=1e-9)
    frame = ObjectSpec(
        name="f", kind="symmetric_frame", half_diagonal=1.1, slenderness=0.2, mass_ratio=0.5
    )
    p_frame = math.sqrt(0.75 * G / 1.1 * 2.0 / 2.5)
    eta = (1 - 1.5 * math.sin(0.2) ** 2 + 1.5 * math.cos(0.4)) / 2.5
    assert frame.rocking() == pytest.approx((p_frame, 0.2, eta), rel=1e-9)


@pytest.mark.parametrize(
    "obj, field, words",
    [
        ({"kind": "arch", **ARCH, "thickness": 0.05}, "thickness", "cannot stand"),
        ({"kind": "arch", **ARCH, "inclusion_angle": 7.0}, "inclusion_angle", "(0, 2 pi)"),
        ({"kind": "asymmetric_frame", **FRAME, "beam_length": -3.0}, "beam_length", "(0, inf)"),
        ({"kind": "asymmetric_frame", **FRAME, "beam_length": 0.5}, "beam_length", "exceed"),
        (
            {"kind": "asymmetric_frame", **{k: v for k, v in FRAME.items() if k != "restitution"}},
            "restitution",
            "needs",
        ),
        ({"kind": "rocking_wall", **WALL, "width": 0.3}, "width", "does not apply"),
        ({"kind": "rocking_wall", **WALL, "slenderness": 0.9}, "slenderness", "pi/4"),
        (
            {"kind": "conical_shell", "height": 6.0, "base_radius": 1.0, "restitution": 0.5},
            "restitution",
            "does not apply",
        ),
        ({"kind": "pyramid", "height": 1.0}, "kind", "'asymmetric_frame'"),
    ],
)
def test_bad_fields_are_refused_naming_the_object_and_the_field(tmp_path, obj, field, words):
    from rockstudy.study import StudyError, load_study

    cells = ", ".join(f"{k} = {v!r}".replace("'", '"') for k, v in obj.items())
    write_at2(tmp_path / "r.AT2", _sine(3.0).scaled(G))
    path = tmp_path / "bad.toml"
    path.write_text(
        STUDY.format(
            objects=f'objects = [{{ name = "Ok", width = 0.4, height = 2.0 }}, '
            f'{{ name = "Odd", {cells} }}]',
            folder=tmp_path,
        )
    )
    with pytest.raises(StudyError) as err:
        load_study(path)
    text = "\n".join(err.value.problems)
    assert f"structure.objects[1] ('Odd').{field}" in text, text
    assert words in text, text


# ------------------------------------------------------------------------------ a study

STUDY = """
name = "kinds"
seed = 1
[structure]
kind = "objects"
{objects}
[motion]
kind = "record"
files = "{folder}"
[design]
kind = "ida"
tolerance = 0.02
scan = 0
"""
CSV = (
    "name,kind,half_diagonal,slenderness,restitution,half_width,height,height_right,"
    "beam_length,beam_half_depth,mass_beam,inclusion_angle,thickness,radius\n"
    "Wall,rocking_wall,1.5,0.12,0.85,,,,,,,,,\n"
    "Frame,asymmetric_frame,,,0.8,0.2,1.5,1.2,3.0,0.2,2.0,,,\n"
    f"Arch,arch,,,0.7,,,,,,,{math.pi!r},0.2,1.0\n"
)


def _sine(p, ratio=1.5):
    """One cycle of a unit sine at omega = ratio p, then rest: overturning is monotone in
    its scale."""
    T = 2 * np.pi / (ratio * p)
    dt = 0.005
    t = np.arange(0, 3 * T, dt)
    return Record(np.where(t <= T, np.sin(2 * np.pi * t / T), 0.0), dt=dt, name="sine")


def test_an_objects_study_of_a_wall_a_frame_and_an_arch(client, tmp_path):
    from rockstudy.motions import load_suite
    from rockstudy.study import load_study, run_study
    from rockstudy.study.running.store import open_result

    frame = EXAMPLES["asymmetric_frame"][1].equivalent_block()
    folder = tmp_path / "records"
    folder.mkdir()
    write_at2(folder / "sine.AT2", _sine(frame.frequency_parameter).scaled(G))
    (tmp_path / "objects.csv").write_text(CSV)
    path = tmp_path / "kinds.toml"
    path.write_text(STUDY.format(objects='file = "objects.csv"', folder=folder))
    study = load_study(path)
    out = tmp_path / "cube.zarr"
    report = run_study(study, out, client=client, base_dir=tmp_path, progress=False)
    assert report.failed_samples == 0
    cube = open_result(out).load()
    assert list(cube["structure"].values) == ["Wall", "Frame", "Arch"]
    for name, kind in (("Wall", "rocking_wall"), ("Frame", "asymmetric_frame"), ("Arch", "arch")):
        row = cube.sel(structure=name)
        assert float(row["frequency_parameter"]) == pytest.approx(
            _expected(EXAMPLES[kind][1])[0], rel=1e-12
        )
    # the frame's capacity is that of its equivalent block alone ([003]): the record scaled to
    # the capacity overturns the block, the highest surviving scale below it does not
    rec = load_suite(folder)[0]
    lo = float(cube["capacity_scale_lower"].sel(structure="Frame")[0])
    hi = float(cube["capacity_scale"].sel(structure="Frame")[0])
    assert np.isfinite(lo) and hi > lo
    assert rs.simulate(frame, rec.scaled(hi)).overturned
    assert not rs.simulate(frame, rec.scaled(lo)).overturned
    # and the Python design function on the same structures gives the same cube
    from rockstudy.study.designs import records as rd

    objects = {
        n: EXAMPLES[k][1]
        for n, k in (("Wall", "rocking_wall"), ("Frame", "asymmetric_frame"), ("Arch", "arch"))
    }
    api = rd.incremental_dynamic_analysis([rec], objects, tolerance=0.02, scan=0)
    for name in ("capacity", "capacity_scale", "capacity_scale_lower"):
        np.testing.assert_allclose(
            np.asarray(cube[name].values, float),
            np.asarray(api[name].values, float),
            rtol=1e-12,
            err_msg=name,
        )


SAMPLED = """
name = "sampled"
seed = 3
[sampler]
kind = "monte_carlo"
n = 6
[structure]
kind = "{kind}"
half_diagonal = {{ dist = "uniform", low = 0.5, high = 3.0 }}
slenderness = {{ dist = "uniform", low = 0.05, high = 0.3 }}
restitution = 0.8
[motion]
kind = "pulse"
shape = "sine"
amplitude_ratio = 2.0
period = 0.5
"""


@pytest.mark.parametrize("kind", [k for k, v in KINDS.items() if v.sampled is not None])
def test_a_sampled_kind_in_a_design_has_the_parameters_of_its_class(kind):
    from rockstudy.study.designs.sampling import make_design
    from rockstudy.study.spec.schema import validate_text

    ds = make_design(validate_text(SAMPLED.format(kind=kind)))
    for R, a, p, theta in zip(
        *(ds[v].values for v in ("half_diagonal", "slenderness")),
        *(ds[v].values for v in ("frequency_parameter", "critical_rotation")),
        strict=True,
    ):
        expect = _expected(KINDS[kind].structure(R, a, 0.8))  # its mechanism, not eq. (23)
        assert (p, theta) == pytest.approx(expect[:2], rel=1e-9)
