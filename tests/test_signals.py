"""Tests of the maneuver input designs (maneuvers.multistep, sweeps, multisine,
combine, inputs), pinned to exact, hand-derived truth."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from maneuvers.base import InputSignal, InputSpecError
from maneuvers.combine import Sequence, Simultaneous
from maneuvers.inputs import (
    INPUT_KINDS,
    default_lateral_input,
    default_three_axis_input,
    make_input,
)
from maneuvers.multisine import Multisine, allocate_harmonics
from maneuvers.multisine_phases import relative_peak_factor, schroeder_phases
from maneuvers.multistep import MultiStep, doublet, multistep, stabilator_2112
from maneuvers.sweeps import FrequencySweep

A = np.deg2rad(1.0)
T50 = np.arange(1500) / 50.0  # 0 .. 29.98 s at 50 Hz
T64 = np.arange(64 * 40) / 64.0  # dyadic grid: every sample exactly representable


def piecewise(t: np.ndarray, pieces: list[tuple[float, float, float]]) -> np.ndarray:
    """Reference signal: value v on [a, b) for each (a, b, v), 0 elsewhere."""
    out = np.zeros_like(t)
    for a, b, v in pieces:
        out[(t >= a) & (t < b)] = v
    return out


# ---------------------------------------------------------------- multi-step
def test_2112_exact_on_50hz_grid() -> None:
    spec = stabilator_2112()
    expected = piecewise(T50, [(1, 3, A), (3, 4, -A), (4, 5, A), (5, 7, -A)])
    got = spec.deflections(T50)
    assert set(got) == {"de"}
    np.testing.assert_array_equal(got["de"], expected)
    assert spec.name == "stabilator_2112"
    assert spec.describe() == "stabilator 2-1-1-2, 1 deg, 1 s unit pulse"
    assert (spec.start_s, spec.active_duration_s, spec.duration_s) == (1.0, 6.0, 8.0)


def test_doublet_and_3211_exact() -> None:
    d = doublet("da", amplitude_deg=2.0, unit_pulse_s=0.5, start_s=1.0)
    a2 = np.deg2rad(2.0)
    np.testing.assert_array_equal(
        d.deflections(T50)["da"], piecewise(T50, [(1, 1.5, a2), (1.5, 2, -a2)])
    )
    m = multistep("3-2-1-1", "dr", 1.0, 1.0, start_s=2.0)
    np.testing.assert_array_equal(
        m.deflections(T50)["dr"],
        piecewise(T50, [(2, 5, A), (5, 7, -A), (7, 8, A), (8, 9, -A)]),
    )
    s211 = multistep("2-1-1", "de")
    np.testing.assert_array_equal(
        s211.deflections(T50)["de"], piecewise(T50, [(1, 3, A), (3, 4, -A), (4, 5, A)])
    )


def test_multistep_half_open_edges_and_scalar_time() -> None:
    spec = stabilator_2112()
    values = [float(spec.deflections(t)["de"]) for t in (0.999, 1.0, 2.999, 3.0, 6.999, 7.0)]
    assert values == [0.0, A, A, -A, -A, 0.0]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(pulse_widths=(1, -1), signs=(1, -1)), "pulse_widths"),
        (dict(pulse_widths=(1, 1), signs=(1,)), "signs has 1"),
        (dict(pulse_widths=(1, 1), signs=(1, 2)), "signs must"),
        (dict(pulse_widths=(), signs=()), "at least one pulse"),
        (dict(pulse_widths=(1, 1), signs=(1, -1), amplitude_deg=-1.0), "amplitude_deg"),
        (dict(pulse_widths=(1, 1), signs=(1, -1), unit_pulse_s=0.0), "unit_pulse_s"),
        (dict(pulse_widths=(1, 1), signs=(1, -1), start_s=-1.0), "start_s"),
        (dict(pulse_widths=(1, 1), signs=(1, -1), surface="elevator"), "valid surfaces"),
    ],
)
def test_multistep_rejects_bad_specs(kwargs: dict, match: str) -> None:
    args = {"surface": "de", **kwargs}
    with pytest.raises(InputSpecError, match=match):
        MultiStep(**args)


# -------------------------------------------------------------------- sweeps
@pytest.mark.parametrize("kind", ["linear", "logarithmic"])
def test_sweep_frequency_law_and_zero_ends(kind: str) -> None:
    sw = FrequencySweep("de", 0.2, 2.0, 20.0, amplitude_deg=1.0, kind=kind)
    big_t = sw.active_duration_s
    assert 20.0 <= big_t < 20.0 + 1.0 / (2 * sw.mean_frequency_hz) + 1e-12
    # numerical derivative of the (unwrapped, closed-form) phase
    h = 1e-5
    f_start = (sw.phase_rad(h) - sw.phase_rad(0.0)) / (2 * np.pi * h)
    f_end = (sw.phase_rad(big_t) - sw.phase_rad(big_t - h)) / (2 * np.pi * h)
    assert f_start == pytest.approx(0.2, rel=1e-4)
    assert f_end == pytest.approx(2.0, rel=1e-4)
    # closed-form phase = cumulative integral of the frequency law
    tau = np.linspace(0.0, big_t, 200001)
    f = sw.instantaneous_frequency_hz(tau)
    integ = np.concatenate(([0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(tau))))
    np.testing.assert_allclose(sw.phase_rad(tau), 2 * np.pi * integ, atol=1e-6)
    # ends on a whole number of half cycles: starts and ends at zero
    assert sw.phase_rad(big_t) == pytest.approx(np.pi * sw.half_cycles, rel=1e-12)
    t = 1.0 + tau[:-1]
    x = sw.deflections(t)["de"]
    np.testing.assert_allclose(x, A * np.sin(sw.phase_rad(tau[:-1])), rtol=0, atol=1e-15)
    assert x[0] == 0.0
    assert abs(sw.deflections(1.0 + big_t - 1e-9)["de"]) < 1e-7 * A
    # zero crossings of the sampled signal (linearly interpolated), plus the
    # exact zeros at 0 and T: each half cycle's length gives its mean frequency
    j = np.flatnonzero(np.diff(np.signbit(x[1:]))) + 1
    tz = tau[j] - x[j] * (tau[j + 1] - tau[j]) / (x[j + 1] - x[j])
    tz = np.concatenate(([0.0], tz, [big_t]))
    assert tz.size == sw.half_cycles + 1
    f_est = 1.0 / (2.0 * np.diff(tz))
    f_mid = sw.instantaneous_frequency_hz(0.5 * (tz[1:] + tz[:-1]))
    np.testing.assert_allclose(f_est, f_mid, rtol=1e-2)
    # extrapolate the crossing estimates (linear in f, or in log f) to 0 and T
    mid = 0.5 * (tz[1:] + tz[:-1])
    g = f_est if kind == "linear" else np.log(f_est)
    ends = [np.polyval(np.polyfit(mid[sl], g[sl], 1), at)
            for sl, at in ((slice(0, 6), 0.0), (slice(-6, None), big_t))]
    if kind != "linear":
        ends = list(np.exp(ends))
    assert ends[0] == pytest.approx(0.2, rel=1e-2)
    assert ends[1] == pytest.approx(2.0, rel=1e-2)


def test_sweep_taper_and_errors() -> None:
    sw = FrequencySweep("da", 0.5, 3.0, 8.0, taper_s=1.0)
    big_t = sw.active_duration_s
    tau = np.linspace(0.0, big_t, 80001)[:-1]
    x = sw.deflections(1.0 + tau)["da"]
    w = np.ones_like(tau)
    w[tau < 1.0] = 0.5 * (1 - np.cos(np.pi * tau[tau < 1.0]))
    w[tau > big_t - 1.0] = 0.5 * (1 - np.cos(np.pi * (big_t - tau[tau > big_t - 1.0])))
    np.testing.assert_allclose(x, A * w * np.sin(sw.phase_rad(tau)), rtol=0, atol=1e-15)
    assert np.abs(x[(tau > 1.0) & (tau < big_t - 1.0)]).max() == pytest.approx(A, rel=1e-4)
    with pytest.raises(InputSpecError, match="f0_hz < f1_hz"):
        FrequencySweep("de", 2.0, 1.0, 10.0)
    with pytest.raises(InputSpecError, match="Nyquist"):
        FrequencySweep("de", 0.1, 30.0, 10.0, sample_rate_hz=50.0)
    with pytest.raises(InputSpecError, match="f0_hz"):
        FrequencySweep("de", 0.0, 1.0, 10.0, kind="logarithmic")
    with pytest.raises(InputSpecError, match="taper"):
        FrequencySweep("de", 0.1, 1.0, 10.0, taper_s=6.0)
    with pytest.raises(InputSpecError, match="sweep_duration_s"):
        FrequencySweep("de", 0.1, 1.0, -10.0)


# ----------------------------------------------------------------- multisine
def sample_period(ms: Multisine, m: int = 512) -> dict[str, np.ndarray]:
    """Signals on the uniform grid of m points over the active window [0, T)."""
    t = ms.start_s + ms.period_s * np.arange(m) / m
    return ms.deflections(t)


def test_schroeder_multisine_flat_power_spectrum() -> None:
    ms = Multisine("de", period_s=10.0, f_min_hz=0.1, f_max_hz=1.0, phases="schroeder")
    assert ms.harmonic_sets == (tuple(range(1, 11)),)
    x = sample_period(ms)["de"]
    mag = np.abs(np.fft.rfft(x))
    design = mag[1:11]
    np.testing.assert_allclose(design, design[0], rtol=1e-9)
    others = np.delete(mag, np.arange(1, 11))
    assert others.max() < 1e-9 * design[0]


def test_schroeder_phase_formula() -> None:
    n = 7
    expected = np.mod([-math.pi * k * (k - 1) / n for k in range(1, n + 1)], 2 * math.pi)
    np.testing.assert_allclose(schroeder_phases(n), expected, atol=1e-12)


@pytest.fixture(scope="module")
def ms3() -> Multisine:
    """Optimised three-surface multisine, 0.1-2 Hz, T = 10 s (designed once)."""
    return make_input("multisine", "de,da,dr", period_s=10.0, f_min_hz=0.1, f_max_hz=2.0)


def test_orthogonal_multisines(ms3: Multisine) -> None:
    ms = ms3
    sets = ms.harmonic_sets
    assert sets == (
        (1, 4, 7, 10, 13, 16, 19),
        (2, 5, 8, 11, 14, 17, 20),
        (3, 6, 9, 12, 15, 18),
    )
    assert not (set(sets[0]) & set(sets[1]) or set(sets[0]) & set(sets[2])
                or set(sets[1]) & set(sets[2]))
    x = sample_period(ms)
    for a in ("de", "da", "dr"):
        for b in ("de", "da", "dr"):
            if a < b:
                inner = np.dot(x[a], x[b])
                assert abs(inner) <= 1e-12 * np.linalg.norm(x[a]) * np.linalg.norm(x[b])
    # each surface's spectrum lives only on its own harmonics
    for s, ks in zip(ms.surfaces, sets):
        mag = np.abs(np.fft.rfft(x[s]))
        assert np.delete(mag, ks).max() < 1e-9 * mag[list(ks)].min()


def test_multisine_peak_zero_start_and_window() -> None:
    ms = Multisine(("de", "dr"), period_s=8.0, f_min_hz=0.125, f_max_hz=1.5,
                   amplitude_deg=(1.0, 2.0))
    t = np.arange(0, ms.duration_s + 2, 1e-3)
    x = ms.deflections(t)
    for s, amp in (("de", 1.0), ("dr", 2.0)):
        peak = np.abs(x[s]).max()
        assert np.deg2rad(amp) * (1 - 2e-3) <= peak <= np.deg2rad(amp) * (1 + 1e-12)
        # starts at zero; by periodicity it ends at zero (value just before T)
        assert abs(ms.deflections(ms.start_s)[s]) < 1e-12
        end = ms.deflections(ms.start_s + ms.period_s - 1e-9)[s]
        assert abs(end) < 1e-6
    assert ms.active_duration_s == 8.0 and ms.duration_s == 10.0


def test_optimized_phases_lower_rpf(ms3: Multisine) -> None:
    ms1 = Multisine("de", period_s=10.0, f_min_hz=0.1, f_max_hz=1.0)
    d = ms1.design
    print(f"\nRPF 1 surface, 10 harmonics: Schroeder {d.rpf_schroeder[0]:.4f} "
          f"-> optimised {d.rpf[0]:.4f}")
    assert d.rpf[0] <= d.rpf_schroeder[0]
    assert d.rpf[0] < 1.2
    # the reported RPF matches the definition applied to samples
    x = sample_period(ms1, 8192)["de"]
    assert relative_peak_factor(x) == pytest.approx(d.rpf[0], rel=1e-3)
    ms2 = Multisine(("de", "da"), period_s=10.0, f_min_hz=0.1, f_max_hz=2.0)
    for n, ms in ((2, ms2), (3, ms3)):
        dd = ms.design
        print(f"RPF {n} surfaces, 0.1-2 Hz: Schroeder "
              f"{[round(r, 4) for r in dd.rpf_schroeder]} -> optimised "
              f"{[round(r, 4) for r in dd.rpf]}")
        assert all(b <= a for a, b in zip(dd.rpf_schroeder, dd.rpf))
    assert relative_peak_factor(np.sin(2 * np.pi * np.arange(100) / 100)) == pytest.approx(1.0)


def test_multisine_explicit_harmonics() -> None:
    single = Multisine("dr", period_s=4.0, harmonics=(3, 1, 2), phases="schroeder")
    assert single.harmonic_sets == ((1, 2, 3),)
    np.testing.assert_allclose(single.frequencies_hz()[0], [0.25, 0.5, 0.75])
    pair = Multisine(("de", "da"), period_s=4.0, harmonics=((1, 3), (2, 4)),
                     amplitude_deg=(1.0, 3.0), phases="schroeder")
    x = sample_period(pair, 64)
    assert np.abs(x["da"]).max() <= np.deg2rad(3.0) * (1 + 1e-12)
    assert abs(np.dot(x["de"], x["da"])) < 1e-12 * np.linalg.norm(x["de"]) * np.linalg.norm(
        x["da"])


def test_multisine_errors() -> None:
    with pytest.raises(InputSpecError, match="2 amplitudes given for 3 surfaces"):
        Multisine(("de", "da", "dr"), f_min_hz=0.1, f_max_hz=1.0, amplitude_deg=(1.0, 2.0))
    with pytest.raises(InputSpecError, match="amplitude_deg for da"):
        Multisine(("de", "da"), f_min_hz=0.1, f_max_hz=1.0, amplitude_deg=(1.0, -2.0))
    with pytest.raises(InputSpecError, match="give a band"):
        Multisine("de")
    with pytest.raises(InputSpecError, match="distinct integers"):
        Multisine("de", harmonics=((1, 1.5),))
    with pytest.raises(InputSpecError, match="fewer than the 3"):
        allocate_harmonics(10.0, 0.1, 0.2, 3)
    with pytest.raises(InputSpecError, match="f_min_hz < f_max_hz"):
        Multisine("de", f_min_hz=1.0, f_max_hz=0.5)
    with pytest.raises(InputSpecError, match="empty harmonic set"):
        Multisine(("de", "da"), harmonics=((1, 2), ()))
    with pytest.raises(InputSpecError, match="overlap"):
        Multisine(("de", "da"), harmonics=((1, 2), (2, 3)))
    with pytest.raises(InputSpecError, match="not both"):
        Multisine("de", f_min_hz=0.1, f_max_hz=1.0, harmonics=((1, 2),))
    with pytest.raises(InputSpecError, match="Nyquist"):
        Multisine("de", period_s=10.0, f_min_hz=0.1, f_max_hz=30.0, sample_rate_hz=50.0)
    with pytest.raises(InputSpecError, match="more than once"):
        Multisine(("de", "de"), f_min_hz=0.1, f_max_hz=1.0)
    with pytest.raises(InputSpecError, match="phase method"):
        Multisine("de", f_min_hz=0.1, f_max_hz=1.0, phases="random")  # type: ignore[arg-type]


# -------------------------------------------------------------- combinations
def test_sequence_timing() -> None:
    seq = default_lateral_input()
    assert seq.surfaces == ("da", "dr")
    assert seq.offsets_s == (0.0, 5.0)
    assert seq.active_windows_s == ((1.0, 3.0), (6.0, 10.0))
    assert (seq.start_s, seq.active_duration_s, seq.duration_s) == (1.0, 9.0, 11.0)
    a2 = np.deg2rad(2.0)
    x = seq.deflections(T64)
    np.testing.assert_array_equal(x["da"], piecewise(T64, [(1, 2, a2), (2, 3, -a2)]))
    np.testing.assert_array_equal(
        x["dr"], piecewise(T64, [(6, 8, a2), (8, 9, -a2), (9, 10, a2)])
    )


def test_three_axis_default_timing() -> None:
    seq = default_three_axis_input()
    assert seq.surfaces == ("de", "da", "dr")
    assert seq.active_windows_s == ((1.0, 7.0), (10.0, 12.0), (15.0, 19.0))
    assert seq.duration_s == 20.0
    x = seq.deflections(T64)
    active = {s: T64[x[s] != 0] for s in x}
    assert (active["de"].min(), active["de"].max()) == (1.0, 7.0 - 1 / 64)
    assert (active["da"].min(), active["da"].max()) == (10.0, 12.0 - 1 / 64)
    assert (active["dr"].min(), active["dr"].max()) == (15.0, 19.0 - 1 / 64)


def test_sequence_same_surface_twice_and_nesting() -> None:
    seq = Sequence((stabilator_2112(), doublet("de")), gap_s=0.5)
    assert seq.surfaces == ("de",)
    x = seq.deflections(T64)["de"]
    ref = piecewise(T64, [(1, 3, A), (3, 4, -A), (4, 5, A), (5, 7, -A),
                          (9.5, 10.5, A), (10.5, 11.5, -A)])
    np.testing.assert_array_equal(x, ref)
    assert seq.duration_s == 8.0 + 0.5 + 4.0
    outer = Sequence((seq, doublet("da")))
    assert outer.active_windows_s[-1] == (13.5, 15.5)


def test_simultaneous_timing_and_refusal() -> None:
    sim = Simultaneous((stabilator_2112(), doublet("da", start_s=2.0, quiet_after_s=3.0)))
    assert sim.surfaces == ("de", "da")
    assert (sim.start_s, sim.active_duration_s, sim.duration_s) == (1.0, 6.0, 8.0)
    x = sim.deflections(T64)
    np.testing.assert_array_equal(x["da"], piecewise(T64, [(2, 3, A), (3, 4, -A)]))
    np.testing.assert_array_equal(x["de"], stabilator_2112().deflections(T64)["de"])
    with pytest.raises(InputSpecError, match="surface 'de' is driven by both part 0"):
        Simultaneous((stabilator_2112(), doublet("de")))
    ms = Multisine(("de", "da"), f_min_hz=0.1, f_max_hz=1.0)
    with pytest.raises(InputSpecError, match="'da'"):
        Simultaneous((ms, doublet("da")))
    with pytest.raises(InputSpecError, match="at least one part"):
        Sequence(())
    with pytest.raises(TypeError, match="does not implement InputSignal"):
        Sequence((stabilator_2112(), "doublet"))  # type: ignore[arg-type]


# ------------------------------------------------------ protocol and registry
@pytest.fixture(scope="module")
def all_specs(ms3: Multisine) -> list[InputSignal]:
    """One of each registry kind plus combinations (immutable, so shared)."""
    specs = [ms3 if k == "multisine" else make_input(k, "da") for k in INPUT_KINDS]
    specs += [
        FrequencySweep("dr", 0.1, 1.0, 5.0, taper_s=1.0),
        default_lateral_input(),
        default_three_axis_input(),
        Simultaneous((doublet("de"), FrequencySweep("da", 0.2, 1.0, 4.0))),
    ]
    return specs


def test_every_spec_zero_outside_active_window(all_specs: list[InputSignal]) -> None:
    for spec in all_specs:
        assert isinstance(spec, InputSignal)
        t = np.arange(0.0, spec.duration_s + 5.0, 1e-2)
        x = spec.deflections(t)
        assert tuple(x) == spec.surfaces
        start, end = spec.start_s, spec.start_s + spec.active_duration_s
        assert spec.start_s >= 1.0 and spec.duration_s - end >= 1.0
        outside = (t < start) | (t >= end)
        for s, v in x.items():
            assert v.shape == t.shape
            assert np.all(v[outside] == 0.0), (spec.name, s)
            assert np.any(v != 0.0)
        assert isinstance(spec.describe(), str) and "\n" not in spec.describe()


def test_specs_are_frozen(all_specs: list[InputSignal]) -> None:
    for spec in all_specs:
        field = dataclasses.fields(spec)[0].name  # type: ignore[arg-type]
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(spec, field, None)
        with pytest.raises(dataclasses.FrozenInstanceError):
            spec.name = "x"  # type: ignore[misc]


def test_registry_kinds_and_errors() -> None:
    assert INPUT_KINDS == (
        "doublet", "2-1-1", "2-1-1-2", "3-2-1-1", "sweep-linear", "sweep-log", "multisine",
    )
    spec = make_input("2-1-1-2")
    assert spec == stabilator_2112()
    assert make_input("Sweep-Log", "dr").kind == "logarithmic"  # type: ignore[attr-defined]
    with pytest.raises(InputSpecError) as err:
        make_input("4-3-2-1")
    msg = str(err.value)
    assert "'4-3-2-1'" in msg and all(k in msg for k in INPUT_KINDS)
    with pytest.raises(InputSpecError, match="exactly one surface"):
        make_input("doublet", "de,da")
    with pytest.raises(InputSpecError, match="valid surfaces"):
        make_input("doublet", "elevator")
    with pytest.raises(InputSpecError, match="amplitude_deg"):
        make_input("doublet", amplitude_deg=-2.0)
    with pytest.raises(InputSpecError, match="Nyquist"):
        make_input("sweep-linear", f1_hz=12.0, sample_rate_hz=20.0)
