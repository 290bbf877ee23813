"""Physics added to (or hidden in) an aircraft: one effect of ``../shared/effects.md`` each.

The same type serves two purposes. Hidden, it makes the concealed-effect recordings the
discrepancy diagnosis must explain; added, it is the diagnosis's repaired model, flown again
to show the fit improve. Each :class:`HiddenEffect` names an effect id and its size in the
convention of effects.md:

- ``unsteady_alphadot``: C += size · α̇c̄/2V (``coefficient``, default Cm; size per rad);
- ``nonlinear_alpha``: C += size · (α − α_ref)^power (default Cm, power 2; size per rad^power);
  α_ref the nominal trim α unless ``reference`` gives it, so the term vanishes, with its
  slope, at trim;
- ``coefficient_error``: C += size · x, x one of α − α_ref, β, p̂, q̂, r̂, δ − δ_ref
  (``regressor``; size is the change of that derivative);
- ``cross_coupling``: C += size · (α − α_ref)·β, or with ``regressor='beta_abs'``
  C += size · |β| (a response even in sideslip, which a symmetric airframe should not have);
- ``flight_condition_drift``: C += size · (V − V_ref)/V_ref;
- ``cg_offset``: the moment reference moves ``size`` ft forward: Cm += size·CZ/c̄,
  Cn −= size·CY/b;
- ``control_delay``: the aerodynamics see ``surface`` τ = size seconds late, while the
  recording keeps the commanded position (an actuator transport delay);
- ``sensor_offset``: the accelerometer sits at ``position_ft`` (body axes, from the c.g.;
  size = its x position) while the metadata still says [0, 0, 0];
- ``sensor_bias``, ``sensor_scale``, ``sensor_time_skew``: the recorded ``channel`` reads
  x + size, (1 + size)·x, or x(t − size).

Aerodynamic effects are written into a copy of the aircraft XML; the delay is a property the
flight loop drives; sensor effects transform the recorded channels.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace

import numpy as np

from models.constants import BODY_COEFFICIENTS as COEFFICIENTS, G0_FPS2, SURFACES

AERO_TERMS = ("unsteady_alphadot", "nonlinear_alpha", "coefficient_error", "cross_coupling",
              "flight_condition_drift", "cg_offset")
SENSOR_EFFECTS = ("sensor_offset", "sensor_bias", "sensor_scale", "sensor_time_skew")
EFFECTS = AERO_TERMS + ("control_delay",) + SENSOR_EFFECTS
REGRESSORS = ("alpha", "beta", "phat", "qhat", "rhat", "de", "da", "dr")
SENSOR_CHANNELS = ("alpha", "beta", "V", "p", "q", "r", "phi", "theta", "ax", "ay", "az")

# JSBSim axis, sign and reference length of each coefficient's added function. Force terms go
# to the wind-axis DRAG and LIFT (CX ≈ −CD, CZ ≈ −CL at small α): an approximation.
_AXES = {"CX": ("DRAG", -1.0, None), "CY": ("SIDE", 1.0, None), "CZ": ("LIFT", -1.0, None),
         "Cl": ("ROLL", 1.0, "metrics/bw-ft"), "Cm": ("PITCH", 1.0, "metrics/cbarw-ft"),
         "Cn": ("YAW", 1.0, "metrics/bw-ft")}


@dataclass(frozen=True)
class HiddenEffect:
    """One effect and its size (effects.md conventions), concealed or added.

    Attributes
    ----------
    effect, size : the effect id and its size.
    surface : the delayed surface of ``control_delay`` (de, da, dr).
    position_ft : the accelerometer position of ``sensor_offset``.
    coefficient : the coefficient an aerodynamic term adds to (CX .. Cn).
    regressor : the derivative ``coefficient_error`` corrects (alpha, beta, phat, ...).
    power : the power of (α − α_ref) of ``nonlinear_alpha``.
    reference : α_ref (rad) of α-dependent terms, V_ref (ft/s) of drift, δ_ref (rad) of a
        surface regressor; None takes the nominal trim value.
    channel : the channel a sensor effect acts on.
    """

    effect: str
    size: float
    surface: str = "de"
    position_ft: tuple[float, float, float] = (0.0, 0.0, 0.0)
    coefficient: str = "Cm"
    regressor: str = ""
    power: int = 2
    reference: float | None = None
    channel: str = ""

    def __post_init__(self) -> None:
        if self.effect not in EFFECTS:
            raise ValueError(f"unknown hidden effect {self.effect!r}; choose one of {EFFECTS}")
        if not math.isfinite(self.size):
            raise ValueError(f"the size of {self.effect} must be finite")
        if self.effect == "control_delay" and not self.size >= 0:
            raise ValueError("a control delay must be non-negative seconds")
        if self.surface not in SURFACES:
            raise ValueError("surface must be de, da or dr")
        if self.coefficient not in COEFFICIENTS:
            raise ValueError(f"coefficient must be one of {COEFFICIENTS}")
        if self.effect == "coefficient_error" and self.regressor not in REGRESSORS:
            raise ValueError(f"coefficient_error needs a regressor among {REGRESSORS}")
        if self.effect == "cross_coupling" and self.regressor not in ("", "beta_abs"):
            raise ValueError("cross_coupling takes regressor '' ((alpha - alpha_ref)*beta) or 'beta_abs' (|beta|)")
        if self.effect == "nonlinear_alpha" and self.power not in (2, 3):
            raise ValueError("nonlinear_alpha takes power 2 or 3")
        if self.effect in ("sensor_bias", "sensor_scale", "sensor_time_skew") and self.channel not in SENSOR_CHANNELS:
            raise ValueError(f"{self.effect} needs a channel among {SENSOR_CHANNELS}")

    def describe(self) -> dict:
        d = {"effect": self.effect, "size": self.size}
        if self.effect == "control_delay":
            d["surface"] = self.surface
        if self.effect == "sensor_offset":
            d["position_ft"] = list(self.position_ft)
        if self.effect in AERO_TERMS and self.effect != "cg_offset" and (
                self.coefficient != "Cm" or self.effect not in ("unsteady_alphadot", "nonlinear_alpha")):
            d["coefficient"] = self.coefficient
        if self.effect == "coefficient_error":
            d["regressor"] = self.regressor
        if self.effect == "nonlinear_alpha" and self.power != 2:
            d["power"] = self.power
        if self.reference is not None:
            d["reference"] = self.reference
        if self.channel:
            d["channel"] = self.channel
        return d

    @property
    def parameter(self) -> str:
        """The name of the estimated parameter (``Cm_alphadot``, ``tau_de``, ``x_accel``)."""
        if self.effect == "unsteady_alphadot":
            return f"{self.coefficient}_alphadot"
        if self.effect == "nonlinear_alpha":
            return f"{self.coefficient}_alpha{self.power}"
        if self.effect == "coefficient_error":
            return f"{self.coefficient}_{self.regressor}"
        if self.effect == "cross_coupling":
            return f"{self.coefficient}_{self.regressor or 'alpha_beta'}"
        if self.effect == "flight_condition_drift":
            return f"{self.coefficient}_dV"
        if self.effect == "cg_offset":
            return "dx_moment_reference"
        if self.effect == "control_delay":
            return f"tau_{self.surface}"
        if self.effect == "sensor_offset":
            return "x_accelerometer"
        kind = {"sensor_bias": "bias", "sensor_scale": "scale", "sensor_time_skew": "skew"}[self.effect]
        return f"{kind}_{self.channel}"


def delay_property(surface: str) -> str:
    return f"sidbench/{surface}-delay-delta-rad"


def _prop(parent: ET.Element, name: str) -> None:
    ET.SubElement(parent, "property").text = name


def _value(parent: ET.Element, x: float) -> None:
    ET.SubElement(parent, "value").text = repr(float(x))


def _difference(parent: ET.Element, prop: str, ref: float) -> None:
    diff = ET.SubElement(parent, "difference")
    _prop(diff, prop)
    _value(diff, ref)


def _factor(parent: ET.Element, name: str, ref: float, surfaces: dict[str, str]) -> None:
    """Append the JSBSim expression of one regressor factor to a <product>."""
    if name == "alpha":
        _difference(parent, "aero/alpha-rad", ref)
    elif name == "beta":
        _prop(parent, "aero/beta-rad")
    elif name == "beta_abs":
        _prop(ET.SubElement(parent, "abs"), "aero/beta-rad")
    elif name in ("phat", "rhat"):
        _prop(parent, "aero/bi2vel")
        _prop(parent, f"velocities/{name[0]}-aero-rad_sec")
    elif name == "qhat":
        _prop(parent, "aero/ci2vel")
        _prop(parent, "velocities/q-aero-rad_sec")
    elif name == "alphadot":
        _prop(parent, "aero/ci2vel")
        _prop(parent, "aero/alphadot-rad_sec")
    elif name in SURFACES:
        _difference(parent, surfaces[name], ref)
    elif name == "dV":
        _difference(parent, "velocities/vt-fps", ref)
        _value(parent, 1.0 / ref)
    else:  # pragma: no cover - guarded by HiddenEffect
        raise ValueError(name)


def _factors(e: HiddenEffect) -> tuple[str, ...]:
    return {"unsteady_alphadot": ("alphadot",), "nonlinear_alpha": ("alpha",) * e.power,
            "coefficient_error": (e.regressor,), "cross_coupling": (e.regressor,) if e.regressor else ("alpha", "beta"),
            "flight_condition_drift": ("dV",)}[e.effect]


def _axis(aero: ET.Element, name: str) -> ET.Element:
    for a in aero.findall("axis"):
        if a.get("name") == name:
            return a
    return ET.SubElement(aero, "axis", name=name)


def _aero_term(aero: ET.Element, e: HiddenEffect, refs: dict[str, float], surfaces: dict[str, str], k: int) -> None:
    if e.effect == "cg_offset":
        for coef, force, sign in (("Cm", "forces/fbz-aero-lbs", 1.0), ("Cn", "forces/fby-aero-lbs", -1.0)):
            fn = ET.SubElement(_axis(aero, _AXES[coef][0]), "function", name=f"aero/coefficient/{coef}_cg_offset_{k}")
            prod = ET.SubElement(fn, "product")
            _prop(prod, force)  # the previous frame's aerodynamic force: a one-frame lag
            _value(prod, sign * e.size)
        return
    axis, sign, length = _AXES[e.coefficient]
    fn = ET.SubElement(_axis(aero, axis), "function", name=f"aero/coefficient/{e.parameter}_{e.effect}_{k}")
    prod = ET.SubElement(fn, "product")
    for p in ("aero/qbar-psf", "metrics/Sw-sqft") + ((length,) if length else ()):
        _prop(prod, p)
    _value(prod, sign * e.size)
    for name in _factors(e):
        ref = e.reference if e.reference is not None else refs.get(name, 0.0)
        _factor(prod, name, ref, surfaces)


def add_hidden_aerodynamics(tree: ET.ElementTree, effects: tuple[HiddenEffect, ...], alpha_ref: float,
                            surfaces: dict[str, str], refs: dict[str, float] | None = None) -> ET.ElementTree:
    """Write the aerodynamic effects into ``tree`` (a copy of the aircraft XML).

    ``refs`` gives the trim value of each regressor (``alpha``, ``dV`` = V_ref, ``de`` ...);
    ``alpha_ref`` is its α entry. An effect's own ``reference`` overrides them.
    """
    refs = {"alpha": alpha_ref, **(refs or {})}
    aero = tree.getroot().find("aerodynamics")
    for k, e in enumerate(effects):
        if e.effect in AERO_TERMS:
            _aero_term(aero, e, refs, surfaces, k)
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


def vane_shift(p, q, r, V, position_ft) -> tuple[np.ndarray, np.ndarray]:
    """What vanes at ``position_ft`` (x, y, z ft from the c.g., body axes) read beyond the
    c.g.'s α and β: the air's velocity there is the c.g.'s plus ω × r, so to first order in
    the rates Δα = (p·y − q·x)/V and Δβ = (r·x − p·z)/V (a vane 15 ft ahead reads α low by
    15·q/V). Rates in rad/s, V in ft/s; arrays or scalars."""
    x, y, z = (float(c) for c in position_ft)
    p, q, r, V = (np.asarray(v, dtype=float) for v in (p, q, r, V))
    return (p * y - q * x) / V, (r * x - p * z) / V


_UNITS = {"alpha": "rad", "beta": "rad", "V": "fps", "p": "rps", "q": "rps", "r": "rps", "phi": "rad",
          "theta": "rad", "ax": "g", "ay": "g", "az": "g"}


def channel_column(channel: str) -> str:
    """The canonical column of a sensor channel (``alpha`` -> ``alpha_rad``)."""
    return f"{channel}_{_UNITS[channel]}"


def apply_sensor_effects(channels: dict[str, np.ndarray], effects: tuple[HiddenEffect, ...], dt: float) -> None:
    """Apply the sensor effects of ``effects`` to recorded ``channels`` (in place)."""
    for e in effects:
        if e.effect == "sensor_offset":
            offset_accelerometer(channels, e.position_ft)
        elif e.effect in ("sensor_bias", "sensor_scale", "sensor_time_skew"):
            col = channel_column(e.channel)
            x = channels[col]
            if e.effect == "sensor_bias":
                channels[col] = x + e.size
            elif e.effect == "sensor_scale":
                channels[col] = (1.0 + e.size) * x
            else:
                t = np.arange(x.size) * dt
                channels[col] = np.interp(t - e.size, t, x)


def frames_of(delay_s: float, dt: float) -> int:
    """A delay in whole simulation frames (rounded)."""
    return int(round(delay_s / dt)) if math.isfinite(delay_s) else 0


def needs_copy(effects: tuple[HiddenEffect, ...]) -> bool:
    """Whether any effect lives in the aircraft XML (rather than in the sensors)."""
    return any(e.effect in AERO_TERMS or e.effect == "control_delay" for e in effects)


# The trim references an added term is written about (alpha and the surfaces in rad, V in ft/s).
REFERENCE_KEYS = ("alpha", "dV", "de", "da", "dr")


def hidden_root(aircraft, condition, refs: dict[str, float] | None = None):
    """Write the aircraft copy with ``aircraft.hidden``'s aerodynamic effects; ``(root, name)``.

    α_ref (and the other trim references) are the nominal aircraft's trim values at
    ``condition`` unless ``refs`` or an effect's ``reference`` gives them, so an added
    α-polynomial vanishes, with its slope, at the trim point. With every one of
    :data:`REFERENCE_KEYS` in ``refs`` no trim is made.
    """
    from models.aircraft import load_fdm, model_xml, nominal_tree
    from models.jsbsim_root import cached_root
    from models.trim import trim
    nominal = replace(aircraft, variant="nominal", hidden=())
    base = dict(refs or {})
    if not all(k in base for k in REFERENCE_KEYS):  # the trim only when some reference is not given
        tp = trim(load_fdm(nominal, 1 / 120), nominal, condition)
        base = {"alpha": tp.alpha_rad, "dV": tp.V_fps, "de": tp.de_rad, "da": tp.da_rad, "dr": tp.dr_rad} | base
    tree = nominal_tree(aircraft.model)
    add_hidden_aerodynamics(tree, tuple(aircraft.hidden), base["alpha"], nominal.surfaces, base)
    name = f"{aircraft.name}-hidden"
    return cached_root(name, tree, model_xml(aircraft.model)), name
