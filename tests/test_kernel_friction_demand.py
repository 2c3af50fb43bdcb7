"""The friction demand and lift-off that the batch's rocking kernel computes on the way.

Oracle: Housner's equation integrated by solve_ivp (DOP853, rtol 1e-12, dense output) from
rest, with uplift, impacts (eq. 2.3 of [000]) and rests, written here; the ground's force on
the block from the rigid-body equations, F_h = m (u_g'' + x_G''), F_v = m (g + u_v'' + y_G''),
with the centre of mass G at (-s R sin phi, R cos phi) from the pivot (phi = alpha - s theta),
its accelerations by the chain rule, maximised on a fine grid and refined; the impacts'
impulse ratio (1 - eta) / ((1 + eta) tan alpha). Of an overturned block, the response up to the
last time |theta| = alpha.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

import rockstudy as rs
from rockstudy.constants import G
from rockstudy.dynamics import _demand
from rockstudy.dynamics.batch import MODEL_CONTACT
from rockstudy.dynamics.constants import REST_FRACTION
from rockstudy.motions import Record, stochastic_record

#: Grid spacing [s] of the oracle's forces, before the largest ratio is refined.
GRID = 2e-4
#: How long the oracle follows the free rocking after the motion [s]: free rocking needs less
#: than tan alpha (test_free_rocking_needs_less_than_tan_alpha), which uplift already needs.
FREE = 2.0


class Ground:
    """u_h'' and u_v'' [m/s^2] of a motion as functions of t, and the times of its kinks."""

    def __init__(self, a_h, a_v, kinks, duration):
        self.a_h, self.a_v, self.kinks, self.duration = a_h, a_v, kinks, duration

    @classmethod
    def sine(cls, amplitude, period):
        w = 2 * math.pi / period

        def a_h(t):
            return np.where((t >= 0) & (t <= period), amplitude * np.sin(w * t), 0.0)

        return cls(a_h, lambda t: 0.0 * np.asarray(t), np.array([0.0, period]), period)

    @classmethod
    def record(cls, record):
        t, h = record.time, record.acceleration
        v = np.zeros_like(h) if record.vertical is None else record.vertical
        end = float(t[-1])

        def a_h(x):
            return np.where((x >= 0) & (x <= end), np.interp(x, t, h), 0.0)

        def a_v(x):
            return np.where((x >= 0) & (x <= end), np.interp(x, t, v), 0.0)

        return cls(a_h, a_v, np.asarray(t, float), end)


class Oracle:
    """Housner's block (p, alpha, eta) under ``ground``, from rest, by solve_ivp."""

    def __init__(self, p, alpha, eta, ground):
        self.p, self.alpha, self.eta, self.ground = p, alpha, eta, ground
        self.radius = 0.75 * G / p**2
        self.pieces = []  # (t0, t1, dense solution, side)
        self.impacts = 0
        self.overturned = False

    def theta_ddot(self, t, th, om, s):
        g = self.ground
        gam = G + g.a_v(t)
        x = self.alpha * s - th
        return -(self.p**2) * (gam / G * np.sin(x) + g.a_h(t) / G * np.cos(x))

    def forces(self, t, th, om, s):
        """(F_h / m, F_v / m): the centre of mass at (-s R sin phi, R cos phi) from the pivot,
        which moves with the ground."""
        g, r = self.ground, self.radius
        phi = self.alpha - s * th
        dphi, ddphi = -s * om, -s * self.theta_ddot(t, th, om, s)
        x_dd = -s * r * (np.cos(phi) * ddphi - np.sin(phi) * dphi**2)
        y_dd = r * (-np.sin(phi) * ddphi - np.cos(phi) * dphi**2)
        return g.a_h(t) + x_dd, G + g.a_v(t) + y_dd

    def uplift(self, t0):
        """The first time >= t0 at which |u_h''| > (g + u_v'') tan alpha (inf if none)."""
        g = self.ground

        def excess(t):
            return np.abs(g.a_h(t)) - (G + g.a_v(t)) * math.tan(self.alpha)

        if excess(t0) > 0:
            return t0
        grid = np.union1d(np.arange(t0, g.duration, GRID), g.kinks[g.kinks > t0])
        above = np.flatnonzero(excess(grid) > 0)
        if above.size == 0:
            return np.inf
        i = above[0]
        return brentq(excess, grid[i - 1], grid[i], xtol=1e-15, rtol=1e-15)

    def run(self):
        g = self.ground
        t = self.uplift(0.0)
        assert np.isfinite(t), "the scene never lifts"
        s = -np.sign(g.a_h(t))
        y = np.array([0.0, 0.0])
        end = g.duration + FREE
        rest = REST_FRACTION * self.p * self.alpha
        while t < end:
            breaks = np.union1d(g.kinks[(g.kinks > t) & (g.kinks < end)], [end])
            t, y, event = self.piece(t, y, s, breaks)
            if event == "fall":
                self.overturned = True
                return self
            if event != "impact":
                return self
            self.impacts += 1
            y = np.array([0.0, self.eta * y[1]])
            if abs(y[1]) < rest:  # at rest until the ground lifts it again
                t = self.uplift(t)
                if not np.isfinite(t) or t >= g.duration:
                    return self
                s, y = -np.sign(g.a_h(t)), np.array([0.0, 0.0])
            else:
                s = -s
        return self

    def piece(self, t, y, s, breaks):
        """Rock on side s from (t, y) across the kinks ``breaks`` until an impact, the fall or
        the last break; returns (t, y, event)."""

        def rhs(t, y):
            return [y[1], self.theta_ddot(t, y[0], y[1], s)]

        def impact(t, y):
            return s * y[0]

        def fall(t, y):
            return s * y[0] - math.pi / 2

        impact.terminal, impact.direction = True, -1
        fall.terminal, fall.direction = True, 1
        for b in breaks:
            sol = solve_ivp(
                rhs,
                (t, b),
                y,
                "DOP853",
                rtol=1e-12,
                atol=1e-14,
                dense_output=True,
                events=[impact, fall],
            )
            if sol.t[-1] > t:
                self.pieces.append((t, sol.t[-1], sol.sol, s))
            t, y = sol.t[-1], sol.y[:, -1]
            if sol.status == 1:
                name = "fall" if sol.t_events[-1].size else "impact"
                if name == "impact":
                    y = np.array([0.0, y[1]])
                return t, y, name
        return t, y, "end"

    def cut(self):
        """The end of the response that counts: of an overturned block the last time
        |theta| = alpha; else inf."""
        if not self.overturned:
            return np.inf
        for t0, t1, sol, s in reversed(self.pieces):
            if s * sol(t0)[0] <= self.alpha < s * sol(t1)[0]:
                return brentq(
                    lambda t, sol=sol, s=s: s * sol(t)[0] - self.alpha, t0, t1, xtol=1e-15
                )
        raise AssertionError("no crossing of alpha")

    def demand(self):
        """(max |F_h / F_v|, min F_v / m) over the response (that counts), with the impacts."""
        t_cut = self.cut()
        best, min_fv = (0.0, None), np.inf
        for t0, t1, sol, s in self.pieces:
            t1 = min(t1, t_cut)
            if t1 <= t0:
                continue
            t = np.linspace(t0, t1, max(int((t1 - t0) / GRID), 8) + 1)
            f_h, f_v = self.forces(t, *sol(t), s)
            min_fv = min(min_fv, float(f_v.min()))
            ratio = np.abs(f_h) / f_v
            i = int(np.argmax(ratio))
            if ratio[i] > best[0]:
                best = (float(ratio[i]), (t[max(i - 1, 0)], t[min(i + 1, t.size - 1)], sol, s))
        lo, hi, sol, s = best[1]

        def minus(t):
            f_h, f_v = self.forces(t, *sol(t), s)
            return -abs(f_h) / f_v

        refined = -minimize_scalar(
            minus, bounds=(lo, hi), method="bounded", options={"xatol": 1e-13}
        ).fun
        demand = max(best[0], refined)
        if self.impacts:
            demand = max(demand, (1 - self.eta) / ((1 + self.eta) * math.tan(self.alpha)))
        return demand, min_fv


