"""The linear models output error fits, their data, and their response and sensitivities.

A model is a :class:`ModelSpec`: named states, inputs and outputs, the non-dimensional
derivatives it estimates, and a function giving A, B, C, D from them and the
:class:`FlightConstants` (seed Eq. 34 for the short period). Bias parameters complete it
(:meth:`ModelSpec.names`):

* one constant on each state equation, ``bias_<state>dot`` (ẋ = Ax + Bu + b_x), and
* one constant on each output, ``bias_<output>`` (y = Cx + Du + b_y),

with the initial state fixed (zero perturbation by default). This set is identifiable
and complete: with A invertible, y(t) = C e^{At}(x₀ + A⁻¹b_x) + (b_y − CA⁻¹b_x) + (input
response), so estimating x₀ as well would add an unidentifiable direction, while any fixed x₀
is absorbed by b_x; the derivative estimates do not depend on the x₀ chosen.

Every matrix is affine in the parameter vector θ (Eq. 34 is linear in the coefficients and
the inertia coupling is constant), so a model is stored as A(θ) = A₀ + Σ θ_j A_j etc.
(:class:`AffineSystem`) and its sensitivities ∂y/∂θ_j follow exactly by differentiating the
discrete recursion (:func:`response_and_sensitivities`).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from estimators.dynamic_models import Parameter
from estimators.regressors import DataOptions, Equation, regression_data
from estimators.state_space import (LATERAL_DERIVATIVES, discretize, discretize_derivatives,
                                    lateral_matrices, propagate, scan, short_period_dimensional,
                                    short_period_matrices)
from maneuvers.recording import Recording
from models.errors import OptionError
from maneuvers.recording import RecordingError
from estimators.regressors import EquationError
from models.constants import G0_FPS2

Matrices = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class FlightConstants:
    """Reference flight condition, geometry and mass of a linear model.

    ``qbar`` psf and ``V`` ft/s are q̄_o and V_o of Eq. 34; ``alpha_o``, ``theta_o`` rad the trim
    angles used by the lateral kinematics; inertias in slug·ft² with I_xz of the seed's sign.
    """

    qbar: float
    V: float
    S: float
    cbar: float
    b: float
    m: float
    Ix: float
    Iy: float
    Iz: float
    Ixz: float
    alpha_o: float = 0.0
    theta_o: float = 0.0
    g: float = G0_FPS2

    def as_dict(self) -> dict[str, float]:
        return {k: float(getattr(self, k)) for k in self.__dataclass_fields__}


@dataclass(frozen=True)
class ModelSpec:
    """A linear model that output error can fit.

    Attributes
    ----------
    name : ``'short-period'`` or ``'lateral'``.
    states, inputs, outputs : quantity names (recording channels without unit).
    derivatives : the non-dimensional derivatives estimated, e.g. ``'Cm_qhat'``.
    equations : the equation-error models giving starting values for them.
    matrices : ``(derivatives, flight) -> (A, B, C, D)``.
    """

    name: str
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    derivatives: tuple[str, ...]
    equations: tuple[Equation, ...]
    matrices: Callable[[Mapping[str, float], FlightConstants], Matrices]

    @property
    def state_biases(self) -> tuple[str, ...]:
        return tuple(f"bias_{s}dot" for s in self.states)

    @property
    def output_biases(self) -> tuple[str, ...]:
        return tuple(f"bias_{o}" for o in self.outputs)

    @property
    def names(self) -> tuple[str, ...]:
        """All parameters: derivatives, then state-equation biases, then output biases."""
        return self.derivatives + self.state_biases + self.output_biases

    @property
    def state_outputs(self) -> tuple[int, ...]:
        """Index in ``outputs`` of each state (each state is measured directly)."""
        return tuple(self.outputs.index(s) for s in self.states)

    # -- the model specification of :mod:`estimators.dynamic_models` ------------------------
    @property
    def parameters(self) -> tuple[Parameter, ...]:
        """Every parameter (derivatives, then biases), starting at 0 (output error starts the
        built-in models from equation error, :class:`estimators.output_error.OutputError`)."""
        return tuple(Parameter(n, 0.0, scale=1.0 if n.endswith("hat") else 0.1) for n in self.names)

    @property
    def constants(self) -> Mapping[str, float]:
        return MappingProxyType({})

    def dynamics(self, t, x, u, theta: Mapping[str, np.ndarray], constants: Mapping[str, float]) -> np.ndarray:
        """ẋ = A x + B u + b_x (Eq. 33a-b; the lateral model alike) for columns of x, u, θ."""
        return self._linear(x, u, theta, constants, state=True)

    def observe(self, t, x, u, theta: Mapping[str, np.ndarray], constants: Mapping[str, float]) -> np.ndarray:
        """y = C x + D u + b_y (Eq. 33c) for columns of x, u, θ."""
        return self._linear(x, u, theta, constants, state=False)

    def _linear(self, x, u, theta, constants, state: bool) -> np.ndarray:
        flight = flight_from_constants(constants)
        x = np.atleast_2d(np.asarray(x, float))
        K = x.shape[1]
        u = np.broadcast_to(np.asarray(u, float).reshape(len(self.inputs), -1), (len(self.inputs), K))
        cols = np.stack([np.broadcast_to(np.asarray(theta[n], float), (K,)) for n in self.names])
        unique, inverse = np.unique(cols, axis=1, return_inverse=True)
        nd, ns = len(self.derivatives), len(self.states)
        out = np.empty((ns if state else len(self.outputs), K))
        for c in range(unique.shape[1]):
            sel = np.flatnonzero(inverse.ravel() == c)
            A, B, C, D = self.matrices(dict(zip(self.derivatives, unique[:nd, c])), flight)
            if state:
                out[:, sel] = A @ x[:, sel] + B @ u[:, sel] + unique[nd:nd + ns, c][:, None]
            else:
                out[:, sel] = C @ x[:, sel] + D @ u[:, sel] + unique[nd + ns:, c][:, None]
        return out


def _short_period(d: Mapping[str, float], f: FlightConstants) -> Matrices:
    dim = short_period_dimensional(d["CZ_alpha"], d["CZ_qhat"], d["CZ_de"], d["Cm_alpha"], d["Cm_qhat"],
                                   d["Cm_de"], f.qbar, f.S, f.cbar, f.m, f.Iy, f.V)
    return short_period_matrices(**dim, V_o=f.V, g=f.g)


def _lateral(d: Mapping[str, float], f: FlightConstants) -> Matrices:
    return lateral_matrices(d, qbar=f.qbar, V=f.V, S=f.S, b=f.b, m=f.m, Ix=f.Ix, Iz=f.Iz, Ixz=f.Ixz,
                            alpha_o=f.alpha_o, theta_o=f.theta_o, g=f.g)


_SP_TERMS = ("alpha", "qhat", "de")
_LAT_TERMS = ("beta", "phat", "rhat", "da", "dr")
MODELS: Mapping[str, ModelSpec] = MappingProxyType({
    "short-period": ModelSpec(
        "short-period", ("alpha", "q"), ("de",), ("alpha", "q", "az"),
        tuple(f"{c}_{x}" for c in ("CZ", "Cm") for x in _SP_TERMS),
        (Equation("CZ", _SP_TERMS), Equation("Cm", _SP_TERMS)), _short_period),
    "lateral": ModelSpec(
        "lateral", ("beta", "p", "r", "phi"), ("da", "dr"), ("beta", "p", "r", "phi", "ay"),
        LATERAL_DERIVATIVES, tuple(Equation(c, _LAT_TERMS) for c in ("CY", "Cl", "Cn")), _lateral),
})
LONGITUDINAL_COEFFICIENTS = ("CZ", "Cm", "CL", "CD", "CX")
LATERAL_COEFFICIENTS = ("CY", "Cl", "Cn")


def flight_from_constants(constants: Mapping[str, float]) -> FlightConstants:
    """FlightConstants from a mapping with its field names, or the names of
    :func:`estimators.dynamic_models.recording_constants` (``V0``, ``qbar0``, ``alpha0``, ``theta0``)."""
    alias = {"qbar": "qbar0", "V": "V0", "alpha_o": "alpha0", "theta_o": "theta0"}
    values = {}
    for k in FlightConstants.__dataclass_fields__:
        if k in constants:
            values[k] = float(constants[k])
        elif k in alias and alias[k] in constants:
            values[k] = float(constants[alias[k]])
    try:
        return FlightConstants(**values)
    except TypeError:
        missing = [k for k in FlightConstants.__dataclass_fields__ if k not in values]
        raise RecordingError(f"the built-in linear models need the constants {missing}") from None


def check_equation(spec: ModelSpec, equation: Equation | None) -> None:
    """Refuse an equation whose dependent or regressors the model does not have: output error
    fits the model's whole structure and must never echo a term it does not fit."""
    if equation is None:
        return
    terms = {eq.dependent: eq.regressors for eq in spec.equations}
    if equation.dependent not in terms:
        raise EquationError(f"output error's {spec.name} model has no {equation.dependent} equation (it fits "
                         f"{', '.join(terms)}): give a model of your own (--model-file) or use equation error")
    extra = [r for r in equation.regressors if r not in terms[equation.dependent]]
    if extra:
        raise EquationError(f"output error's {spec.name} model has no {', '.join(extra)} term in {equation.dependent} "
                         f"(it has {', '.join(terms[equation.dependent])}): give a model that has it "
                         "(--model-file) or use equation error")


