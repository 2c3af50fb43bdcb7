"""The per-object sections of a record design's report.

For a design of named objects (``[structure] kind = "objects"``, or a dict ``{name:
structure}`` given to a design function) the record report answers per object, by name: its
fragility against PGA and against the measure the efficiency table recommends, with its uplift
level marked; its capacity under each record with the governing (lowest) record; and its IDA
curves or stripe points with the switch band. Each section is a function ``(page, ctx)`` of
:data:`rockstudy.study.report_records.SECTIONS`; ``ctx`` is a
:class:`rockstudy.study.report_records.ReportContext`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import xarray as xr

from ...constants import STANDARD_GRAVITY
from ...motions import measures as _ms
from ..analysis import record_fragility as rf
from ..analysis import record_similarity as rsim
from ..analysis.fragility_fit import LACK_OF_FIT_LEVEL, N_BOOT
from ..analysis.risk import cut_levels, felt_as_measured, horizontal
from ..analysis.sampled import fragility_curve
from ..spec.design_kinds import DesignKind, design_kind
from ..spec.feasibility import DEFAULT_MAX_SCALE_FACTOR
from ._page import (
    _log_ticks,
    _mpl_text,
    _names,
    _plt,
    object_colors,
    separation_note,
    shown_separation,
)

__all__ = [
    "FONT",
    "friction_check",
    "ida_axis",
    "IDA_AXIS_MARGIN",
    "object_capacity",
    "object_curves",
    "object_fragility",
    "outcome",
    "quoted_to_report",
    "ReportContext",
    "scale_factors",
    "si_to_report",
]

#: Font size of legends and tick labels of the per-object figures [pt] (print: >= 8).
FONT = 8


def _sizes(ds):
    """Size-class edges [m] of the blocks, or None when they do not span three sizes."""
    R = ds["half_diagonal"].values if "half_diagonal" in ds else np.zeros(0)
    if not (R.size and np.all(np.isfinite(R)) and np.unique(R).size >= 3):
        return None
    return rsim.size_edges(ds, 3)


def _structure_title(ds, j) -> str:
    alpha = float(ds["slenderness"].values[j])
    R = float(ds["half_diagonal"].values[j]) if "half_diagonal" in ds else np.nan
    size = f"R = {R:.3g} m, " if np.isfinite(R) else ""
    name = ds["structure"].values[j]
    label = name if isinstance(name, str) else f"block {j}"
    return f"{label}: {size}alpha = {alpha:.3g} rad"


@dataclass
class ReportContext:
    """What every section of :data:`SECTIONS` reads: the design, the options of the report
    and the answers several sections share (computed once)."""

    ds: xr.Dataset
    n_boot: int = N_BOOT
    compare: xr.Dataset | None = None
    units: str = "g"
    max_scale_factor: float = DEFAULT_MAX_SCALE_FACTOR
    friction: object = None
    #: The one lookup of a measure's name and units (:func:`.report_records.im_label`).
    im_label: Callable[..., str] | None = None
    #: The study the dataset was run from (None for a design made in Python): sections that
    #: read a study's settings (e.g. a ``[hazard]`` section) find them here.
    study: object = None
    #: The site's hazard curve (:class:`rockstudy.risk.HazardCurve`) and the years of the
    #: probability of overturning, for the annual-rate section.
    hazard: object = None
    years: float = 50.0
    _cache: dict = field(default_factory=dict)

    @property
    def design(self) -> str:
        return self.ds.attrs["design"]

    @property
    def kind(self) -> DesignKind:
        """The design's entry in the registry of design kinds."""
        return design_kind(self.design)

    @property
    def objects(self) -> bool:
        """Named objects (the ``structure`` coordinate holds names), not sampled structures."""
        return self.ds["structure"].dtype.kind in "OUS"

    @property
    def edges(self):
        """Size-class edges of sampled structures (None for objects or too few sizes)."""
        return None if self.objects else _sizes(self.ds)

    @property
    def overturned(self) -> bool:
        """Whether any point of the design overturned."""
        if self.kind.capacities:
            return bool((self.ds["censored"].values == 0).any())
        return bool((self.ds["overturned"].values == 1).any())

    @property
    def rocked(self) -> bool:
        """Whether any simulated point left rest."""
        name = "step_max_rotation" if self.kind.capacities else "max_rotation"
        return bool((np.nan_to_num(self.ds[name].values) > 0).any()) or self.overturned

    @property
    def colors(self) -> dict:
        """One colour per object, keyed by name (:func:`object_colors`): every figure's."""
        return object_colors(self.ds["structure"].values)

    def relabel(self, label: str) -> str:
        """An :func:`im_label` in the report's acceleration units: the unit of an acceleration
        (any of :func:`rockstudy.motions.measures.acceleration_units`) read as the report's,
        as :func:`quoted_to_report` converts its values."""
        for unit in _ms.acceleration_units():
            label = label.replace(f" [{unit}]", f" [{self.units}]")
        return label

    text = staticmethod(_mpl_text)  # a name from a file, as matplotlib text
    log_ticks = staticmethod(_log_ticks)

    def record_names(self) -> list[str]:
        return _names(self.ds)

    def structure_title(self, j) -> str:
        return _structure_title(self.ds, j)

    def stripe_label(self) -> str:
        period = self.ds.attrs.get("im_period", np.nan)
        return self.relabel(
            self.im_label(self.ds.attrs.get("im", "pga"), period if np.isfinite(period) else None)
        )

    def recommended(self):
        """(im, period) of the measure of smallest dispersion per power in the efficiency
        table, or None when it cannot be made."""
        if "recommended" not in self._cache:
            try:
                table = self.efficiency()
                table = table[np.isfinite(table["beta_linear"].to_numpy(float))]
                label = table.index[0][0]
                name, _, rest = label.partition("(T=")
                self._cache["recommended"] = (name, float(rest.rstrip(" s)")) if rest else None)
            except (ValueError, IndexError):
                self._cache["recommended"] = None
        return self._cache["recommended"]

    def efficiency(self):
        if "efficiency" not in self._cache:
            with shown_separation():  # a separated measure: no beta, column "separated"
                self._cache["efficiency"] = rf.im_efficiency(self.ds, n_boot=self.n_boot)
        return self._cache["efficiency"]


