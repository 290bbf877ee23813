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
matrix ``T[i, j] = R(|i - j|)``.  ``T`` is never formed, nor ``T X``: with the
thin QR factor ``Q`` of ``X``, ``Q^T T Q`` is accumulated one column ``T q_b``
at a time, either by ``2 r + 1`` shifted additions (O(N r n_p), used for few
lags) or as a circular FFT convolution of the zero-padded column with the
two-sided kernel ``[R(0), R(1), ..., R(r), 0, ..., 0, R(r), ..., R(1)]`` of a
fast length ``L >= N + r`` (O(n_p N log N), used for many lags, including the
default of all ``N - 1`` lags), long enough that no wrapped-around term reaches
the first ``N`` outputs, so the product is the linear one of Eq. 40.  With all
lags the kernel's spectrum is ``|rfft(v, L)|**2 / N`` itself (Eq. 39 by the
Wiener-Khinchin relation), so ``R`` is never transformed back and forth.
Memory is the one copy of ``X`` that is factorised in place (none when its QR
factor is passed in) plus about five float64 vectors of length N at the peak,
whatever ``n_p`` (a 10 M-sample, 4-regressor problem takes some 0.7 GB in all).
Only time-domain (real) data are handled.

With ``autocorrelation="ar"`` the sample estimates of Eq. 39 are replaced, at every lag, by
the autocorrelation of an autoregressive model fitted to them (:func:`autoregressive_autocorrelation`).
Eq. 39's estimates, summed over all lags, vanish for a fitted constant (the residuals' mean is
zero), so a bias term's Eq. 40 standard error is too small by about 1.8 even for white
residuals and 2-2.3 for slowly wandering ones; the model's autocorrelation does not vanish.

Public API
----------
residual_autocorrelation(v, max_lag=None)
autoregressive_autocorrelation(v, max_order=None)
colored_residual_covariance(X, residuals, max_lag=None, *, method="auto", autocorrelation="sample")
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt
from scipy import fft as sp_fft
from scipy import linalg, signal

__all__ = ["residual_autocorrelation", "autoregressive_autocorrelation", "colored_middle",
           "colored_residual_covariance"]

# Up to this many lags the direct O(N r) sums are used; beyond it, FFTs.
# (Measured crossover on N = 1e5, 4 columns: a few tens of lags.)
_DIRECT_MAX_LAG = 32


def _as_real_vector(v: npt.ArrayLike, name: str) -> np.ndarray:
    a = np.asarray(v)
    if np.iscomplexobj(a):
        raise ValueError(f"{name} must be real (time-domain data only)")
    a = np.asarray(a, dtype=float)  # read only here: no copy when already float64
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


# Largest autoregressive order tried by :func:`autoregressive_autocorrelation` (and at most
# a tenth of the record): enough for a first-order Gauss-Markov error plus white noise, whose
# ARMA(1,1) autocorrelation AIC-chosen AR orders of 2-15 reproduce (seeded study, README).
AR_MAX_ORDER = 50


