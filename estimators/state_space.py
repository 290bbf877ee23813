"""Linear time-invariant simulation and the seed's linear aircraft models.

* :func:`discretize` and :func:`discretize_derivatives`: the exact discrete form of
  ẋ = Ax + Bu for inputs held between samples (zero order: constant; first order: linear),
  from one matrix exponential of an augmented matrix (:func:`expm_small`), and its exact
  derivatives with respect to changes of A and B (Fréchet derivatives of that exponential).
* :func:`scan` and :func:`propagate`: x_{k+1} = Φ x_k + w_k for a whole record at once
  (block-Toeplitz matrix products, no Python loop over samples).
* :func:`simulate_linear`: states and outputs y = Cx + Du of a sampled input record.
* :func:`short_period_matrices`, :func:`short_period_dimensional`,
  :func:`short_period_nondimensional`: the seed's short-period model, Eqs. 33-34.
* :func:`lateral_matrices`: the lateral-directional companion model (β, p, r, φ).
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from models.constants import G0_FPS2

HOLDS = ("zoh", "foh")
LATERAL_DERIVATIVES: tuple[str, ...] = tuple(
    f"{c}_{x}" for c in ("CY", "Cl", "Cn") for x in ("beta", "phat", "rhat", "da", "dr"))
"""Names of the lateral model's non-dimensional derivatives, in matrix order."""


def expm_small(E: np.ndarray) -> np.ndarray:
    """Matrix exponential of a small matrix or a stack of them (..., k, k).

    Scaling and squaring: E/2^s with ‖E/2^s‖₁ ≤ 1/2, its Taylor series to degree 18
    (truncation below 0.5¹⁹/19! ≈ 2e-23, so rounding-limited), then s squarings. Only
    matrix products are used. ``scipy.linalg.expm`` gives the same values, but its Padé
    step solves a linear system in SciPy's own bundled OpenBLAS, whose threads contend with
    NumPy's after every large product: measured 9 ms per call instead of 0.2 ms on a
    2-core machine, which made an output-error fit 50 times slower.
    """
    E = np.asarray(E, dtype=float)
    norm = float(np.max(np.sum(np.abs(E), axis=-2))) if E.size else 0.0
    s = int(np.ceil(np.log2(norm / 0.5))) if norm > 0.5 else 0
    X = E / 2.0 ** s
    eye = np.broadcast_to(np.eye(E.shape[-1]), E.shape)
    F = eye + X / 18.0
    for k in range(17, 0, -1):  # Horner: I + X/1 (I + X/2 (… (I + X/18)))
        F = eye + (X @ F) / k
    for _ in range(s):
        F = F @ F
    return F


def _check_hold(hold: str) -> None:
    if hold not in HOLDS:
        raise ValueError(f"hold must be one of {HOLDS}, not {hold!r}")


def _augmented(A: np.ndarray, B: np.ndarray, dt: float, hold: str) -> np.ndarray:
    """The matrix whose exponential holds Φ and the input matrices.

    ZOH: expm([[A, B], [0, 0]]·dt) = [[Φ, Γ], [0, I]], Γ = ∫₀^dt e^{Aτ} dτ B.
    FOH: expm([[A dt, B dt, 0], [0, 0, I], [0, 0, 0]]) has Γ₁ = ∫₀^dt e^{Aτ} dτ B in the
    middle block and Γ₂ = ∫₀^dt e^{A(dt−s)} B s/dt ds in the right block.
    """
    n, m = B.shape
    if hold == "zoh":
        E = np.zeros((n + m, n + m))
        E[:n, :n], E[:n, n:] = A * dt, B * dt
        return E
    E = np.zeros((n + 2 * m, n + 2 * m))
    E[:n, :n], E[:n, n:n + m] = A * dt, B * dt
    E[n:n + m, n + m:] = np.eye(m)
    return E


