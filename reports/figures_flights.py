"""Figures of the flights themselves: time histories, input spectra against the aircraft's
modes, and excursions from trim."""
from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd

from reports.figures_common import FONT, PALETTE, SMALL, FigureOut, done, fmt, is_empty, new_figure, numeric, style_axes

CHANNELS = (("de_deg", "δe", "deg"), ("da_deg", "δa", "deg"), ("dr_deg", "δr", "deg"),
            ("alpha_deg", "α", "deg"), ("beta_deg", "β", "deg"), ("V_fps", "V", "ft/s"),
            ("q_dps", "q", "deg/s"), ("p_dps", "p", "deg/s"), ("r_dps", "r", "deg/s"))
SURFACES = (("de_deg", "stabilator δe"), ("da_deg", "aileron δa"), ("dr_deg", "rudder δr"))
MODE_SURFACES = MappingProxyType({"short period": ("de_deg",), "phugoid": ("de_deg",),
                                  "dutch roll": ("da_deg", "dr_deg"), "roll": ("da_deg", "dr_deg"),
                                  "spiral": ("da_deg", "dr_deg")})
EXCURSIONS = (("max_dalpha_deg", "largest |Δα| (deg)"), ("max_dbeta_deg", "largest |Δβ| (deg)"),
              ("max_dnz_g", "largest |Δn_z| (g)"), ("max_dV_fps", "largest |ΔV| (ft/s)"))
MAX_FLIGHTS = 6
MAX_POINTS = 4000
STILL_BELOW: float = 1e-3
"""A channel whose peak-to-peak stays below this (in its own unit: deg, deg/s, ft/s, g) over every
flight shown is left out of the figures: far below any sensor's resolution (the ``white``
preset's smallest σ is 0.05° on the surfaces, ``harness/noise_presets.py``), so nothing an
estimator could use (β, p, r, δa, δr on a pitch-only maneuver)."""


def _flight_list(flights: pd.DataFrame, max_flights: int) -> tuple[list[str], int]:
    names = list(dict.fromkeys(flights["flight"].astype(str)))
    return names[:max_flights], len(names)


