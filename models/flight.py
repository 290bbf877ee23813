"""Open- and closed-loop flight of a trimmed aircraft, sampled on exact sample times."""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import jsbsim
import numpy as np

from models.aircraft import Aircraft
from models.atmosphere import Turbulence, start_turbulence
from models.axes import wind_axis_coefficients
from models.constants import G0_FPS2
from models.hidden import apply_sensor_effects, delay_deltas, delay_property, frames_of
from models.trim import TrimPoint

Deflections = Callable[[np.ndarray], Mapping[str, np.ndarray]]


class FlightError(RuntimeError):
    """The simulation diverged or produced invalid numbers; the message says when and what."""


@dataclass(frozen=True)
class Loop:
    """How the stabilator is driven.

    ``kind='open'``: surfaces are the trim values plus the input (FCS disabled).
    ``kind='closed'``: the project's own pitch-rate feedback, δs = δs,trim + δs,cmd + K·q
    (seed §III.G), with K = ``pitch_rate_gain`` in rad of stabilator per rad/s of pitch rate.
    Positive K damps the short period (the F-16's Cm_δe is negative and δe is positive
    trailing edge down). The feedback uses the pitch rate of the previous frame, as a digital
    flight control computer would.
    """

    kind: str = "open"
    pitch_rate_gain: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("open", "closed"):
            raise ValueError(f"loop kind must be 'open' or 'closed', not {self.kind!r}")
        if self.kind == "open" and self.pitch_rate_gain != 0.0:
            raise ValueError("an open loop has no feedback gain; use Loop('closed', K)")
        if not math.isfinite(self.pitch_rate_gain):
            raise ValueError("the pitch-rate gain must be finite")

    def describe(self) -> str:
        return "open loop" if self.kind == "open" else f"closed loop, de = de_cmd + {self.pitch_rate_gain:g}*q"


# Recorded channel -> (JSBSim property, scale). Rates are body rates relative to the Earth,
# which in still air are the rates the aerodynamics see (they differ from inertial rates by
# Earth's rotation, at most 7.3e-5 rad/s). Accelerometer channels are computed separately.
_STATE_CHANNELS: tuple[tuple[str, str], ...] = (
    ("V_fps", "velocities/vt-fps"),
    ("alpha_rad", "aero/alpha-rad"),
    ("beta_rad", "aero/beta-rad"),
    ("p_rps", "velocities/p-rad_sec"),
    ("q_rps", "velocities/q-rad_sec"),
    ("r_rps", "velocities/r-rad_sec"),
    ("phi_rad", "attitude/phi-rad"),
    ("theta_rad", "attitude/theta-rad"),
    ("psi_rad", "attitude/psi-rad"),
    ("qbar_psf", "aero/qbar-psf"),
    ("h_ft", "position/h-sl-ft"),
    ("mach_1", "velocities/mach"),
    ("thrust_lbf", "forces/fbx-prop-lbs"),
    ("pdot_rps2", "accelerations/pdot-rad_sec2"),
    ("qdot_rps2", "accelerations/qdot-rad_sec2"),
    ("rdot_rps2", "accelerations/rdot-rad_sec2"),
    ("throttle_1", "fcs/throttle-pos-norm"),
)
_FORCES = ("forces/fbx-total-lbs", "forces/fby-total-lbs", "forces/fbz-total-lbs")
_AERO = ("forces/fbx-aero-lbs", "forces/fby-aero-lbs", "forces/fbz-aero-lbs",
         "moments/l-aero-lbsft", "moments/m-aero-lbsft", "moments/n-aero-lbsft")


@dataclass(frozen=True)
class FlightHistory:
    """Sampled time histories of one flight.

    ``channels`` uses the recording format's canonical column names; ``truth`` holds
    JSBSim's own aerodynamic coefficients about the c.g. (non-dimensional, aero only) per
    sample: CX, CY, CZ, Cl, Cm, Cn and the wind-axis CL, CD of the seed's Eq. 2, plus the
    angle-of-attack rate JSBSim used.
    """

    channels: dict[str, np.ndarray]
    truth: dict[str, np.ndarray]
    sample_rate_hz: float
    sim_rate_hz: float
    frames: int
    loop: Loop = field(default_factory=Loop)


