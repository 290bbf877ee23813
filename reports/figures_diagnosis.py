"""Figures of a model diagnosis (``sidbench diagnose``): where the model departs from the
recording, and whether the augmented model closes the gap.

Every function reads one series table (``DIR/series/<maneuver>.parquet``, see the diagnosis
data contract) and returns a :class:`reports.figures_common.FigureOut` or None when the
columns it needs are missing. Columns are used by name only: ``t_s``, ``meas_<c>``,
``smooth_<c>``, ``before_<c>``, ``after_<c>`` for output channels and ``coef_meas_<j>``,
``coef_model_<j>``, ``coef_after_<j>`` for coefficients.

========================  ==================================================================
function                  figure
========================  ==================================================================
fig_worst_channels        measured and before-model outputs for the worst channels
fig_coefficient_mismatch  coef_meas - coef_model per axis over time, time window shaded
fig_mismatch_spectrum     power spectrum of the coefficient mismatch, band shaded
fig_before_after_outputs  smoothed measurement, before-model and after-model outputs
fig_before_after_coefs    coefficient residual before and after the augmentation
========================  ==================================================================
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from scipy.signal import welch

from reports.figures_common import (FONT, PALETTE, SMALL, FigureOut, done, fmt, grid, new_figure,
                                    style_axes)
from models.constants import BODY_COEFFICIENTS as COEFFICIENTS

__all__ = ["CHANNELS", "COEFFICIENTS", "channel_label", "channel_values", "rms",
           "fig_worst_channels", "fig_coefficient_mismatch", "fig_mismatch_spectrum",
           "fig_before_after_outputs", "fig_before_after_coefs"]

CHANNELS: tuple[str, ...] = ("alpha", "beta", "p", "q", "r", "phi", "theta", "V", "ax", "ay", "az")
"""Output channels of the diagnosis series, in the contract's order."""
"""Non-dimensional force and moment coefficients, in the contract's order."""
MAX_CHANNELS = 4
_DEG = 180.0 / np.pi
_ANGLES = ("alpha", "beta", "phi", "theta")
_RATES = ("p", "q", "r")
_UNITS = {"V": "ft/s", "ax": "g", "ay": "g", "az": "g"}
_MEAS_COLOR = "#9a9a9a"
_SMOOTH_COLOR = "#222222"
_BEFORE_COLOR = PALETTE[3]
_AFTER_COLOR = PALETTE[0]
_WINDOW_COLOR = PALETTE[1]
_BAND_COLOR = PALETTE[2]


def channel_label(channel: str) -> str:
    """Axis label of an output channel in display units (angles in deg, rates in deg/s)."""
    if channel in _ANGLES:
        return f"{channel} (deg)"
    if channel in _RATES:
        return f"{channel} (deg/s)"
    return f"{channel} ({_UNITS[channel]})" if channel in _UNITS else channel


def channel_values(series: pd.DataFrame, column: str, channel: str) -> np.ndarray:
    """A series column as float in display units (radians shown as degrees)."""
    values = pd.to_numeric(series[column], errors="coerce").to_numpy(float)
    return values * _DEG if channel in _ANGLES + _RATES else values


def rms(values: np.ndarray) -> float:
    """Root mean square of the finite values (NaN when there are none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v ** 2))) if v.size else float("nan")


def _has(series: pd.DataFrame | None, columns: Sequence[str]) -> bool:
    """True when ``series`` is a non-empty table holding every one of ``columns``."""
    return isinstance(series, pd.DataFrame) and not series.empty and all(c in series for c in columns)


def _time(series: pd.DataFrame) -> np.ndarray:
    """The time column as float seconds."""
    return pd.to_numeric(series["t_s"], errors="coerce").to_numpy(float)


def _window(window: Sequence[float] | None) -> tuple[float, float] | None:
    """A finite ``(start, end)`` pair with start < end, or None."""
    try:
        a, b = (float(x) for x in window)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        return None
    return (a, b) if np.isfinite(a) and np.isfinite(b) and a < b else None


def _shade(ax: Axes, window: tuple[float, float] | None, label: str) -> None:
    """Shade a time window on the x axis."""
    if window is not None:
        ax.axvspan(window[0], window[1], color=_WINDOW_COLOR, alpha=0.15, label=label, zorder=0)


def _mismatch(series: pd.DataFrame, coef: str, model: str = "model") -> np.ndarray:
    """``coef_meas_<j> - coef_<model>_<j>`` as float."""
    meas = pd.to_numeric(series[f"coef_meas_{coef}"], errors="coerce").to_numpy(float)
    return meas - pd.to_numeric(series[f"coef_{model}_{coef}"], errors="coerce").to_numpy(float)


def _legend(fig, ax: Axes) -> None:
    """One legend above the panels from the first panel's labelled artists."""
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside upper center", ncols=min(len(handles), 5),
                   fontsize=SMALL, frameon=False)


