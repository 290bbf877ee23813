"""A recording made ready for the diagnosis: one common zero-phase filter for every channel,
the noise level of each channel, the kinematic derivatives and the measured coefficients."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from estimators.coefficients import accelerometer_at_cg, force_coefficients, moment_coefficients
from estimators.differentiation import local_polynomial_derivative
from estimators.smoothing import optimal_fourier_smoother, sine_series_derivative, sine_series_filter
from harness.isa import density_altitude_ft
from maneuvers.format_rules import MASS_KEYS
from maneuvers.recording import Recording
from models.constants import BODY_COEFFICIENTS, SURFACES
from models.errors import UserError
from models.hidden import vane_shift
from models.replay import START_WINDOW_S

OUTPUTS = ("alpha", "beta", "p", "q", "r", "phi", "theta", "V", "ax", "ay", "az")
UNITS = {"alpha": "rad", "beta": "rad", "p": "rps", "q": "rps", "r": "rps", "phi": "rad", "theta": "rad",
         "psi": "rad", "V": "fps", "ax": "g", "ay": "g", "az": "g", "h": "ft", "de": "rad", "da": "rad",
         "dr": "rad", "qbar": "psf", "thrust": "lbf"}
# Channels whose bandwidth sets the common filter (when excited): the states.
BANDWIDTH_CHANNELS = ("alpha", "beta", "p", "q", "r")
COEFFICIENTS = BODY_COEFFICIENTS  # the diagnosis works on the six body-axis coefficients
# The states each group of surfaces drives: a state is maneuver-driven only when a surface of
# its group moved (a symmetric airframe's pitch maneuver leaves β, p and r at their noise).
DRIVEN_BY = {"alpha": ("de",), "q": ("de",), "theta": ("de",), "V": ("de",),
             "beta": ("da", "dr"), "p": ("da", "dr"), "r": ("da", "dr"), "phi": ("da", "dr")}
# A driven state's filtered signal must stand this many times above the white noise the
# common filter lets through (sigma * sqrt(mean(w^2)), Parseval on the sine series).
DRIVEN_SNR = 5.0
# The first and last second of a record are where the sine-series smoother is least
# accurate: it removes the line through the raw (noisy) end samples and returns to them. The
# analysis works on the interior (:func:`interior_slice`), and motion is measured there.
EDGE_S = 1.0
# A state whose filtered signal stands this far above that noise moved, whatever moved it (a
# lateral departure swings α by degrees with the stabilator still): drifted_states.
SELF_EVIDENT_SNR = 25.0
# And it must move by at least this much (std about its trend, canonical units): a noise-free
# pitch maneuver's lateral states wiggle by 1e-5 rad, far above a noise floor of zero.
DRIVEN_FLOOR = {"alpha": 0.05 * np.pi / 180, "beta": 0.05 * np.pi / 180, "p": 0.1 * np.pi / 180,
                "q": 0.1 * np.pi / 180, "r": 0.1 * np.pi / 180, "phi": 0.1 * np.pi / 180,
                "theta": 0.1 * np.pi / 180, "V": 0.5, "de": 0.02 * np.pi / 180, "da": 0.02 * np.pi / 180,
                "dr": 0.02 * np.pi / 180}


@dataclass(frozen=True)
class Prepared:
    """One recording, filtered and differentiated by one linear operator.

    Attributes
    ----------
    t, dt : sample times (from 0) and step.
    raw : the recorded channels by quantity (``alpha``, ``q`` ...), canonical units.
    smooth, deriv : the common-filter estimate of each channel and its time derivative.
    noise_std, cutoff_hz : each channel's own optimal-smoother noise level and cut-off.
    weights, common_cutoff_hz : the common filter (sine-series weights) and its cut-off.
    excited : the channels whose signal stands clear of their noise.
    driven : the states the maneuver drove (:func:`maneuver_driven`) and the surfaces that
        moved: the only ones a candidate term may be built on, and the only states the model
        is evaluated along besides ``moved`` (the others are held at their start values: their
        noise, passed through the model's derivatives, would look like a wrong derivative).
    moved : the states the maneuver did not drive that drifted far from their start all the
        same (:func:`drifted_states`): the model is evaluated along them, no term is built on
        them.
    measured : coefficients (Eqs. 1-5) from the filtered channels.
    start : the recording's initial values (means over the first 0.5 s of ``smooth``).
    meta : the recording's metadata.
    mass : mass and inertia per sample (``Recording.mass_at``: metadata constants or channels).
    own_noise : each channel minus its own optimal smoothing (what the smoother calls noise).
    """

    name: str
    t: np.ndarray
    dt: float
    raw: dict[str, np.ndarray]
    smooth: dict[str, np.ndarray]
    deriv: dict[str, np.ndarray]
    noise_std: dict[str, float]
    cutoff_hz: dict[str, float]
    weights: np.ndarray
    common_cutoff_hz: float
    excited: tuple[str, ...]
    measured: dict[str, np.ndarray]
    start: dict[str, float]
    meta: dict = field(default_factory=dict)
    own_noise: dict[str, np.ndarray] = field(default_factory=dict)  # raw − each channel's own optimal smoothing
    mass: dict[str, np.ndarray] = field(default_factory=dict)
    driven: tuple[str, ...] = ()
    moved: tuple[str, ...] = ()
    assumptions: tuple[dict, ...] = ()  # what stood in for missing channels or metadata
    altitude: np.ndarray | None = None  # ft: the h channel (own smoothing), or its stand-in
    recording: Recording | None = None  # the recording itself (for model fits that need its channels)

    @property
    def n(self) -> int:
        return self.t.size

    def filt(self, x: np.ndarray) -> np.ndarray:
        """Apply the common filter to another record."""
        return sine_series_filter(x, self.weights)

    def differentiate(self, x: np.ndarray) -> np.ndarray:
        """The common filter's derivative of another record."""
        return sine_series_derivative(x, self.weights, self.dt)


def clean_channels(p: Prepared, names=None) -> dict[str, np.ndarray]:
    """Each raw channel (of ``names``, default all) less its own noise: its own optimal
    smoothing, not the common filter's."""
    return {c: p.raw[c] - p.own_noise[c] if c in p.own_noise else p.raw[c] for c in (names or p.raw)}


# The metadata keys of the vanes' positions (recording-format.md: "Other sensor positions
# (alpha_vane_ft, ...) may be added the same way"), ft from the c.g. in body axes.
VANE_KEYS = {"alpha": "alpha_vane_ft", "beta": "beta_vane_ft"}


def vanes_at_cg(rec: Recording) -> Recording:
    """``rec`` with α and β read at the vane positions its metadata give carried to the c.g.
    (unchanged when none is given or it was done already).

    A vane away from the c.g. reads the shift :func:`models.hidden.vane_shift` gives (to first
    order in the rates, from ω × r); the recorded rates and airspeed undo it. The positions
    move to ``meta['vanes_at_cg']``, and ``sensors`` holds them at zero, so a second call does
    nothing. Measured on F-16 recordings with both vanes 15 ft ahead, the
    positions declared: taken at the c.g., the diagnosis named a vane 20 ± 3 ft ahead on a
    pitch maneuver and an accelerometer 17 ft aft on a three-axis one; carried, nothing."""
    sensors = dict(rec.meta.get("sensors") or {})
    given = {c: [float(v) for v in sensors[k]] for c, k in VANE_KEYS.items()
             if k in sensors and any(float(v) != 0.0 for v in sensors[k])}
    if not given:
        return rec
    d = rec.data.copy()
    rates = [d[c].to_numpy(dtype=float) for c in ("p_rps", "q_rps", "r_rps", "V_fps")]
    for c, pos in given.items():
        col = f"{c}_rad"
        d[col] = d[col].to_numpy(dtype=float) - vane_shift(*rates, pos)[0 if c == "alpha" else 1]
    meta = dict(rec.meta)
    meta["vanes_at_cg"] = {VANE_KEYS[c]: pos for c, pos in given.items()}
    meta["sensors"] = {**sensors, **{VANE_KEYS[c]: [0.0, 0.0, 0.0] for c in given}}
    return Recording(data=d, meta=meta, name=rec.name)


# The Savitzky-Golay window (s, cubic) of the angular accelerations that carry a declared
# accelerometer position to the c.g. when the recording has no pdot/qdot/rdot: at 50 Hz its
# derivative's gain is 0.994 at 2 Hz and 0.97 at 3 Hz (a quadratic's 0.82 and 0.64), and it
# turns the rate gyros' white noise (0.14 deg/s) into 0.009 g at 10 ft, a third of the
# accelerometers' own, high in frequency where the common filter takes it out.
ACCEL_DERIVATIVE_WINDOW_S = 0.2


def angular_accelerations(rec: Recording) -> list[np.ndarray]:
    """ṗ, q̇, ṙ (rad/s²): the recorded pdot/qdot/rdot when present, else the rates' cubic
    local-polynomial (Savitzky-Golay) derivative over :data:`ACCEL_DERIVATIVE_WINDOW_S`
    (:func:`estimators.differentiation.local_polynomial_derivative`, seed Eq. 24)."""
    d = rec.data
    if all(f"{c}dot_rps2" in d.columns for c in "pqr"):
        return [d[f"{c}dot_rps2"].to_numpy(dtype=float) for c in "pqr"]
    return [rate_derivative(d[f"{c}_rps"].to_numpy(dtype=float), rec.dt) for c in "pqr"]


def rate_derivative(x: np.ndarray, dt: float) -> np.ndarray:
    """A rate's cubic local-polynomial derivative over :data:`ACCEL_DERIVATIVE_WINDOW_S`, as
    the accelerometers are carried to the c.g. with (:func:`angular_accelerations`)."""
    half = max(2, int(round(0.5 * ACCEL_DERIVATIVE_WINDOW_S / dt)))
    window = min(2 * half + 1, x.size - (1 - x.size % 2))  # odd, and no longer than the record
    return local_polynomial_derivative(x, dt, window=window, order=3)


def recarried_accelerations(p: Prepared, rates: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The accelerometer channels carried to the c.g. again (:func:`accelerometer_to_cg`) with
    the rates ``rates`` (p, q, r; rad/s) in place of the recorded ones: what a gyro's
    correction does to them where the accelerometer is off the c.g. (``meta`` keeps its
    position in ``accelerometer_at_cg``); empty where it is at the c.g. or no rate changed.
    The angular accelerations are the recording's own where it gives them, else the rates'
    derivative (:func:`rate_derivative`) as at the load."""
    pos = p.meta.get("accelerometer_at_cg")
    if not pos or not any(pos) or all(rates[c] is p.raw[c] for c in "pqr"):
        return {}
    old, new = [p.raw[c] for c in "pqr"], [rates[c] for c in "pqr"]
    data = p.recording.data if p.recording is not None else None
    if data is not None and all(f"{c}dot_rps2" in data.columns for c in "pqr"):
        old_dot = new_dot = [data[f"{c}dot_rps2"].to_numpy(dtype=float) for c in "pqr"]
    else:
        old_dot, new_dot = [rate_derivative(x, p.dt) for x in old], [rate_derivative(x, p.dt) for x in new]
    zero = np.zeros(p.n)
    # a_cg = a_s − E(ω, ω̇)/g₀: the new c.g. reading is the old one plus E_old less E_new
    less_old = accelerometer_at_cg(zero, zero, zero, *old, *old_dot, pos)
    less_new = accelerometer_at_cg(zero, zero, zero, *new, *new_dot, pos)
    return {c: p.raw[c] - o + n for c, o, n in zip(("ax", "ay", "az"), less_old, less_new)}


def accelerometer_to_cg(rec: Recording) -> Recording:
    """``rec`` with its accelerometers carried to the c.g. from the position its metadata give
    (``sensors.accelerometer_ft``; unchanged at [0, 0, 0] or when done already):
    a_cg = a − [ω̇ × r + ω × (ω × r)]/g₀ (:func:`estimators.coefficients.accelerometer_at_cg`).
    The position moves to ``meta['accelerometer_at_cg']`` and ``sensors`` holds it at zero,
    so that every test (the kinematics, the coefficients, the replays' outputs) sees c.g.
    readings. Measured on an F-16 pitch recording with the accelerometer 10 ft ahead and the
    position declared: taken as read, the kinematics asked for an offset of 12 ± 3 ft (t 4.3)
    and leaned a_z's scale and α's skew with it."""
    sensors = dict(rec.meta.get("sensors") or {})
    pos = [float(v) for v in sensors.get("accelerometer_ft") or (0.0, 0.0, 0.0)]
    if not any(pos):
        return rec
    d = rec.data.copy()
    rates = [d[f"{c}_rps"].to_numpy(dtype=float) for c in "pqr"]
    moved = accelerometer_at_cg(*(d[f"a{c}_g"].to_numpy(dtype=float) for c in "xyz"), *rates,
                                *angular_accelerations(rec), pos)
    for c, col in zip("xyz", moved):
        d[f"a{c}_g"] = col
    meta = dict(rec.meta)
    meta["accelerometer_at_cg"] = pos
    meta["sensors"] = {**sensors, "accelerometer_ft": [0.0, 0.0, 0.0]}
    return Recording(data=d, meta=meta, name=rec.name)


def instruments_at_cg(rec: Recording) -> Recording:
    """``rec`` with its vanes (:func:`vanes_at_cg`) and accelerometers
    (:func:`accelerometer_to_cg`) carried to the c.g. from the positions its metadata give."""
    return accelerometer_to_cg(vanes_at_cg(rec))


# Euler angles a recording may give wrapped (recording-format.md fixes the unit, not the
# range): a heading in [0, 2π) crosses north as a 2π step, one in (−π, π] crosses south.
# θ stays within ±π/2 and is never wrapped.
WRAPPED_ANGLES = ("phi", "psi")


def _channels(rec: Recording) -> dict[str, np.ndarray]:
    """The canonical channels the diagnosis reads, the bank and heading unwrapped
    (:data:`WRAPPED_ANGLES`): a 2π step smoothed is a ramp the kinematics and the gust's
    rotation to north-east-down would read as motion (a heading near north, recorded in
    [0, 2π), gave ψ a noise level of 2.2 rad)."""
    out = {}
    for q, unit in UNITS.items():
        col = f"{q}_{unit}"
        if col in rec.data.columns:
            x = rec.data[col].to_numpy(dtype=float)
            out[q] = np.unwrap(x) if q in WRAPPED_ANGLES else x
    return out


# A recorded throttle (0-1) whose travel exceeds this changed the thrust the recording does not
# carry: 5 % of the lever, a change of the order of 5-10 % of the engine's thrust range (no
# lever's position noise comes near it; a held throttle's channel is constant).
THROTTLE_STEADY = 0.05
THROTTLE_MOVED = ("the recorded throttle moved from {:.2f} to {:.2f} of its travel: the thrust was not constant, "
                  "and the terms its change would imitate are not named (not_checked)")


def throttle_travel(rec: Recording) -> tuple[float, float] | None:
    """The recorded throttle's range (its 1st and 99th percentiles, so that a spike does not
    count) when the recording has a ``throttle_1`` channel and no thrust channel and the
    throttle moved more than :data:`THROTTLE_STEADY`; None otherwise (thrust recorded, no
    throttle channel, or the throttle held)."""
    if "throttle_1" not in rec.data.columns or any(c.startswith("thrust_") for c in rec.data.columns):
        return None
    lo, hi = (float(v) for v in np.percentile(rec.data["throttle_1"].to_numpy(dtype=float), [1.0, 99.0]))
    return (lo, hi) if hi - lo > THROTTLE_STEADY else None


def interior_slice(n: int, dt: float) -> slice:
    """The samples of an ``n``-sample record at step ``dt`` without its first and last
    :data:`EDGE_S`."""
    k = max(1, int(round(EDGE_S / dt)))
    return slice(k, n - k)


def interior_motion(x: np.ndarray) -> float:
    """The standard deviation of ``x`` (a record's interior) about its least-squares line:
    what moved inside the record. Not :func:`about_trend`: the smoothed signal ends on the raw
    end samples, and two end samples off by two noise levels each, in opposite directions,
    tilt the line through them by four (a pitch maneuver's aileron, still but for its 0.05°
    noise, then 'moved' by 0.06° about that line, five times the noise the filter passes)."""
    x = np.asarray(x, dtype=float)
    if x.size < 3:
        return 0.0
    t = np.arange(x.size, dtype=float)
    return float(np.std(x - np.polyval(np.polyfit(t, x, 1), t)))


def about_trend(x: np.ndarray) -> float:
    """The standard deviation of ``x`` about the line through its end points: the signal the
    sine-series filter smooths (it removes that line first)."""
    x = np.asarray(x, dtype=float)
    return float(np.std(x - np.linspace(x[0], x[-1], x.size)))


def common_weights(fits: dict, excited: tuple[str, ...], n: int) -> np.ndarray:
    """The element-wise minimum of the excited states' Wiener weights (all ones beyond
    their last cut-off is never needed: a weight is at most 1).

    The same rule as the smoothed equation-error estimator: one linear filter for every
    record keeps z = Xθ exact through the filter."""
    chosen = [fits[c].weights for c in BANDWIDTH_CHANNELS if c in excited]
    if not chosen:
        # nothing passes the per-sample test (a small response at high dynamic pressure): the
        # state whose own smoothing stands highest above the noise it lets through sets the band
        # (the minimum over every state would smooth the whole maneuver away)
        snr = {c: _own_snr(fits[c]) for c in BANDWIDTH_CHANNELS if c in fits}
        if snr:
            chosen = [fits[max(snr, key=snr.get)].weights]
    return np.min(chosen, axis=0) if chosen else np.ones(n - 2)


def _own_snr(fit) -> float:
    """A channel's own optimal smoothing over the white noise that smoothing lets through."""
    noise = filtered_noise_std(float(np.sqrt(max(fit.noise_variance, 0.0))), fit.weights)
    return about_trend(fit.smoothed) / max(noise, 1e-12)


def prepare(rec: Recording, name: str = "identification") -> Prepared:
    """Filter, differentiate and turn ``rec`` into measured coefficients.

    Raises
    ------
    UserError
        When the recording is too short (under 4 s) or lacks what Eqs. 1-5 need (a user
        error: exit status 2 on the command line).
    """
    rec = instruments_at_cg(rec)
    raw = _channels(rec)
    t = rec.data["t_s"].to_numpy(dtype=float)
    t = t - t[0]
    if t[-1] < 4.0:
        raise UserError(f"recording {rec.name!r} is {t[-1]:.1f} s long; the diagnosis needs at least 4 s")
    dt = float((t[-1] - t[0]) / (t.size - 1))
    assumptions = list(_stand_ins(raw, rec.meta, tuple(rec.data.columns), throttle_travel(rec)))
    fits, filtered = _own_smoothing(raw, dt)
    if filtered:
        assumptions.append({"item": "noise floor", "missing": "a flat (white) noise floor to the Nyquist frequency",
                            "stood_in_by": "the floor each channel shows, falling at the top of the band on "
                                           f"{', '.join(filtered)} (an anti-alias filter before sampling): the "
                                           "noise levels are measured under that shape"})
    noise = {c: float(np.sqrt(max(f.noise_variance, 0.0))) for c, f in fits.items()}
    excited = tuple(c for c, f in fits.items() if about_trend(f.smoothed) > 5.0 * max(noise[c], 1e-12))
    w = common_weights(fits, excited, t.size)
    smooth = {c: sine_series_filter(x, w) for c, x in raw.items()}
    deriv = {c: sine_series_derivative(x, w, dt) for c, x in raw.items()}
    k = max(1, int(round(START_WINDOW_S / dt)))
    start = {c: float(np.mean(x[:k])) for c, x in smooth.items()}
    cutoff = float(np.max(np.nonzero(w > 1e-6)[0], initial=0) + 1) / (2.0 * t[-1])
    try:
        mass = {k: np.asarray(v, dtype=float) for k, v in rec.mass_at().items()}
    except (KeyError, ValueError) as exc:
        raise UserError(f"recording {rec.name!r} lacks mass properties Eqs. 1-5 need: {exc}") from exc
    measured = measured_coefficients(smooth, deriv, rec.meta, mass)
    driven = maneuver_driven({c: x[interior_slice(t.size, dt)] for c, x in smooth.items()}, noise, w, excited)
    moved = drifted_states(smooth, noise, w, k, driven)
    own_noise = {c: np.asarray(f.noise) for c, f in fits.items()}
    if "h" in raw:
        altitude = raw["h"] - own_noise["h"]
    else:
        altitude = stand_in_altitude(raw, own_noise)
        assumptions.append({"item": "altitude", "missing": "h channel",
                            "stood_in_by": f"the ISA altitude of the density 2 q̄ / V² ({np.mean(altitude[:k]):.0f} ft "
                                           "at the start; a standard day assumed)"})
    return Prepared(name=name, t=t, dt=dt, raw=raw, smooth=smooth, deriv=deriv, noise_std=noise,
                    cutoff_hz={c: f.cutoff_hz for c, f in fits.items()}, weights=w, common_cutoff_hz=cutoff,
                    excited=excited, measured=measured, start=start, meta=dict(rec.meta),
                    own_noise=own_noise, mass=mass, driven=driven, moved=moved, assumptions=tuple(assumptions),
                    altitude=altitude, recording=rec)


# A recorder's anti-alias filter: a noise floor flat over 0.15-0.3 of the Nyquist frequency
# (its two halves within FLAT_FACTOR of each other: white noise, above the maneuver's band)
# whose top tenth of the band lies under RECORDER_FALL of that level (white noise: 1 within a
# few %, hundreds of coefficients in each band; a 4th-order filter at half the Nyquist
# frequency: 0.006; a noise-free channel's own spectrum keeps falling through the flat band).
RECORDER_FALL = 0.1
FLAT_FACTOR = 2.0


def recorder_noise_shape(power: np.ndarray, freqs: np.ndarray) -> np.ndarray | None:
    """The shape of a noise floor that falls at the top of the band, as a recorder's
    anti-alias filter leaves it, from the sine-series power ``power`` at ``freqs``; None when
    the floor does not fall there (white noise: the optimal smoother's own assumption).

    The optimal Fourier smoother (seed section III.A) takes the coefficients above its
    cut-off for the noise floor and assumes that floor flat to the Nyquist frequency. A
    record filtered before it was sampled has noise only up to the filter's corner: the
    cut-off then lands where the filtered noise meets nothing, the noise is kept as signal
    and its level is taken as almost zero (5e-8 rad for a 0.1° α vane behind a 12.5 Hz
    4th-order filter at 50 Hz), and every test that weighs a term against the noise goes
    wrong. The floor must be flat over 0.15-0.3 of the Nyquist frequency
    (:data:`FLAT_FACTOR`) and fall under :data:`RECORDER_FALL` of that level at the top.
    Its shape is then its running median (±2 % of the band; medians of χ² ordinates on both
    sides, so their ratio is unbiased) over its median level there, capped at 1, and 1 below
    0.15 of the Nyquist frequency (white noise before the filter): the smoother's
    ``noise_shape``."""
    nyquist = float(freqs[-1])
    ref = (freqs >= 0.15 * nyquist) & (freqs < 0.3 * nyquist)
    low, high = ref & (freqs < 0.225 * nyquist), ref & (freqs >= 0.225 * nyquist)
    top = freqs >= 0.9 * nyquist
    if not (low.sum() >= 10 and high.sum() >= 10 and top.sum() >= 10):
        return None
    level, lower, upper = (float(np.median(power[m])) for m in (ref, low, high))
    flat = lower > 0.0 and upper > 0.0 and 1.0 / FLAT_FACTOR <= upper / lower <= FLAT_FACTOR
    if not flat or float(np.median(power[top])) >= RECORDER_FALL * level:
        return None
    half = max(5, int(0.02 * power.size))
    floor = ndimage.median_filter(power, size=2 * half + 1, mode="nearest")
    shape = np.minimum(floor / level, 1.0)
    shape[freqs < 0.15 * nyquist] = 1.0
    return np.maximum(shape, 1e-12)


# The share of the recorded outputs whose floor must fall for the recording to be taken as
# filtered before sampling (a recorder's filter acts on every channel; one channel's own
# falling spectrum, a smooth surface or thrust history, is not one).
RECORDER_SHARE = 2.0 / 3.0


def _own_smoothing(raw: dict[str, np.ndarray], dt: float) -> tuple[dict, list[str]]:
    """Each channel's own optimal smoothing, and the channels smoothed under the noise floor's
    own shape (:func:`recorder_noise_shape`): those whose floor falls, when at least
    :data:`RECORDER_SHARE` of the recorded outputs show a recorder's anti-alias filter."""
    fits = {c: optimal_fourier_smoother(x, dt) for c, x in raw.items()}
    shapes = {c: recorder_noise_shape(f.coefficients ** 2, f.frequencies_hz) for c, f in fits.items()}
    outputs = [c for c in OUTPUTS if c in raw]
    if not outputs or sum(shapes[c] is not None for c in outputs) < RECORDER_SHARE * len(outputs):
        return fits, []
    filtered = [c for c in raw if shapes[c] is not None]
    for c in filtered:
        fits[c] = optimal_fourier_smoother(raw[c], dt, noise_shape=shapes[c])
    return fits, filtered


def _stand_ins(raw: dict[str, np.ndarray], meta: dict, columns: tuple[str, ...],
               throttle: tuple[float, float] | None = None) -> list[dict]:
    """What the recording leaves out and what the diagnosis assumes instead (altitude is
    handled in :func:`prepare`; thrust's value is the analysis's); ``throttle`` is
    :func:`throttle_travel`'s range, when the recorded throttle contradicts the constant thrust."""
    out = []
    if "thrust" not in raw:
        trim_thrust = (meta.get("trim") or {}).get("thrust_lbf")
        entry = {"item": "thrust", "missing": "thrust channel",
                 "stood_in_by": (f"constant at the metadata's trim thrust, {trim_thrust:.0f} lbf "
                                 "(recording-format: constant at trim)" if trim_thrust is not None else
                                 "constant at the model's trim thrust at the recording's start "
                                 "(recording-format: constant at trim; the metadata give none)")}
        if throttle is not None:
            entry["contradicted_by"] = THROTTLE_MOVED.format(*throttle)
        out.append(entry)
    if "thrust_offset_ft" not in meta:
        out.append({"item": "thrust line", "missing": "thrust_offset_ft",
                    "stood_in_by": "through the c.g. (0 ft): a thrust line off it puts thrust × offset / (q̄·S·c̄) "
                                   "into C_m's mismatch, a constant where thrust is steady"})
    absent = [s for s in SURFACES if s not in raw]
    if absent:
        out.append({"item": "surfaces not recorded", "missing": ", ".join(absent),
                    "stood_in_by": "held at the model's trim deflection throughout (recording-format: only the "
                                   "surfaces that moved are required); a term on them cannot be tested"})
    constant = [k for k in MASS_KEYS if k not in columns]
    if constant:
        given = len(constant) < len(MASS_KEYS)
        out.append({"item": "mass and inertia", "missing": ", ".join(constant) + " channels" if given else
                    "mass channels", "stood_in_by": "the metadata's constants, for the whole maneuver"
                    + (f" (the recording's channels for {', '.join(k for k in MASS_KEYS if k in columns)})"
                       if given else "")})
    sensors = meta.get("sensors") or {}
    if meta.get("accelerometer_at_cg"):
        out.append({"item": "accelerometer position", "missing": "-",
                    "stood_in_by": f"carried to the c.g. from the metadata's position {meta['accelerometer_at_cg']} "
                                   "ft with the recorded rates (a − ω̇ × r − ω × (ω × r); ω̇ "
                                   + ("recorded)" if all(f"{c}dot_rps2" in columns for c in "pqr") else
                                      f"from a {ACCEL_DERIVATIVE_WINDOW_S:g} s Savitzky-Golay derivative of the "
                                      "rates)")})
    elif "accelerometer_ft" not in sensors:
        out.append({"item": "accelerometer position", "missing": "sensors.accelerometer_ft",
                    "stood_in_by": "at the c.g. (any offset is then a finding, sensor_offset)"})
    moved = meta.get("vanes_at_cg") or {}
    if moved:
        where = ", ".join(f"{k} {v}" for k, v in moved.items())
        out.append({"item": "angle-of-attack and sideslip vanes", "missing": "-",
                    "stood_in_by": f"carried to the c.g. from the metadata's positions ({where}) with the recorded "
                                   "rates and airspeed (α − (p·y − q·x)/V, β − (r·x − p·z)/V)"
                                   + ("" if len(moved) == 2 else "; the other vane taken at the c.g.")})
    else:
        out.append({"item": "angle-of-attack and sideslip vanes", "missing": "vane positions",
                    "stood_in_by": "α and β taken as measured at the c.g. (a vane offset is then a finding)"})
    out.append({"item": "angular rates", "missing": "-",
                "stood_in_by": "p, q, r taken as the body rates the aerodynamics see (still air; inertial and "
                               "Earth-relative rates differ by at most 7.3e-5 rad/s)"})
    out.append(_angular_accelerations_stand_in(columns))
    return out


def _angular_accelerations_stand_in(columns: tuple[str, ...]) -> dict:
    """How the moment coefficients get ṗ, q̇, ṙ (seed Eqs. 3-5): always the derivative of
    the common-filtered rates (seed §III.A, method 2), so that every channel of the
    coefficients passes one linear filter; recorded pdot/qdot/rdot, when present, serve only
    to carry a declared accelerometer position to the c.g. (:func:`angular_accelerations`),
    and the output says so."""
    recorded = [f"{c}dot" for c in "pqr" if f"{c}dot_rps2" in columns]
    if recorded:
        return {"item": "angular accelerations", "missing": "-",
                "stood_in_by": f"the recorded {', '.join(recorded)} are not used for the moment coefficients: "
                               "the derivative of the common-filtered rates is (one filter for every channel)"
                               + ("; they serve only to carry a declared accelerometer position to the c.g."
                                  if len(recorded) == 3 else "")}
    return {"item": "angular accelerations", "missing": "pdot, qdot, rdot channels",
            "stood_in_by": "the derivative of the common-filtered rates (seed §III.A, method 2)"}


def filtered_noise_std(noise_std: float, weights: np.ndarray) -> float:
    """The standard deviation white noise of ``noise_std`` keeps through the sine-series
    filter ``weights``: by Parseval on the orthogonal sine basis, sigma * sqrt(mean(w^2))."""
    return float(noise_std * np.sqrt(np.mean(np.asarray(weights) ** 2)))


def maneuver_driven(smooth: dict[str, np.ndarray], noise: dict[str, float], weights: np.ndarray,
                    excited: tuple[str, ...], snr: float = DRIVEN_SNR) -> tuple[str, ...]:
    """The surfaces that moved and the states the maneuver drove, from the record's interior
    ``smooth`` (:func:`interior_slice`).

    A surface counts when it is ``excited`` (its smoothed signal at least 5 times its noise).
    A state counts when a surface of its group moved (:data:`DRIVEN_BY`: the lateral states
    need an aileron or rudder input, the longitudinal ones a stabilator input) *and* its
    filtered signal, about its least-squares line (:func:`interior_motion`), stands ``snr``
    times above the white noise the filter passes.
    Coloured sensor noise inside the band can pass the second test; the first is what keeps
    a pitch maneuver's β, p and r out of the analysis. A state that moved far without its
    group's input (a lateral input's spiral, turbulence) is not driven: the model is evaluated
    along it (:func:`drifted_states`), no term is built on it."""
    def ratio(c: str) -> float:
        signal = interior_motion(smooth[c])
        if signal < DRIVEN_FLOOR.get(c, 0.0):
            return 0.0
        return signal / max(filtered_noise_std(noise.get(c, 0.0), weights), 1e-12)

    # a surface moved when it is excited, or when its filtered signal stands clear of the noise
    # the filter passes (a surface moved by a feedback loop every frame looks noisy sample to
    # sample, yet moves)
    surfaces = [s for s in SURFACES if s in smooth and (s in excited or ratio(s) >= snr)]
    out = list(surfaces)
    for state, group in DRIVEN_BY.items():
        if state not in smooth:
            continue
        if ratio(state) >= snr and any(g in surfaces for g in group):
            out.append(state)
    return tuple(out)


def drifted_states(smooth: dict[str, np.ndarray], noise: dict[str, float], weights: np.ndarray,
                   start_samples: int, driven: tuple[str, ...]) -> tuple[str, ...]:
    """The states not ``driven`` that moved far all the same: their filtered signal, about its
    trend or about their start level (the RMS of x − x_start, x_start the mean of the first
    ``start_samples``), stands :data:`SELF_EVIDENT_SNR` times above the white noise the common
    filter passes.

    The model is evaluated along such a state, but no candidate term is built on it.
    Evaluated along: held at its start, the model would carry its own derivative times the
    whole motion into the mismatch. The excursion counts, not only the signal about the trend
    (what the sine-series filter smooths), because a slow departure is almost all trend: a
    lateral input leaves the DHC-6 in a spiral, α 1.4° and q 3°/s off their start (ratio
    about the trend 5 and 15, excursion 35 and 50), and held there C_Z's mismatch stood at 10
    times its noise. No term: a motion its group's input did not cause is the aircraft's
    slow departure, along which whatever the model leaves out of the power and Mach effects
    grows too (a DHC-6 spiral from 230 to 390 ft/s made a C_m,ΔV "finding" at t = 42; on a
    pitch maneuver its yaw rate drifts 37 times its noise and C_n,r̂ entered at t = 28)."""
    out = []
    for c in DRIVEN_BY:
        if c in driven or c not in smooth:
            continue
        x = smooth[c]
        signal = max(about_trend(x), float(np.sqrt(np.mean((x - np.mean(x[:start_samples])) ** 2))))
        if signal >= max(SELF_EVIDENT_SNR * filtered_noise_std(noise.get(c, 0.0), weights),
                         DRIVEN_FLOOR.get(c, 0.0)):
            out.append(c)
    return tuple(out)


def measured_coefficients(s: dict[str, np.ndarray], d: dict[str, np.ndarray], meta: dict,
                          mass: dict[str, np.ndarray], thrust_lbf: float | None = None) -> dict[str, np.ndarray]:
    """Seed Eqs. 1 and 3-5 from filtered channels ``s`` and their derivatives ``d``.

    Thrust is the recorded channel when present, else ``thrust_lbf`` (the model's trim
    thrust), else zero; the accelerometer is moved to the c.g. when the metadata place it
    elsewhere."""
    geo = meta["geometry"]
    p, q, r = s["p"], s["q"], s["r"]
    pd_, qd, rd = d["p"], d["q"], d["r"]
    ax, ay, az = accelerometer_at_cg(s["ax"], s["ay"], s["az"], p, q, r, pd_, qd, rd,
                                     meta.get("sensors", {}).get("accelerometer_ft", (0.0, 0.0, 0.0)))
    thrust = s.get("thrust", np.full(p.size, thrust_lbf or 0.0))
    forces = force_coefficients(ax, ay, az, thrust, s["qbar"], mass["mass_slug"], geo["S_ft2"])
    moments = moment_coefficients(p, q, r, pd_, qd, rd, s["qbar"], geo["S_ft2"], geo["b_ft"], geo["cbar_ft"],
                                  mass["Ix_slugft2"], mass["Iy_slugft2"], mass["Iz_slugft2"], mass["Ixz_slugft2"],
                                  thrust, meta.get("thrust_offset_ft", 0.0))
    return {**forces, **{k: moments[k] for k in ("Cl", "Cm", "Cn")}}


_SOURCE_WORDS = {"alpha": "α", "beta": "β", "p": "the roll rate", "q": "the pitch rate", "r": "the yaw rate",
                 "V": "the airspeed", "de": "the stabilator", "da": "the aileron", "dr": "the rudder"}


def stand_in_altitude(raw: dict[str, np.ndarray], own_noise: dict[str, np.ndarray]) -> np.ndarray:
    """The altitude (ft) a recording without an ``h`` channel stands in: the ISA pressure
    altitude of the density 2 q̄ / V² that q̄ and V (each by its own optimal smoothing, the
    channel less ``own_noise``) imply, standard day. Kept out of ``raw``: the kinematic checks
    must not see a made-up ḣ."""
    rho = 2.0 * (raw["qbar"] - own_noise["qbar"]) / (raw["V"] - own_noise["V"]) ** 2
    return density_altitude_ft(np.clip(rho, 1e-6, None))


def undriven_reason(p: Prepared, sources: list[str] | tuple[str, ...]) -> str:
    """Why a term built on ``sources`` could not be tested on this recording."""
    missing = [s for s in sources if s not in p.driven]
    lateral = any(s in p.driven for s in ("da", "dr"))
    longitudinal = "de" in p.driven
    words = []
    for s in missing:
        if s in ("beta", "p", "r") and not lateral:
            words.append("no lateral input (aileron and rudder never moved)")
        elif s in ("alpha", "q", "V") and not longitudinal:
            words.append("no longitudinal input (the stabilator never moved)")
        elif s in SURFACES:
            words.append(f"{_SOURCE_WORDS[s]} never moved")
        elif s == "V":
            words.append("the airspeed never moved above its noise (no phugoid)")
        else:
            words.append(f"{_SOURCE_WORDS.get(s, s)} never moved above its noise")
    drifted = [s for s in missing if s in p.moved]
    if drifted:
        words.append(f"{', '.join(_SOURCE_WORDS.get(s, s) for s in drifted)} drifted only with the aircraft's "
                     "departure (the model is evaluated along it; no term is built on it)")
    return "; ".join(dict.fromkeys(words)) or "not excited"
