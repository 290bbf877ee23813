"""Filter error (estimators.filter_error) on the short period with process noise: output error's
±2σ intervals are over-confident there, filter error's cover the truth at their nominal rate
(seeded realizations); without process noise filter error agrees with output error."""
from __future__ import annotations

import numpy as np
import pytest

from estimators.filter_error import FilterError
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
    assert f.names[:11] == o.names and f.names[11] == "K_alpha_alpha"
    for name in SHORT_PERIOD:
        assert abs(f.param(name) - o.param(name)) < 2 * f.std_error(name), name  # both unbiased here
