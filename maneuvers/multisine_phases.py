"""Phase design for flat-spectrum multisines: Schroeder phases, peak-factor
optimisation and the zero-start time shift.

A unit multisine over one period, in normalised time ``u = τ / T ∈ [0, 1)``, is

.. math::  x(u) = \\sum_{n=1}^{N} \\sin(2π k_n u + φ_n),

with integer harmonics ``k_n`` of ``1/T`` and equal amplitudes (flat power
spectrum).  Its rms is ``sqrt(N/2)``, so the relative peak factor

.. math::  \\mathrm{RPF} = \\frac{\\max x - \\min x}{2\\sqrt{2}\\,\\mathrm{rms}}
                        = \\frac{\\max x - \\min x}{2\\sqrt{N}}

is 1 for a single sinusoid.  Low RPF puts more energy into the excitation for
a given peak deflection.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy.optimize import brentq, minimize

P_SCHEDULE: tuple[float, ...] = (4.0, 16.0, 64.0, 256.0)
"""Exponents of the p-norm continuation in :func:`optimize_phases`."""


def schroeder_phases(n_components: int) -> np.ndarray:
    """Schroeder (1970) phases for ``N`` equal-power components.

    Schroeder's rule for component powers ``p_l`` (``Σ p_l = 1``) is
    ``φ_n = φ_1 - 2π Σ_{l<n} (n - l) p_l``.  For a flat spectrum
    ``p_l = 1/N`` the sum is ``n(n-1)/(2N)``, giving

    .. math::  φ_n = -π n (n - 1) / N, \\qquad n = 1..N,

    with ``φ_1 = 0``.  (The variant ``-π n² / N`` differs by the linear term
    ``-π n / N``, i.e. a time shift for equally spaced harmonics.)  Returned
    wrapped to ``[0, 2π)``.
    """
    if n_components < 1:
        raise ValueError(f"need at least one component, got {n_components}")
    n = np.arange(1, n_components + 1, dtype=float)
    return np.mod(-np.pi * n * (n - 1.0) / n_components, 2.0 * np.pi)


def synthesize(harmonics: npt.ArrayLike, phases: npt.ArrayLike, u: npt.ArrayLike) -> np.ndarray:
    """Unit-amplitude multisine ``Σ sin(2π k_n u + φ_n)`` at normalised times ``u``."""
    k = np.asarray(harmonics, dtype=float)
    phi = np.asarray(phases, dtype=float)
    uu = np.asarray(u, dtype=float)
    arg = 2.0 * np.pi * uu[..., None] * k + phi
    return np.sin(arg).sum(axis=-1)


def _derivatives(k: np.ndarray, phi: np.ndarray, u: npt.ArrayLike) -> tuple[np.ndarray, ...]:
    """``x(u)``, ``x'(u)``, ``x''(u)`` of the unit multisine (derivatives in ``u``)."""
    w = 2.0 * np.pi * k
    arg = np.asarray(u, dtype=float)[..., None] * w + phi
    s, c = np.sin(arg), np.cos(arg)
    return s.sum(axis=-1), (w * c).sum(axis=-1), -(w * w * s).sum(axis=-1)


def grid_size(harmonics: npt.ArrayLike, per_cycle: int = 32, minimum: int = 256) -> int:
    """Power-of-two samples per period, ``>= per_cycle`` per cycle of the top harmonic."""
    k_max = int(np.max(np.asarray(harmonics)))
    return 1 << max(minimum, per_cycle * k_max).bit_length()


def _refined_peak(
    k: np.ndarray, phi: np.ndarray, u: np.ndarray, x: np.ndarray, sign: float
) -> float:
    """Largest ``sign * x`` after Newton-refining every grid-local maximum of it.

    Each local maximum of ``sign * x`` on the periodic grid ``u`` (spacing
    ``du``) starts Newton iterations on ``x'(u) = 0`` with steps clipped to
    ``±du``; an iterate is kept only where it increases ``sign * x``.
    """
    y = sign * x
    du = u[1] - u[0]
    peaks = np.flatnonzero((y >= np.roll(y, 1)) & (y >= np.roll(y, -1)))
    uu, best = u[peaks].copy(), y[peaks].copy()
    for _ in range(6):
        _, d1, d2 = _derivatives(k, phi, uu)
        step = np.clip(np.divide(d1, d2, out=np.zeros_like(d1), where=d2 != 0.0), -du, du)
        trial = uu - step
        val = sign * _derivatives(k, phi, trial)[0]
        better = val > best
        uu[better], best[better] = trial[better], val[better]
    return float(best.max())


