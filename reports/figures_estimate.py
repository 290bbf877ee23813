"""Figures of one estimate (``sidbench estimate --report``): measured against model, the residual
and its spectrum, the regressors, and the estimates with their bounds beside the truth."""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import welch

from reports.figures_common import FONT, PALETTE, SMALL, FigureOut, done, fmt, new_figure, style_axes


def _outputs(time: pd.DataFrame) -> list[tuple[str, str, str, str]]:
    """(label, measured column, model column, residual column) per output."""
    if "measured" in time.columns:
        return [("", "measured", "model", "residual")]
    outs = []
    for c in time.columns:
        if c.endswith(":measured"):
            o = c[: -len(":measured")]
            outs.append((o, c, f"{o}:model", f"{o}:residual"))
    return outs


def fig_measured_vs_model(time: pd.DataFrame, dependent: str, method: str) -> FigureOut | None:
    """Measured and model time histories, one panel per output."""
    outs = _outputs(time)
    if not outs:
        return None
    t = time.index.to_numpy(float)
    fig = new_figure(2.6 * len(outs) + 0.6)
    axes = np.atleast_1d(fig.subplots(len(outs), 1, sharex=True))
    r2s = []
    for ax, (label, m, y, r) in zip(axes, outs):
        z, zh = time[m].to_numpy(float), time[y].to_numpy(float)
        ax.plot(t, z, color="#777777", linewidth=0.9, label="measured")
        ax.plot(t, zh, color=PALETTE[0], linewidth=1.4, label=f"model ({method})")
        ax.set_ylabel(label or dependent, fontsize=FONT)
        ss = float(np.sum((z - z.mean()) ** 2))
        r2s.append(1 - float(np.sum((z - zh) ** 2)) / ss if ss > 0 else float("nan"))
        style_axes(ax)
    axes[0].legend(fontsize=SMALL, loc="best", framealpha=0.85)
    axes[-1].set_xlabel("time (s)", fontsize=FONT)
    caption = (f"Measured {dependent} (grey) against the identified model (blue), R² = "
               + ", ".join(fmt(r, 4) for r in r2s)
               + ". Where the blue line leaves the grey one over a stretch of the maneuver the model lacks a term.")
    alt = f"Line chart of measured and model {dependent} against time."
    return done(fig, "measured_vs_model", caption, alt)


def fig_residual(time: pd.DataFrame, dependent: str) -> FigureOut | None:
    """Residual time history (left) and its power spectral density (right), per output."""
    outs = _outputs(time)
    if not outs:
        return None
    t = time.index.to_numpy(float)
    fig = new_figure(2.8 * len(outs) + 0.6)
    axes = np.atleast_2d(fig.subplots(len(outs), 2))
    verdicts = []
    dt = float(np.median(np.diff(t))) if len(t) > 1 else float("nan")
    for (ax1, ax2), (label, _m, _y, r) in zip(axes, outs):
        res = time[r].to_numpy(float)
        ax1.plot(t, res, color=PALETTE[3], linewidth=0.9)
        ax1.axhline(0.0, color="#444444", linewidth=0.7)
        ax1.set_xlabel("time (s)", fontsize=FONT)
        ax1.set_ylabel(f"{label or dependent} residual", fontsize=FONT)
        if len(res) >= 16 and dt > 0:
            freq, pxx = welch(res - res.mean(), fs=1 / dt, nperseg=min(len(res), 256))
            keep = freq > 0
            ax2.loglog(freq[keep], np.maximum(pxx[keep], 1e-300), color=PALETTE[0], linewidth=1.2)
            total = float(pxx.sum())
            if total > 0:
                low = float(pxx[freq <= 2.0].sum()) / total
                share = 2.0 / (0.5 / dt)
                verdicts.append(f"{label or dependent}: {100 * low:.0f} % of the residual power below 2 Hz "
                                f"({100 * share:.0f} % of the bandwidth)")
        else:
            ax2.text(0.5, 0.5, "too few samples for a spectrum", ha="center", va="center", transform=ax2.transAxes)
        ax2.set_xlabel("frequency (Hz)", fontsize=FONT)
        ax2.set_ylabel("PSD (1/Hz)", fontsize=FONT)
        style_axes(ax1)
        style_axes(ax2)
    caption = ("The residual (measured − model) in time, left, and its power spectral density (Welch), right. White "
               "noise gives a flat spectrum; power gathered at low frequency is colored residual (model error or "
               "turbulence), which makes conventional standard errors too small. " + "; ".join(verdicts) + ".")
    return done(fig, "residual", caption, f"Residual of {dependent} against time and its power spectral density.")


