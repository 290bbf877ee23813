"""What a campaign found, ranked: the largest biases, the coverage failures and the method
comparison per case, computed from the scores (never from remembered numbers).

Rules, each a documented parameter:

- **Bias finding**: |bias| beyond the Bonferroni critical value that keeps the chance of any
  false alarm over all the bias tests of the report at ``false_alarm`` (default
  :data:`BIAS_FALSE_ALARM` = 1 %), the rule of the nightly ``unbiased`` gate
  (``harness/nightly-gates.toml``, :func:`harness.gates.family_z`). Error types change the
  bounds, not the estimates, so one bias test is counted per cell and parameter.
- **Coverage failure**: the exact 95 % binomial interval of a cell's coverage lies wholly
  outside :data:`COVERAGE_BAND` = [0.90, 0.99], the band of the nightly ``honest error
  bounds`` gate.
- **Few realizations**: conclusions from fewer than :data:`MIN_REALIZATIONS` = 30 are marked
  rough (at n = 30 the binomial half-width of a 0.95 coverage is ±0.08 and a bias's Monte
  Carlo standard error is itself uncertain by ±13 %).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from harness.gates import family_z

__all__ = ["BIAS_FALSE_ALARM", "COVERAGE_BAND", "MIN_REALIZATIONS", "METHOD_LABELS", "CASE_COLUMNS",
           "Findings", "find", "one_per_estimate", "bias_tests", "bias_findings", "coverage_failures", "case_columns",
           "comparison", "method_label", "rough_note", "status_of", "efficiency_note"]

BIAS_FALSE_ALARM: float = 0.01
"""Family-wise false-alarm rate of the bias findings (the nightly ``unbiased`` gate's)."""
COVERAGE_BAND: tuple[float, float] = (0.90, 0.99)
"""Coverage of the ±2σ intervals counted honest (the nightly ``honest error bounds`` gate's band)."""
MIN_REALIZATIONS: int = 30
"""Below this many realizations per cell, the report says its conclusions are rough."""
METHOD_LABELS: dict[str, str] = {
    "ee-time": "least squares",
    "ee-smooth": "smoothed regressors",
    "ee-freq": "frequency domain",
    "oe": "output error",
    "oe-freq": "output error in the frequency domain",
    "fe": "filter error",
    "ee-concat": "concatenated maneuvers",
    "ee-sequential": "sequential combination",
    "ee-sequential-unequal": "sequential combination, unequal variances",
    "ee-freq-combined": "frequency domain, maneuvers combined",
}
"""Plain names of the methods, for the lead lines."""
CASE_COLUMNS: tuple[str, ...] = ("aircraft", "variant", "condition", "maneuver", "loop", "noise")
"""Grid dimensions that define a case (everything but the method, error type and parameter)."""
_KEYS = ("aircraft", "variant", "condition", "maneuver", "loop", "noise", "method", "equation", "parameter")


@dataclass(frozen=True)
class Findings:
    """The ranked findings of one set of scores.

    Attributes
    ----------
    tests : DataFrame
        One bias test per cell (error types collapsed) and parameter, |bias_z| descending.
    bias_limit : float
        The |bias_z| beyond which a test is a finding.
    biases : DataFrame
        The tests beyond ``bias_limit`` (largest first).
    coverage : DataFrame
        Cells whose coverage interval lies wholly outside :data:`COVERAGE_BAND` (farthest first).
    cells_with_coverage : int
        How many cells had a coverage to test.
    comparison : DataFrame
        Per case and method, the worst |bias_z| (its parameter and bias in %), worst case first.
    cases : tuple of str
        The grid dimensions that vary between cases (they name a case).
    min_n : int
        The fewest realizations behind any cell.
    """

    tests: pd.DataFrame
    bias_limit: float
    biases: pd.DataFrame
    coverage: pd.DataFrame
    cells_with_coverage: int
    comparison: pd.DataFrame
    cases: tuple[str, ...]
    min_n: int

    @property
    def count(self) -> int:
        """Bias findings plus coverage failures."""
        return len(self.biases) + len(self.coverage)

    @property
    def few_realizations(self) -> bool:
        return 0 < self.min_n < MIN_REALIZATIONS


def method_label(method: str) -> str:
    """``'least squares (ee-time)'``; unknown methods by their name alone."""
    label = METHOD_LABELS.get(str(method))
    return f"{label} ({method})" if label else str(method)


def _keys(scores: pd.DataFrame) -> list[str]:
    return [k for k in _KEYS if k in scores]


def one_per_estimate(scores: pd.DataFrame) -> pd.DataFrame:
    """The scores with one row per cell and parameter across error types (they change the
    bounds, not the estimates), in the scores' order."""
    return scores.drop_duplicates(_keys(scores))


def bias_tests(scores: pd.DataFrame) -> pd.DataFrame:
    """One row per cell and parameter with a finite ``bias_z``, error types collapsed (they
    share the estimates), sorted by |bias_z| descending."""
    if scores.empty or "bias_z" not in scores:
        return scores.iloc[0:0].assign(abs_bias_z=pd.Series(dtype=float))
    s = scores[np.isfinite(scores["bias_z"].astype(float))]
    s = one_per_estimate(s).assign(abs_bias_z=lambda d: d["bias_z"].abs())
    return s.sort_values("abs_bias_z", ascending=False, kind="stable").reset_index(drop=True)


def bias_findings(tests: pd.DataFrame, false_alarm: float = BIAS_FALSE_ALARM) -> tuple[pd.DataFrame, float]:
    """The tests beyond the family-wise (Bonferroni) critical value, and that value."""
    limit = family_z(len(tests), false_alarm)
    return tests[tests["abs_bias_z"] > limit].reset_index(drop=True), limit


def coverage_failures(scores: pd.DataFrame, band: tuple[float, float] = COVERAGE_BAND) -> pd.DataFrame:
    """Cells whose coverage interval lies wholly outside ``band``, farthest from it first."""
    need = {"coverage", "coverage_lo", "coverage_hi"}
    if scores.empty or not need <= set(scores):
        return scores.iloc[0:0]
    s = scores[np.isfinite(scores["coverage_lo"].astype(float)) & np.isfinite(scores["coverage_hi"].astype(float))]
    out = s[(s["coverage_hi"] < band[0]) | (s["coverage_lo"] > band[1])]
    gap = np.maximum(band[0] - out["coverage"], out["coverage"] - band[1])
    return out.assign(gap=gap).sort_values("gap", ascending=False, kind="stable").reset_index(drop=True)


def case_columns(scores: pd.DataFrame) -> tuple[str, ...]:
    """The case dimensions that take more than one value (at least ``noise`` when present)."""
    vary = tuple(c for c in CASE_COLUMNS if c in scores and scores[c].nunique() > 1)
    return vary or tuple(c for c in ("noise",) if c in scores)


def comparison(tests: pd.DataFrame, cases: tuple[str, ...]) -> pd.DataFrame:
    """Per case and method, the parameter with the worst |bias_z|; cases ordered by their worst
    method, methods by |bias_z| within a case."""
    if tests.empty:
        return tests
    by = list(cases) + ["method"]
    worst = tests.sort_values("abs_bias_z", ascending=False, kind="stable").drop_duplicates(by)
    top = worst.groupby(list(cases), sort=False)["abs_bias_z"].transform("max") if cases else worst["abs_bias_z"]
    worst = worst.assign(case_worst=top)
    return worst.sort_values(["case_worst", "abs_bias_z"], ascending=False, kind="stable").reset_index(drop=True)


def find(scores: pd.DataFrame, false_alarm: float = BIAS_FALSE_ALARM,
         band: tuple[float, float] = COVERAGE_BAND) -> Findings:
    """Rank what the scores show (see the module docstring for the rules)."""
    tests = bias_tests(scores)
    biases, limit = bias_findings(tests, false_alarm)
    cases = case_columns(scores)
    n = scores["n"].astype(float) if "n" in scores else pd.Series(dtype=float)
    n = n[np.isfinite(n)]
    covered = int(np.isfinite(scores["coverage_lo"].astype(float)).sum()) if "coverage_lo" in scores else 0
    return Findings(tests=tests, bias_limit=limit, biases=biases, coverage=coverage_failures(scores, band),
                    cells_with_coverage=covered, comparison=comparison(tests, cases), cases=cases,
                    min_n=int(n.min()) if len(n) else 0)


def rough_note(n: int) -> str:
    """The caveat for conclusions from ``n`` < :data:`MIN_REALIZATIONS` realizations per cell, or ''."""
    if not 0 < n < MIN_REALIZATIONS:
        return ""
    half = 1.96 * math.sqrt(0.95 * 0.05 / n)
    return (f"Only {n} realizations per cell (fewer than {MIN_REALIZATIONS}): these conclusions are rough "
            f"(a coverage of 0.95 is known to ±{half:.2f}; run more realizations before relying on them).")


def status_of(findings: Findings | None, failed_gates: int = 0) -> str:
    """``'fail'`` when a gate failed, ``'findings'`` when biases or coverage failures were found,
    else ``'ok'``."""
    if failed_gates:
        return "fail"
    return "findings" if findings is not None and findings.count else "ok"


def efficiency_note(scores: pd.DataFrame) -> str:
    """Why an efficiency above 1 (a scatter below the Cramér-Rao bound) is possible, when one
    appears in ``scores``; else ''."""
    if "efficiency" not in scores:
        return ""
    scores = one_per_estimate(scores)
    e = scores["efficiency"].astype(float)
    above = scores[np.isfinite(e) & (e > 1)]
    if above.empty:
        return ""
    methods = list(dict.fromkeys(above["method"].astype(str)))
    text = (f"Efficiency above 1 ({len(above)} cells: {', '.join(methods)}; up to {e[np.isfinite(e)].max():.2f}) "
            "does not mean a method beat the Cramér-Rao bound: the bound is output error's, for its own measured "
            "outputs and their noise, and does not limit equation-error methods, which fit coefficients carrying "
            "the output noise the campaign adds to them.")
    n = int(above["n"].min()) if "n" in above else 0
    if n > 1:
        text += (f" With {n} realizations the variance of the estimates is itself uncertain by "
                 f"±{100 * math.sqrt(2 / (n - 1)):.0f} % (one standard error)"
                 + (", so output error slightly above 1 is Monte Carlo scatter." if "oe" in methods else "."))
    return text
