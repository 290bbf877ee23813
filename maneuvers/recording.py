"""The canonical flight recording: the in-memory type (the format's other parts are re-exported
here, so ``from maneuvers.recording import ...`` reaches all of them).

A recording is one maneuver: uniformly sampled time histories plus the metadata
needed to turn them into force and moment coefficients. The format is specified in
``../shared/recording-format.md``; these modules are its executable form, one job each:

* :mod:`maneuvers.channels`: units and the channel table. :data:`CHANNELS` (quantity,
  canonical unit, accepted units with their conversion factors, required flag, meaning);
  :func:`parse_column` splits a column name ``<quantity>_<unit>`` at its last underscore;
  :func:`to_canonical` converts a table in any accepted units to canonical units and names,
  refusing any column it does not understand.
* :mod:`maneuvers.format_rules`: the rules; :func:`~maneuvers.format_rules.validate` applies
  every one and raises :class:`RecordingError` naming the file, the column or metadata key,
  and the rule broken.
* :mod:`maneuvers.recording_errors`: that error type and how messages name columns and rows.
* this module: :class:`Recording`, canonical data and metadata; :meth:`Recording.validate`.

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

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from maneuvers.channels import (_TRUTH_PREFIX, CHANNELS, RECOGNISED_UNITS, REQUIRED_QUANTITIES, ChannelSpec,
                                canonical_names, convert_in_place, frame_from_columns, parse_column, to_canonical)
from maneuvers.format_rules import (CONTROL_QUANTITIES, FORMAT_ID, GEOMETRY_KEYS, MASS_KEYS, PHYSICAL_LIMITS,
                                    TIME_JITTER_TOL, validate)
from maneuvers.recording_errors import ROW_CONVENTION, RecordingError, _col, _metakey, row_label
from models.constants import G0_FPS2

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

    def validate(self, source: str | None = None) -> Recording:
        """Apply every rule of the format (:func:`maneuvers.format_rules.validate`).

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
        validate(self, source)
        return self
