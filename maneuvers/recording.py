"""The canonical flight recording: the in-memory type and the format's rules.

A recording is one maneuver: uniformly sampled time histories plus the metadata
needed to turn them into force and moment coefficients. The format is specified in
``../shared/recording-format.md``; this module is its executable form.

* :data:`CHANNELS` is the channel table (quantity, canonical unit, accepted units
  with their conversion factors, required flag, meaning).
* :func:`parse_column` splits a column name ``<quantity>_<unit>`` at its last
  underscore.
* :func:`to_canonical` converts a table in any accepted units to canonical units and
  names, refusing any column it does not understand.
* :class:`Recording` holds canonical data and metadata; :meth:`Recording.validate`
  applies every rule of the format and raises :class:`RecordingError` naming the
  file, the column or metadata key, and the rule broken.

Unknown extra channels
----------------------
A column whose quantity is not in :data:`CHANNELS` is kept *verbatim* (same name,
same values) provided its unit is one of the units the table recognises
(:data:`RECOGNISED_UNITS`, e.g. ``'1'``, ``'rad'``, ``'deg'``, ``'fps'``). It is not
converted: the reader cannot know which canonical unit an unknown quantity is meant
to have, and keeping it verbatim is lossless. Columns whose quantity starts with
``truth_`` (e.g. ``truth_Cm_1``) are always kept verbatim, whatever their unit.

Mass and inertia
----------------
Each of ``mass_slug``, ``Ix_slugft2``, ``Iy_slugft2``, ``Iz_slugft2`` and
``Ixz_slugft2`` must be given exactly once: either as a scalar in ``meta['mass']``
or as a channel of the same name (time-varying). Giving one both ways is refused,
because choosing one of them would be a silent guess. ``Ixz_slugft2`` has the sign
of the seed's Eqs. 3-5 (positive 982 for the F-16).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import partial
from types import MappingProxyType
from typing import Any

import numpy as np
import pandas as pd
from models.errors import UserError
from models.constants import G0_FPS2, G0_MPS2, SURFACES

__all__ = [
    "CHANNELS",
    "CONTROL_QUANTITIES",
    "FORMAT_ID",
    "G0_FPS2",
    "GEOMETRY_KEYS",
    "MASS_KEYS",
    "RECOGNISED_UNITS",
    "REQUIRED_QUANTITIES",
    "TIME_JITTER_TOL",
    "ChannelSpec",
    "Recording",
    "RecordingError",
    "PHYSICAL_LIMITS",
    "ROW_CONVENTION",
    "canonical_names",
    "convert_in_place",
    "frame_from_columns",
    "parse_column",
    "row_label",
    "to_canonical",
]

# --------------------------------------------------------------------------------------
# Constants and unit factors
# --------------------------------------------------------------------------------------

FORMAT_ID = "flight-recording/1"
"""Value required in ``meta['format']``."""

TIME_JITTER_TOL = 1e-6
"""Largest accepted relative deviation of a time step from the mean step."""

_FT_M = 0.3048  # international foot, m (exact)
_LBF_N = 4.4482216152605  # pound-force, N (exact)
_KT_FPS = 1852.0 / 3600.0 / _FT_M  # knot, ft/s (= 1.6878098571...)
_PA_PSF = _FT_M**2 / _LBF_N  # 1 Pa in lbf/ft^2 (1 psf = 47.88025898... Pa)
_DEG_RAD = math.pi / 180.0

GEOMETRY_KEYS: tuple[str, ...] = ("S_ft2", "b_ft", "cbar_ft")
"""Keys required in ``meta['geometry']`` (positive, finite)."""

MASS_KEYS: tuple[str, ...] = ("mass_slug", "Ix_slugft2", "Iy_slugft2", "Iz_slugft2", "Ixz_slugft2")
"""Mass properties; each given in ``meta['mass']`` or as a channel of the same name."""

_POSITIVE_MASS_KEYS = frozenset(MASS_KEYS[:4])  # Ixz may have either sign

CONTROL_QUANTITIES: tuple[str, ...] = SURFACES
"""Control-surface quantities; at least one must be present."""

_TRUTH_PREFIX = "truth_"
_QUANTITY_RE = re.compile(r"[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*")
_UNIT_RE = re.compile(r"[A-Za-z0-9]+")


# --------------------------------------------------------------------------------------
# Errors
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# Channel table
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# Column names and unit conversion
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# Validation helpers
# --------------------------------------------------------------------------------------


def _is_real(x: Any) -> bool:
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def _finite_real(x: Any) -> bool:
    return _is_real(x) and math.isfinite(float(x))


def _refuse_unknown_keys(table: dict, known: tuple[str, ...], src: str, where: str) -> None:
    for key in table:
        if key not in known:
            raise RecordingError(
                f"unknown key; known keys: {', '.join(known)}{_did_you_mean(str(key), known)}",
                source=src, key=_metakey(where, str(key)), rule="unknown-key",
            )


_PI = math.pi
PHYSICAL_LIMITS: Mapping[str, tuple[float, float, bool, str]] = MappingProxyType({
    # canonical column: (low, high, low bound excluded, why); generous, only the impossible is refused
    "V_fps": (0.0, 3.0e4, True, "a true airspeed is positive and below 30,000 ft/s"),
    "qbar_psf": (0.0, 1.0e5, True, "a dynamic pressure is positive (in flight) and below 100,000 psf"),
    "alpha_rad": (-_PI, _PI, False, "an air angle lies within +-pi rad"),
    "beta_rad": (-_PI, _PI, False, "an air angle lies within +-pi rad"),
    "theta_rad": (-_PI, _PI, False, "a pitch angle lies within +-pi rad"),
    "phi_rad": (-1.0e3, 1.0e3, False, "a bank angle (even unwrapped) lies within +-1000 rad"),
    "psi_rad": (-1.0e3, 1.0e3, False, "a heading (even unwrapped) lies within +-1000 rad"),
    "p_rps": (-50.0, 50.0, False, "a body rate lies within +-50 rad/s"),
    "q_rps": (-50.0, 50.0, False, "a body rate lies within +-50 rad/s"),
    "r_rps": (-50.0, 50.0, False, "a body rate lies within +-50 rad/s"),
    "ax_g": (-100.0, 100.0, False, "a specific force lies within +-100 g"),
    "ay_g": (-100.0, 100.0, False, "a specific force lies within +-100 g"),
    "az_g": (-100.0, 100.0, False, "a specific force lies within +-100 g"),
    "de_rad": (-_PI, _PI, False, "a surface deflection lies within +-pi rad"),
    "da_rad": (-_PI, _PI, False, "a surface deflection lies within +-pi rad"),
    "dr_rad": (-_PI, _PI, False, "a surface deflection lies within +-pi rad"),
    "mach_1": (0.0, 30.0, False, "a Mach number lies in [0, 30]"),
    "h_ft": (-2.0e4, 2.0e6, False, "a pressure altitude lies within -20,000 and 2,000,000 ft"),
    "pdot_rps2": (-1.0e4, 1.0e4, False, "an angular acceleration lies within +-10,000 rad/s^2"),
    "qdot_rps2": (-1.0e4, 1.0e4, False, "an angular acceleration lies within +-10,000 rad/s^2"),
    "rdot_rps2": (-1.0e4, 1.0e4, False, "an angular acceleration lies within +-10,000 rad/s^2"),
    "thrust_lbf": (-1.0e7, 1.0e7, False, "a thrust lies within +-10,000,000 lbf"),
})
"""Sample limits of the channels (canonical units): a sample outside is refused naming its row."""


# --------------------------------------------------------------------------------------
# The recording
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class Recording:
    """One maneuver in the canonical format.

    Parameters
    ----------
    data : pandas.DataFrame
        Columns ``'<quantity>_<canonical unit>'`` in canonical units, float64, ``t_s``
        first. Treat as read-only.
    meta : dict
        Metadata as in the format document (``format``, ``aircraft``, ``geometry``,
        ``mass``, ``sensors``, ``thrust_offset_ft``, ``source``, ``maneuver``,
        ``trim``) plus optional project keys (``truth``, ``simulation``, ``noise``,
        ``import_notes``...). Nested dicts and lists are kept verbatim.
    name : str
        Short name (the file stem when read from disk).

    Notes
    -----
    Construction does not validate; call :meth:`validate` (which returns ``self``) or
    build with :meth:`from_frame`. Comparison is by identity; use :meth:`equals` for
    exact content equality.
    """

    data: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)
    name: str = "recording"

    def __post_init__(self) -> None:
        if not isinstance(self.data, pd.DataFrame):
            raise TypeError(f"Recording.data must be a pandas.DataFrame, got {type(self.data).__name__}")
        if not isinstance(self.meta, dict):
            raise TypeError(f"Recording.meta must be a dict, got {type(self.meta).__name__}")

    def __repr__(self) -> str:
        return f"Recording(name={self.name!r}, n={len(self.data)}, columns={list(self.data.columns)})"

    # ---------------------------------------------------------------- construction
    @classmethod
    def from_frame(
        cls,
        data: pd.DataFrame,
        meta: dict[str, Any],
        name: str = "recording",
        source: str | None = None,
    ) -> Recording:
        """Convert ``data`` to canonical units (:func:`to_canonical`) and validate.

        Parameters
        ----------
        data : pandas.DataFrame
            Columns in any accepted unit.
        meta : dict
            Metadata.
        name : str
            Recording name.
        source : str, optional
            File named in error messages.

        Returns
        -------
        Recording
            A validated recording.
        """
        return cls(to_canonical(data, source), meta, name).validate(source)

    # ---------------------------------------------------------------- convenience
    @property
    def n(self) -> int:
        """Number of samples."""
        return len(self.data)

    @property
    def t(self) -> np.ndarray:
        """Time, s."""
        return self.channel("t")

    @property
    def dt(self) -> float:
        """Mean time step, s: ``(t[-1] - t[0]) / (n - 1)``."""
        t = self.t
        if len(t) < 2:
            raise RecordingError(
                "needs at least two samples to have a time step",
                source=f"recording {self.name!r}", key=_col("t_s"), rule="too-short",
            )
        return float((t[-1] - t[0]) / (len(t) - 1))

    @property
    def quantities(self) -> dict[str, str]:
        """Quantity -> column name, in column order (assumes parseable names)."""
        return {parse_column(c)[0]: c for c in self.data.columns}

    def column(self, quantity: str) -> str:
        """Column name holding ``quantity`` (e.g. ``'alpha' -> 'alpha_rad'``).

        Raises
        ------
        RecordingError
            If the recording has no such channel.
        """
        for c in self.data.columns:
            if isinstance(c, str) and c.rpartition("_")[0] == quantity:
                return c
        raise RecordingError(
            f"no channel for quantity {quantity!r}",
            source=f"recording {self.name!r}", key=f"quantity {quantity!r}", rule="missing-channel",
        )

    def has(self, quantity: str) -> bool:
        """Whether the recording has a channel for ``quantity``."""
        return any(isinstance(c, str) and c.rpartition("_")[0] == quantity for c in self.data.columns)

    def channel(self, quantity: str) -> np.ndarray:
        """Values of ``quantity`` in canonical units (read-only float64 array).

        Parameters
        ----------
        quantity : str
            E.g. ``'alpha'``, ``'qbar'``, ``'truth_Cm'``, ``'CY'``.

        Raises
        ------
        RecordingError
            Naming the quantity, if it is absent.
        """
        return self.data[self.column(quantity)].to_numpy(dtype=np.float64)

    @property
    def truth(self) -> pd.DataFrame:
        """Truth columns (``truth_<name>_<unit>``), renamed to ``<name>`` (e.g. ``'Cm'``)."""
        cols = {c: c.rpartition("_")[0][len(_TRUTH_PREFIX):]
                for c in self.data.columns if isinstance(c, str) and c.startswith(_TRUTH_PREFIX)}
        return self.data[list(cols)].rename(columns=cols)

    @property
    def geometry(self) -> dict[str, float]:
        """Copy of ``meta['geometry']`` (``S_ft2``, ``b_ft``, ``cbar_ft``)."""
        return dict(self.meta.get("geometry", {}))

    @property
    def mass(self) -> dict[str, float]:
        """Copy of ``meta['mass']``; time-varying properties are channels instead (see :meth:`mass_at`)."""
        return dict(self.meta.get("mass", {}))

    def _mass_source(self, key: str) -> tuple[str, Any]:
        if key in self.data.columns:
            return "channel", self.data[key].to_numpy(dtype=np.float64)
        mass = self.meta.get("mass", {})
        if isinstance(mass, dict) and key in mass:
            return "meta", float(mass[key])
        raise RecordingError(
            "mass property given neither in meta['mass'] nor as a channel",
            source=f"recording {self.name!r}", key=_metakey("mass", key), rule="missing-mass",
        )

    @property
    def mass_is_constant(self) -> bool:
        """True when every mass property comes from ``meta['mass']`` (none is a channel)."""
        return not any(k in self.data.columns for k in MASS_KEYS)

    def mass_at(self, index: int | None = None) -> dict[str, float | np.ndarray]:
        """Mass properties, from ``meta['mass']`` or from channels.

        Parameters
        ----------
        index : int, optional
            Sample index. When given, every value is a float (the channel's value at
            that sample, or the constant). When omitted, every value is a float64
            array of length :attr:`n` (constants broadcast).

        Returns
        -------
        dict
            Keys :data:`MASS_KEYS`: ``mass_slug``, ``Ix_slugft2``, ``Iy_slugft2``,
            ``Iz_slugft2``, ``Ixz_slugft2``.
        """
        out: dict[str, float | np.ndarray] = {}
        for key in MASS_KEYS:
            kind, value = self._mass_source(key)
            if index is not None:
                out[key] = float(value[index]) if kind == "channel" else value
            else:
                out[key] = value if kind == "channel" else np.full(self.n, value)
        return out

    def equals(self, other: Recording) -> bool:
        """Exact equality: same name, metadata, column names/order and bit-identical values."""
        if not isinstance(other, Recording):
            return False
        if self.name != other.name or self.meta != other.meta:
            return False
        if list(self.data.columns) != list(other.data.columns) or self.n != other.n:
            return False
        return all(
            np.array_equal(self.data[c].to_numpy(), other.data[c].to_numpy(), equal_nan=True)
            for c in self.data.columns
        )

    # ---------------------------------------------------------------- validation
    def validate(self, source: str | None = None) -> Recording:
        """Apply every rule of the format.

        Parameters
        ----------
        source : str, optional
            File named in error messages; defaults to ``"recording '<name>'"``.

        Returns
        -------
        Recording
            ``self``, so that ``rec = Recording(...).validate()`` reads naturally.

        Raises
        ------
        RecordingError
            At the first rule broken, naming the file, the column or key, and the rule.
        """
        src = source if source is not None else f"recording {self.name!r}"
        self._check_columns(src)
        t = self._check_time(src)
        self._check_finite(src, t)
        self._check_required(src)
        self._check_plausible(src, t)
        self._check_format(src)
        self._check_geometry(src)
        self._check_mass(src)
        self._check_optional_meta(src)
        return self

    def _check_columns(self, src: str) -> None:
        seen: dict[str, str] = {}
        for name in self.data.columns:
            quantity, target, _ = _target_name(name, src)
            if target != name:
                raise RecordingError(
                    f"unit is not canonical for {quantity!r}; expected column {target!r} "
                    "(convert with to_canonical)",
                    source=src, key=_col(name), rule="non-canonical-unit",
                )
            if quantity in seen:
                raise RecordingError(
                    f"quantity {quantity!r} is given twice (also by column {seen[quantity]!r})",
                    source=src, key=_col(name), rule="duplicate-quantity",
                )
            seen[quantity] = name
            dtype = self.data[name].dtype
            if dtype != np.float64:
                raise RecordingError(
                    f"values must be float64, got {dtype}",
                    source=src, key=_col(name), rule="not-float64",
                )

    def _check_time(self, src: str) -> np.ndarray:
        time_col = CHANNELS["t"].column
        if time_col not in self.data.columns:
            raise RecordingError(
                "time channel is missing", source=src, key=_col(time_col), rule="missing-time",
            )
        if self.data.columns[0] != time_col:
            raise RecordingError(
                f"time must be the first column (first is {self.data.columns[0]!r})",
                source=src, key=_col(time_col), rule="time-not-first",
            )
        t = self.data[time_col].to_numpy()
        if len(t) < 2:
            raise RecordingError(
                f"needs at least two samples, has {len(t)}",
                source=src, key=_col(time_col), rule="too-short",
            )
        bad = np.flatnonzero(~np.isfinite(t))
        if bad.size:
            raise RecordingError(
                f"non-finite time {float(t[bad[0]])!r} at {row_label(bad[0])}",
                source=src, key=_col(time_col), rule="non-finite",
            )
        step = np.diff(t)
        bad = np.flatnonzero(step <= 0.0)
        if bad.size:
            i = int(bad[0])
            raise RecordingError(
                f"time is not strictly increasing: {row_label(i + 1)} has t={float(t[i + 1])!r} after "
                f"t={float(t[i])!r} at row {i + 1}",
                source=src, key=_col(time_col), rule="time-not-increasing",
            )
        mean_step = (t[-1] - t[0]) / (len(t) - 1)
        dev = np.abs(step - mean_step) / mean_step
        worst = int(np.argmax(dev))
        if dev[worst] > TIME_JITTER_TOL:
            raise RecordingError(
                f"time step is not uniform: step {float(step[worst])!r} s between rows {worst + 1} and "
                f"{worst + 2} ({ROW_CONVENTION}; t={float(t[worst])!r}) deviates by {dev[worst]:.3g} (relative) from the "
                f"mean step {float(mean_step)!r} s; tolerance {TIME_JITTER_TOL:g}",
                source=src, key=_col(time_col), rule="time-not-uniform",
            )
        return t

    def _check_finite(self, src: str, t: np.ndarray) -> None:
        for name in self.data.columns:
            values = self.data[name].to_numpy()
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                i = int(bad[0])
                raise RecordingError(
                    f"non-finite sample {float(values[i])!r} at {row_label(i)}, t={float(t[i])!r} s; "
                    f"{bad.size} bad sample(s) in all",
                    source=src, key=_col(name), rule="non-finite",
                )

    def _check_plausible(self, src: str, t: np.ndarray) -> None:
        for name, (low, high, low_open, why) in PHYSICAL_LIMITS.items():
            if name not in self.data.columns:
                continue
            values = self.data[name].to_numpy()
            below = values <= low if low_open else values < low
            bad = np.flatnonzero(below | (values > high))
            if bad.size:
                i = int(bad[0])
                bracket = "(" if low_open else "["
                raise RecordingError(
                    f"physically impossible sample {float(values[i])!r} at {row_label(i)}, t={float(t[i])!r} s: "
                    f"{why}, accepted {bracket}{low:g}, {high:g}]; {bad.size} such sample(s) in all",
                    source=src, key=_col(name), rule="implausible-value",
                )

    def _check_required(self, src: str) -> None:
        columns = set(self.data.columns)
        missing = [CHANNELS[q].column for q in REQUIRED_QUANTITIES if CHANNELS[q].column not in columns]
        if missing:
            raise RecordingError(
                "required channel(s) missing: " + ", ".join(missing),
                source=src, key=", ".join(_col(m) for m in missing), rule="missing-channel",
            )
        controls = [CHANNELS[q].column for q in CONTROL_QUANTITIES]
        if not columns.intersection(controls):
            raise RecordingError(
                "no control-surface channel; at least one of those that moved is required",
                source=src, key=" / ".join(_col(c) for c in controls), rule="no-control-surface",
            )

    def _check_format(self, src: str) -> None:
        if "format" not in self.meta:
            raise RecordingError(
                f"metadata key is missing; expected {FORMAT_ID!r}",
                source=src, key=_metakey("format"), rule="missing-format",
            )
        if self.meta["format"] != FORMAT_ID:
            raise RecordingError(
                f"unsupported format {self.meta['format']!r}; expected {FORMAT_ID!r}",
                source=src, key=_metakey("format"), rule="bad-format",
            )

    def _check_geometry(self, src: str) -> None:
        geometry = self.meta.get("geometry")
        if geometry is None:
            raise RecordingError(
                f"geometry is missing; needs {', '.join(GEOMETRY_KEYS)}",
                source=src, key=_metakey("geometry"), rule="missing-geometry",
            )
        if not isinstance(geometry, dict):
            raise RecordingError(
                f"geometry must be an object, got {type(geometry).__name__}",
                source=src, key=_metakey("geometry"), rule="bad-geometry",
            )
        _refuse_unknown_keys(geometry, GEOMETRY_KEYS, src, "geometry")
        for key in GEOMETRY_KEYS:
            if key not in geometry:
                raise RecordingError(
                    "geometry value is missing", source=src,
                    key=_metakey("geometry", key), rule="missing-geometry",
                )
            value = geometry[key]
            if not (_finite_real(value) and value > 0):
                raise RecordingError(
                    f"geometry value must be a positive finite number, got {value!r}",
                    source=src, key=_metakey("geometry", key), rule="bad-geometry",
                )

    def _check_mass(self, src: str) -> None:
        mass = self.meta.get("mass", {})
        if not isinstance(mass, dict):
            raise RecordingError(
                f"mass must be an object, got {type(mass).__name__}",
                source=src, key=_metakey("mass"), rule="bad-mass",
            )
        _refuse_unknown_keys(mass, MASS_KEYS, src, "mass")
        for key in MASS_KEYS:
            in_meta = key in mass
            in_data = key in self.data.columns
            if in_meta and in_data:
                raise RecordingError(
                    f"given both in meta['mass'] and as channel {key!r}; give it once",
                    source=src, key=_metakey("mass", key), rule="mass-given-twice",
                )
            if not in_meta and not in_data:
                raise RecordingError(
                    f"mass property is missing: give it in meta['mass'] or as channel {key!r}",
                    source=src, key=_metakey("mass", key), rule="missing-mass",
                )
            positive = key in _POSITIVE_MASS_KEYS
            if in_meta:
                value = mass[key]
                if not _finite_real(value) or (positive and value <= 0):
                    need = "a positive finite number" if positive else "a finite number"
                    raise RecordingError(
                        f"must be {need}, got {value!r}",
                        source=src, key=_metakey("mass", key), rule="bad-mass",
                    )
            elif positive:
                values = self.data[key].to_numpy()
                bad = np.flatnonzero(values <= 0)
                if bad.size:
                    raise RecordingError(
                        f"must be positive, got {float(values[bad[0]])!r} at {row_label(bad[0])}",
                        source=src, key=_col(key), rule="bad-mass",
                    )

    def _check_optional_meta(self, src: str) -> None:
        sensors = self.meta.get("sensors")
        if sensors is not None:
            if not isinstance(sensors, dict):
                raise RecordingError(
                    f"sensors must be an object, got {type(sensors).__name__}",
                    source=src, key=_metakey("sensors"), rule="bad-sensors",
                )
            for key, pos in sensors.items():
                if key.endswith("_ft") and not (
                    isinstance(pos, (list, tuple)) and len(pos) == 3 and all(_finite_real(x) for x in pos)
                ):
                    raise RecordingError(
                        f"sensor position must be three finite numbers [x, y, z], got {pos!r}",
                        source=src, key=_metakey("sensors", key), rule="bad-sensors",
                    )
        if "thrust_offset_ft" in self.meta and not _finite_real(self.meta["thrust_offset_ft"]):
            raise RecordingError(
                f"must be a finite number, got {self.meta['thrust_offset_ft']!r}",
                source=src, key=_metakey("thrust_offset_ft"), rule="bad-thrust-offset",
            )
        if "trim" in self.meta and not isinstance(self.meta["trim"], dict):
            raise RecordingError(
                f"must be an object, got {type(self.meta['trim']).__name__}",
                source=src, key=_metakey("trim"), rule="bad-trim",
            )
        for key, value in self.meta.get("trim", {}).items():
            if not _finite_real(value):
                raise RecordingError(
                    f"trim values must be finite numbers (not text), got {value!r}",
                    source=src, key=_metakey("trim", key), rule="bad-trim",
                )
