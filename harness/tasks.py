"""The work of one campaign task: fly (or fetch) the flight, add noise, run every method."""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pandas as pd

from estimators.least_squares import SingularRegressorsError
from estimators.methods import make_estimator, method_info
from estimators.regressors import DataOptions, Equation, EquationError, RegressionData, regression_data
from harness.campaign import FlightKey, Task
from harness.noise import apply_noise, output_noise, stream
from harness.recording_io import read_recording, write_recording
from maneuvers.recording import Recording
from models.constants import SURFACES

LONGITUDINAL = ("CX", "CZ", "Cm", "CL", "CD")
ROW_COLUMNS = ["task_id", "campaign", "flight", "aircraft", "variant", "condition", "maneuver", "loop", "noise",
               "realization", "seed", "method", "errors", "equation", "dependent", "parameter", "estimate",
               "std_error", "truth_local", "truth_fit", "time_s", "max_corr", "ok", "message"]


def fly_key(key: FlightKey, turbulence=None, turbulence_seed: int = 0) -> Recording:
    """Fly the flight ``key`` describes (variant ``'linear'``: the seed's linear models)."""
    if key.variant == "linear":  # turbulence: its own MIL-spec vertical gust (harness.linear_flight)
        from harness.linear_flight import linear_flight
        return linear_flight(key, fly_key, turbulence, turbulence_seed)
    from harness.flying import parse_loop
    from maneuvers.fly import FlightSpec, fly_maneuver
    from models.aircraft import Aircraft
    spec = FlightSpec(input=key.maneuver.build(), aircraft=Aircraft(key.aircraft, key.variant),
                      condition=key.condition, duration_s=key.duration_s, sample_rate_hz=key.sample_rate_hz,
                      loop=parse_loop(key.loop), turbulence=turbulence, turbulence_seed=turbulence_seed)
    return fly_maneuver(spec)


def cached_flight(key: FlightKey, cache_dir: str | Path) -> Recording:
    """The clean flight ``key``, flown once and kept under ``cache_dir/flights/<hash>.parquet``."""
    path = Path(cache_dir) / "flights" / f"{key.digest()}.parquet"
    if path.is_file():
        return read_recording(path)
    rec = fly_key(key)
    write_recording(rec, path)
    return rec


def excited_equations(rec: Recording, equations: tuple[Equation, ...]) -> tuple[Equation, ...]:
    """The equations whose control surfaces this flight moves (a longitudinal input says
    nothing about Cn: such equations are not fitted rather than reported as failures)."""
    moved = {s for s in SURFACES if rec.has(s) and np.ptp(rec.channel(s)) > 0}
    return tuple(eq for eq in equations
                 if all(r in moved for r in eq.regressors if r in SURFACES))


def _estimator(task: Task, method: str, errors: str):
    """The estimator for ``method``: the registry's, or a campaign's ``[method_factories]``
    override (``module:callable`` taking the same keywords), e.g. to plant a regression."""
    kwargs = dict(errors=errors if method_info(method).supports(errors) else "conventional",
                  **estimator_options(task, method))
    if kwargs["errors"] != "colored":
        kwargs.pop("autocorrelation", None)  # the colored bounds' option: nothing to do for conventional ones
    factory = dict(task.method_factories).get(method)
    if factory is None:
        return make_estimator(method, **kwargs)
    import importlib
    module, _, name = factory.partition(":")
    return getattr(importlib.import_module(module), name)(method, **kwargs)


def estimator_options(task: Task, method: str) -> dict:
    """Keyword options of :func:`estimators.methods.make_estimator` from the campaign file."""
    from estimators.methods import parse_frequencies
    opts = dict(dict(task.method_options).get(method, ()))
    out: dict = {}
    if "frequencies" in opts:
        out["frequencies_hz"] = parse_frequencies(str(opts["frequencies"]))
    if "detrend" in opts:
        out["detrend"] = str(opts["detrend"])
    if "max_lag" in opts:
        out["max_lag"] = int(opts["max_lag"])
    if "autocorrelation" in opts:
        out["autocorrelation"] = str(opts["autocorrelation"])
    if "hold" in opts:
        out["hold"] = tuple(str(h) for h in opts["hold"])
    return out


