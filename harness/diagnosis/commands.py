"""The ``sidbench gallery``, ``sidbench diagnosis-sweep`` and ``sidbench outside-sweep`` subcommands."""
from __future__ import annotations

import argparse

from harness.diagnosis.gallery import CASES, case, write_case


def cmd_gallery(args: argparse.Namespace) -> int:
    names = args.case or [c.name for c in CASES]
    for name in names:
        paths = write_case(case(name), args.out, args.seed)
        print(f"{name}: {paths['identification']} and {paths['validation']}")
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    from harness.diagnosis.sweep import markdown, sweep
    rows = sweep(args.out, args.case, args.workers)
    print(markdown(rows))
    print(f"wrote {args.out}/sweep.md and sweep.json")
    return 0


def cmd_outside_sweep(args: argparse.Namespace) -> int:
    from harness.diagnosis.outside import markdown, sweep
    rows = sweep(args.out, args.case, args.workers)
    print(markdown(rows))
    print(f"wrote {args.out}/sweep.md and sweep.json")
    return 0
