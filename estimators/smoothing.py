"""Optimal Fourier smoother: global, zero-phase Wiener smoothing of a record.

Implements the smoother referred to in section III.A of the seed paper
(E. A. Morelli, "Practical Aspects of the Equation-Error Method for Aircraft
Parameter Estimation") and described in E. A. Morelli, "Estimating noise
characteristics from flight test data using optimal Fourier smoothing",
Journal of Aircraft 32(4), 1995.  The record is represented by a Fourier sine
series after removing the straight line through its end points; the sine
coefficients are weighted by a Wiener filter built from a noise floor (white,
or of a known shape such as the floor of a differentiated record, rising with
frequency) and a signal spectrum estimated from the same coefficients; the smoothed
record is the weighted series plus the line.  The method is global (all data
at once) and has zero phase shift by construction.

Public API
----------
optimal_fourier_smoother(x, dt, *, cutoff_hz=None, noise_shape=None) -> FourierSmoothing
FourierSmoothing (frozen result; ``.derivative()`` gives the smoothed
derivative computed in the frequency domain)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy import fft as sp_fft
from scipy import ndimage, stats

__all__ = ["FourierSmoothing", "optimal_fourier_smoother", "sine_series_filter", "sine_series_derivative"]

_MIN_SAMPLES = 8
_CHI2_1_MEDIAN = float(stats.chi2.median(1))  # median of chi-square(1) ~ 0.4549
_MAX_ITER = 50


@dataclass(frozen=True, eq=False)
class FourierSmoothing:
    """Result of :func:`optimal_fourier_smoother` (arrays are read-only).

    Attributes
    ----------
    smoothed : numpy.ndarray, shape (N,)
        Smoothed record, ``line + sum_k weights_k b_k sin(k pi t/T)``.  It
        passes exactly through the first and last samples.
    noise : numpy.ndarray, shape (N,)
        ``x - smoothed`` (zero at both end points).
    noise_variance : float
        **The noise level**: the variance of the noise implied by the floor
        ``N_k`` of the sine coefficients, ``(N - 1)/2 * mean_k(N_k)`` (by
        Parseval).  For the white floor this is
        ``sigma^2 = (N - 1)/2 * mean(b_k**2, f_k > cutoff)`` (for white noise
        of variance sigma^2, ``E[b_k**2] = 2 sigma^2/(N - 1)``).  Unbiased
        when the signal has negligible power above the cut-off.
    noise_sample_variance : float
        Sample variance (``ddof=1``) of the sequence ``noise``.  It is smaller
        than ``noise_variance`` by roughly the fraction of the noise that the
        filter passed into ``smoothed`` (the noise below the cut-off), so it
        is a slightly low estimate of the noise level.
    cutoff_hz : float
        Highest frequency retained: weights are zero above it (0.0 when no
        coefficient is kept).
    frequencies_hz : numpy.ndarray, shape (N - 2,)
        ``f_k = k / (2 T)``, ``k = 1 .. N-2``, ``T = (N - 1) dt``.
    coefficients : numpy.ndarray, shape (N - 2,)
        Raw sine-series coefficients ``b_k`` of the detrended record.
    weights : numpy.ndarray, shape (N - 2,)
        Filter weights ``Phi_k`` in [0, 1] applied to ``b_k``.
    dt : float
        Sampling interval in seconds.
    automatic_cutoff : bool
        True when the cut-off was chosen from the data.
    """

    smoothed: np.ndarray
    noise: np.ndarray
    noise_variance: float
    noise_sample_variance: float
    cutoff_hz: float
    frequencies_hz: np.ndarray
    coefficients: np.ndarray
    weights: np.ndarray
    dt: float
    automatic_cutoff: bool

    def __post_init__(self) -> None:
        for name in ("smoothed", "noise", "frequencies_hz", "coefficients", "weights"):
            getattr(self, name).setflags(write=False)

    def derivative(self) -> np.ndarray:
        """Time derivative of the smoothed record, computed in the frequency domain.

        Differentiating the smoothed representation term by term,

        ``d/dt [a + s t + sum_k Phi_k b_k sin(k pi t / T)]
        = s + sum_k Phi_k b_k (k pi / T) cos(k pi t / T)``,

        where ``s = (x_{N-1} - x_0)/T`` is the slope of the end-point line.
        The cosine sum at ``t_i = i dt``, ``i = 0..N-1``, is a type-I DCT
        (:func:`scipy.fft.dct`) of the coefficients padded with zeros at
        ``k = 0`` and ``k = N - 1``.  This is method 2 of the seed paper's
        section III.A.  Like the smoothed record itself it is least accurate
        near the end points (see
        :func:`estimators.differentiation.interior_mask`).

        Returns
        -------
        numpy.ndarray, shape (N,)
        """
        n = self.smoothed.size
        span = (n - 1) * self.dt
        k = np.arange(1, n - 1)
        amp = np.zeros(n)
        amp[1:-1] = self.weights * self.coefficients * (k * np.pi / span)
        slope = (self.smoothed[-1] - self.smoothed[0]) / span
        return slope + 0.5 * sp_fft.dct(amp, type=1)


def as_record(x: npt.ArrayLike) -> np.ndarray:
    """``x`` as a real 1-D float record; a clear ValueError otherwise."""
    a = np.asarray(x)
    if np.iscomplexobj(a):
        raise ValueError("x must be real")
    a = a.astype(float)
    if a.ndim != 1:
        raise ValueError("x must be a 1-D record")
    return a


def _validate(x: npt.ArrayLike, dt: float) -> tuple[np.ndarray, float]:
    a = as_record(x)
    if a.size < _MIN_SAMPLES:
        raise ValueError(f"x needs at least {_MIN_SAMPLES} samples, got {a.size}")
    if np.isnan(a).any():
        raise ValueError("x contains NaN; the optimal Fourier smoother needs a complete record")
    if not np.all(np.isfinite(a)):
        raise ValueError("x contains infinite values")
    dt = float(dt)
    if not (np.isfinite(dt) and dt > 0.0):
        raise ValueError("dt must be a positive finite number")
    return a, dt


def _sine_coefficients(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """End-point line and sine-series coefficients of the detrended record.

    ``x_i = line_i + sum_{k=1}^{N-2} b_k sin(k pi i/(N-1))`` exactly, with
    ``line_i = x_0 + (x_{N-1} - x_0) i/(N-1)``.  The detrended record is
    zero at both ends, so its odd periodic extension is continuous and is
    represented by the sine series; ``b = DST-I(interior)/(N-1)``.
    """
    n = x.size
    line = x[0] + (x[-1] - x[0]) * (np.arange(n) / (n - 1))
    line[-1] = x[-1]  # exact end point despite rounding
    b = sp_fft.dst((x - line)[1:-1], type=1) / (n - 1)
    return line, b


def _automatic_cutoff(power: np.ndarray, shape: np.ndarray | None = None) -> tuple[int, float]:
    """Number of retained coefficients ``k_c`` and the noise-floor scale ``sigma2``.

    The noise floor is ``N_i = sigma2 * g_i`` with a known shape ``g`` (``None``: white
    noise, ``g_i = 1``) and an unknown scale. ``k_c`` maximises
    ``J(k) = sum_{i<=k} (P_i - 2 N_i)`` (``J(0) = 0``), which is the same as minimising the
    unbiased estimate ``sum_{i>k} (P_i - N_i) + sum_{i<=k} N_i`` of the summed squared error
    of the series truncated after ``k`` terms (signal lost above, noise kept below; for
    ``P_i = S_i + noise``, ``E[P_i] = S_i + N_i``). Its increments have expectation
    ``S_i - N_i``, so ``J`` rises while the signal is above the floor and falls after: ``k_c``
    is where the signal spectrum meets the floor, whatever the floor's shape. The scale starts
    from the robust estimate ``median(P_i/g_i, upper half of the band) / median(chi2_1)`` and
    is then re-estimated from the coefficients above the cut-off as
    ``sum(P_i) / sum(g_i)`` (unbiased when ``E[P_i] = sigma2 g_i`` there, and not
    ill-conditioned where ``g`` is small, unlike the mean of ``P_i/g_i``); the two steps
    alternate until ``k_c`` repeats. At least ``max(2, ceil(K/100))`` coefficients are kept
    above the cut-off to estimate the floor. With ``g = 1`` this is the white-floor rule of
    Morelli (1995).
    """
    k_total = power.size
    g = np.ones(k_total) if shape is None else shape
    reserve = max(2, int(np.ceil(k_total / 100)))
    k_max = k_total - reserve
    upper = slice(k_total // 2, None)
    positive = g[upper] > 0.0
    ratio = power[upper][positive] / g[upper][positive]
    sigma2 = float(np.median(ratio)) / _CHI2_1_MEDIAN if ratio.size else 0.0
    seen: set[int] = set()
    k_c = k_max
    for _ in range(_MAX_ITER):
        j = np.concatenate(([0.0], np.cumsum(power[:k_max] - 2.0 * sigma2 * g[:k_max])))
        k_c = int(np.argmax(j))
        g_sum = float(np.sum(g[k_c:]))
        sigma2 = float(np.sum(power[k_c:])) / g_sum if g_sum > 0.0 else 0.0
        if k_c in seen:
            break
        seen.add(k_c)
    return k_c, sigma2


def _wiener_weights(power: np.ndarray, k_c: int, floor: np.ndarray) -> np.ndarray:
    """Weights ``Phi_k = S_k / (S_k + N_k)`` for ``k <= k_c`` and 0 above.

    ``S_k = max(Pbar_k - N_k, 0)`` is the signal power estimated by subtracting the noise
    floor ``N_k`` (one value per coefficient) from the locally averaged coefficient power
    ``Pbar`` (running mean over ``w`` coefficients, ``w`` odd, about 1 % of the band and at
    least 5; reflected at the band edges). Hence ``Phi_k = max(1 - N_k/Pbar_k, 0)``: ~1 where
    the signal dominates, falling towards ~1/2 as the spectrum approaches the floor near the
    automatic cut-off, and 0 above the cut-off.
    """
    k_total = power.size
    weights = np.zeros(k_total)
    if k_c == 0:
        return weights
    if not np.any(floor[:k_c] > 0.0):
        weights[:k_c] = 1.0
        return weights
    width = max(5, 2 * (k_total // 200) + 1)
    width = min(width, k_total if k_total % 2 else k_total - 1)
    pbar = ndimage.uniform_filter1d(power, size=width, mode="reflect")[:k_c]
    with np.errstate(divide="ignore", invalid="ignore"):
        weights[:k_c] = np.where(pbar > floor[:k_c], 1.0 - floor[:k_c] / pbar, 0.0)
    return weights


def _noise_shape(noise_shape, freqs: np.ndarray) -> np.ndarray | None:
    """The floor's relative shape ``g_k`` at the sine-series frequencies (None: white)."""
    if noise_shape is None:
        return None
    g = np.asarray(noise_shape(freqs) if callable(noise_shape) else noise_shape, dtype=float)
    if g.shape != freqs.shape:
        raise ValueError(f"noise_shape must give one value per sine coefficient ({freqs.size}), got {g.shape}")
    if not np.all(np.isfinite(g)) or np.any(g < 0.0) or not np.any(g > 0.0):
        raise ValueError("noise_shape must be finite, non-negative and not all zero")
    return g


