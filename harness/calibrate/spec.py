"""The ``--parameters`` option: a comma list of adjustment names (:mod:`models.calibration_xml`)."""
from __future__ import annotations

from harness.calibrate.problem import CalibrationError
from models.calibration_xml import Adjustment, parse_adjustment


def parse_parameters(text: str) -> tuple[Adjustment, ...]:
    """``"aero/coefficient/Cnb:scale,Cm_alphadot=-1,tau_de"`` -> the adjustments, in order.

    Raises
    ------
    CalibrationError
        For an empty list, a malformed or unknown name, or a name given twice.
    """
    items = [s.strip() for s in str(text).split(",") if s.strip()]
    if not items:
        raise CalibrationError("--parameters: give at least one parameter (e.g. aero/coefficient/Cnb:scale,Cm_alphadot)")
    out = []
    for s in items:
        try:
            out.append(parse_adjustment(s))
        except ValueError as exc:
            raise CalibrationError(f"--parameters: {exc}") from exc
    names = [a.name for a in out]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CalibrationError(f"--parameters: {', '.join(twice)} given twice")
    return tuple(out)
