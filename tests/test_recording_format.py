"""The canonical recording format: channel table, column names, units and every rule."""

from __future__ import annotations

import math
import pickle
from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd
import pytest

from maneuvers.recording import (
    CHANNELS,
    FORMAT_ID,
    G0_FPS2,
    MASS_KEYS,
    REQUIRED_QUANTITIES,
    Recording,
    TIME_JITTER_TOL,
    RecordingError,
    parse_column,
    to_canonical,
)

SOURCE = "flights/run7.csv"


def make_recording(n: int = 101, dt: float = 0.02, seed: int = 0) -> Recording:
    """A small valid recording with truth, extra channels and nested metadata."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    data: dict[str, np.ndarray] = {"t_s": t}
    for q in REQUIRED_QUANTITIES[1:]:
        data[CHANNELS[q].column] = rng.normal(size=n) * 0.1
    data["V_fps"] = 500.0 + rng.normal(size=n)
    data["az_g"] = -1.0 + 0.01 * rng.normal(size=n)
    data["qbar_psf"] = 300.0 + rng.normal(size=n)
    data["de_rad"] = 0.01 * rng.normal(size=n)
    data["truth_Cm_1"] = rng.normal(size=n) * 1e-3
    data["truth_CX_1"] = rng.normal(size=n) * 1e-3
    data["xyz_deg"] = rng.normal(size=n)
    meta = {
        "format": FORMAT_ID,
        "aircraft": "F-16",
        "geometry": {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32},
        "mass": {"mass_slug": 647.2, "Ix_slugft2": 9496.0, "Iy_slugft2": 55814.0,
                 "Iz_slugft2": 63100.0, "Ixz_slugft2": 982.0},
        "sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]},
        "thrust_offset_ft": -0.3,
        "source": "test",
        "maneuver": "stabilator 2-1-1",
        "trim": {"alpha_rad": 0.087, "V_fps": 427.4, "h_ft": 10000.0},
        "truth": {"Cm": {"alpha": -0.5, "q": [-3.0, 0.1]}, "note": None, "flag": True},
    }
    return Recording(pd.DataFrame(data), meta, name="run7")


def with_data(rec: Recording, edit: Callable[[pd.DataFrame], pd.DataFrame | None]) -> Recording:
    df = rec.data.copy()
    out = edit(df)
    return Recording(df if out is None else out, rec.meta, rec.name)


def with_meta(rec: Recording, edit: Callable[[dict[str, Any]], None]) -> Recording:
    import copy

    meta = copy.deepcopy(rec.meta)
    edit(meta)
    return Recording(rec.data, meta, rec.name)


def refused(rec: Recording, key: str, rule: str, *more: str) -> RecordingError:
    """Validate with SOURCE; assert the error names the file, the key and the rule."""
    with pytest.raises(RecordingError) as info:
        rec.validate(source=SOURCE)
    msg = str(info.value)
    assert SOURCE in msg, msg
    assert key in msg, msg
    assert f"[rule: {rule}]" in msg and info.value.rule == rule, msg
    for text in more:
        assert text in msg, msg
    return info.value


# ------------------------------------------------------------------ table and names


def test_channel_table_required_and_canonical_units() -> None:
    assert set(REQUIRED_QUANTITIES) == {
        "t", "V", "alpha", "beta", "p", "q", "r", "phi", "theta", "psi", "ax", "ay", "az", "qbar"}
    expected = {"t": "s", "V": "fps", "alpha": "rad", "p": "rps", "ax": "g", "de": "rad",
                "qbar": "psf", "h": "ft", "mach": "1", "thrust": "lbf", "pdot": "rps2",
                "throttle": "1", "mass": "slug", "Ixz": "slugft2"}
    for q, unit in expected.items():
        assert CHANNELS[q].canonical == unit
        assert CHANNELS[q].units[unit] == 1.0
    with pytest.raises(TypeError):
        CHANNELS["alpha"].units["grad"] = 1.0  # type: ignore[index]


def test_conversion_factors() -> None:
    assert G0_FPS2 * 0.3048 == pytest.approx(9.80665, rel=1e-13)
    assert CHANNELS["V"].units["kts"] == pytest.approx(1.6878098571, rel=1e-10)
    assert CHANNELS["V"].units["mps"] == pytest.approx(1 / 0.3048, rel=1e-15)
    assert CHANNELS["alpha"].units["deg"] == pytest.approx(math.pi / 180, rel=1e-15)
    assert CHANNELS["ax"].units["fps2"] == pytest.approx(1 / G0_FPS2, rel=1e-15)
    assert CHANNELS["ax"].units["mps2"] == pytest.approx(1 / 9.80665, rel=1e-15)
    assert 1 / CHANNELS["qbar"].units["pa"] == pytest.approx(47.88025898, rel=1e-10)
    assert 1 / CHANNELS["thrust"].units["n"] == pytest.approx(4.4482216152605, rel=1e-15)
    assert CHANNELS["h"].units["m"] == pytest.approx(1 / 0.3048, rel=1e-15)
    assert CHANNELS["qdot"].units["dps2"] == pytest.approx(math.pi / 180, rel=1e-15)


@pytest.mark.parametrize("name, expected", [
    ("alpha_deg", ("alpha", "deg")),
    ("truth_Cm_1", ("truth_Cm", "1")),
    ("Ixz_slugft2", ("Ixz", "slugft2")),
    ("t_s", ("t", "s")),
    ("CY_1", ("CY", "1")),
])
def test_parse_column(name: str, expected: tuple[str, str]) -> None:
    assert parse_column(name) == expected


@pytest.mark.parametrize("name", ["alpha", "_deg", "alpha_", "al pha_deg", "alpha__deg", "1x_deg", ""])
def test_parse_column_refuses(name: str) -> None:
    with pytest.raises(RecordingError, match="bad-column-name") as info:
        parse_column(name, source=SOURCE)
    assert SOURCE in str(info.value) and repr(name) in str(info.value)


# ------------------------------------------------------------------ to_canonical


def test_to_canonical_converts_every_accepted_unit() -> None:
    rng = np.random.default_rng(1)
    raw: dict[str, np.ndarray] = {}
    expected: dict[str, np.ndarray] = {}
    for q, spec in CHANNELS.items():
        if q == "t":
            continue
        for unit, factor in spec.units.items():
            if unit == spec.canonical:
                continue
            x = rng.normal(size=5)
            raw_df = pd.DataFrame({"t_s": np.arange(5.0), f"{q}_{unit}": x})
            out = to_canonical(raw_df)
            assert list(out.columns) == ["t_s", spec.column]
            np.testing.assert_allclose(out[spec.column].to_numpy(), x * factor, rtol=1e-15)
            raw[f"{q}_{unit}"] = x
            expected[spec.column] = x * factor
    assert len(raw) >= 15


def test_to_canonical_keeps_extras_truth_and_moves_time_first() -> None:
    df = pd.DataFrame({
        "alpha_deg": [1.0, 2.0], "t_s": [0.0, 0.1], "xyz_deg": [10.0, 20.0],
        "truth_Cm_1": [0.5, 0.25], "truth_weird_furlong": [1.0, 2.0], "count_1": [1, 2],
    })
    out = to_canonical(df, SOURCE)
    assert list(out.columns) == ["t_s", "alpha_rad", "xyz_deg", "truth_Cm_1", "truth_weird_furlong",
                                 "count_1"]
    assert (out.dtypes == np.float64).all()
    assert np.array_equal(out["xyz_deg"].to_numpy(), [10.0, 20.0])  # verbatim, not converted
    assert np.array_equal(out["alpha_rad"].to_numpy(), np.array([1.0, 2.0]) * (math.pi / 180))
    assert isinstance(out.index, pd.RangeIndex)


def test_to_canonical_is_bit_exact_for_canonical_input() -> None:
    rec = make_recording()
    out = to_canonical(rec.data)
    for c in rec.data.columns:
        assert np.array_equal(out[c].to_numpy().view(np.int64), rec.data[c].to_numpy().view(np.int64))


@pytest.mark.parametrize("column, rule", [
    ("alpha_furlong", "unknown-unit"),
    ("foo_bar", "unknown-unit"),
    ("alpha", "bad-column-name"),
    ("V_Kts", "unknown-unit"),
])
def test_to_canonical_refuses_unknown_names(column: str, rule: str) -> None:
    df = pd.DataFrame({"t_s": [0.0, 1.0], column: [1.0, 2.0]})
    with pytest.raises(RecordingError) as info:
        to_canonical(df, SOURCE)
    msg = str(info.value)
    assert SOURCE in msg and repr(column) in msg and info.value.rule == rule, msg


def test_to_canonical_refuses_duplicate_quantity() -> None:
    df = pd.DataFrame({"t_s": [0.0, 1.0], "alpha_deg": [1.0, 2.0], "alpha_rad": [0.1, 0.2]})
    with pytest.raises(RecordingError) as info:
        to_canonical(df, SOURCE)
    msg = str(info.value)
    assert SOURCE in msg and "'alpha_rad'" in msg and "'alpha_deg'" in msg
    assert info.value.rule == "duplicate-quantity"


def test_to_canonical_refuses_non_numeric() -> None:
    df = pd.DataFrame({"t_s": [0.0, 1.0], "alpha_rad": [0.1, "x"]})
    with pytest.raises(RecordingError, match="non-numeric") as info:
        to_canonical(df, SOURCE)
    assert "'alpha_rad'" in str(info.value) and "row 2" in str(info.value)


# ------------------------------------------------------------------ the valid case


def test_valid_recording_validates_and_convenience() -> None:
    rec = make_recording()
    assert rec.validate() is rec
    assert rec.n == 101
    assert rec.dt == pytest.approx(0.02, rel=1e-12)
    assert np.array_equal(rec.t, rec.data["t_s"].to_numpy())
    assert rec.has("alpha") and not rec.has("thrust")
    assert np.array_equal(rec.channel("alpha"), rec.data["alpha_rad"].to_numpy())
    assert rec.column("truth_Cm") == "truth_Cm_1"
    assert list(rec.truth.columns) == ["Cm", "CX"]
    assert np.array_equal(rec.truth["Cm"].to_numpy(), rec.data["truth_Cm_1"].to_numpy())
    assert rec.geometry == {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32}
    assert rec.mass["Ixz_slugft2"] == 982.0 and rec.mass_is_constant
    assert rec.mass_at(5) == rec.mass
    arrays = rec.mass_at()
    assert set(arrays) == set(MASS_KEYS) and all(a.shape == (rec.n,) for a in arrays.values())
    assert "run7" in repr(rec)


def test_channel_absent_names_quantity() -> None:
    rec = make_recording()
    with pytest.raises(RecordingError, match="'thrust'"):
        rec.channel("thrust")


def test_from_frame_converts_and_validates() -> None:
    rec = make_recording()
    df = rec.data.rename(columns={"alpha_rad": "alpha_deg"})
    df["alpha_deg"] = rec.data["alpha_rad"] * (180 / math.pi)
    built = Recording.from_frame(df, rec.meta, "x", source=SOURCE)
    np.testing.assert_allclose(built.channel("alpha"), rec.channel("alpha"), rtol=1e-14)


def test_time_varying_mass_from_channels() -> None:
    rec = make_recording()
    n = rec.n

    def edit(meta: dict[str, Any]) -> None:
        del meta["mass"]["mass_slug"], meta["mass"]["Ixz_slugft2"]

    rec = with_meta(rec, edit)
    df = rec.data.copy()
    df["mass_slug"] = np.linspace(650.0, 640.0, n)
    df["Ixz_slugft2"] = np.full(n, -50.0)  # Ixz may be negative
    rec = Recording(df, rec.meta, rec.name).validate()
    assert not rec.mass_is_constant
    at3 = rec.mass_at(3)
    assert at3["mass_slug"] == df["mass_slug"][3] and at3["Ix_slugft2"] == 9496.0
    assert np.array_equal(rec.mass_at()["mass_slug"], df["mass_slug"].to_numpy())


def test_error_pickles_with_its_parts() -> None:
    err = RecordingError("bad", source="a.csv", key="column 'x_1'", rule="r1")
    back = pickle.loads(pickle.dumps(err))
    assert str(back) == str(err) and (back.source, back.key, back.rule) == ("a.csv", "column 'x_1'", "r1")


def test_error_without_source_names_the_recording() -> None:
    rec = with_data(make_recording(), lambda df: df.drop(columns=["t_s"]))
    with pytest.raises(RecordingError, match="recording 'run7'"):
        rec.validate()


# ------------------------------------------------------------------ every rule


def test_time_missing() -> None:
    refused(with_data(make_recording(), lambda df: df.drop(columns=["t_s"])), "'t_s'", "missing-time")


def test_time_not_first() -> None:
    def edit(df: pd.DataFrame) -> pd.DataFrame:
        cols = list(df.columns)
        return df[cols[1:] + cols[:1]]

    refused(with_data(make_recording(), edit), "'t_s'", "time-not-first")


def test_time_not_strictly_increasing() -> None:
    def edit(df: pd.DataFrame) -> None:
        t = df["t_s"].to_numpy().copy()
        t[40], t[41] = t[41], t[40]
        df["t_s"] = t

    refused(with_data(make_recording(), edit), "'t_s'", "time-not-increasing", "row 42")


def test_time_repeated_sample_is_not_increasing() -> None:
    def edit(df: pd.DataFrame) -> None:
        t = df["t_s"].to_numpy().copy()
        t[10] = t[9]
        df["t_s"] = t

    refused(with_data(make_recording(), edit), "'t_s'", "time-not-increasing")


def test_time_step_not_uniform() -> None:
    def edit(df: pd.DataFrame) -> None:
        t = df["t_s"].to_numpy().copy()
        t[50] += 0.02 * 1e-5
        df["t_s"] = t

    refused(with_data(make_recording(), edit), "'t_s'", "time-not-uniform", "rows 50 and 51")


def test_time_jitter_below_tolerance_is_accepted() -> None:
    def edit(df: pd.DataFrame) -> None:
        t = df["t_s"].to_numpy().copy()
        t[50] += 0.02 * 2e-7
        df["t_s"] = t

    with_data(make_recording(), edit).validate(SOURCE)


@pytest.mark.parametrize("rate_hz", [60.0, 120.0, 30.0])
@pytest.mark.parametrize("written", ["%.8g", "%.6f", "float32"])
def test_times_rounded_as_written_are_uniform(rate_hz: float, written: str, tmp_path) -> None:
    """A 60, 120 or 30 Hz recording whose times were written to 8 significant digits, six
    decimals or single precision (16.016667 s) steps unevenly by up to 3e-4 of a step, though
    it was sampled uniformly: read, through the CSV, with its samples as written."""
    n = int(200 * rate_hz)  # 200 s: the rounding grows with the time
    exact = 100.0 + np.arange(n) / rate_hz
    if written == "float32":
        t = exact.astype(np.float32).astype(float)
    else:
        t = np.array([float(written % v) for v in exact])
    rec = make_recording(n=n, dt=1.0 / rate_hz)
    rec.data["t_s"] = t
    assert np.max(np.abs(np.diff(t) * rate_hz - 1.0)) > TIME_JITTER_TOL
    from harness.recording_io import read_recording, write_recording
    write_recording(rec, tmp_path / "r.csv")
    back = read_recording(tmp_path / "r.csv")
    assert np.array_equal(back.t, t)


def test_times_off_the_grid_by_more_than_their_rounding_are_refused() -> None:
    """Six-decimal times with one sample 2 µs late (twice its rounding) at 60 Hz, and
    millisecond times at 60 Hz with one sample a millisecond late (its rounding is half
    of that): refused, naming a step next to the late sample (data row ``row + 1``)."""
    for decimals, late, row in ((6, 2e-6, 70), (3, 1e-3, 40)):
        def edit(df: pd.DataFrame, decimals=decimals, late=late, row=row) -> None:
            t = np.round(np.arange(len(df)) / 60.0, decimals)
            t[row] += late
            df["t_s"] = t

        refused(with_data(make_recording(), edit), "'t_s'", "time-not-uniform", f"{row + 1}")


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_sample(bad: float) -> None:
    def edit(df: pd.DataFrame) -> None:
        x = df["q_rps"].to_numpy().copy()
        x[17] = bad
        x[30] = bad
        df["q_rps"] = x

    err = refused(with_data(make_recording(), edit), "'q_rps'", "non-finite", "row 18", "t=0.34")
    assert "2 bad sample" in str(err)


def test_non_finite_time() -> None:
    def edit(df: pd.DataFrame) -> None:
        t = df["t_s"].to_numpy().copy()
        t[3] = np.nan
        df["t_s"] = t

    refused(with_data(make_recording(), edit), "'t_s'", "non-finite", "row 4")


@pytest.mark.parametrize("quantity", [q for q in REQUIRED_QUANTITIES if q != "t"])
def test_missing_required_channel(quantity: str) -> None:
    column = CHANNELS[quantity].column
    refused(with_data(make_recording(), lambda df: df.drop(columns=[column])), f"'{column}'",
            "missing-channel")


def test_non_canonical_unit_in_memory() -> None:
    rec = with_data(make_recording(), lambda df: df.rename(columns={"alpha_rad": "alpha_deg"}))
    refused(rec, "'alpha_deg'", "non-canonical-unit", "alpha_rad")


def test_unknown_unit_in_memory() -> None:
    rec = with_data(make_recording(), lambda df: df.rename(columns={"xyz_deg": "xyz_furlong"}))
    refused(rec, "'xyz_furlong'", "unknown-unit")


def test_unparseable_column_name_in_memory() -> None:
    rec = with_data(make_recording(), lambda df: df.rename(columns={"xyz_deg": "xyz"}))
    refused(rec, "'xyz'", "bad-column-name")


def test_duplicate_quantity_in_memory() -> None:
    def edit(df: pd.DataFrame) -> None:
        df["xyz_rad"] = df["xyz_deg"]

    refused(with_data(make_recording(), edit), "'xyz_rad'", "duplicate-quantity", "'xyz_deg'")


def test_not_float64() -> None:
    def edit(df: pd.DataFrame) -> None:
        df["count_1"] = np.arange(len(df), dtype=np.int64)

    refused(with_data(make_recording(), edit), "'count_1'", "not-float64")


def test_too_short() -> None:
    refused(with_data(make_recording(), lambda df: df.iloc[:1]), "'t_s'", "too-short")


def test_no_control_surface() -> None:
    rec = with_data(make_recording(), lambda df: df.drop(columns=["de_rad"]))
    refused(rec, "'de_rad'", "no-control-surface", "'da_rad'", "'dr_rad'")


@pytest.mark.parametrize("surface", ["de_rad", "da_rad", "dr_rad"])
def test_any_one_control_surface_suffices(surface: str) -> None:
    def edit(df: pd.DataFrame) -> pd.DataFrame:
        values = df["de_rad"].to_numpy()
        return df.drop(columns=["de_rad"]).assign(**{surface: values})

    with_data(make_recording(), edit).validate()


def test_wrong_format() -> None:
    rec = with_meta(make_recording(), lambda m: m.update(format="flight-recording/2"))
    refused(rec, "meta['format']", "bad-format", "flight-recording/2")


def test_missing_format() -> None:
    rec = with_meta(make_recording(), lambda m: m.pop("format"))
    refused(rec, "meta['format']", "missing-format")


def test_missing_geometry() -> None:
    refused(with_meta(make_recording(), lambda m: m.pop("geometry")), "meta['geometry']",
            "missing-geometry")


@pytest.mark.parametrize("key", ["S_ft2", "b_ft", "cbar_ft"])
def test_missing_geometry_key(key: str) -> None:
    rec = with_meta(make_recording(), lambda m: m["geometry"].pop(key))
    refused(rec, f"meta['geometry']['{key}']", "missing-geometry")


@pytest.mark.parametrize("value", [0.0, -30.0, float("nan"), float("inf"), "30", True, None])
def test_bad_geometry_value(value: Any) -> None:
    rec = with_meta(make_recording(), lambda m: m["geometry"].update(b_ft=value))
    refused(rec, "meta['geometry']['b_ft']", "bad-geometry")


@pytest.mark.parametrize("key", MASS_KEYS)
def test_missing_mass(key: str) -> None:
    rec = with_meta(make_recording(), lambda m: m["mass"].pop(key))
    refused(rec, f"meta['mass']['{key}']", "missing-mass")


def test_missing_mass_block() -> None:
    rec = with_meta(make_recording(), lambda m: m.pop("mass"))
    refused(rec, "meta['mass']['mass_slug']", "missing-mass")


@pytest.mark.parametrize("key, value", [("mass_slug", 0.0), ("Iy_slugft2", -1.0),
                                        ("Ixz_slugft2", float("nan")), ("Ix_slugft2", "9496")])
def test_bad_mass_value(key: str, value: Any) -> None:
    rec = with_meta(make_recording(), lambda m: m["mass"].update({key: value}))
    refused(rec, f"meta['mass']['{key}']", "bad-mass")


def test_mass_given_twice() -> None:
    def edit(df: pd.DataFrame) -> None:
        df["Iz_slugft2"] = 63100.0

    refused(with_data(make_recording(), edit), "meta['mass']['Iz_slugft2']", "mass-given-twice")


def test_mass_channel_not_positive() -> None:
    rec = with_meta(make_recording(), lambda m: m["mass"].pop("mass_slug"))

    def edit(df: pd.DataFrame) -> None:
        x = np.full(len(df), 600.0)
        x[7] = -1.0
        df["mass_slug"] = x

    refused(with_data(rec, edit), "'mass_slug'", "bad-mass", "row 8")


def test_bad_sensor_position() -> None:
    rec = with_meta(make_recording(), lambda m: m["sensors"].update(accelerometer_ft=[0.0, 1.0]))
    refused(rec, "meta['sensors']['accelerometer_ft']", "bad-sensors")


def test_bad_thrust_offset() -> None:
    rec = with_meta(make_recording(), lambda m: m.update(thrust_offset_ft=float("nan")))
    refused(rec, "meta['thrust_offset_ft']", "bad-thrust-offset")


def test_project_keys_are_not_needed() -> None:
    def edit(meta: dict[str, Any]) -> None:
        for key in ("truth", "trim", "sensors", "thrust_offset_ft", "source", "maneuver", "aircraft"):
            meta.pop(key)

    with_meta(make_recording(), edit).validate()
