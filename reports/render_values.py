"""Numbers, values and provenance as the report writers show them, and as JSON.

This module owns the formatting shared by the three formats so that they show the same
numbers: a number for people (:func:`format_number`), any table or provenance value as text
(:func:`format_value`), one scalar or a nested structure as JSON-ready values
(:func:`json_value`, :func:`jsonable`), the provenance as ordered ``(label, text)`` pairs
(:func:`provenance_items`) and the bold label of a summary line (:func:`split_label`).
"""
from __future__ import annotations

import datetime as _dt
import math
from collections.abc import Mapping
from pathlib import PurePath
from typing import Any

import numpy as np
import pandas as pd

__all__ = ["format_number", "format_value", "json_value", "jsonable", "provenance_items", "LABEL_MAX",
           "split_label"]

LABEL_MAX: int = 40
"""A summary line starting with a label this short followed by ': ' shows the label in bold."""


# --------------------------------------------------------------------------------------
# Values and numbers
# --------------------------------------------------------------------------------------

def _is_missing(value: Any) -> bool:
    """True for None, NaN, pandas NA and NaT (scalars only)."""
    if value is None or value is pd.NA or value is pd.NaT:
        return True
    if isinstance(value, (float, np.floating)):
        return math.isnan(value)
    if isinstance(value, (np.datetime64, np.timedelta64)):
        return bool(np.isnat(value))
    return False

def _is_number(value: Any) -> bool:
    """True for real or complex numbers other than booleans."""
    return isinstance(value, (int, float, complex, np.number)) and \
        not isinstance(value, (bool, np.bool_))

def format_number(value: Any, digits: int = 4) -> str:
    """Format a number for people: integers exactly, others to ``digits`` significant digits.

    Parameters
    ----------
    value : number
    digits : int, optional
        Significant digits for non-integers (default 4).

    Returns
    -------
    str
        ``'—'`` for NaN/NA, ``'inf'``/``'-inf'`` for infinities, ``'-0'`` shown as ``'0'``.

    Examples
    --------
    >>> format_number(3.14159265), format_number(-123456.7), format_number(120000)
    ('3.142', '-1.235e+05', '120000')
    """
    if _is_missing(value):
        return "—"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (complex, np.complexfloating)):
        return f"{complex(value):.{digits}g}"
    number = float(value)
    if math.isinf(number):
        return "inf" if number > 0 else "-inf"
    if number == 0:
        return "0"
    return f"{number:.{digits}g}"

def format_value(value: Any, digits: int = 4) -> str:
    """Format any table or provenance value as text (numbers via :func:`format_number`)."""
    if _is_missing(value) or _is_number(value) or isinstance(value, (bool, np.bool_)):
        return format_number(value, digits)
    if isinstance(value, (pd.Timestamp, _dt.datetime, _dt.date)):
        return value.isoformat()
    if isinstance(value, Mapping):
        return ", ".join(f"{k} {format_value(v, digits)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return ", ".join(format_value(v, digits) for v in value)
    return str(value)

def json_value(value: Any) -> Any:
    """Convert one scalar to a JSON-ready value: NaN/inf/NA -> None, numpy -> Python."""
    if _is_missing(value):
        return None
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        number = float(value)
        return number if math.isfinite(number) else None
    if isinstance(value, (complex, np.complexfloating)):
        return {"real": json_value(value.real), "imag": json_value(value.imag)}
    if isinstance(value, (pd.Timestamp, _dt.datetime, _dt.date, _dt.time)):
        return value.isoformat()
    if isinstance(value, (pd.Timedelta, _dt.timedelta)):
        return value.total_seconds()
    if isinstance(value, np.datetime64):
        return str(value)
    if isinstance(value, str):
        return value
    if isinstance(value, PurePath):
        return str(value)
    return str(value)

def jsonable(obj: Any) -> Any:
    """Convert a nested structure to JSON-ready values.

    Mappings become dicts with string keys, sequences, sets, arrays, Series and DataFrames
    become lists (a DataFrame: a list of row records), numpy scalars become Python ones,
    NaN/inf become ``None``; anything else unknown becomes its ``str``.
    """
    kind = type(obj)
    if kind is float:
        return obj if math.isfinite(obj) else None
    if obj is None or kind is str or kind is int or kind is bool:
        return obj
    if isinstance(obj, Mapping):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, pd.DataFrame):
        return [jsonable(dict(zip(map(str, obj.columns), row)))
                for row in obj.itertuples(index=False, name=None)]
    if isinstance(obj, (pd.Series, pd.Index)):
        return jsonable(obj.to_numpy())
    if isinstance(obj, (list, tuple, set, frozenset)):
        items = sorted(obj, key=str) if isinstance(obj, (set, frozenset)) else obj
        return [jsonable(v) for v in items]
    return json_value(obj)


