"""Named flight conditions for each aircraft."""
from __future__ import annotations

from dataclasses import dataclass
from models.errors import UserError


class ConditionError(UserError):
    """An unknown or malformed flight condition, or an aircraft without any."""


@dataclass(frozen=True)
class FlightCondition:
    """A trim point named in the field's terms: altitude and true airspeed, wings level.

    Attributes
    ----------
    name : str
        Identifier used on the command line (``--condition``).
    h_ft : float
        Pressure altitude above sea level, ft.
    V_fps : float
        True airspeed, ft/s.
    note : str
        Why this point was chosen.
    bank_deg : float
        A steady coordinated turn at this bank angle (deg); 0, wings level.
    """

    name: str
    h_ft: float
    V_fps: float
    note: str = ""
    bank_deg: float = 0.0


# F-16 at the seed's condition (10,000 ft, alpha near 5 deg), clean (gear up: models.configuration).
# 420 ft/s trims at alpha = 5.27 deg with the leading-edge flap deployed (0.262 rad), clear of
# the flap's switch at alpha = 0.0873 rad (5.00 deg; no hysteresis, so between about 428 and
# 429.5 ft/s the trim holds the flap: models.trim); with the FCS disabled for open-loop flight
# the flap then stays where trim left it.
_F16 = (
    FlightCondition("seed-5deg", 10_000.0, 420.0,
                    "seed condition: 10,000 ft, alpha 5.27 deg (just above the LEF switch at 5.0 deg)"),
    FlightCondition("alpha-7.5", 10_000.0, 364.6,
                    "second condition: 10,000 ft, alpha 7.5 deg, mid-segment of the aero tables"),
)

# The JSBSim 737 (mostly constant coefficients) at its own cruise file's altitude and speed.
_B737 = (
    FlightCondition("cruise", 30_000.0, 750.0, "737 cruise_init.xml: 30,000 ft, 750 ft/s"),
)

# The JSBSim DHC6 (Twin Otter) at the condition of the SIDPAC Twin Otter flight-test recordings
# (../shared/data/sidpac/totter_f1_*: lateral maneuvers): the means of totter_f1_017 (the
# identification record; 20 s, V 231-243 ft/s, h 6,187-6,266 ft, qbar 56.3 psf). 014 (the
# validation record) flew 237.7 ft/s at 6,299 ft, close enough to share it. The recording's
# mass (339.3 slug) and inertia differ from the JSBSim model's (314.4 slug): models.mass.
_DHC6 = (
    FlightCondition("twin-otter-017", 6_223.0, 237.0,
                    "SIDPAC Twin Otter record 017 (lateral, alpha near 0): mean h 6,223 ft, V 237.0 ft/s"),
)

_CONDITIONS: dict[str, tuple[FlightCondition, ...]] = {"f16": _F16, "737": _B737, "dhc6": _DHC6}


def conditions_for(model: str) -> tuple[FlightCondition, ...]:
    """All named conditions of an aircraft model (first is the default)."""
    try:
        return _CONDITIONS[model]
    except KeyError:
        raise ConditionError(f"no flight conditions are defined for aircraft {model!r}; "
                         f"known aircraft: {sorted(_CONDITIONS)}") from None


# Keys of a condition given by value, with their units and the plausible range checked.
_CONDITION_KEYS = {"h": ("ft", -1_000.0, 100_000.0), "V": ("ft/s true airspeed", 1.0, 5_000.0)}


def parse_condition(text: str) -> FlightCondition:
    """A condition given by value: ``'h=10000,V=427.4'`` (pressure altitude in ft, true
    airspeed in ft/s), wings level. Its name is the text in canonical form, so it can stand
    wherever a condition's name does (flight specifications, caches, metadata).

    Raises
    ------
    ValueError
        Naming what is missing, unknown, not a number or out of range.
    """
    values: dict[str, float] = {}
    for part in text.split(","):
        key, sep, value = part.partition("=")
        key = key.strip()
        if not sep or key not in _CONDITION_KEYS:
            raise ConditionError(f"condition {text!r}: expected h=<ft>,V=<ft/s>, e.g. h=10000,V=427.4 "
                             f"(unknown or malformed part {part.strip()!r})")
        try:
            values[key] = float(value)
        except ValueError:
            raise ConditionError(f"condition {text!r}: {key} must be a number, not {value.strip()!r}") from None
    for key, (unit, lo, hi) in _CONDITION_KEYS.items():
        if key not in values:
            raise ConditionError(f"condition {text!r}: {key} is missing (expected h=<ft>,V=<ft/s>)")
        if not lo <= values[key] <= hi:
            raise ConditionError(f"condition {text!r}: {key} = {values[key]:g} {unit} is outside {lo:g} to {hi:g}")
    h, V = values["h"], values["V"]
    return FlightCondition(f"h={h:g},V={V:g}", h, V, "given by value (h in ft, V in ft/s true airspeed)")


def is_condition_value(name: str | None) -> bool:
    """Whether ``name`` gives a condition by value (``h=...,V=...``) rather than by name."""
    return name is not None and "=" in name


def condition_for(model: str, name: str | None = None) -> FlightCondition:
    """The condition of ``model`` called ``name`` (its default when ``name`` is None), or the
    condition ``name`` gives by value (``'h=10000,V=427.4'``, any aircraft)."""
    if is_condition_value(name):
        return parse_condition(name)
    conds = conditions_for(model)
    if name is None:
        return conds[0]
    for c in conds:
        if c.name == name:
            return c
    raise ConditionError(f"aircraft {model!r} has no flight condition {name!r}; "
                     f"choose one of {[c.name for c in conds]}")
