"""Tests for estimators.colored (seed Eqs. 37-41)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import linalg, signal

from estimators.colored import colored_residual_covariance, residual_autocorrelation

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
