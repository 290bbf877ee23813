"""What a report needs besides the scores: flight time histories, modes, example fits.

Written by the runner beside ``results.parquet`` so that reports read files and never fly:

- ``flights.parquet``: each clean flight's time histories (degrees, deg/s, g);
- ``modes.parquet``: the aircraft's modes at the flight's trim point (from the linear models
  built on its truth derivatives: short period, Dutch roll, roll, spiral);
- ``examples.parquet``: for each flight and noise, realization 0 fitted by equation error in
  the time domain: measured, fitted and residual dependent variable against time.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from estimators.methods import make_estimator
from estimators.state_space import lateral_matrices, short_period_dimensional, short_period_matrices
from harness.campaign import Campaign, Task
from harness.noise import apply_noise
from harness.store import write_parquet
from harness.tasks import regression_with_noise, cached_flight, excited_equations
from maneuvers.recording import Recording

DEG = 180.0 / np.pi


def flight_table(label: str, key, rec: Recording) -> pd.DataFrame:
    """Time histories of one clean flight in engineering units."""
    cols = {"t_s": rec.t}
    for q, unit, k in (("alpha", "deg", DEG), ("beta", "deg", DEG), ("V", "fps", 1.0), ("p", "dps", DEG),
                       ("q", "dps", DEG), ("r", "dps", DEG), ("de", "deg", DEG), ("da", "deg", DEG),
                       ("dr", "deg", DEG), ("az", "g", 1.0), ("ay", "g", 1.0)):
        cols[f"{q}_{unit}"] = rec.channel(q) * k if rec.has(q) else np.full(rec.n, np.nan)
    df = pd.DataFrame(cols)
    df.insert(0, "loop", key.loop)
    df.insert(0, "variant", key.variant)
    df.insert(0, "maneuver", key.maneuver.name)
    df.insert(0, "flight", label)
    return df


def _mode_rows(label: str, eig: np.ndarray, names: list[str]) -> list[dict]:
    rows = []
    for name, lam in zip(names, eig):
        wn = abs(lam)
        rows.append({"flight": label, "mode": name, "frequency_hz": wn / (2 * np.pi),
                     "damping": float(-lam.real / wn) if wn > 0 else float("nan"),
                     "real": float(lam.real), "imag": float(lam.imag)})
    return rows


def modes_table(label: str, rec: Recording) -> pd.DataFrame:
    """Short period, Dutch roll, roll and spiral modes of the linear models at trim."""
    meta = rec.meta
    d = {k: v["local"] for k, v in meta.get("truth", {}).get("derivatives", {}).items()}
    trim, g, m = meta.get("trim", {}), rec.geometry, rec.mass_at(0)
    rows: list[dict] = []
    try:
        dim = short_period_dimensional(d["CZ_alpha"], d["CZ_qhat"], d["CZ_de"], d["Cm_alpha"], d["Cm_qhat"],
                                       d["Cm_de"], trim["qbar_psf"], g["S_ft2"], g["cbar_ft"], m["mass_slug"],
                                       m["Iy_slugft2"], trim["V_fps"])
        A = short_period_matrices(**dim, V_o=trim["V_fps"])[0]
        lam = np.linalg.eigvals(A)
        rows += _mode_rows(label, lam[:1] if np.iscomplex(lam).any() else lam, ["short period"] * (1 if np.iscomplex(lam).any() else 2))
        lat = {f"{c}_{v}": d[f"{c}_{v}"] for c in ("CY", "Cl", "Cn") for v in ("beta", "phat", "rhat", "da", "dr")}
        A = lateral_matrices(lat, qbar=trim["qbar_psf"], V=trim["V_fps"], S=g["S_ft2"], b=g["b_ft"],
                             m=m["mass_slug"], Ix=m["Ix_slugft2"], Iz=m["Iz_slugft2"], Ixz=m["Ixz_slugft2"],
                             alpha_o=trim.get("alpha_rad", 0.0), theta_o=trim.get("theta_rad", 0.0))[0]
        lam = np.linalg.eigvals(A)
        cplx = [x for x in lam if x.imag > 1e-9]
        real = sorted([x.real for x in lam if abs(x.imag) <= 1e-9], key=abs)
        if cplx:
            rows += _mode_rows(label, np.array(cplx[:1]), ["dutch roll"])
        if len(real) == 2:
            rows += _mode_rows(label, np.array(real[::-1], dtype=complex), ["roll", "spiral"])
    except (KeyError, ValueError, np.linalg.LinAlgError):
        pass
    return pd.DataFrame(rows, columns=["flight", "mode", "frequency_hz", "damping", "real", "imag"])


def example_table(task: Task, cache_dir: str) -> pd.DataFrame:
    """Realization 0 of a task fitted by time-domain equation error, per equation."""
    clean = cached_flight(task.flight, cache_dir)
    model = task.noise.model()
    noisy = apply_noise(clean, model, task.seed) if (model.channels or model.drop) else clean
    frames = []
    for eq in excited_equations(clean, task.equations):
        try:
            d = regression_with_noise(clean, noisy, eq, task.noise.apply_to, task, model)
            fit = make_estimator("ee-time").fit(d)
        except ValueError:
            continue
        frames.append(pd.DataFrame({"flight": task.flight.label(), "noise": task.noise.name,
                                    "equation": eq.describe(), "dependent": eq.dependent, "t_s": d.t,
                                    "measured": fit.fitted + fit.residuals, "fitted": fit.fitted,
                                    "residual": fit.residuals}))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def write_artifacts(campaign: Campaign, tasks: list[Task], out_dir: Path, cache_dir: str) -> None:
    """Write flights.parquet, modes.parquet and examples.parquet for ``campaign``."""
    keys = sorted({f for t in tasks for f in t.flights}, key=lambda k: k.label())
    flights, modes = [], []
    for key in keys:
        rec = cached_flight(key, cache_dir)
        flights.append(flight_table(key.label(), key, rec))
        modes.append(modes_table(key.label(), rec))
    write_parquet(pd.concat(flights, ignore_index=True), Path(out_dir) / "flights.parquet")
    write_parquet(pd.concat(modes, ignore_index=True), Path(out_dir) / "modes.parquet")
    firsts = [t for t in tasks if t.realization == 0 and not t.extra_flights and t.noise.turbulence is None]
    ex = [example_table(t, cache_dir) for t in firsts]
    ex = [e for e in ex if not e.empty]
    if ex:
        write_parquet(pd.concat(ex, ignore_index=True), Path(out_dir) / "examples.parquet")
