"""Effects seen in spectra and in the replay: a structural mode (a narrow peak in the
high-frequency part of the rate and acceleration signals) and turbulence (gusts: the
air-relative and inertial velocities disagree broadband while the aerodynamics agree)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, signal

from harness.diagnosis.prepare import Prepared

MODE_CHANNELS = ("p", "q", "r", "ax", "ay", "az")
FISHER_P = 1e-6  # a peak must beat white noise at this level (Fisher's g test, all channels)


@dataclass(frozen=True)
class PeakTest:
    channel: str
    frequency_hz: float
    std_error_hz: float
    amplitude: float
    g: float          # the peak's periodogram ordinate over its local median
    p_value: float


def peak_p_value(ratio: float, m: int) -> float:
    """Chance that white-ish noise puts one of ``m`` periodogram ordinates ``ratio`` times
    above its local median: an ordinate is exponentially distributed (χ²₂/2), whose median
    is ln 2 times its mean, so P(P_k > r·median) = 2^(−r); Bonferroni over ``m``."""
    return float(min(1.0, m * 2.0 ** (-ratio)))


def structural_peak(p: Prepared, f_min_hz: float = 2.0, half_width_hz: float = 0.5) -> PeakTest | None:
    """The most significant narrow peak in what the recording's common filter leaves of each
    rate and acceleration channel, above ``f_min_hz`` and three times the filter's cut-off
    (where the maneuver itself has little power). Each periodogram ordinate is compared with the running median of its
    neighbours within ``half_width_hz``, so coloured (sloping) noise is not a peak."""
    best = None
    for c in MODE_CHANNELS:
        if c not in p.raw:
            continue
        x = p.raw[c] - p.smooth[c]
        f, P = signal.periodogram(x, fs=1.0 / p.dt, window="hann", detrend="linear")
        df = f[1] - f[0]
        w = max(5, int(round(half_width_hz / df)) | 1)
        med = ndimage.median_filter(P, size=2 * w + 1, mode="nearest")
        # the top 10 % below Nyquist is left out: the periodogram's last ordinates are not
        # exponentially distributed (real-valued at Nyquist) and the median window is one-sided there
        band = (f >= max(f_min_hz, 3.0 * p.common_cutoff_hz)) & (f <= 0.9 * f[-1])
        if band.sum() < 2 * w:
            continue
        ratio = np.where(med > 0, P / np.maximum(med, 1e-300), 0.0)[band]
        k = int(np.argmax(ratio))
        pv = peak_p_value(float(ratio[k]), int(band.sum()))
        if best is None or pv < best.p_value:
            T = p.t[-1]
            best = PeakTest(c, float(f[band][k]), float(np.sqrt(6.0) / (np.pi * T * np.sqrt(max(ratio[k], 1.0)))),
                            float(np.sqrt(2.0 * P[band][k] * df)), float(ratio[k]), pv)
    return best


@dataclass(frozen=True)
class GustEstimate:
    sigma_w_fps: float
    sigma_v_fps: float
    ratio_to_noise: float


def gust_estimate(kin_residuals: dict[str, np.ndarray], p: Prepared, noise_accel_fps2: float) -> GustEstimate:
    """RMS gust velocities from the kinematic residuals of the w and v equations: in
    turbulence the air-relative velocity differs from the inertial one by the gust, so
    E_w ≈ ẇ_gust; its integral (high-passed at 0.05 Hz to drop sensor-bias drift) is the gust."""
    b, a = signal.butter(2, 0.05, btype="highpass", fs=1.0 / p.dt)
    k = max(1, int(round(1.0 / p.dt)))

    def sigma(e: np.ndarray) -> float:
        g = signal.filtfilt(b, a, np.cumsum(e) * p.dt)
        return float(np.std(g[k:-k]))
    sw, sv = sigma(kin_residuals["w"]), sigma(kin_residuals.get("v", np.zeros(p.n)))
    # what sensor noise alone gives: the same integral of the acceleration noise level
    rng = np.random.default_rng(0)
    floor = np.mean([sigma(rng.normal(0.0, noise_accel_fps2, p.n)) for _ in range(4)])
    return GustEstimate(sw, sv, max(sw, sv) / max(floor, 1e-12))
