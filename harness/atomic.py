"""Writing files whole or not at all: a temporary file in the same folder, then a rename."""
from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import numpy as np

from harness.errors import OutputPathError


def write_atomic(path: str | Path, writer: Callable[[IO[bytes]], Any]) -> Path:
    """Call ``writer(fh)`` on a temporary file beside ``path`` and rename it into place.

    A crash or kill leaves either the old file or the new one, never half of one.
    """
    path = check_output_file(path)
    ensure_folder(path.parent)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            writer(fh)
            fh.flush()
            os.fsync(fh.fileno())
        # mkstemp creates 0600; give the file the permissions an ordinary open() would.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _first_file_on_the_way(folder: Path) -> Path | None:
    """The first existing non-folder among ``folder`` and its parents, if any."""
    for p in (folder, *folder.parents):
        if p.exists():
            return None if p.is_dir() else p
    return None


def ensure_folder(folder: str | Path, what: str = "folder") -> Path:
    """Create ``folder`` (and its parents), or refuse naming the file that is in the way."""
    folder = Path(folder)
    blocker = _first_file_on_the_way(folder)
    if blocker is not None:
        raise OutputPathError(f"{folder}: cannot create this {what}: {blocker} is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputPathError(f"{folder}: cannot create this {what}: {exc.strerror or exc}") from None
    return folder


def check_output_file(path: str | Path, what: str = "output file") -> Path:
    """Refuse, before any work, an output file that is a folder or whose folder is a file."""
    path = Path(path)
    if path.is_dir():
        raise OutputPathError(f"{path}: cannot write this {what}: it is a folder")
    blocker = _first_file_on_the_way(path.parent)
    if blocker is not None:
        raise OutputPathError(f"{path}: cannot write this {what}: {blocker} is a file, not a folder")
    return path


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return write_atomic(path, lambda fh: fh.write(text.encode("utf-8")))


def write_json_atomic(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as indented JSON to ``path`` atomically."""
    return write_text_atomic(path, json.dumps(obj, indent=2, allow_nan=False) + "\n")


def jsonable(x: Any) -> Any:
    """``x`` with NumPy scalars turned into Python ones, tuples into lists, dict keys into
    strings and non-finite floats into None (JSON has no NaN), recursively."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (float, np.floating)):
        v = float(x)
        return v if math.isfinite(v) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x
