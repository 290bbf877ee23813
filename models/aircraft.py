"""Which aircraft to fly, in which variant, and loading it into JSBSim."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import jsbsim

from models.jsbsim_root import aircraft_xml, cached_root, strip_io

VARIANTS = ("nominal", "exact-truth", "unstable")
MODELS = ("f16", "737", "dhc6")

# The model's folder and file name in the jsbsim package (its aircraft/<name>/<name>.xml).
PACKAGE_NAMES: dict[str, str] = {"f16": "f16", "737": "737", "dhc6": "DHC6"}

# The surface positions each model's aerodynamics read (JSBSim signs: de trailing edge down).
# DHC6: the aerodynamics read fcs/elevator-pos-rad (CmDe, CLde), fcs/mag-elevator-pos-rad
# (CDde), fcs/left-aileron-pos-rad (Clda, Cnda; the right aileron is read by nothing) and
# fcs/rudder-pos-rad (CYdr, Cldr, Cndr). fcs/elevator-pos-rad is tied to JSBSim's FGFCS
# setter, which updates the magnitude property in the same call, so writing the elevator
# drives both with the FCS disabled (tested in tests/test_dhc6.py).
SURFACE_PROPERTIES: dict[str, dict[str, str]] = {
    "f16": {"de": "fcs/elevator-pos-rad", "da": "fcs/aileron-pos-rad", "dr": "fcs/rudder-pos-rad"},
    "737": {"de": "fcs/elevator-pos-rad", "da": "fcs/left-aileron-pos-rad", "dr": "fcs/rudder-pos-rad"},
    "dhc6": {"de": "fcs/elevator-pos-rad", "da": "fcs/left-aileron-pos-rad", "dr": "fcs/rudder-pos-rad"},
}

# Models whose engines are JSBSim turboprops: their trim needs models.trim's engine handling.
TURBOPROP_MODELS = ("dhc6",)

# External moments (body axes, lbf*ft) that stand in for the propeller torque while JSBSim
# trims a turboprop (see models.trim); zero at all other times.
TRIM_MOMENT_PROPERTIES: dict[str, str] = {
    ax: f"external_reactions/sidbench-trim-{ax}/magnitude-lbsft" for ax in "lmn"}


@dataclass(frozen=True)
class Aircraft:
    """An aircraft model and variant.

    Attributes
    ----------
    model : str
        JSBSim model: ``'f16'`` (tabulated, nonlinear aerodynamics), ``'737'`` (mostly
        constant coefficients) or ``'dhc6'`` (the Twin Otter, two turboprops: the aircraft of
        the SIDPAC flight-test recordings).
    variant : str
        ``'nominal'``: the package's aircraft (the 737 with its socket input stripped and its
        aerodynamic reference point moved onto the c.g., so its derivatives equal the XML
        constants; the DHC6 with the two changes of :func:`dhc6_tree`, which leave its
        flight unchanged). ``'exact-truth'``: aerodynamics replaced by functions exactly
        linear in the states with the nominal's truth derivatives at the flight condition
        (seed §III.C: no model-structure error). ``'unstable'``: the aerodynamic reference point moved forward
        by ``rp_shift_in``, which makes the airframe statically unstable (seed §II, last
        paragraph: equation error handles open-loop unstable aircraft flown closed loop).
    rp_shift_in : float
        Forward shift of the aerodynamic reference point for the unstable variant, inches.
        The default 8 in (5.9 % of the F-16's chord) turns Cm_alpha from -0.08 to about +0.15
        per rad at the seed condition; a pitch-rate loop with K >= 0.3 s stabilises it.
    """

    model: str = "f16"
    variant: str = "nominal"
    rp_shift_in: float = 8.0
    hidden: tuple = ()  # models.hidden.HiddenEffect: concealed physics for the discrepancy diagnosis

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise ValueError(f"unknown aircraft {self.model!r}; choose one of {MODELS}")
        if self.variant not in VARIANTS:
            raise ValueError(f"unknown variant {self.variant!r}; choose one of {VARIANTS}")

    @property
    def surfaces(self) -> dict[str, str]:
        """Surface name ('de', 'da', 'dr') to the JSBSim property the aerodynamics read."""
        return SURFACE_PROPERTIES[self.model]

    @property
    def label(self) -> str:
        base = self.model if self.variant == "nominal" else f"{self.model}/{self.variant}"
        return base + "".join(f"+{e.effect}" for e in self.hidden)


def new_fdm(root: Path | None, name: str, dt: float) -> jsbsim.FGFDMExec:
    """Create a silent JSBSim instance and load aircraft ``name`` from ``root``."""
    # JSBSim's banner is printed by the constructor unless its (process-wide) debug level
    # is zero beforehand; no other JSBSim output is wanted either.
    jsbsim.FGJSBBase().debug_lvl = 0
    fdm = jsbsim.FGFDMExec(None if root is None else str(root))
    fdm.set_debug_level(0)
    if not fdm.load_model(name):
        raise RuntimeError(f"JSBSim could not load aircraft {name!r} from {root or 'the package root'}")
    fdm.set_dt(dt)
    return fdm


def dhc6_tree() -> ET.ElementTree:
    """The package's DHC6 with two changes that let the project fly it with the FCS disabled.

    1. Its pitching moment due to propeller slipstream (``aero/coefficient/CmT``) reads
       ``systems/propulsion/thrust-coefficient``, a sum computed by the aircraft's
       ``Propulsion.xml`` system. Systems run inside JSBSim's FCS model, so with the FCS
       disabled that sum would freeze at its trim value. The copy reads the sum of the two
       engines' ``propulsion/engine[i]/thrust-coefficient`` directly (with the FCS on, the
       only difference is that the system's sum lagged the engines by one frame).
    2. Three body-axis external moments, ``sidbench-trim-l``, ``-m`` and ``-n``, zero unless
       set: :func:`models.trim.trim` uses them to stand in for the propeller torque while
       JSBSim trims (its turboprop delivers no power during trim, so the trim would
       otherwise balance an aircraft without the torque it flies with).
    """
    tree = strip_io(aircraft_xml(PACKAGE_NAMES["dhc6"]))
    root = tree.getroot()
    replaced = 0
    for fn in root.find("aerodynamics").iter("function"):
        if fn.get("name") != "aero/coefficient/CmT":
            continue
        for parent in fn.iter():
            for i, child in enumerate(list(parent)):
                if child.tag == "property" and (child.text or "").strip() == "systems/propulsion/thrust-coefficient":
                    total = ET.Element("sum")
                    for k in (0, 1):
                        ET.SubElement(total, "property").text = f"propulsion/engine[{k}]/thrust-coefficient"
                    total.tail = child.tail
                    parent.remove(child)
                    parent.insert(i, total)
                    replaced += 1
    if replaced != 1:
        raise RuntimeError(f"DHC6.xml changed: expected one CmT thrust-coefficient input, found {replaced}")
    if root.find("external_reactions") is not None:
        raise RuntimeError("DHC6.xml changed: it now has external reactions of its own")
    ext = ET.Element("external_reactions")
    for ax, direction in zip("lmn", ((1, 0, 0), (0, 1, 0), (0, 0, 1))):
        moment = ET.SubElement(ext, "moment", name=f"sidbench-trim-{ax}", frame="BODY")
        d = ET.SubElement(moment, "direction")
        for tag, v in zip("xyz", direction):
            ET.SubElement(d, tag).text = str(v)
    root.insert(list(root).index(root.find("aerodynamics")), ext)
    return tree


def nominal_tree(model: str) -> ET.ElementTree:
    """The XML of the nominal model (what :func:`nominal_root` loads), freshly parsed."""
    if model == "dhc6":
        return dhc6_tree()
    return strip_io(aircraft_xml(PACKAGE_NAMES[model]))


def nominal_root(model: str) -> tuple[Path | None, str]:
    """Root folder and aircraft name of the nominal model (a stripped copy for the 737, a
    copy for the DHC6: see :func:`dhc6_tree`)."""
    if model == "737":
        return cached_root("737", strip_io(aircraft_xml("737")), "737"), "737"
    if model == "dhc6":
        name = PACKAGE_NAMES["dhc6"]
        return cached_root(name, dhc6_tree(), name), name
    return None, model


def load_fdm(aircraft: Aircraft, dt: float, *, root: Path | None = None,
             name: str | None = None) -> jsbsim.FGFDMExec:
    """Load ``aircraft`` into a new JSBSim instance (not yet trimmed).

    ``root``/``name`` override the model source; the exact-truth variant passes the root
    written by :func:`models.exact.exact_truth_root`.
    """
    if root is None and name is None:
        if aircraft.variant == "exact-truth":
            raise ValueError("the exact-truth variant is built per flight condition: "
                             "use models.exact.exact_truth_root() and pass root= and name=")
        root, name = nominal_root(aircraft.model)
    fdm = new_fdm(root, name or aircraft.model, dt)
    for e in aircraft.hidden:
        if e.effect == "control_delay":
            from models.hidden import delay_property
            fdm[delay_property(e.surface)] = 0.0  # the aerodynamics read it from the first run_ic
    return fdm


def place_reference_point(fdm: jsbsim.FGFDMExec, aircraft: Aircraft) -> bool:
    """Apply the variant's aerodynamic reference point (needs the mass model: after run_ic).

    Returns whether it moved (the caller then re-initialises)."""
    moved = aircraft.model == "737" or aircraft.variant in ("exact-truth", "unstable")
    if aircraft.model == "737" or aircraft.variant == "exact-truth":
        # Moments about the c.g.: put the aerodynamic reference point on it.
        for ax in "xyz":
            fdm[f"metrics/aero-rp-{ax}-in"] = fdm[f"inertia/cg-{ax}-in"]
    if aircraft.variant == "unstable":
        # JSBSim's structural x axis points aft: forward is more negative.
        fdm["metrics/aero-rp-x-in"] = fdm["metrics/aero-rp-x-in"] - aircraft.rp_shift_in
    return moved
