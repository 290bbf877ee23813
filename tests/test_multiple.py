"""Combining maneuvers (estimators.multiple, seed §III.F, Eqs. 42-49), pinned to the algebra of
the seed's equations and to Monte Carlo truth."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from estimators.colored import colored_residual_covariance, residual_autocorrelation
from estimators.equation_error import EquationErrorFrequency, EquationErrorTime
from estimators.least_squares import SingularRegressorsError
from estimators.multiple import (
    colored_middle,
    concatenate,
    fit_a_priori,
    fit_concatenated,
    fit_frequency_combined,
    fit_sequential,
)
from estimators.regressors import RegressionData

THETA = np.array([1.5, -0.7, 0.4, 0.3])  # alpha, qhat, de, bias
NAMES = ("alpha", "qhat", "de")
DT = 0.02


def rel_err(a: np.ndarray, b: np.ndarray) -> float:
    """Largest error relative to the largest magnitude of b."""
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(b)))


def maneuver(rng: np.random.Generator, n: int, sigma: float, offset: float = 0.0) -> RegressionData:
    """Seeded random regressors (each maneuver centred differently) and white equation error."""
    X = rng.standard_normal((n, 3)) * np.array([1.0, 0.5, 2.0]) + offset
    z = X @ THETA[:3] + THETA[3] + sigma * rng.standard_normal(n)
    return RegressionData.from_arrays(z, X, NAMES, DT, dependent="Cm")


def design(d: RegressionData) -> np.ndarray:
    return d.design()


# ---------------------------------------------------------------- concatenation (Eq. 42)
def test_concatenate_stacks_rows_and_continues_time() -> None:
    rng = np.random.default_rng(0)
    ds = [maneuver(rng, n, 0.1) for n in (50, 80, 30)]
    c = concatenate(ds)
    np.testing.assert_array_equal(c.z, np.concatenate([d.z for d in ds]))
    np.testing.assert_array_equal(c.X, np.vstack([d.X for d in ds]))
    np.testing.assert_allclose(np.diff(c.t), DT, rtol=1e-9)
    assert c.t[0] == 0.0 and len(c.t) == 160 and c.equation == ds[0].equation
    assert any("3 maneuvers of 50, 80, 30 samples" in n for n in c.notes)


def test_concatenate_refuses_mixed_equations_and_sample_rates() -> None:
    rng = np.random.default_rng(1)
    a = maneuver(rng, 40, 0.1)
    other = RegressionData.from_arrays(a.z, a.X[:, :2], NAMES[:2], DT, dependent="Cm")
    with pytest.raises(ValueError, match="share one model structure"):
        concatenate([a, other])
    slow = RegressionData.from_arrays(a.z, a.X, NAMES, 2 * DT, dependent="Cm")
    with pytest.raises(ValueError, match="sampled every"):
        concatenate([a, slow])
    with pytest.raises(ValueError, match="no maneuvers"):
        fit_concatenated([])


# ---------------------------------------------------------------- a priori = concatenation (Eqs. 43-49)
@pytest.mark.parametrize("lengths", [(150, 230), (150, 230, 90)])
def test_sequential_a_priori_equals_concatenation(lengths: tuple[int, ...]) -> None:
    """Must-show: with a common σ² (Eqs. 47, 49) the sequential a-priori combination equals
    concatenation to rounding error, estimates AND covariance."""
    rng = np.random.default_rng(42)
    ds = [maneuver(rng, n, 0.2, offset=0.3 * i) for i, n in enumerate(lengths)]
    cat = fit_concatenated(ds)
    seq = fit_sequential(ds, equal_variances=True)
    assert rel_err(seq.params, cat.params) < 1e-10
    assert rel_err(seq.cov, cat.cov) < 1e-10
    assert abs(seq.s2 - cat.s2) < 1e-10 * cat.s2
    assert rel_err(seq.residuals, cat.residuals) < 1e-10
    assert seq.n == cat.n == sum(lengths) and seq.names == cat.names
    # Eq. 49 by hand: σ̂² (Eq. 16, all data) times [Σ XᵢᵀXᵢ]⁻¹
    A = np.vstack([design(d) for d in ds])
    z = np.concatenate([d.z for d in ds])
    theta = np.linalg.solve(A.T @ A, A.T @ z)
    v = z - A @ theta
    s2 = v @ v / (len(z) - A.shape[1])
    assert rel_err(seq.cov, s2 * np.linalg.inv(A.T @ A)) < 1e-10


def test_sequential_result_does_not_depend_on_order() -> None:
    rng = np.random.default_rng(7)
    ds = [maneuver(rng, n, 0.2, offset=0.2 * i) for i, n in enumerate((120, 70, 200))]
    a, b = fit_sequential(ds), fit_sequential(ds[::-1])
    assert rel_err(a.params, b.params) < 1e-10 and rel_err(a.cov, b.cov) < 1e-10


def test_one_maneuver_is_ordinary_least_squares() -> None:
    d = maneuver(np.random.default_rng(3), 200, 0.1)
    ref = EquationErrorTime().fit(d)
    for fit in (fit_sequential([d]), fit_sequential([d], equal_variances=False), fit_concatenated([d])):
        assert rel_err(fit.params, ref.params) < 1e-12 and rel_err(fit.cov, ref.cov) < 1e-12


def test_a_priori_with_common_variance_is_concatenation() -> None:
    """Eq. 45 with Σ₁ = σ²(X₁ᵀX₁)⁻¹ (Eq. 44) and σ₂² = σ² gives Eqs. 47 and 49."""
    rng = np.random.default_rng(11)
    d1, d2 = maneuver(rng, 160, 0.15), maneuver(rng, 110, 0.15, offset=0.5)
    cat = fit_concatenated([d1, d2])
    A1 = design(d1)
    theta1 = np.linalg.lstsq(A1, d1.z, rcond=None)[0]
    prior_cov = cat.s2 * np.linalg.inv(A1.T @ A1)
    fit = fit_a_priori(d2, theta1, prior_cov, sigma2=cat.s2)
    assert rel_err(fit.params, cat.params) < 1e-10 and rel_err(fit.cov, cat.cov) < 1e-10
    assert fit.errors == "a-priori" and fit.n == 110 and fit.s2 == cat.s2


def test_a_priori_matches_eqs_45_and_48_with_own_variance() -> None:
    rng = np.random.default_rng(12)
    d2 = maneuver(rng, 90, 0.3)
    theta1 = THETA + 0.05
    L = rng.standard_normal((4, 4)) * 0.01
    sigma1 = L @ L.T + 1e-4 * np.eye(4)
    fit = fit_a_priori(d2, theta1, sigma1)
    A2 = design(d2)
    own = np.linalg.lstsq(A2, d2.z, rcond=None)[0]
    s2 = float(np.sum((d2.z - A2 @ own) ** 2)) / (90 - 4)  # Eq. 16, maneuver 2 alone
    info = A2.T @ A2 / s2 + np.linalg.inv(sigma1)
    theta = np.linalg.solve(info, A2.T @ d2.z / s2 + np.linalg.solve(sigma1, theta1))  # Eq. 45
    assert abs(fit.s2 - s2) < 1e-12 * s2
    assert rel_err(fit.params, theta) < 1e-10
    assert rel_err(fit.cov, np.linalg.inv(info)) < 1e-10  # Eq. 48
    np.testing.assert_allclose(fit.residuals, d2.z - A2 @ fit.params, atol=1e-12)


def test_a_priori_completes_a_maneuver_that_misses_a_regressor() -> None:
    """Maneuver 2 does not move 'de' (constant 0): alone it cannot estimate Cm_de, with the
    prior it can; σ₂² uses N − rank degrees of freedom."""
    rng = np.random.default_rng(13)
    d1 = maneuver(rng, 200, 0.1)
    X2 = rng.standard_normal((120, 3))
    X2[:, 2] = 0.0
    d2 = RegressionData.from_arrays(X2 @ THETA[:3] + THETA[3] + 0.1 * rng.standard_normal(120), X2, NAMES, DT,
                                    dependent="Cm")
    with pytest.raises(SingularRegressorsError):
        EquationErrorTime().fit(d2)
    prior = fit_concatenated([d1])
    fit = fit_a_priori(d2, prior.params, prior.cov)
    A_rank = np.column_stack([X2[:, :2], np.ones(120)])  # the directions maneuver 2 does excite
    v = d2.z - A_rank @ np.linalg.lstsq(A_rank, d2.z, rcond=None)[0]
    assert fit.s2 == pytest.approx(float(v @ v) / (120 - 3), rel=1e-10)  # Eq. 16, N − rank d.o.f.
    assert np.isfinite(fit.cov).all()
    assert fit.bse[2] <= prior.bse[2] * (1 + 1e-12)  # Cm_de: information from the prior only
    assert np.all(fit.bse[[0, 1, 3]] < 0.9 * prior.bse[[0, 1, 3]])  # the others gain from maneuver 2
    with pytest.raises(SingularRegressorsError, match="first maneuver"):
        fit_sequential([d2, d1])
    assert fit_sequential([d1, d2]).params == pytest.approx(fit_concatenated([d1, d2]).params, rel=1e-10)


# ---------------------------------------------------------------- unequal variances (Eqs. 45-46, 48)
def test_unequal_variances_weight_the_noisier_maneuver_less() -> None:
    """σ₁ = 10 σ₂: the weighted estimate lies near maneuver 2's own, and its covariance is
    Eq. 48 with each σᵢ² from Eq. 16 on that maneuver alone."""
    rng = np.random.default_rng(21)
    d1, d2 = maneuver(rng, 300, 1.0), maneuver(rng, 200, 0.1, offset=0.4)
    fit = fit_sequential([d1, d2], equal_variances=False)
    alone1, alone2 = EquationErrorTime().fit(d1), EquationErrorTime().fit(d2)
    pooled = fit_concatenated([d1, d2])
    dist = lambda a, b: float(np.linalg.norm(a - b))  # noqa: E731
    assert dist(fit.params, alone2.params) < dist(fit.params, alone1.params)
    assert dist(fit.params, alone2.params) < dist(pooled.params, alone2.params)
    A1, A2 = design(d1), design(d2)
    info = A1.T @ A1 / alone1.s2 + A2.T @ A2 / alone2.s2
    assert rel_err(fit.cov, np.linalg.inv(info)) < 1e-10  # Eq. 48
    b = A1.T @ d1.z / alone1.s2 + A2.T @ d2.z / alone2.s2
    assert rel_err(fit.params, np.linalg.solve(info, b)) < 1e-10  # Eq. 46
    assert fit.info["sigma2_per_maneuver"] == pytest.approx([alone1.s2, alone2.s2], rel=1e-10)
    assert fit.errors == "unequal-variances"


def test_unequal_variances_error_bounds_monte_carlo() -> None:
    """What unequal noise does to the bounds. Maneuver 1 (σ = 1) determines Cm_alpha, the
    quiet maneuver 2 (σ = 0.1) determines Cm_qhat. Eq. 48 bounds match the scatter of the
    weighted estimates; the pooled σ² of concatenation (Eq. 49) gives a bound too narrow for
    Cm_alpha and far too wide for Cm_qhat."""
    rng = np.random.default_rng(5)
    n = 200
    X1 = np.column_stack([rng.standard_normal(n), 0.2 * rng.standard_normal(n)])
    X2 = np.column_stack([0.2 * rng.standard_normal(n), rng.standard_normal(n)])
    theta = np.array([1.0, -0.5, 0.2])

    def data(X: np.ndarray, sigma: float) -> RegressionData:
        z = X @ theta[:2] + theta[2] + sigma * rng.standard_normal(n)
        return RegressionData.from_arrays(z, X, ("alpha", "qhat"), DT, dependent="Cm")

    weighted, concat, se_w, se_c = [], [], [], []
    for _ in range(300):
        ds = [data(X1, 1.0), data(X2, 0.1)]
        w, c = fit_sequential(ds, equal_variances=False), fit_concatenated(ds)
        weighted.append(w.params), concat.append(c.params), se_w.append(w.bse), se_c.append(c.bse)
    sd_w, sd_c = np.std(weighted, axis=0), np.std(concat, axis=0)
    se_w, se_c = np.mean(se_w, axis=0), np.mean(se_c, axis=0)
    np.testing.assert_allclose(se_w, sd_w, rtol=0.15)  # Eq. 48 bounds are right
    assert se_c[0] < 0.85 * sd_c[0]  # pooled bound too optimistic for the noisy maneuver's parameter
    assert se_c[1] > 2.5 * sd_c[1]  # and far too pessimistic for the quiet one's
    assert np.all(sd_w[:2] < sd_c[:2])  # weighting is also the more accurate estimate


# ---------------------------------------------------------------- frequency domain
def smooth_maneuver(rng: np.random.Generator, duration_s: float, sigma: float) -> RegressionData:
    """Regressors made of sinusoids in the 0.1-1.5 Hz band, white equation error."""
    t = np.arange(int(round(duration_s / DT)) + 1) * DT
    cols = []
    for _ in range(3):
        f = rng.uniform(0.1, 1.5, 6)
        ph = rng.uniform(0, 2 * np.pi, 6)
        cols.append(np.sin(2 * np.pi * f[None, :] * t[:, None] + ph).sum(axis=1))
    X = np.column_stack(cols)
    z = X @ THETA[:3] + THETA[3] + sigma * rng.standard_normal(len(t))
    return RegressionData.from_arrays(z, X, NAMES, DT, dependent="Cm")


def test_frequency_combination_sums_normal_equations_and_equals_stacking() -> None:
    rng = np.random.default_rng(31)
    ds = [smooth_maneuver(rng, 20.0, 0.05), smooth_maneuver(rng, 13.3, 0.05), smooth_maneuver(rng, 31.1, 0.05)]
    fit = fit_frequency_combined(ds)
    f = np.asarray(fit.info["frequencies_hz"])
    # default band: the seed's rule for the shortest maneuver, 2/T to 1.2 Hz by 0.04 Hz
    assert f[0] == pytest.approx(2 / (round(13.3 / DT) * DT)) and f[-1] <= 1.2 and len(f) == 27
    est = EquationErrorFrequency(frequencies_hz=tuple(f))
    parts = [est.transform(d) for d in ds]
    m = sum(len(p[0]) for p in parts)
    XtX = sum(np.real(p[2].conj().T @ p[2]) for p in parts)  # Σ Re(X̃ᵢ†X̃ᵢ)
    Xtz = sum(np.real(p[2].conj().T @ p[1]) for p in parts)  # Σ Re(X̃ᵢ†z̃ᵢ)
    theta = np.linalg.solve(XtX, Xtz)  # Eq. 19
    z = np.concatenate([p[1] for p in parts])
    X = np.vstack([p[2] for p in parts])
    v = z - X @ theta
    s2 = float(np.real(np.vdot(v, v))) / (m - 3)  # Eq. 21 with m = all frequency points
    assert fit.n == m == 3 * len(f)
    assert rel_err(fit.params, theta) < 1e-10
    assert abs(fit.s2 - s2) < 1e-9 * s2
    assert rel_err(fit.cov, s2 * np.linalg.inv(XtX)) < 1e-9  # Eq. 20
    assert fit.names == ("Cm_alpha", "Cm_qhat", "Cm_de") and fit.domain == "frequency"
    np.testing.assert_allclose(fit.params, THETA[:3], atol=0.01)


def test_frequency_combination_of_one_maneuver_is_the_single_fit() -> None:
    d = smooth_maneuver(np.random.default_rng(32), 20.0, 0.05)
    f = np.linspace(0.1, 1.5, 36)
    one = fit_frequency_combined([d], frequencies_hz=f)
    ref = EquationErrorFrequency(frequencies_hz=tuple(f)).fit(d)
    np.testing.assert_array_equal(one.params, ref.params)
    np.testing.assert_array_equal(one.cov, ref.cov)
    assert one.n == ref.n == 36 and one.names == ref.names


def test_frequency_combination_warns_about_short_maneuvers() -> None:
    rng = np.random.default_rng(33)
    ds = [smooth_maneuver(rng, 20.0, 0.05), smooth_maneuver(rng, 6.0, 0.05)]
    fit = fit_frequency_combined(ds, frequencies_hz="eq18")  # Eq. 18's 0.2 Hz < 2/6 s
    assert any("maneuver 1 lasts 6 s" in w and "2/T" in w for w in fit.warnings)
    assert not any("maneuver 0 lasts" in w for w in fit.warnings)
    # the default band follows the seed's rule for the shortest maneuver: no warning
    auto = fit_frequency_combined(ds)
    assert auto.info["frequencies_hz"][0] == pytest.approx(2 / 6.0)
    assert not any("lasts" in w for w in auto.warnings)


# ---------------------------------------------------------------- colored residuals across joins
PHI = 0.9


def ar1_covariance(n: int) -> np.ndarray:
    k = np.arange(n)
    return PHI ** np.abs(k[:, None] - k[None, :]) / (1 - PHI**2)


def joined_design(n: int, ends: int = 10) -> np.ndarray:
    """Regressor 'a' alternates ±1 inside the maneuver but is +1 on its first and last
    ``ends`` samples, so where two maneuvers are joined a run of 2·ends equal values forms —
    exactly where slowly decaying residual correlation would be (wrongly) counted."""
    a = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    a[:ends] = 1.0
    a[-ends:] = 1.0
    return np.column_stack([a, np.sin(2 * np.pi * 3 * np.arange(n) / n)])


def test_colored_concatenation_of_one_maneuver_is_eq_40() -> None:
    rng = np.random.default_rng(41)
    L = np.linalg.cholesky(ar1_covariance(300))
    t = np.arange(300) * DT
    X = np.column_stack([np.sin(2 * np.pi * 0.7 * t), rng.standard_normal(300)])
    z = X @ [1.0, -0.5] + 0.2 + L @ rng.standard_normal(300)
    # (all lags with a bias column make Eq. 40's bias entry vanish: Σᵢⱼ R̂(i − j) = (Σ v)²/N = 0)
    for lag, bias in ((5, True), (40, True), (None, False)):
        d = RegressionData.from_arrays(z, X, ("a", "b"), DT, bias=bias)
        ref = EquationErrorTime(errors="colored", max_lag=lag).fit(d)
        got = fit_concatenated([d], "colored", max_lag=lag)
        assert rel_err(got.cov, ref.cov) < 1e-10, lag
    d = RegressionData.from_arrays(z, X, ("a", "b"), DT)  # the autoregressive autocorrelation, bias and all lags
    ref = EquationErrorTime(errors="colored", autocorrelation="ar").fit(d)
    got = fit_concatenated([d], "colored", autocorrelation="ar")
    assert rel_err(got.cov, ref.cov) < 1e-10 and got.info["autocorrelation"] == "ar"


def test_colored_concatenation_sums_per_maneuver_blocks_and_ignores_order() -> None:
    rng = np.random.default_rng(42)
    n, r = 60, 30
    L = np.linalg.cholesky(ar1_covariance(n))
    ds = [RegressionData.from_arrays(joined_design(n) @ [1.0, -0.5] + L @ rng.standard_normal(n),
                                     joined_design(n), ("a", "b"), DT, bias=False) for _ in range(5)]
    fit = fit_concatenated(ds, "colored", max_lag=r)
    # Dense Eq. 40 with a block-diagonal E(vvᵀ): one Toeplitz block of Eq. 39 per maneuver.
    A = np.vstack([d.X for d in ds])
    blocks = []
    for i, d in enumerate(ds):
        R = residual_autocorrelation(fit.residuals[i * n:(i + 1) * n], r)
        k = np.abs(np.arange(n)[:, None] - np.arange(n)[None, :])
        blocks.append(np.where(k <= r, R[np.minimum(k, r)], 0.0))
    G = np.linalg.inv(A.T @ A)
    dense = G @ A.T @ scipy.linalg.block_diag(*blocks) @ A @ G
    assert rel_err(fit.cov, dense) < 1e-10
    assert rel_err(sum(colored_middle(d.X, fit.residuals[i * n:(i + 1) * n], r) for i, d in enumerate(ds)),
                   A.T @ scipy.linalg.block_diag(*blocks) @ A) < 1e-10
    # Independent maneuvers: stacking order must not matter.
    perm = [3, 0, 4, 2, 1]
    assert rel_err(fit_concatenated([ds[i] for i in perm], "colored", max_lag=r).cov, fit.cov) < 1e-10
    # Eq. 40 on the stacked rows counts lags across the joins and differs here.
    naive = colored_residual_covariance(A, fit.residuals, r)
    assert naive[0, 0] > 1.15 * fit.cov[0, 0]


def test_colored_concatenation_bounds_match_truth_where_joins_matter() -> None:
    """Monte Carlo: 8 maneuvers of 60 samples with AR(1) equation error (φ = 0.9), independent
    between maneuvers. The true covariance (OLS sandwich with block-diagonal E(vvᵀ)) is
    reproduced by the per-maneuver Eq. 40; Eq. 40 across the joins overstates the standard
    error of the regressor whose values run on across the joins."""
    n, m, r = 60, 8, 30
    X = [joined_design(n) for _ in range(m)]
    A = np.vstack(X)
    G = np.linalg.inv(A.T @ A)
    true = G @ A.T @ scipy.linalg.block_diag(*[ar1_covariance(n)] * m) @ A @ G
    L = np.linalg.cholesky(ar1_covariance(n))
    rng = np.random.default_rng(43)
    ours, naive = [], []
    for _ in range(250):
        ds = [RegressionData.from_arrays(x @ [1.0, -0.5] + L @ rng.standard_normal(n), x, ("a", "b"), DT,
                                         bias=False) for x in X]
        fit = fit_concatenated(ds, "colored", max_lag=r)
        ours.append(fit.cov[0, 0])
        naive.append(colored_residual_covariance(A, fit.residuals, r)[0, 0])
    se_true, se_ours, se_naive = np.sqrt(true[0, 0]), np.sqrt(np.mean(ours)), np.sqrt(np.mean(naive))
    assert abs(se_ours / se_true - 1) < 0.06
    assert se_naive / se_true > 1.10
