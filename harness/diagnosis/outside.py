"""The outside sweep: the discrepancy diagnosis scored on recordings made the way a flight-test
team's data arrive, at flight conditions and on an aircraft the project did not tune it on.

Each case flies one aircraft (the F-16, or the JSBSim package's ``c172x`` given by the path of
its XML; the 737 in a self-check) at a condition given by value, with at most one concealed
effect (``models.hidden``), and post-processes the flight as instruments would record it:

- **Actuators.** Each commanded surface passes through a second-order actuator
  (ω = 40 rad/s, ζ = 0.7, zero-order-hold exact on the simulation frames) *before* it is
  flown, so the aircraft flies the actuator output and the recording holds the measured
  actuator position (plus 0.05° white noise), not the command. (At the closed-loop
  conditions the project's pitch-rate feedback adds to the actuator output.)
- **Gyros measure inertial rates**: p, q, r = JSBSim's Earth-relative body rates plus the
  Earth's rotation in body axes, C_bn·ω_e (from the true attitude and the trim latitude).
- **Air data**: white plus first-order Gauss-Markov noise on α and β (0.1° each, τ = 1 s);
  the ``white`` preset's levels on every other channel; the angular accelerations dropped.
- **Values rounded to 8 significant digits**, as a telemetry export prints them; no altitude
  channel in some cases, no thrust channel in others; metadata a team would write (geometry,
  mass, a trim block of α, V and h from the first second), no simulation details.

Maneuvers: pitch-only (stabilator 3-2-1-1; validation 2-1-1-2), lateral-only (aileron doublet
and rudder 2-1-1; validation rudder doublet and aileron 2-1-1) and three-axis (both), with
null recordings of each kind on each aircraft, and noise-free self-checks (a clean recording
of the model itself: no noise, no actuator, no rounding) of the F-16, the 737 and the c172x.

Scoring (per case, and totals): (a) the right effect *and parameter* first; (b) its size
within 2 standard errors or 25 %; (c) false findings: every finding other than the true one
(on a null, every finding but ``none``); (d) the validation RMS of the affected output drops
by 30 % or more (turbulence excepted; a structural mode's against the smoothed record with
the mode's band put back, as the diagnosis reports it).
"""
from __future__ import annotations

import json
import math
import traceback
from dataclasses import asdict, replace
from pathlib import Path

from harness.atomic import write_text_atomic
from harness.diagnosis.outside_cases import CONDITIONS, OutsideCase, cases, maneuvers
from harness.diagnosis.outside_recording import (OTHER_UNITS, Actuated, accelerometer_away, flight_test_noise,
                                                 postprocess, rewrite_in_units, vanes_ahead, with_sensors)
from harness.diagnosis.refine import validation_rms_pair
from harness.diagnosis.sweep import run_resumable, size_right, validation_drop
from harness.recording_io import write_recording
from maneuvers.fly import FlightSpec, fly_maneuver
from models.aircraft import Aircraft


