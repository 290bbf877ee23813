"""High-accuracy finite Fourier transform of sampled data at arbitrary frequencies.

The frequency-domain equation-error method (seed paper, Eqs. 19-23) needs the
finite Fourier transform

.. math:: \\tilde x(\\omega) = \\int_{t_0}^{t_0+T} x(t)\\, e^{-j\\omega t}\\, dt

of each measured time series on a chosen frequency grid (seed Eq. 18:
0.20, 0.24, ..., 1.20 Hz), where the grid spacing is much finer than the
``1/T`` resolution of a DFT and the record length ``T`` is not a multiple of
any period.  This module evaluates that integral for the smooth piecewise
*cubic* interpolant of the samples instead of the plain Riemann sum, following
the approach described by E. A. Morelli, "High accuracy evaluation of the
finite Fourier transform using sampled data" (NASA TM 110340, 1997), and the
end-point-corrected Fourier integrals described in the numerical-analysis
literature ("Numerical Recipes", section on Fourier integrals).  The formulas
below were derived for this module; see :func:`finite_fourier_transform`.

Public API
----------
finite_fourier_transform(x, dt, frequencies_hz, *, t0=0.0)
plain_dft(x, dt, frequencies_hz, *, t0=0.0)
held_fourier_transform(x, dt, frequencies_hz, *, t0=0.0)
seed_frequencies()
seed_rule_frequencies(duration_s, *, upper_hz=1.2, step_hz=0.04)
interpolation_weights(theta)
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy import signal

__all__ = [
    "finite_fourier_transform",
    "plain_dft",
    "held_fourier_transform",
    "seed_frequencies",
    "seed_rule_frequencies",
    "interpolation_weights",
]

# The seed's rule for a frequency-domain band (§II, after Eq. 18): "frequency resolution of
# 0.04 Hz works well", the upper bound "typically around 1.2 Hz for rigid-body modes of
# full-scale aircraft".
SEED_STEP_HZ = 0.04
RIGID_BODY_UPPER_HZ = 1.2

# Monomial coefficients (ascending powers of s) of the cubic Lagrange basis
# polynomials used on one sampling interval, s = (t - t_m)/dt in [0, 1].
# Interior interval m: nodes s = -1, 0, 1, 2 (samples m-1 .. m+2).
_LAGRANGE_CENTRED = np.array(
    [
        [0.0, -1.0 / 3.0, 1.0 / 2.0, -1.0 / 6.0],  # node -1: -s(s-1)(s-2)/6
        [1.0, -1.0 / 2.0, -1.0, 1.0 / 2.0],  # node 0: (s+1)(s-1)(s-2)/2
        [0.0, 1.0, 1.0 / 2.0, -1.0 / 2.0],  # node 1: -(s+1)s(s-2)/2
        [0.0, -1.0 / 6.0, 0.0, 1.0 / 6.0],  # node 2: (s+1)s(s-1)/6
    ]
)
# First interval (m = 0): one-sided nodes s = 0, 1, 2, 3 (samples 0 .. 3).
_LAGRANGE_ONE_SIDED = np.array(
    [
        [1.0, -11.0 / 6.0, 1.0, -1.0 / 6.0],  # node 0: -(s-1)(s-2)(s-3)/6
        [0.0, 3.0, -5.0 / 2.0, 1.0 / 2.0],  # node 1: s(s-2)(s-3)/2
        [0.0, -3.0 / 2.0, 2.0, -1.0 / 2.0],  # node 2: -s(s-1)(s-3)/2
        [0.0, 1.0 / 3.0, -1.0 / 2.0, 1.0 / 6.0],  # node 3: s(s-1)(s-2)/6
    ]
)
_SERIES_THRESHOLD = 1.0  # |theta| below which the moments use their Taylor series
_SERIES_TERMS = 24  # 1/24! ~ 1.6e-24: ample for |theta| <= 1


def seed_frequencies() -> np.ndarray:
    """Frequency grid of the seed paper's Eq. 18, in Hz.

    Returns
    -------
    numpy.ndarray
        ``[0.20, 0.24, ..., 1.16, 1.20]`` -- 26 points, both ends included,
        built with :func:`numpy.linspace` so that no floating-point
        accumulation in ``arange`` can drop or add the last point.
    """
    return np.linspace(0.20, 1.20, 26)


def seed_rule_frequencies(duration_s: float, *, upper_hz: float = RIGID_BODY_UPPER_HZ,
                          step_hz: float = SEED_STEP_HZ) -> np.ndarray:
    """The band the seed's rule gives a maneuver of length ``T`` (§II, after Eq. 18).

    "The lower bound should be chosen as 2/T, where T is the time length of the maneuver, and
    the upper bound should be chosen to include the dynamics of interest, typically around
    1.2 Hz for rigid-body modes of full-scale aircraft", with "frequency resolution of 0.04 Hz".
    Eq. 18's own 0.20 Hz is this rule for T = 10 s; a 20 s maneuver starts at 0.10 Hz, below
    which a 20 s record holds less than two cycles.

    Parameters
    ----------
    duration_s : float
        ``T``, the record length ``(N - 1) dt``, s.
    upper_hz, step_hz : float, optional
        Upper bound (default 1.2 Hz) and resolution (default 0.04 Hz).

    Returns
    -------
    numpy.ndarray
        ``2/T, 2/T + step, ...`` up to ``upper_hz`` (included when it falls on the grid,
        within 1e-9 of a step).

    Raises
    ------
    ValueError
        When ``2/T`` exceeds ``upper_hz`` (a record shorter than ``2/upper_hz`` s), or on
        non-positive arguments.
    """
    T, upper, step = float(duration_s), float(upper_hz), float(step_hz)
    if not (np.isfinite(T) and T > 0 and upper > 0 and step > 0):
        raise ValueError("duration, upper bound and step must be positive")
    f0 = 2.0 / T
    if f0 > upper * (1 + 1e-12):
        raise ValueError(f"a {T:.3g} s record is too short for the seed's band: its lower bound 2/T = "
                         f"{f0:.3g} Hz is above the upper bound {upper:.3g} Hz")
    n = int(np.floor((upper - f0) / step + 1e-9)) + 1
    return f0 + step * np.arange(n)


def _as_frequencies(frequencies_hz: npt.ArrayLike) -> np.ndarray:
    f = np.asarray(frequencies_hz, dtype=float)
    if f.ndim > 1:
        raise ValueError("frequencies_hz must be a scalar or a 1-D array")
    f = np.atleast_1d(f)
    if f.size == 0:
        raise ValueError("frequencies_hz is empty")
    if not np.all(np.isfinite(f)):
        raise ValueError("frequencies_hz must be finite")
    return f


def _as_samples(x: npt.ArrayLike, min_len: int) -> np.ndarray:
    a = np.asarray(x)
    if np.iscomplexobj(a):
        a = a.astype(complex)
    else:
        a = a.astype(float)
    if a.ndim not in (1, 2):
        raise ValueError("x must be 1-D (N,) or 2-D (N, ncols), time along axis 0")
    if a.shape[0] < min_len:
        raise ValueError(f"x needs at least {min_len} samples along axis 0, got {a.shape[0]}")
    if not np.all(np.isfinite(a)):
        raise ValueError("x contains NaN or infinite values")
    return a


def _transform_inputs(x: npt.ArrayLike, dt: float, frequencies_hz: npt.ArrayLike,
                      min_len: int) -> tuple[np.ndarray, bool, float, np.ndarray]:
    """The checked inputs of a transform: samples as columns, whether ``x`` was 1-D, ``dt``
    and the angular frequencies."""
    a = _as_samples(x, min_len)
    dt = _check_dt(dt)
    omega = 2.0 * np.pi * _as_frequencies(frequencies_hz)
    one_d = a.ndim == 1
    return (a[:, None] if one_d else a), one_d, dt, omega


def _check_dt(dt: float) -> float:
    dt = float(dt)
    if not (np.isfinite(dt) and dt > 0.0):
        raise ValueError("dt must be a positive finite number")
    return dt


def _is_uniform(theta: np.ndarray) -> bool:
    if theta.size < 3:
        return False
    step = np.diff(theta)
    return bool(step[0] != 0.0 and np.allclose(step, step[0], rtol=1e-10, atol=0.0))


def _riemann_sums(x: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """``S(theta_k) = sum_i x_i exp(-1j*theta_k*i)`` for every column of ``x``.

    ``x`` has shape (N, ncols); the result has shape (m, ncols).  A chirp-z
    transform (O((N+m) log(N+m))) is used when the grid is uniform and long
    enough for it to pay off (m >= 64); otherwise the sum is evaluated
    directly as a matrix product (O(N m)), in blocks of samples to bound
    memory.  The direct sum is accurate to ~1e-16 * theta * N relative; the
    chirp-z route loses ~1e-16 * dtheta * N**2 / 2 in its chirp phases
    (~1e-9 relative at N = 1e5), which is why it is not used for short grids
    such as the seed's 26 frequencies, where it is not faster either.
    """
    n = x.shape[0]
    m = theta.size
    if m >= 64 and _is_uniform(theta):
        step = theta[1] - theta[0]
        # z_k = a * w**(-k) = exp(1j*theta_k), so that sum_i x_i z_k**(-i)
        # is the required sum.
        out = signal.czt(
            x, m=m, w=np.exp(-1j * step), a=np.exp(1j * theta[0]), axis=0
        )
        return np.asarray(out, dtype=complex)
    out = np.zeros((m, x.shape[1]), dtype=complex)
    block = max(1, 2**20 // max(m, 1))
    for start in range(0, n, block):
        idx = np.arange(start, min(start + block, n), dtype=float)
        kernel = np.exp(-1j * np.multiply.outer(theta, idx))
        out += kernel @ x[start : start + idx.size]
    return out


def _moments(theta: np.ndarray) -> np.ndarray:
    """``mu_n(theta) = int_0^1 s**n exp(-1j*theta*s) ds`` for n = 0..3.

    Returns shape (4, m).  For ``|theta| <= 1`` the Taylor series
    ``mu_n = sum_k (-1j*theta)**k / (k! (n+k+1))`` is summed (no cancellation);
    otherwise the closed forms from integration by parts are used,
    ``mu_0 = (1 - e)/(1j*theta)``, ``mu_n = (e - n*mu_{n-1})/(-1j*theta)``
    with ``e = exp(-1j*theta)``; their error growth ``n!/|theta|**n`` is at
    most 6 for ``|theta| > 1``.
    """
    mu = np.empty((4, theta.size), dtype=complex)
    small = np.abs(theta) <= _SERIES_THRESHOLD
    if np.any(small):
        u = -1j * theta[small]
        term = np.ones_like(u)  # (-1j*theta)**k / k!
        acc = np.zeros((4, u.size), dtype=complex)
        for k in range(_SERIES_TERMS):
            for n in range(4):
                acc[n] += term / (n + k + 1)
            term = term * u / (k + 1)
        mu[:, small] = acc
    large = ~small
    if np.any(large):
        th = theta[large]
        e = np.exp(-1j * th)
        mu[0, large] = (1.0 - e) / (1j * th)
        for n in range(1, 4):
            mu[n, large] = (e - n * mu[n - 1, large]) / (-1j * th)
    return mu


def interpolation_weights(theta: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Interior weight ``W(theta)`` and left end corrections ``alpha_i(theta)``.

    These are the transfer quantities of the piecewise-cubic Lagrange
    interpolant used by :func:`finite_fourier_transform`; ``theta = omega*dt``.

    Parameters
    ----------
    theta : array_like
        Normalised angular frequencies (radians per sample), real.

    Returns
    -------
    W : numpy.ndarray, shape (m,)
        Real interior weight, ``W(theta) = (6 + theta**2)(3 - 4 cos theta +
        cos 2 theta) / (3 theta**4) = 1 - 11 theta**4/720 +
        23 theta**6/15120 - 139 theta**8/1814400 + ...``.
    alpha : numpy.ndarray, shape (4, m), complex
        Left end corrections ``alpha_0..alpha_3``; at ``theta = 0`` they are
        ``-2/3, 7/24, -1/6, 1/24`` (the end weights of the quadrature rule
        that integrates the interpolant exactly).  The right end uses their
        complex conjugates (see :func:`finite_fourier_transform`).

    Notes
    -----
    With ``c_l(theta) = int_0^1 L_l(s) e^{-j theta s} ds`` for the centred
    cubic Lagrange basis on nodes ``l = -1, 0, 1, 2`` and
    ``d_i(theta) = int_0^1 M_i(s) e^{-j theta s} ds`` for the one-sided basis
    on nodes ``i = 0..3`` (used on the first interval):

    ``W = sum_l c_l e^{j theta l}``,
    ``alpha_i = e^{j theta i} d_i - sum_{l = max(i, -1)}^{2} e^{j theta l} c_l``.

    Both are evaluated from the moments ``mu_n`` (:func:`_moments`), i.e. as
    sums of O(1) terms: this is equivalent to using the Taylor series of
    ``W`` and ``alpha_i`` for small ``theta`` and has no ``1/theta**4``
    cancellation.
    """
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    mu = _moments(th)
    c = _LAGRANGE_CENTRED @ mu  # (4, m): rows l = -1, 0, 1, 2
    d = _LAGRANGE_ONE_SIDED @ mu  # (4, m): rows i = 0, 1, 2, 3
    shifts = np.arange(-1, 3)  # node offsets l
    phase = np.exp(1j * np.multiply.outer(shifts, th))  # e^{j theta l}
    weighted = phase * c  # e^{j theta l} c_l, rows l = -1..2
    w = weighted.sum(axis=0).real
    alpha = np.empty((4, th.size), dtype=complex)
    for i in range(4):
        tail = weighted[max(i, -1) + 1 :].sum(axis=0)  # l = max(i,-1)..2
        alpha[i] = np.exp(1j * i * th) * d[i] - tail
    return w, alpha