def model_spec(model: str | None, equation: Equation | None = None) -> ModelSpec:
    """The model named ``model``; when None, chosen from the equation's dependent variable
    (CZ, Cm, CL, CD, CX → short period; CY, Cl, Cn → lateral), else the short period."""
    if model is None:
        if equation is None or equation.dependent in LONGITUDINAL_COEFFICIENTS:
            model = "short-period"
        elif equation.dependent in LATERAL_COEFFICIENTS:
            model = "lateral"
        else:
            raise EquationError(f"cannot choose an output-error model for dependent {equation.dependent!r}: "
                             f"use one of {LONGITUDINAL_COEFFICIENTS + LATERAL_COEFFICIENTS} or give model=")
    if model not in MODELS:
        raise OptionError(f"unknown output-error model {model!r}; use one of {list(MODELS)}")
    return MODELS[model]


@dataclass(frozen=True)
class OutputErrorData:
    """Sampled inputs and measured outputs of one maneuver, ready for output error.

    Attributes
    ----------
    t : (N,) sample times, uniform step.
    u : (N, n_u) inputs (perturbations, rad), in the model's input order.
    z : (N, n_o) measured outputs (perturbations; a_z, a_y in g), in the model's output order.
    flight : the reference condition, geometry and mass (Eq. 34).
    model : ``'short-period'`` or ``'lateral'``.
    x0 : initial state perturbation (default zero: the record starts at the reference). Any
        fixed value gives the same derivative estimates, since b_x absorbs it (see
        :mod:`estimators.output_error_models`); a deterministic one keeps the bias estimates
        free of the noise of a measured first sample, so their Cramér-Rao bounds hold too.
    notes : remarks from the data assembly.
    """

    t: np.ndarray
    u: np.ndarray
    z: np.ndarray
    flight: FlightConstants
    model: str = "short-period"
    x0: np.ndarray | None = None
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        spec = model_spec(self.model)
        t = np.asarray(self.t, dtype=float)
        u = np.asarray(self.u, dtype=float).reshape(len(t), -1)
        z = np.asarray(self.z, dtype=float).reshape(len(t), -1)
        if u.shape[1] != len(spec.inputs) or z.shape[1] != len(spec.outputs):
            raise ValueError(f"{spec.name} output error needs u with columns {spec.inputs} and z with "
                             f"columns {spec.outputs}; got {u.shape[1]} and {z.shape[1]} columns")
        if len(t) < 8 or not np.all(np.isfinite(u)) or not np.all(np.isfinite(z)):
            raise ValueError("output error needs at least 8 samples of finite data")
        step = np.diff(t)
        if np.any(np.abs(step - step.mean()) > 1e-6 * step.mean()) or step.mean() <= 0:
            raise ValueError("output error needs uniformly sampled data (increasing t, constant step)")
        x0 = np.zeros(len(spec.states)) if self.x0 is None else np.asarray(self.x0, float).ravel()
        if len(x0) != len(spec.states):
            raise ValueError(f"x0 needs {len(spec.states)} values, one per state {spec.states}")
        for name, value in (("t", t), ("u", u), ("z", z), ("x0", x0)):
            object.__setattr__(self, name, value)

    @property
    def dt(self) -> float:
        return float((self.t[-1] - self.t[0]) / (len(self.t) - 1))

    @property
    def spec(self) -> ModelSpec:
        return model_spec(self.model)


