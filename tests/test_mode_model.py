"""A structural mode fitted as a second-order response to a recorded surface
(harness/diagnosis/mode_model.py): the responses against their closed forms, the fit against
a mode of known frequency, damping and gains, the noise a resonance would ring, and the notch
a mode no surface rings keeps."""
from __future__ import annotations

import math

import numpy as np
import pytest

from harness.diagnosis.gallery import StructuralMode, case, write_case
from harness.diagnosis.mode_model import (DrivenMode, acceptable, band_part, fit_driven_mode, mode_responses,
                                          wiener_surface)


def test_mode_responses_to_a_step_are_the_closed_forms():
    """For a unit step, s H/ω (r_rate) is e^(−ζωt) sin(ω_d t)/√(1 − ζ²) and s² H/ω² (r_acc)
    its derivative over ω: e^(−ζωt) [cos(ω_d t) − ζ/√(1 − ζ²) sin(ω_d t)]."""
    f, z, dt = 8.0, 0.03, 1e-4
    w, wd = 2 * math.pi * f, 2 * math.pi * f * math.sqrt(1 - z * z)
    u = np.r_[0.0, np.ones(20000)]  # the first-order hold ramps it up over the first step
    t = (np.arange(u.size) - 0.5) * dt
    R = mode_responses(u, dt, f, z)
    decay = np.exp(-z * w * t)
    rate = decay * np.sin(wd * t) / math.sqrt(1 - z * z)
    acc = decay * (np.cos(wd * t) - z / math.sqrt(1 - z * z) * np.sin(wd * t))
    later = t > 0.01
    assert np.max(np.abs(R[later, 1] - rate[later])) < 2e-3
    assert np.max(np.abs(R[later, 0] - acc[later])) < 2e-3


def test_band_part_keeps_what_lies_in_the_band_only():
    dt = 0.02
    t = np.arange(3000) * dt
    inside, outside = np.sin(2 * np.pi * 8.0 * t), np.sin(2 * np.pi * 3.0 * t) + 0.5 * t
    got = band_part(inside + outside, dt, (7.0, 9.0))
    assert np.max(np.abs(got[200:-200] - inside[200:-200])) < 0.02


def test_wiener_surface_leaves_the_motion_and_removes_most_of_the_noise():
    """A surface that moves below 2 Hz under white sensor noise: its estimate is nearer the
    motion than the record, and the noise left above 5 Hz is a small share of the recorded
    (the cells beside the motion's keep some: their power is averaged over three bins)."""
    rng = np.random.default_rng(3)
    dt = 0.02
    t = np.arange(1500) * dt
    motion = 0.03 * np.sin(2 * np.pi * 0.4 * t) + 0.02 * np.sin(2 * np.pi * 1.3 * t + 1.0)
    noisy = motion + rng.normal(scale=0.001, size=t.size)
    est = wiener_surface(noisy, dt)
    assert np.std(est - motion) < 0.7 * np.std(noisy - motion)
    high = (5.0, 24.0)
    assert np.std(band_part(est, dt, high)) < 0.4 * np.std(band_part(noisy, dt, high))


def test_wiener_surface_keeps_a_steps_content_near_a_mode():
    """Steps through a 40 rad/s actuator (ζ 0.7) under 0.05° of white noise: between 6 and
    10 Hz, where an 8 Hz mode rings, the record's noise is 43 % of the step edges' content;
    the time-varying gain keeps the edges and cuts the noise between them, to within 20 %
    (a gain set on the whole record's spectrum scaled the edges by about one half)."""
    from scipy import signal
    rng = np.random.default_rng(3)
    dt = 0.02
    t = np.arange(1500) * dt
    command = np.zeros_like(t)
    for a, start, width in ((0.035, 2, 3), (-0.035, 5, 2), (0.035, 7, 1), (-0.035, 8, 1)):
        command[(t >= start) & (t < start + width)] = a
    _, surface, _ = signal.lsim(signal.lti([1600.0], [1.0, 56.0, 1600.0]), command, t)
    noisy = surface + rng.normal(scale=math.radians(0.05), size=t.size)
    band = (6.0, 10.0)
    content = np.std(band_part(surface, dt, band))
    assert np.std(band_part(noisy - surface, dt, band)) > 0.4 * content
    assert np.std(band_part(wiener_surface(noisy, dt) - surface, dt, band)) < 0.2 * content


