"""``calibrate``: the JSBSim aircraft itself as the model of output error, its named
adjustments estimated from recordings, validated on another, and handed back as XML."""
from __future__ import annotations

import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from harness.calibrate.auto import auto_parameters
from harness.calibrate.engine import gauss_newton
from harness.calibrate.fitstats import channel_fit, smoothed
from harness.calibrate.problem import (Base, CalibrationError, Flight, Maneuver, base_aircraft, check, fly_indexed,
                                       maneuver)
from harness.calibrate.spec import parse_parameters
from harness.executors import make_executor
from harness.recording_io import read_recording
from models.aircraft import load_fdm
from models.calibration_xml import Adjustment, adjusted_tree, delays, with_actuator_delays
from models.jsbsim_root import write_root
from models.mass import MassProperties
from models.trim import TrimError, trim


@dataclass(frozen=True)
class CalibrationResult:
    """A calibration: the estimates with their bounds, the fits before and after, the flights.

    ``std_error`` is the coloured-residual bound (:mod:`harness.calibrate.engine`),
    ``crb_std_error`` the plain Cramér-Rao bound; ``series[role][k]`` per maneuver the time,
    the measured and smoothed outputs and the flights before and after (each with its mean
    offset from the smoothed recording removed, as in the fit statistics).
    """

    base: Base
    adjustments: tuple[Adjustment, ...]
    start: np.ndarray
    estimate: np.ndarray
    std_error: np.ndarray
    crb_std_error: np.ndarray
    correlation: np.ndarray
    outputs: tuple[str, ...]
    fit_before: dict
    fit_after: dict
    iterations: int
    converged: bool
    refs: dict
    biases: np.ndarray
    series: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    flights: int = 0
    seconds: float = 0.0
    inputs: dict = field(default_factory=dict)

    def parameter_table(self) -> list[dict]:
        """The ``parameters`` list of calibration.json."""
        return [{"name": a.name, "start": float(s), "estimate": float(e), "std_error": float(se), "units": a.units}
                for a, s, e, se in zip(self.adjustments, self.start, self.estimate, self.std_error)]

    def calibrated_tree(self):
        """The calibrated aircraft XML for stock JSBSim (delays as ``<actuator>`` delays)."""
        aircraft = self.base.aircraft
        tree = adjusted_tree(self.base.tree(), self.adjustments, tuple(self.estimate), refs=self.refs,
                             surfaces=aircraft.surfaces)
        return with_actuator_delays(tree, delays(self.adjustments, tuple(self.estimate)), aircraft.surfaces)

    def as_json(self) -> dict:
        """calibration.json's content (the issue's keys first, then the supporting detail)."""
        names = [a.name for a in self.adjustments]
        return {
            "parameters": self.parameter_table(),
            "outputs": list(self.outputs),
            "fit_before": self.fit_before,
            "fit_after": self.fit_after,
            "iterations": self.iterations,
            "converged": self.converged,
            "correlation": np.round(self.correlation, 6).tolist(),
            "correlation_names": names,
            "std_error_kind": "Cramér-Rao bound corrected for coloured residuals (Eq. 40 generalised to output "
                              "error); crb_std_error: the plain Cramér-Rao bound",
            "crb_std_error": {n: float(s) for n, s in zip(names, self.crb_std_error)},
            "output_biases": {m: dict(zip(self.outputs, map(float, b)))
                              for m, b in zip(self.inputs.get("recordings", []), self.biases)},
            "references": self.refs,
            "fit_definition": "per channel: RMS of (smoothed recording - flight) with its mean removed, and Theil's "
                              "U; identification over the recordings fitted, validation over the validation ones",
            "flights": self.flights,
            "seconds": self.seconds,
            "notes": list(self.notes),
            "inputs": self.inputs,
            "seed": None,
        }


def _read(source) -> object:
    return read_recording(source) if isinstance(source, (str, Path)) else source


def _as_list(x) -> list:
    if x is None:
        return []
    return list(x) if isinstance(x, (list, tuple)) else [x]


