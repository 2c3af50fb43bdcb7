"""Closed forms of the linearized block under a one-cycle sine pulse, section 3-4 of [000].

Notation of [000]: a = a_g / (g alpha) (> 1 for uplift), omega = omega_g / p, eta the
coefficient of restitution. Time tau = p t runs from the uplift, at the pulse phase
psi = arcsin(1/a) (eq. 3.3 with the erratum 1/a). The block first rocks on the side opposite to
the acceleration; rotations are in units of alpha and velocities in units of p alpha.

Every public function is a numpy ufunc (numba ``vectorize``; :func:`max_rotation` wraps one and
warns outside the region where it is exact), built on its first use so that importing the module
compiles nothing (:class:`_LazyUfunc`): it broadcasts over arrays and
returns NaN where a <= 1 (no uplift), where a quantity does not exist (e.g. no impact), or where
exp(p T_ex) overflows (omega below about 0.009).
"""

from __future__ import annotations

import functools
import math
import threading
import warnings

import numpy as np
from numba import float64, int8, njit, vectorize

from .. import _validate
from .._roots import newton_bisect
from .._warnings import ClosedFormValidityWarning

__all__ = [
    "build_all",
    "case11_residual",
    "case11_residual_approx",
    "case12_residual",
    "case2_residual",
    "d0_star",
    "FIRST_IMPACT_MAX_ITER",
    "first_impact_time_after_pulse",
    "first_impact_time_during_pulse",
    "first_impact_time_during_pulse_approx",
    "FIRST_IMPACT_TOL",
    "impact_velocity_after_pulse",
    "impact_velocity_during_pulse",
    "kappa",
    "lambda_",
    "limit_residual",
    "max_rotation",
    "max_rotation_small",
    "MODES",
    "NO_UPLIFT",
    "OVER_IMPACT",
    "OVER_NO_IMPACT",
    "overturning_mode",
    "overturning_mode_code",
    "pulse_end_time",
    "restitution_scaling_function",
    "SAFE_AFTER",
    "SAFE_DURING",
]

_F2 = [float64(float64, float64)]
_F3 = [float64(float64, float64, float64)]


class _LazyUfunc:
    """A numba ``vectorize`` ufunc built (compiled, or loaded from numba's cache) on first use.

    Building all the ufuncs of this module eagerly cost about 1 s on every ``import rockstudy``
    even with a warm cache. The wrapper calls and forwards attributes (``outer``, ``reduce``,
    ``types``, ...) to the built ufunc, and pickles by name.
    """

    _lock = threading.RLock()

    def __init__(self, func, signatures, options):
        functools.update_wrapper(self, func)
        self._func, self._signatures, self._options, self._ufunc = func, signatures, options, None

    def build(self):
        """The numpy ufunc itself (built once)."""
        if self._ufunc is None:
            with self._lock:
                if self._ufunc is None:
                    self._ufunc = vectorize(self._signatures, cache=True, **self._options)(
                        self._func
                    )
        return self._ufunc

    def __call__(self, *args, **kwargs):
        return self.build()(*args, **kwargs)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return getattr(self.build(), name)

    def __reduce__(self):
        return _by_name, (self.__name__,)

    def __repr__(self):
        return f"<lazy numba ufunc {self.__module__}.{self.__name__}>"


def _by_name(name):
    return globals()[name]


def _lazy_vectorize(signatures, **options):
    """``numba.vectorize(signatures, cache=True, **options)``, compiled on first use."""
    return lambda func: _LazyUfunc(func, signatures, options)


def build_all():
    """Build every ufunc of the module now (compile, or load from numba's cache); returns
    their names. The warm-up step (``rockstudy compile``) calls this once per install."""
    lazy = {k: v for k, v in globals().items() if isinstance(v, _LazyUfunc)}
    for ufunc in lazy.values():
        ufunc.build()
    return sorted(lazy)


MODES = (
    "no_uplift",
    "safe_impact_during_pulse",
    "safe_impact_after_pulse",
    "overturn_after_impact",
    "overturn_without_impact",
)
NO_UPLIFT, SAFE_DURING, SAFE_AFTER, OVER_IMPACT, OVER_NO_IMPACT = range(5)


