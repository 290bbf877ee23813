"""Filter error for the linear models: output error with process noise (turbulence), a Kalman
filter in the likelihood (Jategaonkar, *Flight Vehicle System Identification*, ch. 5; Maine &
Iliff, NASA RP-1168), in the natural formulation: the filter comes from the noise covariances.

With process noise w and measurement noise v,

    x_{k+1} = Φ x_k + Γ ū_k + w_k,   z_k = C x_k + D̄ ū_k + v_k,
    w_k ~ N(0, Q),   v_k ~ N(0, R), R = diag(R_<output>)                              (FE-1)

(the exact discrete form of the model, ū the inputs with a constant 1 for the biases), the
model outputs of output error are no longer the expected measurements. Q, discretised exactly
with the model (Van Loan's integral, :func:`noise_basis`), comes from any of

* white process noise on a state's equation, spectral density ``Q_<state>`` ≥ 0;
* a first-order (Dryden) gust state disturbing one state, (FE-4) of :func:`gust_augmented`,
  with its standard deviation σ and time constant τ estimated as ``ln_sigma_gust`` and
  ``ln_tau_gust`` (logarithms: positive without a bound, so they cannot stick at 0) — for the
  vertical gust as an α disturbance this is exactly the turbulence of ``harness.linear_flight``;
* the noise δ ~ N(0, Σ) of a measured input: the system is driven by u = u_m − δ, so δ enters
  the states through −Γ_u δ_k and the outputs through −D_u δ_k, correlated in the same sample,
  E[w_k v_kᵀ] = S_c = Γ_u Σ D_uᵀ, Q += Γ_u Σ Γ_uᵀ, R += D_u Σ D_uᵀ (FE-5); Σ is taken from the
  input record itself (FE-6, :func:`input_noise_std`) or given.

The one-step predictions of the steady-state Kalman filter are (for S_c ≠ 0,
:func:`correlated_predictor`: K = (ΦPCᵀ + S_c)S⁻¹):

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

with a backtracking line search on J and the bounds held (Q_<state> ≥ 0; a parameter at a
bound is fixed there while its gradient points outwards, and kept in the covariance). The
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


def correlated_predictor(Phi: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray, Sc: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P, K and S of the one-step predictor when the process and measurement noise of the same
    sample are correlated, E[w_k v_kᵀ] = S_c (FE-5: noise on a measured input enters both):

        K = (Φ P Cᵀ + S_c) S⁻¹,   S = C P Cᵀ + R,   P = Φ P Φᵀ + Q − K S Kᵀ.

    This is the uncorrelated problem of :func:`kalman_predictor` for Φ̃ = Φ − S_c R⁻¹ C and
    Q̃ = Q − S_c R⁻¹ S_cᵀ (the Schur complement of the joint covariance, ≥ 0), whose gain K̃
    gives K = K̃ + S_c R⁻¹ (Anderson & Moore, *Optimal Filtering*, §5.5).
    """
    Phi_t, Q_t, SRi = _decorrelated(Phi, C, Q, R, Sc)
    P, K_t, S = kalman_predictor(Phi_t, C, Q_t, R)
    return P, K_t + SRi, S


def _decorrelated(Phi, C, Q, R, Sc):
    SRi = Sc @ np.linalg.inv(R)
    Q_t = Q - SRi @ Sc.T
    return Phi - SRi @ C, (Q_t + Q_t.T) / 2, SRi


