"""Figures across experiments: bias against collinearity (seed Fig. 7), accuracy against
cost, and the nightly trend."""
from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.dates import AutoDateLocator, ConciseDateFormatter
from matplotlib.lines import Line2D

from reports.figures_common import (FLIGHT_COLS, FONT, LINESTYLES, MARKERS, SMALL, FigureOut, add_series,
                                    collapse_errors, done, errors_rank, finite_scores, fmt, is_empty, log_ticks,
                                    method_color, new_figure, series_style, style_axes)

NOISE_FREE = "none"


def _pick_parameter(s: pd.DataFrame, parameter: str | None, default: str = "Cm_alpha") -> str | None:
    present = list(dict.fromkeys(s["parameter"]))
    if parameter is not None:
        return parameter if parameter in present else None
    return default if default in present else (present[0] if present else None)


def _x_correlation(s: pd.DataFrame) -> pd.Series:
    """Each row's flight correlation: the noise-free cell's max_corr (same method and error
    type, else the median over the noise-free cells of the flight), else its own."""
    fcols = [c for c in FLIGHT_COLS if c in s] + ["equation"]
    x = s["max_corr"].copy()
    if "noise" not in s:
        return x
    clean = s[s["noise"].astype(str) == NOISE_FREE]
    if clean.empty:
        return x
    exact = clean.groupby(fcols + ["method", "errors"], dropna=False)["max_corr"].median().rename("_x1")
    anyref = clean.groupby(fcols, dropna=False)["max_corr"].median().rename("_x2")
    m = s[fcols + ["method", "errors"]].merge(exact.reset_index(), how="left", on=fcols + ["method", "errors"])
    m = m.merge(anyref.reset_index(), how="left", on=fcols)
    ref = m["_x1"].fillna(m["_x2"]).to_numpy(float)
    return pd.Series(np.where(np.isfinite(ref), ref, x.to_numpy(float)), index=s.index)


def fig_bias_vs_correlation(scores: pd.DataFrame | None, parameter: str | None = None) -> FigureOut | None:
    """Bias of one parameter against the largest pairwise regressor correlation (seed Fig. 7).

    Parameters
    ----------
    scores : DataFrame
        The score table.
    parameter : str, optional
        The parameter; default ``'Cm_alpha'`` when present, else the first with a truth. An
        explicitly named parameter that is absent gives None.

    Returns
    -------
    FigureOut or None
        One line per noise level and method, one point per flight; x is the flight's
        noise-free correlation where a noise-free cell exists, else the cell's own.
    """
    if is_empty(scores, ["method", "parameter", "bias_pct", "max_corr", "truth"]):
        return None
    s = finite_scores(scores)
    s = s[np.isfinite(s["bias_pct"].to_numpy(float))]
    p = _pick_parameter(s, parameter)
    if p is None:
        return None
    s = s[s["parameter"] == p]
    s, series, more = add_series(collapse_errors(s))
    s["x"] = _x_correlation(s)
    s = s[np.isfinite(s["x"].to_numpy(float)) & np.isfinite(s["bias_pct"].to_numpy(float))]
    if s.empty:
        return None
    series = [n for n in series if (s["series"] == n).any()]
    noises = list(dict.fromkeys(s["noise"].astype(str))) if "noise" in s else [""]
    noises = noises[:len(LINESTYLES)]
    fig = new_figure(5.2)
    ax = fig.subplots()
    methods = list(s["method"].unique())
    worst = (0.0, "", float("nan"))
    keys = ["series", "noise", "equation"] if "noise" in s else ["series", "equation"]
    for key, g in s.groupby(keys, sort=False):
        noise = str(key[1]) if "noise" in s else ""
        if noise not in noises:
            continue
        g = g.sort_values("x")
        color, _, marker = series_style(str(key[0]), s, methods)
        x, y = g["x"].to_numpy(float), g["bias_pct"].to_numpy(float)
        err = ((200.0 * g["bias_mcse"] / g["truth"].abs()).to_numpy(float) if "bias_mcse" in g
               else np.full(len(g), np.nan))
        ax.errorbar(x, y, yerr=np.where(np.isfinite(err), err, 0.0), color=color, marker=marker, markersize=4,
                    linestyle=LINESTYLES[noises.index(noise)], linewidth=1.4, capsize=2, elinewidth=0.7)
        i = int(np.argmax(np.abs(y)))
        if abs(y[i]) > abs(worst[0]):
            worst = (float(y[i]), f"{key[0]} with noise '{noise}'", float(x[i]))
    ax.axhline(0.0, color="#444444", linewidth=0.8)
    ax.axvline(0.9, color="#444444", linestyle=":", linewidth=1.0)
    ax.text(0.9, 1.0, " |r| = 0.9", transform=ax.get_xaxis_transform(), fontsize=SMALL, va="top", color="#444444")
    lo = float(np.nanmin(s["x"]))
    ax.set_xlim(max(0.0, min(lo, 0.88) - 0.02), 1.005)
    ax.set_xlabel("largest pairwise regressor correlation |r| (Eq. 50)", fontsize=FONT)
    ax.set_ylabel(f"bias of {p} (% of truth)", fontsize=FONT)
    style_axes(ax)
    handles = [Line2D([], [], color=series_style(n, s, methods)[0], marker=series_style(n, s, methods)[2], label=n)
               for n in series]
    handles += [Line2D([], [], color="#666666", linestyle=LINESTYLES[i], label=f"noise {n}")
                for i, n in enumerate(noises) if len(noises) > 1 or n]
    ax.legend(handles=handles, fontsize=SMALL, loc="best", ncols=2 if len(handles) > 6 else 1, framealpha=0.85)
    ref = " (from its noise-free run)" if "noise" in s and (s["noise"].astype(str) == NOISE_FREE).any() else ""
    verdict = (f" The largest bias is {worst[1]}: {fmt(worst[0], 2)} % at |r| = {fmt(worst[2], 3)}."
               if worst[1] else "")
    caption = (f"Each line is one method at one noise level, one point per flight, with ±2 Monte Carlo standard "
               f"errors; x is the flight's largest regressor correlation{ref}. The seed's rule of thumb: beyond "
               f"|r| ≈ 0.9 (dotted) collinearity degrades the estimates." + verdict + more)
    alt = f"Line chart of the bias of {p} in percent against the maximum regressor correlation for {', '.join(series)}."
    return done(fig, "bias_vs_correlation", caption, alt)


