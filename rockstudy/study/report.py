"""``rockstudy report RESULT``: one self-contained HTML page, its PNG figures and CSV tables.

Sections are chosen by what the cube holds: a summary of the outcomes; Sobol' indices (sobol
studies); fragility curves against dimensional and dimensionless intensities; spectra and
overturning maps (grid studies); and the self-similarity of the response (replicated designs:
the collapse metric, and the eta^2 law of [000] eq. 4.16 for the linear model).
"""

from __future__ import annotations

import base64
import html
import io
import json
from pathlib import Path

import numpy as np
import pandas as pd

from ..constants import G
from . import analysis
from .store import open_result


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


class _Page:
    def __init__(self, out: Path):
        self.out = out
        self.parts = []
        self.figures = 0

    def heading(self, text):
        self.parts.append(f"<h2>{html.escape(text)}</h2>")

    def text(self, text):
        self.parts.append(f"<p>{html.escape(text)}</p>")

    def table(self, frame: pd.DataFrame, name: str, caption: str):
        frame.to_csv(self.out / f"{name}.csv")
        self.parts.append(
            f"<p class='cap'>{html.escape(caption)} (<a href='{name}.csv'>{name}.csv</a>)</p>"
        )
        self.parts.append(frame.to_html(float_format=lambda x: f"{x:.4g}", classes="t"))

    def figure(self, fig, name: str, caption: str):
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100)
        fig.savefig(self.out / f"{name}.png", dpi=100)
        _plt().close(fig)
        data = base64.b64encode(buf.getvalue()).decode()
        self.figures += 1
        self.parts.append(
            f"<figure><img alt='{html.escape(name)}' "
            f"src='data:image/png;base64,{data}'>"
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )

    def write(self, title, meta):
        head = (
            f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}"
            "</title><style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
            "img{max-width:100%}table.t{border-collapse:collapse;font-size:12px}"
            "table.t td,table.t th{border:1px solid #ccc;padding:2px 6px}"
            ".cap{color:#555}</style></head><body>"
        )
        check = (
            "<p id='figcheck'>figures not checked</p><script>window.addEventListener("
            "'load',()=>{const im=[...document.images];const ok=im.filter(i=>i.complete"
            "&&i.naturalWidth>0).length;document.getElementById('figcheck').textContent="
            "'figures rendered: '+ok+'/'+im.length;});</script>"
        )
        body = f"<h1>{html.escape(title)}</h1>{meta}" + "".join(self.parts) + check
        path = self.out / "index.html"
        path.write_text(head + body + "</body></html>")
        return path


def _summary(page, ds):
    status = ds["status"].values if "status" in ds else np.ones(ds.sizes["sample"])
    rows = {
        "samples": status.size,
        "ok": int((status == 1).sum()),
        "failed": int((status == 2).sum()),
        "pending": int((status == 0).sum()),
    }
    if "overturned" in ds:
        rows["overturned share"] = float(np.mean(ds["overturned"].values == 1))
    if "max_rotation_ratio" in ds and "overturned" in ds:
        r = ds["max_rotation_ratio"].values[ds["overturned"].values == 0]
        for q in (0.5, 0.9, 0.99):
            rows[f"theta_max / theta_cr, survivors, q{int(q * 100)}"] = float(np.quantile(r, q))
    page.table(pd.DataFrame({"value": rows}), "summary", "Outcomes")


