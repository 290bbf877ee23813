"""The report of any campaign: scores, the seed's figures, and provenance."""
from __future__ import annotations

import numpy as np
import pandas as pd

from reports import figures as F
from reports.load import CampaignOutput, provenance
from reports.render import Report, Section, Table

SCORE_COLUMNS = ["noise", "maneuver", "method", "errors", "parameter", "n", "truth", "mean", "bias_pct", "bias_z",
                 "std", "rmse", "se_ratio", "coverage", "coverage_lo", "coverage_hi", "efficiency", "time_s"]
MAX_TABLE_ROWS = 300


def score_table(scores: pd.DataFrame, title: str = "Scores", caption: str = "") -> Table:
    """Scores with the cells that break a claim highlighted: |bias| beyond 3 Monte Carlo
    standard errors, coverage whose 95 % interval excludes 0.95, standard-error ratios outside
    [0.8, 1.25]."""
    s = scores.reset_index(drop=True)
    cols = [c for c in SCORE_COLUMNS if c in s.columns and (c not in ("maneuver",) or s[c].nunique() > 1)]
    frame = s[cols].head(MAX_TABLE_ROWS).reset_index(drop=True)
    hl = []
    for i, r in frame.iterrows():
        if np.isfinite(r.get("bias_z", np.nan)) and abs(r["bias_z"]) > 3:
            hl.append((i, "bias_z", "bad"))
        if np.isfinite(r.get("coverage_lo", np.nan)) and (r["coverage_hi"] < 0.95 or r["coverage_lo"] > 0.95):
            hl.append((i, "coverage", "bad" if abs(r["coverage"] - 0.95) > 0.1 else "warn"))
        if np.isfinite(r.get("se_ratio", np.nan)) and not 0.8 <= r["se_ratio"] <= 1.25:
            hl.append((i, "se_ratio", "warn"))
    note = f" Showing the first {MAX_TABLE_ROWS} of {len(s)} rows; every number is in the JSON report." \
        if len(s) > MAX_TABLE_ROWS else ""
    return Table(title, frame, (caption or "One row per cell (noise, method, errors) and parameter. Red: |bias| "
                                "over 3 Monte Carlo standard errors or coverage far from 0.95; amber: standard-error "
                                "ratio outside [0.8, 1.25] or coverage's interval excluding 0.95.") + note,
                 tuple(hl))


def method_summary(scores: pd.DataFrame) -> pd.DataFrame:
    """Per noise, method and errors: median coverage, median and worst |bias_z|, median
    relative RMSE and standard-error ratio, over the parameters."""
    s = scores.copy()
    s["abs_bias_z"] = s["bias_z"].abs()
    s["rel_rmse_pct"] = 100 * s["rmse"] / s["truth"].abs()
    g = s.groupby(["noise", "method", "errors"], dropna=False)
    return g.agg(parameters=("parameter", "count"), median_coverage=("coverage", "median"),
                 median_abs_bias_z=("abs_bias_z", "median"), worst_abs_bias_z=("abs_bias_z", "max"),
                 median_rel_rmse_pct=("rel_rmse_pct", "median"), median_se_ratio=("se_ratio", "median"),
                 mean_time_ms=("time_s", lambda x: 1e3 * np.nanmean(x))).reset_index()


def summary_lines(out: CampaignOutput) -> list[str]:
    s = out.truth_scores
    m = out.meta
    lines = [f"{m['campaign']['name']}: {m['campaign']['cells']} cells x {m['campaign']['realizations']} realizations, "
             f"{m.get('estimates', len(out.results))} estimates in {m.get('wall_s', float('nan')):.1f} s on {m.get('executor')}."]
    if not s.empty:
        ms = method_summary(s)
        for _, r in ms.sort_values("median_abs_bias_z").iterrows():
            lines.append(f"{r['method']} ({r['errors']}, {r['noise']}): median coverage {r['median_coverage']:.2f}, "
                         f"worst |bias| {r['worst_abs_bias_z']:.1f} Monte Carlo standard errors, "
                         f"median relative RMSE {r['median_rel_rmse_pct']:.1f} %.")
            if len(lines) >= 9:
                break
    return lines


def _figs(*items):
    return tuple(f for f in items if f is not None)


def campaign_sections(out: CampaignOutput) -> list[Section]:
    s = out.truth_scores
    sections = [Section("Methods at a glance", ("Medians over the parameters of each cell.",),
                        (Table("Methods", method_summary(s), "median_abs_bias_z near 1 and median_coverage near 0.95 "
                               "mean unbiased estimates with honest bounds."),) if not s.empty else ()),
                Section("Accuracy and honesty", (), (score_table(s),),
                        _figs(F.fig_bias(s), F.fig_coverage(s), F.fig_se_ratio(s), F.fig_efficiency(s),
                              F.fig_scatter(out.results, s)))]
    if "max_corr" in s and s["loop"].nunique() > 2:
        sections.append(Section("Collinearity", (), (), _figs(F.fig_bias_vs_correlation(s))))
    if not out.examples.empty:
        sections.append(Section("Model fit and residuals (one realization)", (), (),
                                _figs(F.fig_model_fit(out.examples), F.fig_residuals(out.examples))))
    if not out.flights.empty:
        ex = out.results[out.results["method"] == "excursion"]
        sections.append(Section("Maneuvers", (), (),
                                _figs(F.fig_time_histories(out.flights), F.fig_input_spectra(out.flights, out.modes),
                                      F.fig_excursions(ex) if not ex.empty else None)))
    if not out.differentiation.empty:
        d = out.differentiation.groupby("method")["rms_error_pct"].agg(["mean", "max"]).reset_index()
        sections.append(Section("Differentiating noisy rates (seed Fig. 1)",
                                ("Methods: 1 smoother then local derivative; 2 the smoother's frequency-domain "
                                 "derivative; 3 local derivative then smoother.",),
                                (Table("RMS derivative error, %", d, "Means over the sequences."),),
                                _figs(F.fig_differentiation_error(out.differentiation))))
    return sections


def campaign_report(out: CampaignOutput) -> Report:
    """The report of a campaign's output folder."""
    s = out.truth_scores
    numbers = {"scores": out.scores.replace({np.nan: None}).to_dict(orient="records"),
               "methods": method_summary(s).replace({np.nan: None}).to_dict(orient="records") if not s.empty else []}
    return Report(title=f"Campaign report: {out.meta['campaign']['name']}", kind="campaign",
                  provenance=provenance(out.meta), summary=tuple(summary_lines(out)),
                  sections=tuple(campaign_sections(out)), numbers=numbers)
