"""Issue 13: bad input as a user's files and typos arrive (generated here, never checked in).

Every case runs the real command line and asserts exit status 2, one line on stderr naming
the file and what is wrong, and no output left behind. Internal errors keep their traceback;
Ctrl-C exits 130 with one line; a killed campaign leaves no orphan worker and no temporary
file after the rerun; an interrupted diagnosis folder is marked incomplete.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.io
from test_recording_format import make_recording

from harness.cli import main
from harness.errors import Interrupted, run_reporting_errors
from harness.recording_io import _csv_lines, meta_path_for, read_recording, write_recording
from maneuvers.recording import Recording

ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------------------------------------ helpers


def _good(tmp_path: Path, name: str = "rec.csv", edit=None, meta_edit=None) -> Path:
    rec = make_recording(n=201)
    data = rec.data.copy()
    if edit:
        edit(data)
    meta = json.loads(json.dumps(rec.meta))
    if meta_edit:
        meta_edit(meta)
    path = tmp_path / name
    if path.suffix == ".csv":  # written without validation: the file is meant to break a rule
        path.write_text("".join(_csv_lines(data)))
        meta_path_for(path).write_text(json.dumps(meta))
    else:
        write_recording(Recording(data, meta, rec.name), path)
    return path


def _listing(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def _refused(capsys, argv: list[str], *needles: str, folder: Path | None = None) -> str:
    """Run ``sidbench argv``: exit 2, one line on stderr holding every needle, nothing new in ``folder``."""
    before = _listing(folder) if folder else set()
    code = main(argv)
    out = capsys.readouterr()
    lines = [line for line in out.err.splitlines() if line.strip()]
    assert code == 2, out.err
    assert len(lines) == 1, out.err
    assert "Traceback" not in out.err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    if folder:
        assert _listing(folder) == before, _listing(folder) ^ before
    return lines[0]


def _estimate(path: Path, *extra: str) -> list[str]:
    return ["estimate", "--recording", str(path), "--dependent", "Cm", "--regressors", "alpha,qhat,de", *extra]


def _set(column: str, row: int, value: float):
    def edit(df: pd.DataFrame) -> None:
        x = df[column].to_numpy().copy()
        x[row] = value
        df[column] = x
    return edit


# ------------------------------------------------------------------ recordings


def test_corrupted_parquet(tmp_path, capsys):
    path = _good(tmp_path, "rec.parquet")
    raw = bytearray(path.read_bytes())
    middle = len(raw) // 2
    raw[middle:middle + 64] = bytes(range(64))
    raw[-12:-8] = b"\xff\xff\xff\x7f"  # footer length: the thrift metadata cannot be read
    path.write_bytes(bytes(raw))
    _refused(capsys, _estimate(path), str(path), "Parquet", "bad-parquet", folder=tmp_path)


def _sidpac_struct(with_units: bool = True) -> dict:
    n = 50
    labels = ["V", "alpha", "beta", "p", "q", "r", "phi", "the", "psi", "ax", "ay", "az", "el", "qbar"]
    units = ["(fps)", "(deg)", "(deg)", "(dps)", "(dps)", "(dps)", "(deg)", "(deg)", "(deg)", "(g)", "(g)", "(g)",
             "(deg)", "(psf)"]
    fdata = np.ones((n, len(labels)))
    fds = {"varlab": np.array(labels, dtype=object), "fdata": fdata, "t": np.arange(n) * 0.02}
    if with_units:
        fds["varunits"] = np.array(units, dtype=object)
    return {"fds": fds, "fdata": fdata, "t": np.arange(n) * 0.02}


@pytest.mark.parametrize("case", ["empty", "truncated", "v73", "no-varunits", "garbage"])
def test_bad_mat_files(tmp_path, capsys, case):
    path = tmp_path / "flight.mat"
    if case == "empty":
        path.write_bytes(b"")
    elif case in ("truncated", "no-varunits"):
        scipy.io.savemat(path, _sidpac_struct(with_units=case == "truncated"))
        if case == "truncated":
            path.write_bytes(path.read_bytes()[:300])
    elif case == "v73":  # the 128-byte header of an HDF5-based MATLAB file (version 0x0200)
        head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
        path.write_bytes(head.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02IM" + b"\x89HDF\r\n\x1a\n" + b"\x00" * 512)
    else:
        path.write_bytes(os.urandom(4096))
    needle = {"empty": "empty", "truncated": "MATLAB", "v73": "v7.3", "no-varunits": "varunits",
              "garbage": "MATLAB"}[case]
    _refused(capsys, ["import", str(path), "--out", str(tmp_path / "out" / "x.csv")], str(path), needle,
             folder=tmp_path)
    _refused(capsys, _estimate(path), str(path), needle, folder=tmp_path)


def test_outputs_whose_folder_is_a_file_are_refused_before_any_work(tmp_path, capsys):
    rec = _good(tmp_path)
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    _refused(capsys, _estimate(rec, "--json", str(blocker / "fit.json")), str(blocker), "is a file",
             folder=tmp_path)
    _refused(capsys, ["import", str(rec), "--out", str(blocker / "sub" / "x.csv")], "is a file", folder=tmp_path)
    _refused(capsys, _estimate(rec, "--json", str(tmp_path)), "is a folder", folder=tmp_path)


def test_estimate_prints_no_fit_when_its_json_cannot_be_written(tmp_path, capsys):
    rec = _good(tmp_path)
    (tmp_path / "afile").write_text("x")
    assert main(_estimate(rec, "--json", str(tmp_path / "afile" / "fit.json"))) == 2
    assert capsys.readouterr().out == ""


def test_diagnose_out_naming_a_file(tmp_path, capsys):
    rec = _good(tmp_path)
    target = tmp_path / "report.txt"
    target.write_text("x")
    _refused(capsys, ["diagnose", "--model", "f16", "--recording", str(rec), "--out", str(target)], str(target),
             "is a file", folder=tmp_path)


def test_bad_utf8_in_metadata_names_file_line_and_column(tmp_path, capsys):
    path = _good(tmp_path)
    meta = meta_path_for(path)
    meta.write_bytes(meta.read_bytes().replace(b'"source": "test"', '"source": "Zürich"'.encode("latin-1")))
    line = _refused(capsys, _estimate(path), str(meta), "UTF-8", "byte 0xfc", "line 1", folder=tmp_path)
    assert "bad-encoding" in line


def test_latin1_in_the_csv_header_and_a_data_cell(tmp_path, capsys):
    path = _good(tmp_path)
    text = path.read_bytes()
    path.write_bytes(text.replace(b"xyz_deg", "xyz°_deg".encode("latin-1"), 1))
    _refused(capsys, _estimate(path), str(path), "UTF-8", "byte 0xb0", "header", folder=tmp_path)
    lines = text.split(b"\n")
    cells = lines[5].split(b",")
    cells[3] = b"0.1\xff"
    lines[5] = b",".join(cells)
    path.write_bytes(b"\n".join(lines))
    _refused(capsys, _estimate(path), str(path), "row 5 (data rows counted from 1; file line 6)", "non-numeric",
             folder=tmp_path)


def test_a_folder_named_like_a_recording(tmp_path, capsys):
    (tmp_path / "x.csv").mkdir()
    _refused(capsys, _estimate(tmp_path / "x.csv"), "x.csv", "is a folder", folder=tmp_path)


@pytest.mark.parametrize("column,row,value,needle", [
    ("V_fps", 120, 1e300, "'V_fps'"),
    ("q_rps", 33, 1e300, "'q_rps'"),
    ("qbar_psf", 7, -5.0, "'qbar_psf'"),
])
def test_physically_impossible_samples_name_the_row(tmp_path, capsys, column, row, value, needle):
    path = _good(tmp_path, edit=_set(column, row, value))
    _refused(capsys, _estimate(path), str(path), needle, f"row {row + 1} (data rows counted from 1)",
             "implausible-value", folder=tmp_path)


def test_all_zero_recording(tmp_path, capsys):
    def zero(df: pd.DataFrame) -> None:
        for c in df.columns:
            if c != "t_s":
                df[c] = 0.0
    path = _good(tmp_path, edit=zero)
    _refused(capsys, _estimate(path), str(path), "'V_fps'", "row 1", "implausible-value", folder=tmp_path)


@pytest.mark.parametrize("meta_edit,needles", [
    (lambda m: m["trim"].update(alpha_rad="0.09"), ("meta['trim']['alpha_rad']", "'0.09'", "bad-trim")),
    (lambda m: m["geometry"].update(cbar_ft="11.32"), ("meta['geometry']['cbar_ft']", "bad-geometry")),
    (lambda m: m["geometry"].update(S_ft22=300.0), ("meta['geometry']['S_ft22']", "did you mean 'S_ft2'")),
    (lambda m: m["mass"].update(Ixx_slugft2=1.0), ("meta['mass']['Ixx_slugft2']", "known keys")),
    (lambda m: m["mass"].update(mass_slug=True), ("meta['mass']['mass_slug']", "bad-mass")),
])
def test_metadata_types_and_keys_are_strict(tmp_path, capsys, meta_edit, needles):
    path = _good(tmp_path, meta_edit=meta_edit)
    _refused(capsys, _estimate(path), str(path.with_suffix("")), *needles, folder=tmp_path)


def test_diagnose_refuses_a_text_trim_and_leaves_no_folder(tmp_path, capsys):
    path = _good(tmp_path, meta_edit=lambda m: m["trim"].update(alpha_rad="level"))
    _refused(capsys, ["diagnose", "--model", "f16", "--recording", str(path), "--out", str(tmp_path / "d")],
             "'level'", "bad-trim", folder=tmp_path)


@pytest.mark.parametrize("edit,needles", [
    ("ragged", ("row 3 (data rows counted from 1; file line 4)", "length-mismatch")),
    ("blank", ("row 3 (data rows counted from 1; file line 4)", "blank")),
    ("empty-cell", ("row 4 (data rows counted from 1; file line 5)", "'alpha_rad'")),
    ("text", ("'abc'", "row 2 (data rows counted from 1; file line 3)")),
])
def test_csv_rows_counted_from_1_with_the_file_line(tmp_path, capsys, edit, needles):
    path = _good(tmp_path)
    lines = path.read_text().splitlines()
    if edit == "ragged":
        lines[3] = lines[3].rsplit(",", 1)[0]
    elif edit == "blank":
        lines[3] = ""
    elif edit == "empty-cell":
        cells = lines[4].split(",")
        cells[2] = ""
        lines[4] = ",".join(cells)
    else:
        cells = lines[2].split(",")
        cells[2] = "abc"
        lines[2] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    _refused(capsys, _estimate(path), str(path), *needles, folder=tmp_path)


def test_bad_frequencies_option(tmp_path, capsys):
    path = _good(tmp_path)
    _refused(capsys, _estimate(path, "--method", "ee-freq", "--frequencies", "abc"), "--frequencies", "'abc'",
             folder=tmp_path)


# ------------------------------------------------------------------ round trip and large files


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip_is_bit_exact_for_any_finite_double(tmp_path, suffix):
    rec = make_recording(n=2001)
    rng = np.random.default_rng(5)
    bits = rng.integers(0, 2**64, size=rec.n, dtype=np.uint64).view(np.float64)
    bits = np.where(np.isfinite(bits), bits, 0.1)
    bits[:6] = [5e-324, -0.0, 2.2250738585072014e-308, 1.7976931348623157e308, 0.1 + 0.2, 1e23]
    data = rec.data.copy()
    data["xyz_deg"] = bits
    rec = Recording(data, rec.meta, rec.name)
    back = read_recording(write_recording(rec, tmp_path / f"r{suffix}"))
    for c in rec.data.columns:
        a, b = rec.data[c].to_numpy(), back.data[c].to_numpy()
        assert np.array_equal(a.view(np.uint64), b.view(np.uint64)), c


def test_csv_larger_than_one_read_block_keeps_every_row(tmp_path):
    rec = make_recording(n=150_001)  # ~70 MB of text: many blocks of the streaming reader
    path = write_recording(rec, tmp_path / "big.csv")
    back = read_recording(path)
    assert back.n == rec.n
    for c in rec.data.columns:
        assert np.array_equal(rec.data[c].to_numpy(), back.data[c].to_numpy()), c


# ------------------------------------------------------------------ campaign files

BASE = 'name = "t"\nseed = 1\nrealizations = 2\n'


@pytest.mark.parametrize("text,needles", [
    (BASE + 'colour = "red"\n[grid]\n', ("unknown key colour", "known:")),
    (BASE + '[grid]\nmethods = ["oe"]\n', ("unknown key grid.methods", "did you mean 'method'")),
    (BASE + '[grid]\nnoise = ["x"]\n[noise]\nscael = 2.0\n', ("noise.scael", "did you mean 'scale'")),
    (BASE + '[grid]\nnoise = ["x"]\n[noise.x]\npreset = "white"\nscael = 2.0\n', ("noise.x.scael", "scale")),
    ('name = "t"\nseed = 1\nrealizations = "two"\n[grid]\n', ("realizations must be an integer", "'two'")),
    ('name = "t"\nseed = 1.5\nrealizations = 2\n[grid]\n', ("seed must be an integer",)),
    (BASE + '[grid]\nnoise = ["x"]\n[noise.x]\npreset = "white"\nscale = "2"\n', ("noise.x.scale", "number")),
    (BASE + '[grid]\nvariant = ["banana"]\n', ("variant 'banana'",)),
    (BASE + '[grid]\naircraft = ["f61"]\n', ("aircraft 'f61'", "did you mean 'f16'")),
    (BASE + '[grid]\nmaneuver = ["2-1-1-3"]\n', ("kind '2-1-1-3'",)),
    (BASE + '[grid]\nmethod = ["ee-freq"]\n[method_options.ee-freq]\nfrequencies = "abc"\n', ("frequencies",)),
    (BASE + '[grid]\nmethod = ["ee-freq"]\n[method_options.ee-freq]\nhold = "de"\n', ("hold", "regressor names")),
    (BASE + '[grid]\nmethod = ["ee-freq"]\n[method_factories]\n"ee-freq" = "os:system"\n',
     ("is code", "[plugins] allow")),
    (BASE + '[grid]\nmethod = ["ee-freq"]\n[method_options.ee-freq]\nautocorrelation = "ar"\n',
     ("autocorrelation", "methods with colored errors only")),
    (BASE + '[grid]\nmethod = ["ee-smooth"]\n[method_options.ee-smooth]\nautocorrelation = "arma"\n',
     ("autocorrelation", "'sample' or 'ar'")),
])
def test_campaign_file_mistakes_are_refused_before_anything_is_written(tmp_path, capsys, text, needles):
    path = tmp_path / "c.toml"
    path.write_text(text)
    out = tmp_path / "out"
    _refused(capsys, ["campaign", str(path), "--out", str(out), "--quiet"], str(path), *needles, folder=tmp_path)
    assert not out.exists()


def test_ee_freq_hold_reaches_the_estimator(tmp_path):
    """``[method_options.ee-freq] hold = [...]`` becomes make_estimator's ``hold``."""
    from harness.campaign import load_campaign
    from harness.tasks import _estimator
    (tmp_path / "c.toml").write_text(BASE + '[grid]\nmethod = ["ee-freq"]\n[method_options.ee-freq]\nhold = ["de"]\n')
    campaign = load_campaign(tmp_path / "c.toml")
    task = campaign.tasks()[0]
    assert _estimator(task, "ee-freq", "conventional").hold == ("de",)


