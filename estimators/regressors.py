"""From a recording to an equation-error problem: the dependent variable and named regressors.

A regressor is a term of base quantities joined by ``*``, each optionally raised to a power
with ``^``: ``alpha``, ``qhat``, ``alpha^2``, ``alpha*beta``, ``alphadot_hat``, ``dV``.
Base quantities are perturbations from a reference (seed Eqs. 35-36), so products and powers
follow ``../shared/effects.md`` (``(α − α_trim)·β``):

- any channel of the recording (``alpha``, ``beta``, ``de``, ``V``, ``theta``, ``ay`` ...);
- ``phat``, ``qhat``, ``rhat``: pb/2V, qc̄/2V, rb/2V (the recording's own channel if it has one,
  as SIDPAC files do; otherwise formed with the instantaneous airspeed);
- ``alphadot_hat``, ``betadot_hat``: α̇c̄/2V and β̇b/2V, differentiated from α, β;
- ``dV``: (V − V_ref)/V_ref; ``pdot``, ``qdot``, ``rdot``: angular accelerations;
- ``<surface>dot`` (``dedot``, ``dadot``, ``drdot``): surface rates.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from estimators.coefficients import coefficient_from_recording, thrust_assumption, thrust_source
from estimators.differentiation import smooth_derivative
from maneuvers.recording import Recording, RecordingError
from models.errors import UserError
from models.constants import COEFFICIENTS

ACCELERATION_METHODS = ("auto", "recorded", "smooth-local", "smooth-fourier", "local-smooth")
REFERENCES = ("trim", "first", "none")
_SEED_METHOD = {"smooth-local": 1, "smooth-fourier": 2, "local-smooth": 3}
_TERM = re.compile(r"^([A-Za-z][A-Za-z0-9_]*?)(?:\^([0-9]+))?$")


class EquationError(UserError):
    """A model equation that cannot be built from the recording (unknown term, missing channel)."""


@dataclass(frozen=True)
class Equation:
    """One equation-error model: ``dependent = Σ θ_j · regressor_j (+ bias)``.

    Parameter names are ``<dependent>_<regressor>`` (``Cm_alpha``) and ``bias``.
    """

    dependent: str
    regressors: tuple[str, ...]
    bias: bool = True

    def __post_init__(self) -> None:
        if not self.regressors and not self.bias:
            raise EquationError("an equation needs at least one regressor or a bias term")
        if len(set(self.regressors)) != len(self.regressors):
            raise EquationError(f"regressors repeat: {self.regressors}")

    @classmethod
    def parse(cls, dependent: str, regressors: str, bias: bool = True) -> "Equation":
        """From command-line text: ``Equation.parse('Cm', 'alpha,qhat,de')``."""
        terms = tuple(t.strip() for t in regressors.split(",") if t.strip())
        return cls(dependent.strip(), terms, bias)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f"{self.dependent}_{r}" for r in self.regressors) + (("bias",) if self.bias else ())

    def describe(self) -> str:
        rhs = " + ".join(self.names)
        return f"{self.dependent} = {rhs}"


@dataclass(frozen=True)
class DataOptions:
    """How a recording becomes z and X.

    angular_acceleration : ``'auto'`` uses recorded pdot/qdot/rdot when present, else the
        seed's method 1; ``'recorded'``; ``'smooth-local'`` (method 1: optimal Fourier smoother
        then local polynomial derivative), ``'smooth-fourier'`` (method 2), ``'local-smooth'``
        (method 3).
    reference : perturbations from ``'trim'`` (the recording's ``meta['trim']``; where it
        has no value, such as imported flight data, the raw measured value is used, as in
        SIDPAC's own regressions, and a note says so), from the ``'first'`` sample, or
        ``'none'`` (raw values, so the bias includes the steady parts, Eq. 36).
    dependent_source : ``'auto'`` takes the recording's own coefficient channel when it has
        one (SIDPAC files carry CX ... Cn) and otherwise Eqs. 1-5; ``'computed'`` always uses
        Eqs. 1-5; ``'channel'`` requires the channel.
    """

    angular_acceleration: str = "auto"
    reference: str = "trim"
    dependent_source: str = "auto"

    def __post_init__(self) -> None:
        if self.angular_acceleration not in ACCELERATION_METHODS:
            raise ValueError(f"angular_acceleration must be one of {ACCELERATION_METHODS}")
        if self.reference not in REFERENCES:
            raise ValueError(f"reference must be one of {REFERENCES}")
        if self.dependent_source not in ("auto", "computed", "channel"):
            raise ValueError("dependent_source must be 'auto', 'computed' or 'channel'")


@dataclass(frozen=True)
class RegressionData:
    """z and X of one equation, sampled uniformly in time.

    ``X`` holds the regressors only (N × p); the bias column is added by the estimators that
    use one. ``t`` is the sample time, ``dt`` its step. ``notes`` become the fit's warnings;
    ``assumptions`` say what building z assumed where the recording was silent (thrust).
    """

    equation: Equation
    z: np.ndarray
    X: np.ndarray
    t: np.ndarray
    dt: float
    notes: tuple[str, ...] = ()
    assumptions: tuple[str, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return self.equation.names

    def design(self) -> np.ndarray:
        """X with the bias column appended when the equation has one."""
        return np.column_stack([self.X, np.ones(len(self.z))]) if self.equation.bias else self.X

    @classmethod
    def from_arrays(cls, z, X, regressors: tuple[str, ...], dt: float, *, dependent: str = "z",
                    bias: bool = True) -> "RegressionData":
        """Wrap plain arrays (any source) as an equation-error problem."""
        z = np.asarray(z, dtype=float)
        X = np.asarray(X, dtype=float).reshape(len(z), -1)
        if X.shape[1] != len(regressors):
            raise EquationError(f"X has {X.shape[1]} columns but {len(regressors)} regressor names")
        return cls(Equation(dependent, tuple(regressors), bias), z, X, np.arange(len(z)) * dt, dt)


def _differentiate(x: np.ndarray, dt: float, method: str) -> np.ndarray:
    return smooth_derivative(x, dt, method=_SEED_METHOD[method if method in _SEED_METHOD else "smooth-local"])


class _Builder:
    """Evaluates base quantities and terms of one recording (with caching per call)."""

    def __init__(self, rec: Recording, options: DataOptions) -> None:
        self.rec, self.opt = rec, options
        self.notes: list[str] = []
        self.assumptions: list[str] = []
        self.untrimmed: list[str] = []
        self.cache: dict[str, np.ndarray] = {}
        trim = rec.meta.get("trim", {}) if options.reference == "trim" else {}
        self.trim = trim

    def reference(self, name: str, x: np.ndarray) -> float:
        if self.opt.reference == "none":
            return 0.0
        if name in ("p", "q", "r", "phat", "qhat", "rhat", "pdot", "qdot", "rdot",
                    "alphadot_hat", "betadot_hat", "dedot", "dadot", "drdot", "dV"):
            return 0.0 if self.opt.reference == "trim" else float(x[0])
        if self.opt.reference == "trim":
            for key in (f"{name}_rad", f"{name}_fps", f"{name}_ft", f"{name}_psf", name):
                if key in self.trim:
                    return float(self.trim[key])
            if name not in self.untrimmed:
                self.untrimmed.append(name)
            return 0.0
        return float(x[0])

    def base(self, name: str) -> np.ndarray:
        if name in self.cache:
            return self.cache[name]
        rec, g = self.rec, self.rec.geometry
        if name in ("phat", "qhat", "rhat") and rec.has(name):
            x = rec.channel(name)
        elif name in ("phat", "qhat", "rhat"):
            length = g["cbar_ft"] if name == "qhat" else g["b_ft"]
            x = rec.channel(name[0]) * length / (2 * rec.channel("V"))
        elif name in ("pdot", "qdot", "rdot"):
            x = self.angular_acceleration(name[0])
        elif name in ("alphadot_hat", "betadot_hat"):
            ang = name.split("dot")[0]
            length = g["cbar_ft"] if ang == "alpha" else g["b_ft"]
            x = _differentiate(rec.channel(ang), rec.dt, self.opt.angular_acceleration) * length / (2 * rec.channel("V"))
        elif name in ("dedot", "dadot", "drdot"):
            x = _differentiate(rec.channel(name[:2]), rec.dt, self.opt.angular_acceleration)
        elif name == "dV":
            V = rec.channel("V")
            ref = self.reference("V", V)
            return self.cache.setdefault(name, (V - ref) / ref)
        elif rec.has(name):
            x = rec.channel(name)
        else:
            raise EquationError(f"unknown regressor term {name!r}: the recording has no such channel "
                                f"and it is not a derived quantity (phat, qhat, rhat, alphadot_hat, "
                                f"betadot_hat, dV, pdot, qdot, rdot, dedot, dadot, drdot)")
        return self.cache.setdefault(name, x - self.reference(name, x))

    def term(self, text: str) -> np.ndarray:
        out = None
        for factor in text.split("*"):
            m = _TERM.match(factor.strip())
            if not m:
                raise EquationError(f"cannot read regressor term {text!r} (use names, '*' and '^k')")
            x = self.base(m.group(1)) ** int(m.group(2) or 1)  # a new array (1.0 * x is x exactly)
            out = x if out is None else out * x
        return out

    def angular_acceleration(self, axis: str) -> np.ndarray:
        rec, method = self.rec, self.opt.angular_acceleration
        if method == "recorded" or (method == "auto" and rec.has(f"{axis}dot")):
            return rec.channel(f"{axis}dot")
        return _differentiate(rec.channel(axis), rec.dt, method)

    def dependent(self, name: str) -> np.ndarray:
        rec, src = self.rec, self.opt.dependent_source
        if src != "computed" and rec.has(name):
            return rec.channel(name)
        if src == "channel":
            raise EquationError(f"the recording has no {name!r} channel")
        if name not in COEFFICIENTS:
            raise EquationError(f"unknown dependent variable {name!r}: use one of {COEFFICIENTS} "
                                "or a channel of the recording")
        method = self.opt.angular_acceleration
        if method == "auto":
            diff = None if all(rec.has(f"{a}dot") for a in "pqr") else (lambda x, dt: _differentiate(x, dt, "smooth-local"))
        elif method == "recorded":
            diff = None
        else:
            diff = lambda x, dt: _differentiate(x, dt, method)  # noqa: E731
        assumed = thrust_assumption(rec, name)
        self.assumptions += assumed
        if assumed and thrust_source(rec)[1] == "unknown":
            self.notes.append(f"{name} computed with zero thrust: the recording has neither a thrust channel "
                              "nor a trim thrust (see assumptions)")
        return coefficient_from_recording(rec, name, diff)


def regression_data(rec: Recording, equation: Equation, options: DataOptions = DataOptions()) -> RegressionData:
    """Assemble z and X of ``equation`` from ``rec``.

    Raises
    ------
    EquationError
        Naming an unknown regressor term or dependent variable.
    RecordingError
        When a channel the equation needs is missing.
    """
    b = _Builder(rec, options)
    try:
        z = b.dependent(equation.dependent)
        cols = [b.term(r) for r in equation.regressors]
    except RecordingError as exc:
        raise EquationError(f"{equation.describe()}: {exc}") from exc
    X = np.column_stack(cols) if cols else np.empty((rec.n, 0))
    notes = list(b.notes)
    if b.untrimmed:
        notes.append(f"no trim values for {', '.join(b.untrimmed)}: used as measured, so the bias "
                     "includes their steady parts (Eq. 36)")
    return RegressionData(equation, np.asarray(z, dtype=float), X, rec.t, rec.dt, tuple(notes),
                          tuple(b.assumptions))
