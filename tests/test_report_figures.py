"""Report figures: every figure renders from small synthetic tables that follow the data
contract, survives awkward data (NaNs, one method, one realization, many parameters) and
returns None without data."""
from __future__ import annotations

import dataclasses
import io
import threading

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
import pytest

from reports import figures as F

TRUTH = {"Cm_alpha": -0.08, "Cm_qhat": -4.5, "Cm_de": -0.45, "CZ_alpha": -4.3, "CZ_qhat": -20.0, "CZ_de": -0.6}
METHODS = (("ee-time", "conventional"), ("ee-time", "colored"), ("ee-freq", "conventional"), ("oe", "cramer-rao"))
FLIGHT_CHANNELS = ("alpha_deg", "beta_deg", "V_fps", "p_dps", "q_dps", "r_dps", "de_deg", "da_deg", "dr_deg",
                   "az_g", "ay_g")


def synthetic_results(n_real: int = 20, noises=("none", "white"), maneuvers=("2-1-1-2", "doublet"),
                      methods=METHODS, params=("Cm_alpha", "Cm_qhat", "Cm_de"), seed: int = 0) -> pd.DataFrame:
    """A results table following the contract: estimates scattered about the truth, the
    'ee-time' one biased, plus 'crb' and 'excursion' rows."""
    rng = np.random.default_rng(seed)
    rows = []
    dep = params[0].split("_")[0]
    eq = f"{dep} = " + " + ".join(p.split("_", 1)[1] for p in params)
    for mi, man in enumerate(maneuvers):
        corr = 0.5 + 0.45 * mi / max(len(maneuvers) - 1, 1)
        flight = f"f16/nominal/{man}/open"
        common = dict(campaign="test", flight=flight, aircraft="f16", variant="nominal", condition="seed-5deg",
                      maneuver=man, loop="open", seed="[1, 2]", equation=eq, dependent=dep, message="")
        for noise in noises:
            scale = 0.0 if noise == "none" else 1.0
            for k in range(n_real):
                for method, errors in methods:
                    bias = 0.1 if method == "ee-time" else 0.0
                    for p in params:
                        t = TRUTH.get(p, -1.0)
                        sd = 0.03 * abs(t) * scale
                        est_rng = np.random.default_rng((seed, mi, k, params.index(p), len(method)))
                        est = t * (1 + bias * scale) + sd * est_rng.normal()
                        se = sd * (0.5 if errors == "conventional" and method == "ee-time" else 1.0)
                        rows.append(common | dict(task_id=f"{man}-{noise}-{k}", noise=noise, realization=k,
                                                  method=method, errors=errors, parameter=p, estimate=est,
                                                  std_error=se, truth_local=t, truth_fit=t * 0.9,
                                                  time_s=(0.05 if method == "oe" else 0.002) * (1 + 0.1 * rng.random()),
                                                  max_corr=min(corr + 0.02 * scale, 0.999), ok=True))
                    rows.append(common | dict(task_id=f"{man}-{noise}-{k}", noise=noise, realization=k, method=method,
                                              errors=errors, parameter="bias", estimate=1e-3 * rng.normal(),
                                              std_error=1e-3, truth_local=np.nan, truth_fit=np.nan, time_s=0.002,
                                              max_corr=corr, ok=True))
            for p in params:
                rows.append(common | dict(task_id=f"{man}-{noise}-0", noise=noise, realization=0, method="crb",
                                          errors="", parameter=p, estimate=np.nan,
                                          std_error=0.02 * abs(TRUTH.get(p, 1.0)) if noise != "none" else np.nan,
                                          truth_local=TRUTH.get(p, -1.0), truth_fit=np.nan, time_s=np.nan,
                                          max_corr=np.nan, ok=True))
            for p, v in (("max_dalpha_deg", 3.0 + mi), ("max_dbeta_deg", 0.01), ("max_dnz_g", 0.4), ("dV_fps", -2.0),
                         ("max_dV_fps", 5.0)):
                rows.append(common | dict(task_id=f"{man}-{noise}-0", noise=noise, realization=0, method="excursion",
                                          errors="", equation="", dependent="", parameter=p, estimate=v,
                                          std_error=np.nan, truth_local=np.nan, truth_fit=np.nan, time_s=np.nan,
                                          max_corr=np.nan, ok=True))
    return pd.DataFrame(rows)


def synthetic_flights(n_flights: int = 2, n: int = 500, dt: float = 0.02) -> pd.DataFrame:
    t = np.arange(n) * dt
    frames = []
    for i in range(n_flights):
        de = np.where((t > 1) & (t < 3), 1.0, 0.0) - np.where((t > 3) & (t < 5), 1.0, 0.0)
        data = {c: np.zeros(n) for c in FLIGHT_CHANNELS}
        data.update(de_deg=de - 2.0, alpha_deg=5 + np.convolve(de, np.ones(50) / 50, "same") * (i + 1),
                    q_dps=np.gradient(de) * 10, V_fps=420 - 0.01 * t, az_g=-1 + 0.1 * de)
        if i % 2:
            data["da_deg"] = np.sin(2 * np.pi * 0.5 * t) * (t < 4)
            data["beta_deg"] = 0.1 * data["da_deg"]
        frames.append(pd.DataFrame({"flight": f"flight-{i}", "maneuver": "2-1-1-2", "variant": "nominal",
                                    "loop": "open", "t_s": t, **data}))
    return pd.concat(frames, ignore_index=True)


