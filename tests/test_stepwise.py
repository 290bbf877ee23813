"""Stepwise regression (estimators.stepwise): selection of the true terms, the false-inclusion
rate of F-to-enter 4 against its F(1, ν) distribution, forced terms, exact recovery, collinear
candidates, and that nothing ever waits for input."""
from __future__ import annotations

import builtins

import numpy as np
import pytest
from scipy import stats

from estimators.regressors import RegressionData
from estimators.stepwise import StepwiseResult, StepwiseSpec, stepwise_regression

TRUE = {"x1": 2.0, "x3": -0.5}
BIAS = 0.1
SPURIOUS = ("x2", "x4", "x5", "x6", "x7", "x8")


def library(seed: int, sigma: float, n: int = 400) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """z = 2 x1 − 0.5 x3 + 0.1 + σ·white noise over 8 candidates: x2 correlated with x1 (r = 0.8),
    x4 with x3 (r ≈ 0.7), x5 nearly the whole signal (x1 − 0.25 x3 + 0.2 e, so it enters first
    and must later leave), x6-x8 independent."""
    rng = np.random.default_rng(seed)
    x1, x3 = rng.standard_normal(n), rng.standard_normal(n)
    cand = {"x1": x1, "x2": 0.8 * x1 + 0.6 * rng.standard_normal(n), "x3": x3,
            "x4": 0.7 * x3 + 0.71 * rng.standard_normal(n),
            "x5": x1 - 0.25 * x3 + 0.2 * rng.standard_normal(n),
            "x6": rng.standard_normal(n), "x7": rng.standard_normal(n), "x8": rng.standard_normal(n)}
    z = TRUE["x1"] * x1 + TRUE["x3"] * x3 + BIAS + sigma * rng.standard_normal(n)
    return z, cand


def false_inclusions(results: list[StepwiseResult]) -> int:
    return sum(len(set(r.selected) - set(TRUE)) for r in results)


def binomial_bounds(trials: int, p: float) -> tuple[float, float]:
    return stats.binom.interval(0.999, trials, p)


# ---------------------------------------------------------------- the true model is found
def test_selects_exactly_the_true_terms_for_20_seeds() -> None:
    removals = 0
    for seed in range(20):
        z, cand = library(seed, sigma=0.1)
        res = stepwise_regression(z, cand)
        assert set(res.selected) == set(TRUE), (seed, res.summary())
        assert res.fit.names[-1] == "bias" and set(res.fit.names[:-1]) == set(TRUE)
        for name, value in TRUE.items():
            assert abs(res.fit.param(name) - value) < 4 * res.fit.std_error(name)
        assert abs(res.fit.param("bias") - BIAS) < 4 * res.fit.std_error("bias")
        removals += sum(h.action == "remove" for h in res.history)
    assert removals > 0  # x5 enters first and the backward step takes it out again


def test_false_inclusion_rate_of_f_to_enter_4() -> None:
    """Derivation: once x1 and x3 are in (p = 3 parameters with the bias), the partial F of a
    candidate whose true coefficient is zero has the F(1, N − p − 1) distribution whatever its
    correlation with x1, x3 (white Gaussian equation error, regressors fixed). So each of the 6
    spurious candidates ends up in the model with probability q = P(F(1, N − 4) > 4) ≈ 0.046
    (t-ratio above 2), nearly independently, and the count over R runs is ≈ Binomial(6R, q).
    Under rule 'F' this holds at any noise level; under 'F+PSE' entry also needs
    F > σ²_max/s², which only F = 4 governs when σ²_max/s² < 4 (poor fits, R² < 0.75)."""
    n, runs = 500, 200
    q = stats.f.sf(4.0, 1, n - 4)
    assert 0.044 < q < 0.048
    lo, hi = binomial_bounds(6 * runs, q)
    quiet = [stepwise_regression(*library(1000 + s, sigma=0.1, n=n), rule="F") for s in range(runs)]
    count = false_inclusions(quiet)
    assert lo <= count <= hi, (count, 6 * runs * q, lo, hi)
    assert all(set(TRUE) <= set(r.selected) for r in quiet)
    # The default rule at the same (low) noise: entering needs F > σ²_max/s² ≈ 425, so none.
    default = [stepwise_regression(*library(1000 + s, sigma=0.1, n=n)) for s in range(60)]
    assert false_inclusions(default) == 0
    assert any("would not lower PSE" in r.stop_reason for r in default)


