"""``sidbench bench``: time the project's main operations on this machine.

Every row is the best of ``--repeat`` runs (the least disturbed by other load). Later
issues add their rows to :func:`rows`.
"""
from __future__ import annotations

import argparse
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
    return out


def rows(repeat: int) -> list[BenchRow]:
    """All benchmark rows, in order."""
    return flight_rows(repeat) + estimator_rows(repeat)


def format_rows(table: list[BenchRow]) -> str:
    w = max(len(r.name) for r in table)
    return "\n".join(f"{r.name:<{w}}  {r.value:>10.3f} {r.unit:<4} {r.note}" for r in table)


def cmd_bench(args: argparse.Namespace) -> int:
    print(format_rows(rows(max(1, args.repeat))))
    return 0
