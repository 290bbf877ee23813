"""The structural-mode peak test against inputs' spectral lines and across two maneuvers
(harness.diagnosis.spectra, replication.name_mode_on_both, validation._mode_check)."""
from types import SimpleNamespace

import numpy as np
from scipy import signal, stats

from estimators.smoothing import sine_series_filter
from harness.diagnosis import spectra
from harness.diagnosis.evidence import Candidate

FS, N = 50.0, 1500


def _record(**raw):
    """A stand-in for a prepared recording: ``raw`` channels, nothing smoothed out."""
    return SimpleNamespace(dt=1.0 / FS, n=N, raw=raw, smooth={c: np.zeros(N) for c in raw}, common_cutoff_hz=0.7)


def _roll_echo(seed: int):
    """An aileron with a 5 Hz line (an input harmonic) and the roll rate of a fast roll mode
    (time constant 0.1 s) that follows it, each with its own white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    da = 0.004 * np.sin(2 * np.pi * 5.0 * t) + 0.002 * rng.normal(size=N)
    roll = signal.lti([1.0], [0.1, 1.0])
    _, p, _ = signal.lsim(roll, da, t)
    return da, p + 0.0006 * rng.normal(size=N)


def test_a_roll_rate_following_the_ailerons_line_is_no_mode():
    """The roll rate's 5 Hz line beats white noise by far (a 'mode' when the aileron is not
    recorded), but it is the aileron line's echo: it stands no further above its median than
    the line does."""
    da, p = _roll_echo(1)
    alone = spectra.structural_peak(_record(p=p))
    assert alone.p_value < spectra.FISHER_P and abs(alone.frequency_hz - 5.0) < 0.3
    with_input = spectra.structural_peak(_record(p=p, da=da))
    assert with_input is None or with_input.p_value > 1e-3
    assert spectra.peak_at(_record(p=p, da=da), "p", 5.0) == 1.0


def test_a_mode_ringing_far_above_a_weak_stabilator_line_is_still_a_mode():
    """An 8 Hz mode in q where the stabilator carries a weak line of its own (an input
    harmonic) stands far further above its median than the line: a mode. The aileron's line
    at the same frequency drives no pitch channel."""
    rng = np.random.default_rng(2)
    t = np.arange(N) / FS
    de = 0.0015 * np.sin(2 * np.pi * 8.0 * t) + 0.002 * rng.normal(size=N)
    da = 0.01 * np.sin(2 * np.pi * 8.0 * t) + 0.002 * rng.normal(size=N)
    q = 0.003 * np.sin(2 * np.pi * 8.0 * t) + 0.002 * rng.normal(size=N)
    peak = spectra.structural_peak(_record(q=q, de=de, da=da))
    assert peak.p_value < spectra.FISHER_P and abs(peak.frequency_hz - 8.0) < 0.25
    lines = spectra.input_lines(_record(q=q, de=de, da=da), 100, spectra.welch_dof(N, 100), 2.5)
    assert lines["de"][16] > 1.0 and lines["da"][16] > lines["de"][16]  # 8 Hz, 0.5 Hz bins


def test_echo_is_the_f_test_of_the_two_ratios():
    """spectra.echoes: a peak on a driving surface's line is an echo unless the ratio of the
    two ratios beats F(dof, dof) at ECHO_P; no line, or a surface that does not drive the
    channel, is no echo."""
    dof = 55.0
    limit = stats.f.isf(spectra.ECHO_P, dof, dof)
    line = np.zeros(10)
    line[4] = 2.0
    idx = np.array([4, 4, 7])
    ratio = np.array([2.0 * limit * 0.99, 2.0 * limit * 1.01, 9.0])
    assert spectra.echoes(ratio, idx, "q", {"de": line}, dof).tolist() == [True, False, False]
    assert not spectra.echoes(ratio, idx, "q", {"da": line}, dof).any()


def test_peak_at_a_given_frequency():
    """spectra.peak_at: three ordinates at a frequency given in advance, Bonferroni over the
    three; NaN where the record cannot tell (spectra.untestable_at: an unrecorded channel, a
    frequency outside the searched band)."""
    rng = np.random.default_rng(4)
    t = np.arange(N) / FS
    q = 0.0012 * np.sin(2 * np.pi * 8.0 * t) + 0.002 * rng.normal(size=N)
    rec = _record(q=q)
    assert spectra.peak_at(rec, "q", 8.0) < spectra.MODE_CONFIRM_P
    assert spectra.peak_at(rec, "q", 13.0) > spectra.MODE_CONFIRM_P
    assert np.isnan(spectra.peak_at(rec, "az", 8.0)) and np.isnan(spectra.peak_at(rec, "q", 30.0))
    assert "does not record az" in spectra.untestable_at(rec, "az", 8.0)
    assert "band is 2.0-22.5 Hz" in spectra.untestable_at(rec, "q", 1.5)
    slow = _record(q=rec.raw["q"])
    slow.common_cutoff_hz = 2.9  # the search starts at twice it: 4 Hz is kept as motion
    assert np.isnan(spectra.peak_at(slow, "q", 4.0)) and "cut-off of 2.9 Hz" in spectra.untestable_at(slow, "q", 4.0)
    assert spectra.peak_at(slow, "q", 8.0) < spectra.MODE_CONFIRM_P


def test_a_mode_inside_a_quiet_records_filter_band_is_still_searched():
    """A quiet record's common filter keeps everything to 20 Hz, a 9.4 Hz mode with it: the
    mode search takes the motion to end at RIGID_BODY_CUTOFF_HZ (3 Hz), searches from
    MOTION_POWER_FACTOR times that and finds the mode; what the common filter itself leaves holds nothing."""
    rng = np.random.default_rng(5)
    t = np.arange(N) / FS
    q = 0.05 * np.sin(2 * np.pi * 0.4 * t) + 0.002 * np.sin(2 * np.pi * 9.4 * t) + 1e-5 * rng.normal(size=N)
    k = np.arange(1, N - 1)
    w = (k / (2.0 * t[-1]) <= 20.0).astype(float)
    rec = SimpleNamespace(dt=1.0 / FS, n=N, t=t, raw={"q": q}, smooth={"q": sine_series_filter(q, w)}, weights=w,
                          common_cutoff_hz=20.0)
    assert spectra.motion_cutoff_hz(rec) == spectra.RIGID_BODY_CUTOFF_HZ
    assert spectra.search_floor_hz(rec) == spectra.MOTION_POWER_FACTOR * spectra.RIGID_BODY_CUTOFF_HZ
    assert np.std(rec.raw["q"] - rec.smooth["q"]) < 1e-4 < 1e-3 < np.std(spectra.mode_residual(rec, "q"))
    peak = spectra.structural_peak(rec)
    assert peak.p_value < spectra.FISHER_P and abs(peak.frequency_hz - 9.4) < 0.1
    assert spectra.peak_at(rec, "q", 9.4) < spectra.MODE_CONFIRM_P


def _analysis(rec, peak, candidates=()):
    return SimpleNamespace(prepared=rec, peak=peak, candidates=list(candidates))


def test_a_mode_the_validation_rings_is_named_when_the_identification_shows_it_there():
    """replication.name_mode_on_both: the validation's peak (p < FISHER_P) named when the
    identification's spectrum shows an excess there (p < MODE_CONFIRM_P) though not enough
    to name alone; not when it shows nothing there, nor when it names a mode itself. The
    validation check of the finding is then 'confirmed'."""
    from harness.diagnosis.replication import name_mode_on_both
    from harness.diagnosis.validation import validation_check
    rng = np.random.default_rng(6)
    t = np.arange(N) / FS
    loud = _record(q=0.006 * np.sin(2 * np.pi * 8.0 * t) + 0.002 * rng.normal(size=N))
    weak = _record(q=0.0005 * np.sin(2 * np.pi * 8.0 * t) + 0.002 * rng.normal(size=N))
    quiet = _record(q=0.002 * rng.normal(size=N))
    pv = spectra.structural_peak(loud)
    assert pv.p_value < spectra.FISHER_P
    assert spectra.structural_peak(weak).p_value > spectra.FISHER_P
    a = _analysis(weak, spectra.structural_peak(weak))
    named = name_mode_on_both(a, _analysis(loud, pv))
    assert named is not None and named.selected and named.estimate == pv.frequency_hz
    assert [c.parameter for c in a.candidates] == ["mode_frequency_hz"]
    check = validation_check(_analysis(loud, pv), named)
    assert check["status"] == "confirmed"
    from harness.diagnosis.verdict import finding_dict
    text = finding_dict(named, {}, {}, check)["explanation"]
    assert "too weakly to name alone" in text and "validation maneuver's peak" in text
    assert name_mode_on_both(_analysis(quiet, None), _analysis(loud, pv)) is None
    own = Candidate("structural_mode", None, "q", "mode_frequency_hz", 12.0, 0.25, 9.0, 3.0, "Hz", "", True)
    assert name_mode_on_both(_analysis(weak, None, [own]), _analysis(loud, pv)) is None
    # a mode named on the identification alone that the validation maneuver does not ring
    check = validation_check(_analysis(quiet, None), own)
    assert check["status"] == "untested" and "does not show it" in check["reason"]
    lateral = _record(p=quiet.raw["q"])
    check = validation_check(_analysis(lateral, None), own)
    assert check["status"] == "untested" and "cannot show the mode: it does not record q" in check["reason"]
    # an identification that cannot tell (it does not record q): named on the validation alone
    alone = name_mode_on_both(_analysis(_record(p=quiet.raw["q"]), None), _analysis(loud, pv))
    assert alone.details["replicated"]["identification_cannot"] == "it does not record q"


def test_a_mode_the_identification_could_not_ring_is_named_on_the_validation_alone():
    """replication.name_mode_on_both with spectra.predicted_peak_p: the validation's
    stabilator carries power at 8 Hz (band-limited noise below 12 Hz, above its white floor)
    and rings the mode; an identification whose stabilator carries nothing there but its
    floor could not have shown it, and the mode is named on the validation alone, saying
    so. An identification whose stabilator drives 8 Hz as hard and shows nothing there
    contradicts it: not named."""
    from harness.diagnosis.replication import name_mode_on_both
    rng = np.random.default_rng(8)
    b, a = signal.butter(4, 12.0 / (FS / 2))
    mode = signal.lti([(2 * np.pi * 8.0) ** 2], [1.0, 2 * 0.02 * 2 * np.pi * 8.0, (2 * np.pi * 8.0) ** 2])
    t = np.arange(N) / FS

    def record(drive: float, rings: bool):
        de = drive * signal.filtfilt(b, a, rng.normal(size=N))
        _, x, _ = signal.lsim(mode, de, t)
        q = (0.15 * (x - de) if rings else 0.0) + 0.0005 * rng.normal(size=N)
        return _record(q=q, de=de + 0.0002 * rng.normal(size=N))

    val = record(0.01, True)
    pv = spectra.structural_peak(val)
    assert pv.p_value < spectra.FISHER_P and abs(pv.frequency_hz - 8.0) < 0.5
    quiet = record(0.0, False)
    assert spectra.predicted_peak_p(quiet, val, "q", pv.frequency_hz) >= spectra.MODE_CONFIRM_P
    named = name_mode_on_both(_analysis(quiet, None), _analysis(val, pv))
    assert named is not None and "validation maneuver alone" in named.reason
    assert "too little power" in named.details["replicated"]["identification_cannot"]
    from harness.diagnosis.validation import validation_check
    from harness.diagnosis.verdict import finding_dict
    check = validation_check(_analysis(val, pv), named)
    assert check["status"] == "untested" and "validation maneuver's own spectrum" in check["reason"]
    text = finding_dict(named, {}, {}, check)["explanation"]
    assert "rests on the validation maneuver alone" in text and "identification maneuver alone" not in text
    driven = record(0.01, False)
    assert spectra.predicted_peak_p(driven, val, "q", pv.frequency_hz) < spectra.MODE_CONFIRM_P
    assert name_mode_on_both(_analysis(driven, None), _analysis(val, pv)) is None


def test_a_mode_under_a_tenth_of_the_practical_bias_is_not_named():
    """A peak significant against a noise-free record's rounding (a probe's c172x at 200 Hz:
    75 Hz in a_y, 6e-10 g RMS, p 6e-20) is not a mode worth naming; one carrying the
    smallest true mode's RMS of the sweeps (q 0.00096 rad/s) is."""
    from harness.diagnosis.gust_rules import MODE_PRACTICAL_SHARE, mode_candidate
    from harness.diagnosis.kinematics import PRACTICAL
    from harness.diagnosis.spectra import PeakTest
    tiny = mode_candidate(PeakTest("ay", 74.99, 0.25, 5.8e-10, 4.7, 5.9e-20, 0.0008), True, "peak")
    assert not tiny.selected and tiny.reason.startswith("not named, too small to matter")
    real = mode_candidate(PeakTest("q", 9.51, 0.05, 0.00096, 9.0, 1e-12, 0.029), True, "peak")
    assert real.selected and real.reason == "peak"
    assert 0.00096 > MODE_PRACTICAL_SHARE * PRACTICAL["bias"]["q"]