def extrema(harmonics: npt.ArrayLike, phases: npt.ArrayLike) -> tuple[float, float]:
    """Continuous-time ``(max x, min x)`` of the unit multisine over one period.

    Samples a fine grid (:func:`grid_size`), then Newton-refines every
    grid-local maximum and minimum (:func:`_refined_peak`).
    """
    k = np.asarray(harmonics, dtype=float)
    phi = np.asarray(phases, dtype=float)
    m = grid_size(k)
    u = np.arange(m) / m
    x = synthesize(k, phi, u)
    return _refined_peak(k, phi, u, x, 1.0), -_refined_peak(k, phi, u, x, -1.0)


def relative_peak_factor(x: npt.ArrayLike) -> float:
    """RPF ``(max - min) / (2 sqrt(2) rms)`` of samples covering whole periods.

    Equals 1 for a single sinusoid sampled over whole periods.
    """
    xa = np.asarray(x, dtype=float)
    rms = math.sqrt(float(np.mean(xa * xa)))
    if rms == 0.0:
        raise ValueError("relative peak factor of an all-zero signal is undefined")
    return float(xa.max() - xa.min()) / (2.0 * math.sqrt(2.0) * rms)


def multisine_rpf(harmonics: npt.ArrayLike, phases: npt.ArrayLike) -> float:
    """Continuous-time RPF ``(max - min) / (2 sqrt(N))`` of the unit multisine."""
    hi, lo = extrema(harmonics, phases)
    return (hi - lo) / (2.0 * math.sqrt(len(np.atleast_1d(harmonics))))


def _pnorm_objective(
    params: np.ndarray, cos_basis: np.ndarray, sin_basis: np.ndarray, p: float
) -> tuple[float, np.ndarray]:
    """p-norm of ``x - c`` over the grid and its gradient in ``(φ, c)``.

    ``J = (mean |x_j - c|^p)^(1/p)`` tends to ``max |x - c|`` as ``p → ∞``;
    minimising over the offset ``c`` as well targets ``(max x - min x)/2``,
    i.e. the RPF rather than the crest factor.  Computed as
    ``J = m S^(1/p)`` with ``m = max |x - c|``, ``S = mean (|x - c|/m)^p``
    to avoid overflow; ``∂J/∂x_j = S^(1/p - 1) (|y_j|/m)^(p-1) sign(y_j) / M``.
    """
    phi, c = params[:-1], params[-1]
    cp, sp = np.cos(phi), np.sin(phi)
    x = sin_basis @ cp + cos_basis @ sp  # sin(a + φ) = sin a cos φ + cos a sin φ
    y = x - c
    m = float(np.max(np.abs(y)))
    r = np.abs(y) / m
    s = float(np.mean(r**p))
    j = m * s ** (1.0 / p)
    g_y = s ** (1.0 / p - 1.0) * r ** (p - 1.0) * np.sign(y) / y.size
    g_phi = g_y @ cos_basis * cp - g_y @ sin_basis * sp  # Σ_j g_j cos(a_jn + φ_n)
    return j, np.concatenate((g_phi, [-g_y.sum()]))