def test_autocorrelation_option_reaches_the_colored_bounds_only(tmp_path):
    """``[method_options.ee-smooth] autocorrelation = "ar"`` reaches the colored-bound estimator;
    a conventional-bound task of the same method ignores it (nothing to apply it to)."""
    from harness.campaign import load_campaign
    from harness.tasks import _estimator
    (tmp_path / "c.toml").write_text(BASE + '[grid]\nmethod = ["ee-smooth"]\n[method_options.ee-smooth]\n'
                                     'autocorrelation = "ar"\n')
    task = load_campaign(tmp_path / "c.toml").tasks()[0]
    assert _estimator(task, "ee-smooth", "colored").autocorrelation == "ar"
    assert _estimator(task, "ee-smooth", "conventional").autocorrelation == "sample"


def test_workers_zero_is_refused(tmp_path, capsys):
    _refused(capsys, ["campaign", "regressor-noise", "--out", str(tmp_path / "o"), "--workers", "0"],
             "--workers must be at least 1", folder=tmp_path)


def test_plugins_run_only_when_allowed(tmp_path, monkeypatch):
    from harness.campaign import PLUGINS_ENV, CampaignError, load_campaign
    text = BASE + '[grid]\nmethod = ["ee-freq"]\n[method_factories]\n"ee-freq" = "planted:biased_frequency"\n'
    (tmp_path / "c.toml").write_text(text)
    with pytest.raises(CampaignError, match="is code"):
        load_campaign(tmp_path / "c.toml")
    (tmp_path / "d.toml").write_text(text + '[plugins]\nallow = ["planted:biased_frequency"]\n')
    assert load_campaign(tmp_path / "d.toml").method_factories == (("ee-freq", "planted:biased_frequency"),)
    monkeypatch.setenv(PLUGINS_ENV, "planted:biased_frequency")
    assert load_campaign(tmp_path / "c.toml").method_factories == (("ee-freq", "planted:biased_frequency"),)


