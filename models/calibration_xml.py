"""Named adjustments of a JSBSim aircraft XML: the parameters a calibration estimates.

Four kinds, each a :class:`Adjustment` parsed from its name (:func:`parse_adjustment`):

- ``FUNCTION:scale`` — the aerodynamic ``<function name=FUNCTION>`` multiplied by k
  (start 1): f' = k·f.
- ``FUNCTION:increment`` — Δ added in coefficient units: f' = f + Δ·q̄S (force axes),
  f' = f + Δ·q̄Sb (roll, yaw) or f' = f + Δ·q̄Sc̄ (pitch) for a function that is a term of an
  ``<axis>``; f' = f + Δ for any other function (start 0).
- a term of the diagnosis's vocabulary (``../shared/effects.md``), named as
  :attr:`models.hidden.HiddenEffect.parameter` names it: ``Cm_alphadot`` (C_m += s·α̇c̄/2V),
  ``Cn_beta`` (C_n += s·β), ``Cl_beta_abs`` (C_l += s·|β|), ``Cm_alpha2``, ``Cn_alpha_beta``,
  ``Cm_dV``, ``dx_moment_reference`` ...; written by :func:`models.hidden.add_hidden_aerodynamics`
  (start 0);
- ``tau_de``, ``tau_da``, ``tau_dr`` — a transport delay of the surface (s, start 0). In the
  calibration's own flights the loop feeds the aerodynamics δ(t − τ) (continuous in τ); in
  the stock XML (:func:`with_actuator_delays`) it is a JSBSim ``<actuator>`` with a
  ``<delay>``, which JSBSim rounds down to whole frames;
- mass and reference point: ``ixx:scale``, ``iyy:scale``, ``izz:scale``,
  ``emptywt:scale``, ``ixz:increment`` (slug·ft²), ``cg_x:increment``, ``cg_y``, ``cg_z``
  (the empty-weight c.g., inches) and ``aero_rp_x:increment``, ``aero_rp_z`` (the
  aerodynamic reference point, inches; JSBSim's x points aft).

``NAME=VALUE`` gives a start other than the neutral one.
"""
from __future__ import annotations

import copy
import difflib
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from models.constants import SURFACES
from models.hidden import COEFFICIENTS, REGRESSORS, HiddenEffect, add_hidden_aerodynamics

KINDS = ("scale", "increment", "term", "delay", "mass")
MASS_SCALES = ("ixx", "iyy", "izz", "emptywt")
MASS_INCREMENTS = ("ixz", "cg_x", "cg_y", "cg_z", "aero_rp_x", "aero_rp_y", "aero_rp_z")
# Axis name -> the reference length property of its coefficient (None: a force axis).
_AXIS_LENGTH = {"DRAG": None, "SIDE": None, "LIFT": None, "X": None, "Y": None, "Z": None,
                "ROLL": "metrics/bw-ft", "YAW": "metrics/bw-ft", "PITCH": "metrics/cbarw-ft"}
_INCHES = {"IN": 1.0, "FT": 12.0, "M": 39.37007874015748}
_SLUGFT2 = {"SLUG*FT2": 1.0, "KG*M2": 1.0 / 1.35581794833}


@dataclass(frozen=True)
class Adjustment:
    """One calibrated parameter.

    Attributes
    ----------
    name : the name as given (without ``=start``): reported in calibration.json.
    kind : one of :data:`KINDS`.
    target : the function name (scale, increment), the vocabulary parameter (term), the
        surface (delay) or the mass item (mass).
    start : the starting value.
    units : its units as reported.
    typical : a typical magnitude (finite-difference steps are 1 % of max(|value|, typical)).
    lower : the smallest value allowed (a delay and a scale of a mass property are ≥ 0).
    """

    name: str
    kind: str
    target: str
    start: float
    units: str
    typical: float = 1.0
    lower: float = -math.inf

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown adjustment kind {self.kind!r}; choose one of {KINDS}")
        if not math.isfinite(self.start):
            raise ValueError(f"parameter {self.name}: the start must be a finite number")