def optimize_phases(
    harmonics: npt.ArrayLike,
    initial_phases: npt.ArrayLike,
    p_schedule: tuple[float, ...] = P_SCHEDULE,
) -> np.ndarray:
    """Lower the RPF by p-norm continuation from ``initial_phases``.

    For each ``p`` in ``p_schedule`` minimise the p-norm of ``x - c`` over the
    phases and an offset ``c`` (L-BFGS-B, analytic gradient, see
    :func:`_pnorm_objective`), warm-starting from the previous ``p``.  The
    amplitudes, hence the power spectrum, are untouched.  Deterministic.
    Returns the phases with the lowest continuous-time RPF met along the way
    (never worse than ``initial_phases``), wrapped to ``[0, 2π)``.
    """
    k = np.asarray(harmonics, dtype=float)
    phi0 = np.asarray(initial_phases, dtype=float)
    m = grid_size(k)
    a = 2.0 * np.pi * np.outer(np.arange(m) / m, k)
    sin_basis, cos_basis = np.sin(a), np.cos(a)
    best_phi, best_rpf = phi0, multisine_rpf(k, phi0)
    x0 = synthesize(k, phi0, np.arange(m) / m)
    params = np.concatenate((phi0, [0.5 * (x0.max() + x0.min())]))
    for p in p_schedule:
        res = minimize(
            _pnorm_objective,
            params,
            args=(cos_basis, sin_basis, p),
            jac=True,
            method="L-BFGS-B",
            options={"maxiter": 500, "gtol": 1e-10, "ftol": 1e-13},
        )
        params = res.x
        rpf = multisine_rpf(k, params[:-1])
        if rpf < best_rpf:
            best_phi, best_rpf = params[:-1].copy(), rpf
    return np.mod(best_phi, 2.0 * np.pi)


def zero_start_phases(harmonics: npt.ArrayLike, phases: npt.ArrayLike) -> np.ndarray:
    """Shift the time origin to a zero crossing so that ``x(0) = x(T) = 0``.

    The signal has no mean term, so it crosses zero in every period.  Among
    all zero crossings ``u_0`` the one with the smallest slope ``|x'(u_0)|``
    is chosen (smoothest start), and the time origin is moved there:
    ``φ_n ← φ_n + 2π k_n u_0``.  A time shift leaves the amplitude spectrum,
    the peak values and the RPF unchanged, and by periodicity the window
    ``[0, T)`` then also ends at zero.
    """
    k = np.asarray(harmonics, dtype=float)
    phi = np.asarray(phases, dtype=float)
    m = grid_size(k)
    u = np.arange(m + 1) / m
    x = synthesize(k, phi, u)
    x[-1] = x[0]  # exact periodicity at the seam

    def f(v: float) -> float:
        return float(_derivatives(k, phi, v)[0])

    best_u, best_slope = 0.0, math.inf
    for j in np.flatnonzero(np.sign(x[:-1]) != np.sign(x[1:])):
        root = float(u[j]) if x[j] == 0.0 else brentq(f, u[j], u[j + 1], xtol=1e-15)
        slope = abs(float(_derivatives(k, phi, root)[1]))
        if slope < best_slope:
            best_u, best_slope = root, slope
    return np.mod(phi + 2.0 * np.pi * k * best_u, 2.0 * np.pi)


def design_phases(
    harmonics: npt.ArrayLike, optimize: bool = True, restarts: int = 4, seed: int = 0
) -> tuple[np.ndarray, float, float]:
    """Phases for a flat-spectrum multisine on ``harmonics``, zero-start shifted.

    Starts from Schroeder phases (:func:`schroeder_phases`); if ``optimize``,
    runs :func:`optimize_phases` from them and from ``restarts`` further
    starting points drawn from a local ``numpy.random.default_rng(seed)``
    (deterministic; no global random state), keeping the lowest RPF.  The
    result is then time-shifted by :func:`zero_start_phases`.

    Returns
    -------
    phases : ndarray
        Final phases, radians, in ``[0, 2π)``.
    rpf_schroeder : float
        Continuous-time RPF of the Schroeder phases.
    rpf : float
        Continuous-time RPF of the returned phases (``<= rpf_schroeder``).
    """
    k = np.asarray(harmonics, dtype=float)
    schroeder = schroeder_phases(k.size)
    rpf_schroeder = multisine_rpf(k, schroeder)
    best, best_rpf = schroeder, rpf_schroeder
    if optimize and k.size > 1:
        rng = np.random.default_rng(seed)
        starts = [schroeder] + [rng.uniform(0.0, 2.0 * np.pi, k.size) for _ in range(restarts)]
        for start in starts:
            phases = optimize_phases(k, start)
            rpf = multisine_rpf(k, phases)
            if rpf < best_rpf:
                best, best_rpf = phases, rpf
    shifted = zero_start_phases(k, best)
    return shifted, rpf_schroeder, multisine_rpf(k, shifted)