def _model_of(equation: Equation) -> str:
    return "short-period" if equation.dependent in LONGITUDINAL else "lateral"


def _truth(rec: Recording, name: str) -> tuple[float, float]:
    d = rec.meta.get("truth", {}).get("derivatives", {}).get(name)
    return (float("nan"), float("nan")) if d is None else (float(d["local"]), float(d["fit"]))


def regression_with_noise(clean: Recording, noisy: Recording, eq: Equation, apply_to: str, task: Task,
                noise_model) -> RegressionData:
    """z and X with regressor and output noise set apart as the noise definition says."""
    opts = DataOptions()
    x_src = clean if apply_to == "outputs" else noisy
    z_src = clean if apply_to == "regressors" else noisy
    dx = regression_data(x_src, eq, opts)
    z = dx.z if z_src is x_src else regression_data(z_src, eq, opts).z
    z = output_noise(z, dx.t, eq.dependent, noise_model, task.seed)
    return RegressionData(eq, z, dx.X, dx.t, dx.dt, dx.notes, dx.assumptions)


NAN = float("nan")
ROW_DEFAULTS = {"errors": "", "equation": "", "dependent": "", "estimate": NAN, "std_error": NAN,
                "truth_local": NAN, "truth_fit": NAN, "time_s": NAN, "max_corr": NAN, "ok": True, "message": ""}


def _row(common: dict, **fields) -> dict:
    """One result row: the defaults, overridden by the task's identity, then by ``fields``."""
    return ROW_DEFAULTS | common | fields


def max_correlation(fit) -> float:
    """Largest pairwise |r| (Eq. 50) among the fit's non-bias parameters."""
    keep = [i for i, n in enumerate(fit.names) if not n.startswith("bias")]
    if len(keep) < 2:
        return float("nan")
    r = np.abs(fit.correlation[np.ix_(keep, keep)])
    np.fill_diagonal(r, 0.0)
    return float(np.nanmax(r))


def _rows_for_fit(base: dict, fit, eq: Equation, rec: Recording, elapsed: float) -> list[dict]:
    rows = []
    mc = max_correlation(fit)
    for name, est, se in zip(fit.names, fit.params, fit.bse):
        if name != "bias" and not name.startswith(eq.dependent + "_"):
            continue
        tl, tf = _truth(rec, name)
        rows.append(_row(base, parameter=name, estimate=float(est), std_error=float(se), truth_local=tl,
                         truth_fit=tf, time_s=elapsed, max_corr=mc))
    return rows


def _failure_rows(base: dict, eq: Equation, rec: Recording, message: str) -> list[dict]:
    rows = []
    for r in eq.regressors:
        tl, tf = _truth(rec, f"{eq.dependent}_{r}")
        rows.append(_row(base, parameter=f"{eq.dependent}_{r}", truth_local=tl, truth_fit=tf, ok=False,
                         message=message[:300]))
    return rows


