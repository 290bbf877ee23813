"""``sidbench bench``: time the project's main operations on this machine.

Every row is the best of ``--repeat`` runs (the least disturbed by other load). Later
issues add their rows to :func:`rows`.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class BenchRow:
    """One measured figure."""

    name: str
    value: float
    unit: str
    note: str = ""


def best_of(fn: Callable[[], object], repeat: int) -> float:
    """Least wall time of ``repeat`` calls, seconds."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def flight_rows(repeat: int) -> list[BenchRow]:
    """Trim + fly the default maneuver against raw JSBSim stepping of the same frames."""
    from maneuvers.fly import FlightSpec, fly_maneuver
    from models.aircraft import load_fdm
    from models.conditions import condition_for
    from models.flight import fly, frames_per_sample
    from models.trim import trim

    spec = FlightSpec()
    cond = condition_for("f16")
    n_frames = int(round(spec.length_s * spec.sample_rate_hz)) * frames_per_sample(spec.sample_rate_hz, spec.sim_rate_hz)
    fdms = [load_fdm(spec.aircraft, 1 / 150) for _ in range(2 * repeat)]

    trim_fly_times, raw_times = [], []
    for i in range(repeat):
        fdm = fdms[2 * i]
        t0 = time.perf_counter()
        tp = trim(fdm, spec.aircraft, cond)
        fly(fdm, spec.aircraft, tp, spec.input.deflections, spec.length_s)
        trim_fly_times.append(time.perf_counter() - t0)

        raw = fdms[2 * i + 1]
        trim(raw, spec.aircraft, cond)
        raw.set_dt(1 / 150)
        raw["simulation/models/FGFCS/enabled"] = 0
        run = raw.run
        t0 = time.perf_counter()
        for _ in range(n_frames):
            run()
        raw_times.append(time.perf_counter() - t0)
    tf, tr = min(trim_fly_times), min(raw_times)
    full = best_of(lambda: fly_maneuver(spec), max(1, repeat // 2))
    return [
        BenchRow("trim + fly default maneuver (F-16 2-1-1-2, 20 s)", tf * 1e3, "ms", f"{n_frames} frames at 150 Hz"),
        BenchRow("raw JSBSim stepping, same frames (floor)", tr * 1e3, "ms", "run() only"),
        BenchRow("ratio trim+fly / raw stepping", tf / tr, "x", "target <= 1.5"),
        BenchRow("fly_maneuver end to end (load, trim, fly, truth, recording)", full * 1e3, "ms"),
    ]


def _synthetic_regression(n: int, seed: int = 0):
    """A short-period-like regression of ``n`` samples at 50 Hz with white output noise."""
    import numpy as np

    from estimators.regressors import RegressionData
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    X = np.column_stack([np.sin(0.9 * t) + 0.2 * np.sin(3.1 * t), 0.01 * np.cos(0.9 * t),
                         np.sign(np.sin(0.5 * t)) * 0.017])
    z = X @ np.array([-0.08, -5.9, -0.53]) + 0.002 + 1e-4 * rng.standard_normal(n)
    return RegressionData.from_arrays(z, X, ("alpha", "qhat", "de"), 0.02, dependent="Cm")


def estimator_rows(repeat: int) -> list[BenchRow]:
    """Time per estimate of each method at N = 1,000 and N = 100,000 samples."""
    from estimators.colored import colored_residual_covariance
    from estimators.methods import make_estimator

    out = []
    for n in (1_000, 100_000):
        d = _synthetic_regression(n)
        reps = repeat if n <= 1_000 else max(1, repeat // 3)
        for name, errors in (("ee-time", "conventional"), ("ee-time", "colored"), ("ee-smooth", "conventional"),
                             ("ee-smooth", "colored"), ("ee-freq", "conventional")):
            est = make_estimator(name, errors=errors)
            tsec = best_of(lambda: est.fit(d), reps)
            out.append(BenchRow(f"{name} {errors}, N = {n:,}", tsec * 1e3, "ms",
                                "all lags" if errors == "colored" else ""))
        fit = make_estimator("ee-time").fit(d)
        A = d.design()
        tsec = best_of(lambda: colored_residual_covariance(A, fit.residuals), reps)
        out.append(BenchRow(f"colored covariance alone (Eq. 40, all lags), N = {n:,}", tsec * 1e3, "ms"))
        oe_data = _short_period_oe_data(n)
        from estimators.output_error import OutputError
        oe = OutputError(model="short-period")
        tsec = best_of(lambda: oe.fit(oe_data), reps)
        out.append(BenchRow(f"oe short period, N = {n:,}", tsec * 1e3, "ms", "Gauss-Newton from equation-error start"))
        from estimators.frequency_output_error import FrequencyOutputError
        fd = FrequencyOutputError(model="short-period")
        tsec = best_of(lambda: fd.fit(oe_data), reps)
        nf = len(fd.fit(oe_data).info["frequencies_hz"])
        out.append(BenchRow(f"oe-freq short period, N = {n:,}", tsec * 1e3, "ms",
                            f"{nf} harmonics to 1.2 Hz, same start"))
    model, data = _nonlinear_oe_data()
    from estimators.output_error import OutputError
    tsec = best_of(lambda: OutputError(model=model).fit(data), max(1, repeat // 3))
    out.append(BenchRow("oe nonlinear HFB-320 form (4 states, 12 parameters + 4 x0), N = 600", tsec * 1e3, "ms",
                        "RK4, finite-difference sensitivities; target < 2 s"))
    return out


def _nonlinear_oe_data(seed: int = 1):
    """The example model file's HFB-320-form model, 12 s of a 3-2-1-1 at 50 Hz, simulated at its
    truth (trimmed at 100 m/s, α = θ = 0.05) with noise, fitted from the file's starting values."""
    from pathlib import Path

    import numpy as np

    from estimators.dynamic_models import ManeuverData, load_model_file, simulate
    model = load_model_file(Path(__file__).resolve().parents[1] / "estimators" / "model_files" / "hfb320_model.py")
    c = dict(model.constants)
    qS = 0.5 * c["rho"] * 100.0 ** 2 * c["S"]
    thrust = 0.05 * qS / np.cos(0.05)
    truth = {"CD0": 0.05, "CDa": 0.30, "CDV": 0.02, "CL0": (c["m"] * c["g"] - thrust * np.sin(0.05)) / qS,
             "CLa": 4.5, "CLa2": 3.0, "CLV": 0.1, "Cm0": -0.06, "Cma": -0.6, "Cmq": -15.0, "Cmde": -1.2, "CmV": 0.02}
    t = np.arange(600) * 0.02
    u, s = np.full(600, -0.05), 1.0
    for k, w in enumerate((1.5, 1.0, 0.5, 0.5)):
        u[(t >= s - 1e-9) & (t < s + w - 1e-9)] += (-1) ** k * np.radians(2.0)
        s += w
    consts = {"thrust": thrust}
    _, y = simulate(model, ManeuverData(t, u, np.zeros((600, 7))), np.array([truth[p] for p in model.parameter_names])[:, None],
                    np.array([[100.0], [0.05], [0.05], [0.0]]), {**c, **consts})
    noise = np.array([0.2, np.radians(0.1), np.radians(0.1), np.radians(0.2), np.radians(1.0), 0.05, 0.1])
    z = y[:, :, 0] + np.random.default_rng(seed).standard_normal((600, 7)) * noise
    return model, ManeuverData(t, u, z, constants=consts)


def _short_period_oe_data(n: int, seed: int = 0):
    """Noisy outputs of the seed's Eq. 33 model (F-16 values) under repeated 2-1-1-2 inputs."""
    import numpy as np

    from estimators.output_error_models import FlightConstants, OutputErrorData
    from estimators.state_space import short_period_dimensional, short_period_matrices, simulate_linear
    fc = FlightConstants(qbar=149.0, V=420.0, S=300.0, cbar=11.32, b=30.0, m=641.0, Ix=12289.0, Iy=57108.0,
                         Iz=67072.0, Ixz=1060.0)
    dim = short_period_dimensional(-3.62, -31.4, 0.19, -0.081, -5.93, -0.529, fc.qbar, fc.S, fc.cbar, fc.m,
                                   fc.Iy, fc.V)
    A, B, C, D = short_period_matrices(**dim, V_o=fc.V)
    t = np.arange(n) * 0.02
    phase = t % 20.0
    u = np.radians(1.0) * (((phase >= 1) & (phase < 3)) * 1.0 - ((phase >= 3) & (phase < 4))
                           + ((phase >= 4) & (phase < 5)) - ((phase >= 5) & (phase < 7)))
    _, y = simulate_linear(A, B, C, D, u, 0.02)
    rng = np.random.default_rng(seed)
    z = y + rng.standard_normal(y.shape) * np.array([np.radians(0.1), np.radians(0.14), 0.03])
    return OutputErrorData(t=t, u=u.reshape(-1, 1), z=z, flight=fc)


def campaign_rows(realizations: int = 20) -> list[BenchRow]:
    """Throughput and overhead of a campaign on the local pool, and LocalCluster scaling."""
    import tempfile
    from pathlib import Path

    from harness.campaign import load_campaign
    from harness.runner import run_campaign

    campaign = load_campaign("regressor-noise").with_realizations(realizations)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "cache"
        warm = run_campaign(campaign.with_realizations(1), Path(tmp) / "warm", workers=2, cache_dir=cache,
                            progress=False)  # flights flown and cached once
        run = run_campaign(campaign, Path(tmp) / "pool", workers=2, cache_dir=cache, progress=False)
        m = run.meta
        out.append(BenchRow(f"campaign throughput, local pool 2 workers ({campaign.name}, {m['campaign']['tasks']} tasks)",
                            m["estimates"] / m["wall_s"], "est/s", f"{m['estimates']} estimates in {m['wall_s']:.1f} s"))
        out.append(BenchRow("harness overhead (1 - compute / (wall x workers))", 100 * (m["harness_overhead"] or 0.0),
                            "%", "target < 20 %"))
        walls = {}
        for w in (1, 2):
            r = run_campaign(campaign, Path(tmp) / f"dask{w}", scheduler="local", workers=w, cache_dir=cache,
                             progress=False)
            walls[w] = r.meta["wall_s"]
            out.append(BenchRow(f"dask LocalCluster, {w} worker{'s' if w > 1 else ''}", walls[w], "s",
                                f"{r.meta['estimates'] / walls[w]:.0f} est/s (cluster start-up included)"))
        out.append(BenchRow("LocalCluster scaling 1 -> 2 workers", walls[1] / walls[2], "x", "2 cores"))
        del warm
    return out


def report_rows(target_rows: int = 100_000) -> list[BenchRow]:
    """Scoring and writing a campaign report from a results table of ``target_rows`` rows.

    A small nightly run is replicated (realizations renumbered) up to the target size; the
    timing covers scoring, every figure and the HTML, Markdown and JSON files. The benchmark,
    like the command line, is part of the composition root: it imports the reports package."""
    import shutil
    import tempfile
    from pathlib import Path

    import pandas as pd

    from harness.campaign import load_campaign
    from harness.runner import run_campaign
    from harness.scores import score
    from harness.store import write_parquet
    from reports.campaign_report import campaign_report
    from reports.commands import write_all
    from reports.load import read_output

    with tempfile.TemporaryDirectory() as tmp:
        run = run_campaign(load_campaign("nightly").with_realizations(4), Path(tmp) / "small", workers=2,
                           cache_dir=Path(tmp) / "cache", progress=False)
        base = run.results
        copies = max(1, -(-target_rows // len(base)))
        big = pd.concat([base.assign(realization=base["realization"] + 4 * k) for k in range(copies)],
                        ignore_index=True)
        out = Path(tmp) / "big"
        shutil.copytree(run.out_dir, out, ignore=shutil.ignore_patterns("tasks"))
        write_parquet(big, out / "results.parquet")
        t0 = time.perf_counter()
        write_parquet(score(big, "local"), out / "scores.parquet")
        write_all(campaign_report(read_output(out)), out)
        seconds = time.perf_counter() - t0
    return [BenchRow(f"campaign report from a {len(big):,}-row results table", seconds, "s",
                     "scores + all figures + HTML/Markdown/JSON; target < 30 s")]


def diagnosis_rows(repeat: int) -> list[BenchRow]:
    """The discrepancy diagnosis of a 30 s gallery recording with its validation maneuver
    (analysis, the validation check, the replays, findings and series written), the same end to
    end as a user runs it (``sidbench diagnose`` in a fresh process, report included: issue
    12's bar of 10 s), and the Twin Otter flight data against the DHC6 when ``../shared`` is
    there."""
    import tempfile
    from pathlib import Path

    from harness.diagnosis.gallery import case, write_case
    from harness.diagnosis.run import diagnose

    out = []
    with tempfile.TemporaryDirectory() as tmp:
        paths = write_case(case("unsteady_alphadot"), Path(tmp) / "rec", seed=1)
        seconds = best_of(lambda: diagnose("f16", paths["identification"], Path(tmp) / "d",
                                           paths["validation"]), repeat)
        out.append(BenchRow("diagnose a 30 s F-16 recording + validation", seconds, "s",
                            "in-process, calibration included"))
        cmd = [sys.executable, "-m", "harness", "diagnose", "--model", "f16", "--recording",
               str(paths["identification"]), "--validation", str(paths["validation"]), "--out", str(Path(tmp) / "e")]
        seconds = best_of(lambda: subprocess.run(cmd, check=True, capture_output=True), min(repeat, 3))
        out.append(BenchRow("sidbench diagnose, same, end to end", seconds, "s",
                            "a fresh process: imports, analysis, calibration, report (HTML, Markdown, JSON); bar < 10 s"))
        data = Path(__file__).resolve().parents[2] / "shared" / "data" / "sidpac"
        ident, valid = data / "totter_f1_017_data.mat", data / "totter_f1_014_data.mat"
        if ident.is_file() and valid.is_file():
            seconds = best_of(lambda: diagnose("dhc6", ident, Path(tmp) / "t", valid, mass="recording"), repeat)
            out.append(BenchRow("diagnose Twin Otter 017 + 014 against the DHC6", seconds, "s", "20 s records"))
    return out


def calibration_rows(repeat: int) -> list[BenchRow]:
    """``calibrate``: ten scales from a 30 % wrong start, one 20 s F-16 recording, 2 workers
    (harness/calibrate/benchcase.py; issue 15's bar: 20 s)."""
    from harness.calibrate import calibrate
    from harness.calibrate.benchcase import bench_parameters, bench_recording

    rec, found = bench_recording(), {}

    def run() -> None:
        found["result"] = calibrate("f16", rec, bench_parameters(), workers=2, hold="sample")

    seconds = best_of(run, min(repeat, 2))
    r = found["result"]
    worst = max(abs(e - 1.0) / s for e, s in zip(r.estimate, r.std_error))
    return [BenchRow("calibrate F-16: 10 scales, one 20 s recording, 30 % wrong start", seconds, "s",
                     f"{r.iterations} iterations, {r.flights} JSBSim flights, 2 workers; largest |error| "
                     f"{worst:.1f} s.e.; target <= 20 s")]


LARGE_ROWS = 10_000_000


def large_recording_columns(n: int) -> dict:
    """Twenty channels of a synthetic flight at 100 Hz (the measured angular accelerations
    among them, as the format allows), deterministic."""
    import numpy as np
    rng = np.random.default_rng(0)
    t = np.arange(n) * 0.01
    w = 0.9 * t
    noise = lambda s: s * rng.standard_normal(n)  # noqa: E731
    return {
        "t_s": t, "V_fps": 420.0 + noise(0.5), "alpha_rad": 0.08 + 0.02 * np.sin(w) + noise(1e-4),
        "beta_rad": noise(1e-3), "p_rps": noise(1e-2), "q_rps": 0.018 * np.cos(w) + noise(1e-4),
        "r_rps": noise(1e-2), "phi_rad": noise(1e-2), "theta_rad": 0.08 + 0.02 * np.sin(w),
        "psi_rad": noise(1e-2), "ax_g": noise(1e-2), "ay_g": noise(1e-2), "az_g": -1.0 + noise(1e-2),
        "de_rad": 0.017 * np.sign(np.sin(0.5 * t)) + noise(1e-4), "da_rad": noise(1e-3), "dr_rad": noise(1e-3),
        "qbar_psf": 150.0 + noise(0.2), "pdot_rps2": noise(1e-2), "qdot_rps2": -0.0162 * np.sin(w) + noise(1e-3),
        "rdot_rps2": noise(1e-2),
    }


LARGE_META = {"format": "flight-recording/1", "aircraft": "F-16 (synthetic)",
              "geometry": {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32},
              "mass": {"mass_slug": 647.2, "Ix_slugft2": 9496.0, "Iy_slugft2": 55814.0, "Iz_slugft2": 63100.0,
                       "Ixz_slugft2": 982.0},
              "source": "sidbench bench: synthetic large recording"}


def write_large_recording(folder, n: int = LARGE_ROWS) -> dict:
    """``big.csv`` (+ ``big.meta.json``) and ``big.parquet`` of ``n`` rows in ``folder`` (written with
    pyarrow's writers, shortest round-trip floats: the bench's input, not the project's writer)."""
    import json
    from pathlib import Path

    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    from harness.recording_io import PARQUET_META_KEY
    folder = Path(folder)
    table = pa.table(large_recording_columns(n))
    pacsv.write_csv(table, folder / "big.csv")
    (folder / "big.meta.json").write_text(json.dumps(LARGE_META))
    pq.write_table(table.replace_schema_metadata({PARQUET_META_KEY: json.dumps(LARGE_META).encode()}),
                   folder / "big.parquet")
    return {"csv": folder / "big.csv", "parquet": folder / "big.parquet"}


_MEASURED_ESTIMATE = """
import json, resource, sys, time
t0 = time.perf_counter()
from harness.cli import main
code = main(["estimate", "--recording", sys.argv[1], "--dependent", "Cm", "--regressors", "alpha,qhat,de",
             "--method", "ee-time"])
print(json.dumps({"code": code, "seconds": time.perf_counter() - t0,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def measured_estimate(path) -> dict:
    """``sidbench estimate`` (ee-time, Cm = alpha + qhat + de) in a process of its own: wall seconds
    (imports included) and peak resident memory from its own ``getrusage`` (ru_maxrss)."""
    import json
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    out = subprocess.run([sys.executable, "-c", _MEASURED_ESTIMATE, str(path)], cwd=root, capture_output=True,
                         text=True, check=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    if result["code"] != 0:
        raise RuntimeError(f"estimate of {path} failed: {out.stderr}")
    return result


def large_recording_rows(n: int = LARGE_ROWS) -> list[BenchRow]:
    """A 10 M-row, 20-channel recording (CSV and Parquet) read, validated and estimated."""
    import tempfile
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        paths = write_large_recording(tmp, n)
        for kind in ("csv", "parquet"):
            r = measured_estimate(paths[kind])
            label = f"estimate ee-time Cm from a {n / 1e6:.0f} M-row, 20-channel {kind.upper()}"
            out.append(BenchRow(label, r["seconds"], "s",
                                f"peak {r['peak_mb']:.0f} MB (ru_maxrss); bar < 60 s and < 4 GB"))
    return out


def rows(repeat: int) -> list[BenchRow]:
    """All benchmark rows, in order."""
    return (flight_rows(repeat) + estimator_rows(repeat) + campaign_rows() + report_rows() + diagnosis_rows(repeat)
            + calibration_rows(repeat) + large_recording_rows())


def format_rows(table: list[BenchRow]) -> str:
    w = max(len(r.name) for r in table)
    return "\n".join(f"{r.name:<{w}}  {r.value:>10.3f} {r.unit:<4} {r.note}" for r in table)


def cmd_bench(args: argparse.Namespace) -> int:
    print(format_rows(rows(max(1, args.repeat))))
    return 0