def _section(heading, function, when=None):
    """A section of :data:`SECTIONS`: ``heading`` (text, or a callable of the context),
    then ``function(page, ctx)``; skipped where ``when(ctx)`` is False."""

    def run(page, ctx):
        if when is not None and not when(ctx):
            return
        page.heading(heading(ctx) if callable(heading) else heading)
        function(page, ctx)

    run.__name__ = getattr(function, "__name__", "section")
    return run


def _fits(ctx) -> bool:
    return ctx.overturned


def outcome(page, ctx):
    """In words, when nothing rocked or nothing overturned (no fragility can be fitted)."""
    if ctx.overturned:
        return
    up = ctx.ds["uplift_acceleration"].values / _unit(ctx)
    span = (
        f"from {np.nanmin(up):.3g} to {np.nanmax(up):.3g} {ctx.units}"
        if np.isfinite(up).any()
        else "not stored in this cube"
    )
    if not ctx.rocked:
        page.warning(
            "Nothing rocked: no structure (as simulated: a block, or the equivalent block of "
            "another structure) left rest under any record at any level. The uplift levels "
            f"of the structures (g tan alpha of a block, g lambda of another) are {span}; "
            "no fragility can be fitted. Raise the levels (check the units of "
            "scale_to.value)."
        )
    else:
        page.warning(
            "Nothing overturned: every structure stood under every record at every level "
            "simulated, so no fragility can be fitted; the tables below give how far the "
            "structures rocked. Raise the levels to see overturning."
        )


def scale_factors(page, ctx):
    """A warning box where records are scaled beyond ``max_scale_factor``."""
    if ctx.kind.scale_variable is None:
        return
    scale = ctx.ds[ctx.kind.scale_variable].values
    limit = ctx.max_scale_factor
    beyond = np.abs(np.nan_to_num(scale)) > limit
    if not beyond.any():
        return
    names = ctx.record_names()
    worst = np.unravel_index(int(np.nanargmax(np.abs(scale))), scale.shape)
    what = ctx.kind.text["scaled"]
    page.warning(
        f"{int(beyond.sum())} of {scale.size} {what} scale a record by more than "
        f"max_scale_factor = {limit:g} (largest {float(np.nanmax(np.abs(scale))):.3g} x, record "
        f"{names[worst[0]]}): a record scaled far from what it recorded has the shape of a "
        "weaker or stronger earthquake it is not; prefer records closer to the level."
    )


