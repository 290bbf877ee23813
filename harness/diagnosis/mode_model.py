"""A structural mode as a second-order response to a recorded surface, added to the outputs
it rings in: the model the augmented replay predicts the validation maneuver's mode with.

The flexible coordinate η of a lightly damped mode driven by a surface u obeys
η̈ + 2ζω η̇ + ω² η = ω² u (ω = 2π f). A gyro sees the mode's rate, an accelerometer its
acceleration, so each output rings as a combination of the two responses

    r_acc = s² H(s) u / ω²,   r_rate = s H(s) u / ω,   H(s) = ω² / (s² + 2ζωs + ω²),

both of which vanish at low frequency (the rigid-body band the aerodynamics own). Their gains
are fitted, per output, to the record's content in a band about the spectral peak that named
the mode, u the surface's Wiener estimate, with f and ζ found by variable projection (the
gains solved linearly for each trial f, ζ)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage, optimize, signal, stats

from estimators.filter_error import MAD_TO_SIGMA
from harness.diagnosis.kinematics import T_IN, is_practical
from harness.diagnosis.prepare import Prepared, interior_slice
from harness.diagnosis.sensor_rules import forced_entry_t, kinematic_estimate, plausible_kinematic_check
from harness.diagnosis.spectra import FISHER_P, MODE_CHANNELS, MODE_DRIVERS, notched, sub_floor_peak
from models.constants import SURFACES

# The damping ratios tried before refinement (structural modes: 0.5-20 % of critical).
DAMPING_GRID = np.geomspace(0.005, 0.2, 10)
DAMPING_BOUNDS = (0.002, 0.5)  # the refinement's limits
# The frequencies tried about the spectral peak, as a share of it either side (a mode rung by
# steps peaks a few tenths of a hertz from its natural frequency, spectra._refine).
FREQUENCY_SPAN = 0.12
# An output's pair of mode gains enters when their F statistic beats noise at this level
# (the structural-mode peak's own level, spectra.FISHER_P).
GAIN_P = 1e-6
# The surface estimate's short-time segments (s) and the neighbouring frequencies (of 2 Hz at
# 0.5 s) its Wiener gain averages the cell's power over (wiener_surface): on the outside
# sweep's three driven modes 0.4-0.5 s with three bins explained the validation maneuver's
# band best and alike (0.25 s let the noise through, 1 s smeared the edges).
SEGMENT_S = 0.5
WIENER_BINS = 3
# The noise power subtracted this many times over (Berouti, Schwartz & Makhoul 1979): a cell's
# power, one segment's and three bins', scatters as chi-squared with 6 degrees of freedom, and
# a gain of 1 − N/P lets the noise's upward excursions through. At 3 the outside sweep's modes'
# validation bands were explained 91, 65 and 55 % (at 1: 83, 41, 50 %), and a step's 6-10 Hz
# content through a 40 rad/s actuator was estimated within 10 % (19 % at 1).
OVERSUBTRACTION = 3.0
# A fit is a model of the mode when its damping is at most this (a lightly damped mode; a
# fit that runs to heavy damping has found broadband noise), its frequency within
# FREQUENCY_SPAN of the spectral peak, and it explains at least MIN_EXPLAINED of the band's
# power in the channel the peak is in.
MAX_DAMPING = 0.2
MIN_EXPLAINED = 0.3
# The shortest record a mode is fitted on: the spectral test's four 2 s Welch segments
# (spectra.structural_peak).
MIN_RECORD_S = 8.0
# Half-width of the band a mode's fit is judged in: at least this, or two half-power
# bandwidths (2ζf each) of the fitted mode.
BAND_MIN_HALF_WIDTH_HZ = 0.5


@dataclass(frozen=True)
class DrivenMode:
    """A structural mode fitted as the response to ``surface``: natural frequency (Hz) and its
    standard error, damping ratio, and per output the gains of (r_acc, r_rate) in the output's
    unit per rad of surface."""

    frequency_hz: float
    std_error_hz: float
    damping: float
    surface: str
    gains: dict[str, tuple[float, float]] = field(default_factory=dict)
    explained: dict[str, float] = field(default_factory=dict)  # share of the band's power the fit explains

    def as_dict(self) -> dict:
        return {"frequency_hz": self.frequency_hz, "std_error_hz": self.std_error_hz, "damping": self.damping,
                "surface": self.surface, "gains": {c: list(g) for c, g in self.gains.items()},
                "explained_in_band": dict(self.explained)}

    @classmethod
    def from_dict(cls, d: dict) -> "DrivenMode":
        return cls(d["frequency_hz"], d["std_error_hz"], d["damping"], d["surface"],
                   {c: tuple(g) for c, g in d["gains"].items()}, dict(d.get("explained_in_band", {})))

    def band_hz(self) -> tuple[float, float]:
        """The band the mode's fit is judged in (:data:`BAND_MIN_HALF_WIDTH_HZ`)."""
        half = max(BAND_MIN_HALF_WIDTH_HZ, 4.0 * self.damping * self.frequency_hz)
        return self.frequency_hz - half, self.frequency_hz + half


