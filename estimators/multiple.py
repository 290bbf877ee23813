"""Combining several maneuvers in one equation-error estimate (seed §III.F, Eqs. 42-49).

Three routes, all for one common model equation:

- **concatenation** (Eq. 42): stack z and X of every maneuver and solve one least-squares
  problem (:func:`concatenate`, :func:`fit_concatenated`);
- **a priori** (Eqs. 43-49): fold each new maneuver into the estimate and covariance of the
  ones before it (:func:`fit_a_priori`, :func:`fit_sequential`). With a common noise
  variance this *is* concatenation (Eqs. 47, 49); with maneuver-specific variances it is the
  weighted combination of Eqs. 45-46, 48;
- **frequency domain**: transform every maneuver at the same frequencies and combine the
  transformed data (:func:`fit_frequency_combined`).

The seed's implicit assumptions for combining are: (1) the equation error has the same
character in every maneuver and (2) the parameters are the same in every maneuver. Violating
(1) misstates the error bounds (see :func:`fit_sequential`); violating (2) yields a weighted
average of the single-maneuver estimates.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt
import scipy.linalg

from estimators.colored import colored_middle
from estimators.equation_error import ERRORS, EquationErrorFrequency, fit_frequency_domain, frequency_band
from estimators.least_squares import SingularRegressorsError, check_rank, least_squares, r_squared
from estimators.regressors import Equation, RegressionData
from estimators.result import ModelFit, collinearity

__all__ = [
    "Combined", "concatenate", "colored_middle", "fit_concatenated", "fit_a_priori", "fit_sequential",
    "fit_frequency_combined",
]


@dataclass(frozen=True)
class Combined:
    """Several maneuvers of one equation fitted together (seed §III.F), behind the estimators'
    one ``fit``: ``method`` is ``ee-concat`` (concatenation, Eq. 42, with ``errors``),
    ``ee-sequential`` / ``ee-sequential-unequal`` (a-priori combination with equal or unequal
    variances, Eqs. 45-49) or ``ee-freq-combined`` (common frequencies)."""

    method: str = "ee-concat"
    errors: str = "conventional"
    max_lag: int | None = None
    autocorrelation: str = "sample"
    frequencies_hz: npt.ArrayLike | str | None = None
    detrend: str = "lstsq"

    def fit(self, source: Sequence[RegressionData], equation: Equation | None = None) -> ModelFit:
        datasets = list(source)
        if equation is not None and any(d.equation != equation for d in datasets):
            raise ValueError("fit() got RegressionData and a different equation; pass one or the other")
        if self.method == "ee-concat":
            return fit_concatenated(datasets, errors=self.errors, max_lag=self.max_lag,
                                    autocorrelation=self.autocorrelation)
        if self.method in ("ee-sequential", "ee-sequential-unequal"):
            return fit_sequential(datasets, equal_variances=self.method == "ee-sequential")
        if self.method == "ee-freq-combined":
            return fit_frequency_combined(datasets, frequencies_hz=self.frequencies_hz, detrend=self.detrend)
        raise ValueError(f"no multiple-maneuver method {self.method!r}")


# -- checks and bookkeeping --------------------------------------------------------------------
def _common(datasets: Sequence[RegressionData]) -> tuple[RegressionData, ...]:
    """The datasets as a tuple, after checking they implement one model equation."""
    ds = tuple(datasets)
    if not ds:
        raise ValueError("no maneuvers to combine")
    eq = ds[0].equation
    for i, d in enumerate(ds[1:], start=1):
        if d.equation != eq:
            raise ValueError(f"maneuver {i} implements {d.equation.describe()} but maneuver 0 implements "
                             f"{eq.describe()}: combined maneuvers must share one model structure "
                             "(seed §III.F)")
    return ds


def _slices(datasets: Sequence[RegressionData]) -> tuple[slice, ...]:
    """Row ranges of each maneuver in the stacked data."""
    ends = np.cumsum([len(d.z) for d in datasets])
    return tuple(slice(int(e - len(d.z)), int(e)) for d, e in zip(datasets, ends))


def _warnings(coll, notes: Sequence[str] = ()) -> tuple[str, ...]:
    return tuple(notes) + coll.warnings()


def _unique_notes(datasets: Sequence[RegressionData]) -> tuple[str, ...]:
    return tuple(dict.fromkeys(n for d in datasets for n in d.notes))


# -- concatenation -----------------------------------------------------------------------------
def concatenate(datasets: Sequence[RegressionData]) -> RegressionData:
    """Stack the data of several maneuvers into one problem (seed Eq. 42).

    Parameters
    ----------
    datasets : sequence of RegressionData
        Maneuvers of one model equation (same dependent variable, regressors and bias) and
        the same sampling interval.

    Returns
    -------
    RegressionData
        z and X stacked in the given order. The time axis continues: each maneuver starts one
        sampling interval after the previous one ends, so ``t`` stays uniform. A note records
        the maneuver lengths.

    Raises
    ------
    ValueError
        If the maneuvers implement different equations or have different sampling intervals.

    Notes
    -----
    Estimates do not depend on the order of the rows, but colored-residual error bounds do
    (seed §III.F): use :func:`fit_concatenated`, which knows where maneuvers meet, rather than
    a colored fit of the returned data.
    """
    ds = _common(datasets)
    dt = ds[0].dt
    for i, d in enumerate(ds):
        if not np.isclose(d.dt, dt, rtol=1e-9, atol=0.0):
            raise ValueError(f"maneuver {i} is sampled every {d.dt} s, maneuver 0 every {dt} s: "
                             "resample before concatenating")
    t, start = [], 0.0
    for d in ds:
        t.append(start + (d.t - d.t[0]))
        start = t[-1][-1] + dt
    note = (f"concatenated from {len(ds)} maneuvers of {', '.join(str(len(d.z)) for d in ds)} samples "
            "(seed Eq. 42)")
    return RegressionData(ds[0].equation, np.concatenate([d.z for d in ds]),
                          np.vstack([d.X for d in ds]), np.concatenate(t), dt,
                          _unique_notes(ds) + (note,))


def fit_concatenated(datasets: Sequence[RegressionData], errors: str = "conventional", *,
                     max_lag: int | None = None, autocorrelation: str = "sample") -> ModelFit:
    """Least squares on the concatenated maneuvers (seed Eqs. 42, 14-16, 40).

    Parameters
    ----------
    datasets : sequence of RegressionData
        Maneuvers of one model equation.
    errors : {'conventional', 'colored'}
        ``'conventional'``: Cov = σ̂²(XᵀX)⁻¹ with σ̂² of Eq. 16 from all the data (Eq. 49).
        ``'colored'``: Eq. 40 with the residual autocorrelation taken *within* each maneuver.
    max_lag : int or None
        Largest lag r of Eq. 39 for ``'colored'`` (all lags of each maneuver when None).
    autocorrelation : {'sample', 'ar'}
        ``'colored'``: Eq. 39's estimates, or their autoregressive model's, of each maneuver
        (:func:`estimators.colored.colored_residual_covariance`).

    Returns
    -------
    ModelFit
        ``method='ee-concat'``; ``info['lengths']`` gives the samples per maneuver.

    Notes
    -----
    Colored errors: the maneuvers are flown separately, so their equation errors are
    independent and E(vvᵀ) of Eq. 37 is block diagonal, one Toeplitz block per maneuver
    (Eq. 38 holds within a maneuver, not across the join). Eq. 40 applied to the stacked
    rows would (a) correlate the last samples of one maneuver with the first of the next
    through R̂(k), which depends on the arbitrary order in which maneuvers are stacked, and
    (b) let the products v_i v_{i+k} that straddle a join enter R̂. Here the middle matrix
    of Eq. 40 is computed for each maneuver from its own residuals and its own R̂ (Eq. 39
    with that maneuver's N) and the blocks are summed:
    Cov = (XᵀX)⁻¹ [Σ_m X_mᵀ T_m X_m] (XᵀX)⁻¹. The result does not depend on the order of
    the maneuvers, and with one maneuver it is Eq. 40 exactly.
    """
    if errors not in ERRORS:
        raise ValueError(f"errors must be one of {ERRORS}, not {errors!r}")
    ds = _common(datasets)
    d = concatenate(ds)
    A = d.design()
    ls = least_squares(A, d.z, d.names)
    info: dict = {"maneuvers": len(ds), "lengths": [len(x.z) for x in ds]}
    if errors == "colored":
        middle = sum(colored_middle(A[s], ls.residuals[s], max_lag, autocorrelation=autocorrelation)
                     for s in _slices(ds))
        cov = ls.xtx_inv @ middle @ ls.xtx_inv
        cov = 0.5 * (cov + cov.T)
        info["max_lag"] = max_lag if max_lag is not None else "all lags of each maneuver"
        info["autocorrelation"] = autocorrelation
    else:
        cov = ls.s2 * ls.xtx_inv
    coll = collinearity(A, d.names, cov)
    return ModelFit(method="ee-concat", domain="time", dependent=d.equation.dependent, names=d.names,
                    params=ls.theta, cov=cov, residuals=ls.residuals, fitted=ls.fitted, n=len(d.z),
                    s2=ls.s2, r2=r_squared(d.z, ls.residuals), errors=errors, collinearity=coll,
                    warnings=_warnings(coll, _unique_notes(ds)), info=info)


# -- a priori combination ----------------------------------------------------------------------
@dataclass(frozen=True)
class _Information:
    """An estimate with its square-root information matrix U (UᵀU = Cov⁻¹, U upper triangular)."""

    theta: np.ndarray
    root: np.ndarray

    @property
    def cov(self) -> np.ndarray:
        r_inv = scipy.linalg.solve_triangular(self.root, np.eye(len(self.theta)))
        return r_inv @ r_inv.T

    @classmethod
    def from_covariance(cls, theta: npt.ArrayLike, cov: npt.ArrayLike) -> "_Information":
        theta = np.asarray(theta, dtype=float).ravel()
        cov = np.asarray(cov, dtype=float)
        if cov.shape != (len(theta), len(theta)):
            raise ValueError(f"prior covariance is {cov.shape}, expected {(len(theta), len(theta))}")
        try:
            lower = scipy.linalg.cholesky(0.5 * (cov + cov.T), lower=True)
        except np.linalg.LinAlgError:
            raise ValueError("the a-priori covariance is not positive definite") from None
        # Cov = L Lᵀ so Cov⁻¹ = L⁻ᵀ L⁻¹: the root L⁻¹ is lower triangular; re-triangularise.
        root = scipy.linalg.qr(scipy.linalg.solve_triangular(lower, np.eye(len(theta)), lower=True),
                               mode="r")[0]
        return cls(theta, root)


def _update(prior: _Information, A: np.ndarray, z: np.ndarray, sigma2: float,
            names: tuple[str, ...]) -> _Information:
    """Minimise Eq. 43: the solution of Eq. 45 with the information of Eq. 48.

    Eq. 43 equals ½‖U(θ − θ₁)‖² + ½‖(z − Xθ)/σ‖², a least-squares problem in the stacked
    rows [U; X/σ] θ ≈ [Uθ₁; z/σ]; its normal equations are Eq. 45 and the inverse of its
    normal matrix is Eq. 48. Solving it by QR (never forming the normal matrix) keeps the
    accuracy of the concatenated solution.
    """
    s = np.sqrt(sigma2)
    M = np.vstack([prior.root, A / s])
    b = np.concatenate([prior.root @ prior.theta, z / s])
    check_rank(M, names)
    q, r = scipy.linalg.qr(M, mode="economic")
    return _Information(scipy.linalg.solve_triangular(r, q.T @ b), r)


def _own_variance(A: np.ndarray, z: np.ndarray) -> float:
    """σ̂² of Eq. 16 from one maneuver's own least-squares residuals.

    The degrees of freedom are N − rank(X), so a maneuver that does not excite every
    regressor (the usual reason for combining maneuvers) still yields its noise variance.
    """
    theta, *_ = scipy.linalg.lstsq(A, z)
    rank = np.linalg.matrix_rank(A)
    if len(z) <= rank:
        raise ValueError(f"{len(z)} samples leave no degrees of freedom for the residual variance "
                         f"of a rank-{rank} model: pass sigma2")
    v = z - A @ theta
    return float(v @ v) / (len(z) - rank)


def fit_a_priori(data2: RegressionData, prior_theta: npt.ArrayLike, prior_cov: npt.ArrayLike, *,
                 sigma2: float | None = None) -> ModelFit:
    """Estimate from one maneuver plus a-priori estimates (seed Eqs. 43, 45, 48).

    Minimises J(θ) = (z₂ − X₂θ)ᵀ(z₂ − X₂θ)/(2σ₂²) + ½(θ − θ₁)ᵀΣ₁⁻¹(θ − θ₁) (Eq. 43):

    θ̂ = [X₂ᵀX₂/σ₂² + Σ₁⁻¹]⁻¹ [X₂ᵀz₂/σ₂² + Σ₁⁻¹θ₁]   (Eq. 45)
    Cov(θ̂) = [X₂ᵀX₂/σ₂² + Σ₁⁻¹]⁻¹                      (Eq. 48)

    Parameters
    ----------
    data2 : RegressionData
        The new maneuver; its ``names`` (bias included) order the parameters.
    prior_theta, prior_cov : array_like
        θ₁ and Σ₁ (e.g. ``fit.params`` and ``fit.cov`` of an earlier maneuver, Eq. 44).
    sigma2 : float, optional
        σ₂², the equation-error variance of the new maneuver. Default: Eq. 16 from data2's
        own least-squares residuals (N₂ − rank(X₂) degrees of freedom), so data2 need not
        determine every parameter alone.

    Returns
    -------
    ModelFit
        ``method='ee-apriori'``, ``errors='a-priori'``; residuals, fitted values, R² and ``n``
        refer to data2; ``s2`` is the σ₂² used.
    """
    A, z, names = data2.design(), data2.z, data2.names
    prior = _Information.from_covariance(prior_theta, prior_cov)
    if len(prior.theta) != A.shape[1]:
        raise ValueError(f"the prior has {len(prior.theta)} parameters, the equation {len(names)} ({names})")
    s2 = _own_variance(A, z) if sigma2 is None else float(sigma2)
    if not s2 > 0:
        raise ValueError(f"sigma2 must be positive, got {s2}")
    post = _update(prior, A, z, s2, names)
    cov = post.cov
    fitted = A @ post.theta
    coll = collinearity(A, names, cov)
    return ModelFit(method="ee-apriori", domain="time", dependent=data2.equation.dependent, names=names,
                    params=post.theta, cov=cov, residuals=z - fitted, fitted=fitted, n=len(z), s2=s2,
                    r2=r_squared(z, z - fitted), errors="a-priori", collinearity=coll,
                    warnings=_warnings(coll, data2.notes),
                    info={"sigma2": s2, "sigma2_source": "Eq. 16, data2 alone" if sigma2 is None else "given",
                          "prior_theta": [float(x) for x in prior.theta]})


def fit_sequential(datasets: Sequence[RegressionData], *, equal_variances: bool = True) -> ModelFit:
    """Combine maneuvers one after another, each using the previous result as a priori (Eqs. 43-49).

    Parameters
    ----------
    datasets : sequence of RegressionData
        Maneuvers of one model equation. The first must determine every parameter on its
        own (it provides the first a-priori estimate, Eq. 44); later ones need not.
    equal_variances : bool
        True: the maneuvers share one equation-error variance σ² (the seed's assumption 1).
        σ² cancels from the estimate (Eq. 47), so the recursion runs with unit variance and
        the covariance is σ̂²[Σ XᵢᵀXᵢ]⁻¹ (Eq. 49) with σ̂² from Eq. 16 on all the data. The
        residual sum of squares of all the data is carried along the recursion,
        SSEₖ = SSEₖ₋₁ + ‖Uₖ₋₁(θ̂ₖ − θ̂ₖ₋₁)‖² + ‖zₖ − Xₖθ̂ₖ‖² (exact, since the earlier cost is
        a quadratic with minimum θ̂ₖ₋₁), so no maneuver's data are revisited. The result
        equals :func:`fit_concatenated` to rounding error.
        False: each maneuver keeps its own σᵢ² (Eq. 16 on that maneuver alone), so
        θ̂ = [Σ XᵢᵀXᵢ/σᵢ²]⁻¹ Σ Xᵢᵀzᵢ/σᵢ² (Eq. 46) and Cov = [Σ XᵢᵀXᵢ/σᵢ²]⁻¹ (Eq. 48).

    Returns
    -------
    ModelFit
        ``method='ee-sequential'``; ``errors='conventional'`` (Eq. 49) or
        ``'unequal-variances'`` (Eq. 48). Residuals, fitted values, R², ``n`` and ``s2``
        (Eq. 16) refer to all the data at the final estimate; ``info['sigma2_per_maneuver']``
        holds the σᵢ² used when the variances are unequal.

    Notes
    -----
    Unequal noise variances. Concatenation (or ``equal_variances=True``) weights every
    sample alike and pools σ̂² over all maneuvers. When the σᵢ² differ, that estimate is
    still unbiased but no longer the most accurate, and its Eq. 49 bounds are wrong in a
    parameter-dependent way: the pooled σ̂² is an average of the σᵢ², so a parameter that
    is determined mainly by a quiet maneuver gets bounds that are too wide, and one
    determined mainly by a noisy maneuver gets bounds that are too narrow. The weighted
    form (Eqs. 45-46, 48) gives each maneuver weight 1/σᵢ² — a noisy maneuver then counts
    little — and its covariance is the correct one for that estimate, given the σᵢ².
    """
    ds = _common(datasets)
    names = ds[0].names
    first = ds[0]
    A1 = first.design()
    try:
        ls = least_squares(A1, first.z, names)
    except SingularRegressorsError as exc:
        raise SingularRegressorsError(f"{exc}. The first maneuver supplies the first a-priori estimate "
                                      "(Eq. 44), so it must determine every parameter: put such a "
                                      "maneuver first, or use fit_concatenated") from None
    root = scipy.linalg.qr(A1, mode="r")[0][:A1.shape[1]]
    sigma2s: list[float] = []
    if equal_variances:
        state = _Information(ls.theta, root)
        sse = float(ls.residuals @ ls.residuals)
        for d in ds[1:]:
            A = d.design()
            new = _update(state, A, d.z, 1.0, names)
            v = d.z - A @ new.theta
            step = state.root @ (new.theta - state.theta)
            sse += float(step @ step) + float(v @ v)
            state = new
        n_total = sum(len(d.z) for d in ds)
        s2 = sse / (n_total - len(names))
        cov = s2 * state.cov
    else:
        sigma2s.append(float(ls.s2))
        state = _Information(ls.theta, root / np.sqrt(ls.s2))
        for d in ds[1:]:
            A = d.design()
            sigma2s.append(float(_own_variance(A, d.z)))
            state = _update(state, A, d.z, sigma2s[-1], names)
        cov = state.cov
    A_all = np.vstack([d.design() for d in ds])
    z_all = np.concatenate([d.z for d in ds])
    fitted = A_all @ state.theta
    resid = z_all - fitted
    if not equal_variances:
        s2 = float(resid @ resid) / (len(z_all) - len(names))
    coll = collinearity(A_all, names, cov)
    info: dict = {"maneuvers": len(ds), "lengths": [len(d.z) for d in ds], "equal_variances": equal_variances}
    if sigma2s:
        info["sigma2_per_maneuver"] = sigma2s
    return ModelFit(method="ee-sequential", domain="time", dependent=first.equation.dependent, names=names,
                    params=state.theta, cov=cov, residuals=resid, fitted=fitted, n=len(z_all), s2=s2,
                    r2=r_squared(z_all, resid), errors="conventional" if equal_variances else "unequal-variances",
                    collinearity=coll, warnings=_warnings(coll, _unique_notes(ds)), info=info)


# -- frequency domain --------------------------------------------------------------------------
def fit_frequency_combined(datasets: Sequence[RegressionData], frequencies_hz: npt.ArrayLike | None = None,
                           detrend: str = "lstsq") -> ModelFit:
    """Frequency-domain equation error on several maneuvers at common frequencies (seed §III.F).

    Every maneuver is detrended and transformed at the same frequencies (default the seed's
    rule for the shortest maneuver: 2/T to 1.2 Hz by 0.04 Hz) by
    :meth:`EquationErrorFrequency.transform`, which handles maneuvers of different lengths.

    Interpretation of "the data for the combination of multiple maneuvers is simply the
    addition of the frequency-domain data at each corresponding frequency": what is added
    are the frequency-domain normal-equation data that Eqs. 19-20 are built from,

    Re(X̃†X̃) = Σᵢ Re(X̃ᵢ†X̃ᵢ),   Re(X̃†z̃) = Σᵢ Re(X̃ᵢ†z̃ᵢ),

    each a sum over frequencies of the per-frequency terms, so the contributions of all
    maneuvers at a frequency are added. This is exactly least squares on the stacked
    complex rows [z̃₁; z̃₂; ...] = [X̃₁; X̃₂; ...]θ, which is how it is solved (QR of the
    real stacking of Eq. 23, not the normal equations), with m in Eq. 21 the total number of
    frequency points Σᵢ mᵢ. (Adding the transforms themselves, z̃₁ + z̃₂ = (X̃₁ + X̃₂)θ, is
    also a valid equation but throws away information, and its cross terms Re(X̃₁†X̃₂)
    depend on the arbitrary relative phase of the maneuvers.)

    Parameters
    ----------
    datasets : sequence of RegressionData
        Maneuvers of one model equation; any bias term is dropped (the data are detrended).
    frequencies_hz : array_like or str, optional
        The common frequencies; ``None``/``'auto'`` (default): the seed's rule with T the
        shortest maneuver's length; ``'eq18'``/``'sidpac'``: Eq. 18, 0.20-1.20 Hz by 0.04 Hz.
    detrend : {'lstsq', 'endpoints'}
        How each time series is detrended before the transform (default a least-squares
        line; ``'endpoints'`` is SIDPAC's line through the end points).

    Returns
    -------
    ModelFit
        ``method='ee-freq'``, ``domain='frequency'``, ``n`` = Σᵢ mᵢ.

    Notes
    -----
    The combined fit assumes one noise variance for all frequency points. For white equation
    error of variance σ² the transform's noise variance is σ²·dt·T, which grows with the
    record length T, so maneuvers of very different lengths (or noise levels) violate that
    assumption in the way :func:`fit_sequential` describes for the time domain. A warning
    is added when a maneuver is shorter than the 2/T rule for the lowest frequency (Eq. 18
    discussion).
    """
    ds = _common(datasets)
    eq = ds[0].equation
    no_bias = Equation(eq.dependent, eq.regressors, bias=False)
    shortest = min((len(d.z) - 1) * d.dt for d in ds)
    spec = frequencies_hz if frequencies_hz is None or isinstance(frequencies_hz, str) else np.atleast_1d(frequencies_hz)
    est = EquationErrorFrequency(frequencies_hz=tuple(float(x) for x in frequency_band(spec, shortest)),
                                 detrend=detrend)
    parts = [est.transform(d) for d in ds]
    f = parts[0][0]
    notes = list(_unique_notes(ds))
    if eq.bias:
        notes.append("the frequency-domain method estimates no bias term (the data are detrended first)")
    for i, d in enumerate(ds):
        duration = (len(d.z) - 1) * d.dt
        if duration > 0 and f.min() < 2.0 / duration:
            notes.append(f"maneuver {i} lasts {duration:.3g} s: the lowest frequency {f.min():.3g} Hz is "
                         f"below 2/T = {2.0 / duration:.3g} Hz (seed Eq. 18 discussion)")
    fit = fit_frequency_domain(np.concatenate([p[1] for p in parts]), np.vstack([p[2] for p in parts]),
                               no_bias.names, eq.dependent, f, "ee-freq", tuple(notes))
    return replace(fit, info={**fit.info, "maneuvers": len(ds), "points_per_maneuver": [len(f)] * len(ds)})