@njit(cache=True)
def _psi(a):
    """Uplift phase psi = arcsin(1/a), eq. (3.3) of [000]."""
    return math.asin(1.0 / a)


@njit(cache=True)
def _tau_ex(a, w):
    """p T_ex = (2 pi - psi) / omega: end of the pulse from the uplift, eq. (3.2) of [000]."""
    return (2.0 * math.pi - _psi(a)) / w


@njit(cache=True)
def _abc(a, w):
    """A0*, B0*, C0* of eq. (3.9) of [000] (2 A0 / alpha, 2 B0 / alpha from eq. 3.7)."""
    root = math.sqrt(a * a - 1.0)
    den = w * w + 1.0
    return (w * w + w * root) / den, (w * w - w * root) / den, 2.0 * a / den


@njit(cache=True)
def _d0(a, w):
    """D0* in the product form of eq. (3.9) of [000]."""
    A, B, C = _abc(a, w)
    e = math.exp(_tau_ex(a, w))
    return (A - 0.5 * w * C * e) * (B + 0.5 * w * C / e)


@njit(cache=True)
def _f21(A, B, C, psi, w, tau):
    """2 theta / alpha and 2 theta_dot / (p alpha) before the first impact, eqs. (3.21)-(3.22)
    of [000] (side and the constant term dropped: A0* e^-tau + B0* e^tau + C0* sin - 2)."""
    em, ep = math.exp(-tau), math.exp(tau)
    x = w * tau + psi
    return A * em + B * ep + C * math.sin(x) - 2.0, B * ep - A * em + C * w * math.cos(x)


@njit(cache=True)
def _theta2(a, w, tau):
    """2 theta / alpha of eq. (3.21) of [000], see :func:`_f21`."""
    A, B, C = _abc(a, w)
    return _f21(A, B, C, _psi(a), w, tau)[0]


@njit(cache=True)
def _velocity2(a, w, tau):
    """2 theta_dot / (p alpha) before the first impact, eq. (3.22) of [000]."""
    A, B, C = _abc(a, w)
    return _f21(A, B, C, _psi(a), w, tau)[1]


@njit(cache=True, inline="always")
def _f21_fdf(x, args):
    """2 theta / alpha - 2 of eq. (3.21) of [000] at tau = x and its tau-derivative."""
    A, B, C, psi, w = args
    ep = math.exp(x)
    sn, cs = math.sin(w * x + psi), math.cos(w * x + psi)
    return A / ep + B * ep + C * sn - 2.0, B * ep - A / ep + C * w * cs


# tau_i1 to 1e-13 (relative above 1): the closed forms are compared with the exact solver at
# 1e-10, and the second impact starts from this one.
FIRST_IMPACT_TOL = 1e-13
# Newton from the secant converges in 3-6 steps; bisection alone of a grid cell of at most 0.25
# would need about 42.
FIRST_IMPACT_MAX_ITER = 100


@njit(cache=True)
def _first_impact(A, B, C, psi, w, te):
    """First root of eq. (3.21) of [000] in (0, p T_ex]: (tau_i1, 2 theta_dot / (p alpha),
    sin and cos of omega tau + psi, e^tau) there, or tau = NaN if the pulse ends first.

    The root is bracketed on a grid of a sixteenth of a forcing period (and at most 0.25 in
    tau), walked with recurrences for e^+-tau and the rotating sine, then polished by Newton
    steps (from the secant) safeguarded by bisection.
    """
    d = min(0.25, 0.125 * math.pi / w)
    ed, cd, sd = math.exp(d), math.cos(w * d), math.sin(w * d)
    em, ep, sn, cs = 1.0, 1.0, math.sin(psi), math.cos(psi)  # e^-tau, e^tau, sin, cos at tau
    lo = 0.0
    f_lo = 0.0
    while lo < te:
        hi = lo + d
        em, ep = em / ed, ep * ed
        sn, cs = sn * cd + cs * sd, cs * cd - sn * sd
        if hi >= te:
            hi = te
            f_hi = _f21(A, B, C, psi, w, te)[0]
        else:
            f_hi = A * em + B * ep + C * sn - 2.0
        if f_hi >= 0.0:  # Newton from the secant (from hi while theta = 0 at lo, at uplift)
            x0 = lo + (hi - lo) * f_lo / (f_lo - f_hi) if f_lo < 0.0 else hi
            args = (A, B, C, psi, w)
            x = newton_bisect(
                _f21_fdf, args, lo, hi, x0, -1.0, FIRST_IMPACT_TOL, FIRST_IMPACT_MAX_ITER
            )
            ep = math.exp(x)
            sn, cs = math.sin(w * x + psi), math.cos(w * x + psi)
            return x, B * ep - A / ep + C * w * cs, sn, cs, ep
        lo, f_lo = hi, f_hi
    return np.nan, np.nan, np.nan, np.nan, np.nan


