"""A sweep of the discrepancy diagnosis over every effect id of ``../shared/effects.md``, at
several sizes, surfaces and maneuvers, scored against the bar outside evaluators apply:

a. the right effect is named first (``none`` on a null recording);
b. its size lies within 2 reported standard errors or 25 % of the truth;
c. nothing is named on a null recording;
d. the validation maneuver's RMS error in the affected output drops by at least 30 %.

Each case is an F-16 recording made like the gallery's (``realistic`` noise, an
identification and a different validation maneuver). One JSON result per case is written
as it finishes, so an interrupted sweep resumes; ``sweep.md`` and ``sweep.json`` summarise.
"""
from __future__ import annotations

import json
import math
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

from harness.atomic import write_text_atomic
from harness.diagnosis.gallery import (GalleryCase, StructuralMode, identification_input, validation_input,
                                       write_case)
from harness.diagnosis.refine import validation_rms_pair
from harness.diagnosis.run import diagnose
from harness.noise_presets import preset
from maneuvers.combine import Sequence, Simultaneous
from maneuvers.multistep import MultiStep, multistep
from models.atmosphere import Turbulence
from models.hidden import HiddenEffect as H

DEG = math.pi / 180.0
BAR_DROP = 0.30


def phugoid_inputs() -> tuple[Sequence, Sequence]:
    """The gallery's inputs after a 3 s, 0.5° stabilator pulse that sets the airspeed moving."""
    lead = MultiStep("de", (3.0,), (1,), 1.0, 0.5)
    return (Sequence((lead, multistep("3-2-1-1", "de", 2.0, 0.5), multistep("doublet", "da", 3.0, 1.0),
                      multistep("2-1-1", "dr", 3.0, 1.0)), gap_s=2.0, name="phugoid_identification"),
            Sequence((MultiStep("de", (3.0,), (-1,), 1.0, 0.5), multistep("2-1-1-2", "de", 1.5, 0.7),
                      multistep("doublet", "dr", 3.0, 1.0), multistep("2-1-1", "da", 3.0, 0.7)), gap_s=2.0,
                     name="phugoid_validation"))


def coupled_inputs() -> tuple[Sequence, Sequence]:
    """The gallery's inputs with a rudder (validation: aileron) doublet flown while a 5 s
    stabilator pulse holds α off trim: α and β excited together, for α·β terms."""
    held = MultiStep("de", (5.0,), (-1,), 1.0, 1.5, start_s=0.5)
    return (Sequence((multistep("3-2-1-1", "de", 2.0, 0.5), multistep("doublet", "da", 3.0, 1.0),
                      Simultaneous((held, MultiStep("dr", (1.0, 1.0), (1, -1), 1.0, 4.0, start_s=2.0,
                                                    quiet_after_s=2.5))),
                      multistep("2-1-1", "dr", 3.0, 1.0)), gap_s=2.0, name="coupled_identification"),
            Sequence((multistep("2-1-1-2", "de", 1.5, 0.7),
                      Simultaneous((held, MultiStep("da", (1.0, 1.0), (1, -1), 1.0, 4.0, start_s=2.0,
                                                    quiet_after_s=2.5))),
                      multistep("doublet", "dr", 3.0, 1.0)), gap_s=2.0, name="coupled_validation"))


INPUTS = {"gallery": lambda: (identification_input(), validation_input()), "phugoid": phugoid_inputs,
          "coupled": coupled_inputs}


@dataclass(frozen=True)
class SweepCase:
    """One recording of the sweep and what the diagnosis must say of it."""

    name: str
    effects: tuple = ()
    expect: str = "none"        # the effect id to be named first
    parameter: str = ""         # and its parameter
    truth: float = 0.0          # its size (a coefficient error: the change)
    channel: str = ""           # the affected output (condition d)
    inputs: str = "gallery"
    seed: int = 1
    turbulence: Turbulence | None = None
    mode: StructuralMode | None = None


def _c(name, effect, expect, parameter, truth, channel, **kw) -> SweepCase:
    return SweepCase(name, (effect,) if effect else (), expect, parameter, truth, channel, **kw)


