"""Output error in the frequency domain for the linear models (Klein & Morelli, *Aircraft System
Identification*, ch. 7; the seed's Eqs. 25-29 with transformed data).

The sampled model x_{i+1} = Φ x_i + Γ u_i, y_i = C x_i + D u_i (inputs held between samples,
the exact discrete form of Eq. 33 that time-domain output error simulates,
:func:`estimators.state_space.discretize`) is transformed with the finite Fourier sum
X(ω) = Δt Σ_{i=0}^{N−1} x_i e^{−jωt_i} (:func:`estimators.fourier.plain_dft`). At the
harmonics ω_k = 2πk/(NΔt) of the record, with z_k = e^{jω_kΔt}, this is exact:

    z_k (X_k + Δt Δx) = Φ X_k + Γ U_k,   Δx = x_N − x_0,
    Y_k(θ) = C G_k (Γ U_k − z_k Δt Δx) + D U_k,   G_k = (z_k I − Φ)⁻¹.           (FD-1)

On the harmonics a constant sums to zero, so output biases and trim values drop out; Δx
(``dx_<state>``, the change of state over the record) is estimated with the derivatives, so
records need not end where they began. The frequencies are the harmonics in the seed's band
(2/T to 1.2 Hz by default); the transformed white noise is independent from harmonic to
harmonic, of variance S_jj = E|V_kj|² = NΔt²σ_j².

Why not the high-accuracy transform (:func:`estimators.fourier.finite_fourier_transform`)
with the continuous model? It integrates the samples' cubic interpolant, which misrepresents
held (step) inputs and the steps they put in outputs with feed-through (a_z): on the seed's
2-1-1-2 short period that biased C_mq̂ and C_mδe by ≈2.5 standard errors and the ±2σ coverage
fell to 0.70 (50 realizations). The sampled model's own transform is exact for held inputs.

Maximum likelihood for complex Gaussian residuals v_k = Z_k − Y_k, by relaxation: with S
fixed, Gauss-Newton on J = Σ_k v_kᴴ S⁻¹ v_k + m ln|S|,

    M = 2 Re Σ_k J_kᴴ S⁻¹ J_k,  Δθ = M⁻¹ 2 Re Σ_k J_kᴴ S⁻¹ v_k,  J_k = ∂Y_k/∂θ,     (FD-2)

then S = diag(Σ_k |v_k|²/m) (the frequency-domain Eq. 29). The sensitivities are exact:
∂X_k/∂θ_j = G_k (Φ_j X_k + Γ_j U_k) with Φ_j, Γ_j the exact derivatives of the discrete
matrices (:func:`estimators.state_space.discretize_derivatives`), ∂Y_k/∂θ_j = C ∂X_k/∂θ_j +
C_j X_k + D_j U_k. The Cramér-Rao bound is M⁻¹ (FD-2) at convergence: the factor 2 is the
information of a real parameter in a circular complex residual, E[(Re Jᴴv)²] = ½ JᴴSJ.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from estimators.fourier import RIGID_BODY_UPPER_HZ, plain_dft
from estimators.output_error_models import OutputErrorData, affine_system, resolve_data
from estimators.regressors import DataOptions, Equation
from estimators.result import ModelFit, collinearity
from estimators.state_space import discretize, discretize_derivatives
from maneuvers.recording import Recording


def harmonic_frequencies(duration_s: float, upper_hz: float = RIGID_BODY_UPPER_HZ) -> np.ndarray:
    """The harmonics k/T from 2/T (the seed's lower bound) up to ``upper_hz``, Hz (T = NΔt)."""
    T = float(duration_s)
    k = np.arange(2, int(np.floor(upper_hz * T + 1e-9)) + 1)
    if len(k) < 2:
        raise ValueError(f"a {T:.3g} s record has fewer than two harmonics between 2/T and {upper_hz:g} Hz")
    return k / T


def _model_outputs(Phi, Gam, C, D, U: np.ndarray, dx: np.ndarray, zk: np.ndarray, dt: float):
    """G_k, X_k and Y_k of (FD-1) for every frequency at once."""
    n = len(Phi)
    G = np.linalg.inv(zk[:, None, None] * np.eye(n) - Phi)
    X = np.einsum("kij,kj->ki", G, U @ Gam.T - (zk * dt)[:, None] * dx)
    return G, X, X @ C.T + U @ D.T


@dataclass(frozen=True)
class FrequencyOutputError:
    """Frequency-domain output error for the built-in linear models (see the module docstring).

    Parameters
    ----------
    model : ``'short-period'``, ``'lateral'`` or None (chosen from the equation as
        :class:`estimators.output_error.OutputError` does).
    upper_hz : top of the band (default 1.2 Hz, the seed's rigid-body bound).
    frequencies_hz : explicit frequencies instead (best the harmonics k/T).
    start : starting derivatives by name (default: equation error, as for time-domain OE).
    """

    model: str | None = None
    data: DataOptions = field(default_factory=DataOptions)
    upper_hz: float = RIGID_BODY_UPPER_HZ
    frequencies_hz: tuple[float, ...] | None = None
    start: Mapping[str, float] | None = None
    max_iterations: int = 50
    method: str = "oe-freq"

    def fit(self, source: Recording | OutputErrorData, equation: Equation | None = None) -> ModelFit:
        """Estimate the model's derivatives and the end-state changes Δx; ``cov`` the Cramér-Rao bound."""
        from estimators.output_error import (COST_TOLERANCE, STEP_TOLERANCE, OutputError, _check_information,
                                             _inverse, _Problem)
        data = resolve_data(source, None if isinstance(source, OutputErrorData) else self.model, equation, self.data)
        spec = data.spec
        nd, n, nu = len(spec.derivatives), len(spec.states), len(spec.inputs)
        system = affine_system(spec, data.flight)
        (A0, B0, C0, D0), (dA, dB, dC, dD) = system.base, system.partials
        B0, D0, dA, dB, dC, dD = B0[:, :nu], D0[:, :nu], dA[:nd], dB[:nd, :, :nu], dC[:nd], dD[:nd, :, :nu]
        dt = data.dt
        T = len(data.t) * dt
        f = (np.asarray(self.frequencies_hz, float) if self.frequencies_hz is not None
             else harmonic_frequencies(T, self.upper_hz))
        w = 2 * np.pi * f
        zk = np.exp(1j * w * dt)
        Z = plain_dft(data.z, dt, f)
        U = plain_dft(data.u, dt, f)
        # starting derivatives: as time-domain output error starts (equation error)
        oe = OutputError(model=spec.name, data=self.data, start=self.start)
        if self.start is not None and all(d in self.start for d in spec.derivatives):
            start = dict(self.start)
        else:
            from estimators.output_error import _equation_error_start, _state_equation_start
            start = (_equation_error_start(source, spec, self.data) if isinstance(source, Recording)
                     else _state_equation_start(_Problem(system, data, oe.hold)))
            start.update(dict(self.start or {}))
        names = spec.derivatives + tuple(f"dx_{s}" for s in spec.states)
        theta = np.concatenate([[start[d] for d in spec.derivatives], np.zeros(n)])

        def evaluate(th):
            d = th[:nd]
            A = A0 + np.tensordot(d, dA, 1)
            B = B0 + np.tensordot(d, dB, 1)
            C = C0 + np.tensordot(d, dC, 1)
            D = D0 + np.tensordot(d, dD, 1)
            Phi, Gam, _ = discretize(A, B, dt)
            dPhi, dGam, _ = discretize_derivatives(A, B, dA, dB, dt)
            G, X, Y = _model_outputs(Phi, Gam, C, D, U, th[nd:], zk, dt)
            J = np.empty((nd + n, len(w), len(spec.outputs)), dtype=complex)
            dX = np.einsum("kij,pkj->pki", G, np.einsum("pij,kj->pki", dPhi, X) + np.einsum("pij,kj->pki", dGam, U))
            J[:nd] = dX @ C.T + np.einsum("pij,kj->pki", dC, X) + np.einsum("pij,kj->pki", dD, U)
            J[nd:] = -np.einsum("ij,kjl->lki", C, G) * (zk * dt)[None, :, None]  # ∂Y/∂Δx_l = −C G z Δt e_l
            return Y, J

        def information(J, v, Sinv):
            Jw = J * np.sqrt(Sinv)
            Jr = np.concatenate([Jw.real, Jw.imag], axis=1).reshape(len(J), -1)
            vw = v * np.sqrt(Sinv)
            vr = np.concatenate([vw.real, vw.imag]).ravel()
            return 2 * Jr @ Jr.T, 2 * Jr @ vr

        def cost(v, S):
            return float(np.sum(np.abs(v) ** 2 / S) + len(v) * np.sum(np.log(S)))

        floor = 1e-12 * np.maximum(np.mean(np.abs(Z) ** 2, axis=0), 1e-300)
        Y, J = evaluate(theta)
        S = np.maximum(np.mean(np.abs(Z - Y) ** 2, axis=0), floor)
        cost_J, history, converged, it = cost(Z - Y, S), [], False, 0
        history.append(cost_J)
        for it in range(1, self.max_iterations + 1):
            v = Z - Y
            M, grad = information(J, v, 1 / S)
            d = _check_information(M, names)
            step = np.linalg.solve(M / np.outer(d, d), grad / d) / d
            se = np.sqrt(np.diag(_inverse(M, d)))
            quad = float(np.sum(np.abs(v) ** 2 / S))
            lam, ok = 1.0, False
            for _ in range(12):
                Y_t, J_t = evaluate(theta + lam * step)
                if np.all(np.isfinite(Y_t)) and np.sum(np.abs(Z - Y_t) ** 2 / S) <= quad:
                    ok = True
                    break
                lam /= 2
            if not ok:
                converged = bool(np.max(np.abs(step) / se) < STEP_TOLERANCE)
                break
            theta = theta + lam * step
            Y, J = Y_t, J_t
            S_new = np.maximum(np.mean(np.abs(Z - Y) ** 2, axis=0), floor)
            new = cost(Z - Y, S_new)
            history.append(new)
            change = abs(new - cost_J) / max(abs(cost_J), 1.0)
            dS = float(np.max(np.abs(S_new - S) / S))
            S, cost_J = S_new, new
            if change < COST_TOLERANCE and np.max(np.abs(lam * step) / se) < STEP_TOLERANCE and dS < 1e-4:
                converged = True
                break
        v = Z - Y
        M, _ = information(J, v, 1 / S)
        cov = _inverse(M, _check_information(M, names))
        is_bias = np.array([k.startswith("dx_") for k in names])
        coll = collinearity(np.concatenate([J.real, J.imag], axis=1).reshape(len(J), -1).T, names, cov, is_bias)
        warnings = list(coll.warnings(parameters=True))
        if not converged:
            warnings.append(f"frequency-domain output error did not converge in {it} iterations")
        r2 = 1 - float(np.sum(np.abs(v) ** 2) / np.sum(np.abs(Z - Z.mean(axis=0)) ** 2))
        info = {"S": S.tolist(), "cost": cost_J, "cost_history": history, "iterations": it, "converged": converged,
                "frequencies_hz": f.tolist(), "outputs": list(spec.outputs), "model": spec.name,
                "flight": data.flight.as_dict(), "notes": list(data.notes)}
        return ModelFit(method=self.method, domain="frequency", dependent=",".join(spec.outputs), names=names,
                        params=theta, cov=cov, residuals=v, fitted=Y, n=len(w),
                        s2=float(np.sum(np.abs(v) ** 2 / S)) / v.size, r2=r2, errors="cramer-rao",
                        collinearity=coll, warnings=tuple(warnings), info=info)