def _label(ctx, im, period=None):
    return ctx.relabel(ctx.im_label(im, period))


def _unit(ctx) -> float:
    """The report's unit of acceleration in m/s^2: the unit g (standard gravity, as records
    and ``scale_to`` read it) or 1."""
    return STANDARD_GRAVITY if ctx.units == "g" else 1.0


def quoted_to_report(units, im) -> float:
    """The factor from the quoted unit of ``im`` (the registry's, :func:`rf.quoted`: what the
    fits give) to a report's: an acceleration (by its unit in the registry,
    :func:`rockstudy.motions.measures.is_acceleration`) is shown in the report's acceleration
    ``units`` (g or m/s^2, as :meth:`ReportContext.relabel` labels it); any other measure in
    its quoted unit."""
    if im not in _ms.MEASURES or not _ms.is_acceleration(im):
        return 1.0
    to_si = _ms.units_of(im)
    return to_si[rf.quoted(im)[0]] / to_si[units]


def si_to_report(units, im) -> float:
    """The factor from the SI value of ``im`` (a stored level or measure) to a report's unit
    of it (:func:`quoted_to_report`)."""
    return rf.quoted(im)[1] * quoted_to_report(units, im)


def _object_fit(ctx, im, period):
    """The fragility of each object against ``im`` (rows by name), in the report's units."""
    fit = getattr(rf, ctx.kind.fragility)
    with shown_separation():  # said on the page (separation_note)
        table = fit(ctx.ds, im=im, period=period, by="structure", n_boot=ctx.n_boot)
    f = quoted_to_report(ctx.units, im)
    for col in ("theta", "theta_lo", "theta_hi", "im_min", "im_max"):
        table[col] = table[col] * f
    table.index.name = "object"
    return table


def _uplift(ctx, im) -> np.ndarray | None:
    """Each object's uplift level in ``im`` (its uplift acceleration a_up: g tan alpha of a
    block, g lambda of another structure, eq. 10 of [003]; 1 in PGA / a_up), or None where
    a measure has no single uplift level (NaN for a cube that does not say it)."""
    if im == "pga":
        return ctx.ds["uplift_acceleration"].values / _unit(ctx)
    if im == "pga_ratio":
        return np.ones(ctx.ds.sizes["structure"])
    return None


