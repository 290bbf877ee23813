"""Filter error for the linear models: output error with process noise (turbulence), a Kalman
filter in the likelihood (Jategaonkar, *Flight Vehicle System Identification*, ch. 5; Maine &
Iliff, NASA RP-1168), in the natural formulation: the filter comes from the noise covariances.

With process noise w and measurement noise v,

    x_{k+1} = Φ x_k + Γ ū_k + w_k,   z_k = C x_k + D̄ ū_k + v_k,
    w_k ~ N(0, Q), Q = diag(Q_<state>),   v_k ~ N(0, R), R = diag(R_<output>)       (FE-1)

(the exact discrete form of the model, ū the inputs with a constant 1 for the biases), the
model outputs of output error are no longer the expected measurements; the one-step
predictions of the steady-state Kalman filter are:

    x̂_{k+1} = Φ x̂_k + Γ ū_k + K ν_k,   ν_k = z_k − C x̂_k − D̄ ū_k,                 (FE-2)
    P = Φ P Φᵀ + Q − Φ P Cᵀ S⁻¹ C P Φᵀ,   S = C P Cᵀ + R,   K = Φ P Cᵀ S⁻¹,

P the stabilising solution of the discrete algebraic Riccati equation (solved by the
structure-preserving doubling algorithm: matrix products only), so the predictor
Φ − KC is stable by construction. The innovations are independent, N(0, S), and

    J(θ, Q, R) = ½ Σ_k ν_kᵀ S⁻¹ ν_k + (N/2) ln|S|                                    (FE-3)

is minimised over the model parameters θ and the noise variances together by Fisher scoring
(Gauss-Newton for a Gaussian likelihood whose covariance depends on the parameters):

    M_ij = Σ_k ∂ν_kᵀ/∂p_i S⁻¹ ∂ν_k/∂p_j + (N/2) tr(S⁻¹ ∂S/∂p_i S⁻¹ ∂S/∂p_j),
    ∂J/∂p_i = Σ_k ν_kᵀ S⁻¹ ∂ν_k/∂p_i + ½ tr(S⁻¹ ∂S/∂p_i S⁻¹ (N S − Σ_k ν_k ν_kᵀ)),

with a backtracking line search on J and Q_<state> ≥ 0 held as bounds (a variance at 0 is
fixed there while its gradient points outwards, and left out of the covariance). The
sensitivities are exact. Differentiating the Riccati equation in its Joseph form at the
optimal gain (the terms in ∂K cancel) gives a Stein equation for every parameter,

    ∂P = Φ̄ ∂P Φ̄ᵀ + (∂Φ − K ∂C) P Φ̄ᵀ + Φ̄ P (∂Φ − K ∂C)ᵀ + K ∂R Kᵀ + ∂Q,   Φ̄ = Φ − KC,

solved for all parameters at once (Kronecker form, n² unknowns), then
∂S = ∂C P Cᵀ + C ∂P Cᵀ + C P ∂Cᵀ + ∂R and ∂K = (∂Φ P Cᵀ + Φ ∂P Cᵀ + Φ P ∂Cᵀ − K ∂S) S⁻¹;
(FE-2) is x̂_{k+1} = Φ̄ x̂_k + (Γ − K D̄) ū_k + K z_k, so ∂x̂_{k+1}/∂p_j = Φ̄ ∂x̂_k/∂p_j + ∂Φ̄_j x̂_k
+ ∂(Γ − K D̄)_j ū_k + ∂K_j z_k, one scan for every parameter. Q = 0 is output error (K = 0);
the fit starts there, from output error's estimates and its R. The covariance is the
Cramér-Rao bound M⁻¹.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from estimators.output_error_models import OutputErrorData, _per_parameter, affine_system, resolve_data
from estimators.regressors import DataOptions, Equation
from estimators.result import ModelFit, collinearity
from estimators.state_space import discretize, discretize_derivatives, expm_small, propagate, scan
from maneuvers.recording import Recording


def kalman_predictor(Phi: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray, *, tol: float = 1e-13,
                     max_doublings: int = 60) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steady-state one-step predictor of (FE-1): P, K and S of (FE-2).

    The stabilising solution of P = ΦPΦᵀ + Q − ΦPCᵀ(CPCᵀ + R)⁻¹CPΦᵀ by the structure-preserving
    doubling algorithm (A₀ = Φᵀ, G₀ = CᵀR⁻¹C, H₀ = Q; A_{k+1} = A_k(I + G_kH_k)⁻¹A_k,
    G_{k+1} = G_k + A_k(I + G_kH_k)⁻¹G_kA_kᵀ, H_{k+1} = H_k + A_kᵀH_k(I + G_kH_k)⁻¹A_k → P),
    quadratically convergent, matrix products and n×n solves only.

    Raises
    ------
    np.linalg.LinAlgError
        If the doubling does not converge (no stabilising solution).
    """
    n = len(Phi)
    eye = np.eye(n)
    A, G, H = Phi.T.copy(), C.T @ np.linalg.solve(R, C), Q.copy()
    for _ in range(max_doublings):
        W = eye + G @ H
        WA, WG = np.linalg.solve(W, A), np.linalg.solve(W, G)
        H_new = H + A.T @ H @ WA
        G, A = G + A @ WG @ A.T, A @ WA
        done = np.max(np.abs(H_new - H)) <= tol * max(np.max(np.abs(H_new)), 1e-300)
        H = H_new
        if done or not np.any(A):
            break
    else:
        raise np.linalg.LinAlgError("the Riccati equation of the Kalman filter has no stabilising solution")
    if not np.all(np.isfinite(H)):
        raise np.linalg.LinAlgError("the Riccati equation of the Kalman filter has no stabilising solution")
    P = (H + H.T) / 2
    S = C @ P @ C.T + R
    K = Phi @ P @ C.T @ np.linalg.inv(S)
    return P, K, S


