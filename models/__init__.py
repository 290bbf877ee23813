"""Aircraft: JSBSim loading, trim, surface drive, truth derivatives and variants.

Each part lives in a short module of its own (import from it directly; importing the package
itself loads nothing, so that the packages to its right can take its constants without JSBSim):

- :mod:`models.constants`   standard gravity, the surface and coefficient names
- :mod:`models.errors`      the user-error types every package raises for input the user can fix
- :mod:`models.conditions`  named flight conditions (altitude, airspeed)
- :mod:`models.aircraft`    which aircraft and variant to fly, and loading it into JSBSim
- :mod:`models.jsbsim_root` aircraft copies written to a JSBSim root of their own
- :mod:`models.trim`        trimming, with failures that name their cause
- :mod:`models.flight`      open- and closed-loop flight sampled on exact sample times
- :mod:`models.truth`       non-dimensional derivatives by central differences
- :mod:`models.linearization` the cross-check through ``jsbsim.FGLinearization``
- :mod:`models.exact`       the exact-truth variant (aerodynamics exactly linear)
"""
