"""A user's ASCII/CSV flight data into the canonical format, through a column map.

The map is a small TOML file (``sidbench import DATA --column-map MAP.toml --out REC.csv``)::

    delimiter = "whitespace"   # or ",", ";", "\\t" (default ",")
    comment = "#"              # lines starting with it are skipped (default "#")
    skip_rows = 0              # lines before the header line (default 0)
    time = "time"              # the source column that is time (becomes t_s)
    time_scale = 1.0           # factor to seconds (e.g. 0.001 for milliseconds; default 1)

    [columns]                  # source column -> canonical <quantity>_<unit> (any unit the format accepts)
    TAS = "V_mps"
    AoA = "alpha_rad"
    ...

    [scale]                    # optional: factors applied to a source column before its unit conversion
    elev = 0.5

    negate = ["ail"]           # optional: source columns whose sign is flipped (top-level key)

    [meta]                     # the recording's metadata, as in NAME.meta.json (geometry, mass, ...)
    aircraft = "..."
    [meta.geometry]
    S_ft2 = 300.0

Source columns the map does not name are dropped (and listed). Dynamic pressure, when not
mapped, is computed from Mach and pressure altitude (ISA), as the SIDPAC import does. Every
change made is written to ``meta['import_notes']`` and ``meta['import']``.
"""
from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from harness import isa
from harness.errors import UserError
from maneuvers.recording import FORMAT_ID, Recording, RecordingError, to_canonical

KNOWN_KEYS = {"delimiter", "comment", "skip_rows", "time", "time_scale", "columns", "scale", "negate", "meta"}


class ColumnMapError(UserError):
    """A column map that cannot be used: names the file, the key and what is wrong."""


def load_column_map(path: str | Path) -> dict[str, Any]:
    """Read and check a column map (TOML)."""
    path = Path(path)
    try:
        cmap = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ColumnMapError(f"{path}: no such column map") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ColumnMapError(f"{path}: not a TOML column map: {exc}") from None
    unknown = sorted(set(cmap) - KNOWN_KEYS)
    if unknown:
        raise ColumnMapError(f"{path}: unknown key(s) {unknown}; a column map has {sorted(KNOWN_KEYS)}")
    if "time" not in cmap or not isinstance(cmap["time"], str):
        raise ColumnMapError(f"{path}: key 'time' must name the source time column")
    cols = cmap.get("columns")
    if not isinstance(cols, dict) or not cols or not all(isinstance(v, str) for v in cols.values()):
        raise ColumnMapError(f"{path}: [columns] must map source columns to canonical <quantity>_<unit> names")
    for key in ("scale",):
        if not isinstance(cmap.get(key, {}), dict) or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in cmap.get(key, {}).values()):
            raise ColumnMapError(f"{path}: [{key}] must map source columns to numbers")
    neg = cmap.get("negate", [])
    if not isinstance(neg, list) or not all(isinstance(v, str) for v in neg):
        raise ColumnMapError(f"{path}: 'negate' must be a list of source column names")
    ts = cmap.get("time_scale", 1.0)
    if isinstance(ts, bool) or not isinstance(ts, (int, float)) or not ts > 0:
        raise ColumnMapError(f"{path}: 'time_scale' must be a positive number, not {ts!r}")
    if not isinstance(cmap.get("meta", {}), dict):
        raise ColumnMapError(f"{path}: [meta] must be a table (the recording's metadata)")
    return cmap


def _read_table(path: Path, cmap: dict[str, Any], source: str) -> pd.DataFrame:
    delim = cmap.get("delimiter", ",")
    sep = r"\s+" if delim in ("whitespace", " ", "space") else ("\t" if delim in ("tab", "\\t") else delim)
    try:
        df = pd.read_csv(path, sep=sep, comment=cmap.get("comment", "#") or None,
                         skiprows=int(cmap.get("skip_rows", 0)), engine="c" if sep != r"\s+" else "python")
    except FileNotFoundError:
        raise RecordingError("no such file", source=source, rule="not-a-file") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise RecordingError(f"cannot read it as a table with delimiter {delim!r}: {' '.join(str(exc).split())}",
                             source=source, rule="not-a-table") from None
    df.columns = [str(c).strip() for c in df.columns]
    return df


