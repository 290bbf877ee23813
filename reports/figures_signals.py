"""Figures of signals: numerical differentiation (seed Fig. 1), model fit and residuals
(seed Figs. 4-6)."""
from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd
from scipy.signal import welch

from reports.figures_common import (FONT, MARKERS, PALETTE, SMALL, FigureOut, done, fmt, is_empty, new_figure, numeric,
                                    style_axes)

DIFF_METHODS = MappingProxyType({1: "1: smoother, then local polynomial", 2: "2: smoother, Fourier derivative",
                                 3: "3: local polynomial, then smoother"})


def fig_differentiation_error(differentiation: pd.DataFrame | None) -> FigureOut | None:
    """RMS derivative error per noisy sequence for the seed's three differentiation methods (Fig. 1).

    Parameters
    ----------
    differentiation : DataFrame
        ``method`` (1, 2, 3), ``sequence``, ``rms_error_pct``.

    Returns
    -------
    FigureOut or None
        Markers per sequence with each method's mean (dashed) and a strip of the
        distribution per method.
    """
    if is_empty(differentiation, ["method", "rms_error_pct"]):
        return None
    d = numeric(differentiation, ["rms_error_pct", "sequence"])
    d = d[np.isfinite(d["rms_error_pct"].to_numpy(float))]
    if d.empty:
        return None
    if "sequence" not in d or d["sequence"].isna().all():
        d["sequence"] = d.groupby("method").cumcount()
    keys = sorted(d["method"].unique(), key=lambda m: (str(type(m)), m))
    fig = new_figure(4.6)
    gs = fig.add_gridspec(1, 2, width_ratios=[3.2, 1])
    ax, ax2 = fig.add_subplot(gs[0]), fig.add_subplot(gs[1])
    ax2.sharey(ax)
    rng = np.random.default_rng(0)
    means = {}
    for i, m in enumerate(keys):
        g = d[d["method"] == m].sort_values("sequence")
        color, label = PALETTE[i % len(PALETTE)], DIFF_METHODS.get(_as_int(m), f"method {m}")
        v = g["rms_error_pct"].to_numpy(float)
        means[m] = float(v.mean())
        ax.plot(g["sequence"], v, linestyle="none", marker=MARKERS[i % len(MARKERS)], markersize=4, color=color,
                alpha=0.8, label=f"{label} (mean {means[m]:.2f} %)")
        ax.axhline(means[m], color=color, linestyle="--", linewidth=1.2)
        ax2.plot(i + rng.uniform(-0.18, 0.18, v.size), v, linestyle="none", marker=MARKERS[i % len(MARKERS)],
                 markersize=3, color=color, alpha=0.5)
        ax2.plot([i - 0.3, i + 0.3], [means[m]] * 2, color="black", linewidth=2.0)
    ax.set_xlabel("noisy sequence", fontsize=FONT)
    ax.set_ylabel("RMS derivative error (% of true RMS)", fontsize=FONT)
    ax.legend(fontsize=SMALL, loc="upper right", framealpha=0.85)
    ax2.set_xticks(range(len(keys)))
    ax2.set_xticklabels([f"method {m}" for m in keys], fontsize=SMALL, rotation=30, ha="right")
    ax2.set_title("distribution (bar = mean)", fontsize=SMALL)
    ax2.tick_params(labelleft=False)
    style_axes(ax)
    style_axes(ax2, "y")
    worst = max(means, key=means.get)
    listing = ", ".join(f"method {m} {means[m]:.2f} %" for m in keys)
    n_seq = d["sequence"].nunique()
    caption = (f"Each marker is the RMS error of one noisy sequence's derivative ({n_seq} sequences) and dashed lines "
               f"are the means: {listing}."
               + (f" Method {worst} is the least accurate on average." if len(keys) > 1 else ""))
    alt = f"Scatter of RMS differentiation error in percent for {n_seq} sequences and {len(keys)} methods; {listing}."
    return done(fig, "differentiation_error", caption, alt)