def write_case(c: OutsideCase, out_dir: str | Path) -> dict[str, Path]:
    """Fly and post-process one case's identification and validation recordings; write them
    and ``<case>.answer.json`` into ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cond = c.condition
    label = {"f16": "F-16", "737": "Boeing 737", "c172x": "Cessna 172 (JSBSim c172x)",
             "dhc6": "DHC-6 Twin Otter"}.get(cond.aircraft, cond.aircraft)
    paths, answers = {}, {}
    cv = c.convention
    noise = flight_test_noise(cv.white_scale, cv.gauss_markov_deg, cv.gauss_markov_tau_s)
    for i, (role, inp) in enumerate(zip(("identification", "validation"), maneuvers(c.kind, cond, cv.inputs))):
        flown = inp if c.clean else Actuated(inp, omega_rps=cv.actuator_rps)
        spec = FlightSpec(input=flown, aircraft=Aircraft(cond.model, hidden=c.effects), condition=cond.condition,
                          duration_s=max(cv.duration_s, inp.duration_s), loop=cond.loop, sample_rate_hz=cv.rate_hz)
        if c.turbulence is not None:
            spec = replace(spec, turbulence=c.turbulence, turbulence_seed=100 * c.seed + i)
        flight = fly_maneuver(spec)
        if cv.vanes_ft:
            flight = vanes_ahead(flight, cv.vanes_ft)
        if any(cv.accelerometer_ft):
            flight = accelerometer_away(flight, cv.accelerometer_ft)
        rec, answer = postprocess(flight, noise=not c.clean, seed=1000 * c.seed + i, drop=c.drop,
                                  mode=c.mode, aircraft_label=label, noise_model=noise)
        if cv.vanes_ft:  # the team knows where its nose boom is
            rec = with_sensors(rec, alpha_vane_ft=[cv.vanes_ft, 0.0, 0.0], beta_vane_ft=[cv.vanes_ft, 0.0, 0.0])
        if any(cv.accelerometer_ft):  # and where its accelerometer is
            rec = with_sensors(rec, accelerometer_ft=list(cv.accelerometer_ft))
        paths[role] = write_recording(rec, out_dir / f"{c.name}-{role}.csv")
        if cv.units != "canonical":  # the writer writes canonical units only; the reader takes these
            rewrite_in_units(paths[role], OTHER_UNITS)
        answers[role] = answer["hidden_effects"]
    write_text_atomic(out_dir / f"{c.name}.answer.json", json.dumps(
        {"case": c.name, "aircraft": cond.aircraft, "condition": cond.condition, "loop": cond.loop.describe(),
         "kind": c.kind, "expect": c.expect, "parameter": c.parameter,
         "truth": c.truth if math.isfinite(c.truth) else None, "hidden_effects": answers["identification"],
         "turbulence": None if c.turbulence is None else c.turbulence.describe(),
         "structural_mode": None if c.mode is None else asdict(c.mode), "dropped": list(c.drop),
         "recording": "clean (self-check)" if c.clean else "flight-test-like",
         "convention": asdict(cv)}, indent=1))
    return paths


# Names the diagnosis gives the same parameter: the accelerometer's x position from the
# force-mismatch fit (x_accelerometer) or from the kinematic check (offset_x).
ALIASES = {("sensor_offset", "offset_x"): ("sensor_offset", "x_accelerometer")}


def _key(f: dict) -> tuple[str, str]:
    key = (f.get("effect"), f.get("parameter"))
    return ALIASES.get(key, key)


def score(c: OutsideCase, result: dict) -> dict:
    """Criteria a-d and the false findings of one case from its findings.json content."""
    findings = result["findings"]
    first = findings[0]
    row = {"case": c.name, "aircraft": c.condition.aircraft, "where": c.where, "condition": c.condition.condition,
           "kind": c.kind, "expect": c.expect, "parameter": c.parameter,
           "truth": c.truth if math.isfinite(c.truth) else None, "dropped": list(c.drop), "self_check": c.self_check,
           "convention": c.convention.describe(),
           "first": {k: first.get(k) for k in ("effect", "parameter", "estimate", "std_error")},
           "findings": [{k: f.get(k) for k in ("effect", "parameter", "estimate", "std_error")} for f in findings]}
    if c.expect == "none":
        false = [f for f in findings if f["effect"] != "none"]
        row.update(a=first["effect"] == "none", b=None, d=None)
    else:
        # a ``none`` on an effect is a miss (criterion a), not a false finding
        false = [f for f in findings if f["effect"] != "none" and _key(f) != (c.expect, c.parameter)]
        row["a"] = _key(first) == (c.expect, c.parameter)
        row["b"] = size_right(first, c.expect, c.truth, row["a"])
        row["d"], rms = validation_drop(first, c.channel, row["a"])
        if rms is not None:
            row["validation_rms"] = rms
    # the calibration step's column: the affected output's validation RMS after the
    # equation-error and after the calibrated sizes, and which the diagnosis kept
    row["calibration"] = validation_rms_pair(result.get("calibration") or {}, c.channel)
    row["false"] = [f"{f['effect']}:{f['parameter']}" for f in false]
    row["c"] = len(false)
    return row


def run_case(c: OutsideCase, out: Path) -> dict:
    """Make, diagnose and score one case; its row goes to ``out/results/<case>.json``. A case
    whose recording or diagnosis fails is scored as failing every criterion, with the error."""
    from harness.diagnosis.run import diagnose
    try:
        paths = write_case(c, out / "recordings")
        # the sweep's own processes are the parallelism: the calibration flies in-process
        result = diagnose(c.condition.model, paths["identification"], out / "diagnoses" / c.name,
                          paths["validation"], calibrate_workers=1)
        row = score(c, result) | {"timing_s": result["timing_s"]["total"], "error": None}
    except Exception as exc:  # noqa: BLE001 - a measurement: the row says what broke
        row = {"case": c.name, "aircraft": c.condition.aircraft, "where": c.where, "condition": c.condition.condition,
               "kind": c.kind, "expect": c.expect, "parameter": c.parameter,
               "truth": c.truth if math.isfinite(c.truth) else None, "dropped": list(c.drop),
               "convention": c.convention.describe(), "self_check": c.self_check, "first": None, "findings": [],
               "a": False,
               "b": False if c.expect != "none" and math.isfinite(c.truth) else None, "c": 0, "false": [],
               "d": False if c.channel else None, "timing_s": None,
               "error": f"{type(exc).__name__}: {exc}".splitlines()[0][:300],
               "traceback": traceback.format_exc()[-2000:]}
    write_text_atomic(out / "results" / f"{c.name}.json", json.dumps(row, indent=1))
    return row


# ---------------------------------------------------------------------------------------------
# Summary


def _share(rows: list[dict], k: str) -> str:
    scored = [r for r in rows if r[k] is not None]
    return f"{sum(bool(r[k]) for r in scored)}/{len(scored)}" if scored else "–"


def totals(rows: list[dict]) -> dict:
    """a, b, d as passed/scored; c as the number of false findings and of cases with any."""
    return {"cases": len(rows), "a": _share(rows, "a"), "b": _share(rows, "b"), "d": _share(rows, "d"),
            "false_findings": sum(r["c"] for r in rows), "cases_with_false": sum(r["c"] > 0 for r in rows),
            "errors": sum(bool(r.get("error")) for r in rows)}


def groups(rows: list[dict]) -> dict[str, dict[str, dict]]:
    by = {"aircraft": lambda r: r["aircraft"], "condition": lambda r: f"{r['aircraft']} {r['condition']}",
          "kind": lambda r: r["kind"], "truth": lambda r: "null" if r["expect"] == "none" else "effect",
          "recording": lambda r: "other conventions" if r.get("convention") else "usual"}
    out = {}
    for name, key in by.items():
        keys = list(dict.fromkeys(key(r) for r in rows))
        out[name] = {k: totals([r for r in rows if key(r) == k]) for k in keys}
    return out


def _finding(f: dict | None) -> str:
    if f is None:
        return "error"
    if f["effect"] == "none":
        return "none"
    return f"{f['effect']}: {f['parameter']} = {f['estimate']:.4g} ± {f['std_error']:.2g}"


def markdown(rows: list[dict]) -> str:
    """The per-case table (a, b, c = false findings, d), the totals and the breakdowns."""
    mark = {True: "✔", False: "✘", None: "–"}
    lines = ["| case | aircraft, condition | truth | first finding | a | b | c (false) | d | validation RMS |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        v = r.get("validation_rms")
        drop = f"{v[0]:.3g} → {v[1]:.3g} ({100 * (v[1] / v[0] - 1):+.0f} %)" if v else "–"
        truth = "–" if r["truth"] is None else f"{r['truth']:.4g}"
        first = f"error: {r['error']}" if r.get("error") else _finding(r["first"])
        false = str(r["c"]) + (f" ({', '.join(r['false'])})" if r["false"] else "")
        where = (f"{r['aircraft']} {r['condition']}" + (f", no {'/'.join(r['dropped'])}" if r["dropped"] else "")
                 + (f", {r['convention']}" if r.get("convention") else ""))
        lines.append(f"| {r['case']} | {where} | {truth} | {first} | {mark[r['a']]} | {mark[r['b']]} | {false} | "
                     f"{mark[r['d']]} | {drop} |")
    t = totals(rows)
    lines += ["", f"**Totals** ({t['cases']} cases): a {t['a']}, b {t['b']}, d {t['d']}; **false findings "
                  f"{t['false_findings']}** in {t['cases_with_false']} cases (target 0); errors {t['errors']}.", ""]
    lines += ["| group | cases | a | b | false findings (cases) | d |", "|---|---|---|---|---|---|"]
    for name, gs in groups(rows).items():
        for k, g in gs.items():
            lines.append(f"| {name}: {k} | {g['cases']} | {g['a']} | {g['b']} | {g['false_findings']} "
                         f"({g['cases_with_false']}) | {g['d']} |")
    by_effect: dict[str, int] = {}
    for r in rows:
        for f in r["false"]:
            by_effect[f.split(":")[0]] = by_effect.get(f.split(":")[0], 0) + 1
    if by_effect:
        lines += ["", "False findings by effect named: " + ", ".join(
            f"{k} {v}" for k, v in sorted(by_effect.items(), key=lambda kv: -kv[1])) + "."]
    return "\n".join(lines) + "\n"


def provenance() -> dict:
    """The commit the sweep ran on and the files changed since (diagnosis work in progress shows)."""
    import subprocess
    root = Path(__file__).resolve().parents[2]

    def git(*args: str) -> str:
        try:
            return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=10).stdout
        except (OSError, subprocess.SubprocessError):
            return ""
    return {"commit": git("rev-parse", "HEAD").strip(),
            "modified": [line[3:] for line in git("status", "--porcelain", "--untracked-files=no").splitlines()]}


def sweep(out: str | Path, names: list[str] | None = None, workers: int = 2) -> list[dict]:
    """Run the outside sweep (the cases ``names``, default all) into ``out``; finished cases
    are read back, not run again."""
    out = Path(out)
    chosen, rows = run_resumable(cases(), names, out, workers, run_case, "outside-sweep")
    write_text_atomic(out / "sweep.json", json.dumps(
        {"cases": [asdict(c) | {"effects": [e.describe() for e in c.effects]} for c in chosen],
         "conditions": {k: asdict(v) for k, v in CONDITIONS.items()}, "provenance": provenance(), "rows": rows,
         "totals": totals(rows),
         "groups": groups(rows)}, indent=1, default=str))
    write_text_atomic(out / "sweep.md", markdown(rows))
    return rows
