"""Failure maps: where each method loses accuracy, over (psi, omega) and alpha.

Every map is an ``xarray.Dataset`` over ``psi = |a_g| / (g tan alpha)`` (the pulse peak over
the uplift level of Housner's block) and ``omega = omega_g / p``, against the nonlinear kernel
at rtol 1e-11 as the reference.

- :func:`linearization_error_map`: the linearized model (3.1) of [000] against Housner's
  (2.2). The relative max-rotation error divided by alpha^2 collapses over alpha (it is set by
  sin x - x, cos x - 1 and tan alpha - alpha); it is large where the nonlinear block barely
  lifts (psi -> 1) and near the overturning boundaries, where the models also disagree on
  overturning. The cell maxima of this map are the bound ``method="auto"`` uses.
- :func:`tolerance_error_map`: the kernel at loose tolerances (impacts gained or lost, max
  rotation, overturning).

``python -m rockstudy.verification.accuracy`` regenerates
``rockstudy/data/linearization_bound.npz``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..constants import G
from ..dynamics import _auto
from ..dynamics.batch import simulate_batch

__all__ = [
    "bound_table",
    "cell_maximum",
    "GRID_FREQUENCY",
    "linearization_error_map",
    "main",
    "neighbourhood_maximum",
    "overturning_nearby",
    "pulse_grid_batch",
    "REFERENCE_RTOL",
    "relative_max_rotation_error",
    "robust_decision",
    "tolerance_error_map",
]

GRID_FREQUENCY = 2.0  # p [rad/s] of the maps: they are in (psi, omega), any p will do
REFERENCE_RTOL = 1e-11


def pulse_grid_batch(shape, psi, omega, alpha, eta, method="nonlinear", rtol=REFERENCE_RTOL):
    """:func:`simulate_batch` on a (psi, omega) grid of one-cycle pulses, for one alpha and
    eta (p = 2 rad/s: the maps depend on p only through omega); outputs shaped (psi, omega)."""
    P, W = np.meshgrid(psi, omega, indexing="ij")
    out = simulate_batch(
        frequency_parameter=GRID_FREQUENCY,
        slenderness=alpha,
        restitution=eta,
        pulse=shape,
        amplitude=(P * G * np.tan(alpha)).ravel(),
        period=(2.0 * np.pi / (W * GRID_FREQUENCY)).ravel(),
        method=method,
        rtol=rtol,
    )
    return {k: v.reshape(P.shape) for k, v in out.items()}


def relative_max_rotation_error(test, reference):
    """|theta_test / theta_ref - 1| where neither overturns, 0 where both do, inf where they
    disagree on overturning (or the reference stays at rest and the test does not)."""
    ov_t, ov_r = test["overturned"], reference["overturned"]
    th_t, th_r = test["max_rotation"], reference["max_rotation"]
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(th_t - th_r) / th_r
    rel = np.where((th_r == 0) & (th_t == 0), 0.0, rel)
    rel = np.where(ov_t & ov_r, 0.0, rel)
    return np.where(ov_t != ov_r, np.inf, np.nan_to_num(rel, nan=np.inf))


def robust_decision(batch_kwargs, rows, reference_overturned, rel=1e-4, rtol=1e-10):
    """Whether the nonlinear kernel's overturning decision on ``rows`` of a
    :func:`simulate_batch` call stays ``reference_overturned`` when a_g moves by +-``rel``
    (relative): a robust scene, whose decision a method must get right.

    Parameters
    ----------
    batch_kwargs : dict
        Keyword arguments of :func:`simulate_batch` for a pulse batch; arrays are row-wise.
    rows : array of int
        The rows to check.
    reference_overturned : array of bool
        The reference decision of those rows.
    """
    rows = np.asarray(rows, dtype=int)
    n = np.size(batch_kwargs["amplitude"])
    pick = {
        k: (np.broadcast_to(v, (n,))[rows] if np.ndim(v) and np.size(v) == n else v)
        for k, v in batch_kwargs.items()
        if k not in ("method", "rtol", "outputs")
    }
    robust = np.ones(rows.size, bool)
    if rows.size:
        for factor in (1.0 - rel, 1.0 + rel):
            moved = dict(pick, amplitude=factor * np.asarray(pick["amplitude"]))
            out = simulate_batch(**moved, rtol=rtol, outputs=("overturned",))
            robust &= out["overturned"] == np.asarray(reference_overturned, bool)
    return robust


def linearization_error_map(
    shape="sine",
    psi=None,
    omega=None,
    alpha=(0.01, 0.05, 0.1, 0.2, 0.3),
    eta=(0.7, 0.9),
    rtol=REFERENCE_RTOL,
) -> xr.Dataset:
    """Error of the linearized model against Housner's on one-cycle pulses.

    Parameters
    ----------
    shape : {"sine", "cosine", "half-sine"}
        Pulse shape.
    psi, omega : array_like, optional
        |a_g| / (g tan alpha) (> 1) and omega_g / p; default 60 values each, geometric, in
        [1.001, 40] and [0.05, 50].
    alpha, eta : sequence of float
        Slenderness [rad] and restitution of the blocks.
    rtol : float
        Tolerance of the nonlinear kernel (the reference).

    Returns
    -------
    xarray.Dataset
        ``error`` (relative max-rotation error, inf on overturning disagreement),
        ``scaled_error`` (error / alpha^2), ``overturn_disagreement``, ``overturned`` (the
        reference), on dims (eta, alpha, psi, omega).
    """
    psi = np.geomspace(1.001, 40.0, 60) if psi is None else np.asarray(psi, dtype=float)
    omega = np.geomspace(0.05, 50.0, 60) if omega is None else np.asarray(omega, dtype=float)
    alpha, eta = np.atleast_1d(alpha).astype(float), np.atleast_1d(eta).astype(float)
    err = np.empty((eta.size, alpha.size, psi.size, omega.size))
    over = np.empty(err.shape, bool)
    for i, e in enumerate(eta):
        for j, al in enumerate(alpha):
            ref = pulse_grid_batch(shape, psi, omega, al, e, rtol=rtol)
            lin = pulse_grid_batch(shape, psi, omega, al, e, method="linear")
            err[i, j] = relative_max_rotation_error(lin, ref)
            over[i, j] = ref["overturned"]
    dims = ("eta", "alpha", "psi", "omega")
    with np.errstate(over="ignore"):  # errors near 1e308 where the reference barely lifts
        scaled = err / alpha[None, :, None, None] ** 2
    ds = xr.Dataset(
        {
            "error": (dims, err),
            "scaled_error": (dims, scaled),
            "overturn_disagreement": (dims, np.isinf(err)),
            "overturned": (dims, over),
        },
        coords={"eta": eta, "alpha": alpha, "psi": psi, "omega": omega},
        attrs={"shape": shape, "reference": f"nonlinear kernel, rtol {rtol:g}"},
    )
    ds["psi"].attrs.update(long_name="|a_g| / (g tan alpha)", units="1")
    ds["omega"].attrs.update(long_name="omega_g / p", units="1")
    ds["error"].attrs.update(long_name="relative max-rotation error of eq. (3.1)", units="1")
    return ds


def tolerance_error_map(
    shape="sine", psi=None, omega=None, alpha=(0.05, 0.25), eta=0.9, rtols=(1e-2, 1e-3, 1e-4)
) -> xr.Dataset:
    """The nonlinear kernel at loose tolerances against itself at rtol 1e-11.

    Returns
    -------
    xarray.Dataset
        ``error`` (relative max rotation, inf on overturning disagreement) and
        ``impact_count_error`` (impacts gained or lost), on dims (rtol, alpha, psi, omega).
    """
    psi = np.geomspace(1.001, 40.0, 40) if psi is None else np.asarray(psi, dtype=float)
    omega = np.geomspace(0.05, 50.0, 40) if omega is None else np.asarray(omega, dtype=float)
    alpha = np.atleast_1d(alpha).astype(float)
    shape_ = (len(rtols), alpha.size, psi.size, omega.size)
    err, dn = np.empty(shape_), np.empty(shape_, np.int64)
    for j, al in enumerate(alpha):
        ref = pulse_grid_batch(shape, psi, omega, al, eta)
        for i, rt in enumerate(rtols):
            out = pulse_grid_batch(shape, psi, omega, al, eta, rtol=rt)
            err[i, j] = relative_max_rotation_error(out, ref)
            dn[i, j] = out["n_impacts"] - ref["n_impacts"]
    dims = ("rtol", "alpha", "psi", "omega")
    return xr.Dataset(
        {"error": (dims, err), "impact_count_error": (dims, dn)},
        coords={"rtol": list(rtols), "alpha": alpha, "psi": psi, "omega": omega},
        attrs={"shape": shape, "eta": eta},
    )


def cell_maximum(values, refine):
    """Largest value over each cell of a grid refined ``refine`` times along the last two
    axes (the cell includes its corners and interior points)."""
    n1, n2 = values.shape[-2:]
    c1, c2 = (n1 - 1) // refine, (n2 - 1) // refine
    out = np.full(values.shape[:-2] + (c1, c2), -np.inf)
    for di in range(refine + 1):
        for dj in range(refine + 1):
            out = np.maximum(
                out, values[..., di : di + c1 * refine : refine, dj : dj + c2 * refine : refine]
            )
    return out


def neighbourhood_maximum(values, reach=1):
    """Largest value over each cell and the cells within ``reach`` of it along the last two
    axes (its 3 x 3 neighbourhood for reach 1; the grid's edge cells have fewer neighbours)."""
    pad = [(0, 0)] * (values.ndim - 2) + [(reach, reach)] * 2
    padded = np.pad(values, pad, constant_values=-np.inf)
    n1, n2 = values.shape[-2:]
    out = np.full(values.shape, -np.inf)
    for di in range(2 * reach + 1):
        for dj in range(2 * reach + 1):
            out = np.maximum(out, padded[..., di : di + n1, dj : dj + n2])
    return out


def overturning_nearby(ds, refine, reach=1):
    """Cells (of a :func:`linearization_error_map` refined ``refine`` times per cell) where a
    sample of the cell or of a neighbour cell within ``reach`` overturns in either model.

    Where both models overturn, their max rotations agree (pi/2), but the overturning
    regions of pulses hold thin safe tongues (the block survives between two overturning
    modes) that a finite grid steps over, and the linear model's tongues lie elsewhere; the
    edges of the regions are as uncertain. So a sample that overturns in either model
    vouches for nothing around it.
    """
    either = ds.overturned.values | ds.overturn_disagreement.values
    return neighbourhood_maximum(cell_maximum(either.astype(float), refine), reach) > 0


def bound_table(
    psi_nodes=None,
    omega_nodes=None,
    alpha=(0.01, 0.05, 0.1, 0.2, 0.3),
    eta=(0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0),
    refine=2,
    reach=1,
    shapes=("sine", "cosine", "half-sine"),
):
    """The table behind ``method="auto"``.

    K of a cell is the largest error / alpha^2 over the samples of the cell and of the
    cells within ``reach`` of it (on a grid refined ``refine`` times inside each cell), and
    inf where one of these samples overturns in either model (:func:`overturning_nearby`).
    A finite K thus says: around this cell both models survive everywhere they were sampled,
    and the nearest sample where either overturns is more than ``reach`` cells away. (The
    neighbourhood also covers the error's steep, non-monotonic rise towards psi = 1, where
    the block chatters: with the cell's own samples only, the bound missed 1.2 % of random
    surviving sine scenes there, by up to 5.5 times.)
    """
    psi_nodes = np.geomspace(1.0, 40.0, 41) if psi_nodes is None else np.asarray(psi_nodes)
    omega_nodes = np.geomspace(0.05, 50.0, 49) if omega_nodes is None else np.asarray(omega_nodes)

    def fine(nodes):
        r = np.linspace(0.0, 1.0, refine + 1)[:-1]
        logs = np.log(nodes)
        return np.exp(np.append((logs[:-1, None] + np.diff(logs)[:, None] * r).ravel(), logs[-1]))

    K = []
    for shape in shapes:
        ds = linearization_error_map(shape, fine(psi_nodes), fine(omega_nodes), alpha, eta)
        cells = neighbourhood_maximum(cell_maximum(ds.scaled_error.values, refine), reach)
        K.append(np.where(overturning_nearby(ds, refine, reach), np.inf, cells))
    return {
        "K": np.array(K, dtype=np.float32),
        "shapes": np.array(shapes),
        "eta": np.asarray(eta, dtype=float),
        "alpha": np.asarray(alpha, dtype=float),
        "psi": psi_nodes,
        "omega": omega_nodes,
    }


def main():
    import time

    t0 = time.perf_counter()
    tab = bound_table()
    _auto.TABLE.parent.mkdir(exist_ok=True)
    np.savez_compressed(_auto.TABLE, **tab)
    finite = np.isfinite(tab["K"])
    shares = ", ".join(f"{s} {f.mean():.1%}" for s, f in zip(tab["shapes"], finite, strict=True))
    print(
        f"wrote {_auto.TABLE} in {time.perf_counter() - t0:.0f} s: K {tab['K'].shape}, "
        f"cells bounded: {shares}; median K {np.median(tab['K'][finite]):.2f}"
    )


if __name__ == "__main__":
    main()