def mode_responses(u: np.ndarray, dt: float, frequency_hz: float, damping: float) -> np.ndarray:
    """(r_acc, r_rate) of the module docstring for the surface history ``u`` (rad; taken from
    its first value), each a column: the continuous transfer functions discretised with a
    first-order hold (scipy.signal.cont2discrete), which treats ``u`` as piecewise linear."""
    w = 2.0 * np.pi * frequency_hz
    den = [1.0, 2.0 * damping * w, w * w]
    x = np.asarray(u, dtype=float) - float(u[0])
    out = []
    for num in ([1.0, 0.0, 0.0], [w, 0.0]):
        b, a, _ = signal.cont2discrete((num, den), dt, method="foh")
        out.append(signal.lfilter(np.ravel(b), a, x))
    return np.column_stack(out)


def white_noise_std(x: np.ndarray) -> float:
    """The standard deviation of a record's white noise from its fourth differences: robustly
    (median absolute deviation over that of a unit normal, ``MAD_TO_SIGMA``), and with their
    variance 70 σ² for white noise (the sum of the squared binomial coefficients, C(8, 4)). A
    fourth difference passes a 2 Hz motion at 50 samples/s at 0.4 % of its amplitude and puts a
    step's edge into four samples only, so neither the maneuver's motion nor the sharp edges of
    a step input (whose spectrum can stand above the noise up to Nyquist) are counted as
    noise."""
    d = np.diff(np.asarray(x, dtype=float), 4)
    return float(np.median(np.abs(d - np.median(d))) / MAD_TO_SIGMA / np.sqrt(70.0))


def wiener_surface(u: np.ndarray, dt: float, segment_s: float = SEGMENT_S) -> np.ndarray:
    """The surface history's best estimate from its record, by a time-varying Wiener gain:
    each cell of its short-time Fourier transform (Hann, ``segment_s`` segments overlapping by
    three quarters) scaled by the share of its power that is signal,
    G(t, f) = max(P(t, f) − αN, 0)/P(t, f) (short-time spectral attenuation, Lim & Oppenheim
    1979), P the cell's power averaged over :data:`WIENER_BINS` neighbouring frequencies (its
    scatter would otherwise pass a share of the noise), N the white sensor noise's power per
    cell (:func:`white_noise_std`; σ² Σw²/(Σw)² for scipy.signal.stft's scaling), subtracted
    :data:`OVERSUBTRACTION` times over. A mode's resonance rings the sensor noise of a surface
    as loudly as its motion near the mode (0.05° of potentiometer noise on a 2° doublet, an 8 Hz
    mode at ζ 0.02), so the response is built on an estimate, not on the raw record (fitted on
    it, the gains of a gallery mode come out within 15 %, ``tests/test_mode_model.py``). A step
    through an actuator holds its content near the mode only for a few tenths of a second after
    each edge: a gain set on the whole record's spectrum (tried first) scaled those edges by the
    record's average signal share, about one half on the outside sweep's 8 Hz F-16 mode, and the
    validation maneuver's ringing was predicted at half its size (q's band 54 % explained); set
    per cell it keeps the edges and removes the noise between them (91 %,
    :data:`OVERSUBTRACTION`)."""
    x = np.asarray(u, dtype=float)
    m = float(np.mean(x))
    nper = max(8, min(int(round(segment_s / dt)), x.size))
    overlap = nper - nper // 4
    fs = 1.0 / dt
    _, _, Z = signal.stft(x - m, fs=fs, window="hann", nperseg=nper, noverlap=overlap, boundary="even", padded=True)
    w = signal.get_window("hann", nper)
    N = white_noise_std(x) ** 2 * float(np.sum(w ** 2)) / float(np.sum(w)) ** 2
    P = ndimage.uniform_filter1d(np.abs(Z) ** 2, WIENER_BINS, axis=0, mode="nearest")
    G = np.clip(1.0 - OVERSUBTRACTION * N / np.maximum(P, 1e-300), 0.0, 1.0)
    _, y = signal.istft(Z * G, fs=fs, window="hann", nperseg=nper, noverlap=overlap, boundary=True)
    return y[:x.size] + m


