"""JSBSim in the loop: calibrate a simulator's aircraft to flight recordings by output error.

``calibrate(aircraft, recordings, parameters, validation=..., workers=2) -> CalibrationResult``
(:mod:`harness.calibrate.run`); ``write_calibration(result, out)`` writes calibration.json,
model/ and series/ (:mod:`harness.calibrate.output`).
"""
from harness.calibrate.problem import CalibrationError
from harness.calibrate.run import CalibrationResult, calibrate

__all__ = ["CalibrationError", "CalibrationResult", "calibrate"]