def kalman_predictor_derivatives(Phi, C, P, K, S, dPhi, dC, dQ, dR):
    """∂P, ∂K, ∂S of :func:`kalman_predictor` in the directions (∂Φ_j, ∂C_j, ∂Q_j, ∂R_j),
    stacked (p, ·, ·): the Stein equation of the module docstring, for all j at once."""
    n = len(Phi)
    Fb = Phi - K @ C
    E = dPhi - K @ dC
    EPF = E @ P @ Fb.T
    rhs = EPF + EPF.transpose(0, 2, 1) + K @ dR @ K.T + dQ
    dP = np.linalg.solve(np.eye(n * n) - np.kron(Fb, Fb), rhs.reshape(len(rhs), n * n).T).T.reshape(-1, n, n)
    dP = (dP + dP.transpose(0, 2, 1)) / 2
    PC = P @ C.T
    dCPC = dC @ PC
    dS = dCPC + dCPC.transpose(0, 2, 1) + C @ dP @ C.T + dR
    dK = (dPhi @ PC + Phi @ dP @ C.T + Phi @ P @ dC.transpose(0, 2, 1) - K @ dS) @ np.linalg.inv(S)
    return dP, dK, dS


def _predictor(Phi, Gam, C, D, K, u1, z):
    """One-step predictions x̂ (N, n) and innovations ν (N, n_o) of (FE-2), x̂_0 = 0."""
    F, G = Phi - K @ C, Gam - K @ D
    x = propagate(F, u1[:-1] @ G.T + z[:-1] @ K.T, np.zeros(len(Phi)))
    return x, z - x @ C.T - u1 @ D.T, F


