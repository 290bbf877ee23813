"""Shared pieces of the report figures: the output type, PNG rendering, palette and layout.

Everything here is stateless: figures are built with ``matplotlib.figure.Figure`` and the
Agg canvas directly (never pyplot), so they can be drawn from several threads or processes.
"""
from __future__ import annotations

import io
import math
import zlib
from dataclasses import dataclass
from typing import Iterable, Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

DPI = 110
WIDTH_IN = 9.5
FONT = 9.5
SMALL = 9.0
# Okabe & Ito (2008) without its yellow, ordered so the first colours are the most distinct on white,
# then three of Paul Tol's colour-blind-safe "muted" colours.
PALETTE = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#000000", "#999933",
           "#882255", "#44AA99")
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "h", "<")
LINESTYLES = ("-", "--", ":", "-.", (0, (5, 1, 1, 1, 1, 1)), (0, (1, 3)))
KNOWN_METHODS = ("ee-time", "ee-smooth", "ee-freq", "oe", "ee-concat", "ee-sequential",
                 "ee-sequential-unequal", "ee-freq-combined")
SPECIAL_METHODS = ("crb", "excursion", "check")
ERRORS_ORDER = ("conventional", "colored", "cramer-rao", "")
ERRORS_HATCH = ("", "//", "..", "xx")
PANEL_COLS = ("campaign", "aircraft", "variant", "condition", "maneuver", "loop", "noise")
FLIGHT_COLS = ("campaign", "aircraft", "variant", "condition", "maneuver", "loop")
MAX_PANELS = 6
MAX_CATEGORIES = 24
MAX_SERIES = 10


@dataclass(frozen=True)
class FigureOut:
    """One rendered figure.

    Attributes
    ----------
    name : str
        Stable identifier, usable as a file stem (``'bias'``, ``'coverage'`` ...).
    caption : str
        One or two plain sentences saying what to look at.
    png : bytes
        The figure as PNG.
    alt : str
        Text alternative describing the chart for screen readers.
    """

    name: str
    caption: str
    png: bytes
    alt: str


def figure_to_png(fig: Figure, dpi: int = DPI) -> bytes:
    """Render a figure to PNG bytes with the Agg canvas.

    Parameters
    ----------
    fig : Figure
        A figure built with the object-oriented API.
    dpi : int
        Resolution; 110 reads well on a laptop screen at 9-10 in wide.

    Returns
    -------
    bytes
        The PNG file (no timestamp or software metadata, so equal figures give equal bytes).
    """
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, metadata={"Software": None}, facecolor="white")
    return buf.getvalue()


def new_figure(height_in: float, width_in: float = WIDTH_IN) -> Figure:
    """A white figure with constrained layout, at most 14 in tall."""
    return Figure(figsize=(width_in, min(max(height_in, 2.5), 14.0)), layout="constrained", facecolor="white")


def style_axes(ax: Axes, grid_axis: str = "both") -> None:
    """Readable ticks, a light grid, no top/right spines."""
    ax.tick_params(labelsize=SMALL)
    ax.grid(True, axis=grid_axis, alpha=0.3, linewidth=0.6)
    ax.spines["top"].set_visible(False)
    ax.spines["right"].set_visible(False)


def done(fig: Figure, name: str, caption: str, alt: str) -> FigureOut:
    """Render ``fig`` and wrap it."""
    return FigureOut(name=name, caption=" ".join(caption.split()), png=figure_to_png(fig), alt=" ".join(alt.split()))


def is_empty(df: pd.DataFrame | None, columns: Iterable[str] = ()) -> bool:
    """True when ``df`` is missing, has no rows or lacks one of ``columns``."""
    return df is None or not isinstance(df, pd.DataFrame) or df.empty or any(c not in df.columns for c in columns)


def numeric(df: pd.DataFrame, columns: Iterable[str]) -> pd.DataFrame:
    """A copy of ``df`` with ``columns`` (those present) as float, bad values as NaN."""
    out = df.copy()
    for c in columns:
        if c in out.columns:
            out[c] = pd.to_numeric(out[c], errors="coerce").astype(float)
    return out


def method_order(methods: Iterable[str]) -> list[str]:
    """Known methods in their canonical order, then the others alphabetically."""
    ms = {str(m) for m in methods}
    return [m for m in KNOWN_METHODS if m in ms] + sorted(ms - set(KNOWN_METHODS))


