"""What a calibration flies: the aircraft XML it adjusts, each recording's inputs, start and
measured outputs, and one flight of the adjusted aircraft (the unit of parallel work)."""
from __future__ import annotations

import contextlib
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from harness.errors import UserError
from harness.isa import density_altitude_ft
from models.aircraft import MODEL_ARGUMENT_HELP, MODELS, Aircraft, is_xml_model, model_argument, model_xml, nominal_tree
from models.calibration_xml import Adjustment, adjusted_tree, check_adjustments, delays
from models.constants import SURFACES
from models.flight import FlightError
from models.jsbsim_root import write_root
from models.mass import MassProperties, set_mass_properties
from models.replay import InitialCondition, initial_condition, replay, steady_start
from models.trim import TrimError

HOLDS = ("linear", "sample")
OUTPUTS = ("alpha", "beta", "p", "q", "r", "phi", "theta", "V", "ax", "ay", "az")
UNITS = {"alpha": "rad", "beta": "rad", "p": "rps", "q": "rps", "r": "rps", "phi": "rad", "theta": "rad",
         "V": "fps", "ax": "g", "ay": "g", "az": "g"}


class CalibrationError(UserError):
    """A calibration the user's inputs make impossible: the message names the input and the rule."""


@dataclass(frozen=True)
class Base:
    """The aircraft a calibration adjusts: its XML text (mass already applied), the file it
    came from (its engines and systems), and the :class:`Aircraft` that says how to trim and
    fly it."""

    xml: bytes
    source: str
    model: str
    name: str
    aero_reference: str = "project"  # models.aircraft.Aircraft.aero_reference

    @property
    def aircraft(self) -> Aircraft:
        return Aircraft(self.model, aero_reference=self.aero_reference)

    def tree(self) -> ET.ElementTree:
        return ET.ElementTree(ET.fromstring(self.xml))


def base_aircraft(model: str, mass: MassProperties | None = None, aero_reference: str = "project") -> Base:
    """The :class:`Base` of a project model (``f16``, ``737``, ``dhc6``) or an XML path, with
    ``mass`` written into it when given (:func:`models.mass.set_mass_properties`), its
    aerodynamic reference point placed by ``aero_reference`` (:data:`models.aircraft.AERO_REFERENCES`).

    Raises
    ------
    CalibrationError
        For an unknown model or an unreadable XML.
    """
    given, model = model, model_argument(model)
    if model not in MODELS and not is_xml_model(model):
        raise CalibrationError(f"--model {given!r} is not " + MODEL_ARGUMENT_HELP.format(models=MODELS))
    try:
        aircraft = Aircraft(str(Path(model).resolve()) if is_xml_model(model) else model,
                            aero_reference=aero_reference)
        aircraft.surfaces  # noqa: B018 - names a surface the XML lacks
        tree = nominal_tree(aircraft.model)
        if mass is not None:
            tree = set_mass_properties(tree, mass)
    except (ValueError, OSError, ET.ParseError) as exc:
        raise CalibrationError(f"--model {model}: {exc}") from exc
    return Base(xml=ET.tostring(tree.getroot()), source=str(model_xml(aircraft.model)), model=aircraft.model,
                name=f"{aircraft.name}-calibration", aero_reference=aero_reference)


@dataclass(frozen=True)
class Maneuver:
    """One recording as the output error sees it: time, surfaces (rad), the start the model is
    trimmed at, and the measured outputs (N × n_o, canonical units)."""

    name: str
    t: np.ndarray
    surfaces: dict[str, np.ndarray]
    ic: InitialCondition
    outputs: tuple[str, ...]
    z: np.ndarray
    hold: str = "linear"  # how the surfaces are replayed between samples (models.replay.replay)

    @property
    def dt(self) -> float:
        return float(np.median(np.diff(self.t)))


def _altitude(rec) -> np.ndarray:
    if rec.has("h"):
        return rec.channel("h")
    if rec.has("qbar") and rec.has("V"):
        rho = 2.0 * rec.channel("qbar") / np.maximum(rec.channel("V"), 1.0) ** 2
        return density_altitude_ft(np.clip(rho, 1e-6, None))
    raise CalibrationError(f"recording {rec.name!r} has neither an altitude (h) nor qbar and V to start the model at")