def references(base: Base, m: Maneuver) -> dict[str, float]:
    """The unadjusted aircraft's trim at the first maneuver's start: the references of the
    vocabulary terms (α, V, surfaces: a term vanishes there, with its slope)."""
    aircraft = base.aircraft
    with tempfile.TemporaryDirectory(prefix="sidbench-calibrate-") as d:
        write_root(Path(d), base.name, base.tree(), Path(base.source))
        try:
            tp = trim(load_fdm(aircraft, 1 / 120, root=Path(d), name=base.name), aircraft, m.ic.condition())
        except TrimError as exc:
            raise CalibrationError(f"the model cannot trim at the recording's start: {exc}") from exc
    return {"alpha": tp.alpha_rad, "dV": tp.V_fps, "de": tp.de_rad, "da": tp.da_rad, "dr": tp.dr_rad}


def _evaluator(executor, base: Base, adjustments: tuple[Adjustment, ...], refs: dict, maneuvers: list[Maneuver],
               scratch: str):
    refs_t = tuple(sorted(refs.items()))

    def evaluate(points):
        items = [(k, Flight(base, adjustments, tuple(float(v) for v in th), refs_t, m, scratch))
                 for k, (th, m) in enumerate((th, m) for th in points for m in maneuvers)]
        out: list = [None] * len(items)
        for (k, _), y in executor.imap_unordered(fly_indexed, items):
            out[k] = y
        n = len(maneuvers)
        return [out[i * n:(i + 1) * n] for i in range(len(points))]

    return evaluate


def _correlation(cov: np.ndarray) -> np.ndarray:
    d = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return cov / np.outer(d, d)


def _series(maneuvers: list[Maneuver], smooth: list[np.ndarray], before, after) -> list[dict]:
    out = []
    for m, zs, yb, ya in zip(maneuvers, smooth, before, after):
        cols = {"t_s": m.t - m.t[0]}
        for j, o in enumerate(m.outputs):
            cols[f"meas_{o}"] = m.z[:, j]
            cols[f"smooth_{o}"] = zs[:, j]
            for tag, y in (("before", yb), ("after", ya)):
                cols[f"{tag}_{o}"] = (y[:, j] + np.mean(zs[:, j] - y[:, j])) if y is not None else np.full(len(m.t),
                                                                                                              np.nan)
        out.append({"name": m.name, "columns": cols})
    return out