def frames_per_sample(sample_rate_hz: float, sim_rate_hz: float) -> int:
    """Whole simulation frames per recorded sample: the smallest count that runs at least
    ``sim_rate_hz``. 120 Hz asked with 50 Hz recording gives 3 (the simulation runs at
    150 Hz), so every sample is a simulation frame rather than an interpolation."""
    if sample_rate_hz <= 0 or sim_rate_hz <= 0:
        raise ValueError("sample and simulation rates must be positive")
    return max(1, math.ceil(sim_rate_hz / sample_rate_hz - 1e-9))


def fly(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, trim_point: TrimPoint,
        deflections: Deflections, duration_s: float, *, sample_rate_hz: float = 50.0,
        sim_rate_hz: float = 120.0, loop: Loop = Loop(),
        alpha_limit_rad: float = math.radians(40.0), turbulence: Turbulence | None = None,
        turbulence_seed: int = 0, wind_ned_fps: Mapping[str, np.ndarray] | None = None) -> FlightHistory:
    """Fly a trimmed instance with the surfaces driven directly and record it.

    Parameters
    ----------
    fdm : jsbsim.FGFDMExec
        Trimmed by :func:`models.trim.trim`. Its FCS is disabled here, so the surfaces hold
        what is written each frame (and the F-16's leading-edge flap stays at its trim value).
    deflections : callable
        ``t -> {'de': rad, 'da': rad, 'dr': rad}``, perturbations from trim evaluated on the
        frame times (zero-order hold between frames).
    duration_s : float
        Length of the recording; samples at ``k / sample_rate_hz`` for ``k = 0 .. N-1`` with
        ``N = round(duration_s * sample_rate_hz) + 1``.
    turbulence, turbulence_seed : Turbulence or None, int
        Process noise flown from the first frame on (the trim is calm).
    wind_ned_fps : mapping or None
        A given wind history (``north``, ``east``, ``down``, ft/s, on the recorded sample
        times ``k / sample_rate_hz``; linearly interpolated onto the frames and written to
        ``atmosphere/wind-*-fps`` before each frame): a recorded flight's reconstructed gusts.

    Raises
    ------
    FlightError
        When the states become non-finite or leave the flight envelope (|alpha| or |beta|
        beyond ``alpha_limit_rad``, airspeed below half its trim value): the message names
        the time, the channel and the value.
    """
    n_sub = frames_per_sample(sample_rate_hz, sim_rate_hz)
    frames = _Frames(n_sub, 1.0 / (n_sub * sample_rate_hz), int(round(duration_s * sample_rate_hz)) + 1,
                     sample_rate_hz)
    fdm.set_dt(frames.dt)
    fdm["simulation/models/FGFCS/enabled"] = 0
    if turbulence is not None:
        start_turbulence(fdm, turbulence, turbulence_seed)
    delays = [e for e in aircraft.hidden if e.effect == "control_delay"]
    if delays and loop.kind == "closed":
        raise ValueError("a hidden control delay is flown open loop only")
    commands = {s: np.asarray(v, dtype=float) for s, v in deflections(frames.times).items()}
    trim_pos = {"de": trim_point.de_rad, "da": trim_point.da_rad, "dr": trim_point.dr_rad}
    unknown = set(commands) - set(trim_pos)
    if unknown:
        raise ValueError(f"unknown surfaces {sorted(unknown)}; the aircraft has de, da, dr")
    gain = loop.pitch_rate_gain if loop.kind == "closed" else 0.0
    props = aircraft.surfaces
    node = fdm.get_property_manager().get_node  # property nodes: no path parsed per access
    changes = _frame_writes(node, props, frames, trim_pos, commands, gain, wind_ned_fps, delays)
    de_cmd = (trim_pos["de"] + commands.get("de", np.zeros(frames.n_frames + 1))).tolist()
    read_props = ([p for _, p in _STATE_CHANNELS] + [props["de"], props["da"], props["dr"]]
                  + list(_FORCES) + list(_AERO) + ["aero/alphadot-rad_sec"])
    out = _run_frames(fdm, node, frames, changes, read_props, node(props["de"]).set_double_value,
                      de_cmd, gain, _envelope_check(trim_point, loop, alpha_limit_rad, sample_rate_hz))
    return _history(out, fdm, aircraft, trim_point, frames, loop)