def vocabulary() -> dict[str, HiddenEffect]:
    """Every aerodynamic term of the diagnosis's vocabulary by parameter name (size 0)."""
    effects = [HiddenEffect("cg_offset", 0.0)]
    for c in COEFFICIENTS:
        effects += [HiddenEffect("unsteady_alphadot", 0.0, coefficient=c),
                    HiddenEffect("nonlinear_alpha", 0.0, coefficient=c, power=2),
                    HiddenEffect("nonlinear_alpha", 0.0, coefficient=c, power=3),
                    HiddenEffect("cross_coupling", 0.0, coefficient=c),
                    HiddenEffect("cross_coupling", 0.0, coefficient=c, regressor="beta_abs"),
                    HiddenEffect("flight_condition_drift", 0.0, coefficient=c)]
        effects += [HiddenEffect("coefficient_error", 0.0, coefficient=c, regressor=r) for r in REGRESSORS]
    return {e.parameter: e for e in effects}


def _term_units(e: HiddenEffect) -> str:
    if e.effect == "cg_offset":
        return "ft"
    if e.effect == "nonlinear_alpha":
        return f"1/rad^{e.power}"
    if e.effect == "cross_coupling":
        return "1/rad" if e.regressor == "beta_abs" else "1/rad^2"
    if e.effect == "flight_condition_drift" or e.regressor in ("phat", "qhat", "rhat"):
        return "1"
    return "1/rad"


def parse_adjustment(text: str) -> Adjustment:
    """An :class:`Adjustment` from its name (module docstring), ``NAME[=START]``.

    Raises
    ------
    ValueError
        Naming the text and the accepted forms.
    """
    raw = text.strip()
    name, _, start_text = raw.partition("=")
    name = name.strip()
    start = None
    if start_text.strip():
        try:
            start = float(start_text)
        except ValueError:
            raise ValueError(f"parameter {raw!r}: the start after '=' must be a number") from None
    if not name:
        raise ValueError("an empty parameter name")
    head, sep, op = name.rpartition(":")
    if sep:
        if op not in ("scale", "increment"):
            raise ValueError(f"parameter {name!r}: the adjustment after ':' must be 'scale' or 'increment', "
                             f"not {op!r}")
        if head in MASS_SCALES + MASS_INCREMENTS:
            if (op == "scale") != (head in MASS_SCALES):
                want = "scale" if head in MASS_SCALES else "increment"
                raise ValueError(f"parameter {name!r}: {head} takes ':{want}'")
            units = "1" if op == "scale" else ("slug*ft^2" if head == "ixz" else "in")
            return Adjustment(name, "mass", head, 1.0 if start is None and op == "scale" else (start or 0.0),
                              units, typical=1.0, lower=0.0 if op == "scale" else -math.inf)
        if op == "scale":
            return Adjustment(name, "scale", head, 1.0 if start is None else start, "1", typical=1.0)
        return Adjustment(name, "increment", head, 0.0 if start is None else start, "coefficient", typical=0.01)
    if name.startswith("tau_"):
        surface = name[4:]
        if surface not in SURFACES:
            raise ValueError(f"parameter {name!r}: a delay is tau_de, tau_da or tau_dr")
        return Adjustment(name, "delay", surface, 0.0 if start is None else start, "s", typical=0.02, lower=0.0)
    terms = vocabulary()
    if name in terms:
        return Adjustment(name, "term", name, 0.0 if start is None else start, _term_units(terms[name]), typical=1.0)
    close = difflib.get_close_matches(name, list(terms) + ["tau_de", "tau_da", "tau_dr"], n=3)
    hint = f" (did you mean {', '.join(close)}?)" if close else ""
    raise ValueError(f"unknown parameter {name!r}{hint}: give FUNCTION:scale or FUNCTION:increment for a "
                     "<function> of the aircraft XML, a vocabulary term (Cm_alphadot, Cn_beta, Cl_beta_abs, ...), "
                     "tau_de|tau_da|tau_dr, or a mass item (iyy:scale, cg_x:increment, ...)")


