"""Nightly gates: declared claims checked against the scores, and movement since last run.

Gates live in a TOML file (default ``harness/nightly-gates.toml``):

- ``kind = "coverage"``: coverage of the ±2σ interval within [low, high] for the listed
  methods — allowing for its Monte Carlo uncertainty: a cell fails only when its exact 95 %
  binomial interval lies wholly outside [low, high];
- ``kind = "bias"``: |bias| below ``z`` Monte Carlo standard errors, with ``z`` either a number
  or ``"family"``: the Bonferroni critical value that keeps the chance of any false alarm over
  all the gated cells at ``false_alarm`` (default 1 %);
- ``kind = "movement"``: every score's mean and coverage compared with the previous run of the
  same campaign in the history; a change larger than its Monte Carlo uncertainty (with the
  same family-wise critical value) is a regression. With the campaign's fixed seeds the same
  code gives the same numbers, so anything flagged here is a change in behaviour.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import norm

from models.errors import UserError

DEFAULT_GATES = Path(__file__).resolve().parent / "nightly-gates.toml"


@dataclass(frozen=True)
class Gate:
    name: str
    kind: str
    methods: tuple[str, ...] = ()        # "method/errors", e.g. "ee-freq/conventional"
    noise: tuple[str, ...] = ()
    dependents: tuple[str, ...] = ()
    low: float = 0.0
    high: float = 1.0
    z: float | str = "family"
    false_alarm: float = 0.01


def load_gates(path: str | Path = DEFAULT_GATES) -> tuple[Gate, ...]:
    p = Path(path)
    try:
        d = tomllib.loads(p.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise UserError(f"cannot read gates file {p}: {exc}") from None
    gates = []
    for i, g in enumerate(d.get("gate", [])):
        if g.get("kind") not in ("coverage", "bias", "movement"):
            raise UserError(f"{p}: gate {i} ({g.get('name')!r}): kind must be coverage, bias or movement")
        gates.append(Gate(name=g.get("name", g["kind"]), kind=g["kind"], methods=tuple(g.get("methods", ())),
                          noise=tuple(g.get("noise", ())), dependents=tuple(g.get("dependents", ())),
                          low=float(g.get("low", 0.0)), high=float(g.get("high", 1.0)), z=g.get("z", "family"),
                          false_alarm=float(g.get("false_alarm", 0.01))))
    return tuple(gates)


def _select(scores: pd.DataFrame, gate: Gate) -> pd.DataFrame:
    s = scores[np.isfinite(scores["truth"].astype(float))]
    if gate.methods:
        s = s[(s["method"] + "/" + s["errors"]).isin(gate.methods)]
    if gate.noise:
        s = s[s["noise"].isin(gate.noise)]
    if gate.dependents:
        s = s[s["dependent"].isin(gate.dependents)]
    return s


def family_z(m: int, false_alarm: float) -> float:
    """Two-sided Bonferroni critical value for ``m`` tests at family-wise rate ``false_alarm``."""
    return float(norm.ppf(1 - false_alarm / (2 * max(m, 1))))


def _row(gate: Gate, r: pd.Series, value: float, limit: str, passed: bool, message: str) -> dict:
    return {"gate": gate.name, "kind": gate.kind, "noise": r["noise"], "method": r["method"], "errors": r["errors"],
            "maneuver": r["maneuver"], "parameter": r["parameter"], "value": value, "limit": limit,
            "passed": bool(passed), "message": message}


def check_gates(scores: pd.DataFrame, gates: tuple[Gate, ...], previous: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per gated cell: value, limit, passed, and a message naming method and parameter."""
    rows = []
    for gate in gates:
        s = _select(scores, gate)
        if gate.kind == "coverage":
            for _, r in s.iterrows():
                ok = not (r["coverage_hi"] < gate.low or r["coverage_lo"] > gate.high)
                rows.append(_row(gate, r, r["coverage"], f"[{gate.low:g}, {gate.high:g}]", ok,
                                 f"{r['method']} ({r['errors']}) {r['parameter']} [{r['noise']}, {r['maneuver']}]: "
                                 f"coverage {r['coverage']:.3f} (95 % interval {r['coverage_lo']:.3f}-{r['coverage_hi']:.3f}) "
                                 f"{'within' if ok else 'outside'} [{gate.low:g}, {gate.high:g}]"))
        elif gate.kind == "bias":
            z = family_z(len(s), gate.false_alarm) if gate.z == "family" else float(gate.z)
            for _, r in s.iterrows():
                ok = abs(r["bias_z"]) <= z if math.isfinite(r["bias_z"]) else True
                rows.append(_row(gate, r, r["bias_z"], f"|z| <= {z:.2f}", ok,
                                 f"{r['method']} ({r['errors']}) {r['parameter']} [{r['noise']}, {r['maneuver']}]: "
                                 f"bias {r['bias_pct']:+.2f} % = {r['bias_z']:+.2f} Monte Carlo standard errors "
                                 f"({'within' if ok else 'beyond'} {z:.2f})"))
        elif gate.kind == "movement" and previous is not None and not previous.empty:
            keys = ["aircraft", "variant", "condition", "maneuver", "loop", "noise", "method", "errors", "equation",
                    "parameter"]
            both = s.merge(_select(previous, gate), on=keys, suffixes=("", "_prev"))
            z = family_z(2 * len(both), gate.false_alarm)
            for _, r in both.iterrows():
                se_mean = math.hypot(r["bias_mcse"], r["bias_mcse_prev"])
                d_mean = r["mean"] - r["mean_prev"]
                p = 0.5 * (r["coverage"] + r["coverage_prev"])
                se_cov = math.sqrt(max(p * (1 - p), 1.0 / (r["n"] + r["n_prev"])) * (1 / r["n"] + 1 / r["n_prev"]))
                d_cov = r["coverage"] - r["coverage_prev"]
                moved_mean = se_mean > 0 and abs(d_mean) > z * se_mean
                moved_cov = abs(d_cov) > z * se_cov
                ok = not (moved_mean or moved_cov)
                what = []
                if moved_mean:
                    what.append(f"mean moved {d_mean:+.4g} ({d_mean / se_mean:+.1f} standard errors)")
                if moved_cov:
                    what.append(f"coverage moved {d_cov:+.3f} ({d_cov / se_cov:+.1f} standard errors)")
                rows.append(_row(gate, r, d_mean / se_mean if se_mean > 0 else 0.0, f"|z| <= {z:.2f}", ok,
                                 f"{r['method']} ({r['errors']}) {r['parameter']} [{r['noise']}, {r['maneuver']}]: "
                                 + ("; ".join(what) if what else "no change beyond Monte Carlo uncertainty")
                                 + " since the previous run"))
    cols = ["gate", "kind", "noise", "method", "errors", "maneuver", "parameter", "value", "limit", "passed", "message"]
    return pd.DataFrame(rows, columns=cols)
