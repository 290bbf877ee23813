"""What a campaign flew and how it added noise, in words, for the top of its report.

The aircraft, variant, condition, maneuver and loop come from the scores (what was actually
flown); the noise definitions from the campaign file named in ``run.json``, read again only
when its SHA-256 still matches the run's (otherwise the report says so and names the noises
alone).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from harness.campaign import CampaignError, NoiseDef, load_campaign
from harness.noise import ChannelNoise
from harness.noise_presets import preset

__all__ = ["AIRCRAFT_NAMES", "VARIANT_TEXT", "APPLY_TO_TEXT", "Setup", "read_setup", "flown_text", "sensor_text",
           "noise_text", "noise_table"]

AIRCRAFT_NAMES: dict[str, str] = {"f16": "F-16", "dhc6": "DHC-6 Twin Otter"}
VARIANT_TEXT: dict[str, str] = {
    "linear": "the seed's linear models (Eqs. 33-34) built from the {aircraft}'s JSBSim truth derivatives and "
              "simulated exactly, not the nonlinear JSBSim {aircraft}",
    "exact-truth": "the JSBSim {aircraft} with exactly linear body-axis aerodynamics (exact-truth variant: "
                   "no structure error)",
    "nominal": "the nonlinear JSBSim {aircraft} (tabulated aerodynamics)",
    "unstable": "the JSBSim {aircraft} with its reference point moved forward (unstable variant)",
}
APPLY_TO_TEXT: dict[str, str] = {
    "regressors": "on the regressors only (X from the noisy recording, the output from the clean one)",
    "outputs": "on the outputs only (X from the clean recording)",
    "both": "on every measured channel",
}
_DEG = 180.0 / math.pi
# channel -> (symbol, factor from the canonical unit, unit shown)
_CHANNELS: dict[str, tuple[str, float, str]] = {
    "alpha": ("α", _DEG, "°"), "beta": ("β", _DEG, "°"),
    "p": ("p", _DEG, "°/s"), "q": ("q", _DEG, "°/s"), "r": ("r", _DEG, "°/s"),
    "ax": ("a_x", 1.0, " g"), "ay": ("a_y", 1.0, " g"), "az": ("a_z", 1.0, " g"),
    "phi": ("φ", _DEG, "°"), "theta": ("θ", _DEG, "°"), "psi": ("ψ", _DEG, "°"),
    "de": ("δe", _DEG, "°"), "da": ("δa", _DEG, "°"), "dr": ("δr", _DEG, "°"),
    "V": ("V", 1.0, " ft/s"), "h": ("h", 1.0, " ft"), "qbar": ("q̄", 1.0, " psf"), "mach": ("M", 1.0, ""),
}


@dataclass(frozen=True)
class Setup:
    """The campaign's noise definitions, or why they could not be read."""

    noises: tuple[NoiseDef, ...] = ()
    problem: str = ""


def read_setup(meta: dict) -> Setup:
    """The noise definitions of the campaign file named in the run's metadata, when that file
    is still the one that ran (same SHA-256)."""
    c = meta.get("campaign", {})
    path = c.get("file")
    if not path or not Path(path).is_file():
        return Setup(problem=f"the campaign file {path or '(not recorded)'} is not readable here")
    try:
        campaign = load_campaign(path)
    except (CampaignError, OSError, ValueError) as exc:
        return Setup(problem=f"the campaign file {path} no longer loads ({exc})")
    if c.get("sha256") and campaign.text_hash != c["sha256"]:
        return Setup(problem=f"the campaign file {path} has changed since the run (SHA-256 differs)")
    return Setup(noises=campaign.noises)


def _values(scores: pd.DataFrame, column: str) -> list[str]:
    return [str(v) for v in dict.fromkeys(scores[column].dropna())] if column in scores else []


def flown_text(scores: pd.DataFrame) -> str:
    """``'Flown: the seed's linear models ... of the F-16; condition seed-5deg; maneuver 2-1-1-2; open loop.'``"""
    parts = []
    for aircraft in _values(scores, "aircraft") or ["?"]:
        name = AIRCRAFT_NAMES.get(aircraft, aircraft)
        rows = scores[scores["aircraft"].astype(str) == aircraft] if "aircraft" in scores else scores
        for variant in _values(rows, "variant") or ["nominal"]:
            parts.append(VARIANT_TEXT.get(variant, "the JSBSim {aircraft}, variant " + variant).format(aircraft=name))
    text = "Flown: " + "; ".join(parts)
    for column, label in (("condition", "condition"), ("maneuver", "maneuver"), ("loop", "loop")):
        values = _values(scores, column)
        if values:
            text += f"; {label}{'s' if len(values) > 1 else ''} {', '.join(values)}"
    return text + "."


def _level(value: float, factor: float, unit: str) -> str:
    return f"{value * factor:.3g}{unit}"


def _channel_text(spec: ChannelNoise, factor: float, unit: str) -> str:
    parts = []
    if spec.white_std:
        parts.append(_level(spec.white_std, factor, unit))
    if spec.colored_std:
        parts.append(f"Gauss-Markov {_level(spec.colored_std, factor, unit)} (τ {spec.colored_tau_s:g} s)")
    if spec.bias:
        parts.append(f"bias {_level(spec.bias, factor, unit)}")
    return ", ".join(parts) or "none"


def sensor_text(name: str, scale: float = 1.0) -> str:
    """The preset's sensor levels, channels with equal levels grouped: ``'α, β 0.1°; p, q, r 0.14°/s; ...'``."""
    model = preset(name)
    if scale != 1.0:
        model = model.scaled(scale)
    groups: dict[str, list[str]] = {}
    order = list(_CHANNELS)
    for channel, spec in sorted(model.channels, key=lambda c: order.index(c[0]) if c[0] in order else len(order)):
        symbol, factor, unit = _CHANNELS.get(channel, (channel, 1.0, ""))
        groups.setdefault(_channel_text(spec, factor, unit), []).append(symbol)
    text = "; ".join(f"{', '.join(symbols)} {level}" for level, symbols in groups.items())
    if model.turbulence is not None:
        text += f"; turbulence {model.turbulence.kind}, severity {model.turbulence.severity}"
    return text or "no sensor noise"


def _output_text(noise: NoiseDef) -> str:
    return ", ".join(f"{k} {v:g}" for k, v in noise.output)


def noise_text(noise: NoiseDef) -> str:
    """One line: preset, scale, where it applies, and the output noise."""
    if noise.preset == "none":
        text = "no sensor noise (clean regressors)"
    else:
        scale = f" × {noise.scale:g}" if noise.scale != 1.0 else ""
        text = f"preset {noise.preset}{scale} {APPLY_TO_TEXT.get(noise.apply_to, noise.apply_to)}"
    if noise.output:
        text += f"; white noise on the outputs (σ {_output_text(noise)})"
    if noise.flight_scales:
        text += f"; per maneuver × {', '.join(f'{k:g}' for k in noise.flight_scales)}"
    return text


def noise_table(noises: tuple[NoiseDef, ...]) -> pd.DataFrame:
    """One row per noise definition: name, what it does, the sensor levels (standard deviations)."""
    return pd.DataFrame({"noise": [n.name for n in noises], "definition": [noise_text(n) for n in noises],
                         "sensor noise (σ)": [sensor_text(n.preset, n.scale) if n.preset != "none" else "none"
                                              for n in noises]})
