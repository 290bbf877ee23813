"""The accelerometer position against the force mismatches: a position the kinematics
applied that the force mismatch along the corrected channels asks to undo is taken back; a
term the stepwise fits entered after a named position was taken out must stand beside the
position in the position's own fit, or it is the part of the position the fit did not size."""
from __future__ import annotations

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import corrected_recording, inertial_beta, interior, model_along, undriven_inertial
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.kinematics import PRACTICAL, KinematicResult
from harness.diagnosis.prepare import Prepared, interior_slice
from harness.diagnosis.sensor_rules import kinematic_estimate, plausible_kinematic_check
from harness.diagnosis.term_rules import left_impractical, term_change

__all__ = ["KINEMATIC_POSITIONS", "note_refuted_positions", "refuted_positions", "term_beside_the_position",
           "withhold_beside_the_accelerometer", "withhold_the_positions_rival", "withhold_through_the_inertial_angles",
           "withhold_vane_an_accelerometer_makes"]


# The kinematic check's accelerometer position components (effects.md's sensor_offset).
KINEMATIC_POSITIONS = ("offset_x", "offset_y", "offset_z")

# A position applied from the kinematics is refuted when the force mismatch along the
# corrected channels puts the accelerometer back, at the entry t, by at least this share of it.
REFUTED_SHARE = 0.5


def refuted_positions(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                      applied: dict[str, float]) -> dict[str, dict]:
    """The accelerometer position components the kinematics applied (``applied``, ft) that the
    force mismatch along the channels so corrected (``mismatch``) refutes: its own fit of the
    position (:func:`candidates.accelerometer_offset`) puts that component back, opposite in
    sign, at |t| >= the entry t (:data:`candidates.T_IN`) and at least :data:`REFUTED_SHARE`
    of the applied size. The kinematics size the position from a_y and a_z against the rates'
    derivatives, where a few milliseconds of the gyros' timing read as a position too; the
    force mismatch sizes it against the aerodynamics. An independent script's c172x (196 ft/s,
    doublets at 100 Hz, half the noise) had −1.15 ft applied (kinematic t −8.4, p and r 4-5 ms
    early, t −9 and −6): along the a_y so corrected, x·ṙ in C_Y, the force mismatch asked for
    +1.12 ft (t 23) and C_Y,β, C_Y,δr and C_Y,r̂ changes were named (t 48, −20, −10)."""
    names = [n for n in applied if n in KINEMATIC_POSITIONS]
    if not names:
        return {}
    off = cand.accelerometer_offset(p, mismatch, noise)
    out = {}
    for name in names:
        k = "xyz".index(name[-1])
        value, x, t = applied[name], off.position_ft[k], off.t[k]
        if abs(t) >= cand.T_IN and np.sign(x) == -np.sign(value) and abs(x) >= REFUTED_SHARE * abs(value):
            out[name] = {"applied_ft": float(value), "force_mismatch_ft": float(x),
                         "std_error_ft": float(off.std_error_ft[k]), "t": float(t)}
    return out


def note_refuted_positions(cands: list[Candidate], refuted: dict[str, dict]) -> None:
    """Say on each kinematic position component :func:`refuted_positions` took back that it
    was not applied, and why; a named one is withheld."""
    for c in cands:
        r = refuted.get(c.parameter)
        if r is None or not c.test.startswith("kinematic"):
            continue
        c.details["refuted_by_force_mismatch"] = r
        c.selected = False
        c.reason = (f"not applied or named: along the channels corrected for it ({r['applied_ft']:+.2f} ft) the "
                    f"force mismatch puts the accelerometer back by {r['force_mismatch_ft']:+.2f} ± "
                    f"{r['std_error_ft']:.2f} ft (t = {r['t']:.1f}); the kinematics' position is the gyros' timing, "
                    "not the aerodynamics'")


