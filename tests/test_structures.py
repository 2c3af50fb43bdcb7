"""Equivalent rocking structures of paper [003]: Table I, the wall, the frame, the arch."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.structures import (
    Arch,
    ConicalShell,
    Mechanism,
    PointMassStrut,
    RockingWall,
    SymmetricFrame,
)
from rockstudy.structures import _jet as jt


def rectangular_block(R, alpha):
    def pose(phi):
        return [R * jt.sin(alpha - phi)], [R * jt.cos(alpha - phi)], [-phi]

    return Mechanism((1.0,), (R * R / 3,), pose)


def test_generic_mechanism_recovers_housner_block():
    for R, a in ((0.5, 0.1), (2.0, 0.3)):
        rp = rectangular_block(R, a).rocking_parameters(0.9)
        assert rp.frequency_parameter == pytest.approx(math.sqrt(3 * G / (4 * R)), rel=1e-12)
        assert rp.critical_rotation == pytest.approx(a, rel=1e-12)
        assert rp.uplift == pytest.approx(math.tan(a), rel=1e-12)
        assert rp.uplift_linearized == pytest.approx(a, rel=1e-12)
        assert rp.kappa1 == pytest.approx(1.0, rel=1e-12)


def test_point_mass_strut_table_I():
    R, a = 1.7, 0.25
    rp = PointMassStrut(R, a).rocking_parameters()
    assert rp.frequency_parameter**2 == pytest.approx(G / R, rel=1e-12)
    assert rp.restitution == pytest.approx(math.cos(2 * a), rel=1e-14)
    assert rp.critical_rotation == pytest.approx(a, rel=1e-12)
    assert rp.uplift == pytest.approx(math.tan(a), rel=1e-12)


def _cone_points(H, r, n=400):
    """Area-weighted points on a thin conical surface (apex up), base circle at y = 0."""
    s = (np.arange(n) + 0.5) / n  # fraction of the slant from the apex
    th = 2 * np.pi * (np.arange(n) + 0.5) / n
    S, TH = np.meshgrid(s, th, indexing="ij")
    rho = r * S
    pts = np.stack([rho * np.cos(TH), H * (1 - S), rho * np.sin(TH)], axis=-1).reshape(-1, 3)
    return pts, S.ravel() / S.sum()  # weight ~ ring radius


def test_conical_shell_by_quadrature_of_its_surface():
    H, r = 12.0, 2.0
    cone = ConicalShell(height=H, base_radius=r)
    rp = cone.rocking_parameters()
    pts, w = _cone_points(H, r)
    old = np.array([-r, 0.0, 0.0])
    new = np.array([r, 0.0, 0.0])
    a, b = (pts - old)[:, :2], (pts - new)[:, :2]
    inertia = np.sum(w * np.sum(a * a, axis=1))  # about the tangent at the old pivot
    com = np.sum(w[:, None] * pts, axis=0)
    arm = math.hypot(com[0] - old[0], com[1])
    assert com[1] == pytest.approx(H / 3, rel=1e-4)
    assert rp.frequency_parameter**2 == pytest.approx(G * arm / inertia, rel=1e-4)
    # angular momentum about the new pivot, before and after the impact
    assert rp.restitution == pytest.approx(np.sum(w * np.sum(a * b, axis=1)) / inertia, rel=1e-4)
    assert rp.uplift == pytest.approx(3 * r / H, rel=1e-12)


def test_symmetric_frame_eqs_35_37_and_table_I():
    R, a, gam = 1.3, 0.2, 0.6
    frame = SymmetricFrame(R, a, gam)
    m_c = 1.0
    m, m_bc = m_c / 2, gam * m_c
    i0 = 4 / 3 * m * R * R
    amp = np.linspace(0.0, 0.5, 7)
    t = frame.mechanism().terms(amp)
    phi_abs = math.pi / 2 + a - amp  # angle of the column diagonal, as in (35)
    np.testing.assert_allclose(t["I"] / 2, i0 + 2 * m_bc * R * R, rtol=1e-10)
    # (35) is written in the absolute angle; d/d(amplitude) = -d/d(angle) flips its sign
    np.testing.assert_allclose(t["G"] / 2, (m + m_bc) * R * np.cos(phi_abs), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(t["B"] / 2, (m + m_bc) * R * np.sin(phi_abs), rtol=1e-10)
    rp = frame.rocking_parameters()
    assert rp.uplift == pytest.approx(math.tan(a), rel=1e-10)  # (36)
    assert rp.critical_rotation == pytest.approx(a, rel=1e-10)  # (37)
    p2 = 3 * G / (4 * R) * (1 + 2 * gam) / (1 + 3 * gam)
    assert rp.frequency_parameter**2 == pytest.approx(p2, rel=1e-10)


def test_symmetric_frame_restitution_by_impulse_balance():
    """Columns switch pivots, the beam's top contacts switch diagonals: solve the impulse
    equations numerically (columns: angular momentum about the new pivots with the beam's
    impulse; beam: linear momentum) and compare with the closed form."""
    R, a = 1.0, 0.22
    for gam in (0.0, 0.4, 2.0):
        m1, mb = 0.5, gam
        b, h = R * math.sin(a), R * math.cos(a)
        i_o = 4 / 3 * m1 * R * R
        d_old, d_new = np.array([2 * b, 2 * h]), np.array([-2 * b, 2 * h])  # pivot -> top
        w = 1.0
        v_beam_old = w * np.array([-d_old[1], d_old[0]])
        # unknowns: w_new, Px, Py (impulse from the beam on each column's top)
        cross = lambda u, v: u[0] * v[1] - u[1] * v[0]  # noqa: E731
        A = np.zeros((3, 3))
        rhs = np.zeros(3)
        A[0] = [i_o, -(d_new[0] * 0 - 0), 0]
        # column: I_O w+ - (I_O - 2 m1 b^2) w- = d_new x P
        A[0] = [i_o, d_new[1], -d_new[0]]
        rhs[0] = (i_o - 2 * m1 * b * b) * w
        # beam: mb (v+ - v-) = -2 P, with v+ = w+ z x d_new
        A[1] = [mb * -d_new[1], 2.0, 0.0]
        A[2] = [mb * d_new[0], 0.0, 2.0]
        rhs[1:] = mb * v_beam_old
        w_new = np.linalg.solve(A, rhs)[0]
        assert cross(d_old, d_new) != 0
        eta = SymmetricFrame(R, a, gam).rocking_parameters().restitution
        assert eta == pytest.approx(w_new / w, rel=1e-12)


def test_rocking_wall_eqs_21_23():
    R, a = 1.2, 0.12
    rp = RockingWall(R, a, restitution=0.8).rocking_parameters()
    assert rp.frequency_parameter == pytest.approx(
        math.sqrt(2) * math.sqrt(3 * G / (4 * R)), rel=1e-10
    )
    assert rp.critical_rotation / rp.kappa1 == pytest.approx(2 * a, rel=1e-10)
    assert rp.kappa1 == pytest.approx(0.5, rel=1e-10)
    assert rp.kappa2 == pytest.approx(a / (2 * math.tan(a)), rel=1e-10)
    # eq. (21) divided through: I_nl / (4 m g R) = I_O/(2 m g R) + (2R/g) sin^2(alpha - phi)
    phi = np.linspace(0, 0.2, 5)
    t = RockingWall(R, a).mechanism().terms(phi)
    i_o = 4 / 3 * R * R
    np.testing.assert_allclose(
        t["I"] / (4 * G * R), i_o / (2 * G * R) + 2 * R / G * np.sin(a - phi) ** 2, rtol=1e-10
    )


def _virtual_work_lambda(arch):
    """Collapse multiplier of the arch's hinges by instant centres (no jets, no four-bar)."""
    h = arch.hinges
    r, t = arch.radius, arch.thickness
    pts = [
        np.array([(r + f * t / 2) * math.sin(p), (r + f * t / 2) * math.cos(p)])
        for p, f in zip(h["angles"], h["faces"], strict=True)
    ]
    A, B, C, D = pts
    # block AB turns about A (rate 1), CD about D, BC about the intersection of AB and DC
    d1, d2 = B - A, C - D
    s = np.linalg.solve(np.column_stack([d1, -d2]), D - A)[0]
    ic = A + s * d1
    vb = np.array([-(B - A)[1], (B - A)[0]])
    w2 = np.dot(vb, np.array([-(B - ic)[1], (B - ic)[0]])) / np.dot(B - ic, B - ic)
    vc = w2 * np.array([-(C - ic)[1], (C - ic)[0]])
    w3 = np.dot(vc, np.array([-(C - D)[1], (C - D)[0]])) / np.dot(C - D, C - D)
    work_x = work_y = 0.0
    for k, (centre, w) in enumerate(((A, 1.0), (ic, w2), (D, w3))):
        p1, p2 = h["angles"][k], h["angles"][k + 1]
        n = 2000
        ang = np.linspace(p1, p2, n + 1)[:-1] + (p2 - p1) / (2 * n)
        rad = np.linspace(r - t / 2, r + t / 2, 41)[:-1] + t / 80
        AN, RR = np.meshgrid(ang, rad, indexing="ij")
        x, y, dA = RR * np.sin(AN), RR * np.cos(AN), RR * (p2 - p1) / n * t / 40
        vx, vy = -w * (y - centre[1]), w * (x - centre[0])
        work_x += np.sum(dA * vx)
        work_y += np.sum(dA * vy)
    return work_y / work_x


