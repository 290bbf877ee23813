"""Output error with the simulator in the loop: Gauss-Newton on JSBSim flights.

For maneuvers m with measured outputs z_m (N_m × n_o) and flights y_m(θ), plus a constant
bias b_m per output and maneuver (a sensor offset or trim mismatch; its sensitivity is exact),
the negative log-likelihood with measurement noise R (seed Eqs. 25-26) is

    J(θ, b, R) = ½ Σ_m Σ_i v_miᵀ R⁻¹ v_mi + (N/2) ln|R|,   v_mi = z_mi − y_mi(θ) − b_m.

Relaxation (Eqs. 27-29): with R fixed a Gauss-Newton step

    M = Σ Sᵢᵀ R⁻¹ Sᵢ,   Δ = M⁻¹ Σ Sᵢᵀ R⁻¹ vᵢ,

halved while the flight at θ + λΔ diverges (or fails to trim) or its quadratic cost is not
lower; then R = diag(mean v²) (Eq. 29). The sensitivities S_j = [y(θ + h_j e_j) − y(θ)]/h_j
come from perturbed flights, h_j = 1 % of max(|θ_j|, typical_j) (JSBSim's trim converges
to a tolerance: a smaller step differences its noise). All flights of one evaluation run
through the executor at once. The covariance is the Cramér-Rao bound M⁻¹ and, since
residuals of a model flown against real sensors are coloured, its correction for coloured
residuals (Eq. 40 generalised to output error and several outputs):

    Cov = M⁻¹ [Σ_{o,o'} X_oᵀ T_oo' X_o'] M⁻¹,   X_o = S_o / R_oo,   T_oo'[i, j] = ĉ_oo'(i − j),

with ĉ the residual auto- and cross-correlations (Eq. 39, all lags), evaluated by FFT.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import fft as sfft

FD_FRACTION = 1e-2
MAX_HALVINGS = 8
STEP_TOLERANCE = 0.02     # largest |Δθ_j| in standard errors at convergence
COST_TOLERANCE = 1e-5     # relative change of the quadratic cost at convergence
NOISE_FLOOR = 1e-12

# evaluate(list of parameter vectors) -> per vector, per maneuver: outputs (N × n_o) or a reason
Evaluate = Callable[[Sequence[np.ndarray]], list[list[np.ndarray | str]]]


@dataclass(frozen=True)
class EngineResult:
    """The estimate and its bounds; ``theta`` the physical parameters, ``biases`` one row per
    maneuver, ``cov`` the coloured-residual covariance of ``theta`` and ``crb`` its
    Cramér-Rao bound, ``y`` the final flights, ``R`` the noise variances."""

    theta: np.ndarray
    biases: np.ndarray
    cov: np.ndarray
    crb: np.ndarray
    y: list[np.ndarray]
    R: np.ndarray
    iterations: int
    converged: bool
    cost_history: list[float]
    flights: int
    notes: list[str] = field(default_factory=list)


def steps(theta: np.ndarray, typical: np.ndarray) -> np.ndarray:
    """Finite-difference steps h_j = FD_FRACTION · max(|θ_j|, typical_j)."""
    return FD_FRACTION * np.maximum(np.abs(theta), typical)


def perturbed(theta: np.ndarray, h: np.ndarray, lower: np.ndarray) -> list[np.ndarray]:
    """θ + h_j e_j for each j (a forward step never crosses a lower bound)."""
    out = []
    for j in range(len(theta)):
        th = theta.copy()
        th[j] += h[j]
        out.append(np.maximum(th, lower))
    return out


def sensitivities(y0: list[np.ndarray], ys: list[list[np.ndarray | str]], h: np.ndarray
                  ) -> tuple[list[np.ndarray], list[int]]:
    """S_m (p × N_m × n_o) per maneuver from the flights at θ + h_j e_j; the parameters j
    whose flight failed on some maneuver are returned (their columns left zero there)."""
    failed = []
    S = [np.zeros((len(h),) + y.shape) for y in y0]
    for j, per in enumerate(ys):
        for m, y in enumerate(per):
            if isinstance(y, str):
                failed.append(j)
                continue
            S[m][j] = (y - y0[m]) / h[j]
    return S, sorted(set(failed))


def backward(S: list[np.ndarray], y0: list[np.ndarray], ys: list[list[np.ndarray | str]], h: np.ndarray,
             failed: list[int], labels: list[str]) -> list[str]:
    """Fill the columns of ``failed`` by backward differences [y(θ) − y(θ − h_j e_j)]/h_j from
    the flights ``ys`` (one per failed parameter), in place; notes on any that failed too."""
    notes = []
    for j, label, per in zip(failed, labels, ys):
        for m, y in enumerate(per):
            if isinstance(y, str):
                notes.append(f"{label}: the flights at θ ± h both failed on maneuver {m} ({y}); its "
                             "sensitivity there is taken as zero")
            else:
                S[m][j] = (y0[m] - y) / h[j]
    return notes


def _whitened(v: list[np.ndarray], R: np.ndarray) -> float:
    return 0.5 * float(sum(np.sum(vm ** 2 / R) for vm in v))


def cost(v: list[np.ndarray], R: np.ndarray) -> float:
    """Eq. 26 with R diagonal (the variances ``R``)."""
    n = sum(len(vm) for vm in v)
    return _whitened(v, R) + 0.5 * n * float(np.sum(np.log(R)))


def noise_variances(v: list[np.ndarray], floor: np.ndarray) -> np.ndarray:
    """Eq. 29, diagonal: the mean squared residual per output, floored."""
    stacked = np.vstack(v)
    return np.maximum(np.mean(stacked ** 2, axis=0), floor)


def full_sensitivities(S: list[np.ndarray], n_out: int) -> list[np.ndarray]:
    """Each maneuver's sensitivities to the physical parameters and to every bias (unit for
    its own maneuver's output, zero elsewhere)."""
    p, n_m = S[0].shape[0], len(S)
    out = []
    for m, Sm in enumerate(S):
        full = np.zeros((p + n_m * n_out,) + Sm.shape[1:])
        full[:p] = Sm
        for o in range(n_out):
            full[p + m * n_out + o, :, o] = 1.0
        out.append(full)
    return out


