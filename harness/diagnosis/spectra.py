"""Effects seen in spectra and in the replay: a structural mode (a narrow peak in the
high-frequency part of the rate and acceleration signals) and turbulence (gusts: the
air-relative and inertial velocities disagree broadband while the aerodynamics agree)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, signal, stats

from estimators.colored_stepwise import colored_fit
from estimators.smoothing import sine_series_filter
from harness.diagnosis.prepare import Prepared, interior_slice
from models.constants import SURFACES

MODE_CHANNELS = ("p", "q", "r", "ax", "ay", "az")
FISHER_P = 1e-6  # a peak must beat white noise at this level (Fisher's g test, all channels)
# A surface's spectral line (an input harmonic): an ordinate of its spectrum that beats its
# local median at this level, one ordinate tested (:func:`input_lines`).
INPUT_LINE_P = 1e-3
# A peak on a surface's line is that line's echo unless it stands further above its median
# than the line does by more than the two spectra's scatter allows at this level
# (F(dof, dof), :func:`echoes`).
ECHO_P = 0.05
# The surfaces that drive each channel a mode is sought in (an echo needs its input).
MODE_DRIVERS = {"q": ("de",), "ax": ("de",), "az": ("de",), "p": ("da", "dr"), "r": ("da", "dr"), "ay": ("da", "dr")}
# The surfaces whose lines each channel can echo (:func:`echoes`): an accelerometer off the c.g.
# reads ω̇ × r, every surface's rate response, on every axis. A probe's J-3 Cub (100 ft/s,
# lateral doublets, the accelerometer 5.3 ft left) had a 4.95 Hz "mode" named in a_x, the fifth
# harmonic of its aileron doublet read through ṙ·y (probe seed 4082).
ECHO_DRIVERS = MODE_DRIVERS | {c: ("de", "da", "dr") for c in ("ax", "ay", "az")}
# The other maneuver's spectrum, at a mode frequency one record found (p < FISHER_P), shows
# the mode too at this level (:func:`peak_at`: three ordinates at a frequency given in advance).
MODE_CONFIRM_P = 0.01
GUST_HIGHPASS_HZ = 0.05  # the gust estimate drops what sensor-bias drift puts below this
# The highest cut-off the mode search takes a record's motion to end at. The common filter's
# cut-off is where the record's signal meets its noise: on a quiet record (a noise-free one
# reaches 37 Hz) that keeps a 9 Hz mode as motion, and its in-band part was then read as an α
# scale (an A-4 at 100 Hz, probe seed 3518, 7 Dec 2026). Rigid-body modes of full-scale
# aircraft lie below about 1.2 Hz, and the best smoothing cut-off lies about 0.5 Hz above a
# signal's band (Morelli, Practical Aspects of the Equation-Error Method, Eq. 18 and the
# smoothing section); 3 Hz leaves room for a light aircraft's roll mode and an actuator's
# roll-off.
RIGID_BODY_CUTOFF_HZ = 3.0
# The mode search starts this many times above the motion's cut-off (:func:`search_floor_hz`),
# where the maneuver itself has little power left: from 6 Hz at the latest. At three times
# (9 Hz) a probe's J-3 Cub (111 ft/s, pitch 3-2-1-1, noise half flight test's) rang a 6.5 Hz
# wing mode at 0.8 deg/s in q unseen (probe seed 4078). At 1.5 times the outside sweep's
# c172x lateral maneuvers (cut-offs 1.5-1.9 Hz) gave "modes" at 1.9-2.4 Hz, the shoulder of
# their own roll motion. A peak must still beat its running median and be no echo of an
# input's line (:func:`structural_peak`).
MOTION_POWER_FACTOR = 2.0


@dataclass(frozen=True)
class PeakTest:
    channel: str
    frequency_hz: float
    std_error_hz: float
    amplitude: float
    g: float          # the peak's periodogram ordinate over its local median
    p_value: float
    share: float = float("nan")  # the peak's excess power over the variance of what the filter leaves


def peak_p_value(ratio: float, m: int, dof: float) -> float:
    """Chance that noise puts one of ``m`` spectral ordinates ``ratio`` times above its
    local median, each ordinate an average with ``dof`` degrees of freedom (χ²_dof/dof
    times the true level, whose median is ``chi2.median(dof)/dof`` of it); Bonferroni over
    ``m``."""
    level = ratio * stats.chi2.median(dof)
    return float(min(1.0, m * stats.chi2.sf(level, dof)))


def welch_dof(n: int, nperseg: int) -> float:
    """Degrees of freedom of a Hann-window Welch estimate with 50 % overlap: 2 per segment,
    times 0.95 for the overlap's correlation (Welch 1967; Percival & Walden 1993, §6.17)."""
    segments = max(1, (n - nperseg) // (nperseg // 2) + 1)
    return 2.0 * segments * (0.95 if segments > 1 else 1.0)


def structural_peak(p: Prepared, f_min_hz: float = 2.0, segment_s: float = 2.0,
                    half_width_hz: float = 2.5, band_hz: tuple[float, float] | None = None) -> PeakTest | None:
    """The most significant peak in what the motion leaves of each rate and acceleration
    channel (:func:`mode_residual`), above :func:`search_floor_hz` (where the maneuver itself
    has little power), or within ``band_hz`` when given (:func:`sub_floor_peak`).

    The spectrum is Welch's (Hann, ``segment_s`` segments, 50 % overlap): averaging makes a
    lightly damped mode, rung by each input and decaying within a second or two, a peak a
    few bins wide rather than a scatter of single-ordinate spikes. Each ordinate is compared
    with the running median within ``half_width_hz``, so coloured (sloping) noise is not a
    peak, and only a local maximum of the spectrum (:func:`local_maxima`) is a candidate. The
    frequency is the power-weighted centroid of the peak bin and its neighbours. A peak that
    is the echo of a line a surface driving the channel carries (:func:`echoes`: a harmonic
    of the input, which a fast roll mode follows up to several hertz) is not a candidate."""
    best = None
    fs = 1.0 / p.dt
    nper = int(round(segment_s * fs))
    if p.n < 4 * nper:
        return None
    dof = welch_dof(p.n, nper)
    lines = input_lines(p, nper, dof, half_width_hz)
    for c in MODE_CHANNELS:
        if c not in p.raw:
            continue
        x = mode_residual(p, c)
        f, P, med, w = _median_spectrum(x, fs, nper, half_width_hz)
        df = f[1] - f[0]
        # the top 10 % below Nyquist is left out: the median window is one-sided there
        low, high = band_hz if band_hz is not None else (search_floor_hz(p, f_min_hz), 0.9 * f[-1])
        band = (f >= low) & (f <= min(high, 0.9 * f[-1]))
        if band.sum() < 2 * w:
            continue
        idx = np.flatnonzero(band & local_maxima(P))
        ratio = peak_ratios(P, med, idx)
        keep = ~echoes(ratio, idx, c, lines, dof)
        idx, ratio = idx[keep], ratio[keep]
        if idx.size == 0:
            continue
        k = int(idx[np.argmax(ratio)])
        pv = peak_p_value(float(ratio.max()), int(band.sum()), dof)
        if best is None or pv < best.p_value:
            nb = slice(max(k - 1, 0), min(k + 2, f.size))
            excess = np.maximum(P[nb] - med[nb], 0.0)
            fc, se = _refine(x, fs, float(f[k]), df, nper)
            power = float(np.sum(excess) * df)
            best = PeakTest(c, fc, se, float(np.sqrt(power)), float(ratio.max()), pv,
                            power / max(float(np.var(x)), 1e-300))
    return best


def peak_at(p: Prepared, channel: str, frequency_hz: float, segment_s: float = 2.0,
            half_width_hz: float = 2.5, f_min_hz: float = 2.0) -> float:
    """How likely noise alone puts the spectrum of ``channel`` (what the common filter leaves)
    as far above its running median as it stands within one bin of ``frequency_hz``, a
    frequency given in advance (another record's peak): :func:`peak_p_value` of the largest
    of those three ordinates' ratios, Bonferroni over the three; 1 when that ordinate is the
    echo of a surface's line (:func:`echoes`). NaN when the record cannot tell (see
    :func:`untestable_at`)."""
    if untestable_at(p, channel, frequency_hz, segment_s, f_min_hz):
        return float("nan")
    fs = 1.0 / p.dt
    nper = int(round(segment_s * fs))
    dof = welch_dof(p.n, nper)
    f, P, med, _ = _median_spectrum(mode_residual(p, channel), fs, nper, half_width_hz)
    k = int(np.argmin(np.abs(f - frequency_hz)))
    near = np.arange(max(k - 1, 0), min(k + 2, f.size))
    ratios = P[near] / np.maximum(med[near], 1e-300)
    j = int(np.argmax(ratios))
    if echoes(ratios[j:j + 1], near[j:j + 1], channel, input_lines(p, nper, dof, half_width_hz), dof)[0]:
        return 1.0
    return peak_p_value(float(ratios[j]), near.size, dof)


def predicted_peak_p(p: Prepared, pv: Prepared, channel: str, frequency_hz: float, segment_s: float = 2.0,
                     half_width_hz: float = 2.5) -> float:
    """How clearly record ``p`` should show the mode record ``pv`` shows on ``channel`` at
    ``frequency_hz``, had it rung it: ``pv``'s excess over its running median there, scaled
    by how much less power the surfaces driving the channel (:data:`MODE_DRIVERS`) carry at that
    frequency in ``p`` than in ``pv`` (the largest ratio over them, within a bin, of the power
    above each surface's white sensor floor, the median of its top band, 0.7-0.9 of Nyquist: a
    mode rings in proportion to its input's power at its frequency), over ``p``'s own median;
    :func:`peak_p_value` of that ratio, Bonferroni over three ordinates. A record whose
    driving surfaces carry nothing above their floor there cannot ring the mode. NaN where
    either record cannot tell (:func:`untestable_at`) or no driving surface is recorded in
    both."""
    if untestable_at(p, channel, frequency_hz, segment_s) or untestable_at(pv, channel, frequency_hz, segment_s):
        return float("nan")
    surfaces = [s for s in MODE_DRIVERS.get(channel, ()) if s in p.raw and s in pv.raw]
    if not surfaces:
        return float("nan")

    def spectrum(r: Prepared, c: str):
        nper = int(round(segment_s / r.dt))
        f, P, med, _ = _median_spectrum(mode_residual(r, c), 1.0 / r.dt, nper, half_width_hz)
        k = int(np.argmin(np.abs(f - frequency_hz)))
        near = slice(max(k - 1, 0), min(k + 2, f.size))
        return P[near], med[near], float(np.median(P[(f >= 0.7 * f[-1]) & (f <= 0.9 * f[-1])]))

    def drive(r: Prepared, s: str) -> float:  # the surface's power there above its sensor's white floor
        P, _, floor = spectrum(r, s)
        return max(float(np.max(P)) - floor, 0.0)

    scale = max(drive(p, s) / max(drive(pv, s), 1e-300) for s in surfaces)
    P_v, med_v, _ = spectrum(pv, channel)
    med_i = spectrum(p, channel)[1]
    excess = float(np.max(P_v - med_v))
    ratio = 1.0 + min(scale, 1.0) * max(excess, 0.0) / max(float(np.median(med_i)), 1e-300)
    return peak_p_value(ratio, 3, welch_dof(p.n, int(round(segment_s / p.dt))))


def untestable_at(p: Prepared, channel: str, frequency_hz: float, segment_s: float = 2.0,
                  f_min_hz: float = 2.0) -> str:
    """Why record ``p`` cannot show a mode of ``channel`` at ``frequency_hz`` ('' when it can):
    the channel is not recorded, the record is shorter than four Welch segments, or the
    frequency lies outside the band :func:`structural_peak` searches (below
    :func:`search_floor_hz`; above 0.9 times Nyquist)."""
    fs = 1.0 / p.dt
    if channel not in p.raw:
        return f"it does not record {channel}"
    if p.n < 4 * int(round(segment_s * fs)):
        return f"it is shorter than {4 * segment_s:g} s"
    low = search_floor_hz(p, f_min_hz)
    cut = motion_cutoff_hz(p)
    if low >= 0.45 * fs:
        return (f"it has no spectral band to search: {MOTION_POWER_FACTOR:g} times its motion's cut-off of "
                f"{cut:.1f} Hz lies above 0.9 of Nyquist ({0.45 * fs:.1f} Hz), its smoothing keeping everything "
                "below as motion")
    if not low <= frequency_hz <= 0.9 * 0.5 * fs:
        return (f"its spectral band is {low:.1f}-{0.45 * fs:.1f} Hz (from {f_min_hz:g} Hz or "
                f"{MOTION_POWER_FACTOR:g} times its motion's cut-off of {cut:.1f} Hz, whichever is higher, up to 0.9 "
                "of Nyquist)")
    return ""


def sub_floor_peak(p: Prepared, f_min_hz: float = 2.0) -> PeakTest | None:
    """The most significant peak (:func:`structural_peak`, its running median within
    :data:`SUB_FLOOR_HALF_WIDTH_HZ`) between the motion's cut-off (:func:`motion_cutoff_hz`,
    at least ``f_min_hz``) and the mode search's floor (:func:`search_floor_hz`): where a mode
    and the maneuver's own motion cannot be told apart, so none is named there, but a sensor
    error the kinematics read there is suspect
    (:func:`mode_model.withhold_sensor_errors_a_peak_makes`). None when that band is empty."""
    low, high = max(f_min_hz, motion_cutoff_hz(p)), search_floor_hz(p, f_min_hz)
    if high <= low:
        return None
    return structural_peak(p, f_min_hz, half_width_hz=SUB_FLOOR_HALF_WIDTH_HZ, band_hz=(low, high))


# The running median's half-width in :func:`sub_floor_peak`: its band is a few hertz wide
# (3-6 Hz at the widest), under the two windows :func:`structural_peak` needs at 2.5 Hz.
SUB_FLOOR_HALF_WIDTH_HZ = 1.5


# Quality factor of the sensor model's notch for a structural mode (bandwidth f0/Q): wide
# enough for the mode's frequency uncertainty (a 2 s Welch segment resolves 0.5 Hz).
MODE_NOTCH_Q = 8.0


def notched(raw: dict[str, np.ndarray], dt: float, frequency_hz: float) -> dict[str, np.ndarray]:
    """Channels ``raw`` (sample interval ``dt``) with their rates and accelerations
    (:data:`MODE_CHANNELS`) notched at ``frequency_hz`` (scipy.signal.iirnotch,
    :data:`MODE_NOTCH_Q`, zero phase); ``raw`` unchanged when the frequency lies outside
    (0, Nyquist)."""
    fs = 1.0 / dt
    if not 0.0 < frequency_hz < 0.5 * fs:
        return raw
    b, a = signal.iirnotch(frequency_hz, MODE_NOTCH_Q, fs=fs)
    return raw | {c: signal.filtfilt(b, a, raw[c]) for c in MODE_CHANNELS if c in raw}


def motion_cutoff_hz(p: Prepared) -> float:
    """Where the mode search takes record ``p``'s motion to end: its common filter's cut-off,
    at most :data:`RIGID_BODY_CUTOFF_HZ`."""
    return min(p.common_cutoff_hz, RIGID_BODY_CUTOFF_HZ)


def search_floor_hz(p: Prepared, f_min_hz: float = 2.0) -> float:
    """The lowest frequency the mode search looks at: ``f_min_hz`` or
    :data:`MOTION_POWER_FACTOR` times :func:`motion_cutoff_hz`, whichever is higher (the
    maneuver itself has little power there)."""
    return max(f_min_hz, MOTION_POWER_FACTOR * motion_cutoff_hz(p))


def mode_residual(p: Prepared, channel: str) -> np.ndarray:
    """What the motion leaves of ``channel``: the record less its common filter's output, that
    filter's sine-series weights cut at :func:`motion_cutoff_hz` (unchanged where the common
    cut-off lies below it)."""
    if p.common_cutoff_hz <= RIGID_BODY_CUTOFF_HZ:
        return p.raw[channel] - p.smooth[channel]
    k = np.arange(1, p.weights.size + 1)
    weights = np.where(k / (2.0 * p.t[-1]) <= RIGID_BODY_CUTOFF_HZ, p.weights, 0.0)
    return p.raw[channel] - sine_series_filter(p.raw[channel], weights)


def _median_spectrum(x: np.ndarray, fs: float, nper: int,
                     half_width_hz: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Welch's spectrum of ``x`` (Hann, ``nper`` segments, 50 % overlap), its running median
    within ``half_width_hz`` (at least three ordinates) either side, and that half-width in
    ordinates."""
    f, P = signal.welch(x, fs=fs, window="hann", nperseg=nper, noverlap=nper // 2, detrend="linear")
    w = max(3, int(round(half_width_hz / (f[1] - f[0]))))
    return f, P, ndimage.median_filter(P, size=2 * w + 1, mode="nearest"), w


def input_lines(p: Prepared, nper: int, dof: float, half_width_hz: float) -> dict[str, np.ndarray]:
    """Each recorded surface's spectral lines: at each ordinate of what the common filter
    leaves of it, how far a local maximum that beats its running median at p <
    :data:`INPUT_LINE_P` (:func:`peak_p_value`, one ordinate) stands above that median, the
    largest within a bin either side (0 where there is no line). An input's harmonics are
    such lines: a multisine's components, a square wave's odd harmonics through the
    actuator."""
    out = {}
    fs = 1.0 / p.dt
    for s in SURFACES:
        if s not in p.raw:
            continue
        f, P, med, _ = _median_spectrum(mode_residual(p, s), fs, nper, half_width_hz)
        idx = np.flatnonzero(local_maxima(P))
        ratio = P[idx] / np.maximum(med[idx], 1e-300)
        line = np.zeros(f.size)
        for k, r in zip(idx, ratio):
            if peak_p_value(float(r), 1, dof) < INPUT_LINE_P:
                sl = slice(max(k - 1, 0), k + 2)
                line[sl] = np.maximum(line[sl], r)
        out[s] = line
    return out


def echoes(ratio: np.ndarray, idx: np.ndarray, channel: str, lines: dict[str, np.ndarray],
           dof: float) -> np.ndarray:
    """Which peaks (ordinates ``idx`` of ``channel``, standing ``ratio`` times above their
    running median) are echoes of an input's line: a surface whose lines the channel can echo
    (:data:`ECHO_DRIVERS`) carries a line there (:func:`input_lines`), and the peak stands no
    further above its median than the line does, within the scatter of two independent
    spectral estimates (the ratio of the two ratios tested as F(dof, dof) at
    :data:`ECHO_P`). The rigid body passes an input's line on to the output with a transfer
    function smooth across the median's window, so the output's line stands at most as far
    above its median as the input's (less where the output's noise fills the median): a
    c172x three-axis maneuver's roll rate peaked at 5.0 Hz (p = 1e-9 against noise, 2.8
    times its median) on its aileron's line (2.5 times; outside sweep, 4 Dec 2026). A
    flexible mode rings far above the line that excites it (an F-16's 8 Hz mode at 2.9 times
    its median on a 1.8 times stabilator line)."""
    out = np.zeros(idx.size, dtype=bool)
    for s in ECHO_DRIVERS.get(channel, ()):
        line = lines.get(s)
        if line is None:
            continue
        r_in = line[idx]
        hit = r_in > 0
        out[hit] |= stats.f.sf(ratio[hit] / r_in[hit], dof, dof) >= ECHO_P
    return out


def peak_ratios(P: np.ndarray, median: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """How far each local maximum ``peaks`` of the spectrum ``P`` stands above the noise
    around it: the smaller of its level over the running ``median`` and over its base, the
    higher of the two valleys that part it from higher ground on either side
    (:func:`scipy.signal.peak_prominences`: the level less the prominence). A mode's peak
    rises from the noise floor on both sides, so the two agree; the shoulder of the
    maneuver's own spectrum, falling through the band's lower edge, has a ripple for a
    valley on its low side, as high as itself, however far it stands above the median (the
    F-16's roll response at 600 ft/s: a 2.4 Hz "mode" at the band's edge, 3.0 times its
    median, 1.01 times its base)."""
    level = P[peaks]
    base = level - signal.peak_prominences(P, peaks)[0]
    over_median = np.where(median[peaks] > 0, level / np.maximum(median[peaks], 1e-300), 0.0)
    over_base = np.where(base > 0, level / np.maximum(base, 1e-300), np.inf)
    return np.minimum(over_median, over_base)


def local_maxima(P: np.ndarray) -> np.ndarray:
    """Where the spectrum ``P`` stands above the ordinates on either side: a mode's peak. The
    shoulder of the maneuver's own spectrum, falling through the band's lower edge, is not
    one however far it stands above the running median (which the quiet ordinates below the
    common filter's cut-off pull down). A flat top counts once, at its middle
    (:func:`scipy.signal.find_peaks`)."""
    out = np.zeros(P.size, dtype=bool)
    out[signal.find_peaks(P)[0]] = True
    return out


def _refine(x: np.ndarray, fs: float, f_peak: float, df: float, nper: int) -> tuple[float, float]:
    """The mode frequency between Welch's bins: the same averaged spectrum zero-padded eight
    times (an interpolation, no new resolution), its power-weighted centroid over the part
    of the peak within one bin of ``f_peak`` above half its height. The standard error is
    half a bin: a mode rung by steps peaks where its resonance meets the input's spectrum, a
    few tenths of a hertz from its natural frequency (0.2-0.4 Hz for the gallery's 8 Hz
    mode under a 3-2-1-1)."""
    f, P = signal.welch(x, fs=fs, window="hann", nperseg=nper, noverlap=nper // 2, nfft=8 * nper, detrend="linear")
    near = (f >= f_peak - df) & (f <= f_peak + df)
    floor = float(np.median(P[(f >= f_peak - 5 * df) & (f <= f_peak + 5 * df)]))
    excess = np.maximum(P[near] - floor, 0.0)
    if excess.max() <= 0:
        return f_peak, df / 2.0
    keep = excess >= 0.5 * excess.max()
    return float(np.sum(excess[keep] * f[near][keep]) / np.sum(excess[keep])), df / 2.0


@dataclass(frozen=True)
class GustEstimate:
    sigma_w_fps: float
    sigma_v_fps: float
    ratio_to_noise: float
    w_fps: np.ndarray | None = None  # the body-axis gust histories (air-mass velocity, z, y, x)
    v_fps: np.ndarray | None = None
    u_fps: np.ndarray | None = None


def gust_estimate(kin_residuals: dict[str, np.ndarray], p: Prepared, noise_accel_fps2: float) -> GustEstimate:
    """RMS gust velocities from the kinematic residuals of the w and v equations: in
    turbulence the air-relative velocity differs from the inertial one by the gust, so
    E_w ≈ ẇ_gust; its integral (high-passed at 0.05 Hz to drop sensor-bias drift) is the gust."""
    b, a = signal.butter(2, GUST_HIGHPASS_HZ, btype="highpass", fs=1.0 / p.dt)
    inner = interior_slice(p.n, p.dt)

    def gust(e: np.ndarray) -> np.ndarray:
        # E = d(air-relative)/dt - d(inertial)/dt = -d(air-mass velocity)/dt, body axes
        return -signal.filtfilt(b, a, np.cumsum(e) * p.dt)
    gw, gv = gust(kin_residuals["w"]), gust(kin_residuals.get("v", np.zeros(p.n)))
    sw, sv = float(np.std(gw[inner])), float(np.std(gv[inner]))
    # what white sensor noise alone gives: the operator (integrate, high-pass) is nearly
    # time-invariant, so the variance it passes is σ² times the energy of its response to
    # one impulse (mid-record, away from the ends) -- no random draw needed
    impulse = np.zeros(p.n)
    impulse[p.n // 2] = 1.0
    response = signal.filtfilt(b, a, np.cumsum(impulse) * p.dt)
    floor = noise_accel_fps2 * float(np.sqrt(np.sum(response ** 2)))
    gu = gust(kin_residuals["u"]) if "u" in kin_residuals else None
    return GustEstimate(sw, sv, max(sw, sv) / max(floor, 1e-12), gw, gv, gu)


@dataclass(frozen=True)
class AirShare:
    """How much of the vane-against-inertial angle difference the aerodynamics followed."""
    share: float       # 1 - k: 0 when the difference is all vane error, 1 when it is all air
    std_error: float   # colored-residual standard error (seed Eq. 40)
    angle_rad: float   # RMS of the angle difference (integrated, high-passed kinematic residual / V)


def air_share(angle_difference: np.ndarray, slope: np.ndarray, mismatch: np.ndarray,
              nuisances: list[np.ndarray], dt: float) -> AirShare:
    """Tell gusts from vane errors by what the aerodynamics did.

    The kinematic residual gives the difference e between the vane's angle and the one the
    inertial channels integrate to (:func:`gust_estimate`: e = -w_gust/V). If e is vane
    error n, the model evaluated along the vane is off by C_α·n, and the measured-minus-model
    coefficient carries ΔC = -C_α·n = -C_α·e; if e is air (a gust), the aircraft flew the
    vane's angle and ΔC carries none of it. The least-squares k in
    ΔC = k·(-C_α e) + nuisances + b, both high-passed as the gust estimate is, is the share
    that is vane error, and 1 - k the share that is air.

    Parameters
    ----------
    angle_difference : e (rad), the gust history over the airspeed with its sign flipped.
    slope : the model's ∂C/∂α along the states (per rad), C_Z's for the vertical gust.
    mismatch : the measured-minus-model coefficient ΔC.
    nuisances : maneuver-driven columns (the measured states) that soak up model error
        correlated with the maneuver.
    dt : sample interval (s).

    Returns
    -------
    AirShare with 1 - k, its colored-residual standard error and the RMS of e; the first and
    last second are left out, where the filters start.
    """
    b, a = signal.butter(2, GUST_HIGHPASS_HZ, btype="highpass", fs=1.0 / dt)
    inner = interior_slice(len(mismatch), dt)

    def hp(x: np.ndarray) -> np.ndarray:
        return signal.filtfilt(b, a, np.asarray(x, dtype=float))[inner]
    e = np.asarray(angle_difference, dtype=float)
    theta, se, _ = colored_fit(hp(mismatch), [(-slope * e)[inner]] + [hp(x) for x in nuisances],
                               ["k"] + [f"n{i}" for i in range(len(nuisances))])
    return AirShare(1.0 - float(theta[0]), float(se[0]), float(np.std(e[inner])))


def gust_wind_ned(gust: GustEstimate, phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> dict[str, np.ndarray]:
    """The estimated body-axis gust (u, v, w) as a wind in north-east-down axes (ft/s), for
    replaying the flight through the turbulence it met: C_nb = (R_z(ψ) R_y(θ) R_x(φ))."""
    u = gust.u_fps if gust.u_fps is not None else np.zeros_like(phi)
    v = gust.v_fps if gust.v_fps is not None else np.zeros_like(phi)
    w = gust.w_fps if gust.w_fps is not None else np.zeros_like(phi)
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    north = u * (ct * cp) + v * (cp * st * sf - sp * cf) + w * (cp * st * cf + sp * sf)
    east = u * (ct * sp) + v * (sp * st * sf + cp * cf) + w * (sp * st * cf - cp * sf)
    down = -u * st + v * (ct * sf) + w * (ct * cf)
    return {"north": north, "east": east, "down": down}
