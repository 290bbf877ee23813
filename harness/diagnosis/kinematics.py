"""Sensor effects by kinematic consistency (data compatibility) in equation-error form.

The rigid-body kinematics tie the recorded channels together whatever the aerodynamics:

    u̇ = rv − qw − g sinθ + g a_x            φ̇ = p + tanθ (q sinφ + r cosφ)
    v̇ = pw − ru + g cosθ sinφ + g a_y       θ̇ = q cosφ − r sinφ
    ẇ = qu − pv + g cosθ cosφ + g a_z       ḣ = u sinθ − v sinφ cosθ − w cosφ cosθ
                                            ψ̇ = (q sinφ + r cosφ) / cosθ

with u, v, w from V, α, β. Each equation's residual E (left minus right, both through the
recording's common filter) is zero for perfect sensors. A sensor effect with parameter θ —
a bias, a scale factor, a time skew, an accelerometer or vane away from the c.g. — makes
E ≈ −J θ, J the change of E when the recorded channel is corrected by θ (central
differences). The candidates are then selected by colored t statistics on the stacked,
noise-weighted residuals (:func:`estimators.colored_stepwise.colored_forward_selection`).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy.signal import detrend

from estimators.colored_stepwise import ColoredSelection, colored_fit, colored_forward_selection
from harness.diagnosis.prepare import DRIVEN_BY, Prepared, clean_channels, interior_slice
from models.constants import G0_FPS2 as G0
from models.hidden import vane_shift

EARTH_RADIUS_FT = 20_925_646.3
BIAS_CHANNELS = ("alpha", "beta", "V", "p", "q", "r", "phi", "theta", "ax", "ay", "az")
SCALE_CHANNELS = ("alpha", "beta", "V", "p", "q", "r", "ax", "ay", "az")
SKEW_CHANNELS = ("alpha", "beta", "V", "p", "q", "r", "phi", "theta", "ax", "ay", "az")
# Smallest size worth naming: three times the ``realistic`` preset's own biases (which the
# null recordings carry), 2 % scale, 1.2 samples of skew, 1.5 ft of offset. The skew's floor:
# the noise-free self-checks of the F-16, 737 and c172x show 0.17 sample (the replay's own
# timing); independent scripts' JSBSim recordings up to 0.6 sample at t >= 6 (the rates'
# rectangular-Euler half step, a simulation step as long as the sample interval: 5 ms at
# 100 Hz), so 1.2 samples is twice the largest seen. Two samples left a true 40 ms skew at
# 50 Hz estimated 39.4 ms unnamed; 1.5 (to the twenty-fifth session) a 40 ms q skew at 40 Hz
# estimated 36 ms, on a 737 and on an F-16 flown through its controls.
DEG = np.pi / 180
PRACTICAL = {"bias": {"alpha": 0.3 * DEG, "beta": 0.15 * DEG, "V": 3.0, "p": 0.15 * DEG, "q": 0.15 * DEG,
                      "r": 0.15 * DEG, "phi": 1.0 * DEG, "theta": 1.0 * DEG, "ax": 0.015, "ay": 0.015, "az": 0.015},
             "scale": 0.02, "skew_samples": 1.2, "offset_ft": 1.5}
# Biases every real instrument has at some level (and the ``realistic`` preset's recordings
# carry): always in the kinematic fit, so they never leak into correlated parameters (a
# V scale factor, a skew); named only when significant and of practical size.
NUISANCE_BIASES = ("alpha", "beta", "p", "q", "r", "ax", "ay", "az")
# A scale factor whose column is this correlated with its channel's bias column cannot be
# told from that bias (a channel that hardly moves about its mean): not a candidate.
MAX_SCALE_BIAS_CORRELATION = 0.99
# A scale factor or time skew needs the channel to move: its own optimal smoothing must vary
# by this many times the channel's noise level, or the column is mostly (coloured) noise and
# the estimate an errors-in-variables artefact (a_x in a short maneuver: 0.7 times). A state
# the maneuver did not drive (prepare.DRIVEN_BY: r on a pitch maneuver) needs it to move this
# many times the smallest bias worth naming too (PRACTICAL) before its skew is a candidate: on
# a noise-free record such a state stands far above its noise, and a probe's F-4N (650 ft/s,
# pitch sweep) had an r skew of −27 ms named (t −6.1) beside its right stabilator delay, r
# moving only by the airframe's faint coupling (probe seed 4016). A driven state is exempt: a
# light aircraft's α moves a degree or two and its vane's lag is still read right.
MIN_EXCITATION = 3.0
UNITS = {"alpha": "rad", "beta": "rad", "V": "ft/s", "p": "rad/s", "q": "rad/s", "r": "rad/s", "phi": "rad",
         "theta": "rad", "ax": "g", "ay": "g", "az": "g"}


@dataclass(frozen=True)
class SensorParameter:
    """One candidate sensor parameter: its correction of the raw channels and FD step."""

    name: str           # bias_alpha, scale_q, skew_az, offset_x, vane_alpha_x ...
    effect: str         # effects.md id
    channel: str
    units: str
    step: float
    correct: Callable[[dict, Prepared, float], dict]


def _with(ch: dict, name: str, x: np.ndarray) -> dict:
    out = dict(ch)
    out[name] = x
    return out


# Corrections are partials of module-level functions, so a SensorParameter (and an analysis
# holding one) can be sent to another process.
def _bias_corrected(c: str, ch: dict, p: Prepared, th: float) -> dict:
    return _with(ch, c, ch[c] - th)


def _scale_corrected(c: str, ch: dict, p: Prepared, th: float) -> dict:
    return _with(ch, c, ch[c] / (1.0 + th))


def _skew_corrected(c: str, ch: dict, p: Prepared, th: float) -> dict:
    # the channel lags by τ: x_true(t) = x_meas(t + τ) ≈ x_meas + τ ẋ
    return _with(ch, c, ch[c] + th * p.differentiate(ch[c]))


def _accel_offset_corrected(axis: int, ch: dict, p: Prepared, th: float) -> dict:
    r = np.zeros(3)
    r[axis] = th
    w = np.stack([ch["p"], ch["q"], ch["r"]], axis=-1)
    wd = np.stack([p.differentiate(ch["p"]), p.differentiate(ch["q"]), p.differentiate(ch["r"])], axis=-1)
    extra = (np.cross(wd, r) + np.cross(w, np.cross(w, r))) / G0
    out = dict(ch)
    for i, c in enumerate(("ax", "ay", "az")):
        out[c] = ch[c] - extra[:, i]
    return out


def _vane_corrected(c: str, ch: dict, p: Prepared, th: float) -> dict:
    # a vane th ft ahead of the c.g. (models.hidden.vane_shift: α_v = α − x q/V, β_v = β + x r/V)
    shift = vane_shift(ch["p"], ch["q"], ch["r"], ch["V"], (th, 0.0, 0.0))[0 if c == "alpha" else 1]
    return _with(ch, c, ch[c] - shift)


def _bias(c: str) -> Callable:
    return partial(_bias_corrected, c)


def _scale(c: str) -> Callable:
    return partial(_scale_corrected, c)


def _skew(c: str) -> Callable:
    return partial(_skew_corrected, c)


def _accel_offset(axis: int) -> Callable:
    return partial(_accel_offset_corrected, axis)


def _vane(c: str) -> Callable:
    return partial(_vane_corrected, c)


def sensor_parameters(p: Prepared) -> tuple[SensorParameter, ...]:
    """Every candidate sensor parameter for the channels this recording has."""
    have = set(p.raw)
    out = [SensorParameter(f"bias_{c}", "sensor_bias", c, UNITS[c], 1e-4 if c != "V" else 0.1, _bias(c))
           for c in BIAS_CHANNELS if c in have]
    out += [SensorParameter(f"scale_{c}", "sensor_scale", c, "1", 1e-3, _scale(c)) for c in SCALE_CHANNELS if c in have]
    out += [SensorParameter(f"skew_{c}", "sensor_time_skew", c, "s", p.dt / 4, _skew(c))
            for c in SKEW_CHANNELS if c in have]
    out += [SensorParameter(f"offset_{a}", "sensor_offset", "accelerometer", "ft", 0.1, _accel_offset(i))
            for i, a in enumerate("xyz")]
    out += [SensorParameter(f"vane_{c}_x", "sensor_offset", c, "ft", 0.1, _vane(c)) for c in ("alpha", "beta")]
    return tuple(out)


# The rates one of which every rotational term of an accelerometer arm along each body axis
# carries (ω̇ × r + ω × (ω × r)): an arm along y reads ṙ·y in a_x, −(p² + r²)·y in a_y and
# ṗ·y + q·r·y in a_z. Where the maneuver drove neither (p.driven), the arm is not offered: a
# probe's noise-free c172p on a pitch multisine (a 44 ms q skew named) had a 5.6 ft lateral
# arm named at t 9 off the propeller's slight yaw (ṙ·y in a_x, 22 % of a_x's small
# excursion; seed 4697).
ARM_RATES = {"offset_x": ("q", "r"), "offset_y": ("p", "r"), "offset_z": ("p", "q")}


def _integral(x: np.ndarray, dt: float) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (x[1:] + x[:-1]) * dt)])


def _integrated(rate: np.ndarray, measured: np.ndarray, dt: float, drifts: tuple[np.ndarray, ...] = ()) -> np.ndarray:
    """``rate`` integrated (trapezoid) and placed on ``measured`` by least squares on a
    constant, a linear trend (an accelerometer bias integrates to a ramp) and ``drifts``
    (what a gyro bias integrates to: a q bias in ẇ = qu − pv + ... gives −b ∫u dt); what is
    left of ``measured`` is its slow noise, which the integral does not have."""
    x = _integral(rate, dt)
    t = np.arange(x.size) * dt
    A = np.column_stack([np.ones_like(t), t, *drifts])
    c, *_ = np.linalg.lstsq(A, measured - x, rcond=None)
    return x + A @ c


# What the inertial angles are integrated from (:func:`inertial_angles`).
INERTIAL_CHANNELS = ("V", "alpha", "beta", "p", "q", "r", "phi", "theta", "ay", "az")


def inertial_alpha_change(p: Prepared) -> np.ndarray | None:
    """The inertial α (:func:`inertial_angles`, from each channel's own smoothing) less the
    vane's α at the start, free of the vane's noise; None without the channels it is
    integrated from."""
    if not all(k in p.smooth for k in INERTIAL_CHANNELS):
        return None
    return inertial_angles(clean_channels(p, INERTIAL_CHANNELS), p)["alpha"] - p.start["alpha"]


def inertial_angles(ch: dict[str, np.ndarray], p: Prepared) -> dict[str, np.ndarray]:
    """α and β reconstructed from the inertial instruments: the body w and v equations of the
    module docstring integrated from the accelerometers, gyros and attitude, and placed on
    the vanes' own w and v by a constant, a trend and what the gyro biases integrate to
    (:func:`_integrated`; without the gyro terms a p bias times w, which changes with airspeed
    and α, left a drift that read as C_l and C_n ΔV/V terms at 330 ft/s).

    The vanes' slow noise (a Gauss-Markov wander survives any smoother: it is in the
    maneuver's band) is in the kinematic residual through d(V sin α)/dt; sensitivity columns
    built from the same vane reading share it, and that errors-in-variables correlation
    biases the estimates (an α scale factor of +0.15 ± 0.04 on a 550 ft/s flight that has
    none, with 0.1 deg of wander at τ = 1 s). Built from these angles, the columns carry
    accelerometer noise instead, which the residual's vane term does not."""
    V, a, b = ch["V"], ch["alpha"], ch["beta"]
    u, v, w = V * np.cos(a) * np.cos(b), V * np.sin(b), V * np.sin(a) * np.cos(b)
    P, Q, R, phi, th = ch["p"], ch["q"], ch["r"], ch["phi"], ch["theta"]
    g = G0 * np.cos(th)
    w_dot = Q * u - P * v + g * np.cos(phi) + G0 * ch["az"]
    v_dot = P * w - R * u + g * np.sin(phi) + G0 * ch["ay"]
    iu, iv, iw = (_integral(x, p.dt) for x in (u, v, w))
    w_i = _integrated(w_dot, w, p.dt, (iu, iv))   # q and p biases
    v_i = _integrated(v_dot, v, p.dt, (iw, iu))   # p and r biases
    beta = np.arcsin(np.clip(v_i / V, -1.0, 1.0))
    return {"alpha": np.arctan2(w_i, u), "beta": beta}


def kinematic_alpha_rate(ch: dict[str, np.ndarray]) -> np.ndarray:
    """α̇ from the u and w equations of the module docstring, α = atan(w/u):

        α̇ = (u ẇ − w u̇) / (u² + w²)
           = q − tanβ (p cosα + r sinα)
             + g / (V cosβ) · (a_z cosα − a_x sinα + cosθ cosφ cosα + sinθ sinα)

    (inertial: in gusts the air-relative α̇ differs by the gust's own rate). Built from the
    gyros and accelerometers, it carries their noise instead of the vane's: differentiating
    the α record amplifies the vane noise within the common filter's band: against noise-free
    copies of the outside sweep's pitch maneuvers its error is 20-67 % of α̇'s RMS (109 % on a
    half-amplitude frequency sweep at 500 ft/s: more noise than signal), this one's 5-21 %. A term fitted on the noisy
    derivative is attenuated (errors in variables), and a model evaluated along it passes
    the noise on through its own α̇ derivatives."""
    V, a, b = ch["V"], ch["alpha"], ch["beta"]
    P, Q, R, phi, th = ch["p"], ch["q"], ch["r"], ch["phi"], ch["theta"]
    gravity = np.cos(th) * np.cos(phi) * np.cos(a) + np.sin(th) * np.sin(a)
    return (Q - np.tan(b) * (P * np.cos(a) + R * np.sin(a))
            + G0 / (V * np.cos(b)) * (ch["az"] * np.cos(a) - ch["ax"] * np.sin(a) + gravity))


def kinematic_residuals(ch: dict[str, np.ndarray], p: Prepared) -> dict[str, np.ndarray]:
    """E per kinematic equation (module docstring) from raw-rate channels ``ch``."""
    return {e: p.differentiate(d) - p.filt(f) for e, (d, f) in _kinematic_parts(ch, p).items()}


def _kinematic_parts(ch: dict[str, np.ndarray], p: Prepared) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per kinematic equation, the record differentiated and the one filtered: its residual
    (:func:`kinematic_residuals`) is the first's common-filter derivative less the second's
    common filtering."""
    V, a, b = ch["V"], ch["alpha"], ch["beta"]
    u, v, w = V * np.cos(a) * np.cos(b), V * np.sin(b), V * np.sin(a) * np.cos(b)
    P, Q, R, phi, th = ch["p"], ch["q"], ch["r"], ch["phi"], ch["theta"]
    h = ch.get("h")
    # gravity at the recorded altitude, else at its stand-in (prepare: the ISA altitude of the
    # density): at sea level's, the outside sweep's F-16 at 25,000 ft without h read its
    # 0.04 g a_z bias as 0.04376 (now 0.04139): gravity there is 0.24 % less
    at = h if h is not None else getattr(p, "altitude", None)
    g = G0 * (EARTH_RADIUS_FT / (EARTH_RADIUS_FT + (at if at is not None else 0.0))) ** 2
    out = {
        "u": (u, R * v - Q * w - g * np.sin(th) + G0 * ch["ax"]),
        "v": (v, P * w - R * u + g * np.cos(th) * np.sin(phi) + G0 * ch["ay"]),
        "w": (w, Q * u - P * v + g * np.cos(th) * np.cos(phi) + G0 * ch["az"]),
        "phi": (phi, P + np.tan(th) * (Q * np.sin(phi) + R * np.cos(phi))),
        "theta": (th, Q * np.cos(phi) - R * np.sin(phi)),
    }
    if h is not None:
        out["h"] = (h, u * np.sin(th) - v * np.sin(phi) * np.cos(th) - w * np.cos(phi) * np.cos(th))
    if "psi" in ch:
        # the heading sees the yaw gyro directly: without it an r bias (−R·u in the v
        # equation) is one column with an a_y bias
        out["psi"] = (np.unwrap(ch["psi"]), (Q * np.sin(phi) + R * np.cos(phi)) / np.cos(th))
    return out


def _residual_change(plus: tuple[np.ndarray, np.ndarray], minus: tuple[np.ndarray, np.ndarray],
                     p: Prepared) -> np.ndarray:
    """One equation's residual at ``plus`` less that at ``minus`` (:func:`_kinematic_parts`),
    as the filtered and differentiated change of its parts: the common filter and its
    derivative are linear, so this is half the transforms, and none for a part unchanged."""
    d, f = plus[0] - minus[0], plus[1] - minus[1]
    out = p.differentiate(d) if d.any() else np.zeros(d.size)
    return out - p.filt(f) if f.any() else out


@dataclass(frozen=True)
class KinematicResult:
    selection: ColoredSelection
    parameters: dict[str, SensorParameter]
    forced: tuple[str, ...]           # the nuisance biases, always in the fit
    dropped: dict[str, str]           # candidates left out, and why
    equations: tuple[str, ...]
    weights: dict[str, float]
    residual_rms: dict[str, float]   # per equation, before (weighted units removed)
    start: np.ndarray                # stacked weighted residual before corrections
    columns: dict | None = None      # every offered parameter's stacked weighted column (forced too)
    untestable: dict | None = None   # the columns of scales and skews left out because their channel hardly moves


T_IN = 6.0


def kinematic_check(p: Prepared, *, t_in: float = T_IN, min_gain: float = 0.02, max_terms: int = 8,
                    exclude: frozenset[str] = frozenset()) -> KinematicResult:
    """Select the sensor parameters the kinematics call for (module docstring).

    The entry t is 6 rather than the aerodynamic 5: the kinematic residuals carry the
    differentiated airspeed and angle noise, strongly coloured, and on null recordings the
    airspeed scale and bias reach |t| ≈ 4.6.

    The sensitivity columns J are evaluated on each channel's own optimal smoothing, not on
    the raw channels: built from the raw ones they carry the same noise as the residual, and
    that errors-in-variables correlation biases the estimates (with white noise alone, a V
    scale factor of +0.23 ± 0.07 on a flight that has none). The biases of
    ``NUISANCE_BIASES`` are always in the fit."""
    ch = dict(p.raw)
    clean = clean_channels(p)
    # The first and last second are where the sine-series filter is least accurate.
    inner = interior_slice(p.n, p.dt)
    e0 = kinematic_residuals(ch, p)
    eqs = tuple(e0)
    weights = {e: 1.0 / max(float(np.std(e0[e][inner] - np.mean(e0[e][inner]))), 1e-12) for e in eqs}
    stack = np.concatenate([e0[e][inner] * weights[e] for e in eqs])
    params = {sp.name: sp for sp in sensor_parameters(p)}
    columns = {}
    at = clean | inertial_angles(clean, p)
    for name, sp in params.items():
        plus = _kinematic_parts(sp.correct(at, p, sp.step), p)
        minus = _kinematic_parts(sp.correct(at, p, -sp.step), p)
        # E(0) ≈ −J θ: regress E(0) on −J
        columns[name] = np.concatenate([-_residual_change(plus[e], minus[e], p)[inner] / (2 * sp.step) * weights[e]
                                        for e in eqs])
    dropped, untestable = {}, {}
    for c in set(SCALE_CHANNELS) | set(SKEW_CHANNELS):
        moves = float(np.std(clean[c][inner])) if c in clean else 0.0
        if c in p.noise_std and moves < MIN_EXCITATION * p.noise_std[c]:
            for kind in ("scale", "skew"):
                if (column := columns.pop(f"{kind}_{c}", None)) is not None:
                    untestable[f"{kind}_{c}"] = column
                    dropped[f"{kind}_{c}"] = (f"{c} hardly moves ({moves / max(p.noise_std[c], 1e-300):.1f} times its "
                                              f"noise level): a {kind} cannot be told from noise")
        elif (c in DRIVEN_BY and c not in p.driven and moves < MIN_EXCITATION * PRACTICAL["bias"][c]
              and columns.pop(f"skew_{c}", None) is not None):
            dropped[f"skew_{c}"] = (f"{c} hardly moves and the maneuver did not drive it ({moves:.3g} {UNITS[c]}, "
                                    f"under {MIN_EXCITATION:g} times the smallest {c} bias worth naming): a skew of it "
                                    "would be no practical error")
    for name, rates in ARM_RATES.items():
        if name in columns and p.driven and not any(r in p.driven for r in rates):
            columns.pop(name)
            dropped[name] = (f"the maneuver drove neither {' nor '.join(rates)}: every rotational term of an arm along "
                             f"{name[-1]} carries one of them, so its column is their noise and slight coupled motion")
    for c in SCALE_CHANNELS:
        s, b = columns.get(f"scale_{c}"), columns.get(f"bias_{c}")
        if s is not None and b is not None and np.ptp(s) > 0 and np.ptp(b) > 0:
            corr = abs(float(np.corrcoef(s, b)[0, 1]))
            if corr > MAX_SCALE_BIAS_CORRELATION:
                dropped[f"scale_{c}"] = f"indistinguishable from bias_{c} (correlation {corr:.3f}): {c} hardly moves"
                columns.pop(f"scale_{c}")
    for name in exclude:  # parameters an earlier pass found implausible (see analysis)
        if columns.pop(name, None) is not None:
            dropped[name] = "implausible size in an earlier fit: refitted without it"
    offered = dict(columns)
    forced = {f"bias_{c}": columns.pop(f"bias_{c}") for c in NUISANCE_BIASES if f"bias_{c}" in columns}
    sel = colored_forward_selection(stack, columns, forced=forced, t_in=t_in, min_gain=min_gain, max_terms=max_terms,
                                    constant=False)
    return KinematicResult(selection=sel, parameters=params, forced=tuple(forced), dropped=dropped,
                           equations=eqs, weights=weights,
                           residual_rms={e: float(np.sqrt(np.mean(e0[e][inner] ** 2))) for e in eqs}, start=stack,
                           columns=offered, untestable=untestable)


# The largest error an instrument of each kind plausibly has (a vane 5 deg off, a gyro 5 deg/s,
# an accelerometer 0.2 g, an airspeed 5 % of its value, a scale factor (per channel below), a skew 0.5 s, a
# sensor 30 ft from the c.g.): a kinematic fit that asks for more is not seeing a sensor
# error but some other inconsistency (unmodelled vane noise, a missing channel), and its
# estimate is neither named nor used to correct the channels.
PLAUSIBLE = {"bias": {"alpha": 5.0 * DEG, "beta": 5.0 * DEG, "V": 0.05, "p": 5.0 * DEG, "q": 5.0 * DEG,
                      "r": 5.0 * DEG, "phi": 5.0 * DEG, "theta": 5.0 * DEG, "ax": 0.2, "ay": 0.2, "az": 0.2},
             "scale": {"alpha": 0.3, "beta": 0.3, "V": 0.1}, "skew_s": 0.5, "offset_ft": 30.0}
# (vanes: upwash scale errors of tens of percent are real; a pitot-static airspeed 10 %;
# rates and accelerations: the default below)
PLAUSIBLE_SCALE_DEFAULT = 0.1
# An airspeed error an instrument could make is within PLAUSIBLE's share of V or within this,
# whichever is larger (ft/s, 10 kt): a light aircraft's pitot-static position error at low
# speed alone reaches several knots (the Cessna 172S Pilot's Operating Handbook's airspeed
# calibration, Section 5: 50 KIAS is 56 KCAS, flaps up). A probe's J-3 Cub at 103 ft/s with V
# 11.9 ft/s high (11.5 %) had C_l,p̂ named −0.054 (t −45) in the error's place (probe seed
# 3859); another at 103 ft/s with V 8.8 ft/s high (8.6 %, over 5 % of V) had the bias left out
# of the kinematic fit as implausible and C_m,δe named in its place (probe seed 3998).
AIRSPEED_ERROR_FLOOR_FPS = 16.9


def is_plausible(name: str, value: float, V_fps: float) -> bool:
    """Whether a sensor parameter's size could be an instrument error (:data:`PLAUSIBLE`;
    an airspeed bias is judged against the airspeed ``V_fps``)."""
    kind, _, channel = name.partition("_")
    if kind == "bias":
        limit = PLAUSIBLE["bias"].get(channel, np.inf)
        return abs(value) <= (max(limit * V_fps, AIRSPEED_ERROR_FLOOR_FPS) if channel == "V" else limit)
    if kind == "scale":
        return abs(value) <= PLAUSIBLE["scale"].get(channel, PLAUSIBLE_SCALE_DEFAULT)
    if kind == "skew":
        return abs(value) <= PLAUSIBLE["skew_s"]
    return abs(value) <= PLAUSIBLE["offset_ft"]


def channel_share(sp: SensorParameter, value: float, clean: dict[str, np.ndarray], p: Prepared,
                  inner: slice) -> float:
    """A sensor parameter's practical size: the RMS change its correction makes to the
    channels it acts on (a bias counts whole), over the RMS excursion of the channel about its
    mean; the largest over the channels changed (an accelerometer offset: a_x, a_y, a_z)."""
    corrected = sp.correct(clean, p, value)
    shares = []
    for c, x in corrected.items():
        if c not in clean or x is clean[c]:
            continue
        change = (x - clean[c])[inner]
        excursion = float(np.std(clean[c][inner]))
        rms = float(np.sqrt(np.mean(change ** 2)))
        if rms > 0:
            shares.append(rms / excursion if excursion > 0 else np.inf)
    return max(shares, default=0.0)


def practical_floor(name: str, dt: float) -> float:
    """The smallest size of sensor parameter ``name`` worth naming (:data:`PRACTICAL`), in
    its own units, at sample interval ``dt``."""
    kind, _, channel = name.partition("_")
    if kind == "bias":
        return PRACTICAL["bias"].get(channel, 0.0)
    if kind == "scale":
        return PRACTICAL["scale"]
    if kind == "skew":
        return PRACTICAL["skew_samples"] * dt
    return PRACTICAL["offset_ft"]


def is_practical(name: str, value: float, dt: float) -> bool:
    """Whether a sensor parameter is large enough to name (:func:`practical_floor`)."""
    return abs(value) >= practical_floor(name, dt)


def corrected_channels(raw: dict[str, np.ndarray], p: Prepared, params: dict[str, SensorParameter],
                       values: dict[str, float]) -> dict[str, np.ndarray]:
    """Raw channels with the estimated sensor parameters undone."""
    ch = dict(raw)
    for name, v in values.items():
        ch = params[name].correct(ch, p, v)
    return ch


# A recording's time column and its gyros must agree: the recorded attitudes' change over the
# change the gyros give them is one whatever the instruments' biases and skews. Beyond this
# ratio's distance from one the time column is wrong (a sample rate written wrong on export:
# 60 Hz data stamped at 50 Hz read 0.835), and every derivative the diagnosis takes with it.
# Real data stay inside: the Tu-144's (SIDPAC) bank and pitch angles against its gyros read
# 0.89; the sweeps' recordings, where well determined, 0.93-1.07.
TIME_BASE_TOLERANCE = 0.15
# ... and the ratio must stand this many standard errors from one.
TIME_BASE_Z = 5.0


def time_base_ratio(p: Prepared) -> tuple[float, float] | None:
    """The recorded attitudes' change over the change the gyros give them, integrated over
    the time column (the φ and θ equations of the module docstring; not the heading, which a
    recording may give as magnetic or as the track: the Twin Otter's disagrees with its
    gyros by a ratio of −1.1 and −0.3 where its bank angle agrees to 1.06 and 1.00): the
    least-squares ratio k in angle = k·∫rate dt + a + b·t (each angle and its integral less a
    line, :func:`scipy.signal.detrend`: a constant and a trend take up its start and a gyro
    bias) and its colored-residual standard error (seed Eq. 40: the residual of an integral is
    far from white); None without the attitudes, or where they hardly moved. Integrated, the
    gyros' noise is a small random walk beside the angles' excursion, where differentiated
    angles against the rates would read the noise as a ratio under one. An angle that moves
    less than :data:`MIN_EXCITATION` times its noise level about its line is left out: both
    sides are then noise and the ratio an errors-in-variables artefact (a record in which
    nothing moved read 0.08 ± 0.15, "the sample times look 13 times what they were")."""
    ch = p.raw
    if not all(c in ch for c in ("phi", "theta", "p", "q", "r")):
        return None
    P, Q, R, phi, th = ch["p"], ch["q"], ch["r"], ch["phi"], ch["theta"]
    pairs = [(angle, rate) for name, angle, rate in
             (("phi", phi, P + np.tan(th) * (Q * np.sin(phi) + R * np.cos(phi))),
              ("theta", th, Q * np.cos(phi) - R * np.sin(phi)))
             if float(np.std(detrend(angle))) >= MIN_EXCITATION * p.noise_std.get(name, 0.0)]
    if not pairs:
        return None
    y = np.concatenate([detrend(angle) for angle, _ in pairs])
    x = np.concatenate([detrend(_integral(rate, p.dt)) for _, rate in pairs])
    if float(x @ x) <= 0.0:
        return None
    theta, se, _ = colored_fit(y, [x], ["k"], constant=False)
    return float(theta[0]), float(se[0])


def time_base_problem(p: Prepared) -> str:
    """Why the recording's time column cannot be right ('' when it can): the attitudes change
    at a ratio to what the gyros give (:func:`time_base_ratio`) further from one than
    :data:`TIME_BASE_TOLERANCE` and :data:`TIME_BASE_Z` standard errors."""
    found = time_base_ratio(p)
    if found is None:
        return ""
    k, se = found
    if abs(k - 1.0) <= TIME_BASE_TOLERANCE or abs(k - 1.0) <= TIME_BASE_Z * se:
        return ""
    return (f"its attitudes change {k:.3f} ± {se:.3f} times as fast as its gyros say (over the time column "
            f"t_s, sampled at {1.0 / p.dt:.4g} Hz): the sample times look {1.0 / k:.3f} times what they were; "
            f"a scale error common to the gyros is not plausible beyond {100 * TIME_BASE_TOLERANCE:.0f} %. "
            "Check the time column and the sample rate")