def _sobol(page, ds, study):
    for output in ("max_rotation_ratio", "overturned"):
        if output not in ds:
            continue
        t = analysis.sobol_indices(ds, output, failed="impute", num_resamples=200)
        page.table(t, f"sobol_{output}", f"Sobol' indices of {output} (95 % bootstrap)")
        conv = analysis.sobol_convergence(ds, output, failed="impute", num_resamples=20)
        conv.to_csv(page.out / f"sobol_convergence_{output}.csv")
        plt = _plt()
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 3.6))
        x = np.arange(len(t))
        a1.bar(x - 0.2, t["S1"], 0.4, yerr=t["S1_conf"], label="S1")
        a1.bar(x + 0.2, t["ST"], 0.4, yerr=t["ST_conf"], label="ST")
        a1.set_xticks(x, t.index, rotation=20)
        a1.set(title=f"Sobol' indices of {output}")
        a1.legend()
        for name in t.index:
            s = conv.xs(name, level="input")
            a2.semilogx(s.index, s["ST"], "o-", label=name)
        a2.set(xlabel="N (base samples)", ylabel="ST", title="convergence on nested prefixes")
        a2.legend(fontsize=7)
        fig.tight_layout()
        page.figure(fig, f"sobol_{output}", f"Sobol' indices of {output} and their convergence")


def _middle_third(values):
    """Samples in the middle third of a variable's range (quantiles 1/3 to 2/3)."""
    lo, hi = np.quantile(values, [1 / 3, 2 / 3])
    return (values >= lo) & (values <= hi)


NOT_REACHED = "not reached within the sampled range"
BELOW_RANGE = "below the sampled range"


def _capacities_as_measured(table: pd.DataFrame) -> pd.DataFrame:
    """The fragility table as the report shows it: a median capacity or band limit outside
    the group's observed intensities (``im_min``-``im_max``) is an extrapolation of the
    lognormal shape, so it is shown as text, not as a number."""
    shown = table.astype(object)
    for col in ("theta", "theta_lo", "theta_hi"):
        value = table[col].to_numpy(float)
        shown[col] = [
            NOT_REACHED if v > hi else BELOW_RANGE if v < lo else v
            for v, lo, hi in zip(value, table["im_min"], table["im_max"], strict=True)
        ]
    return shown


def _fragility(page, ds):
    """Fragility by block size: against a_g for pulses of similar period T_p (dimensional),
    and against a_g / (g tan alpha) for pulses of similar omega_g / p (the groups of 6.1)."""
    if "overturned" not in ds or "amplitude" not in ds or "half_diagonal" not in ds:
        return
    d = ds.assign(abs_amplitude=np.abs(ds["amplitude"]))
    bins = np.quantile(d["half_diagonal"].values, [0, 1 / 3, 2 / 3, 1])
    bins[-1] += 1e-12
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    tables = []
    for ax, im, band, label in (
        (axes[0], "abs_amplitude", "period", "a_g [m/s^2], T_p in its middle third"),
        (
            axes[1],
            "amplitude_ratio",
            "omega",
            "a_g / (g tan alpha), omega_g / p in its middle third",
        ),
    ):
        sub = d.isel(sample=np.flatnonzero(_middle_third(d[band].values)))
        try:
            t = analysis.fragility(sub, im, by="half_diagonal", bins=bins, n_boot=100)
        except ValueError as err:  # no block size saw both outcomes
            page.text(f"Fragility against {im}: {err}")
            continue
        t.insert(0, "intensity", im)
        t.insert(1, "band", band)
        tables.append(t)
        grid = np.geomspace(float(sub[im].min()), float(sub[im].max()), 200)
        curve = analysis.fragility_curve(t, grid)
        for g, inside in zip(curve.group.values, t["theta_in_range"], strict=True):
            c = curve.sel(group=g)
            note = "" if inside else " (median outside the data)"
            ax.plot(grid, c.probability, "-" if inside else "--", label=f"R {g} m{note}")
            ax.fill_between(grid, c.lower, c.upper, alpha=0.2)
        ax.set(xscale="log", xlabel=label, ylabel="P(overturn)")
        ax.legend(fontsize=8)
    if not tables:
        plt.close(fig)
        return
    axes[0].set_title("dimensional intensity")
    axes[1].set_title("dimensionless groups (6.1)")
    fig.tight_layout()
    page.figure(
        fig,
        "fragility",
        "Lognormal fragility curves (MLE, 90 % bootstrap bands) by "
        "block size: in dimensional terms the sizes spread apart, in the groups they "
        "collapse (to the extent the groups make the response self-similar); dashed: the "
        "median lies outside the sampled intensities",
    )
    fit = pd.concat(tables)
    fit.to_csv(page.out / "fragility_fit.csv")
    page.table(
        _capacities_as_measured(fit),
        "fragility",
        "Fragility parameters: median capacity theta, log-standard deviation beta; a median "
        f"or band limit outside the group's sampled intensities (im_min-im_max) reads "
        f"'{NOT_REACHED}' (the fitted numbers and flags are in fragility_fit.csv)",
    )
    spread = []
    for t in tables:
        inside = t["theta"][t["theta_in_range"]]
        spread.append(
            f"{t['intensity'].iloc[0]}: {inside.max() / inside.min():.2f}"
            if inside.size >= 2
            else f"{t['intensity'].iloc[0]}: not measured (fewer than two medians within "
            "the sampled range)"
        )
    page.text(
        "Spread of the median capacity between block sizes (max/min of theta, medians within "
        "the sampled range only): " + ", ".join(spread)
    )