@dataclass(frozen=True)
class _Frames:
    """The simulation frames of a flight: ``n_sub`` frames of ``dt`` per sample, ``n_samples``."""

    n_sub: int
    dt: float
    n_samples: int
    sample_rate_hz: float

    @property
    def n_frames(self) -> int:
        return (self.n_samples - 1) * self.n_sub

    @property
    def times(self) -> np.ndarray:
        return np.arange(self.n_frames + 1) * self.dt


_Writes = dict[int, list[tuple[Callable[[float], None], float]]]


def _frame_writes(node, props: Mapping[str, str], frames: _Frames, trim_pos: dict[str, float],
                  commands: dict[str, np.ndarray], gain: float, wind_ned_fps: Mapping[str, np.ndarray] | None,
                  delays: list) -> _Writes:
    """Every property write of the flight before its frame, ``{frame: [(setter, value), ...]}``,
    only where a value changes (the first values are written now): the surfaces (the stabilator
    is written every frame with the feedback when the loop is closed), a given wind, and the
    delayed surfaces a hidden control delay feeds the aerodynamics."""
    n_frames = frames.n_frames
    changes: _Writes = {}

    def write(setter: Callable[[float], None], values: np.ndarray, every_frame: bool = False) -> None:
        setter(float(values[0]))
        where = range(1, n_frames + 1) if every_frame else (np.flatnonzero(np.diff(values)) + 1).tolist()
        for f in where:
            changes.setdefault(f, []).append((setter, float(values[f])))

    for s, cmd in commands.items():
        if not (gain and s == "de"):
            write(node(props[s]).set_double_value, trim_pos[s] + cmd)
    if wind_ned_fps:
        t_samples = np.arange(frames.n_samples) / frames.sample_rate_hz
        for axis, series in wind_ned_fps.items():
            values = np.interp(frames.times, t_samples[:len(series)],
                               np.asarray(series, dtype=float)[:frames.n_samples])
            write(node(f"atmosphere/wind-{axis}-fps").set_double_value, values, every_frame=True)
    for e in delays:
        # the aerodynamics see the surface late: drive its delay property with δ(t − τ) − δ(t)
        values = trim_pos[e.surface] + commands.get(e.surface, np.zeros(n_frames + 1))
        write(node(delay_property(e.surface)).set_double_value, delay_deltas(values, frames_of(e.size, frames.dt)))
    return changes


def _envelope_check(trim_point: TrimPoint, loop: Loop, alpha_limit_rad: float,
                    sample_rate_hz: float) -> Callable[[list[float], int], None]:
    """``check(row, k)``: a FlightError when sample ``k`` (V, α, β first) leaves the envelope."""
    def check(row: list[float], k: int) -> None:
        a, b, v = row[1], row[2], row[0]
        # NaN fails every comparison, so "not (x < limit)" also catches it.
        if not (abs(a) < alpha_limit_rad and abs(b) < alpha_limit_rad and v > 0.5 * trim_point.V_fps):
            raise FlightError(
                f"simulation diverged at t = {k / sample_rate_hz:.2f} s ({loop.describe()}): alpha = "
                f"{math.degrees(a):.1f} deg, beta = {math.degrees(b):.1f} deg, V = {v:.0f} ft/s (limits: |alpha|, "
                f"|beta| < {math.degrees(alpha_limit_rad):.0f} deg, V > {0.5 * trim_point.V_fps:.0f} ft/s); "
                "the aircraft is unstable for this loop or the input is too large")
    return check


