"""Output error for any model (estimators.dynamic_models, estimators.output_error_general):
a nonlinear HFB-320-form model written as a model file recovers its own parameters, its
Cramér-Rao bounds cover the truth at their nominal rate over seeded realizations (one and
two maneuvers), the finite-difference engine reproduces the exact linear one, and output
error never fits a structure other than the one it reports."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from estimators.dynamic_models import (ManeuverData, Model, ModelDefinitionError, Parameter, load_model_file,
                                       simulate)
from estimators.output_error import OutputError, output_error_data
from estimators.output_error_general import fit_model
from estimators.output_error_models import MODELS
from estimators.regressors import Equation
from harness.cli import main
from harness.recording_io import write_recording

from tests.test_output_error import SHORT_PERIOD, SP_NOISE, TRIM, perturbed, short_period_recording

ROOT = Path(__file__).resolve().parents[1]
HFB = load_model_file(ROOT / "estimators" / "model_files" / "hfb320_model.py")
C = dict(HFB.constants)
V0, A0, DE0 = 100.0, 0.05, -0.05
QS = 0.5 * C["rho"] * V0 ** 2 * C["S"]
THRUST = 0.05 * QS / np.cos(A0)  # trim: V̇ = 0 with C_D0 = 0.05
HFB_TRUTH = {"CD0": 0.05, "CDa": 0.30, "CDV": 0.02, "CL0": (C["m"] * C["g"] - THRUST * np.sin(A0)) / QS,
             "CLa": 4.5, "CLa2": 3.0, "CLV": 0.1, "Cm0": -1.2 * 0.05, "Cma": -0.6, "Cmq": -15.0, "Cmde": -1.2,
             "CmV": 0.02}  # trimmed at V0, α0 = θ0, q = 0 with δe = −0.05 (C_m0 = −C_mδe δe)
HFB_NOISE = np.array([0.2, np.radians(0.1), np.radians(0.1), np.radians(0.2), np.radians(1.0), 0.05, 0.1])
X_TRIM = np.array([V0, A0, A0, 0.0])


def elevator(n: int, dt: float, widths=(3, 2, 1, 1), unit: float = 0.5, amp_deg: float = 2.0) -> np.ndarray:
    """δe: a multistep (default 3-2-1-1 with a 0.5 s unit) from 1 s about the trim −0.05 rad."""
    t, u, s = np.arange(n) * dt, np.zeros(n), 1.0
    for k, w in enumerate(widths):
        u[(t >= s - 1e-9) & (t < s + w * unit - 1e-9)] = (-1) ** k * np.radians(amp_deg)
        s += w * unit
    return DE0 + u


def hfb_outputs(u: np.ndarray, dt: float, x0: np.ndarray = X_TRIM, sub: int = 4) -> np.ndarray:
    """Noise-free outputs of the model at the truth, integrated with a step of dt/sub."""
    n = len(u)
    fine = ManeuverData(np.arange(n * sub) * dt / sub, np.repeat(u, sub), np.zeros((n * sub, 7)))
    th = np.array([HFB_TRUTH[p] for p in HFB.parameter_names])[:, None]
    _, y = simulate(HFB, fine, th, x0[:, None], {**C, "thrust": THRUST})
    return y[::sub, :, 0]


def hfb_data(u: np.ndarray, dt: float, seed: int | None, x0: np.ndarray = X_TRIM, name: str = "") -> ManeuverData:
    y = hfb_outputs(u, dt, x0)
    if seed is not None:
        y = y + np.random.default_rng(seed).standard_normal(y.shape) * HFB_NOISE
    return ManeuverData(np.arange(len(u)) * dt, u, y, constants={"thrust": THRUST}, name=name)


TRUTH_VECTOR = np.array([HFB_TRUTH[p] for p in HFB.parameter_names])


# ------------------------------------------------------------------------------- the specification
def test_model_file_defines_a_frozen_model():
    assert isinstance(HFB, Model) and HFB.states == ("V", "alpha", "theta", "q")
    assert len(HFB.parameters) == 12 and HFB.outputs[-2:] == ("ax", "az")
    with pytest.raises(Exception):
        HFB.name = "other"


def test_noise_free_data_give_the_truth():
    u = elevator(600, 0.02)
    fit = OutputError(model=HFB).fit(hfb_data(u, 0.02, None))
    assert fit.info["converged"] and fit.info["sensitivities"] == "finite-difference"
    for name, value in HFB_TRUTH.items():
        assert fit.param(name) == pytest.approx(value, rel=1e-5, abs=1e-7), name
    np.testing.assert_allclose([fit.param(f"x0_{s}") for s in HFB.states], X_TRIM, atol=1e-7)


def test_hfb320_recovers_its_parameters_within_two_standard_errors():
    u = elevator(600, 0.02)
    fit = OutputError(model=HFB).fit(hfb_data(u, 0.02, seed=1))
    assert fit.info["converged"] and fit.errors == "cramer-rao"
    z = (np.array([fit.param(n) for n in HFB.parameter_names]) - TRUTH_VECTOR) / fit.bse[:12]
    assert np.all(np.abs(z) < 2.0), dict(zip(HFB.parameter_names, z.round(2)))
    json.dumps(fit.to_dict())


def _coverage(fits) -> tuple[float, np.ndarray]:
    est = np.array([f.params[:12] for f in fits])
    se = np.array([f.bse[:12] for f in fits])
    inside = np.abs(est - TRUTH_VECTOR) <= 2 * se
    return float(inside.mean()), est


@pytest.mark.slow
@pytest.mark.parametrize("maneuvers", [1, 2])
def test_cramer_rao_coverage_over_seeded_realizations(maneuvers):
    """±2σ intervals of the 12 parameters over 50 realizations cover the truth 0.90–0.99 of the
    time (nominal 0.954; 600 intervals, binomial s.d. 0.009 if independent), and the Monte Carlo
    means are unbiased. Two maneuvers: a 3-2-1-1 and a doublet from another initial state, each
    with its own x₀, fitted together."""
    dt, runs = 0.04, 50
    if maneuvers == 1:
        inputs = [(elevator(300, dt), X_TRIM)]
    else:
        inputs = [(elevator(150, dt), X_TRIM),
                  (elevator(150, dt, widths=(1, 1), unit=1.0, amp_deg=-3.0), X_TRIM + [2.0, 0.01, 0.0, 0.0])]
    clean = [hfb_outputs(u, dt, x0) for u, x0 in inputs]
    start = {**HFB_TRUTH}
    fits = []
    for r in range(runs):
        rng = np.random.default_rng(1000 + r)
        data = [ManeuverData(np.arange(len(u)) * dt, u, y + rng.standard_normal(y.shape) * HFB_NOISE,
                             constants={"thrust": THRUST}) for (u, _), y in zip(inputs, clean)]
        fits.append(fit_model(HFB, data, start=start))
    assert all(f.info["converged"] for f in fits)
    if maneuvers == 2:
        assert fits[0].names[12:] == ("x0_V#1", "x0_alpha#1", "x0_theta#1", "x0_q#1",
                                      "x0_V#2", "x0_alpha#2", "x0_theta#2", "x0_q#2")
    coverage, est = _coverage(fits)
    assert 0.90 <= coverage <= 0.99, coverage
    se = np.mean([f.bse[:12] for f in fits], axis=0)
    assert np.all(np.abs(est.mean(axis=0) - TRUTH_VECTOR) < 4 * se / np.sqrt(runs))


# ------------------------------------------------------------------------------- the built-ins
def test_built_in_models_are_instances_of_the_specification():
    from estimators.dynamic_models import ModelProtocol
    for spec in MODELS.values():
        assert isinstance(spec, ModelProtocol)
        assert tuple(p.name for p in spec.parameters) == spec.names


def test_finite_difference_engine_reproduces_the_exact_linear_one():
    """The short-period ModelSpec through the general engine (RK4, finite differences, x₀ fixed
    at 0 as the linear engine fixes it) gives the exact engine's estimates and bounds."""
    rec = short_period_recording(SP_NOISE, seed=3)
    exact = OutputError(start=perturbed(SHORT_PERIOD)).fit(rec)
    d = output_error_data(rec, "short-period")
    spec = MODELS["short-period"]
    data = ManeuverData(d.t[:400], d.u[:400], d.z[:400], constants=d.flight.as_dict(), x0=np.zeros(2))
    short = OutputError(start=dict(zip(exact.names, exact.params))).fit(
        type(d)(t=d.t[:400], u=d.u[:400], z=d.z[:400], flight=d.flight))
    general = fit_model(spec, [data], start=dict(zip(exact.names, exact.params)), x0="fixed")
    assert np.all(np.abs(general.params - short.params) < 0.02 * short.bse), (general.params - short.params) / short.bse
    np.testing.assert_allclose(general.bse, short.bse, rtol=1e-3)


