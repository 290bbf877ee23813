"""Equation-error estimators in the time and frequency domains.

Every estimator has the same call shape, ``estimator.fit(source, equation) -> ModelFit``,
where ``source`` is a :class:`~maneuvers.recording.Recording` (with an
:class:`~estimators.regressors.Equation`) or ready :class:`RegressionData`. Options that shape
the method go to the constructor, so methods are swapped in one line.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from estimators.colored import colored_residual_covariance
from estimators.fourier import (finite_fourier_transform, held_fourier_transform, seed_frequencies,
                                seed_rule_frequencies)
from estimators.least_squares import least_squares, r_squared
from estimators.coefficients import coefficient_from_recording
from estimators.regressors import DataOptions, Equation, RegressionData, regression_data
from estimators.differentiation import smooth_derivative
from estimators.result import ModelFit, collinearity
from estimators.smoothing import optimal_fourier_smoother, sine_series_filter
from maneuvers.recording import Recording
from models.errors import OptionError

ERRORS = ("conventional", "colored")
AUTOCORRELATIONS = ("sample", "ar")  # Eq. 39 estimates, or their autoregressive model (estimators.colored)
DETRENDS = ("lstsq", "endpoints")
# Named frequency bands of the frequency-domain method: "auto", the seed's rule (2/T to 1.2 Hz
# by 0.04 Hz, §II after Eq. 18); "eq18" (alias "sidpac"), Eq. 18's fixed 0.20:0.04:1.20 Hz,
# SIDPAC's choice and the seed's for its own 10 s examples.
BANDS = ("auto", "eq18", "sidpac")
# Where the frequency-domain method differentiates the rates of the moment equations (Eqs. 3-5)
# when the recording has no angular accelerations: "time", the time-domain smoothed derivative
# of DataOptions (the seed's method 1 by default), or "transform", in the frequency domain
# (see :func:`derivative_transform`).
ACCELERATIONS = ("time", "transform")
_MOMENT_ACCELERATIONS = {"Cl": ("pdot", "rdot"), "Cm": ("qdot",), "Cn": ("pdot", "rdot")}
_SEED_METHODS = {"smooth-local": 1, "smooth-fourier": 2, "local-smooth": 3}
# The SIDPAC convention of the frequency-domain method, by name: Eq. 18's band and the line
# through the end points. ``make_estimator("ee-freq", **SIDPAC_FREQUENCY_OPTIONS)``.
SIDPAC_FREQUENCY_OPTIONS = {"frequencies_hz": "sidpac", "detrend": "endpoints"}

# When the colored-residual (Eq. 40) standard error of a parameter exceeds the white-
# residual (Eq. 15) one by more than this factor, the residuals are called strongly coloured
# and the fit says so: conventional ±2σ intervals whose σ is 1.5 times too small cover
# P(|Z| < 2/1.5) = 82 % instead of 95 %. For white residuals the ratio scatters about 1 by
# roughly 1/sqrt(2m) in standard error, m the number of frequency bins the regressors span
# (about 0.12 measured for broadband regressors below 1.5 Hz over 40 s: the test's 40 seeds
# range 0.71-1.23), so 1.5 is about four of those from 1. Below 1 (residual power above the
# regressors' band) the conventional bounds are conservative; that side is flagged at 1/2.
COLOURED_SE_RATIO = 1.5
COLOURED_SE_RATIO_LOW = 0.5


def _as_data(source: Recording | RegressionData, equation: Equation | None, options: DataOptions) -> RegressionData:
    if isinstance(source, RegressionData):
        if equation is not None and equation != source.equation:
            raise ValueError("fit() got RegressionData and a different equation; pass one or the other")
        return source
    if equation is None:
        raise ValueError("fit(recording, equation): an Equation is needed to fit a recording")
    return regression_data(source, equation, options)


def _warnings(names: tuple[str, ...], fit_coll, notes: tuple[str, ...]) -> tuple[str, ...]:
    return tuple(notes) + fit_coll.warnings()


def colored_to_conventional_se(cov_colored: np.ndarray, cov_conventional: np.ndarray) -> np.ndarray:
    """Per parameter, the colored-residual standard error (Eq. 40) over the white-residual one
    (Eq. 15): 1 for white residuals, far from 1 when the residuals are coloured (seed §III.E)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sqrt(np.diag(cov_colored) / np.diag(cov_conventional))