def kernel(p, alpha, eta, **motion):
    """(friction_demand, lift_off, overturned, model) of one batch row at rtol 1e-11."""
    out = rs.simulate_batch(
        frequency_parameter=p,
        slenderness=alpha,
        restitution=eta,
        friction=10.0,
        rtol=1e-11,
        method="nonlinear",
        outputs=["friction_demand", "lift_off", "overturned", "max_rotation"],
        **motion,
    )
    return out


PULSES = [  # (p, alpha, amplitude / (g tan alpha), period): rocking, rocking long, overturning
    (2.7, 0.2, 1.6, 0.6),
    (3.5, 0.15, 1.3, 0.8),
    (2.0, 0.25, 2.5, 0.4),
    (2.7, 0.2, 3.0, 0.5),
]


@pytest.mark.parametrize("scene", PULSES)
def test_demand_under_a_sine_pulse_is_the_oracles(scene):
    p, alpha, ratio, period = scene
    eta = 1 - 1.5 * math.sin(alpha) ** 2
    amplitude = ratio * G * math.tan(alpha)
    oracle = Oracle(p, alpha, eta, Ground.sine(amplitude, period)).run()
    expected, min_fv = oracle.demand()
    out = kernel(p, alpha, eta, amplitude=amplitude, period=period)
    assert bool(out["overturned"][0]) == oracle.overturned
    assert min_fv > 0 and out["lift_off"][0] == 0
    assert expected > math.tan(alpha)  # the rocking, not the uplift, sets it
    np.testing.assert_allclose(out["friction_demand"][0], expected, rtol=1e-7)


