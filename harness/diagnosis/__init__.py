"""Discrepancy diagnosis: locate where a model and a recording disagree, name the physics
left out (``../shared/effects.md``), model it and show the fit improve.

Modules, in the order the diagnosis runs them: ``prepare`` (smoothing, noise, measured
coefficients), ``locate`` (output and coefficient mismatch, when and in which band),
``kinematics`` (sensor effects by data compatibility), ``candidates`` (aerodynamic and
actuator effects by stepwise regression with colored-residual t statistics and a delay scan),
``spectra`` (structural modes, turbulence, drift), ``augment`` (the repaired model flown
again, fits before and after), ``run`` (the whole diagnosis and its output folder),
``gallery`` (recordings with concealed physics).
"""
