"""Event-driven rocking kernels (private): Housner's block, nonlinear or linearized.

State machine per scene: rest, rocking on side s = +1 or -1, overturned. The side is carried
explicitly (never sgn(theta)), so the right-hand side is smooth across theta = 0 and an impact
is a root of theta on the quintic Hermite interpolant of an accepted DOP853 step. After the
excitation ends nothing is integrated unless the block overturns: the free-rocking map
(energy conservation between impacts, eta per impact) gives the peaks and the decision.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..constants import FALL_ROTATION, G
from ..motions._kernels import (
    KIND_RECORD,
    KIND_RICKER,
    KIND_TRIG,
    ground_acceleration,
    segment_index,
)
from ._dop853 import dop853_error, hermite5, make_dop853_step

MODEL_NONLINEAR = 0
MODEL_LINEAR = 1

PH_END = 0
PH_REST = 1
PH_OVER = 2
PH_FAIL = 3

STATUS_OK = 0
STATUS_MAX_STEPS = 1
STATUS_HISTORY_FULL = 2

#: Post-impact speed below which the block is taken to be at rest, as a fraction of p*alpha.
REST_FRACTION = 1e-4
#: Local error target as a fraction of rtol, so that global errors (peaks, impact times over
#: tens of cycles) stay below rtol; calibrated against the scipy reference at rtol 1e-12.
TOL_SAFETY = 0.1
#: Absolute error scales of theta and theta_dot, as fractions of alpha and p*alpha.
ATOL_FRACTION = 1e-3
#: Impact count reported when eta = 1 (the block never comes to rest).
NEVER_AT_REST = 2**31 - 1


@njit(cache=True)
def _rhs(t, th, om, args):
    """theta_ddot on side s: eq. (2.2) of [000] (nonlinear) or eq. (3.1) (linearized)."""
    p, alpha, s, model, kind, mp, times, samples, k = args
    a = ground_acceleration(kind, mp, times, samples, t, k) / G
    if model == MODEL_LINEAR:
        return p * p * (th - alpha * s - a)
    x = alpha * s - th
    return -p * p * (math.sin(x) + a * math.cos(x))


_step = make_dop853_step(_rhs)


@njit(cache=True)
def uplift_threshold(alpha, model):
    """|u_g''| above which a block at rest starts rocking: g tan(alpha), or g alpha if linearized."""
    return G * alpha if model == MODEL_LINEAR else G * math.tan(alpha)


@njit(cache=True)
def _uplift_trig(mp, thr, t0):
    """First t >= t0 with |a sin(omega t + phase)| >= thr, or inf."""
    a, w, ph, dur = mp[0], mp[1], mp[2], mp[3]
    if abs(a) <= thr:
        return np.inf
    r = thr / abs(a)
    if r >= 1.0:
        return np.inf
    asr = math.asin(r)
    x0 = w * t0 + ph
    m = x0 % math.pi
    if asr < m < math.pi - asr:
        return t0
    x = x0 + (asr - m) if m <= asr else x0 + (math.pi - m) + asr
    t = (x - ph) / w
    return t if t <= dur else np.inf


@njit(cache=True)
def _uplift_ricker(kind, mp, times, samples, thr, t0):
    """First t >= t0 with |u_g''| >= thr, by a scan at T_p/256 and bisection to round-off."""
    dur = mp[3]
    dt = 1.0 / (256.0 * mp[1])
    lo = t0
    if abs(ground_acceleration(kind, mp, times, samples, lo, 0)) >= thr:
        return lo
    while lo < dur:
        hi = min(lo + dt, dur)
        if abs(ground_acceleration(kind, mp, times, samples, hi, 0)) >= thr:
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if abs(ground_acceleration(kind, mp, times, samples, mid, 0)) >= thr:
                    hi = mid
                else:
                    lo = mid
            return hi
        lo = hi
    return np.inf


@njit(cache=True)
def _uplift_record(mp, times, samples, thr, t0):
    """First t >= t0 with |u_g''| >= thr on the piecewise-linear record, or inf."""
    n = times.shape[0]
    if t0 > times[n - 1]:
        return np.inf
    k = segment_index(times, t0, 0)
    a0 = ground_acceleration(KIND_RECORD, mp, times, samples, t0, k)
    if abs(a0) >= thr:
        return t0
    ta = t0
    while k < n - 1:
        tb = times[k + 1]
        b = mp[0] * samples[k + 1]
        if abs(b) >= thr:
            target = thr if b > 0 else -thr
            return ta + (target - a0) / (b - a0) * (tb - ta)
        ta, a0 = tb, b
        k += 1
    return np.inf


@njit(cache=True)
def next_uplift(kind, mp, times, samples, thr, t0):
    """First time >= t0 at which the ground acceleration reaches the uplift threshold thr."""
    if t0 > mp[3]:
        return np.inf
    if kind == KIND_TRIG:
        return _uplift_trig(mp, thr, t0)
    if kind == KIND_RICKER:
        return _uplift_ricker(kind, mp, times, samples, thr, t0)
    return _uplift_record(mp, times, samples, thr, t0)


@njit(cache=True)
def _root_hermite(target, sgn, deriv, h, y0, d0, a0, y1, d1, a1, lo, hi):
    """Root in [lo, hi] (unit step time) of the Hermite value (deriv=False) or derivative.

    Finds where sgn * (q(s) - target) changes from >= 0 at lo to < 0 at hi, by safeguarded
    Newton steps on the bracket.
    """
    s = 0.5 * (lo + hi)
    for _ in range(60):
        v, dv = hermite5(s, h, y0, d0, a0, y1, d1, a1)
        if deriv:
            q = dv
            # derivative of dv in s, by a central difference of the exact quartic
            e = 1e-6
            dq = (hermite5(s + e, h, y0, d0, a0, y1, d1, a1)[1]
                  - hermite5(s - e, h, y0, d0, a0, y1, d1, a1)[1]) / (2 * e)
        else:
            q = v
            dq = dv * h
        f = sgn * (q - target)
        if f >= 0.0:
            lo = s
        else:
            hi = s
        sn = s - (q - target) / dq if dq != 0.0 else 0.5 * (lo + hi)
        if not lo < sn < hi:
            sn = 0.5 * (lo + hi)
        if abs(sn - s) < 1e-15:
            return sn
        s = sn
        if hi - lo < 1e-15:
            break
    return 0.5 * (lo + hi)


@njit(cache=True, inline="always")
def _push(hist, nh, t, th, om):
    """Append a history row if there is room; always count it, so overflow is detectable."""
    if nh < hist.shape[0]:
        hist[nh, 0] = t
        hist[nh, 1] = th
        hist[nh, 2] = om
    return nh + 1


@njit(cache=True)
def _record_step(hist, nh, t, h, th, om, f0, th1, om1, f1):
    """Append the Hermite interpolant at 1/4, 1/2, 3/4 of an accepted step and its end."""
    for j in range(1, 4):
        x, v = hermite5(0.25 * j, h, th, om, f0, th1, om1, f1)
        nh = _push(hist, nh, t + 0.25 * j * h, x, v)
    return _push(hist, nh, t + h, th1, om1)


@njit(cache=True)
def _peak(args, t, th, om, f0, dt, kx, kv):
    """s * theta at the peak near t + dt: a true DOP853 step there, then one Newton step on
    theta_dot = 0 (theta_peak = theta - theta_dot^2 / (2 theta_ddot))."""
    s = args[2]
    th_s, om_s = _step(args, t, th, om, f0, dt, kx, kv)
    f_s = _rhs(t + dt, th_s, om_s, args)
    if f_s == 0.0:
        return s * th_s
    return s * (th_s - 0.5 * om_s * om_s / f_s)


@njit(cache=True)
def _phase(p, alpha, eta, model, kind, mp, times, samples, thr, omega_rest, rtol, t, th, om, s,
           t_stop, h, max_u, n_imp, hist, nh, imps, ni, max_steps):
    """Integrate rocking from (t, th, om) on side s until rest, overturning or t_stop.

    Returns (code, t, th, om, s, h, max_u, n_imp, nh, ni).
    """
    rec = hist.shape[0] > 0
    dur = mp[3]
    tol = TOL_SAFETY * rtol
    kx = np.empty(13)
    kv = np.empty(13)
    k = segment_index(times, t, 0) if kind == KIND_RECORD else 0
    f0 = _rhs(t, th, om, (p, alpha, s, model, kind, mp, times, samples, k))
    steps = 0
    while t < t_stop:
        steps += 1
        if steps > max_steps:
            return PH_FAIL, t, th, om, s, h, max_u, n_imp, nh, ni
        t_next = t_stop
        if kind == KIND_RECORD and t < dur:
            k = segment_index(times, t, k)
            t_next = min(t_next, times[k + 1])
        last = h >= t_next - t
        hs = t_next - t if last else h
        args = (p, alpha, s, model, kind, mp, times, samples, k)
        th1, om1 = _step(args, t, th, om, f0, hs, kx, kv)
        t1 = t_next if last else t + hs
        f1 = _rhs(t1, th1, om1, args)
        kx[12] = om1
        kv[12] = f1
        sc_x = tol * (ATOL_FRACTION * alpha + max(abs(th), abs(th1)))
        sc_v = tol * (ATOL_FRACTION * p * alpha + max(abs(om), abs(om1)))
        err = dop853_error(kx, kv, hs, sc_x, sc_v)
        if not err <= 1.0:
            h = hs * max(0.2, 0.9 * err ** (-0.125)) if err == err else 0.2 * hs
            continue
        fac = 5.0 if err == 0.0 else min(5.0, 0.9 * err ** (-0.125))
        h = max(h, hs * fac) if last else hs * fac

        # ---- events on [t, t1], in the coordinates u = s*theta, v = s*theta_dot ----
        u1 = s * th1
        v0 = s * om
        v1 = s * om1
        s_imp = 2.0
        if u1 < 0.0:
            s_imp = _root_hermite(0.0, s, False, hs, th, om, f0, th1, om1, f1, 0.0, 1.0)
        elif v0 < 0.0 and v1 > 0.0:
            s_tr = _root_hermite(0.0, -s, True, hs, th, om, f0, th1, om1, f1, 0.0, 1.0)
            u_tr = s * hermite5(s_tr, hs, th, om, f0, th1, om1, f1)[0]
            if u_tr < 0.0:
                s_imp = _root_hermite(0.0, s, False, hs, th, om, f0, th1, om1, f1, 0.0, s_tr)
        else:
            # a short hop (up, down through zero, up again) can hide inside one long step
            for j in range(1, 4):
                if s * hermite5(0.25 * j, hs, th, om, f0, th1, om1, f1)[0] < 0.0:
                    s_imp = _root_hermite(0.0, s, False, hs, th, om, f0, th1, om1, f1,
                                          0.25 * (j - 1), 0.25 * j)
                    break
        s_end = min(s_imp, 1.0)
        if v0 >= 0.0 and s * hermite5(s_end, hs, th, om, f0, th1, om1, f1)[1] <= 0.0:
            s_pk = _root_hermite(0.0, s, True, hs, th, om, f0, th1, om1, f1, 0.0, s_end)
            max_u = max(max_u, _peak(args, t, th, om, f0, s_pk * hs, kx, kv))
        if s_imp > 1.0 and u1 >= FALL_ROTATION:
            s_ot = _root_hermite(FALL_ROTATION, -1.0, False, hs, s * th, v0, s * f0, u1, v1,
                                 s * f1, 0.0, 1.0)
            t_ot = t + s_ot * hs
            if rec:
                v_ot = s * hermite5(s_ot, hs, s * th, v0, s * f0, u1, v1, s * f1)[1]
                nh = _push(hist, nh, t_ot, s * FALL_ROTATION, v_ot)
            return PH_OVER, t_ot, s * FALL_ROTATION, om1, s, h, FALL_ROTATION, n_imp, nh, ni
        if s_imp > 1.0:
            max_u = max(max_u, u1)
            if rec:
                nh = _record_step(hist, nh, t, hs, th, om, f0, th1, om1, f1)
            t, th, om, f0 = t1, th1, om1, f1
            continue

        # ---- impact: locate on the interpolant, then one Newton step on a true RK step ----
        hi_ = s_imp * hs
        th_s, om_s = _step(args, t, th, om, f0, hi_, kx, kv)
        f_s = _rhs(t + hi_, th_s, om_s, args)
        dl = -th_s / om_s if om_s != 0.0 else 0.0
        t_imp = t + hi_ + dl
        om_imp = om_s + f_s * dl
        om_post = eta * om_imp
        n_imp += 1
        if rec:
            if ni < imps.shape[0]:
                imps[ni] = t_imp
            ni += 1
            nh = _push(hist, nh, t_imp, 0.0, om_imp)
            nh = _push(hist, nh, t_imp, 0.0, om_post)
        t = t_imp
        th = 0.0
        if abs(om_post) < omega_rest:
            if kind == KIND_RECORD:
                k = segment_index(times, min(t, dur), k)
            a = ground_acceleration(kind, mp, times, samples, t, k)
            if abs(a) < thr:
                return PH_REST, t, 0.0, 0.0, s, h, max_u, n_imp, nh, ni
            s = -1.0 if a > 0.0 else 1.0
            om = 0.0
        else:
            s = -s
            om = om_post
        if kind == KIND_RECORD:
            k = segment_index(times, t, k)
        f0 = _rhs(t, th, om, (p, alpha, s, model, kind, mp, times, samples, k))
    return PH_END, t, th, om, s, h, max_u, n_imp, nh, ni


@njit(cache=True, inline="always")
def _c(x, model):
    """Normalised potential shape: cos x (nonlinear) or its quadratic 1 - x^2/2 (linearized)."""
    return 1.0 - 0.5 * x * x if model == MODEL_LINEAR else math.cos(x)


@njit(cache=True, inline="always")
def _cinv(y, model):
    """Inverse of :func:`_c` on [0, pi]."""
    return math.sqrt(max(2.0 * (1.0 - y), 0.0)) if model == MODEL_LINEAR else math.acos(min(y, 1.0))


@njit(cache=True)
def free_rocking_map(u, v, p, alpha, eta, model, omega_rest):
    r"""Outcome of free rocking from rotation u = s theta and speed v = s theta_dot [rad, rad/s].

    Energy is conserved between impacts and each impact multiplies theta_dot by eta
    (eq. 2.3 of [000]); the peak after an impact follows from
    :math:`\cos(\alpha - \theta_{max}) = \cos\alpha + \dot\theta^2 / 2p^2` (eq. 4.12 of [000]
    for the linearized block). Returns (overturns, peak u, impacts until rest).
    """
    e = 0.5 * (v / p) ** 2 + _c(alpha - u, model)
    peak = u
    if e >= 1.0:
        if (u < alpha and v > 0.0) or (u >= alpha and v >= 0.0):
            return True, FALL_ROTATION, 0
    elif u > alpha:
        return True, FALL_ROTATION, 0
    elif v > 0.0:
        peak = alpha - _cinv(e, model)
    w = math.sqrt(max(2.0 * (e - _c(alpha, model)), 0.0))  # speed at the first impact, / p
    rest = omega_rest / p
    if w < rest:
        return False, peak, 0
    w1 = eta * w
    if _c(alpha, model) + 0.5 * w1 * w1 >= 1.0:
        return True, FALL_ROTATION, 1
    peak = max(peak, alpha - _cinv(_c(alpha, model) + 0.5 * w1 * w1, model))
    if w1 < rest:
        return False, peak, 1
    if eta >= 1.0:
        return False, peak, NEVER_AT_REST
    # impact k has post-impact speed w eta^k; the first one below rest ends the sequence
    return False, peak, 2 + int(math.floor(math.log(rest / w1) / math.log(eta)))


@njit(cache=True)
def scene(p, alpha, eta, model, kind, mp, times, samples, rtol, use_map, t_tail, hist, imps,
          max_steps, th_init=0.0, om_init=0.0):
    """Rock one block through one motion, from rest or from (th_init, om_init) at t = 0.

    Returns (status, max rotation, overturned, impacts, overturning time, history rows,
    impact times recorded).
    """
    thr = uplift_threshold(alpha, model)
    omega_rest = REST_FRACTION * p * alpha
    dur = mp[3]
    rec = hist.shape[0] > 0
    t = 0.0
    th = 0.0
    om = 0.0
    s = 1.0
    h = 0.01 / p
    max_u = 0.0
    n_imp = 0
    nh = 0
    ni = 0
    t_ot = np.nan
    at_rest = th_init == 0.0 and om_init == 0.0
    if not at_rest:
        th = th_init
        om = om_init
        max_u = abs(th_init)
        s = math.copysign(1.0, th_init if th_init != 0.0 else om_init)
    if rec:
        nh = _push(hist, nh, 0.0, th, om)
    while t < dur:
        if at_rest:
            t_up = next_uplift(kind, mp, times, samples, thr, t)
            if t_up >= dur:
                t = dur
                break
            k = segment_index(times, t_up, 0) if kind == KIND_RECORD else 0
            a = ground_acceleration(kind, mp, times, samples, t_up, k)
            s = -1.0 if a > 0.0 else 1.0
            t = t_up
            th = 0.0
            om = 0.0
            at_rest = False
            if rec:
                nh = _push(hist, nh, t, 0.0, 0.0)
        code, t, th, om, s, h, max_u, n_imp, nh, ni = _phase(
            p, alpha, eta, model, kind, mp, times, samples, thr, omega_rest, rtol, t, th, om, s,
            dur, h, max_u, n_imp, hist, nh, imps, ni, max_steps)
        if code == PH_REST:
            at_rest = True
        elif code == PH_OVER:
            return STATUS_OK, FALL_ROTATION, True, n_imp, t, nh, ni
        elif code == PH_FAIL:
            return STATUS_MAX_STEPS, max_u, False, n_imp, np.nan, nh, ni
    if at_rest:
        if rec:
            nh = _push(hist, nh, dur, 0.0, 0.0)
        return STATUS_OK, max_u, False, n_imp, t_ot, nh, ni
    if use_map:
        over, peak, n_post = free_rocking_map(s * th, s * om, p, alpha, eta, model, omega_rest)
        if not over:
            return STATUS_OK, max(max_u, peak), False, n_imp + n_post, t_ot, nh, ni
    code, t, th, om, s, h, max_u, n_imp, nh, ni = _phase(
        p, alpha, eta, model, kind, mp, times, samples, thr, omega_rest, rtol, t, th, om, s,
        t_tail, h, max_u, n_imp, hist, nh, imps, ni, max_steps)
    if code == PH_OVER:
        return STATUS_OK, FALL_ROTATION, True, n_imp, t, nh, ni
    if code == PH_FAIL:
        return STATUS_MAX_STEPS, max_u, False, n_imp, np.nan, nh, ni
    return STATUS_OK, max_u, False, n_imp, t_ot, nh, ni


@njit(cache=True, parallel=True)
def scene_batch(p, alpha, eta, model, kind, mp, times, samples, rtol, max_steps):
    """:func:`scene` over rows of (p, alpha, eta, mp[i]) with the free-rocking map, in parallel."""
    n = p.shape[0]
    status = np.empty(n, np.int8)
    max_rot = np.empty(n)
    over = np.empty(n, np.bool_)
    n_imp = np.empty(n, np.int64)
    t_ot = np.empty(n)
    no_hist = np.empty((0, 3))
    no_imps = np.empty(0)
    for i in prange(n):
        r = scene(p[i], alpha[i], eta[i], model, kind, mp[i], times, samples, rtol, True,
                  np.inf, no_hist, no_imps, max_steps)
        status[i] = r[0]
        max_rot[i] = r[1]
        over[i] = r[2]
        n_imp[i] = r[3]
        t_ot[i] = r[4]
    return status, max_rot, over, n_imp, t_ot
