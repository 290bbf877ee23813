"""Filter error (estimators.filter_error) on the short period with process noise: output error's
±2σ intervals are over-confident there, filter error's cover the truth at their nominal rate
(seeded realizations) — with white process noise on α and q, and with the turbulence
campaign's structure (a first-order gust through α, the stabilator measured with noise);
without process noise filter error agrees with output error."""
from __future__ import annotations

import numpy as np
import pytest

from estimators.filter_error import (FilterError, correlated_predictor, correlated_predictor_derivatives,
                                     gust_augmented, input_noise_std, kalman_predictor,
                                     kalman_predictor_derivatives, noise_basis, noise_inputs)
from estimators.output_error import OutputError
from estimators.state_space import discretize, short_period_matrices
from harness.linear_flight import gust_short_period

from tests.test_output_error import (AZ_TRIM, DT, SHORT_PERIOD, SP_NOISE, TRIM, make_recording, pulses,
                                     short_period_recording, short_period_truth)

PROCESS = np.array([np.radians(0.03), np.radians(0.05)])  # per-sample disturbance of α, q (turbulence)


def turbulent_recording(seed: int):
    t = np.arange(1001) * DT
    de = pulses(t, 1.0, (2, 1, 1, 2), (1, -1, 1, -1), 1.0)
    A, B, C, D = short_period_matrices(**short_period_truth(), V_o=TRIM["V_fps"])
    Phi, G, _ = discretize(A, B, DT)
    rng = np.random.default_rng(seed)
    w = rng.standard_normal((len(t), 2)) * PROCESS
    x = np.zeros((len(t), 2))
    for k in range(len(t) - 1):
        x[k + 1] = Phi @ x[k] + G[:, 0] * de[k] + w[k]
    y = x @ C.T + de[:, None] * D[:, 0] + rng.standard_normal((len(t), 3)) * SP_NOISE
    return make_recording(t, alpha_rad=TRIM["alpha_rad"] + y[:, 0], q_rps=y[:, 1], az_g=AZ_TRIM + y[:, 2],
                          de_rad=TRIM["de_rad"] + de)


def test_coverage_with_process_noise_output_error_against_filter_error():
    runs = 50
    truth = np.array(list(SHORT_PERIOD.values()))
    oe_in, fe_in = [], []
    for r in range(runs):
        rec = turbulent_recording(300 + r)
        o, f = OutputError().fit(rec), FilterError(gust=None).fit(rec)  # white noise on α and q: that structure
        oe_in.append(np.abs(o.params[:6] - truth) <= 2 * o.bse[:6])
        fe_in.append(np.abs(f.params[:6] - truth) <= 2 * f.bse[:6])
    assert np.mean(oe_in) < 0.90, np.mean(oe_in)
    assert 0.90 <= np.mean(fe_in) <= 0.99, np.mean(fe_in)


def test_without_process_noise_filter_error_is_output_error():
    rec = short_period_recording(SP_NOISE, seed=7)
    o = OutputError().fit(rec)
    white, gust = FilterError(gust=None).fit(rec), FilterError().fit(rec)
    assert white.names[:11] == o.names and white.names[11:] == ("Q_alpha", "Q_q", "R_alpha", "R_q", "R_az")
    assert gust.names[11:] == ("ln_sigma_gust", "ln_tau_gust", "R_alpha", "R_q", "R_az")
    assert gust.info["input_noise"] == {"de": 0.0}  # a noise-free stabilator is taken as exact
    # still air: the gust at its floor, said so, without a made-up standard error
    assert "ln_sigma_gust" in gust.info["at_bound"] and any(w.startswith("no gust") for w in gust.warnings)
    assert np.isnan(gust.std_error("ln_sigma_gust")) and np.isnan(gust.std_error("ln_tau_gust"))
    for f in (white, gust):
        for name in SHORT_PERIOD:
            assert abs(f.param(name) - o.param(name)) < 2 * f.std_error(name), name  # both unbiased here


