"""Aircraft with hidden physics: one effect of ``../shared/effects.md`` added to the F-16.

These variants make the concealed-effect recordings the discrepancy diagnosis must explain.
Each :class:`HiddenEffect` names an effect id and its size in the convention of effects.md:

- ``unsteady_alphadot``: a Cm_α̇ term, Cm += size · α̇c̄/2V (size per rad);
- ``nonlinear_alpha``: Cm += size · (α − α_ref)², α_ref the nominal trim α (size per rad²);
  zero with zero slope at trim, so the trim point and the local derivatives are unchanged;
- ``control_delay``: the aerodynamics see ``surface`` τ = size seconds late, while the
  recording keeps the commanded position (an actuator transport delay);
- ``sensor_offset``: the accelerometer sits at ``position_ft`` (body axes, from the c.g.;
  size = its x position) while the metadata still says [0, 0, 0].

Aerodynamic effects are written into a copy of the aircraft XML; the delay is a property the
flight loop drives; the sensor offset transforms the recorded accelerations.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

EFFECTS = ("unsteady_alphadot", "nonlinear_alpha", "control_delay", "sensor_offset")
G0_FPS2 = 32.17404855643


@dataclass(frozen=True)
class HiddenEffect:
    """One concealed effect and its true size (effects.md conventions)."""

    effect: str
    size: float
    surface: str = "de"
    position_ft: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if self.effect not in EFFECTS:
            raise ValueError(f"unknown hidden effect {self.effect!r}; choose one of {EFFECTS}")
        if self.effect == "control_delay" and not self.size >= 0:
            raise ValueError("a control delay must be non-negative seconds")
        if self.surface not in ("de", "da", "dr"):
            raise ValueError("surface must be de, da or dr")

    def describe(self) -> dict:
        d = {"effect": self.effect, "size": self.size}
        if self.effect == "control_delay":
            d["surface"] = self.surface
        if self.effect == "sensor_offset":
            d["position_ft"] = list(self.position_ft)
        return d


def delay_property(surface: str) -> str:
    return f"sidbench/{surface}-delay-delta-rad"


def _prop(parent: ET.Element, name: str) -> None:
    ET.SubElement(parent, "property").text = name


def _value(parent: ET.Element, x: float) -> None:
    ET.SubElement(parent, "value").text = repr(float(x))


def add_hidden_aerodynamics(tree: ET.ElementTree, effects: tuple[HiddenEffect, ...], alpha_ref: float,
                            surfaces: dict[str, str]) -> ET.ElementTree:
    """Write the aerodynamic effects into ``tree`` (a copy of the aircraft XML)."""
    aero = tree.getroot().find("aerodynamics")
    pitch = next(a for a in aero.findall("axis") if a.get("name") == "PITCH")
    for e in effects:
        if e.effect == "unsteady_alphadot":
            fn = ET.SubElement(pitch, "function", name="aero/coefficient/Cm_alphadot_hidden")
            prod = ET.SubElement(fn, "product")
            for p in ("aero/qbar-psf", "metrics/Sw-sqft", "metrics/cbarw-ft", "aero/ci2vel", "aero/alphadot-rad_sec"):
                _prop(prod, p)
            _value(prod, e.size)
        elif e.effect == "nonlinear_alpha":
            fn = ET.SubElement(pitch, "function", name="aero/coefficient/Cm_alpha2_hidden")
            prod = ET.SubElement(fn, "product")
            for p in ("aero/qbar-psf", "metrics/Sw-sqft", "metrics/cbarw-ft"):
                _prop(prod, p)
            _value(prod, e.size)
            for _ in range(2):
                diff = ET.SubElement(prod, "difference")
                _prop(diff, "aero/alpha-rad")
                _value(diff, alpha_ref)
        elif e.effect == "control_delay":
            surface_prop = surfaces[e.surface]
            seen = f"sidbench/{e.surface}-aero-rad"
            for el in aero.iter():
                if el.tag in ("property", "independentVar") and el.text and el.text.strip() == surface_prop:
                    el.text = seen
            fn = ET.Element("function", name=seen)
            total = ET.SubElement(fn, "sum")
            _prop(total, surface_prop)
            _prop(total, delay_property(e.surface))
            aero.insert(0, fn)
    return tree


def delay_deltas(values: np.ndarray, frames: int) -> np.ndarray:
    """δ(t − τ) − δ(t) per frame for a delay of ``frames`` frames (first value held before)."""
    if frames <= 0:
        return np.zeros_like(values)
    late = np.concatenate([np.full(frames, values[0]), values[:-frames]])
    return late - values


def offset_accelerometer(channels: dict[str, np.ndarray], r_ft: tuple[float, float, float]) -> None:
    """Move the recorded accelerometer (g) from the c.g. to ``r_ft``, in place:
    a_s = a_cg + [ω̇ × r + ω × (ω × r)] / g₀."""
    w = np.stack([channels["p_rps"], channels["q_rps"], channels["r_rps"]], axis=-1)
    wd = np.stack([channels["pdot_rps2"], channels["qdot_rps2"], channels["rdot_rps2"]], axis=-1)
    r = np.asarray(r_ft, dtype=float)
    extra = (np.cross(wd, r) + np.cross(w, np.cross(w, r))) / G0_FPS2
    for i, c in enumerate(("ax_g", "ay_g", "az_g")):
        channels[c] = channels[c] + extra[:, i]


def frames_of(delay_s: float, dt: float) -> int:
    """A delay in whole simulation frames (rounded)."""
    return int(round(delay_s / dt)) if math.isfinite(delay_s) else 0


def needs_copy(effects: tuple[HiddenEffect, ...]) -> bool:
    """Whether any effect lives in the aircraft XML (rather than in the sensors)."""
    return any(e.effect in ("unsteady_alphadot", "nonlinear_alpha", "control_delay") for e in effects)


def hidden_root(aircraft, condition):
    """Write the aircraft copy with ``aircraft.hidden``'s aerodynamic effects; ``(root, name)``.

    α_ref of ``nonlinear_alpha`` is the nominal aircraft's trim α at ``condition``, so the
    added term vanishes, with its slope, at the trim point.
    """
    from models.aircraft import Aircraft, load_fdm, nominal_root
    from models.jsbsim_root import aircraft_xml, cached_root, strip_io
    from models.trim import trim
    nominal = Aircraft(aircraft.model, "nominal")
    alpha_ref = trim(load_fdm(nominal, 1 / 120), nominal, condition).alpha_rad
    base_root, base_name = nominal_root(aircraft.model)
    tree = (strip_io(aircraft_xml(aircraft.model)) if base_root is None
            else ET.parse(base_root / "aircraft" / base_name / f"{base_name}.xml"))
    add_hidden_aerodynamics(tree, tuple(aircraft.hidden), alpha_ref, nominal.surfaces)
    name = f"{aircraft.model}-hidden"
    return cached_root(name, tree, aircraft.model), name
