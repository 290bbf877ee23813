"""The report of any campaign: what it found first (the largest biases, coverage failures and
the method comparison), then what it flew, the scores, the seed's figures and provenance."""
from __future__ import annotations

import numpy as np
import pandas as pd

from reports import figures as F
from reports.campaign_setup import read_setup
from reports.findings import (COVERAGE_BAND, Findings, case_columns, efficiency_note, find, one_per_estimate,
                              status_of)
from reports.lead import findings_section, lead_lines, setup_section, status_note
from reports.load import CampaignOutput, provenance
from reports.render import Report, Section, Table

MAX_TABLE_ROWS = 300
SE_RATIO_BAND: tuple[float, float] = (0.8, 1.25)
"""Standard-error ratios counted honest enough not to flag (a 25 % error either way)."""
GATE_KEYS: tuple[str, ...] = ("noise", "method", "errors", "maneuver", "parameter")
"""The columns that name a gated cell in the nightly gate table."""
_ACCURACY_COLUMNS = {"method": "method", "parameter": "parameter", "truth": "truth", "mean": "mean",
                     "bias_pct": "bias %", "bias_z": "bias z", "rmse": "RMSE", "efficiency": "efficiency"}
_HONESTY_COLUMNS = {"method": "method", "errors": "errors", "parameter": "parameter", "mean_se": "mean SE",
                    "std": "scatter", "se_ratio": "SE ratio", "coverage": "coverage"}
_SUMMARY_COLUMNS = {"noise": "noise", "method": "method", "errors": "errors", "parameters": "parameters",
                    "median_coverage": "median coverage", "median_abs_bias_z": "median |bias z|",
                    "worst_abs_bias_z": "worst |bias z|", "median_rel_rmse_pct": "median relative RMSE %",
                    "median_se_ratio": "median SE ratio", "mean_time_ms": "time per estimate ms"}


def _failed_cells(gates: pd.DataFrame | None, kind: str) -> set[tuple]:
    """Keys (:data:`GATE_KEYS`) of the cells that failed a gate of ``kind``."""
    if gates is None or gates.empty:
        return set()
    g = gates[(gates["kind"] == kind) & ~gates["passed"].astype(bool)]
    return {tuple(r[k] for k in GATE_KEYS) for _, r in g.iterrows()}


def _key(r: pd.Series) -> tuple:
    return tuple(r.get(k) for k in GATE_KEYS)


def _accuracy_frame(s: pd.DataFrame) -> pd.DataFrame:
    """The varying case columns, method, parameter, truth, mean, bias, RMSE and efficiency (when
    there is one): what the estimates do, the same for every error type."""
    cases = [c for c in case_columns(s) if c in s]
    cols = [c for c in _ACCURACY_COLUMNS if c in s and (c != "efficiency" or np.isfinite(s[c].astype(float)).any())]
    return s[cases + cols].rename(columns=_ACCURACY_COLUMNS)


def _honesty_frame(s: pd.DataFrame) -> pd.DataFrame:
    """The varying case columns, method, errors, parameter, mean reported standard error, scatter,
    their ratio, coverage and its exact 95 % binomial interval."""
    cases = [c for c in case_columns(s) if c in s]
    frame = s[cases + [c for c in _HONESTY_COLUMNS if c in s]].rename(columns=_HONESTY_COLUMNS)
    if {"coverage_lo", "coverage_hi"} <= set(s):
        frame["95 % interval"] = [f"[{lo:.2f}, {hi:.2f}]" if np.isfinite(lo) and np.isfinite(hi) else "—"
                                  for lo, hi in zip(s["coverage_lo"], s["coverage_hi"])]
    return frame


def _bias_highlights(s: pd.DataFrame, bias_limit: float, gates: pd.DataFrame | None) -> tuple:
    """Red: a bias beyond the limit (with gates: only a failed bias gate; amber otherwise)."""
    failed = _failed_cells(gates, "bias")
    hl = []
    for i, r in s.iterrows():
        z = float(r.get("bias_z", np.nan))
        if np.isfinite(z) and abs(z) > bias_limit:
            hl.append((i, "bias z", "bad" if gates is None or _key(r) in failed else "warn"))
    return tuple(hl)


def _honesty_highlights(s: pd.DataFrame, gates: pd.DataFrame | None) -> tuple:
    """Red: a coverage interval wholly outside the band (with gates: only a failed coverage gate);
    amber: an interval excluding 0.95 otherwise, or a standard-error ratio outside its band."""
    failed = _failed_cells(gates, "coverage")
    lo_band, hi_band = COVERAGE_BAND
    hl = []
    for i, r in s.iterrows():
        lo, hi = float(r.get("coverage_lo", np.nan)), float(r.get("coverage_hi", np.nan))
        if np.isfinite(lo) and np.isfinite(hi) and (hi < 0.95 or lo > 0.95):
            bad = _key(r) in failed if gates is not None else (hi < lo_band or lo > hi_band)
            hl.append((i, "coverage", "bad" if bad else "warn"))
        ratio = float(r.get("se_ratio", np.nan))
        if np.isfinite(ratio) and not SE_RATIO_BAND[0] <= ratio <= SE_RATIO_BAND[1]:
            hl.append((i, "SE ratio", "warn"))
    return tuple(hl)


def _rows_note(shown: int, total: int) -> str:
    return (f" Showing the first {shown} of {total} rows; every number is in the JSON report."
            if total > shown else "")


