"""Tests for estimators.colored (seed Eqs. 37-41)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import linalg, signal

from estimators.colored import autoregressive_autocorrelation, colored_residual_covariance, residual_autocorrelation

N_SMALL = 200


def _problem(n=N_SMALL, seed=0):
    """Regressors with a bias column and AR(1)-coloured least-squares residuals."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    X = np.column_stack(
        [
            np.sin(2 * np.pi * 0.3 * t),
            np.cos(2 * np.pi * 0.7 * t) + 0.1 * rng.normal(size=n),
            rng.normal(size=n),
            np.ones(n),
        ]
    )
    z = X @ np.array([0.5, -1.0, 0.2, 0.1]) + signal.lfilter([1.0], [1.0, -0.9], rng.normal(size=n))
    theta = np.linalg.lstsq(X, z, rcond=None)[0]
    return X, z - X @ theta


def _eq39_direct(v, r):
    n = v.size
    return np.array([sum(v[i] * v[i + k] for i in range(n - k)) / n if k < n else 0.0
                     for k in range(r + 1)])


def _eq40_brute_force(X, v, r):
    """Eq. 40 with the full N x N matrix E(v v^T) = [R(i - j)] (Eq. 38)."""
    n = v.size
    lags = _eq39_direct(v, n - 1)
    lags[min(r, n - 1) + 1:] = 0.0
    big = linalg.toeplitz(lags)
    inv = np.linalg.inv(X.T @ X)
    return inv @ (X.T @ big @ X) @ inv


@pytest.mark.parametrize("max_lag", [None, 0, 1, 5, 32, 33, 120])
def test_autocorrelation_equals_direct_sum_eq39(max_lag):
    _, v = _problem()
    r = N_SMALL - 1 if max_lag is None else max_lag
    got = residual_autocorrelation(v, max_lag)
    assert got.shape == (r + 1,)
    np.testing.assert_allclose(got, _eq39_direct(v, r), rtol=0, atol=1e-13 * np.dot(v, v) / v.size)


def test_autocorrelation_beyond_record_is_zero():
    v = np.array([1.0, -2.0, 0.5])
    got = residual_autocorrelation(v, 5)
    np.testing.assert_allclose(got, [5.25 / 3, -3.0 / 3, 0.5 / 3, 0, 0, 0], atol=1e-15)


@pytest.mark.parametrize("max_lag", [None, 0, 1, 7, 32, 33, 100, 199, 1000])
@pytest.mark.parametrize("method", ["auto", "direct", "fft"])
def test_covariance_equals_brute_force_eq40(max_lag, method):
    X, v = _problem()
    r = N_SMALL - 1 if max_lag is None else max_lag
    got = colored_residual_covariance(X, v, max_lag, method=method)
    ref = _eq40_brute_force(X, v, r)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    np.testing.assert_array_equal(got, got.T)


def test_max_lag_zero_is_eq41_and_eq15():
    X, v = _problem()
    n, n_p = X.shape
    got = colored_residual_covariance(X, v, 0)
    r0 = np.sum(v**2) / n  # Eq. 41: R(0)
    expected = r0 * np.linalg.inv(X.T @ X)
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    # Eq. 15 with the unbiased sigma^2 of Eq. 16 differs only by N/(N - n_p)
    sigma2_eq16 = np.sum(v**2) / (n - n_p)
    np.testing.assert_allclose(got * n / (n - n_p), sigma2_eq16 * np.linalg.inv(X.T @ X), rtol=1e-12)


@pytest.mark.parametrize("max_lag", [None, 0])
def test_symmetric_positive_semidefinite(max_lag):
    X, v = _problem(seed=3)
    cov = colored_residual_covariance(X, v, max_lag)
    np.testing.assert_array_equal(cov, cov.T)
    eig = np.linalg.eigvalsh(cov)
    assert eig.min() >= -1e-12 * eig.max()
    assert np.all(np.diag(cov) > 0)


def test_coloured_residuals_inflate_standard_errors():
    """Positively correlated residuals: the Eq. 40 errors exceed the Eq. 15 ones."""
    X, v = _problem(n=2000, seed=4)
    white = np.sqrt(np.diag(colored_residual_covariance(X, v, 0)))
    coloured = np.sqrt(np.diag(colored_residual_covariance(X, v, 50)))
    assert coloured[-1] > 2 * white[-1]  # bias term, AR(1) with phi = 0.9


def test_one_dimensional_regressor():
    rng = np.random.default_rng(5)
    x = rng.normal(size=50)
    v = rng.normal(size=50)
    got = colored_residual_covariance(x, v, 3)
    ref = _eq40_brute_force(x[:, None], v, 3)
    np.testing.assert_allclose(got, ref, rtol=1e-12)


@pytest.mark.parametrize(
    "X, v, kwargs, exc",
    [
        (np.ones((10, 2)), np.ones(9), {}, ValueError),
        (np.ones((10, 2)) + 1j, np.ones(10), {}, ValueError),
        (np.ones((3, 3)), np.ones(3), {}, ValueError),
        (np.r_[np.ones(9), np.nan][:, None], np.ones(10), {}, ValueError),
        (np.arange(20.0).reshape(10, 2), np.ones(10), {"method": "other"}, ValueError),
        (np.arange(20.0).reshape(10, 2), np.ones(10), {"max_lag": -1}, ValueError),
        (np.arange(20.0).reshape(10, 2), np.ones(10), {"max_lag": 2.5}, TypeError),
        (np.arange(20.0).reshape(10, 2), np.ones(10), {"autocorrelation": "other"}, ValueError),
        (np.ones((10, 2)), np.ones(10), {}, np.linalg.LinAlgError),
    ],
)
def test_invalid_input(X, v, kwargs, exc):
    with pytest.raises(exc):
        colored_residual_covariance(X, v, **kwargs)


