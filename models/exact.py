"""The exact-truth variant: aerodynamics exactly linear in the states (seed §III.C).

The nominal aircraft's local truth derivatives at a trim point become the constant slopes of
new body-axis aerodynamics:

    CX = CX₀ + CX_α Δα + CX_q̂ q̂ + CX_δe Δδe          (likewise CZ, Cm)
    CY = CY₀ + CY_β Δβ + CY_p̂ p̂ + CY_r̂ r̂ + CY_δa Δδa + CY_δr Δδr   (likewise Cl, Cn)

with Δ meaning the difference from trim and p̂ = p·b/2V, q̂ = q·c̄/2V, r̂ = r·b/2V formed with
the instantaneous airspeed (JSBSim's ``aero/bi2vel`` and ``aero/ci2vel``). The moments are
taken about the c.g. (the reference point is put on it). JSBSim's full nonlinear equations of
motion still fly it, so an estimator scored on it faces noise and data problems but no
model-structure error. Its planet does not rotate (see :func:`exact_truth_tree`). CL and CD follow from CX and CZ through Eq. 2 and are therefore not
exactly linear in α.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from models.aircraft import Aircraft, model_xml, nominal_tree
from models.conditions import FlightCondition
from models.jsbsim_root import cached_root, write_root
from models.truth import LATERAL_VARIABLES, LONGITUDINAL_VARIABLES, Derivatives, truth_derivatives

# Axis -> (coefficient, reference length property or None, variables)
_AXES = (
    ("X", "CX", None, LONGITUDINAL_VARIABLES),
    ("Z", "CZ", None, LONGITUDINAL_VARIABLES),
    ("PITCH", "Cm", "metrics/cbarw-ft", LONGITUDINAL_VARIABLES),
    ("Y", "CY", None, LATERAL_VARIABLES),
    ("ROLL", "Cl", "metrics/bw-ft", LATERAL_VARIABLES),
    ("YAW", "Cn", "metrics/bw-ft", LATERAL_VARIABLES),
)


def _value(parent: ET.Element, x: float) -> None:
    ET.SubElement(parent, "value").text = repr(float(x))


def _prop(parent: ET.Element, name: str) -> None:
    ET.SubElement(parent, "property").text = name


def _variable(parent: ET.Element, var: str, surfaces: dict[str, str], trim: dict) -> None:
    """Append the perturbation of ``var`` from trim as a JSBSim function element."""
    if var in ("qhat", "phat", "rhat"):
        prod = ET.SubElement(parent, "product")
        _prop(prod, {"qhat": "velocities/q-aero-rad_sec", "phat": "velocities/p-aero-rad_sec",
                     "rhat": "velocities/r-aero-rad_sec"}[var])
        _prop(prod, "aero/ci2vel" if var == "qhat" else "aero/bi2vel")
        return
    prop, ref = {"alpha": ("aero/alpha-rad", trim["alpha_rad"]), "beta": ("aero/beta-rad", 0.0),
                 "de": (surfaces["de"], trim["de_rad"]), "da": (surfaces["da"], trim["da_rad"]),
                 "dr": (surfaces["dr"], trim["dr_rad"])}[var]
    diff = ET.SubElement(parent, "difference")
    _prop(diff, prop)
    _value(diff, ref)


def linear_aerodynamics(truth: Derivatives, surfaces: dict[str, str]) -> ET.Element:
    """An ``<aerodynamics>`` element exactly linear in the states with ``truth.local`` slopes."""
    aero = ET.Element("aerodynamics")
    for axis, coef, length, variables in _AXES:
        ax = ET.SubElement(aero, "axis", name=axis)
        fn = ET.SubElement(ax, "function", name=f"aero/coefficient/{coef}_linear")
        ET.SubElement(fn, "description").text = f"{coef} exactly linear in the states (sidbench exact-truth)"
        prod = ET.SubElement(fn, "product")
        _prop(prod, "aero/qbar-psf")
        _prop(prod, "metrics/Sw-sqft")
        if length:
            _prop(prod, length)
        total = ET.SubElement(prod, "sum")
        _value(total, truth.trim_coefficients[coef])
        for var in variables:
            term = ET.SubElement(total, "product")
            _value(term, truth.local[f"{coef}_{var}"])
            _variable(term, var, surfaces, truth.condition)
    return aero


def exact_truth_tree(aircraft: Aircraft, condition: FlightCondition) -> tuple[ET.ElementTree, Derivatives]:
    """The exact-truth aircraft XML for ``aircraft.model`` at ``condition``, and the nominal
    truth it was built from."""
    nominal = Aircraft(aircraft.model, "nominal")
    truth = truth_derivatives(nominal, condition)
    tree = nominal_tree(aircraft.model)
    root = tree.getroot()
    old = root.find("aerodynamics")
    index = list(root).index(old)
    root.remove(old)
    root.insert(index, linear_aerodynamics(truth, nominal.surfaces))
    # A non-rotating planet: inertial and Earth-relative rates coincide, so Eqs. 3-5 written
    # with the recorded rates hold exactly (with Earth's rotation they are off by ~1e-7 in
    # Cm, which costs ~1e-5 relative on the smaller derivatives).
    planet = ET.Element("planet")
    ET.SubElement(planet, "rotation_rate", unit="RAD/SEC").text = "0.0"
    root.insert(1, planet)
    return tree, truth


def exact_truth_root(aircraft: Aircraft, condition: FlightCondition,
                     dest: Path | None = None) -> tuple[Path, str]:
    """Write the exact-truth aircraft and return ``(root, name)`` for loading it.

    With ``dest`` the root is written there (for a user to fly it); otherwise into a shared
    cache folder keyed by the XML's content.
    """
    tree, _ = exact_truth_tree(aircraft, condition)
    name = f"{aircraft.name}-exact"
    if dest is not None:
        return write_root(Path(dest), name, tree, model_xml(aircraft.model)), name
    return cached_root(name, tree, model_xml(aircraft.model)), name