def synthetic_modes(flights=("flight-0", "flight-1")) -> pd.DataFrame:
    rows = []
    for f in flights:
        rows += [dict(flight=f, mode="short period", frequency_hz=0.55, damping=0.45),
                 dict(flight=f, mode="dutch roll", frequency_hz=0.48, damping=0.1),
                 dict(flight=f, mode="roll", frequency_hz=0.0, damping=1.0, real=-3.0),
                 dict(flight=f, mode="spiral", frequency_hz=0.0, damping=1.0, real=-0.01)]
    return pd.DataFrame(rows)


def synthetic_examples(n: int = 1000, dt: float = 0.02) -> pd.DataFrame:
    rng = np.random.default_rng(1)
    t = np.arange(n) * dt
    frames = []
    for noise in ("white", "heavy"):
        fitted = 0.01 * np.sin(2 * np.pi * 0.4 * t)
        residual = 0.002 * np.sin(2 * np.pi * 0.3 * t) + 5e-4 * rng.normal(size=n)
        frames.append(pd.DataFrame({"flight": "f16/nominal/2-1-1-2/open", "noise": noise,
                                    "equation": "Cm = alpha + qhat + de", "dependent": "Cm", "t_s": t,
                                    "measured": fitted + residual, "fitted": fitted, "residual": residual}))
    return pd.concat(frames, ignore_index=True)


def synthetic_differentiation(n: int = 30) -> pd.DataFrame:
    rng = np.random.default_rng(2)
    return pd.DataFrame([{"method": m, "sequence": k, "rms_error_pct": 5 + m + rng.normal()}
                         for k in range(n) for m in (1, 2, 3)])


def synthetic_history(scores: pd.DataFrame, runs: int = 5) -> pd.DataFrame:
    frames = []
    for i in range(runs):
        s = scores.copy()
        s["coverage"] = (s["coverage"] - 0.02 * i).clip(0, 1)
        s.insert(0, "start", f"2025-01-{i + 1:02d}T02:00:00+00:00")
        s.insert(0, "run_id", f"run-{i}")
        frames.append(s)
    return pd.concat(frames, ignore_index=True)


@pytest.fixture(scope="module")
def tables() -> dict[str, pd.DataFrame]:
    from harness.scores import score
    results = synthetic_results()
    scores = score(results)
    return {"results": results, "scores": scores, "flights": synthetic_flights(), "modes": synthetic_modes(),
            "examples": synthetic_examples(), "differentiation": synthetic_differentiation(),
            "history": synthetic_history(scores)}


def calls(t: dict[str, pd.DataFrame]) -> dict[str, object]:
    return {
        "differentiation_error": lambda: F.fig_differentiation_error(t["differentiation"]),
        "bias": lambda: F.fig_bias(t["scores"]),
        "model_fit": lambda: F.fig_model_fit(t["examples"]),
        "residuals": lambda: F.fig_residuals(t["examples"]),
        "bias_vs_correlation": lambda: F.fig_bias_vs_correlation(t["scores"]),
        "coverage": lambda: F.fig_coverage(t["scores"]),
        "se_ratio": lambda: F.fig_se_ratio(t["scores"]),
        "efficiency": lambda: F.fig_efficiency(t["scores"]),
        "scatter": lambda: F.fig_scatter(t["results"], t["scores"]),
        "time_histories": lambda: F.fig_time_histories(t["flights"]),
        "input_spectra": lambda: F.fig_input_spectra(t["flights"], t["modes"]),
        "trend": lambda: F.fig_trend(t["history"]),
        "accuracy_vs_cost": lambda: F.fig_accuracy_vs_cost(t["scores"]),
        "excursions": lambda: F.fig_excursions(t["results"]),
    }


NAMES = ("differentiation_error", "bias", "model_fit", "residuals", "bias_vs_correlation", "coverage", "se_ratio",
         "efficiency", "scatter", "time_histories", "input_spectra", "trend", "accuracy_vs_cost", "excursions")


@pytest.fixture(scope="module")
def rendered(tables) -> dict[str, object]:
    """Every figure, drawn once for the module (drawing dominates the test time)."""
    return {name: make() for name, make in calls(tables).items()}


def check(out, name: str | None = None) -> np.ndarray:
    assert isinstance(out, F.FigureOut), out
    assert out.png[:4] == b"\x89PNG"
    img = mpimg.imread(io.BytesIO(out.png))
    assert img.shape[1] > 600 and img.shape[0] > 250
    assert out.caption.strip() and out.alt.strip()
    if name:
        assert out.name == name
    return img


