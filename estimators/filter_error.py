"""Filter error for the linear models: output error with process noise (turbulence), a Kalman
filter in the likelihood (Jategaonkar, *Flight Vehicle System Identification*, ch. 5; Maine &
Iliff, NASA RP-1168).

With process noise w and measurement noise v,

    x_{k+1} = Φ x_k + Γ ū_k + w_k,   z_k = C x_k + D̄ ū_k + v_k

(the exact discrete form of the model, ū the inputs with a constant 1 for the biases), the
model outputs of output error are no longer the expected measurements; the one-step
predictions of the steady-state Kalman filter are. In its innovation form

    x̂_{k+1} = Φ x̂_k + Γ ū_k + K ν_k,   ν_k = z_k − C x̂_k − D̄ ū_k                (FE-1)

the innovations ν_k are independent, N(0, S), and the negative log-likelihood is that of
the seed's Eq. 26 with ν for z − y and S for R:

    J(θ, K, S) = ½ Σ_k ν_kᵀ S⁻¹ ν_k + (N/2) ln|S|.                                 (FE-2)

The gain K (``K_<state>_<output>``) is estimated with the model parameters θ (the innovation
formulation: K and S directly, rather than the process-noise matrix F and R, which give the
same likelihood), by the relaxation of output error: with S fixed, a Gauss-Newton step on
(θ, K), M = Σ (∂ν/∂θ)ᵀ S⁻¹ (∂ν/∂θ); then S = Σ ν νᵀ/N (full: process noise correlates the
innovations). The sensitivities are exact: (FE-1) is x̂_{k+1} = F x̂_k + (Γ − K D̄) ū_k + K z_k
with F = Φ − K C, so ∂x̂_{k+1}/∂θ_j = F ∂x̂_k/∂θ_j + F_j x̂_k + G_j ū_k + K_j z_k (F_j, G_j from
the exact derivatives of Φ and Γ), one scan for every parameter. Steps that make the filter
unstable (spectral radius of F ≥ 1) are halved. K = 0 is output error; the fit starts there,
from output error's estimates. The covariance is the Cramér-Rao bound M⁻¹.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from estimators.output_error_models import OutputErrorData, affine_system, check_equation, model_spec, output_error_data
from estimators.regressors import DataOptions, Equation
from estimators.result import ModelFit, collinearity
from estimators.state_space import discretize, discretize_derivatives, propagate, scan
from maneuvers.recording import Recording

RHO_CAP = 0.999  # largest spectral radius of the predictor F = Φ − KC a step aims at


def _predictor(Phi, Gam, C, D, K, u1, z):
    """One-step predictions x̂ (N, n) and innovations ν (N, n_o) of (FE-1), x̂_0 = 0."""
    F, G = Phi - K @ C, Gam - K @ D
    x = propagate(F, u1[:-1] @ G.T + z[:-1] @ K.T, np.zeros(len(Phi)))
    return x, z - x @ C.T - u1 @ D.T, F


@dataclass(frozen=True)
class FilterError:
    """Filter error (output error with process noise) for the built-in linear models.

    Parameters
    ----------
    model : ``'short-period'``, ``'lateral'`` or None (chosen from the equation).
    start : starting values by name (default: output error's estimates, K = 0).
    """

    model: str | None = None
    data: DataOptions = field(default_factory=DataOptions)
    start: Mapping[str, float] | None = None
    max_iterations: int = 50
    method: str = "fe"

    def fit(self, source: Recording | OutputErrorData, equation: Equation | None = None) -> ModelFit:
        """Estimate θ and the gain K; ``cov`` the Cramér-Rao bound of (FE-2)."""
        from estimators.output_error import (COST_TOLERANCE, STEP_TOLERANCE, DivergenceError, OutputError,
                                             _check_information, _inverse)
        if isinstance(source, OutputErrorData):
            data = source
            check_equation(model_spec(data.model), equation if equation is not None and equation.regressors else None)
        else:
            name = model_spec(self.model, equation).name
            check_equation(model_spec(name), equation)
            data = output_error_data(source, name, self.data)
        spec = data.spec
        oe = OutputError(model=spec.name, data=self.data).fit(data if isinstance(source, OutputErrorData) else source,
                                                            equation)
        system = affine_system(spec, data.flight)
        n, no, pt = len(spec.states), len(spec.outputs), len(spec.names)
        gain_names = tuple(f"K_{s}_{o}" for s in spec.states for o in spec.outputs)
        names = spec.names + gain_names
        theta = np.concatenate([oe.params, np.zeros(n * no)])
        for k, v in dict(self.start or {}).items():
            if k not in names:
                raise ValueError(f"start has unknown parameter {k!r}; filter error has {names}")
            theta[names.index(k)] = float(v)
        z, dt = data.z, data.dt
        u1 = np.column_stack([data.u, np.ones(len(z))])
        dA, dB, dC, dD = system.partials
        eye = np.eye(n * no).reshape(n * no, n, no)

        def evaluate(th, sens=True):
            A, B, C, D = system.matrices(th[:pt])
            K = th[pt:].reshape(n, no)
            Phi, Gam, _ = discretize(A, B, dt)
            x, nu, F = _predictor(Phi, Gam, C, D, K, u1, z)
            if not sens:
                return nu, F, None, None
            dPhi, dGam, _ = discretize_derivatives(A, B, dA, dB, dt)
            dF = np.concatenate([dPhi - K @ dC, -eye @ C])
            dG = np.concatenate([dGam - K @ dD, -eye @ D])
            dK = np.concatenate([np.zeros((pt, n, no)), eye])
            e = np.zeros((len(th), len(z), n))
            e[:, 1:] = (np.einsum("pij,kj->pki", dF, x[:-1]) + np.einsum("pij,kj->pki", dG, u1[:-1])
                        + np.einsum("pij,kj->pki", dK, z[:-1]))
            dx = scan(F, e)
            dC_all = np.concatenate([dC, np.zeros((n * no, no, n))])
            dD_all = np.concatenate([dD, np.zeros((n * no, no, u1.shape[1]))])
            dnu = -(dx @ C.T + np.einsum("pij,kj->pki", dC_all, x) + np.einsum("pij,kj->pki", dD_all, u1))
            return nu, F, dnu, dF

        def radius_gradient(F, dF):
            """Spectral radius of F and its gradient over the parameters (first-order eigenvalue
            perturbation of the dominant eigenvalue: dλ = wᴴ dF v / wᴴ v)."""
            lam, V = np.linalg.eig(F)
            i = int(np.argmax(np.abs(lam)))
            W = np.linalg.inv(V)  # rows: left eigenvectors, scaled so that wᴴ v = 1
            dlam = np.einsum("i,pij,j->p", W[i], dF, V[:, i])
            return float(abs(lam[i])), np.real(np.conj(lam[i]) * dlam) / abs(lam[i])

        def stable(F):
            return bool(np.max(np.abs(np.linalg.eigvals(F))) < 1.0)

        def cost(nu, S):
            L = np.linalg.cholesky(np.linalg.inv(S))
            return 0.5 * float(np.sum((nu @ L) ** 2)) + 0.5 * len(nu) * float(np.linalg.slogdet(S)[1])

        def information(dnu, nu, S):
            L = np.linalg.cholesky(np.linalg.inv(S))
            W = (dnu @ L).reshape(len(dnu), -1)
            return W @ W.T, -W @ (nu @ L).ravel()

        nu, F, dnu, dF = evaluate(theta)
        S = nu.T @ nu / len(nu)
        J, history, converged, it, constrained = cost(nu, S), [], False, 0, False
        history.append(J)
        for it in range(1, self.max_iterations + 1):
            M, grad = information(dnu, nu, S)
            d = _check_information(M, names)
            Minv = _inverse(M, d)
            step = Minv @ grad  # grad = −Σ ∂νᵀS⁻¹ν
            se = np.sqrt(np.diag(Minv))
            # The likelihood of a finite record often keeps falling as the predictor's slowest
            # mode crosses the unit circle (the spectral factor's zero sits close to z = 1 when
            # an output combination carries little low-frequency noise): an unconstrained step
            # would leave the stable region, and halving it only creeps up to the boundary. The
            # step is then the Gauss-Newton step constrained to keep ρ(F) at RHO_CAP to first
            # order (an active set: min ½ΔᵀMΔ − gᵀΔ subject to ∇ρᵀΔ = RHO_CAP − ρ).
            rho, g_rho = radius_gradient(F, dF)
            constrained = bool(rho + g_rho @ step > RHO_CAP)
            if constrained:
                c = min(0.0, RHO_CAP - rho)
                Mg = Minv @ g_rho
                step = step - Mg * ((g_rho @ step - c) / (g_rho @ Mg))
            L = np.linalg.cholesky(np.linalg.inv(S))
            quad = 0.5 * float(np.sum((nu @ L) ** 2))
            lam, ok = 1.0, False
            for _ in range(12):
                trial = theta + lam * step
                nu_t, F_t, _, _ = evaluate(trial, sens=False)
                if stable(F_t) and np.all(np.isfinite(nu_t)) and (
                        0.5 * np.sum((nu_t @ L) ** 2) <= quad or (constrained and rho > RHO_CAP and lam == 1.0)):
                    ok = True
                    break
                lam /= 2
            if not ok:
                if np.max(np.abs(step) / se) < 0.05:  # at the optimum to rounding (the cost sums N terms)
                    converged = True
                    break
                if it > 1:
                    break  # reported as not converged
                raise DivergenceError(f"filter error diverged at iteration {it}: no step reduces the cost "
                                      f"(step {np.max(np.abs(step) / se):.3g} standard errors)")
            theta = trial
            nu, F, dnu, dF = evaluate(theta)
            S_new = nu.T @ nu / len(nu)
            J_new = cost(nu, S_new)
            history.append(J_new)
            change = abs(J_new - J) / max(abs(J), 1.0)
            dS = float(np.max(np.abs(np.diag(S_new) - np.diag(S)) / np.diag(S)))
            S, J = S_new, J_new
            if change < COST_TOLERANCE and np.max(np.abs(lam * step) / se) < STEP_TOLERANCE and dS < 1e-4:
                converged = True
                break
        M, _ = information(dnu, nu, S)
        cov = _inverse(M, _check_information(M, names))
        is_bias = np.array([k.startswith(("bias", "K_")) for k in names])
        coll = collinearity(dnu.reshape(len(dnu), -1).T, names, cov, is_bias)
        warnings = [f"parameters {a} and {b} are highly correlated (|r| = {r:.3f} > 0.9, seed Eq. 50)"
                    for a, b, r in coll.flagged]
        if not converged:
            warnings.append(f"filter error did not converge in {it} iterations")
        r2 = {o: 1 - float(np.sum(nu[:, i] ** 2) / np.sum((z[:, i] - z[:, i].mean()) ** 2))
              for i, o in enumerate(spec.outputs)}
        info = {"S": S.tolist(), "cost": J, "cost_history": history, "iterations": it, "converged": converged,
                "r2": r2, "outputs": list(spec.outputs), "model": spec.name, "flight": data.flight.as_dict(),
                "oe_cost": oe.info["cost"], "notes": list(data.notes),
                "spectral_radius": float(np.max(np.abs(np.linalg.eigvals(F)))), "stability_constrained": constrained}
        L = np.linalg.cholesky(np.linalg.inv(S))
        return ModelFit(method=self.method, domain="time", dependent=",".join(spec.outputs), names=names,
                        params=theta, cov=cov, residuals=nu, fitted=z - nu, n=len(z),
                        s2=float(np.sum((nu @ L) ** 2)) / nu.size, r2=float(np.mean(list(r2.values()))),
                        errors="cramer-rao", collinearity=coll, warnings=tuple(warnings), info=info)
