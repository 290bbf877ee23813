"""The report of a calibration (``sidbench calibrate``): the estimates with their bounds, the
fit before and after per channel, and the measured / before / after time histories. Read from
the output folder (calibration.json, series/*.parquet); written as report.html
(self-contained, figures embedded), report.md and report.json beside them."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from reports.figures_common import done, new_figure, style_axes
from reports.render import Report, Section, Table

_UNITS = {"alpha": "rad", "beta": "rad", "p": "rad/s", "q": "rad/s", "r": "rad/s", "phi": "rad", "theta": "rad",
          "V": "ft/s", "ax": "g", "ay": "g", "az": "g"}


def _parameters(doc: dict) -> pd.DataFrame:
    df = pd.DataFrame(doc["parameters"]).set_index("name")
    df["change_in_se"] = (df["estimate"] - df["start"]) / df["std_error"].where(df["std_error"] > 0)
    crb = doc.get("crb_std_error", {})
    df["crb_std_error"] = [crb.get(n) for n in df.index]
    return df[["start", "estimate", "std_error", "crb_std_error", "units", "change_in_se"]]


def _fit_table(doc: dict, role: str) -> pd.DataFrame:
    rows = []
    for c, after in doc["fit_after"].get(role, {}).items():
        before = doc["fit_before"][role][c]
        rb, ra = before["rms"], after["rms"]
        rows.append({"channel": c, "units": _UNITS.get(c, ""), "rms_before": rb, "rms_after": ra,
                     "change_pct": 100.0 * (ra / rb - 1.0) if rb and ra is not None else None,
                     "theil_u_before": before["theil_u"], "theil_u_after": after["theil_u"]})
    return pd.DataFrame(rows).set_index("channel") if rows else pd.DataFrame()


def fig_time_histories(df: pd.DataFrame, outputs: list[str], title: str, name: str):
    """Measured (grey), smoothed (black), before (red, dashed) and after (blue) per output."""
    shown = [o for o in outputs if f"meas_{o}" in df]
    if not shown:
        return None
    fig = new_figure(1.5 * len(shown) + 0.6)
    axes = fig.subplots(len(shown), 1, sharex=True, squeeze=False)[:, 0]
    t = df["t_s"].to_numpy()
    for ax, o in zip(axes, shown):
        ax.plot(t, df[f"meas_{o}"], color="0.75", lw=0.6, label="measured")
        ax.plot(t, df[f"smooth_{o}"], color="black", lw=1.0, label="measured, smoothed")
        ax.plot(t, df[f"before_{o}"], color="tab:red", lw=1.0, ls="--", label="model before")
        ax.plot(t, df[f"after_{o}"], color="tab:blue", lw=1.0, label="model after")
        ax.set_ylabel(f"{o} ({_UNITS.get(o, '')})", fontsize=8)
        style_axes(ax)
    axes[0].legend(fontsize=7, ncol=4, loc="upper right")
    axes[0].set_title(title, fontsize=9)
    axes[-1].set_xlabel("t (s)", fontsize=8)
    return done(fig, name, f"{title}: measured, the model before and after calibration (each flight's mean offset "
                           "from the smoothed recording removed).", f"time histories of {', '.join(shown)}")


def calibration_report(out_dir: str | Path) -> Report:
    """A :class:`reports.render.Report` of the calibration in ``out_dir``."""
    out = Path(out_dir)
    doc = json.loads((out / "calibration.json").read_text())
    params = _parameters(doc)
    summary = [f"{len(params)} parameters of {doc['model']['base']} calibrated in {doc['iterations']} Gauss-Newton "
               f"iterations ({'converged' if doc['converged'] else 'NOT converged'}), {doc['flights']} JSBSim flights, "
               f"{doc['seconds']:.1f} s."]
    for n, r in params.iterrows():
        summary.append(f"{n}: {r['start']:.4g} → {r['estimate']:.4g} ± {r['std_error']:.2g} {r['units']}")
    for role in doc["fit_after"]:
        fit = _fit_table(doc, role)
        if not fit.empty:
            best = fit["change_pct"].dropna().sort_values()
            if len(best):
                summary.append(f"{role}: RMS error {', '.join(f'{c} {v:+.0f} %' for c, v in best.items())}.")
    summary += [f"Note: {n}" for n in doc.get("notes", [])[:5]]
    stock = doc["model"].get("stock_check", {})
    summary.append(f"Calibrated XML {doc['model']['xml']}: "
                   + ("loads and flies in stock JSBSim." if stock.get("flies") else f"stock JSBSim check: {stock}."))
    sections = [Section("Estimates", (doc.get("std_error_kind", ""),), (Table("Parameters", params),))]
    names = doc.get("correlation_names", list(params.index))
    corr = pd.DataFrame(np.asarray(doc["correlation"], dtype=float), index=names, columns=names).round(3)
    sections.append(Section("Correlation", ("|r| above 0.9: the data cannot tell the pair apart.",),
                            (Table("Parameter correlation", corr),)))
    for role in doc["fit_after"]:
        fit = _fit_table(doc, role)
        figs = []
        for k, s in enumerate(x for x in doc.get("series", []) if x["role"] == role):
            df = pd.read_parquet(out / s["file"])
            fig = fig_time_histories(df, doc["outputs"], f"{role} {k + 1}: {Path(s['recording']).name}",
                                     f"{role}-{k + 1}")
            if fig is not None:
                figs.append(fig)
        sections.append(Section(f"Fit: {role}", (doc.get("fit_definition", ""),),
                                (Table(f"RMS error and Theil's U, {role}", fit),) if not fit.empty else (),
                                tuple(figs)))
    sections.append(Section("Model", (f"Calibrated aircraft: {doc['model']['xml']} ({doc['model']['delays']}); "
                                      f"engines and systems: {doc['model']['engines_and_systems']}.",
                                      f"Stock JSBSim check: {stock}.")))
    return Report(title=f"Calibration of {doc['model']['base']}", kind="estimate",
                  provenance={"file": ", ".join(doc["inputs"].get("recordings", [])), "seed": doc.get("seed")},
                  summary=tuple(summary), sections=tuple(sections), numbers=doc,
                  status="ok" if doc["converged"] else "findings",
                  status_note="" if doc["converged"] else "the fit did not converge")


def write_calibration_report(out_dir: str | Path) -> Path:
    """Write OUT_DIR/report.html (+ .md, .json); returns the HTML path."""
    from reports.commands import write_all
    return write_all(calibration_report(out_dir), Path(out_dir), "report")