def finite_fourier_transform(
    x: npt.ArrayLike,
    dt: float,
    frequencies_hz: npt.ArrayLike,
    *,
    t0: float = 0.0,
) -> np.ndarray:
    """Finite Fourier transform of the cubic interpolant of sampled data.

    Evaluates, at arbitrary frequencies ``f_k``,

    .. math:: X(\\omega) = \\int_{t_0}^{t_0+T} x(t)\\, e^{-j \\omega t}\\, dt,
              \\qquad T = (N-1)\\,dt,\\ \\omega = 2\\pi f,

    where ``x(t)`` is the piecewise-cubic interpolant of the samples
    ``x_i = x(t_0 + i dt)``: on each interval the cubic through the four
    nearest samples (centred), with one-sided cubics on the first and last
    interval.  The result is exact for any cubic polynomial and has
    O(dt**4) error for smooth signals; ``T`` need not be a multiple of any
    period and the frequencies need not lie on a DFT grid.  This is the
    transform used for the frequency-domain equation-error method of the
    seed paper (Eqs. 18-23).

    Parameters
    ----------
    x : array_like, shape (N,) or (N, ncols)
        Uniformly sampled data, time along axis 0; ``N >= 4``.  Real or
        complex; columns are transformed independently.
    dt : float
        Sampling interval in seconds.
    frequencies_hz : array_like, shape (m,)
        Frequencies in Hz (any spacing, any order, negative allowed).
    t0 : float, optional
        Time of the first sample; the integral runs over ``[t0, t0 + T]``.

    Returns
    -------
    numpy.ndarray
        Complex, shape ``(m,)`` for 1-D ``x`` or ``(m, ncols)`` for 2-D ``x``.

    Notes
    -----
    Derivation.  Write ``theta = omega dt``.  On interval ``m`` the
    interpolant is ``sum_l x_{m+l} L_l(s)``, ``s = (t - t_m)/dt``, so the
    interval contributes ``dt e^{-j omega t_0} e^{-j theta m}
    sum_l c_l(theta) x_{m+l}`` with ``c_l = int_0^1 L_l(s) e^{-j theta s} ds``.
    If every interval used the centred stencil, the coefficient of ``x_i``
    would be ``dt e^{-j omega t_0} W(theta) e^{-j theta i}`` with
    ``W = sum_l c_l e^{j theta l}``, the Fourier transform of the (real,
    even) cubic-interpolation kernel.  The missing intervals beyond the ends
    and the one-sided stencils on the first/last interval only change the
    coefficients of the first and last four samples, so

    .. math::

        X(\\omega) = dt\\, e^{-j\\omega t_0} \\Big[ W(\\theta) S(\\theta)
            + \\sum_{i=0}^{3} \\alpha_i(\\theta)\\, x_i\\, e^{-j\\theta i}
            + e^{-j\\theta (N-1)} \\sum_{i=0}^{3} \\overline{\\alpha_i(\\theta)}\\,
              x_{N-1-i}\\, e^{j\\theta i} \\Big],
        \\qquad S(\\theta) = \\sum_{i=0}^{N-1} x_i e^{-j\\theta i},

    with ``alpha_i = e^{j theta i} d_i - sum_{l=max(i,-1)}^{2} e^{j theta l} c_l``
    (``d_i``: same integrals for the one-sided basis).  The right-end terms
    follow from the left ones by the time reversal ``t -> t0 + T - t``,
    which maps the scheme onto itself and ``theta`` onto ``-theta``
    (``alpha_i(-theta) = conj(alpha_i(theta))`` for real ``theta``).  See
    :func:`interpolation_weights` for ``W`` and the ``alpha_i``, which are
    evaluated from Taylor series for ``|theta| <= 1``.  The Riemann sums
    ``S(theta)`` come from a chirp-z transform
    (:func:`scipy.signal.czt`) on long uniform grids and from a direct
    O(N m) matrix product otherwise.

    References
    ----------
    E. A. Morelli, "High accuracy evaluation of the finite Fourier transform
    using sampled data", NASA TM 110340, 1997.
    E. A. Morelli, "Practical Aspects of the Equation-Error Method for
    Aircraft Parameter Estimation" (seed paper), Eqs. 18-23.
    """
    a2, one_d, dt, omega = _transform_inputs(x, dt, frequencies_hz, 4)
    n = a2.shape[0]
    theta = omega * dt
    w, alpha = interpolation_weights(theta)
    s = _riemann_sums(a2, theta)
    idx = np.arange(4)
    left = np.exp(-1j * np.multiply.outer(theta, idx)) * alpha.T  # (m, 4)
    right = (
        np.exp(-1j * np.multiply.outer(theta, (n - 1) - idx)) * np.conj(alpha).T
    )  # coefficient of x_{N-1-i}
    corr = left @ a2[:4] + right @ a2[n - 1 - idx]
    out = dt * np.exp(-1j * omega * float(t0))[:, None] * (w[:, None] * s + corr)
    return out[:, 0] if one_d else out