def method_color(method: str, present: Sequence[str] = ()) -> str:
    """A stable colour: known methods keep theirs in every figure, others follow."""
    if method in KNOWN_METHODS:
        return PALETTE[KNOWN_METHODS.index(method) % len(PALETTE)]
    others = sorted(set(present) - set(KNOWN_METHODS))
    i = others.index(method) if method in others else zlib.crc32(method.encode())
    return PALETTE[(len(KNOWN_METHODS) + i) % len(PALETTE)]


def errors_rank(errors: str) -> int:
    """Position of an error type in the preferred order."""
    return ERRORS_ORDER.index(errors) if errors in ERRORS_ORDER else len(ERRORS_ORDER)


SCORE_NUMBERS = ("truth", "mean", "bias", "bias_pct", "bias_mcse", "bias_z", "std", "rmse", "mean_se", "se_ratio",
                 "coverage", "coverage_lo", "coverage_hi", "time_s", "max_corr", "crb", "efficiency")


def finite_scores(scores: pd.DataFrame) -> pd.DataFrame:
    """Estimation score rows with a finite truth (drops bias terms and special methods).

    Optional columns that are absent are added (numbers as NaN, labels as '') so that the
    figures need not test for each.
    """
    s = numeric(scores, SCORE_NUMBERS)
    for c in SCORE_NUMBERS:
        if c not in s:
            s[c] = np.nan
    for c in ("errors", "equation"):
        if c not in s:
            s[c] = ""
    if "method" in s:
        s = s[~s["method"].astype(str).isin(SPECIAL_METHODS)]
    if "truth" in s:
        s = s[np.isfinite(s["truth"].to_numpy(float))]
    for c in ("errors", "equation", "method", "parameter"):
        if c in s:
            s[c] = s[c].fillna("").astype(str)
    return s.reset_index(drop=True)


def collapse_errors(s: pd.DataFrame) -> pd.DataFrame:
    """Keep one error type per method where the estimates do not depend on it.

    The error type changes only the reported standard errors of most methods, so bias,
    scatter and RMSE would repeat; a method keeps several error types only when the mean
    estimates of its cells differ between them.
    """
    if s.empty or "errors" not in s or s["errors"].nunique() <= 1:
        return s
    keys = [c for c in PANEL_COLS + ("equation", "parameter") if c in s]
    keep = []
    for _, g in s.groupby("method", sort=False):
        kinds = sorted(g["errors"].unique(), key=errors_rank)
        if len(kinds) > 1:
            piv = g.pivot_table(index=keys, columns="errors", values="mean", aggfunc="first", dropna=False)
            a = piv.to_numpy(float)
            if np.allclose(a, a[:, [0]], rtol=1e-9, atol=0.0, equal_nan=True):
                g = g[g["errors"] == kinds[0]]
        keep.append(g)
    return pd.concat(keep)


def add_series(s: pd.DataFrame) -> tuple[pd.DataFrame, list[str], str]:
    """Add a ``series`` label (method, plus error type where a method has several).

    Returns the frame, the series in display order (at most ``MAX_SERIES``; the frame keeps
    only those) and a caption sentence when some were left out ('' otherwise).
    """
    s = s.copy()
    if "errors" not in s:
        s["errors"] = ""
    multi = s.groupby("method")["errors"].nunique()
    s["series"] = [f"{m} ({e})" if multi.get(m, 1) > 1 and e else m for m, e in zip(s["method"], s["errors"])]
    mo = method_order(s["method"].unique())
    order = sorted(s[["method", "errors", "series"]].drop_duplicates().itertuples(index=False),
                   key=lambda r: (mo.index(r.method), errors_rank(r.errors)))
    names = [r.series for r in order]
    note = (f" Only the first {MAX_SERIES} of {len(names)} methods are shown." if len(names) > MAX_SERIES else "")
    names = names[:MAX_SERIES]
    return s[s["series"].isin(names)], names, note


