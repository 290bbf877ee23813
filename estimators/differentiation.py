"""Numerical differentiation of noisy time series (seed paper, section III.A).

The equation-error method needs angular accelerations (seed Eqs. 3-5) that
are usually obtained by differentiating measured, noisy angular rates.  This
module provides

* :func:`local_polynomial_derivative` -- the local quadratic fitted to 5
  points moved along the record (seed Eq. 24), with one-sided end formulas;
* :func:`smooth_derivative` -- the seed paper's three combinations of that
  local derivative with the optimal Fourier smoother
  (:func:`estimators.smoothing.optimal_fourier_smoother`):

  1. optimal Fourier smoother, then the local polynomial derivative;
  2. the smoother's own frequency-domain derivative;
  3. local polynomial derivative, then the optimal Fourier smoother;

* :func:`interior_mask` -- the end buffer.  All methods lose accuracy near
  the ends of the record; the seed paper recommends including 1 s of extra
  data at each end and discarding the results there (for 50 Hz data with a
  deterministic signal in [0, 1] Hz).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt
from scipy import signal

from estimators.smoothing import as_record as _as_record
from estimators.smoothing import optimal_fourier_smoother

__all__ = [
    "interior_mask",
    "local_derivative_noise_shape",
    "local_polynomial_derivative",
    "smooth_derivative",
    "METHODS",
]

METHODS: dict[int, str] = {
    1: "optimal Fourier smoother, then local polynomial derivative",
    2: "optimal Fourier smoother, derivative in the frequency domain",
    3: "local polynomial derivative, then optimal Fourier smoother",
}


def interior_mask(n: int, dt: float, buffer_s: float = 1.0) -> np.ndarray:
    """Boolean mask of the samples more than ``buffer_s`` away from either end.

    Sample ``i`` (time ``i * dt``) is discarded when ``i * dt < buffer_s`` or
    ``(n - 1 - i) * dt < buffer_s``, i.e. ``ceil(buffer_s/dt)`` samples are
    dropped at each end (a relative tolerance of 1e-9 absorbs rounding, so
    ``buffer_s = 1.0``, ``dt = 0.02`` drops exactly 50 samples per end).  This
    implements the seed paper's end buffer (section III.A): record 1 s of
    extra data at each end, differentiate the whole record, and keep only
    ``x[interior_mask(n, dt)]``.

    Parameters
    ----------
    n : int
        Number of samples.
    dt : float
        Sampling interval in seconds.
    buffer_s : float, optional
        Length of the discarded buffer at each end, seconds (default 1.0).

    Returns
    -------
    numpy.ndarray of bool, shape (n,)

    Raises
    ------
    ValueError
        If the buffers leave no sample, or on invalid arguments.
    """
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError("n must be a positive integer")
    dt = float(dt)
    buffer_s = float(buffer_s)
    if not (np.isfinite(dt) and dt > 0.0):
        raise ValueError("dt must be a positive finite number")
    if not (np.isfinite(buffer_s) and buffer_s >= 0.0):
        raise ValueError("buffer_s must be a non-negative finite number")
    drop = max(0, math.ceil(buffer_s / dt - 1e-9))
    if 2 * drop >= n:
        raise ValueError(
            f"a {buffer_s} s buffer at each end leaves no samples of a {n}-sample record"
        )
    mask = np.zeros(int(n), dtype=bool)
    mask[drop : n - drop] = True
    return mask


def local_polynomial_derivative(
    x: npt.ArrayLike,
    dt: float,
    *,
    window: int = 5,
    order: int = 2,
    axis: int = 0,
) -> np.ndarray:
    """Local least-squares polynomial derivative (seed Eq. 24).

    At every sample a polynomial of degree ``order`` in time (default the
    quadratic ``y = a t**2 + b t + c`` of Eq. 24, ``t = 0`` at the centre) is
    fitted by least squares to the ``window`` samples centred on it (default
    5: two on either side); the derivative is the fitted slope at the centre,
    ``b``.  Within ``window // 2`` samples of an end, the polynomial is
    fitted to the first (last) ``window`` samples and its derivative is
    evaluated at the sample in question.  The result is exact for
    polynomials of degree ``<= order``, including the end points.

    This is a Savitzky-Golay derivative and is computed with
    :func:`scipy.signal.savgol_filter` (``deriv=1``, ``mode='interp'``).

    Parameters
    ----------
    x : array_like
        Uniformly sampled real data.
    dt : float
        Sampling interval in seconds.
    window : int, optional
        Odd number of points in each local fit (default 5).
    order : int, optional
        Polynomial degree, ``1 <= order < window`` (default 2).
    axis : int, optional
        Time axis (default 0, i.e. columns of an (N, k) array are series).

    Returns
    -------
    numpy.ndarray
        Derivative estimate, same shape as ``x``.

    Notes
    -----
    For the default (5 points, quadratic) the interior formula is
    ``(-2 x_{i-2} - x_{i-1} + x_{i+1} + 2 x_{i+2}) / (10 dt)``, whose response
    to ``sin(omega t)`` is ``(sin(theta) + 2 sin(2 theta))/(5 dt)`` times
    ``cos(omega t)``, ``theta = omega dt``: relative truncation error
    ``-17 theta**2/30 + O(theta**4)``.
    """
    a = np.asarray(x)
    if np.iscomplexobj(a):
        raise ValueError("x must be real")
    a = a.astype(float)
    dt = float(dt)
    _check_local_polynomial(dt, window, order)
    if a.ndim == 0 or a.shape[axis] < window:
        raise ValueError(f"x needs at least window={window} samples along axis {axis}")
    return signal.savgol_filter(
        a, int(window), int(order), deriv=1, delta=dt, axis=axis, mode="interp"
    )


def local_derivative_noise_shape(
    dt: float, *, window: int = 5, order: int = 2
) -> Callable[[np.ndarray], np.ndarray]:
    """Power gain ``|H(f)|**2`` of the local polynomial derivative: the shape of its noise floor.

    In the interior the local polynomial derivative (Eq. 24) is the linear, time-invariant
    filter ``d_i = sum_j c_j x_{i+j}``, ``j = -m .. m``, ``m = window // 2``, with
    antisymmetric weights (``c_{-j} = -c_j``), so its frequency response is
    ``H(f) = 2 i sum_{j=1}^{m} c_j sin(j theta)``, ``theta = 2 pi f dt``; for the default
    5-point quadratic, ``c_1 = 1/(10 dt)``, ``c_2 = 2/(10 dt)`` and
    ``|H| = |sin(theta) + 2 sin(2 theta)|/(5 dt)``. White noise of variance ``sigma^2`` on
    ``x`` becomes noise of spectral density ``sigma^2 |H(f)|**2`` on ``d``: a floor that
    rises as ``(2 pi f)**2`` at low frequency, peaks near ``theta = 0.87`` (where
    ``cos(theta) + 4 cos(2 theta) = 0``; f about ``0.14/dt``, 6.9 Hz at 50 Hz), vanishes at
    ``cos(theta) = -1/4`` and falls again towards the Nyquist frequency. The optimal Fourier smoother needs this shape to put the automatic
    cut-off of a differentiated record where its signal meets *that* floor (seed method 3;
    :func:`estimators.smoothing.optimal_fourier_smoother`, ``noise_shape``).

    Parameters
    ----------
    dt : float
        Sampling interval, s.
    window, order : int, optional
        The local fit (default 5 points, quadratic, as in Eq. 24).

    Returns
    -------
    callable
        ``f_hz -> |H(f_hz)|**2`` (in (1/s)**2).
    """
    dt = float(dt)
    _check_local_polynomial(dt, window, order)
    m = int(window) // 2
    # use="dot": coefficient j multiplies x_{i - m + j}
    c = signal.savgol_coeffs(int(window), int(order), deriv=1, delta=dt, use="dot")[m + 1:]
    j = np.arange(1, m + 1)

    def shape(f_hz: np.ndarray) -> np.ndarray:
        theta = 2.0 * np.pi * np.asarray(f_hz, dtype=float) * dt
        return (2.0 * np.sin(np.multiply.outer(theta, j)) @ c) ** 2

    return shape


def smooth_derivative(
    x: npt.ArrayLike,
    dt: float,
    method: int = 1,
    *,
    end_buffer_s: float | None = None,
    cutoff_hz: float | None = None,
) -> np.ndarray:
    """Smoothed derivative of a noisy record by one of the seed paper's 3 methods.

    Section III.A of the seed paper:

    1. optimal Fourier smoother, then the local polynomial derivative
       (:func:`local_polynomial_derivative` of the smoothed record);
    2. the smoother's frequency-domain derivative: the sine series of the
       smoothed record differentiated term by term and reconstructed in the
       time domain (:meth:`FourierSmoothing.derivative`);
    3. local polynomial derivative of the noisy record, then the optimal
       Fourier smoother applied to that derivative (with its own automatic
       cut-off, chosen from the spectrum of the noisy derivative unless
       ``cutoff_hz`` is given).  The derivative's noise floor is not white:
       it is white noise through the derivative filter, rising with
       frequency (:func:`local_derivative_noise_shape`), and the smoother is
       given that shape, so the cut-off sits where the signal meets the
       rising floor.  (Assuming a white floor put the cut-off far too high
       and left 42 % RMS error in the seed's Fig. 1 study, against 3.5 %
       for method 1.)

    The seed paper found methods 1 and 2 similar and method 3 less accurate,
    because differentiating first raises the (high-frequency) noise level the
    smoother then has to remove.

    Parameters
    ----------
    x : array_like, shape (N,)
        Uniformly sampled real record (N >= 8).
    dt : float
        Sampling interval in seconds.
    method : {1, 2, 3}, optional
        Differentiation method (default 1).
    end_buffer_s : float, optional
        If given, the results within ``end_buffer_s`` seconds of either end
        are discarded and only the interior, ``d[interior_mask(N, dt,
        end_buffer_s)]``, is returned.  The seed paper recommends recording
        1 s of extra data at each end and using ``end_buffer_s=1.0``.
        ``None`` (default) returns all N samples.
    cutoff_hz : float, optional
        Cut-off frequency for the optimal Fourier smoother; ``None``
        (default) lets the smoother choose it from the data (as for all the
        seed paper's Fig. 1 and 2 results).

    Returns
    -------
    numpy.ndarray
        Derivative estimate: shape (N,), or the interior samples when
        ``end_buffer_s`` is given.
    """
    a = _as_record(x)
    if method == 1:
        smooth = optimal_fourier_smoother(a, dt, cutoff_hz=cutoff_hz)
        d = local_polynomial_derivative(smooth.smoothed, dt)
    elif method == 2:
        d = optimal_fourier_smoother(a, dt, cutoff_hz=cutoff_hz).derivative()
    elif method == 3:
        raw = local_polynomial_derivative(a, dt)
        d = optimal_fourier_smoother(raw, dt, cutoff_hz=cutoff_hz,
                                     noise_shape=local_derivative_noise_shape(dt)).smoothed
    else:
        raise ValueError(f"method must be 1, 2 or 3, got {method!r}")
    if end_buffer_s is None:
        return np.array(d)
    return np.array(d[interior_mask(a.size, dt, end_buffer_s)])


def _check_local_polynomial(dt: float, window: int, order: int) -> None:
    """The local polynomial derivative's arguments (Eq. 24): a positive finite step, an odd
    window of at least 3 points and an order below it."""
    if not (np.isfinite(dt) and dt > 0.0):
        raise ValueError("dt must be a positive finite number")
    if int(window) != window or window < 3 or window % 2 == 0:
        raise ValueError("window must be an odd integer >= 3")
    if int(order) != order or not (1 <= order < window):
        raise ValueError("order must be an integer with 1 <= order < window")