@njit(cache=True)
def _tau_i1(a, w):
    """tau_i1, the first impact during the pulse (eq. 3.21 of [000]), or NaN."""
    A, B, C = _abc(a, w)
    return _first_impact(A, B, C, _psi(a), w, _tau_ex(a, w))[0]


@njit(cache=True)
def _kappa_lambda(a, w):
    """kappa and lambda of eq. (3.26) of [000]: the local fit of sin(omega tau + psi)."""
    x = w + _psi(a)
    c, s = math.cos(x), math.sin(x)
    return -0.5 * math.e * w * (c + w * s), 0.5 * w / math.e * (c - w * s)


@njit(cache=True)
def _tau_i1_hat(a, w):
    """Semi-analytical first impact time, eq. (3.29) of [000]."""
    A, B, C = _abc(a, w)
    k, lam = _kappa_lambda(a, w)
    s = a * math.sin(w + _psi(a))
    disc = (s - 1.0) ** 2 - (A + C * k) * (B + C * lam)
    if disc < 0.0:
        return np.nan
    x = (1.0 - s + math.sqrt(disc)) / (B + C * lam)
    return math.log(x) if x > 0.0 else np.nan


@njit(cache=True)
def _case11_lhs(a, w, eta, tau):
    """Left side of eq. (3.20)/(3.30) of [000] minus 2: >= 0 overturns after the impact at tau."""
    A, B, C = _abc(a, w)
    psi = _psi(a)
    v2 = _f21(A, B, C, psi, w, tau)[1]
    x = w * tau + psi
    return eta * v2 + C * (w * math.exp(tau - _tau_ex(a, w)) - w * math.cos(x) - math.sin(x)) - 2.0


@njit(cache=True)
def _mode(a, w, eta):
    """Overturning mode of Figs. 2 and 4 of [000] (an index into MODES)."""
    if not a > 1.0:
        return NO_UPLIFT
    A, B, C = _abc(a, w)
    psi = _psi(a)
    te = (2.0 * math.pi - psi) / w
    e = math.exp(te)
    if A / e + B * e - 2.0 < 0.0:  # still on the first pivot at the end of the pulse (3.31)
        if B * e + 0.5 * w * C <= 0.0:  # on or beyond the unstable manifold, eq. (3.10)
            return OVER_NO_IMPACT
        d0 = (A - 0.5 * w * C * e) * (B + 0.5 * w * C / e)
        if eta * eta * (1.0 - d0) >= 1.0:  # eq. (3.18)
            return OVER_IMPACT
        return SAFE_AFTER
    tau, v2, sn, cs, ep = _first_impact(A, B, C, psi, w, te)
    if eta * v2 + C * (w * ep / e - w * cs - sn) - 2.0 >= 0.0:  # eqs. (3.20)-(3.21)
        return OVER_IMPACT
    return SAFE_DURING


# ---------------------------------------------------------------------------- public ufuncs


@_lazy_vectorize(_F2)
def pulse_end_time(a, omega):
    r"""Time from uplift to the end of the pulse, p T_ex [-], eq. (3.2)-(3.3) of [000].

    .. math:: p T_{ex} = (2\pi - \psi) / \omega, \qquad \psi = \arcsin(1/a)
    """
    return _tau_ex(a, omega) if a > 1.0 else np.nan


