"""The report of one estimate (``sidbench estimate --report DIR``): measured against model, the
residual in time and its spectrum, the regressors, and the estimates with their bounds (and,
on a simulated recording, the truth beside them). Written as DIR/report.html (self-contained),
report.md and report.json."""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from reports import figures_estimate as FE
from reports.render import Report, Section, Table


def _sha256(path: str) -> str | None:
    p = Path(path)
    try:
        return hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else None
    except OSError:
        return None


def estimate_report(run) -> Report:
    """A :class:`reports.render.Report` of a :class:`harness.estimate_run.EstimateRun`."""
    fit = run.fit
    table = run.parameter_table()
    shown = table.drop(columns=["method", "dependent"] + (["truth_definition"] if "truth_definition" in table else []))
    shown = shown.set_index("parameter")
    highlight = ()
    if run.simulated:
        highlight = tuple((i, "error_in_se", "bad" if abs(z) > 3 else "good")
                          for i, z in enumerate(shown["error_in_se"]) if np.isfinite(z))
    summary = [f"{fit.method} ({fit.domain} domain), {fit.dependent}: {len(fit.names)} parameters from {fit.n} "
               f"points, R² = {fit.rsquared:.5f}, fit error {fit.fit_error:.4g}, errors {fit.errors}."]
    if run.simulated:
        z = shown["error_in_se"].to_numpy(float)
        z = z[np.isfinite(z)]
        if len(z):
            summary.append(f"Against the recording's {run.truth_definition} truth: largest |error| "
                           f"{np.max(np.abs(z)):.2f} standard errors over {len(z)} parameters"
                           + (" (above 3: a bias or bounds too small)." if np.max(np.abs(z)) > 3 else "."))
    else:
        summary.append("The recording carries no truth (flight data): the estimates are shown with their bounds.")
    summary += [f"Warning: {w}" for w in fit.warnings]

    est_caption = ("t = estimate / std error, p its two-sided p-value "
                   + ("(normal: Cramér-Rao bounds)" if fit.uses_normal else f"(Student's t, {fit.df_resid} dof)")
                   + "; the 95 % interval at the same distribution.")
    if run.simulated:
        est_caption += (f" Truth: the recording's {run.truth_definition} derivatives; error_in_se = "
                        "(estimate − truth) / std error, red beyond 3.")
    tables = [Table("Estimates", shown, caption=est_caption, highlight=highlight)]
    corr = pd.DataFrame(np.nan_to_num(np.asarray(fit.correlation)), index=list(fit.names), columns=list(fit.names))
    tables.append(Table("Parameter correlation", corr.round(3),
                        caption="Seed Eq. 50; |r| above 0.9 means the data cannot tell the pair apart."))
    stats = pd.DataFrame({"value": [fit.n, fit.s2, fit.rsquared, fit.fit_error, fit.pse,
                                    fit.collinearity.condition_number if fit.collinearity is not None else np.nan]},
                         index=pd.Index(["points", "s2", "R2", "fit error", "PSE", "condition number"], name="statistic"))
    tables.append(Table("Fit statistics", stats))
    opts = pd.DataFrame({"value": [str(v) for v in run.options.values()]},
                        index=pd.Index(list(run.options), name="option"))

    sections = [Section("Estimates", (), tuple(tables), tuple(f for f in [FE.fig_estimates(table)] if f))]
    if run.time is not None:
        figs = [FE.fig_measured_vs_model(run.time, fit.dependent, fit.method), FE.fig_residual(run.time, fit.dependent)]
        sections.append(Section("Model against measurement", tuple(run.notes), (), tuple(f for f in figs if f)))
    elif run.notes:
        sections.append(Section("Model against measurement", tuple(run.notes)))
    reg_title = "regressors" if fit.method not in ("oe", "oe-freq", "fe") else "recorded surfaces (the model's inputs)"
    reg_fig = FE.fig_regressors(run.regressors, reg_title)
    reg_paragraphs = (f"Regressors: {', '.join(run.regressor_names) or 'none'}.",)
    sections.append(Section("Regressors", reg_paragraphs, (), (reg_fig,) if reg_fig else ()))
    sections.append(Section("Options", ("Every option of the command line, defaults included.",),
                            (Table("Options", opts),)))

    numbers = {"parameters": table.replace({np.nan: None}).to_dict(orient="records"),
               "r2": fit.rsquared, "s2": fit.s2, "fit_error": fit.fit_error, "n": fit.n,
               "options": run.options, "regressors": list(run.regressor_names)}
    provenance = {"file": run.recording, "sha256": _sha256(run.recording)}
    return Report(title=f"Estimate: {fit.dependent} by {fit.method} from {Path(run.recording).name}",
                  kind="estimate", provenance=provenance, summary=tuple(summary), sections=tuple(sections),
                  numbers=numbers)


def write_estimate_report(run, out_dir: str | Path) -> Path:
    """Write OUT_DIR/report.html (+ .md, .json); returns the HTML path."""
    from reports.commands import write_all
    return write_all(estimate_report(run), Path(out_dir), "report")