def test_a_folder_without_finished_tasks_accepts_a_corrected_campaign(tmp_path):
    from harness.campaign import load_campaign
    from harness.runner import _check_out_dir
    out = tmp_path / "out"
    out.mkdir()
    (out / "campaign.json").write_text(json.dumps({"name": "old", "sha256": "0" * 64}))
    (tmp_path / "c.toml").write_text(BASE + "[grid]\n")
    _check_out_dir(out, load_campaign(tmp_path / "c.toml"))  # nothing to protect: no error
    assert json.loads((out / "campaign.json").read_text())["name"] == "t"


# ------------------------------------------------------------------ internal errors, --debug, Ctrl-C


def test_internal_errors_keep_their_traceback(capsys):
    def bug(args):
        return {}["missing"]
    assert run_reporting_errors(bug, None, "estimate") == 1
    err = capsys.readouterr().err
    assert "Traceback" in err and "KeyError" in err and "internal error" in err.splitlines()[-1]


def test_a_plain_value_error_is_a_bug_and_a_user_error_type_is_not(capsys):
    """Only the user-error types are user errors; a plain ValueError (an internal bug) keeps its
    traceback and exits 1, whatever layer raised it."""
    from models.conditions import ConditionError
    from models.errors import UserError

    def bug(args):
        raise ValueError("operands could not be broadcast together")
    assert run_reporting_errors(bug, None, "estimate") == 1
    err = capsys.readouterr().err
    assert "Traceback" in err and "internal error" in err.splitlines()[-1]
    for kind in (UserError, ConditionError):
        def mistake(args, kind=kind):
            raise kind("condition 'h=1': V is missing")
        assert run_reporting_errors(mistake, None, "fly") == 2
        err = capsys.readouterr().err
        assert "Traceback" not in err and err.strip() == "sidbench fly: error: condition 'h=1': V is missing"