def _fit_band(peak_hz: float) -> tuple[float, float]:
    """The band a mode is fitted in: the frequencies searched (:data:`FREQUENCY_SPAN` twice
    over, either side of the peak) and :data:`BAND_MIN_HALF_WIDTH_HZ` beyond. Outside it the
    record holds the rigid-body response to the input's edges, which the responses would
    otherwise be fitted to as well."""
    return (max(peak_hz * (1.0 - 2.0 * FREQUENCY_SPAN) - BAND_MIN_HALF_WIDTH_HZ, 0.0),
            peak_hz * (1.0 + 2.0 * FREQUENCY_SPAN) + BAND_MIN_HALF_WIDTH_HZ)


def _in_band(x: np.ndarray, dt: float, band: tuple[float, float]) -> np.ndarray:
    """:func:`band_part` of each column."""
    return np.column_stack([band_part(x[:, j], dt, band) for j in range(x.shape[1])])


def _sse(y: np.ndarray, u: np.ndarray, dt: float, f: float, z: float, band: tuple[float, float],
         inner: slice) -> float:
    R = _in_band(mode_responses(u, dt, f, z), dt, band)[inner]
    g, *_ = np.linalg.lstsq(R, y, rcond=None)
    return float(np.sum((y - R @ g) ** 2))


def band_part(x: np.ndarray, dt: float, band_hz: tuple[float, float]) -> np.ndarray:
    """``x``'s content within ``band_hz`` (zero phase: its Fourier coefficients outside are set
    to zero, the linear trend removed first, so the record's ends do not leak into the band)."""
    x = signal.detrend(np.asarray(x, dtype=float))
    X = np.fft.rfft(x)
    f = np.fft.rfftfreq(len(x), dt)
    X[(f < band_hz[0]) | (f > band_hz[1])] = 0.0
    return np.fft.irfft(X, n=len(x))


