"""The concealed-effect gallery: F-16 recordings with one effect hidden in the simulation,
the ``realistic`` noise layer on top, an identification and a different validation maneuver.

The recordings' metadata do not reveal the effect: ``meta['simulation']['hidden_effects']``
and the truth derivatives are moved to ``<case>.answer.json`` beside them.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from harness.atomic import write_text_atomic
from harness.noise import apply_noise
from harness.noise_presets import preset
from harness.recording_io import write_recording
from maneuvers.combine import Sequence
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.multistep import multistep
from models.aircraft import Aircraft
from models.hidden import HiddenEffect

DURATION_S = 30.0


def identification_input() -> Sequence:
    """Stabilator 3-2-1-1 (2 deg, 0.5 s unit), aileron doublet (3 deg), rudder 2-1-1 (3 deg)."""
    return Sequence((multistep("3-2-1-1", "de", 2.0, 0.5), multistep("doublet", "da", 3.0, 1.0),
                     multistep("2-1-1", "dr", 3.0, 1.0)), gap_s=2.0, name="gallery_identification")


def validation_input() -> Sequence:
    """A different input: stabilator 2-1-1-2 (1.5 deg, 0.7 s unit), rudder doublet, aileron 2-1-1."""
    return Sequence((multistep("2-1-1-2", "de", 1.5, 0.7), multistep("doublet", "dr", 3.0, 1.0),
                     multistep("2-1-1", "da", 3.0, 0.7)), gap_s=2.0, name="gallery_validation")


@dataclass(frozen=True)
class GalleryCase:
    name: str
    effects: tuple[HiddenEffect, ...]
    parameter: str          # what the diagnosis must report
    truth: float            # its true size (effects.md convention)


CASES = (
    GalleryCase("unsteady_alphadot", (HiddenEffect("unsteady_alphadot", -3.0),), "Cm_alphadot", -3.0),
    GalleryCase("control_delay", (HiddenEffect("control_delay", 0.08, surface="de"),), "tau_de", 0.08),
    GalleryCase("sensor_offset", (HiddenEffect("sensor_offset", 10.0, position_ft=(10.0, 0.0, 0.0)),),
                "x_accelerometer", 10.0),
    GalleryCase("nonlinear_alpha", (HiddenEffect("nonlinear_alpha", 1.0),), "Cm_alpha2", 1.0),
    GalleryCase("none", (), "", 0.0),
)


def case(name: str) -> GalleryCase:
    for c in CASES:
        if c.name == name:
            return c
    raise ValueError(f"no gallery case {name!r}; cases: {[c.name for c in CASES]}")


def conceal(rec):
    """Move the answer out of the recording's metadata; returns (recording, answer)."""
    meta = json.loads(json.dumps(rec.meta))
    answer = {"hidden_effects": meta["simulation"].pop("hidden_effects", []), "truth": meta.pop("truth", None)}
    return type(rec)(data=rec.data, meta=meta, name=rec.name), answer


def write_case(c: GalleryCase, out_dir: str | Path, seed: int = 1) -> dict[str, Path]:
    """Fly, corrupt and write one case: ``<case>-identification.csv`` and
    ``<case>-validation.csv`` (noise seeds ``seed`` and ``seed + 1``) and the answer."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths, answers = {}, {}
    for i, (role, signal) in enumerate((("identification", identification_input()), ("validation", validation_input()))):
        rec = fly_maneuver(FlightSpec(input=signal, aircraft=Aircraft("f16", hidden=c.effects), duration_s=DURATION_S))
        rec = apply_noise(rec, preset("realistic"), seed + i)
        rec, answer = conceal(rec)
        paths[role] = write_recording(rec, out_dir / f"{c.name}-{role}.csv")
        answers[role] = answer["hidden_effects"]
    write_text_atomic(out_dir / f"{c.name}.answer.json", json.dumps(
        {"case": c.name, "parameter": c.parameter, "truth": c.truth, "hidden_effects": answers["identification"],
         "noise": "realistic", "seeds": [seed, seed + 1]}, indent=1))
    return paths
