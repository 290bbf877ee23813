"""``sidbench calibrate``: the command-line front of :func:`harness.calibrate.calibrate`."""
from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from harness.atomic import ensure_folder
from harness.calibrate.output import write_calibration
from harness.calibrate.run import calibrate


def cmd_calibrate(args: argparse.Namespace, write_report: Callable[[Path], object] | None = None) -> int:
    """Calibrate, write OUT/calibration.json, OUT/model/, OUT/series/ and, with ``write_report``
    (the command line passes :func:`reports.calibration_report.write_calibration_report`: the
    harness never imports the reports package), OUT/report.html."""
    ensure_folder(args.out, "--out folder")  # refused before the flights, not after
    outputs = tuple(s.strip() for s in args.outputs.split(",") if s.strip()) if args.outputs else None
    result = calibrate(args.model, args.recording, args.parameters, validation=args.validation, outputs=outputs,
                       workers=args.workers, mass=args.mass, max_iterations=args.max_iterations,
                       hold=args.surfaces)
    doc = write_calibration(result, Path(args.out))
    if write_report is not None:
        write_report(Path(args.out))
    print(f"calibrated {len(doc['parameters'])} parameters in {doc['iterations']} iterations "
          f"({'converged' if doc['converged'] else 'not converged'}; {doc['flights']} flights, "
          f"{doc['seconds']:.1f} s)")
    for p in doc["parameters"]:
        print(f"  {p['name']}: {p['start']:.4g} -> {p['estimate']:.4g} ± {p['std_error']:.2g} {p['units']}")
    for role, fits in doc["fit_after"].items():
        parts = []
        for c, f in fits.items():
            b = doc["fit_before"][role][c]["rms"]
            if b and f["rms"] is not None:
                parts.append(f"{c} {100 * (f['rms'] / b - 1):+.0f}%")
        print(f"  {role} RMS change: {', '.join(parts)}")
    print(f"wrote {Path(args.out) / 'calibration.json'}, {Path(args.out) / 'report.html'}, {doc['model']['xml']}")
    return 0