def fit_driven_mode(p: Prepared, channel: str, frequency_hz: float,
                    drivers: tuple[str, ...] | None = None) -> DrivenMode | None:
    """The mode a spectral peak at ``frequency_hz`` in ``channel`` points to, fitted as the
    response to the surface that drives that channel (:data:`spectra.MODE_DRIVERS`) and
    explains most of it, within :func:`_fit_band` (of ``drivers`` when given); None when no
    recorded surface's response explains it (p ≥ :data:`GAIN_P`): a mode rung by something the
    recording lacks (turbulence, an engine) keeps the sensor model's notch."""
    inner = interior_slice(p.n, p.dt)
    drivers = MODE_DRIVERS.get(channel, ()) if drivers is None else drivers
    surfaces = [s for s in drivers if s in p.raw and np.ptp(p.raw[s]) > 0]
    if channel not in p.raw or not surfaces or not 0.0 < frequency_hz < 0.45 / p.dt:
        return None
    if p.t[-1] < MIN_RECORD_S:  # a record the spectral test could not have named a mode on
        return None
    band = _fit_band(frequency_hz)
    freqs = np.fft.rfftfreq(p.n, p.dt)
    # two degrees of freedom per Fourier ordinate in the band, for the interior samples fitted
    n_eff = int(2 * np.count_nonzero((freqs >= band[0]) & (freqs <= band[1])) * (inner.stop - inner.start) / p.n)
    y = band_part(p.raw[channel], p.dt, band)[inner]
    drive = {s: wiener_surface(p.raw[s], p.dt) for s in surfaces}

    def sse(s: str, f: float, z: float) -> float:
        return _sse(y, drive[s], p.dt, f, z, band, inner)

    best = min((sse(s, f, z), s, f, z) for s in surfaces
               for f in frequency_hz * (1.0 + np.linspace(-FREQUENCY_SPAN, FREQUENCY_SPAN, 13))
               for z in DAMPING_GRID)
    _, s, f0, z0 = best
    res = optimize.minimize(lambda v: sse(s, v[0], float(np.exp(v[1]))), [f0, np.log(z0)], method="Nelder-Mead",
                            bounds=[(frequency_hz * (1.0 - 2.0 * FREQUENCY_SPAN),
                                     frequency_hz * (1.0 + 2.0 * FREQUENCY_SPAN)),
                                    (np.log(DAMPING_BOUNDS[0]), np.log(DAMPING_BOUNDS[1]))],
                            options={"xatol": 1e-4, "fatol": 1e-12 * float(y @ y), "maxiter": 200})
    f, z = float(res.x[0]), float(np.exp(res.x[1]))
    R_all = _in_band(mode_responses(drive[s], p.dt, f, z), p.dt, band)
    R = R_all[inner]
    se_f = _frequency_se(lambda ff: sse(s, ff, z), f, n_eff)
    gains, explained = {}, {}
    judged = DrivenMode(f, se_f, z, s).band_hz()
    for c in MODE_CHANNELS:
        if c not in p.raw:
            continue
        yc = band_part(p.raw[c], p.dt, band)[inner]
        g, pv = _gain_test(R, yc, n_eff)
        if pv < GAIN_P:
            gains[c] = (float(g[0]), float(g[1]))
            yb = band_part(p.raw[c], p.dt, judged)[inner]
            fit = band_part(R_all @ g, p.dt, judged)[inner]
            explained[c] = float(1.0 - np.sum((yb - fit) ** 2) / max(float(yb @ yb), 1e-300))
    if channel not in gains:
        return None
    return DrivenMode(f, se_f, z, s, gains, explained)


def _gain_test(R: np.ndarray, y: np.ndarray, n_eff: int) -> tuple[np.ndarray, float]:
    """Least-squares gains of the band-limited ``y`` on the two responses and the F test's p
    (both zero), with the ``n_eff`` degrees of freedom the band holds (two per Fourier
    ordinate), not one per sample."""
    g, *_ = np.linalg.lstsq(R, y, rcond=None)
    e = y - R @ g
    k = R.shape[1]
    F = float((R @ g) @ (R @ g)) / k / max(float(e @ e) / max(n_eff - k, 1), 1e-300)
    return g, float(stats.f.sf(F, k, max(n_eff - k, 1)))


def _frequency_se(sse, f: float, n_eff: int) -> float:
    """Standard error of the natural frequency from the curvature of the residual sum of
    squares ``sse(f)`` (variable projection: the gains re-solved), the band-limited residual
    white within the band (``n_eff`` degrees of freedom): var f = 2 (SSE/(n_eff − 4)) /
    (∂²SSE/∂f²)."""
    h = 1e-3 * f
    e0, ep, em = sse(f), sse(f + h), sse(f - h)
    curv = (ep - 2.0 * e0 + em) / (h * h)
    return float(np.sqrt(2.0 * e0 / max(n_eff - 4, 1) / curv)) if curv > 0 else float("nan")


def mode_outputs(mode: DrivenMode, p: Prepared) -> dict[str, np.ndarray]:
    """The mode's contribution to each output it rings in, over maneuver ``p`` (from its
    recorded surface, :func:`wiener_surface`); empty when ``p`` does not record that surface."""
    if mode.surface not in p.raw:
        return {}
    R = mode_responses(wiener_surface(p.raw[mode.surface], p.dt), p.dt, mode.frequency_hz, mode.damping)
    return {c: R @ np.asarray(g) for c, g in mode.gains.items()}


