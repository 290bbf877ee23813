"""The model specification output error fits: any model, linear or nonlinear, the user's own.

A model (:class:`Model`, or anything with the same attributes, :class:`ModelProtocol`) is

* ``states``, ``inputs``, ``outputs``: names. Fitted to a recording, inputs and outputs are
  canonical channels (``de``, ``alpha``, ``q``, ``az`` …) in the recording's units; fitted to
  plain arrays (:class:`ManeuverData`), any consistent units the model uses (SI included);
* ``parameters``: :class:`Parameter` (name, starting value, optional bounds);
* ``dynamics(t, x, u, theta, constants)`` → ẋ and ``observe(t, x, u, theta, constants)`` → y,
  the state and output equations ẋ = f(x, u, θ), y = h(x, u, θ) of the seed's Eq. 25;
* ``constants``: default values of the constants the equations read (geometry, mass, trim
  values); those of a recording (:func:`recording_constants`) take precedence.

Both functions are called **vectorised**: ``x`` has shape (n_x, K), ``u`` (n_u, K), ``t`` a
float or an array of K times, and ``theta`` maps each parameter name to an array of K values;
column k is one independent evaluation (the nominal model and its finite-difference
perturbations are integrated together). Written with NumPy element-wise operations
(``V, alpha, theta, q = x``; ``theta["CD0"] + theta["CDa"] * alpha``) a model is vectorised
without effort. Each returns a sequence of n_x (n_o) arrays or scalars, broadcast to K.

:func:`simulate` integrates the state equations by the classical fourth-order Runge-Kutta
rule with one step per sample interval, inputs held (``'zoh'``) or linear (``'foh'``)
between samples (Jategaonkar, *Flight Vehicle System Identification*, ch. 4).
"""
from __future__ import annotations

import math
import runpy
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Protocol, runtime_checkable

import numpy as np

from maneuvers.recording import Recording, RecordingError
from models.errors import UserError
from models.constants import G0_FPS2

__all__ = ["ManeuverData", "Model", "ModelDefinitionError", "ModelProtocol", "Parameter", "load_model_file",
           "maneuver_data", "recording_constants", "simulate"]


class ModelDefinitionError(UserError):
    """A model specification or model file that cannot be used; the message names the rule."""


@dataclass(frozen=True)
class Parameter:
    """One unknown parameter of a model.

    Attributes
    ----------
    name : str
    start : float
        Starting value of the estimation.
    lower, upper : float
        Bounds (default unbounded); the estimate is kept within them.
    scale : float or None
        Typical magnitude, sets the finite-difference step 1e-6·max(|θ|, scale)
        (default max(|start|, 1e-3)).
    """

    name: str
    start: float = 0.0
    lower: float = -math.inf
    upper: float = math.inf
    scale: float | None = None

    def __post_init__(self) -> None:
        if not self.name or not isinstance(self.name, str):
            raise ModelDefinitionError(f"a parameter needs a name, got {self.name!r}")
        for k in ("start", "lower", "upper"):
            object.__setattr__(self, k, float(getattr(self, k)))
        if not (self.lower <= self.start <= self.upper) or math.isnan(self.start):
            raise ModelDefinitionError(f"parameter {self.name}: start {self.start} is not within its bounds "
                                       f"[{self.lower}, {self.upper}]")

    @property
    def typical(self) -> float:
        return float(self.scale) if self.scale else max(abs(self.start), 1e-3)


@runtime_checkable
class ModelProtocol(Protocol):
    """What output error needs of a model (see the module docstring)."""

    name: str
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    @property
    def parameters(self) -> tuple[Parameter, ...]: ...

    def dynamics(self, t, x, u, theta, constants): ...

    def observe(self, t, x, u, theta, constants): ...


def _parameters(spec) -> tuple[Parameter, ...]:
    """Parameters from Parameter objects, or a mapping name → start or (start, lower, upper)."""
    if isinstance(spec, Mapping):
        out = []
        for name, v in spec.items():
            out.append(Parameter(name, *v) if isinstance(v, (tuple, list)) else Parameter(name, float(v)))
        return tuple(out)
    out = tuple(spec)
    if not all(isinstance(p, Parameter) for p in out):
        raise ModelDefinitionError("parameters must be Parameter objects or a mapping name -> start")
    return out