def run_task(task: Task, cache_dir: str) -> tuple[pd.DataFrame, float]:
    """All rows (one per method × errors × equation × parameter) of one task, and the time
    the task's flights and estimates took (for the harness-overhead figure)."""
    if task.extra_flights:
        return run_combined_task(task, cache_dir)
    t_start = time.perf_counter()
    noise_model = task.noise.model()
    turb = task.noise.turbulence
    if turb is not None:
        turb_seed = int(stream(task.seed, "turbulence").integers(1, 2**31 - 1))
        if task.flight.variant == "linear":  # the still-air JSBSim flight it is built on, cached
            from harness.linear_flight import linear_flight
            clean = linear_flight(task.flight, lambda k: cached_flight(k, cache_dir), turb, turb_seed)
        else:
            clean = fly_key(task.flight, turb, turb_seed)
    else:
        clean = cached_flight(task.flight, cache_dir)
    noisy = apply_noise(clean, noise_model, task.seed) if (noise_model.channels or noise_model.drop) else clean
    f = task.flight
    common = {"task_id": task.task_id, "campaign": task.campaign, "flight": f.label(), "aircraft": f.aircraft,
              "variant": f.variant, "condition": f.condition, "maneuver": f.maneuver.name, "loop": f.loop,
              "noise": task.noise.name, "realization": task.realization, "seed": json.dumps(list(task.seed))}
    rows: list[dict] = []
    oe_fits: dict[str, tuple] = {}
    equations = excited_equations(clean, task.equations)
    prepared: dict[Equation, RegressionData] = {}  # one build per equation, shared by the methods
    for method in task.methods:
        info = method_info(method)
        for errors in info.error_types(task.errors):
            for eq in equations:
                base = common | {"method": method, "errors": errors, "equation": eq.describe(),
                                 "dependent": eq.dependent}
                try:
                    if info.whole_model:  # fits its model once per flight, whatever the equation
                        model = _model_of(eq)
                        if (method, model) not in oe_fits:
                            src = noisy  # output error always sees the measured outputs
                            t0 = time.perf_counter()
                            oe_fits[(method, model)] = (make_estimator(method, model=model).fit(src, eq),
                                                        time.perf_counter() - t0)
                        fit, elapsed = oe_fits[(method, model)]
                    else:
                        if eq not in prepared:
                            prepared[eq] = regression_with_noise(clean, noisy, eq, task.noise.apply_to, task, noise_model)
                        d = prepared[eq]
                        est = _estimator(task, method, errors)
                        t0 = time.perf_counter()
                        fit = est.fit(d)
                        elapsed = time.perf_counter() - t0
                    rows += _rows_for_fit(base, fit, eq, clean, elapsed)
                except (SingularRegressorsError, EquationError, ValueError, np.linalg.LinAlgError) as exc:
                    rows += _failure_rows(base, eq, clean, f"{type(exc).__name__}: {exc}")
    if task.realization == 0:
        rows += crb_rows(common, clean, noise_model, equations)
        rows += excursion_rows(common, clean)
    return pd.DataFrame(rows, columns=ROW_COLUMNS), time.perf_counter() - t_start


def preflown(task: Task) -> tuple[FlightKey, ...]:
    """The clean flights a task reads from the cache: its own, or, when turbulence is flown per
    realization, the still-air nominal flight a linear-model flight is built on (none for
    JSBSim's own turbulent flights)."""
    if task.noise.turbulence is None:
        return task.flights
    import dataclasses
    return tuple(dataclasses.replace(f, variant="nominal", loop="open") for f in task.flights
                 if f.variant == "linear")


def prefly(key: FlightKey, cache_dir: str) -> float:
    """Fly and cache one clean flight; the time it took."""
    t0 = time.perf_counter()
    cached_flight(key, cache_dir)
    return time.perf_counter() - t0


def crb_rows(common: dict, clean: Recording, noise_model, equations: tuple[Equation, ...]) -> list[dict]:
    """Cramér-Rao bounds at the true parameters with the true output noise (method 'crb')."""
    from estimators.output_error import cramer_rao_bound
    from estimators.output_error_models import parameter_names
    outputs = {"short-period": ("alpha", "q", "az"), "lateral": ("beta", "p", "r", "phi", "ay")}
    chans = noise_model.channel_map
    rows = []
    for model in sorted({_model_of(eq) for eq in equations}):
        var = [chans[o].white_std ** 2 + chans[o].colored_std ** 2 if o in chans else 0.0 for o in outputs[model]]
        if min(var) <= 0:
            continue  # the bound needs noise on every output
        names = parameter_names(model)
        theta = {n: _truth(clean, n)[0] for n in names}
        theta = {n: (0.0 if np.isnan(v) else v) for n, v in theta.items()}
        try:
            cov = cramer_rao_bound(clean, model, theta, np.array(var))
        except (ValueError, np.linalg.LinAlgError):
            continue
        for eq in equations:
            if _model_of(eq) != model:
                continue
            for name, v in zip(names, np.sqrt(np.diag(cov))):
                if name.startswith(eq.dependent + "_"):
                    tl, tf = _truth(clean, name)
                    rows.append(_row(common, method="crb", equation=eq.describe(), dependent=eq.dependent,
                                     parameter=name, std_error=float(v), truth_local=tl, truth_fit=tf))
    return rows