def _as_int(m: object) -> int | None:
    try:
        return int(m)  # type: ignore[call-overload]
    except (TypeError, ValueError):
        return None


def _example(examples: pd.DataFrame, flight: str | None, noise: str | None,
             equation: str | None) -> tuple[pd.DataFrame, str, str, str] | None:
    """The rows of one example (first flight, noise and equation unless named)."""
    e = examples
    for col, want in (("flight", flight), ("noise", noise), ("equation", equation)):
        if want is not None:
            e = e[e[col].astype(str) == str(want)]
    if e.empty:
        return None
    f = e["flight"].iloc[0]
    e = e[e["flight"] == f]
    n = e["noise"].iloc[0]
    e = e[e["noise"] == n]
    q = e["equation"].iloc[0]
    e = numeric(e[e["equation"] == q], ["t_s", "measured", "fitted", "residual"]).sort_values("t_s")
    e = e[np.isfinite(e["t_s"].to_numpy(float))]
    return (e, str(f), str(n), str(q)) if len(e) else None


def fig_model_fit(examples: pd.DataFrame | None, flight: str | None = None, noise: str | None = None,
                  equation: str | None = None) -> FigureOut | None:
    """Measured and fitted dependent variable against time, residual below (seed Fig. 4).

    Parameters
    ----------
    examples : DataFrame
        The example fits table.
    flight, noise, equation : str, optional
        Which example; default the first of each.

    Returns
    -------
    FigureOut or None
        Two stacked panels sharing the time axis; None when the example is not there.
    """
    if is_empty(examples, ["flight", "noise", "equation", "t_s", "measured", "fitted", "residual"]):
        return None
    sel = _example(examples, flight, noise, equation)
    if sel is None:
        return None
    e, f, n, q = sel
    dep = str(e["dependent"].iloc[0]) if "dependent" in e else q.split("=")[0].strip()
    t, z, zh, res = (e[c].to_numpy(float) for c in ("t_s", "measured", "fitted", "residual"))
    fig = new_figure(5.6)
    ax1, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    ax1.plot(t, z, color="#777777", linewidth=0.9, label="measured")
    ax1.plot(t, zh, color=PALETTE[0], linewidth=1.5, label="equation-error model")
    ax2.plot(t, res, color=PALETTE[3], linewidth=0.9)
    ax2.axhline(0.0, color="#444444", linewidth=0.7)
    ax1.set_ylabel(f"{dep} (non-dimensional)", fontsize=FONT)
    ax2.set_ylabel("residual", fontsize=FONT)
    ax2.set_xlabel("time (s)", fontsize=FONT)
    ax1.set_title(f"{f}, noise {n}: {q}", fontsize=FONT)
    ax1.legend(fontsize=SMALL, loc="best", framealpha=0.85)
    style_axes(ax1)
    style_axes(ax2)
    ok = np.isfinite(z) & np.isfinite(res)
    ss = float(np.sum((z[ok] - z[ok].mean()) ** 2)) if ok.any() else 0.0
    r2 = 1.0 - float(np.sum(res[ok] ** 2)) / ss if ss > 0 else float("nan")
    rms = float(np.sqrt(np.mean(res[ok] ** 2))) if ok.any() else float("nan")
    drift = ""
    k = max(len(res) // 10, 1)
    a, b = np.nanmean(res[:k]) if len(res) else np.nan, np.nanmean(res[-k:]) if len(res) else np.nan
    if np.isfinite(rms) and rms > 0 and a * b < 0 and min(abs(a), abs(b)) > 0.5 * rms:
        drift = (" The residual has opposite signs at the start and the end, which is how flight-condition drift "
                 "shows (seed Fig. 4); an airspeed term in the model removes it.")
    caption = (f"Measured {dep} (grey) and the time-domain equation-error fit (blue) for {f} with noise '{n}' "
               f"(R² = {fmt(r2, 4)}, residual RMS {fmt(rms, 3)}); structure in the residual below that follows the "
               "maneuver points to a missing model term." + drift)
    alt = f"Line chart of measured and fitted {dep} against time for {f}, noise {n}, and the residual below."
    return done(fig, "model_fit", caption, alt)


def fig_residuals(examples: pd.DataFrame | None, flight: str | None = None, noise: str | None = None,
                  equation: str | None = None, band_hz: tuple[float, float] | None = (0.2, 1.2)) -> FigureOut | None:
    """Residual time history and its power spectral density, side by side (seed Figs. 5-6).

    Parameters
    ----------
    examples : DataFrame
        The example fits table.
    flight, noise, equation : str, optional
        Which example; default the first of each.
    band_hz : (float, float) or None
        A band to shade on the spectrum (default: the frequency-domain method's default band);
        the caption gives the share of residual power below its upper end.

    Returns
    -------
    FigureOut or None
        Residual against time and its Welch PSD on log-log axes.
    """
    if is_empty(examples, ["flight", "noise", "equation", "t_s", "residual"]):
        return None
    sel = _example(examples.assign(measured=0.0, fitted=0.0) if "measured" not in examples else examples,
                   flight, noise, equation)
    if sel is None:
        return None
    e, f, n, q = sel
    e = e[np.isfinite(e["residual"].to_numpy(float))]
    if len(e) < 2:
        return None
    t, res = e["t_s"].to_numpy(float), e["residual"].to_numpy(float)
    dep = str(e["dependent"].iloc[0]) if "dependent" in e else q.split("=")[0].strip()
    fig = new_figure(4.2)
    ax1, ax2 = fig.subplots(1, 2)
    ax1.plot(t, res, color=PALETTE[3], linewidth=0.9)
    ax1.axhline(0.0, color="#444444", linewidth=0.7)
    ax1.set_xlabel("time (s)", fontsize=FONT)
    ax1.set_ylabel(f"{dep} residual (non-dimensional)", fontsize=FONT)
    ax1.set_title(f"{f}, noise {n}", fontsize=FONT)
    dt = float(np.median(np.diff(t)))
    verdict = ""
    if len(res) >= 16 and dt > 0:
        fs = 1.0 / dt
        freq, pxx = welch(res - res.mean(), fs=fs, nperseg=min(len(res), 512))
        keep = freq > 0
        ax2.semilogy(freq[keep], np.maximum(pxx[keep], 1e-300), color=PALETTE[0], linewidth=1.2)
        ax2.set_xscale("log")
        if band_hz is not None:
            ax2.axvspan(band_hz[0], band_hz[1], color=PALETTE[2], alpha=0.15, label=f"{band_hz[0]:g}-{band_hz[1]:g} Hz")
            ax2.legend(fontsize=SMALL, loc="upper right", framealpha=0.85)
            total = float(pxx.sum())
            if total > 0:
                lowf = float(pxx[freq <= band_hz[1]].sum()) / total
                width = band_hz[1] / (fs / 2)
                kind = "colored, not white" if lowf > 2 * width else "close to white"
                verdict = (f" {100 * lowf:.0f} % of the residual power lies below {band_hz[1]:g} Hz, "
                           f"{100 * width:.0f} % of the bandwidth: the residual is {kind}.")
        ax2.set_xlabel("frequency (Hz)", fontsize=FONT)
        ax2.set_ylabel("PSD (1/Hz)", fontsize=FONT)
        ax2.set_title("power spectral density (Welch)", fontsize=FONT)
    else:
        ax2.text(0.5, 0.5, "too few samples for a spectrum", ha="center", va="center", transform=ax2.transAxes)
    style_axes(ax1)
    style_axes(ax2)
    caption = ("The equation-error residual in time (left) and its power spectral density (right): white noise "
               "would give a flat spectrum, a hump at low frequency is colored residual from model error, which "
               "makes conventional standard errors too small." + verdict)
    alt = f"Residual of {dep} against time for {f}, noise {n}, and its power spectral density on log axes."
    return done(fig, "residuals", caption, alt)
