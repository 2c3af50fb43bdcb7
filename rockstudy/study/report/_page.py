"""The HTML page shared by the reports (:mod:`.sampled`, :mod:`.records`): sections,
escaped text, tables as the page shows them (CSV beside), and figures embedded as PNG."""

from __future__ import annotations

import base64
import contextlib
import html
import io
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from ..._warnings import SeparationWarning
from ..running.store import open_result


def dataset_of(data, what: str, verify: bool = True) -> tuple[xr.Dataset, str | None]:
    """(the Dataset, the name of its file or None) of a report's input ``data``: an
    :class:`xarray.Dataset` as it is, or the path of a result cube, read with
    :func:`~rockstudy.study.running.store.open_result` (``verify`` its checksums); a
    TypeError naming ``what`` otherwise."""
    if isinstance(data, xr.Dataset):
        return data, None
    if isinstance(data, (str, Path)) or hasattr(data, "__fspath__"):
        path = Path(data)
        return open_result(path, verify=verify).load(), path.stem  # a missing cube: no folder
    raise TypeError(
        f"{what} must be an xarray.Dataset or the path of a result cube, got {type(data).__name__}"
    )


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _shown(value):
    """A table cell as the page shows it: counts as integers, other numbers with three
    significant figures, text as it is."""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return "" if np.isnan(value) else f"{value:.3g}"
    return value


def curve_note(inside, separated, no_rise=False) -> str:
    """The legend's words on a fitted curve: why it is dashed (median outside the data) or
    missing (outcomes separated, or not rising with the intensity: no fit), else none."""
    if separated:
        return " (outcomes separated: no fit)"
    if no_rise:
        return " (no rise with the intensity: no fit)"
    return "" if inside else " (median outside the data)"


def draw_fits(ax, grid, curve, table, ticks) -> bool:
    """The curves of a fragility ``table`` (``curve``: :func:`fragility_curve` on ``grid``) on
    a logarithmic ``ax`` with their bands, dashed where the median lies outside the data,
    labelled with :func:`curve_note`; False, with ``ax`` hidden, when no group has a curve
    (every one separated or without a fit). ``ticks`` labels the log axis."""
    if not np.isfinite(curve["probability"].values).any():
        ax.set_visible(False)
        return False
    flags = zip(
        curve.group.values,
        table["theta_in_range"],
        table["separated"],
        table["no_rise"],
        strict=True,
    )
    for g, inside, separated, no_rise in flags:
        c = curve.sel(group=g)
        note = curve_note(inside, separated, no_rise)
        ax.plot(grid, c.probability, "-" if inside else "--", label=f"{g}{note}")
        ax.fill_between(grid, c.lower, c.upper, alpha=0.2)
    ax.set_xscale("log")
    ticks(ax)
    ax.legend(fontsize=8)
    return True