def acceptable(mode: DrivenMode | None, peak_hz: float, channel: str) -> bool:
    """Whether a fit is a model of the mode a spectral peak at ``peak_hz`` in ``channel``
    points to (:data:`MAX_DAMPING`, :data:`FREQUENCY_SPAN`, :data:`MIN_EXPLAINED`)."""
    return (mode is not None and mode.damping <= MAX_DAMPING
            and abs(mode.frequency_hz - peak_hz) <= FREQUENCY_SPAN * peak_hz
            and mode.explained.get(channel, 0.0) >= MIN_EXPLAINED)


def attach_mode_models(findings: list, maneuvers: dict) -> None:
    """Fit each structural-mode finding as a driven mode (:func:`fit_driven_mode`), on the
    identification maneuver or, when its input does not ring the mode well enough to fit
    (:func:`acceptable`), on the validation maneuver (then the validation's fit after is a
    fit, not a prediction: ``fitted_on`` says which). The fit goes into the finding's
    ``details['mode_model']`` (None: no recorded surface's response explains the mode, and
    the sensor model's notch stands for it). A fitted mode's natural frequency becomes the
    finding's estimate (the spectral peak, where the resonance meets the input's spectrum,
    is kept in ``details['spectral_peak_hz']``). ``maneuvers``: role -> Prepared."""
    for f in findings:
        if f.effect != "structural_mode":
            continue
        f.details["mode_model"] = None
        for role in ("identification", "validation"):
            p = maneuvers.get(role)
            mode = fit_driven_mode(p, f.channel, f.estimate) if p is not None else None
            if acceptable(mode, f.estimate, f.channel):
                f.details["mode_model"] = mode.as_dict() | {"fitted_on": role}
                f.details["spectral_peak_hz"] = [f.estimate, f.std_error]
                f.estimate, f.std_error = mode.frequency_hz, mode.std_error_hz
                break


def driven_modes(findings: list) -> list[DrivenMode]:
    """The driven-mode models the findings carry (:func:`attach_mode_models`)."""
    return [DrivenMode.from_dict(f.details["mode_model"]) for f in findings
            if f.effect == "structural_mode" and f.details.get("mode_model")]


def with_mode_band(p: Prepared, smooth: dict[str, np.ndarray], modes: list[DrivenMode]) -> dict[str, np.ndarray]:
    """The smoothed record with each modelled mode's band (:meth:`DrivenMode.band_hz`) of what
    the common filter removed put back, in the outputs the mode rings: the mode is motion, not
    noise, and the fit before and after is judged against it (the white noise inside the
    band stays; outside it the record is the smoothed one)."""
    out = dict(smooth)
    for m in modes:
        for c in m.gains:
            if c in p.raw and c in out:
                out[c] = out[c] + band_part(p.raw[c] - smooth[c], p.dt, m.band_hz())
    return out


# The sensor errors a modelled mode's own output can make on the channels it rings in.
MODE_SENSOR_EFFECTS = ("sensor_scale", "sensor_time_skew", "sensor_offset")


def modelled_mode_outputs(findings: list, p: Prepared) -> dict[str, np.ndarray]:
    """The modelled modes' output (:func:`attach_mode_models`, :func:`mode_outputs`) over
    maneuver ``p``, summed per channel."""
    outputs: dict[str, np.ndarray] = {}
    for m in driven_modes(findings):
        for c, x in mode_outputs(m, p).items():
            outputs[c] = outputs.get(c, 0.0) + x
    return outputs


def without_outputs(p: Prepared, outputs: dict[str, np.ndarray]) -> Prepared:
    """Maneuver ``p`` with ``outputs`` taken out of its channels, smoothed and differentiated
    again by its common filter."""
    raw = p.raw | {c: p.raw[c] - x for c, x in outputs.items()}
    smooth = p.smooth | {c: p.filt(raw[c]) for c in outputs}
    deriv = p.deriv | {c: p.differentiate(raw[c]) for c in outputs}
    return replace(p, raw=raw, smooth=smooth, deriv=deriv)


