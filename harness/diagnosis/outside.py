"""The outside sweep: the discrepancy diagnosis scored on recordings made the way a flight-test
team's data arrive, at flight conditions and on an aircraft the project did not tune it on.

Each case flies one aircraft (the F-16, or the JSBSim package's ``c172x`` given by the path of
its XML; the 737 in a self-check) at a condition given by value, with at most one concealed
effect (``models.hidden``), and post-processes the flight as instruments would record it:

- **Actuators.** Each commanded surface passes through a second-order actuator
  (ω = 40 rad/s, ζ = 0.7, zero-order-hold exact on the simulation frames) *before* it is
  flown, so the aircraft flies the actuator output and the recording holds the measured
  actuator position (plus 0.05° white noise), not the command. (At the closed-loop
  conditions the project's pitch-rate feedback adds to the actuator output.)
- **Gyros measure inertial rates**: p, q, r = JSBSim's Earth-relative body rates plus the
  Earth's rotation in body axes, C_bn·ω_e (from the true attitude and the trim latitude).
- **Air data**: white plus first-order Gauss-Markov noise on α and β (0.1° each, τ = 1 s);
  the ``white`` preset's levels on every other channel; the angular accelerations dropped.
- **Values rounded to 8 significant digits**, as a telemetry export prints them; no altitude
  channel in some cases, no thrust channel in others; metadata a team would write (geometry,
  mass, a trim block of α, V and h from the first second), no simulation details.

Maneuvers: pitch-only (stabilator 3-2-1-1; validation 2-1-1-2), lateral-only (aileron doublet
and rudder 2-1-1; validation rudder doublet and aileron 2-1-1) and three-axis (both), with
null recordings of each kind on each aircraft, and noise-free self-checks (a clean recording
of the model itself: no noise, no actuator, no rounding) of the F-16, the 737 and the c172x.

Scoring (per case, and totals): (a) the right effect *and parameter* first; (b) its size
within 2 standard errors or 25 %; (c) false findings: every finding other than the true one
(on a null, every finding but ``none``); (d) the validation RMS of the affected output drops
by 30 % or more (turbulence and structural modes excepted).
"""
from __future__ import annotations

import json
import math
import traceback
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal

from harness.atomic import write_text_atomic
from harness.diagnosis.gallery import StructuralMode, conceal
from harness.diagnosis.refine import validation_rms_pair
from harness.diagnosis.sweep import run_resumable, size_right, validation_drop
from harness.noise import ChannelNoise, NoiseModel, apply_noise
from harness.noise_presets import WHITE_LEVELS
from harness.recording_io import write_recording
from maneuvers.channels import CHANNELS
from maneuvers.combine import Sequence
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.multisine import Multisine
from maneuvers.multistep import multistep
from maneuvers.sweeps import FrequencySweep
from maneuvers.recording import Recording
from models.aircraft import Aircraft
from models.atmosphere import Turbulence
from models.flight import Loop
from models.hidden import HiddenEffect as H, offset_accelerometer, vane_shift

DEG = math.pi / 180.0
EARTH_RATE_RPS = 7.292115e-5  # WGS-84, as JSBSim
DURATION_S = 30.0
SIGNIFICANT_DIGITS = 8


def c172x_path() -> str:
    """The JSBSim package's c172x, by the path of its XML (an aircraft the project has no
    model of its own for)."""
    import jsbsim
    return str(Path(jsbsim.get_default_root_dir()) / "aircraft" / "c172x" / "c172x.xml")


# ---------------------------------------------------------------------------------------------
# The recording pipeline


@dataclass(frozen=True)
class Actuated:
    """An input passed through a second-order actuator, ω²/(s² + 2ζωs + ω²), per surface.

    Implements :class:`maneuvers.base.InputSignal`: :meth:`deflections` filters the inner
    input's commands on the (uniform) time grid it is given, the frame grid of the flight
    loop, with the zero-order-hold discretisation (exact for the piecewise-constant
    multi-step commands)."""

    inner: object
    omega_rps: float = 40.0
    zeta: float = 0.7

    @property
    def name(self) -> str:
        return f"{self.inner.name}+actuator"

    @property
    def surfaces(self) -> tuple[str, ...]:
        return self.inner.surfaces

    @property
    def start_s(self) -> float:
        return self.inner.start_s

    @property
    def active_duration_s(self) -> float:
        return self.inner.active_duration_s

    @property
    def duration_s(self) -> float:
        return self.inner.duration_s

    def describe(self) -> str:
        return (f"{self.inner.describe()}, through second-order actuators "
                f"(omega {self.omega_rps:g} rad/s, zeta {self.zeta:g})")

    def deflections(self, t) -> dict[str, np.ndarray]:
        t = np.asarray(t, dtype=float)
        cmd = self.inner.deflections(t)
        if t.size < 2:
            return cmd
        dt = float(t[1] - t[0])
        if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=1e-12):
            raise ValueError("the actuator filters a uniform time grid only")
        w, z = self.omega_rps, self.zeta
        num, den, _ = signal.cont2discrete(([w * w], [1.0, 2.0 * z * w, w * w]), dt, method="zoh")
        b, a = np.ravel(num), np.ravel(den)
        return {s: signal.lfilter(b, a, np.asarray(u, dtype=float)) for s, u in cmd.items()}


