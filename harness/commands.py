"""Subcommands of ``sidbench`` that fly, compute truth, convert recordings, estimate and run
campaigns. Part of the command line, the composition root: it may import the reports package."""
from __future__ import annotations

import argparse
from pathlib import Path

from harness.atomic import check_output_file, write_json_atomic
from harness.errors import OptionError


def cmd_fly(args: argparse.Namespace) -> int:
    import dataclasses

    from harness.flying import spec_from_args
    from harness.noise import apply_noise, stream
    from harness.noise_presets import preset
    from harness.recording_io import write_recording
    from maneuvers.fly import fly_maneuver

    check_output_file(args.out, "--out recording")
    spec = spec_from_args(args)
    noise_name = getattr(args, "noise", "none") or "none"
    seed = int(getattr(args, "seed", 1))
    noise = preset(noise_name)
    if noise.turbulence is not None:  # flown, not added: drawn from the seed as a campaign draws it
        spec = dataclasses.replace(spec, turbulence=noise.turbulence,
                                   turbulence_seed=int(stream(seed, "turbulence").integers(1, 2**31 - 1)))
    rec = fly_maneuver(spec)
    if noise_name != "none":
        rec = apply_noise(rec, noise, seed)
    path = write_recording(rec, args.out)
    print(f"flew {spec.describe()}")
    if noise_name != "none":
        n = rec.meta["noise"]
        print(f"noise {noise_name}, seed {seed}: corrupted {', '.join(n['channels'])}"
              + (f"; dropped {', '.join(n['dropped'])}" if n["dropped"] else "")
              + ("; Dryden turbulence flown" if noise.turbulence is not None else ""))
    print(f"wrote {path} ({rec.n} samples)" + (f" and {Path(path).with_suffix('.meta.json')}"
                                               if Path(path).suffix == ".csv" else ""))
    return 0


def cmd_truth(args: argparse.Namespace) -> int:
    from harness.flying import resolve_aircraft
    from maneuvers.fly import default_truth, truth_table

    if args.json:
        check_output_file(args.json, "--json file")
    aircraft = resolve_aircraft(args.aircraft, args.variant)
    truth = default_truth(aircraft, args.condition)
    print(truth_table(truth))
    if args.check_linearization:
        from models.conditions import condition_for
        from models.exact import exact_truth_root
        from models.linearization import CHECKED, linearization_derivatives
        cond = condition_for(aircraft.model, args.condition)
        kwargs = {}
        if args.variant == "exact-truth":
            root, name = exact_truth_root(aircraft, cond)
            kwargs = {"root": root, "name": name}
        lin = linearization_derivatives(aircraft, cond, **kwargs)
        print("\nCross-check against jsbsim.FGLinearization (state derivatives only):")
        print(f"{'derivative':<12}{'central diff':>14}{'linearization':>15}{'rel diff':>10}")
        for k in CHECKED:
            a, b = truth.local[k], lin[k]
            print(f"{k:<12}{a:>14.6f}{b:>15.6f}{abs(a - b) / max(abs(a), 1e-9):>10.1e}")
    if args.json:
        write_json_atomic(args.json, truth.as_dict())
        print(f"\nwrote {args.json}")
    return 0


def cmd_import(args: argparse.Namespace) -> int:
    from harness.recording_io import read_recording, write_recording

    check_output_file(args.out, "--out recording")
    if getattr(args, "column_map", None):
        from harness.column_map import import_with_map
        rec = import_with_map(args.file, args.column_map)
    else:
        rec = read_recording(args.file)
    path = write_recording(rec, args.out)
    print(f"imported {args.file}: {rec.n} samples at {1 / rec.dt:g} Hz, channels "
          + ", ".join(c for c in rec.data.columns))
    notes = rec.meta.get("import_notes", [])
    if notes:
        print("what the import changed or assumed:")
        for note in notes:
            print(f"  - {note}")
    dropped = (rec.meta.get("sidpac") or {}).get("dropped") or []
    if dropped:
        print("dropped columns: " + "; ".join(dropped))
    print(f"wrote {path}")
    return 0


def _check_estimate_outputs(args: argparse.Namespace) -> None:
    """Refuse bad output paths before the fit (not after it was printed)."""
    from harness.atomic import _first_file_on_the_way
    from harness.errors import OutputPathError

    if args.json:
        check_output_file(args.json, "--json file")
    if getattr(args, "csv", None):
        check_output_file(args.csv, "--csv file")
    if getattr(args, "report", None):
        folder = Path(args.report)
        if folder.exists() and not folder.is_dir():
            raise OutputPathError(f"{folder}: cannot write the --report folder here: it is a file")
        blocker = _first_file_on_the_way(folder.parent)
        if blocker is not None:
            raise OutputPathError(f"{folder}: cannot create the --report folder: {blocker} is a file, not a folder")


