"""The whole diagnosis of one recording (and its validation maneuver) against a model, and
its output folder: findings.json, series/*.parquet, model/ (the augmented JSBSim aircraft)."""
from __future__ import annotations

import contextlib
import json
import time
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import numpy as np

from harness.atomic import jsonable, write_atomic, write_text_atomic
from harness.diagnosis.analysis import analyse
from harness.diagnosis.along import model_along
from harness.diagnosis.augmented import (analysed, calibration_assumptions, fly_all, refine_in_the_loop, replay_before,
                                         sensor_models, terms_of, unsupported_in_the_loop, with_calibration,
                                         recording_start_references, write_model)
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.fcs_surfaces import choose_secondary_surfaces
from harness.diagnosis.limits import detection_limits
from harness.diagnosis.mode_model import (attach_mode_models, withhold_sensor_errors_a_mode_makes,
                                          withhold_sensor_errors_a_peak_makes, withhold_terms_a_mode_makes)
from harness.diagnosis.prepare import instruments_at_cg, prepare
from harness.diagnosis.reference_point import choose_reference_point, withhold_shift_between_placements
from harness.diagnosis.replication import lift_unreplicated_suspicions, name_mode_on_both, name_replicated
from harness.diagnosis.validation import after_mismatch, undecided, validation_check
from harness.diagnosis.verdict import (DiagnosisError, assumptions, check_model_represents, check_time_base,
                                       chosen_findings, excited_axes, finding_dict, focus_axis, located_paragraph,
                                       none_finding, not_checked, remaining_mismatch, structured_part)
from harness.executors import LocalPool
from harness.recording_io import read_recording
from models.aircraft import (AERO_REFERENCES, MODEL_ARGUMENT_HELP, MODELS, Aircraft, is_xml_model, model_argument,
                             nominal_root, reference_point_alternative)
from models.configuration import SECONDARY_SURFACE_LAWS
from models.mass import MassProperties, mass_root
from models.replay import initial_condition


# A mismatch left at this many times its noise level is reported as unexplained (noise in
# the measured states alone leaves up to ~3.5 in the F-16's Cl).
UNEXPLAINED_RATIO = 5.0


def _aircraft(model: str) -> Aircraft:
    """A project model by name, or a JSBSim aircraft XML by path (flown as it is)."""
    given, model = model, model_argument(model)
    if model in MODELS:
        return Aircraft(model)
    if not is_xml_model(model):
        raise DiagnosisError(f"--model {given!r} is not " + MODEL_ARGUMENT_HELP.format(models=MODELS))
    try:
        aircraft = Aircraft(str(Path(model).resolve()))
        aircraft.surfaces  # noqa: B018 - fails early, naming a surface the XML lacks
        nominal_root(aircraft.model)  # and a file its engines or systems need
    except (ValueError, OSError, ET.ParseError) as exc:
        raise DiagnosisError(f"--model {model}: {exc}") from exc
    return aircraft


def _with_recorded_mass(aircraft: Aircraft, rec) -> Aircraft:
    """The aircraft with the recording's mass and inertia (its first sample), as an XML copy."""
    try:
        mp = MassProperties.from_mapping(rec.mass_at(0))
        root, name = mass_root(aircraft.model, mp)
    except (KeyError, ValueError) as exc:
        raise DiagnosisError(f"--mass recording: {exc}") from exc
    return Aircraft(str(root / "aircraft" / name / f"{name}.xml"))


INCOMPLETE = "INCOMPLETE"
"""Marker file in a diagnosis folder while it is being written; a folder holding it was interrupted."""
_open_markers: dict[Path, int] = {}


def check_out_folder(out: str | Path) -> Path:
    """The diagnosis output folder, created; an error naming the file in the way if it cannot be."""
    from harness.atomic import ensure_folder
    try:
        return ensure_folder(out, "--out folder")
    except ValueError as exc:
        raise DiagnosisError(str(exc)) from None