def cases() -> tuple[SweepCase, ...]:
    """The sweep: every effect id, sizes from marginal to clear, and null recordings."""
    out = []
    for coef, reg, size, ch in (("Cm", "qhat", -3.0, "q"), ("Cm", "qhat", -6.0, "q"), ("Cm", "alpha", -0.1, "q"),
                                ("Cl", "beta", -0.02, "p"), ("Cn", "beta", 0.03, "r"), ("Cn", "rhat", -0.1, "r"),
                                ("Cn", "rhat", -0.3, "r"), ("CZ", "alpha", -0.5, "az")):
        out.append(_c(f"coef_{coef}_{reg}{size:+g}", H("coefficient_error", size, coefficient=coef, regressor=reg),
                      "coefficient_error", f"{coef}_{reg}", size, ch))
    out.append(_c("coef_Cn_rhat-0.3_coupled", H("coefficient_error", -0.3, coefficient="Cn", regressor="rhat"),
                  "coefficient_error", "Cn_rhat", -0.3, "r", inputs="coupled"))
    out.append(_c("unsteady_alphadot_Cm-3", H("unsteady_alphadot", -3.0), "unsteady_alphadot", "Cm_alphadot", -3.0,
                  "q"))
    for s, tau, ch in (("de", 0.08, "q"), ("da", 0.06, "p"), ("dr", 0.08, "r")):
        out.append(_c(f"delay_{s}_{tau:g}", H("control_delay", tau, surface=s), "control_delay", f"tau_{s}", tau, ch))
    out.append(_c("delay_de_0.08_s3", H("control_delay", 0.08, surface="de"), "control_delay", "tau_de", 0.08, "q",
                  seed=3))
    out.append(_c("nonlin_Cm_a2_1", H("nonlinear_alpha", 1.0), "nonlinear_alpha", "Cm_alpha2", 1.0, "q"))
    out.append(_c("nonlin_Cm_a2_1_s4", H("nonlinear_alpha", 1.0), "nonlinear_alpha", "Cm_alpha2", 1.0, "q", seed=4))
    out.append(_c("nonlin_CZ_a2_-5", H("nonlinear_alpha", -5.0, coefficient="CZ"), "nonlinear_alpha", "CZ_alpha2",
                  -5.0, "az"))
    for coef, size, ch in (("Cl", -0.5, "p"), ("Cl", -2.0, "p"), ("Cn", 0.5, "r"), ("Cn", 2.0, "r")):
        out.append(_c(f"cross_{coef}_ab_{size:g}", H("cross_coupling", size, coefficient=coef), "cross_coupling",
                      f"{coef}_alpha_beta", size, ch))
    for coef, size, ch in (("Cl", -0.5, "p"), ("Cn", 0.5, "r")):
        out.append(_c(f"cross_{coef}_ab_{size:g}_coupled", H("cross_coupling", size, coefficient=coef),
                      "cross_coupling", f"{coef}_alpha_beta", size, ch, inputs="coupled"))
    for chan, size, label in (("alpha", 0.75 * DEG, "0.75deg"), ("alpha", 1.5 * DEG, "1.5deg"),
                              ("beta", 0.5 * DEG, "0.5deg"), ("beta", 1.0 * DEG, "1deg"), ("q", 0.5 * DEG, "0.5dps"),
                              ("az", 0.02, "0.02g"), ("az", 0.04, "0.04g"), ("V", 4.0, "4fps"), ("V", 10.0, "10fps")):
        out.append(_c(f"bias_{chan}_{label}", H("sensor_bias", size, channel=chan), "sensor_bias", f"bias_{chan}",
                      size, chan))
    for chan, size in (("alpha", 0.08), ("beta", 0.08), ("beta", 0.15), ("V", 0.03), ("V", 0.06)):
        out.append(_c(f"scale_{chan}_{size:g}", H("sensor_scale", size, channel=chan), "sensor_scale",
                      f"scale_{chan}", size, chan))
    for pos in ((10.0, 0.0, 0.0), (5.0, 0.0, 0.0), (5.0, 0.0, -2.0)):
        out.append(_c(f"offset_acc_x{pos[0]:g}" + (f"_z{pos[2]:g}" if pos[2] else ""),
                      H("sensor_offset", pos[0], position_ft=pos), "sensor_offset", "x_accelerometer", pos[0], "az"))
    for y in (3.0, 6.0):
        out.append(_c(f"offset_acc_y{y:g}", H("sensor_offset", 0.0, position_ft=(0.0, y, 0.0)), "sensor_offset",
                      "offset_y", y, "az"))  # a lateral offset moves a_z most: ṗ·y (a_y only by (p² + r²)·y)
    for chan, tau in (("alpha", 0.04), ("alpha", 0.08), ("q", 0.04), ("az", 0.04), ("az", 0.08)):
        out.append(_c(f"skew_{chan}_{tau:g}", H("sensor_time_skew", tau, channel=chan), "sensor_time_skew",
                      f"skew_{chan}", tau, chan))
    for coef, size, ch, inputs in (("Cm", 0.02, "q", "gallery"), ("Cm", 0.02, "q", "phugoid"),
                                   ("CX", -0.05, "V", "phugoid")):
        out.append(_c(f"drift_{coef}_dV_{size:g}_{inputs}", H("flight_condition_drift", size, coefficient=coef),
                      "flight_condition_drift", f"{coef}_dV", size, ch, inputs=inputs))
    for size, seed in ((0.5, 1), (1.0, 1), (1.0, 2), (1.5, 1)):
        out.append(_c(f"cg_{size:g}ft_s{seed}", H("cg_offset", size), "cg_offset", "dx_moment_reference", size, "q",
                      seed=seed))
    for label, mode in (("8Hz", StructuralMode(8.0, 0.02, 0.5, 3.0)), ("8Hz_small", StructuralMode(8.0, 0.03, 0.15, 1.0)),
                        ("9Hz_small", StructuralMode(9.0, 0.04, 0.06, 0.4))):
        out.append(_c(f"struct_{label}", None, "structural_mode", "mode_frequency_hz", mode.frequency_hz, "q",
                      mode=mode))
    for label, turb in (("moderate", Turbulence("dryden", 3, 30.0)), ("severe4", Turbulence("dryden", 4, 30.0))):
        out.append(_c(f"turbulence_{label}", None, "turbulence", "sigma_gust_fps", float("nan"), "", turbulence=turb))
    for seed in range(1, 9):
        out.append(SweepCase(f"none_s{seed}", seed=seed))
    out += [SweepCase("none_phugoid_s1", inputs="phugoid"), SweepCase("none_phugoid_s2", inputs="phugoid", seed=2),
            SweepCase("none_coupled_s1", inputs="coupled")]
    return tuple(out)