def coloured_residuals_warning(names: tuple[str, ...], ratio: np.ndarray, errors: str,
                               limit: float = COLOURED_SE_RATIO,
                               low_limit: float = COLOURED_SE_RATIO_LOW) -> str | None:
    """A warning when the residuals are strongly coloured (see :data:`COLOURED_SE_RATIO`),
    whichever bounds were reported; ``None`` otherwise.

    The bias is left out: a constant regressor sees only the residuals' zero frequency, and
    with all lags Eq. 39 sums to ``sum_k R(k) = (sum v)**2/N``, zero for the residuals of a
    fit with a bias term, so its Eq. 40 variance says nothing about colour.
    """
    keep = np.isfinite(ratio) & np.array([n != "bias" for n in names])
    if not keep.any():
        return None
    safe = np.where(keep, ratio, 1.0)
    # distance beyond the limit on either side, in log units (<= 0 inside the limits)
    over = np.where(keep, np.maximum(np.log(safe / limit), np.log(low_limit / safe)), -np.inf)
    j = int(np.argmax(over))
    if over[j] <= 0.0:
        return None
    what = (f"the colored-residual (Eq. 40) standard error of {names[j]} is {ratio[j]:.2g} times the "
            f"white-residual (Eq. 15) one")
    if errors == "colored":
        return f"residuals are strongly coloured: {what}; the bounds reported are the colored ones (seed §III.E)"
    return (f"residuals are strongly coloured: {what}, so the conventional bounds reported here are off by "
            "that factor; use colored errors (Eq. 40, seed §III.E)")