def accuracy_table(scores: pd.DataFrame, bias_limit: float, gates: pd.DataFrame | None = None) -> Table:
    """One row per cell (error types collapsed: they share the estimates) and parameter: truth,
    mean, bias, RMSE, efficiency; a bias beyond ``bias_limit`` highlighted (with ``gates``, the
    nightly gate table, only a failed gate is red)."""
    every = one_per_estimate(scores)
    s = every.head(MAX_TABLE_ROWS).reset_index(drop=True)
    red = ("Red: a failed bias gate (other cells are not gated: amber at most)" if gates is not None else
           f"Red: |bias| beyond {bias_limit:.2f} Monte Carlo standard errors (Bonferroni, 1 % family-wise)")
    caption = f"One row per cell and parameter; error types share the estimates, so each appears once. {red}."
    note = efficiency_note(scores)
    caption += (" " + note if note else "") + _rows_note(len(s), len(every))
    return Table("Scores: accuracy", _accuracy_frame(s), caption, _bias_highlights(s, bias_limit, gates))


def honesty_table(scores: pd.DataFrame, gates: pd.DataFrame | None = None) -> Table:
    """One row per cell and parameter: the reported standard errors against the scatter, and the
    coverage of the ±2σ intervals with its exact binomial interval."""
    s = scores.reset_index(drop=True).head(MAX_TABLE_ROWS)
    n = sorted({int(x) for x in scores["n"].dropna()}) if "n" in scores else []
    lo, hi = COVERAGE_BAND
    red = ("Red: a failed coverage gate (other cells are not gated: amber at most)" if gates is not None else
           f"Red: a coverage whose 95 % interval lies wholly outside [{lo:.2f}, {hi:.2f}]")
    caption = (f"Mean reported standard error against the scatter of the estimates (SE ratio 1 = honest bounds) and "
               f"coverage of the ±2σ intervals over {'/'.join(map(str, n)) or '?'} realizations. {red}; amber: a "
               f"coverage interval excluding 0.95 or an SE ratio outside [{SE_RATIO_BAND[0]}, {SE_RATIO_BAND[1]}]."
               + _rows_note(len(s), len(scores)))
    return Table("Scores: honesty of the bounds", _honesty_frame(s), caption, _honesty_highlights(s, gates))


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


def summary_table(scores: pd.DataFrame, bias_limit: float) -> Table:
    """:func:`method_summary` with short headings, the worst bias beyond the limit in red."""
    ms = method_summary(scores)
    hl = tuple((i, "worst |bias z|", "bad") for i, z in enumerate(ms["worst_abs_bias_z"])
               if np.isfinite(z) and z > bias_limit)
    return Table("Methods", ms.rename(columns=_SUMMARY_COLUMNS),
                 "Medians over the parameters of each cell: median |bias z| near 1 and median coverage near 0.95 mean "
                 "unbiased estimates with honest bounds.", hl)


def _figs(*items):
    return tuple(f for f in items if f is not None)


def campaign_sections(out: CampaignOutput, findings: Findings | None = None,
                      gates: pd.DataFrame | None = None) -> list[Section]:
    """The sections after the lead: methods at a glance, scores and figures, collinearity,
    model fit, maneuvers, differentiation."""
    s = out.truth_scores
    f = findings if findings is not None else find(s)
    sections = [Section("Methods at a glance", (), (summary_table(s, f.bias_limit),) if not s.empty else ()),
                Section("Accuracy and honesty", (),
                        (accuracy_table(s, f.bias_limit, gates), honesty_table(s, gates)),
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


def _lead_numbers(f: Findings) -> dict:
    """The findings for machines: the limit, the biases, the coverage failures, the comparison."""
    def rows(frame: pd.DataFrame, columns: list[str]) -> list[dict]:
        cols = [c for c in columns if c in frame]
        return frame[cols].replace({np.nan: None}).to_dict(orient="records") if not frame.empty else []
    keys = list(f.cases) + ["method", "parameter", "truth", "bias_pct", "bias_z"]
    return {"bias_limit": f.bias_limit, "bias_tests": len(f.tests), "coverage_band": list(COVERAGE_BAND),
            "cells_with_coverage": f.cells_with_coverage, "min_realizations": f.min_n,
            "biases": rows(f.biases, keys), "comparison": rows(f.comparison, keys),
            "coverage_failures": rows(f.coverage, list(f.cases) + ["method", "errors", "parameter", "coverage",
                                                                   "coverage_lo", "coverage_hi", "se_ratio"])}


def campaign_report(out: CampaignOutput) -> Report:
    """The report of a campaign's output folder; its status is ``'findings'`` when a bias or a
    coverage failure was found (:func:`reports.findings.status_of`)."""
    s = out.truth_scores
    f = find(s)
    setup = read_setup(out.meta)
    numbers = {"lead": _lead_numbers(f),
               "scores": out.scores.replace({np.nan: None}).to_dict(orient="records"),
               "methods": method_summary(s).replace({np.nan: None}).to_dict(orient="records") if not s.empty else []}
    sections = [findings_section(f), setup_section(out, setup)] + campaign_sections(out, f)
    return Report(title=f"Campaign report: {out.meta['campaign']['name']}", kind="campaign",
                  provenance=provenance(out.meta), summary=tuple(lead_lines(out, f, setup)),
                  sections=tuple(sections), numbers=numbers, status=status_of(f), status_note=status_note(f))
