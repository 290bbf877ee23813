"""Output error in the time domain: maximum likelihood for measurement noise (seed Eqs. 25-29).

The model outputs y(θ) of a linear model (:mod:`estimators.output_error_models`: the
short period of Eqs. 33-34 or the lateral-directional model) are matched to the measured
outputs z by minimising the negative log-likelihood of Eq. 26,

    J(θ, R) = ½ Σ_i [z_i − y_i(θ)]ᵀ R⁻¹ [z_i − y_i(θ)] + (N/2) ln|R|,

by relaxation (§III.B): a modified Newton-Raphson (Gauss-Newton) step in θ with R fixed,

    M = Σ_i S_iᵀ R⁻¹ S_i,  Δθ = M⁻¹ Σ_i S_iᵀ R⁻¹ (z_i − y_i),  S_i = ∂y_i/∂θ,

halved until J decreases, then R from Eq. 29 with θ fixed, repeated until both settle. R is
kept diagonal (independent noise on each output, the usual choice; its off-diagonal terms
would only be estimates of zero here). The sensitivities S_i are exact (the derivative of the
discrete solution, not finite differences). The covariance of θ̂ is the Cramér-Rao bound M⁻¹
at convergence with the estimated R.

θ holds non-dimensional derivatives (``CZ_alpha`` … ``Cm_de``, or ``CY_beta`` … ``Cn_dr``);
the model forms the dimensional matrices through Eq. 34 with the reference flight condition of
:func:`flight_constants`, plus the biases described in :mod:`estimators.output_error_models`.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from estimators.differentiation import smooth_derivative
from estimators.equation_error import EquationErrorTime
from estimators.least_squares import SingularRegressorsError, r_squared
from estimators.dynamic_models import ManeuverData, ModelProtocol, maneuver_data
from estimators.output_error_models import (AffineSystem, ModelSpec, OutputErrorData, affine_system,
                                            flight_constants, model_spec, output_error_data, parameter_names,
                                            resolve_data, response, response_and_sensitivities)
from estimators.regressors import DataOptions, Equation
from estimators.result import ModelFit, collinearity
from estimators.state_space import HOLDS, short_period_dimensional
from maneuvers.recording import Recording
from models.errors import OptionError, UserError

__all__ = ["DivergenceError", "NotIdentifiableError", "OutputError", "OutputErrorData",
           "OutputErrorFailure", "cramer_rao_bound", "flight_constants", "output_error_data",
           "parameter_names"]

COST_TOLERANCE = 1e-8  # relative change of J (Eq. 26) between iterations
STEP_TOLERANCE = 1e-3  # parameter change, in Cramér-Rao standard errors
NOISE_TOLERANCE = 1e-4  # relative change of each R_jj
MAX_HALVINGS = 12
MAX_GROWTH = 1e4  # largest growth exp(max Re λ · T) of the starting model over the record:
# starts growing by e^5 were seen to converge, by e^12.6 to swamp every sensitivity
IDENTIFIABILITY_LIMIT = 1e-10  # smallest/largest eigenvalue of the scaled information matrix
NOISE_FLOOR = 1e-12  # R_jj never below this fraction of the output's variance


class OutputErrorFailure(UserError):
    """Output error could not produce estimates; the message names the cause."""


class NotIdentifiableError(OutputErrorFailure):
    """The information matrix is singular: the message names the parameters involved."""


class DivergenceError(OutputErrorFailure):
    """The model response is not finite, or the cost cannot be reduced."""


# ---------------------------------------------------------------------------- the likelihood
@dataclass(frozen=True)
class _Problem:
    system: AffineSystem
    data: OutputErrorData
    hold: str

    @property
    def u1(self) -> np.ndarray:
        return np.column_stack([self.data.u, np.ones(len(self.data.t))])

    def outputs(self, theta: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return response(self.system, theta, self.u1, self.data.x0, self.data.dt, self.hold)[1]

    def sensitivities(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return response_and_sensitivities(self.system, theta, self.u1, self.data.x0, self.data.dt, self.hold)


def _whitener(R: np.ndarray) -> np.ndarray:
    """L with R⁻¹ = L Lᵀ, so vᵀR⁻¹v = |v L|² for a row v."""
    return np.linalg.cholesky(np.linalg.inv(R))


def _cost(v: np.ndarray, R: np.ndarray) -> float:
    """Eq. 26: ½ Σ vᵢᵀR⁻¹vᵢ + (N/2) ln|R|."""
    return 0.5 * float(np.sum((v @ _whitener(R)) ** 2)) + 0.5 * len(v) * float(np.linalg.slogdet(R)[1])


def _information(S: np.ndarray, v: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """M = Σ SᵢᵀR⁻¹Sᵢ and the gradient Σ SᵢᵀR⁻¹vᵢ (S: p×N×n_o)."""
    L = _whitener(R)
    Sw = (S @ L).reshape(len(S), -1)
    return Sw @ Sw.T, Sw @ (v @ L).ravel()


def _noise_covariance(v: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """Eq. 29 kept diagonal, each variance floored (noise-free data would give R = 0)."""
    return np.diag(np.maximum(np.mean(v ** 2, axis=0), floor))


def _check_information(M: np.ndarray, names: tuple[str, ...]) -> np.ndarray:
    """Refuse a singular information matrix, naming the parameters; return the scaling d."""
    d = np.sqrt(np.diag(M))
    dead = [names[j] for j in np.flatnonzero(~(d > 0))]
    if dead:
        raise NotIdentifiableError(f"the outputs do not depend on {', '.join(dead)} for these data: "
                                   "not identifiable (is the input that drives them moving?)")
    w, V = np.linalg.eigh(M / np.outer(d, d))
    null = np.flatnonzero(w <= IDENTIFIABILITY_LIMIT * w[-1])
    if null.size:
        weight = np.abs(V[:, null]).max(axis=1)
        involved = [names[j] for j in np.argsort(-weight) if weight[j] > 0.1 * weight.max()]
        cond = f"{w[-1] / w[0]:.3g}" if w[0] > 0 else "infinite"
        raise NotIdentifiableError(
            f"singular information matrix (scaled condition number {cond}): "
            f"{', '.join(involved)} cannot be separated with these data; fix some of them or fly a "
            "maneuver that excites them independently")
    return d


def _inverse(M: np.ndarray, d: np.ndarray) -> np.ndarray:
    return np.linalg.inv(M / np.outer(d, d)) / np.outer(d, d)


def cramer_rao_bound(source: Recording | OutputErrorData, model: str | None,
                     theta: Mapping[str, float] | np.ndarray, R: np.ndarray, *,
                     options: DataOptions = DataOptions(), hold: str = "zoh") -> np.ndarray:
    """Cramér-Rao bound M⁻¹ of ``model`` for the inputs of ``source`` at parameters ``theta``
    with measurement-noise covariance ``R`` (the same information matrix as the fit).

    Parameters
    ----------
    source : a recording (its inputs, x₀ and flight condition are used) or OutputErrorData.
    model : ``'short-period'``, ``'lateral'`` (None: that of OutputErrorData, else short period).
    theta : mapping name → value (missing biases are zero) or a vector in
        :func:`parameter_names` order.
    R : (n_o,) variances or an n_o×n_o covariance, in the output units (rad, rad/s, g).

    Returns
    -------
    ndarray
        p×p covariance in :func:`parameter_names` order.
    """
    model = model if model is not None else (source.model if isinstance(source, OutputErrorData) else None)
    spec = model_spec(model)
    data = source if isinstance(source, OutputErrorData) else output_error_data(source, spec.name, options)
    th = _as_vector(theta, spec)
    R = np.asarray(R, dtype=float)
    R = np.diag(R) if R.ndim == 1 else R
    problem = _Problem(affine_system(spec, data.flight), data, hold)
    _, S = problem.sensitivities(th)
    M, _ = _information(S, np.zeros_like(data.z), R)
    return _inverse(M, _check_information(M, spec.names))


def _as_vector(theta: Mapping[str, float] | np.ndarray, spec: ModelSpec) -> np.ndarray:
    if not isinstance(theta, Mapping):
        th = np.asarray(theta, dtype=float).ravel()
        if len(th) != len(spec.names):
            raise ValueError(f"theta needs {len(spec.names)} values in the order {spec.names}")
        return th
    unknown = sorted(set(theta) - set(spec.names))
    missing = [d for d in spec.derivatives if d not in theta]
    if unknown or missing:
        raise ValueError(f"{spec.name} parameters: unknown {unknown}, missing {missing}")
    return np.array([float(theta.get(n, 0.0)) for n in spec.names])


# ---------------------------------------------------------------------------- starting values
def _equation_error_start(rec: Recording, spec: ModelSpec, options: DataOptions) -> dict[str, float]:
    """Derivatives from ordinary least squares equation error (seed Eqs. 12-17) on each equation."""
    est, out = EquationErrorTime(data=options), {}
    for eq in spec.equations:
        try:
            fit = est.fit(rec, eq)
        except SingularRegressorsError as exc:
            raise NotIdentifiableError(f"equation-error starting values for {eq.describe()}: {exc}") from exc
        except ValueError as exc:
            raise OutputErrorFailure(f"equation-error starting values failed for {eq.describe()}: {exc}; "
                                     "give OutputError(start=...)") from exc
        out.update({n: fit.param(n) for n in fit.names if n != "bias"})
    return out


def _state_equation_start(problem: _Problem) -> dict[str, float]:
    """Derivatives from equation error on the state equations and the non-state outputs.

    With measured states x̂ and their smoothed derivatives (seed §III.A, method 1), the model
    is linear in θ: ẋ̂ − A₀x̂ − B̄₀ū = Σ θ_j (A_j x̂ + B̄_j ū) and z − C₀x̂ − D̄₀ū = Σ θ_j (C_j x̂ +
    D̄_j ū); each block is scaled by its spread and the stack solved by least squares.
    """
    sys_, data = problem.system, problem.data
    spec = data.spec
    xs = data.z[:, list(spec.state_outputs)]
    xdot = np.column_stack([smooth_derivative(xs[:, i], data.dt) for i in range(xs.shape[1])])
    u1 = problem.u1
    (A0, B0, C0, D0), (dA, dB, dC, dD) = sys_.base, sys_.partials
    other = [i for i in range(len(spec.outputs)) if i not in spec.state_outputs]
    lhs = [xdot - xs @ A0.T - u1 @ B0.T, (data.z - xs @ C0.T - u1 @ D0.T)[:, other]]
    cols = [np.matmul(xs, dA.transpose(0, 2, 1)) + np.matmul(u1, dB.transpose(0, 2, 1)),
            (np.matmul(xs, dC.transpose(0, 2, 1)) + np.matmul(u1, dD.transpose(0, 2, 1)))[:, :, other]]
    rows, X = [], []
    for y, c in zip(lhs, cols):
        scale = np.maximum(np.std(y, axis=0), 1e-300)
        rows.append((y / scale).T.ravel())
        X.append((c / scale).transpose(0, 2, 1).reshape(len(c), -1).T)
    theta = np.linalg.lstsq(np.vstack(X), np.concatenate(rows), rcond=None)[0]
    return dict(zip(spec.derivatives, theta[:len(spec.derivatives)]))


def _check_stability(problem: _Problem, theta: np.ndarray) -> None:
    """Refuse a starting model whose response grows by more than MAX_GROWTH over the record
    (time-domain output error cannot follow it: the seed's §II remark on unstable aircraft)."""
    A = problem.system.matrices(theta)[0]
    rate = float(np.max(np.linalg.eigvals(A).real))
    T = problem.data.t[-1] - problem.data.t[0]
    if rate * T > np.log(MAX_GROWTH):
        raise DivergenceError(
            f"the model at the starting values is unstable (eigenvalue with real part {rate:.3g} 1/s grows "
            f"by e^{rate * T:.3g} over the {T:.3g} s record): time-domain output error cannot follow it from "
            "there; give OutputError(start=...) nearer a bounded model, fit a shorter record, or use "
            "equation error (which also suits unstable aircraft)")


def _bias_start(problem: _Problem, theta: np.ndarray, free: np.ndarray) -> np.ndarray:
    """Least-squares values of the biases flagged in ``free`` with the other parameters fixed
    (exact in one step: the outputs are affine in the biases)."""
    y, S = problem.sensitivities(theta)
    v = problem.data.z - y
    w = 1.0 / np.maximum(np.std(v, axis=0), 1e-300)
    X = (S[free] * w).reshape(int(free.sum()), -1).T
    out = theta.copy()
    out[free] += np.linalg.lstsq(X, (v * w).ravel(), rcond=None)[0]
    return out


def _not_data(source: object):
    raise ValueError(f"output error takes a Recording or ManeuverData, not {type(source).__name__}")


# ---------------------------------------------------------------------------- the estimator
@dataclass(frozen=True)
class OutputError:
    """Output error in the time domain, maximum likelihood by relaxation (seed Eqs. 25-29).

    Parameters
    ----------
    model : ``'short-period'`` or ``'lateral'`` (the built-in linear models, exact
        sensitivities); a :class:`estimators.dynamic_models.Model` of the user's own (any model,
        :mod:`estimators.output_error_general`: one recording or ManeuverData, or a list of
        them fitted together); None chooses a built-in model from the equation passed to
        :meth:`fit` (C_Z, C_m, C_L, C_D, C_X → short period; C_Y, C_l, C_n → lateral), or the
        short period without one. An equation with a dependent or a regressor the built-in
        model does not have is refused (output error fits the model's structure, not the
        equation's).
    x0 : user models: ``'estimate'`` each maneuver's initial state, or ``'fixed'``.
    data : perturbation references, and the options of the equation-error starting fit.
    max_iterations : Gauss-Newton iterations (each followed by an update of R).
    start : starting values by name; derivatives not given come from equation error (ordinary
        least squares, :class:`EquationErrorTime`, on a recording; on the state equations for
        plain :class:`OutputErrorData`); biases not given from linear least squares.
    hold : how inputs behave between samples in the simulation, ``'zoh'`` or ``'foh'``.
    """

    model: object = None
    data: DataOptions = field(default_factory=DataOptions)
    max_iterations: int = 50
    start: Mapping[str, float] | None = None
    hold: str = "zoh"
    method: str = "oe"
    x0: str = "estimate"

    def __post_init__(self) -> None:
        if self.hold not in HOLDS:
            raise ValueError(f"hold must be one of {HOLDS}, not {self.hold!r}")
        if self.max_iterations < 1:
            raise ValueError("max_iterations must be at least 1")
        if self.model is not None and not isinstance(self.model, str) and not isinstance(self.model, ModelProtocol):
            raise ValueError(f"model must be 'short-period', 'lateral' or a Model, not {type(self.model).__name__}")

    def _fit_model(self, source, equation: Equation | None) -> ModelFit:
        """A user's model (:mod:`estimators.output_error_general`), one or several maneuvers."""
        from estimators.output_error_general import fit_model
        model = self.model
        if equation is not None and equation.regressors:
            raise OptionError(f"output error fits model {model.name!r} as it is written; it takes no equation "
                             f"(got {equation.describe()}): leave out the regressors")
        sources = list(source) if isinstance(source, (list, tuple)) else [source]
        datasets = [s if isinstance(s, ManeuverData) else maneuver_data(s, model) if isinstance(s, Recording)
                    else _not_data(s) for s in sources]
        return fit_model(model, datasets, start=self.start, x0=self.x0, hold=self.hold,
                         max_iterations=self.max_iterations, method=self.method)

    def fit(self, source: Recording | OutputErrorData, equation: Equation | None = None) -> ModelFit:
        """Estimate every parameter of the model (the equation only chooses the model).

        Parameters
        ----------
        source : a recording, or :class:`OutputErrorData` (plain arrays).
        equation : used only to choose the model when ``model`` is None; its regressors are
            ignored (the model's structure is fixed).

        Returns
        -------
        ModelFit
            ``method='oe'``, ``domain='time'``, ``dependent`` the outputs (``'alpha,q,az'``),
            all parameters of :func:`parameter_names`, ``cov`` the Cramér-Rao bound
            (``errors='cramer-rao'``), residuals and fitted outputs N×n_o, ``s2`` the weighted
            cost per value Σ vᵀR̂⁻¹v/(N n_o) (1 when R̂ is Eq. 29's estimate), ``r2`` the mean of
            the outputs' R². ``info`` holds ``R`` (n_o×n_o), ``cost`` (Eq. 26) and its history,
            ``iterations``, ``converged``, ``r2`` per output, ``start_source``, ``flight``, the
            fitted ``matrices`` (B and D with their bias columns) and, for the short period,
            the ``dimensional`` derivatives of Eq. 34.

        Raises
        ------
        NotIdentifiableError
            An input never moves, or the information matrix is singular (names the parameters).
        DivergenceError
            The model response overflows, or no step reduces the cost.
        """
        if self.model is not None and not isinstance(self.model, str):
            return self._fit_model(source, equation)
        if isinstance(source, (list, tuple)):
            raise OptionError("several maneuvers are fitted with a Model (estimators.dynamic_models); the built-in "
                             "models take one recording")
        data = resolve_data(source, self.model, equation, self.data)
        name = data.model
        spec = data.spec
        for i, u in enumerate(spec.inputs):
            if np.ptp(data.u[:, i]) == 0:
                dead = [d for d in spec.derivatives if d.endswith(f"_{u}")]
                raise NotIdentifiableError(f"input {u!r} never moves, so {', '.join(dead)} are not "
                                           "identifiable: fly a maneuver that moves it, or fix them")
        problem = _Problem(affine_system(spec, data.flight), data, self.hold)
        theta0, origin = self._start(problem, source)
        return self._relaxation(problem, theta0, origin)

    def _start(self, problem: _Problem, source: Recording | OutputErrorData) -> tuple[np.ndarray, str]:
        spec, given = problem.data.spec, dict(self.start or {})
        unknown = sorted(set(given) - set(spec.names))
        if unknown:
            raise OptionError(f"start has unknown parameters {unknown}; {spec.name} has {spec.names}")
        origin = "given"
        if any(d not in given for d in spec.derivatives):
            if isinstance(source, Recording):
                ee, origin = _equation_error_start(source, spec, self.data), "equation-error"
            else:
                ee, origin = _state_equation_start(problem), "state-equation-error"
            given = {**{d: ee[d] for d in spec.derivatives}, **given}
        theta = np.array([float(given.get(n, 0.0)) for n in spec.names])
        _check_stability(problem, theta)
        free = np.array([n not in given for n in spec.names])
        return (_bias_start(problem, theta, free) if free.any() else theta), origin

    def _relaxation(self, problem: _Problem, theta: np.ndarray, origin: str) -> ModelFit:
        spec, z = problem.data.spec, problem.data.z
        names = spec.names
        floor = NOISE_FLOOR * np.maximum(np.var(z, axis=0), 1e-300)
        y = problem.outputs(theta)
        R = _noise_covariance(z - y, floor)
        J = _cost(z - y, R)
        history, converged, iterations = [J], False, 0
        for iterations in range(1, self.max_iterations + 1):
            y, S = problem.sensitivities(theta)
            v = z - y
            M, grad = _information(S, v, R)
            d = _check_information(M, names)
            step = np.linalg.solve(M / np.outer(d, d), grad / d) / d
            se = np.sqrt(np.diag(_inverse(M, d)))
            small = bool(np.max(np.abs(step) / se) < STEP_TOLERANCE)
            quadratic = 0.5 * float(np.sum((v @ _whitener(R)) ** 2))
            lam, trial = 1.0, None
            for _ in range(MAX_HALVINGS):
                y_t = problem.outputs(theta + lam * step)
                if np.all(np.isfinite(y_t)) and 0.5 * np.sum(((z - y_t) @ _whitener(R)) ** 2) <= quadratic:
                    trial = theta + lam * step
                    break
                lam /= 2
            if trial is None:
                if small:  # at the optimum to rounding: the step is a vanishing fraction of an error bound
                    converged = True
                    break
                raise DivergenceError(
                    f"output error diverged at iteration {iterations}: no step along the Gauss-Newton "
                    f"direction reduces the cost (after {MAX_HALVINGS} halvings); the starting values may be "
                    "too far from the optimum or the model cannot match these data")
            R_new = _noise_covariance(z - y_t, floor)
            J_new = _cost(z - y_t, R_new)
            history.append(J_new)
            change_R = float(np.max(np.abs(np.diag(R_new) - np.diag(R)) / np.diag(R)))
            change_J = abs(J_new - J) / max(abs(J), 1.0)
            theta, R, J = trial, R_new, J_new
            if change_J < COST_TOLERANCE and np.max(np.abs(lam * step) / se) < STEP_TOLERANCE \
                    and change_R < NOISE_TOLERANCE:
                converged = True
                break
        return self._result(problem, theta, R, history, iterations, converged, origin)

    def _result(self, problem: _Problem, theta: np.ndarray, R: np.ndarray, history: list[float],
                iterations: int, converged: bool, origin: str) -> ModelFit:
        spec, z = problem.data.spec, problem.data.z
        y, S = problem.sensitivities(theta)
        v = z - y
        M, _ = _information(S, v, R)
        cov = _inverse(M, _check_information(M, spec.names))
        is_bias = np.array([n.startswith("bias") for n in spec.names])
        coll = collinearity((S @ _whitener(R)).reshape(len(S), -1).T, spec.names, cov, is_bias)
        r2 = {o: r_squared(z[:, i], v[:, i]) for i, o in enumerate(spec.outputs)}
        warnings = list(coll.warnings(parameters=True))
        if not converged:
            warnings.append(f"output error did not converge in {iterations} iterations")
        A, B, C, D = problem.system.matrices(theta)
        info = {"R": R.tolist(), "cost": history[-1], "cost_history": history, "iterations": iterations,
                "converged": converged, "r2": r2, "outputs": list(spec.outputs), "model": spec.name,
                "hold": self.hold, "start_source": origin, "flight": problem.data.flight.as_dict(),
                "matrices": {"A": A.tolist(), "B": B.tolist(), "C": C.tolist(), "D": D.tolist()},
                "notes": list(problem.data.notes)}
        if spec.name == "short-period":
            f = problem.data.flight
            info["dimensional"] = short_period_dimensional(*theta[:6], f.qbar, f.S, f.cbar, f.m, f.Iy, f.V)
        return ModelFit(method=self.method, domain="time", dependent=",".join(spec.outputs), names=spec.names,
                        params=theta, cov=cov, residuals=v, fitted=y, n=len(z),
                        s2=float(np.sum((v @ _whitener(R)) ** 2)) / v.size,
                        r2=float(np.mean(list(r2.values()))), errors="cramer-rao", collinearity=coll,
                        warnings=tuple(warnings), info=info)
