"""Maneuver design review: which input to fly, with the numbers the choice rests on."""
from __future__ import annotations

import numpy as np
import pandas as pd

from reports import figures as F
from reports.findings import rough_note
from reports.load import CampaignOutput, provenance
from reports.render import Report, Section, Table

GROUPS = {"longitudinal": ("Cm", "CZ"), "lateral-directional": ("Cl", "Cn", "CY")}


def _tables(out: CampaignOutput, corr: pd.DataFrame) -> dict[str, pd.DataFrame]:
    s = out.truth_scores
    r = out.results
    crb = r[(r["method"] == "crb") & r["truth_local"].notna()].copy()
    crb["crb_pct"] = 100 * crb["std_error"] / crb["truth_local"].abs()
    acc = s[s["method"] == "ee-freq"].copy()
    acc["rel_rmse_pct"] = 100 * acc["rmse"] / acc["truth"].abs()
    ex = r[r["method"] == "excursion"].pivot_table(index="maneuver", columns="parameter", values="estimate").reset_index()
    worst = corr.groupby("maneuver")["abs_r"].max().rename("max_abs_r").reset_index() if not corr.empty else pd.DataFrame()
    return {"crb": crb.pivot_table(index="parameter", columns="maneuver", values="crb_pct").round(2),
            "accuracy": acc.pivot_table(index="parameter", columns="maneuver", values="rel_rmse_pct").round(2),
            "excursions": ex, "worst_r": worst}


def recommendations(out: CampaignOutput, corr: pd.DataFrame) -> list[str]:
    """One plain recommendation per parameter group, citing the numbers it rests on."""
    t = _tables(out, corr)
    acc, crb, ex = t["accuracy"], t["crb"], t["excursions"].set_index("maneuver") if len(t["excursions"]) else None
    lines = []
    for group, deps in GROUPS.items():
        rows = [p for p in acc.index if p.split("_")[0] in deps]
        if not rows:
            continue
        med = acc.loc[rows].median(axis=0).dropna()
        if med.empty:
            continue
        best = med.idxmin()
        runner = med.drop(best).idxmin() if len(med) > 1 else None
        c = crb.loc[[p for p in rows if p in crb.index], best].median() if best in crb.columns else float("nan")
        w = corr[corr["maneuver"] == best]["abs_r"].max() if not corr.empty else float("nan")
        exc = ""
        if ex is not None and best in ex.index:
            e = ex.loc[best]
            exc = (f"; it costs {e.get('max_dalpha_deg', float('nan')):.1f} deg of alpha, "
                   f"{e.get('max_dbeta_deg', float('nan')):.1f} deg of beta, {e.get('max_dnz_g', float('nan')):.2f} g "
                   f"and {e.get('max_dV_fps', float('nan')):.1f} ft/s of airspeed")
        alt = (f"; next best {runner} ({med[runner]:.1f} %)" if runner else "")
        lines.append(f"{group.capitalize()} ({', '.join(deps)}): fly {best}: median relative RMSE {med[best]:.1f} % "
                     f"over {len(rows)} derivatives (Monte Carlo, {out.meta['campaign']['realizations']} realizations), "
                     f"predicted Cramér-Rao bound {c:.1f} %, largest regressor correlation {w:.2f}"
                     + (" (above the seed's 0.9 rule of thumb)" if w > 0.9 else "") + exc + alt + ".")
    return lines


def maneuver_review(out: CampaignOutput, corr: pd.DataFrame) -> Report:
    t = _tables(out, corr)
    rec = recommendations(out, corr)
    flagged = corr[corr["flagged"]] if not corr.empty else corr
    sections = [
        Section("Recommendation", tuple(rec)),
        Section("Inputs against the aircraft's modes", ("Input power should cover the modes' frequencies.",),
                (Table("Modes at trim", out.modes.drop(columns=["flight"]).drop_duplicates().reset_index(drop=True),
                       "Natural frequency and damping of the linear models at trim (the same for every candidate: "
                       "they share the trim point)."),) if not out.modes.empty else (),
                tuple(f for f in (F.fig_input_spectra(out.flights, out.modes), F.fig_time_histories(out.flights))
                      if f is not None)),
        Section("Cramér-Rao bounds predicted before flying",
                ("Standard deviation of each derivative at the true values with the noise preset's output noise, "
                 "from the output-error information matrix, as % of the derivative.",),
                (Table("Predicted bound, %", t["crb"].reset_index()),)),
        Section("Regressor correlation (seed Eq. 50)",
                (f"{len(flagged)} pairs above |r| = 0.9, the seed's rule of thumb." if len(flagged) else
                 "No pair above |r| = 0.9.",),
                (Table("Largest correlation per maneuver", t["worst_r"]),
                 Table("Pairs above 0.9", flagged) if len(flagged) else Table("All pairs", corr.head(200)))),
        Section("Excursions from trim", (), (Table("Peak excursions", t["excursions"]),),
                tuple(f for f in (F.fig_excursions(out.results[out.results["method"] == "excursion"]),) if f is not None)),
        Section("Monte Carlo accuracy", ("Relative RMSE (%) of the frequency-domain estimates.",),
                (Table("Relative RMSE, %", t["accuracy"].reset_index()),)),
    ]
    numbers = {k: (v.reset_index() if k in ("crb", "accuracy") else v).replace({np.nan: None}).to_dict(orient="records")
               for k, v in t.items()} | {"recommendations": rec}
    rough = rough_note(int(out.meta["campaign"].get("realizations") or 0))
    return Report(title="Maneuver design review", kind="maneuver-review", provenance=provenance(out.meta),
                  summary=tuple(rec) + ((rough,) if rough else ()), sections=tuple(sections), numbers=numbers)
