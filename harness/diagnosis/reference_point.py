"""Where the model's aerodynamic reference point is, read from the recording.

The project flies the 737 with its aerodynamic reference point on the c.g. (its derivatives
are then its XML's constants, shared/jsbsim-notes.md); JSBSim ships it 1.2 ft aft of and
4.9 ft above the c.g. (:func:`models.aircraft.reference_point_alternative`). Moments about
the c.g. then differ by the aerodynamic force times that arm: on a stock 737's lateral
maneuver the side force rolls it by C_Y,β·Δz/b = −0.055 per rad of sideslip beside the XML's
C_l,β of −0.09, and its lift pitches it as a c.g. 1.2 ft forward would. A recording made by
someone else's script may have been flown either way, and the wrong placement reads as a
C_l,β error (t −13 to −478) and a moment-reference offset (t 163).

The moments about the c.g. of the two placements differ by the aerodynamic force times the
arm between them, ``ΔC_l = −Δz·C_Y/b``, ``ΔC_m = (Δz·C_X − Δx·C_Z)/c̄``, ``ΔC_n = Δx·C_Y/b``
(body axes; the 737's arm has no y part). Each moment's change is split into its arms along
the forces (an exact least-squares fit of the change on the model's force coefficients along
the states; parts whose moment is under :data:`PART_SHARE` of the largest are left out), and
each moment's mismatch (seed Eqs. 3-5) against the model as placed is regressed on its
parts, ``mismatch_c = Σ k_j·arm_j·C_F + a + b·t`` (each less a line: the model's own start
and drift), with colored-residual standard errors (seed Eq. 40).

C_F is the model's C_X and C_Y (C_Y along the inertial sideslip, clean; a measured C_X needs
the thrust, which a recording may not have) and the *measured* C_Z: the model's C_Z along a
noisy α vane carries the vane's noise and wander times C_Z,α, which pulled k towards zero
(0.38 ± 0.21 on a stock 737's 25 Hz pitch recording, 0.89 ± 0.15 on the measured C_Z). The
measured C_Z's own noise pulls k towards zero by its reliability λ = 1 − σ²_noise/σ²_C_Z
(the a_z noise level through the common filter, in coefficient units, against C_Z's
excursion): its parts are scaled by λ, and under :data:`RELIABILITY` it gives none.

A recording flown the other way has k = 1 on every part, one flown as placed k = 0 on every
part. A c.g. that is simply elsewhere (``cg_offset``, effects.md: along x) moves the parts
of the arm's x (C_m's along C_Z, C_n's along C_Y) and no other: the placement is read from
C_l's parts (along C_Y: the arm's z; and the arm's y parts) where they tell, and only where
those do not (a pitch maneuver) from each moment's whole change, ``mismatch_c = k·Σ_j
part_j + a + b·t``, which a c.g. offset moves as well (below). C_m's part along C_X (the
arm's z too) is left to the whole change: on a pitch maneuver C_X moves with C_Z, and the
two parts' joint fit split the mismatch's other structure between them (k −0.6 to −3.4 on a
stock 737's pitch recordings whose whole change said 0.9-1.0). Each group's k are combined
by inverse variance; a group tells the placement nearer its k when the other lies beyond
:data:`REFERENCE_Z` standard errors. A concealed effect that moves the same parts (a C_m,α or
c.g. change on a pitch maneuver, a C_l,β change) moves k off the placement it was flown with,
and is then sized against the nearer placement: against the one it was flown with while it
moves k less than half the way. Asked to lie within 3 s.e. of its placement as well, a stock
737 with a 1 ft c.g. offset (k 1.6) was read against the c.g. placement, its offset then
2.2 ft.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import detrend

from estimators.colored_stepwise import colored_fit
from harness.diagnosis.along import interior, model_along
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.prepare import Prepared, filtered_noise_std
from models.aircraft import Aircraft, reference_point_alternative, reference_point_text
from models.constants import G0_FPS2
from models.replay import InitialCondition

REFERENCE_Z = 5.0
"""Standard errors a group's k must lie from a placement to rule it out (the entry t of the
diagnosis's sensor tests)."""


# Parts by the component of the arm between the placements they carry (module docstring): a
# c.g. offset along x moves "Cm/CZ" and "Cn/CY" only; "<moment>/all" is the whole change.
ARM_ZY_PARTS = ("Cl/CY", "Cl/CZ", "Cn/CX")
WHOLE_CHANGES = ("Cl/all", "Cm/all", "Cn/all")
GROUPS = (("the parts no c.g. offset moves", ARM_ZY_PARTS), ("each moment's whole change", WHOLE_CHANGES))