@contextlib.contextmanager
def incomplete_marker(out: Path):
    """Mark ``out`` incomplete while the body runs; the outermost user removes the mark on success
    (so the command line keeps it until the report, written after :func:`diagnose`, is there too)."""
    key = Path(out).resolve()
    outer = key not in _open_markers
    created = not key.exists()
    if outer:
        check_out_folder(key)
        write_text_atomic(key / INCOMPLETE, "sidbench diagnose was writing this folder and did not finish "
                                            "(interrupted or failed): its contents are incomplete. Run it again.\n")
    _open_markers[key] = _open_markers.get(key, 0) + 1
    try:
        yield key
    except BaseException:
        if outer and [p.name for p in key.iterdir()] == [INCOMPLETE]:  # nothing written yet: leave nothing
            (key / INCOMPLETE).unlink(missing_ok=True)
            if created:
                key.rmdir()
        raise
    finally:
        _open_markers[key] -= 1
        if not _open_markers[key]:
            del _open_markers[key]
    if outer:
        (key / INCOMPLETE).unlink(missing_ok=True)


def diagnose(model: str, recording: str | Path, out: str | Path, validation: str | Path | None = None, *,
             mass: str = "model", calibrate: bool = True, calibrate_workers: int = 2,
             aero_reference: str = "auto") -> dict:
    """Diagnose ``recording`` against ``model``; write ``out``; return findings.json's content.

    ``mass='recording'`` flies the model with the recording's mass and inertia
    (:func:`models.mass.set_mass_properties`) instead of its own. ``calibrate`` refines the
    kept aerodynamic and delay terms with JSBSim in the loop as the last step
    (:mod:`harness.diagnosis.refine`; ``calibrate_workers`` processes fly its flights, 1: in
    this process); the calibrated sizes are kept only when they fit at least as well, and
    findings.json's ``calibration`` block says which and why. ``aero_reference`` places the
    model's aerodynamic reference point (:data:`models.aircraft.AERO_REFERENCES`); ``'auto'``
    lets the recording choose for a model the project flies with it moved (the 737:
    :mod:`harness.diagnosis.reference_point`), findings.json's ``assumptions`` saying which.

    Raises
    ------
    DiagnosisError
        For an unknown model; recording, trim and flight errors name their cause themselves.
    """
    with incomplete_marker(Path(out)) as folder, contextlib.ExitStack() as stack:
        # a second process takes the validation maneuver's share (analysis, replays) meanwhile
        pool = stack.enter_context(LocalPool(1)) if validation is not None and calibrate_workers > 1 else None
        return _diagnose(model, recording, folder, validation, mass=mass, calibrate=calibrate,
                         workers=calibrate_workers, pool=pool, aero_reference=aero_reference)


def _loaded(model: str, recording: str | Path, validation: str | Path | None,
            mass: str, aero_reference: str = "auto") -> tuple[Aircraft, dict]:
    """The aircraft (with the recording's mass when asked, its aerodynamic reference point
    where given) and the recordings, instruments at the c.g."""
    if aero_reference != "auto" and aero_reference not in AERO_REFERENCES:
        raise DiagnosisError(f"aero_reference must be 'auto' or one of {AERO_REFERENCES}, not {aero_reference!r}")
    aircraft = _aircraft(model)
    rec = instruments_at_cg(read_recording(recording))
    if mass == "recording":
        aircraft = _with_recorded_mass(aircraft, rec)
    elif mass != "model":
        raise DiagnosisError(f"mass must be 'model' or 'recording', not {mass!r}")
    if aero_reference != "auto":
        aircraft = replace(aircraft, aero_reference=aero_reference)
    recs = {"identification": rec}
    if validation is not None:
        recs["validation"] = instruments_at_cg(read_recording(validation))
    return aircraft, recs


def _checked(a: Analysis, av: Analysis | None) -> tuple[list[Candidate], list[Candidate], dict[int, dict | None]]:
    """The findings kept, those reported apart, and each one's validation check. A finding
    is kept only when the validation maneuver confirms it (or cannot test it: a gust level, a
    spectral peak, a coupling it does not excite, :func:`validation.untestable`)."""
    if av is not None:  # sensor biases each maneuver only suspects, named on the two; and
        name_replicated(a, av)  # terms withheld for a sensor suspicion the validation does not share
        lift_unreplicated_suspicions(a, av)
        name_mode_on_both(a, av)  # and a mode the validation maneuver rings louder
    findings = chosen_findings(a)
    checks = {id(f): validation_check(av, f) if av is not None else undecided(f) for f in findings}
    unconfirmed = [f for f in findings if (checks[id(f)] or {"status": "confirmed"})["status"]
                   not in ("confirmed", "untested")]
    return [f for f in findings if f not in unconfirmed], unconfirmed, checks