# ------------------------------------------------------------------------------- bounds and errors
def test_a_bound_holds_and_is_reported():
    u = elevator(600, 0.02)
    params = tuple(Parameter(p.name, p.start, lower=-14.0) if p.name == "Cmq" else p for p in HFB.parameters)
    capped = Model(**{**{f: getattr(HFB, f) for f in HFB.__dataclass_fields__}, "parameters": params})
    fit = OutputError(model=capped).fit(hfb_data(u, 0.02, seed=2))
    assert fit.param("Cmq") == -14.0  # the truth, -15, is beyond it
    assert any("at a bound: Cmq" in w for w in fit.warnings)


def test_bad_models_are_refused(tmp_path):
    with pytest.raises(ModelDefinitionError, match="not within its bounds"):
        Parameter("a", 2.0, upper=1.0)
    with pytest.raises(ModelDefinitionError, match="repeat"):
        Model("m", ("x", "x"), (), ("x",), {"a": 1.0}, lambda *a: (0, 0), lambda *a: (0,))
    wrong = Model("m", ("x",), ("de",), ("x",), {"a": -1.0}, lambda t, x, u, p, c: (x[0], x[0]),
                  lambda t, x, u, p, c: (x[0],))
    data = ManeuverData(np.arange(20) * 0.1, np.ones(20), np.zeros(20))
    with pytest.raises(ModelDefinitionError, match="dynamics returned 2 values, needs 1"):
        OutputError(model=wrong).fit(data)
    empty = tmp_path / "empty.py"
    empty.write_text("x = 1\n")
    with pytest.raises(ModelDefinitionError, match="defines no 'model'"):
        load_model_file(empty)
    broken = tmp_path / "broken.py"
    broken.write_text("raise RuntimeError('boom')\n")
    with pytest.raises(ModelDefinitionError, match="RuntimeError: boom"):
        load_model_file(broken)
    with pytest.raises(ValueError, match="takes no equation"):
        OutputError(model=HFB).fit(data, Equation("Cm", ("alpha",)))


