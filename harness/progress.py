"""Progress of a campaign: a bar in a terminal, plain lines in CI logs."""
from __future__ import annotations

import sys
import time
from typing import TextIO


class Progress:
    """Shows ``done/total`` and the time left.

    In a terminal the line is redrawn in place; otherwise (CI logs) a plain line is printed
    at most every ``interval_s`` seconds and at the end.
    """

    def __init__(self, total: int, label: str, stream: TextIO | None = None, interval_s: float = 10.0,
                 enabled: bool = True) -> None:
        self.total, self.label = total, label
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.interval_s = interval_s
        self.enabled = enabled and total > 0
        self.start = time.monotonic()
        self.last = -1e9
        self.done = 0

    def _line(self) -> str:
        elapsed = time.monotonic() - self.start
        left = elapsed / self.done * (self.total - self.done) if self.done else float("nan")
        eta = "--:--" if left != left else f"{int(left // 60):02d}:{int(left % 60):02d}"
        frac = self.done / self.total
        if self.tty:
            bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
            return f"\r{self.label} [{bar}] {self.done}/{self.total} {100 * frac:5.1f}%  {eta} left"
        return f"{self.label}: {self.done}/{self.total} ({100 * frac:.0f}%), elapsed {elapsed:.0f} s, {eta} left"

    def update(self, n: int = 1) -> None:
        self.done += n
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            self.stream.write(self._line())
            if self.done >= self.total:
                self.stream.write("\n")
            self.stream.flush()
        elif now - self.last >= self.interval_s or self.done >= self.total:
            print(self._line(), file=self.stream, flush=True)
            self.last = now