@dataclass(frozen=True)
class EquationErrorTime:
    """Ordinary least squares in the time domain (seed Eqs. 12-17).

    Parameters
    ----------
    errors : ``'conventional'`` (Eq. 15, white residuals) or ``'colored'`` (Eqs. 37-41, the
        residual autocorrelation up to ``max_lag`` samples; all lags when None; with
        ``autocorrelation='ar'`` that of an autoregressive model of the residuals, see
        :func:`estimators.colored.colored_residual_covariance`). ``None``
        (default) is the method's own: ``'colored'`` with smoothed regressors (smoothing
        colours the residuals, and the seed's §III.E finds the colored bounds of smoothed
        regressors accurate), ``'conventional'`` without. Either way the fit warns when the
        residuals are strongly coloured (:data:`COLOURED_SE_RATIO`) and reports the ratio of
        the two standard errors in ``info['colored_to_conventional_se']``.
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

    errors: str | None = None
    max_lag: int | None = None
    autocorrelation: str = "sample"
    smooth_regressors: bool = False
    data: DataOptions = field(default_factory=DataOptions)

    def __post_init__(self) -> None:
        if self.errors is None:
            object.__setattr__(self, "errors", "colored" if self.smooth_regressors else "conventional")
        if self.errors not in ERRORS:
            raise OptionError(f"errors must be one of {ERRORS}, not {self.errors!r}")
        if self.autocorrelation not in AUTOCORRELATIONS:
            raise OptionError(f"autocorrelation must be one of {AUTOCORRELATIONS}, not {self.autocorrelation!r}")
        if self.autocorrelation != "sample" and self.errors != "colored":
            raise OptionError("autocorrelation applies to the colored errors (Eq. 40), not to the conventional ones")

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
        ls = least_squares(A, z, d.names, keep_factor=True)
        cov_colored = colored_residual_covariance(A, ls.residuals, max_lag=self.max_lag, factor=ls.factor,
                                                  autocorrelation=self.autocorrelation)
        ls = replace(ls, factor=None)  # Q is N x n_p: not kept past its use
        cov_conventional = ls.s2 * ls.xtx_inv
        cov = cov_colored if self.errors == "colored" else cov_conventional
        ratio = colored_to_conventional_se(cov_colored, cov_conventional)
        info["colored_to_conventional_se"] = [float(r) for r in ratio]
        coll = collinearity(A, d.names, cov)
        colour = coloured_residuals_warning(d.names, ratio, self.errors)
        return ModelFit(method=self.method, domain="time", dependent=d.equation.dependent, names=d.names,
                        params=ls.theta, cov=cov, residuals=ls.residuals, fitted=ls.fitted, n=len(d.z),
                        s2=ls.s2, r2=r_squared(z, ls.residuals), errors=self.errors, collinearity=coll,
                        warnings=_warnings(d.names, coll, d.notes) + ((colour,) if colour else ()),
                        assumptions=d.assumptions,
                        info=info | ({"max_lag": self.max_lag if self.max_lag is not None else len(z) - 1,
                                      "autocorrelation": self.autocorrelation}
                                     if self.errors == "colored" else {}))


def detrend(x: np.ndarray, how: str = "lstsq") -> np.ndarray:
    """Remove a straight line from each column: fitted by least squares (``'lstsq'``, the
    default) or through the first and last samples (``'endpoints'``, so the record starts and
    ends at zero: SIDPAC's choice). With noisy data the end-point line carries the noise of
    two samples and adds a random ramp, in band, to every series; the least-squares line
    averages all of them. Both are linear, so ``z = X theta`` survives either exactly."""
    x = np.asarray(x, dtype=float)
    n = x.shape[0]
    s = np.linspace(0.0, 1.0, n).reshape(-1, *([1] * (x.ndim - 1)))
    if how == "endpoints":
        return x - (x[0] + (x[-1] - x[0]) * s)
    if how == "lstsq":
        A = np.column_stack([np.ones(n), s.ravel()])
        coef, *_ = np.linalg.lstsq(A, x.reshape(n, -1), rcond=None)
        return x - (A @ coef).reshape(x.shape)
    raise OptionError(f"detrend must be 'endpoints' or 'lstsq', not {how!r}")


def frequency_band(frequencies_hz, duration_s: float) -> np.ndarray:
    """The frequencies (Hz) of a band specification for a record of ``duration_s`` seconds.

    ``None`` or ``'auto'``: the seed's rule, 2/T to 1.2 Hz by 0.04 Hz
    (:func:`estimators.fourier.seed_rule_frequencies`); ``'eq18'`` or ``'sidpac'``: Eq. 18,
    0.20:0.04:1.20 Hz; otherwise the frequencies given.
    """
    if frequencies_hz is None or (isinstance(frequencies_hz, str) and frequencies_hz == "auto"):
        return seed_rule_frequencies(duration_s)
    if isinstance(frequencies_hz, str):
        if frequencies_hz in ("eq18", "sidpac"):
            return seed_frequencies()
        raise OptionError(f"frequency band {frequencies_hz!r}: use one of {BANDS} or give frequencies")
    return np.asarray(frequencies_hz, dtype=float)


def continuous_line(x: np.ndarray, dt: float) -> np.ndarray:
    """Samples of the least-squares line of the cubic interpolant of each column of ``x``.

    The line ``c0 + c1 s`` (``s = t/T``) minimising ``int_0^1 (x - c0 - c1 s)**2 ds``:
    ``[1 1/2; 1/2 1/3] c = [int x ds, int s x ds]``, the integrals being the zero-frequency
    finite Fourier transforms of :func:`estimators.fourier.finite_fourier_transform` (exact for
    the cubic interpolant). :func:`derivative_transform` removes the same line from a
    derivative known only through its integral, so every series of an ``'transform'`` fit is
    detrended alike (the sampled least-squares line of :func:`detrend` differs from it by
    O(1/N), 5e-4 relative on a 1,001-sample record).
    """
    x = np.asarray(x, dtype=float)
    n = x.shape[0]
    T = (n - 1) * dt
    s = np.linspace(0.0, 1.0, n).reshape(-1, *([1] * (x.ndim - 1)))
    i0 = finite_fourier_transform(x, dt, [0.0])[0].real / T
    i1 = finite_fourier_transform(x * s, dt, [0.0])[0].real / T
    return (4 * i0 - 6 * i1) + (-6 * i0 + 12 * i1) * s


def derivative_transform(y: np.ndarray, dt: float, frequencies_hz: np.ndarray) -> np.ndarray:
    """Finite Fourier transform of ``dy/dt``, least-squares line removed, from ``y`` itself.

    Integration by parts of the finite transform (seed Eq. 18's transform, the one Eqs. 19-23
    use, over ``[0, T]``) gives

    .. math:: \\int_0^T \\dot y\\, e^{-j\\omega t} dt
              = y(T)\\, e^{-j\\omega T} - y(0) + j\\omega\\, \\tilde y(\\omega),

    exact for any record (it need not start or end at rest). The least-squares line
    ``c0 + c1 s`` (``s = t/T``) of ``dy/dt`` over the record follows from the same integrals,
    ``int_0^1 dy/dt ds = (y(T) - y(0))/T`` and ``int_0^1 s dy/dt ds = (y(T) - mean(y))/T``,
    and its transform is subtracted, as :func:`detrend` (``'lstsq'``) does for the sampled
    series (the line of the interpolant, :func:`continuous_line`). ``tilde y`` and ``mean(y)`` come from :func:`estimators.fourier.finite_fourier_transform`
    (cubic interpolant, so the result is exact to O(dt**4) for smooth ``y``; no smoothing is
    applied: the band, 2/T to 1.2 Hz, is what rejects the noise that differentiation raises).

    Parameters
    ----------
    y : numpy.ndarray, shape (N,)
        Samples of ``y`` at ``i dt``.
    dt : float
        Sampling interval, s.
    frequencies_hz : numpy.ndarray, shape (m,)
        Transform frequencies, Hz.

    Returns
    -------
    numpy.ndarray, complex, shape (m,)
    """
    y = np.asarray(y, dtype=float)
    T = (len(y) - 1) * dt
    f = np.asarray(frequencies_hz, dtype=float)
    w = 2 * np.pi * f
    Y, Y0 = finite_fourier_transform(y, dt, f), finite_fourier_transform(y, dt, [0.0])[0].real
    D = y[-1] * np.exp(-1j * w * T) - y[0] + 1j * w * Y
    i0, i1 = (y[-1] - y[0]) / T, (y[-1] - Y0 / T) / T
    c0, c1 = 4 * i0 - 6 * i1, -6 * i0 + 12 * i1  # [1 1/2; 1/2 1/3] c = [i0, i1]
    line = c0 + c1 * np.linspace(0.0, 1.0, len(y))
    return D - finite_fourier_transform(line, dt, f)


def acceleration_differentiated(rec: Recording, dependent: str, options: DataOptions) -> bool:
    """Whether :func:`estimators.regressors.regression_data` builds ``dependent`` from angular
    accelerations differentiated in the time domain (a moment coefficient, Eqs. 3-5, computed
    from a recording without the accelerations it needs, or with ``angular_acceleration`` set
    to a differentiation method)."""
    if dependent not in _MOMENT_ACCELERATIONS:
        return False
    if options.dependent_source == "channel" or (options.dependent_source == "auto" and rec.has(dependent)):
        return False
    if options.angular_acceleration == "recorded":
        return False
    return not (options.angular_acceleration == "auto" and all(rec.has(f"{a}dot") for a in "pqr"))


def moment_transform(rec: Recording, dependent: str, options: DataOptions,
                     frequencies_hz: np.ndarray) -> np.ndarray:
    """Transform of a moment coefficient (Eqs. 3-5) with its angular accelerations
    differentiated in the frequency domain, detrended by a least-squares line.

    Eqs. 3-5 are affine in the angular accelerations, ``C(t) = g(t) + sum_a k_a(t) a_dot(t)``
    (``k_q = I_y/(qbar S cbar)`` for Cm; ``g`` the rate products and the thrust moment). With
    ``k_a a_dot = d(k_a a)/dt - a dk_a/dt`` the transform is
    ``F[g - sum_a a dk_a/dt] + sum_a F[d(k_a a)/dt]``, the last by
    :func:`derivative_transform` (exact, no smoothing); ``dk_a/dt`` (``qbar``'s slow change:
    a term a few per cent of the coefficient) is differentiated in the time domain by the
    seed's method 1 (or ``options``' method), where its smoothing error is second order.

    Parameters
    ----------
    rec : Recording
    dependent : ``'Cl'``, ``'Cm'`` or ``'Cn'``
    options : DataOptions
        Only ``angular_acceleration`` (the method for ``dk_a/dt``) is used.
    frequencies_hz : numpy.ndarray
        Transform frequencies, Hz.

    Returns
    -------
    numpy.ndarray, complex, shape (m,)
    """
    zero = {a: 0.0 for a in ("pdot", "qdot", "rdot")}
    g = coefficient_from_recording(rec, dependent, accelerations=zero)
    method = _SEED_METHODS.get(options.angular_acceleration, 1)
    u = np.array(g, dtype=float)
    out = np.zeros(len(frequencies_hz), dtype=complex)
    for a in _MOMENT_ACCELERATIONS[dependent]:
        k = coefficient_from_recording(rec, dependent, accelerations={**zero, a: 1.0}) - g
        rate = rec.channel(a[0])
        if np.ptp(k) > 0.0:
            u = u - rate * smooth_derivative(k, rec.dt, method=method)
        out += derivative_transform(k * rate, rec.dt, frequencies_hz)
    return out + finite_fourier_transform(u - continuous_line(u, rec.dt), rec.dt, frequencies_hz)


@dataclass(frozen=True)
class EquationErrorFrequency:
    """Equation error in the frequency domain (seed Eqs. 19-23), no bias term.

    Each time series is detrended (``detrend``: ``'lstsq'``, a least-squares line, by
    default; ``'endpoints'``, the line through the end points, SIDPAC's) and transformed with
    the high-accuracy finite Fourier transform at ``frequencies_hz``: by default (``None`` or
    ``'auto'``) the seed's rule, 2/T to 1.2 Hz in 0.04 Hz steps with T the record length;
    ``'eq18'``/``'sidpac'`` for Eq. 18's fixed 0.20-1.20 Hz; or the frequencies given.
    :data:`SIDPAC_FREQUENCY_OPTIONS` names SIDPAC's convention (Eq. 18 and end points). On a
    20 s 2-1-1-2 the old defaults, Eq. 18 and the end-point line, left 2.5 and 3 Monte Carlo
    standard errors of bias in the seed's regressor-noise study. The complex least-squares
    problem is solved through Eq. 23's real stacking; σ̂² divides by m − n_p with m the number
    of frequencies (Eq. 21).

    Two options (not the defaults) remove the Cm_q̂ bias of moment equations whose angular
    accelerations are differentiated from the rates (Eqs. 3-5; the noise presets drop the
    recorded ones) when the inputs are steps on sample instants, as in the simulated
    2-1-1-2 (noise-free exact-truth F-16: Cm_q̂ −5.65 % of the truth by default):

    ``hold``
        Regressor names (e.g. ``("de",)``) transformed as zero-order holds
        (:func:`estimators.fourier.held_fourier_transform`) instead of cubic interpolants, in
        the Cl, Cm and Cn equations only. A moment coefficient differentiated from a
        continuous rate responds to a step at the step's instant; the cubic interpolant of
        the stepped input's samples (the sample at the step holding the new value) centres
        the jump half a sample early, a phase lead ``pi f dt`` that Eqs. 19-23 absorb mostly
        in Cm_q̂ (the regressor nearest in phase). Held: Cm_q̂ −0.38 %. Force equations and
        recorded accelerations sample the jump the way the input does, so they are left as
        they are (holding ``de`` there would create the same bias, +5.2 % in Cm_q̂ with
        recorded q̇).
    ``acceleration``
        ``'time'`` (default): the dependent variable as built by ``data`` (the time-domain
        smoothed derivative, the seed's method 1). ``'transform'``: for Cl, Cm, Cn fitted from
        a :class:`Recording` whose accelerations are differentiated, the angular
        accelerations are differentiated in the frequency domain instead
        (:func:`moment_transform`, exact integration by parts, no smoother). With ``hold``:
        Cm_q̂ −0.05 %. Ignored for :class:`RegressionData` (campaigns), which has no rates.
    """

    frequencies_hz: tuple[float, ...] | str | None = None
    detrend: str = "lstsq"
    data: DataOptions = field(default_factory=DataOptions)
    method: str = "ee-freq"
    acceleration: str = "time"
    hold: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.detrend not in DETRENDS:
            raise OptionError(f"detrend must be one of {DETRENDS}, not {self.detrend!r}")
        if self.acceleration not in ACCELERATIONS:
            raise OptionError(f"acceleration must be one of {ACCELERATIONS}, not {self.acceleration!r}")
        if self.acceleration == "transform" and self.detrend != "lstsq":
            raise OptionError("acceleration='transform' needs detrend='lstsq': the end points of a "
                              "derivative taken in the frequency domain are not known")
        object.__setattr__(self, "hold", tuple(self.hold))
        if isinstance(self.frequencies_hz, str) and self.frequencies_hz not in BANDS:
            raise OptionError(f"frequency band {self.frequencies_hz!r}: use one of {BANDS} or give frequencies")

    def held(self, equation: Equation) -> tuple[str, ...]:
        """The regressors of ``equation`` transformed as zero-order holds: those named in
        ``hold``, in the moment equations (Cl, Cm, Cn) only."""
        if equation.dependent not in _MOMENT_ACCELERATIONS:
            return ()
        return tuple(h for h in self.hold if h in equation.regressors)

    def transform(self, d: RegressionData, continuous: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Frequencies (Hz) and the transforms of z and X (``continuous``: every series less
        its interpolant's least-squares line, :func:`continuous_line`)."""
        f = frequency_band(self.frequencies_hz, (len(d.z) - 1) * d.dt)
        series = np.column_stack([d.z, d.X])
        flat = series - continuous_line(series, d.dt) if continuous else detrend(series, self.detrend)
        Z = finite_fourier_transform(flat, d.dt, f)
        for name in self.held(d.equation):  # the held samples, less the (smooth) line the detrend removed
            j = 1 + d.equation.regressors.index(name)
            Z[:, j] = (held_fourier_transform(series[:, j], d.dt, f)
                       - finite_fourier_transform(series[:, j] - flat[:, j], d.dt, f))
        return f, Z[:, 0], Z[:, 1:]

    def fit(self, source: Recording | RegressionData, equation: Equation | None = None) -> ModelFit:
        d = _as_data(source, equation, self.data)
        if d.equation.bias:
            d = RegressionData(Equation(d.equation.dependent, d.equation.regressors, bias=False),
                               d.z, d.X, d.t, d.dt, d.notes + ("the frequency-domain method estimates no bias "
                                                                "term (the data are detrended first)",),
                               d.assumptions)
        transformed = (self.acceleration == "transform" and isinstance(source, Recording)
                       and acceleration_differentiated(source, d.equation.dependent, self.data))
        f, z, X = self.transform(d, continuous=transformed)
        if transformed:
            z = moment_transform(source, d.equation.dependent, self.data, f)
        fit = fit_frequency_domain(z, X, d.names, d.equation.dependent, f, self.method, d.notes)
        band = self.frequencies_hz if isinstance(self.frequencies_hz, str) else (
            "auto" if self.frequencies_hz is None else "given")
        return replace(fit, assumptions=d.assumptions, info={**fit.info, "band": band, "detrend": self.detrend,
                                                             "acceleration": "transform" if transformed else "time",
                                                             "hold": list(self.held(d.equation))})


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