def test_false_inclusion_rate_under_the_default_rule_at_high_noise() -> None:
    """σ = 3: σ²_max/s² ≈ (4.25 + 9)/9 ≈ 1.5 < 4, so F-to-enter 4 is the binding test of the
    default 'F+PSE' rule and the count is again ≈ Binomial(6R, P(F(1, N − 4) > 4))."""
    n, runs = 3000, 200
    q = stats.f.sf(4.0, 1, n - 4)
    lo, hi = binomial_bounds(6 * runs, q)
    res = [stepwise_regression(*library(5000 + s, sigma=3.0, n=n)) for s in range(runs)]
    count = false_inclusions(res)
    assert lo <= count <= hi, (count, 6 * runs * q, lo, hi)
    assert sum(set(TRUE) <= set(r.selected) for r in res) >= runs - 4


# ---------------------------------------------------------------- options and edge cases
def test_forced_term_enters_first_and_stays() -> None:
    z, cand = library(3, sigma=0.1)
    res = stepwise_regression(z, cand, forced=("x7",))
    assert res.selected[0] == "x7" and set(res.selected) == {"x7", *TRUE}
    assert res.history[1].action == "force" and res.history[1].name == "x7"
    f = res.partial_f["x7"]
    assert f < 4.0  # a pure-noise term: it would have been removed had it not been forced
    assert [c for c in res.candidates if c.name == "x7"][0].forced
    assert not any(h.action == "remove" and h.name == "x7" for h in res.history)


def test_noise_free_exact_case_recovers_coefficients() -> None:
    z, cand = library(4, sigma=0.0)
    for rule in ("F+PSE", "F"):
        res = stepwise_regression(z, cand, rule=rule)
        assert set(res.selected) == set(TRUE), (rule, res.summary())
        for name, value in TRUE.items():
            assert abs(res.fit.param(name) - value) < 1e-10
        assert abs(res.fit.param("bias") - BIAS) < 1e-10


def test_collinear_duplicate_candidate_is_skipped_with_a_note() -> None:
    z, cand = library(5, sigma=0.1)
    cand["x1_copy"] = 3.0 * cand["x1"]
    cand["x1_plus_x3"] = cand["x1"] + cand["x3"]
    res = stepwise_regression(z, cand)
    # with x1 in, x3 and x1 + x3 span the same model: whichever enters, the other is skipped
    assert "x1" in res.selected and len(res.selected) == 2
    other = ({"x3", "x1_plus_x3"} - set(res.selected)).pop()
    skipped = {h.name for h in res.history if h.action == "skip"}
    assert {"x1_copy", other} <= skipped
    ref = stepwise_regression(z, {k: v for k, v in cand.items() if k not in ("x1_copy", "x1_plus_x3")})
    np.testing.assert_allclose(res.fit.fitted, ref.fit.fitted, atol=1e-12)
    assert all("linearly dependent" in h.note for h in res.history if h.action == "skip")
    table = {c.name: c for c in res.candidates}
    assert np.isnan(table["x1_copy"].partial_f) and "linearly dependent" in table["x1_copy"].note
    # whatever the order of the library, only one of a pair of exact copies can enter
    first = {"x1_copy": cand["x1_copy"], **{k: v for k, v in cand.items() if k != "x1_copy"}}
    res2 = stepwise_regression(z, first)
    assert len({"x1", "x1_copy"} & set(res2.selected)) == 1 and len(res2.selected) == 2
    np.testing.assert_allclose(res2.fit.fitted, ref.fit.fitted, atol=1e-12)


