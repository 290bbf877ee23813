"""The configuration an aircraft flies in: cruise, as a flight-test aircraft is flown.

JSBSim starts every aircraft with its landing gear down (``gear/gear-cmd-norm`` =
``gear/gear-pos-norm`` = 1): the package's F-16 then carries ``aero/coefficient/CDgear``
≈ 1,250 lbf at 10,000 ft and 420 ft/s and trims with 3,380 lbf of thrust instead of the clean
aircraft's ≈ 2,150 lbf (../shared/jsbsim-notes.md, confirmed by tests/test_configuration.py).
Every aircraft here is put into its cruise configuration before it is trimmed:

- retractable gear up and locked: ``gear/gear-cmd-norm`` = 0 before ``run_ic`` and
  ``gear/gear-pos-norm`` = 0 after it (the gear's kinematic would otherwise take 5 s to
  travel); fixed gear (the DHC6, the c172x) stays as it is;
- flaps commanded up (``fcs/flap-cmd-norm`` = 0) where the aircraft has a flap command;
- speed brake and spoilers closed (``fcs/speedbrake-cmd-norm``, ``fcs/spoiler-cmd-norm`` = 0);
- scheduled surfaces (the F-16's leading- and trailing-edge flaps) left to their schedules:
  the FCS sets them at trim and they stay there with the FCS disabled in open-loop flight.

Only the properties an aircraft has are written; what was set is returned so the recording's
metadata can say it (``meta['simulation']['configuration']``).
"""
from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import jsbsim

# Commands written before run_ic (where the aircraft has the property).
CRUISE_COMMANDS: tuple[tuple[str, float], ...] = (
    ("gear/gear-cmd-norm", 0.0),
    ("fcs/flap-cmd-norm", 0.0),
    ("fcs/speedbrake-cmd-norm", 0.0),
    ("fcs/spoiler-cmd-norm", 0.0),
)
# Positions forced after run_ic for retractable gear (its kinematic would take seconds).
RETRACTED_GEAR: tuple[tuple[str, float], ...] = (("gear/gear-pos-norm", 0.0),)
# Positions read back into the metadata after trim.
REPORTED_POSITIONS = ("gear/gear-pos-norm", "fcs/flap-pos-norm", "fcs/flap-pos-deg",
                      "fcs/speedbrake-pos-norm", "fcs/spoiler-pos-norm", "fcs/lef-pos-rad",
                      "fcs/flaperon-mix-rad")


@dataclass(frozen=True)
class Configuration:
    """What is written to put an aircraft into cruise configuration.

    Attributes
    ----------
    retractable_gear : bool
        Whether the aircraft's XML declares retractable landing gear (``<retractable>1``).
    commands : tuple of (property, value)
        Written before ``run_ic`` (only those the aircraft has).
    positions : tuple of (property, value)
        Written after ``run_ic`` (the gear position, for retractable gear).
    """

    retractable_gear: bool
    commands: tuple[tuple[str, float], ...]
    positions: tuple[tuple[str, float], ...]

    def describe(self) -> str:
        gear = "gear up and locked" if self.retractable_gear else "fixed gear"
        return f"cruise: {gear}, flaps up unless scheduled, speed brake and spoilers closed"


def has_retractable_gear(xml_path: Path) -> bool:
    """Whether an aircraft XML declares any retractable landing-gear contact (read once per
    file version: the parse was a fifth of a trim's time)."""
    return _retractable_gear(str(xml_path), Path(xml_path).stat().st_mtime_ns)


@functools.lru_cache(maxsize=64)
def _retractable_gear(xml_path: str, _mtime_ns: int) -> bool:
    root = ET.parse(xml_path).getroot()
    for contact in root.iter("contact"):
        flag = contact.find("retractable")
        if flag is not None and (flag.text or "").strip() in ("1", "true"):
            return True
    return False


def cruise_configuration(xml_path: Path) -> Configuration:
    """The cruise configuration of the aircraft whose XML is at ``xml_path``."""
    retractable = has_retractable_gear(xml_path)
    commands = CRUISE_COMMANDS if retractable else tuple(c for c in CRUISE_COMMANDS if not c[0].startswith("gear/"))
    return Configuration(retractable_gear=retractable, commands=commands,
                         positions=RETRACTED_GEAR if retractable else ())