def withhold_sensor_errors_a_peak_makes(findings: list, p: Prepared) -> list:
    """The findings less the kinematic sensor errors (:data:`MODE_SENSOR_EFFECTS` and biases)
    that a spectral peak between the motion's cut-off and the mode search's floor
    (:func:`spectra.sub_floor_peak`, p under :data:`spectra.FISHER_P`) makes; each one withheld
    is deselected with the reason. Asked only where no structural mode is among the findings.

    No mode is named in that band (the maneuver's own motion falls through it), but a mode
    ringing there reaches the kinematic residuals through the products of the rates. The peak
    is taken out of the identification maneuver ``p``'s rates and accelerations as a notch
    (:func:`spectra.notched`) and as the response of each recorded surface whose fit stands for
    it (:func:`fit_driven_mode`, :func:`acceptable`: a mode driven by a surface rings below its
    resonance too, inside the maneuver's band, and on a two-surface input either may fit the
    resonance best). An error that any of these leaves under its entry t, or under the smallest
    size worth naming (:func:`kinematics.is_practical`), is withheld. A probe's F-16 (489 ft/s,
    lateral sweeps) with a 3.96 Hz mode ringing a_z at 0.04 g (its search starting at 6 Hz) had
    a β bias of 0.67° named (t 5.1), an A-4 (613 ft/s, lateral multisine) with a 4.66 Hz mode
    one of 0.28° (t 5.9; probe seeds 4169 and 4197)."""
    suspects = [f for f in findings if f.selected and f.test.startswith("kinematic")
                and (f.effect in MODE_SENSOR_EFFECTS or f.effect == "sensor_bias")]
    if not suspects or any(f.effect == "structural_mode" for f in findings):
        return findings
    peak = sub_floor_peak(p)
    if peak is None or peak.p_value >= FISHER_P:
        return findings
    raw = notched(p.raw, p.dt, peak.frequency_hz)
    removals = {"a notch": {c: p.raw[c] - raw[c] for c in MODE_CHANNELS if c in raw}}
    for s in SURFACES:
        mode = fit_driven_mode(p, peak.channel, peak.frequency_hz, (s,))
        if acceptable(mode, peak.frequency_hz, peak.channel):
            removals[f"a mode driven by {s}"] = mode_outputs(mode, p)
    checks = {how: plausible_kinematic_check(without_outputs(p, outputs)) for how, outputs in removals.items()}
    withheld = set()
    for f in suspects:
        entry = forced_entry_t(f.parameter, p) if f.effect == "sensor_bias" else T_IN
        left = {how: _what_is_left(kinematic_estimate(kin, f.parameter), f.parameter, p.dt)
                for how, kin in checks.items()}
        how = min(left, key=lambda h: left[h][0])
        t, said = left[how]
        if t >= entry:
            continue
        f.selected = False
        f.details["sub_floor_peak"] = {"channel": peak.channel, "frequency_hz": peak.frequency_hz,
                                       "p_value": peak.p_value, "taken_out_as": how, "t": t}
        f.reason = (f"not named: the {peak.channel} spectrum peaks at {peak.frequency_hz:.2f} Hz (p = "
                    f"{peak.p_value:.1g}), under the mode search's floor, where a mode cannot be told from the "
                    f"maneuver's own motion; with that peak taken out of the rates and accelerations as {how} the "
                    f"kinematics {said} (it had been: {f.reason})")
        withheld.add(id(f))
    return [f for f in findings if id(f) not in withheld]


def _what_is_left(found: tuple[float, float] | None, name: str, dt: float) -> tuple[float, str]:
    """A kinematic estimate's |t| where it is still worth naming (0 where it is gone or under
    :func:`kinematics.is_practical`), and what the kinematics then say of it."""
    if found is None or not is_practical(name, found[0], dt):
        return 0.0, "leave none of it worth naming"
    return found[1], f"stand this at t = {found[1]:.1f}, under their entry t"