def test_debug_shows_the_traceback_of_a_user_error(tmp_path, capsys):
    (tmp_path / "x.csv").mkdir()
    assert main(["--debug", *_estimate(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1].startswith("sidbench estimate: error:")


def test_interruption_exits_130_with_one_line(capsys):
    def stopped(args):
        raise Interrupted("finished tasks are kept in out/tasks; run the same command again to resume")
    assert run_reporting_errors(stopped, None, "campaign") == 130
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "resume" in lines[0]


# ------------------------------------------------------------------ real processes: Ctrl-C and kill -9

LONG = """
name = "long"
seed = 3
realizations = 200
[grid]
variant = ["linear"]
maneuver = ["doublet"]
noise = ["white"]
method = ["ee-time", "oe"]
equations = ["Cm = alpha + qhat + de"]
"""


def _start_campaign(tmp_path: Path) -> tuple[subprocess.Popen, Path, list[str]]:
    path = tmp_path / "long.toml"
    path.write_text(LONG)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "harness", "campaign", str(path), "--out", str(out), "--workers", "2",
           "--cache", str(tmp_path / "cache"), "--quiet"]
    # a shell without job control starts background jobs with SIGINT ignored, and the child
    # would inherit that: Ctrl-C is given its default disposition back, as a terminal has it
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)),
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline and len(list((out / "tasks").glob("*.parquet"))) < 3:
        assert proc.poll() is None, proc.stderr.read().decode()
        time.sleep(0.05)
    return proc, out, cmd