MOMENTS = ("Cl", "Cm", "Cn")

RELIABILITY = 0.8
"""The measured C_Z gives parts only when at most a fifth of its variance (less a line) is
a_z's noise: k is then corrected by at most 1/0.8."""

ACCELEROMETERS = {"CX": "ax", "CY": "ay", "CZ": "az"}

MEASURED = ("CZ",)
"""The force coefficients taken as measured (module docstring); the others are the model's."""


@dataclass(frozen=True)
class ReferenceChoice:
    """The aircraft the diagnosis goes on with and why."""

    aircraft: Aircraft
    k: float | None
    std_error: float | None
    reason: str

    def assumption(self) -> dict:
        """findings.json's ``assumptions`` entry."""
        return {"item": "aerodynamic reference point", "missing": "-", "stood_in_by": self.reason}

    @property
    def between(self) -> bool:
        """Whether the moments put the reference point between the two placements, at least
        :data:`REFERENCE_Z` standard errors from each: neither fits, and the one taken is
        only the nearer (:func:`withhold_shift_between_placements`)."""
        if self.k is None or not self.std_error:
            return False
        return 0.0 < self.k < 1.0 and min(self.k, 1.0 - self.k) >= REFERENCE_Z * self.std_error


# The forces each moment's change between placements is split along (module docstring).
PARTS = {"Cl": ("CY", "CZ"), "Cm": ("CX", "CZ"), "Cn": ("CX", "CY")}

PART_SHARE = 0.05
"""A part whose moment (in lbf·ft per q̄S: times b or c̄) is smaller than this share of the
largest part's is left out: an arm the aircraft does not have (the 737's has no y part,
whose least-squares arm is round-off) or a force the maneuver hardly moves."""

REFERENCE_LENGTH = {"Cl": "b_ft", "Cm": "cbar_ft", "Cn": "b_ft"}


def _arms(change: np.ndarray, forces: dict[str, np.ndarray], names: tuple[str, ...]) -> dict[str, float]:
    """``change`` split along ``forces[names]``: each force's coefficient (least squares, exact
    for a transfer of the forces to another point)."""
    A = np.column_stack([forces[f] for f in names])
    return {f: float(c) for f, c in zip(names, np.linalg.lstsq(A, change, rcond=None)[0])}


def significant_arms(arms: dict[str, dict[str, float]], forces: dict[str, np.ndarray],
                     lengths: dict[str, float]) -> dict[str, dict[str, float]]:
    """``arms[moment][force]`` kept where the part's moment, ``arm·std(force)·length``, is at
    least :data:`PART_SHARE` of the largest part's."""
    size = {(c, f): abs(a) * float(np.std(forces[f])) * lengths[c] for c, by in arms.items() for f, a in by.items()}
    floor = PART_SHARE * max(size.values(), default=0.0)
    return {c: {f: a for f, a in by.items() if floor > 0.0 and size[(c, f)] >= floor} for c, by in arms.items()}


def reliabilities(p: Prepared, measured: dict[str, np.ndarray]) -> dict[str, float]:
    """Each measured force coefficient's reliability λ (module docstring) over the interior."""
    inner = interior(p)
    scale = float(np.mean(p.mass["mass_slug"] * G0_FPS2 / (p.smooth["qbar"] * p.meta["geometry"]["S_ft2"])))
    out = {}
    for f, x in measured.items():
        var = float(np.var(detrend(x[inner])))
        noise = (filtered_noise_std(p.noise_std.get(ACCELEROMETERS[f], 0.0), p.weights) * scale) ** 2
        out[f] = 1.0 - noise / var if var > 0.0 else 0.0
    return out


