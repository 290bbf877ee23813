"""Units and the channel table of the recording format: every channel's quantity, canonical
unit and accepted units with their factors, column names ``<quantity>_<unit>``, and the conversion
of a table to canonical units and names."""
from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
import pandas as pd

from maneuvers.recording_errors import RecordingError, _col, row_label
from models.constants import G0_FPS2, G0_MPS2

__all__ = ["ChannelSpec", "CHANNELS", "REQUIRED_QUANTITIES", "RECOGNISED_UNITS", "parse_column", "to_canonical",
           "canonical_names", "convert_in_place", "frame_from_columns"]

_FT_M = 0.3048  # international foot, m (exact)
_LBF_N = 4.4482216152605  # pound-force, N (exact)
_KT_FPS = 1852.0 / 3600.0 / _FT_M  # knot, ft/s (= 1.6878098571...)
_PA_PSF = _FT_M**2 / _LBF_N  # 1 Pa in lbf/ft^2 (1 psf = 47.88025898... Pa)
_DEG_RAD = math.pi / 180.0

_TRUTH_PREFIX = "truth_"
_QUANTITY_RE = re.compile(r"[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*")
_UNIT_RE = re.compile(r"[A-Za-z0-9]+")


def _is_real(x: Any) -> bool:
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


@dataclass(frozen=True)
class ChannelSpec:
    """One row of the channel table.

    Parameters
    ----------
    quantity : str
        Quantity name, the part of a column name before the last underscore.
    canonical : str
        Canonical unit; canonical column name is ``f"{quantity}_{canonical}"``.
    units : Mapping[str, float]
        Every accepted unit (canonical included, factor 1.0) mapped to the factor that
        converts a value in that unit to the canonical unit (multiply).
    required : bool
        Whether every recording must carry the channel.
    meaning : str
        What the channel is.
    """

    quantity: str
    canonical: str
    units: Mapping[str, float]
    required: bool
    meaning: str

    def __post_init__(self) -> None:
        units = dict(self.units)
        if units.get(self.canonical) != 1.0:
            raise ValueError(f"{self.quantity}: canonical unit {self.canonical!r} must have factor 1.0")
        object.__setattr__(self, "units", MappingProxyType(units))

    @property
    def column(self) -> str:
        """Canonical column name, e.g. ``'alpha_rad'``."""
        return f"{self.quantity}_{self.canonical}"