def term_beside_the_position(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                             axis: str, column: np.ndarray) -> tuple[float, float]:
    """The t of one force-axis term fitted together with the accelerometer position on the
    stacked, noise-weighted force mismatches (:func:`candidates.accelerometer_offset`'s fit,
    one column more: the term's, on its own axis), and the position's x there (ft).
    ``mismatch`` is the force mismatch as evaluated, the position not taken out."""
    Z, X, I = cand.stacked_forces(p, mismatch, noise)
    inner = interior_slice(p.n, p.dt)
    m = inner.stop - inner.start
    col = np.concatenate([column[inner] / noise[c] if c == axis else np.zeros(m) for c in cand.FORCE_AXES])
    keep = [a for a in "xyz" if np.ptp(X[a]) > 1e-12]
    theta, se, _ = colored_fit(Z, [X[a] for a in keep] + I + [col], keep + list(cand.FORCE_AXES) + ["term"],
                               constant=False)
    x = float(theta[keep.index("x")]) if "x" in keep else 0.0
    return (float(theta[-1] / se[-1]) if se[-1] > 0 else 0.0), x


def _term_column(selections: dict, c: Candidate) -> np.ndarray | None:
    entry = selections.get(c.channel)
    if entry is None:
        return None
    return next((term.column for term in entry[1].values() if term.parameter == c.parameter), None)


def withhold_beside_the_accelerometer(cands: list[Candidate], selections: dict, p: Prepared,
                                      mismatch: dict[str, np.ndarray], noise: dict[str, float]) -> None:
    """Deselect a force-axis term (C_X, C_Y, C_Z) that the stepwise entered after a named
    accelerometer position was taken out of the force mismatch, when beside the position, in
    the position's own fit of the three force mismatches (:func:`term_beside_the_position`),
    it falls below the entry t (:data:`candidates.T_IN`). The position is sized by a fit
    without the term; what it leaves follows q̇ (and ṗ, ṙ), which a rate or α̇ term imitates.
    An independent script's c172x (186 ft/s, pitch sweep, 25 Hz, 22° bank) with the
    accelerometer 4 ft ahead had the position named at 2.45 ± 0.34 ft and, ahead of it, a
    C_Z,α̇ change of +6.3 (t −11.4) that stood at t −2.0 beside it. ``mismatch`` is the
    force mismatch as evaluated, before the position's columns were taken out.

    Asked too where the position was read (a component at the entry t) but not named, as a
    lateral or vertical arm is not (x_accelerometer names the x component, 1.5 ft or more): a
    probe's F-16 (21,100 ft / 595 ft/s, lateral 2-1-1s at 40 Hz, 1.38 times the noise) with the
    accelerometer 6.9 ft to the right read y = 6.12 ± 0.32 ft (t 19) and had a C_Y,p̂ change of
    −1.02 named (t −5.5), the (p² + r²)·y the position puts in a_y."""
    position = next((c for c in cands if c.parameter == "x_accelerometer"), None)
    read = _read_component(position)
    if position is None or not (position.selected or read):
        return
    for c in cands:
        if not (c.selected and c.channel in cand.FORCE_AXES and c.test.startswith("stepwise")):
            continue
        column = _term_column(selections, c)
        if column is None:
            continue
        try:
            t, x = term_beside_the_position(p, mismatch, noise, c.channel, column)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        c.details["beside_the_position"] = {"t": t, "x_ft": x}
        if abs(t) >= cand.T_IN:
            continue
        c.selected = False
        c.details["sensor_rival"] = "x_accelerometer"
        if position.selected:
            c.reason = (f"entered after the named accelerometer position was taken out of the force mismatch, but "
                        f"fitted beside the position (x = {x:.2f} ft) on the three force mismatches together it "
                        f"stands at t = {t:.1f}, under the entry t of {cand.T_IN:g}: it is the part of the position "
                        "that fit left")
        else:
            c.reason = (f"entered, but imitated by the accelerometer's position, which the force mismatches read "
                        f"though x_accelerometer does not name it: fitted beside it ({read}) on the three force "
                        f"mismatches together it stands at t = {t:.1f}, under the entry t of {cand.T_IN:g}")


