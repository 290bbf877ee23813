"""``ModelFit``: the one result type every estimator returns (statsmodels-style)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

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

    def warnings(self, *, parameters: bool = False) -> tuple[str, ...]:
        """One line per pair above :data:`COLLINEARITY_LIMIT`: regressors nearly collinear (an
        equation-error fit), or parameters highly correlated (``parameters``: output error)."""
        what = "parameters {} and {} are highly correlated" if parameters else \
            "regressors {} and {} are nearly collinear"
        return tuple(what.format(a, b) + f" (|r| = {r:.3f} > {COLLINEARITY_LIMIT:g}, seed Eq. 50)"
                     for a, b, r in self.flagged)


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


class ParamSeries(pd.Series):
    """A pandas Series indexed by parameter name (``fit.params["Cm_alpha"]``) that also takes
    integer positions and lists of them as the plain array did (``fit.params[0]``,
    ``fit.bse[[0, 2]]``), so code written for the array keeps working."""

    @property
    def _constructor(self):
        return ParamSeries

    @staticmethod
    def _positional(key) -> bool:
        if isinstance(key, (int, np.integer)) and not isinstance(key, (bool, np.bool_)):
            return True
        if isinstance(key, (list, tuple, np.ndarray)) and len(key) and not isinstance(key, str):
            return all(isinstance(k, (int, np.integer)) and not isinstance(k, (bool, np.bool_)) for k in key)
        return False

    # objects that set ``__array_ufunc__ = None`` (numpy's "defer to me", e.g. pytest.approx)
    # get the comparison, as they did from the array
    def __eq__(self, other):
        if getattr(type(other), "__array_ufunc__", 0) is None:
            return NotImplemented
        return super().__eq__(other)

    def __ne__(self, other):
        if getattr(type(other), "__array_ufunc__", 0) is None:
            return NotImplemented
        return super().__ne__(other)

    __hash__ = None

    def __getitem__(self, key):
        if self._positional(key):
            return self.iloc[list(key) if isinstance(key, tuple) else key]
        return super().__getitem__(key)


def _named(values, names, label: str) -> ParamSeries:
    return ParamSeries(np.asarray(values, dtype=float), index=pd.Index(list(names), name="parameter"), name=label)


@dataclass(frozen=True)
class OutputErrorInfo:
    """What output error adds to a fit, typed (``fit.output_error``; the same numbers as ``fit.info``).

    ``model`` the model's name; ``outputs`` the fitted outputs; ``converged``, ``iterations``,
    ``cost`` and ``cost_history`` the Gauss-Newton run; ``noise_covariance`` the output-noise
    covariance R (time domain) or spectral densities S (frequency domain); ``rsquared`` per output;
    ``start_source`` where the starting values came from; ``matrices`` A, B, C, D at the estimate
    (built-in linear models); ``dimensional`` the dimensional short-period derivatives when the
    model is the short period; ``frequencies_hz`` the band (frequency domain); ``notes``.
    """

    model: str
    outputs: tuple[str, ...]
    converged: bool
    iterations: int
    cost: float
    cost_history: tuple[float, ...]
    noise_covariance: np.ndarray
    rsquared: dict[str, float]
    start_source: str | None = None
    matrices: dict[str, np.ndarray] | None = None
    dimensional: dict[str, float] | None = None
    frequencies_hz: np.ndarray | None = None
    notes: tuple[str, ...] = ()

    @classmethod
    def from_info(cls, info: Mapping[str, Any]) -> "OutputErrorInfo":
        R = info.get("R", info.get("S"))
        r2 = info.get("r2", {})
        return cls(model=str(info.get("model", "")), outputs=tuple(info.get("outputs", ())),
                   converged=bool(info.get("converged", False)), iterations=int(info.get("iterations", 0)),
                   cost=float(info.get("cost", float("nan"))),
                   cost_history=tuple(float(c) for c in info.get("cost_history", ())),
                   noise_covariance=np.asarray(R if R is not None else np.zeros((0, 0))),
                   rsquared={k: float(v) for k, v in r2.items()} if isinstance(r2, Mapping) else {},
                   start_source=info.get("start_source"),
                   matrices=None if "matrices" not in info else
                   {k: np.asarray(v) for k, v in info["matrices"].items()},
                   dimensional=None if "dimensional" not in info else dict(info["dimensional"]),
                   frequencies_hz=None if "frequencies_hz" not in info else np.asarray(info["frequencies_hz"]),
                   notes=tuple(info.get("notes", ())))


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
    params : ParamSeries
        Estimates, a pandas Series indexed by name (``fit.params["Cm_alpha"]``; integer
        positions work too, as on the array it used to be).
    cov : ndarray
        Covariance of the estimates (conventional Eq. 15/20, colored Eq. 40, or the
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

    def __post_init__(self):
        object.__setattr__(self, "names", tuple(self.names))
        object.__setattr__(self, "params", _named(self.params, self.names, "params"))

    # -- statsmodels-style accessors -------------------------------------------------
    @property
    def bse(self) -> ParamSeries:
        """Standard errors, sqrt of the covariance diagonal (Eqs. 17 / 22), indexed by name."""
        return _named(np.sqrt(np.diag(np.asarray(self.cov, dtype=float))), self.names, "bse")

    def cov_params(self) -> pd.DataFrame:
        """The covariance as a DataFrame indexed by name on both axes (``np.asarray`` gives the array)."""
        return pd.DataFrame(np.asarray(self.cov, dtype=float), index=list(self.names), columns=list(self.names))

    @property
    def rsquared(self) -> float:
        """R², the statsmodels name of ``r2``."""
        return float(self.r2)

    @property
    def nobs(self) -> int:
        return int(self.n)

    @property
    def df_resid(self) -> int:
        """Residual degrees of freedom n − p (at least 1)."""
        return max(int(self.n) - len(self.names), 1)

    @property
    def uses_normal(self) -> bool:
        """True when the p-values and intervals use the normal distribution (Cramér-Rao bounds
        of output error, asymptotic), else Student's t with ``df_resid`` degrees of freedom."""
        return self.errors == "cramer-rao"

    @property
    def tvalues(self) -> ParamSeries:
        """Estimate over standard error, by name."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return _named(np.asarray(self.params) / np.asarray(self.bse), self.names, "tvalues")

    @property
    def pvalues(self) -> ParamSeries:
        """Two-sided p-values of the t-values (normal for Cramér-Rao bounds, else t with n − p dof)."""
        from scipy import stats
        t = np.abs(np.asarray(self.tvalues))
        p = 2 * (stats.norm.sf(t) if self.uses_normal else stats.t.sf(t, self.df_resid))
        return _named(p, self.names, "pvalues")

    def critical_value(self, alpha: float = 0.05) -> float:
        from scipy import stats
        if not 0 < alpha < 1:
            raise ValueError(f"alpha must lie in (0, 1), not {alpha}")
        return float(stats.norm.isf(alpha / 2) if self.uses_normal else stats.t.isf(alpha / 2, self.df_resid))

    def conf_int(self, alpha: float = 0.05, *, k: float | None = None) -> pd.DataFrame:
        """Confidence intervals as statsmodels gives them: a DataFrame indexed by name with
        columns ``lower`` and ``upper`` (positions 0 and 1: ``.iloc[:, 0]``; ``np.asarray`` gives
        the (p, 2) array), at level 1 − alpha (t with n − p dof, or normal for Cramér-Rao bounds).
        ``k=2`` gives the seed's intervals, estimate ± 2 standard errors."""
        c = float(k) if k is not None else self.critical_value(alpha)
        p, s = np.asarray(self.params), np.asarray(self.bse)
        return pd.DataFrame({"lower": p - c * s, "upper": p + c * s}, index=pd.Index(list(self.names), name="parameter"))

    @property
    def output_error(self) -> OutputErrorInfo | None:
        """Output error's extras, typed (None for the other methods)."""
        if "cost_history" not in self.info:
            return None
        return OutputErrorInfo.from_info(self.info)

    @property
    def correlation(self) -> np.ndarray:
        """Parameter correlation matrix (seed Eq. 50)."""
        return parameter_correlation(self.cov)

    @property
    def fit_error(self) -> float:
        """Fit error: the residual standard deviation sqrt(s²)."""
        return float(np.sqrt(self.s2))

    def truth_errors(self, truth: Mapping[str, float]) -> pd.DataFrame:
        """Estimates beside the truth (``{name: value}``, e.g. a recording's ``meta['truth']``
        derivatives by one definition): truth, error = estimate − truth, and the error in
        standard errors. Parameters without a truth get NaN."""
        tr = np.array([float(truth.get(n, np.nan)) for n in self.names])
        est, se = np.asarray(self.params), np.asarray(self.bse)
        with np.errstate(divide="ignore", invalid="ignore"):
            return pd.DataFrame({"estimate": est, "std_error": se, "truth": tr, "error": est - tr,
                                 "error_in_se": (est - tr) / se}, index=pd.Index(list(self.names), name="parameter"))

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

    def summary(self, truth: Mapping[str, float] | None = None) -> str:
        """A readable table of estimates, standard errors, t-values and fit statistics; with
        ``truth`` ({name: value}) also the truth and the error in standard errors."""
        lines = [f"{self.method} ({self.domain} domain), {self.dependent}: n = {self.n}, "
                 f"errors = {self.errors}",
                 f"{'parameter':<14}{'estimate':>13}{'std error':>12}{'rel %':>8}{'t':>9}"
                 + (f"{'truth':>13}{'error/se':>10}" if truth else "")]
        tv = np.asarray(self.tvalues)
        for i, (name, v, s) in enumerate(zip(self.names, np.asarray(self.params), np.asarray(self.bse))):
            rel = 100 * s / abs(v) if v != 0 else float("inf")
            line = f"{name:<14}{v:>13.6g}{s:>12.4g}{rel:>8.2f}{tv[i]:>9.3g}"
            if truth:
                t = truth.get(name)
                line += (f"{'-':>13}{'-':>10}" if t is None else
                         f"{t:>13.6g}{((v - t) / s if s > 0 else float('nan')):>10.2f}")
            lines.append(line)
        lines.append(f"s2 = {self.s2:.4g}   R2 = {self.r2:.5f}   fit error = {self.fit_error:.4g}   PSE = {self.pse:.4g}")
        if self.collinearity is not None:
            lines.append(f"condition number = {self.collinearity.condition_number:.3g}")
        lines += [f"warning: {w}" for w in self.warnings]
        lines += [f"assumption: {a}" for a in self.assumptions]
        return "\n".join(lines)

    def to_dict(self, *, residuals: bool = False) -> dict:
        """The JSON form of ``sidbench estimate``; ``residuals=True`` adds the residuals and
        fitted values (real and imaginary parts in the frequency domain)."""
        out = self._to_dict()
        ci = np.asarray(self.conf_int(0.05))
        for row, t, pv, (lo, hi) in zip(out["parameters"], np.asarray(self.tvalues), np.asarray(self.pvalues), ci):
            row.update(t_value=float(t), p_value=float(pv), ci95_lower=float(lo), ci95_upper=float(hi))
        if residuals:
            out["residuals"] = _json_array(self.residuals)
            out["fitted"] = _json_array(self.fitted)
        if self.output_error is not None:
            oe = self.output_error
            out["output_error"] = {"model": oe.model, "outputs": list(oe.outputs), "converged": oe.converged,
                                   "iterations": oe.iterations, "cost": oe.cost,
                                   "noise_covariance": np.asarray(oe.noise_covariance, dtype=float).tolist(),
                                   "rsquared": oe.rsquared, "start_source": oe.start_source}
        return out

    def _to_dict(self) -> dict:
        return {
            "method": self.method, "domain": self.domain, "dependent": self.dependent, "n": self.n,
            "errors": self.errors,
            "parameters": [{"name": n, "estimate": float(v), "std_error": float(s)}
                           for n, v, s in zip(self.names, np.asarray(self.params), np.asarray(self.bse))],
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


def _json_array(a) -> list | dict:
    a = np.asarray(a)
    if np.iscomplexobj(a):
        return {"real": a.real.tolist(), "imag": a.imag.tolist()}
    return a.tolist()
