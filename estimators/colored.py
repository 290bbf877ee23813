"""Parameter covariance of least-squares estimates with coloured residuals.

Implements the correction of the seed paper's section III.E (Eqs. 37-41):
when the equation-error residuals ``v`` are serially correlated, the
covariance of the ordinary least-squares estimate
``theta_hat = (X^T X)^{-1} X^T z`` (Eq. 14) is

.. math::

    \\mathrm{Cov}(\\hat\\theta) = (X^T X)^{-1} \\Big[\\sum_{i=1}^{N} x_i
        \\sum_{j=1}^{N} \\hat{\\mathcal R}_{vv}(i-j)\\, x_j^T\\Big] (X^T X)^{-1}
    \\qquad \\text{(Eq. 40)}

with the residual autocorrelation estimate of Eq. 39,
``R(k) = (1/N) sum_{i=1}^{N-k} v_i v_{i+k} = R(-k)``, ``k = 0..r``, and
``R(k) = 0`` for ``|k| > r``.

The middle matrix is ``X^T T X`` with ``T`` the N-by-N symmetric Toeplitz
matrix ``T[i, j] = R(|i - j|)``.  ``T`` is never formed: ``T X`` is computed
column by column either by ``2 r + 1`` shifted additions (O(N r n_p), used
for few lags) or as an FFT convolution of each column with the two-sided
kernel ``[R(r), ..., R(1), R(0), R(1), ..., R(r)]`` (O(n_p N log N), used
for many lags, including the default of all ``N - 1`` lags).  Only time-domain
(real) data are handled.

Public API
----------
residual_autocorrelation(v, max_lag=None)
colored_residual_covariance(X, residuals, max_lag=None, *, method="auto")
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt
from scipy import fft as sp_fft
from scipy import linalg, signal

__all__ = ["residual_autocorrelation", "colored_residual_covariance"]

# Up to this many lags the direct O(N r) sums are used; beyond it, FFTs.
# (Measured crossover on N = 1e5, 4 columns: a few tens of lags.)
_DIRECT_MAX_LAG = 32


def _as_real_vector(v: npt.ArrayLike, name: str) -> np.ndarray:
    a = np.asarray(v)
    if np.iscomplexobj(a):
        raise ValueError(f"{name} must be real (time-domain data only)")
    a = a.astype(float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be 1-D")
    if a.size == 0:
        raise ValueError(f"{name} is empty")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


def _resolve_max_lag(max_lag: int | None, n: int) -> int:
    if max_lag is None:
        return n - 1
    if isinstance(max_lag, (bool, np.bool_)) or not isinstance(max_lag, (int, np.integer)):
        raise TypeError("max_lag must be a non-negative integer or None")
    if max_lag < 0:
        raise ValueError("max_lag must be non-negative")
    return int(max_lag)


def residual_autocorrelation(v: npt.ArrayLike, max_lag: int | None = None) -> np.ndarray:
    """Biased sample autocorrelation of a residual sequence (seed Eq. 39).

    ``R(k) = (1/N) * sum_{i=1}^{N-k} v_i v_{i+k}`` for ``k = 0, 1, ..., r``.

    The mean is *not* removed (Eq. 39 as written; least-squares residuals of
    a model with a bias term have zero mean anyway).  The 1/N normalisation
    makes the full sequence positive semi-definite.

    Parameters
    ----------
    v : array_like, shape (N,)
        Real residuals.
    max_lag : int or None, optional
        Largest lag ``r``.  ``None`` means all lags, ``r = N - 1``.  Lags
        ``k >= N`` are returned as 0 (empty sums).

    Returns
    -------
    numpy.ndarray, shape (r + 1,)
        ``R(0), ..., R(r)``.

    Notes
    -----
    For ``r <= 32`` the sums are evaluated directly (O(N r)); otherwise
    through the FFT of the zero-padded sequence (O(N log N)):
    ``R = irfft(|rfft(v, L)|**2)[:r+1] / N`` with ``L >= 2N - 1`` so that
    the circular correlation equals the linear one.
    """
    a = _as_real_vector(v, "v")
    n = a.size
    r = _resolve_max_lag(max_lag, n)
    out = np.zeros(r + 1)
    r_eff = min(r, n - 1)
    if r_eff <= _DIRECT_MAX_LAG:
        for k in range(r_eff + 1):
            out[k] = np.dot(a[: n - k], a[k:])
    else:
        nfft = sp_fft.next_fast_len(2 * n - 1, real=True)
        spec = sp_fft.rfft(a, nfft)
        out[: r_eff + 1] = sp_fft.irfft(spec.real**2 + spec.imag**2, nfft)[: r_eff + 1]
    return out / n


def _toeplitz_times(r_vals: np.ndarray, q: np.ndarray, method: str) -> np.ndarray:
    """``T @ q`` for ``T[i, j] = r_vals[|i-j|]`` (zero beyond ``len(r_vals)-1``)."""
    n = q.shape[0]
    r = min(r_vals.size - 1, n - 1)
    if method == "direct":
        out = r_vals[0] * q
        for k in range(1, r + 1):
            rk = r_vals[k]
            if rk == 0.0:
                continue
            out[:-k] += rk * q[k:]
            out[k:] += rk * q[:-k]
        return out
    kernel = np.concatenate([r_vals[r:0:-1], r_vals[: r + 1]])  # length 2r+1
    full = signal.fftconvolve(q, kernel[:, None], mode="full", axes=0)
    return full[r : r + n]


def colored_residual_covariance(
    X: npt.ArrayLike,
    residuals: npt.ArrayLike,
    max_lag: int | None = None,
    *,
    method: Literal["auto", "direct", "fft"] = "auto",
) -> np.ndarray:
    """Parameter covariance corrected for coloured residuals (seed Eq. 40).

    .. math::

        \\mathrm{Cov}(\\hat\\theta) = (X^T X)^{-1}
            \\Big[\\sum_i \\sum_j x_i \\hat{\\mathcal R}_{vv}(i-j) x_j^T\\Big]
            (X^T X)^{-1}

    with ``R`` from :func:`residual_autocorrelation` (Eq. 39), truncated to
    ``|i - j| <= max_lag``.  With ``max_lag = 0`` this is Eq. 41 inserted in
    Eq. 37, i.e. Eq. 15 with ``sigma^2 = R(0) = sum(v**2)/N``.

    Parameters
    ----------
    X : array_like, shape (N, n_p)
        Real regressor matrix (a 1-D array is one regressor), full column
        rank.
    residuals : array_like, shape (N,)
        Real least-squares residuals ``v = z - X theta_hat``.
    max_lag : int or None, optional
        Maximum lag ``r`` of Eq. 39; ``None`` (default) uses all ``N - 1``
        lags.  Larger values are clipped to ``N - 1``.
    method : {"auto", "direct", "fft"}, optional
        How ``T X`` is formed.  ``"direct"``: shifted sums, O(N r n_p);
        ``"fft"``: FFT convolution, O(n_p N log N); ``"auto"`` picks
        ``"direct"`` for ``r <= 32`` and ``"fft"`` otherwise.  All give the
        same result to rounding.

    Returns
    -------
    numpy.ndarray, shape (n_p, n_p)
        Symmetric covariance matrix.  Standard errors are the square roots of
        its diagonal (Eq. 17).

    Raises
    ------
    ValueError
        On shape mismatch, non-finite or complex input, or ``N <= n_p``.
    numpy.linalg.LinAlgError
        If ``X`` is rank deficient.

    Notes
    -----
    With the thin QR factorisation ``X = Q R`` (computed with
    :func:`scipy.linalg.qr`), ``(X^T X)^{-1} = R^{-1} R^{-T}`` and the
    middle matrix is ``X^T T X = R^T (Q^T T Q) R``, so

    ``Cov = R^{-1} (Q^T T Q) R^{-T}``,

    which avoids forming ``X^T X`` (and squaring its condition number).
    ``T Q`` is computed without forming ``T`` (see module docstring).

    With all lags the Toeplitz matrix of the biased estimate (Eq. 39) is
    positive semi-definite, so the covariance is too.  A truncated lag
    window (``max_lag < N - 1``, as Eq. 40 prescribes with ``R(k) = 0`` for
    ``|k| > r``) is not guaranteed to be positive semi-definite; with
    residuals whose correlation has died out by lag ``r`` it is in practice.
    """
    xm = np.asarray(X)
    if np.iscomplexobj(xm):
        raise ValueError("X must be real (time-domain data only)")
    xm = xm.astype(float)
    if xm.ndim == 1:
        xm = xm[:, None]
    if xm.ndim != 2:
        raise ValueError("X must be 2-D (N, n_p)")
    if not np.all(np.isfinite(xm)):
        raise ValueError("X contains NaN or infinite values")
    v = _as_real_vector(residuals, "residuals")
    n, n_p = xm.shape
    if v.size != n:
        raise ValueError(f"residuals has {v.size} samples but X has {n} rows")
    if n <= n_p:
        raise ValueError("need more data points than regressors (N > n_p)")
    if method not in ("auto", "direct", "fft"):
        raise ValueError("method must be 'auto', 'direct' or 'fft'")
    r = min(_resolve_max_lag(max_lag, n), n - 1)
    r_vals = residual_autocorrelation(v, r)
    if method == "auto":
        method = "direct" if r <= _DIRECT_MAX_LAG else "fft"

    q, rr = linalg.qr(xm, mode="economic")
    diag = np.abs(np.diag(rr))
    if diag.min() <= np.finfo(float).eps * max(n, n_p) * diag.max():
        raise np.linalg.LinAlgError("X is rank deficient; X^T X is singular")

    tq = _toeplitz_times(r_vals, q, method)
    middle = q.T @ tq
    middle = 0.5 * (middle + middle.T)
    a = linalg.solve_triangular(rr, middle)  # R^{-1} M
    cov = linalg.solve_triangular(rr, a.T).T  # R^{-1} M R^{-T}
    return 0.5 * (cov + cov.T)
