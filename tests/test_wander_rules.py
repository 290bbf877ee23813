"""wander_rules: the unseen wander's level and the standard error it gives an estimate,
pinned to white noise, whose density and whose mean's variance are known."""
import numpy as np
import pytest
from scipy import signal

from harness.diagnosis.spectra import GUST_HIGHPASS_HZ
from harness.diagnosis.wander_rules import slow_wander_std_error, wander_level


def test_the_mean_of_a_flat_spectrum_has_the_white_noise_variance():
    """θ = mean(x): its weights' transform is 1 at DC and 0 elsewhere, so a two-sided density
    P0 below the band gives var θ = P0·fs/N, what white noise of variance σ² = P0·fs gives the
    mean of N samples (σ²/N)."""
    n, dt, level = 1400, 0.02, 3e-6
    se = slow_wander_std_error(np.full(n, 1.0 / n), level, dt)
    assert se == pytest.approx(np.sqrt(level / dt / n), rel=1e-12)


def test_a_column_without_weight_below_the_high_pass_gets_none():
    """A sinusoid's weights at 1 Hz, on a whole number of cycles, carry nothing below 0.05 Hz."""
    t = np.arange(2000) * 0.02
    assert slow_wander_std_error(np.sin(2 * np.pi * t), 1.0, 0.02) == pytest.approx(0.0, abs=1e-9)


def test_the_level_of_high_passed_white_noise_is_its_density():
    """White noise of variance σ² at fs has a two-sided density σ²/fs; high-passed forward and
    backward as the gust estimate is, its level read above the corner with the filter's gain
    divided out is that density. Averaged over the band's ordinates (about 300 here) the
    periodogram's relative scatter is 1/√300 ≈ 6 %; four of them allowed."""
    rng = np.random.default_rng(31)
    fs, sigma, n = 50.0, 0.002, 100_000
    b, a = signal.butter(2, GUST_HIGHPASS_HZ, btype="highpass", fs=fs)
    column = signal.filtfilt(b, a, rng.normal(scale=sigma, size=n))
    assert wander_level(column, 1.0 / fs) == pytest.approx(sigma ** 2 / fs, rel=0.24)