def _run_frames(fdm: jsbsim.FGFDMExec, node, frames: _Frames, changes: _Writes, read_props: list[str],
                set_de: Callable[[float], None], de_cmd: list[float], gain: float,
                check: Callable[[list[float], int], None]) -> np.ndarray:
    """Step the frames, writing what changes before each and the stabilator with the pitch-rate
    feedback when ``gain``; read ``read_props`` on every sample time. Samples x properties."""
    getters = [node(p).get_double_value for p in read_props]
    rows: list[list[float]] = []

    def sample() -> None:
        row = [g() for g in getters]
        rows.append(row)
        check(row, len(rows) - 1)

    sample()
    run = fdm.run
    get_q = node("velocities/q-rad_sec").get_double_value
    f = 0
    for _ in range(frames.n_samples - 1):
        for _ in range(frames.n_sub):
            f += 1
            if f in changes:
                for setter, v in changes[f]:
                    setter(v)
            if gain:
                set_de(de_cmd[f] + gain * get_q())
            run()
        sample()
    out = np.asarray(rows, dtype=float)
    bad = ~np.isfinite(out)
    if bad.any():
        k, col = np.argwhere(bad)[0]
        raise FlightError(f"simulation produced a non-finite {read_props[col]} at t = {k / frames.sample_rate_hz:.2f} s")
    return out


def _history(out: np.ndarray, fdm: jsbsim.FGFDMExec, aircraft: Aircraft, trim_point: TrimPoint, frames: _Frames,
             loop: Loop) -> FlightHistory:
    """The sampled properties as channels (states, surfaces, accelerations in g, the sensor
    effects of hidden physics applied) and the truth coefficients (Eqs. 1-5 and Eq. 2)."""
    sample_rate_hz = frames.sample_rate_hz
    state_cols = [c for c, _ in _STATE_CHANNELS]
    surf_cols = ["de_rad", "da_rad", "dr_rad"]
    mass = fdm["inertia/mass-slugs"]
    channels = {"t_s": np.arange(frames.n_samples) / sample_rate_hz}
    for i, col in enumerate(state_cols):
        channels[col] = out[:, i]
    # JSBSim's heading lies in [0, 2*pi): a yaw through north would jump by 2*pi. Recorded
    # continuous, as a heading gyro's integrated output is.
    channels["psi_rad"] = np.unwrap(channels["psi_rad"])
    j = len(state_cols)
    for i, col in enumerate(surf_cols):
        channels[col] = out[:, j + i]
    for i, col in enumerate(("ax_g", "ay_g", "az_g")):
        channels[col] = out[:, j + 3 + i] / (mass * G0_FPS2)
    apply_sensor_effects(channels, tuple(aircraft.hidden), 1.0 / sample_rate_hz)
    qS = channels["qbar_psf"] * trim_point.S_ft2
    X, Y, Z, L, M, N = (out[:, j + 6 + i] for i in range(6))
    alpha = channels["alpha_rad"]
    CX, CZ = X / qS, Z / qS
    truth = {
        "CX": CX, "CY": Y / qS, "CZ": CZ,
        "Cl": L / (qS * trim_point.b_ft), "Cm": M / (qS * trim_point.cbar_ft), "Cn": N / (qS * trim_point.b_ft),
        **wind_axis_coefficients(CX, CZ, alpha),  # seed Eq. 2: CD, CL
        "alphadot": out[:, j + 12],
    }
    return FlightHistory(channels=channels, truth=truth, sample_rate_hz=sample_rate_hz,
                         sim_rate_hz=frames.n_sub * sample_rate_hz, frames=frames.n_frames, loop=loop)
