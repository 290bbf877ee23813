"""The concealed-effect gallery: F-16 recordings with one effect hidden in the simulation,
the ``realistic`` noise layer on top, an identification and a different validation maneuver.

The recordings' metadata do not reveal the effect: ``meta['simulation']['hidden_effects']``
and the truth derivatives are moved to ``<case>.answer.json`` beside them.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy import signal

from harness.atomic import write_text_atomic
from harness.noise import apply_noise
from harness.noise_presets import preset
from harness.recording_io import write_recording
from maneuvers.combine import Sequence
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.multistep import multistep
from models.aircraft import Aircraft
from models.atmosphere import Turbulence
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
class StructuralMode:
    """A flexible mode the rigid-body simulation lacks, added to the recorded signals: the
    ringing part of a lightly damped second-order response to the stabilator,
    m = x − δe with ẍ + 2ζω ẋ + ω² x = ω² δe (ω = 2π ``frequency_hz``), seen by the pitch
    gyro as ``q_gain``·m (rad/s per rad) and by the normal accelerometer as ``az_gain``·m
    (g per rad)."""

    frequency_hz: float = 8.0
    damping: float = 0.02
    q_gain: float = 0.5
    az_gain: float = 3.0

    def ringing(self, t: np.ndarray, de: np.ndarray, oversample: int = 10) -> np.ndarray:
        """m(t) for stabilator history ``de`` (rad) sampled at ``t`` (simulated on a grid
        ``oversample`` times finer, δe linearly interpolated)."""
        w = 2.0 * math.pi * self.frequency_hz
        mode = signal.lti([w * w], [1.0, 2.0 * self.damping * w, w * w])
        fine = np.linspace(t[0], t[-1], (t.size - 1) * oversample + 1)
        u = np.interp(fine, t, de - de[0])
        _, x, _ = signal.lsim(mode, u, fine)
        return (x - u)[::oversample]

    def add_to(self, rec):
        """A copy of recording ``rec`` with the mode in its q and a_z channels."""
        data = rec.data.copy()
        m = self.ringing(data["t_s"].to_numpy(), data["de_rad"].to_numpy())
        data["q_rps"] = data["q_rps"] + self.q_gain * m
        data["az_g"] = data["az_g"] + self.az_gain * m
        return type(rec)(data=data, meta=rec.meta, name=rec.name)


@dataclass(frozen=True)
class GalleryCase:
    name: str
    effects: tuple[HiddenEffect, ...]
    parameter: str          # what the diagnosis must report
    truth: float            # its true size (effects.md convention)
    turbulence: Turbulence | None = None   # process noise flown with the maneuver
    mode: StructuralMode | None = None     # a flexible mode added to the recorded signals


CASES = (
    GalleryCase("unsteady_alphadot", (HiddenEffect("unsteady_alphadot", -3.0),), "Cm_alphadot", -3.0),
    GalleryCase("control_delay", (HiddenEffect("control_delay", 0.08, surface="de"),), "tau_de", 0.08),
    GalleryCase("sensor_offset", (HiddenEffect("sensor_offset", 10.0, position_ft=(10.0, 0.0, 0.0)),),
                "x_accelerometer", 10.0),
    GalleryCase("nonlinear_alpha", (HiddenEffect("nonlinear_alpha", 1.0),), "Cm_alpha2", 1.0),
    GalleryCase("coefficient_error", (HiddenEffect("coefficient_error", -3.0, regressor="qhat"),), "Cm_qhat", -3.0),
    GalleryCase("cg_offset", (HiddenEffect("cg_offset", 0.5),), "dx_moment_reference", 0.5),
    GalleryCase("sensor_bias", (HiddenEffect("sensor_bias", 1.5 * math.pi / 180, channel="alpha"),), "bias_alpha",
                1.5 * math.pi / 180),
    GalleryCase("structural_mode", (), "mode_frequency_hz", 8.0, mode=StructuralMode()),
    GalleryCase("turbulence", (), "sigma_gust_fps", float("nan"), turbulence=Turbulence("dryden", 3, 30.0)),
    GalleryCase("none", (), "", 0.0),
)


def case(name: str) -> GalleryCase:
    for c in CASES:
        if c.name == name:
            return c
    raise ValueError(f"no gallery case {name!r}; cases: {[c.name for c in CASES]}")


def conceal(rec):
    """Move the answer out of the recording: the hidden effects, the turbulence and the truth
    derivatives from its metadata, the per-sample truth columns from its data; returns
    (recording, answer)."""
    meta = json.loads(json.dumps(rec.meta))
    answer = {"hidden_effects": meta["simulation"].pop("hidden_effects", []), "truth": meta.pop("truth", None),
              "turbulence": meta["simulation"].pop("turbulence", None)}
    data = rec.data.drop(columns=[c for c in rec.data.columns if c.startswith("truth_")])
    return type(rec)(data=data, meta=meta, name=rec.name), answer


def write_case(c: GalleryCase, out_dir: str | Path, seed: int = 1,
               inputs: tuple[Sequence, Sequence] | None = None) -> dict[str, Path]:
    """Fly, corrupt and write one case: ``<case>-identification.csv`` and
    ``<case>-validation.csv`` (noise seeds ``seed`` and ``seed + 1``) and the answer.
    ``inputs`` replaces the gallery's identification and validation inputs."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths, answers = {}, {}
    maneuvers = inputs or (identification_input(), validation_input())
    for i, (role, inputs_) in enumerate(zip(("identification", "validation"), maneuvers)):
        spec = FlightSpec(input=inputs_, aircraft=Aircraft("f16", hidden=c.effects),
                          duration_s=max(DURATION_S, inputs_.duration_s))
        if c.turbulence is not None:
            spec = replace(spec, turbulence=c.turbulence, turbulence_seed=100 * seed + i)
        rec = fly_maneuver(spec)
        if c.mode is not None:
            rec = c.mode.add_to(rec)
        rec = apply_noise(rec, preset("realistic"), seed + i)
        rec, answer = conceal(rec)
        paths[role] = write_recording(rec, out_dir / f"{c.name}-{role}.csv")
        answers[role] = answer["hidden_effects"]
    extra = {}
    if c.turbulence is not None:
        extra["turbulence"] = {"description": c.turbulence.describe(), "seeds": [100 * seed, 100 * seed + 1]}
    if c.mode is not None:
        extra["structural_mode"] = {"frequency_hz": c.mode.frequency_hz, "damping": c.mode.damping,
                                    "q_gain": c.mode.q_gain, "az_gain": c.mode.az_gain}
    write_text_atomic(out_dir / f"{c.name}.answer.json", json.dumps(
        {"case": c.name, "parameter": c.parameter, "truth": c.truth if math.isfinite(c.truth) else None,
         "hidden_effects": answers["identification"], "noise": "realistic", "seeds": [seed, seed + 1], **extra},
        indent=1))
    return paths
