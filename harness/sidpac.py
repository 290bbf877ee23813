"""Import SIDPAC flight-test ``.mat`` files into the canonical recording format.

A SIDPAC data file holds a time vector ``t`` (starting at 0), a data matrix
``fdata`` (N x 90) and a struct ``fds`` with the same data plus labels
(``varlab``), units (``varunits``, e.g. ``' (deg) '``), geometry (``sarea``,
``bspan``, ``cbar``) and descriptive fields. Column numbers below are SIDPAC's,
1-based.

Mapping
-------
* ``time`` (col 1): dropped as a channel; the recording's time is ``t`` (from 0)
  and the file's absolute start time goes to ``meta['sidpac']['start_time_s']``.
* Labelled channels of the format (``V``, ``alpha``, ``beta``, ``p``, ``q``, ``r``,
  ``phi``, ``the`` -> ``theta``, ``psi``, ``ax``/``ay``/``az`` (c.g.-referenced),
  ``el`` -> ``de``, ``ail`` -> ``da``, ``rdr`` -> ``dr``, ``qbar``, ``mach``,
  ``alt`` -> ``h``, ``thrust``, ``pdot``/``qdot``/``rdot``) become canonical
  channels (angles converted to rad, rates to rad/s).
* ``ail`` changes sign: the format uses JSBSim's surface signs (a positive aileron rolls
  the aircraft right, C_l,δa > 0 in the F-16, 737 and DHC6 models), while in SIDPAC's
  files a positive ``ail`` rolls it left (both Twin Otter files give C_l,δa ≈ −0.21 by
  equation error with the file's sign). The flip is written to ``meta['import_notes']``.
* ``mass``, ``Ixx``, ``Iyy``, ``Izz``, ``Ixz``: constant -> scalar in
  ``meta['mass']``; varying -> channel (``mass_slug``, ``Ix_slugft2``, ...).
* ``xcg``/``ycg``/``zcg`` (in) -> ``meta['sidpac']['cg_in']``.
* ``sarea``/``bspan``/``cbar`` -> ``meta['geometry']`` (from the ``fds`` fields).
* Every other labelled column with a known unit and not all zero -> extra channel in
  canonical units (``axm_g``, ``alphadot_rps``, ``CY_1``, ``phat_1``, ``u_fps``,
  ``tef_rad``, ``lonstk_ft``...). Blank-labelled and all-zero columns are dropped,
  except required channels, which are kept even if all zero -- with one exception:
  an all-zero ``qbar`` is physically impossible in flight and is treated as absent.
* A missing ``qbar`` is derived, and the derivation is written to
  ``meta['import_notes']``: from ``rho`` and ``V`` (0.5 rho V^2) when ``rho`` is
  recorded, otherwise from ``mach`` and ``alt`` taken as pressure altitude
  (0.7 p(h) M^2 with the ISA static pressure). If neither is possible the file is
  refused naming ``qbar_psf``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import scipy.io

from harness import isa

from maneuvers.recording import (
    CHANNELS,
    FORMAT_ID,
    REQUIRED_QUANTITIES,
    Recording,
    RecordingError,
    to_canonical,
)

__all__ = ["import_sidpac", "isa_pressure_psf"]

# SIDPAC unit text (inside the parentheses) -> unit string of the recording format.
_SIDPAC_UNITS: dict[str, str] = {
    "sec": "s",
    "fps": "fps",
    "rad": "rad",
    "deg": "deg",
    "rps": "rps",
    "dps": "dps",
    "rps2": "rps2",
    "dps2": "dps2",
    "g": "g",
    "psf": "psf",
    "ft": "ft",
    "lbf": "lbf",
    "slug": "slug",
    "slug-ft2": "slugft2",
    "": "1",
}
_IN_FT = 1.0 / 12.0

# SIDPAC label -> quantity of the format's channel table.
_LABEL_TO_QUANTITY: dict[str, str] = {
    "V": "V", "alpha": "alpha", "beta": "beta",
    "p": "p", "q": "q", "r": "r",
    "phi": "phi", "the": "theta", "psi": "psi",
    "ax": "ax", "ay": "ay", "az": "az",
    "el": "de", "ail": "da", "rdr": "dr",
    "qbar": "qbar", "mach": "mach", "alt": "h", "thrust": "thrust",
    "pdot": "pdot", "qdot": "qdot", "rdot": "rdot",
    # Mass properties. Ixz: SIDPAC uses the same sign convention as the seed's
    # Eqs. 3-5 (the format's convention), so the value is copied as is.
    "mass": "mass", "Ixx": "Ix", "Iyy": "Iy", "Izz": "Iz", "Ixz": "Ixz",
}
# Sign changes from SIDPAC's surface conventions to the format's (JSBSim's): see the docstring.
_SIGN_TO_FORMAT: dict[str, float] = {"ail": -1.0}
_MASS_QUANTITIES = ("mass", "Ix", "Iy", "Iz", "Ixz")
_CG_LABELS = ("xcg", "ycg", "zcg")
_GEOMETRY_FIELDS = {"sarea": "S_ft2", "bspan": "b_ft", "cbar": "cbar_ft"}

# ISA (ICAO standard atmosphere): harness.isa, the one home of its constants.
_ISA_R_J_PER_KG_K = isa.R_J_PER_KG_K
_GAMMA_AIR = isa.GAMMA_AIR
_FT_M = isa.FT_M


def isa_pressure_psf(h_ft: np.ndarray) -> np.ndarray:
    """Static pressure of the ISA at pressure altitude ``h_ft`` (up to 20 km).

    Parameters
    ----------
    h_ft : numpy.ndarray
        Pressure altitude, ft.

    Returns
    -------
    numpy.ndarray
        Static pressure, lbf/ft^2.

    Raises
    ------
    ValueError
        If an altitude lies above 20 km (65617 ft), beyond the two layers modelled.
    """
    p_pa = isa.pressure_pa(h_ft)
    return p_pa * CHANNELS["qbar"].units["pa"]


def _text(value: Any) -> str:
    """MATLAB char data as a Python string ('' for an empty matrix)."""
    if isinstance(value, str):
        return value
    arr = np.asarray(value)
    if arr.size == 0:
        return ""
    if arr.dtype.kind in "US":
        return "".join(str(x) for x in arr.ravel())
    if arr.size == 1:
        item = arr.item()
        return str(int(item)) if isinstance(item, float) and item.is_integer() else str(item)
    return str(value)


def _number(value: Any) -> float | None:
    """A finite scalar from a MATLAB field, or None if absent, empty or not a number."""
    arr = np.asarray(value)
    if arr.size != 1 or arr.dtype.kind not in "iuf":
        return None
    x = float(arr.item())
    return x if math.isfinite(x) else None


def _canonical_extra(unit: str) -> tuple[str, float] | None:
    """Canonical unit and factor for an extra channel in format unit ``unit``."""
    for spec in CHANNELS.values():
        if unit in spec.units:
            return spec.canonical, spec.units[unit]
    return None


def _is_constant(values: np.ndarray) -> bool:
    return bool(np.all(values == values[0]))


def import_sidpac(path: str | Path) -> Recording:
    """Read a SIDPAC ``.mat`` flight-data file as a validated canonical recording.

    Parameters
    ----------
    path : str or Path
        The ``.mat`` file (MATLAB v5, as written by SIDPAC).

    Returns
    -------
    Recording
        Named after the file stem; ``meta`` holds the format keys plus ``sidpac``
        (file details, start time, c.g. position, column provenance, dropped columns)
        and ``import_notes`` (every derivation or assumption made).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    RecordingError
        If the file lacks ``fds``/``fdata``/``t``, lengths disagree, a mapped
        channel has an unexpected unit, ``qbar`` is missing and cannot be derived,
        or the result breaks a rule of the format.
    """
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise FileNotFoundError(f"{source}: no such SIDPAC file")
    file = _read_sidpac(path)
    cols = _Columns(channels={"t_s": file.t})
    for j, (label, unit) in enumerate(zip(file.labels, file.units)):
        cols.take(j + 1, label, unit, file.fdata[:, j], source)
    if cols.blank:
        cols.dropped.append(f"{cols.blank} blank-labelled all-zero column(s)")
    _derive_qbar(cols, source)
    geometry = _geometry(file, cols)
    _check_time_column(file, cols)
    frame = to_canonical(pd.DataFrame(cols.channels), source)
    return Recording(frame, _meta(path, file, cols, geometry), name=path.stem).validate(source)


@dataclass
class _SidpacFile:
    """The parts of a SIDPAC file the import reads, checked for shape."""

    mat: dict[str, Any]
    fds: Any
    fdata: np.ndarray
    t: np.ndarray
    labels: list[str]
    units: list[str]


def _read_sidpac(path: Path) -> _SidpacFile:
    """Load the file and check it holds ``fds`` (labels, units), ``fdata`` and ``t`` of agreeing
    sizes, with no label used twice."""
    source = str(path)
    mat = _load_mat(path)
    fds = mat.get("fds")
    if fds is None or not hasattr(fds, "varlab"):
        raise RecordingError("no SIDPAC 'fds' struct with 'varlab'", source=source, key="fds",
                             rule="not-sidpac")
    for field_name in ("varunits",):
        if not hasattr(fds, field_name):
            raise RecordingError(f"the SIDPAC 'fds' struct has no {field_name!r} field (units of the fdata columns)",
                                 source=source, key=f"fds.{field_name}", rule="not-sidpac")
    if "fdata" not in mat and not hasattr(fds, "fdata"):
        raise RecordingError("no 'fdata' matrix (neither a variable nor a field of fds)", source=source,
                             key="fdata", rule="not-sidpac")
    if "t" not in mat and not hasattr(fds, "t"):
        raise RecordingError("no time vector 't' (neither a variable nor a field of fds)", source=source,
                             key="t", rule="not-sidpac")
    fdata = np.asarray(mat["fdata"] if "fdata" in mat else getattr(fds, "fdata", []), dtype=np.float64)
    t = np.asarray(mat["t"] if "t" in mat else getattr(fds, "t", []), dtype=np.float64).ravel()
    labels = [_text(x).strip() for x in np.atleast_1d(fds.varlab)]
    units = [_text(x).strip().strip("()").strip() for x in np.atleast_1d(fds.varunits)]
    if fdata.ndim != 2 or fdata.shape[0] != t.size:
        raise RecordingError(
            f"fdata has shape {fdata.shape} but t has {t.size} samples",
            source=source, key="fdata", rule="length-mismatch",
        )
    if not (len(labels) == len(units) == fdata.shape[1]):
        raise RecordingError(
            f"fds.varlab has {len(labels)} labels, fds.varunits {len(units)} units, fdata "
            f"{fdata.shape[1]} columns",
            source=source, key="fds.varlab", rule="length-mismatch",
        )
    seen_labels = [lab for lab in labels if lab]
    dupes = sorted({lab for lab in seen_labels if seen_labels.count(lab) > 1})
    if dupes:
        raise RecordingError(f"labels used by more than one column: {dupes}", source=source,
                             key="fds.varlab", rule="duplicate-quantity")
    return _SidpacFile(mat, fds, fdata, t, labels, units)


@dataclass
class _Columns:
    """What the fdata columns become: channels, mass properties, the c.g., geometry columns, the
    air density, the start time, and the notes, dropped columns and provenance that say so."""

    channels: dict[str, np.ndarray] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    dropped: list[str] = field(default_factory=list)
    provenance: dict[str, int | str] = field(default_factory=dict)
    mass_meta: dict[str, float] = field(default_factory=dict)
    cg: dict[str, Any] = field(default_factory=dict)
    geometry_columns: dict[str, float] = field(default_factory=dict)
    rho: np.ndarray | None = None
    start_time: float | None = None
    blank: int = 0

    def take(self, number: int, label: str, unit: str, values: np.ndarray, source: str) -> None:
        """Column ``number`` (1-based): a format channel, a mass property, metadata, an extra
        channel, or dropped, with the reason."""
        all_zero = not np.any(values)
        where = f"column {number} ({label!r}, unit {unit!r})"
        if not label:
            if all_zero:
                self.blank += 1
            else:
                self.dropped.append(f"column {number}: unlabelled, not all zero")
        elif label == "time":
            self.start_time = float(values[0])
        elif label in _GEOMETRY_FIELDS:
            if _is_constant(values):
                self.geometry_columns[_GEOMETRY_FIELDS[label]] = float(values[0])
        elif label in _CG_LABELS:
            self.cg[f"{label}_in"] = (float(values[0]) if _is_constant(values) else
                                      {"min": float(values.min()), "max": float(values.max()),
                                       "mean": float(values.mean())})
        elif label == "rho":
            if not all_zero:
                self.rho = values
            self.dropped.append(f"{where}: air density is not a channel of the format")
        elif label in _LABEL_TO_QUANTITY:
            self._format_channel(number, label, unit, values, where, source)
        else:
            self._extra_channel(number, label, unit, values, where)

    def _format_channel(self, number: int, label: str, unit: str, values: np.ndarray, where: str,
                        source: str) -> None:
        """A column of a quantity the format knows, converted, signed to the format's convention."""
        quantity = _LABEL_TO_QUANTITY[label]
        fmt_unit = _SIDPAC_UNITS.get(unit)
        spec = CHANNELS[quantity]
        if fmt_unit is None or fmt_unit not in spec.units:
            raise RecordingError(
                f"unit {unit!r} cannot be converted to {spec.canonical!r} for {quantity!r}",
                source=source, key=where, rule="unknown-unit",
            )
        all_zero = not np.any(values)
        if quantity == "qbar" and all_zero:
            self.notes.append(f"qbar ({where}) is all zero, impossible in flight: treated as absent.")
            return
        if all_zero and quantity not in REQUIRED_QUANTITIES:
            self.dropped.append(f"{where}: all zero")
            return
        if quantity in _MASS_QUANTITIES and _is_constant(values):
            self.mass_meta[spec.column] = float(values[0]) * spec.units[fmt_unit]
            self.provenance[f"meta.mass.{spec.column}"] = number
            return
        sign = _SIGN_TO_FORMAT.get(label, 1.0)
        if sign != 1.0:
            self.notes.append(f"{quantity} is {where} negated: SIDPAC's positive {label} rolls the aircraft left, "
                              "the format's (JSBSim's) rolls it right.")
        self.channels[f"{quantity}_{fmt_unit}"] = sign * values
        self.provenance[spec.column] = number

    def _extra_channel(self, number: int, label: str, unit: str, values: np.ndarray, where: str) -> None:
        """A column the format does not define: kept in canonical units when the unit is known."""
        if not np.any(values):
            self.dropped.append(f"{where}: all zero")
            return
        if label in CHANNELS or label.startswith("truth_") or not label.replace("_", "").isalnum():
            self.dropped.append(f"{where}: label cannot name an extra channel")
            return
        fmt_unit = _SIDPAC_UNITS.get(unit)
        if unit == "in":
            canon, factor = "ft", _IN_FT
        else:
            conv = _canonical_extra(fmt_unit) if fmt_unit is not None else None
            if conv is None:
                self.dropped.append(f"{where}: unit not known to the format")
                return
            canon, factor = conv
        name = f"{label}_{canon}"
        self.channels[name] = values * factor if factor != 1.0 else values
        self.provenance[name] = number