def _window_text(window: tuple[float, float] | None) -> str:
    return f"{window[0]:g}-{window[1]:g} s" if window else ""


def fig_worst_channels(series: pd.DataFrame | None, channels: Sequence[str], maneuver: str,
                       window: Sequence[float] | None = None) -> FigureOut | None:
    """Raw measurement and the model as given (before) for the worst output channels.

    Parameters
    ----------
    series : DataFrame
        One maneuver's series table.
    channels : sequence of str
        Channels to draw, worst first; those lacking ``meas_``/``before_`` columns are
        skipped and at most four are drawn.
    maneuver : str
        ``'identification'`` or ``'validation'`` (for titles and the figure name).
    window : (float, float), optional
        Time window holding the largest mismatch, shaded.

    Returns
    -------
    FigureOut or None
    """
    if not _has(series, ["t_s"]):
        return None
    chans = [c for c in channels if _has(series, [f"meas_{c}", f"before_{c}"])][:MAX_CHANNELS]
    if not chans:
        return None
    t, span = _time(series), _window(window)
    fig = new_figure(1.0 + 2.0 * len(chans))
    axes = fig.subplots(len(chans), 1, sharex=True, squeeze=False).ravel()
    gaps = []
    for ax, c in zip(axes, chans):
        meas, before = channel_values(series, f"meas_{c}", c), channel_values(series, f"before_{c}", c)
        _shade(ax, span, f"largest mismatch {_window_text(span)}")
        ax.plot(t, meas, color=_MEAS_COLOR, linewidth=0.8, label="measured (raw)")
        ax.plot(t, before, color=_BEFORE_COLOR, linewidth=1.4, label="model as given (before)")
        ax.set_ylabel(channel_label(c), fontsize=FONT)
        style_axes(ax)
        gaps.append(f"{c} {fmt(rms(meas - before))}")
    axes[-1].set_xlabel("time (s)", fontsize=FONT)
    axes[0].set_title(f"{maneuver}: measured against the model as given", fontsize=FONT)
    _legend(fig, axes[0])
    caption = (f"The raw {maneuver} measurement (grey) and the model as given replaying the measured "
               f"surfaces (orange) for the {len(chans)} channels that depart most from it, worst on top. "
               "Look for where the orange line leaves the grey band of noise: a steady offset points to a "
               "sensor bias, a lag or lead to a delay or missing rate term, a growing gap at high "
               "excursion to a nonlinearity. RMS of measured minus model, in display units: "
               + ", ".join(gaps) + ".")
    alt = f"Stacked line charts of measured and modelled {', '.join(chans)} against time for {maneuver}."
    return done(fig, f"worst_channels_{maneuver}", caption, alt)