def _split(F: np.ndarray, n: int, m: int, hold: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Φ, G₀, G₁) of x_{k+1} = Φx_k + G₀u_k + G₁u_{k+1} from the augmented exponential."""
    Phi = F[:n, :n]
    if hold == "zoh":
        return Phi, F[:n, n:n + m], np.zeros((n, m))
    g1, g2 = F[:n, n:n + m], F[:n, n + m:]
    return Phi, g1 - g2, g2


def discretize(A: np.ndarray, B: np.ndarray, dt: float, hold: str = "zoh"
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact discrete form of ẋ = Ax + Bu for inputs held between samples.

    Parameters
    ----------
    A, B : ndarray
        n×n and n×m continuous-time matrices.
    dt : float
        Sampling interval, s.
    hold : ``'zoh'`` (u constant over each interval) or ``'foh'`` (u linear between samples).

    Returns
    -------
    Phi, G0, G1 : ndarray
        x_{k+1} = Φ x_k + G₀ u_k + G₁ u_{k+1} (G₁ = 0 for ``'zoh'``). With the FOH,
        x(t_k + s) = e^{As}x_k + ∫₀^s e^{A(s−τ)}B[u_k + τ(u_{k+1} − u_k)/dt] dτ evaluated at
        s = dt gives G₀ = Γ₁ − Γ₂, G₁ = Γ₂ (see :func:`_augmented`).
    """
    _check_hold(hold)
    A, B = np.atleast_2d(np.asarray(A, float)), np.asarray(B, float).reshape(len(A), -1)
    F = expm_small(_augmented(A, B, dt, hold))
    return _split(F, A.shape[0], B.shape[1], hold)