EXCURSIONS = ("max_dalpha_deg", "max_dbeta_deg", "max_dnz_g", "dV_fps", "max_dV_fps")


def excursions(rec: Recording) -> dict[str, float]:
    """Peak excursions from the first sample: |Δα|, |Δβ| (deg), |Δn_z| (g), the airspeed
    change from start to end and its largest departure (ft/s)."""
    a, b, az, V = (rec.channel(c) for c in ("alpha", "beta", "az", "V"))
    return {"max_dalpha_deg": float(np.degrees(np.max(np.abs(a - a[0])))),
            "max_dbeta_deg": float(np.degrees(np.max(np.abs(b - b[0])))),
            "max_dnz_g": float(np.max(np.abs(az - az[0]))), "dV_fps": float(V[-1] - V[0]),
            "max_dV_fps": float(np.max(np.abs(V - V[0])))}


def excursion_rows(common: dict, clean: Recording) -> list[dict]:
    """The flight's excursions from trim as rows of method 'excursion'."""
    return [_row(common, method="excursion", parameter=k, estimate=v) for k, v in excursions(clean).items()]


def run_combined_task(task: Task, cache_dir: str) -> tuple[pd.DataFrame, float]:
    """A multiple-maneuver task (seed §III.F): every flight gets its own noise (its own
    stream, scaled by ``noise.flight_scales``); the equations are fitted by concatenation
    (Eq. 42), sequential a-priori combination with equal (Eqs. 47, 49) and unequal variances
    (Eqs. 45, 48) and frequency-domain combination. A row of method 'check' records the largest
    relative difference between the concatenated and the sequential estimates."""
    t_start = time.perf_counter()
    cleans, noisies, models = [], [], []
    for i, key in enumerate(task.flights):
        clean = cached_flight(key, cache_dir)
        model = task.noise.model(i)
        seed = task.seed + (i,)
        noisies.append(apply_noise(clean, model, seed) if (model.channels or model.drop) else clean)
        cleans.append(clean)
        models.append((model, seed))
    labels = "+".join(k.maneuver.name for k in task.flights)
    f0 = task.flight
    common = {"task_id": task.task_id, "campaign": task.campaign, "flight": labels, "aircraft": f0.aircraft,
              "variant": f0.variant, "condition": f0.condition, "maneuver": labels, "loop": f0.loop,
              "noise": task.noise.name, "realization": task.realization, "seed": json.dumps(list(task.seed))}
    rows: list[dict] = []
    for eq in task.equations:
        datasets = []
        for clean, noisy, (model, seed) in zip(cleans, noisies, models):
            sub = Task(task.campaign, f0, task.noise, task.realization, seed, (), (), ())
            datasets.append(regression_with_noise(clean, noisy, eq, task.noise.apply_to, sub, model))
        fits = {}
        for method in task.methods:
            for errors in method_info(method).error_types(task.errors):
                base = common | {"method": method, "errors": errors, "equation": eq.describe(),
                                 "dependent": eq.dependent}
                t0 = time.perf_counter()
                try:
                    fit = _estimator(task, method, errors).fit(datasets)
                except (SingularRegressorsError, EquationError, ValueError, np.linalg.LinAlgError) as exc:
                    rows += _failure_rows(base, eq, cleans[0], f"{type(exc).__name__}: {exc}")
                    continue
                fits[(method, errors)] = fit
                rows += _rows_for_fit(base, fit, eq, cleans[0], time.perf_counter() - t0)
        a, b = fits.get(("ee-concat", "conventional")), fits.get(("ee-sequential", "conventional"))
        if a is not None and b is not None:
            rel = float(np.max(np.abs(a.params - b.params) / np.maximum(np.abs(a.params), 1e-300)))
            rel_cov = float(np.max(np.abs(a.cov - b.cov)) / np.max(np.abs(a.cov)))
            for name, v in (("max_rel_diff_estimates", rel), ("max_rel_diff_covariance", rel_cov)):
                rows.append(_row(common, method="check", equation=eq.describe(), dependent=eq.dependent,
                                 parameter=name, estimate=v))
    return pd.DataFrame(rows, columns=ROW_COLUMNS), time.perf_counter() - t_start