def _read_component(position: Candidate | None) -> str:
    """The accelerometer position's components the force mismatches read at the entry t
    (:data:`candidates.T_IN`) and of a practical size (``PRACTICAL["offset_ft"]``, as
    x_accelerometer's), as text ('' for none). (A noise-free 787-8's x of −0.06 ± 0.01 ft
    stood at t −7.7, and a C_Z α² change of −28 fell below the entry t beside it.)"""
    if position is None or "t_xyz" not in position.details:
        return ""
    d = position.details
    return ", ".join(f"{a} = {d['position_ft'][i]:.2f} ± {d['std_error_ft'][i]:.2f} ft, t = {d['t_xyz'][i]:.1f}"
                     for i, a in enumerate("xyz")
                     if abs(d["t_xyz"][i]) >= cand.T_IN and abs(d["position_ft"][i]) >= PRACTICAL["offset_ft"])


def withhold_the_positions_rival(cands: list[Candidate]) -> None:
    """Deselect the stepwise terms of the coefficient error the force mismatch could not tell
    from the accelerometer's position (``candidates.offset_rival``, the position's candidate
    ``offset_rival``) when beside the position they fall below the entry t
    (:data:`candidates.T_IN`) too: the position was not named for its rival, and its rival is
    not named for the position. (Where the error stands beside the position, as a C_Y,β change
    read as an accelerometer aft does, it stays.) An independent script's A-4 (8,400 ft /
    514 ft/s, doublets on each axis at 50 Hz in a 27° bank, no h) with the accelerometer 4 ft
    ahead had the position from the force mismatch at 1.6 ft beyond the kinematics' 2.2 ft,
    t 4.3 beside a C_Y,β change and the change t 4.0 beside it; left to the stepwise fit, the
    C_Y,β change of +0.118 was named first (t 88), the x·ṙ in a_y read as sideslip."""
    off = next((c for c in cands if c.parameter == "x_accelerometer" and "offset_rival" in c.details), None)
    if off is None or abs(off.details.get("offset_rival_t", np.inf)) >= cand.T_IN:
        return
    rivals = set(off.details["offset_rival"].split(" and "))
    for c in cands:
        if c.selected and c.test.startswith("stepwise") and c.parameter in rivals:
            c.selected = False
            c.details["sensor_rival"] = "x_accelerometer"
            t_term, t_position = off.details["offset_rival_t"], off.details["offset_t_beside"]
            c.reason = (f"entered, but not named: the force mismatch cannot tell it from the accelerometer's position "
                        f"(x = {off.estimate:.2f} ft): beside the position it stands at t = {t_term:.1f}, the position "
                        f"at t = {t_position:.1f} beside it, both under the entry t of {cand.T_IN:g}")


# The axes each inertial angle reaches where the model follows it (along.model_states).
INERTIAL_ANGLE_AXES = {"beta": ("CY", "Cl", "Cn"), "alpha": ("CX", "CZ", "Cm")}
# A term is withheld when the named position accounts for at least this share of its change.
THROUGH_THE_ANGLES_SHARE = 0.5


