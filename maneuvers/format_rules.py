"""The rules of the recording format, applied to a recording by :func:`validate`: canonical
columns, uniform time, finite and plausible samples, required channels, the metadata's format,
geometry, mass properties and optional keys."""
from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from maneuvers.channels import CHANNELS, REQUIRED_QUANTITIES, _is_real, _target_name
from maneuvers.recording_errors import ROW_CONVENTION, RecordingError, _col, _did_you_mean, _metakey, row_label
from models.constants import SURFACES

if TYPE_CHECKING:
    from maneuvers.recording import Recording

__all__ = ["FORMAT_ID", "TIME_JITTER_TOL", "GEOMETRY_KEYS", "MASS_KEYS", "CONTROL_QUANTITIES", "PHYSICAL_LIMITS",
           "validate"]

FORMAT_ID = "flight-recording/1"
"""Value required in ``meta['format']``."""

TIME_JITTER_TOL = 1e-6
"""Largest accepted relative deviation of a time step from the mean step (beyond the rounding
of the written times, :data:`TIME_ROUNDING_MAX_STEP_SHARE`)."""

TIME_ROUNDING_MAX_STEP_SHARE = 0.05
"""The coarsest rounding of written times read as uniform: half the written resolution at most
this share of a step. Times a ``%.8g`` export wrote at 60 or 120 Hz (16.016667 s) deviate from
the uniform grid by up to half their last decimal, 3e-5 of a 60 Hz step at 16 s and 3e-4 at
160 s, though the samples were uniform; each such time is within half its own last written unit
of the grid :func:`uniform_to_written_precision` fits. At 5 % of a step the labels are off by a
twentieth of a sample, far below the smallest time effect the diagnosis names (1.5 samples)."""

_FINEST_DECIMAL = 12  # 1e-12 s: below it a float64 time carries no written decimal to find

GEOMETRY_KEYS: tuple[str, ...] = ("S_ft2", "b_ft", "cbar_ft")
"""Keys required in ``meta['geometry']`` (positive, finite)."""

MASS_KEYS: tuple[str, ...] = ("mass_slug", "Ix_slugft2", "Iy_slugft2", "Iz_slugft2", "Ixz_slugft2")
"""Mass properties; each given in ``meta['mass']`` or as a channel of the same name."""

_POSITIVE_MASS_KEYS = frozenset(MASS_KEYS[:4])  # Ixz may have either sign

CONTROL_QUANTITIES: tuple[str, ...] = SURFACES
"""Control-surface quantities; at least one must be present."""


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


def validate(rec: Recording, source: str | None = None) -> None:
    """Apply every rule of the format to ``rec``, in order; the first one broken raises.

    Parameters
    ----------
    rec : Recording
        The recording (canonical data and metadata).
    source : str, optional
        File named in error messages; defaults to ``"recording '<name>'"``.

    Raises
    ------
    RecordingError
        At the first rule broken, naming the file, the column or key, and the rule.
    """
    src = source if source is not None else f"recording {rec.name!r}"
    _check_columns(rec, src)
    t = _check_time(rec, src)
    _check_finite(rec, src, t)
    _check_required(rec, src)
    _check_plausible(rec, src, t)
    _check_format(rec, src)
    _check_geometry(rec, src)
    _check_mass(rec, src)
    _check_optional_meta(rec, src)


def _check_columns(rec: Recording, src: str) -> None:
    seen: dict[str, str] = {}
    for name in rec.data.columns:
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
        dtype = rec.data[name].dtype
        if dtype != np.float64:
            raise RecordingError(
                f"values must be float64, got {dtype}",
                source=src, key=_col(name), rule="not-float64",
            )


def written_resolution(t: np.ndarray) -> np.ndarray:
    """Per sample, the coarsest unit its value is a whole multiple of: a power of ten down to
    1e-12 s (the last decimal a text export wrote: 16.016667 gives 1e-6) or, for a value single
    precision holds exactly, its single-precision spacing; 0 where neither shows.

    An upper bound on the rounding each written time carries (a time that ends in zeros,
    16.5, shows 0.1 though it was written to 1e-6; its deviation from the grid is then
    small anyway)."""
    t = np.asarray(t, dtype=float)
    decimal = np.zeros(t.size)
    pending = np.arange(t.size)  # one unit at a time, coarsest first: memory of the record, not 13 times it
    for unit in 10.0 ** -np.arange(0, _FINEST_DECIMAL + 1, dtype=float):
        x = t[pending] / unit
        whole = np.abs(x - np.rint(x)) <= 64.0 * np.finfo(float).eps * np.maximum(np.abs(x), 1.0)
        decimal[pending[whole]] = unit
        pending = pending[~whole]
        if not pending.size:
            break
    single = t.astype(np.float32)
    exact = single.astype(float) == t
    spacing = np.where(exact, np.spacing(np.abs(single)).astype(float), 0.0)
    return np.maximum(decimal, spacing)


def uniform_to_written_precision(t: np.ndarray) -> bool:
    """Whether times ``t`` lie on a uniform grid to within the rounding they were written with:
    each within half its :func:`written_resolution` (and the grid's own fitting error) of the
    least-squares line through them, and never more than :data:`TIME_ROUNDING_MAX_STEP_SHARE`
    of a step. The samples are then used as written."""
    t = np.asarray(t, dtype=float)
    k = np.arange(t.size, dtype=float)
    line = np.polyval(np.polyfit(k, t, 1), k)
    resid = np.abs(t - line)
    step = (t[-1] - t[0]) / (t.size - 1)
    half = np.minimum(0.5 * written_resolution(t), TIME_ROUNDING_MAX_STEP_SHARE * step)
    slack = 3.0 * float(np.sqrt(np.mean(resid ** 2))) / np.sqrt(t.size) + 8.0 * np.finfo(float).eps * float(
        np.max(np.abs(t)))
    return bool(np.all(resid <= half + slack))