def flight_constants(rec: Recording) -> FlightConstants:
    """Reference condition of a recording: V_o, q̄_o, α_o, θ_o from ``meta['trim']`` when it has
    them, otherwise the mean over the record (the condition the maneuver actually flew about,
    consistent on average with equation error's normalisation by the instantaneous q̄ and V);
    mass and inertia are the record means (constant over a maneuver)."""
    trim = rec.meta.get("trim", {}) if isinstance(rec.meta.get("trim"), dict) else {}
    ref = {k: float(trim[f"{k}_{u}"]) if f"{k}_{u}" in trim else float(np.mean(rec.channel(k)))
           for k, u in (("V", "fps"), ("qbar", "psf"), ("alpha", "rad"), ("theta", "rad"))}
    g, mass = rec.geometry, {k: float(np.mean(v)) for k, v in rec.mass_at().items()}
    return FlightConstants(qbar=ref["qbar"], V=ref["V"], S=g["S_ft2"], cbar=g["cbar_ft"], b=g["b_ft"],
                           m=mass["mass_slug"], Ix=mass["Ix_slugft2"], Iy=mass["Iy_slugft2"],
                           Iz=mass["Iz_slugft2"], Ixz=mass["Ixz_slugft2"], alpha_o=ref["alpha"],
                           theta_o=ref["theta"])