def test_the_scenes_cover_survival_and_overturning():
    """The pulses above hold blocks that stand and one that overturns (its demand up to the
    last time |theta| = alpha)."""
    over = [
        Oracle(p, a, 1 - 1.5 * math.sin(a) ** 2, Ground.sine(r * G * math.tan(a), T))
        .run()
        .overturned
        for p, a, r, T in PULSES
    ]
    assert any(over) and not all(over)


@pytest.mark.parametrize("vertical", [False, True])
def test_demand_under_a_generated_record_is_the_oracles(vertical):
    """A generated record, and the same with a generated vertical component (0.4 g peak)."""
    record = stochastic_record(4.0, duration=3.0, dt=0.01, seed=11)
    if vertical:
        v = stochastic_record(0.4 * G, duration=3.0, dt=0.01, seed=12).acceleration
        record = Record(record.acceleration, dt=0.01, vertical=v)
    p, alpha = 3.0, 0.2
    eta = 1 - 1.5 * math.sin(alpha) ** 2
    oracle = Oracle(p, alpha, eta, Ground.record(record)).run()
    expected, min_fv = oracle.demand()
    out = kernel(p, alpha, eta, record=record, scale=1.0)
    assert not oracle.overturned and not out["overturned"][0] and oracle.impacts > 0
    assert min_fv > 0 and out["lift_off"][0] == 0
    np.testing.assert_allclose(out["friction_demand"][0], expected, rtol=1e-7)


@pytest.mark.parametrize(("ratio", "lifts"), [(12.0, True), (6.0, False)])
def test_lift_off_under_a_strong_short_pulse_is_the_oracles(ratio, lifts):
    """A sine pulse of 12 (6) times the uplift acceleration over 0.1 s, alpha 0.4: its second
    half pushes the rocking block's base back while the block still rocks on the side the
    first half tipped it to, and F_v = m (g + y_G'') turns negative (stays positive): a
    lift-off and an infinite demand (the oracle's finite demand)."""
    p, alpha, period = 2.0, 0.4, 0.1
    eta = 1 - 1.5 * math.sin(alpha) ** 2
    amplitude = ratio * G * math.tan(alpha)
    expected, min_fv = Oracle(p, alpha, eta, Ground.sine(amplitude, period)).run().demand()
    assert (min_fv < -1.0) if lifts else (min_fv > 1.0)
    out = kernel(p, alpha, eta, amplitude=amplitude, period=period)
    assert bool(out["lift_off"][0]) == lifts
    if lifts:
        assert np.isinf(out["friction_demand"][0])
    else:
        np.testing.assert_allclose(out["friction_demand"][0], expected, rtol=1e-7)


def test_rows_below_the_uplift_need_their_peak_acceleration():
    """A block that never lifts needs max |u_h''| / g exactly: a sine pulse and a record,
    each below g tan alpha."""
    alpha = 0.2
    amplitude = np.array([0.3, 0.9]) * G * math.tan(alpha)
    out = kernel(2.5, alpha, 0.9, amplitude=amplitude, period=0.5)
    np.testing.assert_allclose(out["friction_demand"], amplitude / G, rtol=1e-15, atol=0)
    assert not out["lift_off"].any()
    record = stochastic_record(1.0, duration=2.0, seed=4)
    out = kernel(2.5, alpha, 0.9, record=record, scale=1.5)
    peak = 1.5 * np.max(np.abs(record.acceleration))
    assert peak < G * math.tan(alpha)
    np.testing.assert_allclose(out["friction_demand"], peak / G, rtol=1e-15)


def test_free_rocking_needs_less_than_tan_alpha():
    """Free rocking (no ground motion) below the overturning energy, by the rigid-body
    forces with theta_ddot = -p^2 sin(alpha s - theta) and theta_dot from the energy, on a
    dense grid of rotations and energies: F_v > 0 and |F_h / F_v| < tan alpha for every
    alpha up to FREE_ROCKING_SLENDERNESS, which is why the kernel leaves the mapped free
    rocking out of the demand."""
    p = 1.0
    radius = 0.75 * G / p**2
    for alpha in np.linspace(0.01, _demand.FREE_ROCKING_SLENDERNESS, 60):
        u = np.linspace(0.0, alpha, 400)[:, None]  # |theta| on side s = 1
        top = 2 * p**2 * (1 - math.cos(alpha))  # theta_dot^2 at theta = 0 that reaches alpha
        w0 = np.linspace(0.0, 0.999999, 300)[None, :] * top
        w2 = w0 - 2 * p**2 * (np.cos(alpha - u) - math.cos(alpha))  # theta_dot^2
        ok = w2 >= 0
        phi = alpha - u
        th_dd = -(p**2) * np.sin(phi)
        f_h = radius * (np.cos(phi) * th_dd + np.sin(phi) * w2)
        f_v = G + radius * (np.sin(phi) * th_dd - np.cos(phi) * w2)
        assert np.all(f_v[ok] > 0)
        assert np.max(np.abs(f_h[ok]) / f_v[ok]) < math.tan(alpha)