@pytest.mark.parametrize("beta, ratio", [(math.pi, 0.15), (math.pi, 0.25), (2.4, 0.12)])
def test_arch_lambda_by_independent_virtual_work(beta, ratio):
    arch = Arch(beta, ratio * 4.0, 4.0, restitution=0.9)
    lam = arch.hinges["uplift"]
    assert lam > 0
    assert _virtual_work_lambda(arch) == pytest.approx(lam, rel=1e-4)
    assert arch.rocking_parameters().uplift == pytest.approx(lam, rel=1e-10)


def test_arch_milankovitch_minimum_thickness():
    lam = Arch(math.pi, 0.1075, 1.0).hinges
    assert abs(lam["uplift"]) < 2e-3
    # the symmetric half of the self-weight mechanism: hinges near +-54.5 deg of the crown
    assert abs(math.degrees(abs(lam["angles"][0])) - 54.5) < 1.0
    assert Arch(math.pi, 0.12, 1.0).hinges["uplift"] > 0.02
    with pytest.raises(ValueError, match="cannot stand"):
        Arch(math.pi, 0.10, 1.0)


def _quarter_period_by_quadrature(mech, phi0):
    """Time from phi0 at rest to the impact: integral of sqrt(I / (2 g (V(phi0) - V))) over
    (0, phi0) from the mechanism's exact terms (energy conservation, eq. 8 of [003])."""
    v0 = float(mech.terms(np.array([phi0]))["V"][0])

    def smooth(phi):  # sqrt(phi0 - phi) / speed: the 1/sqrt singularity goes to quad's weight
        t = mech.terms(np.array([phi]))
        d = phi0 - phi
        slope = (v0 - t["V"][0]) / d if d > 1e-12 else -t["G"][0]
        return math.sqrt(t["I"][0] / (2 * G * slope))

    return quad(smooth, 0.0, phi0, weight="alg", wvar=(0.0, -0.5), epsrel=1e-11)[0]