@pytest.mark.parametrize("name", NAMES)
def test_every_figure_renders(rendered, name):
    img = check(rendered[name], name)
    assert 0.9 * 9 * 110 < img.shape[1] < 11 * 110  # ~9-10 in at 110 dpi


@pytest.mark.parametrize("name", NAMES)
def test_every_figure_is_none_without_data(name):
    empty = {k: pd.DataFrame() for k in ("results", "scores", "flights", "modes", "examples", "differentiation",
                                          "history")}
    assert calls(empty)[name]() is None
    nothing = {k: None for k in empty}
    assert calls(nothing)[name]() is None


def test_figure_out_is_frozen_and_png_helper_works(rendered):
    from matplotlib.figure import Figure
    with pytest.raises(dataclasses.FrozenInstanceError):
        rendered["bias"].name = "x"  # type: ignore[misc]
    fig = Figure(figsize=(6, 3))
    fig.subplots().plot([0, 1], [1, 0])
    png = F.figure_to_png(fig)
    assert png[:4] == b"\x89PNG" and mpimg.imread(io.BytesIO(png)).shape[1] == 660


def test_captions_name_what_the_data_show(rendered):
    assert "ee-time is the farthest from zero" in rendered["bias"].caption
    assert "Method 3 is the least accurate" in rendered["differentiation_error"].caption
    spectra = rendered["input_spectra"].caption
    assert "short period 0.55 Hz" in spectra and "dutch roll 0.48 Hz" in spectra
    assert "roll 0.48 Hz" in spectra and "spiral 0.0016 Hz" in spectra  # real modes: |λ|/2π
    assert "Lowest median coverage: ee-time (conventional)" in rendered["coverage"].caption
    assert "Most optimistic: ee-time (conventional)" in rendered["se_ratio"].caption
    assert "largest bias is ee-time" in rendered["bias_vs_correlation"].caption
    assert "colored, not white" in rendered["residuals"].caption
    assert "fastest: ee-" in rendered["accuracy_vs_cost"].caption
    assert "(2-1-1-2)" not in rendered["excursions"].caption and "(doublet)" in rendered["excursions"].caption


def test_awkward_data_single_method_single_realization_and_nans():
    from harness.scores import score
    res = synthetic_results(n_real=1, noises=("white",), maneuvers=("doublet",), methods=(("ee-freq", "conventional"),))
    res.loc[res.index[:1], "estimate"] = np.nan
    s = score(res)
    for out in (F.fig_bias(s), F.fig_scatter(res, s), F.fig_bias_vs_correlation(s)):
        check(out)
    assert F.fig_se_ratio(s) is None  # one realization: no empirical scatter
    assert F.fig_efficiency(s) is None
    assert F.fig_bias(s.assign(bias_pct=np.nan)) is None
    assert F.fig_scatter(res.assign(ok=False), s) is None


def test_many_parameters_and_panels_are_limited_and_said():
    from harness.scores import score
    params = tuple(f"Cm_x{i}" for i in range(40))
    res = synthetic_results(n_real=3, noises=("none", "white", "heavy", "realistic"),
                            maneuvers=("2-1-1-2", "doublet"), methods=(("ee-time", "conventional"),), params=params)
    s = score(res)
    out = F.fig_bias(s)
    img = check(out)
    assert "first 24 of 40 parameters" in out.caption and "first 6 of 8 panels" in out.caption
    assert img.shape[0] <= 14 * 110 + 2
    assert F.fig_scatter(res, s, parameter="nope") is None
    assert F.fig_bias_vs_correlation(s, parameter="nope") is None


def test_many_methods_are_limited_and_said(tables):
    s = tables["scores"]
    many = pd.concat([s.assign(method=s["method"] + f"-{i}") for i in range(4)], ignore_index=True)
    assert "Only the first 10 of 16 methods" in check_caption(F.fig_accuracy_vs_cost(many))


def check_caption(out) -> str:
    check(out)
    return out.caption


def test_figure_options(tables):
    ex = tables["examples"]
    assert "'heavy'" in check_caption(F.fig_model_fit(ex, noise="heavy"))
    assert F.fig_model_fit(ex, flight="missing") is None
    assert F.fig_residuals(ex, equation="missing") is None
    assert "3 runs" in check_caption(F.fig_trend(tables["history"], nights=3))
    many = pd.concat([tables["flights"].assign(flight=lambda d, i=i: d["flight"] + f"-{i}") for i in range(4)])
    assert "first 6 of 8 flights" in check_caption(F.fig_time_histories(many))
    assert "No mode frequencies" in check_caption(F.fig_input_spectra(tables["flights"], None))


def test_figures_are_thread_safe_and_deterministic(tables, rendered):
    outs: list = [None] * 2

    def work(i: int) -> None:
        outs[i] = F.fig_accuracy_vs_cost(tables["scores"]).png

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert outs[0] == outs[1] == rendered["accuracy_vs_cost"].png


def test_all_figures_collects_what_the_tables_allow(tables):
    assert F.all_figures() == []
    outs = F.all_figures(differentiation=tables["differentiation"], scores=pd.DataFrame())
    assert [o.name for o in outs] == ["differentiation_error"]