def plain_dft(
    x: npt.ArrayLike,
    dt: float,
    frequencies_hz: npt.ArrayLike,
    *,
    t0: float = 0.0,
) -> np.ndarray:
    """Plain Riemann-sum approximation of the finite Fourier transform.

    ``X(omega) ~ dt * sum_{i=0}^{N-1} x_i exp(-j omega (t0 + i dt))`` -- the
    simple sum that :func:`finite_fourier_transform` corrects; provided for
    comparison.  Its error is O(dt) (the end-point terms of the rectangle
    rule) and it carries the full aliasing of the sampled sum.

    Parameters
    ----------
    x : array_like, shape (N,) or (N, ncols)
        Uniformly sampled data, time along axis 0.
    dt : float
        Sampling interval in seconds.
    frequencies_hz : array_like, shape (m,)
        Frequencies in Hz.
    t0 : float, optional
        Time of the first sample.

    Returns
    -------
    numpy.ndarray
        Complex, shape ``(m,)`` or ``(m, ncols)``.
    """
    a2, one_d, dt, omega = _transform_inputs(x, dt, frequencies_hz, 1)
    s = _riemann_sums(a2, omega * dt)
    out = dt * np.exp(-1j * omega * float(t0))[:, None] * s
    return out[:, 0] if one_d else out