@_lazy_vectorize(_F2)
def d0_star(a, omega):
    r"""D0* of eq. (3.9) of [000], product form (the expanded form there has lost a square).

    .. math::
        D_0^* = \left(A_0^* - \tfrac{\omega}{2} C_0^* e^{pT_{ex}}\right)
                \left(B_0^* + \tfrac{\omega}{2} C_0^* e^{-pT_{ex}}\right)
    """
    return _d0(a, omega) if a > 1.0 else np.nan


@_lazy_vectorize(_F2)
def first_impact_time_after_pulse(a, omega):
    r"""tau_i2: the first impact from uplift when it follows the pulse, eq. (3.13) of [000].

    .. math::
        \tau_{i2} = \ln\frac{1 + \sqrt{1 - D_0^*}}{B_0^* + \frac{\omega}{2} C_0^* e^{-pT_{ex}}}
    """
    if not a > 1.0:
        return np.nan
    A, B, C = _abc(a, omega)
    d = _d0(a, omega)
    den = B + 0.5 * omega * C * math.exp(-_tau_ex(a, omega))
    if d > 1.0 or den <= 0.0:
        return np.nan
    return math.log((1.0 + math.sqrt(1.0 - d)) / den)


@_lazy_vectorize(_F2)
def impact_velocity_after_pulse(a, omega):
    r"""theta_dot / (p alpha) just before that impact, eqs. (3.14)-(3.15) of [000].

    .. math:: \dot\theta_{i2} / (p\alpha) = \sqrt{1 - D_0^*}
    """
    if not a > 1.0:
        return np.nan
    d = _d0(a, omega)
    return math.sqrt(1.0 - d) if d <= 1.0 else np.nan


@_lazy_vectorize(_F3)
def impact_velocity_during_pulse(a, omega, tau):
    r"""theta_dot / (p alpha) at time tau before the first impact, eq. (3.22) of [000].

    .. math::
        2 \dot\theta / (p\alpha) = B_0^* e^{\tau} - A_0^* e^{-\tau}
            + C_0^* \omega \cos(\omega\tau + \psi)
    """
    return 0.5 * _velocity2(a, omega, tau) if a > 1.0 else np.nan


@_lazy_vectorize(_F2)
def kappa(a, omega):
    r"""kappa of eq. (3.26) of [000].

    .. math:: \kappa = -\frac{e\omega}{2}\left[\cos(\omega+\psi) + \omega\sin(\omega+\psi)\right]
    """
    return _kappa_lambda(a, omega)[0] if a > 1.0 else np.nan


@_lazy_vectorize(_F2)
def lambda_(a, omega):
    r"""lambda of eq. (3.26) of [000] (trailing underscore: ``lambda`` is a keyword).

    .. math:: \lambda = \frac{\omega}{2e}\left[\cos(\omega+\psi) - \omega\sin(\omega+\psi)\right]
    """
    return _kappa_lambda(a, omega)[1] if a > 1.0 else np.nan


@_lazy_vectorize(_F2)
def first_impact_time_during_pulse(a, omega):
    """tau_i1: first root of eq. (3.21) of [000] in (0, p T_ex]; NaN if none (numerical form)."""
    return _tau_i1(a, omega) if a > 1.0 else np.nan


def first_impact_time_during_pulse_approx(a, omega, *, check=True):
    r"""Semi-analytical tau_i1 of eq. (3.29) of [000].

    .. math::
        \hat\tau_{i1} = \ln\frac{1 - a\sin(\omega+\psi)
            + \sqrt{[a\sin(\omega+\psi) - 1]^2 - (A_0^* + C_0^*\kappa)(B_0^* + C_0^*\lambda)}}
            {B_0^* + C_0^*\lambda}

    It fits sin(omega tau + psi) around tau = 1 and is within 7 % of (3.21) only for
    0.8 < tau < 1.2 (errors of order one elsewhere); ``check`` warns
    (:class:`rockstudy.ClosedFormValidityWarning`) for results outside that range.
    """
    out = _tau_i1_hat_ufunc(a, omega)
    if check:
        _warn_outside(
            np.isfinite(out) & ((out <= 0.8) | (out >= 1.2)),
            out,
            "eq. (3.29) outside 0.8 < tau < 1.2, where it is within 7 % of (3.21); errors of "
            "order one there",
        )
    return out