def _derive_qbar(cols: _Columns, source: str) -> None:
    """Dynamic pressure, when the file lacks it: 0.5 ρ V² from its ρ and V, or 0.5 γ p M² from
    its Mach number and (pressure) altitude; an error when neither is possible."""
    qbar_col = CHANNELS["qbar"].column
    channels = cols.channels
    if qbar_col in channels:
        return
    v = channels.get("V_fps")
    if cols.rho is not None and v is not None:
        channels["qbar_psf"] = 0.5 * cols.rho * v**2
        cols.notes.append("qbar_psf computed as 0.5*rho*V^2 from the file's rho and V columns.")
    elif "mach_1" in channels and "h_ft" in channels:
        mach, h = channels["mach_1"], channels["h_ft"]
        try:
            p_psf = isa_pressure_psf(h)
        except ValueError as exc:
            raise RecordingError(f"cannot derive qbar: {exc}", source=source,
                                 key=_col_name(qbar_col), rule="missing-channel") from None
        channels["qbar_psf"] = 0.5 * _GAMMA_AIR * p_psf * mach**2
        note = ("qbar_psf computed as 0.5*gamma*p*M^2 (gamma 1.4) from the file's mach and alt, "
                "alt taken as pressure altitude and p the ISA static pressure at it")
        if v is not None:
            # Consistency check: the static temperature implied by V/M vs the ISA's.
            a_fps = v / mach
            t_implied = np.mean((a_fps * _FT_M) ** 2 / (_GAMMA_AIR * _ISA_R_J_PER_KG_K))
            h_m = np.mean(h) * _FT_M
            t_isa = isa.T0_K - isa.LAPSE_K_PER_M * min(h_m, isa.TROPOPAUSE_M)
            note += (f"; check: static temperature implied by V/mach {t_implied:.1f} K, "
                     f"ISA at mean altitude {t_isa:.1f} K")
        cols.notes.append(note + ".")
    else:
        raise RecordingError(
            "dynamic pressure is missing (or all zero) and cannot be derived: needs rho and V, "
            "or mach and alt",
            source=source, key=_col_name(qbar_col), rule="missing-channel",
        )
    cols.provenance[qbar_col] = "derived"


