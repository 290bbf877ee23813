"""Which aircraft to fly, in which variant, and loading it into JSBSim."""
from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path

import jsbsim

from models.jsbsim_root import aircraft_xml, cached_root, engine_root, package_root, strip_io
from models.errors import UserError

VARIANTS = ("nominal", "exact-truth", "unstable")
MODELS = ("f16", "737", "dhc6")

# Where the aerodynamic reference point is put (:func:`place_reference_point`): ``project``
# the project's own placement (the 737's and the exact-truth variant's on the c.g., every
# other model's where its XML puts it), ``xml`` where the XML puts it, ``cg`` on the c.g.
AERO_REFERENCES = ("project", "xml", "cg")

# Models the project flies with the aerodynamic reference point moved off the XML's place,
# by their short names (an XML copy of the 737 with a recording's mass is "737-mass").
MOVED_REFERENCE_MODELS = ("737", "737-mass")

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

# Surface properties an aircraft XML given by path is searched for, in order of preference:
# the first its aerodynamics read is the surface's.
SURFACE_CANDIDATES: dict[str, tuple[str, ...]] = {
    "de": ("fcs/elevator-pos-rad",),
    "da": ("fcs/aileron-pos-rad", "fcs/left-aileron-pos-rad", "fcs/effective-aileron-pos",
           "fcs/right-aileron-pos-rad"),
    "dr": ("fcs/rudder-pos-rad",),
}

# Models whose engines are JSBSim turboprops: their trim needs models.trim's engine handling.
TURBOPROP_MODELS = ("dhc6",)

# External moments (body axes, lbf*ft) that stand in for the propeller torque while JSBSim
# trims a turboprop (see models.trim); zero at all other times.
TRIM_MOMENT_PROPERTIES: dict[str, str] = {
    ax: f"external_reactions/sidbench-trim-{ax}/magnitude-lbsft" for ax in "lmn"}