def correlated_predictor_derivatives(Phi, C, Q, R, Sc, P, K, S, dPhi, dC, dQ, dR, dSc):
    """∂P, ∂K, ∂S of :func:`correlated_predictor` in the directions (∂Φ_j, ∂C_j, ∂Q_j, ∂R_j,
    ∂S_c,j), stacked (p, ·, ·): the chain rule through Φ̃, Q̃ and K = K̃ + S_c R⁻¹ (FE-5) into
    :func:`kalman_predictor_derivatives`."""
    Ri = np.linalg.inv(R)
    SRi = Sc @ Ri
    dSRi = dSc @ Ri - SRi @ dR @ Ri  # ∂(S_c R⁻¹)
    dPhi_t = dPhi - dSRi @ C - SRi @ dC
    dQ_t = dQ - dSRi @ Sc.T - SRi @ dSc.transpose(0, 2, 1)
    dP, dK_t, dS = kalman_predictor_derivatives(Phi - SRi @ C, C, P, K - SRi, S, dPhi_t, dC, dQ_t, dR)
    return dP, dK_t + dSRi, dS


def _predictor(Phi, Gam, C, D, K, u1, z):
    """One-step predictions x̂ (N, n) and innovations ν (N, n_o) of (FE-2), x̂_0 = 0."""
    F, G = Phi - K @ C, Gam - K @ D
    x = propagate(F, u1[:-1] @ G.T + z[:-1] @ K.T, np.zeros(len(Phi)))
    return x, z - x @ C.T - u1 @ D.T, F


GUST_DEFAULT = {"short-period": "alpha", "lateral": None}
"""The state a gust disturbs by default, per built-in model (:class:`FilterError`'s ``gust``):
the short period's α (the vertical gust, the turbulence campaign's study); none for the
lateral model (no lateral-gust study: white process noise on every state)."""

INPUT_NOISE_DEFAULT = {"short-period": ("de",), "lateral": ()}
"""The inputs whose measurement noise :class:`FilterError` takes into account by default
(``input_noise``): the short period's stabilator (the turbulence campaign's study: its 0.05°
position noise alone takes the gust model's Cm coverage from 0.93–0.98 to 0.68–0.85); none for
the lateral model (not studied)."""

MAD_TO_SIGMA = 0.6744897501960817  # median |N(0, 1)|
GUST_FLOOR = 1e-4
"""The gust's smallest standard deviation, as a fraction of output error's residual standard
deviation of the disturbed state: there the gust is "none" (held, and reported so)."""


def input_noise_std(u: np.ndarray) -> np.ndarray:
    """Standard deviation of white noise on a measured input, from the record itself (FE-6):

        σ̂ = median_k |u_{k+1} − 2u_k + u_{k−1}| / (0.6745 √6),

    second differences of white noise having variance 6σ², those of a smooth or piecewise-
    constant input (steps, doublets, sweeps well below the Nyquist frequency) almost nothing;
    the few samples next to a step are outliers the median ignores.

    Parameters
    ----------
    u : (N,) or (N, m) input samples.

    Returns
    -------
    (m,) standard deviations (0 for a noise-free piecewise-constant input).
    """
    d2 = np.diff(np.asarray(u, float).reshape(len(u), -1), n=2, axis=0)
    return np.median(np.abs(d2), axis=0) / (MAD_TO_SIGMA * np.sqrt(6.0))


def gust_augmented(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, state: int,
                   tau: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The model with a first-order gust state appended, (FE-4).

    The gust angle x_g (α_g = w_g/V for the vertical gust) is first-order Dryden-shaped noise,
    ẋ_g = −x_g/τ + n; the model's state ``state`` is the aerodynamic angle (what the forces,
    the moments and the vane see), the kinematic angle less the gust, so its equation gains
    −ẋ_g = x_g/τ − n:

        [ẋ; ẋ_g] = [[A, e_s/τ], [0, −1/τ]] [x; x_g] + [B; 0] u + [−e_s; 1] n,   y = [C 0] x + D u.

    Parameters
    ----------
    A, B, C, D : the model's matrices (n states).
    state : index of the disturbed state.
    tau : the gust's time constant τ, s (JSBSim's and MIL-F-8785C's first-order form: L_w/(2V)).

    Returns
    -------
    The augmented (A, B, C, D), n + 1 states.
    """
    n = len(A)
    Aa = np.zeros((n + 1, n + 1))
    Aa[:n, :n] = A
    Aa[state, n], Aa[n, n] = 1.0 / tau, -1.0 / tau
    return Aa, np.vstack([B, np.zeros((1, B.shape[1]))]), np.hstack([C, np.zeros((len(C), 1))]), D


def noise_inputs(n: int, white: tuple[int, ...], gust: int | None) -> np.ndarray:
    """Columns g_i through which each independent white noise enters the (augmented) state
    equations: e_i for white process noise on state i; [−e_s; 1] for the gust's (FE-4)."""
    cols = [np.eye(n)[i] for i in white]
    if gust is not None:
        g = np.zeros(n)
        g[gust], g[-1] = -1.0, 1.0
        cols.append(g)
    return np.array(cols).reshape(-1, n).T


