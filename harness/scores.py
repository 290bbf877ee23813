"""Scores per cell and parameter: bias, scatter, honesty of the error bounds, efficiency.

A *cell* is everything that defines an experiment except the realization: aircraft, variant,
condition, maneuver, loop, noise, method, errors, equation. For each cell and parameter:

- ``truth`` (the definition named in ``truth_definition``, 'local' or 'fit') and ``mean``;
- ``bias`` = mean − truth, ``bias_pct`` = 100 bias/|truth|, ``bias_mcse`` = s/√n (the Monte
  Carlo standard error of the mean) and ``bias_z`` = bias / bias_mcse;
- ``std`` (empirical, n − 1), ``rmse``;
- ``mean_se`` (mean reported standard error) and ``se_ratio`` = mean_se / std (1.0 means
  honest error bounds);
- ``coverage`` of the ±2σ interval (|estimate − truth| ≤ 2·se) with its exact
  (Clopper-Pearson) 95 % binomial interval ``coverage_lo``, ``coverage_hi``;
- ``crb`` (the Cramér-Rao standard deviation at the true parameters with the true output
  noise, from the output-error information matrix) and ``efficiency`` = crb² / std²;
- ``time_s`` (mean time per estimate), ``max_corr`` (mean largest pairwise |r| of Eq. 50 among
  the derivatives) and the counts ``n`` and ``failures``.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import binomtest

CELL = ["campaign", "aircraft", "variant", "condition", "maneuver", "loop", "noise", "method", "errors",
        "equation", "dependent", "parameter"]
FLIGHT_NOISE = ["campaign", "aircraft", "variant", "condition", "maneuver", "loop", "noise", "dependent", "parameter"]
COVERAGE_K = 2.0


def _cell_scores(g: pd.DataFrame, truth_col: str) -> dict:
    ok = g[g["ok"]]
    est = ok["estimate"].to_numpy(float)
    se = ok["std_error"].to_numpy(float)
    n = len(est)
    truth = float(g[truth_col].iloc[0]) if len(g) else float("nan")
    out = {"n": n, "failures": int((~g["ok"]).sum()), "truth": truth}
    if n == 0:
        return out
    mean = float(est.mean())
    std = float(est.std(ddof=1)) if n > 1 else float("nan")
    if std <= 1e-12 * max(abs(truth), 1e-300) or std == 0.0:
        std = float("nan")  # no scatter (noise-free): ratios against it are undefined
    mcse = std / np.sqrt(n) if n > 1 else float("nan")
    bias = mean - truth
    covered = int(np.sum(np.abs(est - truth) <= COVERAGE_K * se)) if np.isfinite(truth) else 0
    if np.isfinite(truth):
        ci = binomtest(covered, n).proportion_ci(confidence_level=0.95, method="exact")
        lo, hi = float(ci.low), float(ci.high)
    else:
        lo = hi = float("nan")
    out.update({
        "mean": mean, "bias": bias, "bias_pct": 100 * bias / abs(truth) if truth else float("nan"),
        "bias_mcse": mcse, "bias_z": bias / mcse if mcse and mcse > 0 else float("nan"),
        "std": std, "rmse": float(np.sqrt(np.mean((est - truth) ** 2))),
        "mean_se": float(np.mean(se)), "se_ratio": float(np.mean(se) / std) if std and std > 0 else float("nan"),
        "coverage": covered / n if np.isfinite(truth) else float("nan"), "coverage_lo": lo, "coverage_hi": hi,
        "time_s": float(np.nanmean(ok["time_s"].to_numpy(float))),
        "max_corr": float(np.nanmean(ok["max_corr"].to_numpy(float))) if "max_corr" in ok and ok["max_corr"].notna().any() else float("nan"),
    })
    return out


def score(results: pd.DataFrame, truth: str = "local") -> pd.DataFrame:
    """Aggregate a tidy results table (one row per realization × parameter) into scores."""
    if truth not in ("local", "fit"):
        raise ValueError("truth must be 'local' or 'fit'")
    truth_col = f"truth_{truth}"
    est = results[~results["method"].isin(["crb", "excursion", "check"])]
    crb = results[results["method"] == "crb"].groupby(FLIGHT_NOISE, dropna=False)["std_error"].first()
    rows = []
    for key, g in est.groupby(CELL, sort=True, dropna=False):
        row = dict(zip(CELL, key)) | {"truth_definition": truth} | _cell_scores(g, truth_col)
        ck = tuple(row[k] for k in FLIGHT_NOISE)
        c = float(crb.get(ck, np.nan)) if len(crb) else float("nan")
        row["crb"] = c
        std = row.get("std", float("nan"))
        row["efficiency"] = c * c / (std * std) if std and np.isfinite(std) and std > 0 and np.isfinite(c) else float("nan")
        rows.append(row)
    return pd.DataFrame(rows)


SCORE_TABLE_COLUMNS = ["noise", "method", "errors", "parameter", "n", "truth", "bias_pct", "bias_z", "std",
                       "se_ratio", "coverage", "efficiency"]


def format_scores(scores: pd.DataFrame, columns: list[str] | None = None, max_rows: int = 80) -> str:
    """A readable score table for the terminal (parameters with a truth only)."""
    cols = [c for c in (columns or SCORE_TABLE_COLUMNS) if c in scores.columns]
    s = scores[np.isfinite(scores["truth"].astype(float))] if "truth" in scores else scores
    vary = [c for c in ("aircraft", "variant", "maneuver", "loop", "equation") if c in s and s[c].nunique() > 1]
    cols = vary + cols
    with pd.option_context("display.max_rows", max_rows, "display.width", 200, "display.max_columns", 30,
                           "display.float_format", lambda v: f"{v:.4g}"):
        return s[cols].to_string(index=False)
