"""Output error (seed Eqs. 25-29) and the linear models it fits (Eqs. 33-34), pinned to exact
truth: simulation against analytic solutions and scipy.signal.lsim, noise-free recovery of the
short-period and lateral derivatives, and Cramér-Rao bounds against Monte Carlo scatter."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import scipy.linalg
import scipy.signal
from scipy import stats

from estimators.output_error import (DivergenceError, NotIdentifiableError, OutputError, OutputErrorData,
                                     cramer_rao_bound, output_error_data, parameter_names)
from estimators.output_error_models import MODELS, affine_system, response, response_and_sensitivities
from estimators.regressors import Equation
from estimators.state_space import (expm_small, lateral_matrices, propagate, short_period_dimensional,
                                    short_period_matrices, short_period_nondimensional, simulate_linear)
from maneuvers.recording import FORMAT_ID, G0_FPS2, Recording

DT = 0.02
GEOMETRY = {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32}
MASS = {"mass_slug": 641.0, "Ix_slugft2": 9496.0, "Iy_slugft2": 57108.0, "Iz_slugft2": 63100.0,
        "Ixz_slugft2": 982.0}
TRIM = {"alpha_rad": np.deg2rad(5.0), "theta_rad": np.deg2rad(5.0), "V_fps": 420.0, "qbar_psf": 149.0,
        "de_rad": np.deg2rad(-2.0), "da_rad": 0.0, "dr_rad": 0.0}
SHORT_PERIOD = {"CZ_alpha": -3.62, "CZ_qhat": -31.4, "CZ_de": -0.19,
                "Cm_alpha": -0.081, "Cm_qhat": -5.93, "Cm_de": -0.529}
LATERAL = {"CY_beta": -1.146, "CY_phat": 0.2, "CY_rhat": 0.6, "CY_da": 0.02, "CY_dr": 0.05,
           "Cl_beta": -0.098, "Cl_phat": -0.38, "Cl_rhat": 0.11, "Cl_da": -0.06, "Cl_dr": 0.014,
           "Cn_beta": 0.083, "Cn_phat": -0.01, "Cn_rhat": -0.35, "Cn_da": -0.004, "Cn_dr": -0.042}
SP_NOISE = np.array([np.deg2rad(0.1), np.deg2rad(0.3), 0.01])  # alpha rad, q rad/s, az g
AZ_TRIM = -np.cos(TRIM["theta_rad"])


# ------------------------------------------------------------------------------- helpers
def pulses(t: np.ndarray, start: float, widths: tuple[float, ...], signs: tuple[int, ...], deg: float) -> np.ndarray:
    """Square pulses of the given widths (s) and signs from ``start``, amplitude ``deg``."""
    u, s = np.zeros_like(t), start
    for w, sign in zip(widths, signs):
        u[(t >= s - 1e-9) & (t < s + w - 1e-9)] = sign * np.deg2rad(deg)
        s += w
    return u


def make_recording(t: np.ndarray, **channels: np.ndarray) -> Recording:
    """A valid canonical recording at the trim point, with ``channels`` replacing the defaults."""
    n = len(t)
    base = {"V_fps": np.full(n, TRIM["V_fps"]), "alpha_rad": np.full(n, TRIM["alpha_rad"]),
            "beta_rad": np.zeros(n), "p_rps": np.zeros(n), "q_rps": np.zeros(n), "r_rps": np.zeros(n),
            "phi_rad": np.zeros(n), "theta_rad": np.full(n, TRIM["theta_rad"]), "psi_rad": np.zeros(n),
            "ax_g": np.full(n, np.sin(TRIM["theta_rad"])), "ay_g": np.zeros(n), "az_g": np.full(n, AZ_TRIM),
            "qbar_psf": np.full(n, TRIM["qbar_psf"]), "de_rad": np.full(n, TRIM["de_rad"])}
    base.update(channels)
    data = pd.DataFrame({"t_s": t, **{k: np.asarray(v, dtype=float) for k, v in base.items()}})
    meta = {"format": FORMAT_ID, "geometry": dict(GEOMETRY), "mass": dict(MASS), "trim": dict(TRIM)}
    return Recording(data=data, meta=meta, name="linear-model").validate()


def short_period_truth() -> dict[str, float]:
    return short_period_dimensional(**SHORT_PERIOD, qbar=TRIM["qbar_psf"], S=GEOMETRY["S_ft2"],
                                    cbar=GEOMETRY["cbar_ft"], m=MASS["mass_slug"], Iy=MASS["Iy_slugft2"],
                                    V=TRIM["V_fps"])


def lateral_system(derivatives: dict[str, float] = LATERAL):
    return lateral_matrices(derivatives, qbar=TRIM["qbar_psf"], V=TRIM["V_fps"], S=GEOMETRY["S_ft2"],
                            b=GEOMETRY["b_ft"], m=MASS["mass_slug"], Ix=MASS["Ix_slugft2"],
                            Iz=MASS["Iz_slugft2"], Ixz=MASS["Ixz_slugft2"], alpha_o=TRIM["alpha_rad"],
                            theta_o=TRIM["theta_rad"])


def short_period_recording(noise: np.ndarray | None = None, seed: int = 0, de: np.ndarray | None = None,
                           hold: str = "zoh") -> Recording:
    """Eq. 33 driven by the seed's stabilator 2-1-1-2 (1 deg, 1 s unit pulse from 1 s), 20 s at 50 Hz."""
    t = np.arange(1001) * DT
    de = pulses(t, 1.0, (2, 1, 1, 2), (1, -1, 1, -1), 1.0) if de is None else de
    _, y = simulate_linear(*short_period_matrices(**short_period_truth(), V_o=TRIM["V_fps"]), de, DT, hold=hold)
    if noise is not None:
        y = y + np.random.default_rng(seed).standard_normal(y.shape) * noise
    return make_recording(t, alpha_rad=TRIM["alpha_rad"] + y[:, 0], q_rps=y[:, 1], az_g=AZ_TRIM + y[:, 2],
                          de_rad=TRIM["de_rad"] + de)