def withhold_through_the_inertial_angles(cands: list[Candidate], selections: dict, p: Prepared, kin, aircraft, ic,
                                         mismatch: dict[str, np.ndarray], applied: dict[str, float]) -> None:
    """Deselect a stepwise term that a named accelerometer position (x, not applied to the
    channels) makes through an inertial angle the model follows: the inertial sideslip (and an
    undriven α) is integrated from a_y (a_z), which a position off the c.g. gives ṙ·x (q̇·x),
    so the model's angle carries x·r/V and the terms of its axes follow (:data:`INERTIAL_ANGLE_AXES`).
    The model is evaluated again along the channels corrected for the named position (the
    kinematic ``offset_x``, its angles rebuilt), each term refitted beside its axis's other
    selected terms and a constant on both mismatches; withheld when the position accounts
    for :data:`THROUGH_THE_ANGLES_SHARE` of its change, or the rest is under the practical
    share. An independent script's c172r (3,300 ft / 165 ft/s, doublets on each axis in a 28°
    turn at 40 Hz) with its accelerometer 4 ft ahead had the position named (3.6 ft) and a
    C_l,r̂ change of +0.022 (t 6.6, 4.0 % of C_l's excursion) beside it: C_l,β·x·r/V."""
    named = next((c for c in cands if c.selected and c.parameter == "x_accelerometer"), None)
    if named is None or "offset_x" not in kin.parameters or "offset_x" in applied:
        return
    axes = (INERTIAL_ANGLE_AXES["beta"] if inertial_beta(p) else ()) + \
        (INERTIAL_ANGLE_AXES["alpha"] if "alpha" in undriven_inertial(p) else ())
    terms = [c for c in cands if c.selected and c.channel in axes and c.test.startswith("stepwise")]
    if not terms:
        return
    corrected = corrected_recording(p, kin, {**applied, "offset_x": named.estimate})
    changed = model_along(corrected, aircraft, ic).mismatch()
    inner = interior(p)
    for c in terms:
        sel, by_key = selections.get(c.channel, (None, {}))
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter), None)
        if key is None:
            continue
        cols = [by_key[key].column[inner]] + [by_key[k].column[inner] for k in sel.names if k != key and k in by_key]
        A = np.column_stack(cols + [np.ones(inner.stop - inner.start)])
        before = float(np.linalg.lstsq(A, mismatch[c.channel][inner], rcond=None)[0][0])
        after = float(np.linalg.lstsq(A, changed[c.channel][inner], rcond=None)[0][0])
        change = term_change(c)
        if not change:
            continue
        part = (before - after) * np.sign(change)
        if part < THROUGH_THE_ANGLES_SHARE * abs(change) and not left_impractical(c, part, abs(change)):
            continue
        c.selected = False
        c.details["sensor_rival"] = "x_accelerometer"
        c.reason = (f"entered, but not named: the accelerometer position named ({named.estimate:.2f} ft) reaches "
                    f"{c.channel} through the inertial angle the model follows, integrated from the accelerometers, "
                    f"and accounts for {part:.2g} of this change of {abs(change):.3g}")


def withhold_vane_an_accelerometer_makes(cands: list[Candidate], kin: KinematicResult, recorded: Prepared,
                                         applied: dict[str, float]) -> None:
    """Withhold an α vane's position (the kinematics' ``vane_alpha_x``) named beside an
    accelerometer position the force mismatch named (``x_accelerometer``) when, the recording
    as made (``recorded``) taken with the accelerometer at that position (the kinematic
    ``offset_x``) and the other ``applied`` corrections, the kinematics no longer take the vane
    at their entry t (:data:`kinematics.T_IN`). An accelerometer x ahead of the c.g. reads
    q̇·x/g in a_z, which the α equation integrates to q·x/V: exactly a vane x behind the c.g.
    The force mismatch tells the two apart (a vane leaves a_z alone); the α equation cannot.
    A probe's c182 (5,200 ft / 173 ft/s, pitch sweep at 50 Hz, mass channels) with its
    accelerometer 8.8 ft ahead had the position named at 6.7 ± 0.3 ft and beside it a vane
    8.8 ± 0.8 ft behind (t −11.3; probe seed 3632)."""
    accel = next((c for c in cands if c.selected and c.parameter == "x_accelerometer"), None)
    vane = next((c for c in cands if c.selected and c.parameter == "vane_alpha_x"), None)
    if accel is None or vane is None or "offset_x" not in kin.parameters or "offset_x" in applied:
        return
    others = {k: v for k, v in applied.items() if k != "vane_alpha_x"}
    found = kinematic_estimate(plausible_kinematic_check(corrected_recording(recorded, kin, others | {
        "offset_x": accel.estimate})), "vane_alpha_x")
    if found is not None and found[1] >= KIN_T_IN:
        return
    vane.selected = False
    vane.details["sensor_rival"] = "x_accelerometer"
    t = 0.0 if found is None else found[1]
    vane.reason = (f"not named: with the accelerometer at the position the force mismatch names "
                   f"({accel.estimate:.2f} ft) the kinematics stand it at t = {t:.1f}, under their entry t of "
                   f"{KIN_T_IN:g}; an accelerometer ahead of the c.g. reads q̇·x/g in a_z, which the α equation "
                   f"integrates into a vane behind it (it had been: {vane.reason})")