@dataclass(frozen=True)
class FilterError:
    """Filter error (output error with process noise) for the built-in linear models.

    Parameters
    ----------
    model : ``'short-period'``, ``'lateral'`` or None (chosen from the equation).
    process_noise : the states whose equations carry process noise (``Q_<state>`` estimated);
        None: every state.
    start : starting values by name (default: output error's estimates and R, Q = 0).
    """

    model: str | None = None
    data: DataOptions = field(default_factory=DataOptions)
    process_noise: tuple[str, ...] | None = None
    start: Mapping[str, float] | None = None
    max_iterations: int = 50
    method: str = "fe"

    def fit(self, source: Recording | OutputErrorData, equation: Equation | None = None) -> ModelFit:
        """Estimate θ and the noise variances; ``cov`` the Cramér-Rao bound of (FE-3)."""
        from estimators.output_error import (COST_TOLERANCE, STEP_TOLERANCE, DivergenceError, OutputError,
                                             _check_information, _inverse)
        data = resolve_data(source, None if isinstance(source, OutputErrorData) else self.model, equation, self.data)
        spec = data.spec
        oe = OutputError(model=spec.name, data=self.data).fit(data if isinstance(source, OutputErrorData) else source,
                                                            equation)
        noisy = spec.states if self.process_noise is None else tuple(self.process_noise)
        unknown = [s for s in noisy if s not in spec.states]
        if unknown or not noisy:
            raise ValueError(f"process_noise must name states of the {spec.name} model {spec.states}, not {noisy}")
        system = affine_system(spec, data.flight)
        n, no, pt = len(spec.states), len(spec.outputs), len(spec.names)
        nq = len(noisy)
        q_names = tuple(f"Q_{s}" for s in noisy)
        r_names = tuple(f"R_{o}" for o in spec.outputs)
        names = spec.names + q_names + r_names
        p = len(names)
        z, dt = data.z, data.dt
        N = len(z)
        R0 = np.diag(np.asarray(oe.info["R"], float)) if np.ndim(oe.info["R"]) == 2 else np.asarray(oe.info["R"], float)
        theta = np.concatenate([oe.params, np.zeros(nq), R0])
        for k, v in dict(self.start or {}).items():
            if k not in names:
                raise ValueError(f"start has unknown parameter {k!r}; filter error has {names}")
            theta[names.index(k)] = float(v)
        u1 = np.column_stack([data.u, np.ones(N)])
        dA, dB, dC, dD = system.partials
        # Directions of every parameter in Φ's continuous form (A, B), C, D̄, Q and R.
        zeros = lambda *s: np.zeros((p - pt, *s))  # noqa: E731
        dA_all, dB_all = np.concatenate([dA, zeros(n, n)]), np.concatenate([dB, zeros(*dB.shape[1:])])
        dC_all, dD_all = np.concatenate([dC, zeros(no, n)]), np.concatenate([dD, zeros(*dD.shape[1:])])
        dR_all = np.zeros((p, no, no))
        for j in range(no):
            dR_all[pt + nq + j, j, j] = 1.0
        q_slice, r_slice = slice(pt, pt + nq), slice(pt + nq, p)
        state_rows = [spec.states.index(s) for s in noisy]
        moves_A = [j for j in range(pt) if np.any(dA[j])]
        steps = np.array([1e-6 / (np.max(np.abs(dA[j])) * dt) for j in moves_A])

        def noise_basis(A):
            """V_i = ∫₀^dt e^{As} e_i e_iᵀ e^{Aᵀs} ds for each noisy state i (Q_d = Σ Q_i V_i), for
            A (n, n) or a stack of them."""
            A = np.asarray(A)
            stack = A.reshape(-1, n, n)
            big = np.zeros((len(stack), nq, 2 * n, 2 * n))
            big[:, :, :n, :n] = -stack[:, None] * dt
            big[:, :, n:, n:] = stack.transpose(0, 2, 1)[:, None] * dt
            for j, i in enumerate(state_rows):
                big[:, j, i, n + i] = dt
            E = expm_small(big)
            Phi_T = E[:, :, n:, n:]
            V = np.swapaxes(Phi_T, -1, -2) @ E[:, :, :n, n:]
            V = (V + np.swapaxes(V, -1, -2)) / 2
            return V.reshape(*A.shape[:-2], nq, n, n)

        def filter_of(th):
            A, B, C, D = system.matrices(th[:pt])
            Phi, Gam, _ = discretize(A, B, dt)
            Q = np.tensordot(th[q_slice], noise_basis(A), axes=1)
            P, K, S = kalman_predictor(Phi, C, Q, np.diag(th[r_slice]))
            return A, B, C, D, Phi, Gam, P, K, S

        def cost_of(nu, S):
            L = np.linalg.cholesky(np.linalg.inv(S))
            return 0.5 * float(np.sum((nu @ L) ** 2)) + 0.5 * N * float(np.linalg.slogdet(S)[1])

        def evaluate(th, sens=True):
            A, B, C, D, Phi, Gam, P, K, S = filter_of(th)
            x, nu, F = _predictor(Phi, Gam, C, D, K, u1, z)
            if not sens:
                return nu, S, F, None, None
            dPhi, dGam, _ = discretize_derivatives(A, B, dA_all, dB_all, dt)
            # Q_d is linear in the Q_i (exact) and depends on A (central differences, one stacked call)
            dQ_all = np.zeros((p, n, n))
            dQ_all[q_slice] = noise_basis(A)
            if moves_A:
                h = steps[:, None, None] * dA[moves_A]
                Vpm = noise_basis(np.stack([A + h, A - h]))
                dQ_all[moves_A] = np.tensordot(Vpm[0] - Vpm[1], th[q_slice], axes=([1], [0])) / (2 * steps[:, None, None])
            _, dK, dS = kalman_predictor_derivatives(Phi, C, P, K, S, dPhi, dC_all, dQ_all, dR_all)
            dF = dPhi - dK @ C - K @ dC_all
            dG = dGam - dK @ D - K @ dD_all
            e = np.zeros((p, N, n))
            e[:, 1:] = _per_parameter(np.column_stack([x[:-1], u1[:-1], z[:-1]]), np.concatenate([dF, dG, dK], axis=2))
            dx = scan(F, e)
            dnu = -((dx.reshape(-1, n) @ C.T).reshape(p, N, no)
                    + _per_parameter(np.column_stack([x, u1]), np.concatenate([dC_all, dD_all], axis=2)))
            return nu, S, F, dnu, dS

        def scoring(nu, S, dnu, dS):
            """Fisher information M and gradient ∂J/∂p of (FE-3)."""
            Si = np.linalg.inv(S)
            L = np.linalg.cholesky(Si)
            W = (dnu @ L).reshape(p, -1)
            SdS = Si @ dS  # (p, no, no)
            M = W @ W.T + 0.5 * N * np.einsum("iab,jba->ij", SdS, SdS)
            Res = N * S - nu.T @ nu
            grad = W @ (nu @ L).ravel() + 0.5 * np.einsum("iab,bc,ca->i", SdS, Si, Res)
            return M, grad

        try:
            nu, S, F, dnu, dS = evaluate(theta)
        except np.linalg.LinAlgError as exc:
            raise DivergenceError(f"filter error: no steady-state Kalman filter at the start ({exc})") from exc
        J, history, converged, it = cost_of(nu, S), [], False, 0
        history.append(J)
        is_q = np.zeros(p, bool)
        is_q[q_slice] = True
        free = np.ones(p, bool)
        for it in range(1, self.max_iterations + 1):
            M, grad = scoring(nu, S, dnu, dS)
            # Variances at their bound 0 stay there while the likelihood would have them negative.
            free = ~(is_q & (theta <= 0.0) & (grad >= 0.0))
            Mf = M[np.ix_(free, free)]
            fnames = tuple(k for k, f in zip(names, free) if f)
            d = _check_information(Mf, fnames)
            Minv = _inverse(Mf, d)
            step = np.zeros(p)
            step[free] = -Minv @ grad[free]
            se = np.zeros(p)
            se[free] = np.sqrt(np.diag(Minv))
            lam, ok = 1.0, False
            for _ in range(20):
                trial = theta + lam * step
                trial[is_q] = np.maximum(trial[is_q], 0.0)
                if np.all(trial[r_slice] > 0.0):
                    try:
                        nu_t, S_t, _, _, _ = evaluate(trial, sens=False)
                        if np.all(np.isfinite(nu_t)) and cost_of(nu_t, S_t) <= J:
                            ok = True
                            break
                    except np.linalg.LinAlgError:
                        pass
                lam /= 2
            moved = np.abs(trial - theta)[free] / se[free]
            if not ok:
                if np.max(np.abs(step[free]) / se[free]) < 0.05:  # at the optimum to rounding
                    converged = True
                    break
                if it > 1:
                    break  # reported as not converged
                raise DivergenceError(f"filter error diverged at iteration {it}: no step reduces the cost "
                                      f"(step {np.max(np.abs(step[free]) / se[free]):.3g} standard errors)")
            theta = trial
            nu, S, F, dnu, dS = evaluate(theta)
            J_new = cost_of(nu, S)
            history.append(J_new)
            change = abs(J_new - J) / max(abs(J), 1.0)
            J = J_new
            if change < COST_TOLERANCE and np.max(moved) < STEP_TOLERANCE:
                converged = True
                break
        M, grad = scoring(nu, S, dnu, dS)
        free = ~(is_q & (theta <= 0.0) & (grad >= 0.0))
        # The bound of every parameter, a variance held at 0 included: fixing it there would
        # claim the noise structure is known (too small bounds for the derivatives it couples to).
        cov = _inverse(M, _check_information(M, names))
        is_noise = np.array([k.startswith(("bias", "Q_", "R_")) for k in names])
        coll = collinearity(dnu.reshape(p, -1).T, names, cov, is_noise)
        warnings = [f"parameters {a} and {b} are highly correlated (|r| = {r:.3f} > 0.9, seed Eq. 50)"
                    for a, b, r in coll.flagged]
        at_bound = [k for k, f in zip(names, free) if not f]
        if not converged:
            warnings.append(f"filter error did not converge in {it} iterations")
        r2 = {o: 1 - float(np.sum(nu[:, i] ** 2) / np.sum((z[:, i] - z[:, i].mean()) ** 2))
              for i, o in enumerate(spec.outputs)}
        K = filter_of(theta)[7]
        info = {"S": S.tolist(), "K": K.tolist(), "Q": dict(zip(noisy, theta[q_slice].tolist())),
                "R": theta[r_slice].tolist(), "at_bound": at_bound, "cost": J, "gradient": grad.tolist(), "cost_history": history,
                "iterations": it, "converged": converged, "r2": r2, "outputs": list(spec.outputs),
                "model": spec.name, "flight": data.flight.as_dict(), "oe_cost": oe.info["cost"],
                "notes": list(data.notes), "spectral_radius": float(np.max(np.abs(np.linalg.eigvals(F))))}
        L = np.linalg.cholesky(np.linalg.inv(S))
        return ModelFit(method=self.method, domain="time", dependent=",".join(spec.outputs), names=names,
                        params=theta, cov=cov, residuals=nu, fitted=z - nu, n=N,
                        s2=float(np.sum((nu @ L) ** 2)) / nu.size, r2=float(np.mean(list(r2.values()))),
                        errors="cramer-rao", collinearity=coll, warnings=tuple(warnings), info=info)
