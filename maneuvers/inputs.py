"""Registry: build an input specification from its command-line name, plus
the project's default lateral and three-axis inputs.

Kinds
-----
``doublet``, ``2-1-1-2``, ``2-1-1``, ``3-2-1-1``
    :class:`~maneuvers.multistep.MultiStep` on one surface.
``sweep-linear``, ``sweep-log``
    :class:`~maneuvers.sweeps.FrequencySweep` on one surface.
``multisine``
    :class:`~maneuvers.multisine.Multisine`; ``surface`` may be a comma list
    such as ``'de,da,dr'`` (mutually orthogonal inputs).
"""

from __future__ import annotations

from types import MappingProxyType

from maneuvers.base import InputSignal, InputSpecError
from maneuvers.combine import Sequence
from maneuvers.multisine import Multisine, PhaseMethod
from maneuvers.multistep import MULTISTEP_PATTERNS, multistep, stabilator_2112
from maneuvers.sweeps import FrequencySweep

SWEEP_KIND_NAMES: MappingProxyType[str, str] = MappingProxyType(
    {"sweep-linear": "linear", "sweep-log": "logarithmic"}
)
INPUT_KINDS: tuple[str, ...] = (*MULTISTEP_PATTERNS, "sweep-linear", "sweep-log", "multisine")
"""Names understood by :func:`make_input`."""


def _surface_list(surface: str) -> tuple[str, ...]:
    return tuple(s.strip() for s in surface.split(",") if s.strip())


def make_input(
    kind: str,
    surface: str = "de",
    amplitude_deg: float = 1.0,
    unit_pulse_s: float = 1.0,
    *,
    start_s: float = 1.0,
    quiet_after_s: float = 1.0,
    f0_hz: float = 0.1,
    f1_hz: float = 2.0,
    sweep_duration_s: float = 15.0,
    taper_s: float = 0.0,
    period_s: float = 10.0,
    f_min_hz: float = 0.1,
    f_max_hz: float = 2.0,
    phases: PhaseMethod = "optimized",
    sample_rate_hz: float | None = None,
) -> InputSignal:
    """Build the input named ``kind``.

    Parameters
    ----------
    kind
        One of :data:`INPUT_KINDS` (case-insensitive).
    surface
        ``'de'``, ``'da'`` or ``'dr'``; for ``'multisine'`` a comma list.
    amplitude_deg
        Pulse height, sweep amplitude or multisine peak, degrees.
    unit_pulse_s
        Unit-pulse width of multi-step inputs (ignored by other kinds).
    start_s, quiet_after_s
        Quiet time before and after the active window.
    f0_hz, f1_hz, sweep_duration_s, taper_s
        Sweep parameters (see :class:`~maneuvers.sweeps.FrequencySweep`).
    period_s, f_min_hz, f_max_hz, phases
        Multisine parameters (see :class:`~maneuvers.multisine.Multisine`).
    sample_rate_hz
        If given, sweeps and multisines must stay below its Nyquist frequency.

    Raises
    ------
    InputSpecError
        Unknown kind (the message lists the valid ones), several surfaces
        for a single-surface kind, or any invalid parameter.
    """
    key = kind.strip().lower()
    if key not in INPUT_KINDS:
        raise InputSpecError(
            f"unknown input kind {kind!r}; valid kinds: {', '.join(INPUT_KINDS)}"
        )
    surfaces = _surface_list(surface)
    if key == "multisine":
        return Multisine(
            surfaces=surfaces,
            period_s=period_s,
            f_min_hz=f_min_hz,
            f_max_hz=f_max_hz,
            amplitude_deg=amplitude_deg,
            phases=phases,
            start_s=start_s,
            quiet_after_s=quiet_after_s,
            sample_rate_hz=sample_rate_hz,
        )
    if len(surfaces) != 1:
        raise InputSpecError(
            f"input kind {key!r} drives exactly one surface, got {surface!r}; "
            "use 'multisine' for several surfaces at once"
        )
    if key in SWEEP_KIND_NAMES:
        return FrequencySweep(
            surface=surfaces[0],
            f0_hz=f0_hz,
            f1_hz=f1_hz,
            sweep_duration_s=sweep_duration_s,
            amplitude_deg=amplitude_deg,
            kind=SWEEP_KIND_NAMES[key],  # type: ignore[arg-type]
            start_s=start_s,
            quiet_after_s=quiet_after_s,
            taper_s=taper_s,
            sample_rate_hz=sample_rate_hz,
        )
    return multistep(key, surfaces[0], amplitude_deg, unit_pulse_s, start_s, quiet_after_s)


def default_lateral_input() -> Sequence:
    """Aileron doublet (2 deg, 1 s pulses) then rudder 2-1-1 (2 deg, 1 s pulses).

    Each part has 1 s quiet before and after and the parts are 1 s apart, so
    the motions are 3 s apart: da on [1, 3) s, dr on [6, 10) s, 11 s in all.
    """
    return Sequence(
        (multistep("doublet", "da", 2.0, 1.0), multistep("2-1-1", "dr", 2.0, 1.0)),
        gap_s=1.0,
        name="lateral_default",
    )


def default_three_axis_input() -> Sequence:
    """Stabilator 2-1-1-2 (1 deg), then aileron doublet (2 deg), then rudder 2-1-1 (2 deg).

    1 s unit pulses; each part has 1 s quiet before and after and the parts
    are 1 s apart: de on [1, 7) s, da on [10, 12) s, dr on [15, 19) s, 20 s in all.
    """
    return Sequence(
        (
            stabilator_2112(1.0, 1.0),
            multistep("doublet", "da", 2.0, 1.0),
            multistep("2-1-1", "dr", 2.0, 1.0),
        ),
        gap_s=1.0,
        name="three_axis_default",
    )