def fig_accuracy_vs_cost(scores: pd.DataFrame | None) -> FigureOut | None:
    """Median relative RMSE against mean time per estimate, one marker per method and error type.

    Parameters
    ----------
    scores : DataFrame
        The score table (``rmse``, ``truth``, ``time_s``).

    Returns
    -------
    FigureOut or None
        A log-log scatter, markers labelled; down and to the left is better.
    """
    if is_empty(scores, ["method", "rmse", "time_s", "truth"]):
        return None
    s = finite_scores(scores)
    s = s[s["truth"] != 0]
    if s.empty:
        return None
    s, series, more = add_series(s)
    s["rel"] = s["rmse"] / s["truth"].abs()
    agg = s.groupby("series").agg(rel=("rel", "median"), t=("time_s", "mean"), method=("method", "first"),
                                  errors=("errors", "first"))
    ok = np.isfinite(agg["rel"]) & np.isfinite(agg["t"]) & (agg["rel"] > 0) & (agg["t"] > 0)
    left_out = [n for n in agg.index[~ok]]
    agg = agg[ok].reindex([n for n in series if n in agg.index[ok]])
    if agg.empty:
        return None
    fig = new_figure(5.0)
    ax = fig.subplots()
    methods = list(agg["method"])
    spot = agg.assign(kx=np.round(np.log10(agg["t"]), 2), ky=np.round(np.log10(agg["rel"]), 2))
    for name, row in agg.iterrows():
        several = (agg["method"] == row.method).sum() > 1
        ax.plot([row.t], [100 * row.rel], linestyle="none", markersize=8, color=method_color(row.method, methods),
                marker=MARKERS[errors_rank(row.errors) % len(MARKERS) if several else 0])
    for _, g in spot.groupby(["kx", "ky"], sort=False):  # one label for markers on the same spot
        ax.annotate(", ".join(g.index), (g["t"].iloc[0], 100 * g["rel"].iloc[0]), xytext=(7, 4),
                    textcoords="offset points", fontsize=SMALL)
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_ticks(ax, 100 * agg["rel"].to_numpy(float))
    ax.margins(x=0.25, y=0.2)
    ax.set_xlabel("mean time per estimate (s)", fontsize=FONT)
    ax.set_ylabel("median RMSE (% of |truth|)", fontsize=FONT)
    style_axes(ax)
    best, fast = agg["rel"].idxmin(), agg["t"].idxmin()
    caption = (f"Each marker is a method: the median over all its cells and parameters of the RMSE relative to the "
               f"truth against the mean time per estimate; lower and further left is better. Most accurate: {best} "
               f"({fmt(100 * agg.loc[best, 'rel'], 2)} %); fastest: {fast} ({fmt(1e3 * agg.loc[fast, 't'], 2)} ms).")
    if left_out:
        caption += f" Left out for lack of finite values: {', '.join(left_out)}."
    caption += more
    alt = "Log-log scatter of median relative RMSE against mean time per estimate for " + ", ".join(agg.index) + "."
    return done(fig, "accuracy_vs_cost", caption, alt)