def test_kalman_predictor_is_the_riccati_solution_and_its_derivatives_are_exact():
    """The doubling algorithm's P is scipy's DARE solution (singular Q included); ∂K, ∂S of
    the Stein equation agree with central differences of the solver."""
    from scipy.linalg import solve_discrete_are
    A, B, C, D = short_period_matrices(**short_period_truth(), V_o=TRIM["V_fps"])
    Phi, _, _ = discretize(A, B, DT)
    Q, R = np.diag([3e-7, 0.0]), np.diag(SP_NOISE ** 2)
    P, K, S = kalman_predictor(Phi, C, Q, R)
    assert np.allclose(P, solve_discrete_are(Phi.T, C.T, Q, R), rtol=1e-9, atol=1e-20)
    assert np.max(np.abs(np.linalg.eigvals(Phi - K @ C))) < 1
    rng = np.random.default_rng(1)
    dPhi, dC = rng.standard_normal((3, 2, 2)) * 0.01, rng.standard_normal((3, 3, 2))
    dQ, dR = np.zeros((3, 2, 2)), np.zeros((3, 3, 3))
    dQ[1], dR[2] = np.diag([1e-7, 1e-7]), np.diag(SP_NOISE ** 2)
    _, dK, dS = kalman_predictor_derivatives(Phi, C, P, K, S, dPhi, dC, dQ, dR)
    h = 1e-6
    for j in range(3):
        _, K2, S2 = kalman_predictor(Phi + h * dPhi[j], C + h * dC[j], Q + h * dQ[j], R + h * dR[j])
        _, K1, S1 = kalman_predictor(Phi - h * dPhi[j], C - h * dC[j], Q - h * dQ[j], R - h * dR[j])
        assert np.allclose((K2 - K1) / (2 * h), dK[j], rtol=1e-5, atol=1e-6 * np.abs(dK[j]).max())
        assert np.allclose((S2 - S1) / (2 * h), dS[j], rtol=1e-5, atol=1e-6 * np.abs(dS[j]).max())


def test_gradient_is_that_of_the_likelihood():
    """The scoring gradient (exact sensitivities through the Riccati solution and the
    discretised process noise) equals central differences of the negative log-likelihood,
    away from the optimum, for a derivative, a bias and both kinds of noise variance."""
    rec = turbulent_recording(300)
    fit = FilterError(gust=None).fit(rec)
    start = dict(zip(fit.names, fit.params * (1 + 0.05 * np.sin(np.arange(len(fit.params))))))
    grad = dict(zip(fit.names, FilterError(gust=None, start=start, max_iterations=0).fit(rec).info["gradient"]))
    for name in ("Cm_qhat", "bias_q", "Q_alpha", "R_az"):
        h = 1e-4 * abs(start[name])
        cost = [FilterError(gust=None, start=start | {name: start[name] + s}, max_iterations=0).fit(rec).info["cost"]
                for s in (h, -h)]
        assert grad[name] == pytest.approx((cost[0] - cost[1]) / (2 * h), rel=1e-5), name


# ------------------------------------------------------- the turbulence campaign's structure
GUST = {"sigma_w_fps": 6.0, "L_w_ft": 1750.0}  # MIL-spec moderate at 10,000 ft (the campaign's)
WHITE = np.array([np.radians(0.1), np.radians(0.14), 0.98 / 32.174])  # the `white` preset: α, q, a_z
DE_NOISE = np.radians(0.05)  # the `white` preset's stabilator position noise


def gust_recording(seed: int, de_noise: float = DE_NOISE):
    """The short period flown through the vertical gust as the turbulence campaign flies it
    (harness.linear_flight, kinematic α), white sensor noise and a noisy stabilator measurement."""
    t = np.arange(1001) * DT
    de = pulses(t, 1.0, (2, 1, 1, 2), (1, -1, 1, -1), 1.0)
    dim = short_period_truth()
    _, _, C, D = short_period_matrices(**dim, V_o=TRIM["V_fps"])
    rng = np.random.default_rng(seed)
    alpha, q, _ = gust_short_period(dim, TRIM["V_fps"], DT, de, 0.0, GUST["sigma_w_fps"], GUST["L_w_ft"], rng)
    y = np.column_stack([alpha, q]) @ C.T + de[:, None] * D[:, 0] + rng.standard_normal((len(t), 3)) * WHITE
    return make_recording(t, alpha_rad=TRIM["alpha_rad"] + y[:, 0], q_rps=y[:, 1], az_g=AZ_TRIM + y[:, 2],
                          de_rad=TRIM["de_rad"] + de + rng.standard_normal(len(t)) * de_noise)