def lateral_recording(da: np.ndarray | None = None, dr: np.ndarray | None = None) -> Recording:
    """Lateral model driven by an aileron doublet, then a rudder 2-1-1 (2 deg, 1 s pulses), 25 s."""
    t = np.arange(1251) * DT
    da = pulses(t, 1.0, (1, 1), (1, -1), 2.0) if da is None else da
    dr = pulses(t, 6.0, (2, 1, 1), (1, -1, 1), 2.0) if dr is None else dr
    _, y = simulate_linear(*lateral_system(), np.column_stack([da, dr]), DT)
    return make_recording(t, beta_rad=y[:, 0], p_rps=y[:, 1], r_rps=y[:, 2], phi_rad=y[:, 3], ay_g=y[:, 4],
                          da_rad=da, dr_rad=dr)


def perturbed(values: dict[str, float], fraction: float = 0.2) -> dict[str, float]:
    """Alternately −20 % and +20 %: equation-error-like starting values."""
    return {k: v * (1 - fraction if i % 2 == 0 else 1 + fraction) for i, (k, v) in enumerate(values.items())}


def max_relative_error(fit, truth: dict[str, float]) -> float:
    return max(abs(fit.param(k) / v - 1.0) for k, v in truth.items())


@pytest.fixture(scope="module")
def sp_recording() -> Recording:
    return short_period_recording()


@pytest.fixture(scope="module")
def lat_recording() -> Recording:
    return lateral_recording()


# ------------------------------------------------------------------------------- (a) simulation
@pytest.mark.parametrize("hold", ["zoh", "foh"])
def test_first_order_step_response_is_exact(hold):
    a, b = -0.7, 2.0
    t = np.arange(5001) * DT
    x, y = simulate_linear([[a]], [[b]], [[3.0]], [[0.5]], np.ones_like(t), DT, hold=hold)
    exact = b / a * (np.exp(a * t) - 1.0)
    np.testing.assert_allclose(x[:, 0], exact, rtol=0, atol=1e-12)
    np.testing.assert_allclose(y[:, 0], 3.0 * exact + 0.5, rtol=0, atol=1e-11)