def functions(tree: ET.ElementTree) -> dict[str, tuple[ET.Element, str | None]]:
    """The named ``<function>`` elements of the aerodynamics, each with the axis it is a term of
    (None for a function outside an axis)."""
    aero = tree.getroot().find("aerodynamics")
    out: dict[str, tuple[ET.Element, str | None]] = {}
    if aero is None:
        return out
    for fn in aero.iter("function"):
        if fn.get("name"):
            out[fn.get("name")] = (fn, None)
    for axis in aero.findall("axis"):
        for fn in axis.findall("function"):
            if fn.get("name"):
                out[fn.get("name")] = (fn, axis.get("name", "").upper())
    return out


def check_adjustments(tree: ET.ElementTree, adjustments: Sequence[Adjustment]) -> None:
    """Refuse a function the aircraft lacks (naming close ones), a missing mass item or a
    parameter given twice.

    Raises
    ------
    ValueError
    """
    seen: set[str] = set()
    for a in adjustments:
        if a.name in seen:
            raise ValueError(f"parameter {a.name!r} is given twice")
        seen.add(a.name)
    fns = functions(tree)
    for a in adjustments:
        if a.kind in ("scale", "increment") and a.target not in fns:
            close = difflib.get_close_matches(a.target, list(fns), n=3, cutoff=0.5)
            hint = f"; close: {', '.join(close)}" if close else ""
            raise ValueError(f"parameter {a.name!r}: the aircraft's aerodynamics have no <function name="
                             f"{a.target!r}>{hint} ({len(fns)} named functions)")
        if a.kind == "mass":
            _mass_element(tree.getroot(), a.target)


def _operation(fn: ET.Element) -> ET.Element:
    ops = [c for c in fn if c.tag != "description"]
    if len(ops) != 1:
        raise ValueError(f"function {fn.get('name')!r} has {len(ops)} operations (JSBSim expects one)")
    return ops[0]


def _value(parent: ET.Element, x: float) -> None:
    ET.SubElement(parent, "value").text = repr(float(x))


def _scale(fn: ET.Element, k: float) -> None:
    """f' = k·f (module docstring)."""
    op = _operation(fn)
    i = list(fn).index(op)
    fn.remove(op)
    prod = ET.Element("product")
    _value(prod, k)
    prod.append(op)
    fn.insert(i, prod)


def _increment(fn: ET.Element, axis: str | None, delta: float) -> None:
    """f' = f + Δ·q̄S[·ℓ] on an axis, f + Δ elsewhere (module docstring)."""
    op = _operation(fn)
    i = list(fn).index(op)
    fn.remove(op)
    total = ET.Element("sum")
    total.append(op)
    term = ET.SubElement(total, "product")
    _value(term, delta)
    if axis is not None:
        for p in ("aero/qbar-psf", "metrics/Sw-sqft") + ((_AXIS_LENGTH[axis],) if _AXIS_LENGTH.get(axis) else ()):
            ET.SubElement(term, "property").text = p
    fn.insert(i, total)


def _mass_element(root: ET.Element, item: str) -> tuple[ET.Element, str]:
    """The element a mass item changes and its coordinate (``x``, ``y``, ``z`` or '')."""
    if item.startswith("aero_rp_"):
        loc = next((el for el in root.find("metrics").findall("location") if el.get("name") == "AERORP"), None) \
            if root.find("metrics") is not None else None
        if loc is None:
            raise ValueError("the aircraft XML has no <metrics><location name=\"AERORP\">")
        return loc, item[-1]
    mb = root.find("mass_balance")
    if mb is None:
        raise ValueError("the aircraft XML has no <mass_balance>")
    if item.startswith("cg_"):
        loc = next((el for el in mb.findall("location") if el.get("name") == "CG"), None)
        if loc is None:
            raise ValueError("the aircraft XML has no <mass_balance><location name=\"CG\">")
        return loc, item[-1]
    el = mb.find(item)
    if el is None:
        raise ValueError(f"the aircraft XML's <mass_balance> has no <{item}>")
    return el, ""


