"""Truth: non-dimensional stability and control derivatives from JSBSim's own aerodynamics.

Derivatives are about the c.g., per rad, with rates normalised as p̂ = pb/2V, q̂ = qc̄/2V,
r̂ = rb/2V. Two definitions are stored for each, because the tables are piecewise linear:

- ``local``: the slope at trim, by central differences small enough to stay inside the
  table segment that holds the trim point;
- ``fit``: the least-squares slope of a straight line through the coefficient evaluated over
  the maneuver's excursion of that variable (the others held at trim).

Each evaluation writes the state into JSBSim's initial conditions, calls ``run_ic()`` and
reads the aerodynamic forces and moments (~0.2 ms). ``run_ic`` also sets α̇ (and β̇) from
the state derivative, so a q perturbation would pick up any α̇ term: the differencing copy of
the aircraft multiplies every α̇/β̇ reference of its aerodynamics by a gain property held at
zero (α̇ derivatives are then measured on their own, by switching that gain on).
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import jsbsim
import numpy as np

from models.aircraft import Aircraft, load_fdm, model_xml, nominal_tree
from models.conditions import FlightCondition
from models.jsbsim_root import cached_root
from models.trim import TrimPoint, place_untrimmed, trim
from models.axes import wind_axis_coefficients

LONGITUDINAL_COEFFICIENTS = ("CL", "CD", "CX", "CZ", "Cm")
LONGITUDINAL_VARIABLES = ("alpha", "qhat", "de")
LATERAL_COEFFICIENTS = ("CY", "Cl", "Cn")
LATERAL_VARIABLES = ("beta", "phat", "rhat", "da", "dr")
DERIVATIVE_NAMES = tuple(
    [f"{c}_{v}" for c in LONGITUDINAL_COEFFICIENTS for v in LONGITUDINAL_VARIABLES]
    + [f"{c}_{v}" for c in LATERAL_COEFFICIENTS for v in LATERAL_VARIABLES])

# Central-difference steps (rad, or non-dimensional rate). 1e-3 rad = 0.057 deg keeps the
# stencil inside one table segment whenever trim lies more than that from a breakpoint.
STEPS = {"alpha": 1e-3, "beta": 1e-3, "qhat": 1e-3, "phat": 1e-3, "rhat": 1e-3,
         "de": 1e-3, "da": 1e-3, "dr": 1e-3}
UNSTEADY_GAIN = "sidbench/unsteady-gain"


@dataclass(frozen=True)
class Derivatives:
    """Truth derivatives of one aircraft at one trim point.

    ``local[name]`` and ``fit[name]`` are per rad (rates normalised); ``trim_coefficients``
    are the coefficients at trim; ``excursion`` the variable ranges the fit used;
    ``unsteady`` any α̇ / β̇ derivatives found (e.g. ``Cm_alphadot``, α̇ normalised by c̄/2V).
    """

    aircraft: str
    condition: dict
    local: dict[str, float]
    fit: dict[str, float]
    trim_coefficients: dict[str, float]
    excursion: dict[str, tuple[float, float]]
    unsteady: dict[str, float] = field(default_factory=dict)

    def value(self, name: str, definition: str = "local") -> float:
        """A derivative by name under the chosen definition ('local' or 'fit')."""
        table = {"local": self.local, "fit": self.fit}.get(definition)
        if table is None:
            raise ValueError(f"truth definition must be 'local' or 'fit', not {definition!r}")
        if name in table:
            return table[name]
        if name in self.unsteady:
            return self.unsteady[name]
        raise KeyError(f"no truth derivative {name!r}; known: {sorted(table) + sorted(self.unsteady)}")

    @classmethod
    def from_dict(cls, d: Mapping) -> "Derivatives":
        """Inverse of :meth:`as_dict` (e.g. from a recording's ``meta['truth']``)."""
        derivs = d["derivatives"]
        steady = {k: v for k, v in derivs.items() if not k.endswith("_alphadot")}
        return cls(aircraft=d["aircraft"], condition=dict(d["condition"]),
                   local={k: v["local"] for k, v in steady.items()},
                   fit={k: v["fit"] for k, v in steady.items()},
                   trim_coefficients=dict(d["trim_coefficients"]),
                   excursion={k: tuple(v) for k, v in d.get("excursion", {}).items()},
                   unsteady={k: v["local"] for k, v in derivs.items() if k.endswith("_alphadot")})

    def as_dict(self) -> dict:
        """The JSON form written by ``sidbench truth``."""
        derivs = {n: {"local": self.local[n], "fit": self.fit[n]} for n in self.local}
        for n, v in self.unsteady.items():
            derivs[n] = {"local": v, "fit": v}
        return {"aircraft": self.aircraft, "condition": self.condition,
                "derivatives": derivs, "trim_coefficients": self.trim_coefficients,
                "excursion": {k: list(v) for k, v in self.excursion.items()},
                "units": "per rad about the c.g.; rates normalised by cbar/2V (q) and b/2V (p, r)"}


def gate_unsteady_terms(tree: ET.ElementTree) -> tuple[ET.ElementTree, bool]:
    """Multiply every α̇ / β̇ reference in ``<aerodynamics>`` by ``sidbench/unsteady-gain``.

    Returns the modified tree and whether anything was gated. The gated rates are defined as
    aerodynamics-level functions so tables that look them up keep working.
    """
    aero = tree.getroot().find("aerodynamics")
    if aero is None:
        return tree, False
    found = False
    for el in aero.iter():
        if el.tag in ("property", "independentVar") and el.text:
            name = el.text.strip()
            if name in ("aero/alphadot-rad_sec", "aero/betadot-rad_sec"):
                el.text = "sidbench/" + name.split("/")[1]
                found = True
    if found:
        for rate in ("alphadot-rad_sec", "betadot-rad_sec"):
            fn = ET.Element("function", name=f"sidbench/{rate}")
            prod = ET.SubElement(fn, "product")
            ET.SubElement(prod, "property").text = f"aero/{rate}"
            ET.SubElement(prod, "property").text = UNSTEADY_GAIN
            aero.insert(0, fn)
    return tree, found


class CoefficientProbe:
    """Evaluates JSBSim's aerodynamic coefficients at states near trim (run_ic based)."""

    def __init__(self, fdm: jsbsim.FGFDMExec, aircraft: Aircraft, trim_point: TrimPoint,
                 has_unsteady: bool) -> None:
        self.fdm, self.aircraft, self.tp = fdm, aircraft, trim_point
        self.has_unsteady = has_unsteady
        fdm["simulation/models/FGFCS/enabled"] = 0
        if has_unsteady:
            fdm[UNSTEADY_GAIN] = 0.0
        tp = trim_point
        self.rate_scale = {"phat": 2 * tp.V_fps / tp.b_ft, "qhat": 2 * tp.V_fps / tp.cbar_ft,
                           "rhat": 2 * tp.V_fps / tp.b_ft}

    def evaluate(self, **dx: float) -> dict[str, float]:
        """Coefficients at trim plus perturbations ``dx`` (alpha, beta, phat, qhat, rhat in
        rad / normalised; de, da, dr in rad)."""
        fdm, tp = self.fdm, self.tp
        fdm["ic/lat-gc-deg"] = 0.0
        fdm["ic/long-gc-deg"] = 0.0
        fdm["ic/h-sl-ft"] = tp.h_ft
        fdm["ic/vt-fps"] = tp.V_fps
        fdm["ic/alpha-rad"] = tp.alpha_rad + dx.get("alpha", 0.0)
        fdm["ic/beta-rad"] = tp.beta_rad + dx.get("beta", 0.0)
        fdm["ic/theta-rad"] = tp.theta_rad
        fdm["ic/phi-rad"] = tp.phi_rad
        for rate, prop in (("phat", "ic/p-rad_sec"), ("qhat", "ic/q-rad_sec"), ("rhat", "ic/r-rad_sec")):
            fdm[prop] = dx.get(rate, 0.0) * self.rate_scale[rate]
        surf = self.aircraft.surfaces
        for s, base in (("de", tp.de_rad), ("da", tp.da_rad), ("dr", tp.dr_rad)):
            fdm[surf[s]] = base + dx.get(s, 0.0)
        fdm.run_ic()
        return self.read()

    def read(self) -> dict[str, float]:
        fdm, tp = self.fdm, self.tp
        qS = fdm["aero/qbar-psf"] * tp.S_ft2
        X, Y, Z = (fdm[f"forces/fb{a}-aero-lbs"] for a in "xyz")
        L, M, N = (fdm[f"moments/{a}-aero-lbsft"] for a in "lmn")
        a = fdm["aero/alpha-rad"]
        CX, CZ = X / qS, Z / qS
        return {"CX": CX, "CY": Y / qS, "CZ": CZ, "Cl": L / (qS * tp.b_ft),
                "Cm": M / (qS * tp.cbar_ft), "Cn": N / (qS * tp.b_ft),
                **{k: float(v) for k, v in wind_axis_coefficients(CX, CZ, a).items()}}

    def propulsion_moments(self) -> dict[str, float]:
        """The propulsion's moment coefficients at the last ``run_ic``'s state beyond thrust
        times the trim's thrust line (the part seed Eq. 4 takes out of the measured C_m with the
        recorded thrust): a propeller's gyroscopic moments (its spin times the body rates: a
        yaw rate pitches, a pitch rate yaws) and the change of each propeller's inflow with the
        rates. The DHC6's two propellers (25.1 slug·ft² each, aircraft/DHC6/Engines/Propeller.xml)
        at 1,431 rpm give −752 lbf·ft of pitching moment at r = 0.1 rad/s, a C_m of −0.005 at
        230 ft/s and 6,000 ft. Zero for a jet, whose propulsion moment is its thrust line's."""
        fdm, tp = self.fdm, self.tp
        qS = fdm["aero/qbar-psf"] * tp.S_ft2
        beyond_line = fdm["moments/m-prop-lbsft"] - fdm["forces/fbx-prop-lbs"] * tp.thrust_offset_ft
        return {"Cl": fdm["moments/l-prop-lbsft"] / (qS * tp.b_ft), "Cm": beyond_line / (qS * tp.cbar_ft),
                "Cn": fdm["moments/n-prop-lbsft"] / (qS * tp.b_ft)}

    def unsteady_derivatives(self) -> dict[str, float]:
        """α̇ derivatives (α̇ normalised by c̄/2V): the coefficient change when the gated α̇
        terms are switched on at a state with a known α̇, divided by that α̇."""
        if not self.has_unsteady:
            return {}
        fdm, tp = self.fdm, self.tp
        self.evaluate(qhat=0.01)
        off = self.read()
        fdm[UNSTEADY_GAIN] = 1.0
        fdm.run_ic()
        on = self.read()
        fdm[UNSTEADY_GAIN] = 0.0
        adot_hat = fdm["aero/alphadot-rad_sec"] * tp.cbar_ft / (2 * tp.V_fps)
        if abs(adot_hat) < 1e-9:
            return {}
        return {f"{c}_alphadot": (on[c] - off[c]) / adot_hat for c in ("CL", "CX", "CZ", "Cm")}


def _coefficient_names(var: str) -> tuple[str, ...]:
    return LONGITUDINAL_COEFFICIENTS if var in LONGITUDINAL_VARIABLES else LATERAL_COEFFICIENTS


def central_differences(probe: CoefficientProbe) -> dict[str, float]:
    """Local slopes at trim: (C(x+h) - C(x-h)) / 2h for every derivative name."""
    out = {}
    for var in LONGITUDINAL_VARIABLES + LATERAL_VARIABLES:
        h = STEPS[var]
        plus, minus = probe.evaluate(**{var: h}), probe.evaluate(**{var: -h})
        for c in _coefficient_names(var):
            out[f"{c}_{var}"] = (plus[c] - minus[c]) / (2 * h)
    return out


def excursion_fit(probe: CoefficientProbe, excursion: Mapping[str, tuple[float, float]],
                  local: Mapping[str, float], points: int = 41) -> dict[str, float]:
    """Least-squares slope of each coefficient over ``excursion[var] = (lo, hi)``.

    Variables whose excursion is narrower than twice the central-difference step keep the
    local slope (the maneuver did not move them)."""
    out = dict(local)
    for var in LONGITUDINAL_VARIABLES + LATERAL_VARIABLES:
        lo, hi = excursion.get(var, (0.0, 0.0))
        if hi - lo < 2 * STEPS[var]:
            continue
        xs = np.linspace(lo, hi, points)
        vals = [probe.evaluate(**{var: float(x)}) for x in xs]
        for c in _coefficient_names(var):
            y = np.array([v[c] for v in vals])
            out[f"{c}_{var}"] = float(np.polyfit(xs, y, 1)[0])
    return out


def excursion_from_history(channels: Mapping[str, np.ndarray], tp: TrimPoint) -> dict[str, tuple[float, float]]:
    """Ranges of each variable's perturbation from trim over a flight (normalised rates)."""
    V = channels["V_fps"]
    series = {
        "alpha": channels["alpha_rad"] - tp.alpha_rad, "beta": channels["beta_rad"] - tp.beta_rad,
        "phat": channels["p_rps"] * tp.b_ft / (2 * V), "qhat": channels["q_rps"] * tp.cbar_ft / (2 * V),
        "rhat": channels["r_rps"] * tp.b_ft / (2 * V),
        "de": channels["de_rad"] - tp.de_rad, "da": channels["da_rad"] - tp.da_rad,
        "dr": channels["dr_rad"] - tp.dr_rad,
    }
    return {k: (float(np.min(v)), float(np.max(v))) for k, v in series.items()}


def differencing_instance(aircraft: Aircraft, condition: FlightCondition, *,
                          root=None, name=None, dt: float = 1 / 120,
                          at: Mapping[str, float] | None = None) -> tuple[jsbsim.FGFDMExec, TrimPoint, bool]:
    """A trimmed instance of ``aircraft`` whose α̇/β̇ aerodynamic terms are gated (if any).

    With ``at`` (a state: ``alpha``, ``beta``, ``theta``, ``phi`` in rad, surfaces ``de``,
    ``da``, ``dr``) the instance is not trimmed but put at that state at the condition's
    altitude and airspeed (:func:`models.trim.place_untrimmed`): the derivatives are then
    those at a recorded state rather than at an equilibrium."""
    if root is None:
        tree, source = nominal_tree(aircraft.model), model_xml(aircraft.model)
    else:
        source = Path(root) / "aircraft" / name / f"{name}.xml"
        tree = ET.parse(source)
    tree, gated = gate_unsteady_terms(tree)
    if gated or root is not None:
        groot = cached_root(f"{name or aircraft.name}-diff", tree, source)
        fdm = load_fdm(aircraft, dt, root=groot, name=f"{name or aircraft.name}-diff")
    else:
        fdm = load_fdm(aircraft, dt)
    if gated:
        fdm[UNSTEADY_GAIN] = 1.0  # trim with the aircraft as it flies
    tp = trim(fdm, aircraft, condition) if at is None else place_untrimmed(fdm, aircraft, condition, at)
    return fdm, tp, gated


def truth_derivatives(aircraft: Aircraft, condition: FlightCondition,
                      excursion: Mapping[str, tuple[float, float]] | None = None, *,
                      root=None, name=None) -> Derivatives:
    """Truth derivatives of ``aircraft`` trimmed at ``condition``.

    ``excursion`` gives the (lo, hi) perturbation range of each variable for the ``fit``
    definition (see :func:`excursion_from_history`); without it ``fit`` equals ``local``.
    """
    fdm, tp, gated = differencing_instance(aircraft, condition, root=root, name=name)
    probe = CoefficientProbe(fdm, aircraft, tp, gated)
    trim_coefficients = probe.evaluate()
    local = central_differences(probe)
    fit = excursion_fit(probe, excursion or {}, local)
    unsteady = probe.unsteady_derivatives()
    cond = {"name": condition.name, "h_ft": tp.h_ft, "V_fps": tp.V_fps, "alpha_rad": tp.alpha_rad,
            "theta_rad": tp.theta_rad, "qbar_psf": tp.qbar_psf, "mach": tp.mach,
            "de_rad": tp.de_rad, "da_rad": tp.da_rad, "dr_rad": tp.dr_rad, "thrust_lbf": tp.thrust_lbf}
    return Derivatives(aircraft=aircraft.label, condition=cond, local=local, fit=fit,
                       trim_coefficients=trim_coefficients,
                       excursion=dict(excursion or {}), unsteady=unsteady)