def held_fourier_transform(
    x: npt.ArrayLike,
    dt: float,
    frequencies_hz: npt.ArrayLike,
    *,
    t0: float = 0.0,
) -> np.ndarray:
    """Finite Fourier transform of the zero-order hold of sampled data.

    The signal is taken as piecewise constant, ``x(t) = x_i`` on ``[t_i, t_i + dt)``
    (``t_i = t0 + i dt``, ``i = 0 .. N-2``), the shape of a digital command that changes at
    sample instants (a simulated 2-1-1-2 whose steps fall on samples, the sample at a step
    holding the new value). Its transform over ``[t0, t0 + T]``, ``T = (N-1) dt``, is exact:

    .. math:: X(\\omega) = \\frac{1 - e^{-j\\omega dt}}{j\\omega}
              \\sum_{i=0}^{N-2} x_i\\, e^{-j\\omega t_i}

    (``dt`` times the sum at ``omega = 0``). For such a signal the cubic interpolant of
    :func:`finite_fourier_transform` spreads each jump over the interval before it, i.e.
    centres it half a sample early: at frequency ``f`` a phase lead of ``pi f dt`` against
    states that respond to the true step (seed Eqs. 19-23 then fit a regressor shifted by
    ``dt/2``).

    Parameters
    ----------
    x : array_like, shape (N,) or (N, ncols)
        Uniformly sampled data, time along axis 0; ``N >= 2``.
    dt : float
        Sampling interval in seconds.
    frequencies_hz : array_like, shape (m,)
        Frequencies in Hz.
    t0 : float, optional
        Time of the first sample.

    Returns
    -------
    numpy.ndarray
        Complex, shape ``(m,)`` or ``(m, ncols)``.
    """
    a2, one_d, dt, omega = _transform_inputs(x, dt, frequencies_hz, 2)
    theta = omega * dt
    s = _riemann_sums(a2[:-1], theta)
    # (1 - exp(-j theta)) / (j omega) = dt * exp(-j theta/2) * sinc(theta/2), finite at 0
    hold = dt * np.exp(-0.5j * theta) * np.sinc(theta / (2.0 * np.pi))
    out = (np.exp(-1j * omega * float(t0)) * hold)[:, None] * s
    return out[:, 0] if one_d else out