def series_style(series: str, s: pd.DataFrame, methods: Sequence[str]) -> tuple[str, str, str]:
    """Colour (by method), hatch and marker (by error type, where a method has several) of a series."""
    row = s.loc[s["series"] == series].iloc[0]
    several = s.loc[s["method"] == row["method"], "series"].nunique() > 1
    e = errors_rank(str(row["errors"])) if several else 0
    return (method_color(str(row["method"]), methods), ERRORS_HATCH[e % len(ERRORS_HATCH)],
            MARKERS[e % len(MARKERS)])


def panels(df: pd.DataFrame, max_panels: int = MAX_PANELS,
           cols: Sequence[str] = PANEL_COLS) -> tuple[list[tuple[str, pd.DataFrame]], int]:
    """Split ``df`` by the experiment columns that vary; at most ``max_panels`` panels.

    Returns the (title, rows) of the panels kept and the number there were.
    """
    vary = [c for c in cols if c in df and df[c].nunique(dropna=False) > 1]
    if not vary:
        fixed = [f"{c} {df[c].iloc[0]}" for c in ("maneuver", "noise") if c in df and str(df[c].iloc[0])]
        return [(", ".join(fixed), df)], 1
    groups = list(df.groupby(vary, sort=False, dropna=False))
    seen = [list(dict.fromkeys(df[c].astype(str))) for c in vary]

    def rank(kg: tuple) -> tuple:
        # in order of appearance, column by column; within a flight the noise-free case first
        key = kg[0] if isinstance(kg[0], tuple) else (kg[0],)
        return tuple((0 if c == "noise" and str(k) == "none" else 1, order.index(str(k)))
                     for c, k, order in zip(vary, key, seen))

    groups.sort(key=rank)
    out = []
    for key, g in groups[:max_panels]:
        key = key if isinstance(key, tuple) else (key,)
        out.append((", ".join(f"{c} {v}" for c, v in zip(vary, key)), g))
    return out, len(groups)


def categories(g: pd.DataFrame, limit: int = MAX_CATEGORIES) -> tuple[pd.Series, list[str], int]:
    """Category label per row (the parameter, with its equation when a parameter is in
    several), the labels to show in order and how many there were."""
    eqs = g.groupby("parameter")["equation"].nunique() if "equation" in g else pd.Series(dtype=int)
    dup = set(eqs[eqs > 1].index)
    lab = [f"{p}\n[{e.split('=', 1)[-1].strip()}]" if p in dup else p
           for p, e in zip(g["parameter"], g["equation"] if "equation" in g else [""] * len(g))]
    lab = pd.Series(lab, index=g.index)
    order = list(dict.fromkeys(lab))
    return lab, order[:limit], len(order)


def grid(fig: Figure, n: int, max_cols: int = 2, sharey: bool = False) -> list[Axes]:
    """``n`` axes on a grid of at most ``max_cols`` columns."""
    ncols = min(max_cols, n)
    nrows = math.ceil(n / ncols)
    axes = fig.subplots(nrows, ncols, squeeze=False, sharey=sharey).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return list(axes[:n])


def log_ticks(ax: Axes, values: np.ndarray) -> None:
    """Plain numbers (0.5, 1, 2) on a log y axis; minor labels when it spans little."""
    v = values[np.isfinite(values) & (values > 0)]
    plain = FuncFormatter(lambda x, _: f"{x:g}")
    ax.yaxis.set_major_formatter(plain)
    if v.size and np.log10(max(v.max(), 1.0) / min(v.min(), 1.0)) < 1.5:
        ax.yaxis.set_minor_locator(LogLocator(subs=(2.0, 3.0, 5.0)))
        ax.yaxis.set_minor_formatter(plain)
    else:
        ax.yaxis.set_minor_formatter(NullFormatter())


def _rotation(order: list[str], max_cols: int) -> int:
    """0 when the category labels fit side by side, else 35 degrees."""
    avail = (WIDTH_IN / max_cols - 0.9) / max(len(order), 1)
    need = max((max(len(x) for x in c.split("\n")) for c in order), default=0) / 12.0
    return 0 if need < 0.9 * avail else 35


