"""Equation-error estimators and the ModelFit result, pinned to exact linear systems."""
from __future__ import annotations

import json

import numpy as np
import pytest

from estimators.equation_error import EquationErrorFrequency, EquationErrorTime, detrend
from estimators.least_squares import SingularRegressorsError, least_squares
from estimators.methods import make_estimator, parse_frequencies
from estimators.regressors import RegressionData
from harness.cli import main


def _linear_system(n=2000, sigma=0.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    X = np.column_stack([np.sin(0.7 * t) + 0.3 * rng.standard_normal(n), np.cos(1.3 * t), rng.standard_normal(n)])
    theta = np.array([2.0, -0.5, 0.25])
    z = X @ theta + 0.1 + sigma * rng.standard_normal(n)
    return RegressionData.from_arrays(z, X, ("a", "b", "c"), 0.02), theta


def test_ols_recovers_exact_coefficients():
    d, theta = _linear_system()
    fit = EquationErrorTime().fit(d)
    assert np.allclose(fit.params, [*theta, 0.1], rtol=1e-12, atol=1e-13)
    assert fit.names == ("z_a", "z_b", "z_c", "bias")


def test_conventional_covariance_is_eq15():
    d, _ = _linear_system(sigma=0.05)
    fit = EquationErrorTime().fit(d)
    A = d.design()
    r = d.z - A @ fit.params
    s2 = r @ r / (len(r) - 4)  # Eq. 16
    assert fit.s2 == pytest.approx(s2, rel=1e-12)
    assert np.allclose(fit.cov, s2 * np.linalg.inv(A.T @ A), rtol=1e-9)  # Eq. 15
    assert np.allclose(fit.bse, np.sqrt(np.diag(fit.cov)))  # Eq. 17
    ci = fit.conf_int()
    assert np.allclose(ci[:, 1] - ci[:, 0], 4 * fit.bse)
    corr = fit.correlation  # Eq. 50
    assert np.allclose(np.diag(corr), 1) and np.all(np.abs(corr) <= 1 + 1e-12)


def test_complex_least_squares_equals_real_stacking():
    """Eqs. 19-23: complex data solved as real data with the imaginary parts stacked below,
    with σ̂² over m complex points (not 2m)."""
    rng = np.random.default_rng(3)
    X = rng.standard_normal((30, 2)) + 1j * rng.standard_normal((30, 2))
    z = X @ np.array([1.5, -0.7]) + 0.01 * (rng.standard_normal(30) + 1j * rng.standard_normal(30))
    ls = least_squares(X, z, ("a", "b"))
    A = np.vstack([X.real, X.imag])
    b = np.concatenate([z.real, z.imag])
    theta = np.linalg.solve(A.T @ A, A.T @ b)
    assert np.allclose(ls.theta, theta, rtol=1e-12)
    theta19 = np.linalg.solve(np.real(X.conj().T @ X), np.real(X.conj().T @ z))  # Eq. 19
    assert np.allclose(ls.theta, theta19, rtol=1e-10)
    resid = z - X @ ls.theta
    assert ls.s2 == pytest.approx(np.real(np.vdot(resid, resid)) / (30 - 2), rel=1e-12)  # Eq. 21


def test_frequency_domain_recovers_exact_system_without_bias():
    d, theta = _linear_system()
    fit = EquationErrorFrequency(frequencies_hz=tuple(np.arange(0.1, 2.0, 0.04))).fit(d)
    assert "bias" not in fit.names
    assert np.allclose(fit.params, theta, rtol=1e-10)
    assert fit.domain == "frequency" and fit.n == len(np.arange(0.1, 2.0, 0.04))


def test_detrend_end_points_and_least_squares():
    x = np.linspace(0, 1, 11) * 3 + 2 + np.sin(np.linspace(0, np.pi, 11))
    e = detrend(x)
    assert e[0] == pytest.approx(0) and e[-1] == pytest.approx(0, abs=1e-12)
    line = 5 * np.linspace(0, 1, 11) - 1
    assert np.allclose(detrend(line, "lstsq"), 0, atol=1e-12)


def test_singular_regressors_are_named():
    d, _ = _linear_system()
    X = np.column_stack([d.X, 2 * d.X[:, 0] - d.X[:, 1]])
    bad = RegressionData.from_arrays(d.z, X, ("a", "b", "c", "combo"), 0.02)
    with pytest.raises(SingularRegressorsError, match="combo") as exc:
        EquationErrorTime().fit(bad)
    assert "a" in str(exc.value) and "b" in str(exc.value)
    zero = RegressionData.from_arrays(d.z, np.column_stack([d.X, np.zeros(len(d.z))]), ("a", "b", "c", "dr"), 0.02)
    with pytest.raises(SingularRegressorsError, match="dr are identically zero"):
        EquationErrorTime().fit(zero)


def test_collinearity_warning_names_the_pair():
    rng = np.random.default_rng(1)
    a = rng.standard_normal(500)
    b = a + 0.05 * rng.standard_normal(500)
    z = a - b + 0.01 * rng.standard_normal(500)
    fit = EquationErrorTime().fit(RegressionData.from_arrays(z, np.column_stack([a, b]), ("q", "de"), 0.02))
    assert any("z_q and z_de" in w for w in fit.warnings)
    assert fit.collinearity.vif[0] > 100 and fit.collinearity.condition_number > 10


def test_summary_and_json_shape():
    d, _ = _linear_system(sigma=0.01)
    fit = EquationErrorTime().fit(d)
    js = fit.to_dict()
    for key in ("method", "domain", "n", "parameters", "s2", "r2", "covariance", "correlation", "warnings"):
        assert key in js
    assert js["parameters"][3]["name"] == "bias"
    json.dumps(js)
    assert "bias" in fit.summary() and "R2" in fit.summary()
    assert fit.pse > fit.s2 * (len(d.z) - 4) / len(d.z)


def test_method_registry_and_frequency_parsing():
    assert make_estimator("ee-smooth").method == "ee-smooth"
    assert np.allclose(parse_frequencies("0.2:0.04:1.2"), np.arange(26) * 0.04 + 0.2)
    with pytest.raises(ValueError, match="colored applies to the time-domain"):
        make_estimator("ee-freq", errors="colored")
    with pytest.raises(ValueError, match="unknown method"):
        make_estimator("magic")


@pytest.mark.parametrize("method,errors", [("ee-time", "conventional"), ("ee-time", "colored"),
                                           ("ee-freq", "conventional")])
def test_estimate_command_on_twin_otter(tmp_path, shared_dir, method, errors, capsys):
    src = shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat"
    out = tmp_path / "fit.json"
    assert main(["estimate", "--recording", str(src), "--dependent", "Cn", "--regressors",
                 "beta,phat,rhat,da,dr", "--method", method, "--errors", errors, "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    names = [p["name"] for p in d["parameters"]]
    assert names[:5] == ["Cn_beta", "Cn_phat", "Cn_rhat", "Cn_da", "Cn_dr"]
    assert ("bias" in names) == (method != "ee-freq")
    cn_beta = d["parameters"][0]["estimate"]
    assert 0.05 < cn_beta < 0.12  # directional stability of the Twin Otter
    assert "Cn_beta" in capsys.readouterr().out


def test_estimate_errors_are_clear(tmp_path, shared_dir, capsys):
    src = shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat"
    assert main(["estimate", "--recording", str(src), "--dependent", "Cn", "--regressors", "beta,warp"]) == 2
    assert "unknown regressor term 'warp'" in capsys.readouterr().err