@pytest.mark.parametrize(
    "structure",
    [
        PointMassStrut(1.0, 0.2),
        ConicalShell(8.0, 1.0),
        SymmetricFrame(1.0, 0.15, 0.5),
        RockingWall(1.0, 0.1, restitution=1.0),
        Arch(math.pi, 0.6, 4.0, restitution=1.0),
    ],
    ids=lambda s: type(s).__name__,
)
def test_free_rocking_period_integration_vs_energy_quadrature(structure):
    """Quarter period from phi0 to the impact: the kernel on eq. (8) against
    integral of sqrt(I / (2 g (V(phi0) - V))) from the mechanism's exact terms."""
    phi0 = 0.6 * structure.rocking_parameters().critical_rotation
    quarter = _quarter_period_by_quadrature(structure.mechanism(), phi0)
    res = rs.simulate(
        structure, rs.motions.NoMotion(), initial_rotation=phi0, rtol=1e-11, t_max=2.0
    )
    assert res.impact_times[0] == pytest.approx(quarter, rel=1e-7)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: Arch(math.pi, -0.1, 1.0), "thickness"),
        (lambda: Arch(7.0, 0.2, 1.0), "inclusion_angle"),
        (lambda: Arch(math.pi, 1.5, 1.0), "thickness"),
        (lambda: Arch(math.pi, 0.2, -1.0), "radius"),
        (lambda: RockingWall(1.0, 0.9), "slenderness"),
        (lambda: SymmetricFrame(1.0, 0.2, -0.5), "mass_ratio"),
        (lambda: ConicalShell(-1.0, 1.0), "height"),
        (lambda: PointMassStrut(0.0, 0.2), "half_diagonal"),
    ],
)
def test_bad_geometry_is_refused(make, field):
    with pytest.raises(ValueError, match=field):
        make()