@dataclass(frozen=True)
class Model:
    """A model given by its state and output equations (Eq. 25), possibly nonlinear.

    Parameters
    ----------
    name : str
    states, inputs, outputs : tuple of str
        Names (channels of a recording, see the module docstring).
    parameters : tuple of Parameter, or mapping name → start or (start, lower, upper)
    dynamics : callable ``(t, x, u, theta, constants) -> sequence of n_x values`` (ẋ)
    observe : callable ``(t, x, u, theta, constants) -> sequence of n_o values`` (y)
    constants : mapping
        Defaults of the constants the equations read; a recording's own
        (:func:`recording_constants`) and those of :class:`ManeuverData` take precedence.
    bias_outputs : tuple of str
        Outputs that get a constant bias, estimated for each maneuver (``bias_<output>``).
    initial_state : mapping, optional
        Starting values of initial states that are not measured (others start from the first
        sample of the output of the same name; unmeasured ones default to 0).
    """

    name: str
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    parameters: tuple[Parameter, ...]
    dynamics: Callable
    observe: Callable
    constants: Mapping[str, float] = field(default_factory=dict)
    bias_outputs: tuple[str, ...] = ()
    initial_state: Mapping[str, float] | None = None

    def __post_init__(self) -> None:
        for k in ("states", "inputs", "outputs", "bias_outputs"):
            v = getattr(self, k)
            object.__setattr__(self, k, (v,) if isinstance(v, str) else tuple(v))
        object.__setattr__(self, "parameters", _parameters(self.parameters))
        object.__setattr__(self, "constants", MappingProxyType({k: float(v) for k, v in dict(self.constants).items()}))
        if not self.states or not self.outputs or not self.parameters:
            raise ModelDefinitionError(f"model {self.name!r} needs states, outputs and parameters")
        names = [p.name for p in self.parameters]
        for what, seq in (("state", self.states), ("input", self.inputs), ("output", self.outputs),
                          ("parameter", names)):
            dup = sorted({s for s in seq if list(seq).count(s) > 1})
            if dup:
                raise ModelDefinitionError(f"model {self.name!r}: {what} names repeat: {dup}")
        unknown = [b for b in self.bias_outputs if b not in self.outputs]
        if unknown:
            raise ModelDefinitionError(f"model {self.name!r}: bias_outputs {unknown} are not outputs {self.outputs}")
        if not (callable(self.dynamics) and callable(self.observe)):
            raise ModelDefinitionError(f"model {self.name!r}: dynamics and observe must be functions")

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)


@dataclass(frozen=True)
class ManeuverData:
    """One maneuver as plain arrays, for any model.

    Attributes
    ----------
    t : (N,) sample times, uniform step.
    u : (N, n_u) inputs in the model's input order (may have 0 columns).
    z : (N, n_o) measured outputs in the model's output order.
    constants : constants of this maneuver (override the model's defaults).
    x0 : initial state, optional: the starting value of its estimate, or the value used when
        initial states are not estimated.
    name : a label (used in per-maneuver parameter names).
    notes : remarks from the data assembly.
    """

    t: np.ndarray
    u: np.ndarray
    z: np.ndarray
    constants: Mapping[str, float] = field(default_factory=dict)
    x0: np.ndarray | None = None
    name: str = ""
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float).ravel()
        u = np.asarray(self.u, dtype=float).reshape(len(t), -1)
        z = np.asarray(self.z, dtype=float).reshape(len(t), -1)
        if len(t) < 8 or not (np.all(np.isfinite(u)) and np.all(np.isfinite(z)) and np.all(np.isfinite(t))):
            raise ValueError("output error needs at least 8 samples of finite data")
        step = np.diff(t)
        if step.mean() <= 0 or np.any(np.abs(step - step.mean()) > 1e-6 * step.mean()):
            raise ValueError("output error needs uniformly sampled data (increasing t, constant step)")
        x0 = None if self.x0 is None else np.asarray(self.x0, dtype=float).ravel()
        for k, v in (("t", t), ("u", u), ("z", z), ("x0", x0)):
            object.__setattr__(self, k, v)
        object.__setattr__(self, "constants", MappingProxyType({k: float(v) for k, v in dict(self.constants).items()}))

    @property
    def dt(self) -> float:
        return float((self.t[-1] - self.t[0]) / (len(self.t) - 1))


