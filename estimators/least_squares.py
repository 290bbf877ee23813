"""Least squares for real (time-domain) and complex (frequency-domain) data."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg


class SingularRegressorsError(ValueError):
    """The regressors are linearly dependent; the message names the columns involved."""


@dataclass(frozen=True)
class LeastSquares:
    """θ̂, (Re X†X)⁻¹, residuals, fitted values and σ̂² of one least-squares problem."""

    theta: np.ndarray
    xtx_inv: np.ndarray
    residuals: np.ndarray
    fitted: np.ndarray
    s2: float


def _real_stack(A: np.ndarray) -> np.ndarray:
    """Seed Eq. 23: complex rows become their real parts with the imaginary parts below."""
    return np.concatenate([A.real, A.imag], axis=0) if np.iscomplexobj(A) else A


def check_rank(X: np.ndarray, names: tuple[str, ...] | list[str], *, rtol: float = 1e-10) -> None:
    """Refuse linearly dependent regressors, naming the columns of the offending combination.

    Columns are scaled to unit length first, so the test does not depend on units."""
    A = _real_stack(np.asarray(X))
    if A.shape[0] < A.shape[1]:
        raise SingularRegressorsError(f"{A.shape[0]} data points cannot determine {A.shape[1]} parameters "
                                      f"({', '.join(names)})")
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


def least_squares(X: np.ndarray, z: np.ndarray, names: tuple[str, ...] | list[str]) -> LeastSquares:
    """Solve z = Xθ + ν in the least-squares sense.

    Real data: Eqs. 14-16, θ̂ = (XᵀX)⁻¹Xᵀz, σ̂² = (z − ŷ)ᵀ(z − ŷ)/(N − n_p).
    Complex data: Eqs. 19-21, θ̂ = [Re(X†X)]⁻¹ Re(X†z), solved through the real stacking of
    Eq. 23, with σ̂² = (z − ŷ)†(z − ŷ)/(m − n_p) where m counts complex points (not 2m).

    A QR factorisation solves the problem (never the normal equations), so near-collinear
    noise-free data are still solved to rounding error (seed §III.G).

    Raises
    ------
    SingularRegressorsError
        Naming the dependent or all-zero regressors.
    """
    X = np.asarray(X)
    z = np.asarray(z)
    check_rank(X, names)
    A, b = _real_stack(X), _real_stack(z)
    q, r = scipy.linalg.qr(A, mode="economic")
    theta = scipy.linalg.solve_triangular(r, q.T @ b)
    r_inv = scipy.linalg.solve_triangular(r, np.eye(r.shape[0]))
    xtx_inv = r_inv @ r_inv.T
    fitted = X @ theta
    resid = z - fitted
    n, p = X.shape
    s2 = float(np.real(np.vdot(resid, resid))) / (n - p) if n > p else float("nan")
    return LeastSquares(theta=theta, xtx_inv=xtx_inv, residuals=resid, fitted=fitted, s2=s2)


def r_squared(z: np.ndarray, residuals: np.ndarray) -> float:
    """1 − Σ|z − ŷ|² / Σ|z − z̄|²."""
    ss_tot = float(np.sum(np.abs(z - z.mean()) ** 2))
    return 1.0 - float(np.sum(np.abs(residuals) ** 2)) / ss_tot if ss_tot > 0 else float("nan")