def test_equivalent_blocks_run_through_simulate():
    wall = RockingWall(1.0, 0.1, restitution=0.85)
    pulse = rs.motions.SinePulse(1.5 * G * wall.rocking_parameters().uplift, 0.5)
    full = rs.simulate(wall, pulse)  # the mechanism, eq. (8)
    for kappa in ("kappa1", "kappa2"):
        eq = rs.simulate(wall.equivalent_block(kappa), pulse, method="linear")
        assert np.isfinite(eq.max_rotation)
    assert not full.overturned and full.n_impacts > 0
    with pytest.raises(ValueError, match="restitution"):
        rs.simulate(RockingWall(1.0, 0.1), pulse)


def test_error_map_against_simulations():
    """The map's free-rocking period of an exact block equivalent (point mass strut) equals the
    nonlinear kernel's; its block period is the linear solver's; its overturning time is
    solve_ivp's on eq. (8)."""
    from scipy.integrate import solve_ivp

    from rockstudy.verification.equivalent_errors import error_map

    strut = PointMassStrut(1.0, 0.2)
    ds = error_map([strut], {"slenderness": [0.2]}, amplitude=(0.5,), acceleration=(2.0,))
    rp = strut.rocking_parameters()
    blk = rs.structures.EquivalentBlock(rp.frequency_parameter, 0.2, 1.0)
    nl = rs.simulate(blk, rs.motions.NoMotion(), initial_rotation=0.1, rtol=1e-11, t_max=3.0)
    lin = rs.simulate(blk, rs.motions.NoMotion(), method="linear", initial_rotation=0.1, t_max=3.0)
    assert float(ds.period_ratio[0, 0]) == pytest.approx(
        lin.impact_times[0] / nl.impact_times[0], rel=1e-7
    )
    # overturning time: integrate eq. (8) from rest under 2 g lambda until phi_cr
    mech = strut.mechanism()
    a = -2.0 * rp.uplift * G

    def rhs(t, y):
        tt = mech.terms(np.array([y[0]]))
        return [y[1], (tt["G"][0] * G - tt["J"][0] * y[1] ** 2 - tt["B"][0] * a) / tt["I"][0]]

    def reach(t, y):
        return y[0] - rp.critical_rotation

    reach.terminal = True
    sol = solve_ivp(rhs, (0, 50), [0.0, 0.0], events=reach, rtol=1e-11, atol=1e-13)
    t_block = rs.closedform.overturning_time_constant_acceleration(
        rp.frequency_parameter, 2.0, rp.uplift / rp.uplift_linearized
    )
    assert float(ds.overturn_time_ratio_kappa1[0, 0]) == pytest.approx(
        t_block / sol.t_events[0][0], rel=1e-6
    )
    assert float(ds.uplift_ratio[0]) == pytest.approx(0.2 / math.tan(0.2), rel=1e-12)


def test_asymmetric_frame_reduces_to_symmetric_frame():
    from rockstudy.structures import AsymmetricFrame

    b, H, L, h = 0.3, 2.0, 6.0, 0.25
    m_col, m_beam = 1.0, 1.5
    asym = AsymmetricFrame(b, H, H, L, h, m_col, m_beam, m_col)
    sym = SymmetricFrame(math.hypot(b, H), math.atan2(b, H), m_beam / (2 * m_col))
    ref = sym.rocking_parameters()
    for rp in asym.rocking_parameters():
        assert rp.frequency_parameter == pytest.approx(ref.frequency_parameter, rel=1e-10)
        assert rp.critical_rotation == pytest.approx(ref.critical_rotation, rel=1e-10)
        assert rp.uplift == pytest.approx(ref.uplift, rel=1e-10)
        assert rp.kappa1 == pytest.approx(ref.kappa1, rel=1e-10)


