"""The ``sidbench`` command line.

Each subcommand is a function ``cmd_<name>(args) -> int``; heavy imports happen inside them
so that ``--help`` stays quick. Errors the user can fix (a malformed recording, a trim that
fails, a diverging flight, a bad option) print one message naming the cause and exit 2.
"""
from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from harness.flying import add_flight_options


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sidbench",
        description="Validation harness for aircraft parameter estimation: JSBSim flies the "
                    "maneuvers, estimators recover known coefficients, the harness scores them.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", required=True)

    f = sub.add_parser("fly", help="trim an aircraft, fly a maneuver and write the recording",
                       description="Trim, fly one maneuver open or closed loop, and write the "
                                   "recording (CSV + .meta.json, or Parquet) with its truth.")
    add_flight_options(f)
    f.add_argument("--out", required=True, help="output recording: NAME.csv (+ NAME.meta.json) or NAME.parquet")
    f.set_defaults(func="harness.commands:cmd_fly")

    t = sub.add_parser("truth", help="truth derivatives of an aircraft at a flight condition",
                       description="Non-dimensional stability and control derivatives at trim, about "
                                   "the c.g., per rad (rates normalised by cbar/2V and b/2V), by central "
                                   "differences of JSBSim's own aerodynamics: the local slope and the "
                                   "best linear fit over the default maneuvers' excursion.")
    t.add_argument("--aircraft", default="f16", choices=["f16", "737"])
    t.add_argument("--variant", default="nominal", choices=["nominal", "exact-truth", "unstable"])
    t.add_argument("--condition", default=None, help="flight condition name (default: the aircraft's first)")
    t.add_argument("--json", default=None, help="write the derivatives to this JSON file")
    t.add_argument("--check-linearization", action="store_true",
                   help="also compare with jsbsim.FGLinearization and print the relative differences")
    t.set_defaults(func="harness.commands:cmd_truth")

    i = sub.add_parser("import", help="convert a SIDPAC .mat file to the canonical recording format",
                       description="Import a SIDPAC flight-test file (t, fdata, fds) into the canonical "
                                   "format, keeping its computed coefficient and normalised-rate columns.")
    i.add_argument("file", help="SIDPAC .mat file")
    i.add_argument("--out", required=True, help="output recording (.csv or .parquet)")
    i.set_defaults(func="harness.commands:cmd_import")

    b = sub.add_parser("bench", help="measure and print the benchmark table",
                       description="Time the project's main operations on this machine and print them.")
    b.add_argument("--repeat", type=int, default=7, help="repetitions per row (the best is kept)")
    b.set_defaults(func="harness.bench:cmd_bench")

    d = sub.add_parser("demo", help="the main job: fly the default maneuver, print its truth",
                       description="Fly the seed's default maneuver (F-16, stabilator 2-1-1-2, 1 deg, 1 s "
                                   "unit pulse) and print the truth table and where the recording went.")
    d.add_argument("--out", default="out", help="output folder (default: out)")
    d.set_defaults(func="harness.commands:cmd_demo")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``sidbench`` console script."""
    args = _parser().parse_args(argv)
    module, name = args.func.split(":")
    import importlib

    from harness.errors import USER_ERRORS
    func = getattr(importlib.import_module(module), name)
    try:
        return int(func(args) or 0)
    except USER_ERRORS as exc:
        print(f"sidbench {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
