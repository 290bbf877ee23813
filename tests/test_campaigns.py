"""Campaigns: coverage pinned on a known case, executors agree bit for bit, a killed run
resumes without recomputing, campaign files are checked, every built-in campaign runs."""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from harness.campaign import BUILTIN_DIR, CampaignError, load_campaign
from harness.cli import main
from harness.runner import run_campaign

DETERMINISTIC = ["task_id", "flight", "noise", "realization", "seed", "method", "errors", "equation", "parameter",
                 "estimate", "std_error", "truth_local", "truth_fit", "ok"]


def _write(tmp_path: Path, text: str, name: str = "c.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


OLS_CASE = """
name = "ols-coverage"
seed = 11
realizations = {n}
[grid]
variant = ["linear"]
maneuver = ["2-1-1-2"]
noise = ["output-only"]
method = ["ee-time"]
errors = ["conventional"]
equations = ["Cm = alpha + qhat + de"]
[noise.output-only]
preset = "none"
output = {{ Cm = 0.0005 }}
"""


def test_coverage_of_ols_with_white_output_noise_is_nominal(tmp_path):
    """Must show 4: least squares on a linear model (the seed's Eq. 33, exact regressors) with
    white noise on the output only. |θ̂ − θ|/se follows Student's t with N − 4 = 997 degrees of
    freedom, so the ±2σ interval covers with p = P(|t| ≤ 2) = 0.9542; with n = 400 the coverage
    is Binomial(n, p)/n, standard deviation sqrt(p(1 − p)/n) = 0.0105, and we allow 4 of them
    (three parameters tested). The standard-error ratio is mean(se)/s with s the sample standard
    deviation of n estimates, whose relative standard error is 1/sqrt(2(n − 1)) = 0.0354: 4 of
    them again."""
    n = 400
    run = run_campaign(load_campaign(_write(tmp_path, OLS_CASE.format(n=n))), tmp_path / "out",
                       workers=2, cache_dir=tmp_path / "cache", progress=False)
    s = run.scores[run.scores["parameter"] != "bias"]
    assert len(s) == 3
    p = 0.9542
    tol_cov = 4 * math.sqrt(p * (1 - p) / n)
    tol_ratio = 4 / math.sqrt(2 * (n - 1))
    for _, row in s.iterrows():
        assert abs(row["coverage"] - p) <= tol_cov, (row["parameter"], row["coverage"])
        assert row["coverage_lo"] <= row["coverage"] <= row["coverage_hi"]
        assert abs(row["se_ratio"] - 1.0) <= tol_ratio, (row["parameter"], row["se_ratio"])
        assert abs(row["bias_z"]) <= 4.0  # unbiased: bias within 4 Monte Carlo standard errors
    meta = run.meta
    assert meta["seed"] == 11 and meta["campaign"]["sha256"] and meta["versions"]["numpy"]
    assert {"commit", "executor", "start", "end"} <= set(meta)


SMALL = """
name = "small"
seed = 5
realizations = 3
[grid]
variant = ["linear", "exact-truth"]
maneuver = ["2-1-1-2"]
noise = ["white"]
method = ["ee-time", "ee-freq", "oe"]
errors = ["conventional", "colored"]
equations = ["Cm = alpha + qhat + de"]
"""


def test_dask_localcluster_matches_the_local_pool_bit_for_bit(tmp_path):
    """Must show 2: a real two-worker LocalCluster on loopback gives the same numbers."""
    campaign = load_campaign(_write(tmp_path, SMALL))
    pool = run_campaign(campaign, tmp_path / "pool", workers=2, cache_dir=tmp_path / "cache", progress=False)
    dask = run_campaign(campaign, tmp_path / "dask", scheduler="local", workers=2, cache_dir=tmp_path / "cache2",
                        progress=False)
    assert "LocalCluster" in dask.meta["executor"]
    serial = run_campaign(campaign, tmp_path / "serial", workers=1, cache_dir=tmp_path / "cache3", progress=False)
    a, b, c = (r.results[DETERMINISTIC] for r in (pool, dask, serial))
    est = pool.results[pool.results["method"] == "ee-time"]
    assert set(est["errors"]) == {"conventional", "colored"}
    assert set(est["equation"]) == {"Cm = Cm_alpha + Cm_qhat + Cm_de + bias"} and set(est["dependent"]) == {"Cm"}
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    pd.testing.assert_frame_equal(a, c, check_exact=True)


RESUME = """
name = "resume"
seed = 9
realizations = 30
[grid]
variant = ["linear"]
maneuver = ["2-1-1-2", "doublet"]
noise = ["white"]
method = ["ee-time", "ee-smooth", "oe"]
errors = ["conventional"]
equations = ["Cm = alpha + qhat + de", "CZ = alpha + qhat + de"]
"""


def test_killed_campaign_resumes_without_recomputing(tmp_path):
    """Must show 3: kill -9 a running campaign (a real process), rerun the same command: it
    finishes the rest, recomputes nothing, and the results equal an uninterrupted run's."""
    path = _write(tmp_path, RESUME)
    out, cache = tmp_path / "out", tmp_path / "cache"
    cmd = [sys.executable, "-m", "harness", "campaign", str(path), "--out", str(out), "--workers", "1",
           "--cache", str(cache), "--quiet"]
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    tasks = out / "tasks"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list(tasks.glob("*.parquet")) if tasks.is_dir() else []) < 8:
        assert proc.poll() is None, proc.stderr.read().decode()
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in tasks.glob("*.parquet")}
    assert 8 <= len(before) < 60, len(before)
    for p in tasks.glob("*.parquet"):  # every visible task file is whole (a kill mid-write leaves
        pd.read_parquet(p)             # at most a hidden .tmp, which kill -9 gives no chance to remove)
    assert subprocess.run(cmd, env=env, capture_output=True).returncode == 0
    assert not list(tasks.glob(".*.tmp"))  # the rerun removed any temporary the kill left
    after = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in tasks.glob("*.parquet")}
    assert len(after) == 60
    for name, stamp in before.items():
        assert after[name] == stamp, f"task {name} was recomputed"
    import json
    assert json.loads((out / "run.json").read_text())["tasks_run"] == 60 - len(before)
    # a temporary left by a kill in mid-write (planted: the kill above may or may not land in
    # one) is removed by the next run, which leaves the finished tasks alone
    (tasks / ".planted.parquet.abc123.tmp").write_bytes(b"half a parquet")
    assert subprocess.run(cmd, env=env, capture_output=True).returncode == 0
    assert not list(tasks.glob(".*.tmp")) and len(list(tasks.glob("*.parquet"))) == 60
    fresh = run_campaign(load_campaign(path), tmp_path / "fresh", workers=2, cache_dir=cache, progress=False)
    resumed = pd.read_parquet(out / "results.parquet")
    pd.testing.assert_frame_equal(resumed[DETERMINISTIC], fresh.results[DETERMINISTIC], check_exact=True)


