"""The α vane's wander below the gust estimate's high-pass: a term is named only when it
stands beside what that unseen part of the vane's error could put in the mismatch.

Where the model is evaluated along the α vane, the vane's error e passes into C_m's
mismatch as −C_m,α·e (errors in variables), and the fit carries the vane's error column
(:func:`stepwise_axes.vane_noise_columns`) to take it out. That column is the vane's angle
less the inertial one, high-passed at :data:`spectra.GUST_HIGHPASS_HZ` because below it the
inertial integration drifts; a Gauss-Markov wander (τ about 1 s) is flat there, so its
slowest part stays in the mismatch, unmodelled. The colored-residual standard error
(Eq. 40, from the residual's sample autocorrelation over one record) does not cover it for
a column as slow as a drift term's ΔV/V, whose one slow swing the unseen wander follows by
chance as readily as anything. Its share of a term's variance is sized here from the vane
column's own spectrum just above the high-pass, taken as flat below it.
"""
from __future__ import annotations

import numpy as np
from scipy import signal

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import interior
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.spectra import GUST_HIGHPASS_HZ
from harness.diagnosis.stepwise_axes import StepwiseFits
from harness.diagnosis.term_rules import terms_beside_the_vane_column

__all__ = ["WANDER_BAND_HZ", "slow_wander_std_error", "wander_level", "withhold_within_the_unseen_wander"]

# The band the vane column's spectral level is read in: from the gust high-pass to four
# times it (0.05-0.2 Hz; a wander of τ = 1 s has fallen by 2.6 at the top, the inertial
# integration's 1/f² drift rises toward the bottom, and a 28 s record gives about six
# ordinates there).
WANDER_BAND_HZ = (GUST_HIGHPASS_HZ, 4.0 * GUST_HIGHPASS_HZ)


def wander_level(column: np.ndarray, dt: float, band: tuple[float, float] = WANDER_BAND_HZ,
                 highpass_hz: float = GUST_HIGHPASS_HZ) -> float:
    """The two-sided power spectral density (units²/Hz) of the process a high-passed column
    was made from, read from the column's periodogram in ``band`` with the forward-backward
    second-order Butterworth high-pass at ``highpass_hz`` (as :func:`spectra.gust_estimate`
    applies it, gain |H|⁴) divided out; the mean over the band's ordinates."""
    fs = 1.0 / dt
    f, one_sided = signal.periodogram(np.asarray(column, dtype=float), fs=fs, detrend="constant")
    periodogram = 0.5 * one_sided  # two-sided inside the band (DC and Nyquist lie outside it)
    b, a = signal.butter(2, highpass_hz, btype="highpass", fs=fs)
    _, gain = signal.freqz(b, a, worN=f, fs=fs)
    inside = (f >= band[0]) & (f < band[1]) & (np.abs(gain) ** 4 > 0.1)
    if not inside.any():
        return 0.0
    return float(np.mean(periodogram[inside] / np.abs(gain[inside]) ** 4))


def slow_wander_std_error(weights: np.ndarray, level: float, dt: float, below_hz: float = GUST_HIGHPASS_HZ) -> float:
    """The standard error a stationary error of flat two-sided density ``level`` below
    ``below_hz`` (none above) gives an estimate θ = Σ wₙ xₙ: var θ = ∫ P(f)|W(f)|² df over
    |f| < ``below_hz``, W the weights' Fourier transform, summed on the DFT ordinates."""
    w = np.asarray(weights, dtype=float)
    fs = 1.0 / dt
    f = np.fft.rfftfreq(w.size, dt)
    power = np.abs(np.fft.rfft(w)) ** 2
    twice = np.where(f > 0, 2.0, 1.0)  # the negative frequencies of a real record
    var = level * float(np.sum((twice * power)[f < below_hz])) * fs / w.size
    return float(np.sqrt(max(var, 0.0)))


def withhold_within_the_unseen_wander(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                      mismatch: dict[str, np.ndarray]) -> None:
    """Deselect a term on an axis fitted with the α vane's error column (``vane_alpha_noise``)
    whose t falls under the entry t (:data:`candidates.T_IN`) once the vane's wander below
    the column's high-pass is counted: the term's least-squares weights (beside the axis's
    other entered terms, its nuisances and a constant) against the wander's level read from
    the column (:func:`wander_level`), the two variances added. A fast column (q̂, δe) has
    almost no weight there; a drift term's ΔV/V has most of it. An independent script's
    t6texan2 null (8,600 ft / 347 ft/s, doublets on each axis at 50 Hz, the vane's 0.1°
    wander at τ = 1 s) named C_m ΔV/V +0.22 (t 6.9; a real C_m,α̇ change of −3 was there
    too): with the vane noise-free it was 0.003; the unseen wander gives it a standard error
    of 0.095 beside the fit's 0.032, and t falls to 2.2."""
    inner = interior(p)
    for c, sel, by_key, key, nuisances in terms_beside_the_vane_column(cands, step):
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and k != key]
        others += [v[inner] for v in nuisances.values() if np.ptp(v[inner]) > 0]
        z, column = mismatch[c.channel][inner], by_key[key].column[inner]
        try:
            theta, se, _ = colored_fit(z, [column] + others, ["term"] + [f"o{i}" for i in range(len(others))])
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        weights = np.linalg.pinv(np.column_stack([column] + others + [np.ones(z.size)]))[0]
        slow = slow_wander_std_error(weights, wander_level(nuisances["vane_alpha_noise"][inner], p.dt), p.dt)
        spread = float(np.hypot(se[0], slow))
        t = float(theta[0]) / spread if spread > 0 else np.inf
        c.details["unseen_wander"] = {"std_error": slow, "t": t}
        if abs(t) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but the α vane's wander below its error column's {GUST_HIGHPASS_HZ:g} Hz "
                        f"high-pass, unseen and left in the mismatch, gives it a standard error of {slow:.2g} "
                        f"beside the fit's {se[0]:.2g} (t = {t:.1f})")