def optimal_fourier_smoother(
    x: npt.ArrayLike,
    dt: float,
    *,
    cutoff_hz: float | None = None,
    noise_shape: Callable[[np.ndarray], npt.ArrayLike] | npt.ArrayLike | None = None,
) -> FourierSmoothing:
    """Smooth a record with the optimal Fourier (sine-series Wiener) smoother.

    Steps (seed paper, section III.A; Morelli 1995):

    1. Remove the end-point trend: subtract the straight line through the
       first and last samples, so the detrended record is zero at both ends.
    2. Odd (reflected) extension: the detrended record is a finite sine
       series, ``x_d(t_i) = sum_{k=1}^{N-2} b_k sin(k pi t_i / T)``,
       ``T = (N-1) dt``, at frequencies ``f_k = k/(2T)``; ``b`` is a DST-I of
       the interior points (:func:`scipy.fft.dst`).
    3. Noise floor and cut-off.  For white noise of variance ``sigma^2``
       every ``b_k`` gets independent noise with
       ``E[b_k**2] = 2 sigma^2/(N-1)`` -- a flat floor.  Noise that is white
       noise passed through a linear filter of frequency response ``H``
       (for example a numerically differentiated record) has, to the same
       approximation, ``E[b_k**2] = 2 sigma^2 |H(f_k)|**2/(N-1)``: a floor
       ``N_k = s g_k`` of known shape ``g_k = |H(f_k)|**2`` (``noise_shape``)
       and unknown scale ``s``.  Automatic cut-off: the number of retained
       coefficients maximises ``sum_{i<=k} (b_i**2 - 2 N_i)``, i.e. the point
       where the signal power meets the floor (see
       :func:`_automatic_cutoff`), with the scale re-estimated from the
       coefficients above the cut-off.  Manual cut-off: the coefficients with
       ``f_k <= cutoff_hz`` are retained and the scale comes from those above
       ``cutoff_hz``.
    4. Wiener filter ``Phi_k = S_k/(S_k + N_k)`` with the signal power
       ``S_k = max(Pbar_k - N_k, 0)`` from the locally averaged coefficient
       power ``Pbar`` below the cut-off, and ``Phi_k = 0`` above it (see
       :func:`_wiener_weights`).  The same rule is used with a manual
       cut-off.
    5. Reconstruct ``smoothed = line + sum_k Phi_k b_k sin(k pi t/T)`` (an
       inverse DST-I).  No phase shift is introduced: every sine component is
       only scaled by a real weight.

    Parameters
    ----------
    x : array_like, shape (N,)
        Uniformly sampled real record, ``N >= 8``, no NaN.
    dt : float
        Sampling interval in seconds.
    cutoff_hz : float, optional
        Cut-off frequency set by hand.  ``None`` (default) chooses it from the
        data.  A cut-off at or above the highest frequency ``(N-2)/(2T)``
        keeps every coefficient (then ``noise_variance`` is 0).
    noise_shape : callable or array_like, optional
        Relative shape ``g_k`` of the noise floor: a function of the
        frequencies ``f_k`` in Hz (``k = 1 .. N-2``) or one value per
        coefficient, non-negative; only its shape matters.  ``None`` (default)
        is white noise, ``g_k = 1`` (Morelli 1995).  For a record made by a
        linear filter from a record with white noise, give the filter's power
        gain ``|H(f)|**2``
        (:func:`estimators.differentiation.local_derivative_noise_shape` for
        the local polynomial derivative, seed method 3).

    Returns
    -------
    FourierSmoothing
        Frozen result: smoothed record, noise sequence, noise variance
        (floor-based, the noise level) and noise sample variance, cut-off,
        frequencies, raw coefficients, weights; ``.derivative()`` gives the
        frequency-domain derivative of the smoothed record.

    Raises
    ------
    ValueError
        If ``x`` is not a real 1-D record of at least 8 finite samples (NaN
        is refused explicitly), ``dt`` is not positive, or ``cutoff_hz`` is
        not a positive finite number.

    Notes
    -----
    Accuracy is lost near the end points (the odd extension has a jump in
    its second derivative there unless ``x''`` vanishes at the ends, and the
    end-point line carries the noise of the two end samples).  The seed paper
    recommends including 1 s of extra data at each end and discarding it
    (:func:`estimators.differentiation.interior_mask`).  Without
    ``noise_shape`` the method assumes white measurement noise; coloured
    noise of another shape (for example the noise of a numerically
    differentiated signal, whose floor rises with frequency) then biases the
    floor and the automatic cut-off.
    """
    a, dt = _validate(x, dt)
    n = a.size
    span = (n - 1) * dt
    line, b = _sine_coefficients(a)
    power = b * b
    k_total = power.size
    freqs = np.arange(1, k_total + 1) / (2.0 * span)
    shape = _noise_shape(noise_shape, freqs)

    if cutoff_hz is None:
        k_c, scale = _automatic_cutoff(power, shape)
    else:
        fc = float(cutoff_hz)
        if not (np.isfinite(fc) and fc > 0.0):
            raise ValueError("cutoff_hz must be a positive finite number")
        k_c = int(np.searchsorted(freqs, fc, side="right"))
        g_above = float(np.sum(shape[k_c:])) if shape is not None else float(k_total - k_c)
        scale = float(np.sum(power[k_c:])) / g_above if k_c < k_total and g_above > 0.0 else 0.0
    floor = scale * (shape if shape is not None else np.ones(k_total))

    weights = _wiener_weights(power, k_c, floor)
    smoothed = line.copy()
    smoothed[1:-1] += 0.5 * sp_fft.dst(weights * b, type=1)
    noise = a - smoothed
    return FourierSmoothing(
        smoothed=smoothed,
        noise=noise,
        noise_variance=0.5 * (n - 1) * float(np.mean(floor)),
        noise_sample_variance=float(np.var(noise, ddof=1)),
        cutoff_hz=float(freqs[k_c - 1]) if k_c > 0 else 0.0,
        frequencies_hz=freqs,
        coefficients=b,
        weights=weights,
        dt=dt,
        automatic_cutoff=cutoff_hz is None,
    )


