"""Equation-error estimators and the ModelFit result, pinned to exact linear systems."""
from __future__ import annotations

import json

import numpy as np
import pytest

from estimators.equation_error import EquationErrorFrequency, EquationErrorTime, detrend
from estimators.least_squares import SingularRegressorsError, least_squares
from estimators.methods import make_estimator, parse_frequencies
from estimators.regressors import Equation, RegressionData
from maneuvers.recording import Recording
from models.errors import OptionError
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
    ci = np.asarray(fit.conf_int(k=2))  # the seed's estimate ± 2 standard errors
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
    e = detrend(x, "endpoints")
    assert e[0] == pytest.approx(0) and e[-1] == pytest.approx(0, abs=1e-12)
    line = 5 * np.linspace(0, 1, 11) - 1
    assert np.allclose(detrend(line, "lstsq"), 0, atol=1e-12)
    # the default is the least-squares line: its residual is orthogonal to 1 and t
    r = detrend(x)
    np.testing.assert_allclose([r.sum(), r @ np.arange(11)], 0.0, atol=1e-12)


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


def test_autoregressive_autocorrelation_option_widens_the_bias_terms_bound(tmp_path, shared_dir):
    """``autocorrelation='ar'`` (estimators.colored): a bias term's colored bound is no longer
    shrunk by Eq. 39's estimates summing to zero; the choice is in ``info`` and on the command
    line, and it needs colored errors."""
    d = _coloured_problem(0.9)
    sample = EquationErrorTime(errors="colored").fit(d)
    ar = EquationErrorTime(errors="colored", autocorrelation="ar").fit(d)
    np.testing.assert_array_equal(ar.params, sample.params)
    assert ar.bse["bias"] > 1.5 * sample.bse["bias"]
    assert ar.info["autocorrelation"] == "ar" and sample.info["autocorrelation"] == "sample"
    with pytest.raises(OptionError, match="autocorrelation applies to the colored errors"):
        EquationErrorTime(autocorrelation="ar")
    src = shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat"
    out = tmp_path / "fit.json"
    assert main(["estimate", "--recording", str(src), "--dependent", "Cn", "--regressors", "beta,phat,rhat,da,dr",
                 "--method", "ee-smooth", "--autocorrelation", "ar", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["options"]["autocorrelation"] == "ar"


def test_estimate_errors_are_clear(tmp_path, shared_dir, capsys):
    src = shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat"
    assert main(["estimate", "--recording", str(src), "--dependent", "Cn", "--regressors", "beta,warp"]) == 2
    assert "unknown regressor term 'warp'" in capsys.readouterr().err


# ---------------------------------------------------------------- defaults that follow the findings


def _coloured_problem(phi: float, seed: int = 3, n: int = 2001):
    """Broadband smooth regressors (20 random sines each, 0.1-1.5 Hz, as a maneuver's
    response) and AR(1) equation error with coefficient ``phi`` (white for phi = 0),
    innovations of standard deviation 0.01."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    X = np.column_stack([np.sin(2 * np.pi * np.multiply.outer(t, rng.uniform(0.1, 1.5, 20))
                                + rng.uniform(0, 2 * np.pi, 20)).sum(axis=1) for _ in range(2)])
    e = np.zeros(n)
    w = 0.01 * rng.normal(size=n)
    for i in range(1, n):
        e[i] = phi * e[i - 1] + w[i]
    return RegressionData.from_arrays(X @ [1.0, -0.5] + 0.2 + e, X, ("a", "b"), 0.02)


def test_ee_smooth_defaults_to_colored_bounds_ee_time_to_conventional():
    assert make_estimator("ee-smooth").errors == "colored"
    assert EquationErrorTime(smooth_regressors=True).errors == "colored"
    assert make_estimator("ee-time").errors == "conventional"
    assert make_estimator("ee-smooth", errors="conventional").errors == "conventional"
    d = _coloured_problem(0.0)
    fit = make_estimator("ee-smooth").fit(d)
    assert fit.errors == "colored" and "max_lag" in fit.info


def test_strongly_coloured_residuals_are_flagged_whichever_bounds():
    """AR(1) residuals with phi = 0.95 have, below 1.5 Hz, a spectral density about
    (1 - phi)^-2 / ((1 - phi^2)^-1) = (1 + phi)/(1 - phi) = 39 times their white equivalent,
    a standard-error ratio near 6 at the flat part of the spectrum (3-4 here): flagged with
    either bounds. White residuals give ratios of 1 within their sampling scatter (measured
    about 0.12 in standard error for these regressors), far inside [1/2, 1.5]: not flagged."""
    red = _coloured_problem(0.95)
    for errors in ("conventional", "colored"):
        fit = EquationErrorTime(errors=errors).fit(red)
        ratio = np.asarray(fit.info["colored_to_conventional_se"])
        assert ratio[:2].max() > 2.5
        msg = [w for w in fit.warnings if "strongly coloured" in w]
        assert len(msg) == 1 and ("colored errors" in msg[0]) == (errors == "conventional")
    for seed in range(20):
        white = EquationErrorTime().fit(_coloured_problem(0.0, seed))
        assert not any("coloured" in w for w in white.warnings)
        assert np.all(np.abs(np.asarray(white.info["colored_to_conventional_se"][:2]) - 1) < 0.4)


def test_frequency_band_names_and_the_seed_rule():
    from estimators.equation_error import frequency_band
    from estimators.fourier import seed_frequencies, seed_rule_frequencies
    f = seed_rule_frequencies(20.0)
    assert f[0] == pytest.approx(0.1) and f[-1] == pytest.approx(1.18) and len(f) == 28
    np.testing.assert_allclose(seed_rule_frequencies(10.0), seed_frequencies(), atol=1e-12)  # Eq. 18 is T = 10 s
    with pytest.raises(ValueError, match="too short"):
        seed_rule_frequencies(1.0)
    for name in ("eq18", "sidpac"):
        assert parse_frequencies(name) == name
        np.testing.assert_array_equal(frequency_band(name, 20.0), seed_frequencies())
    assert parse_frequencies("auto") == "auto"
    with pytest.raises(ValueError, match="frequency band"):
        EquationErrorFrequency(frequencies_hz="weekly")
    with pytest.raises(ValueError, match="detrend"):
        EquationErrorFrequency(detrend="quadratic")


def test_sidpac_convention_by_name_on_the_twin_otter(shared_dir):
    """SIDPAC parity needs Eq. 18's band and the end-point line, named explicitly: they give
    the same numbers as before the defaults changed (the README's Twin Otter table, 5 figures)
    and, to 1e-12, the same as spelling the options out."""
    from estimators.fourier import seed_frequencies
    from estimators.methods import SIDPAC_FREQUENCY_OPTIONS
    from harness.recording_io import read_recording
    rec = read_recording(shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat")
    eq = Equation("Cn", ("beta", "phat", "rhat", "da", "dr"), bias=False)
    named = make_estimator("ee-freq", **SIDPAC_FREQUENCY_OPTIONS).fit(rec, eq)
    spelled = EquationErrorFrequency(frequencies_hz=tuple(seed_frequencies()), detrend="endpoints").fit(rec, eq)
    np.testing.assert_allclose(named.params, spelled.params, rtol=1e-12, atol=0)
    np.testing.assert_allclose(named.bse, spelled.bse, rtol=1e-12, atol=0)
    np.testing.assert_allclose(named.params, [0.083647, -0.061, -0.20348, 0.0011649, -0.1332], rtol=5e-5)
    np.testing.assert_allclose(named.bse, [0.00117, 0.00499, 0.00411, 0.00178, 0.00192], rtol=5e-3)
    default = make_estimator("ee-freq").fit(rec, eq)
    T = (rec.n - 1) * rec.dt
    assert default.info["frequencies_hz"][0] == pytest.approx(2 / T) and default.info["detrend"] == "lstsq"


def test_thrust_follows_the_format_and_says_what_it_assumed(three_axis_exact):
    """No thrust channel: thrust is constant at trim (recording-format.md), said in the
    assumptions. No trim thrust either: 0, said in the assumptions and the warnings, and CX's
    bias moves by T/(q̄S)."""
    from estimators.regressors import regression_data
    rec = three_axis_exact
    no_channel = Recording(rec.data.drop(columns=[rec.column("thrust")]), rec.meta, "no-thrust")
    meta = {**rec.meta, "trim": {k: v for k, v in rec.meta["trim"].items() if k != "thrust_lbf"}}
    nothing = Recording(no_channel.data, meta, "no-trim-thrust")
    eq = Equation("CX", ("alpha", "qhat", "de"))
    recorded = EquationErrorTime().fit(rec, eq)
    at_trim = EquationErrorTime().fit(no_channel, eq)
    unknown = EquationErrorTime().fit(nothing, eq)
    assert recorded.assumptions == ()
    assert len(at_trim.assumptions) == 1 and "constant at its trim value" in at_trim.assumptions[0]
    assert not any("thrust" in w for w in at_trim.warnings)
    assert len(unknown.assumptions) == 1 and "taken as 0" in unknown.assumptions[0]
    assert any("zero thrust" in w for w in unknown.warnings)
    T, qS = rec.meta["trim"]["thrust_lbf"], rec.meta["trim"]["qbar_psf"] * rec.geometry["S_ft2"]
    shift = unknown.param("bias") - at_trim.param("bias")
    assert shift == pytest.approx(T / qS, rel=0.05)
    js = unknown.to_dict()
    assert js["assumptions"] == list(unknown.assumptions)
    assert "assumption: thrust" in unknown.summary()
    # Cm carries the thrust line's moment (offset -0.3 ft); CZ does not involve thrust
    assert regression_data(nothing, Equation("Cm", ("alpha",))).assumptions
    assert not regression_data(nothing, Equation("CZ", ("alpha",))).assumptions
    freq = make_estimator("ee-freq").fit(nothing, Equation("CX", ("alpha", "qhat", "de"), bias=False))
    assert freq.assumptions == unknown.assumptions


def test_estimate_command_defaults_and_the_sidpac_options(tmp_path, shared_dir):
    src = shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat"
    base = ["estimate", "--recording", str(src), "--dependent", "Cn", "--regressors", "beta,phat,rhat,da,dr"]
    out = tmp_path / "smooth.json"
    assert main(base + ["--method", "ee-smooth", "--json", str(out)]) == 0
    js = json.loads(out.read_text())
    assert js["errors"] == "colored" and "assumptions" in js
    assert any("strongly coloured" in w for w in js["warnings"])
    out = tmp_path / "sidpac.json"
    assert main(base + ["--method", "ee-freq", "--frequencies", "sidpac", "--detrend", "endpoints",
                        "--json", str(out)]) == 0
    assert json.loads(out.read_text())["parameters"][0]["estimate"] == pytest.approx(0.083647, rel=5e-5)


def test_derivative_transform_is_the_transform_of_the_detrended_derivative():
    """Integration by parts (no smoothing) against the transform of the exact derivative's
    samples, least-squares line removed: equal to the interpolation error."""
    from estimators.equation_error import derivative_transform
    from estimators.fourier import finite_fourier_transform
    dt = 0.02
    t = np.arange(1001) * dt
    y = np.sin(2.1 * t + 0.3) + 0.01 * t**2 + 0.5 * np.exp(-0.3 * t)  # not at rest at either end
    ydot = 2.1 * np.cos(2.1 * t + 0.3) + 0.02 * t - 0.15 * np.exp(-0.3 * t)
    f = np.arange(0.1, 1.21, 0.04)
    from estimators.equation_error import continuous_line
    ref = finite_fourier_transform(ydot - continuous_line(ydot, dt), dt, f)
    assert np.max(np.abs(derivative_transform(y, dt, f) - ref)) < 1e-6 * np.max(np.abs(ref))


def _short_period_steps(dt=0.02, T=20.0):
    """The seed's linear short period (Eq. 33 form) driven by a 2-1-1-2 whose steps fall on
    samples, discretised exactly (the input is constant between samples): alpha, q, de and
    the exact qdot at the samples (the sample at a step holding the new value)."""
    from scipy.linalg import expm
    A = np.array([[-1.2, 0.98], [-4.5, -1.6]])  # alpha, q
    B = np.array([-0.12, -11.0])
    n = round(T / dt) + 1
    t = np.arange(n) * dt
    u = np.where((t >= 1.0 - 1e-9) & (t < 3.0 - 1e-9), 1.0, 0.0) - np.where((t >= 3.0 - 1e-9) & (t < 4.0 - 1e-9), 1.0, 0.0)
    u = u + np.where((t >= 4.0 - 1e-9) & (t < 5.0 - 1e-9), 1.0, 0.0) - np.where((t >= 5.0 - 1e-9) & (t < 7.0 - 1e-9), 1.0, 0.0)
    u = np.radians(u)
    M = expm(np.block([[A, B[:, None]], [np.zeros((1, 3))]]) * dt)
    Phi, Gam = M[:2, :2], M[:2, 2]
    x = np.zeros((n, 2))
    for i in range(n - 1):
        x[i + 1] = Phi @ x[i] + Gam * u[i]
    xdot = x @ A.T + np.outer(u, B)
    return t, x[:, 0], x[:, 1], u, xdot[:, 1], np.array([A[1, 0], A[1, 1], B[1]])


def test_ee_freq_hold_removes_the_half_sample_bias_of_stepped_inputs():
    """q̇ differentiated from q (continuous) responds to a step at its instant; the cubic
    interpolant of the stepped de centres the jump half a sample early, and Eqs. 19-23 put
    the phase error into M_q (several per cent, noise-free). Held de removes it; with the
    sampled q̇ (jump sampled like de's) the default is exact and holding would be wrong."""
    from estimators.differentiation import smooth_derivative
    t, alpha, q, de, qdot, truth = _short_period_steps()
    X = np.column_stack([alpha, q, de])

    def err(z, **kw):
        d = RegressionData.from_arrays(z, X, ("alpha", "q", "de"), 0.02, dependent="Cm", bias=False)
        return np.asarray(EquationErrorFrequency(**kw).fit(d).params) / truth - 1

    assert np.max(np.abs(err(qdot))) < 1e-9  # sampled q̇: exact by default
    smoothed = smooth_derivative(q, 0.02, method=1)  # the seed's method 1, as for flight data
    default, held = err(smoothed), err(smoothed, hold=("de",))
    assert abs(default[1]) > 0.03  # M_q off by several per cent without any noise
    assert np.max(np.abs(held)) < 0.01 and abs(held[1]) < 0.2 * abs(default[1])
    force = RegressionData.from_arrays(qdot, X, ("alpha", "q", "de"), 0.02, dependent="CZ", bias=False)
    assert EquationErrorFrequency(hold=("de",)).fit(force).info["hold"] == []  # force equations untouched


def test_ee_freq_transform_and_hold_on_the_exact_truth_f16(three_axis_exact):
    """JSBSim's exact-truth F-16 (no structure error, noise-free), pitch rate differentiated
    by the seed's method 1 as in every noisy campaign: Cm_q̂ is biased by the default and
    recovered by ``hold`` with ``acceleration='transform'``."""
    from estimators.regressors import DataOptions
    rec = three_axis_exact
    eq = Equation("Cm", ("alpha", "qhat", "de"))
    truth = np.array([rec.meta["truth"]["derivatives"][f"Cm_{r}"]["local"] for r in eq.regressors])
    data = DataOptions(angular_acceleration="smooth-local")
    default = np.asarray(EquationErrorFrequency(data=data).fit(rec, eq).params) / truth - 1
    fit = EquationErrorFrequency(data=data, acceleration="transform", hold=("de",)).fit(rec, eq)
    fixed = np.asarray(fit.params) / truth - 1
    assert fit.info["acceleration"] == "transform" and fit.info["hold"] == ["de"]
    assert default[1] < -0.05
    assert abs(fixed[1]) < 0.002 and np.max(np.abs(fixed)) < 0.006
    recorded = EquationErrorFrequency(acceleration="transform").fit(rec, eq)  # q̇ recorded: nothing to do
    assert recorded.info["acceleration"] == "time"
    with pytest.raises(Exception, match="lstsq"):
        EquationErrorFrequency(acceleration="transform", detrend="endpoints")