def test_gust_state_is_the_campaign_turbulence():
    """(FE-4) in the aerodynamic α is harness.linear_flight's gust model (kinematic α) under
    α = α_i − α_g: the same A and, for spectral density 2σ²/τ, the same sampled noise."""
    from harness.linear_flight import _noise_covariance
    dim = short_period_truth()
    A, B, C, D = short_period_matrices(**dim, V_o=TRIM["V_fps"])
    tau = GUST["L_w_ft"] / (2 * TRIM["V_fps"])
    Za, Ma = dim["Z_alpha"], dim["M_alpha"]
    A_h = np.array([[Za, 1.0 + dim["Z_q"], -Za], [Ma, dim["M_q"], -Ma], [0.0, 0.0, -1.0 / tau]])
    Qc = np.zeros((3, 3))
    Qc[2, 2] = 2.0 * 0.01 ** 2 / tau
    _, Qd_h = _noise_covariance(A_h, Qc, DT)
    T = np.array([[1.0, 0.0, -1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])  # (α_i, q, α_g) → (α, q, α_g)
    Aa, Ba, Ca, _ = gust_augmented(A, B, C, D, 0, tau)
    assert np.allclose(Aa, T @ A_h @ np.linalg.inv(T), rtol=1e-12, atol=1e-12)
    Qd = Qc[2, 2] * noise_basis(Aa, noise_inputs(3, (), 0), DT)[0]
    assert np.allclose(Qd, T @ Qd_h @ T.T, rtol=1e-9, atol=1e-12 * np.abs(Qd).max())
    assert np.allclose(Ca[:, :2], C) and not np.any(Ca[:, 2])


def test_input_noise_std_from_second_differences():
    """(FE-6) on the stabilator 2-1-1-2 plus white noise: unbiased within 4 Monte Carlo
    standard errors over 200 seeded records, each within 15 % (≈ 4 of the estimator's own
    standard deviations, ≈ 3.5 % here); a noise-free pulse train gives 0."""
    t = np.arange(1001) * DT
    de = pulses(t, 1.0, (2, 1, 1, 2), (1, -1, 1, -1), 1.0)
    rng = np.random.default_rng(11)
    ratio = input_noise_std(de[:, None] + rng.standard_normal((len(t), 200)) * DE_NOISE) / DE_NOISE
    assert abs(ratio.mean() - 1.0) < 4 * ratio.std(ddof=1) / np.sqrt(len(ratio)), ratio.mean()
    assert np.all(np.abs(ratio - 1.0) < 0.15), (ratio.min(), ratio.max())
    assert input_noise_std(de)[0] == 0.0


def test_correlated_predictor_and_its_derivatives_are_exact():
    """(FE-5) with the noise of a measured input (process noise −Γ_u δ, measurement noise −D_u δ):
    K = (ΦPCᵀ + S_c)S⁻¹ and P = ΦPΦᵀ + Q − KSKᵀ hold, the predictor is stable, and ∂K, ∂S
    agree with central differences of the solver in every kind of direction."""
    A, B, C, D = short_period_matrices(**short_period_truth(), V_o=TRIM["V_fps"])
    Aa, Ba, Ca, _ = gust_augmented(A, B, C, D, 0, 2.0)
    Phi, Gam, _ = discretize(Aa, Ba, DT)
    V = noise_basis(Aa, noise_inputs(3, (), 0), DT)[0]

    def noise(s):  # s: gust spectral density, input variance, R scale, Φ and C perturbations
        Gu, Du = Gam[:, :1], D[:, :1]
        return (Phi + s[3] * np.diag([1e-3, -2e-3, 1e-3]), Ca + s[4] * 0.1 * np.ones_like(Ca),
                s[0] * V + s[1] * Gu @ Gu.T, np.diag(WHITE ** 2) * s[2] + s[1] * Du @ Du.T, s[1] * Gu @ Du.T)

    s0 = np.array([2e-4, DE_NOISE ** 2, 1.0, 0.0, 0.0])
    P, K, S = correlated_predictor(*noise(s0))
    Ph, Cc, Q, R, Sc = noise(s0)
    assert np.allclose(K, (Ph @ P @ Cc.T + Sc) @ np.linalg.inv(S), rtol=1e-10, atol=1e-14)
    assert np.allclose(P, Ph @ P @ Ph.T + Q - K @ S @ K.T, rtol=1e-9, atol=1e-9 * np.abs(P).max())
    assert np.max(np.abs(np.linalg.eigvals(Ph - K @ Cc))) < 1
    scale = np.abs(s0) + np.array([0, 0, 0, 1, 1])
    dirs = [tuple(np.subtract(a, b) for a, b in zip(noise(s0 + scale * e), noise(s0))) for e in np.eye(5)]
    dPhi, dC, dQ, dR, dSc = (np.array(x) for x in zip(*dirs))  # each (5, ·, ·): noise() is linear in s
    _, dK, dS = correlated_predictor_derivatives(Ph, Cc, Q, R, Sc, P, K, S, dPhi, dC, dQ, dR, dSc)
    h = 1e-5
    for j, e in enumerate(np.eye(5)):
        _, K2, S2 = correlated_predictor(*noise(s0 + h * scale * e))
        _, K1, S1 = correlated_predictor(*noise(s0 - h * scale * e))
        assert np.allclose((K2 - K1) / (2 * h), dK[j], rtol=1e-5, atol=1e-6 * np.abs(dK[j]).max()), j
        assert np.allclose((S2 - S1) / (2 * h), dS[j], rtol=1e-5, atol=1e-6 * np.abs(dS[j]).max()), j


def test_gust_gradient_is_that_of_the_likelihood():
    """With the gust state and the stabilator noise, the scoring gradient equals central
    differences of the negative log-likelihood for a derivative, the gust's σ and τ and an R."""
    rec = gust_recording(500)
    fit = FilterError().fit(rec)
    start = dict(zip(fit.names, fit.params + 0.05 * np.abs(fit.params) * np.sin(np.arange(len(fit.params)))))
    grad = dict(zip(fit.names, FilterError(start=start, max_iterations=0).fit(rec).info["gradient"]))
    for name in ("Cm_alpha", "ln_sigma_gust", "ln_tau_gust", "R_q"):
        h = 1e-4 * abs(start[name])
        cost = [FilterError(start=start | {name: start[name] + s}, max_iterations=0).fit(rec).info["cost"]
                for s in (h, -h)]
        assert grad[name] == pytest.approx((cost[0] - cost[1]) / (2 * h), rel=1e-5), name


def test_coverage_in_the_campaign_turbulence_output_error_against_filter_error():
    """The turbulence campaign's structure, 40 seeded records: filter error's ±2σ intervals of
    the six derivatives cover the truth 0.90–0.99 pooled (240 intervals; binomial standard
    deviation ≈ 0.014 at 0.95, so 0.90 is > 3 of them away even if the six were as correlated
    as pairs) and each derivative at least 0.85 (0.95 − 3·0.034, the binomial standard deviation
    of 40); output error's are over-confident (pooled < 0.5). White noise on α and q's equations
    covered Cm_α 0.82 on the campaign, the gust without the stabilator noise 0.68."""
    runs = 40
    truth = np.array(list(SHORT_PERIOD.values()))
    oe_in, fe_in = [], []
    for r in range(runs):
        rec = gust_recording(600 + r)
        o, f = OutputError().fit(rec), FilterError().fit(rec)
        oe_in.append(np.abs(o.params[:6] - truth) <= 2 * o.bse[:6])
        fe_in.append(np.abs(f.params[:6] - truth) <= 2 * f.bse[:6])
    fe_in = np.array(fe_in, float)
    assert np.mean(oe_in) < 0.5, np.mean(oe_in)
    assert 0.90 <= fe_in.mean() <= 0.99, fe_in.mean()
    assert np.all(fe_in.mean(axis=0) >= 0.85), dict(zip(SHORT_PERIOD, fe_in.mean(axis=0)))
