"""Named flight conditions for each aircraft."""
from __future__ import annotations

from dataclasses import dataclass


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
    """

    name: str
    h_ft: float
    V_fps: float
    note: str = ""


# F-16 at the seed's condition (10,000 ft, alpha near 5 deg). The JSBSim F-16 will not trim
# for alpha between about 4.94 and 5.05 deg (427.4-428 ft/s): the leading-edge flap switches at
# alpha = 0.0873 rad with no hysteresis (../shared/jsbsim-notes.md, confirmed here). 420 ft/s
# trims at alpha = 5.24 deg with the flap deployed (0.262 rad), safely clear of the switch; with
# the FCS disabled for open-loop flight the flap then stays where trim left it.
_F16 = (
    FlightCondition("seed-5deg", 10_000.0, 420.0,
                    "seed condition: 10,000 ft, alpha 5.24 deg (just above the LEF switch at 5.0 deg)"),
    FlightCondition("alpha-7.5", 10_000.0, 363.6,
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
        raise ValueError(f"no flight conditions are defined for aircraft {model!r}; "
                         f"known aircraft: {sorted(_CONDITIONS)}") from None


def condition_for(model: str, name: str | None = None) -> FlightCondition:
    """The named condition of ``model`` (its default when ``name`` is None)."""
    conds = conditions_for(model)
    if name is None:
        return conds[0]
    for c in conds:
        if c.name == name:
            return c
    raise ValueError(f"aircraft {model!r} has no flight condition {name!r}; "
                     f"choose one of {[c.name for c in conds]}")
