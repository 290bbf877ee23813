"""Tests for estimators.fourier (high-accuracy finite Fourier transform)."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.fourier import (
    finite_fourier_transform,
    interpolation_weights,
    plain_dft,
    seed_frequencies,
)

DT = 0.02


def _gauss_legendre_reference(poly, t0, dt, n, freqs, nodes=40):
    """int_{t0}^{t0+(n-1)dt} poly(t) exp(-j 2 pi f t) dt by composite Gauss-Legendre.

    40 nodes per sampling interval integrate (cubic x smooth exponential)
    to rounding for |omega dt| <= 2.
    """
    xg, wg = np.polynomial.legendre.leggauss(nodes)
    a = t0 + np.arange(n - 1)[:, None] * dt
    h = dt / 2
    tt = (a + h + h * xg).ravel()
    ww = np.tile(h * wg, n - 1)
    vals = np.polynomial.polynomial.polyval(tt, poly) * ww
    return np.array([np.sum(vals * np.exp(-2j * np.pi * f * tt)) for f in freqs])


def test_seed_frequencies_eq18():
    f = seed_frequencies()
    assert f.shape == (26,)
    assert f[0] == 0.20 and f[-1] == 1.20
    np.testing.assert_allclose(np.diff(f), 0.04, rtol=1e-12)


def test_interpolation_weights_limits_and_closed_form():
    w, alpha = interpolation_weights([0.0])
    assert w[0] == 1.0
    np.testing.assert_allclose(alpha[:, 0], [-2 / 3, 7 / 24, -1 / 6, 1 / 24], atol=1e-15)
    # closed form W = (6 + th^2)(3 - 4 cos th + cos 2 th)/(3 th^4), fine away from 0
    th = np.array([0.5, 0.9, 1.0, 1.1, 2.0, 3.0, np.pi])
    w, _ = interpolation_weights(th)
    closed = (6 + th**2) * (3 - 4 * np.cos(th) + np.cos(2 * th)) / (3 * th**4)
    np.testing.assert_allclose(w, closed, rtol=1e-12)
    # Taylor series near 0
    th = np.array([1e-4, 1e-2, 0.1])
    w, _ = interpolation_weights(th)
    taylor = 1 - 11 * th**4 / 720 + 23 * th**6 / 15120 - 139 * th**8 / 1814400
    np.testing.assert_allclose(w, taylor, rtol=1e-14)
    # continuity across the switch between series and closed-form moments
    w_lo, a_lo = interpolation_weights([1.0 - 1e-12])
    w_hi, a_hi = interpolation_weights([1.0 + 1e-12])
    np.testing.assert_allclose(w_lo, w_hi, atol=1e-11)
    np.testing.assert_allclose(a_lo, a_hi, atol=1e-11)
    # symmetry used for the right end: alpha(-theta) = conj(alpha(theta))
    _, a_pos = interpolation_weights([0.3, 1.7])
    _, a_neg = interpolation_weights([-0.3, -1.7])
    np.testing.assert_allclose(a_neg, np.conj(a_pos), atol=1e-15)


@pytest.mark.parametrize("n", [4, 5, 7, 8, 12, 101, 1000])
def test_exact_for_cubic_polynomial(n):
    dt, t0 = 0.037, 0.3
    poly = np.array([0.7, -1.2, 0.5, 0.9])
    t = t0 + np.arange(n) * dt
    x = np.polynomial.polynomial.polyval(t, poly)
    freqs = np.array([-2.0, 0.0, 0.013, 0.4, 1.2, 5.0, 8.5])
    got = finite_fourier_transform(x, dt, freqs, t0=t0)
    ref = _gauss_legendre_reference(poly, t0, dt, n, freqs)
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=0)


def test_constant_signal_closed_form():
    n = 333
    freqs = seed_frequencies()
    w = 2 * np.pi * freqs
    span = (n - 1) * DT
    got = finite_fourier_transform(np.full(n, 2.5), DT, freqs)
    ref = 2.5 * (1 - np.exp(-1j * w * span)) / (1j * w)
    np.testing.assert_allclose(got, ref, rtol=1e-12)


def _damped_sinusoid_case(dt, n, a=0.5, f0=0.5):
    t = np.arange(n) * dt
    span = (n - 1) * dt
    w0 = 2 * np.pi * f0
    x = np.exp(-a * t) * np.sin(w0 * t)
    w = 2 * np.pi * seed_frequencies()

    def integral(s):  # int_0^T exp(s t) exp(-j w t) dt
        return (np.exp((s - 1j * w) * span) - 1) / (s - 1j * w)

    exact = (integral(-a + 1j * w0) - integral(-a - 1j * w0)) / 2j
    return x, exact


def test_damped_sinusoid_against_closed_form(capsys):
    """x = exp(-a t) sin(w0 t) on [0, T], T = 10.06 s (503 intervals at 50 Hz).

    T is not a multiple of the period (1/f0 = 2 s -> 5.03 periods), and the
    grid is the seed's Eq. 18.  The remaining error is the cubic
    interpolant's own, ~ (11/720)(w0 dt)^4 relative (4e-7 at 0.5 Hz, 50 Hz);
    at 1 Hz it would be ~4e-6.  The plain DFT (Riemann sum) has O(dt) error.
    """
    x, exact = _damped_sinusoid_case(DT, 504)
    high = finite_fourier_transform(x, DT, seed_frequencies())
    plain = plain_dft(x, DT, seed_frequencies())
    err_high = np.max(np.abs(high - exact) / np.abs(exact))
    err_plain = np.max(np.abs(plain - exact) / np.abs(exact))
    with capsys.disabled():
        print(
            f"\nFFT accuracy (damped sinusoid, 0.2-1.2 Hz): max rel error "
            f"high-accuracy = {err_high:.3e}, plain DFT = {err_plain:.3e}, "
            f"ratio = {err_plain / err_high:.0f}"
        )
    assert err_high < 1e-6
    assert err_plain > 100 * err_high


def test_error_is_fourth_order_in_dt():
    """Halving dt (same T) divides the error by ~16 (cubic interpolation)."""
    errs = []
    for dt, n in ((0.04, 252), (0.02, 503), (0.01, 1005)):
        x, exact = _damped_sinusoid_case(dt, n, a=0.3, f0=0.9)
        errs.append(np.max(np.abs(finite_fourier_transform(x, dt, seed_frequencies()) - exact)))
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all((ratios > 12) & (ratios < 20))


def test_columnwise_and_t0_shift():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(300, 3))
    f = seed_frequencies()
    both = finite_fourier_transform(x, DT, f, t0=1.7)
    assert both.shape == (26, 3)
    for j in range(3):
        single = finite_fourier_transform(x[:, j], DT, f)
        np.testing.assert_allclose(both[:, j], single * np.exp(-2j * np.pi * f * 1.7), rtol=1e-13)
    np.testing.assert_allclose(plain_dft(x, DT, f)[:, 1], plain_dft(x[:, 1], DT, f), rtol=1e-13)


def test_chirp_z_path_matches_direct_sum():
    """A long uniform grid takes the chirp-z route; a permuted grid the direct one."""
    rng = np.random.default_rng(1)
    x = rng.normal(size=2000)
    f = np.linspace(0.05, 3.0, 200)  # uniform, >= 64 points -> chirp-z
    perm = rng.permutation(f.size)  # non-uniform order -> direct
    czt_route = finite_fourier_transform(x, DT, f)
    direct = np.empty_like(czt_route)
    direct[perm] = finite_fourier_transform(x, DT, f[perm])
    np.testing.assert_allclose(czt_route, direct, rtol=0, atol=1e-9 * np.abs(direct).max())
    np.testing.assert_allclose(
        plain_dft(x, DT, f),
        DT * np.exp(-2j * np.pi * np.outer(f, np.arange(x.size) * DT)) @ x,
        rtol=0,
        atol=1e-9 * np.abs(direct).max(),
    )


@pytest.mark.parametrize(
    "x, freqs",
    [(np.ones(3), [0.5]), (np.r_[np.ones(9), np.nan], [0.5]), (np.ones(10), [[0.5]]),
     (np.ones(10), []), (np.ones((4, 2, 2)), [0.5])],
)
def test_invalid_input(x, freqs):
    with pytest.raises(ValueError):
        finite_fourier_transform(x, DT, freqs)


def test_held_transform_exact_for_steps_on_samples():
    """A step on a sample instant, the sample holding the new value: the zero-order hold's
    transform is the step's own, int_t1^T e^{-j w t} dt; the cubic interpolant's lags it by
    half a sample in phase (its jump is centred at t1 - dt/2)."""
    from estimators.fourier import held_fourier_transform
    dt, t1, T = 0.02, 1.0, 4.0
    t = np.arange(round(T / dt) + 1) * dt
    x = (t >= t1 - 1e-12).astype(float)
    f = np.array([0.0, 0.3, 1.1])
    w = 2 * np.pi * f[1:]
    exact = np.concatenate([[T - t1], (np.exp(-1j * w * t1) - np.exp(-1j * w * T)) / (1j * w)])
    assert np.allclose(held_fourier_transform(x, dt, f), exact, rtol=0, atol=1e-13)
    cubic = finite_fourier_transform(x, dt, f)
    early = np.concatenate([[T - t1 + dt / 2], (np.exp(-1j * w * (t1 - dt / 2)) - np.exp(-1j * w * T)) / (1j * w)])
    assert np.allclose(cubic, early, rtol=0, atol=1e-2 * dt)
    assert np.max(np.abs(cubic - exact)) > 0.4 * dt