def _geometry(file: _SidpacFile, cols: _Columns) -> dict[str, float]:
    """S, b and c̄ from ``fds`` (or a variable of the file), else from constant fdata columns."""
    geometry: dict[str, float] = {}
    for field_name, key in _GEOMETRY_FIELDS.items():
        value = _number(getattr(file.fds, field_name, None))
        if value is None:
            value = _number(file.mat.get(field_name))
        if value is None and key in cols.geometry_columns:
            value = cols.geometry_columns[key]
            cols.notes.append(f"geometry {key} taken from fdata column {field_name!r} (fds.{field_name} absent).")
        if value is not None:
            geometry[key] = value
            col = cols.geometry_columns.get(key)
            if col is not None and abs(col - value) > 1e-9 * abs(value):
                cols.notes.append(f"geometry {key}: fds.{field_name}={value!r} but fdata column has {col!r}; "
                                  "used fds.")
    return geometry


def _check_time_column(file: _SidpacFile, cols: _Columns) -> None:
    """A note when fdata's own time column disagrees with ``t`` (``t`` is used)."""
    t = file.t
    if cols.start_time is not None and t.size:
        dev = float(np.max(np.abs((file.fdata[:, file.labels.index("time")] - cols.start_time) - (t - t[0]))))
        if dev > 1e-6:
            cols.notes.append(f"the time column differs from t by up to {dev:.3g} s; t used.")


