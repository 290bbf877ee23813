"""Which output channels and coefficients the diagnosis report shows.

This module owns the choice of channels and axes for the report's figures: the channels that
depart most from the model as given (:func:`worst_channels`, by the noise ratios in
``findings.json``'s ``located`` or computed from the series), the channels and coefficients the
findings name (:func:`affected_channels`, :func:`affected_coefficients`), and the mapping of a
finding's axis words to coefficients and of coefficients to the channels that show them first.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import pandas as pd

from reports import figures_diagnosis as FD
from reports.diagnosis_tables import _dict, _findings, _num, _real
from reports.figures_diagnosis import CHANNELS, COEFFICIENTS

__all__ = ["affected_channels", "affected_coefficients", "worst_channels"]

AXIS_COEFFICIENT: Mapping[str, str] = {
    "pitch": "Cm", "roll": "Cl", "yaw": "Cn", "axial": "CX", "side": "CY", "normal": "CZ",
    "x": "CX", "y": "CY", "z": "CZ", "lift": "CZ", "drag": "CX", "sideforce": "CY"}
"""Axis words a finding may use, and the coefficient each names."""
COEFFICIENT_CHANNELS: Mapping[str, tuple[str, ...]] = {
    "Cm": ("q", "alpha", "theta", "az"), "CZ": ("alpha", "az", "q"), "CX": ("V", "ax"),
    "CY": ("beta", "ay"), "Cl": ("p", "phi"), "Cn": ("r", "beta")}
"""Output channels that show a coefficient's error first."""
SHOWN_CHANNELS = 3


# --------------------------------------------------------------------------------------
# Which channels and axes to show
# --------------------------------------------------------------------------------------

def _coefficient_of(name: Any) -> str | None:
    """The coefficient an axis word or coefficient name refers to (``'pitch'`` -> ``'Cm'``)."""
    if not isinstance(name, str) or not name:
        return None
    if name in COEFFICIENTS:
        return name
    lower = name.lower()
    by_lower = {c.lower(): c for c in COEFFICIENTS}
    return by_lower.get(lower) or AXIS_COEFFICIENT.get(lower)

def _finding_coefficient(finding: Mapping) -> str | None:
    """The coefficient a finding acts on: its axis, else its parameter's prefix."""
    coef = _coefficient_of(finding.get("axis"))
    if coef is None and isinstance(finding.get("parameter"), str):
        coef = _coefficient_of(finding["parameter"].split("_")[0])
    return coef

def _ratios(located: Mapping, group: str, maneuver: str = "identification") -> dict[str, float]:
    """``located[group][maneuver][name]['ratio']`` (else ``'rms'``) per name."""
    table = _dict(_dict(_dict(located).get(group)).get(maneuver))
    out = {}
    for name, stats in table.items():
        stats = _dict(stats)
        value = _num(stats.get("ratio"))
        out[str(name)] = value if math.isfinite(value) else _num(stats.get("rms"))
    return out

def _series_ratios(series: pd.DataFrame | None) -> dict[str, float]:
    """Per channel, RMS of smoothed minus before over RMS of raw minus smoothed."""
    out: dict[str, float] = {}
    if series is None:
        return out
    for c in CHANNELS:
        cols = [f"meas_{c}", f"smooth_{c}", f"before_{c}"]
        if all(col in series for col in cols):
            meas, smooth, before = (pd.to_numeric(series[col], errors="coerce").to_numpy(float)
                                    for col in cols)
            noise = FD.rms(meas - smooth)
            out[c] = FD.rms(smooth - before) / noise if noise > 0 else FD.rms(smooth - before)
    return out

def _rank(scores: Mapping[str, float]) -> list[str]:
    """Names by descending score, NaN last."""
    return sorted(scores, key=lambda n: -scores[n] if math.isfinite(scores[n]) else math.inf)

def worst_channels(data: Mapping, series: pd.DataFrame | None, count: int = SHOWN_CHANNELS) -> list[str]:
    """The output channels that depart most from the model as given, worst first.

    Parameters
    ----------
    data : Mapping
        ``findings.json``.
    series : DataFrame or None
        The identification series (used when ``located`` holds no channel statistics).
    count : int, optional
        How many channels to return.

    Returns
    -------
    list of str
        From ``located.outputs.identification`` by noise ratio (``worst_output`` first), or
        computed from the series.
    """
    located = _dict(data.get("located"))
    ranked = _rank(_ratios(located, "outputs")) or _rank(_series_ratios(series))
    worst = located.get("worst_output")
    if isinstance(worst, str) and worst:
        ranked = [worst] + [c for c in ranked if c != worst]
    return ranked[:count]

def affected_channels(data: Mapping, series: pd.DataFrame | None) -> list[str]:
    """The output channels the findings name, else the worst ones.

    A finding's ``channel`` comes first; its axis adds the channels that show that axis's
    coefficient (``pitch`` -> q, alpha, theta, az), ordered by their mismatch.

    Parameters
    ----------
    data : Mapping
        ``findings.json``.
    series : DataFrame or None
        The identification series (for the fallback).

    Returns
    -------
    list of str
    """
    located = _dict(data.get("located"))
    ratios = _ratios(located, "outputs") or _series_ratios(series)
    named: list[str] = []
    for finding in _real(_findings(data)):
        if isinstance(finding.get("channel"), str) and finding["channel"]:
            named.append(finding["channel"])
        related = COEFFICIENT_CHANNELS.get(_finding_coefficient(finding) or "", ())
        named += sorted(related, key=lambda c: -ratios.get(c, -math.inf)
                        if math.isfinite(ratios.get(c, math.nan)) else math.inf)
    named = [c for c in dict.fromkeys(named) if c in CHANNELS]
    return named or worst_channels(data, series)

def affected_coefficients(data: Mapping) -> list[str]:
    """The coefficients the findings act on, else the worst axis (else every axis).

    Parameters
    ----------
    data : Mapping
        ``findings.json``.

    Returns
    -------
    list of str
    """
    named = [c for c in (_finding_coefficient(f) for f in _real(_findings(data))) if c]
    if named:
        return list(dict.fromkeys(named))
    located = _dict(data.get("located"))
    worst = _coefficient_of(located.get("worst_axis"))
    if worst:
        return [worst]
    return _rank(_ratios(located, "coefficients"))[:2] or list(COEFFICIENTS)
