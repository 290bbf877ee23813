"""Method benchmarking: which estimator to use, ranked by accuracy, honesty and cost."""
from __future__ import annotations

import numpy as np
import pandas as pd

from reports import figures as F
from reports.findings import rough_note
from reports.load import CampaignOutput, provenance
from reports.render import Report, Section, Table

CASE = ["campaign", "noise", "maneuver", "loop"]


def _prepare(outputs: list[CampaignOutput]) -> pd.DataFrame:
    s = pd.concat([o.truth_scores for o in outputs], ignore_index=True)
    s = s[np.isfinite(s["rmse"])].copy()
    s["method_label"] = s["method"] + " (" + s["errors"] + ")"
    s["rel_rmse_pct"] = 100 * s["rmse"] / s["truth"].abs()
    # honesty: distance of the coverage from nominal plus the log error of the bound size
    s["dishonesty"] = (s["coverage"] - 0.95).abs() + np.abs(np.log(s["se_ratio"].clip(lower=1e-6)))
    return s


def rankings(s: pd.DataFrame) -> pd.DataFrame:
    """Per case and parameter: the methods ranked by RMSE and by honesty of bounds."""
    out = []
    for key, g in s.groupby(CASE + ["parameter"], dropna=False):
        g = g.sort_values("rmse")
        h = g.sort_values("dishonesty")
        out.append(dict(zip(CASE + ["parameter"], key)) | {
            "best_rmse": g["method_label"].iloc[0], "rel_rmse_pct": g["rel_rmse_pct"].iloc[0],
            "runner_up": g["method_label"].iloc[1] if len(g) > 1 else "",
            "most_honest": h["method_label"].iloc[0], "coverage": h["coverage"].iloc[0],
            "se_ratio": h["se_ratio"].iloc[0]})
    return pd.DataFrame(out)


def overall(s: pd.DataFrame) -> pd.DataFrame:
    """Per method: mean rank by RMSE and by honesty over all cases and parameters, cost."""
    s = s.copy()
    s["rank_rmse"] = s.groupby(CASE + ["parameter"], dropna=False)["rmse"].rank()
    s["rank_honesty"] = s.groupby(CASE + ["parameter"], dropna=False)["dishonesty"].rank()
    g = s.groupby("method_label")
    return g.agg(cells=("parameter", "count"), mean_rank_rmse=("rank_rmse", "mean"),
                 mean_rank_honesty=("rank_honesty", "mean"), median_rel_rmse_pct=("rel_rmse_pct", "median"),
                 median_coverage=("coverage", "median"), mean_time_ms=("time_s", lambda x: 1e3 * np.nanmean(x))
                 ).reset_index().sort_values("mean_rank_rmse")


def breaking_points(s: pd.DataFrame) -> pd.DataFrame:
    """Per method and campaign: the case where it does worst (largest |bias| in Monte Carlo
    standard errors), with its coverage — where the method breaks: noise level, collinearity
    (loop gain), structure error (campaign)."""
    rows = []
    for (m, c), g in s.groupby(["method_label", "campaign"]):
        i = g["bias_z"].abs().idxmax()
        r = g.loc[i]
        rows.append({"method": m, "campaign": c, "worst_case": f"{r['noise']}, {r['maneuver']}, {r['loop']}",
                     "parameter": r["parameter"], "bias_pct": r["bias_pct"], "bias_z": r["bias_z"],
                     "coverage": r["coverage"]})
    return pd.DataFrame(rows)


def _display(frame: pd.DataFrame, caption: str) -> tuple[pd.DataFrame, str]:
    """The frame without the case columns that hold one value (named in the caption instead), so
    that the table fits a 1280 px page; the JSON numbers keep every column."""
    same = [c for c in CASE if c in frame and frame[c].nunique(dropna=False) == 1 and len(frame)]
    if not same:
        return frame, caption
    fixed = ", ".join(f"{c} {frame[c].iloc[0]}" for c in same)
    return frame.drop(columns=same), (caption + " " if caption else "") + f"Every row: {fixed}."


def _table(title: str, frame: pd.DataFrame, caption: str) -> Table:
    shown, text = _display(frame, caption)
    return Table(title, shown.reset_index(drop=True).rename(columns=lambda c: str(c).replace("_", " ")), text)


def benchmark_report(outputs: list[CampaignOutput]) -> Report:
    s = _prepare(outputs)
    ov = overall(s)
    best = ov.iloc[0] if len(ov) else None
    summary = [f"{len(s)} scored cells from {', '.join(o.meta['campaign']['name'] for o in outputs)}."]
    rough = rough_note(int(s["n"].min())) if "n" in s and len(s) else ""
    if best is not None:
        summary.append(f"Most accurate overall: {best['method_label']} (mean RMSE rank {best['mean_rank_rmse']:.2f}, "
                       f"median relative RMSE {best['median_rel_rmse_pct']:.1f} %, {best['mean_time_ms']:.1f} ms per estimate).")
        h = ov.sort_values("mean_rank_honesty").iloc[0]
        summary.append(f"Most honest bounds: {h['method_label']} (median coverage {h['median_coverage']:.2f}).")
    if rough:
        summary.append(rough)
    sections = [
        Section("Overall ranking", ("Ranks are 1 for the best method in each case and parameter, averaged.",),
                (Table("Methods", ov, "Lower ranks are better; coverage near 0.95 means honest bounds."),),
                tuple(f for f in (F.fig_accuracy_vs_cost(s),) if f is not None)),
        Section("Where each method breaks", (), (_table("Worst case per method and campaign", breaking_points(s),
                                                        "The cell with the largest |bias| in Monte Carlo standard "
                                                        "errors."),)),
        Section("Best method per case and parameter", (), (_table("Rankings", rankings(s).head(300), ""),)),
    ]
    numbers = {"overall": ov.replace({np.nan: None}).to_dict(orient="records"),
               "rankings": rankings(s).replace({np.nan: None}).to_dict(orient="records")}
    prov = provenance(outputs[0].meta) | {
        "campaign": ", ".join(o.meta["campaign"]["name"] for o in outputs),
        "file": ", ".join(str(o.path) for o in outputs),
        "sha256": ", ".join((o.meta["campaign"].get("sha256") or "")[:12] for o in outputs),
        "seed": ", ".join(str(o.meta.get("seed")) for o in outputs),
        "start": min(o.meta.get("start", "") for o in outputs), "end": max(o.meta.get("end", "") for o in outputs)}
    return Report(title="Method benchmarking", kind="benchmark", provenance=prov,
                  summary=tuple(summary), sections=tuple(sections), numbers=numbers)
