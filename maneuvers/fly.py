"""Flying a maneuver in JSBSim and packaging it as a recording with its truth."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import jsbsim
import pandas as pd

from maneuvers.base import InputSignal
from maneuvers.multistep import stabilator_2112
from maneuvers.recording import FORMAT_ID, Recording
from models.aircraft import Aircraft, load_fdm
from models.conditions import condition_for
from models.exact import exact_truth_root
from models.hidden import hidden_root, needs_copy
from models.atmosphere import Turbulence
from models.flight import FlightHistory, Loop, fly
from models.trim import TrimPoint, trim
from models.truth import Derivatives, excursion_from_history, truth_derivatives
from models.errors import UserError
from maneuvers.base import InputSpecError

DEFAULT_DURATION_S = 20.0  # the seed's records are 20 s at 50 Hz


@dataclass(frozen=True)
class FlightSpec:
    """Everything that defines one simulated flight (and so its content hash).

    Attributes
    ----------
    input : InputSignal
        The surface inputs (perturbations from trim); default the seed's stabilator 2-1-1-2,
        1 deg, 1 s unit pulse.
    aircraft : Aircraft
        Model and variant.
    condition : str or None
        Name of the flight condition (the aircraft's default when None).
    duration_s : float or None
        Recording length; default 20 s, or the input's length if that is longer.
    sample_rate_hz, sim_rate_hz : float
        Recording rate (default 50 Hz, as in the seed) and the least simulation rate
        (default 120 Hz; raised to a whole multiple of the sample rate, see
        :func:`models.flight.frames_per_sample`).
    loop : Loop
        Open loop, or the pitch-rate feedback δs = δs,cmd + K·q.
    turbulence, turbulence_seed : Turbulence or None, int
        Process noise flown with this flight (its own gusts for each seed).
    """

    input: InputSignal = field(default_factory=stabilator_2112)
    aircraft: Aircraft = field(default_factory=Aircraft)
    condition: str | None = None
    duration_s: float | None = None
    sample_rate_hz: float = 50.0
    sim_rate_hz: float = 120.0
    loop: Loop = field(default_factory=Loop)
    turbulence: Turbulence | None = None
    turbulence_seed: int = 0

    @property
    def length_s(self) -> float:
        if self.duration_s is not None:
            if self.duration_s < self.input.duration_s - 1e-9:
                raise InputSpecError(f"duration {self.duration_s} s is shorter than the input "
                                 f"{self.input.describe()} ({self.input.duration_s} s)")
            return self.duration_s
        return max(DEFAULT_DURATION_S, math.ceil(self.input.duration_s))

    def describe(self) -> str:
        return (f"{self.aircraft.label} at {condition_for(self.aircraft.model, self.condition).name}, "
                f"{self.input.describe()}, {self.loop.describe()}, {self.length_s:g} s at {self.sample_rate_hz:g} Hz")


def _load_and_trim(spec: FlightSpec) -> tuple[jsbsim.FGFDMExec, TrimPoint, dict]:
    cond = condition_for(spec.aircraft.model, spec.condition)
    kwargs: dict = {}
    if spec.aircraft.variant == "exact-truth":
        root, name = exact_truth_root(spec.aircraft, cond)
        kwargs = {"root": root, "name": name}
    elif spec.aircraft.hidden and needs_copy(spec.aircraft.hidden):
        if spec.aircraft.variant != "nominal":
            raise UserError("hidden effects are added to the nominal aircraft only")
        root, name = hidden_root(spec.aircraft, cond)
        kwargs = {"root": root, "name": name}
    fdm = load_fdm(spec.aircraft, 1.0 / 120.0, **kwargs)
    return fdm, trim(fdm, spec.aircraft, cond), kwargs


def fly_maneuver(spec: FlightSpec = FlightSpec()) -> Recording:
    """Fly ``spec`` and return a canonical recording with per-sample truth coefficients.

    The recording's columns follow ``../shared/recording-format.md``; the ``truth_*``
    columns hold JSBSim's own aerodynamic coefficients about the c.g. (``truth_CX_1`` ...,
    ``truth_CL_1``, ``truth_CD_1``) and the α̇ it used (``truth_alphadot_rps``). The
    metadata's ``truth`` key holds the derivatives at trim (local slope and fit over this
    maneuver's excursion) and ``simulation`` what produced the flight.
    """
    fdm, tp, kwargs = _load_and_trim(spec)
    hist = fly(fdm, spec.aircraft, tp, spec.input.deflections, spec.length_s,
               sample_rate_hz=spec.sample_rate_hz, sim_rate_hz=spec.sim_rate_hz, loop=spec.loop,
               turbulence=spec.turbulence, turbulence_seed=spec.turbulence_seed)
    cond = condition_for(spec.aircraft.model, spec.condition)
    truth = truth_derivatives(spec.aircraft, cond, excursion_from_history(hist.channels, tp), **kwargs)
    return to_recording(spec, hist, tp, truth)


def to_recording(spec: FlightSpec, hist: FlightHistory, tp: TrimPoint, truth: Derivatives) -> Recording:
    """Package a flight as a :class:`Recording` in the canonical format."""
    data = dict(hist.channels)
    units = {"alphadot": "rps"}
    for name, values in hist.truth.items():
        data[f"truth_{name}_{units.get(name, '1')}"] = values
    meta = {
        "format": FORMAT_ID,
        "aircraft": {"f16": "F-16", "737": "Boeing 737", "dhc6": "DHC-6 Twin Otter"}.get(
            spec.aircraft.model, spec.aircraft.name),
        "geometry": {"S_ft2": tp.S_ft2, "b_ft": tp.b_ft, "cbar_ft": tp.cbar_ft},
        "mass": {"mass_slug": tp.mass_slug, "Ix_slugft2": tp.Ix_slugft2, "Iy_slugft2": tp.Iy_slugft2,
                 "Iz_slugft2": tp.Iz_slugft2, "Ixz_slugft2": tp.Ixz_slugft2},
        "sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]},
        "thrust_offset_ft": tp.thrust_offset_ft,
        "source": f"JSBSim {jsbsim.__version__} {spec.aircraft.label} (sidbench)",
        "maneuver": spec.input.describe(),
        "trim": {"alpha_rad": tp.alpha_rad, "beta_rad": tp.beta_rad, "phi_rad": tp.phi_rad,
                 "V_fps": tp.V_fps, "h_ft": tp.h_ft,
                 "theta_rad": tp.theta_rad, "qbar_psf": tp.qbar_psf, "mach": tp.mach,
                 "de_rad": tp.de_rad, "da_rad": tp.da_rad, "dr_rad": tp.dr_rad,
                 "thrust_lbf": tp.thrust_lbf, "throttle": tp.throttle},
        "truth": truth.as_dict(),
        "simulation": {
            "jsbsim": jsbsim.__version__, "model": spec.aircraft.model, "variant": spec.aircraft.variant,
            "rp_shift_in": spec.aircraft.rp_shift_in if spec.aircraft.variant == "unstable" else 0.0,
            "condition": tp.condition, "loop": {"kind": spec.loop.kind, "pitch_rate_gain": spec.loop.pitch_rate_gain},
            "turbulence": None if spec.turbulence is None else {
                "kind": spec.turbulence.kind, "severity": spec.turbulence.severity,
                "wind_20ft_fps": spec.turbulence.wind_20ft_fps, "seed": spec.turbulence_seed},
            "sim_rate_hz": hist.sim_rate_hz, "frames": hist.frames, "sample_rate_hz": hist.sample_rate_hz,
            "rates": "body rates relative to the Earth (equal to the air-relative rates in still air)",
            "cg_in": list(tp.cg_in), "aero_rp_in": list(tp.aero_rp_in),
            # gear, flaps, speed brake and scheduled surfaces as flown (models.configuration)
            "configuration": tp.configuration,
            # "jsbsim" (JSBSim's trim) or "surfaces" (the project's, FCS disabled); any
            # scheduled surface held on one side of its switch, and why (models.trim)
            "trim_method": tp.method, "trim_held": tp.held,
            # the concealed physics and its true size (the recording's channels and
            # sensors metadata do not reveal it)
            "hidden_effects": [e.describe() for e in spec.aircraft.hidden],
        },
    }
    return Recording(data=pd.DataFrame(data), meta=meta, name="flight").validate("simulated flight")


def default_truth(aircraft: Aircraft, condition: str | None = None) -> Derivatives:
    """Truth derivatives whose ``fit`` definition spans the default maneuvers' excursions.

    The longitudinal variables take the excursion of the seed's stabilator 2-1-1-2 (1 deg,
    1 s), the lateral ones that of the default lateral input (aileron doublet then rudder
    2-1-1, 2 deg): the ranges a typical recording explores.
    """
    from maneuvers.inputs import default_lateral_input
    from models.truth import LATERAL_VARIABLES

    cond = condition_for(aircraft.model, condition)
    excursion: dict[str, tuple[float, float]] = {}
    kwargs: dict = {}
    for signal, variables in ((stabilator_2112(), ("alpha", "qhat", "de")),
                              (default_lateral_input(), LATERAL_VARIABLES)):
        spec = FlightSpec(input=signal, aircraft=aircraft, condition=condition)
        fdm, tp, kwargs = _load_and_trim(spec)
        hist = fly(fdm, aircraft, tp, signal.deflections, spec.length_s)
        exc = excursion_from_history(hist.channels, tp)
        excursion.update({v: exc[v] for v in variables})
    return truth_derivatives(aircraft, cond, excursion, **kwargs)


def truth_table(truth: Derivatives) -> str:
    """A readable table of the derivatives (local slope and excursion fit)."""
    lines = [f"Truth derivatives: {truth.aircraft} at {truth.condition['name']} "
             f"(h = {truth.condition['h_ft']:.0f} ft, V = {truth.condition['V_fps']:.1f} ft/s, "
             f"alpha = {math.degrees(truth.condition['alpha_rad']):.3f} deg)",
             "per rad about the c.g.; rates normalised by cbar/2V and b/2V",
             f"{'derivative':<12}{'local':>12}{'fit':>12}"]
    for name in truth.local:
        lines.append(f"{name:<12}{truth.local[name]:>12.5f}{truth.fit[name]:>12.5f}")
    for name, v in truth.unsteady.items():
        lines.append(f"{name:<12}{v:>12.5f}{v:>12.5f}")
    return "\n".join(lines)