def sine_series_filter(x: npt.ArrayLike, weights: npt.ArrayLike) -> np.ndarray:
    """Apply sine-series weights ``Phi_k`` to a record, keeping its end-point line.

    This is the linear, zero-phase operator the optimal Fourier smoother applies with its
    own weights (steps 1, 2 and 5 of :func:`optimal_fourier_smoother`), here with weights
    given by the caller, so the *same* filter can be applied to several records. Being
    linear and exact on straight lines, it maps ``z = X theta`` to
    ``filter(z) = filter(X) theta`` for every column set, the bias column included.

    Parameters
    ----------
    x : array_like, shape (N,) or (N, k)
        Uniformly sampled real record(s), ``N >= 8``; 2-D input is filtered column by column.
    weights : array_like, shape (N - 2,)
        One weight per sine coefficient ``k = 1 .. N-2`` (``FourierSmoothing.weights``).
    """
    a = np.asarray(x, dtype=float)
    w = np.asarray(weights, dtype=float)
    if a.ndim == 2:
        return np.column_stack([sine_series_filter(a[:, j], w) for j in range(a.shape[1])])
    a, _ = _validate(a, 1.0)
    if w.shape != (a.size - 2,):
        raise ValueError(f"weights must have N - 2 = {a.size - 2} entries, got {w.shape}")
    line, b = _sine_coefficients(a)
    out = line.copy()
    out[1:-1] += 0.5 * sp_fft.dst(w * b, type=1)
    return out