def import_with_map(data_path: str | Path, map_path: str | Path) -> Recording:
    """A user's ASCII/CSV file, converted to a canonical :class:`Recording` by a column map."""
    data_path, map_path = Path(data_path), Path(map_path)
    cmap = load_column_map(map_path)
    source = str(data_path)
    df = _read_table(data_path, cmap, source)
    mapping: dict[str, str] = {cmap["time"]: "t_s", **cmap["columns"]}
    if mapping.get(cmap["time"]) != "t_s":
        raise ColumnMapError(f"{map_path}: the time column {cmap['time']!r} is also mapped to "
                             f"{cmap['columns'][cmap['time']]!r}")
    named = set(mapping) | set(cmap.get("scale", {})) | set(cmap.get("negate", []))
    missing = [c for c in named if c not in df.columns]
    if missing:
        raise ColumnMapError(f"{map_path}: column(s) {sorted(missing)} not in {data_path.name}, whose header has "
                             f"{list(df.columns)}")
    notes: list[str] = []
    changes: list[dict[str, Any]] = []
    channels: dict[str, np.ndarray] = {}
    for src, dst in mapping.items():
        try:
            values = pd.to_numeric(df[src], errors="raise").to_numpy(dtype=float)
        except (ValueError, TypeError):
            bad = df[src][pd.to_numeric(df[src], errors="coerce").isna()].index[0]
            raise RecordingError(f"value {df[src].iloc[bad]!r} in row {bad + 1} is not a number",
                                 source=source, key=f"column {src!r}", rule="non-numeric") from None
        if src == cmap["time"] and float(cmap.get("time_scale", 1.0)) != 1.0:
            values = values * float(cmap["time_scale"])
            notes.append(f"time {src!r} multiplied by {cmap['time_scale']:g} to seconds.")
            changes.append({"column": src, "change": "scale", "factor": float(cmap["time_scale"])})
        factor = cmap.get("scale", {}).get(src)
        if factor is not None and float(factor) != 1.0:
            values = values * float(factor)
            notes.append(f"{src} multiplied by {float(factor):g} before becoming {dst}.")
            changes.append({"column": src, "change": "scale", "factor": float(factor)})
        if src in cmap.get("negate", []):
            values = -values
            notes.append(f"{src} negated (sign flip) before becoming {dst}.")
            changes.append({"column": src, "change": "negate"})
        if dst in channels:
            raise ColumnMapError(f"{map_path}: two source columns map to {dst!r}")
        channels[dst] = values
    dropped = [c for c in df.columns if c not in mapping]
    if dropped:
        notes.append(f"source column(s) not in the map dropped: {', '.join(dropped)}.")
    frame = to_canonical(pd.DataFrame(channels), source)
    if "qbar_psf" not in frame.columns and {"mach_1", "h_ft"} <= set(frame.columns):
        from harness.sidpac import isa_pressure_psf
        frame["qbar_psf"] = 0.5 * isa.GAMMA_AIR * isa_pressure_psf(frame["h_ft"].to_numpy()) * frame["mach_1"] ** 2
        notes.append("qbar_psf computed as 0.5*gamma*p*M^2 (gamma 1.4) from mach and h (pressure altitude, ISA "
                     "static pressure).")
    converted = [f"{src} -> {dst}" for src, dst in mapping.items() if not dst.endswith(_canonical_unit(dst))]
    if converted:
        notes.append("units converted to canonical: " + ", ".join(converted) + ".")
    meta: dict[str, Any] = {"format": FORMAT_ID, "sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]},
                            "thrust_offset_ft": 0.0, "source": f"{data_path.name} imported with {map_path.name}"}
    meta.update(cmap.get("meta", {}))
    meta["import_notes"] = list(meta.get("import_notes", [])) + notes
    meta["import"] = {"file": data_path.name, "column_map": map_path.name, "columns": mapping,
                      "changes": changes, "dropped": dropped}
    return Recording(frame, meta, name=data_path.stem).validate(source)


def _canonical_unit(name: str) -> str:
    from maneuvers.recording import CHANNELS
    quantity = name.rsplit("_", 1)[0]
    spec = CHANNELS.get(quantity)
    return spec.column.rsplit("_", 1)[1] if spec is not None else name.rsplit("_", 1)[-1]


def recording_to_text(rec: Recording, path: str | Path, columns: dict[str, tuple[str, float]], *,
                      sep: str = " ") -> Path:
    """Write ``rec`` as a plain table: ``columns`` maps a canonical column to (header, factor), the
    value written being canonical × factor (a helper for examples and tests)."""
    path = Path(path)
    out = pd.DataFrame({h: rec.data[c].to_numpy() * f for c, (h, f) in columns.items()})
    lines = [sep.join(out.columns)]
    lines += [sep.join(repr(float(v)) for v in row) for row in out.to_numpy()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


__all__ = ["ColumnMapError", "import_with_map", "load_column_map", "recording_to_text"]