@pytest.mark.parametrize("hold, interp", [("zoh", False), ("foh", True)])
def test_two_state_system_matches_lsim(hold, interp):
    A = np.array([[-1.2, 0.9], [-4.0, -1.5]])
    B = np.array([[0.3, 0.0], [-2.0, 1.0]])
    C = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, -0.2]])
    D = np.array([[0.0, 0.0], [0.0, 0.0], [0.1, 0.0]])
    t = np.arange(1500) * DT
    u = np.random.default_rng(1).standard_normal((len(t), 2))
    x0 = np.array([0.1, -0.2])
    x, y = simulate_linear(A, B, C, D, u, DT, x0, hold=hold)
    _, y_ref, x_ref = scipy.signal.lsim((A, B, C, D), u, t, X0=x0, interp=interp)
    np.testing.assert_allclose(x, x_ref, rtol=0, atol=1e-12)
    np.testing.assert_allclose(y, y_ref, rtol=0, atol=1e-12)


@pytest.mark.parametrize("scale", [1e-3, 0.3, 3.0, 40.0])
def test_matrix_exponential_matches_scipy(scale):
    E = np.random.default_rng(3).standard_normal((6, 6)) * scale
    got = expm_small(np.stack([E, -E]))
    for F, M in zip(got, (E, -E)):
        want = scipy.linalg.expm(M)
        np.testing.assert_allclose(F, want, rtol=0, atol=1e-13 * np.abs(want).max())


def test_propagate_matches_the_recursion_for_an_unstable_system():
    Phi = np.array([[1.0004, 0.1], [0.0, 0.97]])
    rng = np.random.default_rng(2)
    w, x0 = rng.standard_normal((4999, 2, 3)), rng.standard_normal((2, 3))
    ref = np.empty((5000, 2, 3))
    ref[0] = x0
    for k in range(4999):
        ref[k + 1] = Phi @ ref[k] + w[k]
    np.testing.assert_allclose(propagate(Phi, w, x0), ref, rtol=1e-11, atol=1e-11)


@pytest.mark.parametrize("model", ["short-period", "lateral"])
@pytest.mark.parametrize("hold", ["zoh", "foh"])
def test_sensitivities_are_the_derivatives_of_the_response(model, hold, sp_recording):
    spec = MODELS[model]
    data = output_error_data(sp_recording if model == "short-period" else lateral_recording(), model)
    system = affine_system(spec, data.flight)
    truth = SHORT_PERIOD if model == "short-period" else LATERAL
    theta = np.array([truth.get(n, 0.01) for n in spec.names])
    u1 = np.column_stack([data.u, np.ones(len(data.t))])
    x0 = 0.01 * np.ones(len(spec.states))
    _, S = response_and_sensitivities(system, theta, u1, x0, DT, hold)
    for j in range(len(theta)):
        h = 1e-5 * max(abs(theta[j]), 1e-2)
        up = response(system, theta + h * np.eye(len(theta))[j], u1, x0, DT, hold)[1]
        down = response(system, theta - h * np.eye(len(theta))[j], u1, x0, DT, hold)[1]
        np.testing.assert_allclose(S[j], (up - down) / (2 * h), rtol=0, atol=1e-6 * np.abs(S[j]).max())


# ------------------------------------------------------------------------------- (b) Eqs. 33-34
def test_eq34_round_trip_and_scale_factors():
    flight = {"qbar": 149.0, "S": 300.0, "cbar": 11.32, "m": 641.0, "Iy": 57108.0, "V": 420.0}
    dim = short_period_dimensional(**SHORT_PERIOD, **flight)
    qS = 149.0 * 300.0
    assert dim["Z_alpha"] == pytest.approx(qS / (641.0 * 420.0) * -3.62, rel=1e-15)
    assert dim["Z_q"] == pytest.approx(qS * 11.32 / (2 * 641.0 * 420.0 ** 2) * -31.4, rel=1e-15)
    assert dim["M_q"] == pytest.approx(qS * 11.32 ** 2 / (2 * 420.0 * 57108.0) * -5.93, rel=1e-15)
    assert dim["M_de"] == pytest.approx(qS * 11.32 / 57108.0 * -0.529, rel=1e-15)
    back = short_period_nondimensional(**dim, **flight)
    assert back == pytest.approx(SHORT_PERIOD, rel=1e-14)


