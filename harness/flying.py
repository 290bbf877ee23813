"""Command-line options that define a flight, turning them into a FlightSpec, and the default flight."""
from __future__ import annotations

import argparse
from pathlib import Path

from harness.errors import OptionError

INPUT_CHOICES = ("doublet", "2-1-1-2", "2-1-1", "3-2-1-1", "sweep-linear", "sweep-log", "multisine",
                 "three-axis", "lateral")


AIRCRAFT_HELP = ("JSBSim model: f16, 737, dhc6, an aircraft of the jsbsim package's library by name (c172x, "
                 "A320, ...), or the path of a JSBSim aircraft XML (flown as it is, nominal "
                 "variant only) (default: f16)")
CONDITION_HELP = ("flight condition by name (f16: seed-5deg, the default, or alpha-7.5; 737: cruise; dhc6: "
                  "twin-otter-017) or by value, h=<ft>,V=<ft/s true airspeed> (e.g. h=10000,V=427.4; an aircraft "
                  "given by path needs one) (default: the aircraft's first condition)")


def add_flight_options(p: argparse.ArgumentParser) -> None:
    """Options shared by every command that flies an aircraft."""
    p.add_argument("--aircraft", default="f16", metavar="f16|737|dhc6|PATH.xml", help=AIRCRAFT_HELP)
    p.add_argument("--variant", default="nominal", choices=["nominal", "exact-truth", "unstable"],
                   help="nominal; exact-truth (aerodynamics exactly linear, seed §III.C); "
                        "unstable (aero reference point moved forward) (default: nominal)")
    p.add_argument("--condition", default=None, help=CONDITION_HELP)
    p.add_argument("--maneuver", default="2-1-1-2", choices=INPUT_CHOICES,
                   help="input design (default 2-1-1-2); three-axis = de 2-1-1-2, da doublet, dr 2-1-1; "
                        "lateral = da doublet then dr 2-1-1")
    p.add_argument("--surface", default="de", help="de, da or dr (a comma list for multisine) (default: de)")
    p.add_argument("--amplitude-deg", type=float, default=1.0,
                   help="pulse height / sweep amplitude / multisine peak, deg (default: 1)")
    p.add_argument("--unit-pulse-s", type=float, default=1.0, help="unit pulse width of multi-step inputs, s (default: 1)")
    p.add_argument("--sample-rate", type=float, default=50.0, help="recording rate, Hz (default 50)")
    p.add_argument("--sim-rate", type=float, default=120.0,
                   help="least simulation rate, Hz (default 120; raised to a whole multiple of the sample rate)")
    p.add_argument("--duration", type=float, default=None, help="recording length, s (default 20 or the input's length)")
    p.add_argument("--loop", default="open",
                   help="'open' or 'closed:K' for de = de_cmd + K*q (K in rad per rad/s) (default: open)")


def add_noise_options(p: argparse.ArgumentParser) -> None:
    """``--noise PRESET --seed N``: a noisy recording, as a campaign realization makes one."""
    from harness.noise_presets import PRESETS
    p.add_argument("--noise", default="none", choices=PRESETS,
                   help="sensor noise preset of harness/noise_presets.py applied to the recording (turbulence "
                        "presets also fly JSBSim's Dryden turbulence); the truth columns stay clean (default: none)")
    p.add_argument("--seed", type=int, default=1,
                   help="seed of the noise (and turbulence) draw; the same seed gives the same recording (default: 1)")


def resolve_aircraft(model: str, variant: str = "nominal"):
    """``--aircraft``: a project model by name or a JSBSim aircraft XML by path (as ``diagnose --model``)."""
    from models.aircraft import MODEL_ARGUMENT_HELP, MODELS, Aircraft, is_xml_model, model_argument

    given, model = model, model_argument(model)
    if model in MODELS:
        try:
            return Aircraft(model, variant)
        except ValueError as exc:
            raise OptionError(f"--aircraft {given}: {exc}") from None
    if not is_xml_model(model):
        raise OptionError(f"--aircraft {given!r} is not " + MODEL_ARGUMENT_HELP.format(models=list(MODELS)))
    try:
        aircraft = Aircraft(str(Path(model).resolve()), variant)
        aircraft.surfaces  # noqa: B018 - fails early, naming what the XML lacks
    except (ValueError, OSError) as exc:
        raise OptionError(f"--aircraft {model}: {exc}") from None
    return aircraft


def parse_loop(text: str):
    """``'open'`` or ``'closed:K'`` -> :class:`models.flight.Loop`."""
    from models.flight import Loop
    if text == "open":
        return Loop()
    kind, _, gain = text.partition(":")
    if kind != "closed" or not gain:
        raise OptionError(f"--loop must be 'open' or 'closed:K' (e.g. closed:0.5), not {text!r}")
    try:
        return Loop("closed", float(gain))
    except ValueError:
        raise OptionError(f"--loop closed:K needs a number for K, not {gain!r}") from None


def spec_from_args(args: argparse.Namespace):
    """Build the :class:`maneuvers.fly.FlightSpec` the options describe."""
    from maneuvers.fly import FlightSpec
    from maneuvers.inputs import default_lateral_input, default_three_axis_input, make_input

    if args.maneuver == "three-axis":
        signal = default_three_axis_input()
    elif args.maneuver == "lateral":
        signal = default_lateral_input()
    else:
        signal = make_input(args.maneuver, args.surface, args.amplitude_deg, args.unit_pulse_s,
                            sample_rate_hz=args.sample_rate)
    return FlightSpec(input=signal, aircraft=resolve_aircraft(args.aircraft, args.variant), condition=args.condition,
                      duration_s=args.duration, sample_rate_hz=args.sample_rate, sim_rate_hz=args.sim_rate,
                      loop=parse_loop(args.loop))


def fly_default(out: Path) -> Path:
    """Fly the seed's default maneuver, print its truth table, write the recording."""
    from harness.recording_io import write_recording
    from maneuvers.fly import FlightSpec, fly_maneuver, truth_table
    from models.truth import Derivatives

    spec = FlightSpec()
    rec = fly_maneuver(spec)
    truth = Derivatives.from_dict(rec.meta["truth"])
    path = write_recording(rec, Path(out) / "f16_stabilator_2112.csv")
    print(f"Flew {spec.describe()}.\n")
    print(truth_table(truth))
    print(f"\nRecording: {path.resolve()} (+ {path.with_suffix('.meta.json').name}), {rec.n} samples")
    return path