def maneuver(rec, outputs: tuple[str, ...] | None = None, hold: str = "linear") -> Maneuver:
    """A :class:`Maneuver` of a recording; ``outputs`` the channels to match (default: those of
    :data:`OUTPUTS` it has); ``hold`` 'linear' or 'sample' (:func:`models.replay.replay`).

    Raises
    ------
    CalibrationError
        When it lacks a surface channel, V or α, or an asked-for output.
    """
    missing = [q for q in ("V", "alpha") if not rec.has(q)]
    if not any(rec.has(s) for s in SURFACES):
        missing.append("de|da|dr")
    if missing:
        raise CalibrationError(f"recording {rec.name!r} lacks the channels {', '.join(missing)}: the model is "
                               "started from V, α (and h) and driven by the recorded surfaces")
    if hold not in HOLDS:
        raise CalibrationError(f"--surfaces must be one of {HOLDS}, not {hold!r}")
    if outputs is None:
        outputs = tuple(o for o in OUTPUTS if rec.has(o))
    absent = [o for o in outputs if not rec.has(o)]
    if absent or not outputs:
        raise CalibrationError(f"recording {rec.name!r} lacks the output channels {', '.join(absent) or 'all'} "
                               f"(it has {', '.join(o for o in OUTPUTS if rec.has(o)) or 'none of them'})")
    t = rec.t
    ic = initial_condition(t, rec.channel("V"), rec.channel("alpha"), _altitude(rec),
                           phi=rec.channel("phi") if rec.has("phi") else None)
    surfaces = {s: steady_start(rec.channel(s), t) for s in SURFACES if rec.has(s)}
    z = np.column_stack([rec.channel(o) for o in outputs])
    return Maneuver(name=str(rec.name), t=np.asarray(t, dtype=float), surfaces=surfaces, ic=ic,
                    outputs=tuple(outputs), z=z, hold=hold)


@dataclass(frozen=True)
class Flight:
    """One flight: the base aircraft with ``values`` of ``adjustments``, over maneuver ``m``."""

    base: Base
    adjustments: tuple[Adjustment, ...]
    values: tuple[float, ...]
    refs: tuple[tuple[str, float], ...]
    maneuver: Maneuver
    scratch: str = ""  # a JSBSim root folder the flights may write into ("" : a temporary one each)


def fly(job: Flight) -> np.ndarray | str:
    """The outputs (N × n_o) of one flight, or the reason it failed (a trim that finds no
    equilibrium, a divergence): a string, so that a failed flight never raises in a worker.

    The adjusted XML is written into a temporary JSBSim root, loaded and removed; the aircraft
    is trimmed at the maneuver's start and flown with its surfaces (:func:`models.replay.replay`,
    the diagnosis's replay), the delay parameters shifting the surfaces the aerodynamics see.
    """
    b, m = job.base, job.maneuver
    aircraft = b.aircraft
    tree = adjusted_tree(b.tree(), job.adjustments, job.values, refs=dict(job.refs), surfaces=aircraft.surfaces,
                         in_place=True)
    try:
        with contextlib.ExitStack() as stack:
            folder = job.scratch or stack.enter_context(tempfile.TemporaryDirectory(prefix="sidbench-calibrate-"))
            # one aircraft name per process: concurrent workers never write each other's XML,
            # and JSBSim has read it all by the time load_model returns
            name = f"{b.name}-{os.getpid()}"
            write_root(Path(folder), name, tree, Path(b.source))
            hist, _ = replay(aircraft, m.ic, m.t, m.surfaces, root=Path(folder), name=name,
                             delays_s=delays(job.adjustments, job.values), hold=m.hold)
    except (FlightError, TrimError, RuntimeError, ValueError) as exc:
        # a trim without equilibrium, a divergence, an XML JSBSim will not load at these values:
        # the reason goes back to the fit, which halves its step (never a crash in a worker)
        return f"{type(exc).__name__}: {exc}"
    n = len(m.t)
    cols = [hist.channels[f"{o}_{UNITS[o]}"] for o in m.outputs]
    y = np.column_stack(cols)
    if y.shape[0] < n:
        return f"the flight gave {y.shape[0]} samples for {n} recorded"
    y = y[:n]
    if not np.all(np.isfinite(y)):
        return "the flight gave non-finite outputs"
    return y


def fly_indexed(item: tuple[int, Flight]) -> np.ndarray | str:
    """:func:`fly` for an executor's ``(index, flight)`` item."""
    return fly(item[1])


def check(base: Base, adjustments: tuple[Adjustment, ...]) -> None:
    """The adjustments against the aircraft (:func:`models.calibration_xml.check_adjustments`)."""
    try:
        check_adjustments(base.tree(), adjustments)
    except ValueError as exc:
        raise CalibrationError(f"--parameters: {exc}") from exc