def _build_channels() -> Mapping[str, ChannelSpec]:
    angle = {"rad": 1.0, "deg": _DEG_RAD}
    rate = {"rps": 1.0, "dps": _DEG_RAD}
    accel = {"rps2": 1.0, "dps2": _DEG_RAD}
    specific_force = {"g": 1.0, "fps2": 1.0 / G0_FPS2, "mps2": 1.0 / G0_MPS2}
    rows: list[tuple[str, str, dict[str, float], bool, str]] = [
        ("t", "s", {"s": 1.0}, True, "time, strictly increasing, uniform step"),
        ("V", "fps", {"fps": 1.0, "kts": _KT_FPS, "mps": 1.0 / _FT_M}, True, "true airspeed"),
        ("alpha", "rad", angle, True, "angle of attack (air-relative)"),
        ("beta", "rad", angle, True, "sideslip angle (air-relative)"),
        ("p", "rps", rate, True, "body-axis roll rate"),
        ("q", "rps", rate, True, "body-axis pitch rate"),
        ("r", "rps", rate, True, "body-axis yaw rate"),
        ("phi", "rad", angle, True, "Euler roll angle"),
        ("theta", "rad", angle, True, "Euler pitch angle"),
        ("psi", "rad", angle, True, "Euler yaw angle"),
        ("ax", "g", specific_force, True, "body-x specific force measured by the accelerometer"),
        ("ay", "g", specific_force, True, "body-y specific force measured by the accelerometer"),
        ("az", "g", specific_force, True,
         "body-z specific force measured by the accelerometer (about -1 g in level flight)"),
        ("de", "rad", angle, False,
         "stabilator/elevator position (JSBSim sign: positive trailing edge down)"),
        ("da", "rad", angle, False, "aileron position (JSBSim sign convention)"),
        ("dr", "rad", angle, False, "rudder position (JSBSim sign convention)"),
        ("qbar", "psf", {"psf": 1.0, "pa": _PA_PSF}, True, "dynamic pressure"),
        ("h", "ft", {"ft": 1.0, "m": 1.0 / _FT_M}, False, "pressure altitude"),
        ("mach", "1", {"1": 1.0}, False, "Mach number"),
        ("thrust", "lbf", {"lbf": 1.0, "n": 1.0 / _LBF_N}, False, "net thrust along body x"),
        ("pdot", "rps2", accel, False, "measured roll acceleration"),
        ("qdot", "rps2", accel, False, "measured pitch acceleration"),
        ("rdot", "rps2", accel, False, "measured yaw acceleration"),
        ("throttle", "1", {"1": 1.0}, False, "throttle position"),
        ("mass", "slug", {"slug": 1.0}, False, "time-varying mass (instead of meta['mass'])"),
        ("Ix", "slugft2", {"slugft2": 1.0}, False, "time-varying roll inertia"),
        ("Iy", "slugft2", {"slugft2": 1.0}, False, "time-varying pitch inertia"),
        ("Iz", "slugft2", {"slugft2": 1.0}, False, "time-varying yaw inertia"),
        ("Ixz", "slugft2", {"slugft2": 1.0}, False,
         "time-varying product of inertia (sign of the seed's Eqs. 3-5)"),
    ]
    return MappingProxyType(
        {q: ChannelSpec(q, canon, units, req, meaning) for q, canon, units, req, meaning in rows}
    )


CHANNELS: Mapping[str, ChannelSpec] = _build_channels()
"""Channel table: quantity -> :class:`ChannelSpec` (read-only)."""

REQUIRED_QUANTITIES: tuple[str, ...] = tuple(q for q, s in CHANNELS.items() if s.required)
"""Quantities every recording must carry."""

RECOGNISED_UNITS: frozenset[str] = frozenset(u for s in CHANNELS.values() for u in s.units)
"""Every unit string in the channel table; extra channels must use one of these."""


def parse_column(name: str, *, source: str | None = None) -> tuple[str, str]:
    """Split a column name into quantity and unit at its last underscore.

    Parameters
    ----------
    name : str
        Column name, ``<quantity>_<unit>``.
    source : str, optional
        File named in the error message.

    Returns
    -------
    tuple of str
        ``(quantity, unit)``, e.g. ``'alpha_deg' -> ('alpha', 'deg')`` and
        ``'truth_Cm_1' -> ('truth_Cm', '1')``.

    Raises
    ------
    RecordingError
        If the name has no underscore, or either part is empty or contains characters
        other than ASCII letters, digits and (inside the quantity) single underscores.
    """
    if not isinstance(name, str):
        raise RecordingError(
            f"column name must be a string, got {type(name).__name__}",
            source=source, key=_col(name), rule="bad-column-name",
        )
    quantity, sep, unit = name.rpartition("_")
    if not sep or not _QUANTITY_RE.fullmatch(quantity) or not _UNIT_RE.fullmatch(unit):
        raise RecordingError(
            "cannot parse column name; expected '<quantity>_<unit>' "
            "(letters and digits, split at the last underscore)",
            source=source, key=_col(name), rule="bad-column-name",
        )
    return quantity, unit


def _target_name(name: str, source: str | None) -> tuple[str, str, float]:
    """Return ``(quantity, canonical column name, factor)`` for an input column."""
    quantity, unit = parse_column(name, source=source)
    if quantity.startswith(_TRUTH_PREFIX):
        return quantity, name, 1.0
    spec = CHANNELS.get(quantity)
    if spec is not None:
        if unit not in spec.units:
            raise RecordingError(
                f"unknown unit {unit!r} for quantity {quantity!r}; accepted units: "
                f"{', '.join(repr(u) for u in spec.units)}",
                source=source, key=_col(name), rule="unknown-unit",
            )
        return quantity, spec.column, spec.units[unit]
    if unit not in RECOGNISED_UNITS:
        raise RecordingError(
            f"unknown quantity {quantity!r} with unrecognised unit {unit!r}; an extra channel "
            f"must use one of the units {sorted(RECOGNISED_UNITS)}",
            source=source, key=_col(name), rule="unknown-unit",
        )
    return quantity, name, 1.0