@_lazy_vectorize(_F2)
def _tau_i1_hat_ufunc(a, omega):
    """eq. (3.29) of [000]; see :func:`first_impact_time_during_pulse_approx`."""
    return _tau_i1_hat(a, omega) if a > 1.0 else np.nan


def _warn_outside(mask, out, what):
    """Warn once for the points of ``out`` flagged by ``mask``."""
    n = int(np.count_nonzero(mask))
    if n:
        warnings.warn(
            f"{what}: {n} of {np.size(out)} points",
            ClosedFormValidityWarning,
            stacklevel=3,
        )


@_lazy_vectorize(_F2)
def case2_residual(a, omega):
    r"""Overturning without impact, eq. (3.10) of [000]: zero on the boundary, < 0 overturns.

    .. math:: \omega - \sqrt{a^2 - 1} + a e^{-pT_{ex}}
    """
    if not a > 1.0:
        return np.nan
    return omega - math.sqrt(a * a - 1.0) + a * math.exp(-_tau_ex(a, omega))


@_lazy_vectorize(_F3)
def case12_residual(a, omega, eta):
    r"""Overturning after one impact that follows the pulse, eq. (3.18) of [000]: zero on the
    boundary, >= 0 overturns.

    .. math:: \eta^2 (1 - D_0^*) - 1
    """
    return eta * eta * (1.0 - _d0(a, omega)) - 1.0 if a > 1.0 else np.nan


@_lazy_vectorize(_F3)
def case11_residual(a, omega, eta):
    """Overturning after one impact during the pulse, eqs. (3.20)-(3.21) of [000] (numerical
    form): zero on the boundary, >= 0 overturns; NaN if there is no impact during the pulse."""
    if not a > 1.0:
        return np.nan
    return _case11_lhs(a, omega, eta, _tau_i1(a, omega))


def case11_residual_approx(a, omega, eta, *, check=True):
    """The same with the semi-analytical impact time (3.29), i.e. eq. (3.30) of [000].

    Within 6.4 % of (3.20)-(3.21) for 0.4 < omega < 4.2; ``check`` warns
    (:class:`rockstudy.ClosedFormValidityWarning`) for results outside that range.
    """
    out = _case11_approx_ufunc(a, omega, eta)
    if check:
        w = np.broadcast_to(omega, np.shape(out))
        _warn_outside(
            np.isfinite(out) & ((w <= 0.4) | (w >= 4.2)),
            out,
            "eq. (3.30) outside 0.4 < omega < 4.2, where it is within 6.4 % of (3.20)-(3.21)",
        )
    return out


@_lazy_vectorize(_F3)
def _case11_approx_ufunc(a, omega, eta):
    """eq. (3.30) of [000]; see :func:`case11_residual_approx`."""
    if not a > 1.0:
        return np.nan
    return _case11_lhs(a, omega, eta, _tau_i1_hat(a, omega))


@_lazy_vectorize(_F2)
def limit_residual(a, omega):
    r"""The limit tau_i = p T_ex between cases 1.1 and 1.2, eq. (3.31) of [000]: zero on the
    curve, > 0 where the first impact comes before the end of the pulse.

    .. math:: A_0^* e^{-pT_{ex}} + B_0^* e^{pT_{ex}} - 2
    """
    if not a > 1.0:
        return np.nan
    A, B, C = _abc(a, omega)
    e = math.exp(_tau_ex(a, omega))
    return A / e + B * e - 2.0


@_lazy_vectorize([int8(float64, float64, float64)], target="parallel")
def overturning_mode_code(a, omega, eta):
    """Index into :data:`MODES` of the overturning mode (see :func:`overturning_mode`)."""
    return _mode(a, omega, eta)


