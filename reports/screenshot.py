"""Take a PNG screenshot of an HTML report with headless Chromium.

Usage::

    python -m reports.screenshot REPORT.html OUT.png [--width 1280 --height 2000]

Prints the PNG's path. A missing file, a missing Chromium or a failed render prints one line
naming the cause and exits with status 2; no partial PNG is left behind.
"""
from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from reports.browser import DEFAULT_TIMEOUT_S, screenshot

__all__ = ["main", "build_parser"]


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be positive: {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be positive: {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The command line's parser."""
    parser = argparse.ArgumentParser(
        prog="python -m reports.screenshot",
        description="Render an HTML report in headless Chromium and save a PNG screenshot "
                    "(used for the README's pictures). Needs Debian's chromium package.")
    parser.add_argument("report", help="the HTML report to render")
    parser.add_argument("out", help="the PNG file to write")
    parser.add_argument("--width", type=_positive_int, default=1280,
                        help="window width in CSS pixels (default 1280)")
    parser.add_argument("--height", type=_positive_int, default=2000,
                        help="window height in CSS pixels; the page is cut there "
                             "(default 2000)")
    parser.add_argument("--timeout", type=_positive_float, default=DEFAULT_TIMEOUT_S,
                        help=f"seconds before Chromium is killed (default {DEFAULT_TIMEOUT_S:g})")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0, or 2 on an error)."""
    args = build_parser().parse_args(argv)
    try:
        path = screenshot(args.report, args.out, width=args.width, height=args.height,
                          timeout=args.timeout)
    except (OSError, RuntimeError, ValueError) as exc:
        print(f"screenshot: {exc}", file=sys.stderr)
        return 2
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