def fig_trend(history: pd.DataFrame | None, nights: int = 30, nominal: float = 0.95) -> FigureOut | None:
    """Nightly trend of the median coverage and median |bias z| per method.

    Parameters
    ----------
    history : DataFrame
        Score rows of many runs with ``run_id`` and ``start`` (ISO time) columns.
    nights : int
        How many of the latest runs to show.
    nominal : float
        The nominal coverage (dashed line).

    Returns
    -------
    FigureOut or None
        Two panels against the run's start date.
    """
    if is_empty(history, ["run_id", "start", "method", "coverage", "bias_z", "truth"]):
        return None
    h = finite_scores(history)
    if h.empty:
        return None
    runs = h[["run_id", "start"]].drop_duplicates("run_id").copy()
    runs["when"] = pd.to_datetime(runs["start"], errors="coerce", utc=True, format="ISO8601")
    runs = runs.sort_values(["when", "start"], na_position="first").tail(max(int(nights), 1))
    h = h[h["run_id"].isin(runs["run_id"])]
    h, series, more = add_series(h)
    h["abs_z"] = h["bias_z"].abs()
    agg = h.groupby(["series", "run_id"]).agg(cov=("coverage", "median"), z=("abs_z", "median"),
                                              method=("method", "first"), errors=("errors", "first")).reset_index()
    agg = agg.merge(runs, on="run_id")
    single = len(runs) == 1  # one night: a date axis would span microseconds; one labelled position instead
    dated = bool(agg["when"].notna().all()) and not single
    if not dated:
        agg["when"] = agg["run_id"].map({r: i for i, r in enumerate(runs["run_id"])})
    fig = new_figure(6.2)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    methods = list(agg["method"].unique())
    same_bias = set(collapse_errors(h)["series"])  # error types that only change the bounds share one bias line
    for name in series:
        g = agg[agg["series"] == name].sort_values("when")
        if g.empty:
            continue
        color, _, marker = series_style(name, h, methods)
        style = dict(color=color, linewidth=1.4, markersize=4, marker=marker, label=name)
        ax1.plot(g["when"], g["cov"], **style)
        if name in same_bias:
            ax2.plot(g["when"], g["z"], **style)
    ax1.axhline(nominal, color="#444444", linestyle="--", linewidth=1.0)
    ax2.axhline(2.0, color="#444444", linestyle=":", linewidth=1.0)
    ax1.set_ylabel("median coverage", fontsize=FONT)
    ax2.set_ylabel("median |bias z|", fontsize=FONT)
    ax2.set_xlabel("run start (UTC)" if dated or single else "run (oldest to newest)", fontsize=FONT)
    if dated:
        loc = AutoDateLocator()
        ax2.xaxis.set_major_locator(loc)
        ax2.xaxis.set_major_formatter(ConciseDateFormatter(loc))
    elif single:
        when = runs["when"].iloc[0]
        ax2.set_xlim(-1.0, 1.0)
        ax2.set_xticks([0.0], [f"{when:%Y-%m-%d %H:%M}" if pd.notna(when) else str(runs["run_id"].iloc[0])])
    for ax in (ax1, ax2):
        style_axes(ax)
    fig.legend(*ax1.get_legend_handles_labels(), loc="outside upper center", ncols=min(len(series), 5),
               fontsize=SMALL, frameon=False)
    change = ""
    if len(runs) > 1:
        last, prev = runs["run_id"].iloc[-1], runs["run_id"].iloc[-2]
        piv = agg.pivot_table(index="series", columns="run_id", values="cov")
        if last in piv and prev in piv:
            d = (piv[last] - piv[prev]).dropna()
            if len(d) and abs(d).max() > 0:
                k = abs(d).idxmax()
                change = (f" Largest change of coverage since the previous run: {k}, {fmt(piv.loc[k, prev], 2)} → "
                          f"{fmt(piv.loc[k, last], 2)}.")
    span = (f"{runs['when'].iloc[0]:%Y-%m-%d} to {runs['when'].iloc[-1]:%Y-%m-%d}" if dated
            else f"{len(runs)} runs")
    if single:
        span = ax2.get_xticklabels()[0].get_text() + " UTC"
        change = " Only one run so far: the trend starts with the next one." + change
    caption = (f"Median over parameters of each method's coverage (top, nominal {nominal:g} dashed) and of its "
               f"|bias| in Monte Carlo standard errors (bottom, 2 dotted), per nightly run "
               f"({len(runs)} run{'s' if len(runs) > 1 else ''}, {span}); "
               "a step down in coverage or up in |bias z| flags a regression." + change + more)
    alt = (f"Two line charts over {len(runs)} runs of median coverage and median absolute bias z for "
           f"{', '.join(series)}.")
    return done(fig, "trend", caption, alt)
