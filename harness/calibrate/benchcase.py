"""The calibration's speed case (issue 15, must-show 2): ten scales of the F-16's lateral and
pitch-damping functions, one 20 s three-axis recording of the nominal F-16 (realistic noise),
every start 30 % wrong (1.3 and 0.7 alternately), so the answer is 1 for each."""
from __future__ import annotations

from maneuvers.combine import Sequence
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.multistep import multistep
from models.aircraft import Aircraft

FUNCTIONS = ("Cnb", "Clb", "Cnr", "Clp", "Cmq", "Clda", "Cnda", "Cndr", "CYb", "Cldr")
WRONG = 0.3
DURATION_S = 20.0


def bench_recording(seed: int = 3):
    """Stabilator 3-2-1-1, aileron doublet, rudder 2-1-1 (1.5 s apart), 20 s at 50 Hz, the
    ``realistic`` noise layer with ``seed``."""
    from harness.noise import apply_noise
    from harness.noise_presets import preset
    inputs = Sequence((multistep("3-2-1-1", "de", 2.0, 0.5), multistep("doublet", "da", 3.0, 1.0),
                       multistep("2-1-1", "dr", 3.0, 1.0)), gap_s=1.5, name="calibration-bench")
    rec = fly_maneuver(FlightSpec(input=inputs, aircraft=Aircraft("f16"), duration_s=DURATION_S))
    return apply_noise(rec, preset("realistic"), seed)


def bench_parameters() -> str:
    """``aero/coefficient/<f>:scale=<1 ± 0.3>`` for the ten functions."""
    return ",".join(f"aero/coefficient/{f}:scale={1 + WRONG if k % 2 == 0 else 1 - WRONG}"
                    for k, f in enumerate(FUNCTIONS))