@pytest.mark.parametrize("text,message", [
    ("seed = 1\nrealizations = 2\n[grid]\n", "missing key 'name'"),
    ("name='x'\nseed=1\nrealizations=2\n[grid]\nmethod=['magic']\n", "grid.method 'magic'"),
    ("name='x'\nseed=1\nrealizations=2\n[grid]\nnoise=['loud']\n", "grid.noise 'loud'"),
    ("name='x'\nseed=1\nrealizations=2\n[grid]\nequations=['Cm alpha']\n", "must look like"),
    ("name='x'\nseed=1\nrealizations=2\ntruth='mid'\n[grid]\n", "truth must be"),
    ("name='x'\nseed=1\nrealizations=2\n[grid\n", "not valid TOML"),
])
def test_bad_campaign_files_are_refused_naming_the_key(tmp_path, text, message):
    path = _write(tmp_path, text)
    with pytest.raises(CampaignError, match=message) as exc:
        load_campaign(path)
    assert str(path) in str(exc.value)


def test_rerun_into_a_folder_of_another_campaign_is_refused(tmp_path):
    a = load_campaign(_write(tmp_path, OLS_CASE.format(n=2), "a.toml"))
    run_campaign(a, tmp_path / "out", workers=1, cache_dir=tmp_path / "cache", progress=False)
    b = load_campaign(_write(tmp_path, OLS_CASE.format(n=2).replace("seed = 11", "seed = 12"), "b.toml"))
    with pytest.raises(ValueError, match="different campaign file"):
        run_campaign(b, tmp_path / "out", workers=1, cache_dir=tmp_path / "cache", progress=False)


def test_seeds_depend_on_identity_not_order():
    c = load_campaign("regressor-noise")
    tasks = c.tasks()
    again = {t.task_id: t.seed for t in load_campaign("regressor-noise").tasks()[::-1]}
    assert all(again[t.task_id] == t.seed for t in tasks)
    assert len({t.seed for t in tasks}) == len(tasks)
    # the same flight, noise and realization get the same seed in a bigger campaign
    bigger = {t.task_id: t.seed for t in c.with_realizations(150).tasks()}
    assert all(bigger[t.task_id] == t.seed for t in tasks)