def score(c: SweepCase, result: dict) -> dict:
    """Conditions a-d for one case from its findings.json content (None: not applicable)."""
    first = result["findings"][0]
    row = {"case": c.name, "expect": c.expect, "parameter": c.parameter,
           "truth": c.truth if math.isfinite(c.truth) else None,
           "first": {k: first.get(k) for k in ("effect", "parameter", "estimate", "std_error")},
           "also": [f["parameter"] for f in result["findings"][1:]]}
    if c.expect == "none":
        row.update(a=first["effect"] == "none", b=None, c=first["effect"] == "none", d=None)
        return row
    if c.expect == "sensor_bias" and math.isfinite(c.truth):
        row["truth"] = recorded_bias(c)
        row["hidden"] = c.truth
    row["a"] = first["effect"] == c.expect and first["parameter"] == c.parameter
    row["b"] = size_right(first, c.expect, row["truth"] if row["truth"] is not None else c.truth, row["a"])
    row["c"] = None
    row["d"], rms = validation_drop(first, c.channel, row["a"])
    if rms is not None:
        row["validation_rms"] = rms
    return row


def recorded_bias(c: SweepCase) -> float:
    """The bias the recording's instrument has: the concealed one plus the ``realistic`` noise
    layer's own constant bias on that channel (:data:`harness.noise_presets.BIASES`, e.g.
    0.005 g on a_z), which the kinematics see just the same."""
    layer = preset("realistic").channel_map.get(c.channel)
    return c.truth + (layer.bias if layer is not None else 0.0)


def size_right(first: dict, expect: str, truth: float, named: bool) -> bool | None:
    """Criterion b: the first finding, when it is the right one (``named``), has its size
    within 2 standard errors or 25 % of the truth (a coefficient error by its change);
    None when the truth has no size."""
    if not math.isfinite(truth):
        return None
    estimate = first["evidence"].get("change", first["estimate"]) if expect == "coefficient_error" \
        else first["estimate"]
    err = abs(estimate - truth)
    return bool(named and (err <= 2.0 * first["std_error"] or err <= 0.25 * abs(truth)))


def validation_drop(first: dict, channel: str | None, named: bool) -> tuple[bool | None, list | None]:
    """Criterion d: the validation RMS of the affected ``channel`` drops by at least
    :data:`BAR_DROP` with the augmented model the diagnosis reports (its calibrated sizes when
    it kept them), for the right finding; with the (before, after) RMS pair. None when no
    channel is scored."""
    if not channel:
        return None, None
    if "validation" not in first.get("fit_before", {}) or first["effect"] == "none":
        return False, None
    # a structural mode's fit is judged against the smoothed record with the mode's band put
    # back (mode_model.with_mode_band), as the diagnosis reports it
    before = first["fit_before"]["validation"]["outputs"].get(channel, {}).get("rms")
    after = first["fit_after"]["validation"].get("outputs", {}).get(channel, {}).get("rms")
    if not before or after is None:
        return False, None
    return bool(named and 1.0 - after / before >= BAR_DROP), [before, after]


