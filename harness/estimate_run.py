"""One ``sidbench estimate`` run as data: the fit, the options that produced it, the truth the
recording carries, and the time histories a report shows (measured, model, residual, regressors).

The report itself (``reports.estimate_report``) is written by ``harness.commands``, part of the
command line (the composition root); this module, below it, never imports the reports package.
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from estimators.result import ModelFit

TRUTH_DEFINITIONS = ("local", "fit")


@dataclass(frozen=True)
class EstimateRun:
    """What one estimate produced.

    ``options`` every option of the command line (defaults included); ``truth`` the recording's
    truth derivatives by the chosen definition ({name: value}, empty for flight data);
    ``time`` a frame indexed by time (s) with ``measured``, ``model`` and ``residual`` columns
    per output (``<output>:measured`` … for output error, plain names for one dependent);
    ``regressors`` the regressors against time (equation error) or the inputs (output error);
    ``notes`` what the report should say about how ``time`` was formed.
    """

    recording: str
    fit: ModelFit
    options: dict[str, Any]
    truth: dict[str, float] = field(default_factory=dict)
    truth_definition: str = "local"
    simulated: bool = False
    time: pd.DataFrame | None = None
    regressors: pd.DataFrame | None = None
    regressor_names: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()

    def parameter_table(self) -> pd.DataFrame:
        """One row per parameter: estimate, standard error, t, p, 95 % interval, and (when the
        recording is simulated) the truth, the error and the error in standard errors."""
        f = self.fit
        ci = np.asarray(f.conf_int(0.05))
        df = pd.DataFrame({"parameter": list(f.names), "estimate": np.asarray(f.params),
                           "std_error": np.asarray(f.bse), "t_value": np.asarray(f.tvalues),
                           "p_value": np.asarray(f.pvalues), "ci95_lower": ci[:, 0], "ci95_upper": ci[:, 1]})
        if self.simulated:
            tr = np.array([self.truth.get(n, np.nan) for n in f.names], dtype=float)
            df["truth"] = tr
            df["error"] = df["estimate"] - tr
            with np.errstate(divide="ignore", invalid="ignore"):
                df["error_in_se"] = df["error"] / df["std_error"]
            df["truth_definition"] = self.truth_definition
        df.insert(0, "dependent", f.dependent)
        df.insert(0, "method", f.method)
        return df

    def to_dict(self) -> dict:
        """The JSON of ``estimate --json``: the fit with residuals, the regressors and every option."""
        out = self.fit.to_dict(residuals=True)
        out["recording"] = self.recording
        out["options"] = self.options
        out["regressors"] = list(self.regressor_names)
        if self.simulated:
            out["truth_definition"] = self.truth_definition
            for row in out["parameters"]:
                t = self.truth.get(row["name"])
                row["truth"] = None if t is None else float(t)
                row["error_in_se"] = (None if t is None or not row["std_error"] > 0
                                      else (row["estimate"] - t) / row["std_error"])
        if self.time is not None:
            out["t_s"] = self.time.index.to_numpy(float).tolist()
        return out


def options_of(args: argparse.Namespace) -> dict[str, Any]:
    """Every option of the command line as JSON values (the dispatch entry left out)."""
    return {k: v for k, v in sorted(vars(args).items()) if k not in ("func",)
            and (v is None or isinstance(v, (str, int, float, bool, list)))}


def truth_of(meta: dict, definition: str) -> dict[str, float]:
    """The recording's truth derivatives ({name: value}) by ``definition``; {} without truth."""
    derivs = (meta.get("truth") or {}).get("derivatives") or {}
    return {k: float(v[definition]) for k, v in derivs.items() if isinstance(v, dict) and definition in v}


def equation_time_histories(rec, equation, data, fit: ModelFit) -> tuple[pd.DataFrame, pd.DataFrame, tuple[str, ...]]:
    """Measured z, the model Xθ (+ bias) and the residual in time, and the regressors, for an
    equation-error fit in either domain (the frequency domain has no bias: the model is then
    shifted by the mean residual, which the notes say)."""
    from estimators.regressors import regression_data

    d = regression_data(rec, equation, data)
    theta = np.asarray(fit.params)
    model = d.design() @ theta if equation.bias else d.X @ theta[:d.X.shape[1]]
    notes: list[str] = []
    if fit.domain == "frequency":
        shift = float(np.mean(d.z - model))
        model = model + shift
        notes.append(f"The frequency-domain fit has no bias term; its time-domain model Xθ is shown shifted by "
                     f"the mean residual ({shift:.4g}).")
    t = pd.Index(np.asarray(d.t, dtype=float), name="t_s")
    time = pd.DataFrame({"measured": d.z, "model": model, "residual": d.z - model}, index=t)
    regs = pd.DataFrame(np.asarray(d.X, dtype=float), index=t, columns=list(equation.regressors))
    return time, regs, tuple(notes)


def output_error_time_histories(rec, fit: ModelFit) -> tuple[pd.DataFrame | None, pd.DataFrame | None, tuple[str, ...]]:
    """Measured and model outputs of a time-domain output-error fit, and the recorded surfaces."""
    outputs = fit.dependent.split(",")
    if fit.domain != "time" or np.iscomplexobj(fit.residuals):
        return None, None, ("A frequency-domain fit has no time history of its residuals; the parameters are "
                            "shown, the time-history figures are not.",)
    fitted = np.asarray(fit.fitted, dtype=float).reshape(len(fit.fitted), -1)
    res = np.asarray(fit.residuals, dtype=float).reshape(len(fit.residuals), -1)
    t_all = np.asarray(rec.t, dtype=float)
    t = t_all[:len(fitted)] if len(t_all) >= len(fitted) else np.arange(len(fitted)) * float(rec.dt)
    cols = {}
    for i, o in enumerate(outputs[:fitted.shape[1]]):
        cols[f"{o}:measured"] = fitted[:, i] + res[:, i]
        cols[f"{o}:model"] = fitted[:, i]
        cols[f"{o}:residual"] = res[:, i]
    idx = pd.Index(t, name="t_s")
    surfaces = [c for c in rec.data.columns if c.split("_")[0] in ("de", "da", "dr", "ds")]
    regs = None
    if surfaces:
        regs = pd.DataFrame({c: rec.data[c].to_numpy(float)[:len(t)] for c in surfaces}, index=idx)
    return pd.DataFrame(cols, index=idx), regs, ()