@pytest.fixture(scope="module")
def driven():
    """The gallery's no-effect identification recording with an 8 Hz, ζ 0.02 mode rung by
    its stabilator (gallery StructuralMode: q gain 0.5, a_z gain 3), prepared."""
    import tempfile
    from pathlib import Path

    from harness.diagnosis.prepare import prepare
    from harness.recording_io import read_recording
    with tempfile.TemporaryDirectory() as d:
        c = case("structural_mode")
        paths = write_case(c, Path(d), seed=2)
        return c.mode, prepare(read_recording(paths["identification"]))


def test_fit_recovers_the_mode_the_stabilator_rings(driven):
    """Frequency and damping of the mode added to the recording, and its gains: the gallery
    adds g·(H − 1)δe = −g (r_acc + 2ζ r_rate), so the r_acc gains are −0.5 (q) and −3 (a_z)."""
    truth, p = driven
    m = fit_driven_mode(p, "q", truth.frequency_hz - 0.3)  # a spectral peak a little low, as step inputs put it
    assert m is not None and m.surface == "de"
    assert abs(m.frequency_hz - truth.frequency_hz) < max(4 * m.std_error_hz, 0.1)
    assert abs(m.damping - truth.damping) < 0.012
    assert m.gains["q"][0] == pytest.approx(-truth.q_gain, rel=0.15)
    assert m.gains["az"][0] == pytest.approx(-truth.az_gain, rel=0.15)
    assert acceptable(m, truth.frequency_hz - 0.3, "q")
    assert DrivenMode.from_dict(m.as_dict()) == m


def test_a_mode_no_surface_rings_is_not_fitted(driven):
    """A resonance rung by white noise (something the recording does not hold) is no surface's
    response: no driven model (the notch stands for it)."""
    from dataclasses import replace

    from scipy import signal
    _, p = driven
    rng = np.random.default_rng(11)
    w, z = 2 * math.pi * 6.0, 0.02
    b, a, _ = signal.cont2discrete(([w * w], [1.0, 2 * z * w, w * w]), p.dt, method="zoh")
    ring = signal.lfilter(np.ravel(b), a, rng.normal(scale=0.02, size=p.n))
    raw = dict(p.raw)
    for c in ("q", "az"):  # the driven mode the recording had is taken out: the smoothed record's own
        raw[c] = p.smooth[c] + rng.normal(scale=p.noise_std[c], size=p.n)
    raw["q"] = raw["q"] + ring
    m = fit_driven_mode(replace(p, raw=raw), "q", 6.0)
    assert m is None or not acceptable(m, 6.0, "q")


def test_gallery_structural_mode(tmp_path):
    """End to end on the gallery's structural-mode case: the finding's frequency is the fitted
    natural frequency; the augmented model adds the mode to q and a_z, and the validation
    maneuver's q (smoothed, with the mode's band put back) fits at least 30 % better."""
    from harness.diagnosis.run import diagnose
    paths = write_case(case("structural_mode"), tmp_path / "rec", seed=1)
    r = diagnose("f16", paths["identification"], tmp_path / "out", paths["validation"], calibrate_workers=1)
    f = r["findings"][0]
    assert f["effect"] == "structural_mode"
    m = f["evidence"]["mode_model"]
    assert m["surface"] == "de" and {"q", "az"} <= set(m["gains"])
    assert f["estimate"] == m["frequency_hz"] and abs(f["estimate"] - 8.0) < 0.25
    before, after = f["fit_before"]["validation"]["outputs"], f["fit_after"]["validation"]["outputs"]
    assert after["q"]["rms"] < 0.7 * before["q"]["rms"]
    assert after["q"]["rms_raw"] < before["q"]["rms_raw"]
    sensors = {s["effect"]: s for s in
               __import__("json").loads((tmp_path / "out" / "model" / "sensors.json").read_text())}
    assert sensors["structural_mode"]["surface"] == "de"
    assert [m["effect"] for m in r["model"]["outside_the_aircraft"]] == ["structural_mode"]
    assert "natural frequency" in f["explanation"]
    assert 0.0 < f["evidence"]["explained_fraction"] <= 1.0  # a share, not the peak's height over its median
    assert f["evidence"]["peak_over_median"] > 1.0
    summary = r["located"]["summary"]  # what is left is told in the measure the paragraph opens with too
    assert "is still" not in summary or "of it follows the maneuver)" in summary