def _thin(g: pd.DataFrame) -> pd.DataFrame:
    step = max(1, len(g) // MAX_POINTS)
    return g.iloc[::step]


def _moves(x: pd.Series) -> bool:
    """True when the channel's peak-to-peak reaches :data:`STILL_BELOW`."""
    v = x.to_numpy(float)
    v = v[np.isfinite(v)]
    return bool(v.size) and float(np.ptp(v)) >= STILL_BELOW


def _departs(x: pd.Series) -> bool:
    """True when some excursion reaches :data:`STILL_BELOW`."""
    v = np.abs(x.to_numpy(float))
    v = v[np.isfinite(v)]
    return bool(v.size) and float(v.max()) >= STILL_BELOW


def fig_time_histories(flights: pd.DataFrame | None, max_flights: int = MAX_FLIGHTS) -> FigureOut | None:
    """Surface inputs (top row) and responses of the flights, overlaid.

    Parameters
    ----------
    flights : DataFrame
        Clean time histories, one row per sample per flight (degrees, deg/s, ft/s).
    max_flights : int
        At most this many flights (the first ones) are drawn; the caption says so.

    Returns
    -------
    FigureOut or None
        Up to a 3 × 3 grid (δe, δa, δr; α, β, V; q, p, r against time) of the channels that
        move; channels that stay at trim (:data:`STILL_BELOW`) are left out and named in the
        caption.
    """
    if is_empty(flights, ["flight", "t_s"]):
        return None
    chans = [c for c in CHANNELS if c[0] in flights]
    if not chans:
        return None
    names, total = _flight_list(flights, max_flights)
    fl = numeric(flights[flights["flight"].astype(str).isin(names)], ["t_s"] + [c[0] for c in chans])
    fl["flight"] = fl["flight"].astype(str)
    moving = [c for c in chans if _moves(fl[c[0]])]
    still = [c[1] for c in chans if c not in moving]
    if not moving:
        return None
    ncols = min(3, len(moving))
    nrows = -(-len(moving) // ncols)
    fig = new_figure(1.4 + 2.1 * nrows)
    axes = fig.subplots(nrows, ncols, sharex=True, squeeze=False).ravel()
    groups = {k: _thin(g.sort_values("t_s")) for k, g in fl.groupby("flight", sort=False)}
    for ax, (col, sym, unit) in zip(axes, moving):
        for i, name in enumerate(names):
            g = groups.get(name)
            if g is not None:
                ax.plot(g["t_s"], g[col], color=PALETTE[i % len(PALETTE)], linewidth=1.1, label=name)
        ax.set_ylabel(f"{sym} ({unit})", fontsize=FONT)
        style_axes(ax)
    for ax in axes[len(moving):]:
        ax.set_visible(False)
    for ax in axes[max(0, len(moving) - ncols):len(moving)]:
        ax.set_xlabel("time (s)", fontsize=FONT)
    handles, labels = axes[0].get_legend_handles_labels()
    if not handles:
        handles, labels = next((a.get_legend_handles_labels() for a in axes if a.get_legend_handles_labels()[0]),
                               ([], []))
    fig.legend(handles, labels, loc="outside upper center", ncols=min(len(names), 3), fontsize=SMALL, frameon=False)
    big = ""
    if "alpha_deg" in fl:
        ex = {}
        for k, g in groups.items():
            a = g["alpha_deg"].to_numpy(float)
            a = a[np.isfinite(a)]
            if a.size:
                ex[k] = float(np.max(np.abs(a - a[0])))
        if ex:
            k = max(ex, key=ex.get)
            big = f" The largest angle-of-attack excursion is {fmt(ex[k], 2)}° ({k})."
    more = f" Only the first {len(names)} of {total} flights are shown." if total > len(names) else ""
    left = (f" {', '.join(still)} stay at trim on {'this maneuver' if len(names) == 1 else 'these maneuvers'} and "
            "are left out." if still else "")
    caption = ("The surface deflections each maneuver applies, then the aircraft's responses, all as recorded "
               "(clean). Check that every surface an equation needs moves, and that the responses stay small enough "
               "for linear models." + left + big + more)
    alt = (f"{len(moving)} line charts against time ({', '.join(c[1] for c in moving)}) overlaying "
           f"{len(names)} flights.")
    return done(fig, "time_histories", caption, alt)


def _mode_lines(modes: pd.DataFrame | None, names: list[str]) -> pd.DataFrame:
    """Mode name and frequency (Hz): natural frequency, or |real part|/2π for real modes."""
    if is_empty(modes, ["mode", "frequency_hz"]):
        return pd.DataFrame(columns=["mode", "f"])
    m = numeric(modes, ["frequency_hz", "real"])
    if "flight" in m and m["flight"].astype(str).isin(names).any():
        m = m[m["flight"].astype(str).isin(names)]
    f = m["frequency_hz"].to_numpy(float)
    if "real" in m:
        f = np.where(np.isfinite(f) & (f > 0), f, np.abs(m["real"].to_numpy(float)) / (2 * np.pi))
    out = pd.DataFrame({"mode": m["mode"].astype(str).to_numpy(), "f": f})
    out = out[np.isfinite(out["f"]) & (out["f"] > 0)]
    out["r"] = out["f"].round(2)
    return out.drop_duplicates(["mode", "r"])[["mode", "f"]]


def fig_input_spectra(flights: pd.DataFrame | None, modes: pd.DataFrame | None = None, f_max: float = 3.0,
                      max_flights: int = MAX_FLIGHTS) -> FigureOut | None:
    """Fourier magnitude of each flight's surface deflections with the aircraft's modes marked.

    Parameters
    ----------
    flights : DataFrame
        Clean time histories (``de_deg``, ``da_deg``, ``dr_deg`` against ``t_s``).
    modes : DataFrame, optional
        ``flight``, ``mode``, ``frequency_hz`` (natural frequency; 0 or missing for a real
        mode, whose break frequency |real|/2π is used when a ``real`` column is given).
    f_max : float
        Upper end of the frequency axis (Hz).
    max_flights : int
        At most this many flights are drawn.

    Returns
    -------
    FigureOut or None
        One panel per surface that moves, magnitude in dB below each flight's largest
        component (deflection from the first sample, zero-padded FFT).
    """
    if is_empty(flights, ["flight", "t_s"]):
        return None
    names, total = _flight_list(flights, max_flights)
    cols = [c for c, _ in SURFACES if c in flights]
    fl = numeric(flights[flights["flight"].astype(str).isin(names)], ["t_s"] + cols)
    spectra: dict[str, list[tuple[int, np.ndarray, np.ndarray]]] = {c: [] for c in cols}
    for i, (name, g) in enumerate(fl.groupby(fl["flight"].astype(str), sort=False)):
        g = g.sort_values("t_s")
        t = g["t_s"].to_numpy(float)
        if len(t) < 8:
            continue
        dt = float(np.median(np.diff(t)))
        n_fft = max(8192, 1 << int(np.ceil(np.log2(len(t)))))
        freq = np.fft.rfftfreq(n_fft, dt)
        mags = {}
        for c in cols:
            x = g[c].to_numpy(float)
            if np.isfinite(x).all() and np.ptp(x) > 1e-9:
                mags[c] = np.abs(np.fft.rfft(x - x[0], n_fft)) * dt
        peak = max((float(m.max()) for m in mags.values()), default=0.0)
        for c, mag in mags.items():
            keep = freq <= f_max
            spectra[c].append((names.index(name), freq[keep], 20 * np.log10(np.maximum(mag[keep] / peak, 1e-6))))
    used = [c for c in cols if spectra[c]]
    if not used:
        return None
    lines = _mode_lines(modes, names)
    fig = new_figure(1.2 + 2.3 * len(used))
    axes = fig.subplots(len(used), 1, sharex=True, squeeze=False).ravel()
    for ax, c in zip(axes, used):
        for i, f, db in spectra[c]:
            ax.plot(f, db, color=PALETTE[i % len(PALETTE)], linewidth=1.2, label=names[i])
        last, high = -np.inf, False
        for mode, f in sorted(lines.itertuples(index=False), key=lambda r: r[1]):
            if f <= f_max and c in MODE_SURFACES.get(mode.lower(), (c,)):
                ax.axvline(f, color="#444444", linestyle=":", linewidth=1.0)
                high = (not high) if f - last < 0.08 * f_max else True  # stagger labels of close modes
                last = f
                ax.text(f, 0.97 if high else 0.03, f"{mode} {fmt(f, 2)} Hz", rotation=90,
                        va="top" if high else "bottom",
                        ha="left", fontsize=SMALL, color="#333333", transform=ax.get_xaxis_transform(),
                        bbox=dict(facecolor="white", alpha=0.75, edgecolor="none", pad=1.0))
        ax.set_ylim(-60, 5)
        ax.set_xlim(0, f_max)
        ax.set_ylabel(f"{dict(SURFACES)[c]}\n(dB re peak)", fontsize=FONT)
        style_axes(ax)
    axes[-1].set_xlabel("frequency (Hz)", fontsize=FONT)
    handles = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(list(handles.values()), list(handles.keys()), loc="outside upper center",
               ncols=min(len(handles), 3), fontsize=SMALL, frameon=False)
    listed = "; ".join(f"{m} {fmt(f, 2)} Hz" for m, f in lines.itertuples(index=False))
    off = lines[lines["f"] > f_max]
    mode_txt = (f" Dotted lines mark the aircraft's modes ({listed})." if len(lines)
                else " No mode frequencies were available.")
    if len(off):
        mode_txt += f" {len(off)} mode(s) lie above {f_max:g} Hz, off the chart."
    more = f" Only the first {len(names)} of {total} flights are shown." if total > len(names) else ""
    caption = ("Fourier magnitude of each surface deflection from trim, in dB below the flight's largest "
               "component: a maneuver excites a mode where its spectrum is high (within about 20 dB of the peak) at "
               "that mode's frequency." + mode_txt + more)
    alt = f"Line charts of input spectra (0-{f_max:g} Hz) for {', '.join(dict(SURFACES)[c] for c in used)}."
    return done(fig, "input_spectra", caption, alt)


def fig_excursions(results: pd.DataFrame | None) -> FigureOut | None:
    """Peak excursions from trim per maneuver, one panel per quantity.

    Parameters
    ----------
    results : DataFrame
        The results table; only rows of method ``'excursion'`` (parameters
        ``max_dalpha_deg``, ``max_dbeta_deg``, ``max_dnz_g``, ``max_dV_fps``, value in
        ``estimate``) are used, the largest over noises and realizations.

    Returns
    -------
    FigureOut or None
        Horizontal bars per flight (maneuver, plus aircraft/variant/condition/loop when they
        vary), at most 30 flights.
    """
    if is_empty(results, ["method", "parameter", "estimate", "maneuver"]):
        return None
    ex = results[(results["method"] == "excursion") & results["parameter"].isin([p for p, _ in EXCURSIONS])]
    ex = numeric(ex, ["estimate"])
    if ex.empty or not np.isfinite(ex["estimate"].to_numpy(float)).any():
        return None
    vary = [c for c in ("aircraft", "variant", "condition", "loop") if c in ex and ex[c].nunique() > 1]
    ex = ex.assign(label=ex["maneuver"].astype(str).str.cat([ex[c].astype(str) for c in vary], sep=", ")
                   if vary else ex["maneuver"].astype(str))
    table = ex.pivot_table(index="label", columns="parameter", values="estimate", aggfunc="max", sort=False)
    total = len(table)
    table = table.iloc[:30]
    shown = [(p, title) for p, title in EXCURSIONS if p in table and _departs(table[p])]
    if not shown:
        return None
    ncols = min(2, len(shown))
    nrows = -(-len(shown) // ncols)
    fig = new_figure(1.0 + nrows * (0.8 + 0.22 * len(table)))
    axes = fig.subplots(nrows, ncols, sharey=True, squeeze=False).ravel()
    y = np.arange(len(table))
    for ax, (p, title), color in zip(axes, shown, PALETTE):
        v = table[p].to_numpy(float)
        ax.barh(y, np.where(np.isfinite(v), np.abs(v), 0.0), color=color, height=0.7)
        ax.set_xlabel(title, fontsize=FONT)
        style_axes(ax, "x")
    for ax in axes[len(shown):]:
        ax.set_visible(False)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels(table.index, fontsize=SMALL)
    axes[0].invert_yaxis()
    big = ""
    if "max_dalpha_deg" in table and table["max_dalpha_deg"].notna().any():
        k = table["max_dalpha_deg"].abs().idxmax()
        big = f" The largest angle-of-attack excursion is {fmt(abs(table.loc[k, 'max_dalpha_deg']), 2)}° ({k})."
    more = f" Only the first 30 of {total} flights are shown." if total > 30 else ""
    still = [title.split(" (")[0].replace("largest ", "") for p, title in EXCURSIONS if (p, title) not in shown]
    left = f" {', '.join(still)} stay at zero and are left out." if still else ""
    caption = ("Bars are each maneuver's largest departure from trim; large excursions carry the aircraft across "
               "table breakpoints, where local and fitted truths differ and linear models strain." + big + left
               + more)
    alt = (f"{len(shown)} horizontal bar charts of peak excursions "
           f"({', '.join(t.split(' (')[0].replace('largest ', '') for _, t in shown)}) for {len(table)} maneuvers.")
    return done(fig, "excursions", caption, alt)