def object_fragility(page, ctx):
    """Per object: the lognormal fragility against PGA and the recommended measure."""
    if not ctx.objects or not ctx.overturned:
        return
    page.heading("Fragility of each object")
    measures = [("pga", None)]
    best = ctx.recommended()
    if best is not None and best != ("pga", None):
        measures.append(best)
    plt = _plt()
    fig, axes = plt.subplots(1, len(measures), figsize=(5.2 * len(measures), 4.2), squeeze=False)
    tables = []
    for ax, (im, period) in zip(axes[0], measures, strict=True):
        try:
            t = _object_fit(ctx, im, period)
        except ValueError as err:
            page.text(f"Fragility of the objects against {_label(ctx, im, period)}: {err}")
            ax.set_visible(False)
            continue
        separation_note(page, t, f"Fragility of the objects against {_label(ctx, im, period)}")
        if not _plot_objects(ax, ctx, t, im, period):
            page.text(
                f"Fragility of the objects against {_label(ctx, im, period)}: no object's fit "
                f"is defined (records per object: {int(t['n'].max())}; a lognormal fit needs "
                "at least two distinct capacities or outcomes)"
            )
            ax.set_visible(False)
            continue
        t.insert(0, "intensity", _label(ctx, im, period))
        tables.append(t)
    if not tables:
        plt.close(fig)
        return
    fig.tight_layout()
    page.figure(
        fig,
        "object_fragility",
        "Fragility of each object (lognormal fit, 90 % pointwise band) against PGA and "
        "against the measure the efficiency table recommends; dotted vertical lines: each "
        "object's uplift level (g tan alpha of a block; g lambda, eq. 10 of [003], of a "
        "wall, frame or arch: the structure's own, not its equivalent block's), drawn where "
        "the measure has one (PGA, PGA / uplift level); open circles, in the object's "
        "colour: "
        + ctx.kind.text["observed"]
        + (
            "; under these horizontal records nothing can overturn below it, so the fragility "
            "in PGA is 0 there (dashed: the fitted lognormal's tail, which the annual rates "
            "leave out)"
            if horizontal(ctx.ds) and felt_as_measured(ctx.ds)
            else ""
        ),
    )
    table = pd.concat(tables)
    cols = ["intensity", "theta", "theta_lo", "theta_hi", "beta", "n", "theta_in_range"]
    cols += ["separated", "no_rise"] + (["lack_of_fit_p"] if "lack_of_fit_p" in table else [])
    shown = table[cols].rename(
        columns={
            "theta": "median capacity",
            "theta_lo": "median, lower",
            "theta_hi": "median, upper",
            "beta": "beta (MLE)",
            "n": "records",
            "theta_in_range": "median within the data",
            "separated": "outcomes separated (no fit)",
            "no_rise": "no rise with the intensity (no fit)",
            "lack_of_fit_p": "lognormal vs capacities, p (Shapiro-Wilk)",
        }
    )
    for col in ("median capacity", "median, lower", "median, upper"):
        shown[col] = [  # an object that never overturned: its median is not reached
            "not reached (never overturned)" if v == np.inf else v for v in shown[col]
        ]
    up = _uplift(ctx, "pga")
    names = list(map(str, ctx.ds["structure"].values))
    shown.insert(1, f"uplift level, PGA [{ctx.units}]", [up[names.index(n)] for n in table.index])
    page.table(shown, "object_fragility", "Fragility of each object, by name (90 % bands)")
    _capacities_not_lognormal(page, ctx, table)


def _capacities_not_lognormal(page, ctx, table):
    """A warning naming the objects whose IDA capacities do not look lognormal (Shapiro-Wilk
    p of ln capacity below :data:`LACK_OF_FIT_LEVEL`, :func:`rf.capacities_lack_of_fit`)."""
    if "lack_of_fit_p" not in table:
        return
    bad = table[table["lack_of_fit_p"] < LACK_OF_FIT_LEVEL]
    if bad.empty:
        return
    names = ", ".join(
        f"{o} in {r['intensity']} (p = {r['lack_of_fit_p']:.2g})" for o, r in bad.iterrows()
    )
    page.warning(
        f"The capacities of {names} do not look lognormal (Shapiro-Wilk test of their "
        f"logarithms at the {LACK_OF_FIT_LEVEL:g} level): the records may fall in families "
        "that topple the object at distant levels. Read those medians and betas as a summary, "
        "and the IDA curves as the data."
    )


def _cut(ctx, im) -> np.ndarray:
    """Where each object's fragility is 0 (:func:`cut_levels`: nothing overturns below its
    uplift, or below where the simulated block lifts if lower), in ``im``: PGA, or PGA / a_up;
    NaN for another measure or where there is no cut."""
    if im not in ("pga", "pga_ratio"):
        return np.full(ctx.ds.sizes["structure"], np.nan)
    up = _uplift(ctx, "pga")
    level = cut_levels(ctx.ds, "pga", ctx.units, up)
    return level if im == "pga" else level / up