@pytest.mark.parametrize("name", sorted(p.stem for p in BUILTIN_DIR.glob("*.toml")))
def test_every_builtin_campaign_runs_from_the_command_line(name, tmp_path, capsys):
    assert main(["campaign", name, "--out", str(tmp_path / name), "--realizations", "2", "--workers", "2",
                 "--cache", str(tmp_path / "cache"), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert f"campaign {name}" in out and "wrote" in out
    scores = pd.read_parquet(tmp_path / name / "scores.parquet")
    assert len(scores) and np.isfinite(scores["mean"]).any()


def test_builtin_campaign_names():
    """The six of the campaigns issue and the turbulence campaign of the output-error one."""
    assert sorted(p.stem for p in BUILTIN_DIR.glob("*.toml")) == sorted(
        ["regressor-noise", "error-bounds", "collinearity", "multiple-maneuvers", "maneuver-design", "nightly",
         "turbulence"])


def test_scores_against_hand_computed_values():
    from harness.scores import score
    est = np.array([1.0, 1.2, 0.8, 1.1, 0.9])
    se = np.array([0.1, 0.1, 0.1, 0.01, 0.2])
    base = {"campaign": "c", "aircraft": "f16", "variant": "v", "condition": "x", "maneuver": "m", "loop": "open",
            "noise": "n", "method": "ee-time", "errors": "conventional", "equation": "e", "dependent": "Cm",
            "parameter": "Cm_alpha", "truth_local": 1.05, "truth_fit": 1.0, "time_s": 0.01, "max_corr": 0.5,
            "ok": True}
    df = pd.DataFrame([base | {"realization": i, "estimate": e, "std_error": s} for i, (e, s) in enumerate(zip(est, se))])
    sc = score(df, "local").iloc[0]
    std = est.std(ddof=1)
    assert sc["mean"] == pytest.approx(1.0) and sc["bias"] == pytest.approx(-0.05)
    assert sc["bias_pct"] == pytest.approx(-0.05 / 1.05 * 100)
    assert sc["bias_z"] == pytest.approx(-0.05 / (std / math.sqrt(5)))
    assert sc["rmse"] == pytest.approx(math.sqrt(np.mean((est - 1.05) ** 2)))
    assert sc["se_ratio"] == pytest.approx(se.mean() / std)
    # covered: |e - 1.05| <= 2 se -> 1.0 yes, 1.2 yes (0.15 <= 0.2), 0.8 no, 1.1 no (0.05 > 0.02), 0.9 yes
    assert sc["coverage"] == pytest.approx(3 / 5)
    from scipy.stats import binomtest
    ci = binomtest(3, 5).proportion_ci(method="exact")
    assert sc["coverage_lo"] == pytest.approx(ci.low) and sc["coverage_hi"] == pytest.approx(ci.high)
    assert score(df, "fit").iloc[0]["truth"] == 1.0


def test_scheduler_address_of_a_running_cluster(tmp_path):
    """``--scheduler tcp://HOST:PORT``: a scheduler started elsewhere (here a LocalCluster on
    loopback) runs the campaign with the same numbers as the local pool."""
    from distributed import LocalCluster
    campaign = load_campaign(_write(tmp_path, OLS_CASE.format(n=4)))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=":0") as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = run_campaign(campaign, tmp_path / "remote", scheduler=cluster.scheduler_address, workers=2,
                              cache_dir=tmp_path / "c1", progress=False)
    pool = run_campaign(campaign, tmp_path / "pool", workers=2, cache_dir=tmp_path / "c2", progress=False)
    assert "dask scheduler tcp://127.0.0.1" in remote.meta["executor"]
    pd.testing.assert_frame_equal(remote.results[DETERMINISTIC], pool.results[DETERMINISTIC], check_exact=True)


TURB = """
name = "turb"
seed = 1
realizations = 3
[grid]
variant = ["exact-truth"]
maneuver = ["2-1-1-2"]
noise = ["turbulence-light"]
method = ["ee-time"]
errors = ["conventional"]
equations = ["Cm = alpha + qhat + de"]
"""


def test_turbulence_is_flown_per_realization_and_reproducible(tmp_path):
    campaign = load_campaign(_write(tmp_path, TURB))
    a = run_campaign(campaign, tmp_path / "a", workers=2, cache_dir=tmp_path / "cache", progress=False)
    b = run_campaign(campaign, tmp_path / "b", workers=1, cache_dir=tmp_path / "cache", progress=False)
    est = a.results[a.results["parameter"] == "Cm_alpha"]["estimate"]
    assert est.nunique() == 3  # each realization flew its own gusts
    pd.testing.assert_frame_equal(a.results[DETERMINISTIC], b.results[DETERMINISTIC], check_exact=True)