def information(S: list[np.ndarray], v: list[np.ndarray], R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """M = Σ SᵢᵀR⁻¹Sᵢ and g = Σ SᵢᵀR⁻¹vᵢ over all maneuvers."""
    w = 1.0 / np.sqrt(R)
    rows = [(Sm * w).reshape(len(Sm), -1) for Sm in S]
    X = np.concatenate(rows, axis=1)
    r = np.concatenate([(vm * w).ravel() for vm in v])
    return X @ X.T, X @ r


def colored_middle(S: list[np.ndarray], v: list[np.ndarray], R: np.ndarray) -> np.ndarray:
    """Σ_m Σ_{o,o'} X_moᵀ T_m,oo' X_mo' (module docstring), the residuals' auto- and
    cross-correlations at all lags (Eq. 39, ĉ_oo'(k) = (1/N) Σ_n v_o[n + k] v_o'[n]) included:
    the noise a replay's recorded inputs carry reaches several outputs at once.

    By the correlation theorem, with zero-padded transforms of length L ≥ 2N − 1,
    Σ_ij a_oi ĉ_oo'(i − j) b_o'j = (1/(L N)) Σ_f conj(A_o(f)) V_o(f) conj(V_o'(f)) B_o'(f), so the
    whole matrix is (1/(L N)) Σ_f W(f) W(f)ᴴ with W_j(f) = Σ_o conj(A_oj(f)) V_o(f)."""
    p = S[0].shape[0]
    out = np.zeros((p, p))
    for Sm, vm in zip(S, v):
        n = vm.shape[0]
        L = sfft.next_fast_len(2 * n)
        A = sfft.rfft(Sm / R, L, axis=1)          # p × F × n_o
        V = sfft.rfft(vm, L, axis=0)              # F × n_o
        W = np.einsum("pfo,fo->pf", A.conj(), V)
        wts = np.full(W.shape[1], 2.0)
        wts[0] = 1.0
        if L % 2 == 0:
            wts[-1] = 1.0
        out += np.real((W * wts) @ W.conj().T) / (L * n)
    return out


def _scaled_inverse(M: np.ndarray) -> np.ndarray:
    d = np.sqrt(np.maximum(np.diag(M), 1e-300))
    return np.linalg.pinv(M / np.outer(d, d)) / np.outer(d, d)


def gauss_newton(evaluate: Evaluate, theta0: np.ndarray, typical: np.ndarray, lower: np.ndarray,
                 z: list[np.ndarray], *, max_iterations: int = 20, names: Sequence[str] = ()) -> EngineResult:
    """Fit θ (and the biases) to ``z`` by the relaxation of the module docstring.

    Raises
    ------
    RuntimeError
        When the model cannot be flown at the starting values.
    """
    p, n_m, n_out = len(theta0), len(z), z[0].shape[1]
    theta = np.maximum(np.asarray(theta0, dtype=float), lower)
    flights = 0

    def batch(points: list[np.ndarray]) -> list[list[np.ndarray | str]]:
        nonlocal flights
        flights += len(points) * n_m
        return evaluate(points)

    notes: list[str] = []

    def label(j: int) -> str:
        return names[j] if j < len(names) else f"parameter {j}"

    def differences(th: np.ndarray, y0: list[np.ndarray], ys, h: np.ndarray) -> list[np.ndarray]:
        S, failed = sensitivities(y0, ys, h)
        if failed:
            back = []
            for j in failed:
                pt = th.copy()
                pt[j] -= h[j]
                back.append(pt)
            notes.extend(f"{label(j)}: the flight at θ + h failed; backward difference" for j in failed)
            notes.extend(backward(S, y0, batch(back), h, failed, [label(j) for j in failed]))
        return S

    h = steps(theta, typical)
    first = batch([theta] + perturbed(theta, h, lower))
    y = first[0]
    bad = [f"{m}: {r}" for m, r in enumerate(y) if isinstance(r, str)]
    if bad:
        raise RuntimeError(f"the model cannot fly the recordings at the starting values ({'; '.join(bad)})")
    S = differences(theta, y, first[1:], h)
    dead = [label(j) for j in range(p) if not any(np.any(Sm[j] != 0) for Sm in S)]
    if dead:
        raise RuntimeError(f"the recorded outputs do not depend on {', '.join(dead)} in these flights: not "
                           "identifiable (is the surface or motion that drives it in the recording?)")
    b = np.array([np.mean(zm - ym, axis=0) for zm, ym in zip(z, y)])
    floor = NOISE_FLOOR * np.maximum(np.var(np.vstack(z), axis=0), 1e-300)

    def residuals(ys: list[np.ndarray], bias: np.ndarray) -> list[np.ndarray]:
        return [zm - ym - bias[m] for m, (zm, ym) in enumerate(zip(z, ys))]

    v = residuals(y, b)
    R = noise_variances(v, floor)
    history = [cost(v, R)]
    converged, iterations = False, 0
    se = np.full(p + n_m * n_out, np.inf)
    for iterations in range(1, max_iterations + 1):
        Sf = full_sensitivities(S, n_out)
        M, g = information(Sf, v, R)
        step = _scaled_inverse(M) @ g
        se = np.sqrt(np.maximum(np.diag(_scaled_inverse(M)), 1e-300))
        if np.max(np.abs(step[:p]) / se[:p]) < STEP_TOLERANCE:
            converged = True
            break
        quad = _whitened(v, R)
        lam, accepted = 1.0, None
        for k in range(MAX_HALVINGS):
            th_t = np.maximum(theta + lam * step[:p], lower)
            b_t = b + lam * step[p:].reshape(n_m, n_out)
            h_t = steps(th_t, typical)
            # the first trial also flies its perturbations: when it is accepted (the usual case)
            # its sensitivities are ready without another round of flights
            pts = [th_t] + (perturbed(th_t, h_t, lower) if k == 0 else [])
            res = batch(pts)
            y_t = res[0]
            failed = [r for r in y_t if isinstance(r, str)]
            if failed:
                notes.append(f"iteration {iterations}: the flight at step {lam:g} failed ({failed[0]}); step halved")
            elif _whitened(residuals(y_t, b_t), R) <= quad:
                accepted = (th_t, b_t, y_t, res[1:] if k == 0 else None, h_t)
                break
            lam /= 2
        if accepted is None:
            left = float(np.max(np.abs(step[:p]) / se[:p]))
            # the flights' own numerical noise (JSBSim's trim converges to a tolerance) leaves a
            # floor under the cost: a step smaller than the estimates' uncertainty is at it
            converged = left < 1.0
            notes.append(f"iteration {iterations}: no step along the Gauss-Newton direction lowered the cost "
                         f"after {MAX_HALVINGS} halvings (the step left is {left:.2g} standard errors); stopped there")
            break
        th_t, b_t, y_t, pert, h_t = accepted
        if pert is None:
            pert = batch(perturbed(th_t, h_t, lower))
        moved = np.max(np.abs(th_t - theta) / se[:p])
        theta, b, y = th_t, b_t, y_t
        S = differences(theta, y, pert, h_t)
        v = residuals(y, b)
        R_old, R = R, noise_variances(v, floor)
        history.append(cost(v, R))
        change = abs(history[-1] - history[-2]) / max(abs(history[-2]), 1.0)
        if moved < STEP_TOLERANCE or (change < COST_TOLERANCE and np.allclose(R, R_old, rtol=1e-3)):
            converged = True
            break
    Sf = full_sensitivities(S, n_out)
    M, _ = information(Sf, v, R)
    Minv = _scaled_inverse(M)
    cov = Minv @ colored_middle(Sf, v, R) @ Minv
    return EngineResult(theta=theta, biases=b, cov=cov[:p, :p], crb=Minv[:p, :p], y=y, R=R, iterations=iterations,
                        converged=converged, cost_history=history, flights=flights, notes=notes)
