"""The nightly accuracy report: gates, regressions since last night, trends, the findings, then
the scores (where only gate failures are red)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from reports import figures as F
from reports.campaign_report import GATE_KEYS, campaign_sections
from reports.campaign_setup import read_setup
from reports.findings import find, status_of
from reports.lead import findings_section, lead_lines, status_note
from reports.load import CampaignOutput, provenance
from reports.render import Report, Section, Table

NIGHTLY_LEAD_LINES: int = 6
"""Lines of the campaign lead (verdict, largest bias, cases, coverage) after the gate verdict."""


def history_frame(history: list) -> pd.DataFrame:
    """All stored runs' scores stacked, with run id and start time."""
    frames = [s.assign(run_id=m["run_id"], start=m["start"]) for m, s in history]
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def gate_summary(gates: pd.DataFrame) -> pd.DataFrame:
    """Per gate: cells checked, passed, failed, and the worst value seen."""
    if gates.empty:
        return pd.DataFrame(columns=["gate", "cells", "passed", "failed", "limit"])
    g = gates.groupby(["gate", "kind"], sort=False)
    out = g.agg(cells=("passed", "size"), passed=("passed", "sum"), limit=("limit", "first")).reset_index()
    out["failed"] = out["cells"] - out["passed"]
    return out[["gate", "kind", "cells", "passed", "failed", "limit"]]


def gate_rows(gates: pd.DataFrame, scores: pd.DataFrame) -> pd.DataFrame:
    """The gated cells, failures first, each with the interval its verdict rests on: the exact
    95 % binomial interval of a coverage, bias ± 1.96 Monte Carlo standard errors (in standard
    errors: z ± 1.96) of a bias."""
    if gates.empty:
        return gates
    keys = [k for k in GATE_KEYS if k in gates and k in scores]
    cols = [c for c in ("coverage_lo", "coverage_hi") if c in scores]
    s = scores.drop_duplicates(keys)[keys + cols] if cols else scores[keys].drop_duplicates()
    g = gates.merge(s, on=keys, how="left") if cols else gates.assign(coverage_lo=np.nan, coverage_hi=np.nan)
    interval = []
    for _, r in g.iterrows():
        if r["kind"] == "coverage" and np.isfinite(r["coverage_lo"]):
            interval.append(f"[{r['coverage_lo']:.3f}, {r['coverage_hi']:.3f}]")
        elif r["kind"] in ("bias", "movement") and np.isfinite(r["value"]):
            interval.append(f"[{r['value'] - 1.96:+.2f}, {r['value'] + 1.96:+.2f}]")
        else:
            interval.append("—")
    g = g.assign(interval=interval).drop(columns=["coverage_lo", "coverage_hi"])
    g = g.sort_values("passed", kind="stable").reset_index(drop=True)
    order = [c for c in ("gate", "noise", "method", "errors", "maneuver", "parameter", "value", "interval", "limit",
                         "passed") if c in g]
    return g[order]


def nightly_report(out: CampaignOutput, gates: pd.DataFrame, history: list, previous: dict | None,
                   nights: int = 30) -> Report:
    """The nightly document; ``status`` is 'fail' when any gate fails, 'findings' when the scores
    show biases or coverage failures the gates do not cover (:func:`reports.findings.status_of`)."""
    failed = gates[~gates["passed"]] if not gates.empty else gates
    findings = find(out.truth_scores)
    status = status_of(findings, len(failed))
    verdict = "FAIL" if len(failed) else "PASS"
    compared = f"compared with run {previous['run_id']}" if previous else "no previous run to compare with"
    summary = [f"{verdict}: {len(gates) - len(failed)} of {len(gates)} gated cells pass; {compared}."]
    summary += [f"{r['gate']}: {r['message']}" for _, r in failed.head(8).iterrows()]
    if len(failed) > 8:
        summary.append(f"... and {len(failed) - 8} more failures (see the gate table).")
    summary += lead_lines(out, findings, read_setup(out.meta))[2:NIGHTLY_LEAD_LINES + 2]
    full = gate_rows(gates, out.truth_scores).head(300)
    hl = tuple((i, "passed", "bad" if not r["passed"] else "good") for i, r in full.iterrows())
    moved = gates[(gates["kind"] == "movement") & ~gates["passed"]] if not gates.empty else gates
    tables = [Table("Gate summary", gate_summary(gates), "One row per gate: how many gated cells pass.",
                    tuple((i, "failed", "bad") for i, r in gate_summary(gates).iterrows() if r["failed"]))]
    if len(failed):
        tables.append(Table("Failures", failed[["gate", "message"]].reset_index(drop=True),
                            "Each names the method, noise, maneuver and parameter that broke the claim."))
    tables.append(Table("All gated cells", full, "Failures first. interval: the exact 95 % binomial interval of a "
                        "coverage (a cell fails only when it lies wholly outside the limits), or value ± 1.96 of a "
                        "bias or movement in Monte Carlo standard errors.", hl))
    sections = [
        Section("Gates", ("Each gate states a claim the methods meet, with limits that allow for Monte Carlo "
                          "uncertainty (see harness/nightly-gates.toml). Cells outside the gates are not failures: "
                          "the score table marks their departures amber.",), tuple(tables)),
        Section("Regressions since the previous run",
                (("None: no score moved beyond its Monte Carlo uncertainty." if moved.empty else
                  f"{len(moved)} scores moved beyond their Monte Carlo uncertainty.") if previous else
                 "This is the first run in the history.",),
                (Table("Moved scores", moved.drop(columns=["kind"])),) if len(moved) else ()),
        Section(f"Trends over the last {nights} runs", (), (),
                tuple(f for f in (F.fig_trend(history_frame(history), nights),) if f is not None)),
        findings_section(findings),
    ] + campaign_sections(out, findings, gates)
    numbers = {"status": status, "gates": gates.replace({np.nan: None}).to_dict(orient="records"),
               "scores": out.scores.replace({np.nan: None}).to_dict(orient="records"),
               "history_runs": [m["run_id"] for m, _ in history]}
    note = f"{len(failed)} of {len(gates)} gated cells fail" if len(failed) else status_note(findings)
    return Report(title="Nightly accuracy report", kind="nightly", provenance=provenance(out.meta),
                  summary=tuple(summary), sections=tuple(sections), numbers=numbers, status=status, status_note=note)