def _calibrated(model: str, recs: dict, aircraft: Aircraft, mass: str, workers: int, maneuvers: dict,
                befores: dict, a: Analysis, findings: list[Candidate], unconfirmed: list[Candidate],
                checks: dict, flown: dict, pool: LocalPool | None):
    """The calibration in the loop; a term it sizes at nothing is withdrawn (reported apart)
    and the others are flown and calibrated again without it. Returns the calibration, the
    findings, the unconfirmed, the modelled terms, the added effects and the flights."""
    modelled = list(findings)
    added = terms_of(modelled, a.applied)
    calibration, modelled, added, flown = refine_in_the_loop(model, recs, aircraft, mass, workers, maneuvers,
                                                             befores, modelled, added, flown, pool)
    withdrawn = unsupported_in_the_loop(findings, calibration, checks)
    if withdrawn:
        unconfirmed = unconfirmed + withdrawn
        findings = [f for f in findings if f not in withdrawn]
        modelled = list(findings)
        added = terms_of(modelled, a.applied)
        flown = fly_all(maneuvers, aircraft, added, modelled, befores, pool=pool)
        calibration, modelled, added, flown = refine_in_the_loop(model, recs, aircraft, mass, workers, maneuvers,
                                                                 befores, modelled, added, flown, pool)
    return calibration, findings, unconfirmed, modelled, added, flown


def _after_findings(located: dict, a: Analysis, findings: list[Candidate]) -> None:
    """Add to the located paragraph what mismatch the findings leave (:data:`UNEXPLAINED_RATIO`)."""
    if not findings:
        return
    worst = max(excited_axes(a.prepared, located["remaining"]), key=lambda c: located["remaining"][c]["ratio"])
    w = located["remaining"][worst]
    removed = f"{100 * w['removed']:.0f} % of it removed" if w["removed"] >= 0.005 else "none of it removed"
    if w["ratio"] >= UNEXPLAINED_RATIO:
        # the part of it that follows the maneuver, in the measure the paragraph opened with
        left = float(np.std(structured_part(a.prepared, after_mismatch(a, findings)[0][worst]))) / a.noise[worst]
        located["summary"] += (f" After the findings, the mismatch left in {worst} is still {w['ratio']:.1f} times "
                               f"its noise level ({removed}; {left:.1f} of it follows the maneuver)"
                               + (": no candidate term explains it." if w["removed"] < 0.2 else "."))
    else:
        located["summary"] += (f" After the findings, no axis's mismatch is above {UNEXPLAINED_RATIO:g} times its "
                               f"noise level (largest: {worst}, {w['ratio']:.1f}).")


def _write_series(out: Path, series: dict) -> None:
    (out / "series").mkdir(parents=True, exist_ok=True)
    for name, df in series.items():
        write_atomic(out / "series" / f"{name}.parquet", lambda fh, df=df: df.to_parquet(fh, index=False))