def fig_coefficient_mismatch(series: pd.DataFrame | None, worst: str | None = None,
                             window: Sequence[float] | None = None) -> FigureOut | None:
    """``coef_meas - coef_model`` against time, one panel per coefficient.

    Parameters
    ----------
    series : DataFrame
        The identification series table.
    worst : str, optional
        The coefficient holding the largest mismatch (named in its panel title).
    window : (float, float), optional
        Time window holding the largest mismatch, shaded.

    Returns
    -------
    FigureOut or None
    """
    if not _has(series, ["t_s"]):
        return None
    coefs = [j for j in COEFFICIENTS if _has(series, [f"coef_meas_{j}", f"coef_model_{j}"])]
    if not coefs:
        return None
    t, span = _time(series), _window(window)
    fig = new_figure(1.2 + 1.9 * ((len(coefs) + 1) // 2))
    axes = grid(fig, len(coefs), 2)
    sizes = []
    for ax, j in zip(axes, coefs):
        d = _mismatch(series, j)
        _shade(ax, span, f"largest mismatch {_window_text(span)}")
        ax.plot(t, d, color=PALETTE[4] if j == worst else _SMOOTH_COLOR, linewidth=0.9,
                label="measured - model")
        ax.axhline(0.0, color="#666666", linewidth=0.6)
        ax.set_title(f"{j}" + (" (largest mismatch)" if j == worst else "") + f", RMS {fmt(rms(d))}",
                     fontsize=FONT)
        ax.set_xlabel("time (s)", fontsize=SMALL)
        style_axes(ax)
        sizes.append(f"{j} {fmt(rms(d))}")
    _legend(fig, axes[0])
    where = f" The shaded span ({_window_text(span)}) is where the largest mismatch lives." if span else ""
    caption = ("Coefficient from the measurements (Eqs. 1-5, smoothed data) minus the model's "
               "aerodynamics along the measured states, per axis. A model that is right leaves only "
               "noise about zero; look for the axis whose trace has structure that follows the maneuver, "
               "and for when it happens." + where + " RMS: " + ", ".join(sizes) + ".")
    alt = f"Line charts of the coefficient mismatch against time for {', '.join(coefs)}."
    return done(fig, "coefficient_mismatch", caption, alt)


def _psd(t: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Welch power spectral density of a signal sampled at ``t`` (None if too short)."""
    ok = np.isfinite(t) & np.isfinite(d)
    t, d = t[ok], d[ok]
    if d.size < 16:
        return None
    dt = float(np.median(np.diff(t)))
    if not dt > 0:
        return None
    freq, pxx = welch(d - d.mean(), fs=1.0 / dt, nperseg=min(d.size, 256))
    keep = freq > 0
    return freq[keep], pxx[keep]


def _band_share(freq: np.ndarray, pxx: np.ndarray, band: tuple[float, float]) -> tuple[float, float]:
    """Share of the power and of the frequency range inside ``band``."""
    inside = (freq >= band[0]) & (freq <= band[1])
    total = float(pxx.sum())
    power = float(pxx[inside].sum()) / total if total > 0 else float("nan")
    return power, float(inside.mean())


def fig_mismatch_spectrum(series: pd.DataFrame | None, worst: str | None = None,
                          band: Sequence[float] | None = None) -> FigureOut | None:
    """Power spectral density of ``coef_meas - coef_model`` per coefficient, band shaded.

    Parameters
    ----------
    series : DataFrame
        The identification series table.
    worst : str, optional
        The coefficient holding the largest mismatch (drawn thicker; the caption quotes its
        share of power in the band).
    band : (float, float), optional
        Frequency band holding most of the mismatch power, in Hz, shaded.

    Returns
    -------
    FigureOut or None
    """
    if not _has(series, ["t_s"]):
        return None
    t, span = _time(series), _window(band)
    spectra = {j: _psd(t, _mismatch(series, j)) for j in COEFFICIENTS
               if _has(series, [f"coef_meas_{j}", f"coef_model_{j}"])}
    spectra = {j: s for j, s in spectra.items() if s is not None}
    if not spectra:
        return None
    fig = new_figure(4.2)
    ax = fig.subplots()
    if span:
        ax.axvspan(span[0], span[1], color=_BAND_COLOR, alpha=0.15, zorder=0,
                   label=f"mismatch band {span[0]:g}-{span[1]:g} Hz")
    for i, (j, (freq, pxx)) in enumerate(spectra.items()):
        ax.loglog(freq, np.maximum(pxx, 1e-300), color=PALETTE[i % len(PALETTE)],
                  linewidth=2.2 if j == worst else 1.0, label=j + (" (largest)" if j == worst else ""))
    ax.set_xlabel("frequency (Hz)", fontsize=FONT)
    ax.set_ylabel("PSD of measured - model (1/Hz)", fontsize=FONT)
    ax.legend(fontsize=SMALL, loc="lower left", framealpha=0.85, ncols=2)
    style_axes(ax)
    share = ""
    key = worst if worst in spectra else next(iter(spectra))
    if span:
        power, width = _band_share(*spectra[key], span)
        share = (f" {fmt(100 * power, 3)} % of the {key} mismatch power lies in the shaded band, which "
                 f"spans {fmt(100 * width, 2)} % of the frequencies shown.")
    caption = ("Power spectral density (Welch) of the coefficient mismatch per axis. Noise alone gives a "
               "flat floor; look for the band where an axis rises above it: low frequencies point to "
               "a slowly varying (static or nonlinear) error, power near the short-period frequency to a "
               "missing rate or unsteady term." + share)
    alt = f"Log-log spectra of the coefficient mismatch for {', '.join(spectra)} with the band shaded."
    return done(fig, "mismatch_spectrum", caption, alt)


def _before_after_panels(series: pd.DataFrame | None, names: Sequence[str], need: Sequence[str],
                         window: Sequence[float] | None, panel_height: float):
    """The names (at most ``MAX_CHANNELS``) whose ``need`` columns the series has, the time,
    the shaded span and a figure with one stacked panel each; None when nothing can be drawn."""
    if not _has(series, ["t_s"]):
        return None
    chosen = [c for c in names if _has(series, [n.format(c) for n in need])][:MAX_CHANNELS]
    if not chosen:
        return None
    fig = new_figure(1.0 + panel_height * len(chosen))
    axes = fig.subplots(len(chosen), 1, sharex=True, squeeze=False).ravel()
    return chosen, _time(series), _window(window), fig, axes


def fig_before_after_outputs(series: pd.DataFrame | None, channels: Sequence[str], maneuver: str,
                             window: Sequence[float] | None = None) -> FigureOut | None:
    """Smoothed measurement, model as given and augmented model for the affected channels.

    Parameters
    ----------
    series : DataFrame
        One maneuver's series table.
    channels : sequence of str
        Channels to draw (at most four, those with ``smooth_``, ``before_`` and ``after_``).
    maneuver : str
        ``'identification'`` or ``'validation'``.
    window : (float, float), optional
        Time window to shade (the identification's largest mismatch).

    Returns
    -------
    FigureOut or None
    """
    need = ("smooth_{}", "before_{}", "after_{}")
    panels = _before_after_panels(series, channels, need, window, 2.0)
    if panels is None:
        return None
    chans, t, span, fig, axes = panels
    changes = []
    for ax, c in zip(axes, chans):
        smooth, before, after = (channel_values(series, n.format(c), c) for n in need)
        _shade(ax, span, f"largest mismatch {_window_text(span)}")
        ax.plot(t, smooth, color=_SMOOTH_COLOR, linewidth=1.0, label="measured (smoothed)")
        ax.plot(t, before, color=_BEFORE_COLOR, linewidth=1.2, linestyle="--", label="before (model as given)")
        ax.plot(t, after, color=_AFTER_COLOR, linewidth=1.4, label="after (augmented model)")
        ax.set_ylabel(channel_label(c), fontsize=FONT)
        style_axes(ax)
        changes.append(f"{c} {fmt(rms(smooth - before))} -> {fmt(rms(smooth - after))}")
    axes[-1].set_xlabel("time (s)", fontsize=FONT)
    axes[0].set_title(f"{maneuver}: before and after the augmentation", fontsize=FONT)
    _legend(fig, axes[0])
    held_out = (" This maneuver was not used to estimate the added terms, so agreement here is "
                "evidence, not fit." if maneuver == "validation" else "")
    caption = (f"Smoothed {maneuver} measurement (black), the model as given (orange, dashed) and the "
               "augmented model (blue). Look at whether the blue line follows the black one where the "
               "orange one departed." + held_out + " RMS of smoothed measurement minus model, before -> "
               "after: " + ", ".join(changes) + ".")
    alt = f"Stacked line charts of {', '.join(chans)} for {maneuver}: measurement, model before and after."
    return done(fig, f"before_after_outputs_{maneuver}", caption, alt)


def fig_before_after_coefs(series: pd.DataFrame | None, coefs: Sequence[str], maneuver: str,
                           window: Sequence[float] | None = None) -> FigureOut | None:
    """Coefficient residual before (``meas - model``) and after (``meas - after``).

    Parameters
    ----------
    series : DataFrame
        One maneuver's series table.
    coefs : sequence of str
        Coefficients to draw (at most four, those with all three coefficient columns).
    maneuver : str
        ``'identification'`` or ``'validation'``.
    window : (float, float), optional
        Time window to shade.

    Returns
    -------
    FigureOut or None
    """
    need = ("coef_meas_{}", "coef_model_{}", "coef_after_{}")
    panels = _before_after_panels(series, coefs, need, window, 1.9)
    if panels is None:
        return None
    chosen, t, span, fig, axes = panels
    changes = []
    for ax, j in zip(axes, chosen):
        before, after = _mismatch(series, j, "model"), _mismatch(series, j, "after")
        _shade(ax, span, f"largest mismatch {_window_text(span)}")
        ax.plot(t, before, color=_BEFORE_COLOR, linewidth=0.9, label="residual before")
        ax.plot(t, after, color=_AFTER_COLOR, linewidth=0.9, label="residual after")
        ax.axhline(0.0, color="#666666", linewidth=0.6)
        ax.set_ylabel(f"{j} residual", fontsize=FONT)
        style_axes(ax)
        changes.append(f"{j} {fmt(rms(before))} -> {fmt(rms(after))}")
    axes[-1].set_xlabel("time (s)", fontsize=FONT)
    axes[0].set_title(f"{maneuver}: coefficient residual before and after", fontsize=FONT)
    _legend(fig, axes[0])
    caption = (f"Measured coefficient minus the model as given (orange) and minus the augmented model "
               f"(blue) on the {maneuver} maneuver. Look for the structure that follows the maneuver "
               "in the orange trace to be gone from the blue one, leaving noise about zero. RMS before "
               "-> after: " + ", ".join(changes) + ".")
    alt = f"Line charts of the coefficient residual of {', '.join(chosen)} before and after, {maneuver}."
    return done(fig, f"before_after_coefficients_{maneuver}", caption, alt)