def euler_to_body(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """C_bn (NED to body, 3-2-1 Euler angles) per sample: shape (n, 3, 3)."""
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    return np.stack([
        np.stack([ct * cp, ct * sp, -st], -1),
        np.stack([sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct], -1),
        np.stack([cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct], -1)], -2)


def earth_rate_body(phi, theta, psi, latitude_rad: float = 0.0) -> np.ndarray:
    """The Earth's rotation in body axes, (n, 3) rad/s: C_bn·[Ω cos λ, 0, −Ω sin λ]."""
    w_n = np.array([EARTH_RATE_RPS * math.cos(latitude_rad), 0.0, -EARTH_RATE_RPS * math.sin(latitude_rad)])
    return euler_to_body(np.asarray(phi), np.asarray(theta), np.asarray(psi)) @ w_n


def inertial_gyros(data: pd.DataFrame, latitude_rad: float = 0.0) -> pd.DataFrame:
    """A copy with p, q, r turned from Earth-relative into inertial body rates (what a gyro
    measures). The project's trim flies at latitude 0 (``models.trim``); the transport rate
    of flight over the curved Earth (V/R ≈ 2e-5 rad/s) is left out."""
    out = data.copy()
    w = earth_rate_body(data["phi_rad"].to_numpy(), data["theta_rad"].to_numpy(), data["psi_rad"].to_numpy(),
                        latitude_rad)
    for i, c in enumerate(("p_rps", "q_rps", "r_rps")):
        out[c] = data[c].to_numpy() + w[:, i]
    return out


def round_significant(x: np.ndarray, digits: int = SIGNIFICANT_DIGITS) -> np.ndarray:
    """``x`` rounded to ``digits`` significant decimal digits (as a ``%.8g`` export prints)."""
    fmt = f"{{:.{digits}g}}".format
    return np.array([float(fmt(v)) for v in np.asarray(x, dtype=float).tolist()])


def flight_test_noise(white_scale: float = 1.0, gauss_markov_deg: float = 0.1,
                      gauss_markov_tau_s: float = 1.0) -> NoiseModel:
    """White noise at the ``white`` preset's levels (times ``white_scale``) on every channel,
    and on α and β a first-order Gauss-Markov process besides (``gauss_markov_deg``, time
    constant ``gauss_markov_tau_s``):
    vane and air-data errors that wander. No deliberate biases (a sensor bias is a concealed
    effect of its own)."""
    channels = {k: ChannelNoise(white_std=white_scale * v) for k, v in WHITE_LEVELS.items()}
    for k in ("alpha", "beta"):
        channels[k] = ChannelNoise(white_std=white_scale * WHITE_LEVELS[k], colored_std=gauss_markov_deg * DEG,
                                   colored_tau_s=gauss_markov_tau_s)
    return NoiseModel.build("flight-test", channels, source=(
        f"sidbench outside sweep: white preset levels x {white_scale:g}, Gauss-Markov {gauss_markov_deg:g} deg "
        f"(tau {gauss_markov_tau_s:g} s) on alpha and beta"), drop=("pdot", "qdot", "rdot"))


def _team_meta(meta: dict, data: pd.DataFrame, aircraft_label: str, maneuver: str) -> dict:
    """What a flight-test team would send: format, aircraft, geometry, mass, sensors, thrust
    line, a trim block from the first second of data; nothing about the simulation."""
    first = data["t_s"] <= data["t_s"].iloc[0] + 1.0
    trim = {"alpha_rad": float(data.loc[first, "alpha_rad"].mean()), "V_fps": float(data.loc[first, "V_fps"].mean())}
    if "h_ft" in data:
        trim["h_ft"] = float(data.loc[first, "h_ft"].mean())
    return {"format": meta["format"], "aircraft": aircraft_label, "geometry": meta["geometry"], "mass": meta["mass"],
            "sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]}, "thrust_offset_ft": meta.get("thrust_offset_ft", 0.0),
            "source": "flight-test-like recording (sidbench outside sweep): measured surfaces, inertial gyros, "
                      "8 significant digits", "maneuver": maneuver, "trim": trim}


def postprocess(rec: Recording, *, noise: bool = True, seed: int = 1, drop: tuple[str, ...] = (),
                mode: StructuralMode | None = None, aircraft_label: str = "",
                noise_model: NoiseModel | None = None) -> tuple[Recording, dict]:
    """A flown recording as a flight-test team's data arrive; ``(recording, answer)``.

    ``noise=False`` gives the clean self-check recording (Earth-relative rates, no noise, no
    rounding: the model's own flight, concealed). ``drop`` removes quantities (``h``,
    ``thrust``)."""
    if mode is not None:
        rec = mode.add_to(rec)
    if noise:
        rec = Recording(data=inertial_gyros(rec.data), meta=rec.meta, name=rec.name)
        rec = apply_noise(rec, noise_model or flight_test_noise(), seed)
    rec, answer = conceal(rec)
    data = rec.data.drop(columns=[c for c in rec.data.columns
                                  if c.split("_")[0] in set(drop) | {"pdot", "qdot", "rdot"}])
    if noise:
        data = pd.DataFrame({c: round_significant(data[c].to_numpy()) for c in data.columns})
    meta = _team_meta(rec.meta, data, aircraft_label or rec.meta.get("aircraft", ""), rec.meta.get("maneuver", ""))
    return Recording(data=data, meta=meta, name=rec.name).validate("outside recording"), answer


# ---------------------------------------------------------------------------------------------
# Conditions, maneuvers and cases


@dataclass(frozen=True)
class Condition:
    """Where a case flies: aircraft, condition by value, loop, input amplitudes (deg)."""

    key: str
    aircraft: str          # 'f16', '737', 'dhc6' or 'c172x'
    condition: str         # 'h=...,V=...'
    de_deg: float
    da_deg: float
    dr_deg: float
    pitch_rate_gain: float = 0.0   # > 0: the project's pitch-rate loop (the bare airframe diverges here)
    note: str = ""

    @property
    def model(self) -> str:
        return c172x_path() if self.aircraft == "c172x" else self.aircraft

    @property
    def loop(self) -> Loop:
        return Loop("closed", self.pitch_rate_gain) if self.pitch_rate_gain else Loop()


CONDITIONS = {c.key: c for c in (
    Condition("S", "f16", "h=10000,V=420", 2.0, 3.0, 3.0, note="the seed's: 10,000 ft, 420 ft/s, alpha 5.3 deg"),
    Condition("L", "f16", "h=5000,V=330", 2.0, 3.0, 3.0, note="5,000 ft, 330 ft/s, alpha 7.9 deg"),
    Condition("F", "f16", "h=10000,V=427.4", 1.5, 3.0, 3.0,
              note="10,000 ft, 427.4 ft/s, alpha 5.03 deg: at the leading-edge-flap switch (5.00 deg)"),
    Condition("M", "f16", "h=15000,V=550", 1.0, 3.0, 3.0, 0.3,
              note="15,000 ft, 550 ft/s, alpha 3.1 deg; pitch-rate loop K = 0.3 s (open loop it dives)"),
    Condition("H", "f16", "h=25000,V=700", 1.0, 2.0, 2.0, 0.3,
              note="25,000 ft, 700 ft/s, alpha 2.5 deg; pitch-rate loop K = 0.3 s (open loop it diverges)"),
    Condition("C1", "c172x", "h=4000,V=180", 2.0, 5.0, 5.0, note="c172x, 4,000 ft, 180 ft/s, alpha 0.8 deg"),
    Condition("C2", "c172x", "h=8000,V=200", 2.0, 5.0, 5.0, note="c172x, 8,000 ft, 200 ft/s, alpha 0.6 deg"),
    Condition("A", "f16", "h=20000,V=380", 2.0, 3.0, 3.0, note="20,000 ft, 380 ft/s, alpha 9.8 deg"),
    Condition("Q", "f16", "h=5000,V=650", 1.0, 2.0, 2.0, 0.3,
              note="5,000 ft, 650 ft/s, alpha 0.65 deg; pitch-rate loop K = 0.3 s"),
    Condition("U", "f16", "h=25000,V=500", 1.5, 3.0, 3.0, note="25,000 ft, 500 ft/s, alpha 6.4 deg"),
    Condition("C3", "c172x", "h=2000,V=150", 2.5, 5.0, 5.0, note="c172x, 2,000 ft, 150 ft/s, alpha 1.6 deg"),
    Condition("C4", "c172x", "h=10000,V=170", 2.0, 5.0, 5.0, note="c172x, 10,000 ft, 170 ft/s, alpha 1.6 deg"),
    Condition("B", "737", "h=30000,V=750", 1.0, 3.0, 3.0, note="737 cruise, 30,000 ft, 750 ft/s"),
    Condition("D", "dhc6", "h=6000,V=230", 2.0, 2.0, 2.0,
              note="DHC-6 Twin Otter (two turboprops), 6,000 ft, 230 ft/s: a lateral input leaves it in a "
                   "slow spiral, alpha and q drifting by degrees"),
)}

KINDS = ("pitch", "lateral", "three_axis")


INPUT_STYLES = ("multistep", "multisine", "sweep")


def maneuvers(kind: str, cond: Condition, style: str = "multistep") -> tuple[object, Sequence]:
    """Identification and (different) validation inputs of a kind at a condition.

    ``style`` is the identification input's: multi-steps (pitch 3-2-1-1; aileron doublet and
    rudder 2-1-1), an orthogonal multisine on the kind's surfaces at the same peak deflections
    (15 s, 0.1-1.5 Hz), or a linear frequency sweep (20 s, 0.1-2 Hz, half the peak deflection;
    the stabilator's, or for a lateral or three-axis kind the aileron's). The validation
    maneuver is always the multi-step one."""
    a_e, a_a, a_r = cond.de_deg, cond.da_deg, cond.dr_deg
    pitch_id = (multistep("3-2-1-1", "de", a_e, 0.5),)
    pitch_va = (multistep("2-1-1-2", "de", 0.75 * a_e, 0.7),)
    lat_id = (multistep("doublet", "da", a_a, 1.0), multistep("2-1-1", "dr", a_r, 1.0))
    lat_va = (multistep("doublet", "dr", a_r, 1.0), multistep("2-1-1", "da", a_a, 0.7))
    ident, valid = {"pitch": (pitch_id, pitch_va), "lateral": (lat_id, lat_va),
                    "three_axis": (pitch_id + lat_id, pitch_va + lat_va)}[kind]
    validation = Sequence(valid, gap_s=2.0, name=f"outside_{kind}_validation")
    if style == "multistep":
        return Sequence(ident, gap_s=2.0, name=f"outside_{kind}_identification"), validation
    surfaces = {"pitch": ("de",), "lateral": ("da", "dr"), "three_axis": ("de", "da", "dr")}[kind]
    peak = {"de": a_e, "da": a_a, "dr": a_r}
    if style == "multisine":
        return (Multisine(surfaces, period_s=15.0, f_min_hz=0.1, f_max_hz=1.5,
                          amplitude_deg=tuple(peak[x] for x in surfaces), name=f"outside_{kind}_multisine"),
                validation)
    if style == "sweep":
        surface = "de" if kind == "pitch" else "da"
        return FrequencySweep(surface, 0.1, 2.0, 20.0, 0.5 * peak[surface], name=f"outside_{kind}_sweep"), validation
    raise ValueError(f"input style {style!r} is not one of {INPUT_STYLES}")


@dataclass(frozen=True)
class Convention:
    """How a case's recording departs from the sweep's usual one (the defaults: none). The
    conventions a team's data may legally use that the project's own recordings never do."""

    inputs: str = "multistep"      # INPUT_STYLES: the identification input
    rate_hz: float = 50.0          # sample rate
    white_scale: float = 1.0       # white noise, times the white preset's levels
    gauss_markov_deg: float = 0.1  # the α and β vanes' Gauss-Markov wander
    gauss_markov_tau_s: float = 1.0  # and its time constant
    actuator_rps: float = 40.0     # the second-order actuators' natural frequency (ζ 0.7)
    duration_s: float = DURATION_S
    units: str = "canonical"       # or 'deg-kts': angles in deg, rates in deg/s, V in kts, h in m
    vanes_ft: float = 0.0          # both vanes this far ahead of the c.g., the position in the metadata
    accelerometer_ft: tuple[float, float, float] = (0.0, 0.0, 0.0)  # its position, in the metadata too

    def describe(self) -> str:
        """The departures from the usual recording, '' for none."""
        base = Convention()
        words = {"inputs": lambda v: v, "rate_hz": lambda v: f"{v:g} Hz", "white_scale": lambda v: f"noise x{v:g}",
                 "gauss_markov_deg": lambda v: f"vane wander {v:g} deg",
                 "gauss_markov_tau_s": lambda v: f"wander tau {v:g} s",
                 "actuator_rps": lambda v: f"actuator {v:g} rad/s",
                 "duration_s": lambda v: f"{v:g} s", "units": lambda v: v,
                 "vanes_ft": lambda v: f"vanes {v:g} ft ahead",
                 "accelerometer_ft": lambda v: "accelerometer " + " ".join(f"{a}{x:g}" for a, x in zip("xyz", v)) + " ft"}
        return ", ".join(words[k](getattr(self, k)) for k in words if getattr(self, k) != getattr(base, k))


@dataclass(frozen=True)
class OutsideCase:
    """One recording pair of the outside sweep and what the diagnosis must say of it."""

    name: str
    where: str                  # a CONDITIONS key
    kind: str                   # pitch, lateral, three_axis
    effects: tuple = ()
    expect: str = "none"
    parameter: str = ""
    truth: float = 0.0
    channel: str = ""           # the affected output (condition d)
    seed: int = 1
    turbulence: Turbulence | None = None
    mode: StructuralMode | None = None
    drop: tuple[str, ...] = ()  # quantities the team did not record (h, thrust)
    clean: bool = False         # the noise-free self-check
    self_check: bool = False
    convention: Convention = Convention()

    @property
    def condition(self) -> Condition:
        return CONDITIONS[self.where]


def _drops(i: int) -> tuple[str, ...]:
    """Every third case lacks the altitude channel, every third (shifted) the thrust."""
    return {0: (), 1: ("h",), 2: ("thrust",)}[i % 3]


def _size_label(truth: float) -> str:
    """A case name's size: as given, or in degrees when it is a small angle (0.5deg)."""
    return f"{truth:g}" if abs(truth) >= 0.01 or truth == 0 else f"{truth / DEG:g}deg"


def cases() -> tuple[OutsideCase, ...]:
    """167 cases: every effect id of effects.md over five F-16 conditions and two c172x
    conditions, the three maneuver kinds, nulls of each kind on each aircraft, self-checks;
    then the DHC-6, the conventions, light gusts, the 737, and five more conditions."""
    spec = [
        # where, kind, effect, expect, parameter, truth, channel
        # --- F-16, pitch-only
        ("S", "pitch", H("coefficient_error", -3.0, regressor="qhat"), "Cm_qhat", -3.0, "q"),
        ("L", "pitch", H("unsteady_alphadot", -3.0), "Cm_alphadot", -3.0, "q"),
        ("M", "pitch", H("coefficient_error", -0.1, regressor="alpha"), "Cm_alpha", -0.1, "q"),
        ("H", "pitch", H("coefficient_error", -0.5, coefficient="CZ", regressor="alpha"), "CZ_alpha", -0.5, "az"),
        ("F", "pitch", H("nonlinear_alpha", 1.0), "Cm_alpha2", 1.0, "q"),
        ("S", "pitch", H("control_delay", 0.08, surface="de"), "tau_de", 0.08, "q"),
        ("L", "pitch", H("cg_offset", 0.5), "dx_moment_reference", 0.5, "q"),
        ("F", "pitch", H("sensor_bias", 1.5 * DEG, channel="alpha"), "bias_alpha", 1.5 * DEG, "alpha"),
        ("M", "pitch", H("sensor_bias", 0.5 * DEG, channel="q"), "bias_q", 0.5 * DEG, "q"),
        ("H", "pitch", H("sensor_scale", 0.08, channel="alpha"), "scale_alpha", 0.08, "alpha"),
        ("S", "pitch", H("sensor_offset", 10.0, position_ft=(10.0, 0.0, 0.0)), "x_accelerometer", 10.0, "az"),
        ("L", "pitch", H("sensor_time_skew", 0.04, channel="q"), "skew_q", 0.04, "q"),
        ("F", "pitch", H("flight_condition_drift", 0.02), "Cm_dV", 0.02, "q"),
        ("H", "pitch", H("sensor_bias", 0.04, channel="az"), "bias_az", 0.04, "az"),
        # --- F-16, lateral-only
        ("S", "lateral", H("coefficient_error", -0.02, coefficient="Cl", regressor="beta"), "Cl_beta", -0.02, "p"),
        ("L", "lateral", H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r"),
        ("H", "lateral", H("coefficient_error", -0.3, coefficient="Cn", regressor="rhat"), "Cn_rhat", -0.3, "r"),
        ("L", "lateral", H("coefficient_error", -0.1, coefficient="Cl", regressor="phat"), "Cl_phat", -0.1, "p"),
        ("F", "lateral", H("control_delay", 0.06, surface="da"), "tau_da", 0.06, "p"),
        ("S", "lateral", H("control_delay", 0.08, surface="dr"), "tau_dr", 0.08, "r"),
        ("M", "lateral", H("cross_coupling", -0.2, coefficient="Cl", regressor="beta_abs"), "Cl_beta_abs", -0.2, "p"),
        ("L", "lateral", H("sensor_bias", 1.0 * DEG, channel="beta"), "bias_beta", 1.0 * DEG, "beta"),
        ("F", "lateral", H("sensor_bias", 0.5 * DEG, channel="r"), "bias_r", 0.5 * DEG, "r"),
        ("S", "lateral", H("sensor_scale", 0.15, channel="beta"), "scale_beta", 0.15, "beta"),
        ("M", "lateral", H("sensor_offset", 0.0, position_ft=(0.0, 6.0, 0.0)), "offset_y", 6.0, "az"),  # ṗ·y on a_z
        ("H", "lateral", H("sensor_time_skew", 0.04, channel="p"), "skew_p", 0.04, "p"),
        # --- F-16, three-axis
        ("S", "three_axis", H("cross_coupling", -2.0, coefficient="Cl"), "Cl_alpha_beta", -2.0, "p"),
        ("F", "three_axis", H("cross_coupling", 2.0, coefficient="Cn"), "Cn_alpha_beta", 2.0, "r"),
        ("L", "three_axis", H("coefficient_error", -6.0, regressor="qhat"), "Cm_qhat", -6.0, "q"),
        ("H", "three_axis", H("unsteady_alphadot", -3.0), "Cm_alphadot", -3.0, "q"),
        ("M", "three_axis", H("cg_offset", 1.0), "dx_moment_reference", 1.0, "q"),
        ("F", "three_axis", H("control_delay", 0.06, surface="de"), "tau_de", 0.06, "q"),
        ("S", "three_axis", H("sensor_bias", 0.75 * DEG, channel="alpha"), "bias_alpha", 0.75 * DEG, "alpha"),
        ("L", "three_axis", H("sensor_offset", 5.0, position_ft=(5.0, 0.0, 0.0)), "x_accelerometer", 5.0, "az"),
        ("H", "three_axis", H("sensor_time_skew", 0.04, channel="az"), "skew_az", 0.04, "az"),
        ("F", "three_axis", H("nonlinear_alpha", -5.0, coefficient="CZ"), "CZ_alpha2", -5.0, "az"),
        ("L", "three_axis", H("sensor_bias", 0.04, channel="az"), "bias_az", 0.04, "az"),
        ("M", "three_axis", H("sensor_scale", 0.06, channel="V"), "scale_V", 0.06, "V"),
        ("S", "three_axis", H("sensor_bias", 10.0, channel="V"), "bias_V", 10.0, "V"),
        ("M", "three_axis", H("flight_condition_drift", 0.02), "Cm_dV", 0.02, "q"),
        # --- c172x (the package's, by path)
        ("C1", "pitch", H("coefficient_error", -6.0, regressor="qhat"), "Cm_qhat", -6.0, "q"),
        ("C2", "pitch", H("unsteady_alphadot", -3.0), "Cm_alphadot", -3.0, "q"),
        ("C2", "pitch", H("control_delay", 0.08, surface="de"), "tau_de", 0.08, "q"),
        ("C1", "pitch", H("sensor_bias", 1.0 * DEG, channel="alpha"), "bias_alpha", 1.0 * DEG, "alpha"),
        ("C2", "pitch", H("nonlinear_alpha", 1.0), "Cm_alpha2", 1.0, "q"),
        ("C1", "lateral", H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r"),
        ("C2", "lateral", H("control_delay", 0.08, surface="dr"), "tau_dr", 0.08, "r"),
        ("C1", "lateral", H("sensor_bias", 1.0 * DEG, channel="beta"), "bias_beta", 1.0 * DEG, "beta"),
        ("C2", "lateral", H("control_delay", 0.06, surface="da"), "tau_da", 0.06, "p"),
        ("C2", "three_axis", H("cg_offset", 0.25), "dx_moment_reference", 0.25, "q"),
        ("C1", "three_axis", H("sensor_offset", 5.0, position_ft=(5.0, 0.0, 0.0)), "x_accelerometer", 5.0, "az"),
        ("C1", "three_axis", H("coefficient_error", -0.5, coefficient="CZ", regressor="alpha"), "CZ_alpha", -0.5,
         "az"),
        ("C2", "three_axis", H("cross_coupling", -2.0, coefficient="Cl"), "Cl_alpha_beta", -2.0, "p"),
        ("C1", "three_axis", H("sensor_scale", 0.1, channel="alpha"), "scale_alpha", 0.1, "alpha"),
        ("C2", "three_axis", H("sensor_time_skew", 0.04, channel="q"), "skew_q", 0.04, "q"),
        ("C1", "three_axis", H("flight_condition_drift", 0.02), "Cm_dV", 0.02, "q"),
    ]
    out: list[OutsideCase] = []
    for where, kind, e, param, truth, ch in spec:
        label = _size_label(truth)
        out.append(OutsideCase(f"{where}_{kind}_{e.effect}_{param}_{label}", where, kind, (e,), e.effect, param,
                               truth, ch))
    mode, small_mode = StructuralMode(8.0, 0.02, 0.5, 3.0), StructuralMode(7.0, 0.03, 0.3, 2.0)
    for where, kind, m in (("S", "pitch", mode), ("M", "three_axis", mode), ("C2", "pitch", small_mode)):
        out.append(OutsideCase(f"{where}_{kind}_structural_mode_{m.frequency_hz:g}Hz", where, kind, (),
                               "structural_mode", "mode_frequency_hz", m.frequency_hz, "", mode=m))
    for where, kind, sev in (("M", "pitch", 3), ("H", "lateral", 3), ("S", "three_axis", 4), ("C2", "three_axis", 3)):
        out.append(OutsideCase(f"{where}_{kind}_turbulence_sev{sev}", where, kind, (), "turbulence", "sigma_gust_fps",
                               float("nan"), "", turbulence=Turbulence("dryden", sev, 30.0)))
    nulls = [("S", "pitch", 1), ("H", "pitch", 2), ("F", "pitch", 3), ("L", "lateral", 4), ("M", "lateral", 5),
             ("S", "three_axis", 6), ("L", "three_axis", 7), ("M", "three_axis", 8), ("H", "three_axis", 9),
             ("F", "three_axis", 10), ("C1", "pitch", 11), ("C2", "lateral", 12), ("C1", "three_axis", 13),
             ("C2", "three_axis", 14)]
    for where, kind, seed in nulls:
        out.append(OutsideCase(f"{where}_{kind}_none_s{seed}", where, kind, seed=seed))
    out = [replace(c, drop=_drops(i)) for i, c in enumerate(out)]
    out += _twin_otter_cases()
    out += _convention_cases()
    out += _light_gust_cases()
    out += _airliner_cases()
    out += _more_condition_cases()
    for where in ("S", "B", "C1", "D"):
        out.append(OutsideCase(f"selfcheck_{CONDITIONS[where].aircraft}_{where}", where, "three_axis", clean=True,
                               self_check=True))
    return tuple(out)


def _twin_otter_cases() -> list[OutsideCase]:
    """The DHC-6 (a turboprop, its propeller torque trimmed): a third aircraft, whose lateral
    inputs leave a slow spiral (its own drops, so the F-16 and c172x cases stay as they were)."""
    spec = [
        ("pitch", H("coefficient_error", -6.0, regressor="qhat"), "Cm_qhat", -6.0, "q"),
        ("pitch", H("sensor_bias", 0.5 * DEG, channel="q"), "bias_q", 0.5 * DEG, "q"),
        ("pitch", H("control_delay", 0.08, surface="de"), "tau_de", 0.08, "q"),
        ("lateral", H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r"),
        ("lateral", H("control_delay", 0.06, surface="da"), "tau_da", 0.06, "p"),
        ("three_axis", H("cg_offset", 0.5), "dx_moment_reference", 0.5, "q"),
        ("three_axis", H("sensor_bias", 1.0 * DEG, channel="beta"), "bias_beta", 1.0 * DEG, "beta"),
    ]
    out = [OutsideCase(f"D_{kind}_{e.effect}_{param}_{_size_label(truth)}", "D", kind, (e,), e.effect, param, truth,
                       ch) for kind, e, param, truth, ch in spec]
    out += [OutsideCase(f"D_{kind}_none_s{seed}", "D", kind, seed=seed)
            for kind, seed in (("pitch", 15), ("lateral", 16), ("three_axis", 17))]
    return [replace(c, drop=_drops(i)) for i, c in enumerate(out)]


def _convention_cases() -> list[OutsideCase]:
    """Recordings in conventions the project's own never use (:class:`Convention`): multisine
    and sweep inputs, 25 and 100 Hz, twice the noise, a wider vane wander, slower actuators,
    15 and 60 s, other units, vanes on a nose boom (their position in the metadata). Mostly
    nulls (what goes wrong is the point), and a few effects (their own drops and seeds, so the
    other cases stay as they were)."""
    spec = [  # where, kind, convention, effect (None: a null), parameter, truth, channel
        ("S", "three_axis", Convention(inputs="multisine"), None),
        ("L", "pitch", Convention(inputs="sweep"), None),
        ("M", "pitch", Convention(duration_s=15.0), None),
        ("S", "pitch", Convention(rate_hz=100.0), None),
        ("S", "pitch", Convention(rate_hz=25.0), None),
        ("S", "three_axis", Convention(white_scale=2.0), None),
        ("S", "three_axis", Convention(actuator_rps=20.0), None),
        ("C1", "three_axis", Convention(inputs="multisine"), None),
        ("F", "pitch", Convention(duration_s=60.0), None),
        ("S", "lateral", Convention(units="deg-kts"), None),
        ("H", "three_axis", Convention(gauss_markov_deg=0.2), None),
        ("L", "lateral", Convention(inputs="sweep"), None),
        ("D", "three_axis", Convention(inputs="multisine"), None),
        ("S", "three_axis", Convention(inputs="multisine"),
         (H("coefficient_error", -3.0, regressor="qhat"), "Cm_qhat", -3.0, "q")),
        ("L", "lateral", Convention(inputs="sweep"),
         (H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r")),
        ("S", "pitch", Convention(rate_hz=100.0), (H("control_delay", 0.06, surface="de"), "tau_de", 0.06, "q")),
        ("F", "pitch", Convention(rate_hz=25.0), (H("nonlinear_alpha", 1.0), "Cm_alpha2", 1.0, "q")),
        ("H", "three_axis", Convention(white_scale=2.0),
         (H("sensor_bias", 0.5 * DEG, channel="q"), "bias_q", 0.5 * DEG, "q")),
        ("S", "three_axis", Convention(actuator_rps=20.0), (H("cg_offset", 1.0), "dx_moment_reference", 1.0, "q")),
        ("L", "pitch", Convention(units="deg-kts"), (H("unsteady_alphadot", -3.0), "Cm_alphadot", -3.0, "q")),
        ("S", "three_axis", Convention(vanes_ft=15.0), None),
        ("L", "pitch", Convention(vanes_ft=15.0), None),
        ("M", "lateral", Convention(vanes_ft=15.0), None),
        ("S", "pitch", Convention(vanes_ft=15.0),
         (H("coefficient_error", -3.0, regressor="qhat"), "Cm_qhat", -3.0, "q")),
        ("S", "three_axis", Convention(accelerometer_ft=(10.0, 2.0, 3.0)), None),
        ("L", "lateral", Convention(accelerometer_ft=(10.0, 2.0, 3.0)), None),
        ("C1", "three_axis", Convention(accelerometer_ft=(4.0, 1.0, 2.0)), None),
        ("M", "pitch", Convention(accelerometer_ft=(10.0, 2.0, 3.0)),
         (H("coefficient_error", -6.0, regressor="qhat"), "Cm_qhat", -6.0, "q")),
        # vanes wandering as far as a gust moves them: at 700 ft/s a 0.4 deg wander is the
        # 3 ft/s a turbulence finding needs, at 180 ft/s the angle light gusts make
        ("H", "pitch", Convention(gauss_markov_deg=0.4), None),
        ("C1", "three_axis", Convention(gauss_markov_deg=0.4), None),
        # the wander slower and faster than the usual 1 s: nearly a bias drifting over the
        # record, or nearly white
        ("S", "three_axis", Convention(gauss_markov_deg=0.2, gauss_markov_tau_s=5.0), None),
        ("M", "lateral", Convention(gauss_markov_deg=0.2, gauss_markov_tau_s=5.0), None),
        ("L", "pitch", Convention(gauss_markov_deg=0.15, gauss_markov_tau_s=10.0), None),
        ("C1", "pitch", Convention(gauss_markov_deg=0.2, gauss_markov_tau_s=0.3), None),
        ("S", "pitch", Convention(gauss_markov_deg=0.2, gauss_markov_tau_s=5.0),
         (H("coefficient_error", -3.0, regressor="qhat"), "Cm_qhat", -3.0, "q")),
        ("L", "lateral", Convention(gauss_markov_deg=0.2, gauss_markov_tau_s=5.0),
         (H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r")),
        # noisier instruments than the white preset's, on every kind of maneuver and aircraft
        ("M", "three_axis", Convention(white_scale=3.0), None),
        ("C1", "pitch", Convention(white_scale=2.0), None),
        ("H", "lateral", Convention(white_scale=2.0), None),
        ("D", "lateral", Convention(white_scale=2.0), None),
        ("L", "pitch", Convention(white_scale=3.0, gauss_markov_deg=0.2), None),
        ("H", "three_axis", Convention(white_scale=3.0), None),
        ("S", "pitch", Convention(white_scale=3.0),
         (H("coefficient_error", -3.0, regressor="qhat"), "Cm_qhat", -3.0, "q")),
    ]
    out = []
    for i, (where, kind, cv, effect) in enumerate(spec):
        tag = "_".join("".join(ch for ch in part if ch.isalnum() or ch in ".-") for part in cv.describe().split(", "))
        if effect is None:
            out.append(OutsideCase(f"{where}_{kind}_none_{tag}", where, kind, seed=40 + i, convention=cv))
            continue
        e, param, truth, ch = effect
        label = _size_label(truth)
        out.append(OutsideCase(f"{where}_{kind}_{e.effect}_{param}_{label}_{tag}", where, kind, (e,), e.effect,
                               param, truth, ch, seed=40 + i, convention=cv))
    return [replace(c, drop=_drops(i)) for i, c in enumerate(out)]


def _airliner_cases() -> list[OutsideCase]:
    """The 737 at its cruise (30,000 ft, 750 ft/s: the highest dynamic pressure per unit of
    input of the sweep), beside its self-check: a few effects and a null of each kind (their
    own drops and seeds, so the other cases stay as they were)."""
    spec = [("pitch", H("coefficient_error", -6.0, regressor="qhat"), "Cm_qhat", -6.0, "q"),
            ("lateral", H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r"),
            ("three_axis", H("control_delay", 0.08, surface="de"), "tau_de", 0.08, "q"),
            ("pitch", H("sensor_bias", 0.5 * DEG, channel="q"), "bias_q", 0.5 * DEG, "q")]
    out = []
    for i, (kind, e, param, truth, ch) in enumerate(spec):
        label = _size_label(truth)
        out.append(OutsideCase(f"B_{kind}_{e.effect}_{param}_{label}", "B", kind, (e,), e.effect, param, truth, ch,
                               seed=90 + i))
    out += [OutsideCase(f"B_{kind}_none_s{95 + i}", "B", kind, seed=95 + i)
            for i, kind in enumerate(("pitch", "lateral", "three_axis"))]
    return [replace(c, drop=_drops(i)) for i, c in enumerate(out)]


def _more_condition_cases() -> list[OutsideCase]:
    """Five more conditions (F-16 at 20,000 ft and 380 ft/s, alpha 9.8 deg; at 5,000 ft and
    650 ft/s; at 25,000 ft and 500 ft/s; the c172x at 2,000 and 10,000 ft): a null of each kind
    at each, and one effect at four of them (their own seeds and drops, so the other cases
    stay as they were)."""
    out = []
    for i, where in enumerate(("A", "Q", "U", "C3", "C4")):
        out += [OutsideCase(f"{where}_{kind}_none_s{501 + 3 * i + j}", where, kind, seed=501 + 3 * i + j)
                for j, kind in enumerate(KINDS)]
    spec = [("A", "pitch", H("coefficient_error", -6.0, regressor="qhat"), "Cm_qhat", -6.0, "q"),
            ("U", "lateral", H("coefficient_error", 0.03, coefficient="Cn", regressor="beta"), "Cn_beta", 0.03, "r"),
            ("C3", "pitch", H("control_delay", 0.08, surface="de"), "tau_de", 0.08, "q"),
            ("C4", "lateral", H("coefficient_error", -0.02, coefficient="Cl", regressor="beta"), "Cl_beta", -0.02,
             "p")]
    out += [OutsideCase(f"{where}_{kind}_{e.effect}_{param}_{_size_label(truth)}", where, kind, (e,), e.effect, param,
                        truth, ch, seed=600 + i) for i, (where, kind, e, param, truth, ch) in enumerate(spec)]
    return [replace(c, drop=_drops(c.seed)) for c in out]


def _light_gust_cases() -> list[OutsideCase]:
    """Turbulence too light to name (Dryden severity 1-2: σ 0.9-1.9 ft/s, under the 3 ft/s a
    turbulence finding needs), on the slow aircraft too, where the same gust is a larger
    angle: the diagnosis must not take the gusts for sensor errors; and a coefficient error
    flown through such gusts. Scored as turbulence cases (not naming it is a miss)."""
    spec = [("S", "three_axis", 1, None), ("L", "pitch", 2, None), ("C1", "three_axis", 2, None),
            ("H", "lateral", 1, None), ("M", "three_axis", 2, None), ("D", "pitch", 2, None),
            ("S", "pitch", 2, (H("coefficient_error", -3.0, regressor="qhat"), "Cm_qhat", -3.0, "q"))]
    out = []
    for i, (where, kind, sev, effect) in enumerate(spec):
        gusts = Turbulence("dryden", sev, 30.0)
        if effect is None:
            out.append(OutsideCase(f"{where}_{kind}_light_turbulence_sev{sev}", where, kind, (), "turbulence",
                                   "sigma_gust_fps", float("nan"), "", seed=70 + i, turbulence=gusts))
            continue
        e, param, truth, ch = effect
        out.append(OutsideCase(f"{where}_{kind}_{e.effect}_{param}_{truth:g}_light_turbulence_sev{sev}", where, kind,
                               (e,), e.effect, param, truth, ch, seed=70 + i, turbulence=gusts))
    return [replace(c, drop=_drops(i)) for i, c in enumerate(out)]


# ---------------------------------------------------------------------------------------------
# Making, diagnosing and scoring a case


def write_case(c: OutsideCase, out_dir: str | Path) -> dict[str, Path]:
    """Fly and post-process one case's identification and validation recordings; write them
    and ``<case>.answer.json`` into ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cond = c.condition
    label = {"f16": "F-16", "737": "Boeing 737", "c172x": "Cessna 172 (JSBSim c172x)",
             "dhc6": "DHC-6 Twin Otter"}.get(cond.aircraft, cond.aircraft)
    paths, answers = {}, {}
    cv = c.convention
    noise = flight_test_noise(cv.white_scale, cv.gauss_markov_deg, cv.gauss_markov_tau_s)
    for i, (role, inp) in enumerate(zip(("identification", "validation"), maneuvers(c.kind, cond, cv.inputs))):
        flown = inp if c.clean else Actuated(inp, omega_rps=cv.actuator_rps)
        spec = FlightSpec(input=flown, aircraft=Aircraft(cond.model, hidden=c.effects), condition=cond.condition,
                          duration_s=max(cv.duration_s, inp.duration_s), loop=cond.loop, sample_rate_hz=cv.rate_hz)
        if c.turbulence is not None:
            spec = replace(spec, turbulence=c.turbulence, turbulence_seed=100 * c.seed + i)
        flight = fly_maneuver(spec)
        if cv.vanes_ft:
            flight = vanes_ahead(flight, cv.vanes_ft)
        if any(cv.accelerometer_ft):
            flight = accelerometer_away(flight, cv.accelerometer_ft)
        rec, answer = postprocess(flight, noise=not c.clean, seed=1000 * c.seed + i, drop=c.drop,
                                  mode=c.mode, aircraft_label=label, noise_model=noise)
        if cv.vanes_ft:  # the team knows where its nose boom is
            rec = with_sensors(rec, alpha_vane_ft=[cv.vanes_ft, 0.0, 0.0], beta_vane_ft=[cv.vanes_ft, 0.0, 0.0])
        if any(cv.accelerometer_ft):  # and where its accelerometer is
            rec = with_sensors(rec, accelerometer_ft=list(cv.accelerometer_ft))
        paths[role] = write_recording(rec, out_dir / f"{c.name}-{role}.csv")
        if cv.units != "canonical":  # the writer writes canonical units only; the reader takes these
            rewrite_in_units(paths[role], OTHER_UNITS)
        answers[role] = answer["hidden_effects"]
    write_text_atomic(out_dir / f"{c.name}.answer.json", json.dumps(
        {"case": c.name, "aircraft": cond.aircraft, "condition": cond.condition, "loop": cond.loop.describe(),
         "kind": c.kind, "expect": c.expect, "parameter": c.parameter,
         "truth": c.truth if math.isfinite(c.truth) else None, "hidden_effects": answers["identification"],
         "turbulence": None if c.turbulence is None else c.turbulence.describe(),
         "structural_mode": None if c.mode is None else asdict(c.mode), "dropped": list(c.drop),
         "recording": "clean (self-check)" if c.clean else "flight-test-like",
         "convention": asdict(cv)}, indent=1))
    return paths


# The 'deg-kts' convention: every quantity that has one in recording-format.md's table in its
# other accepted unit (angles in deg, rates in deg/s, airspeed in kts, altitude in m).
OTHER_UNITS = {"rad": "deg", "rps": "dps", "V_fps": "kts", "h_ft": "m"}


def with_sensors(rec: Recording, **positions: list[float]) -> Recording:
    """``rec`` with sensor positions (ft from the c.g., body axes) written into its metadata's
    ``sensors`` block, as a team that knows them would."""
    sensors = {**(rec.meta.get("sensors") or {}), **positions}
    return Recording(data=rec.data, meta={**rec.meta, "sensors": sensors}, name=rec.name)


def vanes_ahead(rec: Recording, x_ft: float) -> Recording:
    """A flight's α and β as vanes ``x_ft`` ahead of the c.g. read them
    (:func:`models.hidden.vane_shift`)."""
    d = rec.data.copy()
    da, db = vane_shift(*(d[c].to_numpy(dtype=float) for c in ("p_rps", "q_rps", "r_rps", "V_fps")), (x_ft, 0.0, 0.0))
    d["alpha_rad"] = d["alpha_rad"].to_numpy(dtype=float) + da
    d["beta_rad"] = d["beta_rad"].to_numpy(dtype=float) + db
    return Recording(data=d, meta=rec.meta, name=rec.name)


def accelerometer_away(rec: Recording, position_ft: tuple[float, float, float]) -> Recording:
    """A flight's accelerometers as read at ``position_ft`` from the c.g.
    (:func:`models.hidden.offset_accelerometer`, with the flight's own angular accelerations)."""
    d = rec.data.copy()
    channels = {c: d[c].to_numpy(dtype=float) for c in d.columns}
    offset_accelerometer(channels, position_ft)
    for c in ("ax_g", "ay_g", "az_g"):
        d[c] = channels[c]
    return Recording(data=d, meta=rec.meta, name=rec.name)


def rewrite_in_units(path: Path, units: dict[str, str]) -> None:
    """Rewrite the CSV ``path`` with its canonical columns in other accepted units (``units``
    maps a canonical unit, or a whole column name, to the unit wanted), by the reader's own
    factors (:data:`maneuvers.channels.CHANNELS`), so reading it back gives the canonical
    values; the file is replaced whole (temporary file, then rename)."""
    data = pd.read_csv(path)
    cols = {}
    for name in data.columns:
        quantity, _, unit = name.partition("_")
        want = units.get(name) or units.get(unit)
        spec = CHANNELS.get(quantity)
        if want and spec is not None and want in spec.units:
            cols[f"{quantity}_{want}"] = data[name].to_numpy() / spec.units[want]
        else:
            cols[name] = data[name].to_numpy()
    write_text_atomic(path, pd.DataFrame(cols).to_csv(index=False))


# Names the diagnosis gives the same parameter: the accelerometer's x position from the
# force-mismatch fit (x_accelerometer) or from the kinematic check (offset_x).
ALIASES = {("sensor_offset", "offset_x"): ("sensor_offset", "x_accelerometer")}


def _key(f: dict) -> tuple[str, str]:
    key = (f.get("effect"), f.get("parameter"))
    return ALIASES.get(key, key)


def score(c: OutsideCase, result: dict) -> dict:
    """Criteria a-d and the false findings of one case from its findings.json content."""
    findings = result["findings"]
    first = findings[0]
    row = {"case": c.name, "aircraft": c.condition.aircraft, "where": c.where, "condition": c.condition.condition,
           "kind": c.kind, "expect": c.expect, "parameter": c.parameter,
           "truth": c.truth if math.isfinite(c.truth) else None, "dropped": list(c.drop), "self_check": c.self_check,
           "convention": c.convention.describe(),
           "first": {k: first.get(k) for k in ("effect", "parameter", "estimate", "std_error")},
           "findings": [{k: f.get(k) for k in ("effect", "parameter", "estimate", "std_error")} for f in findings]}
    if c.expect == "none":
        false = [f for f in findings if f["effect"] != "none"]
        row.update(a=first["effect"] == "none", b=None, d=None)
    else:
        # a ``none`` on an effect is a miss (criterion a), not a false finding
        false = [f for f in findings if f["effect"] != "none" and _key(f) != (c.expect, c.parameter)]
        row["a"] = _key(first) == (c.expect, c.parameter)
        row["b"] = size_right(first, c.expect, c.truth, row["a"])
        row["d"], rms = validation_drop(first, c.channel, row["a"])
        if rms is not None:
            row["validation_rms"] = rms
    # the calibration step's column: the affected output's validation RMS after the
    # equation-error and after the calibrated sizes, and which the diagnosis kept
    row["calibration"] = validation_rms_pair(result.get("calibration") or {}, c.channel)
    row["false"] = [f"{f['effect']}:{f['parameter']}" for f in false]
    row["c"] = len(false)
    return row


def run_case(c: OutsideCase, out: Path) -> dict:
    """Make, diagnose and score one case; its row goes to ``out/results/<case>.json``. A case
    whose recording or diagnosis fails is scored as failing every criterion, with the error."""
    from harness.diagnosis.run import diagnose
    try:
        paths = write_case(c, out / "recordings")
        # the sweep's own processes are the parallelism: the calibration flies in-process
        result = diagnose(c.condition.model, paths["identification"], out / "diagnoses" / c.name,
                          paths["validation"], calibrate_workers=1)
        row = score(c, result) | {"timing_s": result["timing_s"]["total"], "error": None}
    except Exception as exc:  # noqa: BLE001 - a measurement: the row says what broke
        row = {"case": c.name, "aircraft": c.condition.aircraft, "where": c.where, "condition": c.condition.condition,
               "kind": c.kind, "expect": c.expect, "parameter": c.parameter,
               "truth": c.truth if math.isfinite(c.truth) else None, "dropped": list(c.drop),
               "convention": c.convention.describe(), "self_check": c.self_check, "first": None, "findings": [],
               "a": False,
               "b": False if c.expect != "none" and math.isfinite(c.truth) else None, "c": 0, "false": [],
               "d": False if c.channel else None, "timing_s": None,
               "error": f"{type(exc).__name__}: {exc}".splitlines()[0][:300],
               "traceback": traceback.format_exc()[-2000:]}
    write_text_atomic(out / "results" / f"{c.name}.json", json.dumps(row, indent=1))
    return row


# ---------------------------------------------------------------------------------------------
# Summary


def _share(rows: list[dict], k: str) -> str:
    scored = [r for r in rows if r[k] is not None]
    return f"{sum(bool(r[k]) for r in scored)}/{len(scored)}" if scored else "–"


def totals(rows: list[dict]) -> dict:
    """a, b, d as passed/scored; c as the number of false findings and of cases with any."""
    return {"cases": len(rows), "a": _share(rows, "a"), "b": _share(rows, "b"), "d": _share(rows, "d"),
            "false_findings": sum(r["c"] for r in rows), "cases_with_false": sum(r["c"] > 0 for r in rows),
            "errors": sum(bool(r.get("error")) for r in rows)}


def groups(rows: list[dict]) -> dict[str, dict[str, dict]]:
    by = {"aircraft": lambda r: r["aircraft"], "condition": lambda r: f"{r['aircraft']} {r['condition']}",
          "kind": lambda r: r["kind"], "truth": lambda r: "null" if r["expect"] == "none" else "effect",
          "recording": lambda r: "other conventions" if r.get("convention") else "usual"}
    out = {}
    for name, key in by.items():
        keys = list(dict.fromkeys(key(r) for r in rows))
        out[name] = {k: totals([r for r in rows if key(r) == k]) for k in keys}
    return out


def _finding(f: dict | None) -> str:
    if f is None:
        return "error"
    if f["effect"] == "none":
        return "none"
    return f"{f['effect']}: {f['parameter']} = {f['estimate']:.4g} ± {f['std_error']:.2g}"


def markdown(rows: list[dict]) -> str:
    """The per-case table (a, b, c = false findings, d), the totals and the breakdowns."""
    mark = {True: "✔", False: "✘", None: "–"}
    lines = ["| case | aircraft, condition | truth | first finding | a | b | c (false) | d | validation RMS |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        v = r.get("validation_rms")
        drop = f"{v[0]:.3g} → {v[1]:.3g} ({100 * (v[1] / v[0] - 1):+.0f} %)" if v else "–"
        truth = "–" if r["truth"] is None else f"{r['truth']:.4g}"
        first = f"error: {r['error']}" if r.get("error") else _finding(r["first"])
        false = str(r["c"]) + (f" ({', '.join(r['false'])})" if r["false"] else "")
        where = (f"{r['aircraft']} {r['condition']}" + (f", no {'/'.join(r['dropped'])}" if r["dropped"] else "")
                 + (f", {r['convention']}" if r.get("convention") else ""))
        lines.append(f"| {r['case']} | {where} | {truth} | {first} | {mark[r['a']]} | {mark[r['b']]} | {false} | "
                     f"{mark[r['d']]} | {drop} |")
    t = totals(rows)
    lines += ["", f"**Totals** ({t['cases']} cases): a {t['a']}, b {t['b']}, d {t['d']}; **false findings "
                  f"{t['false_findings']}** in {t['cases_with_false']} cases (target 0); errors {t['errors']}.", ""]
    lines += ["| group | cases | a | b | false findings (cases) | d |", "|---|---|---|---|---|---|"]
    for name, gs in groups(rows).items():
        for k, g in gs.items():
            lines.append(f"| {name}: {k} | {g['cases']} | {g['a']} | {g['b']} | {g['false_findings']} "
                         f"({g['cases_with_false']}) | {g['d']} |")
    by_effect: dict[str, int] = {}
    for r in rows:
        for f in r["false"]:
            by_effect[f.split(":")[0]] = by_effect.get(f.split(":")[0], 0) + 1
    if by_effect:
        lines += ["", "False findings by effect named: " + ", ".join(
            f"{k} {v}" for k, v in sorted(by_effect.items(), key=lambda kv: -kv[1])) + "."]
    return "\n".join(lines) + "\n"


def provenance() -> dict:
    """The commit the sweep ran on and the files changed since (diagnosis work in progress shows)."""
    import subprocess
    root = Path(__file__).resolve().parents[2]

    def git(*args: str) -> str:
        try:
            return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=10).stdout
        except (OSError, subprocess.SubprocessError):
            return ""
    return {"commit": git("rev-parse", "HEAD").strip(),
            "modified": [line[3:] for line in git("status", "--porcelain", "--untracked-files=no").splitlines()]}


def sweep(out: str | Path, names: list[str] | None = None, workers: int = 2) -> list[dict]:
    """Run the outside sweep (the cases ``names``, default all) into ``out``; finished cases
    are read back, not run again."""
    out = Path(out)
    chosen, rows = run_resumable(cases(), names, out, workers, run_case, "outside-sweep")
    write_text_atomic(out / "sweep.json", json.dumps(
        {"cases": [asdict(c) | {"effects": [e.describe() for e in c.effects]} for c in chosen],
         "conditions": {k: asdict(v) for k, v in CONDITIONS.items()}, "provenance": provenance(), "rows": rows,
         "totals": totals(rows),
         "groups": groups(rows)}, indent=1, default=str))
    write_text_atomic(out / "sweep.md", markdown(rows))
    return rows