def _diagnose(model: str, recording: str | Path, out: Path, validation: str | Path | None, *, mass: str,
              calibrate: bool = True, workers: int = 2, pool: LocalPool | None = None,
              aero_reference: str = "auto") -> dict:
    t0 = time.perf_counter()
    aircraft, recs = _loaded(model, recording, validation, mass, aero_reference)
    pending = None
    # the validation maneuver is analysed in a second process meanwhile, with the aircraft
    # placed as the identification says where it can be placed two ways, and its FCS's other
    # surfaces as the identification says where it has such (fcs_surfaces.py)
    choosing = ((aero_reference == "auto" and reference_point_alternative(aircraft) is not None)
                or aircraft.name in SECONDARY_SURFACE_LAWS)
    if validation is not None and pool is not None and not choosing:
        pending = pool.pool.submit(analysed, recs["validation"], "validation", aircraft)
    p = prepare(recs["identification"], "identification")
    check_time_base(p)
    ic = initial_condition(p.t, p.smooth["V"], p.smooth["alpha"], p.altitude, phi=p.smooth.get("phi"))
    reference = choose_reference_point(p, aircraft, ic, aero_reference)
    if reference is not None:
        aircraft = reference.aircraft
    aircraft, surfaces_note = choose_secondary_surfaces(p, aircraft, ic)
    if validation is not None and pool is not None and choosing:
        pending = pool.pool.submit(analysed, recs["validation"], "validation", aircraft)
    a = analyse(p, aircraft, ic)
    withhold_shift_between_placements(a.candidates, reference)
    check_model_represents(a, model, lambda: model_along(p, aircraft, ic))
    befores = {"identification": replay_before(p, aircraft, a)}
    av = None
    if validation is not None:
        pv, av, befores["validation"] = (pending.result() if pending is not None else
                                         analysed(recs["validation"], "validation", aircraft))
    findings, unconfirmed, checks = _checked(a, av)
    attach_mode_models(findings, {"identification": p} | ({"validation": pv} if av is not None else {}))
    findings = withhold_sensor_errors_a_mode_makes(findings, p)
    findings = withhold_sensor_errors_a_peak_makes(findings, p)
    findings = withhold_terms_a_mode_makes(findings, p, lambda quiet: analyse(quiet, aircraft, ic))
    modelled = list(findings)
    added = terms_of(modelled, a.applied)
    timing = {"analysis": time.perf_counter() - t0}
    # the recording as prepared (``a.prepared`` carries the sensor corrections; fits are
    # against what was recorded)
    maneuvers = {"identification": (p, a)} | ({"validation": (pv, av)} if av is not None else {})
    flown = fly_all(maneuvers, aircraft, added, modelled, befores, pool=pool)
    calibration = {"used": False, "reason": "not asked for (calibrate=False, --no-calibrate)"}
    if calibrate:
        t1 = time.perf_counter()
        calibration, findings, unconfirmed, modelled, added, flown = _calibrated(
            model, recs, aircraft, mass, workers, maneuvers, befores, a, findings, unconfirmed, checks, flown, pool)
        timing["calibration"] = time.perf_counter() - t1
    _, fb_id, fa_id, series_id = flown["identification"]
    fits_b, fits_a = {"identification": fb_id}, {"identification": fa_id}
    series = {"identification": series_id}
    located = located_paragraph(a, fb_id, "identification", focus_axis(findings))
    located["remaining"] = remaining_mismatch(a, fb_id, fa_id)
    _after_findings(located, a, findings)
    if av is not None:
        av, fb_v, fa_v, series_v = flown["validation"]
        fits_b["validation"], fits_a["validation"] = fb_v, fa_v
        series["validation"] = series_v
        located["outputs"]["validation"] = located_paragraph(av, fb_v, "validation")["outputs"]["validation"]
    timing["total"] = time.perf_counter() - t0
    model_info = write_model(out, aircraft, ic, added, sensor_models(modelled),
                             calibration.get("references") if calibration["used"] else None,
                             start_refs=recording_start_references(p, ic))
    result = {
        "findings": [with_calibration(finding_dict(f, fits_b, fits_a, checks.get(id(f))), calibration)
                     for f in findings] or [none_finding(a, fits_b)],
        "located": located,
        "not_confirmed": [finding_dict(f, {}, {}, checks.get(id(f))) for f in unconfirmed],
        "calibration": calibration,
        "assumptions": (assumptions(a, aircraft, mass, surfaces_note) + ([reference.assumption()] if reference else [])
                        + calibration_assumptions(calibration)),
        "not_checked": not_checked(a, validation is not None),
        "detection_limits": detection_limits(a),
        "noise": {c: {"std": p.noise_std[c], "cutoff_hz": p.cutoff_hz[c]} for c in p.noise_std},
        "candidates": [c.as_dict() for c in sorted(a.candidates, key=lambda c: -abs(c.t))],
        "model": model_info,
        "inputs": {"identification": str(recording), "validation": str(validation) if validation else None,
                   "model": model, "mass": mass},
        "common_filter_cutoff_hz": p.common_cutoff_hz,
        "timing_s": timing,
        "seed": None,
    }
    _write_series(out, series)
    write_text_atomic(out / "findings.json", json.dumps(jsonable(result), indent=1))
    return result
