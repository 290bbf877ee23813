"""The outside sweep's recording pipeline: a flight post-processed as a flight-test team's
instruments would record it (actuators flown, gyros measuring inertial rates, white plus
Gauss-Markov air-data noise, values rounded to 8 significant digits, the metadata a team
writes), and the legal conventions the sweep writes besides the canonical one (other units,
sensor positions). See :mod:`harness.diagnosis.outside`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal

from harness.atomic import write_text_atomic
from harness.diagnosis.gallery import StructuralMode, conceal
from harness.noise import ChannelNoise, NoiseModel, apply_noise
from harness.noise_presets import WHITE_LEVELS
from maneuvers.channels import CHANNELS
from maneuvers.recording import Recording
from models.hidden import offset_accelerometer, vane_shift


DEG = math.pi / 180.0
EARTH_RATE_RPS = 7.292115e-5  # WGS-84, as JSBSim
SIGNIFICANT_DIGITS = 8


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
