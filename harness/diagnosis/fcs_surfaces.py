"""Whether the recording was flown with the model's FCS moving its other surfaces.

A recording carries δe, δa and δr (recording-format.md). The F-16's FCS also moves its
leading-edge flap (a switch at α = 5°) and its flaperons (with the aileron) as it flies; the
project flies and evaluates the model with the FCS disabled, those surfaces where trim put
them. A recording flown with the FCS on (a flight-test F-16, or a script that drives the stick)
then differs from the model by what those surfaces do, and the diagnosis read it as terms on
α, the surfaces or the moment reference (probe 53: up to nine wrong terms on one record). The
model is evaluated along the recording both ways (:func:`models.replay.aero_along` with
``secondary_surfaces`` "held" and "fcs") and the FCS's laws are taken when they fit the
recorded coefficients clearly better (:data:`FCS_FIT_RATIO`); the output says which, and why.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from harness.diagnosis.along import interior, model_along
from harness.diagnosis.prepare import COEFFICIENTS, Prepared
from models.aircraft import Aircraft
from models.configuration import SECONDARY_SURFACE_LAWS
from models.replay import InitialCondition

# The FCS's laws are taken when the mismatch they leave, summed over the coefficients they change
# (each as a share of its coefficient's excursion), is under this fraction of the held surfaces'
# one. A coefficient they change by less than CHANGED_SHARE of its held mismatch's RMS is left
# out (a pitch maneuver's lateral coefficients: equal both ways, they would only dilute the
# sum). Where the recording gives the two nothing to tell apart (α on one side of the flap's
# switch, no aileron) no coefficient changes and the surfaces stay held.
FCS_FIT_RATIO = 0.5
CHANGED_SHARE = 0.1
# Nor is a held mismatch switched that is under this share of the excursions: a record whose α
# dips across the flap's switch for an instant (held 0.0001 against 0.0000, noise-free) gains
# nothing worth an assumption.
MIN_HELD_SHARE = 0.01


def mismatches(p: Prepared, aircraft: Aircraft, ic: InitialCondition) -> tuple[dict, dict]:
    """The mismatch and the measured coefficients over the record's interior, the model
    evaluated along the recording as ``aircraft`` says."""
    along = model_along(p, aircraft, ic)
    inner = interior(p)
    mm = along.mismatch()
    return {c: mm[c][inner] for c in COEFFICIENTS}, {c: along.measured[c][inner] for c in COEFFICIENTS}


def compared_shares(held: dict, fcs: dict, measured: dict) -> tuple[float, float, list[str]]:
    """Σ var(mismatch)/var(measured) over the coefficients the FCS's laws change (by at least
    :data:`CHANGED_SHARE` of the held mismatch's RMS), held and moved, and those coefficients."""
    changed = [c for c in COEFFICIENTS if np.var(measured[c]) > 0
               and np.std(held[c] - fcs[c]) >= CHANGED_SHARE * np.std(held[c])]
    share = {k: sum(float(np.var(m[c]) / np.var(measured[c])) for c in changed) for k, m in (("held", held),
                                                                                          ("fcs", fcs))}
    return share["held"], share["fcs"], changed


def choose_secondary_surfaces(p: Prepared, aircraft: Aircraft, ic: InitialCondition) -> tuple[Aircraft, dict | None]:
    """``aircraft`` with its other FCS-driven surfaces held, or moved by the FCS's laws where
    the recording fits them clearly better, and the assumption that says which (None for an
    aircraft without such laws)."""
    if aircraft.name not in SECONDARY_SURFACE_LAWS:
        return aircraft, None
    moved = replace(aircraft, secondary_surfaces="fcs")
    held, measured = mismatches(p, aircraft, ic)
    held_share, fcs_share, changed = compared_shares(held, mismatches(p, moved, ic)[0], measured)
    chosen = moved if changed and held_share >= MIN_HELD_SHARE and fcs_share < FCS_FIT_RATIO * held_share \
        else aircraft
    how = ("moved as its FCS moves them (the leading-edge flap switched by alpha, the flaperons following the "
           "aileron)" if chosen is moved else "held where the model's trim put them, its FCS disabled")
    why = (f"the mismatch of {', '.join(changed)} along the recording, summed as shares of their excursions, is "
           f"{held_share:.3g} with them held and {fcs_share:.3g} moved by the FCS (moved only below "
           f"{FCS_FIT_RATIO:g} of held, and held over {MIN_HELD_SHARE:g})" if changed else
           "the FCS would not move them here (no alpha across the flap's switch, no aileron)")
    return chosen, {
        "item": "other control surfaces",
        "missing": "their positions (not recording-format channels)",
        "stood_in_by": (f"{how}: {why}; the replays and the calibration fly them held "
                        "(harness/diagnosis/fcs_surfaces.py)"),
        "choice": chosen.secondary_surfaces, "shares": {"held": held_share, "fcs": fcs_share}}