def autoregressive_autocorrelation(v: npt.ArrayLike, max_order: int | None = None) -> tuple[np.ndarray, int]:
    """Residual autocorrelation at every lag from an autoregressive model of the residuals.

    The AR(p) model is fitted to the sample autocorrelation of Eq. 39 by the Yule-Walker
    equations (Levinson-Durbin recursion, which keeps it stationary), its order ``p`` the one of
    least Akaike information criterion ``N ln(sigma_p^2) + 2 p`` (``sigma_p^2`` the order-``p``
    prediction-error variance), ``p = 0`` (white) allowed.  The model's autocorrelation equals
    Eq. 39's for lags ``0..p`` and follows the model's recursion
    ``R(k) = sum_i a_i R(k - i)`` beyond, so it does not sum to zero over the lags as the sample
    estimates of zero-mean residuals do.

    Parameters
    ----------
    v : array_like, shape (N,)
        Real residuals.
    max_order : int or None, optional
        Largest order tried; ``None`` uses ``min(AR_MAX_ORDER, N // 10)``.

    Returns
    -------
    (R, p) : numpy.ndarray of shape (N,), int
        ``R(0), ..., R(N - 1)`` and the chosen order.
    """
    a = _as_real_vector(v, "v")
    n = a.size
    p_max = min(AR_MAX_ORDER, n // 10) if max_order is None else min(int(max_order), n - 1)
    r = residual_autocorrelation(a, max(p_max, 1))
    out = np.zeros(n)
    out[0] = r[0]
    if r[0] <= 0.0:
        return out, 0
    coef = np.zeros(0)
    err = r[0]
    best = (n * np.log(err), 0, coef)
    for p in range(1, p_max + 1):
        k = (r[p] - coef @ r[p - 1:0:-1]) / err
        if not abs(k) < 1.0:
            break
        coef = np.concatenate([coef - k * coef[::-1], [k]])
        err *= 1.0 - k * k
        aic = n * np.log(err) + 2 * p
        if aic < best[0]:
            best = (aic, p, coef)
    _, order, coef = best
    out[: order + 1] = r[: order + 1]
    if order and n > order + 1:
        # R(k) = sum_i a_i R(k - i) for k > p: the model's recursion run with no input from R(1..p)
        den = np.concatenate([[1.0], -coef])
        zi = signal.lfiltic([1.0], den, out[order:0:-1])
        out[order + 1:] = signal.lfilter([1.0], den, np.zeros(n - order - 1), zi=zi)[0]
    return out, order


def _kernel_spectrum(v: np.ndarray, r: int, r_vals: np.ndarray | None, nfft: int) -> np.ndarray:
    """Real spectrum (``rfft`` bins) of the circular kernel ``c`` of length ``nfft`` with
    ``c[k] = c[nfft - k] = R(k)`` for ``k = 0..r`` and zero elsewhere.

    With all lags (``r = N - 1``) and ``nfft >= 2N - 1``, ``c`` is the circular
    autocorrelation of ``v`` zero-padded to ``nfft`` divided by ``N``, whose spectrum is
    ``|rfft(v, nfft)|**2 / N`` exactly: no inverse transform is needed.  Otherwise ``c`` is
    formed from ``r_vals`` (``R(0..r)``, needed only then) and transformed (its spectrum is
    real as ``c`` is even; the rounding-level imaginary part is dropped).
    """
    n = v.size
    if r_vals is None:
        spec = sp_fft.rfft(v, nfft)
        out = np.square(spec.real)
        out += np.square(spec.imag)
        del spec
        out /= n
        return out
    c = np.zeros(nfft)
    c[: r + 1] = r_vals
    if r:
        c[nfft - r:] = r_vals[r:0:-1]
    return sp_fft.rfft(c, overwrite_x=True).real.copy()


def _toeplitz_quadratic(q: np.ndarray, v: np.ndarray, r: int, r_vals: np.ndarray | None,
                        method: str) -> np.ndarray:
    """``q^T T q`` for ``T[i, j] = R(|i-j|)`` of the residuals ``v`` (zero beyond lag
    ``r <= N - 1``; ``r_vals`` holds ``R(0..r)``, ``None`` for all lags by FFT), ``T``
    never formed and ``T q`` formed one column at a time (memory O(N), not O(N n_p)).

    ``"direct"``: ``T q_b`` by ``2 r + 1`` shifted additions.  ``"fft"``: ``T q_b`` as the
    first ``N`` samples of the circular convolution, length ``L >= N + r`` (a fast length),
    of ``q_b`` zero-padded with the even kernel of :func:`_kernel_spectrum`; with ``L >= N + r``
    no wrapped-around term reaches the first ``N`` outputs, so this is the linear (Eq. 40)
    product exactly, up to rounding.
    """
    n, n_p = q.shape
    middle = np.empty((n_p, n_p))
    if method == "direct":
        y = np.empty(n)
        for b in range(n_p):
            qb = q[:, b]
            np.multiply(r_vals[0], qb, out=y)
            for k in range(1, r + 1):
                rk = r_vals[k]
                if rk == 0.0:
                    continue
                y[:-k] += rk * qb[k:]
                y[k:] += rk * qb[:-k]
            middle[:, b] = q.T @ y
        return middle
    nfft = sp_fft.next_fast_len(n + r, real=True)
    spec_c = _kernel_spectrum(v, r, r_vals, nfft)
    for b in range(n_p):
        buf = np.zeros(nfft)
        buf[:n] = q[:, b]
        spec = sp_fft.rfft(buf, overwrite_x=True)
        del buf
        if b == n_p - 1 and b > 0:
            # the last column's other entries are the last row's (symmetry), computed already;
            # its diagonal q_b^T T q_b by Parseval, sum over all L bins of C |S|^2 / L (the rfft
            # bins stand for two each except the zero frequency and, for even L, Nyquist)
            power = np.square(spec.real)
            power += np.square(spec.imag)
            del spec
            power *= spec_c
            total = 2.0 * power.sum() - power[0] - (power[-1] if nfft % 2 == 0 else 0.0)
            middle[:b, b] = middle[b, :b]
            middle[b, b] = total / nfft
            return middle
        spec *= spec_c
        y = sp_fft.irfft(spec, nfft, overwrite_x=True)
        del spec
        middle[:, b] = q.T @ y[:n]
        del y
    return middle


def colored_middle(X: npt.ArrayLike, residuals: npt.ArrayLike, max_lag: int | None = None,
                   method: Literal["auto", "direct", "fft"] = "auto",
                   autocorrelation: Literal["sample", "ar"] = "sample") -> np.ndarray:
    """The middle matrix of seed Eq. 40, ``X^T T X`` with ``T[i, j] = R(|i - j|)`` the residual
    autocorrelation of Eq. 39 (1/N normalisation; ``autocorrelation="ar"``: its autoregressive
    model's, :func:`autoregressive_autocorrelation`), zero beyond ``max_lag`` (all lags when None;
    at most N - 1), symmetrised; ``T`` is never formed (see :func:`_toeplitz_quadratic`)."""
    x = np.asarray(X, dtype=float)
    v = np.asarray(residuals, dtype=float)
    n = x.shape[0]
    r = min(_resolve_max_lag(max_lag, n), n - 1)
    if method == "auto":
        method = "direct" if r <= _DIRECT_MAX_LAG else "fft"
    if autocorrelation == "ar":
        r_vals = autoregressive_autocorrelation(v)[0][: r + 1]
    elif autocorrelation == "sample":
        # with all lags the FFT route takes the kernel's spectrum straight from the residuals'
        r_vals = None if (method == "fft" and r == n - 1) else residual_autocorrelation(v, r)
    else:
        raise ValueError("autocorrelation must be 'sample' or 'ar'")
    middle = _toeplitz_quadratic(x, v, r, r_vals, method)
    return 0.5 * (middle + middle.T)


def colored_residual_covariance(
    X: npt.ArrayLike,
    residuals: npt.ArrayLike,
    max_lag: int | None = None,
    *,
    method: Literal["auto", "direct", "fft"] = "auto",
    factor: tuple[np.ndarray, np.ndarray] | None = None,
    autocorrelation: Literal["sample", "ar"] = "sample",
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
    factor : (Q, R), optional
        The thin QR factorisation of ``X`` (``scipy.linalg.qr(X, mode="economic")``) when the
        caller has it already (``least_squares(..., keep_factor=True)``): it is used as given
        instead of factorising ``X`` again.
    autocorrelation : {"sample", "ar"}, optional
        ``"sample"`` (default): Eq. 39's estimates.  ``"ar"``: the autocorrelation of an
        autoregressive model fitted to them, at every lag
        (:func:`autoregressive_autocorrelation`); a bias term's standard error is then honest
        (Eq. 39's estimates of zero-mean residuals sum to zero over all lags, which leaves a
        constant's Eq. 40 variance about a third of the truth), other terms' as before.

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
    if xm.ndim == 1:
        xm = xm[:, None]
    if xm.ndim != 2:
        raise ValueError("X must be 2-D (N, n_p)")
    if factor is None:
        # one Fortran-ordered float64 copy, factorised in place below (X itself is never changed)
        xm = np.array(xm, dtype=float, order="F")
    if not np.isfinite(xm).all():
        raise ValueError("X contains NaN or infinite values")
    v = _as_real_vector(residuals, "residuals")
    n, n_p = xm.shape
    if v.size != n:
        raise ValueError(f"residuals has {v.size} samples but X has {n} rows")
    if n <= n_p:
        raise ValueError("need more data points than regressors (N > n_p)")
    if method not in ("auto", "direct", "fft"):
        raise ValueError("method must be 'auto', 'direct' or 'fft'")
    if autocorrelation not in ("sample", "ar"):
        raise ValueError("autocorrelation must be 'sample' or 'ar'")
    r = min(_resolve_max_lag(max_lag, n), n - 1)

    if factor is None:
        q, rr = linalg.qr(xm, mode="economic", overwrite_a=True, check_finite=False)
    else:
        q, rr = (np.asarray(f, dtype=float) for f in factor)
        if q.shape != (n, n_p) or rr.shape != (n_p, n_p):
            raise ValueError(f"factor must be the thin QR factorisation of X: Q {n} x {n_p}, R {n_p} x {n_p}")
    del xm
    diag = np.abs(np.diag(rr))
    if diag.min() <= np.finfo(float).eps * max(n, n_p) * diag.max():
        raise np.linalg.LinAlgError("X is rank deficient; X^T X is singular")

    middle = colored_middle(q, v, r, method, autocorrelation)
    del q
    a = linalg.solve_triangular(rr, middle)  # R^{-1} M
    cov = linalg.solve_triangular(rr, a.T).T  # R^{-1} M R^{-T}
    return 0.5 * (cov + cov.T)