def _grid(page, ds):
    dims = list(ds.dims)
    if len(dims) != 2:
        return
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    y, x = dims
    for ax, var in zip(axes, ("overturned", "max_rotation_ratio"), strict=True):
        if var not in ds:
            continue
        val = ds[var].values.astype(float)
        if var == "max_rotation_ratio" and "overturned" in ds:
            val = np.where(ds["overturned"].values == 1, np.nan, val)
        mesh = ax.pcolormesh(ds[x].values, ds[y].values, val, shading="auto")
        fig.colorbar(mesh, ax=ax)
        ax.set(xlabel=x, ylabel=y, title=var, xscale="log", yscale="log")
    fig.tight_layout()
    page.figure(fig, "grid_maps", "Overturning map and rocking spectrum over the grid")


def _similarity(page, ds, study):
    law_411 = study.motion.amplitude_a is not None
    groups = ["a" if law_411 else "uplift_ratio", "omega", "restitution"]
    surv = ds.isel(sample=np.flatnonzero(ds["overturned"].values == 0))
    # the response of the design's law: theta / alpha (4.10; theta g / a_g differs by the group
    # factor 1 / a only) or theta g / (a_g cos alpha) = theta * uplift_ratio / sin(alpha) (6.1)
    response = (
        surv["max_rotation"] / surv["slenderness"]
        if law_411
        else surv["max_rotation"] * surv["uplift_ratio"] / np.sin(surv["slenderness"])
    )
    surv = surv.assign(law_response=response)
    rows = {}
    for label, sel in (
        ("all", slice(None)),
        ("slender (alpha < 0.12)", surv["slenderness"].values < 0.12),
        ("non-slender (alpha > 0.2)", surv["slenderness"].values > 0.2),
    ):
        sub = surv if label == "all" else surv.isel(sample=np.flatnonzero(sel))
        try:
            collapse = analysis.collapse_metric(sub, "law_response", groups)
        except ValueError:  # too few survivors share a group point in this subset
            collapse = "not replicated (too few survivors share a group point)"
        row = {"collapse metric (design groups)": collapse}
        for law, resp, law_groups in (
            (
                "(4.11)",
                sub["max_rotation"] * G / (sub["a"] * G * sub["slenderness"]),
                ["a", "omega", "restitution"],
            ),
            (
                "(6.1)",
                sub["max_rotation"]
                / (sub["uplift_ratio"] ** -1 * np.tan(sub["slenderness"]) * sub["cos_alpha"]),
                ["uplift_ratio", "omega", "restitution"],
            ),
        ):
            share = analysis.unexplained_share(sub.assign(resp=resp), "resp", law_groups)
            row[f"unexplained share, {law} groups"] = share.value
            row[f"its floor, {law} groups"] = share.floor
        rows[label] = {**row, "samples": sub.sizes["sample"]}
    page.table(
        pd.DataFrame(rows).T,
        "collapse",
        "Share of the variance of the survivors' response within group points "
        f"({', '.join(groups)}), and left unexplained by a smooth fit over each law's "
        "groups, next to that fit's floor (the share it leaves for a smooth, cubic response of "
        "the groups alone on the same samples; a lower estimate: values within a few times "
        "the floor cannot be told from complete similarity with this many samples)",
    )
    if study.run.method == "linear" and study.motion.amplitude_a is not None:
        _eta_law(page, surv)