class AircraftError(UserError):
    """An unknown aircraft or variant, or an aircraft XML JSBSim cannot fly as asked."""


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
    aero_reference : str
        Where the aerodynamic reference point is (:data:`AERO_REFERENCES`): ``'project'``
        (default) the variant's own placement, ``'xml'`` the XML's (the 737 as JSBSim ships
        it: 1.2 ft aft of and 4.9 ft above its c.g., so its side force rolls it and its lift
        pitches it beyond the XML's moment constants), ``'cg'`` on the c.g. Only the nominal
        variant takes another than ``'project'``.
    rp_shift_in : float
        Forward shift of the aerodynamic reference point for the unstable variant, inches.
        The default 8 in (5.9 % of the F-16's chord) turns Cm_alpha from -0.08 to about +0.15
        per rad at the seed condition; a pitch-rate loop with K >= 0.3 s stabilises it.
    """

    model: str = "f16"
    variant: str = "nominal"
    rp_shift_in: float = 8.0
    hidden: tuple = ()  # models.hidden.HiddenEffect: concealed physics for the discrepancy diagnosis
    aero_reference: str = "project"
    # the surfaces the FCS moves beside de, da, dr (models.configuration.SECONDARY_SURFACE_LAWS):
    # "held" where trim put them (the FCS disabled), or "fcs" moved by the FCS's laws where the
    # model is evaluated along a recording (models.replay.aero_along; its flights keep them held)
    secondary_surfaces: str = "held"

    def __post_init__(self) -> None:
        if self.aero_reference not in AERO_REFERENCES:
            raise AircraftError(f"unknown aerodynamic reference point {self.aero_reference!r}; "
                                f"choose one of {AERO_REFERENCES}")
        if self.aero_reference != "project" and self.variant != "nominal":
            raise AircraftError(f"variant {self.variant!r} places its own aerodynamic reference point: "
                                f"aero_reference {self.aero_reference!r} is only for the nominal variant")
        if self.model not in MODELS and not is_xml_model(self.model):
            raise AircraftError(f"unknown aircraft {self.model!r}; choose one of {MODELS} or give the path "
                             "of a JSBSim aircraft XML (<name>.xml)")
        if is_xml_model(self.model):
            if not Path(self.model).is_file():
                raise AircraftError(f"no JSBSim aircraft file {self.model!r}")
            if self.variant != "nominal":
                raise AircraftError(f"an aircraft given by path flies as it is: variant {self.variant!r} "
                                 "is only built for the project's models")
        if self.variant not in VARIANTS:
            raise AircraftError(f"unknown variant {self.variant!r}; choose one of {VARIANTS}")
        if self.secondary_surfaces not in ("held", "fcs"):
            raise AircraftError(f"secondary_surfaces must be 'held' or 'fcs', not {self.secondary_surfaces!r}")

    @property
    def surfaces(self) -> dict[str, str]:
        """Surface name ('de', 'da', 'dr') to the JSBSim property the aerodynamics read."""
        if is_xml_model(self.model):
            return xml_surface_properties(self.model)
        return SURFACE_PROPERTIES[self.model]

    @property
    def name(self) -> str:
        """The model's short name: 'f16', '737', 'dhc6', or an XML file's stem."""
        return Path(self.model).stem if is_xml_model(self.model) else self.model

    @property
    def label(self) -> str:
        base = self.name if self.variant == "nominal" else f"{self.name}/{self.variant}"
        base += "" if self.aero_reference == "project" else f"@rp-{self.aero_reference}"
        return base + "".join(f"+{e.effect}" for e in self.hidden)


def is_xml_model(model: str) -> bool:
    """Whether ``model`` is the path of a JSBSim aircraft XML rather than a project model name."""
    return str(model).lower().endswith(".xml")


def library_xml(name: str) -> Path | None:
    """The jsbsim package's aircraft XML for a library name (``c172x``, ``A320``: its
    ``aircraft/<name>/<name>.xml``, the name matched without regard to case when only one
    matches), or None. The project's own models are not looked up here."""
    folder = package_root() / "aircraft"
    exact = folder / name / f"{name}.xml"
    if exact.is_file():
        return exact
    matches = [p for p in folder.glob("*/*.xml") if p.stem.lower() == str(name).lower()
               and p.parent.name.lower() == str(name).lower()]
    return matches[0] if len(matches) == 1 else None


def model_argument(model: str) -> str:
    """A ``--model``/``--aircraft`` argument as the project reads it: a project model name in
    any case (``F16``, ``DHC6``: the project's model, configured as it flies, not the package's
    file) or an XML path as given, a name of the jsbsim package's aircraft library
    (:func:`library_xml`) as the path of its XML, anything else unchanged (the caller refuses
    it)."""
    if is_xml_model(model):
        return model
    if str(model).lower() in MODELS:
        return str(model).lower()
    found = library_xml(model)
    return str(found) if found is not None else model


MODEL_ARGUMENT_HELP = ("one of the project's models {models}, the name of an aircraft in the jsbsim package's "
                       "library (c172x, A320, …) or the path of a JSBSim aircraft XML (<name>.xml)")


def model_xml(model: str) -> Path:
    """The aircraft XML a model is built from: the package's, or the file given by path."""
    if is_xml_model(model):
        return Path(model).resolve()
    name = PACKAGE_NAMES[model]
    return package_root() / "aircraft" / name / f"{name}.xml"


def is_turboprop(model: str) -> bool:
    """Whether the model's engines are JSBSim turboprops (they need :func:`models.trim.trim`'s
    engine handling): the DHC6, or an XML whose engine files are ``<turboprop_engine>``."""
    if not is_xml_model(model):
        return model in TURBOPROP_MODELS
    source = model_xml(model)
    prop = ET.parse(source).getroot().find("propulsion")
    places = (engine_root(source) / "engine", source.parent, source.parent / "Engines")
    for el in (prop.findall("engine") if prop is not None else []):
        for d in places:
            path = d / f"{el.get('file', '')}.xml"
            if path.is_file():
                if ET.parse(path).getroot().tag == "turboprop_engine":
                    return True
                break
    return False


def has_propeller(model: str) -> bool:
    """Whether any of the model's thrusters is a JSBSim ``<propeller>`` (its torque, P-factor
    and slipstream then change with airspeed at a fixed throttle, outside the aerodynamics;
    read once per version of the aircraft file, as :func:`aerodynamics_reads`)."""
    source = model_xml(model)
    return _has_propeller(source, source.stat().st_mtime_ns)


@functools.lru_cache(maxsize=64)
def _has_propeller(source: Path, _mtime_ns: int) -> bool:
    prop = ET.parse(source).getroot().find("propulsion")
    places = (engine_root(source) / "engine", source.parent, source.parent / "Engines")
    for el in (prop.iter("thruster") if prop is not None else []):
        name = el.get("file", "")
        files = (name,) if name.endswith(".xml") else (name, f"{name}.xml")
        for path in (d / f for d in places for f in files):
            if path.is_file():
                if ET.parse(path).getroot().tag == "propeller":
                    return True
                break
    return False


def missing_files(model: str) -> list[str]:
    """The engine, thruster and system files an aircraft XML given by path names but JSBSim
    would not find (engines in ``<root>/engine``, beside the XML or in its ``Engines/``;
    systems beside it, in its ``Systems/`` or in ``<root>/systems``)."""
    source = model_xml(model)
    root = ET.parse(source).getroot()
    engines = engine_root(source)
    missing = []
    for el in root.iter():
        name = el.get("file")
        if not name or el.tag not in ("engine", "thruster", "system"):
            continue
        places = ([engines / "engine", source.parent, source.parent / "Engines"] if el.tag != "system"
                  else [source.parent, source.parent / "Systems", engines / "systems"])
        files = (name,) if name.endswith(".xml") else (name, f"{name}.xml")
        if not any((d / f).is_file() for d in places for f in files):
            missing.append(f"{el.tag} file {name!r} (looked in {', '.join(str(d) for d in places)})")
    return missing


def aerodynamics_reads(model: str) -> frozenset[str]:
    """The properties an aircraft XML's ``<aerodynamics>`` reads (``<property>`` and
    ``<independentVar>`` elements), read once per version of the file (a diagnosis asks about
    a hundred times: the parses were a twelfth of its time)."""
    source = model_xml(model)
    return _aerodynamics_reads(source, source.stat().st_mtime_ns)


@functools.lru_cache(maxsize=64)
def _aerodynamics_reads(source: Path, _mtime_ns: int) -> frozenset[str]:
    aero = ET.parse(source).getroot().find("aerodynamics")
    if aero is None:
        return frozenset()
    return frozenset((el.text or "").strip() for el in aero.iter() if el.tag in ("property", "independentVar"))


def xml_surface_properties(model: str) -> dict[str, str]:
    """The surface properties an aircraft XML's aerodynamics read (``SURFACE_CANDIDATES``).

    Raises
    ------
    ValueError
        Naming the surface none of whose candidate properties the aerodynamics read.
    """
    read = aerodynamics_reads(model)
    out = {}
    for s, props in SURFACE_CANDIDATES.items():
        found = [p for p in props if p in read]
        if not found:
            word = props[0].split("/")[1].split("-")[0]  # 'elevator', 'aileron', 'rudder'
            other = sorted(p for p in read if p.startswith("fcs/") and word in p and "mag-" not in p)
            instead = (f" (they read {', '.join(other)} instead: a position in other units, which the XML "
                       "does not relate to the recording's radians)" if other else "")
            raise AircraftError(f"{model}: its aerodynamics read none of {props}{instead}, so the {s} input "
                                "has nowhere to go (the project drives these surface properties directly)")
        out[s] = found[0]
    return out


def other_fcs_properties(model: str, surfaces: dict[str, str]) -> tuple[str, ...]:
    """The ``fcs/`` properties an aircraft XML's aerodynamics read beyond the three surfaces it
    is driven by (``surfaces``) and the magnitudes JSBSim ties to them (``fcs/mag-*``): flaps,
    speed brakes, the F-16's leading-edge flap and flaperons. The project flies and evaluates the
    model with its FCS disabled, so these stay where trim put them; a recording flown with the
    FCS on may have moved them."""
    primary = set(surfaces.values())
    return tuple(p for p in sorted(aerodynamics_reads(model)) if p.startswith("fcs/") and p not in primary
                 and not (p.startswith("fcs/mag-") and p.replace("fcs/mag-", "fcs/") in primary))


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
    if is_xml_model(model):
        try:
            return strip_io(ET.parse(model_xml(model)))
        except ET.ParseError as exc:
            raise AircraftError(f"{model} is not a readable JSBSim aircraft XML: {exc}") from exc
    return strip_io(aircraft_xml(PACKAGE_NAMES[model]))


def nominal_root(model: str) -> tuple[Path | None, str]:
    """Root folder and aircraft name of the nominal model (a stripped copy for the 737, a
    copy for the DHC6: see :func:`dhc6_tree`; a copy of an XML given by path, its sibling
    files and its root's engines linked beside it)."""
    if model == "737":
        return cached_root("737", strip_io(aircraft_xml("737")), model_xml(model)), "737"
    if is_xml_model(model) and (missing := missing_files(model)):
        raise AircraftError(f"{model} names files JSBSim will not find: {'; '.join(missing)}")
    if model == "dhc6" or is_xml_model(model):
        name = PACKAGE_NAMES.get(model) or Path(model).stem
        return cached_root(name, nominal_tree(model), model_xml(model)), name
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
    fdm = new_fdm(root, name or aircraft.name, dt)
    for e in aircraft.hidden:
        if e.effect == "control_delay":
            from models.hidden import delay_property
            fdm[delay_property(e.surface)] = 0.0  # the aerodynamics read it from the first run_ic
    return fdm


def reference_on_cg(aircraft: Aircraft) -> bool:
    """Whether ``aircraft`` flies with its aerodynamic reference point on the c.g.
    (:attr:`Aircraft.aero_reference`; the project puts the 737's there so that its
    derivatives are its XML's constants, shared/jsbsim-notes.md)."""
    if aircraft.aero_reference == "project":
        return aircraft.model == "737" or aircraft.variant == "exact-truth"
    return aircraft.aero_reference == "cg"


def reference_point_alternative(aircraft: Aircraft) -> Aircraft | None:
    """``aircraft`` with its aerodynamic reference point placed the other way, for a model the
    project flies with it moved (:data:`MOVED_REFERENCE_MODELS`: the 737 on its c.g. where
    JSBSim ships it 1.2 ft aft and 4.9 ft above; its XML copy with a recording's mass, flown
    as it is, then has the c.g. as the alternative); None for every other model or variant.
    A recording made by someone else's script may have been flown either way."""
    if aircraft.variant != "nominal" or aircraft.name not in MOVED_REFERENCE_MODELS:
        return None
    if reference_on_cg(aircraft):
        return replace(aircraft, aero_reference="xml")
    on_cg = replace(aircraft, aero_reference="project")
    return on_cg if reference_on_cg(on_cg) else replace(aircraft, aero_reference="cg")


def placement(aircraft: Aircraft) -> str:
    """``aircraft``'s aerodynamic reference point as an explicit :attr:`Aircraft.aero_reference`
    (``'cg'`` or ``'xml'``): the same placement for another :class:`Aircraft` of the same XML
    (a calibration's copy with a recording's mass)."""
    return "cg" if reference_on_cg(aircraft) else "xml"


def reference_point_text(aircraft: Aircraft) -> str:
    """Where ``aircraft``'s aerodynamic reference point is, in words."""
    return "on the c.g." if reference_on_cg(aircraft) else "at the XML's AERORP"


def place_reference_point(fdm: jsbsim.FGFDMExec, aircraft: Aircraft) -> bool:
    """Apply the variant's aerodynamic reference point (needs the mass model: after run_ic).

    Returns whether it moved (the caller then re-initialises)."""
    moved = reference_on_cg(aircraft) or aircraft.variant == "unstable"
    if reference_on_cg(aircraft):
        # Moments about the c.g.: put the aerodynamic reference point on it.
        for ax in "xyz":
            fdm[f"metrics/aero-rp-{ax}-in"] = fdm[f"inertia/cg-{ax}-in"]
    if aircraft.variant == "unstable":
        # JSBSim's structural x axis points aft: forward is more negative.
        fdm["metrics/aero-rp-x-in"] = fdm["metrics/aero-rp-x-in"] - aircraft.rp_shift_in
    return moved