def noise_basis(A: np.ndarray, G: np.ndarray, dt: float) -> np.ndarray:
    """V_i = ∫₀^dt e^{As} g_i g_iᵀ e^{Aᵀs} ds for every column g_i of G (Van Loan, 1978), so that
    the discrete process-noise covariance is Q_d = Σ_i q_i V_i for spectral densities q_i;
    for A (n, n) or a stack (..., n, n); returns (..., k, n, n)."""
    A = np.asarray(A)
    n, k = G.shape
    stack = A.reshape(-1, n, n)
    big = np.zeros((len(stack), k, 2 * n, 2 * n))
    big[:, :, :n, :n] = -stack[:, None] * dt
    big[:, :, n:, n:] = stack.transpose(0, 2, 1)[:, None] * dt
    big[:, :, :n, n:] = np.einsum("ai,bi->iab", G, G) * dt
    E = expm_small(big)
    V = np.swapaxes(E[:, :, n:, n:], -1, -2) @ E[:, :, :n, n:]
    V = (V + np.swapaxes(V, -1, -2)) / 2
    return V.reshape(*A.shape[:-2], k, n, n)


@dataclass(frozen=True)
class NoiseLayout:
    """Where the noise parameters sit in the parameter vector of :class:`FilterError`: the
    model's ``pt`` parameters, white process-noise spectral densities ``Q_<state>``, the gust's
    ``ln_sigma_gust`` and ``ln_tau_gust`` (if any), then ``R_<output>``."""

    pt: int
    white: tuple[int, ...]
    gust: int | None
    no: int

    @property
    def q(self) -> slice:
        return slice(self.pt, self.pt + len(self.white))

    @property
    def sigma(self) -> int | None:
        return None if self.gust is None else self.q.stop

    @property
    def tau(self) -> int | None:
        return None if self.gust is None else self.q.stop + 1

    @property
    def r(self) -> slice:
        start = self.q.stop + (0 if self.gust is None else 2)
        return slice(start, start + self.no)

    @property
    def p(self) -> int:
        return self.r.stop

    def weights(self, th: np.ndarray) -> np.ndarray:
        """Spectral densities q_i of the columns of :func:`noise_inputs`: the white Q_<state>,
        and the gust's 2σ²/τ (stationary variance σ² of x_g, FE-4)."""
        w = list(th[self.q])
        if self.gust is not None:
            w.append(2.0 * np.exp(2.0 * th[self.sigma] - th[self.tau]))
        return np.asarray(w, float)