def _children(pid: int) -> list[int]:
    out = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        out += [int(x) for x in (task / "children").read_text().split()]
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state not in ("Z", "X")


def test_ctrl_c_on_a_campaign_exits_130_with_the_resume_hint(tmp_path):
    proc, out, _ = _start_campaign(tmp_path)
    workers = _children(proc.pid)
    os.kill(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    lines = err.decode().strip().splitlines()
    assert proc.returncode == 130, err.decode()
    assert len(lines) == 1 and "run the same command again to resume" in lines[0], err.decode()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.1)
    assert not any(_alive(p) for p in workers)


def test_kill_9_leaves_no_orphan_workers_and_the_rerun_no_temporary_file(tmp_path):
    proc, out, cmd = _start_campaign(tmp_path)
    workers = _children(proc.pid)
    assert len(workers) >= 2
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.1)
    assert not any(_alive(p) for p in workers), "pool workers outlived their parent"
    (out / "tasks" / ".deadbeef.parquet.abc123.tmp").write_bytes(b"")  # what a kill mid-write leaves
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert done.returncode == 0, done.stderr.decode()
    assert not list((out / "tasks").glob(".*.tmp"))


# ------------------------------------------------------------------ diagnosis folder


def test_interrupted_diagnosis_folder_is_marked_incomplete(tmp_path):
    from harness.diagnosis.run import INCOMPLETE, incomplete_marker
    out = tmp_path / "d"
    with pytest.raises(KeyboardInterrupt):
        with incomplete_marker(out):
            (out / "findings.json").write_text("{}")
            raise KeyboardInterrupt
    assert (out / INCOMPLETE).is_file()
    with incomplete_marker(out):  # the rerun: marked while running, clean at the end
        with incomplete_marker(out):  # diagnose() inside the command's own marker: the outer one decides
            pass
        assert (out / INCOMPLETE).is_file()
    assert not (out / INCOMPLETE).exists()
    fresh = tmp_path / "e"
    with pytest.raises(ValueError):
        with incomplete_marker(fresh):
            raise ValueError("bad recording")
    assert not fresh.exists()  # refused before anything was written: nothing left
