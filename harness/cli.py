"""The ``sidbench`` command line.

The command line is the composition root: it sits above every package it wires together, and
it (this module, ``harness.commands``, ``harness.bench`` and ``harness.__main__``) is the one place
that may import the reports package; nothing below imports it back (tests/test_architecture.py).
Each subcommand is a function ``cmd_<name>(args) -> int``, its module imported only when it
runs, so that ``--help`` stays quick; the report-writing subcommands live in ``reports.commands``.
Errors the user can fix (a malformed recording, a trim that
fails, a diverging flight, a bad option) print one message naming the cause and exit 2.
"""
from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from estimators.registry import METHODS
from harness.flying import AIRCRAFT_HELP, CONDITION_HELP, add_flight_options, add_noise_options


def _commands():
    """The harness's subcommands (each module below is imported only when a subcommand runs)."""
    from harness import commands
    return commands


def _bench():
    from harness import bench
    return bench


def _report_commands():
    from reports import commands
    return commands


def _diagnosis_commands():
    from harness.diagnosis import commands
    return commands


def _calibrate(args: argparse.Namespace) -> int:
    """``sidbench calibrate``: the calibration (harness) and its report (reports), wired here."""
    from harness.calibrate.command import cmd_calibrate
    from reports.calibration_report import write_calibration_report
    return cmd_calibrate(args, write_calibration_report)