@dataclass(frozen=True)
class FilterError:
    """Filter error (output error with process noise) for the built-in linear models.

    Parameters
    ----------
    model : ``'short-period'``, ``'lateral'`` or None (chosen from the equation).
    process_noise : the states whose equations carry white process noise (``Q_<state>``
        estimated, ≥ 0); None: none when there is a gust state, else every state.
    gust : the state a first-order (Dryden) gust disturbs, (FE-4): ``'alpha'`` (the vertical
        gust as α_g = w_g/V) or ``'beta'``; its σ and τ are estimated (``ln_sigma_gust``,
        ``ln_tau_gust``); None: no gust state; ``'default'``: :data:`GUST_DEFAULT` of the model
        (α for the short period — on the ``turbulence`` campaign white noise on α and q covered
        Cm_α 0.82, on α alone 0.68, the gust state with the stabilator's noise (the defaults)
        0.92–0.97 for all six derivatives: README).
    gust_tau_start_s : the gust time constant τ the fit starts from, s (the gust σ starts at
        output error's residual standard deviation of the disturbed state).
    input_noise : the inputs measured with white noise (FE-5): that noise enters the state
        equations through Γ and the outputs through D, correlated; ``'default'``:
        :data:`INPUT_NOISE_DEFAULT` of the model; None or ``()``: inputs taken as exact.
    input_noise_std : its standard deviation per input (known, e.g. from a calibration);
        inputs not given take :func:`input_noise_std` of their record (FE-6). Held fixed: in
        the likelihood it was poorly determined (at its bound 0 in 31 of 100 turbulent
        records, with optimistic Cm bounds there, as white noise on q's equation before it).
    tau_bounds_s : bounds of τ, s; None: (Δt, 10 T), T the record length.
    start : starting values by name (default: output error's estimates and R, Q = 0).
    """

    model: str | None = None
    data: DataOptions = field(default_factory=DataOptions)
    process_noise: tuple[str, ...] | None = None
    gust: str | None = "default"
    gust_tau_start_s: float = 1.0
    input_noise: tuple[str, ...] | str | None = "default"
    input_noise_std: Mapping[str, float] | None = None
    tau_bounds_s: tuple[float, float] | None = None
    start: Mapping[str, float] | None = None
    max_iterations: int = 50
    method: str = "fe"

    def fit(self, source: Recording | OutputErrorData, equation: Equation | None = None) -> ModelFit:
        """Estimate θ and the noise parameters; ``cov`` the Cramér-Rao bound of (FE-3)."""
        from estimators.output_error import (COST_TOLERANCE, STEP_TOLERANCE, DivergenceError, OutputError,
                                             _check_information, _inverse)
        data = resolve_data(source, None if isinstance(source, OutputErrorData) else self.model, equation, self.data)
        spec = data.spec
        oe = OutputError(model=spec.name, data=self.data).fit(data if isinstance(source, OutputErrorData) else source,
                                                            equation)
        gust = GUST_DEFAULT.get(spec.name) if self.gust == "default" else self.gust
        if gust is not None and gust not in spec.states:
            raise ValueError(f"gust must name a state of the {spec.name} model {spec.states}, not {gust!r}")
        noisy = (spec.states if gust is None else ()) if self.process_noise is None else tuple(self.process_noise)
        unknown = [s for s in noisy if s not in spec.states]
        if unknown or not (noisy or gust):
            raise ValueError(f"process_noise must name states of the {spec.name} model {spec.states}, not {noisy}"
                             + ("" if gust else " (and there is no gust state)"))
        measured = (INPUT_NOISE_DEFAULT.get(spec.name, ()) if self.input_noise == "default"
                    else tuple(self.input_noise or ()))
        if any(i not in spec.inputs for i in measured) or any(i not in measured for i in self.input_noise_std or {}):
            raise ValueError(f"input_noise must name inputs of the {spec.name} model {spec.inputs} and "
                             f"input_noise_std only those, not {measured}, {dict(self.input_noise_std or {})}")
        system = affine_system(spec, data.flight)
        n, no, pt = len(spec.states), len(spec.outputs), len(spec.names)
        lay = NoiseLayout(pt, tuple(spec.states.index(s) for s in noisy),
                          None if gust is None else spec.states.index(gust), no)
        ui = [spec.inputs.index(i) for i in measured]
        na = n + (gust is not None)  # states of the filter (the gust's appended)
        G = noise_inputs(na, lay.white, None if gust is None else lay.gust)
        q_names = tuple(f"Q_{s}" for s in noisy)
        g_names = () if gust is None else ("ln_sigma_gust", "ln_tau_gust")
        r_names = tuple(f"R_{o}" for o in spec.outputs)
        names = spec.names + q_names + g_names + r_names
        p = lay.p
        z, dt = data.z, data.dt
        N = len(z)
        R0 = np.diag(np.asarray(oe.info["R"], float)) if np.ndim(oe.info["R"]) == 2 else np.asarray(oe.info["R"], float)
        lower, upper = np.full(p, -np.inf), np.full(p, np.inf)
        lower[lay.q] = 0.0
        theta = np.concatenate([oe.params, np.zeros(len(noisy)), np.zeros(len(g_names)), R0])
        given = dict(self.input_noise_std or {})
        sig_u = np.array([float(given[i]) if i in given else float(input_noise_std(data.u[:, j])[0])
                          for i, j in zip(measured, ui)])
        Sig = np.diag(sig_u ** 2)
        if gust is not None:
            r_gust = R0[spec.state_outputs[lay.gust]]
            theta[lay.sigma] = 0.5 * np.log(r_gust)
            lower[lay.sigma] = 0.5 * np.log(r_gust) + np.log(GUST_FLOOR)
            tb = self.tau_bounds_s if self.tau_bounds_s is not None else (dt, 10.0 * N * dt)
            lower[lay.tau], upper[lay.tau] = np.log(tb[0]), np.log(tb[1])
            theta[lay.tau] = np.clip(np.log(self.gust_tau_start_s), lower[lay.tau], upper[lay.tau])
        for k, v in dict(self.start or {}).items():
            if k not in names:
                raise ValueError(f"start has unknown parameter {k!r}; filter error has {names}")
            theta[names.index(k)] = float(v)
        u1 = np.column_stack([data.u, np.ones(N)])
        dA, dB, dC, dD = system.partials
        pad = lambda M, r, c: np.concatenate(  # noqa: E731  model partials, zero for the noise parameters
            [np.pad(M, ((0, 0), (0, r - M.shape[1]), (0, c - M.shape[2]))), np.zeros((p - pt, r, c))])
        dA_model, dB_all = pad(dA, na, na), pad(dB, na, dB.shape[2])
        dC_all, dD_all = pad(dC, no, na), pad(dD, no, dD.shape[2])
        dR_all = np.zeros((p, no, no))
        dR_all[np.arange(lay.r.start, p), np.arange(no), np.arange(no)] = 1.0
        moves_A = [j for j in range(pt) if np.any(dA[j])] + ([] if gust is None else [lay.tau])

        def matrices(th):
            A, B, C, D = system.matrices(th[:pt])
            if gust is not None:
                A, B, C, D = gust_augmented(A, B, C, D, lay.gust, float(np.exp(th[lay.tau])))
            return A, B, C, D

        def dA_of(th):
            """∂A/∂p_j: the model's (constant) and ln τ's (FE-4: ∂(1/τ)/∂ln τ = −1/τ)."""
            out = dA_model.copy()
            if gust is not None:
                inv_tau = float(np.exp(-th[lay.tau]))
                out[lay.tau, lay.gust, n], out[lay.tau, n, n] = -inv_tau, inv_tau
            return out

        def noise_of(th, Phi, Gam, D, A):
            """Q, R and S_c of (FE-1, FE-5): the process noise, plus a measured input's noise δ,
            which enters the states through −Γ_u δ and the outputs through −D_u δ."""
            Q = np.tensordot(lay.weights(th), noise_basis(A, G, dt), axes=1)
            Gu, Du = Gam[:, ui], D[:, ui]
            return Q + Gu @ Sig @ Gu.T, np.diag(th[lay.r]) + Du @ Sig @ Du.T, Gu @ Sig @ Du.T

        def filter_of(th):
            A, B, C, D = matrices(th)
            Phi, Gam, _ = discretize(A, B, dt)
            Q, R, Sc = noise_of(th, Phi, Gam, D, A)
            P, K, S = correlated_predictor(Phi, C, Q, R, Sc)
            return A, B, C, D, Phi, Gam, P, K, S, Q, R, Sc

        def cost_of(nu, S):
            L = np.linalg.cholesky(np.linalg.inv(S))
            return 0.5 * float(np.sum((nu @ L) ** 2)) + 0.5 * N * float(np.linalg.slogdet(S)[1])

        def evaluate(th, sens=True):
            A, B, C, D, Phi, Gam, P, K, S, Q, R, Sc = filter_of(th)
            x, nu, F = _predictor(Phi, Gam, C, D, K, u1, z)
            if not sens:
                return nu, S, F, None, None
            dA_all = dA_of(th)
            dPhi, dGam, _ = discretize_derivatives(A, B, dA_all, dB_all, dt)
            # Q_d = Σ q_i V_i(A): linear in the q_i (exact), on A by central differences (one stacked call)
            w, V = lay.weights(th), noise_basis(A, G, dt)
            dQ_all = np.zeros((p, na, na))
            dQ_all[lay.q] = V[:len(lay.white)]
            if gust is not None:
                dQ_all[lay.sigma] = 2.0 * w[-1] * V[-1]  # q = 2σ²/τ: ∂q/∂ln σ = 2q, ∂q/∂ln τ = −q
                dQ_all[lay.tau] = -w[-1] * V[-1]
            if moves_A and np.any(w):
                steps = np.array([1e-6 / (np.max(np.abs(dA_all[j])) * dt) for j in moves_A])
                h = steps[:, None, None] * dA_all[moves_A]
                Vpm = noise_basis(np.stack([A + h, A - h]), G, dt)
                dQ_all[moves_A] += np.tensordot(Vpm[0] - Vpm[1], w, axes=([1], [0])) / (2 * steps[:, None, None])
            # the input noise's share (FE-5), Σ fixed: through Γ_u and D_u
            Gu, Du, dGu, dDu = Gam[:, ui], D[:, ui], dGam[:, :, ui], dD_all[:, :, ui]
            sym = lambda X: X + X.transpose(0, 2, 1)  # noqa: E731
            dQ_all = dQ_all + sym(dGu @ Sig @ Gu.T)
            dRt = dR_all + sym(dDu @ Sig @ Du.T)
            dSc = dGu @ Sig @ Du.T + Gu @ Sig @ dDu.transpose(0, 2, 1)
            _, dK, dS = correlated_predictor_derivatives(Phi, C, Q, R, Sc, P, K, S, dPhi, dC_all, dQ_all, dRt, dSc)
            dF = dPhi - dK @ C - K @ dC_all
            dG = dGam - dK @ D - K @ dD_all
            e = np.zeros((p, N, na))
            e[:, 1:] = _per_parameter(np.column_stack([x[:-1], u1[:-1], z[:-1]]), np.concatenate([dF, dG, dK], axis=2))
            dx = scan(F, e)
            dnu = -((dx.reshape(-1, na) @ C.T).reshape(p, N, no)
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

        def held(th, grad):
            """Parameters at a bound with the likelihood pushing them out (active set); τ with
            a gust at its floor (no gust: its time constant has no information)."""
            out = ((th <= lower) & (grad >= 0.0)) | ((th >= upper) & (grad <= 0.0))
            if gust is not None and out[lay.sigma]:
                out[lay.tau] = True
            return out

        def uninformed(free):
            """Parameters the information matrix says nothing about: a gust's σ and τ with the
            gust at its floor (log-parameterised: no information there)."""
            out = np.zeros(p, bool)
            if gust is not None and not free[lay.sigma]:
                out[lay.sigma] = out[lay.tau] = True
            return out

        try:
            nu, S, F, dnu, dS = evaluate(theta)
        except np.linalg.LinAlgError as exc:
            raise DivergenceError(f"filter error: no steady-state Kalman filter at the start ({exc})") from exc
        J, history, converged, it = cost_of(nu, S), [], False, 0
        history.append(J)
        free = np.ones(p, bool)
        for it in range(1, self.max_iterations + 1):
            M, grad = scoring(nu, S, dnu, dS)
            free = ~held(theta, grad)
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
                trial = np.clip(theta + lam * step, lower, upper)
                if np.all(trial[lay.r] > 0.0):
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
        free = ~held(theta, grad)
        # The bound of every parameter, a variance held at 0 included: fixing it there would
        # claim the noise structure is known (too small bounds for the derivatives it couples to).
        # Only parameters without information are left out (NaN): :func:`uninformed`.
        keep = ~uninformed(free)
        cov = np.full((p, p), np.nan)
        Mk = M[np.ix_(keep, keep)]
        cov[np.ix_(keep, keep)] = _inverse(Mk, _check_information(Mk, tuple(k for k, f in zip(names, keep) if f)))
        is_noise = np.array([k.startswith(("bias", "Q_", "R_", "ln_")) for k in names])
        coll = collinearity(dnu[keep].reshape(int(keep.sum()), -1).T, tuple(k for k, f in zip(names, keep) if f),
                            cov[np.ix_(keep, keep)], is_noise[keep])
        warnings = [f"parameters {a} and {b} are highly correlated (|r| = {r:.3f} > 0.9, seed Eq. 50)"
                    for a, b, r in coll.flagged]
        at_bound = [k for k, f in zip(names, free) if not f]
        if not converged:
            warnings.append(f"filter error did not converge in {it} iterations")
        if gust is not None and not keep[lay.sigma]:
            warnings.append(f"no gust in these data: its standard deviation is at its floor ({GUST_FLOOR:g} of "
                            f"{gust}'s output-error residual), so ln_sigma_gust and ln_tau_gust have no standard error "
                            "(gust=None fits without the gust state)")
        r2 = {o: 1 - float(np.sum(nu[:, i] ** 2) / np.sum((z[:, i] - z[:, i].mean()) ** 2))
              for i, o in enumerate(spec.outputs)}
        K = filter_of(theta)[7]
        input_info = {i: float(v) for i, v in zip(measured, sig_u)}
        gust_info = None if gust is None else {
            "state": gust, "sigma": float(np.exp(theta[lay.sigma])), "tau_s": float(np.exp(theta[lay.tau])),
            # as a vertical (lateral) gust velocity and MIL-F-8785C scale length: σ_w = Vσ, L_w = 2Vτ
            "sigma_velocity": float(data.flight.V * np.exp(theta[lay.sigma])),
            "scale_length": float(2.0 * data.flight.V * np.exp(theta[lay.tau]))}
        info = {"S": S.tolist(), "K": K.tolist(), "Q": dict(zip(noisy, theta[lay.q].tolist())), "gust": gust_info,
                "input_noise": input_info,
                "R": theta[lay.r].tolist(), "at_bound": at_bound, "cost": J, "gradient": grad.tolist(),
                "cost_history": history, "iterations": it, "converged": converged, "r2": r2,
                "outputs": list(spec.outputs), "model": spec.name, "flight": data.flight.as_dict(),
                "oe_cost": oe.info["cost"], "notes": list(data.notes),
                "spectral_radius": float(np.max(np.abs(np.linalg.eigvals(F))))}
        L = np.linalg.cholesky(np.linalg.inv(S))
        return ModelFit(method=self.method, domain="time", dependent=",".join(spec.outputs), names=names,
                        params=theta, cov=cov, residuals=nu, fitted=z - nu, n=N,
                        s2=float(np.sum((nu @ L) ** 2)) / nu.size, r2=float(np.mean(list(r2.values()))),
                        errors="cramer-rao", collinearity=coll, warnings=tuple(warnings), info=info)