def _eta_law(page, surv):
    """The restitution law (4.14)-(4.16) of [000] against the cube's linear responses."""
    from ..closedform import d0_star, limit_residual

    a, w, eta = (surv[v].values for v in ("a", "omega", "restitution"))
    after = limit_residual(a, w) < 0  # first impact after the pulse
    x = eta**2 * (1 - d0_star(a, w))
    law = 0.5 * x
    th = surv["max_rotation_ratio"].values
    ok = after & np.isfinite(x) & (x > 0) & (th >= law * 0.5)
    err = np.abs(law[ok] / th[ok] - 1)
    edges = np.array([0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.0])
    idx = np.digitize(x[ok], edges)
    rows = {
        f"{edges[i - 1]:g}-{edges[i]:g}": {
            "median rel. error": float(np.median(err[idx == i])),
            "samples": int((idx == i).sum()),
        }
        for i in range(1, len(edges))
        if np.any(idx == i)
    }
    page.table(
        pd.DataFrame(rows).T,
        "eta_law",
        "eta^2 law theta_m/alpha ~ eta^2 (1 - D0*) / 2 (eq. 4.14 with the expansion of "
        "4.13) against the linear solver, by x = eta^2 (1 - D0*), impacts after the pulse",
    )
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(law[ok], th[ok], ".", ms=2)
    lim = [law[ok].min(), law[ok].max()]
    ax.plot(lim, lim, "k--", lw=1)
    ax.set(xlabel="eta^2 (1 - D0*) / 2", ylabel="theta_max / alpha (solver)")
    fig.tight_layout()
    page.figure(fig, "eta_law", "The eta^2 law against the solver")


def _version(versions) -> str:
    """rockstudy's version from a cube's ``versions`` attribute (JSON), as plain text: the
    attribute comes from a file that may have been made or edited by anyone."""
    try:
        value = json.loads(versions)
    except (TypeError, ValueError):
        return "?"
    return str(value.get("rockstudy", "?")) if isinstance(value, dict) else "?"


def make_report(result, out=None) -> Path:
    """Write the report of a result cube into ``out`` (default: RESULT's name + '_report')."""
    result = Path(result)
    out = Path(out) if out is not None else result.with_name(result.stem + "_report")
    out.mkdir(parents=True, exist_ok=True)
    ds = open_result(result).load()
    study = analysis.study_of(ds)
    page = _Page(out)
    page.heading("Summary")
    _summary(page, ds)
    if study.sampler.kind == "sobol":
        page.heading("Sensitivity")
        _sobol(page, ds, study)
    if study.sampler.kind == "grid":
        page.heading("Spectrum and overturning map")
        _grid(page, ds)
    elif study.motion.kind == "pulse":
        page.heading("Fragility")
        _fragility(page, ds)
    if study.sampler.replicates > 1 and "overturned" in ds:
        page.heading("Self-similarity")
        _similarity(page, ds, study)
    meta = (
        f"<p>{html.escape(study.description)}</p><p class='cap'>study sha256 "
        f"{html.escape(str(ds.attrs.get('study_sha256', ''))[:16])}, seed {study.seed}, "
        f"rockstudy {html.escape(_version(ds.attrs.get('versions')))}</p>"
    )
    return page.write(f"rockstudy report: {study.name}", meta)
