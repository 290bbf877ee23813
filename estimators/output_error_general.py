"""Output error for any model (:mod:`estimators.dynamic_models`), one or several maneuvers.

Maximum likelihood for measurement noise (seed Eqs. 25-29), by relaxation: with R fixed, a
Gauss-Newton (modified Newton-Raphson) step on

    J(θ, R) = ½ Σ_m Σ_i [z_mi − y_mi(θ)]ᵀ R⁻¹ [z_mi − y_mi(θ)] + (N/2) ln|R|,   N = Σ_m N_m,

    M = Σ S_iᵀ R⁻¹ S_i,  Δθ = M⁻¹ Σ S_iᵀ R⁻¹ (z_i − y_i),  S_i = ∂y_i/∂θ,

halved until the quadratic part decreases, then R from Eq. 29 (diagonal) with θ fixed, until
both settle. The maneuvers m share the model parameters and R (the likelihood of the
concatenated record); each has its own initial state x₀ₘ (estimated by default) and its own
constant bias on each output the model lists in ``bias_outputs``. The covariance is the
Cramér-Rao bound M⁻¹ at convergence.

Sensitivities are forward finite differences, vectorised: the nominal model and one copy per
parameter and initial state, each perturbed by h_j = 1e-6·max(|θ_j|, scale_j), are integrated
together (:func:`estimators.dynamic_models.simulate`), S_j = [y(θ + h_j e_j) − y(θ)]/h_j. Bias
sensitivities are exact (unit). Bounded parameters: a parameter at a bound whose step points
outward is held there for that step, and every trial is clipped into the bounds.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from estimators.dynamic_models import ManeuverData, check_data, simulate
from estimators.least_squares import r_squared
from estimators.result import ModelFit, collinearity

FD_STEP = 1e-6
X0_MODES = ("estimate", "fixed")


@dataclass(frozen=True)
class _Layout:
    """Where each parameter lives in the full vector: globals, then per maneuver x₀ and biases."""

    model: object
    maneuvers: int
    estimate_x0: bool

    @property
    def globals_(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.model.parameters)

    def suffix(self, m: int) -> str:
        return "" if self.maneuvers == 1 else f"#{m + 1}"

    def local_names(self, m: int) -> tuple[str, ...]:
        s = self.suffix(m)
        x0 = tuple(f"x0_{x}{s}" for x in self.model.states) if self.estimate_x0 else ()
        return x0 + tuple(f"bias_{o}{s}" for o in _bias_outputs(self.model))

    @property
    def names(self) -> tuple[str, ...]:
        out = self.globals_
        for m in range(self.maneuvers):
            out += self.local_names(m)
        return out

    def block(self, m: int) -> slice:
        n_local = len(self.local_names(0))
        start = len(self.globals_) + m * n_local
        return slice(start, start + n_local)


def _bias_outputs(model) -> tuple[str, ...]:
    """Outputs with a per-maneuver bias (``Model.bias_outputs``; none for other models)."""
    return tuple(getattr(model, "bias_outputs", ()) or ())


def _steps(layout: _Layout, theta: np.ndarray, typical: np.ndarray) -> np.ndarray:
    return FD_STEP * np.maximum(np.abs(theta), typical)


def _maneuver(layout: _Layout, data: ManeuverData, constants: Mapping[str, float], theta: np.ndarray,
              m: int, typical: np.ndarray, x0_fixed: np.ndarray | None, hold: str
              ) -> tuple[np.ndarray, np.ndarray]:
    """Outputs (N, n_o) and sensitivities (p_total, N, n_o) of maneuver m."""
    model = layout.model
    pg, n, no = len(layout.globals_), len(model.states), len(model.outputs)
    blk = theta[layout.block(m)]
    x0 = blk[:n] if layout.estimate_x0 else x0_fixed
    biases = blk[n:] if layout.estimate_x0 else blk
    n_x0 = n if layout.estimate_x0 else 0
    K = 1 + pg + n_x0
    hg = _steps(layout, theta[:pg], typical[:pg])
    th = np.repeat(theta[:pg, None], K, axis=1)
    th[np.arange(pg), 1 + np.arange(pg)] += hg
    X0 = np.repeat(x0[:, None], K, axis=1)
    s = layout.block(m).start
    hx = _steps(layout, x0, typical[s:s + n]) if n_x0 else np.zeros(0)
    X0[np.arange(n_x0), 1 + pg + np.arange(n_x0)] += hx
    _, Y = simulate(model, data, th, X0, constants, hold)
    bias = np.zeros(no)
    bias_idx = [model.outputs.index(b) for b in _bias_outputs(model)]
    bias[bias_idx] = biases
    y = Y[:, :, 0] + bias
    S = np.zeros((len(theta), len(data.t), no))
    d = (Y[:, :, 1:] - Y[:, :, :1]) / np.concatenate([hg, hx])
    S[:pg] = d[:, :, :pg].transpose(2, 0, 1)
    if n_x0:
        S[s:s + n] = d[:, :, pg:].transpose(2, 0, 1)
    for k, j in enumerate(bias_idx):
        S[s + n_x0 + k, :, j] = 1.0
    return y, S


def _start_x0(model, data: ManeuverData) -> np.ndarray:
    if data.x0 is not None:
        return data.x0.copy()
    init = dict(model.initial_state or {})
    out = []
    for s in model.states:
        if s in init:
            out.append(float(init[s]))
        elif s in model.outputs:
            out.append(float(data.z[0, model.outputs.index(s)]))
        else:
            out.append(0.0)
    return np.array(out)


def fit_model(model, datasets: Sequence[ManeuverData], *, start: Mapping[str, float] | None = None,
              x0: str = "estimate", hold: str = "zoh", max_iterations: int = 50, method: str = "oe") -> ModelFit:
    """Output error for ``model`` on one or several maneuvers (see the module docstring).

    Parameters
    ----------
    model : a :class:`~estimators.dynamic_models.Model` (or any :class:`ModelProtocol`).
    datasets : the maneuvers, :class:`ManeuverData` in the model's channel order.
    start : starting values by name (overriding the parameters' own starts; ``x0_<state>``,
        ``bias_<output>`` with ``#m`` for maneuver m when there are several).
    x0 : ``'estimate'`` each maneuver's initial state (from the first samples of the measured
        states), or ``'fixed'`` at ``ManeuverData.x0`` (else those first samples).

    Returns
    -------
    ModelFit
        ``names`` the model parameters, then each maneuver's ``x0_*`` and ``bias_*``; ``cov``
        the Cramér-Rao bound; residuals and fitted outputs stacked over the maneuvers;
        ``info`` as for the linear models plus ``maneuvers`` and ``sensitivities``.
    """
    from estimators.output_error import (COST_TOLERANCE, MAX_HALVINGS, NOISE_FLOOR, NOISE_TOLERANCE,
                                         STEP_TOLERANCE, DivergenceError, _check_information, _cost, _information,
                                         _inverse, _noise_covariance, _whitener)
    if x0 not in X0_MODES:
        raise ValueError(f"x0 must be one of {X0_MODES}, not {x0!r}")
    datasets = list(datasets)
    if not datasets:
        raise ValueError("output error needs at least one maneuver")
    for d in datasets:
        check_data(model, d)
    layout = _Layout(model, len(datasets), x0 == "estimate")
    names = layout.names
    consts = [{**dict(getattr(model, "constants", {}) or {}), **dict(d.constants)} for d in datasets]
    x0s = [_start_x0(model, d) for d in datasets]
    given = dict(start or {})
    unknown = sorted(set(given) - set(names))
    if unknown:
        raise ValueError(f"start has unknown parameters {unknown}; model {model.name!r} has {names}")
    theta = np.array([p.start for p in model.parameters] + [0.0] * (len(names) - len(layout.globals_)))
    lower = np.array([p.lower for p in model.parameters] + [-np.inf] * (len(names) - len(layout.globals_)))
    upper = np.array([p.upper for p in model.parameters] + [np.inf] * (len(names) - len(layout.globals_)))
    typical = np.array([p.typical for p in model.parameters] + [1e-3] * (len(names) - len(layout.globals_)))
    n = len(model.states)
    for m in range(len(datasets)):
        s = layout.block(m).start
        if layout.estimate_x0:
            theta[s:s + n] = x0s[m]
            typical[s:s + n] = np.maximum(np.abs(x0s[m]), 1e-3)
    for k, v in given.items():
        theta[names.index(k)] = float(v)
    theta = np.clip(theta, lower, upper)
    # biases not given: the mean output error at the start (exact: the outputs are affine in them)
    for m, d in enumerate(datasets if _bias_outputs(model) else ()):
        y, _ = _maneuver(layout, d, consts[m], theta, m, typical, x0s[m], hold)
        blk = layout.local_names(m)
        for b, o in zip(blk[n if layout.estimate_x0 else 0:], _bias_outputs(model)):
            if b not in given:
                j = model.outputs.index(o)
                theta[names.index(b)] += float(np.mean(d.z[:, j] - y[:, j]))

    z = np.vstack([d.z for d in datasets])
    floor = NOISE_FLOOR * np.maximum(np.var(z, axis=0), 1e-300)

    def evaluate(th: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ys, Ss = zip(*(_maneuver(layout, d, consts[m], th, m, typical, x0s[m], hold)
                       for m, d in enumerate(datasets)))
        return np.vstack(ys), np.concatenate(Ss, axis=1)

    y, S = evaluate(theta)
    if not np.all(np.isfinite(y)):
        raise DivergenceError(f"model {model.name!r} does not give finite outputs at the starting values: "
                              "give starts nearer a model that stays bounded over the record")
    R = _noise_covariance(z - y, floor)
    J = _cost(z - y, R)
    history, converged, iterations, change_R = [J], False, 0, np.inf
    for iterations in range(1, max_iterations + 1):
        v = z - y
        M, grad = _information(S, v, R)
        d = _check_information(M, names)
        step = np.linalg.solve(M / np.outer(d, d), grad / d) / d
        held = ((theta <= lower) & (step < 0)) | ((theta >= upper) & (step > 0))
        if held.any():
            free = ~held
            step = np.zeros_like(step)
            Mf = M[np.ix_(free, free)]
            df = d[free]
            step[free] = np.linalg.solve(Mf / np.outer(df, df), grad[free] / df) / df
        se = np.sqrt(np.diag(_inverse(M, d)))
        if np.max(np.abs(step) / se) < STEP_TOLERANCE and change_R < NOISE_TOLERANCE:
            converged = True  # the next step would move no estimate by a thousandth of its error bound
            break
        quadratic = 0.5 * float(np.sum((v @ _whitener(R)) ** 2))
        lam, accepted = 1.0, None
        for _ in range(MAX_HALVINGS):
            trial = np.clip(theta + lam * step, lower, upper)
            y_t, S_t = evaluate(trial)
            if np.all(np.isfinite(y_t)) and 0.5 * np.sum(((z - y_t) @ _whitener(R)) ** 2) <= quadratic:
                accepted = trial
                break
            lam /= 2
        if accepted is None:
            if np.max(np.abs(step) / se) < STEP_TOLERANCE:
                converged = True
                break
            raise DivergenceError(
                f"output error diverged at iteration {iterations}: no step along the Gauss-Newton direction "
                f"reduces the cost (after {MAX_HALVINGS} halvings); start nearer the optimum")
        R_new = _noise_covariance(z - y_t, floor)
        J_new = _cost(z - y_t, R_new)
        history.append(J_new)
        change_R = float(np.max(np.abs(np.diag(R_new) - np.diag(R)) / np.diag(R)))
        change_J = abs(J_new - J) / max(abs(J), 1.0)
        moved = np.max(np.abs(accepted - theta) / se)
        theta, R, J, y, S = accepted, R_new, J_new, y_t, S_t
        if change_J < COST_TOLERANCE and moved < STEP_TOLERANCE and change_R < NOISE_TOLERANCE:
            converged = True
            break
    v = z - y
    M, _ = _information(S, v, R)
    cov = _inverse(M, _check_information(M, names))
    is_bias = np.array([k.startswith(("bias", "x0_")) for k in names])
    coll = collinearity((S @ _whitener(R)).reshape(len(S), -1).T, names, cov, is_bias)
    r2 = {o: r_squared(z[:, i], v[:, i]) for i, o in enumerate(model.outputs)}
    warnings = list(coll.warnings(parameters=True))
    at_bound = [k for k, t, lo, hi in zip(names, theta, lower, upper) if t <= lo or t >= hi]
    if at_bound:
        warnings.append(f"parameters at a bound: {', '.join(at_bound)} (their Cramér-Rao bounds assume "
                        "they are free)")
    if not converged:
        warnings.append(f"output error did not converge in {iterations} iterations")
    info = {"R": R.tolist(), "cost": history[-1], "cost_history": history, "iterations": iterations,
            "converged": converged, "r2": r2, "outputs": list(model.outputs), "model": model.name,
            "hold": hold, "start_source": "given" if given else "model", "maneuvers": len(datasets),
            "samples": [len(d.t) for d in datasets], "sensitivities": "finite-difference",
            "x0": x0, "notes": [n for d in datasets for n in d.notes]}
    return ModelFit(method=method, domain="time", dependent=",".join(model.outputs), names=names, params=theta,
                    cov=cov, residuals=v, fitted=y, n=len(z), s2=float(np.sum((v @ _whitener(R)) ** 2)) / v.size,
                    r2=float(np.mean(list(r2.values()))), errors="cramer-rao", collinearity=coll,
                    warnings=tuple(warnings), info=info)
