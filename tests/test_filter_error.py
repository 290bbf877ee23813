"""Filter error (estimators.filter_error) on the short period with process noise: output error's
±2σ intervals are over-confident there, filter error's cover the truth at their nominal rate
(seeded realizations); without process noise filter error agrees with output error."""
from __future__ import annotations

import numpy as np
import pytest

from estimators.filter_error import FilterError, kalman_predictor, kalman_predictor_derivatives
from estimators.methods import make_estimator
from estimators.output_error import OutputError
from estimators.state_space import discretize, short_period_matrices

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
        o, f = OutputError().fit(rec), make_estimator("fe").fit(rec)
        oe_in.append(np.abs(o.params[:6] - truth) <= 2 * o.bse[:6])
        fe_in.append(np.abs(f.params[:6] - truth) <= 2 * f.bse[:6])
    assert np.mean(oe_in) < 0.90, np.mean(oe_in)
    assert 0.90 <= np.mean(fe_in) <= 0.99, np.mean(fe_in)


def test_without_process_noise_filter_error_is_output_error():
    rec = short_period_recording(SP_NOISE, seed=7)
    o, f = OutputError().fit(rec), FilterError().fit(rec)
    assert f.names[:11] == o.names and f.names[11:] == ("Q_alpha", "Q_q", "R_alpha", "R_q", "R_az")
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
    fit = FilterError().fit(rec)
    start = dict(zip(fit.names, fit.params * (1 + 0.05 * np.sin(np.arange(len(fit.params))))))
    grad = dict(zip(fit.names, FilterError(start=start, max_iterations=0).fit(rec).info["gradient"]))
    for name in ("Cm_qhat", "bias_q", "Q_alpha", "R_az"):
        h = 1e-4 * abs(start[name])
        cost = [FilterError(start=start | {name: start[name] + s}, max_iterations=0).fit(rec).info["cost"]
                for s in (h, -h)]
        assert grad[name] == pytest.approx((cost[0] - cost[1]) / (2 * h), rel=1e-5), name
