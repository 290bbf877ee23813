"""Named noise presets with documented levels.

Sensor levels of ``white`` follow Table 3 ("Magnitude of sensor noise standard deviations")
of *Designing Stipulated Gains of Aircraft Stability and Control Augmentation Systems for
Semiglobal Trajectories Tracking*, ISRN Aerospace Engineering, 2014 (Hindawi, article
409408): angle of attack and sideslip 0.1 deg, rate gyros 0.14 deg/s, accelerometers
0.98 ft/s² (0.0305 g), attitude 0.573 deg, altitude 10 ft. Where that table gives none, or a
figure far from a research-grade flight-test installation, the project's own choice is marked
"sidbench": surface position potentiometers 0.05 deg, airspeed 1 ft/s (the table's 11 ft/s
is a cockpit indicator, not a flight-test air-data system), dynamic pressure 0.5 psf, Mach
0.001. All presets drop the angular accelerations JSBSim records (pdot, qdot, rdot): flight
recordings rarely have them, so estimators must differentiate the rates.

``realistic`` adds to ``white`` first-order Gauss-Markov noise (τ = 0.5 s) at half the white
level on the air data, rates and accelerations — the serially correlated sensor noise of the
seed's colored-noise studies — and small constant biases (α 0.1 deg, β 0.05 deg, rates
0.05 deg/s, accelerometers 0.005 g). ``heavy`` is ``realistic`` at three times the level.
The turbulence presets fly JSBSim's MIL-spec Dryden model (severity 1 light, 3 moderate;
20-ft wind 15 and 30 ft/s) with ``white`` sensors.
"""
from __future__ import annotations

import math

from harness.noise import ChannelNoise, NoiseModel
from models.atmosphere import Turbulence
from models.errors import OptionError
from models.constants import G0_FPS2 as G0

DEG = math.pi / 180.0
ANGULAR_ACCELERATIONS = ("pdot", "qdot", "rdot")

_SOURCE = ("ISRN Aerospace Engineering 2014, article 409408, Table 3 (alpha, beta, rates, "
           "accelerometers, attitude, altitude); sidbench choices for surfaces, V, qbar, Mach")

WHITE_LEVELS = {  # canonical units
    "alpha": 0.1 * DEG, "beta": 0.1 * DEG,
    "p": 0.14 * DEG, "q": 0.14 * DEG, "r": 0.14 * DEG,
    "ax": 0.98 / G0, "ay": 0.98 / G0, "az": 0.98 / G0,
    "phi": 0.573 * DEG, "theta": 0.573 * DEG, "psi": 0.573 * DEG,
    "h": 10.0,
    "de": 0.05 * DEG, "da": 0.05 * DEG, "dr": 0.05 * DEG,
    "V": 1.0, "qbar": 0.5, "mach": 0.001,
}
COLORED = ("alpha", "beta", "p", "q", "r", "ax", "ay", "az")
BIASES = {"alpha": 0.1 * DEG, "beta": 0.05 * DEG, "p": 0.05 * DEG, "q": 0.05 * DEG, "r": 0.05 * DEG,
          "ax": 0.005, "ay": 0.005, "az": 0.005}


def _white() -> dict[str, ChannelNoise]:
    return {k: ChannelNoise(white_std=v) for k, v in WHITE_LEVELS.items()}


def _realistic(factor: float = 1.0) -> dict[str, ChannelNoise]:
    out = {}
    for k, v in WHITE_LEVELS.items():
        out[k] = ChannelNoise(white_std=factor * v,
                              colored_std=factor * 0.5 * v if k in COLORED else 0.0, colored_tau_s=0.5,
                              bias=factor * BIASES.get(k, 0.0))
    return out


def preset(name: str) -> NoiseModel:
    """The preset called ``name`` (see :data:`PRESETS`)."""
    if name == "none":
        return NoiseModel.build("none", source="no noise")
    if name == "white":
        return NoiseModel.build("white", _white(), source=_SOURCE, drop=ANGULAR_ACCELERATIONS)
    if name == "realistic":
        return NoiseModel.build("realistic", _realistic(), source=_SOURCE + "; colored and bias levels: sidbench",
                                drop=ANGULAR_ACCELERATIONS)
    if name == "heavy":
        return NoiseModel.build("heavy", _realistic(3.0), source="3 x realistic", drop=ANGULAR_ACCELERATIONS)
    if name == "turbulence-light":
        return NoiseModel.build("turbulence-light", _white(), turbulence=Turbulence("dryden", 1, 15.0),
                                source=_SOURCE + "; JSBSim MIL-spec Dryden, severity 1", drop=ANGULAR_ACCELERATIONS)
    if name == "turbulence-moderate":
        return NoiseModel.build("turbulence-moderate", _white(), turbulence=Turbulence("dryden", 3, 30.0),
                                source=_SOURCE + "; JSBSim MIL-spec Dryden, severity 3", drop=ANGULAR_ACCELERATIONS)
    raise OptionError(f"unknown noise preset {name!r}; choose one of {PRESETS}")


PRESETS = ("none", "white", "realistic", "heavy", "turbulence-light", "turbulence-moderate")