def cmd_estimate(args: argparse.Namespace) -> int:
    from estimators.methods import make_estimator, method_info, parse_frequencies
    from estimators.regressors import DataOptions, Equation
    from harness.estimate_run import equation_time_histories, output_error_time_histories
    from harness.recording_io import read_recording

    _check_estimate_outputs(args)
    if args.max_lag is not None and args.max_lag < 0:
        raise OptionError(f"--max-lag must be at least 0, not {args.max_lag}")
    try:
        freqs = parse_frequencies(args.frequencies) if args.frequencies else None
    except ValueError as exc:
        raise OptionError(f"--frequencies {args.frequencies!r} is not a band F0:DF:F1 in Hz, a comma list of "
                          f"frequencies, auto, eq18 or sidpac ({exc})") from None
    if getattr(args, "model_file", None):
        return _estimate_model_file(args)
    if args.dependent is None or args.regressors is None:
        raise OptionError("--dependent and --regressors are required (or --method oe --model-file FILE)")
    rec = read_recording(args.recording)
    equation = Equation.parse(args.dependent, args.regressors, bias=not args.no_bias and method_info(args.method).bias)
    data = DataOptions(angular_acceleration=args.angular_acceleration, reference=args.reference)
    estimator = make_estimator(args.method, errors=args.errors, max_lag=args.max_lag,
                               autocorrelation=args.autocorrelation, frequencies_hz=freqs,
                               detrend=args.detrend, data=data)
    fit = estimator.fit(rec, equation)
    if method_info(args.method).whole_model:  # output error fits its model's terms
        print(f"{args.recording}: output error, {fit.info['model']} model, outputs {fit.dependent}")
        time, regs, notes = output_error_time_histories(rec, fit)
        names = tuple(regs.columns) if regs is not None else ()
    else:
        print(f"{args.recording}: {equation.describe()}")
        time, regs, notes = equation_time_histories(rec, equation, data, fit)
        names = equation.regressors
    _finish_estimate(args, rec, fit, time, regs, names, notes)
    return 0


def _finish_estimate(args, rec, fit, time, regs, names, notes) -> None:
    """Print the table (with the truth when the recording carries it) and write --json, --csv, --report."""
    from harness.estimate_run import EstimateRun, options_of, truth_of

    definition = getattr(args, "truth", "local") or "local"
    truth = truth_of(rec.meta, definition)
    simulated = bool(truth)
    if simulated and getattr(args, "reference", "trim") == "trim" and "bias" in fit.names:
        trim = (rec.meta.get("truth") or {}).get("trim_coefficients") or {}
        if fit.dependent in trim:
            truth["bias"] = float(trim[fit.dependent])
    print(fit.summary(truth=truth if simulated else None))
    if simulated:
        print(f"truth: the recording's {definition} derivatives; error/se = (estimate - truth) / std error")
    run = EstimateRun(recording=str(args.recording), fit=fit, options=options_of(args), truth=truth,
                      truth_definition=definition, simulated=simulated, time=time, regressors=regs,
                      regressor_names=tuple(names), notes=tuple(notes))
    if args.json:
        write_json_atomic(args.json, _finite(run.to_dict()))
        print(f"wrote {args.json}")
    if getattr(args, "csv", None):
        from harness.atomic import write_text_atomic
        write_text_atomic(args.csv, run.parameter_table().to_csv(index=False, float_format="%.17g"))
        print(f"wrote {args.csv}")
    if getattr(args, "report", None):
        from reports.estimate_report import write_estimate_report
        html = write_estimate_report(run, args.report)
        print(f"wrote {html}")


def _finite(obj):
    """NaN and inf as null, so the JSON is strict."""
    import math
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    return obj


def _estimate_model_file(args: argparse.Namespace) -> int:
    """``estimate --method oe --model-file FILE``: output error for the model the file defines."""
    from estimators.dynamic_models import load_model_file
    from estimators.output_error import OutputError
    from harness.estimate_run import output_error_time_histories
    from harness.recording_io import read_recording

    if args.method != "oe":
        raise OptionError(f"--model-file is for --method oe, not {args.method}")
    if args.dependent is not None or args.regressors is not None:
        raise OptionError("--model-file fits the model as the file writes it: leave out --dependent and --regressors")
    model = load_model_file(args.model_file)
    rec = read_recording(args.recording)
    fit = OutputError(model=model).fit(rec)
    print(f"{args.recording}: model {model.name} from {args.model_file} (outputs {', '.join(model.outputs)}; "
          f"inputs {', '.join(model.inputs) or 'none'})")
    time, regs, notes = output_error_time_histories(rec, fit)
    _finish_estimate(args, rec, fit, time, regs, tuple(model.inputs), notes)
    return 0


def cmd_campaign(args: argparse.Namespace) -> int:
    from harness.campaign import load_campaign
    from harness.runner import run_campaign
    from harness.scores import format_scores

    if args.workers is not None and args.workers < 1:
        raise OptionError(f"--workers must be at least 1, not {args.workers} (leave it out to use every core)")
    campaign = load_campaign(args.file)
    if args.realizations is not None:
        if args.realizations < 1:
            raise OptionError(f"--realizations must be at least 1, not {args.realizations}")
        campaign = campaign.with_realizations(args.realizations)
    run = run_campaign(campaign, args.out, scheduler=args.scheduler, workers=args.workers, cache_dir=args.cache,
                       history_dir=args.history, progress=not args.quiet)
    m = run.meta
    print(f"campaign {campaign.name}: {m['campaign']['cells']} cells x {campaign.realizations} realizations, "
          f"{m['estimates']} estimates; {m['tasks_run']} tasks run, {m['tasks_resumed']} resumed; "
          f"{m['wall_s']:.1f} s on {m['executor']}")
    print(format_scores(run.scores))
    print(f"\nwrote {run.out_dir / 'results.parquet'}, {run.out_dir / 'scores.parquet'}, {run.out_dir / 'run.json'}")
    return 0


def cmd_diagnose(args: argparse.Namespace) -> int:
    """``sidbench diagnose``: the diagnosis and its report (``reports.commands``), with OUT marked
    incomplete until both are written."""
    from harness.diagnosis.run import incomplete_marker
    from reports.commands import cmd_diagnose as diagnose_and_report

    with incomplete_marker(Path(args.out)):
        return int(diagnose_and_report(args) or 0)