def _write_existing(fdm: jsbsim.FGFDMExec, pairs: tuple[tuple[str, float], ...]) -> dict[str, float]:
    pm = fdm.get_property_manager()
    written = {}
    for prop, value in pairs:
        if pm.hasNode(prop):
            fdm[prop] = value
            written[prop] = value
    return written


def command_configuration(fdm: jsbsim.FGFDMExec, config: Configuration) -> dict[str, float]:
    """Write the configuration's commands (before ``run_ic``); returns what was written."""
    return _write_existing(fdm, config.commands)


def place_configuration(fdm: jsbsim.FGFDMExec, config: Configuration) -> dict[str, float]:
    """Write the configuration's positions (after ``run_ic``); returns what was written."""
    return _write_existing(fdm, config.positions)


def configuration_record(fdm: jsbsim.FGFDMExec, config: Configuration, written: dict[str, float]) -> dict:
    """The configuration as flown, for ``meta['simulation']['configuration']``: what was set
    and the positions of gear, flaps, speed brake and scheduled surfaces after trim."""
    pm = fdm.get_property_manager()
    return {
        "description": config.describe(),
        "gear": "up and locked" if config.retractable_gear else "fixed",
        "set": dict(written),
        "positions": {p: float(fdm[p]) for p in REPORTED_POSITIONS if pm.hasNode(p)},
    }


# The F-16's leading-edge flap (JSBSim's f16.xml, <switch name="fcs/lef-pos-rad">), airborne and
# gear up: (position, the alpha above which it is set), rad, the higher first; -0.0349 rad above
# Mach 0.9 below both; else 0.
F16_LEF_BY_ALPHA = ((0.436, 0.2618), (0.262, 0.0873))
F16_LEF_SUPERSONIC = (-0.0349, 0.9)  # (position rad, Mach above which)

# Surfaces an aircraft's FCS schedules discontinuously (switches with no hysteresis): their
# possible positions, in order of preference when no position is consistent with the schedule
# at the equilibrium it gives (see models.trim.trim): the F-16's leading-edge flap.
SCHEDULED_SURFACES: dict[str, dict[str, tuple[float, ...]]] = {
    "f16": {"fcs/lef-pos-rad": (F16_LEF_BY_ALPHA[1][0], 0.0, F16_LEF_BY_ALPHA[0][0], F16_LEF_SUPERSONIC[0])},
}


# The surfaces an aircraft's FCS moves in flight from its states and its pilot's surfaces, beside
# the three the recording carries (recording-format: de, da, dr): the laws by which JSBSim's
# f16.xml moves them, for evaluating a recording flown with the FCS on (the project flies and
# evaluates the model with its FCS disabled, where they stay at trim). From f16.xml: the
# leading-edge flap is the switch above (F16_LEF_BY_ALPHA, F16_LEF_SUPERSONIC); the flaperons' mix
# <fcs/flaperon-mix-rad> = 1.4324 (clip(−tef − a) + clip(tef − a)), clip to ±1, with the aileron's
# speed-compensated command a = (δa / 0.375)(1 − 0.85 M) (the scheduled gain 1 → 0.15 over Mach
# 0 → 1) and the trailing-edge flap's normalised position tef = 2.864789 × (0.349 rad below 250
# kt calibrated, −0.0349 above Mach 0.9, else 0). The kinematic rate limits (the aileron's 0.3 s,
# the flaps' 3 s full travel) are left out.
def f16_secondary_surfaces(alpha_rad: float, mach: float, vc_kts: float, da_rad: float) -> dict[str, float]:
    """The F-16's leading-edge flap and flaperon mix (rad) as its FCS sets them at a state."""
    lef = next((pos for pos, above in F16_LEF_BY_ALPHA if alpha_rad > above),
               F16_LEF_SUPERSONIC[0] if mach > F16_LEF_SUPERSONIC[1] else 0.0)
    gain = 1.0 - 0.85 * min(max(mach, 0.0), 1.0)
    a = min(max(da_rad / 0.375, -1.0), 1.0) * gain
    tef = 2.864789 * (0.349 if vc_kts < 250.0 else -0.0349 if mach > 0.9 else 0.0)
    mix = 1.4324 * (min(max(-tef - a, -1.0), 1.0) + min(max(tef - a, -1.0), 1.0))
    return {"fcs/lef-pos-rad": lef, "fcs/flaperon-mix-rad": mix}


SECONDARY_SURFACE_LAWS = {"f16": f16_secondary_surfaces}
