"""Discrepancy diagnosis: locate where a model and a recording disagree, name the physics
left out (``../shared/effects.md``), model it and show the fit improve.

Modules, in the order the diagnosis runs them: ``prepare`` (smoothing, noise, measured
coefficients), ``kinematics`` (sensor effects by data compatibility), ``candidates``
(aerodynamic and actuator effects by stepwise regression with colored-residual t statistics and
a delay scan), ``spectra`` (structural modes, turbulence, drift), ``analysis`` (every candidate test
on one recording, in order, into ``evidence``'s records: ``along``, the model along the measured
states; ``gust_rules``, turbulence and light gusts; ``stepwise_axes``, the per-axis stepwise fits;
``sensor_rules`` and ``sensor_naming``, sensor verdicts and sensor errors named on two tests;
``term_rules``, what keeps an aerodynamic term from being named), ``fits`` (fit statistics before
and after), ``run`` (the whole diagnosis and its output folder: ``validation``, each finding tested on
the validation maneuver; ``augmented``, the repaired model flown again and calibrated;
``verdict``, the findings' words, what was not checked and what was assumed),
``gallery`` (recordings with concealed physics), ``sweep`` and ``outside`` (the diagnosis scored
on concealed effects and on flight-test-like recordings), ``commands`` (the subcommands).
"""