def output_error_data(recording: Recording, model: str = "short-period",
                      options: DataOptions = DataOptions()) -> OutputErrorData:
    """Inputs and outputs of ``model`` from a recording, as perturbations per ``options.reference``.

    The project's convention of :func:`estimators.regressors.regression_data` is used: with
    ``'trim'``, values from ``meta['trim']`` (rates from zero; a quantity without a trim value
    is used as measured, noted in ``notes``), ``'first'`` the first sample, ``'none'`` raw
    values. The references only move the bias estimates, never the derivatives.
    """
    spec = model_spec(model)
    channels = spec.outputs + spec.inputs
    d = regression_data(recording, Equation(channels[0], channels, bias=False),
                        DataOptions(reference=options.reference))
    n_o = len(spec.outputs)
    return OutputErrorData(t=recording.t, u=d.X[:, n_o:], z=d.X[:, :n_o], flight=flight_constants(recording),
                           model=spec.name, notes=d.notes)


def parameter_names(model: str) -> tuple[str, ...]:
    """Every parameter of ``model`` in estimation order (derivatives, state-equation biases,
    output biases)."""
    return model_spec(model).names


@dataclass(frozen=True)
class AffineSystem:
    """A(θ) = A₀ + Σ θ_j dA[j] (B̄, C, D̄ alike), with B̄ = [B b_x], D̄ = [D b_y] acting on the
    inputs extended by a constant 1, so biases are ordinary entries of the matrices."""

    names: tuple[str, ...]
    base: Matrices
    partials: Matrices  # each of shape (p, rows, cols)

    def matrices(self, theta: np.ndarray) -> Matrices:
        return tuple(m0 + np.tensordot(theta, dm, axes=1) for m0, dm in zip(self.base, self.partials))


def affine_system(spec: ModelSpec, flight: FlightConstants) -> AffineSystem:
    """Decompose the model into its affine form (exact: the model is affine in θ).

    Raises
    ------
    AssertionError
        If the matrices are not affine in θ (a programming error in a model definition).
    """
    nd, ns, no = len(spec.derivatives), len(spec.states), len(spec.outputs)

    def full(theta: np.ndarray) -> Matrices:
        A, B, C, D = spec.matrices(dict(zip(spec.derivatives, theta[:nd])), flight)
        return (A, np.column_stack([B, theta[nd:nd + ns]]), C, np.column_stack([D, theta[nd + ns:]]))

    p = nd + ns + no
    base = full(np.zeros(p))
    cols = [full(e) for e in np.eye(p)]
    partials = tuple(np.stack([c[i] - base[i] for c in cols]) for i in range(4))
    system = AffineSystem(spec.names, base, partials)
    probe = np.linspace(-1.0, 1.0, p)
    for got, want in zip(system.matrices(probe), full(probe)):
        assert np.allclose(got, want, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(want).max())), \
            f"model {spec.name!r} is not affine in its parameters"
    return system


