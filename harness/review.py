"""Maneuver design review: candidate inputs flown, scored, and their regressors' correlation."""
from __future__ import annotations

import hashlib
from pathlib import Path

import pandas as pd

from estimators.methods import make_estimator
from harness.campaign import Campaign, FlightKey, ManeuverDef, NoiseDef, parse_equation
from harness.runner import CampaignRun, run_campaign
from harness.store import write_parquet
from harness.tasks import cached_flight, excited_equations
from estimators.result import COLLINEARITY_LIMIT

LON = ("Cm = alpha + qhat + de", "CZ = alpha + qhat + de")
LAT = ("CY = beta + phat + rhat + da + dr", "Cl = beta + phat + rhat + da + dr", "Cn = beta + phat + rhat + da + dr")
DEFAULT_CANDIDATES = ("doublet", "2-1-1-2", "3-2-1-1", "sweep-linear", "multisine")


def candidate(kind: str, axis: str, amplitude_deg: float, active_s: float = 6.0) -> ManeuverDef:
    """A candidate input of ``kind`` on one axis with ``active_s`` seconds of motion."""
    surface = "de" if axis == "lon" else "da,dr"
    units = {"doublet": 2, "2-1-1-2": 6, "2-1-1": 4, "3-2-1-1": 7}
    opts: tuple = ()
    unit = 1.0
    if kind in units:
        unit = active_s / units[kind]
    elif kind.startswith("sweep"):
        opts = (("f0_hz", 0.1), ("f1_hz", 1.5), ("sweep_duration_s", active_s))
    elif kind == "multisine":
        opts = (("f_max_hz", 1.5), ("f_min_hz", 1.0 / active_s), ("period_s", active_s))
    return ManeuverDef(f"{axis}-{kind}", kind, surface, amplitude_deg, round(unit, 4), opts)


def review_campaign(aircraft: str = "f16", condition: str = "seed-5deg", kinds=DEFAULT_CANDIDATES,
                    axes=("lon", "lat"), noise: str = "realistic", realizations: int = 30,
                    variant: str = "exact-truth", seed: int = 77) -> Campaign:
    """The candidates as a campaign (frequency-domain equation error and output error)."""
    flights = []
    for axis in axes:
        amp = 1.0 if axis == "lon" else 2.0
        flights += [FlightKey(aircraft, variant, condition, candidate(k, axis, amp), "open", None, 50.0) for k in kinds]
    eqs = tuple(parse_equation(e) for e in (LON if "lon" in axes else ()) + (LAT if "lat" in axes else ()))
    text = f"{aircraft}|{condition}|{kinds}|{axes}|{noise}|{realizations}|{variant}|{seed}"
    return Campaign(name="maneuver-review", description="maneuver design review: " + ", ".join(kinds), seed=seed,
                    realizations=realizations, truth="local", flights=tuple(flights), noises=(NoiseDef(noise, noise),),
                    methods=("ee-freq", "oe"), errors=("conventional",), equations=eqs, path="(review-maneuvers)",
                    text_hash=hashlib.sha256(text.encode()).hexdigest(),
                    method_options=(("ee-freq", (("detrend", "lstsq"), ("frequencies", "0.1:0.04:1.5"))),))


def correlation_table(campaign: Campaign, cache_dir: str) -> pd.DataFrame:
    """Pairwise parameter correlations (Eq. 50) of each flight's regressors, noise-free."""
    rows = []
    for key in campaign.flights:
        rec = cached_flight(key, cache_dir)
        for eq in excited_equations(rec, campaign.equations):
            fit = make_estimator("ee-time").fit(rec, eq)
            r = fit.correlation
            for i, a in enumerate(fit.names):
                for j, b in enumerate(fit.names):
                    if j > i and "bias" not in (a, b):
                        rows.append({"maneuver": key.maneuver.name, "equation": eq.dependent, "pair": f"{a} / {b}",
                                     "abs_r": float(abs(r[i, j])), "flagged": bool(abs(r[i, j]) > COLLINEARITY_LIMIT)})
    return pd.DataFrame(rows)


def run_review(campaign: Campaign, out_dir: str | Path, *, workers=None, scheduler=None, cache_dir=None,
               progress=True) -> tuple[CampaignRun, pd.DataFrame]:
    run = run_campaign(campaign, out_dir, workers=workers, scheduler=scheduler, cache_dir=cache_dir, progress=progress)
    corr = correlation_table(campaign, str(cache_dir or ".sidbench-cache"))
    write_parquet(corr, Path(out_dir) / "correlations.parquet")
    return run, corr