def discretize_derivatives(A: np.ndarray, B: np.ndarray, dA: np.ndarray, dB: np.ndarray, dt: float,
                           hold: str = "zoh") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Derivatives (dΦ_j, dG₀_j, dG₁_j) of :func:`discretize` in the directions (dA_j, dB_j).

    The augmented matrix E of :func:`_augmented` is linear in (A, B), so each derivative is
    the Fréchet derivative of the matrix exponential at E in the direction dE_j, which is the
    top-right block of exp([[E, dE_j], [0, E]]) (exact, not a finite difference). All
    directions are exponentiated in one stacked call.

    Parameters
    ----------
    A, B : ndarray
        n×n and n×m.
    dA, dB : ndarray
        (p, n, n) and (p, n, m): the change of A and B per unit change of each parameter.

    Returns
    -------
    dPhi, dG0, dG1 : ndarray
        Shapes (p, n, n), (p, n, m), (p, n, m).
    """
    _check_hold(hold)
    A, B = np.asarray(A, float), np.asarray(B, float)
    dA, dB = np.asarray(dA, float), np.asarray(dB, float)
    n, m, p = A.shape[0], B.shape[1], len(dA)
    E = _augmented(A, B, dt, hold)
    k = len(E)
    big = np.zeros((p, 2 * k, 2 * k))
    big[:, :k, :k] = big[:, k:, k:] = E
    big[:, :n, k:k + n] = dA * dt
    big[:, :n, k + n:k + n + m] = dB * dt
    dF = expm_small(big)[:, :k, k:]
    dPhi = dF[:, :n, :n]
    if hold == "zoh":
        return dPhi, dF[:, :n, n:n + m], np.zeros((p, n, m))
    dg1, dg2 = dF[:, :n, n:n + m], dF[:, :n, n + m:]
    return dPhi, dg1 - dg2, dg2


def _powers(Phi: np.ndarray, L: int) -> np.ndarray:
    """Φ⁰ … Φᴸ stacked, shape (L+1, n, n)."""
    out = np.empty((L + 1, *Phi.shape))
    out[0] = np.eye(len(Phi))
    for i in range(1, L + 1):
        out[i] = out[i - 1] @ Phi
    return out


def _block_toeplitz(powers: np.ndarray, L: int) -> np.ndarray:
    """Tᵀ for x_i = Σ_{j≤i} Φ^{i−j} e_j within a block: rows of samples times Tᵀ."""
    n = powers.shape[1]
    T = np.zeros((L, n, L, n))
    for i in range(L):
        T[i, :, :i + 1, :] = np.moveaxis(powers[i::-1], 0, 1)  # block (i, j) = Φ^{i−j}
    return T.reshape(L * n, L * n).T


def scan(Phi: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Inclusive linear scan x_k = Φ x_{k−1} + e_k (x_0 = e_0) of m columns at once.

    The record is cut into blocks of L samples. Inside every block the response to the
    block's own forcing is one matrix product with the block-Toeplitz matrix of Φ⁰ … Φ^{L−1};
    the state at each block's end then follows the same scan with Φ^L (recursively, over
    N/L points), and the carried state adds Φ^{i+1} s_{c−1} to sample i of block c. This
    touches the data a few times in all, whatever N, instead of once per sample.

    Parameters
    ----------
    Phi : ndarray, n×n
    e : ndarray, (m, N, n)
        Column-wise forcing, e[:, 0] the initial states.

    Returns
    -------
    ndarray, (m, N, n)
        When a power of Φ overflows within the record, the response itself exceeds the
        floating-point range and the result is not finite.
    """
    m, N, n = e.shape
    L = int(max(4, min(32, 128 // n)))
    with np.errstate(over="ignore", invalid="ignore"):
        if N <= L:
            return (e.reshape(m, N * n) @ _block_toeplitz(_powers(Phi, N), N)).reshape(m, N, n)
        blocks = -(-N // L)
        ep = np.zeros((m, blocks * L, n))
        ep[:, :N] = e
        P = _powers(Phi, L)
        x = (ep.reshape(m * blocks, L * n) @ _block_toeplitz(P, L)).reshape(m, blocks, L, n)
        ends = scan(P[L], x[:, :, L - 1, :])
        carry = P[1:].transpose(2, 0, 1).reshape(n, L * n)  # [c, (i, r)] = Φ^{i+1}[r, c]
        x[:, 1:] += (ends[:, :-1].reshape(-1, n) @ carry).reshape(m, blocks - 1, L, n)
    return x.reshape(m, blocks * L, n)[:, :N]


def propagate(Phi: np.ndarray, w: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """Solve x_{k+1} = Φ x_k + w_k, k = 0 … N−2, from x_0 for a whole record (:func:`scan`).

    Parameters
    ----------
    Phi : ndarray, n×n
    w : ndarray, (N−1, n) or (N−1, n, m)
        Forcing of each step (m independent columns share Φ).
    x0 : ndarray, (n,) or (n, m)

    Returns
    -------
    ndarray, (N, n) or (N, n, m)
    """
    Phi = np.asarray(Phi, float)
    w = np.asarray(w, float)
    vector = w.ndim == 2
    w3 = w[:, :, None] if vector else w
    n, m = Phi.shape[0], w3.shape[2]
    e = np.empty((m, len(w3) + 1, n))
    e[:, 0] = np.asarray(x0, float).reshape(n, m).T
    e[:, 1:] = np.moveaxis(w3, 2, 0)
    x = np.moveaxis(scan(Phi, e), 0, 2)
    return x[:, :, 0] if vector else x


def simulate_linear(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, u: np.ndarray,
                    dt: float, x0: np.ndarray | None = None, *, hold: str = "zoh"
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Exact sampled response of ẋ = Ax + Bu, y = Cx + Du.

    Parameters
    ----------
    A, B, C, D : ndarray
        n×n, n×n_u, n_o×n, n_o×n_u. Constant (bias) terms enter as a column of ones in u.
    u : ndarray, (N, n_u) or (N,)
        Input samples at t_k = k·dt, held between samples per ``hold``.
    dt : float
        Sampling interval, s.
    x0 : ndarray, optional
        Initial state (zeros by default).
    hold : ``'zoh'`` or ``'foh'``
        Zero-order (piecewise constant) or first-order (piecewise linear) input.

    Returns
    -------
    x, y : ndarray
        N×n states and N×n_o outputs at the sample times.
    """
    A = np.atleast_2d(np.asarray(A, float))
    u = np.asarray(u, float).reshape(len(u), -1)
    n = A.shape[0]
    B = np.asarray(B, float).reshape(n, u.shape[1])
    C = np.atleast_2d(np.asarray(C, float))
    D = np.asarray(D, float).reshape(C.shape[0], u.shape[1])
    Phi, G0, G1 = discretize(A, B, dt, hold)
    w = u[:-1] @ G0.T + (u[1:] @ G1.T if hold == "foh" else 0.0)
    x = propagate(Phi, w, np.zeros(n) if x0 is None else np.asarray(x0, float))
    return x, x @ C.T + u @ D.T


# ---------------------------------------------------------------------- short period, Eqs. 33-34
def short_period_matrices(Z_alpha: float, Z_q: float, Z_de: float, M_alpha: float, M_q: float,
                          M_de: float, V_o: float, g: float = G0_FPS2
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A, B, C, D of the seed's short-period model, Eq. 33.

    States (α, q) in rad and rad/s, input δ_s in rad, outputs (α, q, a_z) with a_z in g:

    α̇ = Z_α α + (1 + Z_q) q + Z_δs δ_s        (33a)
    q̇ = M_α α + M_q q + M_δs δ_s              (33b)
    a_z = (V_o/g)(Z_α α + Z_q q + Z_δs δ_s)   (33c)
    """
    k = V_o / g
    A = np.array([[Z_alpha, 1.0 + Z_q], [M_alpha, M_q]], dtype=float)
    B = np.array([[Z_de], [M_de]], dtype=float)
    C = np.array([[1.0, 0.0], [0.0, 1.0], [k * Z_alpha, k * Z_q]], dtype=float)
    D = np.array([[0.0], [0.0], [k * Z_de]], dtype=float)
    return A, B, C, D


def _short_period_scales(qbar: float, S: float, cbar: float, m: float, Iy: float, V: float
                         ) -> dict[str, float]:
    """Factors of Eq. 34: dimensional derivative = factor × non-dimensional derivative."""
    return {"Z_alpha": qbar * S / (m * V), "Z_q": qbar * S * cbar / (2 * m * V ** 2),
            "Z_de": qbar * S / (m * V), "M_alpha": qbar * S * cbar / Iy,
            "M_q": qbar * S * cbar ** 2 / (2 * V * Iy), "M_de": qbar * S * cbar / Iy}


_SP_PAIRS = (("Z_alpha", "CZ_alpha"), ("Z_q", "CZ_qhat"), ("Z_de", "CZ_de"),
             ("M_alpha", "Cm_alpha"), ("M_q", "Cm_qhat"), ("M_de", "Cm_de"))


def short_period_dimensional(CZ_alpha: float, CZ_qhat: float, CZ_de: float, Cm_alpha: float,
                             Cm_qhat: float, Cm_de: float, qbar: float, S: float, cbar: float,
                             m: float, Iy: float, V: float) -> dict[str, float]:
    """Dimensional short-period derivatives from non-dimensional ones, seed Eq. 34.

    Z_α = q̄S/(mV) C_Zα, Z_q = q̄Sc̄/(2mV²) C_Zq, Z_δs = q̄S/(mV) C_Zδs,
    M_α = q̄Sc̄/I_y C_mα, M_q = q̄Sc̄²/(2V I_y) C_mq, M_δs = q̄Sc̄/I_y C_mδs.

    Returns
    -------
    dict
        ``Z_alpha, Z_q, Z_de, M_alpha, M_q, M_de`` (1/s, –, 1/s, 1/s², 1/s, 1/s²), ready for
        ``short_period_matrices(**d, V_o=V)``.
    """
    nd = {"CZ_alpha": CZ_alpha, "CZ_qhat": CZ_qhat, "CZ_de": CZ_de,
          "Cm_alpha": Cm_alpha, "Cm_qhat": Cm_qhat, "Cm_de": Cm_de}
    k = _short_period_scales(qbar, S, cbar, m, Iy, V)
    return {dim: k[dim] * nd[c] for dim, c in _SP_PAIRS}


def short_period_nondimensional(Z_alpha: float, Z_q: float, Z_de: float, M_alpha: float, M_q: float,
                                M_de: float, qbar: float, S: float, cbar: float, m: float, Iy: float,
                                V: float) -> dict[str, float]:
    """Inverse of :func:`short_period_dimensional` (Eq. 34 solved for the coefficients)."""
    dim = {"Z_alpha": Z_alpha, "Z_q": Z_q, "Z_de": Z_de, "M_alpha": M_alpha, "M_q": M_q, "M_de": M_de}
    k = _short_period_scales(qbar, S, cbar, m, Iy, V)
    return {c: dim[d] / k[d] for d, c in _SP_PAIRS}


# ---------------------------------------------------------------------- lateral-directional
def lateral_matrices(derivatives: Mapping[str, float], *, qbar: float, V: float, S: float, b: float,
                     m: float, Ix: float, Iz: float, Ixz: float, alpha_o: float = 0.0,
                     theta_o: float = 0.0, g: float = G0_FPS2
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A, B, C, D of the linear lateral-directional model from non-dimensional derivatives.

    States (β, p, r, φ), inputs (δ_a, δ_r), outputs (β, p, r, φ, a_y in g). Small
    perturbations in body axes about wings-level trim at α_o, θ_o, airspeed V, with
    p̂ = pb/2V, r̂ = rb/2V and C_Y = C_Yβ β + C_Yp p̂ + C_Yr r̂ + C_Yδa δ_a + C_Yδr δ_r
    (C_l, C_n alike, the seed's Eqs. 9-11 without constants):

    β̇ = (q̄S/mV) C_Y + sin α_o p − cos α_o r + (g/V) cos θ_o φ
    [I_x −I_xz; −I_xz I_z] [ṗ; ṙ] = q̄Sb [C_l; C_n]   (Eqs. 3 and 5 linearised, q = 0)
    φ̇ = p + tan θ_o r
    a_y = (q̄S/mg) C_Y

    I_xz has the seed's sign (Eqs. 3-5); the 2×2 inertia coupling is solved exactly.

    Parameters
    ----------
    derivatives : mapping
        All of :data:`LATERAL_DERIVATIVES` (``CY_beta`` … ``Cn_dr``), per rad.
    """
    missing = [k for k in LATERAL_DERIVATIVES if k not in derivatives]
    extra = [k for k in derivatives if k not in LATERAL_DERIVATIVES]
    if missing or extra:
        raise ValueError(f"lateral_matrices needs exactly {list(LATERAL_DERIVATIVES)}; "
                         f"missing {missing}, unknown {extra}")
    h = b / (2 * V)
    scale = np.array([1.0, h, h, 1.0, 1.0])  # β, p̂/p, r̂/r, δa, δr
    coef = np.array([[derivatives[f"{c}_{x}"] for x in ("beta", "phat", "rhat", "da", "dr")]
                     for c in ("CY", "Cl", "Cn")], dtype=float) * scale  # per β, p, r, δa, δr
    kY = qbar * S / (m * V)
    inertia = np.array([[Ix, -Ixz], [-Ixz, Iz]], dtype=float)
    moments = np.linalg.solve(inertia, qbar * S * b * coef[1:])  # rows ṗ, ṙ
    A = np.zeros((4, 4))
    A[0, :3] = kY * coef[0, :3] + np.array([0.0, np.sin(alpha_o), -np.cos(alpha_o)])
    A[0, 3] = g / V * np.cos(theta_o)
    A[1:3, :3] = moments[:, :3]
    A[3, 1], A[3, 2] = 1.0, np.tan(theta_o)
    B = np.zeros((4, 2))
    B[0] = kY * coef[0, 3:]
    B[1:3] = moments[:, 3:]
    kA = qbar * S / (m * g)
    C = np.vstack([np.eye(4), np.append(kA * coef[0, :3], 0.0)])
    D = np.vstack([np.zeros((4, 2)), kA * coef[0, 3:]])
    return A, B, C, D