def calibrate(aircraft: str | Base, recordings, parameters: str | Sequence[str | Adjustment], *,
              validation=None, outputs: Sequence[str] | None = None, workers: int = 2, mass: str = "model",
              max_iterations: int = 20, hold: str = "linear", aero_reference: str = "project") -> CalibrationResult:
    """Calibrate ``aircraft`` (``f16``, ``737``, ``dhc6``, an XML path, or a :class:`Base`) to
    ``recordings`` (paths or :class:`~maneuvers.recording.Recording`, one or several).

    Parameters
    ----------
    parameters : a comma list or a sequence of names (:mod:`models.calibration_xml`), or
        :class:`Adjustment` objects; ``auto`` adds the terms the diagnosis adds to the aircraft
        (run now on the first recording and validation), ``auto=FINDINGS.json`` those of an
        earlier diagnosis (:mod:`harness.calibrate.auto`).
    validation : recordings the calibrated model is only flown on (a prediction).
    outputs : the channels matched (default: every one of alpha, beta, p, q, r, phi, theta, V,
        ax, ay, az the first recording has).
    workers : processes flying the perturbed flights (1: in this process).
    mass : ``'model'`` (the aircraft's own) or ``'recording'`` (the first recording's mass and
        inertia at its first sample, written into the XML).
    hold : how the recorded surfaces are replayed between samples: ``'linear'`` (a surface that
        moves continuously: flight data) or ``'sample'`` (each sample held until the next: a
        stepped input sampled at its edges, as simulated recordings are).
    aero_reference : where a model given by name has its aerodynamic reference point
        (:data:`models.aircraft.AERO_REFERENCES`; the diagnosis passes the placement it chose).

    Raises
    ------
    CalibrationError
        For a bad parameter, an unknown function, a recording missing channels, a model that
        cannot fly the recordings at the starting values.
    """
    t0 = time.perf_counter()
    recs = [_read(r) for r in _as_list(recordings)]
    vals = [_read(r) for r in _as_list(validation)]
    if not recs:
        raise CalibrationError("calibrate needs at least one recording")
    if mass not in ("model", "recording"):
        raise CalibrationError(f"--mass must be 'model' or 'recording', not {mass!r}")
    items = [s.strip() for s in parameters.split(",")] if isinstance(parameters, str) else _as_list(parameters)
    auto: list[str] = []
    for it in [i for i in items if isinstance(i, str) and (i == "auto" or i.startswith("auto="))]:
        auto += auto_parameters(it, str(aircraft), _as_list(recordings)[0], next(iter(_as_list(validation)), None),
                                mass)
    items = [i for i in items if not (isinstance(i, str) and (i == "auto" or i.startswith("auto=")))] + auto
    if all(isinstance(i, Adjustment) for i in items) and items:
        adjustments = tuple(items)
    else:
        adjustments = parse_parameters(",".join(i if isinstance(i, str) else i.name for i in items if i))
    if isinstance(aircraft, Base):
        base = aircraft
    else:
        mp = None
        if mass == "recording":
            try:
                mp = MassProperties.from_mapping(recs[0].mass_at(0))
            except (KeyError, ValueError) as exc:
                raise CalibrationError(f"--mass recording: {exc}") from exc
        base = base_aircraft(str(aircraft), mp, aero_reference)
    check(base, adjustments)
    ident = [maneuver(r, tuple(outputs) if outputs else None, hold) for r in recs]
    outs = ident[0].outputs
    ident = [maneuver(r, outs, hold) for r in recs]
    valid = [maneuver(r, outs, hold) for r in vals]
    refs = references(base, ident[0])
    start = np.array([a.start for a in adjustments])
    typical = np.array([a.typical for a in adjustments])
    lower = np.array([a.lower for a in adjustments])
    with tempfile.TemporaryDirectory(prefix="sidbench-calibrate-") as scratch, make_executor(None, workers) as ex:
        evaluate = _evaluator(ex, base, adjustments, refs, ident, scratch)
        try:
            res = gauss_newton(evaluate, start, typical, lower, [m.z for m in ident], max_iterations=max_iterations,
                               names=[a.name for a in adjustments])
        except RuntimeError as exc:
            raise CalibrationError(str(exc)) from exc
        final = _evaluator(ex, base, adjustments, refs, ident + valid, scratch)([start, res.theta])
    n_id = len(ident)
    smooth = [smoothed(m.z, m.dt) for m in ident + valid]
    b_flights = [y if not isinstance(y, str) else None for y in final[0]]
    a_flights = [y if not isinstance(y, str) else None for y in final[1]]
    notes = list(res.notes) + [f"{(ident + valid)[k].name}: the {tag} flight failed: {y}"
                               for tag, fl in (("before", final[0]), ("after", final[1]))
                               for k, y in enumerate(fl) if isinstance(y, str)]
    roles = {"identification": slice(0, n_id)} | ({"validation": slice(n_id, None)} if valid else {})
    fit_before = {r: channel_fit(smooth[s], b_flights[s], outs) for r, s in roles.items()}
    fit_after = {r: channel_fit(smooth[s], a_flights[s], outs) for r, s in roles.items()}
    allm = ident + valid
    series = {r: _series(allm[s], smooth[s], b_flights[s], a_flights[s]) for r, s in roles.items()}
    inputs = {"model": base.model, "mass": mass, "recordings": [m.name for m in ident],
              "validation": [m.name for m in valid], "workers": workers, "max_iterations": max_iterations, "surfaces": hold, "auto": auto,
              "start_h_ft": ident[0].ic.h_ft, "start_V_fps": ident[0].ic.V_fps}
    return CalibrationResult(
        base=base, adjustments=adjustments, start=start, estimate=res.theta,
        std_error=np.sqrt(np.diag(res.cov)), crb_std_error=np.sqrt(np.diag(res.crb)),
        correlation=_correlation(res.cov), outputs=outs, fit_before=fit_before, fit_after=fit_after,
        iterations=res.iterations, converged=res.converged, refs=refs, biases=res.biases, series=series,
        notes=tuple(notes), flights=res.flights + len(final) * len(allm), seconds=time.perf_counter() - t0,
        inputs=inputs)