def _without_mode(p, seed: int = 5):
    """``p`` with q and a_z replaced by their smoothed records plus white noise of their level:
    no mode left to fit."""
    from dataclasses import replace
    rng = np.random.default_rng(seed)
    raw = dict(p.raw)
    for c in ("q", "az"):
        raw[c] = p.smooth[c] + rng.normal(scale=p.noise_std[c], size=p.n)
    return replace(p, raw=raw)


def test_a_mode_the_identification_does_not_ring_is_fitted_on_the_validation(driven):
    """attach_mode_models: the identification maneuver holds no mode to fit, the validation
    maneuver does: the model is the validation's, ``fitted_on`` says so, and the finding's
    estimate becomes the fitted natural frequency (the spectral peak kept apart)."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.mode_model import attach_mode_models
    truth, p = driven
    f = Candidate("structural_mode", None, "q", "mode_frequency_hz", 7.7, 0.25, 10.0, 0.2, "Hz", "peak", True)
    attach_mode_models([f], {"identification": _without_mode(p), "validation": p})
    assert f.details["mode_model"]["fitted_on"] == "validation"
    assert f.details["spectral_peak_hz"] == [7.7, 0.25]
    assert f.estimate == f.details["mode_model"]["frequency_hz"] and abs(f.estimate - truth.frequency_hz) < 0.2
    g = Candidate("structural_mode", None, "q", "mode_frequency_hz", 7.7, 0.25, 10.0, 0.2, "Hz", "peak", True)
    attach_mode_models([g], {"identification": _without_mode(p)})
    assert g.details["mode_model"] is None and g.estimate == 7.7  # the notch stands for it


def test_the_mode_band_is_put_back_only_where_the_mode_rings(driven):
    """with_mode_band adds the band of what the common filter removed to the outputs the mode
    has gains in, and leaves the others as smoothed."""
    from harness.diagnosis.mode_model import with_mode_band
    _, p = driven
    m = DrivenMode(8.0, 0.01, 0.02, "de", {"q": (-0.5, 0.0)})
    out = with_mode_band(p, p.smooth, [m])
    assert np.array_equal(out["az"], p.smooth["az"]) and np.array_equal(out["alpha"], p.smooth["alpha"])
    added = out["q"] - p.smooth["q"]
    assert np.allclose(added, band_part(p.raw["q"] - p.smooth["q"], p.dt, m.band_hz()))
    assert np.std(added) > 0.5 * np.std(band_part(p.raw["q"], p.dt, m.band_hz()))


def test_a_record_whose_smoothing_keeps_the_whole_band_has_none_to_search(driven):
    """spectra.untestable_at: a common-filter cut-off of 9 Hz is taken as the motion's 3 Hz
    (spectra.RIGID_BODY_CUTOFF_HZ), so a 50 Hz record searches 6-22.5 Hz (twice it,
    spectra.MOTION_POWER_FACTOR); at 10 Hz that floor lies above 0.9 of Nyquist (4.5 Hz): no
    band, said so (not an inverted band)."""
    from dataclasses import replace

    from harness.diagnosis.spectra import untestable_at
    _, p = driven
    quiet = replace(p, common_cutoff_hz=9.0)
    assert "band is 6.0-22.5 Hz" in untestable_at(quiet, "q", 4.0) and untestable_at(quiet, "q", 8.0) == ""
    why = untestable_at(replace(quiet, dt=0.1), "q", 4.0)
    assert why.startswith("it has no spectral band to search") and "(4.5 Hz)" in why
    assert untestable_at(p, "q", 8.0) == ""


def test_a_record_too_short_for_the_spectral_test_is_not_fitted(driven):
    from dataclasses import replace
    _, p = driven
    k = int(6.0 / p.dt)
    short = replace(p, t=p.t[:k], raw={c: v[:k] for c, v in p.raw.items()},
                    smooth={c: v[:k] for c, v in p.smooth.items()})
    assert fit_driven_mode(short, "q", 8.0) is None
