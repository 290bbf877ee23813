"""The user-error types: something the user can fix (a malformed file, a bad option, an unknown
aircraft or condition). Defined in the lowest package so that every package can raise them; the
command line prints them as one line and exits 2 (``harness.errors``); any other exception is a
bug and keeps its traceback."""
from __future__ import annotations


class UserError(ValueError):
    """Something the user can fix; the message names the file, key or option and the rule."""


class OptionError(UserError):
    """An option (command line, campaign file, keyword) with a value the code cannot use."""
