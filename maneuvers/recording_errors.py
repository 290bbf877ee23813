"""The recording format's error type and how its messages name a column, a row and a
metadata key."""
from __future__ import annotations

from functools import partial
from typing import Any

from models.errors import UserError

__all__ = ["RecordingError", "ROW_CONVENTION", "row_label"]


class RecordingError(UserError):
    """A recording breaks a rule of the format.

    The message names the file (or the recording, when no file is known), the column
    or metadata key, what is wrong, and the rule's identifier in brackets, e.g.
    ``"run1.csv: column 'alpha_deg': ... [rule: duplicate-quantity]"``.

    Parameters
    ----------
    message : str
        What is wrong.
    source : str, optional
        The file (or other origin) of the recording.
    key : str, optional
        The column or metadata key concerned, already quoted for display.
    rule : str, optional
        Short identifier of the rule broken (e.g. ``'time-not-uniform'``).

    Attributes
    ----------
    detail, source, key, rule
        The parts the message was built from.
    """

    def __init__(
        self,
        message: str,
        *,
        source: str | None = None,
        key: str | None = None,
        rule: str | None = None,
    ) -> None:
        self.detail = message
        self.source = source
        self.key = key
        self.rule = rule
        parts = [source if source else "<recording of unknown origin>"]
        if key:
            parts.append(key)
        text = ": ".join(parts) + ": " + message
        if rule:
            text += f" [rule: {rule}]"
        super().__init__(text)

    def __reduce__(self) -> tuple[Any, tuple[str]]:
        # Keep source/key/rule when pickled (e.g. by a process pool).
        return (
            partial(RecordingError, source=self.source, key=self.key, rule=self.rule),
            (self.detail,),
        )


def _col(name: object) -> str:
    return f"column {name!r}"


ROW_CONVENTION = "data rows counted from 1"
"""How every message numbers samples: the first sample (the line after a CSV's header) is row 1."""


def row_label(index: int) -> str:
    """``'row 42 (data rows counted from 1)'`` for the sample at 0-based ``index``."""
    return f"row {int(index) + 1} ({ROW_CONVENTION})"


def _did_you_mean(word: str, known: tuple[str, ...] | list[str]) -> str:
    import difflib
    close = difflib.get_close_matches(word, list(known), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


def _metakey(*path: str) -> str:
    return "meta" + "".join(f"[{p!r}]" for p in path)
