"""The single-ODE "complex" formulation of rocking (Prieto & Lourenco 2005, paper [001]).

The rotation is the real part of x = chi e^{i psi}; rocking becomes a central-force motion
with a small angular momentum l = chi^2 psi_dot, impacts are fast half-turns of psi near the
origin, and restitution mu is a Dirac-like damping force. In dimensionless time t = p tau,
eqs. (31)-(37) of [001] with the errata of DESIGN.md (l^2 / chi^3, l / chi^2, 2 ln(mu) chi_2 l
/ (pi chi_1^2)) read

    chi'' = l^2 / chi^3 - sin(alpha - alpha chi) / alpha + 2 ln(mu) chi' l / (pi chi^2)
            + F(t) cos(psi) cos(alpha - alpha chi),        psi' = l / chi^2,

with F = -u_g''(t / p) / (g alpha) for any ground motion (beta cos(omega t) in [001]). theta =
alpha chi cos(psi). It converges to Housner's model only as l -> 0 and needs steps below l
(here an adaptive Dormand-Prince 5(4) with h <= l / 10, as [001] recommends), so it is costly:
the work-precision chart of the project shows by how much. chi never goes below chi_c of eq.
(40), sin(alpha - alpha chi_c) chi_c^3 = alpha l^2 (about l^(2/3), eq. 41).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numba import njit
from scipy.integrate import RK45
from scipy.interpolate import CubicHermiteSpline
from scipy.optimize import brentq

from .._warnings import ComplexAccuracyWarning, ComplexFromRestWarning
from ..constants import FALL_ROTATION, G
from ..motions._kernels import KIND_RECORD, ground_acceleration, segment_index
from ._rocking import STEP_GROW_LIMIT, STEP_SAFETY, STEP_SHRINK_LIMIT

__all__ = [
    "BAD_STEP_SHRINK",
    "chi_c",
    "FROM_REST_WARNING",
    "LARGE_L",
    "LARGE_L_WARNING",
    "simulate_complex",
]

_A = tuple(tuple(float(x) for x in row) for row in RK45.A)
_B = tuple(float(x) for x in RK45.B)
_C = tuple(float(x) for x in RK45.C)
_E = tuple(float(x) for x in RK45.E)
#: A step with a NaN error estimate, or that takes the log-radius below 0, is retried this much
#: shorter (the controller's formula has nothing to say about it).
BAD_STEP_SHRINK = 0.25


#: Above this l the complex formulation's error exceeds about 1 % of alpha on [001]'s
#: free-rocking case (tests/test_complex.py measures 0.161, 0.037 and 0.0056 alpha at
#: l = 1e-2, 1e-3 and 1e-4).
LARGE_L = 1e-4
LARGE_L_WARNING = (
    "method='complex' with l = {l:g} > {large:g}: on [001]'s free-rocking case the history error "
    "against Housner's model is 0.16 alpha at l = 1e-2, 0.037 alpha at 1e-3 and 0.0056 alpha "
    "at 1e-4 (order 0.6-0.8 in l); decrease l (the cost grows as 1/l)."
)

FROM_REST_WARNING = (
    "method='complex' from rest: [001] validates the formulation from displaced states only. "
    "At rest it sits at chi_c spinning at psi' = l / chi_c^2 ~ l^(-1/3), so the direction and "
    "phase of the departure when the ground lifts the block are set by that spin, not by "
    "Housner's uplift, and do not improve as l -> 0 (measured on 20 random sine pulses: "
    "max-rotation errors up to 55-75 %, one overturning decision in 20 wrong). Use "
    "method='nonlinear' from rest, or give an initial rotation."
)


def chi_c(alpha: float, l: float) -> float:
    """The lower bound of chi, eq. (40) of [001]: sin(alpha - alpha chi) chi^3 = alpha l^2."""
    # the smallest root: sin(alpha - alpha chi) chi^3 rises from 0 to its maximum below 1/2
    return brentq(
        lambda c: math.sin(alpha - alpha * c) * c**3 - alpha * l * l,
        1e-300,
        0.5,
        xtol=1e-300,
        rtol=1e-15,
    )


@njit(cache=True)
def _rhs(t, y, out, p, alpha, lnmu, l, kind, mp, times, samples, seg):
    chi, v, psi = y[0], y[1], y[2]
    tau = t / p
    if kind == KIND_RECORD and tau <= mp[3]:
        seg[0] = segment_index(times, tau, seg[0])
    f = -ground_acceleration(kind, mp, times, samples, tau, seg[0]) / (G * alpha)
    c = math.cos(alpha - alpha * chi)
    out[0] = v
    out[1] = (
        l * l / chi**3
        - math.sin(alpha - alpha * chi) / alpha
        + 2.0 * lnmu * v * l / (math.pi * chi * chi)
        + f * math.cos(psi) * c
    )
    out[2] = l / (chi * chi)


@njit(cache=True)
def _integrate(
    p, alpha, lnmu, l, kind, mp, times, samples, y0, t_end, rtol, h_max, hist, max_steps
):
    """Dormand-Prince 5(4) on (chi, chi', psi) from y0 to t_end; every accepted step is logged
    in ``hist`` (t, chi, chi', psi) while there is room. Returns (rows, steps, status)."""
    y = y0.copy()
    k = np.zeros((7, 3))
    ytmp = np.empty(3)
    ynew = np.empty(3)
    seg = np.zeros(1, np.int64)
    t = 0.0
    h = h_max
    nh = 0
    steps = 0
    fall = FALL_ROTATION / alpha
    _rhs(t, y, k[0], p, alpha, lnmu, l, kind, mp, times, samples, seg)
    while t < t_end:
        steps += 1
        if steps > max_steps:
            return nh, steps, 1
        hs = min(h, t_end - t)
        for i in range(1, 6):  # six stages; the seventh is f at the new point (FSAL)
            for m in range(3):
                acc = 0.0
                for j in range(i):
                    acc += _A[i][j] * k[j, m]
                ytmp[m] = y[m] + hs * acc
            _rhs(t + _C[i] * hs, ytmp, k[i], p, alpha, lnmu, l, kind, mp, times, samples, seg)
        err = 0.0
        for m in range(3):
            acc = 0.0
            for j in range(6):
                acc += _B[j] * k[j, m]
            ynew[m] = y[m] + hs * acc
        _rhs(t + hs, ynew, k[6], p, alpha, lnmu, l, kind, mp, times, samples, seg)
        for m in range(3):
            e = 0.0
            for j in range(7):
                e += _E[j] * k[j, m]
            scale = rtol * (1e-3 + max(abs(y[m]), abs(ynew[m])))
            err = max(err, abs(hs * e) / scale)
        if not err <= 1.0 or ynew[0] <= 0.0:
            bad = not err == err or ynew[0] <= 0.0
            h = hs * (BAD_STEP_SHRINK if bad else max(STEP_SHRINK_LIMIT, STEP_SAFETY * err**-0.2))
            continue
        t += hs
        y[:] = ynew
        k[0, :] = k[6, :]
        grow = STEP_GROW_LIMIT if err == 0.0 else min(STEP_GROW_LIMIT, STEP_SAFETY * err**-0.2)
        h = min(h_max, hs * grow)
        if nh < hist.shape[0]:
            hist[nh, 0] = t
            hist[nh, 1] = y[0]
            hist[nh, 2] = y[1]
            hist[nh, 3] = y[2]
            nh += 1
        if y[0] >= fall:
            return nh, steps, 2
    return nh, steps, 0


def _start(p, alpha, l, motion, x0, chi_rest):
    """The start (chi, chi', psi) of the complex formulation from theta, theta_dot = x0 [rad,
    rad/s] at t = 0 (from rest: chi_c, leaning the way the ground first pushes), with the
    warnings of a start from rest and of a large l."""
    th0, om0 = x0
    chi0 = max(abs(th0) / alpha, chi_rest)
    psi0 = 0.0 if th0 >= 0 else math.pi
    a0 = motion.ground_acceleration(0.0)
    if th0 == 0.0 and om0 == 0.0 and a0 > 0:  # lean the way the first push of the ground goes
        psi0 = math.pi
    if th0 == 0.0 and om0 == 0.0 and motion.peak >= G * math.tan(alpha):
        warnings.warn(FROM_REST_WARNING, ComplexFromRestWarning, stacklevel=5)
    if l > LARGE_L:
        warnings.warn(
            LARGE_L_WARNING.format(l=l, large=LARGE_L), ComplexAccuracyWarning, stacklevel=5
        )
    v0 = om0 / (p * alpha) * (1.0 if th0 >= 0 else -1.0)
    return np.array([chi0, v0, psi0])


def _run(p, alpha, eta, l, spec, y0, t_phys, rtol, max_steps):
    """:func:`_integrate` from y0 to t_phys [s] into a history that grows until it holds the
    run, under the motion of ``spec`` (its ``kernel_spec()``). Returns (history, rows,
    steps, status)."""
    kind, mp, times, samples, _ = spec
    cap = 200_000
    while True:
        hist = np.empty((cap, 4))
        nh, steps, status = _integrate(
            p,
            alpha,
            math.log(eta),
            l,
            kind,
            mp,
            times,
            samples,
            y0,
            p * t_phys,
            rtol,
            l / 10.0,
            hist,
            max_steps,
        )
        if nh < cap or status != 0:
            break
        cap *= 4
    return hist, nh, steps, status


def _fields(hist, steps, over, p, alpha, l, y0, chi_rest, t_eval):
    """The RockingResult fields of a run's history rows (t p, chi, chi', psi): theta and
    theta_dot, the impacts (psi passing an odd multiple of pi/2), the peaks and the dense
    output on the cubic Hermite interpolant (see :func:`simulate_complex`)."""
    t = hist[:, 0] / p
    chi, dchi, psi = hist[:, 1], hist[:, 2], hist[:, 3]
    theta = alpha * chi * np.cos(psi)
    dpsi = l / chi**2
    theta_dot = p * alpha * (dchi * np.cos(psi) - chi * np.sin(psi) * dpsi)
    # impacts: psi passes an odd multiple of pi/2 (the real part changes sign)
    turns = np.floor((psi - math.pi / 2) / math.pi)
    jumps = np.flatnonzero(np.diff(turns) != 0)
    impacts = t[jumps]
    chi0, v0, psi0 = y0
    th_init = alpha * chi0 * math.cos(psi0)
    om_init = p * alpha * (v0 * math.cos(psi0) - chi0 * math.sin(psi0) * l / chi0**2)
    curve = CubicHermiteSpline(
        np.concatenate([[0.0], t]),
        np.concatenate([[th_init], theta]),
        np.concatenate([[om_init], theta_dot]),
    )
    turns = curve.derivative().roots(extrapolate=False)
    th_turn = curve(turns)
    peak = (th_turn * curve(turns, 2) < 0.0) & (np.abs(th_turn) > 2.0 * alpha * chi_rest)
    dense = {}
    if t_eval is not None:
        after = t_eval > (t[-1] if over else np.inf)
        dense = {
            "t_eval": t_eval,
            "theta_eval": np.where(after, np.nan, curve(t_eval)),
            "theta_dot_eval": np.where(after, np.nan, curve(t_eval, 1)),
        }
    return {
        "peak_times": turns[peak],
        "peak_rotations": th_turn[peak],
        **dense,
        "t": t,
        "theta": theta,
        "theta_dot": theta_dot,
        "max_rotation": FALL_ROTATION if over else float(np.max(np.abs(theta), initial=0)),
        "overturned": over,
        "impact_times": impacts,
        "overturn_time": float(t[-1]) if over else math.nan,
        "steps": int(steps),
    }


def simulate_complex(
    p,
    alpha,
    eta,
    motion,
    l=1e-4,
    rtol=1e-8,
    t_end=None,
    x0=(0.0, 0.0),
    max_steps=50_000_000,
    t_eval=None,
):
    """Integrate the complex formulation; returns a dict of the RockingResult fields.

    Parameters
    ----------
    p, alpha, eta : float
        Frequency parameter [rad/s], slenderness [rad], restitution (mu of [001]).
    l : float
        The dimensionless angular momentum; the model tends to Housner's as l -> 0.
    t_end : float, optional
        End of the history [s] (default: the motion plus 10 / p).
    x0 : (float, float)
        theta [rad] and theta_dot [rad/s] at t = 0; from rest the block starts at chi_c.
    t_eval : ndarray, optional
        Sorted times [s] in [0, t_end] at which to return the state (NaN after a fall), on
        the cubic Hermite interpolant of (theta, theta_dot) at the steps, which are below
        l / (10 p) long: its error, of order (step)^4, is far below the model's own.

    The peaks (maxima of |theta|) are the roots of theta_dot on the same interpolant, those
    with |theta| above 2 alpha chi_c: the model's rest is an orbit of radius chi_c about the
    pivot (eq. 40 of [001]), whose wobble is not rocking.
    """
    if not 0 < l < 0.1:
        raise ValueError(f"l must lie in (0, 0.1), got {l!r}")
    spec = motion.kernel_spec()
    if spec[4].size:
        raise ValueError(
            "motion: the complex formulation of [001] takes no vertical component (its "
            "gravity is constant); use the nonlinear kernel or the scipy reference"
        )
    chi_rest = chi_c(alpha, l)
    y0 = _start(p, alpha, l, motion, x0, chi_rest)
    t_phys = (motion.duration + 10.0 / p) if t_end is None else t_end
    if t_eval is not None and t_eval.size and t_eval[-1] > t_phys:
        raise ValueError(
            f"t_eval reaches {t_eval[-1]!r} s, beyond the simulated end {t_phys!r} s of "
            "method='complex' (the motion and 10 / p after it unless t_max is given)"
        )
    hist, nh, steps, status = _run(p, alpha, eta, l, spec, y0, t_phys, rtol, max_steps)
    if status == 1:
        raise RuntimeError(f"complex: more than max_steps={max_steps} steps")
    return _fields(hist[:nh], steps, status == 2, p, alpha, l, y0, chi_rest, t_eval)
