"""The nightly gate passes on a clean run and catches a planted regression by name."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pandas as pd

from harness.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parent))  # worker processes import `planted`

NIGHTLY_SMALL = """
name = "nightly-test"
seed = 4
realizations = 60
truth = "local"
[grid]
variant = ["exact-truth"]
maneuver = ["2-1-1-2", "lateral"]
noise = ["white"]
method = ["ee-freq", "ee-smooth"]
errors = ["colored"]
equations = ["CZ = alpha + qhat + de", "CY = beta + phat + rhat + da + dr"]
[method_options.ee-freq]
frequencies = "0.1:0.04:1.2"
detrend = "lstsq"
"""


def _run(tmp_path, name, text, capsys):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    code = main(["nightly", "--out", str(tmp_path / name), "--history", str(tmp_path / "history"), "--campaign",
                 str(path), "--workers", "2", "--cache", str(tmp_path / "cache"), "--quiet"])
    return code, capsys.readouterr()


def test_nightly_gate_passes_clean_and_fails_on_a_planted_regression(tmp_path, capsys):
    code, out = _run(tmp_path, "night1", NIGHTLY_SMALL, capsys)
    assert code == 0, out.err + out.out
    assert (tmp_path / "night1" / "nightly.html").is_file() and (tmp_path / "night1" / "nightly.md").is_file()
    gates = pd.read_parquet(tmp_path / "night1" / "gates.parquet")
    assert len(gates) and gates["passed"].all()
    # the same code again: nothing moves
    code, out = _run(tmp_path, "night2", NIGHTLY_SMALL, capsys)
    assert code == 0, out.err
    moved = pd.read_parquet(tmp_path / "night2" / "gates.parquet")
    assert (moved["kind"] == "movement").any() and moved["passed"].all()
    # plant a 10 % bias in the frequency-domain estimator
    planted = (NIGHTLY_SMALL + '\n[plugins]\nallow = ["planted:biased_frequency"]\n'
               '\n[method_factories]\n"ee-freq" = "planted:biased_frequency"\n')
    code, out = _run(tmp_path, "night3", planted, capsys)
    assert code == 1
    assert "GATE FAILED" in out.err and "ee-freq" in out.err and "CZ_alpha" in out.err
    report = json.loads((tmp_path / "night3" / "nightly.json").read_text())
    assert report["status"] == "fail"
    failed = pd.read_parquet(tmp_path / "night3" / "gates.parquet").query("not passed")
    assert set(failed["method"]) == {"ee-freq"}
    assert {"bias", "movement"} <= set(failed["kind"])
