"""The sidbench command line: help everywhere, fly / truth / import / demo, clear errors."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from harness.cli import main
from harness.recording_io import read_recording
from models.truth import DERIVATIVE_NAMES

SUBCOMMANDS = ("fly", "truth", "import", "bench", "demo")
VENV_BIN = Path(sys.executable).parent


def test_console_script_and_module_both_answer_help():
    for cmd in ([str(VENV_BIN / "sidbench"), "--help"], [sys.executable, "-m", "harness", "--help"]):
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
        for sub in SUBCOMMANDS:
            assert sub in out


@pytest.mark.parametrize("sub", SUBCOMMANDS)
def test_every_subcommand_has_help(sub, capsys):
    with pytest.raises(SystemExit) as exc:
        main([sub, "--help"])
    assert exc.value.code == 0
    assert "usage: sidbench " + sub in capsys.readouterr().out


def test_fly_writes_csv_and_meta(tmp_path, capsys):
    out = tmp_path / "rec.csv"
    assert main(["fly", "--aircraft", "f16", "--maneuver", "2-1-1-2", "--surface", "de",
                 "--amplitude-deg", "1", "--out", str(out)]) == 0
    assert out.is_file() and (tmp_path / "rec.meta.json").is_file()
    rec = read_recording(out)
    assert rec.n == 1001 and rec.dt == pytest.approx(0.02)
    assert set(DERIVATIVE_NAMES) <= set(rec.meta["truth"]["derivatives"])
    assert {"Cm", "CZ", "Cl"} <= set(rec.truth.columns)
    assert "wrote" in capsys.readouterr().out


def test_fly_options_closed_loop_parquet_and_rates(tmp_path):
    out = tmp_path / "rec.parquet"
    assert main(["fly", "--maneuver", "doublet", "--loop", "closed:0.3", "--sample-rate", "100",
                 "--duration", "10", "--variant", "exact-truth", "--out", str(out)]) == 0
    rec = read_recording(out)
    assert rec.n == 1001 and rec.dt == pytest.approx(0.01)
    assert rec.meta["simulation"]["loop"] == {"kind": "closed", "pitch_rate_gain": 0.3}
    assert rec.meta["simulation"]["variant"] == "exact-truth"


def test_truth_json_schema(tmp_path):
    path = tmp_path / "truth.json"
    assert main(["truth", "--aircraft", "f16", "--json", str(path)]) == 0
    d = json.loads(path.read_text())
    assert d["aircraft"] == "f16"
    assert {"h_ft", "V_fps", "alpha_rad"} <= set(d["condition"])
    assert set(DERIVATIVE_NAMES) <= set(d["derivatives"])
    for v in d["derivatives"].values():
        assert set(v) == {"local", "fit"}
    # the lateral fit spans the default lateral input's excursion
    assert d["derivatives"]["Cn_beta"]["fit"] != d["derivatives"]["Cn_beta"]["local"]


def test_truth_check_linearization_prints_comparison(capsys):
    assert main(["truth", "--condition", "alpha-7.5", "--check-linearization"]) == 0
    out = capsys.readouterr().out
    assert "FGLinearization" in out and "Cm_alpha" in out


def test_import_sidpac(tmp_path, shared_dir):
    src = shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat"
    out = tmp_path / "totter.csv"
    assert main(["import", str(src), "--out", str(out)]) == 0
    rec = read_recording(out)
    assert rec.n == 1001 and rec.has("Cn") and rec.has("phat")


def test_demo_prints_truth_and_recording_path(tmp_path, capsys):
    # 20 realizations on one worker: the main job end to end (`make demo` runs its 100)
    assert main(["demo", "--out", str(tmp_path), "--realizations", "20", "--workers", "1"]) == 0
    out = capsys.readouterr().out
    assert "Cm_alpha" in out and "Recording:" in out
    assert (tmp_path / "f16_stabilator_2112.csv").is_file()


@pytest.mark.parametrize("argv,message", [
    (["fly", "--loop", "closed:x", "--out", "x.csv"], "--loop closed:K needs a number"),
    (["fly", "--loop", "half", "--out", "x.csv"], "--loop must be"),
    (["fly", "--condition", "nowhere", "--out", "x.csv"], "no flight condition 'nowhere'"),
    (["fly", "--variant", "unstable", "--amplitude-deg", "2", "--duration", "40", "--out", "x.csv"], "diverged"),
    (["fly", "--maneuver", "doublet", "--surface", "de,da", "--out", "x.csv"], "exactly one surface"),
    (["import", "missing.mat", "--out", "x.csv"], "missing.mat"),
])
def test_user_errors_exit_2_with_a_message(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.startswith(f"sidbench {argv[0]}: error:")
    assert not (tmp_path / "x.csv").exists()
