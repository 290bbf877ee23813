"""``ModelFit``: the one result type every estimator returns (statsmodels-style)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

COLLINEARITY_LIMIT = 0.9  # seed §III.G: trouble starts when |r| exceeds about 0.9


@dataclass(frozen=True)
class Collinearity:
    """Collinearity diagnostics of a regressor set.

    ``pairwise`` is |r_jk| of Eq. 50 (parameter correlation, the seed's measure);
    ``vif`` the variance inflation factor of each regressor, 1/(1 − R_j²), from the centred
    regressors (nan for the bias); ``condition_number`` that of the regressor matrix with
    columns scaled to unit length.
    """

    pairwise: np.ndarray
    vif: np.ndarray
    condition_number: float
    flagged: tuple[tuple[str, str, float], ...]


def parameter_correlation(cov: np.ndarray) -> np.ndarray:
    """Seed Eq. 50: r_jk = C_jk / sqrt(C_jj C_kk)."""
    d = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        r = cov / np.outer(d, d)
    np.fill_diagonal(r, 1.0)
    return r


# Above this many rows the diagnostics below work through blocks of rows (a few MB each) instead
# of centred, scaled copies of the whole regressor matrix; below it they are computed as always.
_BLOCK_ROWS = 1 << 16


def _blocks(n: int):
    for start in range(0, n, _BLOCK_ROWS):
        yield slice(start, min(start + _BLOCK_ROWS, n))


def variance_inflation(X: np.ndarray, is_bias: np.ndarray) -> np.ndarray:
    """VIF_j = 1/(1 − R_j²) of each non-constant column regressed on the others (centred):
    the diagonal of the inverse correlation matrix of the regressors."""
    cols = np.flatnonzero(~is_bias)
    out = np.full(X.shape[1], np.nan)
    if len(cols) == 0:
        return out
    if not np.iscomplexobj(X) and X.shape[0] > _BLOCK_ROWS:
        # the same centred cross-products, accumulated block by block
        mean = X[:, cols].mean(axis=0) if len(cols) == X.shape[1] else np.array([X[:, j].mean() for j in cols])
        G = np.zeros((len(cols), len(cols)))
        for rows in _blocks(X.shape[0]):
            B = X[rows][:, cols] - mean
            G += B.T @ B
        norms = np.sqrt(np.diag(G))
        if np.any(norms == 0):
            return out
        Rm = G / np.outer(norms, norms)
    else:
        Xr = np.real(X[:, cols]) if not np.iscomplexobj(X) else np.vstack([X[:, cols].real, X[:, cols].imag])
        Xc = Xr - (Xr.mean(axis=0) if not np.iscomplexobj(X) else 0.0)
        norms = np.linalg.norm(Xc, axis=0)
        if np.any(norms == 0):
            return out
        Rm = (Xc / norms).T @ (Xc / norms)
    if len(cols) == 1:
        out[cols] = 1.0
        return out
    out[cols] = np.diag(np.linalg.pinv(Rm))
    return out


def scaled_condition_number(X: np.ndarray) -> float:
    """Condition number of X with each column scaled to unit Euclidean length."""
    A = np.vstack([X.real, X.imag]) if np.iscomplexobj(X) else X
    if A.shape[0] > _BLOCK_ROWS and A.shape[0] > A.shape[1]:
        # cond(A D^-1) = cond(R) of its QR factor, built block by block (R of [R; next block])
        norms = np.sqrt(sum(np.einsum("ij,ij->j", A[rows], A[rows]) for rows in _blocks(A.shape[0])))
        norms[norms == 0] = 1.0
        R = np.zeros((0, A.shape[1]))
        for rows in _blocks(A.shape[0]):
            R = np.linalg.qr(np.vstack([R, A[rows] / norms]), mode="r")
        return float(np.linalg.cond(R))
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    return float(np.linalg.cond(A / norms))


def collinearity(X: np.ndarray, names: tuple[str, ...], cov: np.ndarray,
                 is_bias: np.ndarray | None = None) -> Collinearity:
    """Diagnostics and the warnings for pairs with |r| > 0.9 (seed's rule of thumb)."""
    if is_bias is None:
        is_bias = np.array([n == "bias" for n in names])
    r = np.abs(parameter_correlation(cov))
    flagged = []
    for j in range(len(names)):
        for k in range(j + 1, len(names)):
            if r[j, k] > COLLINEARITY_LIMIT and not (is_bias[j] or is_bias[k]):
                flagged.append((names[j], names[k], float(r[j, k])))
    return Collinearity(pairwise=r, vif=variance_inflation(X, is_bias),
                        condition_number=scaled_condition_number(X), flagged=tuple(flagged))


@dataclass(frozen=True)
class ModelFit:
    """Estimates with their uncertainty, residuals and fit statistics.

    Attributes
    ----------
    method : str
        ``'ee-time'``, ``'ee-smooth'``, ``'ee-freq'``, ``'oe'`` ...
    domain : str
        ``'time'`` or ``'frequency'``.
    dependent : str
        What was modelled (``'Cm'``; for output error the outputs, e.g. ``'alpha,q,az'``).
    names : tuple of str
        Parameter names, e.g. ``'Cm_alpha'``; the constant term is ``'bias'``.
    params, cov : ndarray
        Estimates and their covariance (conventional Eq. 15/20, colored Eq. 40, or the
        Cramér-Rao bound for output error, per ``errors``).
    residuals, fitted : ndarray
        z − ŷ and ŷ (complex in the frequency domain; N×n_o for output error).
    n : int
        Data points used (N samples, or m frequencies).
    s2 : float
        Residual variance estimate (Eq. 16 / 21; for output error the trace-weighted
        cost per point).
    r2 : float
        Coefficient of determination, 1 − Σ|z − ŷ|²/Σ|z − z̄|².
    errors : str
        How ``cov`` was computed.
    warnings : tuple of str
        What the user should know about this result (collinearity, strongly coloured
        residuals, missing trim values ...).
    assumptions : tuple of str
        What was assumed where the recording was silent (e.g. thrust constant at trim).
    """

    method: str
    domain: str
    dependent: str
    names: tuple[str, ...]
    params: np.ndarray
    cov: np.ndarray
    residuals: np.ndarray
    fitted: np.ndarray
    n: int
    s2: float
    r2: float
    errors: str = "conventional"
    collinearity: Collinearity | None = None
    warnings: tuple[str, ...] = ()
    info: Mapping = field(default_factory=dict)
    assumptions: tuple[str, ...] = ()

    # -- statsmodels-style accessors -------------------------------------------------
    @property
    def bse(self) -> np.ndarray:
        """Standard errors, sqrt of the covariance diagonal (Eqs. 17 / 22)."""
        return np.sqrt(np.diag(self.cov))

    def cov_params(self) -> np.ndarray:
        return self.cov

    def conf_int(self, k: float = 2.0) -> np.ndarray:
        """Intervals estimate ± k·standard error, shape (p, 2). The seed uses k = 2."""
        return np.column_stack([self.params - k * self.bse, self.params + k * self.bse])

    @property
    def correlation(self) -> np.ndarray:
        """Parameter correlation matrix (seed Eq. 50)."""
        return parameter_correlation(self.cov)

    @property
    def fit_error(self) -> float:
        """Fit error: the residual standard deviation sqrt(s²)."""
        return float(np.sqrt(self.s2))

    @property
    def pse(self) -> float:
        """Predicted square error: mean square fit error + σ²_max p/N, with σ²_max the
        variance of the dependent variable about its mean (Klein & Morelli's statistic for
        choosing model structure: it grows when terms are added that do not pay)."""
        z = self.fitted + self.residuals
        z = z.reshape(len(z), -1)
        sigma2_max = float(np.mean(np.abs(z - z.mean(axis=0)) ** 2))
        mse = float(np.mean(np.abs(self.residuals) ** 2))
        return mse + sigma2_max * len(self.params) / self.n

    def param(self, name: str) -> float:
        return float(self.params[self.index(name)])

    def std_error(self, name: str) -> float:
        return float(self.bse[self.index(name)])

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"{self.method} fit has no parameter {name!r}; it has {list(self.names)}") from None

    def summary(self) -> str:
        """A readable table of estimates, standard errors and fit statistics."""
        lines = [f"{self.method} ({self.domain} domain), {self.dependent}: n = {self.n}, "
                 f"errors = {self.errors}",
                 f"{'parameter':<14}{'estimate':>13}{'std error':>12}{'rel %':>8}"]
        for name, v, s in zip(self.names, self.params, self.bse):
            rel = 100 * s / abs(v) if v != 0 else float("inf")
            lines.append(f"{name:<14}{v:>13.6g}{s:>12.4g}{rel:>8.2f}")
        lines.append(f"s2 = {self.s2:.4g}   R2 = {self.r2:.5f}   fit error = {self.fit_error:.4g}   PSE = {self.pse:.4g}")
        if self.collinearity is not None:
            lines.append(f"condition number = {self.collinearity.condition_number:.3g}")
        lines += [f"warning: {w}" for w in self.warnings]
        lines += [f"assumption: {a}" for a in self.assumptions]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The JSON form of ``sidbench estimate``."""
        return {
            "method": self.method, "domain": self.domain, "dependent": self.dependent, "n": self.n,
            "errors": self.errors,
            "parameters": [{"name": n, "estimate": float(v), "std_error": float(s)}
                           for n, v, s in zip(self.names, self.params, self.bse)],
            "s2": float(self.s2), "r2": float(self.r2), "fit_error": self.fit_error, "pse": self.pse,
            "covariance": np.asarray(self.cov, dtype=float).tolist(),
            "correlation": np.nan_to_num(self.correlation).tolist(),
            "collinearity": None if self.collinearity is None else {
                "condition_number": self.collinearity.condition_number,
                "vif": [None if np.isnan(v) else float(v) for v in self.collinearity.vif]},
            "warnings": list(self.warnings),
            "assumptions": list(self.assumptions),
            "info": {k: v for k, v in self.info.items() if isinstance(v, (int, float, str, list, dict, bool))},
        }