def test_short_period_matrices_follow_eq33():
    A, B, C, D = short_period_matrices(-0.6, -0.02, -0.03, -0.7, -0.8, -4.0, V_o=420.0)
    np.testing.assert_array_equal(A, [[-0.6, 0.98], [-0.7, -0.8]])
    np.testing.assert_array_equal(B, [[-0.03], [-4.0]])
    k = 420.0 / G0_FPS2
    np.testing.assert_allclose(C, [[1, 0], [0, 1], [k * -0.6, k * -0.02]], rtol=1e-15)
    np.testing.assert_allclose(D, [[0], [0], [k * -0.03]], rtol=1e-15)


def test_lateral_matrices_solve_the_inertia_coupling():
    A, B, C, D = lateral_system()
    qSb = TRIM["qbar_psf"] * GEOMETRY["S_ft2"] * GEOMETRY["b_ft"]
    h = GEOMETRY["b_ft"] / (2 * TRIM["V_fps"])
    inertia = np.array([[MASS["Ix_slugft2"], -MASS["Ixz_slugft2"]], [-MASS["Ixz_slugft2"], MASS["Iz_slugft2"]]])
    moments = inertia @ np.hstack([A[1:3, :3], B[1:3]]) / qSb  # Cl, Cn per beta, p, r, da, dr
    for row, c in enumerate(("Cl", "Cn")):
        want = [LATERAL[f"{c}_beta"], LATERAL[f"{c}_phat"] * h, LATERAL[f"{c}_rhat"] * h,
                LATERAL[f"{c}_da"], LATERAL[f"{c}_dr"]]
        np.testing.assert_allclose(moments[row], want, rtol=1e-13)
    assert A[0, 2] == pytest.approx(-np.cos(TRIM["alpha_rad"]) + 0.6 * h * 149 * 300 / (641 * 420))
    assert A[3, 2] == pytest.approx(np.tan(TRIM["theta_rad"]))
    assert C[4, 0] == pytest.approx(149 * 300 / (641 * G0_FPS2) * -1.146)


# ------------------------------------------------------------------------------- (c) exact truth
@pytest.mark.parametrize("start", ["perturbed", "equation-error"])
def test_short_period_exact_truth_is_recovered(start, sp_recording):
    est = OutputError(start=perturbed(SHORT_PERIOD) if start == "perturbed" else None)
    fit = est.fit(sp_recording, Equation("Cm", ("alpha", "qhat", "de")))
    assert fit.info["converged"] and fit.info["iterations"] < 20
    assert fit.info["start_source"] == ("given" if start == "perturbed" else "equation-error")
    assert max_relative_error(fit, SHORT_PERIOD) < 1e-8
    truth = short_period_truth()
    assert max(abs(fit.info["dimensional"][k] / v - 1) for k, v in truth.items()) < 1e-8
    assert fit.param("bias_az") == pytest.approx(AZ_TRIM, abs=1e-10)  # a_z is used as measured
    assert np.abs(fit.residuals).max() < 1e-8


def test_exact_truth_with_first_order_hold(sp_recording):
    rec = short_period_recording(hold="foh")
    fit = OutputError(hold="foh", start=perturbed(SHORT_PERIOD)).fit(rec)
    assert max_relative_error(fit, SHORT_PERIOD) < 1e-8


def test_plain_arrays_are_fitted_from_state_equation_error_starts(sp_recording):
    data = output_error_data(sp_recording, "short-period")
    arrays = OutputErrorData(t=data.t, u=data.u, z=data.z, flight=data.flight)
    fit = OutputError().fit(arrays)
    assert fit.info["start_source"] == "state-equation-error"
    assert max_relative_error(fit, SHORT_PERIOD) < 1e-8


def test_model_fit_carries_the_output_error_record(sp_recording):
    fit = OutputError().fit(sp_recording)
    assert (fit.method, fit.domain, fit.dependent, fit.errors) == ("oe", "time", "alpha,q,az", "cramer-rao")
    assert fit.names == parameter_names("short-period")
    assert fit.names[6:] == ("bias_alphadot", "bias_qdot", "bias_alpha", "bias_q", "bias_az")
    assert fit.residuals.shape == fit.fitted.shape == (sp_recording.n, 3) and fit.n == sp_recording.n
    assert set(fit.info["r2"]) == {"alpha", "q", "az"}
    assert np.array(fit.info["R"]).shape == (3, 3)
    assert {"cost", "iterations", "converged", "flight", "matrices"} <= set(fit.info)
    json.dumps(fit.to_dict())