def reference_point_ratios(p: Prepared, aircraft: Aircraft, other: Aircraft,
                           ic: InitialCondition) -> dict[str, tuple[float, float]]:
    """Each part's k and standard error, by ``'<moment>/<force>'``, and each moment's whole
    change's, by ``'<moment>/all'`` (module docstring); empty where the placements' moments
    do not differ along the recording."""
    here, there = model_along(p, aircraft, ic), model_along(p, other, ic)
    inner = interior(p)
    forces = {f: here.aero.coefficients[f][inner] for f in ("CX", "CY", "CZ")}
    lam = reliabilities(p, {f: here.measured[f] for f in MEASURED})
    regressors = {f: (lam[f] * here.measured[f][inner] if f in MEASURED else forces[f]) for f in forces
                  if f not in MEASURED or lam[f] >= RELIABILITY}
    geometry = p.meta["geometry"]
    arms = significant_arms({c: _arms(there.aero.coefficients[c][inner] - here.aero.coefficients[c][inner], forces,
                                      names) for c, names in PARTS.items()},
                            forces, {c: geometry[g] for c, g in REFERENCE_LENGTH.items()})
    found = {}
    for c in PARTS:
        parts = {f: arm * regressors[f] for f, arm in arms[c].items() if f in regressors}
        if not parts:
            continue
        change = sum(parts.values())
        y = detrend(here.measured[c][inner] - here.aero.coefficients[c][inner])
        for columns in (parts, {"all": change}):
            theta, se, _ = colored_fit(y, [detrend(x) for x in columns.values()], list(columns), constant=False)
            found.update({f"{c}/{f}": (float(k), float(s)) for f, k, s in zip(columns, theta, se)
                          if s > 0.0 and np.isfinite(k)})
    return found


def combined_ratio(ratios: dict[str, tuple[float, float]], names: tuple[str, ...]) -> tuple[float, float] | None:
    """The inverse-variance k of the parts ``names`` found in ``ratios`` and its standard
    error; None when there are none."""
    found = [ratios[n] for n in names if n in ratios]
    if not found:
        return None
    w = np.array([1.0 / s ** 2 for _, s in found])
    return float(np.sum(w * np.array([e for e, _ in found])) / np.sum(w)), float(1.0 / np.sqrt(np.sum(w)))


def told(k: float, se: float) -> float | None:
    """The placement (0 as placed, 1 the other) a group's k tells: the nearer, when the other
    lies at least :data:`REFERENCE_Z` standard errors away; else None."""
    nearer, other = (0.0, 1.0) if abs(k) <= abs(k - 1.0) else (1.0, 0.0)
    return nearer if abs(k - other) >= REFERENCE_Z * se else None


def choose_reference_point(p: Prepared, aircraft: Aircraft, ic: InitialCondition,
                           given: str = "auto") -> ReferenceChoice | None:
    """The placement the recording says it was flown with, for a model with two
    (:func:`models.aircraft.reference_point_alternative`); None for every other model.
    ``given`` other than ``'auto'`` is the user's placement, taken as it is."""
    if given != "auto":
        return None
    other = reference_point_alternative(aircraft)
    if other is None:
        return None
    ratios = reference_point_ratios(p, aircraft, other, ic)
    here, there = reference_point_text(aircraft), reference_point_text(other)
    if not ratios:
        return ReferenceChoice(aircraft, None, None,
                               f"{here}: the recording does not tell ({there} moves no moment along it)")
    texts = []
    for group, names in GROUPS:
        found = combined_ratio(ratios, names)
        if found is None:
            continue
        k, se = found
        texts.append(f"{group}: k = {k:.2f} ± {se:.2g}")
        verdict = told(k, se)
        if verdict is None:
            continue
        measured = f"{'; '.join(texts)} of the way from {here} to {there}; --aero-reference sets it"
        if verdict == 1.0:
            return ReferenceChoice(other, k, se, f"{there}, as the recording's moments say ({measured})")
        return ReferenceChoice(aircraft, k, se, f"{here}, as the recording's moments say ({measured})")
    return ReferenceChoice(aircraft, None, None,
                           f"{here}: the recording does not tell ({'; '.join(texts)} of the way to {there}); a "
                           f"recording flown with it {there} shows a moment-reference offset")


def withhold_shift_between_placements(cands: list[Candidate], reference: ReferenceChoice | None) -> None:
    """Deselect a moment-reference shift when the recording's moments put the reference point
    between the placements (:attr:`ReferenceChoice.between`): the placement is itself what a
    shift measures, and the shift named is then the distance to the nearer placement, which
    an effect that moves the same parts (a C_m,α change on a pitch maneuver) makes as well.
    A probe's stock 737 (11,900 ft / 588 ft/s, pitch sweep, flown with the XML's placement)
    with C_m,α 0.35 higher read k = 0.44 ± 0.03 and, placed on the c.g., had a 0.58 ft shift
    named (t 68) in the C_m,α change's place."""
    if reference is None or not reference.between:
        return
    for c in cands:
        if c.selected and c.effect == "cg_offset":
            c.selected = False
            c.reason = (f"not named: the model's aerodynamic reference point is itself uncertain (the moments put it "
                        f"k = {reference.k:.2f} ± {reference.std_error:.2g} of the way between its two placements, "
                        "neither within their entry distance); a shift of the moment reference is what the other "
                        f"placement would be (it had been: {c.reason})")
