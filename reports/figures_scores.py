"""Figures of the scores per parameter: bias (seed Fig. 3), coverage, honesty of the
reported errors, efficiency and the scatter of the estimates themselves."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.lines import Line2D

from reports.figures_common import (MARKERS, PANEL_COLS, SMALL, SPECIAL_METHODS, FigureOut, add_series,
                                    categories, collapse_errors, dodged, done, errors_rank, finite_scores, fmt,
                                    grid, is_empty, method_color, method_order, new_figure, numeric, panel_note,
                                    panels, style_axes)
from reports.findings import efficiency_note


def _layout(parts: list[tuple[str, pd.DataFrame]]) -> tuple[int, float]:
    """Columns and height (in) for categorical panels."""
    widest = max(categories(g)[2] for _, g in parts)
    cols = 2 if len(parts) >= 4 and widest <= 8 else 1
    rows = math.ceil(len(parts) / cols)
    per_row = 2.4 + (0.5 if widest > 6 else 0.0)
    return cols, 1.0 + per_row * rows


def _median_by_series(s: pd.DataFrame, col: str, absolute: bool = False) -> pd.Series:
    v = s[col].abs() if absolute else s[col]
    return v.groupby(s["series"]).median().dropna()


def _notes(notes: list[str]) -> str:
    return (" " + " ".join(notes)) if notes else ""


def fig_bias(scores: pd.DataFrame | None) -> FigureOut | None:
    """Mean bias of each estimate in percent of its truth (the seed's Fig. 3).

    Parameters
    ----------
    scores : DataFrame
        The score table (one row per cell and parameter).

    Returns
    -------
    FigureOut or None
        Grouped bars per parameter and method with ±2 Monte Carlo standard errors, one panel
        per experiment (noise, maneuver ... whichever vary; at most six); None without data.
    """
    if is_empty(scores, ["method", "parameter", "bias_pct", "truth"]):
        return None
    s = finite_scores(scores)
    s = s[np.isfinite(s["bias_pct"].to_numpy(float))]
    if s.empty:
        return None
    s, series, more = add_series(collapse_errors(s))
    mcse = s["bias_mcse"] if "bias_mcse" in s else pd.Series(np.nan, index=s.index)
    err = 200.0 * mcse / s["truth"].abs()
    s["lo"], s["hi"] = s["bias_pct"] - err, s["bias_pct"] + err
    parts, total = panels(s)
    cols, height = _layout(parts)
    fig = new_figure(height)
    notes = dodged(fig, parts, series, s, y="bias_pct", lo="lo", hi="hi", ylabel="bias (% of truth)", kind="bar",
                   ref=0.0, max_cols=cols, min_span=1.0)
    shown = pd.concat([g for _, g in parts])
    med = _median_by_series(shown, "bias_pct", absolute=True)
    if len(med) > 1:
        verdict = (f"{med.idxmax()} is the farthest from zero (median |bias| {fmt(med.max(), 2)} % of truth) and "
                   f"{med.idxmin()} the closest ({fmt(med.min(), 2)} %).")
    else:
        verdict = f"The median |bias| is {fmt(med.iloc[0], 2)} % of truth." if len(med) else ""
    caption = ("Bars are the mean bias of each estimate as a percent of its truth, with ±2 Monte Carlo standard "
               f"errors; a bar whose error bar misses zero is a real bias. {verdict}"
               + panel_note(len(parts), total) + more + _notes(notes))
    alt = (f"Grouped bar chart in {len(parts)} panel(s) ({'; '.join(t for t, _ in parts)}): bias in percent of "
           f"truth per parameter for {', '.join(series)}.")
    return done(fig, "bias", caption, alt)


def fig_coverage(scores: pd.DataFrame | None, nominal: float = 0.95) -> FigureOut | None:
    """Coverage of the ±2σ intervals per method and parameter.

    Parameters
    ----------
    scores : DataFrame
        The score table.
    nominal : float
        The coverage the intervals should have (drawn as a dashed line).

    Returns
    -------
    FigureOut or None
        Dots with their exact 95 % binomial interval, one panel per experiment.
    """
    if is_empty(scores, ["method", "parameter", "coverage", "truth"]):
        return None
    s = finite_scores(scores)
    s = s[np.isfinite(s["coverage"].to_numpy(float))]
    if s.empty:
        return None
    s, series, more = add_series(s)
    for c in ("coverage_lo", "coverage_hi"):
        if c not in s:
            s[c] = np.nan
    parts, total = panels(s)
    cols, height = _layout(parts)
    fig = new_figure(height)
    notes = dodged(fig, parts, series, s, y="coverage", lo="coverage_lo", hi="coverage_hi",
                   ylabel="coverage of ±2σ interval", ref=nominal, ref_label=f"nominal {nominal:g}", max_cols=cols)
    low = float(np.nanmin(s[["coverage", "coverage_lo"]].to_numpy(float)))
    for ax in fig.axes:
        ax.set_ylim(min(0.0, low) - 0.03, 1.03)
    shown = pd.concat([g for _, g in parts])
    below = int((shown["coverage_hi"] < nominal).sum())
    med = _median_by_series(shown, "coverage")
    worst = f" Lowest median coverage: {med.idxmin()} ({fmt(med.min(), 2)})." if len(med) else ""
    caption = (f"Dots are the fraction of realizations whose ±2σ interval contains the truth, with its exact 95 % "
               f"binomial interval; the dashed line is the nominal {nominal:g}. {below} of {len(shown)} intervals lie "
               f"wholly below it, i.e. the reported error bounds are too small there.{worst}"
               + panel_note(len(parts), total) + more + _notes(notes))
    alt = f"Dot plot of coverage per parameter for {', '.join(series)} in {len(parts)} panel(s), nominal {nominal:g}."
    return done(fig, "coverage", caption, alt)


def fig_se_ratio(scores: pd.DataFrame | None) -> FigureOut | None:
    """Mean reported standard error over the empirical standard deviation (log scale).

    Parameters
    ----------
    scores : DataFrame
        The score table; cells without scatter (noise-free, one realization) are left out.

    Returns
    -------
    FigureOut or None
        Dots per method and parameter with a line at 1 (honest error bounds).
    """
    if is_empty(scores, ["method", "parameter", "se_ratio", "truth"]):
        return None
    s = finite_scores(scores)
    s = s[np.isfinite(s["se_ratio"].to_numpy(float)) & (s["se_ratio"] > 0)]
    if s.empty:
        return None
    s, series, more = add_series(s)
    parts, total = panels(s)
    cols, height = _layout(parts)
    fig = new_figure(height)
    notes = dodged(fig, parts, series, s, y="se_ratio", lo=None, hi=None, ylabel="mean reported SE / empirical SD",
                   log=True, ref=1.0, ref_label="honest (ratio 1)", max_cols=cols)
    shown = pd.concat([g for _, g in parts])
    med = _median_by_series(shown, "se_ratio")
    logdev = np.abs(np.log(med))
    verdict = (f" Most optimistic: {med.idxmin()} (median ratio {fmt(med.min(), 2)}); closest to honest: "
               f"{logdev.idxmin()} ({fmt(med[logdev.idxmin()], 2)})." if len(med) > 1 else
               (f" Median ratio {fmt(med.iloc[0], 2)}." if len(med) else ""))
    caption = ("Each dot is the mean standard error a method reported divided by the actual scatter of its "
               "estimates; below 1 the error bounds are too optimistic, above 1 too conservative." + verdict
               + panel_note(len(parts), total) + more + _notes(notes))
    alt = f"Dot plot, log scale, of the ratio of reported to empirical standard error for {', '.join(series)}."
    return done(fig, "se_ratio", caption, alt)


def _above_one(scores: pd.DataFrame) -> str:
    note = efficiency_note(scores)
    return " " + note if note else ""


def fig_efficiency(scores: pd.DataFrame | None) -> FigureOut | None:
    """Efficiency (Cramér-Rao variance over empirical variance) where a bound is known.

    Parameters
    ----------
    scores : DataFrame
        The score table (``crb`` and ``efficiency`` columns).

    Returns
    -------
    FigureOut or None
        Dots per method and parameter, log scale, line at 1; None when no cell has a finite
        Cramér-Rao bound.
    """
    if is_empty(scores, ["method", "parameter", "efficiency", "crb", "truth"]):
        return None
    s = finite_scores(scores)
    s = s[np.isfinite(s["crb"].to_numpy(float)) & np.isfinite(s["efficiency"].to_numpy(float))
          & (s["efficiency"] > 0)]
    if s.empty:
        return None
    s, series, more = add_series(collapse_errors(s))
    parts, total = panels(s)
    cols, height = _layout(parts)
    fig = new_figure(height)
    notes = dodged(fig, parts, series, s, y="efficiency", lo=None, hi=None, ylabel="efficiency  CRB² / variance",
                   log=True, ref=1.0, ref_label="Cramér-Rao bound reached", max_cols=cols)
    shown = pd.concat([g for _, g in parts])
    med = _median_by_series(shown, "efficiency")
    verdict = (f" Highest median efficiency: {med.idxmax()} ({fmt(med.max(), 2)}); lowest: {med.idxmin()} "
               f"({fmt(med.min(), 2)})." if len(med) > 1 else
               (f" Median efficiency {fmt(med.iloc[0], 2)}." if len(med) else ""))
    caption = ("Efficiency is the Cramér-Rao variance divided by the variance of the estimates: 1 means a method "
               "extracts all the information in the data, 0.5 that its estimates scatter with twice the variance "
               "of the bound." + verdict + _above_one(shown) + panel_note(len(parts), total) + more + _notes(notes))
    alt = f"Dot plot, log scale, of estimation efficiency per parameter for {', '.join(series)}."
    return done(fig, "efficiency", caption, alt)


def _scatter_parameter(results: pd.DataFrame, s: pd.DataFrame, parameter: str | None) -> str | None:
    if parameter is not None:
        return parameter if (results["parameter"] == parameter).any() else None
    if not s.empty:
        for p in s.loc[np.isfinite(s["mean"].to_numpy(float)), "parameter"]:
            if (results["parameter"] == p).any():
                return str(p)
    tl = numeric(results[["parameter", "truth_local"]], ["truth_local"]) if "truth_local" in results else None
    if tl is not None:
        fin = tl[np.isfinite(tl["truth_local"].to_numpy(float))]
        if not fin.empty:
            return str(fin["parameter"].iloc[0])
    rest = results.loc[results["parameter"].astype(str) != "bias", "parameter"]
    return str(rest.iloc[0]) if len(rest) else None


def fig_scatter(results: pd.DataFrame | None, scores: pd.DataFrame | None,
                parameter: str | None = None) -> FigureOut | None:
    """Every realization's estimate of one parameter, per method.

    Parameters
    ----------
    results : DataFrame
        The tidy results table.
    scores : DataFrame or None
        The score table; gives the truth in the campaign's definition (else ``truth_local``).
    parameter : str, optional
        The parameter; default the first with a finite truth.

    Returns
    -------
    FigureOut or None
        Dots (jittered) per method, the truth as a dashed line and the mean ± 2 × the mean
        reported standard error for each error type; one panel per experiment (at most six).
    """
    if is_empty(results, ["method", "parameter", "estimate"]):
        return None
    s = finite_scores(scores) if not is_empty(scores, ["method", "parameter", "truth"]) else pd.DataFrame()
    est = results[~results["method"].astype(str).isin(SPECIAL_METHODS)]
    p = _scatter_parameter(est, s, parameter)
    if p is None:
        return None
    r = numeric(est[est["parameter"] == p], ["estimate", "std_error", "truth_local"])
    if "ok" in r:
        r = r[r["ok"].fillna(False).astype(bool)]
    r = r[np.isfinite(r["estimate"].to_numpy(float))]
    if r.empty:
        return None
    r["errors"] = r["errors"].fillna("").astype(str) if "errors" in r else ""
    r["method"] = r["method"].astype(str)
    # one cloud per method; the error types only change the bounds
    first = r.groupby("method")["errors"].agg(lambda e: sorted(e.unique(), key=errors_rank)[0])
    all_methods = method_order(r["method"].unique())
    methods = all_methods[:10]
    more = f" Only the first 10 of {len(all_methods)} methods are shown." if len(all_methods) > 10 else ""
    parts, total = panels(r[r["method"].isin(methods)])
    cols = 2 if len(parts) >= 4 else 1
    fig = new_figure(1.0 + 2.7 * math.ceil(len(parts) / cols))
    axes = grid(fig, len(parts), cols)
    rng = np.random.default_rng(0)
    kinds = sorted(r["errors"].unique(), key=errors_rank)
    far: dict[str, float] = {}
    for ax, (title, g) in zip(axes, parts):
        truth = float("nan")
        if not s.empty:
            keys = [c for c in PANEL_COLS if c in g and c in s]
            t = s[(s["parameter"] == p)]
            for c in keys:
                t = t[t[c].astype(str) == str(g[c].iloc[0])]
            truth = float(t["truth"].iloc[0]) if len(t) else truth
        if not np.isfinite(truth) and "truth_local" in g:
            fin = g["truth_local"].dropna()
            truth = float(fin.iloc[0]) if len(fin) else truth
        for i, m in enumerate(methods):
            gm = g[g["method"] == m]
            if gm.empty:
                continue
            e0 = first[m] if (gm["errors"] == first[m]).any() else sorted(gm["errors"].unique(), key=errors_rank)[0]
            dots = gm[gm["errors"] == e0]["estimate"].to_numpy(float)
            ax.plot(i - 0.15 + rng.uniform(-0.12, 0.12, dots.size), dots, linestyle="none", marker="o",
                    markersize=3, alpha=0.45, color=method_color(m, methods), zorder=2)
            if np.isfinite(truth) and truth != 0:
                far[m] = max(far.get(m, 0.0), abs(dots.mean() - truth) / abs(truth))
            for k, e in enumerate(sorted(gm["errors"].unique(), key=errors_rank)):
                ge = gm[gm["errors"] == e]
                mean = float(ge["estimate"].mean())
                se = float(ge["std_error"].mean()) if "std_error" in ge else float("nan")
                ax.errorbar([i + 0.1 + 0.1 * k], [mean], yerr=[[2 * se if np.isfinite(se) else 0.0]] * 2,
                            fmt=MARKERS[errors_rank(e) % len(MARKERS)], color="#222222", markersize=5, capsize=3,
                            elinewidth=1.0, zorder=4)
        if np.isfinite(truth):
            ax.axhline(truth, color="black", linestyle="--", linewidth=1.3, zorder=3)
        ax.set_xticks(range(len(methods)))
        ax.set_xticklabels(methods, fontsize=SMALL, rotation=0 if len(methods) <= 6 else 30)
        ax.set_xlim(-0.6, len(methods) - 0.4)
        ax.set_title(title, fontsize=9.5)
        ax.set_ylabel(f"{p} (per rad)", fontsize=9.5)
        style_axes(ax, "y")
    handles = [Line2D([], [], color="black", linestyle="--", label="truth")]
    handles += [Line2D([], [], color="#222222", marker=MARKERS[errors_rank(e) % len(MARKERS)], linestyle="-",
                       label=f"mean ± 2 SE{', ' + e if e else ''}") for e in kinds]
    fig.legend(handles=handles, loc="outside upper center", ncols=min(len(handles), 4), fontsize=SMALL, frameon=False)
    worst = max(far, key=far.get) if far else None
    verdict = (f" The mean farthest from the truth is {worst}'s ({fmt(100 * far[worst], 2)} % off)." if worst else "")
    caption = (f"Each dot is one realization's estimate of {p}, the dashed line is the truth and the black bars are "
               "the mean ± twice the mean reported standard error; bars much shorter than the cloud of dots mean "
               "optimistic error bounds." + verdict + panel_note(len(parts), total) + more)
    alt = f"Strip plot of the estimates of {p} per method ({', '.join(methods)}) in {len(parts)} panel(s)."
    return done(fig, "scatter", caption, alt)
