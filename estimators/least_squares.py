"""Least squares for real (time-domain) and complex (frequency-domain) data."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from models.errors import UserError


class SingularRegressorsError(UserError):
    """The regressors are linearly dependent; the message names the columns involved."""


@dataclass(frozen=True)
class LeastSquares:
    """θ̂, (Re X†X)⁻¹, residuals, fitted values and σ̂² of one least-squares problem."""

    theta: np.ndarray
    xtx_inv: np.ndarray
    residuals: np.ndarray
    fitted: np.ndarray
    s2: float
    # (Q, R), the thin QR factorisation of the (real-stacked) regressors, when asked for
    # (``keep_factor``): colored_residual_covariance reuses it instead of factorising again
    factor: tuple[np.ndarray, np.ndarray] | None = None


def _real_stack(A: np.ndarray) -> np.ndarray:
    """Seed Eq. 23: complex rows become their real parts with the imaginary parts below."""
    return np.concatenate([A.real, A.imag], axis=0) if np.iscomplexobj(A) else A


def _check_shape(A: np.ndarray, names: tuple[str, ...] | list[str]) -> None:
    if A.shape[0] < A.shape[1]:
        raise SingularRegressorsError(f"{A.shape[0]} data points cannot determine {A.shape[1]} parameters "
                                      f"({', '.join(names)})")


def _check_scaled(A: np.ndarray, names: tuple[str, ...] | list[str], rtol: float) -> None:
    """The zero-column and singular-value tests of :func:`check_rank` on ``A``: the regressors
    themselves or their triangular QR factor ``R`` (same column norms, same singular values and
    right singular vectors once the columns are scaled, since ``Q`` is orthonormal)."""
    norms = np.linalg.norm(A, axis=0)
    zero = [names[j] for j in np.flatnonzero(norms == 0)]
    if zero:
        raise SingularRegressorsError(f"regressor(s) {', '.join(zero)} are identically zero: "
                                      "the data do not excite them")
    _, s, vt = np.linalg.svd(A / norms, full_matrices=False)
    if s[-1] <= rtol * s[0]:
        v = np.abs(vt[-1])
        involved = [names[j] for j in np.argsort(-v) if v[j] > 0.05 * v.max()]
        raise SingularRegressorsError(
            f"singular regressors: {' , '.join(involved)} are linearly dependent "
            f"(scaled condition number {s[0] / max(s[-1], 1e-300):.3g}); remove one of them or "
            "fly a maneuver that separates them")


def check_rank(X: np.ndarray, names: tuple[str, ...] | list[str], *, rtol: float = 1e-10) -> None:
    """Refuse linearly dependent regressors, naming the columns of the offending combination.

    Columns are scaled to unit length first, so the test does not depend on units."""
    A = _real_stack(np.asarray(X))
    _check_shape(A, names)
    _check_scaled(A, names, rtol)


def least_squares(X: np.ndarray, z: np.ndarray, names: tuple[str, ...] | list[str], *,
                  keep_factor: bool = False) -> LeastSquares:
    """Solve z = Xθ + ν in the least-squares sense.

    Real data: Eqs. 14-16, θ̂ = (XᵀX)⁻¹Xᵀz, σ̂² = (z − ŷ)ᵀ(z − ŷ)/(N − n_p).
    Complex data: Eqs. 19-21, θ̂ = [Re(X†X)]⁻¹ Re(X†z), solved through the real stacking of
    Eq. 23, with σ̂² = (z − ŷ)†(z − ŷ)/(m − n_p) where m counts complex points (not 2m).

    A QR factorisation solves the problem (never the normal equations), so near-collinear
    noise-free data are still solved to rounding error (seed §III.G). ``keep_factor`` keeps
    it in the result (``factor = (Q, R)``, N × n_p more memory while the result lives).

    Raises
    ------
    SingularRegressorsError
        Naming the dependent or all-zero regressors.
    """
    X = np.asarray(X)
    z = np.asarray(z)
    A, b = _real_stack(X), _real_stack(z)
    _check_shape(A, names)
    # check_rank's test on the n_p x n_p factor R instead of the N x n_p regressors (no scaled
    # copy and SVD of a long matrix): a zero column of A is an exactly zero column of R
    # (Householder reflections map zero to zero), and A D^-1 = Q (R D^-1) has the singular
    # values and right singular vectors of R D^-1.
    # factorised in place in a Fortran-ordered copy of ours (scipy's own copy of a C-ordered
    # array is several times slower for a long, narrow matrix)
    q, r = scipy.linalg.qr(np.array(A, order="F"), mode="economic", overwrite_a=True)
    _check_scaled(r, names, rtol=1e-10)
    theta = scipy.linalg.solve_triangular(r, q.T @ b)
    r_inv = scipy.linalg.solve_triangular(r, np.eye(r.shape[0]))
    xtx_inv = r_inv @ r_inv.T
    fitted = X @ theta
    resid = z - fitted
    n, p = X.shape
    s2 = float(np.real(np.vdot(resid, resid))) / (n - p) if n > p else float("nan")
    return LeastSquares(theta=theta, xtx_inv=xtx_inv, residuals=resid, fitted=fitted, s2=s2,
                        factor=(q, r) if keep_factor else None)


def r_squared(z: np.ndarray, residuals: np.ndarray) -> float:
    """1 − Σ|z − ŷ|² / Σ|z − z̄|²."""
    ss_tot = float(np.sum(np.abs(z - z.mean()) ** 2))
    return 1.0 - float(np.sum(np.abs(residuals) ** 2)) / ss_tot if ss_tot > 0 else float("nan")


# What is left of a vector its columns explain, relative to its norm, below which it is rounding.
NOTHING_LEFT = 1e-10


def residual_after(x: np.ndarray, columns: list[np.ndarray]) -> np.ndarray:
    """``x`` less its least-squares fit on ``columns`` (``x`` itself when there are none): the
    part of a regressor or a measurement the columns cannot explain."""
    if not columns:
        return np.asarray(x, dtype=float)
    A = np.column_stack(columns)
    return x - A @ np.linalg.lstsq(A, x, rcond=None)[0]


def partial_correlation(a: np.ndarray, b: np.ndarray, columns: list[np.ndarray]) -> float:
    """The correlation of ``a`` and ``b`` once their fits on ``columns`` are taken out (0 when
    either has nothing left beyond rounding: :data:`NOTHING_LEFT` of its own norm)."""
    ra, rb = residual_after(a, columns), residual_after(b, columns)
    if any(np.linalg.norm(r) <= NOTHING_LEFT * np.linalg.norm(x) for r, x in ((ra, a), (rb, b))):
        return 0.0
    return float(ra @ rb) / float(np.linalg.norm(ra) * np.linalg.norm(rb))