class _DefaultsFormatter(argparse.HelpFormatter):
    """Every option's help ends with its default, unless the text already states it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if "default" in text.lower() or action.default is argparse.SUPPRESS or not action.option_strings \
                or action.required or isinstance(action, argparse._HelpAction):
            return text
        d = action.default
        if isinstance(action, argparse._StoreTrueAction):
            shown = "off"
        elif d is None:
            shown = "none"
        else:
            shown = str(d)
        return f"{text} (default: {shown})".strip()


def _add_fly(sub) -> None:
    f = sub.add_parser("fly", help="trim an aircraft, fly a maneuver and write the recording",
                       description="Trim, fly one maneuver open or closed loop, and write the "
                                   "recording (CSV + .meta.json, or Parquet) with its truth.")
    add_flight_options(f)
    add_noise_options(f)
    f.add_argument("--out", required=True, help="output recording: NAME.csv (+ NAME.meta.json) or NAME.parquet")
    f.set_defaults(func=lambda a: _commands().cmd_fly(a))


def _add_truth(sub) -> None:
    t = sub.add_parser("truth", help="truth derivatives of an aircraft at a flight condition",
                       description="Non-dimensional stability and control derivatives at trim, about "
                                   "the c.g., per rad (rates normalised by cbar/2V and b/2V), by central "
                                   "differences of JSBSim's own aerodynamics: the local slope and the "
                                   "best linear fit over the default maneuvers' excursion.")
    t.add_argument("--aircraft", default="f16", metavar="f16|737|dhc6|PATH.xml", help=AIRCRAFT_HELP)
    t.add_argument("--variant", default="nominal", choices=["nominal", "exact-truth", "unstable"],
                   help="aircraft variant (default: nominal)")
    t.add_argument("--condition", default=None, help=CONDITION_HELP)
    t.add_argument("--json", default=None, help="write the derivatives to this JSON file (default: none)")
    t.add_argument("--check-linearization", action="store_true",
                   help="also compare with jsbsim.FGLinearization and print the relative differences "
                        "(default: off)")
    t.set_defaults(func=lambda a: _commands().cmd_truth(a))


def _add_import(sub) -> None:
    i = sub.add_parser("import", help="convert a SIDPAC .mat file, or a user's ASCII/CSV file with a column map, "
                                      "to the canonical recording format",
                       description="Import a SIDPAC flight-test file (t, fdata, fds) into the canonical "
                                   "format, keeping its computed coefficient and normalised-rate columns; or a "
                                   "user's ASCII/CSV flight data (any delimiter, a header line) through a column "
                                   "map (TOML: source column -> canonical <quantity>_<unit>, the time column, scale "
                                   "factors, sign flips, the metadata; see harness/column_map.py). Prints every "
                                   "change made (signs, derived channels, dropped columns).")
    i.add_argument("file", help="SIDPAC .mat file, or with --column-map the user's ASCII/CSV data file")
    i.add_argument("--column-map", default=None, metavar="MAP.toml",
                   help="column map (TOML) for a user's ASCII/CSV file (default: none: FILE is a SIDPAC .mat or a "
                        "canonical recording)")
    i.add_argument("--out", required=True, help="output recording (.csv or .parquet)")
    i.set_defaults(func=lambda a: _commands().cmd_import(a))


def _add_estimate(sub) -> None:
    e = sub.add_parser("estimate", help="estimate model parameters from a recording",
                       description="Fit one equation (dependent = sum of regressors + bias) by equation "
                                   "error in the time domain (ee-time), with smoothed regressors "
                                   "(ee-smooth), in the frequency domain (ee-freq), or by output error "
                                   "(oe). Prints a table; --json writes every number.")
    e.add_argument("--recording", required=True, help="canonical recording (.csv/.parquet) or SIDPAC .mat")
    e.add_argument("--dependent", default=None,
                   help="CX, CY, CZ, Cl, Cm, Cn, CL or CD (from Eqs. 1-5, or the recording's own column); "
                        "required unless --model-file is given")
    e.add_argument("--regressors", default=None,
                   help="comma list: alpha, beta, qhat, phat, rhat, de, da, dr, dV, alphadot_hat, "
                        "products a*b and powers a^2 ...; required unless --model-file is given")
    e.add_argument("--model-file", default=None,
                   help="oe: a Python file defining `model` (estimators.dynamic_models.Model), fitted as written "
                        "instead of the built-in linear models; the file is code that runs: use only files you trust")
    e.add_argument("--method", default="ee-time", choices=METHODS,
                   help="ee-time, ee-smooth (smoothed regressors), ee-freq (frequency domain), oe (output error), "
                        "oe-freq (output error in the frequency domain), fe (filter error)")
    e.add_argument("--errors", default=None, choices=["conventional", "colored"],
                   help="time-domain error bounds: conventional (Eq. 15) or colored residuals (Eq. 40); "
                        "default colored for ee-smooth, conventional for ee-time")
    e.add_argument("--max-lag", type=int, default=None, help="colored errors: largest lag (default: all)")
    e.add_argument("--autocorrelation", choices=("sample", "ar"), default="sample",
                   help="colored errors: the residual autocorrelation, Eq. 39's estimates (default) or their "
                        "autoregressive model ('ar': a bias term's bound honest too)")
    e.add_argument("--frequencies", default=None,
                   help="ee-freq band: auto (default: the seed's rule, 2/T to 1.2 Hz by 0.04 Hz), sidpac or "
                        "eq18 (Eq. 18, 0.20:0.04:1.20), F0:DF:F1 in Hz, or a comma list")
    e.add_argument("--detrend", default="lstsq", choices=["lstsq", "endpoints"],
                   help="ee-freq detrending: least-squares line (default) or the line through the end points "
                        "(SIDPAC's; with --frequencies sidpac, SIDPAC's convention)")
    e.add_argument("--no-bias", action="store_true", help="no bias term (ee-freq never has one)")
    e.add_argument("--reference", default="trim", choices=["trim", "first", "none"],
                   help="regressors as perturbations from trim (default; raw where no trim is known), "
                        "from the first sample, or raw (Eqs. 35-36)")
    e.add_argument("--angular-acceleration", default="auto",
                   choices=["auto", "recorded", "smooth-local", "smooth-fourier", "local-smooth"],
                   help="pdot/qdot/rdot for Eqs. 3-5: recorded channels, or the seed's differentiation "
                        "method 1, 2 or 3 (auto: recorded if present, else method 1)")
    e.add_argument("--truth", default="local", choices=["local", "fit"],
                   help="which truth a simulated recording's table shows beside the estimates: the local slope "
                        "at trim or the fit over the excursion (default local)")
    e.add_argument("--json", default=None,
                   help="write the result to this JSON file: estimates, bounds, t and p values, residuals, fitted "
                        "values, regressors and every option (default: none)")
    e.add_argument("--csv", default=None,
                   help="write one row per parameter to this CSV file: estimate, std error, t, p, 95%% interval "
                        "and, on a simulated recording, truth and error in standard errors (default: none)")
    e.add_argument("--report", default=None, metavar="DIR",
                   help="write DIR/report.html (self-contained): measured vs model, residual and its spectrum, "
                        "regressors, estimates with bounds and truth (default: none)")
    e.set_defaults(func=lambda a: _commands().cmd_estimate(a))


def _add_campaign(sub) -> None:
    c = sub.add_parser("campaign", help="run a Monte Carlo campaign and print its scores",
                       description="Run a campaign file (TOML; or the name of a built-in campaign: "
                                   "regressor-noise, error-bounds, collinearity, multiple-maneuvers, "
                                   "maneuver-design, nightly). Finished tasks are kept in OUT/tasks, so an "
                                   "interrupted run resumes where it stopped.")
    c.add_argument("file", help="campaign TOML file or built-in name")
    c.add_argument("--out", required=True, help="output folder (results.parquet, scores.parquet, run.json)")
    c.add_argument("--scheduler", default=None,
                   help="'local' for a dask LocalCluster, or tcp://HOST:PORT of a Dask scheduler "
                        "(default: a local process pool)")
    c.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    c.add_argument("--realizations", type=int, default=None, help="override the file's realizations per cell")
    c.add_argument("--cache", default=None, help="flight cache folder (default .sidbench-cache)")
    c.add_argument("--history", default=None, help="also keep the scores in this history folder")
    c.add_argument("--quiet", action="store_true", help="no progress display")
    c.set_defaults(func=lambda a: _commands().cmd_campaign(a))


def _add_bench(sub) -> None:
    b = sub.add_parser("bench", help="measure and print the benchmark table",
                       description="Time the project's main operations on this machine and print them.")
    b.add_argument("--repeat", type=int, default=7, help="repetitions per row (the best is kept)")
    b.set_defaults(func=lambda a: _bench().cmd_bench(a))


def _add_demo(sub) -> None:
    d = sub.add_parser("demo", help="the main job: fly, print the truth, run a quick campaign, write a report",
                       description="Fly the seed's default maneuver (F-16, stabilator 2-1-1-2, 1 deg, 1 s "
                                   "unit pulse), print its truth table, run a quick regressor-noise campaign and "
                                   "write OUT/report.html (+ .md, .json).")
    d.add_argument("--out", default="out", help="output folder (default: out)")
    d.add_argument("--realizations", type=int, default=100, help="realizations of the demo campaign (default 100)")
    d.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    d.set_defaults(func=lambda a: _report_commands().cmd_demo(a))


def _add_diagnose(sub) -> None:
    g = sub.add_parser("diagnose", help="locate and name what a model leaves out of a recording, model it, "
                                        "show the fit improve",
                       description="Compare a model with a recording (canonical format): replay the recorded "
                                   "surfaces from trim, locate the mismatch, test every effect of effects.md, add "
                                   "the significant ones to the model, refine their sizes with JSBSim in the loop "
                                   "(--calibrate) and fly it again. Writes OUT/findings.json, "
                                   "OUT/report.html, OUT/series/*.parquet and OUT/model/ (the augmented aircraft).")
    g.add_argument("--model", required=True,
                   help="aircraft model in models/ (f16, 737, dhc6), an aircraft of the jsbsim package's library by "
                        "name (c172x, A320, ...), or the path of a JSBSim aircraft XML")
    g.add_argument("--mass", choices=("model", "recording"), default="model",
                   help="fly the model with its own mass properties (default) or with the recording's (mass, "
                        "inertia at its first sample)")
    g.add_argument("--aero-reference", choices=("auto", "project", "xml", "cg"), default="auto",
                   help="where the model's aerodynamic reference point is: auto (default) lets the recording choose "
                        "for a model the project flies with it moved (the 737: on its c.g., or where JSBSim ships it), "
                        "project, xml (where the aircraft XML puts it) or cg (on the c.g.)")
    g.add_argument("--recording", required=True, help="identification recording (.csv beside .meta.json, or .parquet)")
    g.add_argument("--validation", default=None, help="a second maneuver to validate the repaired model on")
    g.add_argument("--out", required=True, help="output folder")
    g.add_argument("--calibrate", action=argparse.BooleanOptionalAction, default=True,
                   help="last step: refine the added aerodynamic and delay terms with JSBSim in the loop (output "
                        "error, as sidbench calibrate), keeping the calibrated sizes only when the identification "
                        "fit and the validation RMS of the outputs they drive are at least as good (default: on; "
                        "surfaces held sample to sample for a simulated recording, interpolated for flight data)")
    g.add_argument("--workers", type=int, default=2, help="processes (default 2): the calibration's flights; above 1 the validation maneuver is also analysed, replayed and drawn in a second process (same results)")
    g.set_defaults(func=lambda a: _commands().cmd_diagnose(a))


def _add_calibrate(sub) -> None:
    cal = sub.add_parser("calibrate", help="JSBSim in the loop: calibrate an aircraft XML to flight recordings by "
                                           "output error",
                         description="Fly the JSBSim aircraft with the recorded surfaces from each recording's start "
                                     "and fit named adjustments of its own XML (a scale or increment of any "
                                     "aerodynamic <function>, an added term of the diagnosis's vocabulary, a surface "
                                     "delay, a mass or reference-point change) by output error: Gauss-Newton on "
                                     "finite-difference sensitivities from perturbed flights in parallel. Writes "
                                     "OUT/calibration.json, OUT/model/ (the calibrated XML, which flies in stock "
                                     "JSBSim), OUT/series/ and OUT/report.html.")
    cal.add_argument("--model", required=True, help="aircraft: f16, 737, dhc6, an aircraft of the jsbsim package's "
                     "library by name (c172x, ...), or the path of a JSBSim aircraft XML")
    cal.add_argument("--recording", required=True, action="append",
                     help="identification recording (.csv beside .meta.json, .parquet or SIDPAC .mat); repeatable")
    cal.add_argument("--validation", action="append", default=None,
                     help="recording the calibrated model is only flown on (a prediction); repeatable (default: none)")
    cal.add_argument("--parameters", required=True,
                     help="comma list: FUNCTION:scale or FUNCTION:increment (e.g. aero/coefficient/Cnb:scale), a "
                          "vocabulary term (Cm_alphadot, Cn_beta, Cl_beta_abs, ...), tau_de|tau_da|tau_dr, iyy:scale, "
                          "cg_x:increment ...; NAME=VALUE sets the start; auto: the terms the diagnosis adds (run on "
                          "the first recording and validation), auto=FINDINGS.json: an earlier diagnosis's")
    cal.add_argument("--out", required=True, help="output folder")
    cal.add_argument("--outputs", default=None,
                     help="comma list of channels matched (default: those of alpha,beta,p,q,r,phi,theta,V,ax,ay,az "
                          "the recording has)")
    cal.add_argument("--mass", choices=("model", "recording"), default="model",
                     help="fly the model with its own mass properties or with the recording's (first sample) "
                          "(default: model)")
    cal.add_argument("--surfaces", choices=("linear", "sample"), default="linear",
                     help="the recorded surfaces between samples: linear (a continuously moving surface, flight data) "
                          "or sample (each sample held until the next: a stepped input sampled at its edges, as "
                          "simulated recordings are) (default: linear)")
    cal.add_argument("--workers", type=int, default=2, help="processes flying the perturbed flights (default 2)")
    cal.add_argument("--max-iterations", type=int, default=20, help="Gauss-Newton iterations at most (default 20)")
    cal.set_defaults(func=_calibrate)


def _add_gallery(sub) -> None:
    gg = sub.add_parser("gallery", help="write the concealed-effect recordings (identification + validation)",
                        description="Fly the F-16 with one hidden effect per case, add the realistic noise layer "
                                    "and write OUT/<case>-identification.csv, -validation.csv and the answer.")
    gg.add_argument("--out", default="out/gallery", help="output folder")
    gg.add_argument("--seed", type=int, default=1, help="noise seed of the identification maneuver (validation: +1)")
    gg.add_argument("--case", action="append", default=None, help="one case (repeatable; default all)")
    gg.set_defaults(func=lambda a: _diagnosis_commands().cmd_gallery(a))


def _add_diagnosis_sweep(sub) -> None:
    sw = sub.add_parser("diagnosis-sweep", help="score the diagnosis on concealed effects of every id, sizes and "
                                                "maneuvers against the outside bar",
                        description="Fly about seventy F-16 recordings with one concealed effect each (every id of "
                                    "effects.md, several sizes, surfaces and maneuvers) and null recordings, "
                                    "diagnose each and score it: right effect first, size within 2 s.e. or 25 %, "
                                    "none on nulls, validation RMS -30 %. Writes OUT/sweep.md, OUT/sweep.json and "
                                    "one result per case (a rerun resumes).")
    sw.add_argument("--out", default="out/sweep", help="output folder")
    sw.add_argument("--case", action="append", default=None, help="one case (repeatable; default all)")
    sw.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    sw.set_defaults(func=lambda a: _diagnosis_commands().cmd_sweep(a))


def _add_outside_sweep(sub) -> None:
    so = sub.add_parser("outside-sweep", help="score the diagnosis on flight-test-like recordings at other conditions "
                                              "and on a second aircraft (c172x)",
                        description="Fly about 170 cases the way a flight-test team's data arrive (surfaces "
                                    "measured after a second-order actuator, inertial gyros, Gauss-Markov noise on "
                                    "alpha and beta, 8 significant digits, no h or thrust in some): eight F-16 "
                                    "conditions, four c172x, the 737 and the DHC-6, pitch-only, lateral-only and "
                                    "three-axis maneuvers, every effect id, nulls and noise-free self-checks. "
                                    "Scores a: right effect and parameter first, b: size within 2 s.e. or 25 %, "
                                    "c: false findings, d: validation RMS -30 %. Writes OUT/sweep.md, OUT/sweep.json "
                                    "and one result per case (a rerun resumes).")
    so.add_argument("--out", default="out/outside-sweep", help="output folder")
    so.add_argument("--case", action="append", default=None, help="one case (repeatable; default all)")
    so.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    so.set_defaults(func=lambda a: _diagnosis_commands().cmd_outside_sweep(a))


def _add_report(sub) -> None:
    r = sub.add_parser("report", help="turn campaign output into HTML, Markdown and JSON reports",
                       description="Write report.html (self-contained), report.md and report.json for a campaign "
                                   "output folder; --kind benchmark ranks the methods over one or more folders.")
    r.add_argument("dirs", nargs="+", help="campaign output folder(s)")
    r.add_argument("--kind", default="campaign", choices=["campaign", "benchmark"],
                   help="campaign: one folder's report; benchmark: methods ranked over several folders")
    r.add_argument("--out", default=None, help="where to write (default: the first folder)")
    r.set_defaults(func=lambda a: _report_commands().cmd_report(a))


def _add_nightly(sub) -> None:
    n = sub.add_parser("nightly", help="run the nightly campaign, compare, gate, report",
                       description="Run the nightly campaign, append it to the history, compare it with the previous "
                                   "run and the declared gates, and write nightly.html/.md/.json. Exits 1 when a gate "
                                   "fails, naming the method and parameter.")
    n.add_argument("--out", required=True, help="output folder of tonight's run")
    n.add_argument("--history", default=None, help="history folder (default: OUT/../history)")
    n.add_argument("--campaign", default="nightly", help="campaign to run (default: nightly)")
    n.add_argument("--gates", default=str(Path(__file__).resolve().parent / "nightly-gates.toml"),
                   help="gates file (TOML)")
    n.add_argument("--realizations", type=int, default=None,
                   help="override the campaign's realizations per cell (default: the campaign's own)")
    n.add_argument("--nights", type=int, default=30, help="runs shown in the trends (default 30)")
    n.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    n.add_argument("--scheduler", default=None,
                   help="'local' for a dask LocalCluster, or tcp://HOST:PORT of a Dask scheduler "
                        "(default: a local process pool)")
    n.add_argument("--cache", default=None, help="flight cache folder (default .sidbench-cache)")
    n.add_argument("--quiet", action="store_true", help="no progress display")
    n.set_defaults(func=lambda a: _report_commands().cmd_nightly(a))


def _add_review_maneuvers(sub) -> None:
    v = sub.add_parser("review-maneuvers", help="maneuver design review of candidate inputs",
                       description="Fly candidate inputs on an aircraft and condition, score them by Monte Carlo, "
                                   "and write review.html: input spectra against the modes, predicted Cramér-Rao "
                                   "bounds, regressor correlations (|r| > 0.9 flagged), excursions, accuracy, and a "
                                   "recommendation per parameter group.")
    v.add_argument("--aircraft", default="f16", choices=["f16", "737"], help="JSBSim model")
    v.add_argument("--condition", default="seed-5deg",
                   help="flight condition by name or by value, h=<ft>,V=<ft/s true airspeed>")
    v.add_argument("--maneuvers", default="doublet,2-1-1-2,3-2-1-1,sweep-linear,multisine",
                   help="comma list of input kinds (matched 6 s of motion and amplitude)")
    v.add_argument("--axis", default="both", choices=["lon", "lat", "both"],
                   help="longitudinal inputs (stabilator), lateral (aileron, rudder) or both")
    v.add_argument("--noise", default="realistic",
                   help="noise preset of the Monte Carlo realizations (harness/noise_presets.py)")
    v.add_argument("--realizations", type=int, default=30, help="Monte Carlo realizations per maneuver")
    v.add_argument("--out", required=True, help="output folder (review.html, .md, .json and the campaign output)")
    v.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    v.add_argument("--scheduler", default=None,
                   help="'local' for a dask LocalCluster, or tcp://HOST:PORT of a Dask scheduler "
                        "(default: a local process pool)")
    v.add_argument("--cache", default=None, help="flight cache folder (default .sidbench-cache)")
    v.add_argument("--quiet", action="store_true", help="no progress display")
    v.set_defaults(func=lambda a: _report_commands().cmd_review_maneuvers(a))


def _parser() -> argparse.ArgumentParser:
    """The command line: the global options, then each subcommand's parser (``_add_<name>``)."""
    p = argparse.ArgumentParser(
        prog="sidbench",
        description="Validation harness for aircraft parameter estimation: JSBSim flies the "
                    "maneuvers, estimators recover known coefficients, the harness scores them.")
    p.add_argument("--debug", action="store_true",
                   help="show the traceback of user errors too (one line and exit status 2 without it)")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in (_add_fly, _add_truth, _add_import, _add_estimate, _add_campaign, _add_bench, _add_demo,
                _add_diagnose, _add_calibrate, _add_gallery, _add_diagnosis_sweep, _add_outside_sweep, _add_report,
                _add_nightly, _add_review_maneuvers):
        add(sub)
    for command in sub.choices.values():
        command.formatter_class = _DefaultsFormatter
    p.formatter_class = _DefaultsFormatter
    return p


def _single_threaded_blas() -> None:
    """One BLAS thread per process (before numpy loads): campaign workers already use every
    core, and numpy's and scipy's separate OpenBLAS pools otherwise contend, making small
    LAPACK calls up to 50x slower and timings irreproducible."""
    import os
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``sidbench`` console script."""
    _single_threaded_blas()
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv  # accepted anywhere on the line, before or after the subcommand
    from harness.errors import quiet_broken_pipe, run_reporting_errors
    try:
        args = _parser().parse_args([a for a in argv if a != "--debug"])
    except BrokenPipeError:  # `sidbench x --help | head`
        return quiet_broken_pipe()
    return run_reporting_errors(args.func, args, args.command, debug=debug)


if __name__ == "__main__":
    raise SystemExit(main())