def _forcing(G0: np.ndarray, G1: np.ndarray, u: np.ndarray, hold: str) -> np.ndarray:
    w = u[:-1] @ G0.T
    return w + u[1:] @ G1.T if hold == "foh" else w


def response(system: AffineSystem, theta: np.ndarray, u1: np.ndarray, x0: np.ndarray, dt: float,
             hold: str = "zoh") -> tuple[np.ndarray, np.ndarray]:
    """States and outputs (N×n, N×n_o) for inputs ``u1`` already extended by a column of ones."""
    A, B, C, D = system.matrices(theta)
    Phi, G0, G1 = discretize(A, B, dt, hold)
    x = propagate(Phi, _forcing(G0, G1, u1, hold), x0)
    return x, x @ C.T + u1 @ D.T


def response_and_sensitivities(system: AffineSystem, theta: np.ndarray, u1: np.ndarray, x0: np.ndarray,
                               dt: float, hold: str = "zoh") -> tuple[np.ndarray, np.ndarray]:
    """Outputs y (N×n_o) and their exact sensitivities S[j] = ∂y/∂θ_j, shape (p, N, n_o).

    Differentiating x_{k+1} = Φx_k + G₀ū_k + G₁ū_{k+1} gives, with x₀ fixed,
    ∂x_{k+1}/∂θ_j = Φ ∂x_k/∂θ_j + ∂Φ_j x_k + ∂G₀_j ū_k + ∂G₁_j ū_{k+1} (∂Φ_j … from the
    Fréchet derivative of the matrix exponential), and ∂y/∂θ_j = C ∂x/∂θ_j + C_j x + D_j ū.
    All p sensitivity recursions share Φ and are scanned together.
    """
    A, B, C, D = system.matrices(theta)
    dA, dB, dC, dD = system.partials
    Phi, G0, G1 = discretize(A, B, dt, hold)
    x = propagate(Phi, _forcing(G0, G1, u1, hold), x0)
    p, n, N = len(theta), A.shape[0], len(u1)
    dPhi, dG0, dG1 = discretize_derivatives(A, B, dA, dB, dt, hold)
    Z = np.column_stack([x, u1])
    e = np.zeros((p, N, n))  # e[:, 0] = ∂x₀/∂θ = 0
    e[:, 1:] = _per_parameter(Z[:-1], np.concatenate([dPhi, dG0], axis=2))
    if hold == "foh":
        e[:, 1:] += _per_parameter(u1[1:], dG1)
    S = (scan(Phi, e).reshape(-1, n) @ C.T).reshape(p, N, -1)
    S += _per_parameter(Z, np.concatenate([dC, dD], axis=2))
    return x @ C.T + u1 @ D.T, S


def _per_parameter(a: np.ndarray, T: np.ndarray) -> np.ndarray:
    """out[j, k] = T[j] a[k] for every parameter j as one matrix product: (K, c), (p, r, c) → (p, K, r)."""
    p, r, c = T.shape
    return (a @ T.transpose(2, 0, 1).reshape(c, p * r)).reshape(len(a), p, r).transpose(1, 0, 2)


def resolve_data(source: "Recording | OutputErrorData", model: str | None, equation: Equation | None,
                 options: DataOptions) -> OutputErrorData:
    """The built-in model's data from a recording or given arrays, with the equation checked
    against the model (:func:`check_equation`: regressors it does not have are refused).

    Raises
    ------
    ValueError
        When ``model`` names another model than the given data's, or the equation asks for
        terms the model lacks.
    """
    if isinstance(source, OutputErrorData):
        if model is not None and model != source.model:
            raise ValueError(f"model {model!r} given {source.model!r} data")
        check_equation(model_spec(source.model), equation if equation is not None and equation.regressors else None)
        return source
    name = model_spec(model, equation).name
    check_equation(model_spec(name), equation)
    return output_error_data(source, name, options)
