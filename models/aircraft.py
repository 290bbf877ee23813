"""Which aircraft to fly, in which variant, and loading it into JSBSim."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import jsbsim

from models.jsbsim_root import aircraft_xml, cached_root, strip_io

VARIANTS = ("nominal", "exact-truth", "unstable")
MODELS = ("f16", "737")

# The surface positions each model's aerodynamics read (JSBSim signs: de trailing edge down).
SURFACE_PROPERTIES: dict[str, dict[str, str]] = {
    "f16": {"de": "fcs/elevator-pos-rad", "da": "fcs/aileron-pos-rad", "dr": "fcs/rudder-pos-rad"},
    "737": {"de": "fcs/elevator-pos-rad", "da": "fcs/left-aileron-pos-rad", "dr": "fcs/rudder-pos-rad"},
}


@dataclass(frozen=True)
class Aircraft:
    """An aircraft model and variant.

    Attributes
    ----------
    model : str
        JSBSim model: ``'f16'`` (tabulated, nonlinear aerodynamics) or ``'737'`` (mostly
        constant coefficients).
    variant : str
        ``'nominal'``: the package's aircraft (the 737 with its socket input stripped and its
        aerodynamic reference point moved onto the c.g., so its derivatives equal the XML
        constants). ``'exact-truth'``: aerodynamics replaced by functions exactly linear in the
        states with the nominal's truth derivatives at the flight condition (seed §III.C: no
        model-structure error). ``'unstable'``: the aerodynamic reference point moved forward
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


def nominal_root(model: str) -> tuple[Path | None, str]:
    """Root folder and aircraft name of the nominal model (a stripped copy for the 737)."""
    if model == "737":
        return cached_root("737", strip_io(aircraft_xml("737")), "737"), "737"
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