def _observed(ctx, im, period, j) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) of object ``j``'s data beside its fitted curve, in the report's unit of ``im``:
    for an IDA its capacities (first overturning intensities) at the plotting positions
    (k - 1/2) / n of their ranks among its n records (a censored record counts, above them
    all); for stripes the share of the points that overturned at each level (at the
    geometric mean of the points' intensities there); for a cloud each record's outcome (0
    stood, 1 overturned) at its intensity."""
    f = quoted_to_report(ctx.units, im)
    if ctx.kind.capacities:
        cap, _, cens, ok = rf.ida_arrays(ctx.ds, im, period)
        n = int(ok[:, j].sum())
        x = np.sort(cap[:, j][ok[:, j] & ~cens[:, j]]) * f
        return x, (np.arange(1, x.size + 1) - 0.5) / max(n, 1)
    x, y, ok = rf.stripe_arrays(ctx.ds, im, period)
    if not ctx.kind.levels:  # one point of each record
        return x[ok[:, j], j] * f, (y[ok[:, j], j] == 1).astype(float)
    x, y, ok = (a[:, j].reshape(a.shape[0], -1) for a in (x, y, ok))  # (record, level)
    xs, ys = [], []
    for k in range(x.shape[1]):
        sel = ok[:, k]
        if sel.any():
            xs.append(float(np.exp(np.mean(np.log(x[sel, k])))) * f)
            ys.append(float(np.mean(y[sel, k] == 1)))
    return np.asarray(xs), np.asarray(ys)


def _plot_objects(ax, ctx, t, im, period) -> bool:
    """Each object's fitted curve and band on ``ax``; False (nothing drawn) when no fit is
    defined."""
    low, high = np.nanmin(t["im_min"]), np.nanmax(t["im_max"])
    up = _uplift(ctx, im)
    names = list(map(str, ctx.ds["structure"].values))
    if up is not None and np.isfinite(up).any():
        low = min(low, np.nanmin(up))
    if not (np.isfinite(low) and np.isfinite(high) and high >= low > 0):
        return False
    grid = np.geomspace(low / 1.2, high * 1.2, 200)
    curve = fragility_curve(t, grid)
    cut = _cut(ctx, im)
    shade = 0.15 if curve.sizes["group"] <= 3 else 0.07  # many bands overlap
    drawn = 0
    for g in curve.group.values:
        c = curve.sel(group=g)
        if not np.isfinite(c.probability.values).any():
            continue
        drawn += 1
        j = names.index(str(g))
        x_u = up[j] if up is not None else np.nan
        above = grid >= cut[j] if np.isfinite(cut[j]) else np.ones(grid.size, bool)
        p = np.where(above, c.probability, 0.0)
        color = ctx.colors[str(g)]
        ax.plot(grid, p, "-", label=ctx.text(str(g)), color=color)
        if not above.all():  # the fitted lognormal's tail, where the object cannot rock
            ax.plot(grid[~above], c.probability[~above], "--", lw=0.8, color=color)
        ax.fill_between(grid[above], c.lower[above], c.upper[above], alpha=shade, color=color)
        if up is not None:
            ax.axvline(x_u, ls=":", lw=1.5, color=color)
        ax.plot(*_observed(ctx, im, period, j), "o", ms=3.5, mfc="none", color=color)
    if not drawn:
        return False
    ax.set(xscale="log", ylim=(-0.02, 1.02), ylabel="probability of overturning [-]")
    ax.set_xlabel(_label(ctx, im, period), fontsize=FONT + 1)
    ctx.log_ticks(ax)
    ax.tick_params(labelsize=FONT)
    ax.legend(fontsize=FONT, loc="lower right")  # (an S-curve leaves that corner empty)
    return True


# ------------------------------------------------------------------------------ capacity


def _ida_capacity(ctx):
    """(cells, values, what): the PGA at first overturning of each object (rows) under each
    record (columns); censored: 'above' the highest scale seen to stand."""
    ds, f = ctx.ds, 1.0 / _unit(ctx)
    pga = ds["pga"].values[:, None] * f
    cap = ds["capacity_scale"].values * pga
    value = np.where(ds["censored"].values == 1, np.nan, cap).T
    lower = (ds["capacity_scale_lower"].values * pga).T
    cells = np.empty(value.shape, object)  # numbers, or text where censored
    for k, v in np.ndenumerate(value):
        cells[k] = float(v) if np.isfinite(v) else f"above {lower[k]:.3g}"
    what = (
        f"the PGA [{ctx.units}] of the scaled record at the object's first overturning "
        "(the IDA capacity; 'above': censored, standing at the highest scale reached"
        + (
            f", the ladder's top at {ds.attrs['max_pga_ratio']:g} times the object's "
            "uplift PGA, unless the record's free fall stopped it lower"
            if "max_pga_ratio" in ds.attrs
            else ""
        )
        + ")"
    )
    return cells, value, what


def _stripe_capacity(ctx):
    """(cells, values, what): the bracket of levels in which each object first overturned
    under each record (the lowest overturning level, in the stripes' measure)."""
    ds = ctx.ds
    im = ds.attrs.get("im", "pga")
    levels = ds["level"].values * si_to_report(ctx.units, im)
    over = ds["overturned"].values == 1  # (record, structure, level)
    first = np.where(over.any(-1), over.argmax(-1), -1).T
    cells = np.empty(first.shape, object)
    for (j, i), k in np.ndenumerate(first):
        if k < 0:
            cells[j, i] = f"above {levels[-1]:.3g}"
        elif k == 0:
            cells[j, i] = f"at or below {levels[0]:.3g}"
        else:
            cells[j, i] = f"{levels[k - 1]:.3g} to {levels[k]:.3g}"
    what = (
        f"the stripe levels, {ctx.stripe_label()}, between which the object first "
        "overturned (the highest level below that it stood at, the lowest it overturned at)"
    )
    return cells, np.where(first >= 0, levels[np.maximum(first, 0)], np.nan), what


def _cloud_capacity(ctx):
    """(cells, values, what): under the unscaled records, whether each object overturned."""
    ds, f = ctx.ds, 1.0 / _unit(ctx)
    over = (ds["overturned"].values == 1).T
    pga = np.broadcast_to(ds["pga"].values * f, over.shape)
    cells = np.where(over, "overturned", "stands").astype(object)
    what = (
        "whether the object overturned under the unscaled record (the governing "
        f"capacity: the lowest PGA [{ctx.units}] of a record that overturned it)"
    )
    return cells, np.where(over, pga, np.nan), what


def object_capacity(page, ctx):
    """A table: the capacity of each object under each record, with the governing record."""
    if not ctx.objects:
        return
    page.heading("Capacity of each object under each record")
    cells, values, what = globals()[ctx.kind.capacity](ctx)
    records = ctx.record_names()
    table = pd.DataFrame(cells, index=list(map(str, ctx.ds["structure"].values)), columns=records)
    table.index.name = "object"
    govern = [  # every record at the lowest capacity (stripes often tie)
        (", ".join(records[k] for k in np.flatnonzero(v == np.nanmin(v))), float(np.nanmin(v)))
        if np.isfinite(v).any()
        else ("", np.nan)
        for v in values
    ]
    # first: a wide table scrolls, and these are what the table is read for
    table.insert(0, "governing capacity", [v for _, v in govern])
    table.insert(0, "governing record(s) (lowest capacity)", [g for g, _ in govern])
    page.table(table, "object_capacity", f"Capacity of each object under each record: {what}")
    if not np.isfinite(values).any():
        page.text("No object overturned under any record: no record governs.")


# ------------------------------------------------------------------------------ curves


def _panels(n):
    cols = min(n, 3)
    rows = -(-n // cols)
    plt = _plt()
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.9 * rows), squeeze=False)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    return fig, axes.ravel()[:n]


def _ida_curve(ax, ctx, i, j, offset):
    """Record i's IDA curve of object j: its simulated points in increasing scale, its
    first overturning (cross) and the switch band above it (shaded)."""
    ds = ctx.ds
    pga = ds["pga"].values[i] / _unit(ctx)
    alpha = float(ds["slenderness"].values[j])
    s = ds["step_scale"].values[i, j]
    ok = np.isfinite(s)
    order = np.argsort(s[ok], kind="stable")
    s = s[ok][order]
    over = ds["step_overturned"].values[i, j][ok][order] == 1
    x = np.where(over, 1.0, np.minimum(ds["step_max_rotation"].values[i, j][ok][order] / alpha, 1))
    cap = ds["capacity_scale"].values[i, j]
    upto = ~(s > cap)
    name = ctx.text(ctx.record_names()[i])
    (line,) = ax.plot(x[upto], s[upto] * pga, "-", lw=1.2, label=name)
    color = line.get_color()
    first = over & upto  # the first overturning; the scan above it drawn faint
    ax.plot(x[first] + offset, s[first] * pga, "x", color=color, ms=5, mew=1.2)
    ax.plot(x[over & ~upto] + offset, s[over & ~upto] * pga, "x", color=color, ms=4, alpha=0.35)
    above = (s > cap) & ~over
    ax.plot(x[above] + offset, s[above] * pga, "o", mfc="none", color=color, ms=5)
    top = ds["highest_survival_scale"].values[i, j]
    if np.isfinite(top) and np.isfinite(cap):
        ax.axhspan(cap * pga, top * pga, color=color, alpha=0.12, lw=0)


#: Margin of an IDA panel's PGA axis around the capacities and the uplift level (a factor
#: on a log axis): the ladder's scan and switch bands above them run off the top.
IDA_AXIS_MARGIN = 1.3


def ida_axis(ctx, j) -> tuple[float, float] | None:
    """The PGA span (report units) of object ``j``'s IDA panel: from its uplift level and
    lowest capacity to its highest capacity (or censoring level), widened by
    :data:`IDA_AXIS_MARGIN`; None when none of these is known."""
    ds = ctx.ds
    cens = ds["censored"].values[:, j] == 1
    scale = np.where(
        cens, ds["capacity_scale_lower"].values[:, j], ds["capacity_scale"].values[:, j]
    )
    values = np.append(scale * ds["pga"].values / _unit(ctx), _uplift(ctx, "pga")[j])
    values = values[np.isfinite(values) & (values > 0)]
    if not values.size:
        return None
    return float(values.min()) / IDA_AXIS_MARGIN, float(values.max()) * IDA_AXIS_MARGIN


def object_curves(page, ctx):
    """Per object: the IDA curves (or the stripe points) of every record, in order of scale."""
    if not ctx.objects or not ctx.kind.text["objects"]:
        return
    page.heading(ctx.kind.text["objects"])
    draw = globals()[ctx.kind.draw]
    names = list(map(str, ctx.ds["structure"].values))
    records = ctx.record_names()
    fig, axes = _panels(len(names))
    spread = 0.015 * (np.arange(len(records)) - (len(records) - 1) / 2)
    uplift = _uplift(ctx, "pga")
    for j, ax in enumerate(axes):
        for i in range(len(records)):
            draw(ax, ctx, i, j, spread[i])
        if np.isfinite(uplift[j]):  # NaN: a cube that does not say it
            ax.axhline(uplift[j], ls=":", lw=1.2, color="0.3")
        ax.set_yscale("log")
        if ctx.kind.capacities and (span := ida_axis(ctx, j)) is not None:
            ax.set_ylim(*span)
        ax.set_xlim(-0.04, 1.08)
        ax.set_title(ctx.text(ctx.structure_title(j)), fontsize=FONT + 1)
        ax.set_xlabel("peak rotation / slenderness, theta_max / alpha [-]", fontsize=FONT + 1)
        ax.set_ylabel(f"PGA of the scaled record [{ctx.units}]", fontsize=FONT + 1)
        ctx.log_ticks(ax, "y")
        ax.tick_params(labelsize=FONT)
    _shared_legend(fig, axes[0], len(records))
    page.figure(
        fig,
        f"object_{ctx.design}",
        "Every object under every record: "
        + ctx.kind.text["objects_note"]
        + "; dotted: the object's uplift level (g tan alpha of a block, g lambda of another "
        "structure); markers of the records are offset "
        "slightly in x so that none hides another",
    )


def _cloud_point(ax, ctx, i, j, offset):
    """Record i's point of block j in a cloud: hollow circle (stood) or cross (overturned)."""
    ds = ctx.ds
    y = ds["pga"].values[i] / _unit(ctx)
    over = bool(ds["overturned"].values[i, j] == 1)
    x = 1.0 if over else min(ds["max_rotation"].values[i, j] / ds["slenderness"].values[j], 1.0)
    style = {"marker": "x", "ms": 6} if over else {"marker": "o", "mfc": "none", "ms": 5}
    ax.plot([x + offset], [y], ls="none", label=_mpl_text(ctx.record_names()[i]), **style)


def _shared_legend(fig, ax, n):
    """One legend of the records below the panels (none hides a curve), then the layout."""
    cols = min(n, 4)
    height = 0.22 * -(-n // cols) + 0.1  # [in]
    fig.legend(*ax.get_legend_handles_labels(), loc="lower center", ncol=cols, fontsize=FONT)
    fig.tight_layout(rect=(0, height / fig.get_figheight(), 1, 1))


def _stripe_points(ax, ctx, i, j, offset):
    ds = ctx.ds
    y = ds["scale"].values[i, j] * ds["pga"].values[i] / _unit(ctx)
    x = ds["max_rotation"].values[i, j] / float(ds["slenderness"].values[j])
    over = ds["overturned"].values[i, j] == 1
    x = np.where(over, 1.0, np.minimum(x, 1.0)) + offset
    order = np.argsort(y)
    name = ctx.text(ctx.record_names()[i])
    (line,) = ax.plot(x[order], y[order], "-", lw=0.8, alpha=0.6, label=name)
    ax.plot(x[~over], y[~over], "o", mfc="none", color=line.get_color(), ms=5)
    ax.plot(x[over], y[over], "x", color=line.get_color(), ms=6, mew=1.2)


# ------------------------------------------------------------------------------ friction


def _ida_scenes(ctx) -> str:
    """What the scenes of an IDA's contact check are, with their PGA range; '' otherwise."""
    ds = ctx.ds
    if not ctx.kind.capacities or "capacity_scale_lower" not in ds:
        return ""
    pga = (ds["capacity_scale_lower"] * ds["pga"]).values / _unit(ctx)
    pga = pga[np.isfinite(pga) & np.isfinite(ds["friction_demand"].values)]
    span = f", here PGA {pga.min():.3g} to {pga.max():.3g} {ctx.units}" if pga.size else ""
    return (
        " (IDA: each scene is a record at the highest scale simulated below the object's first "
        "overturning, or the highest it stood at where it never overturned"
        f"{span}: the strongest shaking each object was seen to stand)"
    )


def friction_check(page, ctx):
    """Per object (or per record for sampled structures): the scenes whose friction demand
    exceeds the friction coefficient or that lift off, with a warning box."""
    ds = ctx.ds
    if "friction_demand" not in ds:
        return
    page.heading("Friction and lift-off: where the block model stops")
    demand = ds["friction_demand"]
    finite = demand.where(np.isfinite(demand))
    lift = ds["lift_off"] == 1
    by = ("structure", "record") if ctx.objects else ("record",)
    rest = [d for d in demand.dims if d not in by]
    table = {
        "scenes": demand.notnull().sum(rest).astype(int),
        "largest finite friction demand |F_h / F_v| [-]": finite.max(rest),
        "lift-offs": lift.sum(rest).astype(int),
    }
    flags = None
    if ctx.friction is not None:
        from ..analysis.contact import friction_array, outside_model

        flags = outside_model(ds, ctx.friction)
        table["friction coefficient mu [-]"] = (
            friction_array(ds, ctx.friction).broadcast_like(demand).max(rest)
        )
        table["scenes outside the model (demand > mu or lift-off)"] = flags.sum(rest).astype(int)
    frame = xr.Dataset(table).to_dataframe(dim_order=list(by))[list(table)]
    names = dict(zip(map(str, ds["record"].values), ctx.record_names(), strict=True))
    if ctx.objects:
        frame.index = [f"{o} / {names[str(r)]}" for o, r in frame.index]
    else:
        frame.index = [names[str(r)] for r in frame.index]
    frame.index.name = "object / record" if ctx.objects else "record"
    top = frame["largest finite friction demand |F_h / F_v| [-]"]
    frame["largest finite friction demand |F_h / F_v| [-]"] = [  # no finite demand: F_v < 0
        "lifted off (F_v < 0)" if np.isnan(v) and n > 0 else v
        for v, n in zip(top, frame["lift-offs"], strict=True)
    ]
    if flags is not None and bool(flags.any()):
        from ..analysis.contact import summary_line

        page.warning(summary_line(ds, ctx.friction) + _ida_scenes(ctx))
    elif flags is not None:
        page.text("No scene needs more friction than mu or lifts off: the block model holds.")
    page.table(
        frame,
        "friction_check",
        "The contact check of each scene: the friction demand max |F_h / F_v| (below uplift "
        "it is max |a_g| / g), the lift-offs and the scenes outside the rocking-block model"
        + ctx.kind.text["friction"],
    )