# ------------------------------------------------------------------------------- no silent structure
def test_regressors_the_model_does_not_have_are_refused():
    rec = short_period_recording()
    with pytest.raises(ValueError, match="no alphadot_hat term in CZ"):
        OutputError().fit(rec, Equation("CZ", ("alpha", "qhat", "de", "alphadot_hat")))
    with pytest.raises(ValueError, match="has no CL equation"):
        OutputError().fit(rec, Equation("CL", ("alpha",)))


SP_FILE = '''
import numpy as np
from estimators.dynamic_models import Model, Parameter

def dynamics(t, x, u, p, c):
    alpha, q = x
    da, de = alpha - c["trim_alpha_rad"], u[0] - c["trim_de_rad"]
    return (p["Za"] * da + (1 + p["Zq"]) * q + p["Zde"] * de,
            p["Ma"] * da + p["Mq"] * q + p["Mde"] * de)

def observe(t, x, u, p, c):
    return x[0], x[1]

model = Model("short-period-dimensional", ("alpha", "q"), ("de",), ("alpha", "q"),
              {"Za": -1.0, "Zq": 0.0, "Zde": 0.0, "Ma": -1.0, "Mq": -1.0, "Mde": -1.0}, dynamics, observe)
'''


def test_estimate_refuses_regressors_and_takes_a_model_file(tmp_path, capsys):
    path = write_recording(short_period_recording(), tmp_path / "sp.csv")
    rc = main(["estimate", "--recording", str(path), "--dependent", "CZ", "--regressors",
               "alpha,qhat,de,alphadot_hat", "--method", "oe"])
    err = capsys.readouterr().err
    assert rc == 2 and "no alphadot_hat term in CZ" in err
    model_file = tmp_path / "sp_model.py"
    model_file.write_text(SP_FILE)
    out_json = tmp_path / "fit.json"
    rc = main(["estimate", "--recording", str(path), "--method", "oe", "--model-file", str(model_file),
               "--json", str(out_json)])
    out = capsys.readouterr().out
    assert rc == 0 and "model short-period-dimensional" in out
    from tests.test_output_error import short_period_truth
    truth = short_period_truth()
    got = {p["name"]: p["estimate"] for p in json.loads(out_json.read_text())["parameters"]}
    for mine, theirs in (("Za", "Z_alpha"), ("Zq", "Z_q"), ("Zde", "Z_de"), ("Ma", "M_alpha"), ("Mq", "M_q"),
                         ("Mde", "M_de")):
        assert got[mine] == pytest.approx(truth[theirs], rel=1e-5), mine
    rc = main(["estimate", "--recording", str(path), "--method", "oe", "--model-file", str(model_file),
               "--regressors", "alpha"])
    assert rc == 2 and "leave out --dependent and --regressors" in capsys.readouterr().err
