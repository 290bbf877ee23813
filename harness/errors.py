"""User errors and internal errors, and how the command line reports them.

* A **user error** is something the user can fix: a malformed recording, a bad campaign file
  or option, an output path that cannot be written, a trim that fails. It is printed as one
  line naming the file, the column or key, and the rule, and the command exits with status 2.
  ``--debug`` adds the traceback.
* An **interruption** (Ctrl-C) prints one line (with how to resume, where that applies) and
  exits with status 130.
* Anything else is an **internal error** (a bug): its traceback is printed, followed by one
  line saying so, and the command exits with status 1.

User-facing errors derive from :class:`UserError` (defined in :mod:`models.errors`, the lowest
package, so that every package can raise it); a trim or flight failure (``TrimError``,
``FlightError``), a failed diagnosis and a path the user gave that cannot be used are user errors
too. A plain ``ValueError`` is not: it is a bug, reported with its traceback.
"""
from __future__ import annotations

import sys
import traceback
from collections.abc import Callable
from typing import Any, TextIO

from models.errors import OptionError, UserError

__all__ = ["UserError", "OptionError", "OutputPathError", "Interrupted", "user_errors", "quiet_broken_pipe",
           "run_reporting_errors", "EXIT_USER", "EXIT_INTERNAL", "EXIT_INTERRUPTED", "EXIT_BROKEN_PIPE"]


class OutputPathError(UserError):
    """An output file or folder that cannot be written where it was asked for."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C, with a message saying what was kept and how to resume."""


EXIT_USER = 2
EXIT_INTERNAL = 1
EXIT_INTERRUPTED = 130

# OS errors that name a path the user gave (missing file, a file where a folder is needed...).
_PATH_ERRORS: tuple[type[BaseException], ...] = (
    FileNotFoundError, FileExistsError, IsADirectoryError, NotADirectoryError, PermissionError)


def user_errors() -> tuple[type[BaseException], ...]:
    """Every exception type reported as a user error: :class:`UserError` and its subclasses (a
    malformed recording, input spec, equation, campaign, column map, output-error model...), a
    failed trim or flight, a failed diagnosis, running out of memory and an unusable path.
    Imported lazily: some of these modules import this one."""
    from harness.diagnosis.verdict import DiagnosisError
    from models.flight import FlightError
    from models.trim import TrimError
    return (UserError, TrimError, FlightError, DiagnosisError, MemoryError) + _PATH_ERRORS


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, MemoryError):
        return "out of memory" + (f": {exc}" if str(exc) else "")
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text


EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a shell reports for a writer whose reader left


def quiet_broken_pipe() -> int:
    """The reader of our output went away (``sidbench … | head``): stop quietly. Standard output
    is pointed at /dev/null so that Python's final flush has nowhere to fail."""
    import os
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return EXIT_BROKEN_PIPE


def run_reporting_errors(func: Callable[[Any], int | None], args: Any, command: str, *, debug: bool = False,
                         stream: TextIO | None = None) -> int:
    """Run ``func(args)`` and turn what it raises into a message and an exit status."""
    err = stream or sys.stderr
    prefix = f"sidbench {command}"
    try:
        status = int(func(args) or 0)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        return quiet_broken_pipe()
    except KeyboardInterrupt as exc:
        if debug:
            traceback.print_exc(file=err)
        print(f"{prefix}: interrupted" + (f"; {exc}" if str(exc) else ""), file=err)
        return EXIT_INTERRUPTED
    except user_errors() as exc:
        if debug:
            traceback.print_exc(file=err)
        print(f"{prefix}: error: {_one_line(exc)}", file=err)
        return EXIT_USER
    except Exception as exc:  # noqa: BLE001 - a bug: keep its traceback
        traceback.print_exc(file=err)
        print(f"{prefix}: internal error (a bug, not your input): {type(exc).__name__}: {_one_line(exc)}",
              file=err)
        return EXIT_INTERNAL
