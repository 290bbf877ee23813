"""Equation-error estimators in the time and frequency domains.

Every estimator has the same call shape, ``estimator.fit(source, equation) -> ModelFit``,
where ``source`` is a :class:`~maneuvers.recording.Recording` (with an
:class:`~estimators.regressors.Equation`) or ready :class:`RegressionData`. Options that shape
the method go to the constructor, so methods are swapped in one line.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from estimators.colored import colored_residual_covariance
from estimators.fourier import finite_fourier_transform, seed_frequencies
from estimators.least_squares import least_squares, r_squared
from estimators.regressors import DataOptions, Equation, RegressionData, regression_data
from estimators.result import ModelFit, collinearity
from estimators.smoothing import optimal_fourier_smoother, sine_series_filter
from maneuvers.recording import Recording

ERRORS = ("conventional", "colored")


def _as_data(source: Recording | RegressionData, equation: Equation | None, options: DataOptions) -> RegressionData:
    if isinstance(source, RegressionData):
        if equation is not None and equation != source.equation:
            raise ValueError("fit() got RegressionData and a different equation; pass one or the other")
        return source
    if equation is None:
        raise ValueError("fit(recording, equation): an Equation is needed to fit a recording")
    return regression_data(source, equation, options)


def _warnings(names: tuple[str, ...], fit_coll, notes: tuple[str, ...]) -> tuple[str, ...]:
    w = list(notes)
    for a, b, r in fit_coll.flagged:
        w.append(f"regressors {a} and {b} are nearly collinear (|r| = {r:.3f} > 0.9, seed Eq. 50)")
    return tuple(w)


@dataclass(frozen=True)
class EquationErrorTime:
    """Ordinary least squares in the time domain (seed Eqs. 12-17).

    Parameters
    ----------
    errors : ``'conventional'`` (Eq. 15, white residuals) or ``'colored'`` (Eqs. 37-41, the
        residual autocorrelation up to ``max_lag`` samples; all lags when None).
    smooth_regressors : smooth the regressors with the optimal Fourier smoother first (the
        seed's method 4 of §III.C), which removes most of the regressor-noise bias of Eq. 32.
        One filter serves every column: each regressor's optimal (Wiener) weights are found
        from its own spectrum, and their element-wise minimum (the most smoothing any
        regressor asks for at each frequency, in practice that of the smoothest state such
        as α) is applied to all regressors *and* to the dependent variable. A common linear
        filter keeps ``z = Xθ`` exact, so noise-free data are still fitted exactly (a
        square-wave δe smoothed on its own would no longer match the sharp Cm it produced),
        and filtering every column alike costs variance, not bias; the regressor noise above
        the cut-off, the source of the Eq. 32 bias, is gone. (The element-wise maximum, the
        least smoothing, left a bias of 7-9 Monte Carlo standard errors in the seed's
        regressor-noise study; the minimum none.)
    data : how the recording becomes z and X (angular accelerations, perturbations).
    """

    errors: str = "conventional"
    max_lag: int | None = None
    smooth_regressors: bool = False
    data: DataOptions = field(default_factory=DataOptions)

    def __post_init__(self) -> None:
        if self.errors not in ERRORS:
            raise ValueError(f"errors must be one of {ERRORS}, not {self.errors!r}")

    @property
    def method(self) -> str:
        return "ee-smooth" if self.smooth_regressors else "ee-time"

    def fit(self, source: Recording | RegressionData, equation: Equation | None = None) -> ModelFit:
        d = _as_data(source, equation, self.data)
        X, z = d.X, d.z
        info: dict = {}
        if self.smooth_regressors and X.shape[1]:
            fits = [optimal_fourier_smoother(X[:, j], d.dt) for j in range(X.shape[1])]
            weights = np.min([f.weights for f in fits], axis=0)
            X, z = sine_series_filter(X, weights), sine_series_filter(z, weights)
            info["smoother_cutoff_hz"] = max(f.cutoff_hz for f in fits)
        A = np.column_stack([X, np.ones(len(z))]) if d.equation.bias else X
        ls = least_squares(A, z, d.names)
        if self.errors == "colored":
            cov = colored_residual_covariance(A, ls.residuals, max_lag=self.max_lag)
        else:
            cov = ls.s2 * ls.xtx_inv
        coll = collinearity(A, d.names, cov)
        return ModelFit(method=self.method, domain="time", dependent=d.equation.dependent, names=d.names,
                        params=ls.theta, cov=cov, residuals=ls.residuals, fitted=ls.fitted, n=len(d.z),
                        s2=ls.s2, r2=r_squared(z, ls.residuals), errors=self.errors, collinearity=coll,
                        warnings=_warnings(d.names, coll, d.notes),
                        info=info | ({"max_lag": self.max_lag if self.max_lag is not None else len(z) - 1}
                                     if self.errors == "colored" else {}))


def detrend(x: np.ndarray, how: str = "endpoints") -> np.ndarray:
    """Remove a straight line from each column: through the first and last samples
    (``'endpoints'``, so the record starts and ends at zero) or fitted by least squares
    (``'lstsq'``)."""
    x = np.asarray(x, dtype=float)
    n = x.shape[0]
    s = np.linspace(0.0, 1.0, n).reshape(-1, *([1] * (x.ndim - 1)))
    if how == "endpoints":
        return x - (x[0] + (x[-1] - x[0]) * s)
    if how == "lstsq":
        A = np.column_stack([np.ones(n), s.ravel()])
        coef, *_ = np.linalg.lstsq(A, x.reshape(n, -1), rcond=None)
        return x - (A @ coef).reshape(x.shape)
    raise ValueError(f"detrend must be 'endpoints' or 'lstsq', not {how!r}")


@dataclass(frozen=True)
class EquationErrorFrequency:
    """Equation error in the frequency domain (seed Eqs. 19-23), no bias term.

    Each time series is detrended (``'endpoints'`` by default) and transformed with the
    high-accuracy finite Fourier transform at ``frequencies_hz`` (default the seed's Eq. 18,
    0.20 to 1.20 Hz in 0.04 Hz steps). The complex least-squares problem is solved through
    Eq. 23's real stacking; σ̂² divides by m − n_p with m the number of frequencies (Eq. 21).
    """

    frequencies_hz: tuple[float, ...] | None = None
    detrend: str = "endpoints"
    data: DataOptions = field(default_factory=DataOptions)
    method: str = "ee-freq"

    def transform(self, d: RegressionData) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Frequencies (Hz) and the transforms of z and X."""
        f = np.asarray(self.frequencies_hz if self.frequencies_hz is not None else seed_frequencies(), dtype=float)
        series = np.column_stack([d.z, d.X])
        Z = finite_fourier_transform(detrend(series, self.detrend), d.dt, f)
        return f, Z[:, 0], Z[:, 1:]

    def fit(self, source: Recording | RegressionData, equation: Equation | None = None) -> ModelFit:
        d = _as_data(source, equation, self.data)
        if d.equation.bias:
            d = RegressionData(Equation(d.equation.dependent, d.equation.regressors, bias=False),
                               d.z, d.X, d.t, d.dt, d.notes + ("the frequency-domain method estimates no bias "
                                                                "term (the data are detrended first)",))
        f, z, X = self.transform(d)
        return fit_frequency_domain(z, X, d.names, d.equation.dependent, f, self.method, d.notes)


def fit_frequency_domain(z: np.ndarray, X: np.ndarray, names: tuple[str, ...], dependent: str,
                         frequencies_hz: np.ndarray, method: str = "ee-freq",
                         notes: tuple[str, ...] = ()) -> ModelFit:
    """Complex least squares on transformed data (Eqs. 19-22)."""
    ls = least_squares(X, z, names)
    cov = ls.s2 * ls.xtx_inv
    coll = collinearity(X, names, cov, np.zeros(len(names), dtype=bool))
    return ModelFit(method=method, domain="frequency", dependent=dependent, names=names, params=ls.theta,
                    cov=cov, residuals=ls.residuals, fitted=ls.fitted, n=len(z), s2=ls.s2,
                    r2=r_squared(z, ls.residuals), errors="conventional", collinearity=coll,
                    warnings=_warnings(names, coll, notes),
                    info={"frequencies_hz": [float(x) for x in frequencies_hz]})