def test_model_is_chosen_from_the_equation(lat_recording):
    fit = OutputError().fit(lat_recording, Equation("Cl", ("beta", "phat")))
    assert fit.dependent == "beta,p,r,phi,ay" and fit.names[:2] == ("CY_beta", "CY_phat")
    with pytest.raises(ValueError, match="cannot choose"):
        OutputError().fit(lat_recording, Equation("alpha", ("beta",)))


# ------------------------------------------------------------------------------- (d) noise, CRB
def test_cramer_rao_bounds_match_monte_carlo_scatter(sp_recording):
    runs = 50
    fits = [OutputError().fit(short_period_recording(SP_NOISE, seed=100 + k)) for k in range(runs)]
    assert all(f.info["converged"] for f in fits)
    est = np.array([f.params for f in fits])
    names = fits[0].names
    truth = np.array([SHORT_PERIOD.get(n, 0.0) for n in names])
    truth[names.index("bias_az")] = AZ_TRIM
    crb = cramer_rao_bound(sp_recording, "short-period", dict(zip(names, truth)), SP_NOISE ** 2)
    bound = np.sqrt(np.diag(crb))
    # the bound the fits report (with their estimated R) is the bound at the truth
    np.testing.assert_allclose(np.mean([f.bse for f in fits], axis=0), bound, rtol=0.05)
    # family-wise level 1 %, Bonferroni over the parameters
    level = 0.01 / len(names)
    z = stats.norm.ppf(1 - level / 2)
    assert np.all(np.abs(est.mean(axis=0) - truth) < z * bound / np.sqrt(runs))
    # (n−1)s²/σ² ~ χ²(n−1): the scatter s over the bound σ lies in this band
    low, high = np.sqrt(stats.chi2.ppf([level / 2, 1 - level / 2], runs - 1) / (runs - 1))
    ratio = est.std(axis=0, ddof=1) / bound
    assert np.all((ratio > low) & (ratio < high)), dict(zip(names, ratio.round(3)))


# ------------------------------------------------------------------------------- (e) lateral
@pytest.mark.parametrize("start", ["perturbed", "equation-error"])
def test_lateral_exact_truth_is_recovered(start, lat_recording):
    est = OutputError(model="lateral", start=perturbed(LATERAL) if start == "perturbed" else None)
    fit = est.fit(lat_recording)
    assert fit.info["converged"]
    assert max_relative_error(fit, LATERAL) < 1e-8
    assert fit.names[15:] == ("bias_betadot", "bias_pdot", "bias_rdot", "bias_phidot",
                              "bias_beta", "bias_p", "bias_r", "bias_phi", "bias_ay")


# ------------------------------------------------------------------------------- (f) failures
@pytest.mark.parametrize("start", [None, SHORT_PERIOD])
def test_no_input_is_not_identifiable(start, sp_recording):
    quiet = short_period_recording(de=np.zeros(sp_recording.n))
    with pytest.raises(NotIdentifiableError, match=r"input 'de' never moves.*CZ_de, Cm_de"):
        OutputError(start=start).fit(quiet)


def test_inputs_moving_together_are_not_identifiable():
    t = np.arange(1251) * DT
    da = pulses(t, 1.0, (2, 1, 1), (1, -1, 1), 2.0)
    rec = lateral_recording(da=da, dr=0.5 * da)
    with pytest.raises(NotIdentifiableError, match="singular information matrix") as err:
        OutputError(model="lateral", start=LATERAL).fit(rec)
    assert "CY_da" in str(err.value) and "CY_dr" in str(err.value)
    with pytest.raises(NotIdentifiableError, match="CY_da"):  # equation error refuses first
        OutputError(model="lateral").fit(rec)


def test_an_exploding_starting_model_is_refused(sp_recording):
    with pytest.raises(DivergenceError, match="unstable"):
        OutputError(start={**SHORT_PERIOD, "Cm_alpha": 0.4}).fit(sp_recording)


def test_bad_options_are_refused(sp_recording):
    with pytest.raises(ValueError, match="hold"):
        OutputError(hold="cubic")
    with pytest.raises(ValueError, match="unknown parameters"):
        OutputError(start={"Cm_beta": 1.0}).fit(sp_recording)
    with pytest.raises(ValueError, match="unknown output-error model"):
        OutputError(model="phugoid").fit(sp_recording)