def sine_series_derivative(x: npt.ArrayLike, weights: npt.ArrayLike, dt: float) -> np.ndarray:
    """Time derivative of :func:`sine_series_filter` ``(x, weights)``, term by term.

    ``d/dt [line + sum_k Phi_k b_k sin(k pi t/T)] = s + sum_k Phi_k b_k (k pi/T) cos(k pi t/T)``
    (seed §III.A, method 2), the same operation as :meth:`FourierSmoothing.derivative` with
    weights given by the caller, so every record of a set is filtered *and* differentiated by
    one linear operator.

    Parameters
    ----------
    x : array_like, shape (N,) or (N, k)
        Uniformly sampled real record(s), ``N >= 8``.
    weights : array_like, shape (N - 2,)
        One weight per sine coefficient.
    dt : float
        Sampling interval, s.
    """
    a = np.asarray(x, dtype=float)
    w = np.asarray(weights, dtype=float)
    if a.ndim == 2:
        return np.column_stack([sine_series_derivative(a[:, j], w, dt) for j in range(a.shape[1])])
    a, dt = _validate(a, dt)
    n = a.size
    if w.shape != (n - 2,):
        raise ValueError(f"weights must have N - 2 = {n - 2} entries, got {w.shape}")
    span = (n - 1) * dt
    _, b = _sine_coefficients(a)
    k = np.arange(1, n - 1)
    amp = np.zeros(n)
    amp[1:-1] = w * b * (k * np.pi / span)
    return (a[-1] - a[0]) / span + 0.5 * sp_fft.dct(amp, type=1)
