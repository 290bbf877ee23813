"""``sidbench fly --noise PRESET --seed N`` writes a noisy recording; ``fly`` and ``truth`` take
``dhc6`` and the path of a JSBSim aircraft XML as ``diagnose`` does; piped output ends quietly."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from harness.cli import main
from harness.recording_io import read_recording

ROOT = Path(__file__).resolve().parents[1]


def _fly(tmp_path, name, *extra):
    assert main(["fly", "--duration", "10", "--out", str(tmp_path / name), *extra]) == 0
    return read_recording(tmp_path / name)


def test_fly_noise_seed(tmp_path):
    clean = _fly(tmp_path, "clean.csv")
    a = _fly(tmp_path, "a.csv", "--noise", "realistic", "--seed", "5")
    b = _fly(tmp_path, "b.csv", "--noise", "realistic", "--seed", "5")
    c = _fly(tmp_path, "c.csv", "--noise", "realistic", "--seed", "6")
    q = clean.column("q")
    assert np.array_equal(a.data[q], b.data[q])  # the seed reproduces the draw
    assert not np.array_equal(a.data[q], c.data[q]) and not np.array_equal(a.data[q], clean.data[q])
    noise = (a.data[q] - clean.data[q]).to_numpy()
    assert 0.5 * 0.14 * np.pi / 180 < noise.std() < 3 * 0.14 * np.pi / 180  # the preset's gyro level
    assert a.meta["noise"]["seed"] == 5 and a.meta["noise"]["model"]["name"] == "realistic"
    assert not a.has("qdot") and clean.has("qdot")  # presets drop the recorded angular accelerations
    truth = [c for c in clean.data.columns if c.startswith("truth_")]
    assert truth and all(np.array_equal(a.data[t], clean.data[t]) for t in truth)  # truth stays clean


def test_fly_and_truth_take_dhc6_and_an_xml_path(tmp_path, capsys):
    import jsbsim
    rec = _fly(tmp_path, "dhc6.csv", "--aircraft", "dhc6")
    assert rec.meta["truth"]["aircraft"] == "dhc6"
    xml = Path(jsbsim.get_default_root_dir()) / "aircraft" / "c172x" / "c172x.xml"
    rec = _fly(tmp_path, "c172x.csv", "--aircraft", str(xml), "--condition", "h=4000,V=180", "--maneuver", "doublet")
    assert rec.n == 501
    assert main(["truth", "--aircraft", "dhc6"]) == 0
    assert "dhc6 at twin-otter-017" in capsys.readouterr().out
    assert main(["truth", "--aircraft", str(xml), "--condition", "h=4000,V=180"]) == 0
    by_path = capsys.readouterr().out
    assert "Cm_alpha" in by_path
    assert main(["truth", "--aircraft", "c172x", "--condition", "h=4000,V=180"]) == 0  # by its library name
    assert capsys.readouterr().out == by_path
    assert main(["fly", "--aircraft", "nope", "--out", str(tmp_path / "x.csv")]) == 2
    assert "--aircraft 'nope'" in capsys.readouterr().err


def test_output_piped_to_a_reader_that_leaves_ends_quietly(tmp_path):
    code = ("import sys; from harness.cli import main; sys.exit(main(['truth', '--aircraft', '737']))")
    p = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.read(5)
    p.stdout.close()  # what `| head -1` does
    err = p.stderr.read().decode()
    p.wait(timeout=120)
    assert "Traceback" not in err and "BrokenPipe" not in err and "internal error" not in err, err