def test_given_qr_factor_gives_the_same_covariance():
    """least_squares(..., keep_factor=True) hands its QR factor on: no second factorisation,
    the same numbers."""
    from estimators.least_squares import least_squares

    X, v = _problem(n=3000, seed=6)
    z = X @ np.array([0.5, -1.0, 0.2, 0.1]) + v
    ls = least_squares(X, z, ("a", "b", "c", "bias"), keep_factor=True)
    for max_lag in (None, 10, 500):
        np.testing.assert_array_equal(colored_residual_covariance(X, ls.residuals, max_lag, factor=ls.factor),
                                      colored_residual_covariance(X, ls.residuals, max_lag))
    assert least_squares(X, z, ("a", "b", "c", "bias")).factor is None
    with pytest.raises(ValueError, match="factor"):
        colored_residual_covariance(X[:, :3], ls.residuals, factor=ls.factor)


def test_autoregressive_autocorrelation_keeps_eq39_up_to_its_order_and_follows_the_model_beyond():
    """Order 1 (AR(1) residuals, phi 0.9): R(0), R(1) are Eq. 39's, R(k) = R(0) (R(1)/R(0))^k."""
    _, v = _problem(n=3000, seed=7)
    model, order = autoregressive_autocorrelation(v, max_order=1)
    sample = residual_autocorrelation(v, 2)
    assert order == 1
    np.testing.assert_allclose(model[:2], sample[:2], rtol=1e-12)
    k = np.arange(v.size)
    np.testing.assert_allclose(model, sample[0] * (sample[1] / sample[0]) ** k, rtol=1e-9, atol=1e-300)


def test_autoregressive_autocorrelation_of_white_noise_is_nearly_white_and_of_ar2_is_order_2():
    """The order of least AIC: low for white noise, whose model long-run variance
    R(0) + 2 sum R(k) then stays within 0.1 of R(0) (an AR(1) coefficient's standard error is
    1/sqrt(N) = 0.014 at N = 5,000; the ratio is about 1 + 2 phi); at least 2 for a long AR(2)
    record, whose model autocorrelation then gives back a1 1.5, a2 -0.7 from the Yule-Walker
    equations of its first lags (within a few of their standard errors, about 0.01 at N = 20,000;
    AIC may add an order or a few, which changes nothing there)."""
    rng = np.random.default_rng(8)
    model, order = autoregressive_autocorrelation(rng.normal(size=5000))
    assert order <= 3
    assert abs((model[0] + 2 * model[1:].sum()) / model[0] - 1.0) < 0.1
    v = signal.lfilter([1.0], [1.0, -1.5, 0.7], rng.normal(size=20000))
    model, order = autoregressive_autocorrelation(v, max_order=10)
    assert order >= 2
    a = np.linalg.solve([[model[0], model[1]], [model[1], model[0]]], model[1:3])
    np.testing.assert_allclose(a, [1.5, -0.7], atol=0.04)


def _bias_term_scatter(autocorrelation, phi, white, reps=200, n=1500, seed=9):
    """Empirical standard deviation of a fitted constant over ``reps`` seeded records, and the
    mean Eq. 40 standard error reported for it (residuals: white + first-order Gauss-Markov)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    X = np.column_stack([np.sin(2 * np.pi * 0.2 * t), np.ones(n)])
    est, se = [], []
    for _ in range(reps):
        e = white * rng.normal(size=n)
        if phi:
            e += signal.lfilter([np.sqrt(1 - phi**2)], [1.0, -phi], rng.normal(size=n))
        theta, *_ = np.linalg.lstsq(X, e, rcond=None)
        cov = colored_residual_covariance(X, e - X @ theta, autocorrelation=autocorrelation)
        est.append(theta[1])
        se.append(np.sqrt(cov[1, 1]))
    return np.std(est), np.mean(se)


def test_a_bias_terms_eq40_error_is_honest_with_the_autoregressive_autocorrelation():
    """Eq. 39's estimates of zero-mean residuals sum to zero over all lags: with all lags a
    constant's Eq. 40 standard error is too small, by about 1.8 even for white residuals. With
    the autoregressive model's autocorrelation it matches the scatter of 200 seeded records
    (the scatter's own relative standard error is 1/sqrt(400) = 5 %: tolerance 3 of them); on a
    slow Gauss-Markov residual (tau 1 s at 50 Hz, 30 s) it is at least 1.5 times closer."""
    emp, se_ar = _bias_term_scatter("ar", 0.0, 1.0)
    _, se_sample = _bias_term_scatter("sample", 0.0, 1.0)
    assert abs(emp / se_ar - 1.0) < 0.15
    assert emp / se_sample > 1.5
    emp, se_ar = _bias_term_scatter("ar", np.exp(-0.02), 0.3)
    _, se_sample = _bias_term_scatter("sample", np.exp(-0.02), 0.3)
    assert emp / se_sample > 1.5 * (emp / se_ar) ** 0.5 and emp / se_ar < 1.4


def test_autoregressive_autocorrelation_leaves_a_white_fits_slopes_alone():
    """White residuals, order 0: the covariance is Eq. 15's (sigma^2 = R(0))."""
    rng = np.random.default_rng(10)
    X = np.column_stack([rng.normal(size=800), np.ones(800)])
    v = rng.normal(size=800)
    v -= X @ np.linalg.lstsq(X, v, rcond=None)[0]
    assert autoregressive_autocorrelation(v)[1] == 0
    np.testing.assert_allclose(colored_residual_covariance(X, v, autocorrelation="ar"),
                               colored_residual_covariance(X, v, 0), rtol=1e-10)
