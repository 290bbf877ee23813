"""The nightly accuracy report: gates, regressions since last night, trends, then the scores."""
from __future__ import annotations

import numpy as np
import pandas as pd

from reports import figures as F
from reports.campaign_report import campaign_sections, summary_lines
from reports.load import CampaignOutput, provenance
from reports.render import Report, Section, Table


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


def nightly_report(out: CampaignOutput, gates: pd.DataFrame, history: list, previous: dict | None,
                   nights: int = 30) -> Report:
    """The nightly document; ``status`` is 'fail' when any gate fails."""
    failed = gates[~gates["passed"]] if not gates.empty else gates
    status = "fail" if len(failed) else "ok"
    summary = [f"{'FAIL' if status == 'fail' else 'PASS'}: {len(gates) - len(failed)} of {len(gates)} gated cells pass"
               + (f"; compared with run {previous['run_id']}" if previous else "; no previous run to compare with") + "."]
    summary += [f"{r['gate']}: {r['message']}" for _, r in failed.head(8).iterrows()]
    if len(failed) > 8:
        summary.append(f"... and {len(failed) - 8} more failures (see the gate table).")
    summary += summary_lines(out)[:4]
    gt = gates.sort_values("passed", kind="stable").reset_index(drop=True) if not gates.empty else gates
    full = gt.drop(columns=["kind", "message"]).head(300) if not gt.empty else gt
    hl = tuple((i, "passed", "bad" if not r["passed"] else "good") for i, r in full.iterrows())
    moved = gates[(gates["kind"] == "movement") & ~gates["passed"]] if not gates.empty else gates
    tables = [Table("Gate summary", gate_summary(gates), "One row per gate: how many gated cells pass.",
                    tuple((i, "failed", "bad") for i, r in gate_summary(gates).iterrows() if r["failed"]))]
    if len(failed):
        tables.append(Table("Failures", failed[["gate", "message"]].reset_index(drop=True),
                            "Each names the method, noise, maneuver and parameter that broke the claim."))
    tables.append(Table("All gated cells", full, "Failures first.", hl))
    sections = [
        Section("Gates", ("Each gate states a claim the methods meet, with limits that allow for Monte Carlo "
                          "uncertainty (see harness/nightly-gates.toml).",), tuple(tables)),
        Section("Regressions since the previous run",
                (("None: no score moved beyond its Monte Carlo uncertainty." if moved.empty else
                  f"{len(moved)} scores moved beyond their Monte Carlo uncertainty.") if previous else
                 "This is the first run in the history.",),
                (Table("Moved scores", moved.drop(columns=["kind"])),) if len(moved) else ()),
        Section(f"Trends over the last {nights} runs", (), (),
                tuple(f for f in (F.fig_trend(history_frame(history), nights),) if f is not None)),
    ] + campaign_sections(out)
    numbers = {"status": status, "gates": gates.replace({np.nan: None}).to_dict(orient="records"),
               "scores": out.scores.replace({np.nan: None}).to_dict(orient="records"),
               "history_runs": [m["run_id"] for m, _ in history]}
    return Report(title="Nightly accuracy report", kind="nightly", provenance=provenance(out.meta),
                  summary=tuple(summary), sections=tuple(sections), numbers=numbers, status=status)