def test_runs_without_interaction(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*_args, **_kwargs):
        raise AssertionError("stepwise_regression asked for input")

    monkeypatch.setattr(builtins, "input", refuse)
    monkeypatch.setattr("sys.stdin", None)
    res = stepwise_regression(*library(6, sigma=0.1))
    assert res.history[-1].action == "stop" and res.stop_reason


def test_partial_f_table_matches_its_definition() -> None:
    """F = (SSE_without − SSE_with) / s²_with, s²_with = SSE_with / (N − p_with)."""
    z, cand = library(7, sigma=0.5, n=300)
    res = stepwise_regression(z, cand)
    n = len(z)

    def sse(names: list[str]) -> tuple[float, int]:
        A = np.column_stack([cand[k] for k in names] + [np.ones(n)])
        v = z - A @ np.linalg.lstsq(A, z, rcond=None)[0]
        return float(v @ v), A.shape[1]

    sel = list(res.selected)
    for c in res.candidates:
        if c.included:
            with_, p = sse(sel)
            without, _ = sse([k for k in sel if k != c.name])
        else:
            with_, p = sse(sel + [c.name])
            without, _ = sse(sel)
        assert c.partial_f == pytest.approx((without - with_) / (with_ / (n - p)), rel=1e-8), c.name


def test_history_and_fit_reuse_modelfit_statistics() -> None:
    z, cand = library(8, sigma=0.2)
    res = stepwise_regression(z, cand, dependent="Cm")
    last = res.history[-1]
    assert last.pse == pytest.approx(res.fit.pse, rel=1e-14)
    assert last.r2 == pytest.approx(res.fit.r2, rel=1e-14) and last.s2 == pytest.approx(res.fit.s2, rel=1e-14)
    assert res.fit.method == "stepwise" and res.fit.dependent == "Cm" and res.fit.collinearity is not None
    mse = float(np.mean(res.fit.residuals**2))
    assert res.fit.pse == pytest.approx(mse + np.var(z) * 3 / len(z), rel=1e-12)
    adds = [h for h in res.history if h.action == "add"]
    assert all(h.partial_f > 4.0 for h in adds)
    assert "stepwise regression" in res.summary()


def test_accepts_regression_data() -> None:
    z, cand = library(9, sigma=0.1)
    names = tuple(cand)
    data = RegressionData.from_arrays(z, np.column_stack([cand[k] for k in names]), names, 0.02, dependent="Cm")
    res = stepwise_regression(None, data, forced=("x6",))
    assert res.selected[0] == "Cm_x6" and set(res.selected) == {"Cm_x6", "Cm_x1", "Cm_x3"}
    assert res.fit.names[-1] == "bias" and res.fit.dependent == "Cm" and res.fit.info["dt"] == 0.02


def test_settings_are_validated_and_max_terms_is_honoured() -> None:
    z, cand = library(10, sigma=0.1)
    with pytest.raises(ValueError, match="f_out"):
        stepwise_regression(z, cand, f_in=2.0, f_out=4.0)
    with pytest.raises(ValueError, match="rule"):
        stepwise_regression(z, cand, rule="AIC")
    with pytest.raises(KeyError, match="not a candidate"):
        stepwise_regression(z, cand, forced=("x9",))
    with pytest.raises(ValueError, match="shape"):
        stepwise_regression(z, {**cand, "short": np.ones(3)})
    res = stepwise_regression(z, cand, max_terms=1)
    assert len(res.selected) == 1 and "max_terms" in res.stop_reason
    spec = StepwiseSpec()
    with pytest.raises(AttributeError):
        spec.f_in = 1.0  # type: ignore[misc]
    nobias = stepwise_regression(z - BIAS, cand, bias=False)
    assert set(nobias.selected) == set(TRUE) and "bias" not in nobias.fit.names