def overturning_mode(a, omega, eta):
    """Label every (a, omega, eta) by its mode in Figs. 2 and 4 of [000].

    ``no_uplift`` (a <= 1); ``safe_impact_during_pulse``; ``safe_impact_after_pulse``;
    ``overturn_after_impact`` (case 1.1 by eqs. 3.20-3.21 where the first impact comes during
    the pulse, case 1.2 by eq. 3.18 after it); ``overturn_without_impact`` (case 2, eq. 3.10).
    The limit curve (3.31) separates impacts during and after the pulse. Overturning after two or
    more impacts is not covered by the closed forms (it is labelled safe).

    Returns
    -------
    ndarray of str
    """
    return np.asarray(MODES)[overturning_mode_code(a, omega, eta)]


def _control_point(a, omega, eta):
    """(a, omega, eta) as float arrays, or a ValueError naming the one that is not a finite
    number in its range: a real, omega > 0, eta in [0, 1]."""
    return (
        _validate.real_array("a", a),
        _validate.real_array("omega", omega, 1e-300, label="finite and > 0"),
        _validate.real_array("eta", eta, 0.0, 1.0, label="in [0, 1]"),
    )


def max_rotation(a, omega, eta, *, check=True):
    r"""Peak rotation after the first impact, theta_max / alpha, eq. (4.13) of [000].

    Exact when the first impact follows the pulse (above the curve 3.31); NaN where the block
    overturns after that impact, or where D0* > 1 (it does not come back to an impact).

    .. math:: \theta_m / \alpha = 1 - \sqrt{1 - \eta^2 (1 - D_0^*)}

    Parameters
    ----------
    a, omega, eta : array_like
        a_g / (g alpha) (finite; NaN results where a <= 1: no uplift), omega_g / p (> 0) and
        the restitution (in [0, 1]), broadcast together.
    check : bool
        Warn (:class:`rockstudy.ClosedFormValidityWarning`) when points lie below the (3.31)
        curve, where the first impact comes during the pulse and (4.13) is an approximation
        (median error 16 %, unbounded near the overturning boundaries; see
        :mod:`rockstudy.verification.validity`).

    Raises
    ------
    ValueError
        Naming the argument that is not a finite number in its range.
    """
    a, omega, eta = _control_point(a, omega, eta)
    out = _max_rotation(a, omega, eta)
    if check:
        during = np.broadcast_to(limit_residual(a, omega) > 0.0, np.shape(out))
        _warn_outside(
            during & np.isfinite(out),
            out,
            "eq. (4.13) below the (3.31) curve: the first impact comes during the pulse, and "
            "(4.13) only approximates the max rotation there (median error 16 %, unbounded "
            "near the overturning boundaries)",
        )
    return out


@_lazy_vectorize(_F3, target="parallel")
def _max_rotation(a, omega, eta):
    """eq. (4.13) of [000]; see :func:`max_rotation`."""
    if not a > 1.0:
        return np.nan
    d0 = _d0(a, omega)
    x = 1.0 - eta * eta * (1.0 - d0)
    return 1.0 - math.sqrt(x) if x > 0.0 and d0 <= 1.0 else np.nan


@_lazy_vectorize(_F3)
def max_rotation_small(a, omega, eta):
    r"""Small-velocity form of (4.13): theta_max / alpha, eq. (4.14) of [000].

    .. math:: \theta_m / \alpha \simeq \tfrac{1}{2} \eta^2 (1 - D_0^*)

    (The transcription prints sqrt(1 - D0*); expanding (4.13) for small
    eta^2 (1 - D0*) gives the square, as used here.)
    """
    return 0.5 * eta * eta * (1.0 - _d0(a, omega)) if a > 1.0 else np.nan


@_lazy_vectorize(_F2)
def restitution_scaling_function(a, omega):
    r"""f(a, omega) of the restitution law theta_m / alpha ~ f eta^2 / 2, eq. (4.16) of [000].

    .. math:: f(a, \omega) = 1 - D_0^*
    """
    return 1.0 - _d0(a, omega) if a > 1.0 else np.nan