def check_data(model, data: ManeuverData) -> None:
    """Refuse data whose columns do not match the model's inputs and outputs."""
    if data.u.shape[1] != len(model.inputs) or data.z.shape[1] != len(model.outputs):
        raise ValueError(f"model {model.name!r} needs u with columns {tuple(model.inputs)} and z with columns "
                         f"{tuple(model.outputs)}; got {data.u.shape[1]} and {data.z.shape[1]} columns")
    if data.x0 is not None and len(data.x0) != len(model.states):
        raise ValueError(f"x0 needs {len(model.states)} values, one per state {tuple(model.states)}")


def recording_constants(rec: Recording) -> dict[str, float]:
    """Constants of a recording for a model's equations.

    ``S``, ``cbar``, ``b`` (ft, ft²), ``m`` (slug), ``Ix``, ``Iy``, ``Iz``, ``Ixz`` (slug·ft², the
    record means), ``g`` (ft/s²), the reference condition ``V0`` (ft/s), ``qbar0`` (psf),
    ``alpha0``, ``theta0`` (rad) (trim values, else record means), and every trim value of
    ``meta['trim']`` as ``trim_<key>`` (e.g. ``trim_de_rad``, ``trim_thrust_lbf``).
    """
    from estimators.output_error_models import flight_constants
    f = flight_constants(rec)
    out = {"S": f.S, "cbar": f.cbar, "b": f.b, "m": f.m, "Ix": f.Ix, "Iy": f.Iy, "Iz": f.Iz, "Ixz": f.Ixz,
           "g": G0_FPS2, "V0": f.V, "qbar0": f.qbar, "alpha0": f.alpha_o, "theta0": f.theta_o}
    trim = rec.meta.get("trim") if isinstance(rec.meta.get("trim"), dict) else {}
    out.update({f"trim_{k}": float(v) for k, v in trim.items() if isinstance(v, (int, float))})
    return out


def maneuver_data(rec: Recording, model) -> ManeuverData:
    """The model's inputs and outputs from a recording, by canonical channel name, as recorded
    (total values in the recording's units), with :func:`recording_constants`."""
    missing = [c for c in tuple(model.inputs) + tuple(model.outputs) if not rec.has(c)]
    if missing:
        raise RecordingError(f"recording {rec.name!r} has no channel {', '.join(missing)} that model "
                         f"{model.name!r} needs (inputs {tuple(model.inputs)}, outputs {tuple(model.outputs)})")
    u = np.column_stack([rec.channel(c) for c in model.inputs]) if model.inputs else np.zeros((rec.n, 0))
    z = np.column_stack([rec.channel(c) for c in model.outputs])
    return ManeuverData(t=rec.t, u=u, z=z, constants=recording_constants(rec), name=rec.name)


