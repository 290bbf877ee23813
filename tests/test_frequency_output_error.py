"""Frequency-domain output error (estimators.frequency_output_error): exact on noise-free held-input
data (also when the record ends away from where it began), agreement with time-domain output error
within the standard errors, and Cramér-Rao coverage over seeded realizations."""
from __future__ import annotations

import numpy as np
import pytest

from estimators.frequency_output_error import FrequencyOutputError, harmonic_frequencies
from estimators.methods import make_estimator
from estimators.output_error import OutputError
from estimators.regressors import Equation

from tests.test_output_error import DT, SHORT_PERIOD, SP_NOISE, pulses, short_period_recording


def test_noise_free_held_input_data_give_the_truth():
    fit = FrequencyOutputError().fit(short_period_recording())
    assert fit.info["converged"] and fit.domain == "frequency" and fit.errors == "cramer-rao"
    for name, value in SHORT_PERIOD.items():
        assert fit.param(name) == pytest.approx(value, rel=1e-8), name


def test_a_record_ending_away_from_trim_is_exact_through_the_end_state_change():
    t = np.arange(1001) * DT
    de = pulses(t, 1.0, (2, 1, 1, 2, 20), (1, -1, 1, -1, 1), 1.0)  # ends on a held step
    fit = FrequencyOutputError().fit(short_period_recording(de=de))
    for name, value in SHORT_PERIOD.items():
        assert fit.param(name) == pytest.approx(value, rel=1e-8), name
    assert abs(fit.param("dx_alpha")) > 1e-3  # the state moved over the record


def test_harmonics_span_the_seed_band():
    f = harmonic_frequencies(20.0)
    assert f[0] == pytest.approx(0.1) and f[-1] == pytest.approx(1.2) and np.allclose(np.diff(f), 0.05)


def test_frequency_and_time_domain_agree_within_their_standard_errors():
    rec = short_period_recording(SP_NOISE, seed=5)
    td, fd = OutputError().fit(rec), make_estimator("oe-freq").fit(rec)
    for name in SHORT_PERIOD:
        # the difference of an efficient and a less efficient estimate has variance ≈ σ_fd² − σ_td²
        assert abs(fd.param(name) - td.param(name)) < 2 * fd.std_error(name), name
    assert np.all(fd.bse[:6] >= 0.9 * td.bse[:6])  # the band holds less information than the record


def test_cramer_rao_coverage_over_seeded_realizations():
    runs = 50
    fits = [FrequencyOutputError().fit(short_period_recording(SP_NOISE, seed=200 + k)) for k in range(runs)]
    truth = np.array(list(SHORT_PERIOD.values()))
    est = np.array([f.params[:6] for f in fits])
    se = np.array([f.bse[:6] for f in fits])
    coverage = float(np.mean(np.abs(est - truth) <= 2 * se))
    assert 0.90 <= coverage <= 0.99, coverage
    assert np.all(np.abs(est.mean(axis=0) - truth) < 4 * se.mean(axis=0) / np.sqrt(runs))


def test_regressors_the_model_does_not_have_are_refused():
    with pytest.raises(ValueError, match="no alphadot_hat term"):
        FrequencyOutputError().fit(short_period_recording(), Equation("Cm", ("alpha", "alphadot_hat")))