def test_the_check_runs_no_row_again_under_pulses_and_records(monkeypatch):
    """The friction check of Housner's block under pulses and records comes from the batch
    kernel: no row is run again through the single-scene path (its history check refused
    here), with method "nonlinear" and "auto", rows that rock, stand and overturn."""
    from rockstudy.dynamics import contact

    def refused(*args, **kwargs):
        raise AssertionError("a row was run again for its friction demand")

    monkeypatch.setattr(contact, "check_contact", refused)
    alpha = np.array([0.2, 0.2, 0.15])
    pulse = dict(amplitude=np.array([1.6, 3.0, 0.5]) * G * np.tan(alpha), period=0.5)
    record = dict(record=stochastic_record(4.0, duration=3.0, seed=11), scale=[1.0, 0.3, 2.0])
    for motion in (pulse, record):
        for method in ("nonlinear", "auto"):
            out = rs.simulate_batch(
                frequency_parameter=3.0, slenderness=alpha, friction=0.5, method=method, **motion
            )
            assert np.all(np.isfinite(out["friction_demand"])), (motion.keys(), method)


# ------------------------------------- a demand beyond mu between two samples of a record
# ``model="auto"`` sends a record scene to the contact model when its friction demand exceeds
# mu between two of the record's samples, where no sample of the record shows it.
#
# Oracle: Housner's block integrated by solve_ivp with the ground's forces maximised on a fine
# grid and refined (:class:`Oracle`); the same forces at the
# record's sample times give the largest ratio a check on the samples alone would see.

P, ALPHA, ETA = 3.0, 0.2, 0.95  # impulse ratio of the impacts 0.13 < tan alpha: rocking sets it
AMPLITUDE = 1.3  # / (g tan alpha)
#: mu this far (relative) on either side of the oracle's demand.
MARGIN = 1e-5


def sampled_demand(oracle, times):
    """The largest ``|F_h|`` / F_v of the oracle's response at the record's sample times."""
    best = 0.0
    for t0, t1, sol, s in oracle.pieces:
        t = times[(times >= t0) & (times <= t1)]
        if t.size:
            f_h, f_v = oracle.forces(t, *sol(t), s)
            best = max(best, float(np.max(np.abs(f_h) / f_v)))
    return best


def plateau_record():
    """0.25 s at +1.3 g tan alpha, 0.25 s at -1.3 g tan alpha, then 2.5 s at rest, sampled
    every 0.05 s: the ground is constant between the samples of each plateau, where the
    rocking alone sets the forces' ratio (its largest value falls between two samples)."""
    acc = np.zeros(60)
    acc[1:6], acc[6:11] = AMPLITUDE * G * math.tan(ALPHA), -AMPLITUDE * G * math.tan(ALPHA)
    return Record(acc, dt=0.05)


@pytest.fixture(scope="module")
def scene():
    record = plateau_record()
    oracle = Oracle(P, ALPHA, ETA, Ground.record(record)).run()
    demand, min_fv = oracle.demand()
    assert not oracle.overturned and min_fv > 0
    assert demand > math.tan(ALPHA) and demand > (1 - ETA) / ((1 + ETA) * math.tan(ALPHA))
    return record, demand, sampled_demand(oracle, record.time)


def auto_model(record, mu):
    """The ``model`` code ``"auto"`` gives the scene at friction mu."""
    out = rs.simulate_batch(
        frequency_parameter=P,
        slenderness=ALPHA,
        restitution=ETA,
        record=record,
        scale=1.0,
        friction=mu,
        model="auto",
        rtol=1e-9,
        outputs=["model", "friction_demand"],
    )
    return int(out["model"][0])


def test_the_demand_peaks_between_two_samples(scene):
    _, demand, sampled = scene
    assert sampled < demand * (1 - 10 * MARGIN)


def test_a_demand_just_above_mu_between_samples_runs_the_contact_model(scene):
    record, demand, _ = scene
    assert auto_model(record, demand * (1 - MARGIN)) == MODEL_CONTACT


def test_a_demand_just_below_mu_keeps_housners_model(scene):
    record, demand, _ = scene
    assert auto_model(record, demand * (1 + MARGIN)) != MODEL_CONTACT