def load_model_file(path: str | Path):
    """Run a model file and return the ``model`` it defines.

    A model file is Python code, run as it is: load only files you trust.

    Raises
    ------
    FileNotFoundError
        No such file.
    ModelDefinitionError
        The file raises, defines no ``model``, or its ``model`` lacks what output error needs.
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"model file {str(path)!r} not found")
    try:
        namespace = runpy.run_path(str(p), run_name="sidbench_model")
    except Exception as exc:  # the user's code: report it in one line
        raise ModelDefinitionError(f"model file {p}: {type(exc).__name__}: {exc}") from exc
    model = namespace.get("model")
    if model is None:
        raise ModelDefinitionError(f"model file {p} defines no 'model' (a estimators.dynamic_models.Model)")
    if not isinstance(model, ModelProtocol):
        raise ModelDefinitionError(f"model file {p}: 'model' is a {type(model).__name__}, not a Model "
                                   "(needs states, inputs, outputs, parameters, dynamics, observe)")
    return model


# ---------------------------------------------------------------------------- evaluation
def _columns(fn: Callable, rows: int, what: str, model, t, x, u, theta: Mapping[str, np.ndarray],
             constants: Mapping[str, float], K: int) -> np.ndarray:
    """Call a model function on K columns and stack its result as (rows, K)."""
    out = fn(t, x, u, theta, constants)
    try:
        out = list(out)
    except TypeError:
        raise ModelDefinitionError(f"model {model.name!r}: {what} must return a sequence of {rows} values") from None
    if len(out) != rows:
        raise ModelDefinitionError(f"model {model.name!r}: {what} returned {len(out)} values, needs {rows}")
    try:  # fast path: every value already has K entries
        arr = np.array(out, dtype=float)
        if arr.shape == (rows, K):
            return arr
    except ValueError:
        pass
    try:
        return np.stack([np.broadcast_to(np.asarray(o, dtype=float), (K,)) for o in out])
    except ValueError as exc:
        raise ModelDefinitionError(f"model {model.name!r}: {what} values do not broadcast to {K} columns "
                                   f"(write it with element-wise NumPy operations): {exc}") from None


def simulate(model, data: ManeuverData, theta: np.ndarray, x0: np.ndarray, constants: Mapping[str, float],
             hold: str = "zoh") -> tuple[np.ndarray, np.ndarray]:
    """States and outputs of K parameter/initial-state columns at once.

    Classical Runge-Kutta, one step per sample interval h:
    x_{k+1} = x_k + h/6 (k₁ + 2k₂ + 2k₃ + k₄), k₁ = f(t_k, x_k, u_k),
    k₂ = f(t_k + h/2, x_k + h k₁/2, u_{k+½}), k₃ = f(t_k + h/2, x_k + h k₂/2, u_{k+½}),
    k₄ = f(t_k + h, x_k + h k₃, u_{k+1}), with u_{k+½} = u_{k+1} = u_k for a zero-order hold
    and the mid-point and end values of the linear interpolant for a first-order hold.

    Parameters
    ----------
    theta : (p, K) parameter columns, in ``model.parameters`` order.
    x0 : (n_x, K) initial-state columns.

    Returns
    -------
    x : (N, n_x, K), y : (N, n_o, K); non-finite where the response overflows.
    """
    names = tuple(p.name for p in model.parameters)
    K, n, N = theta.shape[1], len(model.states), len(data.t)
    th = dict(zip(names, theta))
    u = data.u
    h = data.dt
    X = np.empty((N, n, K))
    X[0] = x0
    x = X[0]
    f = model.dynamics
    ub = np.repeat(u[:, :, None], K, axis=2)  # (N, n_u, K): every column sees the same inputs
    umid = 0.5 * (ub[:-1] + ub[1:]) if hold == "foh" else ub
    with np.errstate(all="ignore"):
        for k in range(N - 1):
            tk = data.t[k]
            uk = ub[k]
            um, ue = (umid[k], ub[k + 1]) if hold == "foh" else (uk, uk)
            k1 = _columns(f, n, "dynamics", model, tk, x, uk, th, constants, K)
            k2 = _columns(f, n, "dynamics", model, tk + h / 2, x + (h / 2) * k1, um, th, constants, K)
            k3 = _columns(f, n, "dynamics", model, tk + h / 2, x + (h / 2) * k2, um, th, constants, K)
            k4 = _columns(f, n, "dynamics", model, tk + h, x + h * k3, ue, th, constants, K)
            x = X[k + 1] = x + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4)
            if not np.all(np.isfinite(x)):
                X[k + 1:] = np.nan
                break
        # the output equation for every sample and column in one call
        xs = X.transpose(1, 0, 2).reshape(n, N * K)
        us = np.repeat(u.T, K, axis=1)
        ts = np.repeat(data.t, K)
        ths = {k: np.tile(v, N) for k, v in th.items()}
        y = _columns(model.observe, len(model.outputs), "observe", model, ts, xs, us, ths, constants, N * K)
    return X, y.reshape(len(model.outputs), N, K).transpose(1, 0, 2)
