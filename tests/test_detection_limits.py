"""Detection limits (harness.diagnosis.limits): the size below which a tested parameter could
not have been named, so that a verdict of 'none' says what it rules out."""
from __future__ import annotations

import numpy as np
import pytest

from harness.diagnosis import candidates as cand
from harness.diagnosis.limits import NOT_ENTERED, gain_floor, share_floor
from harness.diagnosis.run import diagnose
from harness.noise import apply_noise
from harness.noise_presets import preset
from harness.recording_io import write_recording
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.multistep import stabilator_2112
from models.aircraft import Aircraft
from models.hidden import HiddenEffect


def _sse(z: np.ndarray, cols: list[np.ndarray]) -> float:
    A = np.column_stack(cols + [np.ones(z.size)])
    r = z - A @ np.linalg.lstsq(A, z, rcond=None)[0]
    return float(r @ r)


def test_gain_floor_is_the_coefficient_whose_entry_removes_exactly_the_minimum_gain():
    """A term estimated at k = gain_floor(...) removes, when it enters, exactly MIN_GAIN of the
    residual variance (the stepwise's gain, (SSE_without − SSE_with)/SSE_without)."""
    rng = np.random.default_rng(7)
    n = 800
    fixed = [np.sin(np.linspace(0, 9, n)), rng.normal(size=n)]
    column = 0.6 * fixed[0] + rng.normal(size=n)
    noise = rng.normal(scale=0.3, size=n)
    A = np.column_stack(fixed + [column, np.ones(n)])
    noise -= A @ np.linalg.lstsq(A, noise, rcond=None)[0]  # its own estimate 0: then k is the estimate
    sse_with = _sse(noise, fixed + [column])
    k = gain_floor(column, fixed, sse_with)
    z = noise + k * column
    without, with_ = _sse(z, fixed), _sse(z, fixed + [column])
    assert with_ == pytest.approx(sse_with, rel=1e-9)
    assert (without - with_) / without == pytest.approx(cand.MIN_GAIN, rel=1e-9)
    assert gain_floor(fixed[0] * 2.0, fixed, sse_with) == np.inf  # in the span of the others


def test_share_floor_inverts_the_practical_share():
    rng = np.random.default_rng(8)
    column, measured = rng.normal(size=500), rng.normal(scale=0.02, size=500)
    k = share_floor(column, measured)
    assert cand.contribution_share(column, k, measured) == pytest.approx(cand.PRACTICAL_SHARE, rel=1e-12)


def _pitch(tmp_path, name, hidden=(), seed=3):
    rec = fly_maneuver(FlightSpec(aircraft=Aircraft("f16", hidden=hidden), input=stabilator_2112(), duration_s=20.0))
    noisy = apply_noise(rec, preset("realistic"), seed=seed)
    clean = noisy.data[[c for c in noisy.data.columns if not c.startswith("truth_")]]
    meta = {k: v for k, v in noisy.meta.items() if k not in ("truth", "simulation")}
    path = tmp_path / f"{name}.csv"
    write_recording(type(noisy)(data=clean, meta=meta, name=name), path)
    return diagnose("f16", path, tmp_path / name, calibrate=False)


@pytest.fixture(scope="module")
def pitch_null(tmp_path_factory):
    return _pitch(tmp_path_factory.mktemp("limits"), "null")


def test_limits_of_a_pitch_null_cover_what_it_tested_and_nothing_else(pitch_null):
    rows = {r["parameter"]: r for r in pitch_null["detection_limits"]}
    assert [f["effect"] for f in pitch_null["findings"]] == ["none"]
    # every longitudinal coefficient error the stepwise tried has a limit; no lateral one (not offered)
    for p in ("Cm_alpha", "Cm_qhat", "Cm_de", "CZ_alpha", "CX_alpha"):
        assert p in rows
    assert not [p for p in rows if p.split("_")[0] in ("CY", "Cl", "Cn")]
    by_candidate = {c["parameter"]: c for c in pitch_null["candidates"]}
    for p, r in rows.items():
        assert r["limit"] == pytest.approx(max(r["floors"].values()))
        assert r["limit"] >= r["floors"]["significance"]
        assert r["std_error"] == pytest.approx(by_candidate[p]["std_error"])
        # an estimate that cleared its limit was withheld by another rule, which the row quotes
        assert ("withheld" in r) == (r["estimate"] >= r["limit"])
        if "withheld" in r:
            reason = by_candidate[p]["reason"]
            assert r["withheld"] == (NOT_ENTERED if reason == "not entered" else reason)
            assert not by_candidate[p]["selected"]
    cm_alpha = rows["Cm_alpha"]
    assert cm_alpha["floors"]["significance"] == pytest.approx(cand.T_IN * by_candidate["Cm_alpha"]["std_error"])
    assert cm_alpha["relative_to_model"] == pytest.approx(cm_alpha["limit"] / abs(cm_alpha["model_value"]))
    assert rows["tau_de"]["limit"] >= 0.04 - 1e-12  # the smallest delay named


def test_an_effect_under_the_limit_is_not_named_and_one_well_above_it_is(pitch_null, tmp_path):
    """C_m,q̂ changes flown through the same noise (the null's limit 0.58, 10 % of the model's
    −5.6, set by the entry t): at 0.4 times the limit the estimate stays under it (not named);
    at three times it the change is named."""
    row = next(r for r in pitch_null["detection_limits"] if r["parameter"] == "Cm_qhat")
    small = _pitch(tmp_path, "small", (HiddenEffect("coefficient_error", -0.4 * row["limit"], regressor="qhat"),))
    assert "Cm_qhat" not in [f["parameter"] for f in small["findings"]]
    big = _pitch(tmp_path, "big", (HiddenEffect("coefficient_error", -3.0 * row["limit"], regressor="qhat"),))
    assert [f["parameter"] for f in big["findings"]][:1] == ["Cm_qhat"]