# The tests whose terms are read off the coefficient mismatch (stepwise_axes, candidates).
MISMATCH_TESTS = ("stepwise", "delay scan")


def withhold_terms_a_mode_makes(findings: list, p: Prepared, reanalysed: Callable[[Prepared], object]) -> list:
    """The findings less the terms read off the coefficient mismatch that the analysis of
    maneuver ``p`` with a modelled mode's output taken out of its channels
    (:func:`modelled_mode_outputs`, :func:`without_outputs`; ``reanalysed`` runs it and returns
    its Analysis) no longer names; each one withheld is deselected with the reason. A mode
    driven by a surface rings below its resonance too, in the rigid-body band, where q̇ and
    the accelerations carry it into the measured moment and force coefficients as the
    surface's own derivative: a probe's F-4N (24,700 ft / 545 ft/s, three-axis sweeps at
    40 Hz, q̇ recorded) with a 10.5 Hz mode driven by the stabilator in q, a_x and a_z had the
    mode named and beside it C_X,δe −0.19 and C_m,δe −1.23 (t −11 and −8), confirmed by the
    validation maneuver, which rang the same mode (probe seed 3680)."""
    terms = [f for f in findings if f.selected and f.test.startswith(MISMATCH_TESTS)]
    outputs = modelled_mode_outputs(findings, p) if terms else {}
    if not outputs:
        return findings
    again = {(c.channel, c.parameter): c for c in reanalysed(without_outputs(p, outputs)).candidates}
    withheld = set()
    for f in terms:
        other = again.get((f.channel, f.parameter))
        if other is None or not other.selected:
            said = "not a candidate" if other is None else f"t = {other.t:.1f}, {other.reason}"
            _withhold_for_the_mode(f, outputs, f"the analysis no longer names it ({said})")
            withheld.add(id(f))
    return [f for f in findings if id(f) not in withheld]


def _withhold_for_the_mode(f, outputs: dict, said: str) -> None:
    """Deselect finding ``f``, saying what ``said`` with the mode's ``outputs`` taken out."""
    f.selected = False
    f.reason = (f"not named: with the named mode's output taken out of {', '.join(sorted(outputs))} {said}; the "
                f"mode, driven by a surface, rings below its resonance too (it had been: {f.reason})")


def withhold_sensor_errors_a_mode_makes(findings: list, p: Prepared) -> list:
    """The findings less the sensor errors (:data:`MODE_SENSOR_EFFECTS`) that the kinematics no
    longer take, at their entry t, with a modelled mode's output (:func:`attach_mode_models`)
    over the identification maneuver ``p`` taken out of the channels it rings in
    (:func:`mode_outputs`); each one withheld is deselected with the reason. A mode driven by
    a surface rings below its resonance too (its quasi-static part follows the surface's
    rate), inside the maneuver's band, where the kinematics read it as the gyro's own error:
    a probe's F-4N (16,100 ft / 679 ft/s, three-axis 2-1-1s at 50 Hz) with a 10.1 Hz mode
    driven by the stabilator's rate in q and a_z had the mode named, and beside it a q skew of
    30 ms and a q scale of +0.097 (t 7.7 and 7.3). A channel the mode does not ring in is
    asked too, its kinematics being built from those it does: a noise-free A-4 (9,100 ft /
    659 ft/s, 100 Hz) with a 9.4 Hz mode in q and a_z had an α scale of −0.081 (t −8.6)
    named beside it (probe seed 3518)."""
    outputs = modelled_mode_outputs(findings, p)
    suspects = {id(f) for f in findings if f.effect in MODE_SENSOR_EFFECTS} if outputs else set()
    if not suspects:
        return findings
    kin = plausible_kinematic_check(without_outputs(p, outputs))
    withheld = set()
    for f in findings:
        found = kinematic_estimate(kin, f.parameter) if id(f) in suspects else None
        if id(f) in suspects and (found is None or found[1] < T_IN):
            t = 0.0 if found is None else found[1]
            _withhold_for_the_mode(f, outputs, f"the kinematics stand it at t = {t:.1f}, under their entry t")
            withheld.add(id(f))
    return [f for f in findings if id(f) not in withheld]