def dodged(fig: Figure, parts: list[tuple[str, pd.DataFrame]], series: list[str], s: pd.DataFrame, *,
           y: str, lo: str | None, hi: str | None, ylabel: str, kind: str = "dot", log: bool = False,
           ref: float | None = None, ref_label: str = "", max_cols: int = 1, min_span: float = 0.0) -> list[str]:
    """Draw one panel per part: categories along x, the series side by side.

    ``y`` is plotted with an error bar from ``lo`` to ``hi`` (absolute values, NaN for none).
    A linear axis spans at least ``±min_span`` about ``ref`` (so rounding noise does not
    fill a panel). Returns notes for the caption (categories left out, values not drawable
    on a log axis).
    """
    methods = list(s["method"].unique())
    notes: list[str] = []
    axes = grid(fig, len(parts), max_cols)
    m = len(series)
    width = 0.8 / max(m, 1)
    dropped_log, most = 0, 0
    for ax, (title, g) in zip(axes, parts):
        lab, order, total = categories(g)
        if total > len(order):
            most = max(most, total)
        pos = {c: i for i, c in enumerate(order)}
        for j, name in enumerate(series):
            rows = g[(g["series"] == name) & lab.isin(pos).to_numpy()]
            if rows.empty:
                continue
            x = lab[rows.index].map(pos).to_numpy(float) + (j - (m - 1) / 2) * width
            v = rows[y].to_numpy(float)
            ok = np.isfinite(v) & ((v > 0) if log else True)
            dropped_log += int(np.sum(np.isfinite(v) & ~ok))
            x, v, rows = x[ok], v[ok], rows[ok]
            color, hatch, marker = series_style(name, s, methods)
            if kind == "bar":
                ax.bar(x, v, width * 0.95, color=color, hatch=hatch, edgecolor="white" if not hatch else "#333333",
                       linewidth=0.4, zorder=2)
            else:
                ax.plot(x, v, linestyle="none", marker=marker, color=color, markersize=5, zorder=3)
            if lo and hi:
                a, b = rows[lo].to_numpy(float), rows[hi].to_numpy(float)
                fin = np.isfinite(a) & np.isfinite(b)
                if log:
                    fin &= (a > 0) & (b > 0)
                if fin.any():
                    ax.errorbar(x[fin], v[fin], yerr=[np.maximum(v[fin] - a[fin], 0), np.maximum(b[fin] - v[fin], 0)],
                                fmt="none", ecolor="#222222" if kind == "bar" else color, elinewidth=0.9,
                                capsize=2, zorder=4)
        if ref is not None:
            ax.axhline(ref, color="#444444", linestyle="--", linewidth=1.0, zorder=1)
        if log:
            ax.set_yscale("log")
            log_ticks(ax, g[y].to_numpy(float))
        elif min_span > 0:
            a, b = ax.get_ylim()
            c = ref or 0.0
            ax.set_ylim(min(a, c - min_span), max(b, c + min_span))
        ax.set_xticks(range(len(order)))
        rot = _rotation(order, max_cols)
        ax.set_xticklabels(order, rotation=rot, ha="right" if rot else "center", fontsize=SMALL)
        ax.set_xlim(-0.6, len(order) - 0.4)
        ax.set_title(title, fontsize=FONT)
        ax.set_ylabel(ylabel, fontsize=FONT)
        style_axes(ax, "y")
    handles = []
    for name in series:
        color, hatch, marker = series_style(name, s, methods)
        if kind == "bar":
            handles.append(Patch(facecolor=color, hatch=hatch, edgecolor="#333333" if hatch else color, label=name))
        else:
            handles.append(Line2D([], [], color=color, marker=marker, linestyle="none", label=name))
    if ref is not None and ref_label:
        handles.append(Line2D([], [], color="#444444", linestyle="--", label=ref_label))
    fig.legend(handles=handles, loc="outside upper center", ncols=min(len(handles), 5), fontsize=SMALL,
               frameon=False)
    if most:
        notes.append(f"Only the first {MAX_CATEGORIES} of {most} parameters are shown per panel.")
    if dropped_log:
        notes.append(f"{dropped_log} values that are zero or negative cannot be drawn on the log scale.")
    return notes


def panel_note(shown: int, total: int) -> str:
    """Caption sentence for panels left out."""
    return f" Only the first {shown} of {total} panels are shown." if total > shown else ""


def fmt(v: float, digits: int = 3) -> str:
    """A number for a caption."""
    return "n/a" if v is None or not np.isfinite(v) else f"{v:.{digits}g}"
