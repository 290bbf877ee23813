"""``--parameters auto``: the diagnosis's findings as the structure to calibrate.

The terms the diagnosis added to the aircraft (``findings.json`` → ``model.terms``: an
aerodynamic term of the vocabulary or a surface delay, each with its equation-error size) are
the parameters, each started at that size; sensor effects, a structural mode and turbulence are
not aircraft parameters and are left out."""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

from harness.calibrate.problem import CalibrationError
from models.hidden import AERO_TERMS


def findings_parameters(findings: dict) -> list[str]:
    """``NAME=SIZE`` for each aerodynamic or delay term of a diagnosis (findings.json's content),
    at its equation-error size (a diagnosis that kept its calibrated sizes lists them in
    ``calibration.parameters`` beside the equation-error ones)."""
    terms = (findings.get("model") or {}).get("terms") or []
    calibration = findings.get("calibration") or {}
    ee = {p["name"]: p["equation_error"] for p in calibration.get("parameters") or []
          if calibration.get("used") and p.get("equation_error") is not None}
    return [f"{t['parameter']}={float(ee.get(t['parameter'], t['size']))!r}" for t in terms
            if t.get("effect") in AERO_TERMS + ("control_delay",)]


def auto_parameters(spec: str, model: str, recording, validation, mass: str) -> list[str]:
    """The parameters of ``auto`` (run the diagnosis on ``recording`` and ``validation`` now) or
    ``auto=FINDINGS.json`` (an earlier diagnosis's findings).

    Raises
    ------
    CalibrationError
        When the findings cannot be read or name no aircraft term.
    """
    _, _, path = spec.partition("=")
    if path.strip():
        try:
            doc = json.loads(Path(path.strip()).read_text())
        except (OSError, ValueError) as exc:
            raise CalibrationError(f"--parameters {spec}: cannot read the diagnosis's findings: {exc}") from exc
    else:
        if not isinstance(recording, (str, Path)):
            raise CalibrationError("--parameters auto runs the diagnosis on the recording's file: give its path")
        from harness.diagnosis.run import diagnose
        with tempfile.TemporaryDirectory(prefix="sidbench-calibrate-auto-") as d:
            doc = diagnose(model, recording, Path(d) / "diagnosis",
                           validation if isinstance(validation, (str, Path)) else None, mass=mass, calibrate=False)
    found = findings_parameters(doc)
    if not found:
        raise CalibrationError(f"--parameters {spec}: the diagnosis added no aerodynamic or delay term to the "
                               "aircraft; name the parameters to calibrate")
    return found