# --------------------------------------------------------------------------------------
# Provenance
# --------------------------------------------------------------------------------------

_PROVENANCE_ORDER = ("campaign", "file", "sha256", "commit", "dirty", "versions", "seed",
                     "executor", "workers", "start", "end", "generated_at")


def _parse_time(value: Any) -> _dt.datetime | None:
    if isinstance(value, _dt.datetime):
        return value
    if isinstance(value, str):
        try:
            return _dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
        except ValueError:
            return None
    return None

def _duration(start: Any, end: Any) -> str:
    """``'12.3 s'``/``'4 min 5 s'``/``'2 h 3 min'`` between two times, or '' if unknown."""
    t0, t1 = _parse_time(start), _parse_time(end)
    if t0 is None or t1 is None or (t0.tzinfo is None) != (t1.tzinfo is None):
        return ""
    seconds = (t1 - t0).total_seconds()
    if seconds < 0:
        return ""
    if seconds < 60:
        return f"{seconds:.3g} s"
    if seconds < 3600:
        return f"{int(seconds // 60)} min {int(seconds % 60)} s"
    return f"{int(seconds // 3600)} h {int(seconds % 3600 // 60)} min"

def provenance_items(provenance: Mapping[str, Any]) -> list[tuple[str, str]]:
    """The provenance as ``(label, text)`` pairs in a fixed, readable order.

    Known keys are merged where that reads better (commit with ``+dirty``, executor with
    its workers, start and end with the duration); unknown keys follow in their own order.
    Missing or empty keys are left out.
    """
    p = dict(provenance)
    items: list[tuple[str, str]] = []

    def present(key: str) -> bool:
        return key in p and p[key] is not None and p[key] != ""

    if present("campaign"):
        items.append(("Campaign", format_value(p["campaign"])))
    if present("file"):
        items.append(("File", format_value(p["file"])))
    if present("sha256"):
        items.append(("SHA-256", format_value(p["sha256"])))
    if present("commit"):
        commit = format_value(p["commit"])
        if p.get("dirty"):
            commit += " (+dirty)"
        items.append(("Commit", commit))
    elif p.get("dirty"):
        items.append(("Commit", "(+dirty)"))
    if present("versions"):
        versions = p["versions"]
        text = (" · ".join(f"{k} {format_value(v)}" for k, v in versions.items())
                if isinstance(versions, Mapping) else format_value(versions))
        items.append(("Versions", text))
    if present("seed"):
        items.append(("Seed", format_value(p["seed"])))
    if present("executor") or present("workers"):
        text = format_value(p["executor"]) if present("executor") else ""
        if present("workers"):
            workers = format_value(p["workers"])
            text = f"{text}, {workers} workers" if text else f"{workers} workers"
        items.append(("Executor", text))
    if present("start") or present("end"):
        start = format_value(p["start"]) if present("start") else "?"
        end = format_value(p["end"]) if present("end") else "?"
        duration = _duration(p.get("start"), p.get("end"))
        items.append(("Run", f"{start} → {end}" + (f" ({duration})" if duration else "")))
    if present("generated_at"):
        items.append(("Generated", format_value(p["generated_at"])))
    for key, value in p.items():
        if key in _PROVENANCE_ORDER or value is None or value == "":
            continue
        items.append((str(key).replace("_", " ").capitalize(), format_value(value)))
    return items

def split_label(line: str, max_chars: int = LABEL_MAX) -> tuple[str, str]:
    """``('Largest bias', 'least squares ...')`` for ``'Largest bias: least squares ...'``: the
    text before the first ``': '`` when it is at most ``max_chars`` long, else ``('', line)``."""
    head, sep, rest = line.partition(": ")
    if sep and head.strip() and len(head) <= max_chars:
        return head, rest
    return "", line