def _as_float64(values: Any, name: str, source: str | None) -> np.ndarray:
    """Return ``values`` as a new float64 array, refusing non-numeric entries."""
    arr = np.asarray(values)
    if arr.dtype.kind in "iuf":
        return np.array(arr, dtype=np.float64, copy=True)
    for row, v in enumerate(arr.ravel().tolist()):
        if not _is_real(v):
            raise RecordingError(
                f"non-numeric value {v!r} at {row_label(row)}",
                source=source, key=_col(name), rule="non-numeric",
            )
    return np.array([float(v) for v in arr.ravel().tolist()], dtype=np.float64)


def to_canonical(df: pd.DataFrame, source: str | None = None) -> pd.DataFrame:
    """Convert a table in any accepted units to canonical units and column names.

    Parameters
    ----------
    df : pandas.DataFrame
        Columns named ``<quantity>_<unit>`` in any unit of :data:`CHANNELS`, extra
        channels with a recognised unit, and ``truth_*`` columns.
    source : str, optional
        File named in error messages.

    Returns
    -------
    pandas.DataFrame
        New float64 table with a ``RangeIndex``; ``t_s`` first (when present), the
        other columns in their input order. Known quantities are converted and renamed
        (``alpha_deg`` -> ``alpha_rad``); extra and ``truth_*`` columns are kept
        verbatim. Values already canonical are copied bit for bit.

    Raises
    ------
    RecordingError
        For an unparseable column name, an unknown unit, two columns of the same
        quantity, or a non-numeric value.
    """
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"to_canonical expects a pandas.DataFrame, got {type(df).__name__}")
    names = list(df.columns)
    targets = canonical_names(names, source)
    columns = {name: _as_float64(df.iloc[:, position].to_numpy(), name, source)
               for position, name in enumerate(names)}
    return frame_from_columns(convert_in_place(columns, targets), len(df))


def canonical_names(names: list[Any], source: str | None = None) -> dict[Any, tuple[str, float]]:
    """Input column name -> (canonical column name, factor), refusing what the format does not allow.

    Raises
    ------
    RecordingError
        For an unparseable column name, an unknown unit or two columns of the same quantity.
    """
    out: dict[Any, tuple[str, float]] = {}
    seen: dict[str, str] = {}
    for name in names:
        quantity, target, factor = _target_name(name, source)
        if quantity in seen:
            raise RecordingError(
                f"quantity {quantity!r} is given twice (also by column {seen[quantity]!r})",
                source=source, key=_col(name), rule="duplicate-quantity",
            )
        seen[quantity] = name
        out[name] = (target, factor)
    return out


def convert_in_place(columns: dict[Any, np.ndarray], targets: dict[Any, tuple[str, float]]) -> dict[str, np.ndarray]:
    """Rename and scale float64 ``columns`` (which the caller gives up: scaled in place, no copy)
    to canonical units; ``t_s`` first, the others in input order."""
    out: dict[str, np.ndarray] = {}
    for name in list(columns):
        target, factor = targets[name]
        values = columns.pop(name)
        if factor != 1.0:
            np.multiply(values, factor, out=values)  # the same bits as ``values * factor``
        out[target] = values
    time_col = CHANNELS["t"].column
    order = ([time_col] if time_col in out else []) + [c for c in out if c != time_col]
    return {c: out[c] for c in order}


def frame_from_columns(columns: dict[str, np.ndarray], n: int) -> pd.DataFrame:
    """A table over ``columns`` without copying them (one block per column)."""
    return pd.DataFrame(columns, index=pd.RangeIndex(n), copy=False)