def _meta(path: Path, file: _SidpacFile, cols: _Columns, geometry: dict[str, float]) -> dict[str, Any]:
    """The recording's metadata: the format keys, the file's details and every note of the import."""
    fds, notes = file.fds, cols.notes
    aircraft = _text(getattr(fds, "aircraft", "")).strip()
    maneuver = _text(getattr(fds, "maneuver", "")).strip()
    description = _text(getattr(fds, "description", "")).strip()
    test_date = _text(getattr(fds, "test_date", "")).strip()
    varying_mass = [CHANNELS[q].column for q in _MASS_QUANTITIES if CHANNELS[q].column in cols.channels]
    if varying_mass:
        notes.append("time-varying mass properties kept as channels: " + ", ".join(varying_mass) + ".")
    notes.append("ax/ay/az are SIDPAC's c.g.-referenced accelerations (accelerometer_ft = [0, 0, 0]); "
                 "the measured ones are kept as axm_g/aym_g/azm_g when present.")
    notes.append("thrust_offset_ft is not in the file; set to 0.0, i.e. any thrust moment stays in the "
                 "moment coefficients, as in SIDPAC's own Cl/Cm/Cn columns.")
    notes.append("elevator and rudder signs copied from SIDPAC unchanged: they agree with JSBSim's (trailing edge "
                 "down, and trailing edge left, positive: the Twin Otter's C_n,δr < 0 as in JSBSim's models).")
    notes.append("Ixz copied unchanged: SIDPAC uses the seed's (Eqs. 3-5) sign convention.")
    return {
        "format": FORMAT_ID,
        "aircraft": aircraft,
        "geometry": geometry,
        "mass": cols.mass_meta,
        "sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]},
        "thrust_offset_ft": 0.0,
        "source": (f"SIDPAC file {path.name}: {aircraft}, maneuver {maneuver}, {description}, "
                   f"{test_date or 'test date not recorded'}"),
        "maneuver": description,
        "sidpac": {
            "file": path.name,
            "aircraft": aircraft,
            "maneuver": maneuver,
            "description": description,
            "test_date": test_date,
            "pilot": _text(getattr(fds, "pilot", "")).strip(),
            "created": _text(getattr(fds, "created", "")).strip(),
            "start_time_s": cols.start_time,
            "cg_in": cols.cg,
            "columns": cols.provenance,
            "dropped": cols.dropped,
        },
        "import_notes": notes,
    }


def _load_mat(path: Path) -> dict[str, Any]:
    """The variables of a MATLAB v5 file, or an error naming the file and what is wrong with it."""
    source = str(path)
    if path.stat().st_size == 0:
        raise RecordingError("file is empty", source=source, key="file", rule="bad-mat")
    try:
        return scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)
    except NotImplementedError:
        raise RecordingError("MATLAB v7.3 (HDF5) files are not supported; save it from MATLAB with "
                             "save(FILE, '-v7')", source=source, key="file", rule="unsupported-mat") from None
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - scipy's parser raises many kinds on damaged bytes
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise RecordingError(f"not a readable MATLAB v5 .mat file (empty, truncated or damaged: {text})",
                             source=source, key="file", rule="bad-mat") from None


def _col_name(name: str) -> str:
    return f"column {name!r}"