def _adjust_mass(root: ET.Element, item: str, value: float) -> None:
    el, coord = _mass_element(root, item)
    if coord:
        c = el.find(coord)
        if c is None:
            c = ET.SubElement(el, coord)
            c.text = "0"
        per_in = 1.0 / _INCHES.get(el.get("unit", "IN").upper(), 1.0)
        c.text = repr(float(c.text) + value * per_in)
    elif item in MASS_SCALES:
        el.text = repr(float(el.text) * value)
    else:  # ixz increment, slug ft^2 in JSBSim's own sign (the XML's <ixz>)
        el.text = repr(float(el.text) + value * _SLUGFT2.get(el.get("unit", "SLUG*FT2").upper(), 1.0) ** -1)


def term_effects(adjustments: Sequence[Adjustment], values: Sequence[float]) -> tuple[HiddenEffect, ...]:
    """The vocabulary terms among ``adjustments`` as :class:`HiddenEffect` of their sizes."""
    terms = vocabulary()
    out = []
    for a, v in zip(adjustments, values):
        if a.kind == "term":
            e = terms[a.target]
            out.append(HiddenEffect(e.effect, float(v), coefficient=e.coefficient, regressor=e.regressor,
                                    power=e.power))
    return tuple(out)


def delays(adjustments: Sequence[Adjustment], values: Sequence[float]) -> dict[str, float]:
    """Surface -> delay (s) of the delay parameters."""
    return {a.target: float(v) for a, v in zip(adjustments, values) if a.kind == "delay"}


def adjusted_tree(tree: ET.ElementTree, adjustments: Sequence[Adjustment], values: Sequence[float], *,
                  refs: Mapping[str, float], surfaces: Mapping[str, str], in_place: bool = False) -> ET.ElementTree:
    """A copy of ``tree`` (``tree`` itself with ``in_place``) with every adjustment at its value
    (delays excepted: see :func:`with_actuator_delays`). ``refs`` are the trim references of
    the vocabulary terms (``alpha``, ``dV``, ``de`` ...: :func:`models.hidden.add_hidden_aerodynamics`)."""
    out = tree if in_place else copy.deepcopy(tree)
    fns = functions(out)
    for a, v in zip(adjustments, values):
        if a.kind == "scale":
            _scale(fns[a.target][0], v)
        elif a.kind == "increment":
            fn, axis = fns[a.target]
            _increment(fn, axis, v)
        elif a.kind == "mass":
            _adjust_mass(out.getroot(), a.target, v)
    effects = term_effects(adjustments, values)
    if effects:
        add_hidden_aerodynamics(out, effects, float(refs.get("alpha", 0.0)), dict(surfaces), dict(refs))
    return out


def delayed_property(surface: str) -> str:
    """The property the aerodynamics of the stock XML read for a delayed surface."""
    return f"sidbench/{surface}-delayed-rad"


def with_actuator_delays(tree: ET.ElementTree, delays_s: Mapping[str, float], surfaces: Mapping[str, str]
                         ) -> ET.ElementTree:
    """A copy of ``tree`` whose aerodynamics read each delayed surface through a JSBSim
    ``<actuator>`` with a ``<delay type="time">`` (a ``<system>`` of its own, run by JSBSim's
    flight-control model each frame): the XML flies in stock JSBSim. JSBSim rounds the delay
    down to whole frames."""
    out = copy.deepcopy(tree)
    active = {s: t for s, t in delays_s.items() if t > 0}
    if not active:
        return out
    root = out.getroot()
    system = ET.Element("system", name="sidbench-calibration")
    channel = ET.SubElement(system, "channel", name="actuator delays")
    aero = root.find("aerodynamics")
    for s, tau in active.items():
        prop = surfaces[s]
        act = ET.SubElement(channel, "actuator", name=delayed_property(s))
        ET.SubElement(act, "input").text = prop
        ET.SubElement(act, "delay", type="time").text = repr(float(tau))
        for el in aero.iter():
            if el.tag in ("property", "independentVar") and (el.text or "").strip() == prop:
                el.text = delayed_property(s)
    root.insert(list(root).index(aero), system)
    return out