def run_case(c: SweepCase, out: Path) -> dict:
    """Make, diagnose and score one case; its row is written to ``out/results/<case>.json``."""
    paths = write_case(GalleryCase(c.name, c.effects, c.parameter, c.truth, c.turbulence, c.mode),
                       out / "recordings", c.seed, INPUTS[c.inputs]())
    # the sweep's own processes are the parallelism: the calibration flies in-process
    result = diagnose("f16", paths["identification"], out / "diagnoses" / c.name, paths["validation"],
                      calibrate_workers=1)
    row = score(c, result) | {"seed": c.seed, "inputs": c.inputs, "timing_s": result["timing_s"]["total"],
                              "calibration": validation_rms_pair(result.get("calibration") or {}, c.channel)}
    write_text_atomic(out / "results" / f"{c.name}.json", json.dumps(row, indent=1))
    return row


def passes(row: dict) -> bool:
    return all(row[k] is not False for k in "abcd") and bool(row["a"])


def markdown(rows: list[dict]) -> str:
    """The sweep table and its summary line."""
    mark = {True: "✔", False: "✘", None: "–"}
    lines = ["| case | truth | first finding | a | b | c | d | validation RMS |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        f = r["first"]
        finding = f["effect"] if f["effect"] == "none" else \
            f"{f['effect']}: {f['parameter']} = {f['estimate']:.4g} ± {f['std_error']:.2g}"
        v = r.get("validation_rms")
        drop = f"{v[0]:.3g} → {v[1]:.3g} ({100 * (v[1] / v[0] - 1):+.0f} %)" if v else "–"
        truth = "–" if r["truth"] is None else f"{r['truth']:.4g}"
        lines.append(f"| {r['case']} | {truth} | {finding} | " + " | ".join(mark[r[k]] for k in "abcd")
                     + f" | {drop} |")
    nulls = [r for r in rows if r["expect"] == "none"]
    lines.append("")
    lines.append(f"{sum(passes(r) for r in rows)} of {len(rows)} cases meet every condition; "
                 f"{sum(bool(r['a']) for r in rows if r['expect'] != 'none')} of {len(rows) - len(nulls)} effects are "
                 f"named first; {sum(bool(r['c']) for r in nulls)} of {len(nulls)} null recordings give none.")
    return "\n".join(lines) + "\n"


def run_resumable(all_cases, names: list[str] | None, out: Path, workers: int, run, what: str):
    """Select ``all_cases`` by name (all when ``names`` is None), run those without a result
    file under ``out/results`` in a process pool (``run(case, out)`` writes it) and read every
    chosen case's result back. Returns ``(chosen, rows)``; a rerun resumes."""
    chosen = [c for c in all_cases if names is None or c.name in names]
    if names is not None and len(chosen) != len(set(names)):
        known = {c.name for c in all_cases}
        raise ValueError(f"no {what} case {sorted(set(names) - known)}")
    todo = [c for c in chosen if not (out / "results" / f"{c.name}.json").is_file()]
    if todo:
        with ProcessPoolExecutor(max_workers=max(1, workers)) as pool:
            for c, row in zip(todo, pool.map(run, todo, [out] * len(todo))):
                error = row.get("error") if isinstance(row, dict) else None
                print(f"{c.name}: {'error: ' + error if error else 'done'}", flush=True)
    return chosen, [json.loads((out / "results" / f"{c.name}.json").read_text()) for c in chosen]


def sweep(out: str | Path, names: list[str] | None = None, workers: int = 2) -> list[dict]:
    """Run the sweep (the cases ``names``, default all) into ``out``; finished cases are read
    back, not run again."""
    out = Path(out)
    chosen, rows = run_resumable(cases(), names, out, workers, run_case, "sweep")
    write_text_atomic(out / "sweep.json", json.dumps({"cases": [asdict(c) | {"effects": [e.describe() for e in
                                                                                          c.effects]}
                                                                for c in chosen], "rows": rows}, indent=1,
                                                     default=str))
    write_text_atomic(out / "sweep.md", markdown(rows))
    return rows