@contextlib.contextmanager
def shown_separation():
    """A context in which :class:`~rockstudy.SeparationWarning` is not repeated on the console:
    for the fits whose separated groups the page names (:func:`separation_note`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SeparationWarning)
        yield


def _named(table, column) -> str:
    """The groups of ``table`` flagged in ``column``, listed in words ("" for none)."""
    if column not in table:
        return ""
    return ", ".join(str(g) for g in table.index[table[column].to_numpy(bool)])


def separation_note(page, table, what) -> None:
    """A boxed warning naming the groups of a fragility ``table`` whose outcomes are
    separated in the intensity (column ``separated``) or do not rise with it (``no_rise``),
    in words: why they have no curve."""
    if flat := _named(table, "no_rise"):
        page.warning(
            f"{what}: the points of {flat} at which the block overturned do not lie higher in "
            "the intensity, on average, than those at which it stood: no increasing "
            "fragility curve fits them (the likelihood has no maximum), so neither the "
            "median nor beta is estimated and no curve is drawn."
        )
    groups = _named(table, "separated")
    if not groups:
        return
    page.warning(
        f"{what}: the outcomes of {groups} are separated in the intensity: every "
        "point that overturned lies at or above every point that stood. The likelihood then "
        "has no maximum, so the dispersion beta cannot be estimated and no curve is drawn; "
        "the data only bound the median between the highest intensity at which the block "
        "stood and the lowest at which it overturned (the lower and upper median columns). "
        "Points between these two intensities would make the fit identifiable."
    )


class _Page:
    def __init__(self, out: Path):
        self.out = out
        self.parts = []
        self.figures = 0

    def heading(self, text):
        self.parts.append(f"<h2>{html.escape(text)}</h2>")

    def text(self, text):
        self.parts.append(f"<p>{html.escape(text)}</p>")

    def warning(self, text):
        """A boxed warning (escaped): what makes the results below less trustworthy."""
        self.parts.append(f"<div class='warn'><b>Warning:</b> {html.escape(text)}</div>")

    def preformatted(self, text):
        self.parts.append(f"<pre>{html.escape(text)}</pre>")

    def table(self, frame: pd.DataFrame, name: str, caption: str, hide_empty=(), show=None):
        """``frame`` into ``name``.csv and onto the page: its columns ``show`` (default all),
        less those of ``hide_empty`` that hold nothing (all NaN); the CSV keeps them all."""
        frame.to_csv(self.out / f"{name}.csv")
        self.parts.append(
            f"<p class='cap'>{html.escape(caption)} (<a href='{name}.csv'>{name}.csv</a>)</p>"
        )
        frame = frame if show is None else frame[[c for c in frame if c in show]]
        frame = frame.drop(columns=[c for c in hide_empty if c in frame and frame[c].isna().all()])
        shown = frame.map(_shown).rename(index=_shown, columns=_shown)
        # to_html escapes every cell; a table wider than the page scrolls inside its box
        self.parts.append(f"<div class='wide'>{shown.to_html(classes='t')}</div>")

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
            # a wide table may use the whole width of a 1,400-pixel page, and its headings
            # wrap between words (row headings do not)
            ".wide{overflow-x:auto;width:min(1360px,100vw - 20px);position:relative;"
            "left:50%;transform:translateX(-50%)}"
            "table.t{margin:auto}table.t thead th{overflow-wrap:break-word}"
            "table.t tbody th{white-space:nowrap}"
            "table.t td,table.t th{border:1px solid #ccc;padding:2px 6px}"
            ".cap{color:#555}.warn{border:2px solid #c60;background:#fff4e5;padding:6px 10px;"
            "margin:8px 0}</style></head><body>"
        )
        # a check for headless browsers, invisible to the reader: the count of decoded figures
        # goes into the body's data-figures attribute ("shown/total")
        check = (
            "<script>window.addEventListener('load',()=>{const im=[...document.images];"
            "const ok=im.filter(i=>i.complete&&i.naturalWidth>0).length;"
            "document.body.dataset.figures=ok+'/'+im.length;});</script>"
        )
        body = f"<h1>{html.escape(title)}</h1>{meta}" + "".join(self.parts) + check
        path = self.out / "index.html"
        path.write_text(head + body + "</body></html>")
        return path


def _names(ds) -> list[str]:
    """Record names as text (a cube may store them as bytes)."""
    values = ds["record_name"].values if "record_name" in ds.coords else ds["record"].values
    return [v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v) for v in values]


def _log_ticks(ax, axis="x"):
    """Plain-number labels (0.2, 1, 5) on a logarithmic axis, with as many minor labels
    (mantissas 2 and 5, then 2, 3, 5 and 7, then every one) as needed for at least three
    numbered ticks; an axis too short even for that (under about a third of a decade) gets
    three to five evenly spaced numbered ticks instead. Every axis is read without counting
    decades. Call it after plotting."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator, NullFormatter

    lo, hi = ax.get_xlim() if axis == "x" else ax.get_ylim()
    target = ax.xaxis if axis == "x" else ax.yaxis
    labelled, enough = [], not hi > lo > 0
    for mantissas in ((1.0,), (1.0, 2.0, 5.0), (1.0, 2.0, 3.0, 5.0, 7.0), tuple(range(1, 10))):
        if enough:
            break
        labelled = [float(m) for m in mantissas]
        decades = 10.0 ** np.arange(np.floor(np.log10(lo)), np.ceil(np.log10(hi)) + 1)
        ticks = np.outer(decades, labelled).ravel()
        enough = ((ticks >= lo) & (ticks <= hi)).sum() >= 3

    def minor(v, _):
        mantissa = v / 10.0 ** np.floor(np.log10(v)) if v > 0 else 0.0
        return f"{v:g}" if np.isclose(mantissa, labelled).any() else ""

    target.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    target.set_minor_formatter(FuncFormatter(minor))
    if not enough:  # a short span: evenly spaced round numbers
        ticks = MaxNLocator(4).tick_values(lo, hi)
        target.set_major_locator(FixedLocator(ticks[(ticks >= lo) & (ticks <= hi)]))
        target.set_minor_formatter(NullFormatter())
    ax.tick_params(axis=axis, which="both", labelsize=8)


def object_colors(names) -> dict[str, tuple]:
    """One colour per object, keyed by its name: matplotlib's tab10 (tab20 beyond ten
    objects, repeating beyond twenty) given in the sorted order of the names, so that every
    figure of a report that is given the same objects, in any order (a ranking, a subset
    drawn), colours each object alike."""
    from matplotlib import colormaps

    unique = sorted({str(n) for n in names})
    cmap = colormaps["tab10" if len(unique) <= 10 else "tab20"]
    return {n: cmap(k % cmap.N) for k, n in enumerate(unique)}


def _mpl_text(text: str) -> str:
    """Text for a matplotlib label: a '$' from a file must not start mathtext."""
    return text.replace("$", r"\$")


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


_FRAGILITY_NAMES = {
    "theta": "median capacity",
    "beta": "beta (MLE)",
    "theta_lo": "median capacity, lower",
    "theta_hi": "median capacity, upper",
    "beta_lo": "beta, lower",
    "beta_hi": "beta, upper",
    "n": "samples",
    "im_min": "lowest intensity",
    "im_max": "highest intensity",
    "theta_in_range": "median within the samples",
    "band_in_range": "band within the samples",
    "separated": "outcomes separated (no fit)",
    "no_rise": "no rise with the intensity (no fit)",
    "band": "subset of the samples",
    "lack_of_fit_p": "lognormal vs data, p (lack of fit)",
}
