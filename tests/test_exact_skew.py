"""The exact fractional shift the time-skew contest uses (harness.diagnosis.exact_skew)."""
from __future__ import annotations

import numpy as np
import pytest

from harness.diagnosis.exact_skew import fractional_shift


@pytest.mark.parametrize("tau", [0.08, -0.013, 0.005])
def test_fractional_shift_advances_a_sinusoid_by_tau(tau):
    """x(t + τ) of sin ωt is sin ω(t + τ) (analytic), at whole and fractional samples alike,
    away from the record's ends where the even extension folds."""
    dt, w = 0.02, 2 * np.pi * 0.8
    t = np.arange(0.0, 30.0, dt)
    shifted = fractional_shift(np.sin(w * t), tau, dt)
    inner = slice(100, -100)
    assert np.max(np.abs(shifted - np.sin(w * (t + tau)))[inner]) < 2e-3


def test_fractional_shift_keeps_white_noise_power_at_half_a_sample():
    """Linear interpolation half a sample over halves white noise's variance (the mean of two
    independent samples), which would let a residual favour fractional shifts; the Fourier
    shift keeps it (seeded; the variance ratio's scatter is about √(2/N), 0.014 here)."""
    x = np.random.default_rng(7).normal(size=10_000)
    ratio = np.var(fractional_shift(x, 0.5, 1.0)[200:-200]) / np.var(x)
    assert ratio == pytest.approx(1.0, abs=0.06)


def test_partial_correlation_takes_out_the_shared_columns():
    """a = u + s, b = u − s, with u the shared column: their plain correlation is 0 for
    orthogonal u, s of equal norm, and once u is taken out it is −1 (analytic); a column the
    others explain entirely has nothing left (0)."""
    from estimators.least_squares import partial_correlation, residual_after
    t = np.linspace(0.0, 1.0, 1000, endpoint=False)
    u, s = np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)
    assert np.corrcoef(u + s, u - s)[0, 1] == pytest.approx(0.0, abs=1e-12)
    assert partial_correlation(u + s, u - s, [u]) == pytest.approx(-1.0, abs=1e-12)
    assert np.allclose(residual_after(2.0 * u, [u]), 0.0, atol=1e-12)
    assert partial_correlation(2.0 * u, s, [u]) == 0.0
