"""The noise layer: each kind against its definition, with tolerances from the statistics."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from harness.noise import ChannelNoise, NoiseModel, apply_noise, band_limited, corrupt, gauss_markov, stream
from harness.noise_presets import PRESETS, WHITE_LEVELS, preset
from maneuvers.recording import Recording

N = 200_000
T = np.arange(N) * 0.02


def test_white_noise_level():
    y = corrupt(np.zeros(N), T, ChannelNoise(white_std=0.3), stream(1, "x"))
    # sample std of N Gaussians: relative standard error 1/sqrt(2N) = 0.16 %; allow 5 of them
    assert y.std() == pytest.approx(0.3, rel=5 / math.sqrt(2 * N))
    assert abs(y.mean()) < 5 * 0.3 / math.sqrt(N)


def test_gauss_markov_level_and_correlation():
    dt, tau = 0.02, 0.5
    y = gauss_markov(N, dt, 2.0, tau, np.random.default_rng(2))
    phi = math.exp(-dt / tau)
    # effective sample size of an AR(1): N (1 - phi) / (1 + phi)
    n_eff = N * (1 - phi) / (1 + phi)
    assert y.std() == pytest.approx(2.0, rel=5 / math.sqrt(2 * n_eff))
    r1 = np.corrcoef(y[:-1], y[1:])[0, 1]
    assert r1 == pytest.approx(phi, abs=5 * (1 - phi**2) / math.sqrt(N))


def test_band_limited_spectrum_is_zero_outside_band():
    y = band_limited(4096, 0.02, 1.5, (0.5, 2.0), np.random.default_rng(3))
    f = np.fft.rfftfreq(4096, 0.02)
    spec = np.abs(np.fft.rfft(y))
    assert np.max(spec[(f < 0.5) | (f > 2.0)]) < 1e-9 * np.max(spec)
    assert y.std() == pytest.approx(1.5, rel=1e-12)


def test_deterministic_errors_are_exact():
    x = np.linspace(0.0, 1.0, 101)
    t = np.arange(101) * 0.01
    y = corrupt(x, t, ChannelNoise(bias=0.2, scale=0.1), stream(0, "x"))
    assert np.allclose(y, 1.1 * x + 0.2, atol=1e-15)
    q = corrupt(x, t, ChannelNoise(quantum=0.05), stream(0, "x"))
    assert np.allclose(q / 0.05, np.round(q / 0.05), atol=1e-9)
    assert np.max(np.abs(q - x)) <= 0.025 + 1e-12
    skewed = corrupt(x, t, ChannelNoise(skew_s=0.03), stream(0, "x"))
    assert np.allclose(skewed[3:], x[:-3], atol=1e-12)  # x(t - 0.03) on a ramp
    assert np.all(skewed[:4] == x[0])


def test_spike_count_is_poisson():
    rate, dur = 0.5, T[-1]
    y = corrupt(np.zeros(N), T, ChannelNoise(spike_rate_hz=rate, spike_std=10.0), stream(4, "x"))
    k = np.count_nonzero(y)
    lam = rate * dur
    assert abs(k - lam) < 5 * math.sqrt(lam)


def _recording(n=501):
    t = np.arange(n) * 0.02
    cols = {c: np.zeros(n) for c in ("V_fps", "alpha_rad", "beta_rad", "p_rps", "q_rps", "r_rps", "phi_rad",
                                      "theta_rad", "psi_rad", "ax_g", "ay_g", "az_g", "de_rad", "qbar_psf",
                                      "pdot_rps2", "qdot_rps2", "rdot_rps2", "truth_Cm_1")}
    cols["V_fps"] += 420.0
    cols["qbar_psf"] += 150.0
    cols["az_g"] -= 1.0
    data = pd.DataFrame({"t_s": t, **cols})
    meta = {"format": "flight-recording/1", "aircraft": "test", "geometry": {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32},
            "mass": {"mass_slug": 600.0, "Ix_slugft2": 1e4, "Iy_slugft2": 5e4, "Iz_slugft2": 6e4, "Ixz_slugft2": 1e3}}
    return Recording(data=data, meta=meta, name="t").validate()


def test_apply_noise_is_reproducible_and_per_channel_independent():
    rec = _recording()
    a = apply_noise(rec, preset("white"), 7)
    b = apply_noise(rec, preset("white"), 7)
    c = apply_noise(rec, preset("white"), 8)
    assert a.data.equals(b.data)
    assert not a.data["alpha_rad"].equals(c.data["alpha_rad"])
    only_alpha = apply_noise(rec, preset("white").only(("alpha",)), 7)
    assert np.array_equal(only_alpha.channel("alpha"), a.channel("alpha"))  # same stream
    assert np.array_equal(only_alpha.channel("q"), rec.channel("q"))
    assert np.array_equal(a.truth["Cm"], rec.truth["Cm"])  # truth stays clean
    assert a.meta["noise"]["seed"] == 7 and "alpha" in a.meta["noise"]["channels"]
    assert not a.has("qdot") and "qdot" in a.meta["noise"]["dropped"]


def test_every_preset_builds_and_levels_have_a_source():
    for name in PRESETS:
        m = preset(name)
        assert m.name == name and m.source
    assert preset("white").channel_map["alpha"].white_std == pytest.approx(0.1 * math.pi / 180)
    assert preset("heavy").channel_map["q"].white_std == pytest.approx(3 * WHITE_LEVELS["q"])
    assert preset("turbulence-moderate").turbulence.severity == 3
    with pytest.raises(ValueError, match="unknown noise preset"):
        preset("loud")


def test_invalid_specs_are_refused():
    with pytest.raises(ValueError, match="white_std"):
        ChannelNoise(white_std=-1.0)
    with pytest.raises(ValueError, match="band_hz"):
        ChannelNoise(band_hz=(2.0, 1.0))
    NoiseModel.build("x")  # empty is fine