def test_a_peak_under_the_search_floor_is_found_in_its_own_band():
    """spectra.sub_floor_peak: a record whose motion ends at 2.9 Hz is searched for modes from
    5.8 Hz (twice it); a 4 Hz line in q lies under that floor, is no structural peak, and is the
    peak of the band between the two. A record with nothing there has none."""
    rng = np.random.default_rng(6)
    t = np.arange(N) / FS
    q = 0.0015 * np.sin(2 * np.pi * 4.0 * t) + 0.002 * rng.normal(size=N)
    rec = _record(q=q)
    rec.common_cutoff_hz = 2.9
    assert spectra.search_floor_hz(rec) == 2.0 * 2.9
    above = spectra.structural_peak(rec)
    assert above is None or above.p_value > spectra.FISHER_P
    peak = spectra.sub_floor_peak(rec)
    assert peak.p_value < spectra.FISHER_P and abs(peak.frequency_hz - 4.0) < 0.3
    quiet = _record(q=0.002 * rng.normal(size=N))
    quiet.common_cutoff_hz = 2.9
    found = spectra.sub_floor_peak(quiet)
    assert found is None or found.p_value > spectra.FISHER_P


def test_notched_takes_a_line_out_of_the_rates_and_accelerations_only():
    """spectra.notched: a 4 Hz line is taken out of q (to under 5 % of its amplitude) and the
    surface is left as it was; a frequency beyond Nyquist changes nothing."""
    t = np.arange(N) / FS
    raw = {"q": np.sin(2 * np.pi * 4.0 * t), "de": np.sin(2 * np.pi * 4.0 * t)}
    out = spectra.notched(raw, 1.0 / FS, 4.0)
    assert np.std(out["q"][200:-200]) < 0.05 * np.std(raw["q"])
    assert out["de"] is raw["de"]
    assert spectra.notched(raw, 1.0 / FS, 30.0) is raw