def fig_regressors(regressors: pd.DataFrame | None, title: str = "regressors") -> FigureOut | None:
    """Each regressor (or input) against time, one panel each (at most eight)."""
    if regressors is None or regressors.empty:
        return None
    cols = list(regressors.columns)[:8]
    t = regressors.index.to_numpy(float)
    fig = new_figure(1.5 * len(cols) + 0.8)
    axes = np.atleast_1d(fig.subplots(len(cols), 1, sharex=True))
    for i, (ax, c) in enumerate(zip(axes, cols)):
        ax.plot(t, regressors[c].to_numpy(float), color=PALETTE[i % len(PALETTE)], linewidth=1.0)
        ax.set_ylabel(str(c), fontsize=SMALL)
        style_axes(ax)
    axes[-1].set_xlabel("time (s)", fontsize=FONT)
    more = f" (the first 8 of {regressors.shape[1]})" if regressors.shape[1] > 8 else ""
    caption = (f"The {title}{more} against time, as the estimator saw them (perturbations from trim where the "
               "options say so). Regressors that move together cannot be told apart: see the correlation table.")
    return done(fig, "regressors", caption, f"Line charts of the {title} against time.")


def fig_estimates(table: pd.DataFrame) -> FigureOut | None:
    """Each estimate with its 95 % interval, normalised by its own magnitude, truth beside it."""
    if table.empty:
        return None
    names = table["parameter"].tolist()
    est = table["estimate"].to_numpy(float)
    lo, hi = table["ci95_lower"].to_numpy(float), table["ci95_upper"].to_numpy(float)
    truth = table["truth"].to_numpy(float) if "truth" in table else np.full(len(est), np.nan)
    scale = np.where(np.isfinite(truth) & (truth != 0), np.abs(truth), np.maximum(np.abs(est), 1e-300))
    y = np.arange(len(names))[::-1]
    fig = new_figure(0.45 * len(names) + 1.6, 7.5)
    ax = fig.subplots()
    ax.errorbar(est / scale, y, xerr=[(est - lo) / scale, (hi - est) / scale], fmt="o", color=PALETTE[0],
                ecolor=PALETTE[0], capsize=3, label="estimate ± 95 % interval")
    if np.isfinite(truth).any():
        ax.plot(truth / scale, y, "D", color=PALETTE[3], markerfacecolor="none", markersize=8, label="truth")
    ax.set_yticks(y, names, fontsize=SMALL)
    ax.set_xlabel("value / |truth| (or / |estimate| without a truth)", fontsize=FONT)
    ax.axvline(0, color="#444444", linewidth=0.7)
    ax.legend(fontsize=SMALL, loc="best", framealpha=0.85)
    style_axes(ax, "x")
    inside = [n for n, a, b, t in zip(names, lo, hi, truth) if np.isfinite(t) and a <= t <= b]
    has_truth = int(np.isfinite(truth).sum())
    extra = (f" The truth lies inside {len(inside)} of {has_truth} intervals." if has_truth else "")
    caption = ("Each estimate with its 95 % interval, divided by the magnitude of its truth (or of itself), so "
               "parameters of different size share one axis." + extra)
    return done(fig, "estimates", caption, "Dot plot of the estimates with their intervals and the truth.")