def test_asymmetric_frame_uplift_eq_33():
    """lambda_p, lambda_n of the generic four-bar mechanism against eq. (33) by virtual work."""
    from rockstudy.structures import AsymmetricFrame

    rng = np.random.default_rng(4)
    for _ in range(10):
        b = rng.uniform(0.15, 0.4)
        H = rng.uniform(1.5, 3.0)
        frame = AsymmetricFrame(
            b,
            H,
            H * rng.uniform(0.5, 0.95),
            rng.uniform(4, 10),
            rng.uniform(0.1, 0.5),
            *rng.uniform(0.5, 3.0, 3),
        )
        pos, neg = frame.rocking_parameters()
        lp, ln = frame.uplift_closed_form()
        assert pos.uplift == pytest.approx(lp, rel=1e-12)
        assert neg.uplift == pytest.approx(ln, rel=1e-12)
        assert pos.uplift != pytest.approx(neg.uplift, rel=1e-3)  # asymmetric
    with pytest.raises(ValueError, match="beam_length"):
        AsymmetricFrame(0.5, 2.0, 1.5, 1.5, 0.2)


def test_mechanism_kernel_against_solve_ivp_on_eq_8():
    """The tabulated kernel against solve_ivp on eq. (8) with the exact jet terms: a wall and
    an arch lifted by a sine pulse, up to the first impact."""
    from scipy.integrate import solve_ivp

    for structure in (
        RockingWall(1.0, 0.1, restitution=0.8),
        Arch(math.pi, 0.8, 5.0, restitution=0.9),
    ):
        mech, rp = structure.mechanism(), structure.rocking_parameters()
        pulse = rs.motions.SinePulse(1.6 * G * rp.uplift, 0.6)
        res = rs.simulate(structure, pulse, rtol=1e-10)
        # reference: uplift when u_g'' reaches g lambda (onto the negative side: the ground
        # term enters eq. (8) as +B u_g''), then eq. (8) in the amplitude
        w = 2 * math.pi / 0.6
        t_up = math.asin(rp.uplift * G / pulse.amplitude) / w

        def rhs(t, y, mech=mech, pulse=pulse):
            tt = mech.terms(np.array([y[0]]))
            a = pulse.ground_acceleration(t)
            return [y[1], (tt["G"][0] * G - tt["J"][0] * y[1] ** 2 + tt["B"][0] * a) / tt["I"][0]]

        def impact(t, y):
            return y[0]

        impact.terminal, impact.direction = True, -1
        sol = solve_ivp(
            rhs,
            (t_up, 30),
            [0.0, 0.0],
            events=impact,
            rtol=1e-11,
            atol=1e-14,
            dense_output=True,
            max_step=0.01,
        )
        assert res.impact_times[0] == pytest.approx(sol.t_events[0][0], abs=1e-7)
        i = np.searchsorted(res.t, res.impact_times[0])  # the pre-impact row
        assert res.theta_dot[i] == pytest.approx(-sol.y_events[0][0][1], rel=1e-7)


def test_asymmetric_frame_dynamics():
    from rockstudy.structures import AsymmetricFrame

    b, H = 0.3, 2.0
    sym = SymmetricFrame(math.hypot(b, H), math.atan2(b, H), 0.75)
    eta = sym.rocking_parameters().restitution
    same = AsymmetricFrame(b, H, H, 6.0, 0.25, 1.0, 1.5, 1.0, restitution=eta)
    pulse = rs.motions.SinePulse(1.5 * G * b / H, 0.7)
    a = rs.simulate(same, pulse, rtol=1e-10)
    s = rs.simulate(sym, pulse, rtol=1e-10)
    assert a.max_rotation == pytest.approx(s.max_rotation, rel=1e-6)
    # an asymmetric frame answers a mirrored pulse differently
    asym = AsymmetricFrame(b, H, 0.7 * H, 6.0, 0.25, 1.0, 1.5, 1.0, restitution=0.9)
    up = rs.simulate(asym, pulse)
    down = rs.simulate(asym, rs.motions.SinePulse(-pulse.amplitude, 0.7))
    assert up.max_rotation != pytest.approx(down.max_rotation, rel=1e-3)


def test_asymmetric_frame_free_rocking_period_each_direction():
    from rockstudy.structures import AsymmetricFrame

    frame = AsymmetricFrame(0.3, 2.0, 1.5, 6.0, 0.25, 1.0, 1.5, 1.0, restitution=1.0)
    for direction, params in zip((1, -1), frame.rocking_parameters(), strict=True):
        phi0 = 0.5 * params.critical_rotation
        quarter = _quarter_period_by_quadrature(frame.mechanism(direction), phi0)
        res = rs.simulate(
            frame, rs.motions.NoMotion(), initial_rotation=direction * phi0, rtol=1e-11, t_max=2.0
        )
        assert res.impact_times[0] == pytest.approx(quarter, rel=1e-7)
