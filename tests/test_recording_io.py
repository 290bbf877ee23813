"""Reading and writing recordings: exact round trips, unit conversion, atomicity, bad files."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from test_recording_format import make_recording

from harness.recording_io import PARQUET_META_KEY, meta_path_for, read_recording, write_recording
from maneuvers.recording import G0_FPS2, Recording, RecordingError


def awkward(rec: Recording) -> Recording:
    """Same recording with values that stress float formatting."""
    df = rec.data.copy()
    n = len(df)
    rng = np.random.default_rng(7)
    special = np.array([0.1, 1 / 3, -0.0, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                        123456789.12345679, -2.5e-17, math.pi, 1e22])
    x = rng.normal(size=n) * 10.0 ** rng.integers(-30, 30, size=n)
    x[: special.size] = special
    df["xyz_deg"] = x
    df["truth_Cm_1"] = rng.normal(size=n) / 7.0
    return Recording(df, rec.meta, rec.name)


def assert_bit_identical(a: Recording, b: Recording) -> None:
    assert list(a.data.columns) == list(b.data.columns)
    for c in a.data.columns:
        x, y = a.data[c].to_numpy(), b.data[c].to_numpy()
        assert y.dtype == np.float64
        assert np.array_equal(x, y), c
        assert np.array_equal(x.view(np.int64), y.view(np.int64)), c  # also -0.0 vs 0.0
    assert a.meta == b.meta


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip_is_exact(tmp_path: Path, suffix: str) -> None:
    rec = awkward(make_recording()).validate()
    path = write_recording(rec, tmp_path / f"run7{suffix}")
    assert path == tmp_path / f"run7{suffix}"
    back = read_recording(path)
    assert back.name == "run7"
    assert_bit_identical(rec, back)
    assert back.equals(rec)
    assert np.array_equal(back.truth["Cm"].to_numpy(), rec.truth["Cm"].to_numpy())
    assert back.meta["truth"]["Cm"]["q"] == [-3.0, 0.1]


def test_csv_form(tmp_path: Path) -> None:
    rec = make_recording(n=3)
    path = write_recording(rec, tmp_path / "small.csv")
    lines = path.read_text(encoding="utf-8").splitlines()
    assert lines[0] == ",".join(rec.data.columns)
    assert len(lines) == 4
    assert lines[2].split(",")[0] == "0.02"
    meta = json.loads(meta_path_for(path).read_text(encoding="utf-8"))
    assert meta == rec.meta
    assert meta_path_for(path).name == "small.meta.json"


def test_csv_round_trip_of_written_files_is_stable(tmp_path: Path) -> None:
    rec = awkward(make_recording())
    first = write_recording(rec, tmp_path / "a.csv")
    second = write_recording(read_recording(first), tmp_path / "b.csv")
    assert first.read_bytes() == second.read_bytes()
    assert meta_path_for(first).read_bytes() == meta_path_for(second).read_bytes()


def test_numpy_values_in_meta_are_written_as_plain_json(tmp_path: Path) -> None:
    rec = make_recording()
    meta = dict(rec.meta, noise={"seed": np.int64(3), "sigma": np.float64(0.25),
                                 "vector": np.array([1.0, 2.0]), "pair": (1, 2)})
    back = read_recording(write_recording(Recording(rec.data, meta, rec.name), tmp_path / "n.csv"))
    assert back.meta["noise"] == {"seed": 3, "sigma": 0.25, "vector": [1.0, 2.0], "pair": [1, 2]}


def test_non_finite_meta_value_is_refused(tmp_path: Path) -> None:
    rec = make_recording()
    meta = dict(rec.meta, noise={"sigma": [0.1, float("nan")]})
    target = tmp_path / "n.csv"
    with pytest.raises(RecordingError) as info:
        write_recording(Recording(rec.data, meta, rec.name), target)
    msg = str(info.value)
    assert str(target) in msg and "meta['noise']['sigma'][1]" in msg and info.value.rule == "bad-meta"
    assert list(tmp_path.iterdir()) == []


def test_units_are_converted_on_read(tmp_path: Path) -> None:
    rec = make_recording()
    c = rec.data
    foreign = pd.DataFrame({
        "t_s": c["t_s"],
        "V_kts": c["V_fps"] / 1.6878098571,
        "alpha_deg": np.degrees(c["alpha_rad"]),
        "beta_deg": np.degrees(c["beta_rad"]),
        "p_dps": np.degrees(c["p_rps"]),
        "q_dps": np.degrees(c["q_rps"]),
        "r_dps": np.degrees(c["r_rps"]),
        "phi_deg": np.degrees(c["phi_rad"]),
        "theta_deg": np.degrees(c["theta_rad"]),
        "psi_deg": np.degrees(c["psi_rad"]),
        "ax_fps2": c["ax_g"] * G0_FPS2,
        "ay_mps2": c["ay_g"] * 9.80665,
        "az_fps2": c["az_g"] * G0_FPS2,
        "qbar_pa": c["qbar_psf"] * 47.88025898033584,
        "de_deg": np.degrees(c["de_rad"]),
        "h_m": np.full(len(c), 3048.0),
        "thrust_n": np.full(len(c), 4448.2216152605),
        "qdot_dps2": np.full(len(c), 57.29577951308232),
        "truth_Cm_1": c["truth_Cm_1"],
        "xyz_deg": c["xyz_deg"],
    })
    path = tmp_path / "foreign.csv"
    foreign.to_csv(path, index=False, float_format="%.17g")
    meta_path_for(path).write_text(json.dumps(rec.meta), encoding="utf-8")
    back = read_recording(path)
    expected = {**{k: c[k].to_numpy() for k in c.columns},
                "h_ft": np.full(len(c), 10000.0), "thrust_lbf": np.full(len(c), 1000.0),
                "qdot_rps2": np.ones(len(c))}
    assert set(back.data.columns) == set(expected) - {"truth_CX_1"}
    for col in back.data.columns:
        np.testing.assert_allclose(back.data[col].to_numpy(), expected[col], rtol=1e-12, atol=0, err_msg=col)
    # The extra channel is kept verbatim, not converted.
    assert np.array_equal(back.data["xyz_deg"].to_numpy(), c["xyz_deg"].to_numpy())


def test_parquet_with_foreign_units_is_converted(tmp_path: Path) -> None:
    rec = make_recording()
    df = rec.data.rename(columns={"alpha_rad": "alpha_deg"})
    df["alpha_deg"] = np.degrees(rec.data["alpha_rad"])
    table = pa.Table.from_pandas(df, preserve_index=False)
    table = table.replace_schema_metadata({PARQUET_META_KEY: json.dumps(rec.meta).encode()})
    pq.write_table(table, tmp_path / "f.parquet")
    back = read_recording(tmp_path / "f.parquet")
    np.testing.assert_allclose(back.channel("alpha"), rec.channel("alpha"), rtol=1e-14)


# ------------------------------------------------------------------ atomic writing


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_write_leaves_no_temporary_files(tmp_path: Path, suffix: str) -> None:
    rec = make_recording()
    write_recording(rec, tmp_path / f"r{suffix}")
    write_recording(rec, tmp_path / f"r{suffix}")  # overwrite
    expected = {"r.csv", "r.meta.json"} if suffix == ".csv" else {"r.parquet"}
    assert {p.name for p in tmp_path.iterdir()} == expected


def test_write_creates_missing_folder(tmp_path: Path) -> None:
    path = write_recording(make_recording(), tmp_path / "deep" / "er" / "r.csv")
    assert path.is_file() and meta_path_for(path).is_file()


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_failed_write_keeps_old_file_and_no_temporaries(tmp_path: Path, suffix: str,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    rec = make_recording()
    path = write_recording(rec, tmp_path / f"r{suffix}")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    def failing_replace(src: str, dst: str) -> None:
        raise OSError("disk full (simulated)")

    monkeypatch.setattr(os, "replace", failing_replace)
    changed = Recording(rec.data.assign(V_fps=rec.data["V_fps"] + 1.0), rec.meta, rec.name)
    with pytest.raises(OSError, match="simulated"):
        write_recording(changed, path)
    monkeypatch.undo()
    after = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert after == before


def test_invalid_recording_is_not_written(tmp_path: Path) -> None:
    rec = make_recording()
    bad = Recording(rec.data.drop(columns=["qbar_psf"]), rec.meta, rec.name)
    target = tmp_path / "bad.csv"
    with pytest.raises(RecordingError, match="qbar_psf") as info:
        write_recording(bad, target)
    assert str(target) in str(info.value)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ bad files


def write_raw(tmp_path: Path, text: str, meta: dict | None = None, name: str = "raw") -> Path:
    path = tmp_path / f"{name}.csv"
    path.write_text(text, encoding="utf-8")
    if meta is not None:
        meta_path_for(path).write_text(json.dumps(meta), encoding="utf-8")
    return path


def good_csv_text(tmp_path: Path) -> tuple[str, dict]:
    rec = make_recording(n=6)
    path = write_recording(rec, tmp_path / "src" / "good.csv")
    return path.read_text(encoding="utf-8"), rec.meta


def test_missing_meta_file(tmp_path: Path) -> None:
    text, _ = good_csv_text(tmp_path)
    path = write_raw(tmp_path, text)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    msg = str(info.value)
    assert str(path) in msg and "raw.meta.json" in msg and info.value.rule == "missing-meta-file"


@pytest.mark.parametrize("edit, line", [("drop", 4), ("extra", 5)])
def test_ragged_row_is_a_length_mismatch(tmp_path: Path, edit: str, line: int) -> None:
    text, meta = good_csv_text(tmp_path)
    lines = text.splitlines()
    if edit == "drop":
        lines[line - 1] = lines[line - 1].rsplit(",", 1)[0]
    else:
        lines[line - 1] += ",1.0"
    path = write_raw(tmp_path, "\n".join(lines) + "\n", meta)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    msg = str(info.value)
    assert str(path) in msg and f"line {line}" in msg and info.value.rule == "length-mismatch", msg


def test_blank_line_inside_data_is_refused(tmp_path: Path) -> None:
    text, meta = good_csv_text(tmp_path)
    lines = text.splitlines()
    lines.insert(3, "")
    path = write_raw(tmp_path, "\n".join(lines) + "\n\n", meta)
    with pytest.raises(RecordingError, match="line 4") as info:
        read_recording(path)
    assert info.value.rule == "length-mismatch"


def test_non_numeric_cell(tmp_path: Path) -> None:
    text, meta = good_csv_text(tmp_path)
    lines = text.splitlines()
    cells = lines[2].split(",")
    cells[2] = "abc"
    lines[2] = ",".join(cells)
    path = write_raw(tmp_path, "\n".join(lines) + "\n", meta)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    msg = str(info.value)
    assert str(path) in msg and "'alpha_rad'" in msg and "line 3" in msg and info.value.rule == "non-numeric"


def test_unknown_unit_in_file(tmp_path: Path) -> None:
    text, meta = good_csv_text(tmp_path)
    path = write_raw(tmp_path, text.replace("alpha_rad", "alpha_grad", 1), meta)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    msg = str(info.value)
    assert str(path) in msg and "'alpha_grad'" in msg and info.value.rule == "unknown-unit"


def test_duplicate_header_in_file(tmp_path: Path) -> None:
    text, meta = good_csv_text(tmp_path)
    lines = text.splitlines()
    lines = [line + "," + line.split(",")[2] for line in lines]
    path = write_raw(tmp_path, "\n".join(lines) + "\n", meta)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert "'alpha_rad'" in str(info.value) and info.value.rule == "duplicate-quantity"


def test_rules_are_applied_on_read_naming_the_file(tmp_path: Path) -> None:
    text, meta = good_csv_text(tmp_path)
    lines = text.splitlines()
    lines[3], lines[4] = lines[4], lines[3]
    path = write_raw(tmp_path, "\n".join(lines) + "\n", meta)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert str(path) in str(info.value) and info.value.rule == "time-not-increasing"


def test_bad_meta_json(tmp_path: Path) -> None:
    text, _ = good_csv_text(tmp_path)
    path = write_raw(tmp_path, text)
    meta_path_for(path).write_text("{not json", encoding="utf-8")
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert "raw.meta.json" in str(info.value) and info.value.rule == "bad-meta-json"


def test_wrong_format_in_meta_file(tmp_path: Path) -> None:
    text, meta = good_csv_text(tmp_path)
    path = write_raw(tmp_path, text, dict(meta, format="other/9"))
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert str(path) in str(info.value) and "meta['format']" in str(info.value)
    assert info.value.rule == "bad-format"


def test_parquet_without_meta(tmp_path: Path) -> None:
    path = tmp_path / "plain.parquet"
    make_recording().data.to_parquet(path, index=False)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert str(path) in str(info.value) and info.value.rule == "missing-meta"


@pytest.mark.parametrize("name", ["r.txt", "r.json"])
def test_unknown_file_type(tmp_path: Path, name: str) -> None:
    with pytest.raises(RecordingError, match="unknown-file-type"):
        read_recording(tmp_path / name)
    with pytest.raises(RecordingError, match="unknown-file-type"):
        write_recording(make_recording(), tmp_path / name)


@pytest.mark.parametrize("name", ["nothere.csv", "nothere.parquet", "nothere.mat"])
def test_missing_file(tmp_path: Path, name: str) -> None:
    with pytest.raises(FileNotFoundError, match=name):
        read_recording(tmp_path / name)
