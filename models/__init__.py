"""Aircraft: JSBSim loading, trim, surface drive, truth derivatives and variants.

The public names are re-exported here; each lives in a short module of its own:

- :mod:`models.conditions`  named flight conditions (altitude, airspeed)
- :mod:`models.aircraft`    which aircraft and variant to fly, and loading it into JSBSim
- :mod:`models.jsbsim_root` aircraft copies written to a JSBSim root of their own
- :mod:`models.trim`        trimming, with failures that name their cause
- :mod:`models.flight`      open- and closed-loop flight sampled on exact sample times
- :mod:`models.truth`       non-dimensional derivatives by central differences
- :mod:`models.linearization` the cross-check through ``jsbsim.FGLinearization``
- :mod:`models.exact`       the exact-truth variant (aerodynamics exactly linear)
"""
from models.aircraft import Aircraft, VARIANTS, load_fdm
from models.conditions import FlightCondition, condition_for, conditions_for
from models.trim import TrimError, TrimPoint, trim
from models.flight import FlightError, Loop, fly
from models.truth import DERIVATIVE_NAMES, Derivatives, truth_derivatives

__all__ = [
    "Aircraft", "VARIANTS", "load_fdm", "FlightCondition", "condition_for", "conditions_for",
    "TrimError", "TrimPoint", "trim", "FlightError", "Loop", "fly",
    "DERIVATIVE_NAMES", "Derivatives", "truth_derivatives",
]