def _check_time(rec: Recording, src: str) -> np.ndarray:
    time_col = CHANNELS["t"].column
    if time_col not in rec.data.columns:
        raise RecordingError(
            "time channel is missing", source=src, key=_col(time_col), rule="missing-time",
        )
    if rec.data.columns[0] != time_col:
        raise RecordingError(
            f"time must be the first column (first is {rec.data.columns[0]!r})",
            source=src, key=_col(time_col), rule="time-not-first",
        )
    t = rec.data[time_col].to_numpy()
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
    if dev[worst] > TIME_JITTER_TOL and not uniform_to_written_precision(t):
        raise RecordingError(
            f"time step is not uniform: step {float(step[worst])!r} s between rows {worst + 1} and "
            f"{worst + 2} ({ROW_CONVENTION}; t={float(t[worst])!r}) deviates by {dev[worst]:.3g} (relative) from the "
            f"mean step {float(mean_step)!r} s; tolerance {TIME_JITTER_TOL:g}, beyond the rounding of the written "
            "times",
            source=src, key=_col(time_col), rule="time-not-uniform",
        )
    return t


def _check_finite(rec: Recording, src: str, t: np.ndarray) -> None:
    for name in rec.data.columns:
        values = rec.data[name].to_numpy()
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            i = int(bad[0])
            raise RecordingError(
                f"non-finite sample {float(values[i])!r} at {row_label(i)}, t={float(t[i])!r} s; "
                f"{bad.size} bad sample(s) in all",
                source=src, key=_col(name), rule="non-finite",
            )


def _check_plausible(rec: Recording, src: str, t: np.ndarray) -> None:
    for name, (low, high, low_open, why) in PHYSICAL_LIMITS.items():
        if name not in rec.data.columns:
            continue
        values = rec.data[name].to_numpy()
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


def _check_required(rec: Recording, src: str) -> None:
    columns = set(rec.data.columns)
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


def _check_format(rec: Recording, src: str) -> None:
    if "format" not in rec.meta:
        raise RecordingError(
            f"metadata key is missing; expected {FORMAT_ID!r}",
            source=src, key=_metakey("format"), rule="missing-format",
        )
    if rec.meta["format"] != FORMAT_ID:
        raise RecordingError(
            f"unsupported format {rec.meta['format']!r}; expected {FORMAT_ID!r}",
            source=src, key=_metakey("format"), rule="bad-format",
        )


def _require_object(value, name: str, src: str, rule: str) -> None:
    """A metadata block that must be a JSON object: refused (``rule``) when it is not."""
    if not isinstance(value, dict):
        raise RecordingError(f"{name} must be an object, got {type(value).__name__}",
                             source=src, key=_metakey(name), rule=rule)


def _check_geometry(rec: Recording, src: str) -> None:
    geometry = rec.meta.get("geometry")
    if geometry is None:
        raise RecordingError(
            f"geometry is missing; needs {', '.join(GEOMETRY_KEYS)}",
            source=src, key=_metakey("geometry"), rule="missing-geometry",
        )
    _require_object(geometry, "geometry", src, "bad-geometry")
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


def _check_mass(rec: Recording, src: str) -> None:
    mass = rec.meta.get("mass", {})
    _require_object(mass, "mass", src, "bad-mass")
    _refuse_unknown_keys(mass, MASS_KEYS, src, "mass")
    for key in MASS_KEYS:
        in_meta = key in mass
        in_data = key in rec.data.columns
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
            values = rec.data[key].to_numpy()
            bad = np.flatnonzero(values <= 0)
            if bad.size:
                raise RecordingError(
                    f"must be positive, got {float(values[bad[0]])!r} at {row_label(bad[0])}",
                    source=src, key=_col(key), rule="bad-mass",
                )


def _check_optional_meta(rec: Recording, src: str) -> None:
    sensors = rec.meta.get("sensors")
    if sensors is not None:
        _require_object(sensors, "sensors", src, "bad-sensors")
        for key, pos in sensors.items():
            if key.endswith("_ft") and not (
                isinstance(pos, (list, tuple)) and len(pos) == 3 and all(_finite_real(x) for x in pos)
            ):
                raise RecordingError(
                    f"sensor position must be three finite numbers [x, y, z], got {pos!r}",
                    source=src, key=_metakey("sensors", key), rule="bad-sensors",
                )
    if "thrust_offset_ft" in rec.meta and not _finite_real(rec.meta["thrust_offset_ft"]):
        raise RecordingError(
            f"must be a finite number, got {rec.meta['thrust_offset_ft']!r}",
            source=src, key=_metakey("thrust_offset_ft"), rule="bad-thrust-offset",
        )
    if "trim" in rec.meta:
        _require_object(rec.meta["trim"], "trim", src, "bad-trim")
    for key, value in rec.meta.get("trim", {}).items():
        if not _finite_real(value):
            raise RecordingError(
                f"trim values must be finite numbers (not text), got {value!r}",
                source=src, key=_metakey("trim", key), rule="bad-trim",
            )
